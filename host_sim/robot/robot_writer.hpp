// Writes a RobotModel in the project's YAML format (docs/robot-model.md), exactly enough
// (17 significant digits) that load_robot reads back the same numbers.
#pragma once

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "robot/robot_model.hpp"

namespace jg::robot {

/// The YAML text; `header` (optional) becomes leading comment lines.
[[nodiscard]] std::string robot_yaml(const RobotModel& model, const std::string& header = {});

/// Writes atomically (temporary file in the same folder, then rename): a failure leaves
/// no half-written file. Throws io::FormatError naming the path on failure. The file gets a
/// top-level `identity` key when an identity source is set and gives an object.
void write_robot(const std::string& path, const RobotModel& model, const std::string& header = {});

/// Where write_robot takes the `identity` of the file it writes: the CLI registers the
/// running command's (cli::result_identity: version, command, options, input SHA-256), so a
/// robot file from `--model-out` says what made it as every JSON the tool writes does
/// (issue 29). Unset (library use, tests): no key. Not thread-safe: set it once at start.
void set_identity_source(std::function<nlohmann::json()> source);

/// The `identity` key's YAML: a block mapping whose values are JSON, which is YAML flow
/// syntax, so every YAML reader takes it; "" for anything but a non-empty object.
[[nodiscard]] std::string identity_yaml(const nlohmann::json& identity);

}  // namespace jg::robot
