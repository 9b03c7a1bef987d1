// Signed 32-bit Q-format fixed point with compile-time fractional bits.
//
// Q<F> stores round(x * 2^F) in an int32_t. Range: [-(2^31-1), 2^31-1] * 2^-F.
// The range is symmetric on purpose: INT32_MIN is never produced, so negation and abs
// can never overflow.
//
// Scaling and overflow behaviour (every routine in this file and in qmath.hpp):
// - Intermediates are 64-bit (int64_t); results are rounded to nearest (ties toward
//   +infinity, i.e. add half an LSB then arithmetic shift right) and then **saturated**
//   to the symmetric range. Nothing ever wraps: a wrapped torque would be a spike.
// - Operators (+, -, *, unary -) saturate silently: they are the hot path and have no
//   place to report. Conversions from float/double take a caller-owned NumericStatus
//   and record NaN, infinities and out-of-range values there (sticky until cleared).
// - Mixed formats are never implicit: use q_cast<Q<G>>(x) or mul<G>(a, b).
// - Right shifts of negative values are arithmetic (GCC and Clang define this; C++20
//   requires it).
// - QTerm<F> (below) is the one exception to the symmetric range: an intermediate value
//   that may be INT32_MIN, with no operators, only multiplied, added or turned into a Q<F>.
#pragma once

#include <cstdint>
#include <limits>
#include <type_traits>
#if defined(__ARM_FEATURE_DSP) && (__ARM_FEATURE_DSP == 1)
#include <arm_acle.h>
#endif

