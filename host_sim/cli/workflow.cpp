// identify, calibrate, replay: the workflow on recordings.
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/identify_rigid.hpp"
#include "cli/progress.hpp"
#include "eval/pipeline.hpp"

namespace jg::cli {
namespace {
struct WorkflowOptions {
  std::string recording, model, json, friction, threshold, scalar = "float";
  double margin = 0.5;
  int debounce = 1, runs = 10;
  unsigned long long seed = 1;
  ObserverOptions observer;
  robot::LoadOptions model_options;
  RecordingOptions input;
};

/// The "resampling" and "torque" fields every workflow JSON carries.
nlohmann::json input_json(const LoadedRecording& in) {
  return {{"resampling", resampling_json(in.data.report)}, {"torque", io::to_string(in.torque)}};
}
}  // namespace

Command add_identify(CLI::App& app) {
  auto o = std::make_shared<WorkflowOptions>();
  o->observer.gains = {60.0};
  auto* cmd = app.add_subcommand("identify",
                                 "Identify LuGre friction per joint from the observer's output on a collision-free\n"
                                 "excitation recording (paper's GA, 10 runs, then Levenberg-Marquardt).\n"
                                 "Example: jointguard identify out/excitation.csv --model models/ref3.yaml --json out/friction.json");
  cmd->add_option("recording", o->recording, "Recording (CSV)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--json", o->json, "Write the identified parameters here (contract format)");
  cmd->add_option("--seed", o->seed, "GA seed")->capture_default_str();
  cmd->add_option("--runs", o->runs, "GA runs (result = mean)")->capture_default_str()->check(CLI::Range(1, 100));
  o->input.add_to(cmd);
  cmd->add_option("--gain", o->observer.gains[0], "First-order observer gain K [1/s]")->capture_default_str();
  auto rigid = std::make_shared<RigidBodyCliOptions>();
  add_rigid_body_options(cmd, *rigid);
  return {cmd, [o, rigid]() {
            const auto model = robot::load_robot(o->model, o->model_options);
            const auto in = load_recording(o->recording, o->input);
            // Rigid-body identification and the GA both fit one continuous run: the longest
            // segment when gaps split the file.
            const auto& rec = in.longest();
            if (in.data.segments.size() > 1) {
              std::printf("identify: using the longest of %zu segments, t = %.3f .. %.3f s\n", in.data.segments.size(),
                          rec.t.front(), rec.t.back());
            }
            if (rigid->enabled) {
              return run_identify_rigid(rec, o->recording, resampling_json(in.data.report), model, o->model, o->json, *rigid);
            }
            ident::GaSettings ga;
            ga.seed = o->seed;
            ga.runs = o->runs;
            Progress bar("identify");
            const auto r = about_recording(o->recording, [&] {
              return eval::identify_recording(rec, model, ObserverGains{ObserverKind::first_order, o->observer.gains[0], 0, 0}, ga,
                                              [&](double f) { bar.update(f); });
            });
            bar.finish();
            std::printf("joint  sigma0      sigma1    sigma2   tau_c    tau_s    w_s      rms [N·m]\n");
            for (std::size_t j = 0; j < r.size(); ++j) {
              const auto& p = r[j].params;
              std::printf("%5d  %9.1f  %8.2f  %7.4f  %7.4f  %7.4f  %7.5f  %.4f\n", rec.joint_ids[j], p.sigma0, p.sigma1, p.sigma2,
                          p.tau_c, p.tau_s, p.w_s, r[j].rms);
              for (const auto& w : r[j].warnings) std::printf("       warning: %s\n", w.c_str());
            }
            if (!o->json.empty()) {
              auto extra = input_json(in);
              extra["segment_used"] = {{"t_begin", rec.t.front()}, {"t_end", rec.t.back()}};
              eval::write_friction_json(o->json, r, rec.joint_ids, extra);
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

Command add_calibrate(CLI::App& app) {
  auto o = std::make_shared<WorkflowOptions>();
  auto* cmd = app.add_subcommand("calibrate",
                                 "Thresholds from a collision-free recording: max |mu| + margin per joint, with and\n"
                                 "without friction compensation, plus a stiction allowance near standstill.\n"
                                 "Example: jointguard calibrate out/free.csv --model models/ref3.yaml --friction out/friction.json --json out/threshold.json");
  cmd->add_option("recording", o->recording, "Collision-free recording (CSV)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--friction", o->friction, "Friction JSON from identify")->required()->check(CLI::ExistingFile);
  cmd->add_option("--json", o->json, "Write the thresholds here (contract format)");
  cmd->add_option("--margin", o->margin, "Safety margin added to the band [N·m]")->capture_default_str()->check(finite_range(0.0, 1000.0));
  o->input.add_to(cmd);
  o->observer.add_to(cmd);
  return {cmd, [o]() {
            const auto model = robot::load_robot(o->model, o->model_options);
            const auto in = load_recording(o->recording, o->input);
            const auto& rec = in.data.segments.front();
            const auto friction = eval::read_friction_json(o->friction, rec.joint_ids);
            const auto t = about_recording(o->recording, [&] {
              return eval::calibrate_segments(in.data.segments, model, friction, o->observer.to_gains(in.data.report.rate_hz), o->margin);
            });
            std::printf("joint  band without / with compensation [N·m]  shrink  threshold (moving)  + at standstill\n");
            for (std::size_t j = 0; j < t.threshold.size(); ++j) {
              std::printf("%5d  %12.3f / %-12.3f              %5.1fx  %10.3f          %+.3f\n", rec.joint_ids[j], t.band_uncompensated[j],
                          t.band[j], t.band_uncompensated[j] / std::max(t.threshold[j] - t.margin, 1e-9), t.threshold[j],
                          t.low_speed_extra[j]);
            }
            if (!o->json.empty()) {
              eval::write_threshold_json(o->json, t, rec.joint_ids, input_json(in));
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

Command add_replay(CLI::App& app) {
  auto o = std::make_shared<WorkflowOptions>();
  auto* cmd = app.add_subcommand("replay",
                                 "Run a recording through the firmware core (float or Q16.16) and print detections.\n"
                                 "Example: jointguard replay out/shoulder.csv --model models/ref3.yaml --friction out/friction.json --threshold out/threshold.json --scalar q");
  cmd->add_option("recording", o->recording, "Recording (CSV)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--friction", o->friction, "Friction JSON from identify")->required()->check(CLI::ExistingFile);
  cmd->add_option("--threshold", o->threshold, "Threshold JSON from calibrate")->required()->check(CLI::ExistingFile);
  cmd->add_option("--scalar", o->scalar, "Firmware scalar")->check(CLI::IsMember({"float", "q"}))->capture_default_str();
  o->input.add_to(cmd, "Control/observer rate [Hz]: the recording is resampled to it by time stamp (default: its own median step, rounded)");
  cmd->add_option("--debounce", o->debounce, "Cycles over threshold before a detection")->capture_default_str()->check(CLI::Range(1, 50));
  cmd->add_option("--json", o->json, "Write the events here (contract format)");
  o->observer.add_to(cmd);
  return {cmd, [o]() {
            const auto model = robot::load_robot(o->model, o->model_options);
            const auto in = load_recording(o->recording, o->input);
            const auto& ids = in.data.segments.front().joint_ids;
            const auto friction = eval::read_friction_json(o->friction, ids);
            const auto thresholds = eval::read_threshold_json(o->threshold, ids);
            // Each segment runs from a fresh state; events keep the recording's time stamps.
            const auto r = about_recording(o->recording, [&] {
              return eval::replay_segments(in.data.segments, model, friction, thresholds, o->observer.to_gains(in.data.report.rate_hz),
                                           o->scalar, o->debounce);
            });
            std::printf("%zu detection(s)\n", r.events.size());
            nlohmann::json j = input_json(in);
            j["events"] = nlohmann::json::array();
            for (const auto& e : r.events) {
              std::printf("  t = %.4f s: link %d (joints over threshold:", e.t, e.link);
              for (const int k : e.joints_over) std::printf(" %d", k);
              std::printf(")\n");
              j["events"].push_back({{"t", e.t}, {"link", e.link}, {"joints_over", e.joints_over}});
            }
            j["external_torque_max"] = r.external_torque_max;
            j["scalar"] = o->scalar;
            if (!o->json.empty()) {
              write_json_file(o->json, j);
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

}  // namespace jg::cli
