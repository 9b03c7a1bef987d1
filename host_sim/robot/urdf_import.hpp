// URDF import (urdfdom): a serial chain of revolute joints whose fixed transforms are
// modified-D-H representable (joint axis z, origin = RotX(alpha) TransX(a) TransZ(d)).
#pragma once

#include <string>

#include "robot/robot_model.hpp"

namespace jg::robot {
RobotModel import_urdf(const std::string& path);
}