namespace jg {

/// Sticky, caller-owned record of numeric events at conversion boundaries
/// (sensor inputs, received frames, host-to-firmware parameter conversion).
struct NumericStatus {
  std::uint32_t saturated = 0;  ///< values clipped to the representable range
  std::uint32_t not_finite = 0; ///< NaN or infinity seen (mapped to 0 or to +/-max)
  [[nodiscard]] constexpr bool ok() const noexcept { return saturated == 0U && not_finite == 0U; }
  constexpr void clear() noexcept {
    saturated = 0U;
    not_finite = 0U;
  }
};

namespace detail {
/// constexpr NaN test without ==/!= on floating point (-Wfloat-equal).
template <class T>
constexpr bool is_nan(T x) noexcept {
  return !(x <= x);  // NOLINT(misc-redundant-expression): false only for NaN, by design
}
/// constexpr finiteness test (std::isfinite is not constexpr in C++17).
template <class T>
constexpr bool is_finite(T x) noexcept {
  return x <= std::numeric_limits<T>::max() && x >= std::numeric_limits<T>::lowest();
}

/// All arguments finite: x - x is 0 for finite x and NaN for +/-inf and NaN, and a NaN
/// survives the sum, so one subtraction and one addition per value and one NaN test
/// (instead of two compares and branches per value). IEEE arithmetic (no -ffast-math).
template <class T, class... Rest>
constexpr bool all_finite(T x, Rest... rest) noexcept {
  const T residue = ((x - x) + ... + (rest - rest));  // NOLINT(misc-redundant-expression): 0 or NaN, by design
  return !is_nan(residue);
}

inline constexpr std::int32_t kRawMax = std::numeric_limits<std::int32_t>::max();
inline constexpr std::int32_t kRawMin = -kRawMax;  // symmetric range

/// Saturate a 64-bit value to the symmetric int32 range.
constexpr std::int32_t saturate32(std::int64_t v) noexcept {
  if (v > kRawMax) {
    return kRawMax;
  }
  if (v < kRawMin) {
    return kRawMin;
  }
  return static_cast<std::int32_t>(v);
}

/// Maps INT32_MIN (the one int32 outside the symmetric range) to kRawMin; identity
/// otherwise. On Cortex-M4 (DSP extension) this is two saturating subtractions,
/// 0 - (0 - v) (QSUB: -INT32_MIN saturates to INT32_MAX, whose negation is kRawMin),
/// instead of a compare against a literal and a conditional move. The builtin's result is
/// also opaque to GCC, which otherwise widens a saturated result feeding a 32x32->64
/// product into a 64-bit phi and the product into a 64x64 multiplication.
/// Same results on every target: the host evaluates the plain comparison.
inline std::int32_t symmetric_raw_target(std::int32_t v) noexcept {
#if defined(__ARM_FEATURE_DSP) && (__ARM_FEATURE_DSP == 1)
  return __qsub(0, __qsub(0, v));
#else
  return v == std::numeric_limits<std::int32_t>::min() ? kRawMin : v;
#endif
}
/// Identity, opaque to the optimiser: an empty inline-assembler statement that claims to
/// change v. Costs no instruction. Placed on a result chosen by a branch (an early exit, a
/// saturation), it stops GCC from widening the select into a 64-bit phi when the value
/// feeds a 32x32->64 product (which turns one SMLAL into UMULL, MLA and an add chain).
inline std::int32_t opaque_raw_target(std::int32_t v) noexcept {
#if defined(__GNUC__) && defined(__arm__)
  __asm("" : "+r"(v));
#endif
  return v;
}
constexpr std::int32_t opaque_raw(std::int32_t v) noexcept {
  if (__builtin_is_constant_evaluated()) {
    return v;
  }
  return opaque_raw_target(v);
}
constexpr std::int32_t symmetric_raw(std::int32_t v) noexcept {
  if (__builtin_is_constant_evaluated()) {
    return v == std::numeric_limits<std::int32_t>::min() ? kRawMin : v;
  }
  return symmetric_raw_target(v);
}
/// Saturating int32 sum in the symmetric range (QADD on Cortex-M4, then symmetric_raw).
inline std::int32_t add_sat_target(std::int32_t a, std::int32_t b) noexcept {
#if defined(__ARM_FEATURE_DSP) && (__ARM_FEATURE_DSP == 1)
  return symmetric_raw_target(__qadd(a, b));
#else
  std::int32_t r = 0;
  if (__builtin_add_overflow(a, b, &r)) {
    return a > 0 ? kRawMax : kRawMin;
  }
  return symmetric_raw_target(r);
#endif
}
inline std::int32_t sub_sat_target(std::int32_t a, std::int32_t b) noexcept {
#if defined(__ARM_FEATURE_DSP) && (__ARM_FEATURE_DSP == 1)
  return symmetric_raw_target(__qsub(a, b));
#else
  std::int32_t r = 0;
  if (__builtin_sub_overflow(a, b, &r)) {
    return a > 0 ? kRawMax : kRawMin;
  }
  return symmetric_raw_target(r);
#endif
}

/// Arithmetic shift with round-to-nearest (ties toward +inf). shift may be negative
/// (left shift); left shifts saturate. Result is still 64-bit; callers saturate.
constexpr std::int64_t shift_round(std::int64_t v, int shift) noexcept {
  if (shift > 0) {
    if (shift >= 63) {
      return 0;
    }
    return (v + (std::int64_t{1} << (shift - 1))) >> shift;
  }
  if (shift < 0) {
    const int left = -shift;
    constexpr std::int64_t big = std::int64_t{1} << 62;
    if (left >= 62) {
      return v > 0 ? big : (v < 0 ? -big : 0);
    }
    const std::int64_t limit = big >> left;
    if (v >= limit) {
      return big;
    }
    if (v <= -limit) {
      return -big;
    }
    return v * (std::int64_t{1} << left);
  }
  return v;
}
}  // namespace detail

template <int FracBits>
class Q;
template <int FracBits>
class QTerm;

namespace detail {
/// The rounding and range test of round_presum and round_presum_term: acc >> Shift,
/// saturated by the sign when it does not fit int32 (INT32_MIN included: it fits).
template <int Shift>
constexpr std::int32_t round_presum_raw(std::int64_t acc) noexcept {
  static_assert(Shift >= 1 && Shift <= 32, "the range test looks at the high word only");
  const auto hi = static_cast<std::int32_t>(acc >> 32);
  auto v = static_cast<std::int32_t>(acc >> Shift);
  // v is exact iff the high word is v's sign extension (one CMP with a shifted operand);
  // out of range is the rare case: keep the common path straight-line.
  if (__builtin_expect(static_cast<long>(hi != (v >> (32 - Shift))), 0L) != 0L) {
    v = hi < 0 ? kRawMin : kRawMax;
  }
  return v;
}
/// Rounds and saturates an exact 64-bit sum of products to Q<F>: `acc` holds the result's
/// raw value times 2^Shift **with the rounding constant 2^(Shift-1) already added**, so the
/// rounding is one arithmetic shift. The result fits when bits 63..31+Shift all copy the
/// sign, i.e. when the high word equals (acc >> Shift) >> (32 - Shift) taken as int32;
/// otherwise it saturates by the sign. Shift in [1, 32] keeps the test on the high word.
template <int F, int Shift = F>
constexpr Q<F> round_presum(std::int64_t acc) noexcept {
  // INT32_MIN passes the range test but is outside the symmetric range.
  return Q<F>::from_symmetric_raw(symmetric_raw(round_presum_raw<Shift>(acc)));
}
/// As round_presum, to an intermediate term (QTerm): the same rounding and saturation,
/// without the mapping of INT32_MIN (two QSUBs on Cortex-M4); opaque_raw keeps the result
/// a 32-bit value for the products it feeds.
template <int F, int Shift = F>
constexpr QTerm<F> round_presum_term(std::int64_t acc) noexcept {
  return QTerm<F>::from_raw(opaque_raw(round_presum_raw<Shift>(acc)));
}
template <int Shift>
constexpr std::int64_t rounding_constant() noexcept {
  return std::int64_t{1} << (Shift - 1);
}

}  // namespace detail

template <int FracBits>
class Q {
  static_assert(FracBits >= 1 && FracBits <= 30,
                "Q<F>: 1..30 fractional bits (1.0 must be representable)");

