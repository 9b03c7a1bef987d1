// Residual detector (change against the estimate's slow baseline): float, double and Q.
#include <gtest/gtest.h>

#include <cmath>

#include "jointguard/detection/detector.hpp"
#include "jointguard/detection/residual_detector.hpp"

namespace {
template <class S>
class ResidualTyped : public ::testing::Test {};
using Scalars = ::testing::Types<float, double, jg::q16>;
TYPED_TEST_SUITE(ResidualTyped, Scalars);

template <class S>
jg::ResidualChangeParams<S> params(double threshold, double smoothing) {
  return {jg::from_double<S>(threshold), jg::from_double<S>(smoothing)};
}

TYPED_TEST(ResidualTyped, FirstCycleStartsTheBaselineAtTheEstimate) {
  using S = TypeParam;
  const auto p = params<S>(0.5, 0.05);
  jg::ResidualChangeState<S> st;
  EXPECT_NEAR(jg::to_double(jg::residual_deviation(st, jg::from_double<S>(7.0))), 0.0, 1e-9) << "not started";
  EXPECT_FALSE(jg::residual_change_step(p, st, jg::from_double<S>(7.0))) << "a large estimate at start is no change";
  EXPECT_NEAR(jg::to_double(st.baseline), 7.0, 1e-4);
  EXPECT_FALSE(jg::residual_change_step(p, st, jg::from_double<S>(7.4)));
  EXPECT_TRUE(jg::residual_change_step(p, st, jg::from_double<S>(6.4))) << "two-sided";
}

TYPED_TEST(ResidualTyped, SlowDriftFollowedFastRiseSeen) {
  using S = TypeParam;
  // Smoothing 0.05 (T = 20 cycles). A ramp of 0.01 N·m per cycle (the friction building
  // up over a reversal) leaves a residual of about 0.01 / 0.05 = 0.2 N·m: never over 0.5.
  const auto p = params<S>(0.5, 0.05);
  jg::ResidualChangeState<S> st;
  double mu = 0.0;
  for (int k = 0; k < 400; ++k, mu += 0.01) EXPECT_FALSE(jg::residual_change_step(p, st, jg::from_double<S>(mu))) << k;
  EXPECT_NEAR(jg::to_double(jg::residual_deviation(st, jg::from_double<S>(mu))), 0.2, 0.02);
  // A contact rising 1 N·m over 5 cycles on top of it: seen before the rise ends.
  bool seen = false;
  for (int k = 1; k <= 5 && !seen; ++k, mu += 0.01) seen = jg::residual_change_step(p, st, jg::from_double<S>(mu + 0.2 * k));
  EXPECT_TRUE(seen);
}

TYPED_TEST(ResidualTyped, DisabledByZeroThreshold) {
  using S = TypeParam;
  const auto p = params<S>(0.0, 0.05);
  jg::ResidualChangeState<S> st;
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(jg::residual_change_step(p, st, jg::from_double<S>(k * 5.0)));
  EXPECT_FALSE(st.started);
}

TYPED_TEST(ResidualTyped, SeesAContactTheStandstillAllowanceHides) {
  using S = TypeParam;
  // Band 2 N·m + 8 N·m standstill allowance: a 4 N·m step on a joint the contact has
  // stopped (velocity 0) stays under the band but shows against the baseline.
  const jg::JointThreshold<S> th{jg::from_double<S>(2.0), S{}, jg::from_double<S>(8.0), jg::from_double<S>(1.0 / 0.03)};
  const auto p = params<S>(3.0, 0.05);
  jg::ResidualChangeState<S> rs;
  jg::JointDetectorState band_alone, both;
  const jg::DebounceSettings one{1};
  const S before = jg::from_double<S>(1.0), after = jg::from_double<S>(5.0);
  EXPECT_FALSE(jg::detector_step(th, one, both, before, jg::from_double<S>(0.3), jg::residual_change_step(p, rs, before)));
  EXPECT_FALSE(jg::detector_step(th, one, band_alone, after, S{}));
  EXPECT_TRUE(jg::detector_step(th, one, both, after, S{}, jg::residual_change_step(p, rs, after)));
}
}  // namespace

TEST(ResidualQ, ResidualSaturatesIntoAnAlarm) {
  using S = jg::q16;
  // A baseline near the top of the range and an estimate near the bottom: the difference
  // saturates at -32768 N·m (never wraps to a small positive value): a change is seen.
  const auto p = params<S>(1.0, 0.5);
  jg::ResidualChangeState<S> st;
  EXPECT_FALSE(jg::residual_change_step(p, st, S::from_double(30000.0)));
  EXPECT_TRUE(jg::residual_change_step(p, st, S::from_double(-30000.0)));
  EXPECT_LT(jg::to_double(st.baseline), 30000.0);
}
