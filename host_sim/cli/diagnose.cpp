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
#include "diagnosis/cross_motion.hpp"
#include "cli/common.hpp"
#include "diagnosis/arm.hpp"
#include "diagnosis/diagnose.hpp"
#include "diagnosis/model_out.hpp"
#include "arm_identification/rigid_body_identification.hpp"
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
  std::string model, json, friction, out, model_out;
  std::vector<std::string> real, sim;  ///< several recordings of one arm; --sim one per --real when given
  bool no_rigid_body = false;
  bool trace = false;  ///< each selection step to stderr
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
  if (f.params.count("centred_on_last_axis") != 0) {
    // A payload centred on the last joint's axis: its sideways offset was not resolved (the
    // centred fit won), so it is unknown, not zero with zero spread.
    for (const char* k : {"com_x_m", "com_y_m", "com_x_m_sigma", "com_y_m_sigma"}) out["params"][k] = nullptr;
  }
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
  if (!friction_file.empty()) {
    ctx.friction = eval::read_friction_json(friction_file, real.longest().joint_ids);
    report_input_identity("friction", friction_file);
  }
  return ctx;
}

/// The recordings' per-joint signals one after the other: `per_segment(r, segment)` for every
/// uniform segment of every recording (derivatives taken within it). With several
/// recordings, each follows the one before on the time axis (each has its own clock), and
/// `spans` gets each one's samples.
template <class PerSegment>
std::vector<diag::JointSignals> signals_of(const std::vector<LoadedRecording>& reals, PerSegment&& per_segment,
                                           std::vector<diag::SampleSpan>* spans = nullptr) {
  std::vector<std::vector<diag::JointSignals>> parts;
  std::size_t samples = 0;
  double t_next = 0.0;
  for (std::size_t r = 0; r < reals.size(); ++r) {
    const std::size_t begin = samples;
    const double shift = r == 0 ? 0.0 : t_next - reals[r].data.segments.front().t.front();
    for (const auto& seg : reals[r].data.segments) {
      auto part = about_recording(reals[r].path, [&] { return per_segment(r, seg); });
      for (auto& js : part) {
        for (auto& t : js.t) t += shift;
      }
      if (!part.empty() && !part.front().t.empty()) {
        samples += part.front().size();
        t_next = part.front().t.back() + part.front().dt;
      }
      parts.push_back(std::move(part));
    }
    if (spans != nullptr) spans->push_back({begin, samples});
  }
  return diag::concatenate_signals(parts);
}

/// The per-joint signals of the model's prediction over the real motion.
std::vector<diag::JointSignals> model_signals(const std::vector<LoadedRecording>& reals, const diag::ModelContext& ctx,
                                              std::vector<diag::SampleSpan>* spans = nullptr) {
  return signals_of(reals, [&](std::size_t, const io::Recording& seg) { return diag::signals_from_model(seg, ctx); }, spans);
}

/// Real against simulated, each --real with its --sim (the simulated part that covers each
/// real segment).
std::vector<diag::JointSignals> paired_signals(const std::vector<LoadedRecording>& reals, const std::vector<std::string>& sims,
                                               double max_gap_s, const diag::ModelContext& ctx, nlohmann::json& j,
                                               std::vector<diag::SampleSpan>* spans) {
  std::vector<LoadedRecording> simulated;
  RecordingOptions sim_input;
  sim_input.max_gap_s = max_gap_s;
  for (const auto& path : sims) simulated.push_back(load_recording(path, sim_input));
  j["simulated"] = {{"resampling", resampling_json(simulated.front().data.report)}, {"torque", io::to_string(simulated.front().torque)}};
  return signals_of(
      reals,
      [&](std::size_t r, const io::Recording& seg) {
        const io::Recording* s = covering(simulated[r].data.segments, seg.t.front(), seg.t.back(), seg.meta.sample_time);
        if (s == nullptr) {
          throw std::invalid_argument(sims[r] + ": no continuous part covers the real recording's t = " + std::to_string(seg.t.front()) +
                                      " .. " + std::to_string(seg.t.back()) + " s");
        }
        return diag::signals_from_pair(seg, *s, ctx);
      },
      spans);
}

