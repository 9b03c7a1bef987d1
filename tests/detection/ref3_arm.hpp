// The reference arm (models/ref3.yaml) as the contact estimator's tests use it: the model,
// its rigid-body dynamics, the default contact segments, and a posture helper.
#pragma once

#include "detection/contact_estimate.hpp"
#include "robot/robot_model.hpp"

namespace jg::test {

struct Ref3Arm {
  robot::RobotModel model = robot::load_robot(JG_SOURCE_DIR "/models/ref3.yaml");
  sim::ArmDynamics arm = model.dynamics();
  /// The default segments, no surface prior (an isotropic force prior).
  detection::ContactEstimatorParams params = detection::default_contact_params(model.reaches());
};

inline sim::JointVector posture(double waist, double shoulder, double elbow) {
  sim::JointVector q(3);
  q << waist, shoulder, elbow;
  return q;
}

}  // namespace jg::test
