// Accuracy of the Q math routines against double. The bounds asserted here are the
// worst-case errors stated in docs/fixed-point.md; each test prints what it measured.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

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