/// The recording whose longest segment is the longest of all (rigid-body identification,
/// joint names).
const LoadedRecording& primary(const std::vector<LoadedRecording>& reals) {
  std::size_t best = 0;
  for (std::size_t r = 1; r < reals.size(); ++r) {
    if (reals[r].longest().t.size() > reals[best].longest().t.size()) best = r;
  }
  return reals[best];
}

/// Reads every --real; they must be of one arm (joint count and torque kind) and fit the model.
std::vector<LoadedRecording> load_reals(const DiagnoseCliOptions& o, std::size_t model_joints) {
  std::vector<LoadedRecording> reals;
  for (const auto& path : o.real) {
    reals.push_back(load_recording(path, o.input));
    const auto& r = reals.back();
    if (r.longest().joints() != model_joints) {
      throw std::invalid_argument(path + ": " + std::to_string(r.longest().joints()) + " joints, the model has " +
                                  std::to_string(model_joints));
    }
    if (r.torque != reals.front().torque) {
      throw std::invalid_argument(path + ": torque columns of kind " + io::to_string(r.torque) + ", " + o.real.front() +
                                  " has " + io::to_string(reals.front().torque) + ": give --torque-kind");
    }
  }
  return reals;
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

/// What the diagnosis reports for the recordings as a whole.
struct DiagnoseRun {
  std::vector<LoadedRecording> reals;
  std::vector<std::string> names;  ///< the --real paths
  robot::RobotModel nominal, model, used;
  robot::RobotModel before_refit;  ///< `used` before the rigid-body refit replaced its links
  std::vector<robot::PlantEffect> folded;  ///< arm-level effects held in the links, written back as effects
  std::vector<std::string> model_effect_notes;
  diag::ArmDiagnosisOptions arm_options;
  std::optional<dyn::RigidBodyIdResult> rb;
  diag::ArmDiagnosis named;  ///< causes named against the robot file, before the refit
  nlohmann::json j;
};

/// An arm-level diagnosis whose causes did not transfer between recordings: nothing claimed,
/// what it found reported as unexplained.
void withdraw_arm_causes(diag::ArmDiagnosis& a, const std::string& why) {
  for (auto f : a.findings) {
    f.text += " (" + why + ")";
    a.unexplained.push_back(f);
  }
  a.findings.clear();
  a.model.clear();
  for (auto& e : a.explained) std::fill(e.begin(), e.end(), 0.0);
  std::fill(a.explained_rms.begin(), a.explained_rms.end(), 0.0);
  a.notes.push_back(why);
}

/// Named causes first, against the robot file itself (a payload nobody declared, a link's
/// mass): the rigid-body refit then explains only what they leave, never a payload in 40 base
/// parameters. Folded into `run.used`.
void name_causes_against_file(const DiagnoseCliOptions& o, DiagnoseRun& run) {
  const sim::ArmDynamics prior_arm = run.used.dynamics();
  const auto prior_ctx = model_context(prior_arm, run.used, run.nominal, o.friction, primary(run.reals));
  // Carried throughout only: a link holds it, and a step is found after the refit.
  diag::ArmDiagnosisOptions named_options = run.arm_options;
  named_options.payload_picked_up = false;
  // A drive's torque constant scales what the currents read: named here, against the file,
  // where the refit's base parameters have not yet taken it.
  named_options.torque_constants = primary(run.reals).torque == io::TorqueKind::current;
  std::vector<diag::SampleSpan> spans;
  const auto signals = model_signals(run.reals, prior_ctx, &spans);
  run.named = diag::diagnose_arm(signals, named_options, &prior_arm);
  if (spans.size() > 1 && !run.named.findings.empty()) {
    // Several recordings: what is named must hold for each of them, fitted on the others.
    const auto folds = diag::cross_motion_folds(signals, spans, named_options, &prior_arm, false);
    run.j["cross_motion_named"] = nlohmann::json::array();
    for (const auto& f : folds) {
      run.j["cross_motion_named"].push_back(
          {{"left_out", run.names[f.left_out]}, {"arm_causes", f.arm_causes}, {"arm_mse_ratio", f.arm_mse_ratio}});
    }
    if (const std::string why = diag::arm_not_transferring(folds, run.names, diag::cause_names(run.named.model)); !why.empty()) {
      withdraw_arm_causes(run.named, why);
    }
  }
  // Folded alone: the file's own effects were folded (or kept) before.
  robot::RobotModel with_named = run.used;
  with_named.plant_effects = diag::plant_effects_of(run.named, {});
  diag::fold_arm_effects(with_named, &run.folded);
  diag::fold_drive_effects(with_named, &run.folded);
  with_named.plant_effects = run.used.plant_effects;
  run.used = with_named;
}

/// The whole arm's rigid body and friction identified on the training blocks of the longest
/// segment (one cause, the arm's inertial parameters, fitted once); the diagnosis then works
/// on what that model leaves.
void refit_rigid_body(DiagnoseRun& run) {
  const LoadedRecording& real = primary(run.reals);
  dyn::RigidBodyIdOptions ro;
  ro.joint_torque_sensor = real.torque == io::TorqueKind::tau_j;
  ro.friction_offset = false;  // a constant is `current_offset`'s to name, per joint, against its null
  if (!run.used.plant_effects.empty()) {
    // The file's per-joint effects are part of the model (the loop's second round): the
    // friction and links are identified on top of them, as the diagnosis will predict with
    // them, so the baseline does not take them a second time.
    const sim::ArmDynamics arm = run.used.dynamics();
    const diag::ModelContext ctx = model_context(arm, run.used, run.nominal, std::string(), real);
    ro.known_torque = diag::joint_effects_torque(run.used.plant_effects, diag::signals_from_model(real.longest(), ctx), nullptr);
  }
  try {
    run.rb = dyn::identify_rigid_body(real.longest(), run.used, ro);
  } catch (const std::invalid_argument& e) {
    std::printf("arm: rigid body not identified (%s): the robot file's is used\n", e.what());
    run.j["arm"]["notes"].push_back(std::string("rigid body not identified: ") + e.what());
  }
  if (run.rb) report_rigid_body(*run.rb, run.used, run.j["arm"]);
  run.before_refit = run.used;
  if (run.rb && run.rb->accepted) run.used = run.rb->model;
}

/// The signals the diagnosis works on: real against simulated, or against the model's
/// prediction with the file's per-joint effects and the identified friction in it.
std::vector<diag::JointSignals> diagnosis_signals(const DiagnoseCliOptions& o, const sim::ArmDynamics& arm, DiagnoseRun& run,
                                                  std::vector<diag::SampleSpan>& spans) {
  const LoadedRecording& real = primary(run.reals);
  // With the arm identified, its friction is the identified one (below), not --friction's.
  const diag::ModelContext ctx = model_context(arm, run.used, run.nominal, run.rb ? std::string() : o.friction, real);
  std::vector<diag::JointSignals> signals = o.sim.empty() ? model_signals(run.reals, ctx, &spans)
                                                          : paired_signals(run.reals, o.sim, o.input.max_gap_s, ctx, run.j, &spans);
  std::size_t segments = 0;
  for (const auto& r : run.reals) segments += r.data.segments.size();
  if (segments > 1) std::printf("diagnosis over all %zu segments, one after the other\n", segments);
  for (auto& s : signals) s.joint_torque_sensor = real.torque == io::TorqueKind::tau_j;
  if (!run.used.plant_effects.empty() && o.sim.empty()) {
    auto notes = diag::add_joint_effects(run.used.plant_effects, signals);
    notes.insert(notes.begin(), run.model_effect_notes.begin(), run.model_effect_notes.end());
    std::printf("the robot file's plant_effects are in the model's prediction (%zu)\n", run.used.plant_effects.size());
    run.j["model_plant_effects"] = {{"count", run.used.plant_effects.size()}, {"notes", notes}};
  }
  if (run.rb) {  // the identified friction is part of the model's prediction
    for (std::size_t jj = 0; jj < signals.size() && jj < run.rb->friction.size(); ++jj) {
      auto& s = signals[jj];
      for (std::size_t k = 0; k < s.size(); ++k) {
        const double f = run.rb->friction[jj].torque(s.dq[k]);
        s.tau_model[k] += f;
        s.residual[k] -= f;
      }
    }
  }
  run.j["segments_used"] = segments;
  return signals;
}

/// What transfers between the recordings (leave-one-recording-out); with one recording
/// nothing to do. Returns the (joint, effect) pairs that do not transfer; the arm's reason,
/// if its causes do not, in `arm_why`.
std::vector<diag::NotTransferring> cross_motion(const std::vector<diag::JointSignals>& signals,
                                                const std::vector<diag::SampleSpan>& spans, const sim::ArmDynamics& arm,
                                                const std::vector<std::string>& claimed, DiagnoseRun& run,
                                                std::string& arm_why) {
  if (spans.size() < 2) return {};
  const auto folds = diag::cross_motion_folds(signals, spans, run.arm_options, &arm);
  nlohmann::json cm = nlohmann::json::array();
  for (const auto& f : folds) {
    nlohmann::json jf{{"left_out", run.names[f.left_out]}, {"arm_causes", f.arm_causes}, {"arm_mse_ratio", f.arm_mse_ratio}};
    jf["joints"] = nlohmann::json::array();
    std::printf("cross-motion: fitted on the others, %s: RMS per joint before -> after", run.names[f.left_out].c_str());
    for (const auto& cj : f.joints) {
      jf["joints"].push_back({{"joint", cj.joint}, {"rms_before", cj.rms_before}, {"rms_after_arm", cj.rms_after_arm},
                              {"rms_after", cj.rms_after}, {"effects", cj.effects}, {"worse_effects", cj.worse_effects}});
      std::printf(" %.3f->%.3f", cj.rms_before, cj.rms_after);
    }
    std::printf(" N·m\n");
    cm.push_back(jf);
  }
  run.j["cross_motion"] = cm;
  arm_why = diag::arm_not_transferring(folds, run.names, claimed);
  return diag::effects_not_transferring(folds, run.names);
}

void report_arm(const diag::ArmDiagnosis& arm_diag, nlohmann::json& j) {
  for (const auto& n : arm_diag.notes) j["arm"]["notes"].push_back(n);
  j["arm"]["unexplained"] = nlohmann::json::array();
  for (const auto& f : arm_diag.unexplained) {
    j["arm"]["unexplained"].push_back({{"effect", f.effect}, {"params", f.params}, {"description", f.text}});
    std::printf("arm: unexplained: %s\n", f.text.c_str());
  }
  for (const auto& f : arm_diag.findings) {
    j["arm"]["findings"].push_back(finding_json(f));
    std::printf("arm: %s: %s\n", robot::effect_cstr(f.effect), f.text.c_str());
  }
  if (arm_diag.findings.empty()) std::printf("arm: no payload or link mass error found\n");
}

/// What the diagnosis leaves unexplained on a joint, as a multiple of its noise: the held-out
/// RMS after the findings over the noise estimated from the data. Above kUnexplainedOverNoise a
/// mismatch remains that no effect of the vocabulary explains; said so, never "nothing missing".
constexpr double kUnexplainedOverNoise = 1.5;
double heldout_rms_left(const diag::JointDiagnosis& d) { return d.findings.empty() ? d.heldout_rms_before : d.heldout_rms_after; }
double unexplained_over_noise(const diag::JointDiagnosis& d) {
  return d.noise_rms > 0.0 ? heldout_rms_left(d) / d.noise_rms : 0.0;
}

nlohmann::json joint_json(const diag::JointDiagnosis& d) {
  nlohmann::json jj{{"joint", d.joint}, {"rms_before", d.rms_before}, {"rms_after", d.rms_after},
                    {"heldout_rms_before", d.heldout_rms_before}, {"heldout_rms_after", d.heldout_rms_after},
                    {"noise_rms", d.noise_rms}, {"whiteness_ljung_box", d.whiteness_q}, {"whiteness_p", d.whiteness_p}};
  jj["findings"] = nlohmann::json::array();
  for (const auto& f : d.findings) jj["findings"].push_back(finding_json(f));
  if (d.findings.empty()) jj["findings"].push_back({{"effect", robot::Effect::none}, {"params", nlohmann::json::object()}, {"confidence", 1.0}});
  jj["location"] = {{"segments", d.location.segments.size()}, {"dependence", d.location.dependence},
                    {"best_periods_per_rev", d.location.best_periods_per_rev}, {"lag_s", d.location.lag_s},
                    {"reversal_rms", d.location.reversal_rms}, {"elsewhere_rms", d.location.elsewhere_rms}};
  jj["notes"] = d.notes;
  if (const double r = unexplained_over_noise(d); r > kUnexplainedOverNoise) {
    jj["unexplained"] = {{"heldout_rms", heldout_rms_left(d)},
                         {"over_noise", r},
                         {"description", "a mismatch no effect of the vocabulary explains"}};
  }
  return jj;
}

void print_joint(const diag::JointDiagnosis& d) {
  std::printf("joint %d: ", d.joint);
  const double unexplained = unexplained_over_noise(d);
  if (d.findings.empty()) {
    if (unexplained > kUnexplainedOverNoise) {
      std::printf("unexplained: held-out RMS %.3f N·m, %.1fx the noise (%.3f N·m), and no effect of the vocabulary "
                  "explains it\n",
                  d.heldout_rms_before, unexplained, d.noise_rms);
    } else {
      std::printf("nothing missing beyond the noise (%.3f N·m); RMS %.3f N·m\n", d.noise_rms, d.rms_before);
    }
    return;
  }
  for (std::size_t i = 0; i < d.findings.size(); ++i) {
    std::printf("%s%s: %s", i ? "; " : "missing ", robot::effect_cstr(d.findings[i].effect), d.findings[i].text.c_str());
  }
  std::printf("; RMS %.3f -> %.3f N·m on held-out data (noise %.3f)", d.heldout_rms_before, d.heldout_rms_after, d.noise_rms);
  if (unexplained > kUnexplainedOverNoise) std::printf("; %.1fx the noise remains unexplained", unexplained);
  std::printf("\n");
}

void plot_joint(const std::string& out, const diag::JointSignals& s, const diag::JointDiagnosis& d) {
  report::Plot p;
  p.title = "joint " + std::to_string(d.joint) + ": residual and fitted effects";
  p.x_label = "t [s]";
  p.y_label = "torque [N·m]";
  p.series.push_back({"residual (real - model)", s.t, s.residual, "#9aa7b8", 0.8});
  p.series.push_back({"fitted effects", s.t, d.fitted, "#d62728", 1.4});
  io::write_text_atomic((std::filesystem::path(out) / ("joint" + std::to_string(d.joint) + "_residual.svg")).string(),
                        report::render_svg(p));
  if (d.findings.empty()) return;
  report::Plot v;  // residual against the strongest finding's variable
  v.title = "joint " + std::to_string(d.joint) + ": residual against velocity";
  v.x_label = "dq [rad/s]";
  v.y_label = "torque [N·m]";
  std::vector<double> after(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) after[k] = s.residual[k] - d.fitted[k];
  v.series.push_back({"before", s.dq, s.residual, "#9aa7b8", 0.6});
  v.series.push_back({"after", s.dq, after, "#2ca02c", 0.6});
  io::write_text_atomic((std::filesystem::path(out) / ("joint" + std::to_string(d.joint) + "_velocity.svg")).string(),
                        report::render_svg(v));
}

/// The named physics written back where the simulation lives (robot file + plant_effects):
/// `simulate --model` and a new diagnosis include it. Arm-level effects held in the links
/// (the file's own and those named here) are taken back out and written as effects; the same
/// cause found again is one entry.
void write_model_out(const DiagnoseCliOptions& o, DiagnoseRun& run, const diag::ArmDiagnosis& arm_diag,
                     const std::vector<diag::JointDiagnosis>& diagnoses) {
  bool identified = run.rb && run.rb->accepted;
  robot::RobotModel out_model = identified ? run.rb->model : run.used;
  out_model.plant_effects = run.used.plant_effects;
  auto notes = diag::unfold_arm_effects(out_model, run.folded);
  if (identified && !notes.empty()) {
    // A cause named against the file (a payload) cannot be taken back out of the identified
    // links: written as itself on the file's rigid body, never hidden in a link.
    out_model = run.before_refit;
    out_model.plant_effects = run.used.plant_effects;
    notes = diag::unfold_arm_effects(out_model, run.folded);
    notes.push_back("the identified rigid body is not written: a named cause could not be taken back out of its links");
    identified = false;
  }
  for (const auto& n : notes) run.j["arm"]["notes"].push_back(n);
  const auto effects = diag::plant_effects_of(arm_diag, diagnoses);
  out_model.plant_effects = diag::merge_plant_effects(out_model.plant_effects, effects);
  std::string how = "Written by jointguard diagnose --model " + o.model;
  for (const auto& r : o.real) how += " --real " + r;
  for (const auto& s : o.sim) how += " --sim " + s;
  robot::write_robot(o.model_out, out_model, how + " --model-out " + o.model_out);
  run.j["model_out"] = {{"file", o.model_out}, {"plant_effects", out_model.plant_effects.size()}, {"rigid_body_identified", identified}};
  std::printf("wrote %s: %zu plant effect(s)%s\n", o.model_out.c_str(), out_model.plant_effects.size(),
              identified ? ", identified rigid body" : "");
}

/// The effects of `joint` that did not transfer, and the notes saying so.
diag::DiagnoseOptions joint_options(int joint, const std::vector<diag::NotTransferring>& not_transferring, bool trace,
                                    std::vector<std::string>& notes) {
  diag::DiagnoseOptions jo;
  jo.trace = trace;
  for (const auto& n : not_transferring) {
    if (n.joint != joint) continue;
    jo.excluded_effects.push_back(n.effect);
    notes.push_back(n.why);
  }
  return jo;
}

int run_diagnose(const DiagnoseCliOptions& o) {
  if (!o.sim.empty() && o.sim.size() != o.real.size()) {
    std::fprintf(stderr, "jointguard diagnose: error: --sim: give one per --real (%zu, in their order), or none; got %zu\n",
                 o.real.size(), o.sim.size());
    return 2;
  }
  DiagnoseRun run;
  run.names = o.real;
  run.nominal = robot::load_robot(o.model, o.model_options);
  run.reals = load_reals(o, run.nominal.joints.size());
  const LoadedRecording& real = primary(run.reals);
  // A joint torque sensor does not see the rotor: no reflected rotor inertia then.
  run.model = robot::for_torque_kind(run.nominal, real.torque);
  run.j["arm"] = {{"findings", nlohmann::json::array()}, {"notes", nlohmann::json::array()}};
  run.used = run.model;
  // A robot file written by --model-out carries what an earlier diagnosis found: in the
  // prediction too (arm-level effects folded into the links, per-joint ones below).
  run.model_effect_notes = diag::fold_arm_effects(run.used, &run.folded);
  // The file's torque-constant errors in its drives' K_I, as they read the currents (against
  // the robot file; a simulated recording made with them carries them already).
  if (o.sim.empty() && real.torque == io::TorqueKind::current) diag::fold_drive_effects(run.used, &run.folded);
  if (!run.used.joints.empty()) run.arm_options.com_bound_m = std::max(run.arm_options.com_bound_m, run.used.joints.back().reach_m + 0.5);
  run.arm_options.max_payload_kg = run.model.rated_payload_kg;
  run.arm_options.joint.trace = o.trace;
  // Each recording has its own clock: a payload picked up "when" is not one thing across them.
  if (run.reals.size() > 1) run.arm_options.payload_picked_up = false;
  if (o.sim.empty() && !o.no_rigid_body) {
    name_causes_against_file(o, run);
    refit_rigid_body(run);
  }
  const sim::ArmDynamics arm = run.used.dynamics();
  std::vector<diag::SampleSpan> spans;
  std::vector<diag::JointSignals> signals = diagnosis_signals(o, arm, run, spans);
  // Causes that are one thing in the world (a payload, a link's mass) next, once for the
  // arm, then each joint.
  diag::ArmDiagnosis arm_diag = diag::diagnose_arm(signals, run.arm_options, &arm);
  std::string arm_why;
  const auto not_transferring = cross_motion(signals, spans, arm, diag::cause_names(arm_diag.model), run, arm_why);
  if (!arm_why.empty() && !arm_diag.findings.empty()) withdraw_arm_causes(arm_diag, arm_why);
  signals = diag::without_arm_causes(signals, arm_diag);
  merge_named(run.named, arm_diag);
  report_arm(arm_diag, run.j);
  run.j["resampling"] = resampling_json(real.data.report);
  run.j["torque"] = io::to_string(real.torque);
  if (run.reals.size() > 1) {
    run.j["recordings"] = nlohmann::json::array();
    for (std::size_t r = 0; r < run.reals.size(); ++r) {
      run.j["recordings"].push_back({{"file", run.names[r]}, {"samples", spans[r].end - spans[r].begin},
                                     {"resampling", resampling_json(run.reals[r].data.report)}});
    }
  }
  run.j["joints"] = nlohmann::json::array();
  if (!o.out.empty()) std::filesystem::create_directories(o.out);
  std::vector<diag::JointDiagnosis> diagnoses;
  for (const auto& s : signals) {
    std::vector<std::string> notes;
    const diag::DiagnoseOptions jo = joint_options(s.joint, not_transferring, o.trace, notes);
    diag::JointDiagnosis d = about_recording(real.path, [&] { return diag::diagnose_joint(s, jo); });
    d.notes.insert(d.notes.end(), notes.begin(), notes.end());
    diagnoses.push_back(d);
    run.j["joints"].push_back(joint_json(d));
    print_joint(d);
    if (!o.out.empty()) plot_joint(o.out, s, d);
  }
  if (!o.model_out.empty()) write_model_out(o, run, arm_diag, diagnoses);
  if (!o.json.empty()) {
    write_json_file(o.json, run.j);
    std::printf("wrote %s\n", o.json.c_str());
  }
  return 0;
}

}  // namespace

