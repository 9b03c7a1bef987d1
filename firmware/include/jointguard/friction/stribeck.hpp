// Static friction models: Coulomb + viscous, and the Stribeck curve (which is also the
// steady state of LuGre). Parameters apart from state; pure functions.
#pragma once

#include "jointguard/numeric/qmath.hpp"

namespace jg {

/// The Stribeck level s(w) = tau_c + (tau_s - tau_c) exp(-(w / w_s)^2), stored in the
/// form the step needs (difference and inverse velocity precomputed on the host).
/// Q16.16: coulomb, stribeck_drop in N·m (|.| < 32768); inv_stribeck_velocity in s/rad
/// (w_s >= 3.1e-5 rad/s). (w * inv_w_s)^2 may saturate: exp of the saturated negative
/// value is 0, which is the correct limit.
template <class S>
struct StribeckCurve {
  S coulomb{};                ///< tau_c [N·m]
  S stribeck_drop{};          ///< tau_s - tau_c [N·m] (negative when tau_s < tau_c)
  S inv_stribeck_velocity{};  ///< 1 / w_s [s/rad]
};

/// s(w) as an intermediate term (term_t<S>, QTerm in fixed point: LuGre's step only
/// multiplies it and adds it to a product). u = w / w_s is a term (only squared); u^2 >= 0,
/// so its negation is exact.
template <class S>
[[nodiscard]] constexpr term_t<S> stribeck_level_term(const StribeckCurve<S>& c, S velocity) noexcept {
  const term_t<S> u = mul_term(velocity, c.inv_stribeck_velocity);
  return mac_term(c.coulomb, c.stribeck_drop, jg::exp(-square(u)));
}
template <class S>
[[nodiscard]] constexpr S stribeck_level(const StribeckCurve<S>& c, S velocity) noexcept {
  return from_term(stribeck_level_term(c, velocity));
}

template <class S>
struct CoulombViscousParams {
  S coulomb{};  ///< tau_c [N·m]
  S viscous{};  ///< sigma2 [N·m·s/rad]
};

/// tau_f = tau_c sign(w) + sigma2 w.
template <class S>
[[nodiscard]] constexpr S coulomb_viscous_torque(const CoulombViscousParams<S>& p, S velocity) noexcept {
  return p.coulomb * jg::sign(velocity) + p.viscous * velocity;
}

template <class S>
struct StribeckParams {
  StribeckCurve<S> curve{};
  S viscous{};  ///< sigma2 [N·m·s/rad]
};

/// tau_f = s(w) sign(w) + sigma2 w: LuGre's steady-state friction.
template <class S>
[[nodiscard]] constexpr S stribeck_torque(const StribeckParams<S>& p, S velocity) noexcept {
  return stribeck_level(p.curve, velocity) * jg::sign(velocity) + p.viscous * velocity;
}

}  // namespace jg
