// The external torque that reaches a joint's motor: the ground truth an isolation ceiling
// may count on (run_detection's `isolable`).
//
// A joint that stands still when a contact begins holds the push with its static friction
// until it slips: the friction's change cancels the push, the motor's torque and so the
// current do not move, and no estimator from the currents can see it on that joint (the
// Panda model's 1,000-collision campaign: 7 of 19 isolation misses at decision time were
// such joints, 1.2-7.3 N·m of true torque with 0.08-0.61 N·m of estimate change).
#pragma once

#include <vector>

#include "sim/simulation.hpp"

namespace jg::eval {

/// Where a joint counts as standing still: its true speed at most `speed_rad_s` over the
/// `before_s` before the contact's onset and every cycle since.
struct StandstillRule {
  double speed_rad_s = 0.0;
  double before_s = 0.0;
};

/// Per joint and cycle of `r.recording` (control period `dt` [s]): tau_ext, less on a joint
/// standing still from before the onset (the first cycle with any external torque) the
/// friction's change since the cycle before it, counted only along the push and up to its
/// size (a change the other way, the controller's torque into a stuck joint, says nothing
/// of the contact). Never larger in magnitude than tau_ext, never of the other sign; a joint
/// that moves keeps tau_ext from its first moving cycle on. Empty when the simulation did
/// not record the plant's friction (SimulationResult::plant_friction_nm).
[[nodiscard]] std::vector<std::vector<double>> torque_reaching_motor(const sim::SimulationResult& r, double dt,
                                                                     const StandstillRule& still);

}  // namespace jg::eval
