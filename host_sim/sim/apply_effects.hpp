// Physical effects written into a robot file by `diagnose --model-out` (robot::PlantEffect)
// applied to a simulation setup as the plant's truth: friction truth changes per joint,
// drive sensor errors, the current channel's delay, rotor inertia, elastic gears, a
// payload or a link's mass. The controller keeps the nominal model.
#pragma once

#include <string>
#include <vector>

#include "robot/plant_effects.hpp"
#include "sim/simulation.hpp"

namespace jg::sim {

struct EffectsReport {
  std::vector<std::string> applied;       ///< "joint 2: coulomb: tau_c 8.2 -> 8.5 N·m", ...
  std::vector<std::string> not_modelled;  ///< effects without a plant setting, with why
};

/// Applies `effects` to `setup`; `dt` is the control period (a fitted delay becomes whole
/// periods). Effects the plant has no setting for are listed, never dropped silently.
EffectsReport apply_plant_effects(const std::vector<robot::PlantEffect>& effects, double dt, SimulationSetup& setup);

}  // namespace jg::sim
