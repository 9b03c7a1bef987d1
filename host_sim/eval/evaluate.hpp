// Closed-loop evaluation: the simulated arm runs a scenario while the estimator and the
// detector run every control cycle; on detection the reaction takes over the controller.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "eval/contact_window.hpp"
#include "eval/estimator.hpp"
#include "jointguard/detection/detector.hpp"
#include "jointguard/detection/hold_detector.hpp"
#include "jointguard/detection/residual_detector.hpp"
#include "sim/simulation.hpp"

namespace jg::eval {

struct DetectionConfig {
  std::vector<double> threshold;  ///< eps0 per joint [N·m]
  std::vector<double> per_speed;  ///< band growth per joint [N·m·s/rad] (empty = 0)
  std::vector<double> low_speed_extra;  ///< stiction allowance near standstill [N·m] (empty = 0)
  double low_speed_width = 0.03;        ///< [rad/s]
  double isolation_fraction = 0.3;      ///< joints above this share of their threshold join the signature
  double isolation_window_s = 0.0;      ///< the signature gathered over this long from the detection [s]
  /// The cycles up to this long after the detection [s] whose aligned estimate
  /// (aligned_estimate.hpp: the motor torque paired with the momentum difference it belongs
  /// to, so the reaction's own torque step is not read as a contact) joins the signature;
  /// 0: the detection cycle alone. One cycle at 1 kHz; none at 125 Hz, whose next cycle comes
  /// 8 ms into the stop, when the friction the stop sweeps through dominates.
  double isolation_aligned_s = 0.001;
  double observer_gain_per_s = 0.0;     ///< first-order observer gain K [1/s] (0: no aligned estimate)
  /// The observer balances with the torque mean (momentum_observer.hpp): its estimate is
  /// already the aligned one, the host's correction is not added (it would be doubled).
  bool observer_aligns_motor_torque = false;
  /// A joint at standstill (|dq| <= 0.02 rad/s for 5 ms) whose holding detector is not armed
  /// takes part in the signature by its change from a 50 ms baseline of its estimate, not by
  /// its level (the friction it came to rest with); false: by its level (the former rule).
  bool isolation_standstill_change = true;
  int debounce_cycles = 1;
  /// Change detection while a joint's controller holds (hold_detector.hpp): threshold per
  /// joint [N·m] (empty or 0: off), settle and reference windows [s].
  std::vector<double> hold_threshold;
  double hold_settle_s = 0.15, hold_reference_s = 0.016;
  /// Change detection against the estimate's slow baseline at any speed
  /// (residual_detector.hpp): threshold per joint [N·m] (empty or 0: off), baseline time
  /// constant [s].
  std::vector<double> residual_threshold;
  double residual_time_constant_s = 0.05;
  Reaction reaction = Reaction::stop;
  std::vector<LuGreParams<double>> friction;  ///< for the zero-gravity mode's friction compensation
  double retreat_rad = 0.1;   ///< retreat: joint-space path length [rad] to go back along
  double retreat_s = 0.3;     ///< retreat: time to go back [s], then hold
  double reflex_gain = 1.0;   ///< reflex: motor torque = gravity + gain x estimated contact torque
  double reflex_s = 0.3;      ///< reflex: duration [s], then hold where the arm is
  ContactWindowConfig contact;  ///< the contact estimate over a short window from the detection
};

struct Trace {
  std::vector<double> t;
  std::vector<std::vector<double>> mu, tau_ext;  ///< [joint][sample]
};

/// What a false alarm looked like at its first cycle, to find its cause: which joints
/// flagged and through which detector, and every joint's posture, velocity, estimate and
/// moving band (the band at the measured velocity) then.
struct FalseAlarm {
  double t_s = 0.0;
  JointMask flagged = 0, by_band = 0, by_residual = 0, by_hold = 0;
  std::vector<double> q_rad, dq_rad_s, mu_nm, band_nm;
};

struct RunResult {
  std::string name;
  int index = 0;                           ///< position in its campaign (0-based): the merge order
  double t_collision = 0.0;                ///< start of the first scheduled collision [s]
  std::optional<double> t_threshold;       ///< first time the true |tau_ext| exceeds the threshold in effect
  std::optional<double> t_detected;
  int link_true = 0, link_isolated = 0;
  int link_first_cycle = 0;                ///< the signature's link at the detection cycle alone
  double peak_force_n = 0.0;
  /// max over joints and samples of |tau_ext| / threshold in effect (the band at the
  /// measured velocity, standstill allowance included)
  double max_true_ratio = 0.0;
  double max_true_ratio_moving = 0.0;      ///< the same against the moving threshold eps0 alone
  std::vector<double> false_alarm_times;   ///< detections with no contact in the preceding 0.5 s
  std::vector<FalseAlarm> false_alarms;    ///< the same alarms in detail (their first cycle)
  std::optional<double> t_node_flagged;    ///< first cycle a drive's own detector flagged (distributed runs)
  int link_node_isolated = 0;              ///< highest joint flagged by the drives at that cycle
  std::optional<double> t_input_fault;     ///< first cycle a drive reported an input fault (the arm holds)
  std::optional<double> t_comm_fault;      ///< first cycle a drive reported a communication fault (the arm holds)
  /// The simulated bus of a run compared on it (ExperimentConfig::compare_on_bus): frames,
  /// wire time and run time [s], cycles whose status frames were not all in by the next.
  struct BusLoad {
    std::size_t frames = 0, incomplete_cycles = 0;
    double busy_s = 0.0, elapsed_s = 0.0;
  };
  std::optional<BusLoad> bus;
  std::vector<double> contact_force_n;     ///< contact force per control cycle [N] (runs with collisions)
  bool detected_by_hold = false;           ///< the first detection came from the holding detector alone
  bool detected_by_residual = false;       ///< the first detection came from the residual detector, not the band
  /// The collided link is nameable at all: the highest joint whose |tau_ext| that reaches the
  /// motor (less what a stuck joint's static friction takes) clears its moving threshold at
  /// some cycle of the contact is the collided link.
  bool isolable = false;
  /// The same from the cycles up to the isolation decision only (the detection plus the
  /// cycles the decision waits for; the whole run when nothing was detected): the ceiling
  /// of what the information at decision time can name. A subset of `isolable`.
  bool isolable_at_decision = false;
  double held_push_nm = 0.0;               ///< held_push: the torque the push puts on its own joint [N·m]
  double peak_true_torque_held = 0.0;      ///< max true |tau_ext| on a joint while its controller held [N·m]
  /// On the collided link's own joint, the largest true |tau_ext| and the largest of the torque
  /// that reaches its motor (less what a stuck joint's static friction takes:
  /// eval/torque_reaching_motor.hpp) [N·m]: what any estimator from the currents can see there.
  double peak_true_torque_own = 0.0, peak_reaching_torque_own = 0.0;
  /// Where the true torque peaks against the moving threshold: the joint (1-based, 0 when no
  /// contact), its true |tau_ext| [N·m] and measured |velocity| [rad/s] there (miss analysis).
  int peak_joint = 0;
  double peak_true_torque_nm = 0.0, speed_at_peak_rad_s = 0.0;
  /// Runs with a second estimator (the other firmware scalar) beside the one that acts: the
  /// same detector's first detection on its estimate (it sees the same measurements; only
  /// the first estimator's detection drives the reaction).
  bool compared = false;
  std::optional<double> t_detected_other;
  /// The contact estimated over the window after the detection (link, point, force) and the
  /// truth beside it; empty when nothing was detected or the window did not end in the run.
  std::optional<ContactOutcome> contact;
  Trace trace;
  io::Recording recording;  ///< the run's recording (kept only with record_trace)
};

/// Runs one scenario. `record_trace` keeps mu and tau_ext per cycle for plots. `other`
/// (optional): a second estimator fed the same measurements, whose detections are only
/// recorded (RunResult::t_detected_other), e.g. the other scalar's firmware core.
RunResult run_detection(const sim::SimulationSetup& setup, Estimator& estimator, const DetectionConfig& detection,
                        const std::string& name, bool record_trace, Estimator* other = nullptr);

/// The holding detector's parameters from seconds at sample time dt: settle and reference
/// windows rounded up to whole cycles (at least one cycle of reference).
HoldChangeParams<double> hold_params(double threshold, double settle_s, double reference_s, double dt);

/// The residual detector's parameters: smoothing dt / T (at most 1).
ResidualChangeParams<double> residual_params(double threshold, double time_constant_s, double dt);

/// Collision-free run for calibration: max |mu| per joint (the observer band).
std::vector<double> observer_band(const sim::SimulationSetup& setup, Estimator& estimator, double settle_s = 0.5);

}  // namespace jg::eval
