// The loop closed: the physics the diagnosis named, with its fitted parameters, written
// back where the simulation lives: as a robot file's `plant_effects` (diagnose
// --model-out) that sim/apply_effects.hpp turns into the plant's settings, so that the
// simulation re-run with it can be compared against the real recording again.
#pragma once

#include <string>
#include <vector>

#include "diagnosis/arm.hpp"
#include "diagnosis/diagnose.hpp"
#include "io/recording.hpp"
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
/// `folded`, when given, receives the effects folded, in order (for unfold_arm_effects).
std::vector<std::string> fold_arm_effects(robot::RobotModel& model, std::vector<robot::PlantEffect>* folded = nullptr);

/// fold_arm_effects undone: each folded effect taken back out of its link (a payload as the
/// point mass it was folded as) and listed in the model's plant_effects again, so that a
/// written robot file holds a payload as a payload. An effect whose removal would leave the
/// link without a body's inertia (the link was re-identified meanwhile) stays inside; notes say so.
std::vector<std::string> unfold_arm_effects(robot::RobotModel& model, const std::vector<robot::PlantEffect>& folded);

/// A drive's torque-constant error (`torque_constant` plant effects, current data) held where
/// it lives: in the drive's K_I, read as the file's K_I / (1 + k), so that every later stage
/// (the named causes, the rigid-body refit, the per-joint diagnosis) reads the currents with
/// it; removed from plant_effects and appended to `folded` (unfold_arm_effects writes it back).
void fold_drive_effects(robot::RobotModel& model, std::vector<robot::PlantEffect>* folded);

/// `found` added to `existing`: the same cause (effect, joint, setting) found again is one
/// entry with its coefficients added (a torque constant's scale errors compounded), never a
/// second entry (the loop converges in the file).
std::vector<robot::PlantEffect> merge_plant_effects(std::vector<robot::PlantEffect> existing, const std::vector<robot::PlantEffect>& found);

/// The per-joint plant_effects' torque on each joint's signals, [joint][sample] (zeros where
/// a joint has none); effects that cannot be predicted on these signals leave zeros and a note.
std::vector<std::vector<double>> joint_effects_torque(const std::vector<robot::PlantEffect>& effects,
                                                      const std::vector<JointSignals>& signals, std::vector<std::string>* notes);

/// `model`'s own per-joint plant_effects predicted on `rec`'s motion ([joint][sample]): what a
/// fit on top of them takes off the measured torque first (dyn::RigidBodyIdOptions::
/// known_torque). Rotor inertias from `nominal`; notes as joint_effects_torque's.
std::vector<std::vector<double>> known_joint_torque(const robot::RobotModel& model, const robot::RobotModel& nominal,
                                                    const io::Recording& rec, std::vector<std::string>* notes);

/// The per-joint plant_effects' torque added to each joint's predicted torque (and taken off
/// its residual), and the gear effects' deflection (joint_elasticity, backlash found in the
/// deflection channel) taken off the measured deflection; returns notes on effects that
/// cannot be predicted on these signals.
std::vector<std::string> add_joint_effects(const std::vector<robot::PlantEffect>& effects, std::vector<JointSignals>& signals);

}  // namespace jg::diag
