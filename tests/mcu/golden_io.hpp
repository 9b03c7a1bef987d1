// Little-endian field serialisation for the golden files (explicit, never struct bytes:
// layouts may differ between the host and the MCU ABI).
#pragma once

#include <cstdint>
#include <cstring>

#include "jointguard/dynamics/link.hpp"
#include "jointguard/friction/lugre.hpp"
#include "jointguard/observer/momentum_observer.hpp"

namespace jg::golden {

struct Cursor {
  std::uint8_t* data;
  std::size_t size;
  std::size_t pos = 0;
  bool ok = true;
  void put32(std::uint32_t v) {
    if (pos + 4 > size) {
      ok = false;
      return;
    }
    for (int i = 0; i < 4; ++i) data[pos++] = static_cast<std::uint8_t>(v >> (8U * static_cast<unsigned>(i)));
  }
  std::uint32_t get32() {
    if (pos + 4 > size) {
      ok = false;
      return 0U;
    }
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(data[pos++]) << (8U * static_cast<unsigned>(i));
    return v;
  }
};

inline void put(Cursor& c, float v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, 4);
  c.put32(u);
}
template <int F>
inline void put(Cursor& c, Q<F> v) {
  c.put32(static_cast<std::uint32_t>(v.raw()));
}
inline void get(Cursor& c, float& v) {
  const std::uint32_t u = c.get32();
  std::memcpy(&v, &u, 4);
}
template <int F>
inline void get(Cursor& c, Q<F>& v) {
  v = Q<F>::from_raw(static_cast<std::int32_t>(c.get32()));
}

/// Visits every scalar of the coefficient structs in a fixed order.
template <class S, class Fn>
void visit(LuGreDiscrete<S>& d, Fn&& fn) {
  fn(d.bristle_gain);
  fn(d.bristle_damping);
  fn(d.viscous);
  fn(d.curve.coulomb);
  fn(d.curve.stribeck_drop);
  fn(d.curve.inv_stribeck_velocity);
}
template <class S, class Fn>
void visit(ObserverCoeffs<S>& o, Fn&& fn) {
  fn(o.decay[0]);
  fn(o.decay[1]);
  fn(o.input_gain[0]);
  fn(o.input_gain[1]);
  fn(o.inv_dt);
}
template <class S, class Fn>
void visit(Vec3<S>& v, Fn&& fn) {
  fn(v.x);
  fn(v.y);
  fn(v.z);
}
template <class S, class Fn>
void visit(LinkConstants<S>& l, Fn&& fn) {
  fn(l.cos_alpha_prev);
  fn(l.sin_alpha_prev);
  fn(l.a_prev);
  fn(l.d);
  fn(l.theta_offset);
  fn(l.mass);
  visit(l.first_moment, fn);
  fn(l.inertia_origin.xx);
  fn(l.inertia_origin.yy);
  fn(l.inertia_origin.zz);
  fn(l.inertia_origin.xy);
  fn(l.inertia_origin.xz);
  fn(l.inertia_origin.yz);
  visit(l.origin_in_parent, fn);
  fn(l.a_cos_alpha_prev);
  fn(l.a_sin_alpha_prev);
  fn(l.d_sin_alpha_prev);
  fn(l.rotor_inertia);
  fn(l.torque_constant);
  fn(l.current_limit);
  fn(l.neg_sin_alpha_prev);
  fn(l.neg_d);
  fn(l.neg_a_cos_alpha_prev);
  fn(l.neg_a_sin_alpha_prev);
  visit(l.neg_first_moment, fn);
  visit(l.neg_origin_in_parent, fn);
}

}  // namespace jg::golden
