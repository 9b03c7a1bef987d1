// The firmware's estimation cycle, joint by joint, driven on the host (float or Q16.16):
// the same per-joint functions the nodes run, composed over the chain in-process.
#pragma once

#include "eval/estimator.hpp"
#include "jointguard/node/joint_estimator.hpp"
#include "robot/robot_model.hpp"

namespace jg::eval {

struct FirmwareEstimatorConfig {
  robot::RobotModel model;
  double dt = 0.001;
  ObserverGains observer{};
  bool compensate_friction = true;
  std::vector<LuGreParams<double>> friction;
  /// JointEstimatorParams::holding_velocity_deadband per joint [rad/s] (empty: 0).
  std::vector<double> holding_velocity_deadband;
};

/// The holding velocity deadband per joint [rad/s]: 1.5 counts of the motor encoder
/// (sim::SensorConfig: 10,000 counts per motor turn, differenced over one period) at the
/// link side, the velocity dither of a joint at rest.
std::vector<double> holding_deadband(const robot::RobotModel& model, double rate_hz);

/// scalar: "float" or "q". Throws when a parameter does not fit the scalar (range check).
std::unique_ptr<Estimator> make_firmware_estimator(const FirmwareEstimatorConfig& c, const std::string& scalar);

/// Refuses, before any run, LuGre parameters the firmware scalar cannot hold at the sample
/// time dt [s]: std::invalid_argument naming the friction file `path`, the joint (its id)
/// and the values, so the user fixes that entry (not the recording the run would read).
void check_friction_fits(const std::string& path, const std::vector<LuGreParams<double>>& friction,
                         const std::vector<int>& joint_ids, double dt, const std::string& scalar);

}  // namespace jg::eval
