// Q-format type: compile-time properties, conversions, saturation, rounding.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "jointguard/numeric/q.hpp"

namespace {
using jg::NumericStatus;
using jg::q16;
using jg::q30;

// ---- compile-time checks
static_assert(sizeof(q16) == 4, "Q is a 32-bit storage type");
static_assert(q16::from_double(1.0).raw() == 65536);
static_assert(q16::from_double(-1.5).raw() == -98304);
static_assert(q16::from_double(0.5 / 65536.0).raw() == 1, "ties round toward +inf");
static_assert(q16::from_double(-0.5 / 65536.0).raw() == 0, "ties round toward +inf");
static_assert(q16::from_double(1e9).raw() == 2147483647, "saturates, never wraps");
static_assert(q16::from_double(-1e9).raw() == -2147483647, "symmetric range");
static_assert((q16::from_double(30000.0) + q16::from_double(30000.0)).raw() == 2147483647);
static_assert((q16::from_double(-30000.0) - q16::from_double(30000.0)).raw() == -2147483647);
static_assert((q16::from_double(300.0) * q16::from_double(300.0)).raw() == 2147483647);
static_assert((q16::from_double(1.5) * q16::from_double(-2.0)).raw() == q16::from_double(-3.0).raw());
static_assert((-q16::from_raw(std::numeric_limits<std::int32_t>::min())).raw() == 2147483647,
              "INT32_MIN is mapped into the symmetric range; negation cannot overflow");
static_assert(jg::q_cast<q30>(q16::from_double(1.25)).raw() == (5 << 28));
static_assert(jg::q_cast<q30>(q16::from_double(3.0)).raw() == 2147483647, "q_cast saturates");
static_assert(jg::q_cast<q16>(q30::from_raw(1 << 13)).raw() == 1, "q_cast rounds to nearest");
static_assert(jg::mul<16>(q30::from_double(0.5), q16::from_double(10.0)).raw() == q16::from_double(5.0).raw());
static_assert(std::numeric_limits<q16>::is_specialized && !std::numeric_limits<q16>::is_modulo);
static_assert(std::numeric_limits<q16>::epsilon().raw() == 1);
static_assert(std::numeric_limits<q16>::lowest().raw() == -std::numeric_limits<q16>::max().raw());
static_assert(!std::is_convertible_v<double, q16> && !std::is_convertible_v<q16, double>,
              "explicit conversions only");
static_assert(!std::is_convertible_v<q30, q16>, "mixed formats must be explicit");

TEST(Q, ConversionRoundTripWithinHalfLsb) {
  NumericStatus st;
  for (double x = -1000.0; x <= 1000.0; x += 0.37123) {
    const q16 q = q16::from_double(x, st);
    EXPECT_LE(std::fabs(q.to_double() - x), 0.5 / 65536.0 + 1e-15) << x;
  }
  EXPECT_TRUE(st.ok());
}

TEST(Q, NaNInfAndOutOfRangeSaturateAndRaiseStickyFlag) {
  NumericStatus st;
  EXPECT_EQ(q16::from_double(std::nan(""), st).raw(), 0);
  EXPECT_EQ(st.not_finite, 1U);
  EXPECT_EQ(q16::from_double(std::numeric_limits<double>::infinity(), st).raw(), 2147483647);
  EXPECT_EQ(q16::from_double(-std::numeric_limits<double>::infinity(), st).raw(), -2147483647);
  EXPECT_EQ(st.not_finite, 3U);
  EXPECT_EQ(q16::from_double(40000.0, st).raw(), 2147483647);
  EXPECT_EQ(st.saturated, 1U);
  // Sticky: a later valid conversion does not clear it.
  EXPECT_EQ(q16::from_double(1.0, st).raw(), 65536);
  EXPECT_FALSE(st.ok());
  st.clear();
  EXPECT_TRUE(st.ok());
}

TEST(Q, FromFloatMatchesFromDoubleAndFlags) {
  NumericStatus st;
  for (float x = -300.0F; x <= 300.0F; x += 0.731F) {
    EXPECT_EQ(q16::from_float(x, st).raw(), q16::from_double(static_cast<double>(x), st).raw()) << x;
  }
  EXPECT_TRUE(st.ok());
  EXPECT_EQ(q16::from_float(std::numeric_limits<float>::quiet_NaN(), st).raw(), 0);
  EXPECT_EQ(q16::from_float(std::numeric_limits<float>::infinity(), st).raw(), 2147483647);
  EXPECT_EQ(q16::from_float(-1e6F, st).raw(), -2147483647);
  EXPECT_EQ(st.not_finite, 2U);
  EXPECT_EQ(st.saturated, 1U);
}

TEST(Q, MultiplicationRoundsToNearest) {
  // Exhaustive-ish: products of many raw values against double, error <= 0.5 LSB.
  double worst = 0.0;
  for (std::int32_t a = -3000000; a <= 3000000; a += 12347) {
    for (std::int32_t b = -200000; b <= 200000; b += 9973) {
      const q16 qa = q16::from_raw(a), qb = q16::from_raw(b);
      const double exact = qa.to_double() * qb.to_double();
      worst = std::max(worst, std::fabs((qa * qb).to_double() - exact));
    }
  }
  EXPECT_LE(worst, 0.5 / 65536.0);
}

TEST(Q, SaturationNeverWraps) {
  const q16 big = std::numeric_limits<q16>::max();
  const q16 small = std::numeric_limits<q16>::lowest();
  EXPECT_EQ((big + big).raw(), big.raw());
  EXPECT_EQ((small + small).raw(), small.raw());
  EXPECT_EQ((big - small).raw(), big.raw());
  EXPECT_EQ((big * small).raw(), small.raw());
  EXPECT_EQ((small * small).raw(), big.raw());
  q16 acc{};
  for (int i = 0; i < 100000; ++i) {
    acc += q16::from_double(1000.0);
    ASSERT_GE(acc.raw(), 0) << "wrapped at step " << i;
  }
  EXPECT_EQ(acc.raw(), big.raw());
}
}  // namespace
