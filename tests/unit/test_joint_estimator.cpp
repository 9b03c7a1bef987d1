// One joint's cycle rejects non-finite joint states and neighbour messages: the last good
// outputs are kept and the fault is counted; nothing reaches the estimator's state.
#include <gtest/gtest.h>

#include <limits>

#include "jointguard/node/joint_estimator.hpp"

namespace {
TEST(JointEstimator, RejectsNonFiniteInputsAndKeepsLastGoodOutput) {
  jg::JointEstimatorParams<float> p{};
  jg::LinkDescription d;
  d.mass = 2.0;
  d.com[0] = 0.2;
  d.inertia_com[2] = 0.03;
  ASSERT_EQ(jg::convert_link(d, p.link), jg::Error::ok);
  ASSERT_EQ(jg::discretize(jg::ObserverGains{}, 0.001, p.observer), jg::Error::ok);
  p.compensate_friction = false;
  p.threshold = {5.0F, 0.0F, 0.0F, 0.0F};
  jg::JointEstimatorState<float> s{};
  jg::OutwardMessage<float> parent{}, child_out{};
  parent.gravity.z = -9.81F;
  jg::InwardMessage<float> child{}, up{};
  for (int k = 0; k < 50; ++k) {
    ASSERT_EQ(jg::joint_outward(p, s, 0.3F, 0.2F, parent, child_out), jg::Error::ok);
    (void)jg::joint_inward_and_estimate(p, s, 0.2F, 3.0F, child, up);
  }
  const auto good = s;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(jg::joint_outward(p, s, nan, 0.2F, parent, child_out), jg::Error::not_finite);
  (void)jg::joint_inward_and_estimate(p, s, 0.2F, 3.0F, child, up);
  EXPECT_EQ(s.external_torque, good.external_torque);
  EXPECT_EQ(s.observer.section[0], good.observer.section[0]);
  EXPECT_EQ(up.mass, good.last_to_parent.mass);
  jg::InwardMessage<float> bad = child;
  bad.linear_momentum.y = std::numeric_limits<float>::infinity();
  ASSERT_EQ(jg::joint_outward(p, s, 0.3F, 0.2F, parent, child_out), jg::Error::ok);
  jg::ObserverInputStatus status;
  (void)jg::joint_inward_and_estimate(p, s, 0.2F, 3.0F, bad, up, &status);
  EXPECT_EQ(status.error, jg::Error::not_finite);
  EXPECT_EQ(s.observer.section[0], good.observer.section[0]);
  EXPECT_EQ(s.rejected_cycles, 2U);
  ASSERT_EQ(jg::joint_outward(p, s, 0.3F, 0.2F, parent, child_out), jg::Error::ok);
  (void)jg::joint_inward_and_estimate(p, s, 0.2F, 3.0F, child, up);
  EXPECT_FALSE(s.input_fault);
}
}  // namespace

namespace {
TEST(LinkConstants, FoldedOnTheHostAndBounded) {
  jg::LinkDescription d;
  d.alpha_prev = 1.5707963267948966;
  d.a_prev = 0.3;
  d.d = 0.1;
  d.mass = 2.0;
  d.com[0] = 0.2;
  d.com[2] = 0.05;
  d.inertia_com[0] = 0.01;
  d.inertia_com[1] = 0.02;
  d.inertia_com[2] = 0.03;
  jg::LinkConstants<double> c{};
  ASSERT_EQ(jg::convert_link(d, c), jg::Error::ok);
  // Parallel-axis theorem about O_i, first moment m c, origin (a, -sin(alpha) d, cos(alpha) d).
  EXPECT_NEAR(c.inertia_origin.xx, 0.01 + 2.0 * 0.05 * 0.05, 1e-15);
  EXPECT_NEAR(c.inertia_origin.yy, 0.02 + 2.0 * (0.2 * 0.2 + 0.05 * 0.05), 1e-15);
  EXPECT_NEAR(c.inertia_origin.zz, 0.03 + 2.0 * 0.2 * 0.2, 1e-15);
  EXPECT_NEAR(c.inertia_origin.xz, -2.0 * 0.2 * 0.05, 1e-15);
  EXPECT_NEAR(c.first_moment.x, 0.4, 1e-15);
  EXPECT_NEAR(c.origin_in_parent.y, -0.1, 1e-15);
  EXPECT_NEAR(c.origin_in_parent.z, 0.0, 1e-15);
  EXPECT_NEAR(c.a_sin_alpha_prev, 0.3, 1e-15);
  EXPECT_NEAR(c.d_sin_alpha_prev, 0.1, 1e-15);
  // The negated copies the fixed-point steps multiply by are exact negations, bit for bit.
  jg::LinkConstants<jg::q16> cq{};
  ASSERT_EQ(jg::convert_link(d, cq), jg::Error::ok);
  EXPECT_EQ(cq.neg_sin_alpha_prev.raw(), -cq.sin_alpha_prev.raw());
  EXPECT_EQ(cq.neg_d.raw(), -cq.d.raw());
  EXPECT_EQ(cq.neg_a_cos_alpha_prev.raw(), -cq.a_cos_alpha_prev.raw());
  EXPECT_EQ(cq.neg_a_sin_alpha_prev.raw(), -cq.a_sin_alpha_prev.raw());
  EXPECT_EQ(cq.neg_first_moment.x.raw(), -cq.first_moment.x.raw());
  EXPECT_EQ(cq.neg_first_moment.z.raw(), -cq.first_moment.z.raw());
  EXPECT_EQ(cq.neg_origin_in_parent.y.raw(), -cq.origin_in_parent.y.raw());
  EXPECT_EQ(cq.neg_origin_in_parent.z.raw(), -cq.origin_in_parent.z.raw());
  EXPECT_EQ(cq.neg_origin_in_parent.x.raw(), -cq.origin_in_parent.x.raw());
  EXPECT_EQ(c.neg_d, -c.d);
  // Beyond kMaxLinkConstant the fused 64-bit sums of the Q16.16 recursion could overflow:
  // refused for every scalar, `out` untouched.
  d.mass = 5000.0;
  jg::LinkConstants<jg::q16> q{};
  EXPECT_EQ(jg::convert_link(d, q), jg::Error::out_of_range);
  EXPECT_EQ(jg::convert_link(d, c), jg::Error::out_of_range);
  EXPECT_NEAR(c.first_moment.x, 0.4, 1e-15);
}
}  // namespace
