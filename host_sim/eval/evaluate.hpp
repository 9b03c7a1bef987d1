// Closed-loop evaluation: the simulated arm runs a scenario while the estimator and the
// detector run every control cycle; on detection the reaction takes over the controller.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "eval/estimator.hpp"
#include "jointguard/detection/detector.hpp"
#include "sim/simulation.hpp"

namespace jg::eval {

struct DetectionConfig {
  std::vector<double> threshold;  ///< eps0 per joint [N·m]
  std::vector<double> per_speed;  ///< band growth per joint [N·m·s/rad] (empty = 0)
  std::vector<double> low_speed_extra;  ///< stiction allowance near standstill [N·m] (empty = 0)
  double low_speed_width = 0.03;        ///< [rad/s]
  double isolation_fraction = 0.3;      ///< joints above this share of their threshold join the signature
  int debounce_cycles = 1;
  Reaction reaction = Reaction::stop;
  std::vector<LuGreParams<double>> friction;  ///< for the zero-gravity mode's friction compensation
  double retreat_rad = 0.1;   ///< retreat: joint-space path length [rad] to go back along
  double retreat_s = 0.3;     ///< retreat: time to go back [s], then hold
  double reflex_gain = 1.0;   ///< reflex: motor torque = gravity + gain x estimated contact torque
  double reflex_s = 0.3;      ///< reflex: duration [s], then hold where the arm is
};

struct Trace {
  std::vector<double> t;
  std::vector<std::vector<double>> mu, tau_ext;  ///< [joint][sample]
};

struct RunResult {
  std::string name;
  int index = 0;                           ///< position in its campaign (0-based): the merge order
  double t_collision = 0.0;                ///< start of the first scheduled collision [s]
  std::optional<double> t_threshold;       ///< first time the true |tau_ext| exceeds the threshold in effect
  std::optional<double> t_detected;
  int link_true = 0, link_isolated = 0;
  double peak_force_n = 0.0;
  /// max over joints and samples of |tau_ext| / threshold in effect (the band at the
  /// measured velocity, standstill allowance included)
  double max_true_ratio = 0.0;
  double max_true_ratio_moving = 0.0;      ///< the same against the moving threshold eps0 alone
  std::vector<double> false_alarm_times;   ///< detections with no contact in the preceding 0.5 s
  std::optional<double> t_node_flagged;    ///< first cycle a drive's own detector flagged (distributed runs)
  int link_node_isolated = 0;              ///< highest joint flagged by the drives at that cycle
  std::optional<double> t_input_fault;     ///< first cycle a drive reported an input fault (the arm holds)
  std::optional<double> t_comm_fault;      ///< first cycle a drive reported a communication fault (the arm holds)
  std::vector<double> contact_force_n;     ///< contact force per control cycle [N] (runs with collisions)
  Trace trace;
  io::Recording recording;  ///< the run's recording (kept only with record_trace)
};

/// Runs one scenario. `record_trace` keeps mu and tau_ext per cycle for plots.
RunResult run_detection(const sim::SimulationSetup& setup, Estimator& estimator, const DetectionConfig& detection,
                        const std::string& name, bool record_trace);

/// Collision-free run for calibration: max |mu| per joint (the observer band).
std::vector<double> observer_band(const sim::SimulationSetup& setup, Estimator& estimator, double settle_s = 0.5);

}  // namespace jg::eval
