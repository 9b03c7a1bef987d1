// The C API computes exactly what the C++ core computes: a 3-joint chain run through
// jg_joint_outward / jg_joint_inward_and_estimate and through the templates directly, with
// the same constants, gives bit-identical messages, estimates and flags every cycle (in the
// build's scalar: float or Q16.16).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
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

jg::JointEstimatorParams<S> cpp_params(const jg_joint_config& c, const jg_joint_options* o = nullptr) {
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
  EXPECT_EQ(jg::discretize(jg::ObserverGains{jg::ObserverKind::first_order, 150.0, 0.0, 0.0,
                                             o != nullptr && o->align_motor_torque},
                           c.sample_time_s, p.observer),
            jg::Error::ok);
  jg::NumericStatus st{};
  p.threshold = {jg::convert<S>(2.0, st), jg::convert<S>(0.5, st), jg::convert<S>(3.0, st), jg::convert<S>(1.0 / 0.03, st)};
  p.debounce.cycles = 2;
  if (o != nullptr) {  // as the host converts them (eval/joint_params.hpp, evaluate.cpp hold_params)
    const auto samples = [&c](double sec) { return static_cast<std::uint16_t>(std::ceil(sec / c.sample_time_s - 1e-9)); };
    p.hold.change_threshold = jg::convert<S>(o->hold_change_threshold, st);
    p.hold.settle_cycles = samples(o->hold_settle_s);
    p.hold.reference_cycles = samples(o->hold_reference_s);
    p.hold.inv_reference_cycles = jg::convert<S>(1.0 / p.hold.reference_cycles, st);
    p.holding_velocity_deadband = jg::convert<S>(o->holding_velocity_deadband, st);
  }
  EXPECT_TRUE(st.ok());
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

/// The chain through the C API (with `options` when given, holding in every second
/// half-second) and through the core; returns the cycles flagged (-1 at the first
/// difference), and in `armed_cycles` the joint-cycles whose holding detector was armed.
int run_chain(const jg_joint_options* options, int* armed_cycles = nullptr) {
  constexpr int n = 3;
  jg_joint_params cp[n];
  jg_joint_state cs[n];
  jg::JointEstimatorParams<S> p[n];
  jg::JointEstimatorState<S> s[n]{};
  for (int j = 0; j < n; ++j) {
    const jg_joint_config c = config_of(j);
    EXPECT_EQ(options == nullptr ? jg_joint_init(&c, &cp[j], &cs[j]) : jg_joint_init_options(&c, options, &cp[j], &cs[j]),
              JG_OK);
    p[j] = cpp_params(c, options);
  }
  const double g[3] = {0.0, 0.0, -9.81};
  jg_outward_message cbase{};
  EXPECT_EQ(jg_base_message(g, &cbase), JG_OK);
  jg_inward_message ctip{};
  jg_tip_message(&ctip);
  const auto base = jg::base_message(jg::Vec3<S>{S{}, S{}, from_double(-9.81)});
  const auto tip = jg::tip_message<S>();
  int flagged_cycles = 0;
  for (int k = 0; k < 3000; ++k) {
    const double t = 1e-3 * k;
    // Held: the arm at rest where it was at 0.5 s and 1.5 s (its velocity one dither count).
    const bool holding = options != nullptr && (k / 500) % 2 == 1;
    const double tm = holding ? 0.5 * (k / 500) : t;
    S q[n], dq[n], tau[n];
    for (int j = 0; j < n; ++j) {
      q[j] = from_double(0.5 * std::sin(1.3 * tm + j));
      dq[j] = from_double(holding ? (k % 3 == 0 ? 0.004 : 0.0) : 0.65 * std::cos(1.3 * t + j));
      // A motor torque that does not match the model, with a step at 2 s: the estimates
      // move and the detectors flag.
      tau[j] = from_double(3.0 * std::sin(0.7 * t) + (t > 2.0 ? 8.0 : 0.0));
    }
    jg_outward_message cdown[n + 1];
    jg::OutwardMessage<S> down[n + 1];
    cdown[0] = cbase;
    down[0] = base;
    for (int j = 0; j < n; ++j) {
      const jg_error ce = options == nullptr
                              ? jg_joint_outward(&cp[j], &cs[j], raw(q[j]), raw(dq[j]), &cdown[j], &cdown[j + 1])
                              : jg_joint_outward_holding(&cp[j], &cs[j], raw(q[j]), raw(dq[j]), holding, &cdown[j], &cdown[j + 1]);
      EXPECT_EQ(ce, JG_OK);
      EXPECT_EQ(jg::joint_outward(p[j], s[j], q[j], dq[j], holding, down[j], down[j + 1]), jg::Error::ok);
      EXPECT_EQ(cdown[j + 1].origin_velocity[1], raw(down[j + 1].origin_velocity.y));
    }
    jg_inward_message cup[n + 1];
    jg::InwardMessage<S> up[n + 1];
    cup[n] = ctip;
    up[n] = tip;
    for (int j = n - 1; j >= 0; --j) {
      const bool cf =
          options == nullptr
              ? jg_joint_inward_and_estimate(&cp[j], &cs[j], raw(dq[j]), raw(tau[j]), &cup[j + 1], &cup[j])
              : jg_joint_inward_and_estimate_holding(&cp[j], &cs[j], raw(dq[j]), raw(tau[j]), holding, &cup[j + 1], &cup[j]);
      const bool f = jg::joint_inward_and_estimate(p[j], s[j], dq[j], tau[j], holding, up[j + 1], up[j]);
      EXPECT_EQ(cf, f) << "cycle " << k << " joint " << j + 1;
      EXPECT_EQ(jg_joint_external_torque(&cs[j]), raw(s[j].external_torque)) << "cycle " << k << " joint " << j + 1;
      EXPECT_EQ(jg_joint_friction_torque(&cs[j]), raw(s[j].friction_torque));
      EXPECT_EQ(cup[j].angular_momentum[2], raw(up[j].angular_momentum.z));
      EXPECT_EQ(cup[j].mass, raw(up[j].mass));
      if (cf != f || jg_joint_external_torque(&cs[j]) != raw(s[j].external_torque)) {
        return -1;  // one report, not 3000
      }
      flagged_cycles += f ? 1 : 0;
      if (armed_cycles != nullptr && s[j].hold.armed) {
        ++*armed_cycles;
      }
    }
  }
  return flagged_cycles;
}

TEST(CApi, ChainIsBitIdenticalToTheCore) {
  EXPECT_GT(run_chain(nullptr), 0);  // the run exercised the detector, not only the recursion
}

TEST(CApi, HoldingAndTorqueMeanAreBitIdenticalToTheCore) {
  // The holding detector armed in each hold (150 + 16 cycles), the dither deadband and the
  // observer's torque mean on: the C API's options give exactly the core's parameters.
  jg_joint_options o{};
  o.hold_change_threshold = 0.4;
  o.hold_settle_s = 0.15;
  o.hold_reference_s = 0.016;
  o.holding_velocity_deadband = 0.005;
  o.align_motor_torque = true;
  int armed = 0;
  EXPECT_GT(run_chain(&o, &armed), 0);
  // Armed after the 166th held cycle (150 settle + 16 reference) to the hold end, in each of the three holds (500
  // cycles each), on every joint: (500 - 165) x 3 x 3.
  EXPECT_EQ(armed, (500 - 165) * 3 * 3);
}

TEST(CApi, OptionsAreCheckedAndLeaveTheStorageUntouched) {
  const jg_joint_config c = config_of(1);
  jg_joint_params p;
  jg_joint_state s;
  std::memset(&p, 0xA5, sizeof p);
  const jg_joint_params before = p;
  jg_joint_options o{};
  o.hold_settle_s = -0.1;
  EXPECT_EQ(jg_joint_init_options(&c, &o, &p, &s), JG_INVALID_PARAMETER);
  o = jg_joint_options{};
  o.holding_velocity_deadband = std::nan("");
  EXPECT_EQ(jg_joint_init_options(&c, &o, &p, &s), JG_NOT_FINITE);
  o = jg_joint_options{};
  o.hold_reference_s = 70.0;  // 70,000 samples at 1 kHz: over the counters' 65535
  EXPECT_EQ(jg_joint_init_options(&c, &o, &p, &s), JG_OUT_OF_RANGE);
  EXPECT_EQ(std::memcmp(&p, &before, sizeof p), 0);
  o = jg_joint_options{};  // all zero: what jg_joint_init does (the defaults' hold is off)
  EXPECT_EQ(jg_joint_init_options(&c, &o, &p, &s), JG_OK);
}

TEST(CApi, StorageHoldsTheObjects) {
  EXPECT_LE(sizeof(jg::JointEstimatorParams<S>), sizeof(jg_joint_params));
  EXPECT_LE(sizeof(jg::JointEstimatorState<S>), sizeof(jg_joint_state));
  EXPECT_STREQ(jg_scalar_name(), jg::kScalarName);
}
}  // namespace
