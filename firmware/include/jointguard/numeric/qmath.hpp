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
inline constexpr std::int64_t kTurnsPerRadQ32 = 683565276;  // round(2^32 / (2 pi))
inline constexpr std::int32_t kLog2eQ30 = 1549082005;       // round(log2(e) * 2^30)

/// floor(a * b / 2^32): the high word of the 32x32->64 product (SMMUL / SMULL on
/// Cortex-M4). The polynomial kernels below choose their Q formats so that every product
/// is exactly this: no 64-bit shifts, no rounding constant.
constexpr std::int32_t mul_hi(std::int32_t a, std::int32_t b) noexcept {
  const std::int64_t product = std::int64_t{a} * b;
  return static_cast<std::int32_t>(product >> 32);
}

/// Saturating int64 sum. Only used where more than two full-range products meet: two
/// products of Q values are below 2^62 in magnitude each, so a pair never overflows.
/// Written with the sign rule rather than __builtin_add_overflow, which GCC 12 expands
/// with 64-bit sign extensions on Cortex-M: this is ADDS/ADC and a test on the high words.
constexpr std::int64_t add_sat64(std::int64_t a, std::int64_t b) noexcept {
  const auto r = static_cast<std::int64_t>(static_cast<std::uint64_t>(a) + static_cast<std::uint64_t>(b));
  if (((a ^ r) & (b ^ r)) < 0) {
    return a > 0 ? std::numeric_limits<std::int64_t>::max() : std::numeric_limits<std::int64_t>::min();
  }
  return r;
}

/// Every T is Q<F> or QTerm<F>.
template <int F, class... T>
inline constexpr bool all_q_operands_v = ((is_q_operand_v<T> && T::frac_bits == F) && ...);

/// Adds the exact products a*b (Q(2F), 64-bit) to `acc`. Operands Q<F> or QTerm<F>, never
/// two QTerms in one product: each product is then below 2^62 in magnitude.
template <int F>
constexpr std::int64_t add_products(std::int64_t acc) noexcept {
  return acc;
}
template <int F, class A, class B, class... Rest>
constexpr std::int64_t add_products(std::int64_t acc, A a, B b, Rest... rest) noexcept {
  static_assert(all_q_operands_v<F, A, B>, "one format");
  static_assert(!(is_q_term_v<A> && is_q_term_v<B>), "a product of two QTerms could reach 2^62");
  return add_products<F>(acc + std::int64_t{a.raw()} * b.raw(), rest...);
}
/// c 2^F plus the rounding constant: the addend of mac and mac_bounded (below 2^(31+F)).
template <int F, class C>
constexpr std::int64_t addend(C c) noexcept {
  const auto lo = (static_cast<std::uint32_t>(c.raw()) << F) | (std::uint32_t{1} << (F - 1));
  const auto hi = static_cast<std::uint32_t>(c.raw() >> (32 - F));
  return static_cast<std::int64_t>((std::uint64_t{hi} << 32U) | lo);
}
/// The rounding constant plus the products: sums of at most two products, exact.
template <int F, class... T>
constexpr std::int64_t products_sum(T... operands) noexcept {
  static_assert(sizeof...(T) <= 4, "more than two full-range products can overflow int64");
  return add_products<F>(rounding_constant<F>(), operands...);
}
/// c 2^F + a*b with the rounding constant, exact.
template <int F, class C, class A, class B>
constexpr std::int64_t mac_sum(C c, A a, B b) noexcept {
  return add_products<F>(addend<F>(c), a, b);
}
/// Two exact pairs of products joined with an overflow check, with the rounding constant.
template <int F, class A, class B, class C, class D, class E, class G, class H, class K>
constexpr std::int64_t two_pairs_sum(A a, B b, C c, D d, E e, G f, H g, K h) noexcept {
  return add_sat64(add_products<F>(rounding_constant<F>(), a, b, c, d), add_products<F>(0, e, f, g, h));
}

