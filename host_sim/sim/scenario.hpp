// Scenario files (YAML): what `jointguard simulate` runs. Format documented in
// docs/scenarios.md; every key carries its unit; unknown keys are refused.
#pragma once

#include <string>

#include "robot/plant_effects.hpp"
#include "robot/robot_model.hpp"
#include "sim/apply_effects.hpp"
#include "sim/simulation.hpp"

namespace jg::sim {

/// The robot as the plant needs it: links, drives and nominal friction/controller gains.
struct PlantModel {
  std::string name;
  std::vector<PlantLink> links;
  std::vector<JointDriveConfig> drives;
  std::vector<double> link_lengths;  ///< reach of each link (for placing contacts) [m]
  /// Effects found by `diagnose` and written into the robot file: applied to the plant.
  std::vector<robot::PlantEffect> plant_effects;
};

/// Loads a robot file (the project's YAML or a URDF) for the plant.
/// `options`: the URDF chain (--base/--tip) and the drive file (--drive) the command line gave.
PlantModel load_plant_model(const std::string& path, const robot::LoadOptions& options = {});

struct Scenario {
  std::string file;
  PlantModel model;
  SimulationSetup setup;
  EffectsReport effects;  ///< what the model's plant_effects changed in the setup
};

/// Parses a scenario; `model` paths are relative to the scenario file's folder.
/// `model_override`: a robot file used instead of the scenario's `model` (e.g. the one
/// `diagnose --model-out` wrote); its plant_effects are applied to the plant last.
/// `model_options`: how the robot file is read (URDF chain, drive file), for either.
Scenario load_scenario(const std::string& path, unsigned long long seed_override = 0, bool has_seed_override = false,
                       const std::string& model_override = "", const robot::LoadOptions& model_options = {});

}  // namespace jg::sim
