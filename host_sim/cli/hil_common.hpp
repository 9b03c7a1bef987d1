// Options and runner shared by `plant` and `simulate --bus sim`.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli/common.hpp"

namespace jg::cli {

struct HilOptions {
  std::string scenario, iface, bus = "none", model, friction, threshold, scalar = "float", json, trace, out, reaction = "stop";
  int debounce = 1, timeout_ms = 2000;
  unsigned long long seed = 0;
  bool has_seed = false;
  double duration_s = 0.0;
  std::vector<std::string> faults;  ///< --fault KIND[:TARGET]@START[:DURATION]
  ObserverOptions observer;
  robot::LoadOptions model_options;
  /// `plant`: --iface or --bus sim; `simulate`: --bus sim only (its scenario and --out are its own).
  void add_to(CLI::App* cmd, bool plant);
};

/// Runs the scenario with the drives in the loop and prints/writes the results.
int run_hil_command(const HilOptions& o);

}  // namespace jg::cli