 public:
  using raw_type = std::int32_t;
  static constexpr int frac_bits = FracBits;
  static constexpr std::int64_t one_raw = std::int64_t{1} << FracBits;

  constexpr Q() noexcept = default;

  /// Wraps a raw value; INT32_MIN is mapped to the symmetric minimum.
  [[nodiscard]] static constexpr Q from_raw(std::int32_t r) noexcept {
    Q q;
    // Written as an equality test (CMP with an immediate, no literal load on Cortex-M).
    q.raw_ = r == std::numeric_limits<std::int32_t>::min() ? detail::kRawMin : r;
    return q;
  }
  [[nodiscard]] constexpr std::int32_t raw() const noexcept { return raw_; }

  /// Compile-time constants and host-side conversion. NaN -> 0, +/-inf and out of range
  /// saturate; each such event is counted in `status`.
  [[nodiscard]] static constexpr Q from_double(double x, NumericStatus& status) noexcept {
    if (detail::is_nan(x)) {
      ++status.not_finite;
      return Q{};
    }
    const double scaled = x * static_cast<double>(one_raw);
    if (scaled >= static_cast<double>(detail::kRawMax)) {
      if (scaled > std::numeric_limits<double>::max()) {
        ++status.not_finite;
      } else if (scaled >= static_cast<double>(detail::kRawMax) + 0.5) {
        ++status.saturated;
      }
      return from_raw(detail::kRawMax);
    }
    if (scaled <= static_cast<double>(detail::kRawMin)) {
      if (scaled < -std::numeric_limits<double>::max()) {
        ++status.not_finite;
      } else if (scaled <= static_cast<double>(detail::kRawMin) - 0.5) {
        ++status.saturated;
      }
      return from_raw(detail::kRawMin);
    }
    // Round to nearest, ties toward +inf, without std::floor (constexpr).
    const double shifted = scaled + 0.5;
    auto truncated = static_cast<std::int64_t>(shifted);
    if (static_cast<double>(truncated) > shifted) {
      --truncated;  // truncation went toward zero for a negative value
    }
    return from_raw(detail::saturate32(truncated));
  }
  /// Wraps a raw value known to be in the symmetric range (never INT32_MIN): the
  /// producers in qmath.hpp map INT32_MIN themselves (detail::symmetric_raw).
  [[nodiscard]] static constexpr Q from_symmetric_raw(std::int32_t r) noexcept {
    Q q;
    q.raw_ = r;
    return q;
  }
  /// For constants known to be in range (checked at compile time when constexpr).
  [[nodiscard]] static constexpr Q from_double(double x) noexcept {
    NumericStatus ignored{};
    return from_double(x, ignored);
  }
  /// Runtime conversion on the MCU (single-precision FPU, no double arithmetic).
  [[nodiscard]] static Q from_float(float x, NumericStatus& status) noexcept {
    if (detail::is_nan(x)) {
      ++status.not_finite;
      return Q{};
    }
    constexpr float kMaxF = 2147483520.0F;  // largest float below 2^31
    const float scaled = x * static_cast<float>(one_raw);
    if (scaled >= kMaxF) {
      if (scaled > std::numeric_limits<float>::max()) {
        ++status.not_finite;
      } else if (scaled > kMaxF) {
        ++status.saturated;
      }
      return from_raw(detail::kRawMax);
    }
    if (scaled <= -kMaxF) {
      if (scaled < -std::numeric_limits<float>::max()) {
        ++status.not_finite;
      } else if (scaled < -kMaxF) {
        ++status.saturated;
      }
      return from_raw(detail::kRawMin);
    }
    // Round to nearest, ties toward +inf. Adding 0.5F would itself round above 2^23;
    // the fraction left by truncation is exact in float, so decide on it instead.
    auto truncated = static_cast<std::int32_t>(scaled);
    const float fraction = scaled - static_cast<float>(truncated);
    if (fraction >= 0.5F) {
      ++truncated;
    } else if (fraction < -0.5F) {
      --truncated;
    }
    return from_raw(truncated);
  }

