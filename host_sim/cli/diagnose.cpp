// `jointguard diagnose`: where simulation and a real recording differ, which physics is
// missing, its fitted parameters, and the held-out improvement. JSON per the contract,
// a human summary, and SVG plots.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "diagnosis/diagnose.hpp"
#include "diagnosis/pairing.hpp"
#include "eval/pipeline.hpp"
#include "report/svg_plot.hpp"
#include "robot/robot_model.hpp"
#include "robot/torque_kind.hpp"

namespace jg::cli {
namespace {
struct DiagnoseCliOptions {
  std::string model, real, sim, json, friction, out;
  RecordingOptions input;  ///< for --real; --sim is read as it is (its torque is what the simulation wrote)
};

/// The simulated segment that covers [t0, t1], or nullptr.
const io::Recording* covering(const std::vector<io::Recording>& segments, double t0, double t1, double dt) {
  for (const auto& s : segments) {
    if (s.t.front() <= t0 + dt && s.t.back() >= t1 - dt) return &s;
  }
  return nullptr;
}
}  // namespace

Command add_diagnose(CLI::App& app) {
  auto o = std::make_shared<DiagnoseCliOptions>();
  auto* cmd = app.add_subcommand("diagnose",
                                 "Locate where a real recording and the simulation disagree, name the missing physics,\n"
                                 "fit it and show the held-out improvement. Without --sim the model predicts the torque\n"
                                 "over the real motion (inverse dynamics + --friction).\n"
                                 "Example: jointguard diagnose --model models/ref3.yaml --real out/real.csv --sim out/sim.csv --json out/diagnosis.json --out out/diagnosis");
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--real", o->real, "Real recording (CSV)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--sim", o->sim, "Simulated recording of the same motion (CSV)")->check(CLI::ExistingFile);
  cmd->add_option("--friction", o->friction, "Nominal friction JSON (identify) for the model's prediction")->check(CLI::ExistingFile);
  cmd->add_option("--json", o->json, "Write findings here (contract format)");
  cmd->add_option("--out", o->out, "Folder for the plots (SVG) and summary");
  o->input.add_to(cmd);
  return {cmd, [o]() {
            const LoadedRecording real = load_recording(o->real, o->input);
            const auto nominal = robot::load_robot(o->model);
            // A joint torque sensor does not see the rotor: no reflected rotor inertia then.
            const auto model = robot::for_torque_kind(nominal, real.torque);
            if (real.longest().joints() != model.joints.size()) {
              throw std::invalid_argument(o->real + ": " + std::to_string(real.longest().joints()) + " joints, the model has " +
                                          std::to_string(model.joints.size()));
            }
            const sim::ArmDynamics arm(model.plant_links());
            diag::ModelContext ctx;
            ctx.arm = &arm;
            for (const auto& j : model.joints) ctx.torque_constant.push_back(j.link.torque_constant);
            for (const auto& j : nominal.joints) ctx.rotor_inertia.push_back(j.link.rotor_inertia);
            if (!o->friction.empty()) ctx.friction = eval::read_friction_json(o->friction, real.longest().joint_ids);
            // Every uniform segment of the real recording, its derivatives taken within it.
            std::vector<std::vector<diag::JointSignals>> parts;
            nlohmann::json j;
            if (!o->sim.empty()) {
              RecordingOptions sim_input;
              sim_input.max_gap_s = o->input.max_gap_s;
              const LoadedRecording simulated = load_recording(o->sim, sim_input);
              j["simulated"] = {{"resampling", resampling_json(simulated.data.report)}, {"torque", io::to_string(simulated.torque)}};
              for (const auto& seg : real.data.segments) {
                const io::Recording* s = covering(simulated.data.segments, seg.t.front(), seg.t.back(), seg.meta.sample_time);
                if (s == nullptr) {
                  throw std::invalid_argument(o->sim + ": no continuous part covers the real recording's t = " +
                                              std::to_string(seg.t.front()) + " .. " + std::to_string(seg.t.back()) + " s");
                }
                parts.push_back(about_recording(o->real, [&] { return diag::signals_from_pair(seg, *s, ctx); }));
              }
            } else {
              for (const auto& seg : real.data.segments) {
                parts.push_back(about_recording(o->real, [&] { return diag::signals_from_model(seg, ctx); }));
              }
            }
            if (parts.size() > 1) std::printf("diagnosis over all %zu segments, one after the other\n", parts.size());
            const std::vector<diag::JointSignals> signals = diag::concatenate_signals(parts);
            j["resampling"] = resampling_json(real.data.report);
            j["torque"] = io::to_string(real.torque);
            j["segments_used"] = parts.size();
            j["joints"] = nlohmann::json::array();
            if (!o->out.empty()) std::filesystem::create_directories(o->out);
            for (const auto& s : signals) {
              const diag::JointDiagnosis d = about_recording(o->real, [&] { return diag::diagnose_joint(s); });
              nlohmann::json jj{{"joint", d.joint}, {"rms_before", d.rms_before}, {"rms_after", d.rms_after},
                                {"heldout_rms_before", d.heldout_rms_before}, {"heldout_rms_after", d.heldout_rms_after},
                                {"noise_rms", d.noise_rms}, {"whiteness_ljung_box", d.whiteness_q}, {"whiteness_p", d.whiteness_p}};
              jj["findings"] = nlohmann::json::array();
              for (const auto& f : d.findings) {
                jj["findings"].push_back({{"effect", f.effect}, {"params", f.params}, {"confidence", f.confidence},
                                          {"delta_bic", f.delta_bic}, {"description", f.text}});
              }
              if (d.findings.empty()) jj["findings"].push_back({{"effect", "none"}, {"params", nlohmann::json::object()}, {"confidence", 1.0}});
              jj["location"] = {{"segments", d.location.segments.size()}, {"dependence", d.location.dependence},
                                {"best_periods_per_rev", d.location.best_periods_per_rev}, {"lag_s", d.location.lag_s},
                                {"reversal_rms", d.location.reversal_rms}, {"elsewhere_rms", d.location.elsewhere_rms}};
              jj["notes"] = d.notes;
              j["joints"].push_back(jj);
              // Human summary.
              std::printf("joint %d: ", d.joint);
              if (d.findings.empty()) {
                std::printf("nothing missing beyond the noise (%.3f N·m); RMS %.3f N·m\n", d.noise_rms, d.rms_before);
              } else {
                for (std::size_t i = 0; i < d.findings.size(); ++i) {
                  std::printf("%s%s: %s", i ? "; " : "missing ", d.findings[i].effect.c_str(), d.findings[i].text.c_str());
                }
                std::printf("; RMS %.3f -> %.3f N·m on held-out data (noise %.3f)\n", d.heldout_rms_before, d.heldout_rms_after,
                            d.noise_rms);
              }
              if (!o->out.empty()) {
                report::Plot p;
                p.title = "joint " + std::to_string(d.joint) + ": residual and fitted effects";
                p.x_label = "t [s]";
                p.y_label = "torque [N·m]";
                p.series.push_back({"residual (real - model)", s.t, s.residual, "#9aa7b8", 0.8});
                p.series.push_back({"fitted effects", s.t, d.fitted, "#d62728", 1.4});
                std::ofstream(std::filesystem::path(o->out) / ("joint" + std::to_string(d.joint) + "_residual.svg")) << report::render_svg(p);
                if (!d.findings.empty()) {  // residual against the strongest finding's variable
                  report::Plot v;
                  v.title = "joint " + std::to_string(d.joint) + ": residual against velocity";
                  v.x_label = "dq [rad/s]";
                  v.y_label = "torque [N·m]";
                  std::vector<double> after(s.size());
                  for (std::size_t k = 0; k < s.size(); ++k) after[k] = s.residual[k] - d.fitted[k];
                  v.series.push_back({"before", s.dq, s.residual, "#9aa7b8", 0.6});
                  v.series.push_back({"after", s.dq, after, "#2ca02c", 0.6});
                  std::ofstream(std::filesystem::path(o->out) / ("joint" + std::to_string(d.joint) + "_velocity.svg")) << report::render_svg(v);
                }
              }
            }
            if (!o->json.empty()) {
              write_json_file(o->json, j);
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

}  // namespace jg::cli