/// Angle (Q<F> rad) -> quadrant (nearest quarter turn, 0..3) and the remainder
/// z in Q1.31 as a fraction of an eighth turn, z in [-1, 1): angle = quadrant pi/2 + z pi/4.
/// The angle in turns is a uint32 fraction of a turn (round(x 2^32 / 2pi), the 64-bit
/// product rounded once); its wrap modulo 2^32 **is** the reduction modulo 2 pi, for any x.
/// 1/(2 pi) is precomputed (Q0.32 in kTurnsPerRadQ32): no division, no 2 pi subtraction.
template <int F, class X>
constexpr void reduce_angle(X x, std::uint32_t& quadrant, std::int32_t& z_q31) noexcept {
  static_assert(all_q_operands_v<F, X>, "a Q<F> or QTerm<F> angle (any int32 raw value)");
  const std::int64_t turns_qf32 = std::int64_t{x.raw()} * kTurnsPerRadQ32 + rounding_constant<F>();
  const auto turns = static_cast<std::uint32_t>(static_cast<std::uint64_t>(turns_qf32) >> static_cast<unsigned>(F));
  const std::uint32_t shifted = turns + (std::uint32_t{1} << 29U);
  quadrant = shifted >> 30U;
  // [-2^29, 2^29) quarter-turn units of 2^-30, times 4: Q1.31 eighth turns, |z| < 1.
  const auto rem = static_cast<std::int32_t>(shifted & ((std::uint32_t{1} << 30U) - 1U)) - (std::int32_t{1} << 29);
  z_q31 = rem * 4;
}

/// sin(z pi/4) and cos(z pi/4) for z in [-1, 1) (Q1.31), results Q2.30.
/// Near-minimax polynomials in w = z^2 (Remez, cos with its constant term fixed at 1 so
/// that cos 0 is exact): sin/z degree 3 (error 2.4e-9), (cos - 1)/w degree 3 (error
/// 1.9e-10). Horner steps are single high-word products (mul_hi, floor): each
/// coefficient k is stored in Q(30 + 2k) (cos) or Q(31 + 2k) (sin), so every step drops
/// exactly 2 fractional bits and no intermediate exceeds 0.8 (all fit int32).
/// Arithmetic error: a few Q2.30 LSB (measured in test_qmath: < 6e-9 total).
constexpr void sincos_eighth_q30(std::int32_t z_q31, std::int32_t& s_q30, std::int32_t& c_q30) noexcept {
  const std::int32_t w = mul_hi(z_q31, z_q31);  // z^2, Q2.30, in [0, 2^30]
  std::int32_t c = 973608;                      // Q38
  c = -22399897 + mul_hi(c, w);                 // Q36
  c = 272375456 + mul_hi(c, w);                 // Q34
  c = -1324675878 + mul_hi(c, w);               // Q32
  c_q30 = (std::int32_t{1} << 30) + mul_hi(c, w);
  std::int32_t s = -4941550;                    // Q37
  s = 85555993 + mul_hi(s, w);                  // Q35
  s = -693598004 + mul_hi(s, w);                // Q33
  s = 1686629708 + mul_hi(s, w);                // Q31 (~pi/4)
  s_q30 = mul_hi(z_q31, s);
}

/// sin and cos of a Q<F> angle in Q2.30: one reduction, both polynomials, quadrant swap.
template <int F, class X>
constexpr void sincos_q30(X x, std::int32_t& s_q30, std::int32_t& c_q30) noexcept {
  std::uint32_t quadrant = 0;
  std::int32_t z = 0;
  reduce_angle<F>(x, quadrant, z);
  std::int32_t s = 0;
  std::int32_t c = 0;
  sincos_eighth_q30(z, s, c);
  // sin(q pi/2 + r) = s, c, -s, -c and cos(q pi/2 + r) = c, -s, -c, s for q = 0..3.
  const bool odd = (quadrant & 1U) != 0U;
  s_q30 = odd ? c : s;
  c_q30 = odd ? s : c;
  if ((quadrant & 2U) != 0U) {
    s_q30 = -s_q30;
  }
  if (((quadrant + 1U) & 2U) != 0U) {
    c_q30 = -c_q30;
  }
}

