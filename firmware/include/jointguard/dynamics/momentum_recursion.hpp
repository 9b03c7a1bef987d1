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
// [kg], gravity [m/s^2] all well inside +/-32768 for a collaborative arm. Every output
// component is one exact 64-bit sum of products (the link's folded constants, see
// LinkConstants), rounded to 0.5 LSB and saturated once. The sums use mac_bounded /
// dot_bounded (no 64-bit overflow check): their operands are full-range signals (< 2^31
// raw, whatever a neighbour sends) times either sin/cos entries (<= 2^16 raw) or link
// constants (< 2^28 raw, enforced by convert_link), at most 7 products and one signal
// addend per sum: below 7 * 2^59 + 2^47 < 2^63. Where two signals multiply (gravity and
// Coriolis terms) the checked sum_of_products is used. Values that are only multiplied or
// added further (the parent's point velocity before its rotation, the rotations' middle
// products, the subtree's momenta and first moment before re-expression) are intermediate
// terms (term_t<S>, QTerm in fixed point: INT32_MIN allowed, |raw| <= 2^31, which keeps the
// bounds above); every output (messages, state, p_i, beta_i) is a symmetric Q16.16 value.
// Constants that are subtracted come pre-negated in fixed point (LinkConstants::neg_*,
// negated()). Error against double: tests/dynamics.
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
  Vec3<S> parent_angular_velocity{}, parent_point_velocity{};  ///< in frame i, at O_i
  /// Link i's, frame i: the parent's rotated into frame i plus dq about z, so its x and y
  /// are the parent's (the inward step reads them as such). O_i's velocity is
  /// parent_point_velocity: O_i lies on joint i's axis.
  Vec3<S> angular_velocity{};
  Vec3<S> gravity{};  ///< frame i
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

/// -x for a link constant x: its negated copy in fixed point (LinkConstants::neg_*, no
/// negation per cycle), the negation itself in floating point (free there: VFMS and
/// VNMLA fold it into the multiply-add, while the copy would cost a load).
template <class S>
[[nodiscard]] constexpr S negated(S x, S negated_copy) noexcept {
  if constexpr (is_q_v<S>) {
    (void)x;
    return negated_copy;
  } else {
    (void)negated_copy;
    return -x;
  }
}

/// Outward step of joint i: its own constants and state plus the parent's message give
/// the message to the child (and what the inward step needs).
template <class S>
constexpr void outward_step(const LinkConstants<S>& c, S q, S dq, const OutwardMessage<S>& parent,
                            OutwardState<S>& st, OutwardMessage<S>& to_child) noexcept {
  S ct{};
  S s_t{};
  jg::sincos(add_term(q, c.theta_offset), s_t, ct);  // the reduction takes any raw angle
  const S ca = c.cos_alpha_prev;
  const S sa = c.sin_alpha_prev;
  const S neg_sa = negated(sa, c.neg_sin_alpha_prev);
  st.rotation = {ct, s_t, ca, sa};
  // Velocity of the parent's point at O_i, u = v + w x o (o = O_i in frame i-1), first
  // rotated by RotX(alpha)^T; with o = (a, -sa d, ca d) the products of constants fold to
  //   u'_x = v_x + ca d w_y + sa d w_z
  //   u'_y = ca v_y + sa v_z - d w_x - sa a w_y + ca a w_z
  //   u'_z = -sa v_y + ca v_z - ca a w_y - sa a w_z
  // (ca^2 + sa^2 = 1 used on the host), then RotZ(theta)^T.
  const Vec3<S>& w = parent.angular_velocity;
  const Vec3<S>& v = parent.origin_velocity;
  // ux, uy: intermediate terms (only multiplied by cos/sin theta below).
  const term_t<S> ux = mac_bounded_term(v.x, c.origin_in_parent.z, w.y, c.d_sin_alpha_prev, w.z);
  const term_t<S> uy =
      dot_bounded_term(ca, v.y, sa, v.z, negated(c.d, c.neg_d), w.x,
                       negated(c.a_sin_alpha_prev, c.neg_a_sin_alpha_prev), w.y, c.a_cos_alpha_prev, w.z);
  const S uz =
      dot_bounded(neg_sa, v.y, ca, v.z, negated(c.a_cos_alpha_prev, c.neg_a_cos_alpha_prev),
                  w.y, negated(c.a_sin_alpha_prev, c.neg_a_sin_alpha_prev), w.z);
  st.parent_point_velocity = {sum_of_products(ct, ux, s_t, uy), sum_of_products(-s_t, ux, ct, uy), uz};
  st.parent_angular_velocity = to_link(st.rotation, neg_sa, parent.angular_velocity);
  st.gravity = to_link(st.rotation, neg_sa, parent.gravity);
  st.angular_velocity = st.parent_angular_velocity;
  st.angular_velocity.z = st.angular_velocity.z + dq;
  to_child = {st.angular_velocity, st.parent_point_velocity, st.gravity};
}

