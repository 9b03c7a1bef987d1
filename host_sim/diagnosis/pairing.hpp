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
  bool correct_friction = false;                  ///< also correct the pair for friction of the motion difference
};

/// Residual = real - simulated motor torque, the simulated recording resampled onto the
/// real one's time base (linear). Refuses different joint sets, non-overlapping spans or
/// non-uniform real sampling, naming the reason.
std::vector<JointSignals> signals_from_pair(const io::Recording& real, const io::Recording& simulated,
                                            const ModelContext& model);

/// Residual = real motor torque - (inverse dynamics over the real motion + friction).
std::vector<JointSignals> signals_from_model(const io::Recording& real, const ModelContext& model);

}  // namespace jg::diag