/// Q2.30 -> Q<F>, rounded (ties toward +inf). For |v| <= 2^30 (sin, cos: the polynomials
/// stay within 1 + 2e-9) the result is at most 2^F: no saturation needed (F <= 30).
template <int F>
constexpr Q<F> from_unit_q30(std::int32_t v) noexcept {
  if constexpr (F == 30) {
    return Q<F>::from_raw(v);
  } else {
    return Q<F>::from_symmetric_raw((v + (std::int32_t{1} << (29 - F))) >> (30 - F));
  }
}

/// 2^(k/16), k = 0..15, Q1.31 unsigned (2^31 <= T < 2^32).
inline constexpr std::uint32_t kExp2Table[16] = {2147483648U, 2242560872U, 2341847524U, 2445529972U,
                                                 2553802834U, 2666869345U, 2784941738U, 2908241642U,
                                                 3037000500U, 3171459999U, 3311872529U, 3458501653U,
                                                 3611622603U, 3771522796U, 3938502376U, 4112874773U};

/// 2^f for f in [0, 1) given as Q0.32, result Q2.30 in [2^30, 2^31): table of 2^(k/16)
/// for the top 4 bits, and for the rest g < 1/16 a near-minimax (Remez) quadratic of
/// (2^g - 1)/g (error 2.9e-10 on 2^g); one unsigned high-word product joins them.
constexpr std::uint32_t exp2_frac_q30(std::uint32_t f_q32) noexcept {
  const std::uint32_t k = f_q32 >> 28U;
  const auto t = static_cast<std::int32_t>((f_q32 & 0x0FFFFFFFU) << 3U);  // g in Q35, < 2^31
  std::int32_t p = 236623;                    // Q22
  p = 8059945 + mul_hi(p, t);                 // Q25
  p = 186065300 + mul_hi(p, t);               // Q28 (~ln 2)
  // 2^g in Q1.31 (unsigned): 1 + g p, g p < 2^-4 * 0.7.
  const std::uint32_t two_g = 0x80000000U + static_cast<std::uint32_t>(mul_hi(p, t));
  const std::uint64_t product = std::uint64_t{kExp2Table[k]} * two_g;
  return static_cast<std::uint32_t>(product >> 32U);
}

