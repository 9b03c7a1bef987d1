// Second, independent cross-check of the momentum recursion against Orocos KDL
// (ChainDynParam: JntToMass, JntToGravity, JntToCoriolis), on both shipped models:
// p = M dq (+ rotor) and beta = g - C^T dq with C^T dq = M' dq - C dq (M' along dq by
// central differences of KDL's mass matrix).
#include <gtest/gtest.h>

#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <random>

#include "jointguard/dynamics/momentum_recursion.hpp"
#include "robot/robot_model.hpp"

namespace {

// Modified D-H as a KDL chain: a fixed segment RotX(alpha_prev) TransX(a_prev), then a
// revolute segment about z whose tip is TransZ(d): the tip frame is the link frame, in which
// KDL expresses the segment's inertia.
KDL::Chain chain_of(const jg::robot::RobotModel& m) {
  KDL::Chain chain;
  for (const auto& j : m.joints) {
    const auto& l = j.link;
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::None),
                                  KDL::Frame(KDL::Rotation::RotX(l.alpha_prev), KDL::Vector(l.a_prev, 0.0, 0.0))));
    const KDL::RotationalInertia inertia(l.inertia_com[0], l.inertia_com[1], l.inertia_com[2], l.inertia_com[3],
                                         l.inertia_com[4], l.inertia_com[5]);
    const KDL::RigidBodyInertia body(l.mass, KDL::Vector(l.com[0], l.com[1], l.com[2]), inertia);
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ, 1.0, l.theta_offset),
                                  KDL::Frame(KDL::Vector(0.0, 0.0, l.d)), body));
  }
  return chain;
}

void check_model(const char* file) {
  const auto model = jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/" + file);
  const KDL::Chain chain = chain_of(model);
  KDL::ChainDynParam dyn(chain, KDL::Vector(model.gravity[0], model.gravity[1], model.gravity[2]));
  const unsigned n = chain.getNrOfJoints();
  ASSERT_EQ(n, model.joints.size());
  std::vector<jg::LinkConstants<double>> links(n);
  std::vector<jg::LinkConstants<float>> links_f(n);
  std::vector<jg::LinkConstants<jg::q16>> links_q(n);
  for (unsigned i = 0; i < n; ++i) {
    ASSERT_EQ(jg::convert_link(model.joints[i].link, links[i]), jg::Error::ok);
    ASSERT_EQ(jg::convert_link(model.joints[i].link, links_f[i]), jg::Error::ok);
    ASSERT_EQ(jg::convert_link(model.joints[i].link, links_q[i]), jg::Error::ok);
  }
  double worst_f = 0.0, worst_q = 0.0;
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> uq(-2.5, 2.5), uv(-1.5, 1.5);
  double worst_p = 0.0, worst_beta = 0.0;
  for (int trial = 0; trial < 2000; ++trial) {
    KDL::JntArray q(n), dq(n), g(n), cdq(n);
    double qs[7], dqs[7];
    for (unsigned i = 0; i < n; ++i) {
      qs[i] = q(i) = uq(rng);
      dqs[i] = dq(i) = uv(rng);
    }
    KDL::JntSpaceInertiaMatrix M(n), Mp(n), Mm(n);
    dyn.JntToMass(q, M);
    dyn.JntToGravity(q, g);
    dyn.JntToCoriolis(q, dq, cdq);
    const double eps = 1e-6;
    KDL::JntArray qp(n), qm(n);
    for (unsigned i = 0; i < n; ++i) {
      qp(i) = q(i) + eps * dq(i);
      qm(i) = q(i) - eps * dq(i);
    }
    dyn.JntToMass(qp, Mp);
    dyn.JntToMass(qm, Mm);
    jg::JointMomentum<double> out[7];
    jg::chain_momentum(links.data(), static_cast<int>(n), qs, dqs,
                       jg::Vec3<double>{model.gravity[0], model.gravity[1], model.gravity[2]}, out);
    float qf[7], dqf[7];
    jg::q16 qq[7], dqq[7];
    jg::NumericStatus st;
    for (unsigned i = 0; i < n; ++i) {
      qf[i] = static_cast<float>(qs[i]);
      dqf[i] = static_cast<float>(dqs[i]);
      qq[i] = jg::q16::from_double(qs[i], st);
      dqq[i] = jg::q16::from_double(dqs[i], st);
    }
    jg::JointMomentum<float> of[7];
    jg::JointMomentum<jg::q16> oq[7];
    jg::chain_momentum(links_f.data(), static_cast<int>(n), qf, dqf,
                       jg::Vec3<float>{0.0F, 0.0F, static_cast<float>(model.gravity[2])}, of);
    jg::chain_momentum(links_q.data(), static_cast<int>(n), qq, dqq,
                       jg::Vec3<jg::q16>{jg::q16{}, jg::q16{}, jg::q16::from_double(model.gravity[2])}, oq);
    for (unsigned i = 0; i < n; ++i) {
      double p = model.joints[i].link.rotor_inertia * dq(i), mdot_dq = 0.0;
      for (unsigned k = 0; k < n; ++k) {
        p += M(i, k) * dq(k);
        mdot_dq += (Mp(i, k) - Mm(i, k)) / (2.0 * eps) * dq(k);
      }
      const double beta = g(i) - (mdot_dq - cdq(i));
      worst_p = std::max(worst_p, std::fabs(out[i].momentum - p) / (1.0 + std::fabs(p)));
      worst_beta = std::max(worst_beta, std::fabs(out[i].beta - beta) / (1.0 + std::fabs(beta)));
      worst_f = std::max({worst_f, std::fabs(static_cast<double>(of[i].momentum) - p), std::fabs(static_cast<double>(of[i].beta) - beta)});
      worst_q = std::max({worst_q, std::fabs(oq[i].momentum.to_double() - p), std::fabs(oq[i].beta.to_double() - beta)});
    }
  }
  std::printf("%s against KDL over 2000 states: worst relative error p %.2e, beta %.2e; absolute float %.2e, Q16.16 %.2e\n",
              file, worst_p, worst_beta, worst_f, worst_q);
  EXPECT_LT(worst_f, 1e-4);
  EXPECT_LT(worst_q, 2e-3);
  EXPECT_LT(worst_p, 1e-9);
  EXPECT_LT(worst_beta, 1e-8);  // limited by the central-difference M' of the reference
}

TEST(MomentumRecursionKdl, ReferenceArm) { check_model("ref3.yaml"); }
TEST(MomentumRecursionKdl, FrankaPanda) { check_model("panda.yaml"); }

}  // namespace
