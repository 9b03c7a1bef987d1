// `jointguard diagnose`: where simulation and a real recording differ, which physics is
// missing, its fitted parameters, and the held-out improvement. JSON per the contract,
// a human summary, and SVG plots.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "diagnosis/arm.hpp"
#include "diagnosis/diagnose.hpp"
#include "diagnosis/model_out.hpp"
#include "dynamics/rigid_body_identification.hpp"
#include "diagnosis/pairing.hpp"
#include "io/atomic_write.hpp"
#include "eval/pipeline.hpp"
#include "report/svg_plot.hpp"
#include "robot/robot_model.hpp"
#include "robot/robot_writer.hpp"
#include "robot/torque_kind.hpp"

namespace jg::cli {
namespace {
struct DiagnoseCliOptions {
  std::string model, real, sim, json, friction, out, model_out;
  bool no_rigid_body = false;
  robot::LoadOptions model_options;
  RecordingOptions input;  ///< for --real; --sim is read as it is (its torque is what the simulation wrote)
};

/// The simulated segment that covers [t0, t1], or nullptr.
const io::Recording* covering(const std::vector<io::Recording>& segments, double t0, double t1, double dt) {
  for (const auto& s : segments) {
    if (s.t.front() <= t0 + dt && s.t.back() >= t1 - dt) return &s;
  }
  return nullptr;
}
/// The rigid-body identification as an arm-level finding: held-out RMS per joint of the
/// robot file's rigid body (with friction fitted) against the identified model's.
void report_rigid_body(const dyn::RigidBodyIdResult& r, const robot::RobotModel& prior, nlohmann::json& arm) {
  nlohmann::json f{{"effect", "rigid_body"}, {"confidence", r.accepted ? 1.0 : 0.0}};
  nlohmann::json p = nlohmann::json::object();
  p["base_parameters"] = r.base_parameters;
  p["heldout_mse_ratio"] = r.heldout_mse_ratio;
  p["acceleration_sigma_s"] = r.acceleration.sigma_s;
  for (std::size_t j = 0; j < r.heldout_rms_after.size(); ++j) {
    const std::string n = std::to_string(j + 1);
    p["heldout_rms_file_rigid_body_joint" + n] = r.heldout_rms_prior_rigid[j];
    p["heldout_rms_file_with_friction_joint" + n] = r.heldout_rms_prior[j];
    p["heldout_rms_identified_joint" + n] = r.heldout_rms_after[j];
  }
  for (std::size_t l = 0; l < r.links.size() && l < prior.joints.size(); ++l) {
    p["link" + std::to_string(l + 1) + "_mass_kg_before"] = r.links[l].before(0);
    p["link" + std::to_string(l + 1) + "_mass_kg_after"] = r.links[l].after(0);
  }
  f["params"] = p;
  f["description"] = r.accepted ? "the arm's rigid-body parameters identified (base parameters, physically consistent), "
                                  "better on the held-out blocks than the robot file's"
                                : "identified rigid body not better on the held-out blocks: the robot file's is kept";
  std::printf("arm: rigid body %s (%d base parameters, acceleration filter %.1f ms); held-out RMS per joint, robot file + "
              "fitted friction -> identified:",
              r.accepted ? "identified" : "kept", r.base_parameters, 1e3 * r.acceleration.sigma_s);
  for (std::size_t j = 0; j < r.heldout_rms_after.size(); ++j) std::printf(" %.3f->%.3f", r.heldout_rms_prior[j], r.heldout_rms_after[j]);
  std::printf(" N·m\n");
  if (r.accepted) arm["findings"].push_back(f);
  for (const auto& n : r.notes) arm["notes"].push_back(n);
}
/// One finding in the contract's form, with its evidence against the recording's own
/// variation (the null the tool computes: docs/diagnosis.md).
nlohmann::json finding_json(const diag::Finding& f) {
  nlohmann::json out{{"effect", f.effect}, {"params", f.params}, {"confidence", f.confidence}, {"delta_bic", f.delta_bic},
                     {"description", f.text}};
  if (f.null_z > 0.0) {
    out["evidence"] = {{"null", "delete-one-block jackknife over the recording's contiguous blocks"},
                       {"z", f.null_z},
                       {"needed", diag::DiagnoseOptions{}.min_null_z}};
  }
  return out;
}

/// What the signals need of the model: `arm` (its dynamics; must outlive the context), the
/// torque constants of `model` (as read for this torque kind), the nominal rotor inertias,
/// and `friction_file`'s LuGre when one is given.
diag::ModelContext model_context(const sim::ArmDynamics& arm, const robot::RobotModel& model, const robot::RobotModel& nominal,
                                 const std::string& friction_file, const LoadedRecording& real) {
  diag::ModelContext ctx;
  ctx.arm = &arm;
  for (const auto& jd : model.joints) ctx.torque_constant.push_back(jd.link.torque_constant);
  for (const auto& jd : nominal.joints) ctx.rotor_inertia.push_back(jd.link.rotor_inertia);
  if (!friction_file.empty()) ctx.friction = eval::read_friction_json(friction_file, real.longest().joint_ids);
  return ctx;
}

/// The per-joint signals of the model's prediction over the real motion: every uniform
/// segment, its derivatives taken within it, one after the other.
std::vector<diag::JointSignals> model_signals(const LoadedRecording& real, const std::string& path, const diag::ModelContext& ctx) {
  std::vector<std::vector<diag::JointSignals>> parts;
  for (const auto& seg : real.data.segments) {
    parts.push_back(about_recording(path, [&] { return diag::signals_from_model(seg, ctx); }));
  }
  return diag::concatenate_signals(parts);
}

/// The causes named against the robot file (before the rigid-body refit) joined to those
/// found after it: one list of arm-level findings, each cause once. (The named causes' model
/// is in the links the rest was fitted with, and written back from there.)
void merge_named(const diag::ArmDiagnosis& named, diag::ArmDiagnosis& after) {
  // A cause found again after the refit is the remainder on top of the named one (both are
  // written back, added): both are listed, the named one first.
  after.findings.insert(after.findings.begin(), named.findings.begin(), named.findings.end());
  after.unexplained.insert(after.unexplained.begin(), named.unexplained.begin(), named.unexplained.end());
  std::vector<std::string> notes;
  for (const auto& n : named.notes) notes.push_back("against the robot file: " + n);
  after.notes.insert(after.notes.begin(), notes.begin(), notes.end());
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
  cmd->add_option("--json", o->json, "Write findings here (contract format)")->check(output_file());
  cmd->add_option("--out", o->out, "Folder for the plots (SVG) and summary");
  cmd->add_option("--model-out", o->model_out,
                  "Write the robot file with what was found: identified links (model vs real) and the named effects as\n"
                  "plant_effects, so that `simulate --model` and a new diagnosis include them")
      ->check(output_file());
  cmd->add_flag("--no-rigid-body", o->no_rigid_body,
                "Without --sim: keep the robot file's rigid body (default: identify the whole arm's rigid body and\n"
                "friction on the training blocks first, an arm-level finding, then diagnose what remains)");
  add_model_selection(cmd, o->model_options);
  o->input.add_to(cmd);
  return {cmd, [o]() {
            const LoadedRecording real = load_recording(o->real, o->input);
            const auto nominal = robot::load_robot(o->model, o->model_options);
            // A joint torque sensor does not see the rotor: no reflected rotor inertia then.
            const auto model = robot::for_torque_kind(nominal, real.torque);
            if (real.longest().joints() != model.joints.size()) {
              throw std::invalid_argument(o->real + ": " + std::to_string(real.longest().joints()) + " joints, the model has " +
                                          std::to_string(model.joints.size()));
            }
            nlohmann::json j;
            j["arm"] = {{"findings", nlohmann::json::array()}, {"notes", nlohmann::json::array()}};
            // Model against real: the whole arm's rigid body and friction identified first on
            // the training blocks (one cause, the arm's inertial parameters, fitted once), the
            // diagnosis then works on what that model leaves.
            robot::RobotModel used = model;
            // A robot file written by --model-out carries what an earlier diagnosis found: in the
            // prediction too (arm-level effects folded into the links, per-joint ones below).
            std::vector<robot::PlantEffect> folded;  // arm-level effects held in the links, written back as effects
            const auto model_effect_notes = diag::fold_arm_effects(used, &folded);
            diag::ArmDiagnosisOptions arm_options;
            if (!used.joints.empty()) arm_options.com_bound_m = std::max(arm_options.com_bound_m, used.joints.back().reach_m + 0.5);
            arm_options.max_payload_kg = model.rated_payload_kg;
            std::optional<dyn::RigidBodyIdResult> rb;
            // Named causes first, against the robot file itself (a payload nobody declared, a
            // link's mass): the rigid-body refit below then explains only what they leave,
            // never a payload in 40 base parameters.
            diag::ArmDiagnosis named;
            if (o->sim.empty() && !o->no_rigid_body) {
              const sim::ArmDynamics prior_arm = used.dynamics();
              const auto prior_ctx = model_context(prior_arm, model, nominal, o->friction, real);
              // Carried throughout only: a link holds it, and a step is found after the refit.
              diag::ArmDiagnosisOptions named_options = arm_options;
              named_options.payload_picked_up = false;
              named = diag::diagnose_arm(model_signals(real, o->real, prior_ctx), named_options, &prior_arm);
              // Folded alone: the file's own effects were folded (or kept) above.
              robot::RobotModel with_named = used;
              with_named.plant_effects = diag::plant_effects_of(named, {});
              diag::fold_arm_effects(with_named, &folded);
              with_named.plant_effects = used.plant_effects;
              used = with_named;
            }
            if (o->sim.empty() && !o->no_rigid_body) {
              dyn::RigidBodyIdOptions ro;
              ro.joint_torque_sensor = real.torque == io::TorqueKind::tau_j;
              try {
                rb = dyn::identify_rigid_body(real.longest(), used, ro);
              } catch (const std::invalid_argument& e) {
                std::printf("arm: rigid body not identified (%s): the robot file's is used\n", e.what());
                j["arm"]["notes"].push_back(std::string("rigid body not identified: ") + e.what());
              }
              if (rb) report_rigid_body(*rb, used, j["arm"]);
              if (rb && rb->accepted) used = rb->model;
            }
            const sim::ArmDynamics arm = used.dynamics();
            // With the arm identified, its friction is the identified one (below), not --friction's.
            const diag::ModelContext ctx = model_context(arm, model, nominal, rb ? std::string() : o->friction, real);
            // Every uniform segment of the real recording, its derivatives taken within it.
            std::vector<diag::JointSignals> signals;
            if (!o->sim.empty()) {
              std::vector<std::vector<diag::JointSignals>> parts;
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
              signals = diag::concatenate_signals(parts);
            } else {
              signals = model_signals(real, o->real, ctx);
            }
            const std::size_t segments = real.data.segments.size();
            if (segments > 1) std::printf("diagnosis over all %zu segments, one after the other\n", segments);
            for (auto& s : signals) s.joint_torque_sensor = real.torque == io::TorqueKind::tau_j;
            if (!used.plant_effects.empty() && o->sim.empty()) {
              auto notes = diag::add_joint_effects(used.plant_effects, signals);
              notes.insert(notes.begin(), model_effect_notes.begin(), model_effect_notes.end());
              std::printf("the robot file's plant_effects are in the model's prediction (%zu)\n", used.plant_effects.size());
              j["model_plant_effects"] = {{"count", used.plant_effects.size()}, {"notes", notes}};
            }
            if (rb) {
              // The identified friction is part of the model's prediction.
              for (std::size_t jj = 0; jj < signals.size() && jj < rb->friction.size(); ++jj) {
                auto& s = signals[jj];
                for (std::size_t k = 0; k < s.size(); ++k) {
                  const double f = rb->friction[jj].torque(s.dq[k]);
                  s.tau_model[k] += f;
                  s.residual[k] -= f;
                }
              }
            }
            // Causes that are one thing in the world (a payload, a link's mass) next, once
            // for the arm, then each joint.
            diag::ArmDiagnosis arm_diag = diag::diagnose_arm(signals, arm_options, &arm);
            signals = diag::without_arm_causes(signals, arm_diag);
            merge_named(named, arm_diag);
            for (const auto& n : arm_diag.notes) j["arm"]["notes"].push_back(n);
            j["arm"]["unexplained"] = nlohmann::json::array();
            for (const auto& f : arm_diag.unexplained) {
              j["arm"]["unexplained"].push_back({{"effect", f.effect}, {"params", f.params}, {"description", f.text}});
              std::printf("arm: unexplained: %s\n", f.text.c_str());
            }
            for (const auto& f : arm_diag.findings) {
              j["arm"]["findings"].push_back(finding_json(f));
              std::printf("arm: %s: %s\n", f.effect.c_str(), f.text.c_str());
            }
            if (arm_diag.findings.empty()) std::printf("arm: no payload or link mass error found\n");
            std::vector<diag::JointDiagnosis> diagnoses;
            j["resampling"] = resampling_json(real.data.report);
            j["torque"] = io::to_string(real.torque);
            j["segments_used"] = segments;
            j["joints"] = nlohmann::json::array();
            if (!o->out.empty()) std::filesystem::create_directories(o->out);
            for (const auto& s : signals) {
              const diag::JointDiagnosis d = about_recording(o->real, [&] { return diag::diagnose_joint(s); });
              diagnoses.push_back(d);
              nlohmann::json jj{{"joint", d.joint}, {"rms_before", d.rms_before}, {"rms_after", d.rms_after},
                                {"heldout_rms_before", d.heldout_rms_before}, {"heldout_rms_after", d.heldout_rms_after},
                                {"noise_rms", d.noise_rms}, {"whiteness_ljung_box", d.whiteness_q}, {"whiteness_p", d.whiteness_p}};
              jj["findings"] = nlohmann::json::array();
              for (const auto& f : d.findings) {
                jj["findings"].push_back(finding_json(f));
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
                io::write_text_atomic((std::filesystem::path(o->out) / ("joint" + std::to_string(d.joint) + "_residual.svg")).string(),
                                      report::render_svg(p));
                if (!d.findings.empty()) {  // residual against the strongest finding's variable
                  report::Plot v;
                  v.title = "joint " + std::to_string(d.joint) + ": residual against velocity";
                  v.x_label = "dq [rad/s]";
                  v.y_label = "torque [N·m]";
                  std::vector<double> after(s.size());
                  for (std::size_t k = 0; k < s.size(); ++k) after[k] = s.residual[k] - d.fitted[k];
                  v.series.push_back({"before", s.dq, s.residual, "#9aa7b8", 0.6});
                  v.series.push_back({"after", s.dq, after, "#2ca02c", 0.6});
                  io::write_text_atomic((std::filesystem::path(o->out) / ("joint" + std::to_string(d.joint) + "_velocity.svg")).string(),
                                        report::render_svg(v));
                }
              }
            }
            if (!o->model_out.empty()) {
              // The named physics written back where the simulation lives (robot file +
              // plant_effects): `simulate --model` and a new diagnosis include it.
              // Arm-level effects held in the links (the file's own and those named here) are
              // taken back out and written as effects; the same cause found again is one entry.
              robot::RobotModel out_model = rb && rb->accepted ? rb->model : used;
              out_model.plant_effects = used.plant_effects;
              for (const auto& n : diag::unfold_arm_effects(out_model, folded)) j["arm"]["notes"].push_back(n);
              const auto effects = diag::plant_effects_of(arm_diag, diagnoses);
              out_model.plant_effects = diag::merge_plant_effects(out_model.plant_effects, effects);
              robot::write_robot(o->model_out, out_model,
                                 "Written by jointguard diagnose --model " + o->model + " --real " + o->real +
                                     (o->sim.empty() ? "" : " --sim " + o->sim) + " --model-out " + o->model_out);
              j["model_out"] = {{"file", o->model_out}, {"plant_effects", out_model.plant_effects.size()}, {"rigid_body_identified", rb && rb->accepted}};
              std::printf("wrote %s: %zu plant effect(s)%s\n", o->model_out.c_str(), out_model.plant_effects.size(),
                          rb && rb->accepted ? ", identified rigid body" : "");
            }
            if (!o->json.empty()) {
              write_json_file(o->json, j);
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

}  // namespace jg::cli
