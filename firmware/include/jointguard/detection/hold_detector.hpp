// Holding-aware change detection: a contact on a joint whose drive holds a setpoint.
//
// Why: at rest the friction is stiction, which no velocity-driven model predicts, so the
// band detector (detector.hpp) carries a standstill allowance of several N·m there. But a
// drive knows when it holds (its position controller's setpoint is constant): while it
// holds, the friction it holds, the gravity and the controller's torque are constant, so
// the compensated estimate mu stays at the value it took on arrival, up to noise. A contact
// shows as a change of mu from that value, whatever the stiction holds.
//
// Per joint and cycle, with `holding` from the drive's controller:
//   - not holding: the state is cleared (re-armed on the next hold);
//   - the first `settle_cycles` held cycles are skipped (the arrival's transients: the
//     tracking error decaying, the observer settling);
//   - the next `reference_cycles` are averaged into the reference mu_ref;
//   - from then on (armed) the cycle is over when |mu - mu_ref| > change_threshold.
// A change_threshold <= 0 disables the detector (never over).
//
// Scalar: any (float, double, Q16.16). Q16.16: torques in N·m; the reference sum
// saturates at +-32768 N·m (more than reference_cycles x the largest mu a joint sees: a
// saturated sum gives a wrong reference, whose change then shows, i.e. an alarm, never a
// silent miss); the mean is the sum times 1/reference_cycles (rounded once); the
// difference mu - mu_ref saturates. Counters saturate at 65535.
#pragma once

#include <cstdint>

#include "jointguard/numeric/qmath.hpp"

namespace jg {

template <class S>
struct HoldChangeParams {
  S change_threshold{};                 ///< h [N·m]; <= 0: disabled
  std::uint16_t settle_cycles = 0;      ///< held cycles skipped before the reference
  std::uint16_t reference_cycles = 1;   ///< held cycles averaged into the reference (>= 1)
  S inv_reference_cycles = from_double<S>(1.0);  ///< 1 / reference_cycles
};

template <class S>
struct HoldChangeState {
  std::uint16_t held_cycles = 0;  ///< consecutive held cycles before arming (saturates)
  S reference_sum{};              ///< [N·m] sum of mu over the reference window
  S reference{};                  ///< mu_ref [N·m], valid when armed
  bool armed = false;
};

/// One joint, one cycle: true when the joint is held, armed, and its estimate has moved
/// more than the change threshold away from the reference taken on arrival.
template <class S>
[[nodiscard]] constexpr bool hold_change_step(const HoldChangeParams<S>& p, HoldChangeState<S>& s, bool holding,
                                              S external_torque) noexcept {
  if (!holding || !(S{} < p.change_threshold)) {
    s = HoldChangeState<S>{};
    return false;
  }
  if (s.armed) {
    return p.change_threshold < jg::abs(external_torque - s.reference);
  }
  if (s.held_cycles >= p.settle_cycles) {
    s.reference_sum = s.reference_sum + external_torque;
  }
  if (s.held_cycles < 65535U) {
    ++s.held_cycles;
  }
  const std::uint16_t window = p.reference_cycles == 0U ? std::uint16_t{1} : p.reference_cycles;
  if (static_cast<std::uint32_t>(s.held_cycles) >= static_cast<std::uint32_t>(p.settle_cycles) + window) {
    s.reference = s.reference_sum * p.inv_reference_cycles;
    s.armed = true;
  }
  return false;
}

/// The estimate's deviation from the reference [N·m] (0 when not armed): what the
/// calibration gathers over collision-free holds.
template <class S>
[[nodiscard]] constexpr S hold_deviation(const HoldChangeState<S>& s, S external_torque) noexcept {
  return s.armed ? jg::abs(external_torque - s.reference) : S{};
}

}  // namespace jg
