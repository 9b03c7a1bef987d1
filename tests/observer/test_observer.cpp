// Observers: discrete step and frequency responses against the continuous transfer
// functions, tracking of a known disturbance on a simulated joint, Q16.16 against double,
// bounded state, rejected inputs.
#include <gtest/gtest.h>

#include <complex>
#include <random>

#include "jointguard/observer/momentum_observer.hpp"
#include "tuning/observer_tuning.hpp"

namespace {
using jg::ObserverGains;
using jg::ObserverKind;

const ObserverGains kPresets[] = {{ObserverKind::first_order, 60.0, 0.0, 0.0},
                                  {ObserverKind::lowpass2, 60.0, 120.0, 0.0},
                                  {ObserverKind::paper_bandpass, 60.0, 2.0, 0.0},
                                  {ObserverKind::paper_improved, 60.0, 120.0, 60.0}};

// Continuous unit step response of (b1 s + b0)/((s+K1)(s+K2)) (or K/(s+K)).
double continuous_step(const ObserverGains& g, double t) {
  const auto tf = jg::transfer_of(g);
  if (tf.order == 1) return 1.0 - std::exp(-tf.pole1 * t);
  const double k1 = tf.pole1, k2 = tf.pole2;
  const double a1 = (tf.b0 - tf.b1 * k1) / (k2 - k1), a2 = (tf.b1 * k2 - tf.b0) / (k2 - k1);
  return a1 / k1 * (1.0 - std::exp(-k1 * t)) + a2 / k2 * (1.0 - std::exp(-k2 * t));
}

std::complex<double> continuous_response(const ObserverGains& g, double w) {
  const auto tf = jg::transfer_of(g);
  const std::complex<double> s(0.0, w);
  if (tf.order == 1) return tf.pole1 / (s + tf.pole1);
  return (tf.b1 * s + tf.b0) / ((s + tf.pole1) * (s + tf.pole2));
}

TEST(Observer, StepResponseMatchesContinuousAtTheSamples) {
  for (const double dt : {0.001, 0.008}) {
    for (const auto& g : kPresets) {
      jg::ObserverCoeffs<double> c{};
      ASSERT_EQ(jg::discretize(g, dt, c), jg::Error::ok);
      jg::ObserverState<double> st{};
      (void)jg::observer_step(c, st, 0.0, 0.0, 0.0, 0.0);
      double worst = 0.0;
      for (int k = 0; k < static_cast<int>(2.0 / dt); ++k) {
        // The unit disturbance step through beta (d = tau_m - beta - ...): the filter D(s)
        // alone, whichever motor torque the balance takes (its mean: test_torque_mean.cpp).
        const double y = jg::observer_step(c, st, 0.0, 0.0, -1.0, 0.0);
        worst = std::max(worst, std::fabs(y - continuous_step(g, (k + 1) * dt)));
      }
      std::printf("%-15s dT %.3f: worst step-response error %.2e\n", jg::to_string(g.kind), dt, worst);
      EXPECT_LT(worst, 1e-9) << jg::to_string(g.kind);
    }
  }
}

TEST(Observer, FrequencyResponseMatchesContinuousBelowATenthOfNyquist) {
  const double dt = 0.001;
  for (const auto& g : kPresets) {
    jg::ObserverCoeffs<double> c{};
    ASSERT_EQ(jg::discretize(g, dt, c), jg::Error::ok);
    for (const double f : {0.5, 2.0, 10.0, 30.0, 50.0}) {
      // Drive with a sine of the disturbance, measure amplitude after settling.
      jg::ObserverState<double> st{};
      (void)jg::observer_step(c, st, 0.0, 0.0, 0.0, 0.0);
      const double w = 2.0 * M_PI * f;
      double amp = 0.0;
      const int n = static_cast<int>(std::max(6.0, 20.0 / f) / dt);
      for (int k = 0; k < n; ++k) {
        const double y = jg::observer_step(c, st, 0.0, std::sin(w * k * dt), 0.0, 0.0);
        if (k > n / 2) amp = std::max(amp, std::fabs(y));
      }
      const double expected = std::abs(continuous_response(g, w));
      EXPECT_NEAR(amp, expected, 0.03 * std::max(expected, 0.05)) << jg::to_string(g.kind) << " at " << f << " Hz";
    }
  }
}

// A joint p' = tau_m - beta - d integrated finely; the observer sees p at 1 kHz.
TEST(Observer, FollowsAKnownDisturbanceAndQ16StaysCloseToDouble) {
  const double dt = 0.001, inertia = 1.2;
  for (const auto& g : kPresets) {
    jg::ObserverCoeffs<double> cd{};
    jg::ObserverCoeffs<jg::q16> cq{};
    ASSERT_EQ(jg::discretize(g, dt, cd), jg::Error::ok);
    ASSERT_EQ(jg::discretize(g, dt, cq), jg::Error::ok);
    jg::ObserverState<double> sd{};
    jg::ObserverState<jg::q16> sq{};
    double velocity = 0.0, worst_q = 0.0, tail_sum = 0.0, max_state = 0.0;
    int tail_n = 0;
    jg::NumericStatus ns;
    for (int k = 0; k < 60000; ++k) {  // 60 s
      const double t = k * dt;
      const double tau_m = 20.0 * std::sin(2.0 * M_PI * 0.3 * t);
      const double beta = 15.0 * std::cos(0.7 * t);
      const double d = (t > 30.0 ? 8.0 : 0.0) + 2.0 * std::sin(2.0 * M_PI * 0.1 * t);
      for (int sub = 0; sub < 10; ++sub) velocity += (tau_m - beta - d) / inertia * dt / 10.0;
      const double p = inertia * velocity;
      const double rd = jg::observer_step(cd, sd, p, tau_m, beta, 0.0);
      const double rq = jg::observer_step(cq, sq, jg::q16::from_double(p, ns), jg::q16::from_double(tau_m, ns),
                                          jg::q16::from_double(beta, ns), jg::q16{})
                            .to_double();
      worst_q = std::max(worst_q, std::fabs(rq - rd));
      max_state = std::max({max_state, std::fabs(sd.section[0]), std::fabs(sd.section[1])});
      if (t > 50.0) {
        tail_sum += rd;
        ++tail_n;
      }
      if (t > 45.0 && g.kind != ObserverKind::paper_bandpass) {
        const double dc = jg::transfer_of(g).b0 / (jg::transfer_of(g).pole1 * (jg::transfer_of(g).order == 2 ? jg::transfer_of(g).pole2 : 1.0));
        ASSERT_NEAR(rd, dc * d, 0.3) << jg::to_string(g.kind) << " t " << t;
      }
    }
    std::printf("%-15s: Q16.16 worst |error| vs double over 60 s %.2e N·m; largest state %.1f\n", jg::to_string(g.kind),
                worst_q, max_state);
    EXPECT_LT(worst_q, 5e-3);
    EXPECT_LT(max_state, 1000.0) << "states stay bounded";
    if (g.kind == ObserverKind::paper_bandpass) {
      EXPECT_LT(std::fabs(tail_sum / tail_n), 0.1) << "the band-pass lets the sustained 8 N·m step fade";
    }
    EXPECT_TRUE(ns.ok());
  }
}

TEST(Observer, NonFiniteInputsAreRejectedAndStateKept) {
  jg::ObserverCoeffs<float> c{};
  ASSERT_EQ(jg::discretize(kPresets[1], 0.001, c), jg::Error::ok);
  jg::ObserverState<float> st{};
  (void)jg::observer_step(c, st, 0.0F, 0.0F, 0.0F, 0.0F);
  const float good = jg::observer_step(c, st, 0.0F, 5.0F, 0.0F, 0.0F);
  const auto before = st;
  jg::ObserverInputStatus status;
  const float r = jg::observer_step(c, st, 0.0F, std::numeric_limits<float>::quiet_NaN(), 0.0F, 0.0F, &status);
  EXPECT_EQ(status.error, jg::Error::not_finite);
  EXPECT_EQ(r, good);
  EXPECT_EQ(st.section[0], before.section[0]);
  EXPECT_EQ(st.section[1], before.section[1]);
  EXPECT_EQ(st.last_motor_torque, before.last_motor_torque) << "the torque mean's state is kept too";
  EXPECT_EQ(st.last_momentum, before.last_momentum);
  jg::ObserverCoeffs<jg::q16> q{};
  EXPECT_EQ(jg::discretize(ObserverGains{ObserverKind::first_order, -5.0, 0, 0}, 0.001, q), jg::Error::invalid_parameter);
  EXPECT_EQ(jg::discretize(kPresets[0], 0.0, q), jg::Error::invalid_parameter);
}

TEST(Tuning, FiguresAndEqualNoiseGains) {
  for (const auto& g : kPresets) {
    const auto f = jg::tuning::analyse(g, 0.001);
    std::printf("%-15s delay50 %.1f ms delay90 %.1f ms overshoot %.2f dc %.2f noise gain %.3f\n", jg::to_string(g.kind),
                1e3 * f.delay50_s, 1e3 * f.delay90_s, f.overshoot, f.dc_gain, f.noise_gain);
    EXPECT_GT(f.delay50_s, 0.0);
  }
  const auto f1 = jg::tuning::analyse(kPresets[0], 0.001);
  EXPECT_NEAR(f1.delay50_s, std::log(2.0) / 60.0, 0.0015) << "first order: ln2 / K";
  const auto g = jg::tuning::gains_for_noise(kPresets[1], 0.001, 0.5, 0.05);
  EXPECT_NEAR(jg::tuning::analyse(g, 0.001).noise_gain * 0.5, 0.05, 1e-6);
}
}  // namespace
