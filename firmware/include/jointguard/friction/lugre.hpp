// LuGre friction per joint (READING.md section 4), with the paper's implicit-Euler
// discretisation, carried in a scaled state so that fixed point has the resolution.
//
// Physical model:  tau_f = sigma0 z + sigma1 z' + sigma2 w,
//                  z'    = w - sigma0 |w| z / s(w).
// The bristle deflection z is ~tau_s/sigma0 ~ 5e-5 rad: below a Q16.16 LSB's worth of
// useful resolution, and sigma0 ~ 1e5 does not even fit Q16.16. The state is therefore
// the **bristle torque** zeta = sigma0 z [N·m] and the coefficients are folded with the
// sample time on the host (discretize), where double precision is available:
//
//   a      = sigma0 dT                      bristle_gain     [N·m·s/rad]
//   c1     = sigma1 / (sigma0 dT)           bristle_damping  [-]
//   zeta_k = (zeta_{k-1} + a w) / (1 + a|w|/s)               (paper eq. 13, times sigma0)
//          = zeta_{k-1} + (w s - zeta_{k-1}|w|) * a / (s + a|w|)
//   tau_f  = zeta_k + c1 (zeta_k - zeta_{k-1}) + sigma2 w
//
// The incremental form is used because its one division, g = a / (s + a|w|), never
// multiplies a large number by a rounded ratio: (w s - zeta|w|) is zero at steady
// sliding, so the rounding of g does not show in the output. It is the same implicit
// step, unconditionally stable for any dT (|zeta_k| <= max(|zeta_{k-1}|, s)).
//
// Q16.16 (every member below): ranges needed for the paper's parameters at 125 Hz:
// a <= 800, c1 <= 3.2 at 1 kHz, |w| <= 40 rad/s, |a w| < 32768 -> fits. Intermediates
// are exact 64-bit sums of at most two products, each rounded once and saturated
// (mac, sum_of_products, diff_of_products_scaled).
#pragma once

#include "jointguard/error.hpp"
#include "jointguard/friction/stribeck.hpp"
#include "jointguard/numeric/qmath.hpp"

namespace jg {

/// Physical LuGre parameters (host side, usually double), as identified (paper Table 1).
template <class S>
struct LuGreParams {
  S sigma0{};  ///< bristle stiffness [N·m/rad]
  S sigma1{};  ///< bristle micro-damping [N·m·s/rad]
  S sigma2{};  ///< viscous coefficient [N·m·s/rad]
  S tau_c{};   ///< Coulomb level [N·m]
  S tau_s{};   ///< static (stiction) level [N·m]
  S w_s{};     ///< Stribeck velocity [rad/s]
};

/// Firmware coefficients: LuGre folded with a sample time, in the firmware scalar.
template <class S>
struct LuGreDiscrete {
  S bristle_gain{};     ///< sigma0 * dT [N·m·s/rad]
  S bristle_damping{};  ///< sigma1 / (sigma0 * dT) [-]
  S viscous{};          ///< sigma2 [N·m·s/rad]
  StribeckCurve<S> curve{};
};

/// Per-joint state: the bristle torque sigma0 * z [N·m].
template <class S>
struct LuGreState {
  S bristle_torque{};
};

/// Checks a physical parameter set: all finite, sigma0, tau_c, tau_s, w_s > 0,
/// sigma1, sigma2 >= 0.
[[nodiscard]] constexpr Error validate(const LuGreParams<double>& p) noexcept {
  using detail::is_finite;
  if (!is_finite(p.sigma0) || !is_finite(p.sigma1) || !is_finite(p.sigma2) || !is_finite(p.tau_c) ||
      !is_finite(p.tau_s) || !is_finite(p.w_s)) {
    return Error::not_finite;
  }
  if (!(p.sigma0 > 0.0) || !(p.tau_c > 0.0) || !(p.tau_s > 0.0) || !(p.w_s > 0.0) ||
      p.sigma1 < 0.0 || p.sigma2 < 0.0) {
    return Error::invalid_parameter;
  }
  return Error::ok;
}

/// Host-side: fold physical parameters with the sample time dt [s] and convert them to
/// the firmware scalar with a range check. `out` is written only on success.
template <class S>
[[nodiscard]] constexpr Error discretize(const LuGreParams<double>& p, double dt,
                                         LuGreDiscrete<S>& out) noexcept {
  if (const Error e = validate(p); e != Error::ok) {
    return e;
  }
  if (!(dt > 0.0) || dt > 1.0) {
    return Error::invalid_parameter;
  }
  NumericStatus status{};
  LuGreDiscrete<S> d{};
  d.bristle_gain = convert<S>(p.sigma0 * dt, status);
  d.bristle_damping = convert<S>(p.sigma1 / (p.sigma0 * dt), status);
  d.viscous = convert<S>(p.sigma2, status);
  d.curve.coulomb = convert<S>(p.tau_c, status);
  d.curve.stribeck_drop = convert<S>(p.tau_s - p.tau_c, status);
  d.curve.inv_stribeck_velocity = convert<S>(1.0 / p.w_s, status);
  if (!status.ok()) {
    return Error::out_of_range;
  }
  // A level that rounds to zero in the scalar would make the step divide by |w| alone.
  if (!(S{} < d.curve.coulomb) || !(S{} < d.curve.coulomb + d.curve.stribeck_drop) ||
      !(S{} < d.bristle_gain)) {
    return Error::out_of_range;
  }
  out = d;
  return Error::ok;
}

/// One sample: advances the bristle state with joint velocity w [rad/s] and returns the
/// friction torque [N·m] (positive opposes positive motion).
template <class S>
[[nodiscard]] constexpr S lugre_step(const LuGreDiscrete<S>& c, LuGreState<S>& state,
                                     S velocity) noexcept {
  // level, the bristle update and the torque change are intermediate terms (QTerm in
  // fixed point): only factors and addends of the sums that follow.
  const term_t<S> level = stribeck_level_term(c.curve, velocity);
  const S speed = jg::abs(velocity);
  const S gain = jg::div(c.bristle_gain, mac(level, c.bristle_gain, speed));
  const S previous = state.bristle_torque;
  const S next = previous + jg::diff_of_products_scaled_term(velocity, level, previous, speed, gain);
  state.bristle_torque = next;
  return next + sum_of_products_term(c.bristle_damping, sub_term(next, previous), c.viscous, velocity);
}

}  // namespace jg
