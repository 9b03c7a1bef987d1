// Builds the per-joint diagnosis signals from a real recording and either a simulated
// recording of the same motion or the model's own prediction over the real motion.
#pragma once

#include <optional>
#include <vector>

#include "diagnosis/signals.hpp"
#include "io/recording.hpp"
#include "jointguard/friction/lugre.hpp"
#include "dynamics/rigid_body.hpp"

namespace jg::diag {

struct ModelContext {
  const sim::ArmDynamics* arm = nullptr;          ///< nominal rigid-body model (optional)
  std::vector<LuGreParams<double>> friction;      ///< nominal friction per joint (optional)
  std::vector<double> torque_constant;            ///< K_I per joint, to use currents (optional)
  /// Reflected rotor inertia per joint [kg m^2] (optional): when the real torque is a joint
  /// torque sensor's (tau_j) and the simulated one a motor torque, the simulation's rotor
  /// torque J_r * ddq is taken off it (the sensor does not see it).
  std::vector<double> rotor_inertia;
  bool correct_friction = false;                  ///< also correct the pair for friction of the motion difference
  /// Width of the Gaussian derivative for the acceleration [s]; < 0: from the data
  /// (dynamics/acceleration.hpp), 0: the +/-10 ms Savitzky-Golay slope.
  double acceleration_sigma_s = -1.0;
};

/// Residual = real - simulated torque, the simulated recording resampled onto the real
/// one's time base (linear). Refuses different joint sets, non-overlapping spans or
/// non-uniform real sampling (io::regularize makes recordings uniform), naming the reason.
/// Each recording's torque is the kind it carries (Recording::torque_kind).
std::vector<JointSignals> signals_from_pair(const io::Recording& real, const io::Recording& simulated,
                                            const ModelContext& model);

/// Residual = real motor torque - (inverse dynamics over the real motion + friction).
std::vector<JointSignals> signals_from_model(const io::Recording& real, const ModelContext& model);

/// Per-segment signals (each computed on one uniform segment, derivatives within it) one
/// after the other, for a diagnosis over every segment of a recording split at gaps.
std::vector<JointSignals> concatenate_signals(const std::vector<std::vector<JointSignals>>& parts);

}  // namespace jg::diag
