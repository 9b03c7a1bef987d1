// Options and runner shared by `plant` and `simulate --bus sim`.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli/common.hpp"
#include "sim/scenario.hpp"

namespace jg::cli {

struct HilOptions {
  std::string scenario, iface, bus = "none", model, friction, threshold, scalar = "float", json, trace, out, reaction = "stop";
  int debounce = 1, timeout_ms = 2000;
  unsigned long long seed = 0;
  bool has_seed = false;
  double duration_s = 0.0;
  double plant_rate_hz = 0.0;  ///< simulate --plant-rate (0: the scenario's)
  std::vector<std::string> faults;  ///< --fault KIND[:TARGET]@START[:DURATION]
  ObserverOptions observer;
  robot::LoadOptions model_options;
  /// `plant`: --iface or --bus sim; `simulate`: --bus sim only (its scenario and --out are its own).
  void add_to(CLI::App* cmd, bool plant);
};

/// simulate --plant-rate: replaces the scenario's plant_rate_hz (`plant_rate_hz` 0: unchanged);
/// refused below the scenario's control rate, naming the scenario file.
void override_plant_rate(sim::Scenario& scenario, double plant_rate_hz, const std::string& scenario_path);

/// Runs the scenario with the drives in the loop and prints/writes the results.
int run_hil_command(const HilOptions& o);

}  // namespace jg::cli
