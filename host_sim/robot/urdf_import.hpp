// URDF import: any serial chain of revolute (and continuous) joints, read with urdfdom.
// - The chain runs from `base_link` (default: the root) to `tip_link` (default: the deepest
//   leaf; refused when leaves at the same depth end different chains).
// - Links rigidly attached to a moving link (fixed joints: flange, tool0, sensors, also side
//   branches) are lumped into it with the parallel-axis theorem; side branches hanging off a
//   chain link through other joints are carried locked at their zero position; links before
//   the first moving joint (a fixed `world` joint) belong to the base and carry no dynamics.
// - Arbitrary axes and origins are written in modified D-H (urdf_import_dh.hpp) with gravity
//   along -z of the root link.
// - Prismatic, floating and planar joints on the chain are refused naming the joint.
// - Reading and the checks of bad values: urdf_read.hpp.
#pragma once

#include <string>

#include "robot/robot_model.hpp"

namespace jg::robot {
RobotModel import_urdf(const std::string& path, const std::string& base_link = "", const std::string& tip_link = "");
}
