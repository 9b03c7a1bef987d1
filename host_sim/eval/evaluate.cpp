#include "eval/evaluate.hpp"

#include <cmath>
#include <stdexcept>

#include "eval/aligned_estimate.hpp"
#include "eval/decision_signature.hpp"
#include "eval/torque_reaching_motor.hpp"
#include "identification/lugre_batch.hpp"
#include "jointguard/node/joint_reaction.hpp"

namespace jg::eval {
namespace {
constexpr double kHeldSignatureFraction = 0.6;
/// Cycles the master waits for the drives' first reaction torques before holding the arm itself.
constexpr int kReactionAnswerCycles = 5;
// One cycle of the estimator on a measurement; the first measurement also starts it.
void estimate(Estimator& estimator, const sim::Measurement& m, JointMask holding, bool& started, sim::JointVector& mu) {
  const EstimatorInput in{m.q, m.dq, m.tau_m, holding};
  if (!started) {
    estimator.reset(in);
    started = true;
  }
  estimator.step(in, mu);
}
}  // namespace

HoldChangeParams<double> hold_params(double threshold, double settle_s, double reference_s, double dt) {
  HoldChangeParams<double> p;
  p.change_threshold = threshold;
  const auto cycles = [dt](double s) { return std::min(65535.0, std::ceil(std::max(0.0, s) / dt - 1e-9)); };
  p.settle_cycles = static_cast<std::uint16_t>(cycles(settle_s));
  p.reference_cycles = static_cast<std::uint16_t>(std::max(1.0, cycles(reference_s)));
  p.inv_reference_cycles = 1.0 / p.reference_cycles;
  return p;
}

ResidualChangeParams<double> residual_params(double threshold, double time_constant_s, double dt) {
  ResidualChangeParams<double> p;
  p.change_threshold = threshold;
  p.smoothing = time_constant_s > dt ? dt / time_constant_s : 1.0;
  return p;
}

namespace {
/// The detectors' parameters per joint at the control rate: the band, the holding detector's
/// and the residual detector's.
struct DetectorParams {
  std::vector<JointThreshold<double>> band;
  std::vector<HoldChangeParams<double>> hold;
  std::vector<ResidualChangeParams<double>> residual;
  DebounceSettings debounce;
};

DetectorParams detector_params(const DetectionConfig& d, std::size_t n, double dt) {
  DetectorParams p{std::vector<JointThreshold<double>>(n), std::vector<HoldChangeParams<double>>(n),
                   std::vector<ResidualChangeParams<double>>(n), DebounceSettings{static_cast<std::uint8_t>(d.debounce_cycles)}};
  for (std::size_t j = 0; j < n; ++j) {
    p.band[j] = {d.threshold[j], d.per_speed.empty() ? 0.0 : d.per_speed[j], d.low_speed_extra.empty() ? 0.0 : d.low_speed_extra[j],
                 1.0 / d.low_speed_width};
    p.hold[j] = hold_params(j < d.hold_threshold.size() ? d.hold_threshold[j] : 0.0, d.hold_settle_s, d.hold_reference_s, dt);
    p.residual[j] = residual_params(j < d.residual_threshold.size() ? d.residual_threshold[j] : 0.0, d.residual_time_constant_s, dt);
  }
  return p;
}

/// One estimator's detectors' state per joint.
struct DetectorStates {
  std::vector<JointDetectorState> band;
  std::vector<HoldChangeState<double>> hold;
  std::vector<ResidualChangeState<double>> residual;
  explicit DetectorStates(std::size_t n) : band(n), hold(n), residual(n) {}
};

// A joint at standstill holds whatever friction it came to rest with (anywhere within
// +-tau_s): its estimate's level says nothing of a contact, its change does. Per joint:
// cycles at standstill in a row and a slow baseline of the estimate (50 ms).
constexpr double kStandstillSpeed = 0.02, kStandstillS = 0.005, kBaselineS = 0.05;

/// What a run's cycles read and never change.
struct RunParams {
  const sim::SimulationSetup& setup;
  const DetectionConfig& d;
  std::size_t n = 0;
  double dt = 0.0;  ///< control period [s]
  sim::ArmDynamics nominal;
  DetectorParams detectors;
  std::vector<LuGreDiscrete<double>> friction;  ///< the zero-gravity mode's friction prediction
  ReactionGains<double> gains;
  std::size_t path_capacity = 0;  ///< retreat: cycles of the path kept (the last 3 s)
  int aligned_cycles = 0;         ///< cycles after the detection isolated on the aligned estimate
  double decision_after_s = 0.0;  ///< the isolation's decision waits this long after the detection [s]
  double baseline_gain = 0.0;     ///< per cycle, of the standstill baseline
  /// Per cycle, for the ground truth: the holding mask and each joint's threshold in effect.
  bool record_ground_truth = false;
  bool record_trace = false;