/// floor(n / d) for d != 0 and n < d 2^32 (the quotient fits 32 bits): normalised long
/// division in two 16-bit digits, each a 32/32 UDIV plus at most two corrections
/// (Hacker's Delight, divlu). Replaces the 64/64 library division (__aeabi_uldivmod).
constexpr std::uint32_t udiv64_32(std::uint64_t n, std::uint32_t d) noexcept {
  const auto s = static_cast<unsigned>(__builtin_clz(d));  // d != 0
  d <<= s;
  n <<= s;  // n < d 2^32 before the shift, so nothing is lost
  const auto u1 = static_cast<std::uint32_t>(n >> 32U);
  const auto u0 = static_cast<std::uint32_t>(n);
  const std::uint32_t dh = d >> 16U;
  const std::uint32_t dl = d & 0xFFFFU;
  const std::uint32_t un1 = u0 >> 16U;
  const std::uint32_t un0 = u0 & 0xFFFFU;
  std::uint32_t q1 = u1 / dh;
  std::uint32_t rhat = u1 - q1 * dh;
  while (q1 > 0xFFFFU || q1 * dl > ((rhat << 16U) | un1)) {
    --q1;
    rhat += dh;
    if (rhat > 0xFFFFU) {
      break;
    }
  }
  const std::uint32_t un21 = (u1 << 16U) + un1 - q1 * d;  // modulo 2^32 by design
  std::uint32_t q0 = un21 / dh;
  rhat = un21 - q0 * dh;
  while (q0 > 0xFFFFU || q0 * dl > ((rhat << 16U) | un0)) {
    --q0;
    rhat += dh;
    if (rhat > 0xFFFFU) {
      break;
    }
  }
  return (q1 << 16U) | q0;
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
/// exp's raw result (jg::exp below documents it), in the symmetric range.
template <int F>
constexpr std::int32_t exp_raw(Q<F> x) noexcept {
  const std::int64_t y = std::int64_t{x.raw()} * kLog2eQ30;  // Q(F+30)
  const auto n = static_cast<std::int32_t>(y >> (F + 30));
  if (n <= -(F + 2)) {
    return 0;
  }
  if (n >= 31 - F) {
    return kRawMax;
  }
  const auto f_q32 = static_cast<std::uint32_t>(static_cast<std::uint64_t>(y) >> static_cast<unsigned>(F - 2));
  const std::uint32_t p = exp2_frac_q30(f_q32);  // [2^30, 2^31)
  // Round p 2^(n - 30 + F) to an integer: shift right by s = 30 - F - n in [0, 31];
  // p + 2^(s-1) < 2^31 + 2^30 fits uint32.
  const auto s = static_cast<unsigned>(30 - F - n);
  const std::uint32_t r = (p + ((std::uint32_t{1} << s) >> 1U)) >> s;
  return r > static_cast<std::uint32_t>(kRawMax) ? kRawMax : static_cast<std::int32_t>(r);
}
/// div's raw result (jg::div below documents it), in the symmetric range.
template <int F>
constexpr std::int32_t div_raw(Q<F> a, Q<F> b) noexcept {
  if (b.raw() == 0) {
    return a.raw() > 0 ? kRawMax : (a.raw() < 0 ? kRawMin : 0);
  }
  const bool negative = (a.raw() < 0) != (b.raw() < 0);
  // |raw| <= 2^31 - 1 (symmetric range): the negations cannot overflow.
  const auto den = static_cast<std::uint32_t>(b.raw() < 0 ? -b.raw() : b.raw());
  const std::uint64_t num = (std::uint64_t{static_cast<std::uint32_t>(a.raw() < 0 ? -a.raw() : a.raw())}
                             << static_cast<unsigned>(F)) + (den >> 1U);
  if ((num >> 32U) >= den) {  // quotient >= 2^32: far out of range
    return negative ? kRawMin : kRawMax;
  }
  const std::uint32_t quotient = udiv64_32(num, den);
  if (quotient > static_cast<std::uint32_t>(kRawMax)) {
    return negative ? kRawMin : kRawMax;
  }
  const auto q = static_cast<std::int32_t>(quotient);
  return negative ? -q : q;  // 0 <= q <= kRawMax
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
/// e^x, Q<F> -> Q<F> (F >= 2). y = x log2(e) (Q(F+30), one 32x32 product) splits into
/// n = floor(y) and f in [0, 1) (Q0.32); 2^f from the 16-entry table and a quadratic
/// (detail::exp2_frac_q30, Q2.30); the result is 2^f shifted by n, rounded once.
/// Early exits, exact: n <= -(F+2) means e^x < 2^-(F+1), half an LSB, so the result is 0;
/// n >= 31-F means e^x >= 2^(31-F), beyond the range, so it saturates.
/// Error: 0.5 LSB plus 4e-9 relative (measured in tests).
template <int F>
[[nodiscard]] constexpr Q<F> exp(Q<F> x) noexcept {
  static_assert(F >= 2, "exp: the fraction of x log2(e) is taken from bit F-2 of the product");
  // The result is chosen by the early exits: opaque_raw keeps GCC from widening it into a
  // 64-bit phi where it feeds a product (stribeck_level, threshold_at).
  return Q<F>::from_symmetric_raw(detail::opaque_raw(detail::exp_raw(x)));
}
/// sin and cos of one angle, Q<F> (or QTerm<F>) rad -> Q<F>: one exact reduction modulo 2 pi (any x)
/// and two short polynomials (detail::sincos_q30). Error 0.5 LSB plus < 1e-8.
template <int F, class X, std::enable_if_t<detail::all_q_operands_v<F, X>, int> = 0>
constexpr void sincos(X x, Q<F>& s, Q<F>& c) noexcept {
  std::int32_t s30 = 0;
  std::int32_t c30 = 0;
  detail::sincos_q30<F>(x, s30, c30);
  s = detail::from_unit_q30<F>(s30);
  c = detail::from_unit_q30<F>(c30);
}
/// sin(x), Q<F> rad -> Q<F>; as sincos.
template <int F>
[[nodiscard]] constexpr Q<F> sin(Q<F> x) noexcept {
  Q<F> s{};
  Q<F> c{};
  sincos(x, s, c);
  return s;
}
/// cos(x), Q<F> rad -> Q<F>; as sincos.
template <int F>
[[nodiscard]] constexpr Q<F> cos(Q<F> x) noexcept {
  Q<F> s{};
  Q<F> c{};
  sincos(x, s, c);
  return c;
}
/// a / b, Q<F> -> Q<F>: (|a| << F + |b|/2) / |b| in 64/32 bits (detail::udiv64_32), i.e.
/// rounded to nearest (ties away from zero), saturated. b == 0 gives +/-max by the sign
/// of a, and 0 for 0/0.
template <int F>
[[nodiscard]] constexpr Q<F> div(Q<F> a, Q<F> b) noexcept {
  // Chosen by branches (b == 0, saturation, sign): opaque_raw, as in exp.
  return Q<F>::from_symmetric_raw(detail::opaque_raw(detail::div_raw(a, b)));
}

template <int F>
struct precise_coefficient<Q<F>> {
  using type = Q<30>;
};
/// Q2.30 coefficient * Q<F> -> Q<F>: 64-bit product, one rounding, saturation.
template <int F>
[[nodiscard]] constexpr Q<F> scale(Q<30> coefficient, Q<F> x) noexcept {
  return detail::round_presum<F, 30>(std::int64_t{coefficient.raw()} * x.raw() + detail::rounding_constant<30>());
}
/// c1 * x1 + c2 * x2 with Q2.30 coefficients, Q<F> (or QTerm<F>) -> Q<F>: both products
/// exact (Q(F+30), each below 2^62 in magnitude, so the pair cannot overflow int64), one
/// rounding, one saturation (a filter section: decay * state + gain * input).
template <class X1, class X2, std::enable_if_t<detail::all_q_operands_v<X1::frac_bits, X1, X2>, int> = 0>
[[nodiscard]] constexpr Q<X1::frac_bits> scale_sum(Q<30> c1, X1 x1, Q<30> c2, X2 x2) noexcept {
  return detail::round_presum<X1::frac_bits, 30>(std::int64_t{c1.raw()} * x1.raw() + std::int64_t{c2.raw()} * x2.raw() +
                                     detail::rounding_constant<30>());
}

// The sums below take Q<F> or QTerm<F> operands (no product of two QTerms: each product
// then stays below 2^62 in magnitude, as for Q<F> operands, see QTerm) and come in two
// forms: the plain name gives a Q<F> (INT32_MIN mapped), the *_term name a QTerm<F> for an
// intermediate (same rounding and saturation, no mapping).

/// c + a*b: exact (one product below 2^62 plus c 2^F below 2^(31+F) cannot overflow
/// int64), one rounding, one saturation. No precondition.
template <class C, class A, class B, std::enable_if_t<detail::all_q_operands_v<C::frac_bits, C, A, B>, int> = 0>
[[nodiscard]] constexpr Q<C::frac_bits> mac(C c, A a, B b) noexcept {
  return detail::round_presum<C::frac_bits>(detail::mac_sum<C::frac_bits>(c, a, b));
}
template <class C, class A, class B, std::enable_if_t<detail::all_q_operands_v<C::frac_bits, C, A, B>, int> = 0>
[[nodiscard]] constexpr QTerm<C::frac_bits> mac_term(C c, A a, B b) noexcept {
  return detail::round_presum_term<C::frac_bits>(detail::mac_sum<C::frac_bits>(c, a, b));
}
/// a*b: exact product, one rounding, one saturation, as a QTerm<F> (Q<F>'s operator* gives
/// the Q<F>).
template <class A, class B, std::enable_if_t<detail::all_q_operands_v<A::frac_bits, A, B>, int> = 0>
[[nodiscard]] constexpr QTerm<A::frac_bits> mul_term(A a, B b) noexcept {
  return detail::round_presum_term<A::frac_bits>(detail::products_sum<A::frac_bits>(a, b));
}
/// x*x as a Q<F>: the sum is never negative, so the rounded result is never INT32_MIN and
/// needs no mapping (it saturates at the maximum).
template <class X, std::enable_if_t<is_q_operand_v<X>, int> = 0>
[[nodiscard]] constexpr Q<X::frac_bits> square(X x) noexcept {
  constexpr int F = X::frac_bits;
  return Q<F>::from_symmetric_raw(detail::opaque_raw(
      detail::round_presum_raw<F>(std::int64_t{x.raw()} * x.raw() + detail::rounding_constant<F>())));
}
/// a*b + c*d: both products exact in 64 bits (each below 2^62 in magnitude, so the sum
/// cannot overflow), one rounding, one saturation.
template <class A, class B, class C, class D,
          std::enable_if_t<detail::all_q_operands_v<A::frac_bits, A, B, C, D>, int> = 0>
[[nodiscard]] constexpr Q<A::frac_bits> sum_of_products(A a, B b, C c, D d) noexcept {
  return detail::round_presum<A::frac_bits>(detail::products_sum<A::frac_bits>(a, b, c, d));
}
template <class A, class B, class C, class D,
          std::enable_if_t<detail::all_q_operands_v<A::frac_bits, A, B, C, D>, int> = 0>
[[nodiscard]] constexpr QTerm<A::frac_bits> sum_of_products_term(A a, B b, C c, D d) noexcept {
  return detail::round_presum_term<A::frac_bits>(detail::products_sum<A::frac_bits>(a, b, c, d));
}
/// a*b + c*d + e*f, Q<F>: one rounding, one saturation (dot products, matrix rows). The
/// third product is added with an overflow check (three full-range products can exceed
/// int64).
template <int F>
[[nodiscard]] constexpr Q<F> sum_of_products(Q<F> a, Q<F> b, Q<F> c, Q<F> d, Q<F> e, Q<F> f) noexcept {
  return detail::round_presum<F>(
      detail::add_sat64(detail::add_products<F>(detail::rounding_constant<F>(), a, b, c, d), std::int64_t{e.raw()} * f.raw()));
}
/// a*b + c*d + e*f + g*h: two exact pairs joined with an overflow check, one rounding.
template <class A, class B, class C, class D, class E, class G, class H, class K,
          std::enable_if_t<detail::all_q_operands_v<A::frac_bits, A, B, C, D, E, G, H, K>, int> = 0>
[[nodiscard]] constexpr Q<A::frac_bits> sum_of_products(A a, B b, C c, D d, E e, G f, H g, K h) noexcept {
  return detail::round_presum<A::frac_bits>(detail::two_pairs_sum<A::frac_bits>(a, b, c, d, e, f, g, h));
}
template <class A, class B, class C, class D, class E, class G, class H, class K,
          std::enable_if_t<detail::all_q_operands_v<A::frac_bits, A, B, C, D, E, G, H, K>, int> = 0>
[[nodiscard]] constexpr QTerm<A::frac_bits> sum_of_products_term(A a, B b, C c, D d, E e, G f, H g, K h) noexcept {
  return detail::round_presum_term<A::frac_bits>(detail::two_pairs_sum<A::frac_bits>(a, b, c, d, e, f, g, h));
}

/// c + a0*b0 + a1*b1 + ... for operands whose magnitudes the caller has bounded, Q<F>:
/// one exact 64-bit sum (SMLAL chain), one rounding, one saturation, **no overflow check
/// on the 64-bit sum**. Precondition (each call site states why it holds):
/// sum |a_i.raw * b_i.raw| + |c.raw| 2^F < 2^63 - 2^F, e.g. any number of products of a
/// full-range signal (<= 2^31) with an operand below 2^16 (|sin|, |cos| <= 1) or with a
/// link constant below 2^28 (4096 in Q16.16, checked by convert_link), up to 7 of them.
template <class C, class A, class B, class... Rest,
          std::enable_if_t<detail::all_q_operands_v<C::frac_bits, C, A, B, Rest...>, int> = 0>
[[nodiscard]] constexpr Q<C::frac_bits> mac_bounded(C c, A a, B b, Rest... rest) noexcept {
  constexpr int F = C::frac_bits;
  return detail::round_presum<F>(detail::add_products<F>(detail::addend<F>(c), a, b, rest...));
}
template <class C, class A, class B, class... Rest,
          std::enable_if_t<detail::all_q_operands_v<C::frac_bits, C, A, B, Rest...>, int> = 0>
[[nodiscard]] constexpr QTerm<C::frac_bits> mac_bounded_term(C c, A a, B b, Rest... rest) noexcept {
  constexpr int F = C::frac_bits;
  return detail::round_presum_term<F>(detail::add_products<F>(detail::addend<F>(c), a, b, rest...));
}
/// a0*b0 + a1*b1 + ..., as mac_bounded without the addend.
template <class A, class B, class... Rest,
          std::enable_if_t<detail::all_q_operands_v<A::frac_bits, A, B, Rest...>, int> = 0>
[[nodiscard]] constexpr Q<A::frac_bits> dot_bounded(A a, B b, Rest... rest) noexcept {
  constexpr int F = A::frac_bits;
  return detail::round_presum<F>(detail::add_products<F>(detail::rounding_constant<F>(), a, b, rest...));
}
template <class A, class B, class... Rest,
          std::enable_if_t<detail::all_q_operands_v<A::frac_bits, A, B, Rest...>, int> = 0>
[[nodiscard]] constexpr QTerm<A::frac_bits> dot_bounded_term(A a, B b, Rest... rest) noexcept {
  constexpr int F = A::frac_bits;
  return detail::round_presum_term<F>(detail::add_products<F>(detail::rounding_constant<F>(), a, b, rest...));
}

namespace detail {
/// (a*b - c*d) in Q(F+8) (a QTerm: it is only multiplied by the scale), then times scale,
/// with the rounding constant of the last step added: see diff_of_products_scaled.
template <int F, class A, class B>
constexpr std::int64_t diff_scaled_sum(A a, B b, Q<F> c, Q<F> d, Q<F> scale) noexcept {
  constexpr int kExtra = 8;
  static_assert(F > kExtra, "the difference is kept in Q(F+8) within 32 bits");
  // Two products of magnitude < 2^62: the difference cannot overflow int64. -c is exact
  // (c is a Q<F>): the difference is one SMLAL chain.
  const std::int64_t diff_2f = add_products<F>(rounding_constant<F - kExtra>(), a, b, -c, d);
  constexpr int kDiffFrac = F + kExtra;
  constexpr int kDiffShift = F - kExtra;
  const std::int32_t diff = round_presum_term<kDiffFrac, kDiffShift>(diff_2f).raw();  // Q(F+8), saturated
  const std::int64_t scaled = std::int64_t{diff} * scale.raw();
  return scaled + rounding_constant<kDiffFrac>();
}
}  // namespace detail

/// (a*b - c*d) * scale, Q<F> -> Q<F>, with one rounding instead of three: the
/// difference of products is exact in Q(2F) (64-bit), rounded once to Q(F+8) and then
/// multiplied by scale in 64 bits. Use where a small difference is amplified by a large
/// scale (LuGre's implicit step: scale up to sigma0 dT / s ~ 200). Requires
/// |a*b - c*d| < 2^(23-F+16) (128 for Q16.16) and |scale| < 2^(31-F) (the format's
/// range); the difference saturates beyond that, the result always saturates. a and b may
/// be QTerms (not both), c and d are Q<F> (c is negated).
template <int F, class A, class B, std::enable_if_t<detail::all_q_operands_v<F, A, B>, int> = 0>
[[nodiscard]] constexpr Q<F> diff_of_products_scaled(A a, B b, Q<F> c, Q<F> d, Q<F> scale) noexcept {
  return detail::round_presum<F, F + 8>(detail::diff_scaled_sum<F>(a, b, c, d, scale));
}
template <int F, class A, class B, std::enable_if_t<detail::all_q_operands_v<F, A, B>, int> = 0>
[[nodiscard]] constexpr QTerm<F> diff_of_products_scaled_term(A a, B b, Q<F> c, Q<F> d, Q<F> scale) noexcept {
  return detail::round_presum_term<F, F + 8>(detail::diff_scaled_sum<F>(a, b, c, d, scale));
}

// ---------------------------------------------------------------- fused, float / double

/// sin and cos of one angle (float/double: the library's own).
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
inline void sincos(T x, T& s, T& c) noexcept {
  s = std::sin(x);
  c = std::cos(x);
}
/// c + a * b for float/double.
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T mac(T c, T a, T b) noexcept {
  return c + a * b;
}
/// c1 * x1 + c2 * x2 for float/double.
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T scale_sum(T c1, T x1, T c2, T x2) noexcept {
  return c1 * x1 + c2 * x2;
}
/// a*b + c*d + e*f + g*h for float/double.
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T sum_of_products(T a, T b, T c, T d, T e, T f, T g, T h) noexcept {
  return a * b + c * d + e * f + g * h;
}
namespace detail {
template <class T>
constexpr T add_products_fp(T acc) noexcept {
  return acc;
}
template <class T, class... Rest>
constexpr T add_products_fp(T acc, T a, T b, Rest... rest) noexcept {
  return add_products_fp(acc + a * b, rest...);
}
}  // namespace detail
/// c + a0*b0 + a1*b1 + ..., left to right, for float/double (no bound needed).
template <class T, class... Rest, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T mac_bounded(T c, T a, T b, Rest... rest) noexcept {
  return detail::add_products_fp(c + a * b, rest...);
}
/// a0*b0 + a1*b1 + ..., left to right, for float/double.
template <class T, class... Rest, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T dot_bounded(T a, T b, Rest... rest) noexcept {
  return detail::add_products_fp(a * b, rest...);
}

// ---------------------------------------------------------------- intermediate terms

/// The type of an intermediate value (QTerm, q.hpp): QTerm<F> for Q<F>, the scalar itself
/// for float and double, whose *_term functions below are the plain ones.
template <class S>
struct term_of {
  using type = S;
};
template <int F>
struct term_of<Q<F>> {
  using type = QTerm<F>;
};
template <class S>
using term_t = typename term_of<S>::type;

template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T from_term(T x) noexcept {
  return x;
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T add_term(T a, T b) noexcept {
  return a + b;
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T sub_term(T a, T b) noexcept {
  return a - b;
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T mul_term(T a, T b) noexcept {
  return a * b;
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T square(T x) noexcept {
  return x * x;
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T mac_term(T c, T a, T b) noexcept {
  return c + a * b;
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T sum_of_products_term(T a, T b, T c, T d) noexcept {
  return a * b + c * d;
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T sum_of_products_term(T a, T b, T c, T d, T e, T f, T g, T h) noexcept {
  return a * b + c * d + e * f + g * h;
}
template <class T, class... Rest, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T mac_bounded_term(T c, T a, T b, Rest... rest) noexcept {
  return detail::add_products_fp(c + a * b, rest...);
}
template <class T, class... Rest, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T dot_bounded_term(T a, T b, Rest... rest) noexcept {
  return detail::add_products_fp(a * b, rest...);
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T diff_of_products_scaled_term(T a, T b, T c, T d, T scale) noexcept {
  return (a * b - c * d) * scale;
}

// ---------------------------------------------------------------- midpoint

/// (a + b) / 2, the mean of two values of one format. Q<F>: the sum exact in 64 bits, one
/// rounding to nearest (ties toward +infinity: + 1, arithmetic shift right by 1), so the
/// error is at most 0.5 LSB. It cannot overflow and needs no saturation: the mean of two
/// values of the symmetric range lies between them, so it is in that range (never
/// INT32_MIN). Float and double: a / 2 + b / 2 (halving is exact above the subnormals, and
/// unlike (a + b) / 2 the sum cannot overflow to infinity for finite a and b).
template <int F>
[[nodiscard]] constexpr Q<F> midpoint(Q<F> a, Q<F> b) noexcept {
  return Q<F>::from_symmetric_raw(static_cast<std::int32_t>((std::int64_t{a.raw()} + b.raw() + 1) >> 1));
}
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
[[nodiscard]] constexpr T midpoint(T a, T b) noexcept {
  return a * T(0.5) + b * T(0.5);
}

}  // namespace jg
