// Detector: threshold band, debounce, latching, isolation by signature; float and Q.
#include <gtest/gtest.h>

#include <cmath>

#include "jointguard/detection/detector.hpp"
#include "jointguard/detection/hold_detector.hpp"

namespace {
template <class S>
class DetectorTyped : public ::testing::Test {};
using Scalars = ::testing::Types<float, double, jg::q16>;
TYPED_TEST_SUITE(DetectorTyped, Scalars);

TYPED_TEST(DetectorTyped, DebounceAndLatch) {
  using S = TypeParam;
  const jg::JointThreshold<S> th{jg::from_double<S>(5.0), jg::from_double<S>(0.0)};
  jg::JointDetectorState st;
  const jg::DebounceSettings three{3};
  EXPECT_FALSE(jg::detector_step(th, three, st, jg::from_double<S>(6.0), S{}));
  EXPECT_FALSE(jg::detector_step(th, three, st, jg::from_double<S>(-6.0), S{}));
  EXPECT_FALSE(jg::detector_step(th, three, st, jg::from_double<S>(4.0), S{})) << "a dip resets the count";
  EXPECT_FALSE(jg::detector_step(th, three, st, jg::from_double<S>(6.0), S{}));
  EXPECT_FALSE(jg::detector_step(th, three, st, jg::from_double<S>(6.0), S{}));
  EXPECT_TRUE(jg::detector_step(th, three, st, jg::from_double<S>(-6.0), S{}));
  EXPECT_TRUE(jg::detector_step(th, three, st, jg::from_double<S>(0.0), S{})) << "latched";
  jg::reset_detector(st);
  EXPECT_FALSE(jg::detector_step(th, three, st, jg::from_double<S>(0.0), S{}));
}

TYPED_TEST(DetectorTyped, BandGrowsWithSpeed) {
  using S = TypeParam;
  const jg::JointThreshold<S> th{jg::from_double<S>(2.0), jg::from_double<S>(4.0)};
  jg::JointDetectorState st;
  EXPECT_FALSE(jg::detector_step(th, {1}, st, jg::from_double<S>(3.5), jg::from_double<S>(0.5)));  // band 4
  EXPECT_TRUE(jg::detector_step(th, {1}, st, jg::from_double<S>(3.5), jg::from_double<S>(0.2)));   // band 2.8
}

TYPED_TEST(DetectorTyped, StandstillAllowanceFadesWithSpeed) {
  using S = TypeParam;
  // eps0 2 N·m, 8 N·m more at rest, Gaussian width 10 mrad/s.
  const jg::JointThreshold<S> th{jg::from_double<S>(2.0), S{}, jg::from_double<S>(8.0), jg::from_double<S>(100.0)};
  EXPECT_NEAR(jg::to_double(jg::threshold_at(th, S{})), 10.0, 1e-4);
  // Q16.16 holds 0.01 rad/s as 0.009995: the band there is 3e-3 N·m higher.
  EXPECT_NEAR(jg::to_double(jg::threshold_at(th, jg::from_double<S>(0.01))), 2.0 + 8.0 * std::exp(-1.0), 5e-3);
  EXPECT_NEAR(jg::to_double(jg::threshold_at(th, jg::from_double<S>(-0.03))), 2.0, 2e-3);
  jg::JointDetectorState st;
  EXPECT_FALSE(jg::detector_step(th, {1}, st, jg::from_double<S>(5.0), S{})) << "held by stiction at rest";
  EXPECT_TRUE(jg::detector_step(th, {1}, st, jg::from_double<S>(5.0), jg::from_double<S>(0.05))) << "moving";
}

TEST(Detector, IsolationNamesTheHighestFlaggedJoint) {
  static_assert(jg::isolate_link(0b000) == 0);
  static_assert(jg::isolate_link(0b001) == 1);
  static_assert(jg::isolate_link(0b011) == 2);
  static_assert(jg::isolate_link(0b111) == 3);
  static_assert(jg::isolate_link(0b101) == 3);
  EXPECT_EQ(jg::isolate_link(0b1000000), 7);
}
}  // namespace

