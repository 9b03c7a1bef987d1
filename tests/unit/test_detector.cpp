// Detector: threshold band, debounce, latching, isolation by signature; float and Q.
#include <gtest/gtest.h>

#include <cmath>

#include "jointguard/detection/detector.hpp"

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
