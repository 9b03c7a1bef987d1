// Distributed generalized momentum p = M(q) dq (+ rotor) and beta = g(q) - C^T(q,dq) dq,
// one joint module at a time, from its own link constants and its neighbours' messages.
// No joint acceleration anywhere. Derivation: docs/dynamics.md. In short, with spatial
// vectors about joint i's origin in frame i:
//   p_i      = z . n_i + B_i dq_i          n_i: angular momentum of links i..n about O_i
//   g_i      = -z . (h_i x g)              h_i: first moment (sum m c) of links i..n
//   (C^T dq)_i = dT/dq_i = -z . (w_par x n_i + v_par x L_i)
//                                          w_par, v_par: parent link's angular velocity and
//                                          the velocity of its point at O_i; L_i: linear
//                                          momentum of links i..n.
// so an outward pass (base to tip) carries each link's velocity and the gravity vector,
// and an inward pass (tip to base) carries the subtree's momentum and first moment.
// The factorisation this yields is the Christoffel one: M' - 2C is skew-symmetric
// (checked numerically in tests/dynamics).
//
// Q16.16: velocities [rad/s, m/s], momenta [N·m·s, N·s], first moments [kg m], masses
// [kg], gravity [m/s^2] all well inside +/-32768 for a collaborative arm; each scalar
// operation rounds to 0.5 LSB and saturates. Error against double: tests/dynamics.
#pragma once

#include "jointguard/dynamics/link.hpp"

namespace jg {

/// Outward message from link i-1 to link i, in frame i-1.
template <class S>
struct OutwardMessage {
  Vec3<S> angular_velocity{};  ///< of link i-1 [rad/s]
  Vec3<S> origin_velocity{};   ///< of frame i-1's origin [m/s]
  Vec3<S> gravity{};           ///< gravity acceleration [m/s^2]
};

/// Inward message from link i+1 to link i, already in frame i about O_i (the sender
/// knows its own transform, the receiver only its own).
template <class S>
struct InwardMessage {
  Vec3<S> angular_momentum{};  ///< of links i+1..n about O_i [N·m·s]
  Vec3<S> linear_momentum{};   ///< [N·s]
  Vec3<S> first_moment{};      ///< sum m c about O_i [kg m]
  S mass{};                    ///< [kg]
};

/// What the outward step leaves for the same joint's inward step.
template <class S>
struct OutwardState {
  DhRotation<S> rotation{};
  Vec3<S> origin_in_parent{};  ///< O_i in frame i-1 [m]
  Vec3<S> parent_angular_velocity{}, parent_point_velocity{};  ///< in frame i, at O_i
  Vec3<S> angular_velocity{}, origin_velocity{}, gravity{};    ///< link i, frame i
};

template <class S>
struct JointMomentum {
  S momentum{};  ///< p_i [N·m·s]
  S beta{};      ///< g_i - (C^T dq)_i [N·m]
  S gravity{};   ///< g_i [N·m] (the zero-gravity reaction uses it)
};

/// Base of the chain: at rest, gravity in the base frame.
template <class S>
[[nodiscard]] constexpr OutwardMessage<S> base_message(const Vec3<S>& gravity) noexcept {
  OutwardMessage<S> m{};
  m.gravity = gravity;
  return m;
}

/// Tip of the chain: nothing beyond the last link.
template <class S>
[[nodiscard]] constexpr InwardMessage<S> tip_message() noexcept {
  return InwardMessage<S>{};
}

/// Outward step of joint i: its own constants and state plus the parent's message give
/// the message to the child (and what the inward step needs).
template <class S>
constexpr void outward_step(const LinkConstants<S>& c, S q, S dq, const OutwardMessage<S>& parent,
                            OutwardState<S>& st, OutwardMessage<S>& to_child) noexcept {
  const S theta = q + c.theta_offset;
  st.rotation = {jg::cos(theta), jg::sin(theta), c.cos_alpha_prev, c.sin_alpha_prev};
  st.origin_in_parent = {c.a_prev, -(c.sin_alpha_prev * c.d), c.cos_alpha_prev * c.d};
  st.parent_angular_velocity = to_link(st.rotation, parent.angular_velocity);
  st.parent_point_velocity =
      to_link(st.rotation, parent.origin_velocity + cross(parent.angular_velocity, st.origin_in_parent));
  st.gravity = to_link(st.rotation, parent.gravity);
  st.angular_velocity = st.parent_angular_velocity;
  st.angular_velocity.z = st.angular_velocity.z + dq;
  st.origin_velocity = st.parent_point_velocity;  // O_i lies on joint i's axis
  to_child = {st.angular_velocity, st.origin_velocity, st.gravity};
}

/// Inward step of joint i: adds its own link to the child's subtree message, returns the
/// message to the parent and this joint's p_i, beta_i.
template <class S>
constexpr void inward_step(const LinkConstants<S>& c, S dq, const OutwardState<S>& st, const InwardMessage<S>& child,
                           InwardMessage<S>& parent_message, JointMomentum<S>& out) noexcept {
  const Vec3<S> com_velocity = st.origin_velocity + cross(st.angular_velocity, c.com);
  const Vec3<S> own_linear = c.mass * com_velocity;
  const Vec3<S> own_angular = c.inertia_com * st.angular_velocity + cross(c.com, own_linear);
  const Vec3<S> n = own_angular + child.angular_momentum;
  const Vec3<S> l = own_linear + child.linear_momentum;
  const Vec3<S> h = c.first_moment + child.first_moment;
  const S m = c.mass + child.mass;
  out.momentum = n.z + c.rotor_inertia * dq;
  out.gravity = -(cross(h, st.gravity).z);
  // (C^T dq)_i = dT/dq_i = -z . (w_par x n + v_par x L)
  const S coriolis_transpose = -(cross(st.parent_angular_velocity, n).z + cross(st.parent_point_velocity, l).z);
  out.beta = out.gravity - coriolis_transpose;
  // Re-express the subtree about O_{i-1} in frame i-1 for the parent.
  const Vec3<S> l_parent = to_parent(st.rotation, l);
  parent_message.linear_momentum = l_parent;
  parent_message.angular_momentum = to_parent(st.rotation, n) + cross(st.origin_in_parent, l_parent);
  parent_message.first_moment = to_parent(st.rotation, h) + m * st.origin_in_parent;
  parent_message.mass = m;
}

/// Centralised composition of the same steps over a whole chain (host and tests).
template <class S>
constexpr void chain_momentum(const LinkConstants<S>* links, int n, const S* q, const S* dq, const Vec3<S>& gravity,
                              JointMomentum<S>* out) noexcept {
  OutwardState<S> states[kMaxJoints]{};
  OutwardMessage<S> msg = base_message(gravity);
  for (int i = 0; i < n && i < kMaxJoints; ++i) {
    OutwardMessage<S> next{};
    outward_step(links[i], q[i], dq[i], msg, states[i], next);
    msg = next;
  }
  InwardMessage<S> back = tip_message<S>();
  for (int i = (n < kMaxJoints ? n : kMaxJoints) - 1; i >= 0; --i) {
    InwardMessage<S> up{};
    inward_step(links[i], dq[i], states[i], back, up, out[i]);
    back = up;
  }
}

}  // namespace jg
