// The observer's balance with the mean of the last two motor torques (momentum_observer.hpp,
// align_motor_torque): on a joint without contact whose velocity is an encoder difference,
// a motor torque step does not move the estimate; with the torque of the sample (the former
// balance, still the default) it moves by (1 - exp(-K dT)) dT / 2. Float and Q16.16, as the
// firmware runs them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "jointguard/observer/momentum_observer.hpp"

namespace {

constexpr double kInertia = 0.8, kDt = 0.001, kGain = 150.0;

template <class S>
S to_scalar(double x) {
  if constexpr (jg::is_q_v<S>) {
    return S::from_double(x);
  } else {
    return static_cast<S>(x);
  }
}
template <class S>
double as_double(S x) {
  if constexpr (jg::is_q_v<S>) {
    return x.to_double();
  } else {
    return static_cast<double>(x);
  }
}

/// A rigid joint of inertia I [kg m^2], no friction, gravity or contact (the true external
/// torque is 0). The motor torque is held over each sample and steps from `before` to
/// `after` [N·m] at sample 200; positions are exact, the velocity is the position difference
/// over one sample. Returns the largest |estimate| [N·m] from the first sample on (the first
/// sample primes; the velocity difference is consistent from the start: no transient).
template <class S>
double largest_estimate(bool align, double before, double after) {
  jg::ObserverGains g{jg::ObserverKind::first_order, kGain, 0.0, 0.0};
  g.align_motor_torque = align;
  jg::ObserverCoeffs<S> c{};
  EXPECT_EQ(jg::discretize(g, kDt, c), jg::Error::ok);
  jg::ObserverState<S> st{};
  // Started in steady motion under `before`: the mean velocity over the sample before 0.
  const double a0 = before / kInertia;
  double v = 0.3, q = 0.0, q_last = -(v - a0 * kDt) * kDt - 0.5 * a0 * kDt * kDt, held = before;
  double largest = 0.0;
  for (int k = 0; k < 400; ++k) {
    const double velocity = (q - q_last) / kDt;  // sample k: held is the torque over [k-1, k]
    const S r = jg::observer_step(c, st, to_scalar<S>(kInertia * velocity), to_scalar<S>(held), S{}, S{});
    largest = std::max(largest, std::fabs(as_double(r)));
    held = k + 1 >= 200 ? after : before;  // the command for [k, k+1]
    const double a = held / kInertia;
    q_last = q;
    q += v * kDt + 0.5 * a * kDt * kDt;
    v += a * kDt;
  }
  return largest;
}

template <class S>
class TorqueMean : public ::testing::Test {};
using Scalars = ::testing::Types<float, jg::q16>;
TYPED_TEST_SUITE(TorqueMean, Scalars);

TYPED_TEST(TorqueMean, ATorqueStepDoesNotMoveTheEstimateOfAJointWithoutContact) {
  // A 50 N·m step (the stop reaction's damping term is 21 N·m median, 60 at the 95th
  // percentile): the former balance reads 25 N·m for one sample, the estimate jumps by
  // (1 - exp(-0.15)) x 25 = 3.48 N·m; the torque mean leaves rounding only (Q16.16: the
  // momentum's 1.5e-5 N·m·s LSB over dT is 0.015 N·m of disturbance, times 1 - exp(-0.15)).
  const double former = largest_estimate<TypeParam>(false, 0.0, -50.0);
  const double aligned = largest_estimate<TypeParam>(true, 0.0, -50.0);
  std::printf("50 N·m torque step, no contact: largest |estimate| %.4f N·m former balance, %.2e N·m torque mean\n",
              former, aligned);
  EXPECT_NEAR(former, (1.0 - std::exp(-kGain * kDt)) * 25.0, 0.05);
  EXPECT_LT(aligned, 0.01);
}

TYPED_TEST(TorqueMean, TheFirstSamplePrimesTheTorqueMean) {
  // A constant 40 N·m from the first sample on: had the first sample left tau_{k-1} at 0,
  // the second would balance 20 N·m too little and the estimate would jump by 2.8 N·m.
  EXPECT_LT(largest_estimate<TypeParam>(true, 40.0, 40.0), 0.01);
}

TYPED_TEST(TorqueMean, TheFirstBalanceTakesTheTorqueOfItsSampleAlone) {
  // An arm at rest whose drive measures no torque at the first sample, then its 40 N·m
  // holding torque (beta holds the gravity): the mean with the first sample's 0 would read
  // 20 N·m of disturbance (an estimate jump of 2.8 N·m at 1 kHz).
  jg::ObserverCoeffs<TypeParam> c{};
  jg::ObserverGains g{jg::ObserverKind::first_order, kGain, 0.0, 0.0};
  g.align_motor_torque = true;
  ASSERT_EQ(jg::discretize(g, kDt, c), jg::Error::ok);
  jg::ObserverState<TypeParam> st{};
  const TypeParam hold = to_scalar<TypeParam>(40.0);
  (void)jg::observer_step(c, st, TypeParam{}, TypeParam{}, hold, TypeParam{});
  double largest = 0.0;
  for (int k = 1; k < 50; ++k) {
    largest = std::max(largest, std::fabs(as_double(jg::observer_step(c, st, TypeParam{}, hold, hold, TypeParam{}))));
  }
  EXPECT_EQ(largest, 0.0);
}

TEST(TorqueMean, NonFiniteTorqueLeavesTheTorqueMeanUntouched) {
  jg::ObserverCoeffs<float> c{};
  jg::ObserverGains g{jg::ObserverKind::first_order, kGain, 0.0, 0.0};
  g.align_motor_torque = true;
  ASSERT_EQ(jg::discretize(g, kDt, c), jg::Error::ok);
  ASSERT_TRUE(c.align_motor_torque);
  jg::ObserverState<float> st{};
  (void)jg::observer_step(c, st, 0.0F, 10.0F, 0.0F, 0.0F);
  (void)jg::observer_step(c, st, 0.0F, 10.0F, 0.0F, 0.0F);
  const auto before = st;
  jg::ObserverInputStatus status;
  (void)jg::observer_step(c, st, 0.0F, std::numeric_limits<float>::infinity(), 0.0F, 0.0F, &status);
  EXPECT_EQ(status.error, jg::Error::not_finite);
  EXPECT_EQ(st.last_motor_torque, before.last_motor_torque);
  EXPECT_EQ(st.section[0], before.section[0]);
  // The next good sample balances with the mean of 10 and 10, as if the bad one never came.
  jg::ObserverState<float> twin = before;
  EXPECT_EQ(jg::observer_step(c, st, 0.0F, 10.0F, 0.0F, 0.0F), jg::observer_step(c, twin, 0.0F, 10.0F, 0.0F, 0.0F));
}

TEST(TorqueMean, Q16MidpointRoundsToNearestAndCannotOverflow) {
  using jg::q16;
  EXPECT_EQ(jg::midpoint(q16::from_raw(3), q16::from_raw(4)).raw(), 4) << "3.5 LSB: ties toward +infinity";
  EXPECT_EQ(jg::midpoint(q16::from_raw(-3), q16::from_raw(-4)).raw(), -3);
  EXPECT_EQ(jg::midpoint(q16::from_raw(-5), q16::from_raw(5)).raw(), 0);
  const q16 top = q16::from_raw(std::numeric_limits<std::int32_t>::max());
  const q16 bottom = q16::from_raw(-std::numeric_limits<std::int32_t>::max());
  EXPECT_EQ(jg::midpoint(top, top).raw(), top.raw()) << "no overflow at the top of the range";
  EXPECT_EQ(jg::midpoint(bottom, bottom).raw(), bottom.raw()) << "never INT32_MIN";
  EXPECT_EQ(jg::midpoint(top, bottom).raw(), 0);
}

}  // namespace