  [[nodiscard]] constexpr double to_double() const noexcept {
    return static_cast<double>(raw_) / static_cast<double>(one_raw);
  }
  [[nodiscard]] constexpr float to_float() const noexcept {
    return static_cast<float>(raw_) * (1.0F / static_cast<float>(one_raw));
  }

  // Same-format arithmetic: 64-bit intermediate, rounding, saturation.
  // On Cortex-M4 QADD/QSUB saturate in one instruction (symmetric_raw then maps
  // INT32_MIN); elsewhere the overflow builtins. Same results on every target.
  friend constexpr Q operator+(Q a, Q b) noexcept {
    if (!__builtin_is_constant_evaluated()) {
      return from_symmetric_raw(detail::add_sat_target(a.raw_, b.raw_));
    }
    std::int32_t r = 0;
    if (__builtin_add_overflow(a.raw_, b.raw_, &r)) {
      return from_raw(a.raw_ > 0 ? detail::kRawMax : detail::kRawMin);
    }
    return from_raw(r);
  }
  friend constexpr Q operator-(Q a, Q b) noexcept {
    if (!__builtin_is_constant_evaluated()) {
      return from_symmetric_raw(detail::sub_sat_target(a.raw_, b.raw_));
    }
    std::int32_t r = 0;
    if (__builtin_sub_overflow(a.raw_, b.raw_, &r)) {
      return from_raw(a.raw_ > 0 ? detail::kRawMax : detail::kRawMin);
    }
    return from_raw(r);
  }
  /// Exact: the stored value is never INT32_MIN, so its negation is in range (one RSB).
  friend constexpr Q operator-(Q a) noexcept {
    Q q;
    q.raw_ = -a.raw_;
    return q;
  }
  /// Q<F> * Q<F> -> Q<F>: 32x32->64 product (SMULL on Cortex-M4), round, saturate.
  /// 32x32->64 multiply-accumulate with the rounding constant (SMLAL), then the range
  /// test on the high word (detail::round_presum).
  friend constexpr Q operator*(Q a, Q b) noexcept {
    return detail::round_presum<FracBits>(std::int64_t{a.raw_} * b.raw_ + detail::rounding_constant<FracBits>());
  }
  constexpr Q& operator+=(Q b) noexcept { return *this = *this + b; }
  constexpr Q& operator-=(Q b) noexcept { return *this = *this - b; }
  constexpr Q& operator*=(Q b) noexcept { return *this = *this * b; }