  RunParams(const sim::SimulationSetup& s, const DetectionConfig& config, bool trace)
      : setup(s),
        d(config),
        n(s.plant.links.size()),
        dt(1.0 / s.control_rate_hz),
        nominal(s.nominal_links.empty() ? s.plant.links : s.nominal_links, s.plant.gravity),
        detectors(detector_params(config, n, dt)),
        friction(config.friction.size()),
        // The reaction law is the drives' own (node/joint_reaction.hpp), here in double: with
        // drives on a bus the master commands it and applies the torques they send back.
        gains(reaction_gains<double>(dt, config.retreat_s, config.reflex_s)),
        path_capacity(static_cast<std::size_t>(3.0 * s.control_rate_hz) + 1),
        baseline_gain(std::min(1.0, dt / kBaselineS)),
        record_ground_truth(!s.collisions.empty() || trace),
        record_trace(trace) {
    for (std::size_t j = 0; j < d.friction.size(); ++j) {
      if (discretize(d.friction[j], dt, friction[j]) != Error::ok) throw std::invalid_argument("detection: invalid LuGre");
    }
    gains.reflex_gain = d.reflex_gain;
    // The aligned estimate exists for a first-order observer's gain only (AlignedEstimate::enabled).
    const bool aligned = AlignedEstimate(n, d.observer_gain_per_s, dt).enabled();
    aligned_cycles = aligned ? static_cast<int>(std::floor(std::max(0.0, d.isolation_aligned_s) / dt + 1e-9)) : 0;
    decision_after_s = std::max(d.isolation_window_s, aligned_cycles * dt);
  }
};

/// What a run's cycles carry from one to the next.
struct RunState {
  bool started = false, reacting = false, comm_stop = false;
  sim::JointVector mu;    ///< the estimate [N·m]
  sim::JointVector hold;  ///< where the arm is held [rad]
  // Retreat: the path the arm came along (joint positions per cycle, newest last, the
  // last few seconds) and the point it goes back to.
  std::vector<sim::JointVector> path;
  sim::JointVector retreat_to;
  std::vector<JointReactionState<double>> reaction;
  bool drives_react = false;
  int unanswered_cycles = 0;
  std::vector<LuGreState<double>> friction_state;
  sim::JointVector friction_now;
  DetectorStates detectors;
  JointMask window_signature = 0;  ///< joints taking part in the signature since the detection
  /// Joints that took part cycle by cycle: flagged by a detector at the detection cycle, by
  /// their holding change since it, or (isolation_window_s past the aligned cycles) over
  /// their bar on a cycle. The aligned decision's own joints are `decision`'s.
  JointMask flagged_signature = 0;
  /// The joints' estimates over the aligned decision (the detection cycle and the aligned ones).
  DecisionSignature decision;
  double last_alarm_t = -1e9;      ///< [s]
  bool other_started = false;
  sim::JointVector other_mu;
  DetectorStates other_detectors;
  std::vector<int> still_cycles;
  std::vector<double> baseline, baseline_at_detection;
  bool baseline_started = false;
  sim::JointVector contact_tau, contact_threshold;
  std::vector<JointMask> holding_trace;  ///< per cycle (record_ground_truth)
  std::vector<double> in_effect_trace;   ///< per cycle and joint (record_ground_truth)
  ContactWindow contact;
  AlignedEstimate aligned;

