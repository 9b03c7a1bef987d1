// One joint module's own constants: what a joint MCU knows about its link. No parsing on
// the MCU: the host converts a robot description (YAML/URDF) into these with range checks.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>

#include "jointguard/dynamics/vec3.hpp"
#include "jointguard/error.hpp"

namespace jg {

inline constexpr int kMaxJoints = 7;

/// Link i and its joint (revolute about the link frame's z axis), modified D-H (Craig):
/// frame i is reached from frame i-1 by RotX(alpha_prev) TransX(a_prev) RotZ(q + offset)
/// TransZ(d). Everything in SI units, in link frame i.
///
/// Besides the D-H parameters, the host folds the products of constants the steps need
/// (in double, one rounding each), so that the firmware forms every output component as
/// one exact sum of products with one rounding (docs/dynamics.md, momentum_recursion.hpp).
/// Range (checked by convert_link for every scalar): lengths, mass, first moment and
/// inertias below kMaxLinkConstant, so that in Q16.16 they are below 2^28 raw and any
/// seven products with full-range signals fit a 64-bit sum (mac_bounded).
template <class S>
struct LinkConstants {
  S cos_alpha_prev{}, sin_alpha_prev{};  ///< of alpha_{i-1} (precomputed on the host)
  S a_prev{};          ///< a_{i-1} [m]
  S d{};               ///< d_i [m]
  S theta_offset{};    ///< [rad]
  S mass{};            ///< [kg]
  Vec3<S> first_moment{};  ///< mass x centre of mass, link frame [kg m]
  Sym3<S> inertia_origin{};  ///< about O_i, link axes: I_com + m (|c|^2 1 - c c^T) [kg m^2]
  Vec3<S> origin_in_parent{};  ///< O_i in frame i-1: (a, -sin(alpha) d, cos(alpha) d) [m]
  S a_cos_alpha_prev{}, a_sin_alpha_prev{};  ///< a_{i-1} cos/sin(alpha_{i-1}) [m]
  S d_sin_alpha_prev{};  ///< d_i sin(alpha_{i-1}) [m]
  S rotor_inertia{};   ///< reflected to the link side, J_m N^2 [kg m^2]
  S torque_constant{}; ///< K_I = motor torque constant x gear ratio [N·m/A]
  S current_limit{};   ///< [A]
  /// The negated copies of the constants the steps subtract, exactly -x of the fields
  /// above (filled by convert_link): the sums of products then need no negation per cycle.
  S neg_sin_alpha_prev{}, neg_d{}, neg_a_cos_alpha_prev{}, neg_a_sin_alpha_prev{};
  Vec3<S> neg_first_moment{}, neg_origin_in_parent{};
};

/// Largest magnitude accepted for a link's lengths [m], mass [kg], first moment [kg m]
/// and inertias [kg m^2] (2^12: 2^28 raw in Q16.16; see LinkConstants).
inline constexpr double kMaxLinkConstant = 4096.0;

/// The same constants in double on the host (as read from a robot file).
struct LinkDescription {
  double a_prev = 0.0, alpha_prev = 0.0, d = 0.0, theta_offset = 0.0;
  double mass = 0.0;
  double com[3] = {0.0, 0.0, 0.0};
  double inertia_com[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};  ///< xx, yy, zz, xy, xz, yz
  double rotor_inertia = 0.0, torque_constant = 1.0, current_limit = 1.0;
};

/// Host-side conversion with range checks (finite, physical, within kMaxLinkConstant and
/// the scalar's range); `out` is written only on success.
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
  const double ca = std::cos(l.alpha_prev);
  const double sa = std::sin(l.alpha_prev);
  const double(&c)[3] = l.com;
  const double(&ic)[6] = l.inertia_com;  // xx, yy, zz, xy, xz, yz
  const double c2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  // Parallel-axis theorem: inertia about O_i = I_com + m (|c|^2 1 - c c^T).
  const double io[6] = {ic[0] + l.mass * (c2 - c[0] * c[0]), ic[1] + l.mass * (c2 - c[1] * c[1]),
                        ic[2] + l.mass * (c2 - c[2] * c[2]), ic[3] - l.mass * c[0] * c[1],
                        ic[4] - l.mass * c[0] * c[2],         ic[5] - l.mass * c[1] * c[2]};
  const double fm[3] = {l.mass * c[0], l.mass * c[1], l.mass * c[2]};
  const double bounded[] = {l.a_prev, l.d,  l.mass, fm[0], fm[1], fm[2], io[0], io[1],
                            io[2],    io[3], io[4], io[5], l.rotor_inertia};
  if (!std::all_of(std::begin(bounded), std::end(bounded), [](double v) { return v <= kMaxLinkConstant && v >= -kMaxLinkConstant; })) {
    return Error::out_of_range;
  }
  NumericStatus st{};
  LinkConstants<S> out_c{};
  out_c.cos_alpha_prev = convert<S>(ca, st);
  out_c.sin_alpha_prev = convert<S>(sa, st);
  out_c.a_prev = convert<S>(l.a_prev, st);
  out_c.d = convert<S>(l.d, st);
  out_c.theta_offset = convert<S>(l.theta_offset, st);
  out_c.mass = convert<S>(l.mass, st);
  out_c.first_moment = {convert<S>(fm[0], st), convert<S>(fm[1], st), convert<S>(fm[2], st)};
  out_c.inertia_origin = {convert<S>(io[0], st), convert<S>(io[1], st), convert<S>(io[2], st),
                          convert<S>(io[3], st), convert<S>(io[4], st), convert<S>(io[5], st)};
  out_c.origin_in_parent = {convert<S>(l.a_prev, st), convert<S>(-sa * l.d, st), convert<S>(ca * l.d, st)};
  out_c.a_cos_alpha_prev = convert<S>(l.a_prev * ca, st);
  out_c.a_sin_alpha_prev = convert<S>(l.a_prev * sa, st);
  out_c.d_sin_alpha_prev = convert<S>(l.d * sa, st);
  out_c.rotor_inertia = convert<S>(l.rotor_inertia, st);
  out_c.torque_constant = convert<S>(l.torque_constant, st);
  out_c.current_limit = convert<S>(l.current_limit, st);
  // Negations are exact in every scalar (Q: the symmetric range).
  out_c.neg_sin_alpha_prev = -out_c.sin_alpha_prev;
  out_c.neg_d = -out_c.d;
  out_c.neg_a_cos_alpha_prev = -out_c.a_cos_alpha_prev;
  out_c.neg_a_sin_alpha_prev = -out_c.a_sin_alpha_prev;
  out_c.neg_first_moment = {-out_c.first_moment.x, -out_c.first_moment.y, -out_c.first_moment.z};
  out_c.neg_origin_in_parent = {-out_c.origin_in_parent.x, -out_c.origin_in_parent.y, -out_c.origin_in_parent.z};
  if (!st.ok()) {
    return Error::out_of_range;
  }
  out = out_c;
  return Error::ok;
}

}  // namespace jg