// Holding detector: settle, reference, two-sided change, re-armed when the joint moves.
namespace {
template <class S>
jg::HoldChangeParams<S> hold_params(double threshold, std::uint16_t settle, std::uint16_t reference) {
  return {jg::from_double<S>(threshold), settle, reference, jg::from_double<S>(1.0 / reference)};
}

TYPED_TEST(DetectorTyped, HoldChangeArmsAfterSettleAndReference) {
  using S = TypeParam;
  const auto p = hold_params<S>(0.5, 3, 4);
  jg::HoldChangeState<S> st;
  // Arrival transients (settle): large values are ignored and never enter the reference.
  for (int k = 0; k < 3; ++k) EXPECT_FALSE(jg::hold_change_step(p, st, true, jg::from_double<S>(9.0)));
  EXPECT_FALSE(st.armed);
  // Reference window: mean of 1.0, 1.2, 0.8, 1.0 = 1.0 N·m.
  for (const double mu : {1.0, 1.2, 0.8, 1.0}) EXPECT_FALSE(jg::hold_change_step(p, st, true, jg::from_double<S>(mu)));
  ASSERT_TRUE(st.armed);
  EXPECT_NEAR(jg::to_double(st.reference), 1.0, 1e-4);
  EXPECT_FALSE(jg::hold_change_step(p, st, true, jg::from_double<S>(1.45))) << "within the change threshold";
  EXPECT_TRUE(jg::hold_change_step(p, st, true, jg::from_double<S>(1.55))) << "a rise";
  EXPECT_TRUE(jg::hold_change_step(p, st, true, jg::from_double<S>(0.45))) << "a fall: two-sided";
  EXPECT_NEAR(jg::to_double(jg::hold_deviation(st, jg::from_double<S>(0.45))), 0.55, 1e-4);
  // The joint moves: cleared, and a new hold starts from scratch.
  EXPECT_FALSE(jg::hold_change_step(p, st, false, jg::from_double<S>(5.0)));
  EXPECT_FALSE(st.armed);
  EXPECT_EQ(st.held_cycles, 0U);
  for (int k = 0; k < 7; ++k) EXPECT_FALSE(jg::hold_change_step(p, st, true, jg::from_double<S>(5.0)));
  ASSERT_TRUE(st.armed);
  EXPECT_NEAR(jg::to_double(st.reference), 5.0, 1e-4) << "the reference of the new hold";
  EXPECT_FALSE(jg::hold_change_step(p, st, true, jg::from_double<S>(5.3)));
}

TYPED_TEST(DetectorTyped, HoldChangeDisabledByZeroThreshold) {
  using S = TypeParam;
  const auto p = hold_params<S>(0.0, 0, 1);
  jg::HoldChangeState<S> st;
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(jg::hold_change_step(p, st, true, jg::from_double<S>(k * 3.0)));
  EXPECT_FALSE(st.armed);
}

TYPED_TEST(DetectorTyped, HoldChangeSharesTheDebounceWithTheBand) {
  using S = TypeParam;
  // Band 2 N·m + 8 N·m standstill allowance: a 1 N·m change at rest is far below it.
  const jg::JointThreshold<S> th{jg::from_double<S>(2.0), S{}, jg::from_double<S>(8.0), jg::from_double<S>(100.0)};
  const auto p = hold_params<S>(0.6, 0, 1);
  jg::HoldChangeState<S> hs;
  jg::JointDetectorState ds;
  const jg::DebounceSettings two{2};
  const S rest = jg::from_double<S>(-3.0);
  EXPECT_FALSE(jg::detector_step(th, two, ds, rest, S{}, jg::hold_change_step(p, hs, true, rest)));
  const S pushed = jg::from_double<S>(-2.0);
  EXPECT_FALSE(jg::detector_step(th, two, ds, pushed, S{}, jg::hold_change_step(p, hs, true, pushed))) << "debounce 1 of 2";
  EXPECT_TRUE(jg::detector_step(th, two, ds, pushed, S{}, jg::hold_change_step(p, hs, true, pushed)));
  jg::JointDetectorState moving;
  EXPECT_FALSE(jg::detector_step(th, two, moving, pushed, S{}, false)) << "the band alone does not see it";
  EXPECT_FALSE(jg::detector_step(th, two, moving, pushed, S{}, false));
}
}  // namespace

TEST(DetectorQ, HoldReferenceSumSaturatesIntoAnAlarmNotAMiss) {
  using S = jg::q16;
  // 4 cycles of 20000 N·m would sum past the Q16.16 range (32768): the sum saturates, the
  // reference comes out wrong (8192 instead of 20000), and the held estimate then shows as
  // a change: an alarm, never a silent miss.
  const auto p = hold_params<S>(1.0, 0, 4);
  jg::HoldChangeState<S> st;
  for (int k = 0; k < 4; ++k) EXPECT_FALSE(jg::hold_change_step(p, st, true, S::from_double(20000.0)));
  ASSERT_TRUE(st.armed);
  EXPECT_NEAR(jg::to_double(st.reference), 32768.0 / 4.0, 1.0);
  EXPECT_TRUE(jg::hold_change_step(p, st, true, S::from_double(20000.0)));
}
