// The C API computes exactly what the C++ core computes: a 3-joint chain run through
// jg_joint_outward / jg_joint_inward_and_estimate and through the templates directly, with
// the same constants, gives bit-identical messages, estimates and flags every cycle (in the
// build's scalar: float or Q16.16).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "jointguard.h"
#include "jointguard/node/joint_estimator.hpp"
#include "jointguard/scalar.hpp"

namespace {
using S = jg::Scalar;

jg_joint_config config_of(int j) {
  jg_joint_config c{};
  c.link.a_prev = j == 0 ? 0.0 : 0.3;
  c.link.alpha_prev = j == 1 ? -M_PI / 2 : 0.0;
  c.link.d = j == 0 ? 0.2 : 0.0;
  c.link.mass = 3.0 - 0.8 * j;
  c.link.com[0] = 0.15;
  c.link.com[2] = 0.01 * j;
  c.link.inertia_com[0] = 0.01;
  c.link.inertia_com[1] = 0.02;
  c.link.inertia_com[2] = 0.03;
  c.link.rotor_inertia = 0.05;
  c.link.torque_constant = 2.0;
  c.link.current_limit = 10.0;
  c.compensate_friction = true;
  c.friction = {400.0, 3.0, 0.4, 1.1, 1.4, 0.05};
  c.observer = JG_OBSERVER_FIRST_ORDER;
  c.gain_k1 = 150.0;
  c.threshold = {2.0, 0.5, 3.0, 0.03};
  c.debounce_cycles = 2;
  c.sample_time_s = 0.001;
  return c;
}

jg::JointEstimatorParams<S> cpp_params(const jg_joint_config& c) {
  jg::JointEstimatorParams<S> p{};
  jg::LinkDescription l{};
  l.a_prev = c.link.a_prev;
  l.alpha_prev = c.link.alpha_prev;
  l.d = c.link.d;
  l.mass = c.link.mass;
  std::memcpy(l.com, c.link.com, sizeof l.com);
  std::memcpy(l.inertia_com, c.link.inertia_com, sizeof l.inertia_com);
  l.rotor_inertia = c.link.rotor_inertia;
  l.torque_constant = c.link.torque_constant;
  l.current_limit = c.link.current_limit;
  EXPECT_EQ(jg::convert_link(l, p.link), jg::Error::ok);
  EXPECT_EQ(jg::discretize(jg::LuGreParams<double>{400.0, 3.0, 0.4, 1.1, 1.4, 0.05}, c.sample_time_s, p.friction), jg::Error::ok);
  EXPECT_EQ(jg::discretize(jg::ObserverGains{jg::ObserverKind::first_order, 150.0, 0.0, 0.0}, c.sample_time_s, p.observer),
            jg::Error::ok);
  jg::NumericStatus st{};
  p.threshold = {jg::convert<S>(2.0, st), jg::convert<S>(0.5, st), jg::convert<S>(3.0, st), jg::convert<S>(1.0 / 0.03, st)};
  p.debounce.cycles = 2;
  return p;
}

template <class T>
jg_scalar raw(T v) {
  if constexpr (jg::is_q_v<T>) {
    return v.raw();
  } else {
    return v;
  }
}
S from_double(double x) {
  jg::NumericStatus st{};
  return jg::convert<S>(x, st);
}

TEST(CApi, ChainIsBitIdenticalToTheCore) {
  constexpr int n = 3;
  jg_joint_params cp[n];
  jg_joint_state cs[n];
  jg::JointEstimatorParams<S> p[n];
  jg::JointEstimatorState<S> s[n]{};
  for (int j = 0; j < n; ++j) {
    const jg_joint_config c = config_of(j);
    ASSERT_EQ(jg_joint_init(&c, &cp[j], &cs[j]), JG_OK);
    p[j] = cpp_params(c);
  }
  const double g[3] = {0.0, 0.0, -9.81};
  jg_outward_message cbase{};
  ASSERT_EQ(jg_base_message(g, &cbase), JG_OK);
  jg_inward_message ctip{};
  jg_tip_message(&ctip);
  const auto base = jg::base_message(jg::Vec3<S>{S{}, S{}, from_double(-9.81)});
  const auto tip = jg::tip_message<S>();
  int flagged_cycles = 0;
  for (int k = 0; k < 3000; ++k) {
    const double t = 1e-3 * k;
    S q[n], dq[n], tau[n];
    for (int j = 0; j < n; ++j) {
      q[j] = from_double(0.5 * std::sin(1.3 * t + j));
      dq[j] = from_double(0.65 * std::cos(1.3 * t + j));
      // A motor torque that does not match the model, with a step at 2 s: the estimates
      // move and the detectors flag.
      tau[j] = from_double(3.0 * std::sin(0.7 * t) + (t > 2.0 ? 8.0 : 0.0));
    }
    jg_outward_message cdown[n + 1];
    jg::OutwardMessage<S> down[n + 1];
    cdown[0] = cbase;
    down[0] = base;
    for (int j = 0; j < n; ++j) {
      ASSERT_EQ(jg_joint_outward(&cp[j], &cs[j], raw(q[j]), raw(dq[j]), &cdown[j], &cdown[j + 1]), JG_OK);
      ASSERT_EQ(jg::joint_outward(p[j], s[j], q[j], dq[j], down[j], down[j + 1]), jg::Error::ok);
      ASSERT_EQ(cdown[j + 1].origin_velocity[1], raw(down[j + 1].origin_velocity.y));
    }
    jg_inward_message cup[n + 1];
    jg::InwardMessage<S> up[n + 1];
    cup[n] = ctip;
    up[n] = tip;
    for (int j = n - 1; j >= 0; --j) {
      const bool cf = jg_joint_inward_and_estimate(&cp[j], &cs[j], raw(dq[j]), raw(tau[j]), &cup[j + 1], &cup[j]);
      const bool f = jg::joint_inward_and_estimate(p[j], s[j], dq[j], tau[j], up[j + 1], up[j]);
      ASSERT_EQ(cf, f) << "cycle " << k << " joint " << j + 1;
      ASSERT_EQ(jg_joint_external_torque(&cs[j]), raw(s[j].external_torque)) << "cycle " << k << " joint " << j + 1;
      ASSERT_EQ(jg_joint_friction_torque(&cs[j]), raw(s[j].friction_torque));
      ASSERT_EQ(cup[j].angular_momentum[2], raw(up[j].angular_momentum.z));
      ASSERT_EQ(cup[j].mass, raw(up[j].mass));
      flagged_cycles += f ? 1 : 0;
    }
  }
  EXPECT_GT(flagged_cycles, 0);  // the run exercised the detector, not only the recursion
}

TEST(CApi, StorageHoldsTheObjects) {
  EXPECT_LE(sizeof(jg::JointEstimatorParams<S>), sizeof(jg_joint_params));
  EXPECT_LE(sizeof(jg::JointEstimatorState<S>), sizeof(jg_joint_state));
  EXPECT_STREQ(jg_scalar_name(), jg::kScalarName);
}
}  // namespace
