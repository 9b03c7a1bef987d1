// Accuracy of the Q math routines against double. The bounds asserted here are the
// worst-case errors stated in docs/fixed-point.md; each test prints what it measured.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "jointguard/numeric/qmath.hpp"

namespace {
using jg::q16;
using jg::q30;
constexpr double kLsb16 = 1.0 / 65536.0;

static_assert(jg::sqrt(q16::from_double(4.0)).raw() == q16::from_double(2.0).raw());
static_assert(jg::exp(q16{}).raw() == 65536, "exp(0) = 1 exactly");
static_assert(jg::sin(q16{}).raw() == 0 && jg::cos(q16{}).raw() == 65536);
static_assert(jg::div(q16::from_double(1.0), q16{}).raw() == 2147483647, "x/0 defined");
static_assert(jg::div(q16::from_double(-1.0), q16{}).raw() == -2147483647, "x/0 defined");
static_assert(jg::div(q16{}, q16{}).raw() == 0, "0/0 defined");
static_assert(jg::abs(q16::from_double(-2.5)).raw() == q16::from_double(2.5).raw());
static_assert(jg::sign(q16::from_double(-0.001)).raw() == -65536 && jg::sign(q16{}).raw() == 0);

template <class Fn, class Ref>
double worst_error(double lo, double hi, double step, Fn fn, Ref ref, double* at = nullptr) {
  double worst = 0.0;
  for (double x = lo; x <= hi; x += step) {
    const q16 q = q16::from_double(x);
    const double err = std::fabs(fn(q).to_double() - ref(q.to_double()));
    if (err > worst) {
      worst = err;
      if (at != nullptr) {
        *at = x;
      }
    }
  }
  return worst;
}

TEST(QMath, Sqrt) {
  const double w = worst_error(0.0, 30000.0, 0.6173, [](q16 x) { return jg::sqrt(x); },
                               [](double x) { return std::sqrt(x); });
  std::printf("sqrt Q16.16 worst error: %.3g LSB\n", w / kLsb16);
  EXPECT_LE(w, 0.5 * kLsb16 + 1e-12);
  EXPECT_EQ(jg::sqrt(q16::from_double(-3.0)).raw(), 0);
}

TEST(QMath, ExpOverStribeckRange) {
  // The Stribeck curve evaluates exp(-u^2), u^2 in [0, 32767].
  const double w = worst_error(-40.0, 0.0, 0.000731, [](q16 x) { return jg::exp(x); },
                               [](double x) { return std::exp(x); });
  std::printf("exp Q16.16 worst error on [-40, 0]: %.3g LSB\n", w / kLsb16);
  EXPECT_LE(w, 1.0 * kLsb16);
  EXPECT_EQ(jg::exp(q16::from_double(-30000.0)).raw(), 0);
}

TEST(QMath, ExpPositiveRelative) {
  double worst_rel = 0.0;
  for (double x = 0.0; x < 10.39; x += 0.0013) {
    const q16 q = q16::from_double(x);
    const double ref = std::exp(q.to_double());
    worst_rel = std::max(worst_rel, std::fabs(jg::exp(q).to_double() - ref) / ref);
  }
  std::printf("exp Q16.16 worst relative error on [0, 10.39]: %.3g\n", worst_rel);
  EXPECT_LE(worst_rel, 2e-5);  // dominated by the 1-LSB output rounding near x = 0
  EXPECT_EQ(jg::exp(q16::from_double(11.0)).raw(), 2147483647) << "saturates";
  EXPECT_EQ(jg::exp(q16::from_double(20000.0)).raw(), 2147483647) << "saturates";
}

TEST(QMath, SinCosOverManyTurns) {
  double at = 0.0;
  const double ws = worst_error(-200.0, 200.0, 0.000917, [](q16 x) { return jg::sin(x); },
                                [](double x) { return std::sin(x); }, &at);
  const double wc = worst_error(-200.0, 200.0, 0.000917, [](q16 x) { return jg::cos(x); },
                                [](double x) { return std::cos(x); });
  std::printf("sin/cos Q16.16 worst error on [-200, 200] rad: %.3g / %.3g LSB (sin at %.4f)\n",
              ws / kLsb16, wc / kLsb16, at);
  EXPECT_LE(ws, 1.0 * kLsb16);
  EXPECT_LE(wc, 1.0 * kLsb16);
  // Q2.30: the trigonometric core itself.
  double w30 = 0.0;
  for (double x = -3.2; x <= 3.2; x += 0.000123) {
    const q30 q = q30::from_double(x * 0.5);  // Q2.30 holds |x| < 2
    w30 = std::max(w30, std::fabs(jg::sin(q).to_double() - std::sin(q.to_double())));
  }
  std::printf("sin Q2.30 worst error on [-1.6, 1.6]: %.3g (%.3g LSB)\n", w30, w30 * 1073741824.0);
  EXPECT_LE(w30, 8e-9);
}

TEST(QMath, DivisionRoundsAndSaturates) {
  double worst = 0.0;
  for (double a = -500.0; a <= 500.0; a += 1.713) {
    for (double b = -50.0; b <= 50.0; b += 0.2917) {
      const q16 qa = q16::from_double(a), qb = q16::from_double(b);
      if (qb.raw() == 0) {
        continue;
      }
      const double exact = qa.to_double() / qb.to_double();
      if (std::fabs(exact) >= 32767.0) {
        continue;
      }
      worst = std::max(worst, std::fabs(jg::div(qa, qb).to_double() - exact));
    }
  }
  std::printf("div Q16.16 worst error: %.3g LSB\n", worst / kLsb16);
  EXPECT_LE(worst, 0.5 * kLsb16 + 1e-12);
  EXPECT_EQ(jg::div(q16::from_double(30000.0), q16::from_double(0.001)).raw(), 2147483647);
  EXPECT_EQ(jg::div(q16::from_double(-30000.0), q16::from_double(0.001)).raw(), -2147483647);
}

TEST(QMath, FloatOverloadsShareDefinedEdges) {
  EXPECT_EQ(jg::sqrt(-1.0F), 0.0F);
  EXPECT_EQ(jg::div(1.0F, 0.0F), std::numeric_limits<float>::max());
  EXPECT_EQ(jg::div(-1.0, 0.0), std::numeric_limits<double>::lowest());
  EXPECT_EQ(jg::div(0.0F, 0.0F), 0.0F);
  EXPECT_EQ(jg::sign(-3.0), -1.0);
}

TEST(QMath, ConvertIsRangeChecked) {
  jg::NumericStatus st;
  EXPECT_EQ(jg::convert<float>(1e300, st), std::numeric_limits<float>::max());
  EXPECT_EQ(st.saturated, 1U);
  EXPECT_EQ(jg::convert<float>(std::nan(""), st), 0.0F);
  EXPECT_EQ(st.not_finite, 1U);
  EXPECT_EQ(jg::convert<q16>(1e6, st).raw(), 2147483647);
  EXPECT_EQ(st.saturated, 2U);
}
}  // namespace

