// The math the core needs, one overload set for float, double and Q<F>, so that core
// algorithms written once as templates on their scalar compile for all three.
//
// Q<F> routines: input and output are the same format Q<F> unless stated. Internal
// work is in Q2.30 held in int64_t (so products of two Q2.30 values fit in 62 bits);
// results are rounded to nearest and saturated, never wrapped. Worst-case errors are
// measured against double by tests/unit/test_qmath.cpp and listed in docs/fixed-point.md.
//
// float/double routines forward to <cmath> but share the Q routines' defined results at
// the edges (sqrt of a negative is 0, division by zero is +/-max or 0), so the scalar
// choice never changes control flow.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "jointguard/numeric/q.hpp"

namespace jg {

// ---------------------------------------------------------------- conversions

/// Compile-time constants in any scalar (saturating for Q; use in constexpr context so
/// no double arithmetic reaches the MCU).
template <class S>
[[nodiscard]] constexpr S from_double(double x) noexcept {
  if constexpr (is_q_v<S>) {
    return S::from_double(x);
  } else {
    return static_cast<S>(x);
  }
}

/// Host-side, range-checked conversion (parameters identified in double -> firmware
/// scalar). Records NaN/inf and out-of-range values in `status`.
template <class S>
[[nodiscard]] constexpr S convert(double x, NumericStatus& status) noexcept {
  if constexpr (is_q_v<S>) {
    return S::from_double(x, status);
  } else {
    if (detail::is_nan(x) || x > std::numeric_limits<double>::max() ||
        x < -std::numeric_limits<double>::max()) {
      ++status.not_finite;
      return detail::is_nan(x) ? S{0} : (x > 0 ? std::numeric_limits<S>::max() : std::numeric_limits<S>::lowest());
    }
    if (x > static_cast<double>(std::numeric_limits<S>::max())) {
      ++status.saturated;
      return std::numeric_limits<S>::max();
    }
    if (x < static_cast<double>(std::numeric_limits<S>::lowest())) {
      ++status.saturated;
      return std::numeric_limits<S>::lowest();
    }
    return static_cast<S>(x);
  }
}

/// Runtime conversion of a measured float (sensor, frame payload) on the MCU.
template <class S>
[[nodiscard]] S from_float(float x, NumericStatus& status) noexcept {
  if constexpr (is_q_v<S>) {
    return S::from_float(x, status);
  } else {
    if (!std::isfinite(x)) {
      ++status.not_finite;
      return S{0};
    }
    return static_cast<S>(x);
  }
}

template <class S>
[[nodiscard]] constexpr double to_double(S x) noexcept {
  if constexpr (is_q_v<S>) {
    return x.to_double();
  } else {
    return static_cast<double>(x);
  }
}

template <class S>
[[nodiscard]] constexpr float to_float(S x) noexcept {
  if constexpr (is_q_v<S>) {
    return x.to_float();
  } else {
    return static_cast<float>(x);
  }
}

// ---------------------------------------------------------------- float / double

template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] inline T abs(T x) noexcept { return std::fabs(x); }
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T sign(T x) noexcept { return x > T{0} ? T{1} : (x < T{0} ? T{-1} : T{0}); }
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] inline T sqrt(T x) noexcept { return x > T{0} ? std::sqrt(x) : T{0}; }
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] inline T exp(T x) noexcept { return std::exp(x); }
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] inline T sin(T x) noexcept { return std::sin(x); }
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] inline T cos(T x) noexcept { return std::cos(x); }
/// a / b with a defined result for b == 0: +/-max by the sign of a, 0 for 0/0.
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T div(T a, T b) noexcept {
  if (b > T{0} || b < T{0}) {
    return a / b;
  }
  return a > T{0} ? std::numeric_limits<T>::max()
                  : (a < T{0} ? std::numeric_limits<T>::lowest() : T{0});
}

// ---------------------------------------------------------------- generic

/// Coefficients close to 1 (filter decays exp(-K dT)) need more resolution than a signal
/// format gives: for Q<F> they are held in Q2.30 (|c| < 2, LSB 9.3e-10); float and double
/// keep their own type.
template <class S>
struct precise_coefficient {
  using type = S;
};
template <class S>
using precise_coefficient_t = typename precise_coefficient<S>::type;

/// coefficient * x for float/double.
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T scale(T coefficient, T x) noexcept {
  return coefficient * x;
}

