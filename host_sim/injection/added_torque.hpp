// What a list of plant effects adds to a recording's torque reading over its measured
// motion, computed on the recording's uniform segments (io/regularize.hpp) with the
// diagnosis's own signals and effect columns, so that an injected effect is the effect the
// diagnosis would fit.
#pragma once

#include <vector>

#include "io/recording.hpp"
#include "jointguard/friction/lugre.hpp"
#include "robot/plant_effects.hpp"
#include "robot/robot_model.hpp"

namespace jg::inject {

/// The model the effects are computed with.
struct InjectModel {
  const robot::RobotModel* model = nullptr;      ///< nominal arm (for the recording's torque kind)
  std::vector<double> torque_constant;           ///< K_I per joint [N·m/A]: currents read as N·m
  std::vector<LuGreParams<double>> friction;     ///< nominal friction per joint (optional: model-curve effects)
};

/// The torque the effects add on one uniform segment, before the sensor's scale and offset.
struct SegmentAddition {
  std::vector<double> t;                      ///< the segment's uniform grid [s]
  std::vector<std::vector<double>> added_nm;  ///< [joint][sample] [N·m]
  /// Per joint, the sum over the samples of (delay x d tau_model/dt)^2 [N·m^2]: what a
  /// time_delay adds against the model's torque, the diagnosis's delay column (a shifted
  /// reading also reshuffles its noise and fast content, which no model predicts). Zero
  /// without a delay on the joint.
  std::vector<double> delay_on_model_ss;
};

/// Per joint: the reading becomes scale * (reading + added) + offset_nm (the drive's current
/// channel: the scale error acts on the torque the motor produced, the offset is added to it).
struct SensorChange {
  std::vector<double> scale;
  std::vector<double> offset_nm;
};

/// Arm-level effects (inverse dynamics of the changed arm minus the nominal one on the
/// measured q, dq and the signals' acceleration), per-joint effects (predict_effects over the
/// segments one after the other, as diagnose sees them) and the reading's delay, per segment.
std::vector<SegmentAddition> physics_added(const std::vector<io::Recording>& segments, const InjectModel& m,
                                           const std::vector<robot::PlantEffect>& effects);

/// Whether a per-joint effect's torque is a function of one sample's position and velocity
/// alone (Coulomb, viscous, a plain Stribeck excess, a direction asymmetry's levels, a position
/// ripple; a temperature drift, of its time too). Such an effect acts on a recording at each
/// row's own state (rows_added): the uniform grid's value interpolated back to a row sampled
/// off the grid (the UR10e's 10-12 ms steps) would flatten what is sharp in velocity.
bool acts_on_the_row_alone(const robot::PlantEffect& e);

/// What such effects add at each row of the recording as read, before it was made uniform
/// ([joint][row], N·m), with the diagnosis's own columns over the rows' t, q and dq. `step_s`:
/// the uniform grid's step (the signals' nominal dt).
std::vector<std::vector<double>> rows_added(const io::Recording& rows, const std::vector<robot::PlantEffect>& effects, double step_s);

/// torque_constant (scale 1 + b, several multiply) and current_offset (b [N·m], several add).
SensorChange sensor_change(const std::vector<robot::PlantEffect>& effects, std::size_t joints);

}  // namespace jg::inject
