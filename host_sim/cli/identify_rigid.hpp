// `jointguard identify REC --model M --rigid-body --model-out M2 [--json F]`: whole-arm
// rigid-body identification (host_sim/arm_identification/rigid_body_identification.hpp)
// hooked into the identify subcommand.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "io/recording.hpp"
#include "robot/robot_model.hpp"

namespace jg::cli {

struct RigidBodyCliOptions {
  bool enabled = false;
  std::string model_out;
  double com_margin_m = 0.1;
  double sigma_ms = 0.0;
  double prior_weight = 10.0;
  double friction_eps = 0.0;
  double slow_speed = -1.0;
  bool payload_only = false;
  bool asymmetric_coulomb = false;
};

/// Adds --rigid-body and its options to `cmd` (the identify subcommand).
void add_rigid_body_options(CLI::App* cmd, RigidBodyCliOptions& o);

/// Runs it on a recording already read and regularized (uniform steps, its torque kind
/// chosen by --torque-kind); `model_label` names the prior in the outputs. Exit code 0/1.
int run_identify_rigid(const io::Recording& rec, const std::string& recording, const nlohmann::json& resampling,
                       const robot::RobotModel& prior, const std::string& model_label, const std::string& json,
                       const RigidBodyCliOptions& o);

}  // namespace jg::cli
