// Sensors and actuators of a joint drive, as the firmware sees them:
//  - link-side absolute encoder (19 bit per turn): quantised position;
//  - motor incremental encoder (2500 lines x4, behind the gear): velocity by differencing
//    counts over one control period, expressed at the link side;
//  - motor current: commanded current (the drive's current loop is taken as ideal) plus
//    offset, white noise and ADC quantisation; torque produced with the *true* torque
//    constant, reported with the *nominal* one (torque-constant error);
//  - a measurement delay of whole control periods; current saturation at the limit.
#pragma once

#include <deque>
#include <random>
#include <vector>

#include "dynamics/rigid_body.hpp"

namespace jg::sim {

struct JointDriveConfig {
  double gear_ratio = 100.0;
  double torque_constant_nominal = 10.0;  ///< K_I at the link side [N·m/A]
  double torque_constant_error = 0.0;     ///< true K_I = nominal (1 + error)
  double current_limit_a = 10.0;          ///< [A]
  double current_offset_a = 0.0;          ///< [A] added to the measurement
  double current_noise_rms_a = 0.0;       ///< [A] white, per sample
  double current_lsb_a = 0.0;             ///< ADC step [A], 0 = not quantised
};

struct SensorConfig {
  std::vector<JointDriveConfig> drives;  ///< one per joint
  int link_encoder_bits = 19;
  int motor_encoder_counts_per_rev = 10000;  ///< 2500 lines x4
  int delay_samples = 0;          ///< all measurements, whole control periods
  int current_delay_samples = 0;  ///< extra delay of the current channel alone (torque lags motion)
  unsigned long long seed = 1;
  // Second shapes of sensor/actuator effects, default off (outputs unchanged when off); used
  // by the second concealed-effect generator (diagnosis/testset_second.cpp).
  /// A fraction of a sample more on the current channel (in [0, 1)): linear interpolation
  /// between consecutive samples, as an anti-aliasing filter's group delay would give.
  double current_delay_fraction = 0.0;
  /// Per joint (empty = off): the true torque constant falls with the current, K(i) =
  /// K_nominal (1 + error) (1 - s |i|), s [1/A] (mild magnetic saturation).
  std::vector<double> torque_constant_saturation_per_a;
  /// Per joint (empty = off): the current offset drifts linearly, offset + rate t [A/s].
  std::vector<double> current_offset_drift_a_per_s;
};

struct Measurement {
  JointVector q, dq, current, tau_m;  ///< tau_m = nominal K_I x measured current [N·m]
};

class JointSensors {
 public:
  JointSensors(SensorConfig config, int joints);
  /// Current command for a desired link-side torque (saturated at the current limit).
  [[nodiscard]] JointVector current_command(const JointVector& torque_demand) const;
  /// Torque the motors really produce for a current command (true torque constant).
  [[nodiscard]] JointVector produced_torque(const JointVector& current_cmd) const;
  /// Samples the sensors at the end of a control period of length dt.
  Measurement sample(const JointVector& q_link, const JointVector& theta_motor_link_units,
                     const JointVector& current_cmd, double dt);
  [[nodiscard]] const SensorConfig& config() const { return config_; }

 private:
  SensorConfig config_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_normal_{0.0, 1.0};
  JointVector last_counts_;
  bool first_ = true;
  std::deque<Measurement> pipeline_;
  std::deque<JointVector> current_pipeline_;
  JointVector last_current_;  ///< the previous sample's current (fractional delay)
  double time_s_ = 0.0;       ///< time of the samples so far (offset drift)
};

}  // namespace jg::sim