  friend constexpr bool operator==(Q a, Q b) noexcept { return a.raw_ == b.raw_; }
  friend constexpr bool operator!=(Q a, Q b) noexcept { return a.raw_ != b.raw_; }
  friend constexpr bool operator<(Q a, Q b) noexcept { return a.raw_ < b.raw_; }
  friend constexpr bool operator>(Q a, Q b) noexcept { return a.raw_ > b.raw_; }
  friend constexpr bool operator<=(Q a, Q b) noexcept { return a.raw_ <= b.raw_; }
  friend constexpr bool operator>=(Q a, Q b) noexcept { return a.raw_ >= b.raw_; }

 private:
  std::int32_t raw_ = 0;
};

/// An intermediate value of a fixed-point computation in the format of Q<F>: the same raw
/// value, rounded and saturated like every Q<F> result, but in the **full** int32 range:
/// INT32_MIN (-32768.0 in Q16.16), the one raw value a Q<F> never holds, is allowed. It
/// saves the mapping of INT32_MIN into the symmetric range (two QSUBs on Cortex-M4) on
/// values that never reach a negation, an absolute value or an output. A QTerm therefore
/// has no negation, no comparison, no arithmetic operators of its own: it is only
///   - a factor of an exact 64-bit product (|raw| <= 2^31, so a product with a Q<F>
///     value, |raw| <= 2^31 - 1, stays below 2^62 in magnitude, like two Q<F> values);
///   - the addend c of c 2^F + products (below 2^(31+F));
///   - an operand of the saturating sums add_term/sub_term (QADD/QSUB take any int32);
///   - turned into a Q<F> by from_term (or by adding it to a Q<F>), which maps INT32_MIN
///     to the symmetric minimum.
/// Produced by the *_term functions of qmath.hpp (term_t<S> is S itself for float and
/// double, so the core's templates read the same for every scalar).
template <int FracBits>
class QTerm {
 public:
  using raw_type = std::int32_t;
  static constexpr int frac_bits = FracBits;

  constexpr QTerm() noexcept = default;
  [[nodiscard]] static constexpr QTerm from_raw(std::int32_t r) noexcept {
    QTerm t;
    t.raw_ = r;
    return t;
  }
  [[nodiscard]] constexpr std::int32_t raw() const noexcept { return raw_; }

