// The model as a given torque reading sees it. A motor current (or K_I * i) drives the
// rotor too: the reflected rotor inertia J_m N^2 belongs in the prediction. A joint torque
// sensor sits after the gear: it reads the link side only, so the rotor's inertia (and the
// motor-side friction, which the user's friction file models for that reading) is not in it.
#pragma once

#include "io/recording.hpp"
#include "robot/robot_model.hpp"

namespace jg::robot {

/// The model to apply to a recording carrying `kind`: for tau_j, every joint's rotor
/// inertia is zero; otherwise the model unchanged.
[[nodiscard]] inline RobotModel for_torque_kind(const RobotModel& model, io::TorqueKind kind) {
  RobotModel out = model;
  if (kind == io::TorqueKind::tau_j) {
    for (auto& j : out.joints) j.link.rotor_inertia = 0.0;
  }
  return out;
}

}  // namespace jg::robot