/// a*b + c*d and a*b + c*d + e*f for float/double (Q<F> overloads below round once).
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T sum_of_products(T a, T b, T c, T d) noexcept {
  return a * b + c * d;
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T sum_of_products(T a, T b, T c, T d, T e, T f) noexcept {
  return a * b + c * d + e * f;
}

/// (a*b - c*d) * scale for float/double.
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T diff_of_products_scaled(T a, T b, T c, T d, T scale) noexcept {
  return (a * b - c * d) * scale;
}

template <class S>
[[nodiscard]] constexpr S min(S a, S b) noexcept { return b < a ? b : a; }
template <class S>
[[nodiscard]] constexpr S max(S a, S b) noexcept { return a < b ? b : a; }
template <class S>
[[nodiscard]] constexpr S clamp(S x, S lo, S hi) noexcept { return x < lo ? lo : (hi < x ? hi : x); }

// ---------------------------------------------------------------- Q<F>

namespace detail {
inline constexpr std::int64_t kOneQ30 = std::int64_t{1} << 30;
inline constexpr std::int64_t kLog2eQ30 = 1549082005;   // round(log2(e) * 2^30)
inline constexpr std::int64_t kLn2Q30 = 744261118;      // round(ln(2) * 2^30)
inline constexpr std::int64_t kHalfPiQ30 = 1686629713;  // round(pi/2 * 2^30)
inline constexpr std::int64_t kTurnsPerRadQ32 = 683565276;  // round(2^32 / (2 pi))

/// Q2.30 product of two values known to fit 32 bits (|x| < 2): a 32x32->64 multiply
/// (SMULL on Cortex-M4), rounded.
constexpr std::int64_t mul_q30(std::int64_t a, std::int64_t b) noexcept {
  const std::int64_t p = std::int64_t{static_cast<std::int32_t>(a)} * static_cast<std::int32_t>(b);
  return (p + (std::int64_t{1} << 29)) >> 30;
}

/// 1/k! in Q2.30 for k = 0..10 (Taylor coefficients; no run-time division).
inline constexpr std::int32_t kInvFactorialQ30[11] = {1073741824, 1073741824, 536870912, 178956971, 44739243, 8947849,
                                                      1491308,    213044,     26631,     2959,      296};

/// e^t for t in [0, ln 2), Q2.30 in and out; Taylor to t^10 by Horner (truncation < 4e-10).
constexpr std::int64_t exp_unit_q30(std::int64_t t) noexcept {
  std::int64_t acc = kInvFactorialQ30[10];
  for (int k = 9; k >= 0; --k) {
    acc = mul_q30(acc, t) + kInvFactorialQ30[k];
  }
  return acc;
}

/// sin r and cos r for |r| <= pi/4, Q2.30 (Taylor to r^9 / r^10 in r^2, truncation < 2e-9).
constexpr std::int64_t sin_small_q30(std::int64_t r) noexcept {
  const std::int64_t r2 = mul_q30(r, r);
  // r (1 - r2/3! + r2^2/5! - r2^3/7! + r2^4/9!)
  std::int64_t acc = kInvFactorialQ30[9];
  acc = kInvFactorialQ30[7] - mul_q30(r2, acc);
  acc = kInvFactorialQ30[5] - mul_q30(r2, acc);
  acc = kInvFactorialQ30[3] - mul_q30(r2, acc);
  acc = kInvFactorialQ30[1] - mul_q30(r2, acc);
  return mul_q30(r, acc);
}
constexpr std::int64_t cos_small_q30(std::int64_t r) noexcept {
  const std::int64_t r2 = mul_q30(r, r);
  std::int64_t acc = kInvFactorialQ30[10];
  acc = kInvFactorialQ30[8] - mul_q30(r2, acc);
  acc = kInvFactorialQ30[6] - mul_q30(r2, acc);
  acc = kInvFactorialQ30[4] - mul_q30(r2, acc);
  acc = kInvFactorialQ30[2] - mul_q30(r2, acc);
  return kInvFactorialQ30[0] - mul_q30(r2, acc);
}

/// Reduce an angle to the nearest quarter turn: returns the quadrant (0..3) and the
/// remainder in Q2.30 radians, |r| <= pi/4. The angle in turns is held as a uint32
/// fraction of a turn: wrapping modulo 2^32 **is** the modulo-2pi reduction here.
template <int F>
constexpr void reduce_angle(Q<F> x, std::uint32_t& quadrant, std::int64_t& r_q30) noexcept {
  const std::int64_t turns_q32 = shift_round(std::int64_t{x.raw()} * kTurnsPerRadQ32, F);
  const auto turns = static_cast<std::uint32_t>(static_cast<std::uint64_t>(turns_q32));
  const std::uint32_t shifted = turns + (std::uint32_t{1} << 29U);
  quadrant = shifted >> 30U;
  const auto rem = static_cast<std::int32_t>(shifted & ((std::uint32_t{1} << 30U) - 1U)) -
                   (std::int32_t{1} << 29);  // [-2^29, 2^29): fraction of a quarter turn
  r_q30 = shift_round(std::int64_t{rem} * kHalfPiQ30, 30);  // rem * 2^-32 turn = rem * pi/2 * 2^-30 rad
}

constexpr std::uint64_t isqrt64(std::uint64_t n) noexcept {
  std::uint64_t res = 0;
  std::uint64_t bit = std::uint64_t{1} << 62U;
  while (bit > n) {
    bit >>= 2U;
  }
  while (bit != 0U) {
    if (n >= res + bit) {
      n -= res + bit;
      res = (res >> 1U) + bit;
    } else {
      res >>= 1U;
    }
    bit >>= 2U;
  }
  if (n > res) {  // remainder > res  <=>  n_orig >= (res + 0.5)^2 : round up
    ++res;
  }
  return res;
}
}  // namespace detail

/// |x|; exact (the symmetric range makes it overflow-free).
template <int F>
[[nodiscard]] constexpr Q<F> abs(Q<F> x) noexcept {
  return x.raw() < 0 ? -x : x;
}
/// -1, 0 or +1 in Q<F>.
template <int F>
[[nodiscard]] constexpr Q<F> sign(Q<F> x) noexcept {
  return Q<F>::from_raw(x.raw() > 0 ? static_cast<std::int32_t>(Q<F>::one_raw)
                                    : (x.raw() < 0 ? -static_cast<std::int32_t>(Q<F>::one_raw) : 0));
}
/// sqrt(x), Q<F> -> Q<F>; 64-bit integer square root of raw << F, rounded to nearest
/// (error <= 0.5 LSB). Negative input -> 0.
template <int F>
[[nodiscard]] constexpr Q<F> sqrt(Q<F> x) noexcept {
  if (x.raw() <= 0) {
    return Q<F>{};
  }
  const auto n = static_cast<std::uint64_t>(x.raw()) << static_cast<unsigned>(F);
  return Q<F>::from_raw(detail::saturate32(static_cast<std::int64_t>(detail::isqrt64(n))));
}
/// e^x, Q<F> -> Q<F>. x*log2(e) = n + f is split in Q2.30; 2^f by a Taylor series in
/// Q2.30, then shifted by n with rounding. Saturates to max for large x, rounds to 0 for
/// very negative x. Error: about 1 LSB plus 2e-9 relative (measured in tests).
template <int F>
[[nodiscard]] constexpr Q<F> exp(Q<F> x) noexcept {
  const std::int64_t y_q30 = detail::shift_round(std::int64_t{x.raw()} * detail::kLog2eQ30, F);
  const std::int64_t n = y_q30 >> 30;  // floor
  const std::int64_t f_q30 = y_q30 - n * detail::kOneQ30;
  const std::int64_t pow2f = detail::exp_unit_q30(detail::mul_q30(f_q30, detail::kLn2Q30));
  const std::int64_t shift = 30 - F - n;
  if (shift > 62) {
    return Q<F>{};
  }
  if (shift < -31) {
    return std::numeric_limits<Q<F>>::max();
  }
  return Q<F>::from_raw(detail::saturate32(detail::shift_round(pow2f, static_cast<int>(shift))));
}
/// sin(x), Q<F> rad -> Q<F>; any x (reduced modulo 2 pi exactly in turns). Error ~1 LSB.
template <int F>
[[nodiscard]] constexpr Q<F> sin(Q<F> x) noexcept {
  std::uint32_t quadrant = 0;
  std::int64_t r = 0;
  detail::reduce_angle(x, quadrant, r);
  std::int64_t v = 0;
  switch (quadrant) {
    case 0U: v = detail::sin_small_q30(r); break;
    case 1U: v = detail::cos_small_q30(r); break;
    case 2U: v = -detail::sin_small_q30(r); break;
    default: v = -detail::cos_small_q30(r); break;
  }
  return Q<F>::from_raw(detail::saturate32(detail::shift_round(v, 30 - F)));
}
/// cos(x), Q<F> rad -> Q<F>; as sin.
template <int F>
[[nodiscard]] constexpr Q<F> cos(Q<F> x) noexcept {
  std::uint32_t quadrant = 0;
  std::int64_t r = 0;
  detail::reduce_angle(x, quadrant, r);
  std::int64_t v = 0;
  switch (quadrant) {
    case 0U: v = detail::cos_small_q30(r); break;
    case 1U: v = -detail::sin_small_q30(r); break;
    case 2U: v = -detail::cos_small_q30(r); break;
    default: v = detail::sin_small_q30(r); break;
  }
  return Q<F>::from_raw(detail::saturate32(detail::shift_round(v, 30 - F)));
}
/// a / b, Q<F> -> Q<F>: (a << F) / b in 64 bits, rounded to nearest (ties away from
/// zero), saturated. b == 0 gives +/-max by the sign of a, and 0 for 0/0.
template <int F>
[[nodiscard]] constexpr Q<F> div(Q<F> a, Q<F> b) noexcept {
  if (b.raw() == 0) {
    return a.raw() > 0 ? std::numeric_limits<Q<F>>::max()
                       : (a.raw() < 0 ? std::numeric_limits<Q<F>>::min() : Q<F>{});
  }
  const bool negative = (a.raw() < 0) != (b.raw() < 0);
  const auto num = static_cast<std::uint64_t>(a.raw() < 0 ? -std::int64_t{a.raw()} : std::int64_t{a.raw()})
                   << static_cast<unsigned>(F);
  const auto den = static_cast<std::uint64_t>(b.raw() < 0 ? -std::int64_t{b.raw()} : std::int64_t{b.raw()});
  const auto quotient = static_cast<std::int64_t>((num + den / 2U) / den);
  return Q<F>::from_raw(detail::saturate32(negative ? -quotient : quotient));
}

template <int F>
struct precise_coefficient<Q<F>> {
  using type = Q<30>;
};
/// Q2.30 coefficient * Q<F> -> Q<F>: 64-bit product, one rounding, saturation.
template <int F>
[[nodiscard]] constexpr Q<F> scale(Q<30> coefficient, Q<F> x) noexcept {
  return mul<F>(coefficient, x);
}

namespace detail {
/// Saturating int64 sum (the products of two Q values are below 2^62 in magnitude, so
/// only sums of several extreme values can overflow).
constexpr std::int64_t add_sat64(std::int64_t a, std::int64_t b) noexcept {
  std::int64_t r = 0;
  if (__builtin_add_overflow(a, b, &r)) {
    return a > 0 ? std::numeric_limits<std::int64_t>::max() : std::numeric_limits<std::int64_t>::min();
  }
  return r;
}
template <int F>
constexpr Q<F> round_product_sum(std::int64_t sum) noexcept {
  return Q<F>::from_raw(saturate32(shift_round(sum, F)));
}
}  // namespace detail

/// a*b + c*d, Q<F>: both products exact in 64 bits, one rounding, one saturation.
template <int F>
[[nodiscard]] constexpr Q<F> sum_of_products(Q<F> a, Q<F> b, Q<F> c, Q<F> d) noexcept {
  return detail::round_product_sum<F>(
      detail::add_sat64(std::int64_t{a.raw()} * b.raw(), std::int64_t{c.raw()} * d.raw()));
}
/// a*b + c*d + e*f, Q<F>: one rounding, one saturation (dot products, matrix rows).
template <int F>
[[nodiscard]] constexpr Q<F> sum_of_products(Q<F> a, Q<F> b, Q<F> c, Q<F> d, Q<F> e, Q<F> f) noexcept {
  return detail::round_product_sum<F>(detail::add_sat64(
      detail::add_sat64(std::int64_t{a.raw()} * b.raw(), std::int64_t{c.raw()} * d.raw()), std::int64_t{e.raw()} * f.raw()));
}

/// (a*b - c*d) * scale, Q<F> -> Q<F>, with one rounding instead of three: the
/// difference of products is exact in Q(2F) (64-bit), rounded once to Q(F+8) and then
/// multiplied by scale in 64 bits. Use where a small difference is amplified by a large
/// scale (LuGre's implicit step: scale up to sigma0 dT / s ~ 200). Requires
/// |a*b - c*d| < 2^(23-F+16) (128 for Q16.16) and |scale| < 2^(31-F) (the format's
/// range); the difference saturates beyond that, the result always saturates.
template <int F>
[[nodiscard]] constexpr Q<F> diff_of_products_scaled(Q<F> a, Q<F> b, Q<F> c, Q<F> d, Q<F> scale) noexcept {
  constexpr int kExtra = 8;
  const std::int64_t diff_2f = std::int64_t{a.raw()} * b.raw() - std::int64_t{c.raw()} * d.raw();
  const std::int64_t diff = detail::saturate32(detail::shift_round(diff_2f, F - kExtra));
  return Q<F>::from_raw(detail::saturate32(detail::shift_round(diff * scale.raw(), F + kExtra)));
}

}  // namespace jg
