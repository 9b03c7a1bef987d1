// The loop closed: the physics the diagnosis named, with its fitted parameters, written
// back where the simulation lives: as a robot file's `plant_effects` (diagnose
// --model-out) that sim/apply_effects.hpp turns into the plant's settings, so that the
// simulation re-run with it can be compared against the real recording again.
#pragma once

#include <string>
#include <vector>

#include "diagnosis/arm.hpp"
#include "diagnosis/diagnose.hpp"
#include "robot/plant_effects.hpp"
#include "robot/robot_model.hpp"
#include "sim/apply_effects.hpp"

namespace jg::diag {

/// The findings as the robot file's `plant_effects` (what `diagnose --model-out` writes).
std::vector<robot::PlantEffect> plant_effects_of(const ArmDiagnosis& arm, const std::vector<JointDiagnosis>& joints);

/// plant_effects_of applied to `setup` (the nominal simulation of the same motion).
sim::EffectsReport apply_findings(const ArmDiagnosis& arm, const std::vector<JointDiagnosis>& joints, double dt,
                                  sim::SimulationSetup& setup);

/// A robot file's own plant_effects in the model's prediction over a real motion (the loop
/// closed on real recordings): the arm-level ones a link's parameters can hold (a payload
/// carried throughout, a link's mass) are folded into the links and removed from the list;
/// returns notes on what stays out of the prediction.
std::vector<std::string> fold_arm_effects(robot::RobotModel& model);

/// The per-joint plant_effects' torque added to each joint's predicted torque (and taken off
/// its residual); returns notes on effects that cannot be predicted on these signals.
std::vector<std::string> add_joint_effects(const std::vector<robot::PlantEffect>& effects, std::vector<JointSignals>& signals);

}  // namespace jg::diag