Command add_diagnose(CLI::App& app) {
  auto o = std::make_shared<DiagnoseCliOptions>();
  auto* cmd = app.add_subcommand("diagnose",
                                 "Locate where a real recording and the simulation disagree, name the missing physics,\n"
                                 "fit it and show the held-out improvement. Without --sim the model predicts the torque\n"
                                 "over the real motion (inverse dynamics + --friction). Several --real recordings of one\n"
                                 "arm: one fit across them, and each recording in turn predicted from the others (what does\n"
                                 "not transfer is not claimed).\n"
                                 "Example: jointguard diagnose --model models/ref3.yaml --real out/real.csv --sim out/sim.csv --json out/diagnosis.json --out out/diagnosis");
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--real", o->real, "Real recording (CSV); repeat for several recordings of the same arm")
      ->required()
      ->check(CLI::ExistingFile)
      ->take_all()
      ->allow_extra_args(false);
  cmd->add_option("--sim", o->sim, "Simulated recording of the same motion (CSV); one per --real, in their order")
      ->check(CLI::ExistingFile)
      ->allow_extra_args(false);
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
  cmd->add_flag("--trace", o->trace, "Print each selection step (candidates, evidence, rejections) to stderr");
  add_model_selection(cmd, o->model_options);
  o->input.add_to(cmd);
  return {cmd, [o]() { return run_diagnose(*o); }};
}

}  // namespace jg::cli
