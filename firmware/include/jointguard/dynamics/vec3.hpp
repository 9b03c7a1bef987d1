// 3-vectors and the few operations the per-link recursion needs, for any core scalar.
// Q16.16: each product is 64-bit, rounded and saturated (q.hpp); a cross or dot product
// therefore has at most 3 roundings of 0.5 LSB per component.
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
template <class S>
[[nodiscard]] constexpr Vec3<S> cross(const Vec3<S>& a, const Vec3<S>& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class S>
[[nodiscard]] constexpr S dot(const Vec3<S>& a, const Vec3<S>& b) noexcept {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

/// Symmetric 3x3 (inertia tensors): xx, yy, zz, xy, xz, yz.
template <class S>
struct Sym3 {
  S xx{}, yy{}, zz{}, xy{}, xz{}, yz{};
};
template <class S>
[[nodiscard]] constexpr Vec3<S> operator*(const Sym3<S>& m, const Vec3<S>& v) noexcept {
  return {m.xx * v.x + m.xy * v.y + m.xz * v.z, m.xy * v.x + m.yy * v.y + m.yz * v.z,
          m.xz * v.x + m.yz * v.y + m.zz * v.z};
}

/// The rotation between a link frame and its parent for modified D-H:
/// parent_R_link = RotX(alpha_prev) RotZ(theta). Stored as the values the steps use.
template <class S>
struct DhRotation {
  S ct{}, st{};  ///< cos, sin of the joint angle (theta = q + offset)
  S ca{}, sa{};  ///< cos, sin of alpha_prev (constants)
};

/// parent_R_link * v
template <class S>
[[nodiscard]] constexpr Vec3<S> to_parent(const DhRotation<S>& r, const Vec3<S>& v) noexcept {
  const S x1 = r.ct * v.x - r.st * v.y;
  const S y1 = r.st * v.x + r.ct * v.y;
  return {x1, r.ca * y1 - r.sa * v.z, r.sa * y1 + r.ca * v.z};
}
/// parent_R_link^T * v
template <class S>
[[nodiscard]] constexpr Vec3<S> to_link(const DhRotation<S>& r, const Vec3<S>& v) noexcept {
  const S y1 = r.ca * v.y + r.sa * v.z;
  const S z1 = -r.sa * v.y + r.ca * v.z;
  return {r.ct * v.x + r.st * y1, -r.st * v.x + r.ct * y1, z1};
}

}  // namespace jg
