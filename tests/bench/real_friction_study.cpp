// Real-data friction study: LuGre identified on one file of a joint, then diagnosis of
// what it leaves out, evaluated on the joint's other files (held out).
// Usage: jg_real_friction_study DATA_DIR [--start-offset]   (../shared/data/real/franka-joint-friction)
#include <cstdio>
#include <filesystem>
#include <string>

#include "diagnosis/friction_study.hpp"

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : "../shared/data/real/franka-joint-friction";
  // --start-offset: predictions offset like the data (each file's torque minus its value at
  // the first sample); the training file's constant stays with it (StudyFile).
  const bool offset_at_start = argc > 2 && std::string(argv[2]) == "--start-offset";
  if (!std::filesystem::exists(dir)) {
    std::printf("SKIP: %s not found (real data is evaluation-only and not shipped)\n", dir.c_str());
    return 0;
  }
  struct Case { const char* name; int joint; std::vector<std::string> files; std::size_t train; };
  const Case cases[] = {{"case3", 2, {"case3_slow.csv", "case3_middle.csv", "case3_high.csv"}, 1},
                        {"case4", 7, {"case4_slow.csv", "case4_middle.csv", "case4_high.csv"}, 1}};
  for (const Case& c : cases) {
    std::vector<jg::diag::StudyFile> files;
    for (const auto& f : c.files) {
      jg::diag::StudyFile sf;
      sf.path = dir + "/" + f;
      sf.read.time_column = "time";
      sf.read.torque_column_pattern = "q{j}_tau_J_compensate";
      sf.offset_at_start = offset_at_start;
      files.push_back(sf);
    }
    jg::ident::SearchRanges ranges;
    ranges.lower = {10.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    ranges.upper = {20000.0, 50.0, 10.0, 3.0, 3.0, 0.2};
    jg::ident::GaSettings ga;
    const auto r = jg::diag::friction_study(files, c.train, ga, ranges);
    std::printf("%s joint %d: LuGre sigma0 %.1f sigma1 %.3f sigma2 %.4f tau_c %.4f tau_s %.4f w_s %.4f\n", c.name, r.joint,
                r.lugre.sigma0, r.lugre.sigma1, r.lugre.sigma2, r.lugre.tau_c, r.lugre.tau_s, r.lugre.w_s);
    for (const auto& f : r.diagnosis.findings) std::printf("  finding: %s (confidence %.2f): %s\n", jg::robot::effect_cstr(f.effect), f.confidence, f.text.c_str());
    for (const auto& f : r.files)
      std::printf("  %-18s %s LuGre RMS %.4f  LuGre+effects RMS %.4f\n", std::filesystem::path(f.path).filename().c_str(),
                  f.training ? "(train)" : "(held) ", f.lugre_rms, f.extended_rms);
  }
  return 0;
}