/// Inward step of joint i: adds its own link to the child's subtree message, returns the
/// message to the parent and this joint's p_i, beta_i.
template <class S>
constexpr void inward_step(const LinkConstants<S>& c, S dq, const OutwardState<S>& st, const InwardMessage<S>& child,
                           InwardMessage<S>& parent_message, JointMomentum<S>& out) noexcept {
  const Vec3<S>& w = st.angular_velocity;
  const Vec3<S>& v = st.parent_point_velocity;  // O_i's velocity
  const Vec3<S>& fm = c.first_moment;
  const Vec3<S>& nfm = c.neg_first_moment;
  const Sym3<S>& in = c.inertia_origin;
  // Own link about O_i, with the child's subtree added in the same sums:
  //   linear  m (v + w x c)        = m v + w x (m c)
  //   angular I_c w + c x m(v + w x c) = I_O w + (m c) x v   (I_O: parallel-axis, host)
  // l, n, h: intermediate terms (QTerm in fixed point: only factors of the sums below, an
  // addend, never negated).
  using T = term_t<S>;
  const Vec3<T> l = {mac_bounded_term(child.linear_momentum.x, c.mass, v.x, w.y, fm.z, -w.z, fm.y),
                     mac_bounded_term(child.linear_momentum.y, c.mass, v.y, w.z, fm.x, -w.x, fm.z),
                     mac_bounded_term(child.linear_momentum.z, c.mass, v.z, w.x, fm.y, -w.y, fm.x)};
  const Vec3<T> n = {
      mac_bounded_term(child.angular_momentum.x, in.xx, w.x, in.xy, w.y, in.xz, w.z, fm.y, v.z, negated(fm.z, nfm.z), v.y),
      mac_bounded_term(child.angular_momentum.y, in.xy, w.x, in.yy, w.y, in.yz, w.z, fm.z, v.x, negated(fm.x, nfm.x), v.z),
      mac_bounded_term(child.angular_momentum.z, in.xz, w.x, in.yz, w.y, in.zz, w.z, fm.x, v.y, negated(fm.y, nfm.y), v.x)};
  const Vec3<T> h = {add_term(fm.x, child.first_moment.x), add_term(fm.y, child.first_moment.y),
                     add_term(fm.z, child.first_moment.z)};
  const S m = c.mass + child.mass;
  out.momentum = mac_bounded(n.z, c.rotor_inertia, dq);
  // g_i = -z . (h x g); beta = g_i - (C^T dq)_i with (C^T dq)_i = -z . (w_par x n + v_par x L)
  out.gravity = sum_of_products(h.y, st.gravity.x, h.x, -st.gravity.y);  // -g.y: h is a term
  const Vec3<S>& wp = st.parent_angular_velocity;
  out.beta = out.gravity + sum_of_products_term(wp.x, n.y, -wp.y, n.x, v.x, l.y, -v.y, l.x);
  // Re-express the subtree about O_{i-1} in frame i-1 for the parent:
  //   L' = R L,  N' = R n + o x L',  H' = R h + m o,  R = RotX(alpha) RotZ(theta).
  const DhRotation<S>& r = st.rotation;
  const Vec3<S>& o = c.origin_in_parent;
  const Vec3<S>& no = c.neg_origin_in_parent;
  const S neg_sa = negated(r.sa, c.neg_sin_alpha_prev);
  const Vec3<S> lp = to_parent(r, neg_sa, l);
  const T ny1 = sum_of_products_term(r.st, n.x, r.ct, n.y);
  parent_message.angular_momentum = {dot_bounded(r.ct, n.x, -r.st, n.y, o.y, lp.z, negated(o.z, no.z), lp.y),
                                     dot_bounded(r.ca, ny1, neg_sa, n.z, o.z, lp.x, negated(o.x, no.x), lp.z),
                                     dot_bounded(r.sa, ny1, r.ca, n.z, o.x, lp.y, negated(o.y, no.y), lp.x)};
  const T hy1 = sum_of_products_term(r.st, h.x, r.ct, h.y);
  parent_message.first_moment = {dot_bounded(r.ct, h.x, -r.st, h.y, m, o.x), dot_bounded(r.ca, hy1, neg_sa, h.z, m, o.y),
                                 dot_bounded(r.sa, hy1, r.ca, h.z, m, o.z)};
  parent_message.linear_momentum = lp;
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
