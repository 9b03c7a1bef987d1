#include "eval/evaluate.hpp"

#include <cmath>
#include <stdexcept>

#include "eval/aligned_estimate.hpp"
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

RunResult run_detection(const sim::SimulationSetup& setup, Estimator& estimator, const DetectionConfig& d,
                        const std::string& name, bool record_trace, Estimator* other) {
  const std::size_t n = setup.plant.links.size();
  if (d.threshold.size() != n) throw std::invalid_argument("detection: one threshold per joint required");
  RunResult out;
  out.name = name;
  out.t_collision = setup.collisions.empty() ? 0.0 : setup.collisions.front().t_start;
  out.link_true = setup.collisions.empty() ? 0 : setup.collisions.front().link;
  const sim::ArmDynamics nominal(setup.nominal_links.empty() ? setup.plant.links : setup.nominal_links, setup.plant.gravity);
  std::vector<JointThreshold<double>> thresholds(n);
  std::vector<JointDetectorState> states(n);
  for (std::size_t j = 0; j < n; ++j) {
    thresholds[j] = {d.threshold[j], d.per_speed.empty() ? 0.0 : d.per_speed[j],
                     d.low_speed_extra.empty() ? 0.0 : d.low_speed_extra[j], 1.0 / d.low_speed_width};
  }
  std::vector<HoldChangeParams<double>> hold_detector(n);
  std::vector<HoldChangeState<double>> hold_states(n);
  const double dt = 1.0 / setup.control_rate_hz;
  for (std::size_t j = 0; j < n; ++j) {
    hold_detector[j] = hold_params(j < d.hold_threshold.size() ? d.hold_threshold[j] : 0.0, d.hold_settle_s, d.hold_reference_s, dt);
  }
  std::vector<ResidualChangeParams<double>> residual_detector(n);
  std::vector<ResidualChangeState<double>> residual_states(n), other_residual_states(n);
  for (std::size_t j = 0; j < n; ++j) {
    residual_detector[j] = residual_params(j < d.residual_threshold.size() ? d.residual_threshold[j] : 0.0,
                                           d.residual_time_constant_s, dt);
  }
  // Per cycle, for the ground truth below: the holding mask and each joint's threshold in
  // effect (the band at the measured velocity, or the change threshold while the holding
  // detector is armed, whichever is lower).
  const bool record_ground_truth = !setup.collisions.empty() || record_trace;
  std::vector<JointMask> holding_trace;
  std::vector<double> in_effect_trace;
  std::vector<LuGreDiscrete<double>> friction(d.friction.size());
  std::vector<LuGreState<double>> friction_state(d.friction.size());
  for (std::size_t j = 0; j < d.friction.size(); ++j) {
    if (discretize(d.friction[j], dt, friction[j]) != Error::ok) throw std::invalid_argument("detection: invalid LuGre");
  }
  bool started = false, reacting = false, comm_stop = false;
  sim::JointVector hold;
  // Retreat: the path the arm came along (joint positions per cycle, newest last, the
  // last few seconds) and the point it goes back to; reflex: the collided joints.
  std::vector<sim::JointVector> path;
  const std::size_t path_capacity = static_cast<std::size_t>(3.0 * setup.control_rate_hz) + 1;
  sim::JointVector retreat_to;
  JointMask collided = 0;
  // The reaction law is the drives' own (node/joint_reaction.hpp), here in double: with
  // drives on a bus the master commands it and applies the torques they send back.
  ReactionGains<double> gains = reaction_gains<double>(dt, d.retreat_s, d.reflex_s);
  gains.reflex_gain = d.reflex_gain;
  std::vector<JointReactionState<double>> reaction(n);
  bool drives_react = false;
  int unanswered_cycles = 0;
  sim::JointVector friction_now = sim::JointVector::Zero(static_cast<Eigen::Index>(n));
  sim::JointVector mu;
  JointMask mask = 0;
  JointMask window_signature = 0;  // joints taking part in the signature since the detection
  double last_alarm_t = -1e9;
  const double isolation_fraction = d.isolation_fraction;
  out.compared = other != nullptr;
  bool other_started = false;
  sim::JointVector other_mu;
  std::vector<JointDetectorState> other_states(n);
  std::vector<HoldChangeState<double>> other_hold_states(n);
  const DebounceSettings debounce{static_cast<std::uint8_t>(d.debounce_cycles)};
  ContactWindow contact(d.contact, dt);
  AlignedEstimate aligned(n, d.observer_gain_per_s, dt);
  const int aligned_cycles = aligned.enabled() ? static_cast<int>(std::floor(std::max(0.0, d.isolation_aligned_s) / dt + 1e-9)) : 0;
  const double decision_after_s = std::max(d.isolation_window_s, aligned_cycles * dt);
  // A joint at standstill holds whatever friction it came to rest with (anywhere within
  // +-tau_s): its estimate's level says nothing of a contact, its change does. Per joint:
  // cycles at standstill in a row and a slow baseline of the estimate (50 ms).
  constexpr double kStandstillSpeed = 0.02, kStandstillS = 0.005, kBaselineS = 0.05;
  const bool standstill_change = d.isolation_standstill_change;
  std::vector<int> still_cycles(n, 0);
  std::vector<double> baseline(n, 0.0), baseline_at_detection(n, 0.0);
  bool baseline_started = false;
  const double baseline_gain = std::min(1.0, dt / kBaselineS);
  sim::JointVector contact_tau(static_cast<Eigen::Index>(n)), contact_threshold(static_cast<Eigen::Index>(n));
  const sim::ControlOverride hook = [&](const sim::CycleContext& ctx) -> std::optional<sim::JointVector> {
    const sim::Measurement& m = *ctx.measurement;
    const JointMask holding = sim::holding_mask(*ctx.reference);
    estimate(estimator, m, holding, started, mu);
    aligned.step(m.tau_m);
    if (!out.t_detected) baseline_at_detection = baseline;  // the baseline before this cycle's estimate
    for (std::size_t j = 0; j < n; ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      still_cycles[j] = std::fabs(m.dq(i)) <= kStandstillSpeed ? still_cycles[j] + 1 : 0;
      baseline[j] = baseline_started ? baseline[j] + baseline_gain * (mu(i) - baseline[j]) : mu(i);
    }
    baseline_started = true;
    if (!reacting && d.reaction == Reaction::retreat) {
      if (path.size() == path_capacity) path.erase(path.begin());
      path.push_back(m.q);
    }
    // Zero gravity: the friction prediction every cycle from the start, as the drives'
    // estimators run it (their reaction uses that prediction).
    for (std::size_t j = 0; d.reaction == Reaction::zero_gravity && j < friction.size() && j < n; ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      friction_now(i) = lugre_step(friction[j], friction_state[j], m.dq(i));
    }
    if (!out.t_comm_fault && estimator.communication_fault()) {
      // A drive lost its neighbours: its estimate is no longer trustworthy, so the arm
      // takes the safe reaction (hold) whatever the configured collision reaction is.
      out.t_comm_fault = ctx.t;
      if (!reacting) hold = m.q;
      reacting = true;
      comm_stop = true;
    }
    if (!out.t_input_fault && estimator.input_fault()) {
      // A drive could not use its sample (NaN or out of range): same safe reaction.
      out.t_input_fault = ctx.t;
      if (!reacting) hold = m.q;
      reacting = true;
      comm_stop = true;
    }
    if (const JointMask reported = estimator.reported_flags(); reported != 0 && !out.t_node_flagged) {
      out.t_node_flagged = ctx.t;
      out.link_node_isolated = isolate_link(reported);
    }
    if (other != nullptr) {
      // The same detector on the second estimator: only its first detection is recorded
      // (one before the contact is a false alarm, re-armed as below).
      estimate(*other, m, holding, other_started, other_mu);
      JointMask other_now = 0;
      for (std::size_t j = 0; j < n; ++j) {
        const auto i = static_cast<Eigen::Index>(j);
        const bool held_change = hold_change_step(hold_detector[j], other_hold_states[j], ((holding >> j) & 1U) != 0U, other_mu(i));
        const bool changed = residual_change_step(residual_detector[j], other_residual_states[j], other_mu(i)) || held_change;
        if (detector_step(thresholds[j], debounce, other_states[j], other_mu(i), m.dq(i), changed)) other_now |= static_cast<JointMask>(1U << j);
      }
      if (other_now != 0 && (setup.collisions.empty() || ctx.t < out.t_collision)) {
        for (auto& st : other_states) reset_detector(st);
      } else if (other_now != 0 && !out.t_detected_other) {
        out.t_detected_other = ctx.t;
      }
    }
    JointMask now = 0;
    JointMask by_band = 0, by_residual = 0, by_hold = 0;
    for (std::size_t j = 0; j < n; ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      const bool held_change = hold_change_step(hold_detector[j], hold_states[j], ((holding >> j) & 1U) != 0U, mu(i));
      const bool residual_change = residual_change_step(residual_detector[j], residual_states[j], mu(i));
      if (residual_change) by_residual |= static_cast<JointMask>(1U << j);
      if (held_change) by_hold |= static_cast<JointMask>(1U << j);
      const bool changed = residual_change || held_change;
      if (detector_step(thresholds[j], debounce, states[j], mu(i), m.dq(i), changed)) {
        now |= static_cast<JointMask>(1U << j);
      }
      const double band = threshold_at(thresholds[j], m.dq(i));
      if (band < std::fabs(mu(i))) by_band |= static_cast<JointMask>(1U << j);
      const double in_effect = hold_states[j].armed ? std::min(band, hold_detector[j].change_threshold) : band;
      if (record_ground_truth) in_effect_trace.push_back(in_effect);
      // The contact estimate explains a held joint's change since arrival (its estimate
      // there is mostly the friction it holds).
      contact_tau(i) = hold_states[j].armed ? mu(i) - hold_states[j].reference : mu(i);
      contact_threshold(i) = in_effect;
    }
    if (record_ground_truth) holding_trace.push_back(holding);
    if (now != 0 && (setup.collisions.empty() || ctx.t < out.t_collision)) {
      // An alarm with no contact: count one per episode (a new one only after 0.5 s below
      // every threshold), re-arm, do not react.
      if (ctx.t - last_alarm_t > 0.5) {
        out.false_alarm_times.push_back(ctx.t);
        FalseAlarm a{ctx.t, now, by_band, by_residual, by_hold, {}, {}, {}, {}};
        for (std::size_t j = 0; j < n; ++j) {
          const auto i = static_cast<Eigen::Index>(j);
          a.q_rad.push_back(m.q(i));
          a.dq_rad_s.push_back(m.dq(i));
          a.mu_nm.push_back(mu(i));
          a.band_nm.push_back(threshold_at(thresholds[j], m.dq(i)));
        }
        out.false_alarms.push_back(std::move(a));
      }
      last_alarm_t = ctx.t;
      for (auto& st : states) reset_detector(st);
      now = 0;
    } else if ((now != 0 && !out.t_detected) || (out.t_detected && ctx.t <= *out.t_detected + decision_after_s + 1e-9)) {
      // Isolation from the signature at the detection cycle and the aligned cycles after it
      // (isolation_aligned_s: the estimate with the reaction's torque step paired with the
      // motion it causes; later cycles mostly see the stop's friction sweep, not the
      // contact), or from every joint that takes part over a short window from it
      // (isolation_window_s; a contact's own joint may lag a joint below it by a few cycles).
      // The reaction is commanded at the detection cycle with that cycle's signature.
      if (!out.t_detected) {
        out.t_detected = ctx.t;
        out.detected_by_hold = by_band == 0 && by_residual == 0;
        out.detected_by_residual = by_band == 0 && by_residual != 0;
        out.link_first_cycle = 0;
      }
      // Signature with a lower bar than detection: a joint takes part when its estimate is
      // above 30 % of its threshold (about its collision-free band), so a contact whose own
      // joint sees less torque than a joint below it is still named by its own joint.
      // The first aligned_cycles after the detection: the aligned estimate, with the
      // reaction's torque step paired with the motion it causes (aligned_estimate.hpp);
      // the detector's flags there see the unaligned estimate, so they do not join.
      const bool after = ctx.t > *out.t_detected + 1e-9;
      const bool use_aligned = after && ctx.t <= *out.t_detected + aligned_cycles * dt + 1e-9;
      JointMask signature = use_aligned ? JointMask{0} : now;
      // A joint whose holding detector is armed takes part by its change since arrival
      // (|mu| there is mostly the friction it holds): over kHeldSignatureFraction of its
      // change threshold, about the largest collision-free change (1.5x it + 0.2 N·m).
      for (std::size_t j = 0; j < n; ++j) {
        const double value =
            mu(static_cast<Eigen::Index>(j)) + (use_aligned && !d.observer_aligns_motor_torque ? aligned.correction(j) : 0.0);
        const bool still = standstill_change && still_cycles[j] * dt >= kStandstillS - 1e-9;
        // A joint held by static friction takes the reaction's torque step in its friction,
        // not in its motion: its estimate moves by the step, aligned or not (the paper's waist
        // collision, on an arm at rest: the elbow's estimate by 0.7 N·m). It takes part from
        // the detection cycle only.
        if (use_aligned && still) continue;
        const bool part = hold_states[j].armed
                              ? hold_deviation(hold_states[j], value) > kHeldSignatureFraction * hold_detector[j].change_threshold
                              : std::fabs(still ? value - baseline_at_detection[j] : value) > isolation_fraction * d.threshold[j];
        if (part) signature |= static_cast<JointMask>(1U << j);
      }
      window_signature |= signature;
      out.link_isolated = isolate_link(window_signature);
      if (out.link_first_cycle == 0) out.link_first_cycle = out.link_isolated;
      collided = window_signature;
      if (!reacting) {
        hold = m.q;
        retreat_to = m.q;
        double back = 0.0;  // walk back along the recorded path by retreat_rad
        for (std::size_t k = path.size(); k-- > 1 && back < d.retreat_rad;) {
          back += (path[k] - path[k - 1]).norm();
          retreat_to = path[k - 1];
        }
        if (d.reaction != Reaction::none) {
          drives_react = estimator.command_reaction(d.reaction, collided, retreat_to);
          for (std::size_t j = 0; j < n && !drives_react; ++j) {
            const auto i = static_cast<Eigen::Index>(j);
            start_reaction(reaction[j], ReactionCommand<double>{d.reaction, ((collided >> j) & 1U) != 0U, retreat_to(i)}, m.q(i));
          }
        }
      }
      reacting = reacting || d.reaction != Reaction::none;
    }
    if (!setup.collisions.empty()) contact.add(nominal, ctx.t, m.q, contact_tau, contact_threshold, out.t_detected, out.link_isolated);
    mask = now;
    if (record_trace) {
      out.trace.t.push_back(ctx.t);
      if (out.trace.mu.empty()) {
        out.trace.mu.resize(n);
      }
      for (std::size_t j = 0; j < n; ++j) out.trace.mu[j].push_back(mu(static_cast<Eigen::Index>(j)));
    }
    if (!reacting) return std::nullopt;
    sim::JointVector demand = nominal.gravity_torque(m.q);
    if (comm_stop) {
      // The master's own safe hold: the drives may be unable to run or report anything.
      for (std::size_t j = 0; j < n; ++j) {
        const auto i = static_cast<Eigen::Index>(j);
        demand(i) += gains.hold_stiffness * (hold(i) - m.q(i)) - gains.hold_damping * m.dq(i);
      }
    } else if (drives_react) {
      // The drives run the reaction; until their first torques are in (the cycle after the
      // detection) the trajectory's controller keeps the arm.
      sim::JointVector tau;
      if (!estimator.reaction_torque(tau)) {
        // Drives that do not answer the command within a few cycles (lost, or firmware
        // without reactions): the master holds the arm itself.
        if (++unanswered_cycles <= kReactionAnswerCycles) return std::nullopt;
        comm_stop = true;
        for (std::size_t j = 0; j < n; ++j) {
          const auto i = static_cast<Eigen::Index>(j);
          demand(i) += gains.hold_stiffness * (hold(i) - m.q(i)) - gains.hold_damping * m.dq(i);
        }
        return demand;
      }
      demand += tau;
    } else {
      for (std::size_t j = 0; j < n; ++j) {
        const auto i = static_cast<Eigen::Index>(j);
        demand(i) += reaction_torque(gains, reaction[j], m.q(i), m.dq(i), mu(i), friction_now(i));
        if (reaction[j].kind == Reaction::reflex) hold(i) = reaction[j].hold;  // a later comm fault holds there
      }
    }
    return demand;
  };
  // Track contact times through a recording (ground truth).
  // The ground truth (external torque, contact) comes from the recording; a collision-free
  // run needs none, and recording six hours would take gigabytes.
  sim::SimulationSetup s = setup;
  s.record = record_ground_truth;
  sim::SimulationResult r = sim::run_simulation(s, hook);
  const auto& rec = r.recording;
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    const bool traced = k < holding_trace.size();
    int highest_clear = 0;  // the highest joint whose true torque clears its moving band
    for (std::size_t j = 0; j < n; ++j) {
      // Against the threshold in effect (the band at the velocity the detector saw, or the
      // change threshold of an armed holding detector), and against the moving threshold
      // alone (stricter: counts impacts on a joint at rest).
      const double magnitude = std::fabs(rec.tau_ext[j][k]);
      const double in_effect = traced ? in_effect_trace[k * n + j] : threshold_at(thresholds[j], rec.dq[j][k]);
      const double ratio = magnitude / in_effect;
      out.max_true_ratio = std::max(out.max_true_ratio, ratio);
      if (magnitude / d.threshold[j] > out.max_true_ratio_moving) {
        out.max_true_ratio_moving = magnitude / d.threshold[j];
        out.peak_joint = static_cast<int>(j) + 1;
        out.peak_true_torque_nm = magnitude;
        out.speed_at_peak_rad_s = std::fabs(rec.dq[j][k]);
      }
      if (!out.t_threshold && ratio > 1.0) out.t_threshold = rec.t[k];
      if (magnitude > d.threshold[j]) highest_clear = static_cast<int>(j) + 1;
      if (traced && ((holding_trace[k] >> j) & 1U) != 0U) {
        out.peak_true_torque_held = std::max(out.peak_true_torque_held, magnitude);
      }
    }
    // Isolable: at some cycle of the run the true torques name the collided link (the
    // highest joint over its noise band, the moving threshold, is the collided link's).
    if (highest_clear != 0 && highest_clear == out.link_true) {
      out.isolable = true;
      // Up to the decision (the detection cycle plus the cycles the decision waits for).
      if (!out.t_detected || rec.t[k] <= *out.t_detected + decision_after_s + 1e-9) out.isolable_at_decision = true;
    }
  }
  out.peak_force_n = r.peak_contact_force_n;
  if (!setup.collisions.empty()) {
    // The truth is the contact as it acted (a surface contact's side is resolved at its onset).
    sim::CollisionEvent acted = setup.collisions.front();
    if (r.first_contact.link != 0) acted.point_in_link = r.first_contact.point_in_link;
    contact.set_truth(nominal, acted, r.contact_force_n, rec.tau_ext);
  }
  out.contact = contact.outcome();
  out.contact_force_n = std::move(r.contact_force_n);
  if (record_trace) {
    out.trace.tau_ext = rec.tau_ext;
    out.trace.t.resize(std::min(out.trace.t.size(), rec.t.size()));
    out.recording = std::move(r.recording);  // rec (its alias) is not used after this
  }
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