  explicit RunState(const RunParams& p)
      : reaction(p.n),
        friction_state(p.d.friction.size()),
        friction_now(sim::JointVector::Zero(static_cast<Eigen::Index>(p.n))),
        detectors(p.n),
        decision(p.n),
        other_detectors(p.n),
        still_cycles(p.n, 0),
        baseline(p.n, 0.0),
        baseline_at_detection(p.n, 0.0),
        contact_tau(static_cast<Eigen::Index>(p.n)),
        contact_threshold(static_cast<Eigen::Index>(p.n)),
        contact(p.d.contact, p.dt),
        aligned(p.n, p.d.observer_gain_per_s, p.dt) {}
};

/// The joints over their threshold this cycle, and by which detector.
struct CycleFlags {
  JointMask now = 0, by_band = 0, by_residual = 0, by_hold = 0;
};

/// The estimate of this cycle, and what the isolation and the reactions track beside it
/// (standstill, baseline, the path back, the friction prediction).
void observe(const RunParams& p, RunState& s, Estimator& estimator, const sim::Measurement& m, JointMask holding,
             const RunResult& out) {
  estimate(estimator, m, holding, s.started, s.mu);
  s.aligned.step(m.tau_m);
  if (!out.t_detected) s.baseline_at_detection = s.baseline;  // the baseline before this cycle's estimate
  for (std::size_t j = 0; j < p.n; ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    s.still_cycles[j] = std::fabs(m.dq(i)) <= kStandstillSpeed ? s.still_cycles[j] + 1 : 0;
    s.baseline[j] = s.baseline_started ? s.baseline[j] + p.baseline_gain * (s.mu(i) - s.baseline[j]) : s.mu(i);
  }
  s.baseline_started = true;
  if (!s.reacting && p.d.reaction == Reaction::retreat) {
    if (s.path.size() == p.path_capacity) s.path.erase(s.path.begin());
    s.path.push_back(m.q);
  }
  // Zero gravity: the friction prediction every cycle from the start, as the drives'
  // estimators run it (their reaction uses that prediction).
  for (std::size_t j = 0; p.d.reaction == Reaction::zero_gravity && j < p.friction.size() && j < p.n; ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    s.friction_now(i) = lugre_step(p.friction[j], s.friction_state[j], m.dq(i));
  }
}

/// The drives' faults and their own detectors' first flag.
void check_faults(Estimator& estimator, double t, const sim::Measurement& m, RunState& s, RunResult& out) {
  if (!out.t_comm_fault && estimator.communication_fault()) {
    // A drive lost its neighbours: its estimate is no longer trustworthy, so the arm
    // takes the safe reaction (hold) whatever the configured collision reaction is.
    out.t_comm_fault = t;
    if (!s.reacting) s.hold = m.q;
    s.reacting = true;
    s.comm_stop = true;
  }
  if (!out.t_input_fault && estimator.input_fault()) {
    // A drive could not use its sample (NaN or out of range): same safe reaction.
    out.t_input_fault = t;
    if (!s.reacting) s.hold = m.q;
    s.reacting = true;
    s.comm_stop = true;
  }
  if (const JointMask reported = estimator.reported_flags(); reported != 0 && !out.t_node_flagged) {
    out.t_node_flagged = t;
    out.link_node_isolated = isolate_link(reported);
  }
}

/// The same detector on the second estimator: only its first detection is recorded (one
/// before the contact is a false alarm, re-armed as for the first).
void compare_other(const RunParams& p, RunState& s, Estimator& other, const sim::Measurement& m, JointMask holding,
                   double t, RunResult& out) {
  estimate(other, m, holding, s.other_started, s.other_mu);
  const DetectorParams& dp = p.detectors;
  DetectorStates& ds = s.other_detectors;
  JointMask other_now = 0;
  for (std::size_t j = 0; j < p.n; ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    const bool held_change = hold_change_step(dp.hold[j], ds.hold[j], ((holding >> j) & 1U) != 0U, s.other_mu(i));
    const bool changed = residual_change_step(dp.residual[j], ds.residual[j], s.other_mu(i)) || held_change;
    if (detector_step(dp.band[j], dp.debounce, ds.band[j], s.other_mu(i), m.dq(i), changed)) other_now |= static_cast<JointMask>(1U << j);
  }
  if (other_now != 0 && (p.setup.collisions.empty() || t < out.t_collision)) {
    for (auto& st : ds.band) reset_detector(st);
  } else if (other_now != 0 && !out.t_detected_other) {
    out.t_detected_other = t;
  }
}

/// Every joint's detectors on this cycle's estimate; records the threshold in effect (the band
/// at the measured velocity, or the change threshold while the holding detector is armed,
/// whichever is lower) and the contact estimate's inputs.
CycleFlags detect(const RunParams& p, RunState& s, const sim::Measurement& m, JointMask holding) {
  const DetectorParams& dp = p.detectors;
  DetectorStates& ds = s.detectors;
  CycleFlags f;
  for (std::size_t j = 0; j < p.n; ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    const bool held_change = hold_change_step(dp.hold[j], ds.hold[j], ((holding >> j) & 1U) != 0U, s.mu(i));
    const bool residual_change = residual_change_step(dp.residual[j], ds.residual[j], s.mu(i));
    if (residual_change) f.by_residual |= static_cast<JointMask>(1U << j);
    if (held_change) f.by_hold |= static_cast<JointMask>(1U << j);
    const bool changed = residual_change || held_change;
    if (detector_step(dp.band[j], dp.debounce, ds.band[j], s.mu(i), m.dq(i), changed)) f.now |= static_cast<JointMask>(1U << j);
    const double band = threshold_at(dp.band[j], m.dq(i));
    if (band < std::fabs(s.mu(i))) f.by_band |= static_cast<JointMask>(1U << j);
    const double in_effect = ds.hold[j].armed ? std::min(band, dp.hold[j].change_threshold) : band;
    if (p.record_ground_truth) s.in_effect_trace.push_back(in_effect);
    // The contact estimate explains a held joint's change since arrival (its estimate
    // there is mostly the friction it holds).
    s.contact_tau(i) = ds.hold[j].armed ? s.mu(i) - ds.hold[j].reference : s.mu(i);
    s.contact_threshold(i) = in_effect;
  }
  if (p.record_ground_truth) s.holding_trace.push_back(holding);
  return f;
}

/// An alarm with no contact: counted once per episode (a new one only after 0.5 s below every
/// threshold), the detectors re-armed, no reaction.
void count_false_alarm(const RunParams& p, RunState& s, const sim::Measurement& m, double t, const CycleFlags& f,
                       RunResult& out) {
  if (t - s.last_alarm_t > 0.5) {
    out.false_alarm_times.push_back(t);
    FalseAlarm a{t, f.now, f.by_band, f.by_residual, f.by_hold, {}, {}, {}, {}};
    for (std::size_t j = 0; j < p.n; ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      a.q_rad.push_back(m.q(i));
      a.dq_rad_s.push_back(m.dq(i));
      a.mu_nm.push_back(s.mu(i));
      a.band_nm.push_back(threshold_at(p.detectors.band[j], m.dq(i)));
    }
    out.false_alarms.push_back(std::move(a));
  }
  s.last_alarm_t = t;
  for (auto& st : s.detectors.band) reset_detector(st);
}

/// Isolation from the signature at the detection cycle and the aligned cycles after it
/// (isolation_aligned_s: the estimate with the reaction's torque step paired with the
/// motion it causes; later cycles mostly see the stop's friction sweep, not the contact),
/// or from every joint that takes part over a short window from it (isolation_window_s; a
/// contact's own joint may lag a joint below it by a few cycles).
void isolate(const RunParams& p, RunState& s, double t, const CycleFlags& f, RunResult& out) {
  if (!out.t_detected) {
    out.t_detected = t;
    out.detected_by_hold = f.by_band == 0 && f.by_residual == 0;
    out.detected_by_residual = f.by_band == 0 && f.by_residual != 0;
    out.link_first_cycle = 0;
  }
  // Signature with a lower bar than detection: a joint takes part when its estimate is
  // above 30 % of its threshold (about its collision-free band), so a contact whose own
  // joint sees less torque than a joint below it is still named by its own joint.
  // The first aligned_cycles after the detection: the aligned estimate, with the
  // reaction's torque step paired with the motion it causes (aligned_estimate.hpp);
  // the detector's flags there see the unaligned estimate, so they do not join.
  const bool after = t > *out.t_detected + 1e-9;
  const bool use_aligned = after && t <= *out.t_detected + p.aligned_cycles * p.dt + 1e-9;
  const bool in_aligned_decision = !after || use_aligned;
  JointMask signature = use_aligned ? JointMask{0} : f.now;
  // A joint whose holding detector is armed takes part by its change since arrival
  // (|mu| there is mostly the friction it holds): over kHeldSignatureFraction of its
  // change threshold, about the largest collision-free change (1.5x it + 0.2 N·m).
  // Over the detection cycle and the aligned ones, a joint that is not held takes part by
  // its largest estimate there while the estimate keeps its sign, by its mean once the sign
  // changes (the coupling's ringing: decision_signature.hpp; Panda: joint 4 -0.97 then
  // +0.59 N·m, the bar 0.82).
  std::vector<double> bar(p.n);
  for (std::size_t j = 0; j < p.n; ++j) {
    bar[j] = p.d.isolation_fraction * p.d.threshold[j];
    const double value =
        s.mu(static_cast<Eigen::Index>(j)) + (use_aligned && !p.d.observer_aligns_motor_torque ? s.aligned.correction(j) : 0.0);
    const bool still = p.d.isolation_standstill_change && s.still_cycles[j] * p.dt >= kStandstillS - 1e-9;
    // A joint held by static friction takes the reaction's torque step in its friction,
    // not in its motion: its estimate moves by the step, aligned or not (the paper's waist
    // collision, on an arm at rest: the elbow's estimate by 0.7 N·m). It takes part from
    // the detection cycle only.
    if (use_aligned && still) continue;
    const HoldChangeState<double>& held = s.detectors.hold[j];
    const double excess = still ? value - s.baseline_at_detection[j] : value;
    if (!held.armed && in_aligned_decision) {
      s.decision.add(j, excess);
      continue;
    }
    const bool part = held.armed ? hold_deviation(held, value) > kHeldSignatureFraction * p.detectors.hold[j].change_threshold
                                 : std::fabs(excess) > bar[j];
    if (part) signature |= static_cast<JointMask>(1U << j);
  }
  s.flagged_signature |= signature;
  s.window_signature = s.flagged_signature | s.decision.mask(bar);
  out.link_isolated = isolate_link(s.window_signature);
  if (out.link_first_cycle == 0) out.link_first_cycle = out.link_isolated;
}

/// The reaction commanded at the detection cycle with that cycle's signature: to the drives
/// when they run it, else here per joint.
void begin_reaction(const RunParams& p, RunState& s, Estimator& estimator, const sim::Measurement& m) {
  const JointMask collided = s.window_signature;
  s.hold = m.q;
  s.retreat_to = m.q;
  double back = 0.0;  // walk back along the recorded path by retreat_rad
  for (std::size_t k = s.path.size(); k-- > 1 && back < p.d.retreat_rad;) {
    back += (s.path[k] - s.path[k - 1]).norm();
    s.retreat_to = s.path[k - 1];
  }
  if (p.d.reaction == Reaction::none) return;
  s.drives_react = estimator.command_reaction(p.d.reaction, collided, s.retreat_to);
  for (std::size_t j = 0; j < p.n && !s.drives_react; ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    start_reaction(s.reaction[j], ReactionCommand<double>{p.d.reaction, ((collided >> j) & 1U) != 0U, s.retreat_to(i)}, m.q(i));
  }
}

/// The hold's spring and damper towards `s.hold` added to `demand`.
void add_hold(const RunParams& p, const RunState& s, const sim::Measurement& m, sim::JointVector& demand) {
  for (std::size_t j = 0; j < p.n; ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    demand(i) += p.gains.hold_stiffness * (s.hold(i) - m.q(i)) - p.gains.hold_damping * m.dq(i);
  }
}

/// The torque the reacting arm is commanded; none while the drives' first torques are not in.
std::optional<sim::JointVector> reaction_demand(const RunParams& p, RunState& s, Estimator& estimator, const sim::Measurement& m) {
  sim::JointVector demand = p.nominal.gravity_torque(m.q);
  if (s.comm_stop) {
    // The master's own safe hold: the drives may be unable to run or report anything.
    add_hold(p, s, m, demand);
  } else if (s.drives_react) {
    // The drives run the reaction; until their first torques are in (the cycle after the
    // detection) the trajectory's controller keeps the arm.
    sim::JointVector tau;
    if (!estimator.reaction_torque(tau)) {
      // Drives that do not answer the command within a few cycles (lost, or firmware
      // without reactions): the master holds the arm itself.
      if (++s.unanswered_cycles <= kReactionAnswerCycles) return std::nullopt;
      s.comm_stop = true;
      add_hold(p, s, m, demand);
      return demand;
    }
    demand += tau;
  } else {
    for (std::size_t j = 0; j < p.n; ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      demand(i) += reaction_torque(p.gains, s.reaction[j], m.q(i), m.dq(i), s.mu(i), s.friction_now(i));
      if (s.reaction[j].kind == Reaction::reflex) s.hold(i) = s.reaction[j].hold;  // a later comm fault holds there
    }
  }
  return demand;
}

/// One control cycle: estimate, detect, isolate, react.
std::optional<sim::JointVector> detection_cycle(const RunParams& p, RunState& s, Estimator& estimator, Estimator* other,
                                                const sim::CycleContext& ctx, RunResult& out) {
  const sim::Measurement& m = *ctx.measurement;
  const JointMask holding = sim::holding_mask(*ctx.reference);
  observe(p, s, estimator, m, holding, out);
  check_faults(estimator, ctx.t, m, s, out);
  if (other != nullptr) compare_other(p, s, *other, m, holding, ctx.t, out);
  const CycleFlags f = detect(p, s, m, holding);
  if (f.now != 0 && (p.setup.collisions.empty() || ctx.t < out.t_collision)) {
    count_false_alarm(p, s, m, ctx.t, f, out);
  } else if ((f.now != 0 && !out.t_detected) || (out.t_detected && ctx.t <= *out.t_detected + p.decision_after_s + 1e-9)) {
    isolate(p, s, ctx.t, f, out);
    if (!s.reacting) begin_reaction(p, s, estimator, m);
    s.reacting = s.reacting || p.d.reaction != Reaction::none;
  }
  if (!p.setup.collisions.empty()) {
    s.contact.add(p.nominal, ctx.t, m.q, s.contact_tau, s.contact_threshold, out.t_detected, out.link_isolated);
  }
  if (p.record_trace) {
    out.trace.t.push_back(ctx.t);
    if (out.trace.mu.empty()) out.trace.mu.resize(p.n);
    for (std::size_t j = 0; j < p.n; ++j) out.trace.mu[j].push_back(s.mu(static_cast<Eigen::Index>(j)));
  }
  if (!s.reacting) return std::nullopt;
  return reaction_demand(p, s, estimator, m);
}

/// The recording's true external torques against the thresholds: the peak ratios, the first
/// crossing, whether the collided link was isolable at all and by the decision (from the
/// torque that reaches the motor).
void ground_truth_figures(const RunParams& p, const RunState& s, const sim::SimulationResult& r, RunResult& out) {
  const io::Recording& rec = r.recording;
  const std::vector<std::vector<double>> reaching = torque_reaching_motor(r, p.dt, {kStandstillSpeed, kStandstillS});
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    const bool traced = k < s.holding_trace.size();
    int highest_clear = 0;  // the highest joint whose torque reaching the motor clears its moving band
    for (std::size_t j = 0; j < p.n; ++j) {
      // Against the threshold in effect (the band at the velocity the detector saw, or the
      // change threshold of an armed holding detector), and against the moving threshold
      // alone (stricter: counts impacts on a joint at rest).
      const double magnitude = std::fabs(rec.tau_ext[j][k]);
      const double in_effect = traced ? s.in_effect_trace[k * p.n + j] : threshold_at(p.detectors.band[j], rec.dq[j][k]);
      const double ratio = magnitude / in_effect;
      const double reaching_motor = reaching.empty() ? magnitude : std::fabs(reaching[j][k]);
      out.max_true_ratio = std::max(out.max_true_ratio, ratio);
      if (magnitude / p.d.threshold[j] > out.max_true_ratio_moving) {
        out.max_true_ratio_moving = magnitude / p.d.threshold[j];
        out.peak_joint = static_cast<int>(j) + 1;
        out.peak_true_torque_nm = magnitude;
        out.speed_at_peak_rad_s = std::fabs(rec.dq[j][k]);
      }
      if (!out.t_threshold && ratio > 1.0) out.t_threshold = rec.t[k];
      if (reaching_motor > p.d.threshold[j]) highest_clear = static_cast<int>(j) + 1;
      if (static_cast<int>(j) + 1 == out.link_true) {
        out.peak_true_torque_own = std::max(out.peak_true_torque_own, magnitude);
        out.peak_reaching_torque_own = std::max(out.peak_reaching_torque_own, reaching_motor);
      }
      if (traced && ((s.holding_trace[k] >> j) & 1U) != 0U) {
        out.peak_true_torque_held = std::max(out.peak_true_torque_held, magnitude);
      }
    }
    // Isolable: at some cycle of the run the torques that reach the motors name the collided
    // link (the highest joint over its noise band, the moving threshold, is the collided link's).
    if (highest_clear != 0 && highest_clear == out.link_true) {
      out.isolable = true;
      // Up to the decision (the detection cycle plus the cycles the decision waits for).
      if (!out.t_detected || rec.t[k] <= *out.t_detected + p.decision_after_s + 1e-9) out.isolable_at_decision = true;
    }
  }
}

/// The simulation's own figures into the result: the contact force, the contact estimate
/// against the contact as it acted, and (with the trace) the recording.
void finish(const RunParams& p, RunState& s, sim::SimulationResult& r, RunResult& out) {
  out.peak_force_n = r.peak_contact_force_n;
  if (!p.setup.collisions.empty()) {
    // The truth is the contact as it acted (a surface contact's side is resolved at its onset).
    sim::CollisionEvent acted = p.setup.collisions.front();
    if (r.first_contact.link != 0) acted.point_in_link = r.first_contact.point_in_link;
    s.contact.set_truth(p.nominal, acted, r.contact_force_n, r.recording.tau_ext);
  }
  out.contact = s.contact.outcome();
  out.contact_force_n = std::move(r.contact_force_n);
  if (p.record_trace) {
    out.trace.tau_ext = r.recording.tau_ext;
    out.trace.t.resize(std::min(out.trace.t.size(), r.recording.t.size()));
    out.recording = std::move(r.recording);
  }
}
}  // namespace