 private:
  std::int32_t raw_ = 0;
};

template <class T>
struct is_q : std::false_type {};
template <int F>
struct is_q<Q<F>> : std::true_type {};
template <class T>
inline constexpr bool is_q_v = is_q<T>::value;
template <class T>
struct is_q_term : std::false_type {};
template <int F>
struct is_q_term<QTerm<F>> : std::true_type {};
template <class T>
inline constexpr bool is_q_term_v = is_q_term<T>::value;
/// Q<F> or QTerm<F>: what the fixed-point products take as operands.
template <class T>
inline constexpr bool is_q_operand_v = is_q_v<T> || is_q_term_v<T>;

/// QTerm<F> -> Q<F>: INT32_MIN maps to the symmetric minimum (two QSUBs on Cortex-M4).
template <int F>
[[nodiscard]] constexpr Q<F> from_term(QTerm<F> t) noexcept {
  return Q<F>::from_symmetric_raw(detail::symmetric_raw(t.raw()));
}

namespace detail {
/// Saturating int32 sum and difference in the full int32 range: QADD/QSUB on Cortex-M4,
/// elsewhere the overflow builtins saturating as QADD/QSUB do (same results everywhere).
inline std::int32_t qadd_target(std::int32_t a, std::int32_t b) noexcept {
#if defined(__ARM_FEATURE_DSP) && (__ARM_FEATURE_DSP == 1)
  return __qadd(a, b);
#else
  std::int32_t r = 0;
  if (__builtin_add_overflow(a, b, &r)) {
    return a < 0 ? std::numeric_limits<std::int32_t>::min() : std::numeric_limits<std::int32_t>::max();
  }
  return r;
#endif
}
inline std::int32_t qsub_target(std::int32_t a, std::int32_t b) noexcept {
#if defined(__ARM_FEATURE_DSP) && (__ARM_FEATURE_DSP == 1)
  return __qsub(a, b);
#else
  std::int32_t r = 0;
  if (__builtin_sub_overflow(a, b, &r)) {
    return a < 0 ? std::numeric_limits<std::int32_t>::min() : std::numeric_limits<std::int32_t>::max();
  }
  return r;
#endif
}
constexpr std::int32_t qadd(std::int32_t a, std::int32_t b) noexcept {
  if (!__builtin_is_constant_evaluated()) {
    return qadd_target(a, b);
  }
  const std::int64_t r = std::int64_t{a} + b;
  return r > std::numeric_limits<std::int32_t>::max()   ? std::numeric_limits<std::int32_t>::max()
         : r < std::numeric_limits<std::int32_t>::min() ? std::numeric_limits<std::int32_t>::min()
                                                        : static_cast<std::int32_t>(r);
}
constexpr std::int32_t qsub(std::int32_t a, std::int32_t b) noexcept {
  if (!__builtin_is_constant_evaluated()) {
    return qsub_target(a, b);
  }
  const std::int64_t r = std::int64_t{a} - b;
  return r > std::numeric_limits<std::int32_t>::max()   ? std::numeric_limits<std::int32_t>::max()
         : r < std::numeric_limits<std::int32_t>::min() ? std::numeric_limits<std::int32_t>::min()
                                                        : static_cast<std::int32_t>(r);
}
}  // namespace detail

/// a + b and a - b of Q<F> or QTerm<F> operands, as a QTerm<F>: saturated to the full int32
/// range (QADD/QSUB), no mapping of INT32_MIN.
template <class A, class B, std::enable_if_t<is_q_operand_v<A> && is_q_operand_v<B>, int> = 0>
[[nodiscard]] constexpr QTerm<A::frac_bits> add_term(A a, B b) noexcept {
  static_assert(A::frac_bits == B::frac_bits, "one format");
  return QTerm<A::frac_bits>::from_raw(detail::qadd(a.raw(), b.raw()));
}
template <class A, class B, std::enable_if_t<is_q_operand_v<A> && is_q_operand_v<B>, int> = 0>
[[nodiscard]] constexpr QTerm<A::frac_bits> sub_term(A a, B b) noexcept {
  static_assert(A::frac_bits == B::frac_bits, "one format");
  return QTerm<A::frac_bits>::from_raw(detail::qsub(a.raw(), b.raw()));
}
/// Q<F> +/- QTerm<F> -> Q<F>: saturated, INT32_MIN mapped (as Q<F>'s own + and -).
template <int F>
[[nodiscard]] constexpr Q<F> operator+(Q<F> a, QTerm<F> b) noexcept {
  return from_term(add_term(a, b));
}
template <int F>
[[nodiscard]] constexpr Q<F> operator+(QTerm<F> a, Q<F> b) noexcept {
  return from_term(add_term(a, b));
}
template <int F>
[[nodiscard]] constexpr Q<F> operator-(Q<F> a, QTerm<F> b) noexcept {
  return from_term(sub_term(a, b));
}

/// Explicit format change Q<Fi> -> Q<Fo>: rounds when dropping bits, saturates when
/// adding integer bits would overflow.
template <class To, int Fi>
[[nodiscard]] constexpr To q_cast(Q<Fi> x) noexcept {
  static_assert(is_q_v<To>, "q_cast converts between Q formats");
  return To::from_raw(detail::saturate32(detail::shift_round(x.raw(), Fi - To::frac_bits)));
}

/// Mixed-format product Q<Fa> * Q<Fb> -> Q<Fo>; 64-bit intermediate Q(Fa+Fb), rounded.
template <int Fo, int Fa, int Fb>
[[nodiscard]] constexpr Q<Fo> mul(Q<Fa> a, Q<Fb> b) noexcept {
  const std::int64_t prod = std::int64_t{a.raw()} * b.raw();
  return Q<Fo>::from_raw(detail::saturate32(detail::shift_round(prod, Fa + Fb - Fo)));
}

/// Q16.16: the core's default format for physical signals (torque N·m, velocity rad/s,
/// angle rad, momentum N·m·s). Range +/-32768, resolution 1.53e-5.
using q16 = Q<16>;
/// Q2.30 (range +/-2): unit vectors, rotation-matrix entries, trigonometric results.
using q30 = Q<30>;

}  // namespace jg

