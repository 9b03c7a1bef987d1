// LuGre friction in float and Q16.16 against the double reference; the model's own
// behaviour (steady state, reversal, stick-slip, presliding hysteresis); bad parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "jointguard/friction/lugre.hpp"
#include "jointguard/friction/stribeck.hpp"
#include "models/paper_friction.hpp"
#include "motion/excitation.hpp"

namespace {
using jg::Error;
using jg::LuGreDiscrete;
using jg::LuGreParams;
using jg::LuGreState;
using jg::q16;

template <class S>
LuGreDiscrete<S> coeffs(const LuGreParams<double>& p, double dt) {
  LuGreDiscrete<S> d{};
  EXPECT_EQ(jg::discretize(p, dt, d), Error::ok);
  return d;
}

template <class S>
S to_s(double x) {
  jg::NumericStatus st;
  return jg::convert<S>(x, st);
}

template <class S>
class LuGreTyped : public ::testing::Test {};
using Scalars = ::testing::Types<float, q16>;
TYPED_TEST_SUITE(LuGreTyped, Scalars);

// Worst |S - double| over the paper's excitation, per parameter set and sample time,
// (a) against double on the exact velocity, (b) against double fed the velocity as the
// scalar represents it (the arithmetic alone). Q16.16's total error is dominated by the
// velocity's quantisation (LSB 1.5e-5 rad/s times sigma0 dT of bristle gain per step).
// Bounds (docs/fixed-point.md lists the measured values this test prints):
//   float: total 1e-4 N·m;  Q16.16: total 0.02 N·m, arithmetic 5e-4 N·m.
TYPED_TEST(LuGreTyped, MatchesDoubleOnPaperTrajectory) {
  using S = TypeParam;
  constexpr bool kFloat = std::is_same_v<S, float>;
  const double bound_total = kFloat ? 1e-4 : 0.02;
  const double bound_arith = kFloat ? 1e-4 : 5e-4;
  const jg::sim::PaperExcitation traj;
  for (const double dt : {0.008, 0.001}) {
    for (std::size_t j = 0; j < jg::sim::kPaperTable1.size(); ++j) {
      const auto& p = jg::sim::kPaperTable1[j];
      const auto cd = coeffs<double>(p, dt);
      const auto cs = coeffs<S>(p, dt);
      LuGreState<double> sd{}, sd_quantised{};
      LuGreState<S> ss{};
      double worst = 0.0, worst_arith = 0.0;
      for (long k = 0; static_cast<double>(k) * dt <= traj.duration(); ++k) {
        const double w = traj.at(static_cast<double>(k) * dt).dq;
        const S ws = to_s<S>(w);
        const double ref = jg::lugre_step(cd, sd, w);
        const double ref_quantised = jg::lugre_step(cd, sd_quantised, jg::to_double(ws));
        const double got = jg::to_double(jg::lugre_step(cs, ss, ws));
        worst = std::max(worst, std::fabs(got - ref));
        worst_arith = std::max(worst_arith, std::fabs(got - ref_quantised));
      }
      std::printf("%s joint %zu dT %.3f: worst |error| %.3e N·m, arithmetic alone %.3e N·m\n",
                  kFloat ? "float" : "Q16.16", j + 1, dt, worst, worst_arith);
      EXPECT_LE(worst, bound_total) << "joint " << j + 1 << " dT " << dt;
      EXPECT_LE(worst_arith, bound_arith) << "joint " << j + 1 << " dT " << dt;
    }
  }
}

TYPED_TEST(LuGreTyped, SteadySlidingEqualsStribeckCurve) {
  using S = TypeParam;
  const auto& p = jg::sim::kPaperTable1[1];
  const auto c = coeffs<S>(p, 0.001);
  const jg::StribeckParams<S> st{c.curve, c.viscous};
  for (const double w : {-1.0, -0.2, -0.05, 0.02, 0.1, 0.5, 2.0}) {
    LuGreState<S> s{};
    S tau{};
    for (int k = 0; k < 3000; ++k) {
      tau = jg::lugre_step(c, s, to_s<S>(w));
    }
    const double expected = p.tau_c + (p.tau_s - p.tau_c) * std::exp(-(w / p.w_s) * (w / p.w_s));
    const double expected_total = (w > 0 ? expected : -expected) + p.sigma2 * w;
    EXPECT_NEAR(jg::to_double(tau), expected_total, 2e-3) << "w " << w;
    EXPECT_NEAR(jg::to_double(jg::stribeck_torque(st, to_s<S>(w))), expected_total, 2e-3) << "w " << w;
  }
}

TYPED_TEST(LuGreTyped, VelocityReversalIsBoundedAndFlipsSign) {
  using S = TypeParam;
  const auto& p = jg::sim::kPaperTable1[0];
  const double dt = 0.001;
  const auto c = coeffs<S>(p, dt);
  LuGreState<S> s{};
  const double level_max = std::max(p.tau_c, p.tau_s);
  double before = 0.0, after = 0.0;
  for (int k = 0; k < 2000; ++k) {  // 0.5 rad/s, then a reversal ramp over 20 ms
    const double t = k * dt;
    const double w = t < 1.0 ? 0.5 : std::max(-0.5, 0.5 - (t - 1.0) * 50.0);
    const S tau = jg::lugre_step(c, s, to_s<S>(w));
    ASSERT_LE(std::fabs(jg::to_double(s.bristle_torque)), level_max + 1e-3) << "bristle bound, t " << t;
    if (k == 999) before = jg::to_double(tau);
    if (k == 1999) after = jg::to_double(tau);
  }
  EXPECT_NEAR(before, p.tau_c + p.sigma2 * 0.5, 0.02);
  EXPECT_NEAR(after, -(p.tau_c + p.sigma2 * 0.5), 0.02);
}

// A mass dragged through a spring over a LuGre contact with tau_s > tau_c sticks and
// slips (the classic LuGre benchmark). Mass dynamics in double, friction in S.
TYPED_TEST(LuGreTyped, StickSlipAppearsWithStiction) {
  using S = TypeParam;
  const LuGreParams<double> p{1e5, 300.0, 0.4, 1.0, 1.5, 0.01};
  const double dt = 0.0005, mass = 1.0, spring = 10.0, drive = 0.1;
  const auto c = coeffs<S>(p, dt);
  LuGreState<S> s{};
  double x = 0.0, v = 0.0;
  int slips = 0;
  bool sticking = true;
  double stuck_time = 0.0;
  for (int k = 0; k < static_cast<int>(20.0 / dt); ++k) {
    const double t = k * dt;
    const double f = jg::to_double(jg::lugre_step(c, s, to_s<S>(v)));
    const double a = (spring * (drive * t - x) - f) / mass;
    v += a * dt;  // semi-implicit Euler
    x += v * dt;
    const bool now_sticking = std::fabs(v) < 0.005;
    if (sticking && !now_sticking) ++slips;
    if (now_sticking && t > 2.0) stuck_time += dt;
    sticking = now_sticking;
  }
  EXPECT_GE(slips, 5) << "expected repeated stick-slip";
  EXPECT_GT(stuck_time, 3.0) << "expected long stick phases";
}

// Small motion: the bristles act as a spring of stiffness sigma0 (presliding). Larger
// motion: a hysteresis loop between the two sliding levels.
TYPED_TEST(LuGreTyped, PreslidingSpringAndHysteresis) {
  using S = TypeParam;
  const auto& p = jg::sim::kPaperTable1[2];
  const double dt = 0.0002, freq = 1.0;
  const auto c = coeffs<S>(p, dt);
  auto loop = [&](double amplitude, double& slope, double& width) {
    LuGreState<S> s{};
    std::vector<double> xs, taus;
    const int n = static_cast<int>(3.0 / freq / dt);
    for (int k = 0; k < n; ++k) {
      const double t = k * dt;
      const double x = amplitude * std::sin(2 * M_PI * freq * t);
      const double w = amplitude * 2 * M_PI * freq * std::cos(2 * M_PI * freq * t);
      const double tau = jg::to_double(jg::lugre_step(c, s, to_s<S>(w)));
      if (t >= 2.0 / freq) {  // last period
        xs.push_back(x);
        taus.push_back(tau);
      }
    }
    // slope between the extremes, and the loop's width at x ~ 0
    std::size_t imax = 0, imin = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
      if (xs[i] > xs[imax]) imax = i;
      if (xs[i] < xs[imin]) imin = i;
    }
    slope = (taus[imax] - taus[imin]) / (xs[imax] - xs[imin]);
    double up = 0.0, down = 0.0;
    for (std::size_t i = 1; i < xs.size(); ++i) {
      if (xs[i - 1] < 0.0 && xs[i] >= 0.0) up = taus[i];
      if (xs[i - 1] > 0.0 && xs[i] <= 0.0) down = taus[i];
    }
    width = up - down;
  };
  double slope = 0.0, width = 0.0;
  loop(0.1 * p.tau_s / p.sigma0, slope, width);
  EXPECT_NEAR(slope / p.sigma0, 1.0, 0.15) << "presliding stiffness ~ sigma0";
  EXPECT_LT(std::fabs(width), 0.1 * p.tau_s) << "thin loop in presliding";
  loop(20.0 * p.tau_s / p.sigma0, slope, width);
  EXPECT_GT(width, 1.5 * std::min(p.tau_c, p.tau_s)) << "hysteresis loop when sliding";
}