namespace {
// Reference semantics of the fused kernels: the exact sum in 128-bit-free double-checked
// integer arithmetic (__int128 on the host), rounded half up, saturated symmetrically.
std::int32_t reference_round(__int128 sum_q2f) {
  const __int128 r = (sum_q2f + (__int128{1} << 15)) >> 16;
  if (r > 2147483647) {
    return 2147483647;
  }
  if (r < -2147483647) {
    return -2147483647;
  }
  return static_cast<std::int32_t>(r);
}

TEST(QMath, FusedSumsRoundOnceAndSaturateSymmetrically) {
  const std::int32_t edges[] = {0, 1, -1, 32767, -32768, 65535, 65536, -65536, 2147483647, -2147483647,
                                1073741824, -1073741824, 123456789, -987654321, 1900000000, -1900000000};
  for (const std::int32_t a : edges) {
    for (const std::int32_t b : edges) {
      for (const std::int32_t c : edges) {
        const q16 qa = q16::from_raw(a), qb = q16::from_raw(b), qc = q16::from_raw(c);
        const __int128 ab = static_cast<__int128>(a) * b;
        ASSERT_EQ((qa * qb).raw(), reference_round(ab)) << a << " " << b;
        ASSERT_EQ(jg::sum_of_products(qa, qb, qc, qa).raw(), reference_round(ab + static_cast<__int128>(c) * a));
        ASSERT_EQ(jg::sum_of_products(qa, qb, qc, qa, qb, qc).raw(),
                  reference_round(ab + static_cast<__int128>(c) * a + static_cast<__int128>(b) * c));
        ASSERT_EQ(jg::sum_of_products(qa, qb, qc, qa, qb, qc, qa, qa).raw(),
                  reference_round(ab + static_cast<__int128>(c) * a + static_cast<__int128>(b) * c +
                                  static_cast<__int128>(a) * a));
        ASSERT_EQ(jg::mac(qc, qa, qb).raw(), reference_round(ab + static_cast<__int128>(c) * 65536));
        ASSERT_EQ((qa + qb).raw(), reference_round((static_cast<__int128>(a) + b) * 65536));
        ASSERT_EQ((qa - qb).raw(), reference_round((static_cast<__int128>(a) - b) * 65536));
      }
    }
  }
  // INT32_MIN is never produced: a result of exactly -32768.0 (raw -2^31, which passes
  // the high-word range test) maps to the symmetric minimum.
  EXPECT_EQ((q16::from_double(-16384.0) * q16::from_double(2.0)).raw(), -2147483647);
  EXPECT_EQ(jg::dot_bounded(q16::from_double(-16384.0), q16::from_double(2.0)).raw(), -2147483647);
  EXPECT_EQ((q16::from_double(-32767.0) - q16::from_double(1.0)).raw(), -2147483647);
  EXPECT_EQ(jg::mac(q16::from_double(-32767.0), q16::from_double(-1.0), q16::from_double(1.0)).raw(), -2147483647);
}

// Intermediate terms (QTerm): the same rounding and saturation as Q<F>, but a result of
// exactly -2^31 raw stays INT32_MIN (no mapping), and the sums saturate like QADD/QSUB.
std::int32_t reference_round_term(__int128 sum_q2f) {
  const __int128 r = (sum_q2f + (__int128{1} << 15)) >> 16;
  if (r > 2147483647) {
    return 2147483647;
  }
  if (r < -__int128{2147483648}) {
    return -2147483647;  // saturated by the sign, as every Q<F> result
  }
  return static_cast<std::int32_t>(r);
}
std::int32_t saturate_full(__int128 v) {
  return v > 2147483647 ? 2147483647 : (v < -__int128{2147483648} ? std::numeric_limits<std::int32_t>::min() : static_cast<std::int32_t>(v));
}
constexpr std::int32_t kInt32Min = std::numeric_limits<std::int32_t>::min();
// Compile time (constexpr branch) and run time (QADD/QSUB or the overflow builtins) agree.
static_assert(jg::add_term(q16::from_raw(-2147483647), q16::from_raw(-1)).raw() == kInt32Min);
static_assert(jg::sub_term(jg::QTerm<16>::from_raw(kInt32Min), q16::from_raw(1)).raw() == kInt32Min);
static_assert(jg::sub_term(q16{}, jg::QTerm<16>::from_raw(kInt32Min)).raw() == 2147483647, "0 - (-2^31) saturates up");
static_assert(jg::from_term(jg::QTerm<16>::from_raw(kInt32Min)).raw() == -2147483647);
static_assert(jg::dot_bounded_term(q16::from_double(-16384.0), q16::from_double(2.0)).raw() == kInt32Min);

TEST(QMath, TermsRoundLikeQAndKeepInt32Min) {
  const std::int32_t edges[] = {0, 1, -1, 32767, -32768, 65536, -65536, 2147483647, -2147483647, kInt32Min,
                                1073741824, -1073741825, 123456789, -987654321, 1900000000, -1900000000};
  for (const std::int32_t a : edges) {
    const auto ta = jg::QTerm<16>::from_raw(a);
    EXPECT_EQ(jg::from_term(ta).raw(), a == kInt32Min ? -2147483647 : a);
    ASSERT_EQ(jg::square(ta).raw(), reference_round(static_cast<__int128>(a) * a)) << a;
    for (const std::int32_t b : edges) {
      const q16 qb = q16::from_raw(b);  // a Q value: INT32_MIN maps to -2147483647
      const std::int32_t rb = qb.raw();
      const __int128 ab = static_cast<__int128>(a) * rb;
      ASSERT_EQ(jg::add_term(ta, qb).raw(), saturate_full(static_cast<__int128>(a) + rb)) << a << " " << b;
      ASSERT_EQ(jg::sub_term(ta, qb).raw(), saturate_full(static_cast<__int128>(a) - rb)) << a << " " << b;
      ASSERT_EQ(jg::sub_term(qb, ta).raw(), saturate_full(static_cast<__int128>(rb) - a)) << a << " " << b;
      ASSERT_EQ((qb + ta).raw(), reference_round((static_cast<__int128>(rb) + a) * 65536)) << a << " " << b;
      ASSERT_EQ((qb - ta).raw(), reference_round((static_cast<__int128>(rb) - a) * 65536)) << a << " " << b;
      ASSERT_EQ(jg::mul_term(ta, qb).raw(), reference_round_term(ab)) << a << " " << b;
      ASSERT_EQ(jg::mac_term(ta, ta, qb).raw(), reference_round_term(ab + static_cast<__int128>(a) * 65536));
      ASSERT_EQ(jg::mac(ta, qb, ta).raw(), reference_round(ab + static_cast<__int128>(a) * 65536));
      // One term per product: each product stays below 2^62, the pair is exact.
      ASSERT_EQ(jg::sum_of_products_term(ta, qb, qb, ta).raw(), reference_round_term(2 * ab));
      ASSERT_EQ(jg::sum_of_products(qb, ta, ta, qb).raw(), reference_round(2 * ab));
      // Two exact pairs joined with the int64 overflow check (saturates at +/-2^63).
      const __int128 i64_max = std::numeric_limits<std::int64_t>::max(), i64_min = std::numeric_limits<std::int64_t>::min();
      const __int128 four = 4 * ab + (__int128{1} << 15);
      ASSERT_EQ(jg::sum_of_products(ta, qb, qb, ta, ta, qb, qb, ta).raw(),
                reference_round((four > i64_max ? i64_max : (four < i64_min ? i64_min : four)) - (__int128{1} << 15)));
      ASSERT_EQ(jg::scale_sum(jg::q30::from_raw(1 << 30), ta, jg::q30::from_raw(-(1 << 29)), qb).raw(),
                reference_round((static_cast<__int128>(a) * (1 << 30) - static_cast<__int128>(rb) * (1 << 29)) >> 14));
    }
  }
}

TEST(QMath, BoundedSumsMatchTheExactSum) {
  // Within the documented bound (a full-range signal times operands below 2^28).
  std::uint32_t seed = 12345U;
  auto next = [&seed]() {
    seed = seed * 1664525U + 1013904223U;
    return static_cast<std::int32_t>(seed);
  };
  for (int i = 0; i < 200000; ++i) {
    const q16 c = q16::from_raw(next() / 2), s0 = q16::from_raw(next() / 2), s1 = q16::from_raw(next() / 2),
              s2 = q16::from_raw(next() / 2);
    const q16 k0 = q16::from_raw(next() >> 4), k1 = q16::from_raw(next() >> 4), k2 = q16::from_raw(next() >> 4);
    const __int128 exact = static_cast<__int128>(c.raw()) * 65536 + static_cast<__int128>(s0.raw()) * k0.raw() +
                           static_cast<__int128>(s1.raw()) * k1.raw() + static_cast<__int128>(s2.raw()) * k2.raw();
    ASSERT_EQ(jg::mac_bounded(c, s0, k0, s1, k1, s2, k2).raw(), reference_round(exact));
    ASSERT_EQ(jg::dot_bounded(s0, k0, s1, k1, s2, k2).raw(), reference_round(exact - static_cast<__int128>(c.raw()) * 65536));
  }
}

TEST(QMath, DivisionMatchesThe64BitQuotientExactly) {
  // The 64/32 long division (UDIV digits) against the plain 64-bit quotient it replaced.
  std::uint32_t seed = 777U;
  auto next = [&seed]() {
    seed = seed * 1664525U + 1013904223U;
    return static_cast<std::int32_t>(seed);
  };
  for (int i = 0; i < 400000; ++i) {
    const int shift_a = i % 31;
    const int shift_b = (i / 31) % 31;
    std::int32_t a = next() >> shift_a;
    std::int32_t b = next() >> shift_b;
    a = a == std::numeric_limits<std::int32_t>::min() ? a + 1 : a;
    b = b == std::numeric_limits<std::int32_t>::min() ? b + 1 : b;
    if (b == 0) {
      continue;
    }
    const std::int64_t ua = a < 0 ? -std::int64_t{a} : a;
    const std::int64_t ub = b < 0 ? -std::int64_t{b} : b;
    const std::int64_t q = ((ua << 16) + ub / 2) / ub;
    const std::int64_t sat = q > 2147483647 ? 2147483647 : q;
    const std::int64_t expected = (a < 0) != (b < 0) ? -sat : sat;
    ASSERT_EQ(jg::div(q16::from_raw(a), q16::from_raw(b)).raw(), expected) << a << " / " << b;
  }
}

TEST(QMath, ExpEarlyExitsAreExact) {
  // Below -(F+1) ln 2 the result is under half an LSB; from ln(2^15) up it saturates.
  const double zero_below = -17.0 * std::log(2.0);
  for (double x = zero_below - 3.0; x < zero_below + 0.2; x += 1.0 / 65536.0 * 37.0) {
    const q16 q = q16::from_double(x);
    const double ref = std::exp(q.to_double()) * 65536.0;
    EXPECT_NEAR(static_cast<double>(jg::exp(q).raw()), ref, 0.5 + 1e-6) << x;
  }
  for (double x = 10.3; x < 10.5; x += 0.0007) {
    const q16 q = q16::from_double(x);
    const double ref = std::min(std::exp(q.to_double()) * 65536.0, 2147483647.0);
    EXPECT_NEAR(static_cast<double>(jg::exp(q).raw()), ref, ref * 1e-8 + 0.5) << x;
  }
}

TEST(QMath, SinCosTogether) {
  for (double x = -40.0; x <= 40.0; x += 0.01237) {
    q16 s{}, c{};
    jg::sincos(q16::from_double(x), s, c);
    EXPECT_EQ(s.raw(), jg::sin(q16::from_double(x)).raw());
    EXPECT_EQ(c.raw(), jg::cos(q16::from_double(x)).raw());
    EXPECT_LE(std::abs(s.raw()), 65536);
    EXPECT_LE(std::abs(c.raw()), 65536);
  }
}
}  // namespace
