// The loop closed: the physics the diagnosis named, with its fitted parameters, written
// back where the simulation lives: as a robot file's `plant_effects` (diagnose
// --model-out) that sim/apply_effects.hpp turns into the plant's settings, so that the
// simulation re-run with it can be compared against the real recording again.
#pragma once

#include <vector>

#include "diagnosis/arm.hpp"
#include "diagnosis/diagnose.hpp"
#include "robot/plant_effects.hpp"
#include "sim/apply_effects.hpp"

namespace jg::diag {

/// The findings as the robot file's `plant_effects` (what `diagnose --model-out` writes).
std::vector<robot::PlantEffect> plant_effects_of(const ArmDiagnosis& arm, const std::vector<JointDiagnosis>& joints);

/// plant_effects_of applied to `setup` (the nominal simulation of the same motion).
sim::EffectsReport apply_findings(const ArmDiagnosis& arm, const std::vector<JointDiagnosis>& joints, double dt,
                                  sim::SimulationSetup& setup);

}  // namespace jg::diag
