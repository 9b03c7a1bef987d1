// The model as a given torque reading sees it. A motor current (or K_I * i) drives the
// rotor too: the reflected rotor inertia J_m N^2 belongs in the prediction. A joint torque
// sensor sits after the gear: it reads the link side only, so the rotor's inertia (and the
// motor-side friction, which the user's friction file models for that reading) is not in it.
#pragma once

#include "io/recording.hpp"
#include "robot/robot_model.hpp"

namespace jg::robot {

/// Refuses motor currents with a model whose torque constants are placeholders (a URDF
/// without --drive): read with K_I = 1 N·m/A every torque would be silently wrong.
inline void check_torque_constant(const RobotModel& model, io::TorqueKind kind) {
  if (kind != io::TorqueKind::current || !model.torque_constant_assumed) return;
  throw io::FormatError(model.source + ": the recording's torque is motor current (i<j>) and this URDF gives no torque "
                        "constant (K_I would be 1 N·m/A): give --drive FILE with k_i (docs/robot-model.md#urdf), or "
                        "torque columns (tau_m<j>)");
}

/// The model to apply to a recording carrying `kind`: for tau_j, every joint's rotor
/// inertia is zero; otherwise the model unchanged. Currents need known torque constants.
[[nodiscard]] inline RobotModel for_torque_kind(const RobotModel& model, io::TorqueKind kind) {
  check_torque_constant(model, kind);
  RobotModel out = model;
  if (kind == io::TorqueKind::tau_j) {
    for (auto& j : out.joints) j.link.rotor_inertia = 0.0;
  }
  return out;
}

}  // namespace jg::robot