RunResult run_detection(const sim::SimulationSetup& setup, Estimator& estimator, const DetectionConfig& d,
                        const std::string& name, bool record_trace, Estimator* other) {
  if (d.threshold.size() != setup.plant.links.size()) throw std::invalid_argument("detection: one threshold per joint required");
  RunResult out;
  out.name = name;
  out.t_collision = setup.collisions.empty() ? 0.0 : setup.collisions.front().t_start;
  out.link_true = setup.collisions.empty() ? 0 : setup.collisions.front().link;
  const RunParams p(setup, d, record_trace);
  RunState s(p);
  out.compared = other != nullptr;
  const sim::ControlOverride hook = [&](const sim::CycleContext& ctx) { return detection_cycle(p, s, estimator, other, ctx, out); };
  // The ground truth (external torque, contact) comes from the recording; a collision-free
  // run needs none, and recording six hours would take gigabytes.
  sim::SimulationSetup with_recording = setup;
  with_recording.record = p.record_ground_truth;
  sim::SimulationResult r = sim::run_simulation(with_recording, hook);
  ground_truth_figures(p, s, r, out);
  finish(p, s, r, out);
  return out;
}

std::vector<double> observer_band(const sim::SimulationSetup& setup, Estimator& estimator, double settle_s) {
  const std::size_t n = setup.plant.links.size();
  std::vector<double> band(n, 0.0);
  bool started = false;
  sim::JointVector mu;
  const sim::ControlOverride hook = [&](const sim::CycleContext& ctx) -> std::optional<sim::JointVector> {
    const sim::Measurement& m = *ctx.measurement;
    estimate(estimator, m, sim::holding_mask(*ctx.reference), started, mu);
    if (ctx.t >= settle_s) {
      for (std::size_t j = 0; j < n; ++j) band[j] = std::max(band[j], std::fabs(mu(static_cast<Eigen::Index>(j))));
    }
    return std::nullopt;
  };
  sim::SimulationSetup s = setup;
  s.record = false;
  (void)sim::run_simulation(s, hook);
  return band;
}

}  // namespace jg::eval
