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
  /// > 0: instead, the deadband of each joint is this many of its velocity steps, the step
  /// measured from the estimator's own input: the smallest non-zero |dq| it has been given
  /// (one encoder count per sample, whatever the encoder; until the joint has moved a count
  /// its dq is 0 and no deadband is needed). What replay/calibrate take from a recording
  /// (pipeline.cpp), causal: no assumption about the encoder, nothing read from the plant.
  double holding_deadband_steps = 0.0;
};

/// The holding deadband in velocity steps: 1.5, so that a joint at rest whose encoder
/// dithers by one count reads as still and two counts per sample read as motion.
inline constexpr double kHoldingDeadbandSteps = 1.5;

/// The holding velocity deadband per joint [rad/s] as `evaluate`, the drives on the bus and
/// the HIL runs configure it: 1.5 counts of an assumed 10,000-count motor encoder
/// (sim::SensorConfig's default, differenced over one period) at the link side. Wrong for
/// another encoder (the second arm's 4,096 counts: below one count, so no deadband at
/// all); the centralised estimator can measure the step instead (holding_deadband_steps).
std::vector<double> holding_deadband(const robot::RobotModel& model, double rate_hz);

/// scalar: "float" or "q". Throws when a parameter does not fit the scalar (range check).
std::unique_ptr<Estimator> make_firmware_estimator(const FirmwareEstimatorConfig& c, const std::string& scalar);

/// Refuses, before any run, LuGre parameters the firmware scalar cannot hold at the sample
/// time dt [s]: std::invalid_argument naming the friction file `path`, the joint (its id)
/// and the values, so the user fixes that entry (not the recording the run would read).
void check_friction_fits(const std::string& path, const std::vector<LuGreParams<double>>& friction,
                         const std::vector<int>& joint_ids, double dt, const std::string& scalar);

}  // namespace jg::eval