/// numeric_limits for Q<F>. Fixed point has no denormals or infinities: min() is the
/// most negative value (as for integers), epsilon() is one LSB (the spacing everywhere).
template <int F>
class std::numeric_limits<jg::Q<F>> {
 public:
  static constexpr bool is_specialized = true;
  static constexpr bool is_signed = true;
  static constexpr bool is_integer = false;
  static constexpr bool is_exact = true;
  static constexpr bool has_infinity = false;
  static constexpr bool has_quiet_NaN = false;
  static constexpr bool has_signaling_NaN = false;
  static constexpr bool is_bounded = true;
  static constexpr bool is_modulo = false;  // saturates, never wraps
  static constexpr bool is_iec559 = false;
  static constexpr bool traps = false;
  static constexpr bool tinyness_before = false;
  static constexpr int radix = 2;
  static constexpr int digits = 31;
  static constexpr int digits10 = 9;
  static constexpr int max_digits10 = 0;
  static constexpr int min_exponent = 0;
  static constexpr int min_exponent10 = 0;
  static constexpr int max_exponent = 0;
  static constexpr int max_exponent10 = 0;
  static constexpr std::float_round_style round_style = std::round_to_nearest;
  static constexpr jg::Q<F> min() noexcept { return jg::Q<F>::from_raw(jg::detail::kRawMin); }
  static constexpr jg::Q<F> lowest() noexcept { return min(); }
  static constexpr jg::Q<F> max() noexcept { return jg::Q<F>::from_raw(jg::detail::kRawMax); }
  static constexpr jg::Q<F> epsilon() noexcept { return jg::Q<F>::from_raw(1); }
  static constexpr jg::Q<F> round_error() noexcept { return jg::Q<F>::from_raw(1); }  // 0.5 LSB rounds up to 1 LSB
  static constexpr jg::Q<F> infinity() noexcept { return jg::Q<F>{}; }
  static constexpr jg::Q<F> quiet_NaN() noexcept { return jg::Q<F>{}; }
  static constexpr jg::Q<F> signaling_NaN() noexcept { return jg::Q<F>{}; }
  static constexpr jg::Q<F> denorm_min() noexcept { return epsilon(); }
};
