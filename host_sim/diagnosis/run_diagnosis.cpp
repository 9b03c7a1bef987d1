#include "diagnosis/run_diagnosis.hpp"

#include <algorithm>
#include <stdexcept>

#include "diagnosis/model_out.hpp"
#include "diagnosis/pairing.hpp"
#include "robot/effect_catalogue.hpp"
#include "robot/torque_kind.hpp"

namespace jg::diag {
namespace {

/// What a run carries from stage to stage besides its result.
struct RunState {
  robot::RobotModel model;         ///< the robot file for the recordings' torque kind
  robot::RobotModel used;          ///< what predicts: the file's effects, the named causes, the refit
  robot::RobotModel before_refit;  ///< `used` before the rigid-body refit replaced its links
  std::vector<robot::PlantEffect> folded;  ///< arm-level effects held in the links, written back as effects
  std::vector<std::string> model_effect_notes;
  ArmDiagnosisOptions arm_options;
  ArmDiagnosis named;  ///< causes named against the robot file, before the refit
};

/// The simulated segment that covers [t0, t1] [s], or nullptr; `dt` [s] the tolerance.
const io::Recording* covering(const std::vector<io::Recording>& segments, double t0, double t1, double dt) {
  for (const auto& s : segments) {
    if (s.t.front() <= t0 + dt && s.t.back() >= t1 - dt) return &s;
  }
  return nullptr;
}

/// What the signals need of the model: `arm` (its dynamics; must outlive the context), the
/// torque constants of `model` (as read for this torque kind), the nominal rotor inertias,
/// and the nominal friction when one is given.
ModelContext model_context(const sim::ArmDynamics& arm, const robot::RobotModel& model, const robot::RobotModel& nominal,
                           const std::vector<LuGreParams<double>>& friction) {
  ModelContext ctx;
  ctx.arm = &arm;
  for (const auto& jd : model.joints) ctx.torque_constant.push_back(jd.link.torque_constant);
  for (const auto& jd : nominal.joints) ctx.rotor_inertia.push_back(jd.link.rotor_inertia);
  ctx.friction = friction;
  return ctx;
}

/// The recordings' per-joint signals one after the other: `per_segment(r, segment)` for every
/// uniform segment of every recording (derivatives taken within it). With several
/// recordings, each follows the one before on the time axis (each has its own clock), and
/// `spans` gets each one's samples.
template <class PerSegment>
std::vector<JointSignals> signals_of(const std::vector<io::LoadedRecording>& reals, PerSegment&& per_segment,
                                     std::vector<SampleSpan>* spans = nullptr) {
  std::vector<std::vector<JointSignals>> parts;
  std::size_t samples = 0;
  double t_next = 0.0;
  for (std::size_t r = 0; r < reals.size(); ++r) {
    const std::size_t begin = samples;
    const double shift = r == 0 ? 0.0 : t_next - reals[r].data.segments.front().t.front();
    for (const auto& seg : reals[r].data.segments) {
      auto part = io::about_recording(reals[r].path, [&] { return per_segment(r, seg); });
      for (auto& js : part) {
        for (auto& t : js.t) t += shift;
        for (auto& t : js.rows_t) t += shift;
      }
      if (!part.empty() && !part.front().t.empty()) {
        samples += part.front().size();
        t_next = part.front().t.back() + part.front().dt;
      }
      parts.push_back(std::move(part));
    }
    if (spans != nullptr) spans->push_back({begin, samples});
  }
  return concatenate_signals(parts);
}

/// The per-joint signals of the model's prediction over the real motion.
std::vector<JointSignals> model_signals(const std::vector<io::LoadedRecording>& reals, const ModelContext& ctx,
                                        std::vector<SampleSpan>* spans = nullptr) {
  return signals_of(reals, [&](std::size_t, const io::Recording& seg) { return signals_from_model(seg, ctx); }, spans);
}

/// Real against simulated, each real recording with its simulated one (the simulated part
/// that covers each real segment).
std::vector<JointSignals> paired_signals(const std::vector<io::LoadedRecording>& reals,
                                         const std::vector<io::LoadedRecording>& sims, const ModelContext& ctx,
                                         std::vector<SampleSpan>* spans) {
  return signals_of(
      reals,
      [&](std::size_t r, const io::Recording& seg) {
        const io::Recording* s = covering(sims[r].data.segments, seg.t.front(), seg.t.back(), seg.meta.sample_time);
        if (s == nullptr) {
          throw std::invalid_argument(sims[r].path + ": no continuous part covers the real recording's t = " +
                                      std::to_string(seg.t.front()) + " .. " + std::to_string(seg.t.back()) + " s");
        }
        return signals_from_pair(seg, *s, ctx);
      },
      spans);
}

/// The causes named against the robot file (before the rigid-body refit) joined to those
/// found after it: one list of arm-level findings, each cause once. (The named causes' model
/// is in the links the rest was fitted with, and written back from there.)
void merge_named(const ArmDiagnosis& named, ArmDiagnosis& after) {
  // A cause found again after the refit is the remainder on top of the named one (both are
  // written back, added): both are listed, the named one first.
  after.findings.insert(after.findings.begin(), named.findings.begin(), named.findings.end());
  after.unexplained.insert(after.unexplained.begin(), named.unexplained.begin(), named.unexplained.end());
  std::vector<std::string> notes;
  for (const auto& n : named.notes) notes.push_back("against the robot file: " + n);
  after.notes.insert(after.notes.begin(), notes.begin(), notes.end());
}

/// An arm-level diagnosis whose causes did not transfer between recordings: nothing claimed,
/// what it found reported as unexplained.
void withdraw_arm_causes(ArmDiagnosis& a, const std::string& why) {
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

std::vector<std::string> paths_of(const std::vector<io::LoadedRecording>& reals) {
  std::vector<std::string> names;
  for (const auto& r : reals) names.push_back(r.path);
  return names;
}

/// Stage 1: the robot file for the recordings' torque kind, its own effects folded in, and
/// the arm-level options the arm's size and rating give.
RunState prepare(const DiagnosisInputs& in, const DiagnosisSettings& settings) {
  RunState st;
  const io::LoadedRecording& real = primary(in.reals);
  // A joint torque sensor does not see the rotor: no reflected rotor inertia then.
  st.model = robot::for_torque_kind(in.nominal, real.torque);
  st.used = st.model;
  // A robot file written by --model-out carries what an earlier diagnosis found: in the
  // prediction too (arm-level effects folded into the links, per-joint ones in stage 3).
  st.model_effect_notes = fold_arm_effects(st.used, &st.folded);
  // The file's torque-constant errors in its drives' K_I, as they read the currents (against
  // the robot file; a simulated recording made with them carries them already).
  if (in.sims.empty() && real.torque == io::TorqueKind::current) fold_drive_effects(st.used, &st.folded);
  if (!st.used.joints.empty()) st.arm_options.com_bound_m = std::max(st.arm_options.com_bound_m, st.used.joints.back().reach_m + 0.5);
  st.arm_options.max_payload_kg = st.model.rated_payload_kg;
  st.arm_options.joint.trace = settings.trace;
  // Each recording has its own clock: a payload picked up "when" is not one thing across them.
  if (in.reals.size() > 1) st.arm_options.payload_picked_up = false;
  return st;
}

/// Stage 2a: named causes first, against the robot file itself (a payload nobody declared, a
/// link's mass): the rigid-body refit then explains only what they leave, never a payload in
/// 40 base parameters. Folded into `st.used`.
void name_causes_against_file(const DiagnosisInputs& in, RunState& st, DiagnosisResult& out) {
  const sim::ArmDynamics prior_arm = st.used.dynamics();
  const auto prior_ctx = model_context(prior_arm, st.used, in.nominal, in.friction);
  // Carried throughout only: a link holds it, and a step is found after the refit.
  ArmDiagnosisOptions named_options = st.arm_options;
  named_options.payload_picked_up = false;
  // A drive's torque constant scales what the currents read: named here, against the file,
  // where the refit's base parameters have not yet taken it.
  named_options.torque_constants = primary(in.reals).torque == io::TorqueKind::current;
  std::vector<SampleSpan> spans;
  const auto signals = model_signals(in.reals, prior_ctx, &spans);
  st.named = diagnose_arm(signals, named_options, &prior_arm);
  if (spans.size() > 1 && !st.named.findings.empty()) {
    // Several recordings: what is named must hold for each of them, fitted on the others.
    out.named_folds = cross_motion_folds(signals, spans, named_options, &prior_arm, false);
    const std::string why = arm_not_transferring(*out.named_folds, paths_of(in.reals), cause_names(st.named.model));
    if (!why.empty()) withdraw_arm_causes(st.named, why);
  }
  // Folded alone: the file's own effects were folded (or kept) before.
  robot::RobotModel with_named = st.used;
  with_named.plant_effects = plant_effects_of(st.named, {});
  fold_arm_effects(with_named, &st.folded);
  fold_drive_effects(with_named, &st.folded);
  with_named.plant_effects = st.used.plant_effects;
  st.used = with_named;
}

/// Stage 2b: the whole arm's rigid body and friction identified on the training blocks of the
/// longest segment (one cause, the arm's inertial parameters, fitted once); the diagnosis
/// then works on what that model leaves.
void refit_rigid_body(const DiagnosisInputs& in, RunState& st, DiagnosisResult& out) {
  const io::LoadedRecording& real = primary(in.reals);
  dyn::RigidBodyIdOptions ro;
  ro.joint_torque_sensor = real.torque == io::TorqueKind::tau_j;
  ro.friction_offset = false;  // a constant is `current_offset`'s to name, per joint, against its null
  if (!st.used.plant_effects.empty()) {
    // The file's per-joint effects are part of the model (the loop's second round): the
    // friction and links are identified on top of them, as the diagnosis will predict with
    // them, so the baseline does not take them a second time.
    ro.known_torque = known_joint_torque(st.used, in.nominal, real.longest(), nullptr);
  }
  try {
    out.rigid_body = dyn::identify_rigid_body(real.longest(), st.used, ro);
  } catch (const std::invalid_argument& e) {
    out.rigid_body_refused = e.what();
  }
  st.before_refit = st.used;
  if (out.rigid_body && out.rigid_body->accepted) st.used = out.rigid_body->model;
}

/// The identified friction added to the model's prediction (it is part of the model).
void add_identified_friction(const std::vector<dyn::FrictionFit>& friction, std::vector<JointSignals>& signals) {
  for (std::size_t jj = 0; jj < signals.size() && jj < friction.size(); ++jj) {
    auto& s = signals[jj];
    for (std::size_t k = 0; k < s.size(); ++k) {
      const double f = friction[jj].torque(s.dq[k]);
      s.tau_model[k] += f;
      s.residual[k] -= f;
    }
  }
}

/// The friction baseline a robot file carries, as the refit's friction (the same shape).
std::vector<dyn::FrictionFit> friction_of(const std::vector<robot::FrictionBaseline>& baseline) {
  std::vector<dyn::FrictionFit> out;
  for (const auto& b : baseline) {
    dyn::FrictionFit f;
    f.coulomb_pos = b.coulomb_pos_nm;
    f.coulomb_neg = b.coulomb_neg_nm;
    f.coulomb = 0.5 * (b.coulomb_pos_nm + b.coulomb_neg_nm);
    f.viscous = b.viscous_nms_rad;
    f.offset = b.offset_nm;
    f.eps = b.eps_rad_s;
    out.push_back(f);
  }
  return out;
}

/// The refit's friction as the robot file writes it.
std::vector<robot::FrictionBaseline> baseline_of(const std::vector<dyn::FrictionFit>& friction) {
  std::vector<robot::FrictionBaseline> out;
  for (const auto& f : friction) out.push_back({f.coulomb_pos, f.coulomb_neg, f.viscous, f.offset, f.eps});
  return out;
}

/// Stage 3: the signals the diagnosis works on: real against simulated, or against the
/// model's prediction with the file's per-joint effects and the identified friction in it.
std::vector<JointSignals> diagnosis_signals(const DiagnosisInputs& in, const sim::ArmDynamics& arm, const RunState& st,
                                            DiagnosisResult& out) {
  const io::LoadedRecording& real = primary(in.reals);
  // With the arm identified (now or by an earlier diagnosis), its friction is the identified
  // one (below), not the nominal one.
  const bool identified = out.rigid_body.has_value() || out.file_baseline;
  const ModelContext ctx = model_context(arm, st.used, in.nominal, identified ? std::vector<LuGreParams<double>>() : in.friction);
  std::vector<JointSignals> signals = in.sims.empty() ? model_signals(in.reals, ctx, &out.spans)
                                                      : paired_signals(in.reals, in.sims, ctx, &out.spans);
  for (const auto& r : in.reals) out.segments += r.data.segments.size();
  for (auto& s : signals) s.joint_torque_sensor = real.torque == io::TorqueKind::tau_j;
  if (!st.used.plant_effects.empty() && in.sims.empty()) {
    auto notes = add_joint_effects(st.used.plant_effects, signals);
    notes.insert(notes.begin(), st.model_effect_notes.begin(), st.model_effect_notes.end());
    out.file_effects = FileEffectsInPrediction{st.used.plant_effects.size(), notes};
  }
  if (out.rigid_body) add_identified_friction(out.rigid_body->friction, signals);
  if (out.file_baseline) add_identified_friction(friction_of(st.used.friction_baseline), signals);
  return signals;
}

/// Stage 4: the arm-level causes, once for the arm, and what transfers between the
/// recordings (leave-one-recording-out; with one recording nothing to check). Returns the
/// (joint, effect) pairs that do not transfer; the arm's causes are withdrawn if they do not.
std::vector<NotTransferring> diagnose_arm_level(const DiagnosisInputs& in, const sim::ArmDynamics& arm, RunState& st,
                                                const std::vector<JointSignals>& signals, DiagnosisResult& out) {
  out.arm = diagnose_arm(signals, st.arm_options, &arm);
  std::vector<NotTransferring> not_transferring;
  if (out.spans.size() >= 2) {
    const auto names = paths_of(in.reals);
    out.folds = cross_motion_folds(signals, out.spans, st.arm_options, &arm);
    const std::string why = arm_not_transferring(*out.folds, names, cause_names(out.arm.model));
    if (!why.empty() && !out.arm.findings.empty()) withdraw_arm_causes(out.arm, why);
    not_transferring = effects_not_transferring(*out.folds, names);
  }
  return not_transferring;
}

/// The options of `joint`'s diagnosis: its effects that did not transfer excluded, and the
/// notes saying so. An effect the robot file already carries on the joint (`file_effects`,
/// written by an earlier diagnosis and in the prediction) is offered again only at the file's
/// setting: a change of its size (a drive's constant that moved since the file was written) is
/// found and merged into the file's entry, but a second component of the cause (a Stribeck
/// curve at another speed scale) is the remainder of a shape the vocabulary's form does not
/// fit, which the loop would otherwise add round after round. It stays in the joint's
/// unexplained residual. A ripple at another period is another ripple (diagnose.cpp,
/// keep_only_file_settings), offered beside the file's.
DiagnoseOptions joint_options(int joint, const std::vector<NotTransferring>& not_transferring,
                              const std::vector<robot::PlantEffect>& file_effects, bool trace, std::vector<std::string>& notes) {
  DiagnoseOptions jo;
  jo.trace = trace;
  for (const auto& n : not_transferring) {
    if (n.joint != joint) continue;
    jo.excluded_effects.push_back(n.effect);
    notes.push_back(n.why);
  }
  for (const auto& e : file_effects) {
    if (e.joint != joint || std::find(jo.excluded_effects.begin(), jo.excluded_effects.end(), e.effect) != jo.excluded_effects.end()) {
      continue;
    }
    jo.only_at_setting.emplace_back(e.effect, e.setting);
    if (robot::effect_info(e.effect).components_at_settings) {
      notes.push_back(robot::effect_word(e.effect) + " is in the robot file already (an earlier diagnosis): offered again at the file's " +
                      std::string(robot::effect_info(e.effect).setting) + ", as a change of its size, and at any other as another component beside it");
    } else {
      notes.push_back(robot::effect_word(e.effect) + " is in the robot file already (an earlier diagnosis): offered again only at the file's setting, as a change of its size; what another shape of it would add is in the unexplained residual");
    }
  }
  return jo;
}

/// Whether the diagnosis named a cause, for the arm or on any joint.
bool named_anything(const DiagnosisResult& r) {
  if (!r.arm.findings.empty()) return true;
  return std::any_of(r.joints.begin(), r.joints.end(), [](const JointDiagnosis& d) { return !d.findings.empty(); });
}

/// `signals` with each joint's fitted effects (JointDiagnosis::fitted) taken off the residual
/// and put into the model's prediction.
std::vector<JointSignals> without_joint_effects(std::vector<JointSignals> signals, const std::vector<JointDiagnosis>& joints) {
  for (auto& s : signals) {
    const auto d = std::find_if(joints.begin(), joints.end(), [&](const JointDiagnosis& j) { return j.joint == s.joint; });
    if (d != joints.end()) s = with_fitted_in_model(std::move(s), d->fitted);
  }
  return signals;
}

/// Tells the caller that `stage` ended.
void stage_done(const DiagnosisSettings& settings, DiagnosisStage stage, const DiagnosisResult& out) {
  if (settings.on_stage) settings.on_stage(stage, out);
}

/// Stage 5: each joint's diagnosis on the signals the arm-level causes left (out.signals),
/// into out.joints.
void diagnose_joints(const std::vector<NotTransferring>& not_transferring, const std::vector<robot::PlantEffect>& file_effects,
                     const std::string& path, const DiagnosisSettings& settings, DiagnosisResult& out) {
  for (const auto& s : out.signals) {
    std::vector<std::string> notes;
    const DiagnoseOptions jo = joint_options(s.joint, not_transferring, file_effects, settings.trace, notes);
    JointDiagnosis d = io::about_recording(path, [&] { return diagnose_joint(s, jo); });
    d.notes.insert(d.notes.end(), notes.begin(), notes.end());
    out.joints.push_back(d);
    stage_done(settings, DiagnosisStage::joint, out);
  }
}

/// Each joint's diagnosis (out.joints, on out.signals) taken on to where the loop settles
/// (diagnose_joint_to_convergence), with the options it was diagnosed with.
void joints_to_convergence(const std::vector<NotTransferring>& not_transferring, const std::vector<robot::PlantEffect>& file_effects,
                           const std::string& path, bool trace, DiagnosisResult& out) {
  for (std::size_t i = 0; i < out.joints.size() && i < out.signals.size(); ++i) {
    std::vector<std::string> notes;
    const DiagnoseOptions jo = joint_options(out.signals[i].joint, not_transferring, file_effects, trace, notes);
    io::about_recording(path, [&] { return diagnose_joint_to_convergence(out.signals[i], jo, out.joints[i]); });
  }
}

/// Stages 4 and 5: the arm's causes, then each joint on what they leave. Without sims, on one
/// recording, when anything was named, one backfitting step follows: the arm's causes again on what the
/// joints' effects leave, then the joints on what those leave. In one pass the arm's causes are
/// fitted with the joints' effects still in the residual, and the loop's next round, which has
/// them in the prediction, names the difference (the real Panda: two link-mass corrections of
/// 2.4 g). Each joint is then taken on to where the loop settles (joints_to_convergence). The
/// stages are reported once, after the last pass.
void arm_and_joints(const DiagnosisInputs& in, const sim::ArmDynamics& arm, const std::vector<JointSignals>& signals,
                    const DiagnosisSettings& settings, RunState& st, DiagnosisResult& out) {
  // The file's per-joint effects (as written, before any was folded into a drive's K_I) are
  // in the prediction only without simulated recordings.
  const std::vector<robot::PlantEffect> file_effects = in.sims.empty() ? st.model.plant_effects : std::vector<robot::PlantEffect>();
  const std::string& path = primary(in.reals).path;
  auto not_transferring = diagnose_arm_level(in, arm, st, signals, out);
  out.signals = without_arm_causes(signals, out.arm);
  if (!in.sims.empty()) {
    merge_named(st.named, out.arm);
    stage_done(settings, DiagnosisStage::arm, out);
    diagnose_joints(not_transferring, file_effects, path, settings, out);
    return;
  }
  DiagnosisSettings quiet = settings;
  quiet.on_stage = nullptr;
  diagnose_joints(not_transferring, file_effects, path, quiet, out);
  // With several recordings (out.spans) what transfers between them is judged on the
  // first pass's residual, where the joints' effects still are: no second pass there.
  if (out.spans.size() < 2 && named_anything(out)) {
    not_transferring = diagnose_arm_level(in, arm, st, without_joint_effects(signals, out.joints), out);
    out.signals = without_arm_causes(signals, out.arm);
    out.joints.clear();
    diagnose_joints(not_transferring, file_effects, path, quiet, out);
  }
  joints_to_convergence(not_transferring, file_effects, path, settings.trace, out);
  merge_named(st.named, out.arm);
  stage_done(settings, DiagnosisStage::arm, out);
  std::vector<JointDiagnosis> joints = std::move(out.joints);
  out.joints.clear();
  for (auto& d : joints) {
    out.joints.push_back(std::move(d));
    stage_done(settings, DiagnosisStage::joint, out);
  }
}

/// Stage 6: the named physics written back where the simulation lives (robot file +
/// plant_effects): `simulate --model` and a new diagnosis include it. Arm-level effects held
/// in the links (the file's own and those named here) are taken back out and written as
/// effects; the same cause found again is one entry. The file describes the arm, not the
/// reading: a joint torque sensor's model has no rotor inertia (robot::for_torque_kind), and
/// the rotors written are the robot file's (`nominal`), which every command reads (`simulate`
/// needs them for an elastic gear; a diagnosis of tau_j zeroes them again).
ModelOut model_out_of(const RunState& st, const DiagnosisResult& r, const robot::RobotModel& nominal, bool joint_torque_sensor) {
  ModelOut out;
  out.rigid_body_identified = r.rigid_body && r.rigid_body->accepted;
  out.model = out.rigid_body_identified ? r.rigid_body->model : st.used;
  out.model.plant_effects = st.used.plant_effects;
  out.notes = unfold_arm_effects(out.model, st.folded);
  if (out.rigid_body_identified && !out.notes.empty()) {
    // A cause named against the file (a payload) cannot be taken back out of the identified
    // links: written as itself on the file's rigid body, never hidden in a link.
    out.model = st.before_refit;
    out.model.plant_effects = st.used.plant_effects;
    out.notes = unfold_arm_effects(out.model, st.folded);
    out.notes.push_back("the identified rigid body is not written: a named cause could not be taken back out of its links");
    out.rigid_body_identified = false;
  }
  // The friction identified with the links written is written beside them (the next round
  // takes both): the identified links, or the file's when the refit kept them (its friction
  // was then fitted with those). Not when the identified links had to give way to the file's.
  if (r.rigid_body && (out.rigid_body_identified || !r.rigid_body->accepted)) {
    out.model.friction_baseline = baseline_of(r.rigid_body->friction);
  }
  out.model.plant_effects = merge_plant_effects(out.model.plant_effects, plant_effects_of(r.arm, r.joints));
  for (std::size_t j = 0; joint_torque_sensor && j < out.model.joints.size() && j < nominal.joints.size(); ++j) {
    out.model.joints[j].link.rotor_inertia = nominal.joints[j].link.rotor_inertia;
  }
  return out;
}

}  // namespace

const io::LoadedRecording& primary(const std::vector<io::LoadedRecording>& reals) {
  std::size_t best = 0;
  for (std::size_t r = 1; r < reals.size(); ++r) {
    if (reals[r].longest().t.size() > reals[best].longest().t.size()) best = r;
  }
  return reals[best];
}

void check_recording(const io::LoadedRecording& r, const io::LoadedRecording& first, std::size_t model_joints) {
  if (r.longest().joints() != model_joints) {
    throw std::invalid_argument(r.path + ": " + std::to_string(r.longest().joints()) + " joints, the model has " +
                                std::to_string(model_joints));
  }
  if (r.torque != first.torque) {
    throw std::invalid_argument(r.path + ": torque columns of kind " + io::to_string(r.torque) + ", " + first.path +
                                " has " + io::to_string(first.torque) + ": give --torque-kind");
  }
}

DiagnosisResult run_diagnosis(const DiagnosisInputs& in, const DiagnosisSettings& settings) {
  DiagnosisResult out;
  RunState st = prepare(in, settings);
  // A file whose links and friction an earlier diagnosis identified is the model as it
  // stands: naming causes against it or refitting it would start the loop's next round from
  // another residual than the one the last round left (and claim its own baseline again).
  out.file_baseline = in.sims.empty() && !st.model.friction_baseline.empty();
  if (in.sims.empty() && settings.identify_rigid_body && !out.file_baseline) {
    name_causes_against_file(in, st, out);
    refit_rigid_body(in, st, out);
  }
  stage_done(settings, DiagnosisStage::rigid_body, out);
  const sim::ArmDynamics arm = st.used.dynamics();
  const std::vector<JointSignals> signals = diagnosis_signals(in, arm, st, out);
  stage_done(settings, DiagnosisStage::signals, out);
  // Causes that are one thing in the world (a payload, a link's mass) next, once for the
  // arm, then each joint on what they leave.
  arm_and_joints(in, arm, signals, settings, st, out);
  if (settings.model_out) out.model_out = model_out_of(st, out, in.nominal, primary(in.reals).torque == io::TorqueKind::tau_j);
  return out;
}

double heldout_rms_left(const JointDiagnosis& d) { return d.findings.empty() ? d.heldout_rms_before : d.heldout_rms_after; }

double unexplained_over_noise(const JointDiagnosis& d) { return d.noise_rms > 0.0 ? heldout_rms_left(d) / d.noise_rms : 0.0; }

}  // namespace jg::diag
