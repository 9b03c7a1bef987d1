// Drive parameters by joint name (`--drive FILE`): what a URDF does not carry (the
// current-to-torque constant, gear ratio, reflected rotor inertia, current limit), applied
// to any robot model. Format (docs/robot-model.md):
//   joints: [shoulder_pan_joint, ...]          # names as in the model, any order
//   k_i: [10.0, ...]                           # N·m/A at the link side
//   gear_ratio: [..], rotor_inertia_kg_m2: [..], current_limit_a: [..]   # optional
// Every model joint must be listed and every listed joint must exist.
#pragma once

#include <string>

#include "robot/robot_model.hpp"

namespace jg::robot {
void apply_drive_file(RobotModel& model, const std::string& path);
}
