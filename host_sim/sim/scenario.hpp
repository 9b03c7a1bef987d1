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

/// A plant file (docs/scenarios.md, "A plant file"): what the simulated arm is beyond its
/// robot file, the hidden truth detection never reads: its friction, sensors, controller
/// and integration. `evaluate --plant FILE` and a scenario's `plant:` key apply it; without
/// one the plant is the reference arm's (the paper's Table 1, 19-bit/10000-count encoders,
/// 0.01 A noise, PD at min(40, rate / 8) rad/s, RK4).
struct PlantSpec {
  std::string file;
  double plant_rate_hz = 0.0;  ///< 0: the default (max(2000, 2 x control rate))
  Integrator integrator = Integrator::rk4;
  std::vector<JointFrictionTruth> friction;  ///< per joint (empty: unchanged)
  // Sensors (negative / unset: unchanged).
  bool has_sensors = false;
  double current_noise_rms_a = -1.0, current_lsb_a = -1.0, current_offset_a = 0.0, torque_constant_error = 0.0;
  int delay_samples = 0, link_encoder_bits = 19, motor_encoder_counts_per_rev = 10000;
  // Controller: PD(+I) scaled by each joint's inertia at the start, bandwidth capped at
  // control rate / 8 as the reference arm's; kp = M bw^2, kd = 2 zeta M bw, ki = kp x
  // integral_rad_s, the integral clamped at integral_limit_nm (0: no integral action).
  bool has_controller = false;
  double bandwidth_rad_s = 40.0, damping_ratio = 1.0, integral_rad_s = 0.0, integral_limit_nm = 0.0;
  bool inertia_feedforward = true;
};

/// Reads a plant file for an arm of `joints` joints (refusals name file, line and field).
PlantSpec load_plant_spec(const std::string& path, std::size_t joints);
/// Applies `spec` to a set-up whose links, trajectory and control rate are set.
void apply_plant_spec(const PlantSpec& spec, SimulationSetup& setup);

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
