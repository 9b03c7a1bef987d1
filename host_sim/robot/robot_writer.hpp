// Writes a RobotModel in the project's YAML format (docs/robot-model.md), exactly enough
// (17 significant digits) that load_robot reads back the same numbers.
#pragma once

#include <string>

#include "robot/robot_model.hpp"

namespace jg::robot {

/// The YAML text; `header` (optional) becomes leading comment lines.
[[nodiscard]] std::string robot_yaml(const RobotModel& model, const std::string& header = {});

/// Writes atomically (temporary file in the same folder, then rename): a failure leaves
/// no half-written file. Throws io::FormatError naming the path on failure.
void write_robot(const std::string& path, const RobotModel& model, const std::string& header = {});

}  // namespace jg::robot
