// The loop closed: the physics the diagnosis named, with its fitted parameters, written
// back into the simulation where it lives (the plant's friction truth, drives, payload,
// rotor inertia, elastic gears), so that the simulation re-run with it can be compared
// against the real recording again. Each finding maps to one plant setting; findings the
// plant has no setting for are listed, never dropped silently.
#pragma once

#include <string>
#include <vector>

#include "diagnosis/arm.hpp"
#include "diagnosis/diagnose.hpp"
#include "sim/simulation.hpp"

namespace jg::diag {

struct ModelOutReport {
  std::vector<std::string> applied;       ///< "joint 2: coulomb tau_c 8.2 -> 8.5 N·m", ...
  std::vector<std::string> not_modelled;  ///< findings without a plant setting, with why
};

/// Applies the arm-level and per-joint findings to `setup` (the nominal simulation of the
/// same motion): after this, simulating `setup` includes the named physics. `dt` is the
/// recording's sample time (to turn a fitted delay into whole control periods).
ModelOutReport apply_findings(const ArmDiagnosis& arm, const std::vector<JointDiagnosis>& joints, double dt,
                              sim::SimulationSetup& setup);

}  // namespace jg::diag
