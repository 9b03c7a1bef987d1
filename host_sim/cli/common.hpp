// Helpers shared by the subcommands: options every command spells the same way.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "jointguard/observer/momentum_observer.hpp"
#include "robot/robot_model.hpp"

namespace jg::cli {

/// --observer first_order|lowpass2|paper_bandpass|paper_improved and --gains K1[,K2[,K3]].
/// Without --gains the first-order observer takes the default for the loop rate
/// (tuning::default_gains); the other presets need their gains.
struct ObserverOptions {
  std::string preset = "first_order";
  std::vector<double> gains;
  void add_to(CLI::App* cmd);
  [[nodiscard]] ObserverGains to_gains(double rate_hz) const;
};

void check_scalar(const std::string& scalar);

/// --base LINK, --tip LINK (a URDF's chain) and --drive FILE (drive parameters by joint
/// name), next to every --model.
void add_model_selection(CLI::App* cmd, robot::LoadOptions& o);

}  // namespace jg::cli
