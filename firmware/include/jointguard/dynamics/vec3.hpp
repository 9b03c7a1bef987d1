// 3-vectors and the few operations the per-link recursion needs, for any core scalar.
// Q16.16: products are exact in 64 bits and each component is rounded (0.5 LSB) and
// saturated once (sum_of_products).
#pragma once

#include "jointguard/numeric/qmath.hpp"

namespace jg {

template <class S>
struct Vec3 {
  S x{}, y{}, z{};
};

template <class S>
[[nodiscard]] constexpr Vec3<S> operator+(const Vec3<S>& a, const Vec3<S>& b) noexcept {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class S>
[[nodiscard]] constexpr Vec3<S> operator-(const Vec3<S>& a, const Vec3<S>& b) noexcept {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class S>
[[nodiscard]] constexpr Vec3<S> operator*(S k, const Vec3<S>& a) noexcept {
  return {k * a.x, k * a.y, k * a.z};
}
// Components are written as sums of products so that fixed point rounds and saturates
// once per component (sum_of_products), not once per product.
template <class S>
[[nodiscard]] constexpr Vec3<S> cross(const Vec3<S>& a, const Vec3<S>& b) noexcept {
  return {sum_of_products(a.y, b.z, -a.z, b.y), sum_of_products(a.z, b.x, -a.x, b.z),
          sum_of_products(a.x, b.y, -a.y, b.x)};
}
template <class S>
[[nodiscard]] constexpr S dot(const Vec3<S>& a, const Vec3<S>& b) noexcept {
  return sum_of_products(a.x, b.x, a.y, b.y, a.z, b.z);
}

/// Symmetric 3x3 (inertia tensors): xx, yy, zz, xy, xz, yz.
template <class S>
struct Sym3 {
  S xx{}, yy{}, zz{}, xy{}, xz{}, yz{};
};
template <class S>
[[nodiscard]] constexpr Vec3<S> operator*(const Sym3<S>& m, const Vec3<S>& v) noexcept {
  return {sum_of_products(m.xx, v.x, m.xy, v.y, m.xz, v.z), sum_of_products(m.xy, v.x, m.yy, v.y, m.yz, v.z),
          sum_of_products(m.xz, v.x, m.yz, v.y, m.zz, v.z)};
}

/// The rotation between a link frame and its parent for modified D-H:
/// parent_R_link = RotX(alpha_prev) RotZ(theta). Stored as the values the steps use.
template <class S>
struct DhRotation {
  S ct{}, st{};  ///< cos, sin of the joint angle (theta = q + offset)
  S ca{}, sa{};  ///< cos, sin of alpha_prev (constants)
};

/// parent_R_link * v (v's components S or intermediate terms term_t<S>; y1 is a term: it
/// is only multiplied by cos/sin alpha). neg_sa: -r.sa (a constant the caller has, see
/// negated() in momentum_recursion.hpp).
template <class S, class V>
[[nodiscard]] constexpr Vec3<S> to_parent(const DhRotation<S>& r, S neg_sa, const Vec3<V>& v) noexcept {
  const S x1 = sum_of_products(r.ct, v.x, -r.st, v.y);
  const term_t<S> y1 = sum_of_products_term(r.st, v.x, r.ct, v.y);
  return {x1, sum_of_products(r.ca, y1, neg_sa, v.z), sum_of_products(r.sa, y1, r.ca, v.z)};
}
/// parent_R_link^T * v (y1 is an intermediate term: only multiplied by cos/sin theta);
/// neg_sa as for to_parent.
template <class S>
[[nodiscard]] constexpr Vec3<S> to_link(const DhRotation<S>& r, S neg_sa, const Vec3<S>& v) noexcept {
  const term_t<S> y1 = sum_of_products_term(r.ca, v.y, r.sa, v.z);
  const S z1 = sum_of_products(neg_sa, v.y, r.ca, v.z);
  return {sum_of_products(r.ct, v.x, r.st, y1), sum_of_products(-r.st, v.x, r.ct, y1), z1};
}

}  // namespace jg
