// The workflow on recordings: identify friction from observer output, calibrate the
// thresholds, replay through the firmware core. Shared by the CLI and the demo.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "eval/estimator.hpp"
#include "identification/identify.hpp"
#include "io/recording.hpp"
#include "jointguard/detection/detector.hpp"
#include "jointguard/observer/momentum_observer.hpp"
#include "robot/robot_model.hpp"

namespace jg::eval {

/// Contract JSON (--friction): {"joints": [{"joint", "sigma0", ..., "w_s", "rms"}]}
void write_friction_json(const std::string& path, const std::vector<ident::IdentificationResult>& r,
                         const std::vector<int>& joint_ids);
std::vector<LuGreParams<double>> read_friction_json(const std::string& path);

struct Thresholds {
  std::vector<double> threshold;               ///< with friction compensation, while moving [N·m]
  std::vector<double> low_speed_extra;         ///< added near standstill (stiction) [N·m]
  double low_speed_width = 0.03;               ///< w_band [rad/s]
  std::vector<double> threshold_uncompensated; ///< without [N·m]
  std::vector<double> band, band_uncompensated;  ///< observed max |mu| before the margin
  double margin = 0.0;
};
/// Contract JSON (--threshold): {"joints": [{"joint", "threshold", "threshold_uncompensated"}]}
void write_threshold_json(const std::string& path, const Thresholds& t, const std::vector<int>& joint_ids);
Thresholds read_threshold_json(const std::string& path);

/// Motor torque per joint from a recording (tau_m columns, or currents x K_I of the model).
std::vector<std::vector<double>> motor_torque(const io::Recording& rec, const robot::RobotModel& model);

/// Resamples a recording to `rate_hz` (linear interpolation); returns it unchanged when
/// the rate already matches within 0.1 %.
io::Recording resample(const io::Recording& rec, double rate_hz);

/// Observer output per joint over a recording (firmware core, float, no compensation).
std::vector<std::vector<double>> observer_disturbance(const io::Recording& rec, const robot::RobotModel& model,
                                                     const ObserverGains& gains, bool compensate,
                                                     const std::vector<LuGreParams<double>>& friction,
                                                     const std::string& scalar = "float");

std::vector<ident::IdentificationResult> identify_recording(const io::Recording& rec, const robot::RobotModel& model,
                                                            const ObserverGains& gains, const ident::GaSettings& ga,
                                                            const std::function<void(double)>& progress = {});

Thresholds calibrate_recording(const io::Recording& rec, const robot::RobotModel& model,
                               const std::vector<LuGreParams<double>>& friction, const ObserverGains& gains,
                               double margin, double settle_s = 0.5);

struct ReplayEvent {
  double t = 0.0;
  int link = 0;
  std::vector<int> joints_over;
};
struct ReplayResult {
  std::vector<ReplayEvent> events;
  std::vector<double> external_torque_max;
  std::vector<double> t;
  std::vector<std::vector<double>> mu;  ///< [joint][sample]
};
/// The detector's band per joint from calibrated thresholds.
std::vector<JointThreshold<double>> threshold_bands(const Thresholds& t);

ReplayResult replay_recording(const io::Recording& rec, const robot::RobotModel& model,
                              const std::vector<LuGreParams<double>>& friction, const Thresholds& thresholds,
                              const ObserverGains& gains, const std::string& scalar, int debounce_cycles);

}  // namespace jg::eval
