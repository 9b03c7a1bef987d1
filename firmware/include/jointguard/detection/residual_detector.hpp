// Change detection during motion: a contact as a fast change of the estimate against its
// own slow baseline.
//
// Why: near standstill the band detector (detector.hpp) carries the stiction allowance of
// several N·m, because the friction a slow joint holds is not predicted by any
// velocity-driven model; and a contact that stops a joint moves its band up to that
// allowance. The estimate mu minus a slow baseline of itself (an exponential average, time
// constant T) does not depend on the measured velocity: it shows a contact's rise almost
// whole when the rise is short against T (for a ramp of rise time r the residual at its end
// is (T / r)(1 - exp(-r / T)) of the ramp's height: 0.63 for r = T). Measured limit
// (docs/history.md, "Campaign detection: the ceiling"): the unpredicted friction of a slow
// joint also builds up within tens of ms (collision-free |mu - baseline| up to 3.1-3.8 N·m
// with T = 50 ms, reached near standstill), so the calibrated threshold (4.9-6.0 N·m) lies
// between the moving band and the standstill band: it brings some detections forward, it
// found no collision the band missed.
//
// Per joint and cycle:
//   residual = mu - baseline;  baseline += smoothing x residual   (smoothing = dt / T)
//   over when |residual| > change_threshold.
// The first cycle after a reset starts the baseline at mu (never over). A change_threshold
// <= 0 disables the detector (never over, no state change).
//
// Scalar: any (float, double, Q16.16). Q16.16: torques in N·m; the residual saturates;
// smoothing x residual is one rounded product (an update below one LSB, 1.5e-5 N·m, is
// lost: the baseline stays within LSB / smoothing of a constant mu, 0.8 mN·m at 1 kHz with
// T = 50 ms, far below any threshold); the baseline saturates.
// Cost per joint and cycle: one subtraction, one product, one addition, one |x| and one
// comparison.
#pragma once

#include "jointguard/numeric/qmath.hpp"

namespace jg {

template <class S>
struct ResidualChangeParams {
  S change_threshold{};  ///< h [N·m]; <= 0: disabled
  S smoothing{};         ///< dt / T of the baseline, in (0, 1]
};

template <class S>
struct ResidualChangeState {
  S baseline{};  ///< [N·m]
  bool started = false;
};

/// One joint, one cycle: updates the baseline and returns whether mu has moved more than
/// the change threshold away from it.
template <class S>
[[nodiscard]] constexpr bool residual_change_step(const ResidualChangeParams<S>& p, ResidualChangeState<S>& s,
                                                  S external_torque) noexcept {
  if (!(S{} < p.change_threshold)) {
    return false;
  }
  if (!s.started) {
    s.baseline = external_torque;
    s.started = true;
    return false;
  }
  const S residual = external_torque - s.baseline;
  s.baseline = s.baseline + p.smoothing * residual;
  return p.change_threshold < jg::abs(residual);
}

/// |mu - baseline| before the update (0 before the first cycle): what the calibration
/// gathers over collision-free motion. Call before residual_change_step.
template <class S>
[[nodiscard]] constexpr S residual_deviation(const ResidualChangeState<S>& s, S external_torque) noexcept {
  return s.started ? jg::abs(external_torque - s.baseline) : S{};
}

}  // namespace jg
