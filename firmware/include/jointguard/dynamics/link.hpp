// One joint module's own constants: what a joint MCU knows about its link. No parsing on
// the MCU: the host converts a robot description (YAML/URDF) into these with range checks.
#pragma once

#include <algorithm>
#include <cstdint>
#include <iterator>

#include "jointguard/dynamics/vec3.hpp"
#include "jointguard/error.hpp"

namespace jg {

inline constexpr int kMaxJoints = 7;

/// Link i and its joint (revolute about the link frame's z axis), modified D-H (Craig):
/// frame i is reached from frame i-1 by RotX(alpha_prev) TransX(a_prev) RotZ(q + offset)
/// TransZ(d). Everything in SI units, in link frame i.
template <class S>
struct LinkConstants {
  S cos_alpha_prev{}, sin_alpha_prev{};  ///< of alpha_{i-1} (precomputed on the host)
  S a_prev{};          ///< a_{i-1} [m]
  S d{};               ///< d_i [m]
  S theta_offset{};    ///< [rad]
  S mass{};            ///< [kg]
  Vec3<S> first_moment{};  ///< mass x centre of mass, link frame [kg m]
  Sym3<S> inertia_com{};   ///< about the centre of mass, link axes [kg m^2]
  Vec3<S> com{};           ///< centre of mass [m]
  S rotor_inertia{};   ///< reflected to the link side, J_m N^2 [kg m^2]
  S torque_constant{}; ///< K_I = motor torque constant x gear ratio [N·m/A]
  S current_limit{};   ///< [A]
};

/// The same constants in double on the host (as read from a robot file).
struct LinkDescription {
  double a_prev = 0.0, alpha_prev = 0.0, d = 0.0, theta_offset = 0.0;
  double mass = 0.0;
  double com[3] = {0.0, 0.0, 0.0};
  double inertia_com[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};  ///< xx, yy, zz, xy, xz, yz
  double rotor_inertia = 0.0, torque_constant = 1.0, current_limit = 1.0;
};

/// Host-side conversion with range checks; `out` is written only on success.
template <class S>
[[nodiscard]] Error convert_link(const LinkDescription& l, LinkConstants<S>& out) noexcept {
  const double values[] = {l.a_prev, l.alpha_prev, l.d, l.theta_offset, l.mass, l.com[0], l.com[1], l.com[2],
                           l.inertia_com[0], l.inertia_com[1], l.inertia_com[2], l.inertia_com[3], l.inertia_com[4],
                           l.inertia_com[5], l.rotor_inertia, l.torque_constant, l.current_limit};
  if (!std::all_of(std::begin(values), std::end(values), [](double v) { return detail::is_finite(v); })) {
    return Error::not_finite;
  }
  if (l.mass < 0.0 || l.rotor_inertia < 0.0 || !(l.torque_constant > 0.0) || !(l.current_limit > 0.0) ||
      l.inertia_com[0] < 0.0 || l.inertia_com[1] < 0.0 || l.inertia_com[2] < 0.0) {
    return Error::invalid_parameter;
  }
  NumericStatus st{};
  LinkConstants<S> c{};
  c.cos_alpha_prev = convert<S>(std::cos(l.alpha_prev), st);
  c.sin_alpha_prev = convert<S>(std::sin(l.alpha_prev), st);
  c.a_prev = convert<S>(l.a_prev, st);
  c.d = convert<S>(l.d, st);
  c.theta_offset = convert<S>(l.theta_offset, st);
  c.mass = convert<S>(l.mass, st);
  c.com = {convert<S>(l.com[0], st), convert<S>(l.com[1], st), convert<S>(l.com[2], st)};
  c.first_moment = {convert<S>(l.mass * l.com[0], st), convert<S>(l.mass * l.com[1], st),
                    convert<S>(l.mass * l.com[2], st)};
  c.inertia_com = {convert<S>(l.inertia_com[0], st), convert<S>(l.inertia_com[1], st),
                   convert<S>(l.inertia_com[2], st), convert<S>(l.inertia_com[3], st),
                   convert<S>(l.inertia_com[4], st), convert<S>(l.inertia_com[5], st)};
  c.rotor_inertia = convert<S>(l.rotor_inertia, st);
  c.torque_constant = convert<S>(l.torque_constant, st);
  c.current_limit = convert<S>(l.current_limit, st);
  if (!st.ok()) {
    return Error::out_of_range;
  }
  out = c;
  return Error::ok;
}

}  // namespace jg
