// `jointguard identify REC --model M --rigid-body --model-out M2 [--json F]`: whole-arm
// rigid-body identification (host_sim/dynamics/rigid_body_identification.hpp) hooked into
// the identify subcommand.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "robot/robot_model.hpp"

namespace jg::cli {

struct RigidBodyCliOptions {
  bool enabled = false;
  std::string model_out;
  std::string torque_kind = "auto";  ///< joint | motor | auto (tau_j<j> columns: joint, else motor)
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

/// Runs it; `rate_hz` > 0 resamples by time stamp to that rate first. Exit code 0/1.
int run_identify_rigid(const std::string& recording, const std::string& model, const std::string& json, double rate_hz,
                       const RigidBodyCliOptions& o);
/// The same with the prior already loaded (e.g. with URDF/drive load options); `model_label`
/// names it in the outputs.
int run_identify_rigid(const std::string& recording, const robot::RobotModel& prior, const std::string& model_label,
                       const std::string& json, double rate_hz, const RigidBodyCliOptions& o);

}  // namespace jg::cli