TEST(LuGreParams, BadParametersAreRefusedAndOutputUntouched) {
  LuGreDiscrete<q16> out{};
  out.viscous = q16::from_double(42.0);
  LuGreParams<double> p = jg::sim::kPaperTable1[0];
  p.sigma0 = std::nan("");
  EXPECT_EQ(jg::discretize(p, 0.001, out), Error::not_finite);
  p = jg::sim::kPaperTable1[0];
  p.tau_c = -1.0;
  EXPECT_EQ(jg::discretize(p, 0.001, out), Error::invalid_parameter);
  p = jg::sim::kPaperTable1[0];
  EXPECT_EQ(jg::discretize(p, 0.0, out), Error::invalid_parameter);
  p.sigma0 = 1e8;  // sigma0 dT = 1e5 does not fit Q16.16
  EXPECT_EQ(jg::discretize(p, 0.001, out), Error::out_of_range);
  p = jg::sim::kPaperTable1[0];
  p.w_s = 1e-6;  // 1/w_s = 1e6 does not fit Q16.16
  EXPECT_EQ(jg::discretize(p, 0.001, out), Error::out_of_range);
  EXPECT_EQ(out.viscous.raw(), q16::from_double(42.0).raw());
  LuGreDiscrete<float> f{};
  EXPECT_EQ(jg::discretize(p, 0.001, f), Error::ok) << "float has the range";
}
}  // namespace
