// The distributed momentum recursion against the plant's independent rigid-body model
// (CRBA for M, RNEA for C dq + g, central differences for M'): p and beta in double,
// float and Q16.16 over thousands of random states; skew-symmetry of M' - 2C.
#include <gtest/gtest.h>

#include <random>

#include "diagnosis/testset.hpp"
#include "jointguard/dynamics/momentum_recursion.hpp"
#include "dynamics/rigid_body.hpp"

namespace {
using jg::sim::JointVector;

jg::LinkDescription describe(const jg::sim::PlantLink& l) {
  jg::LinkDescription d;
  d.a_prev = l.a_prev;
  d.alpha_prev = l.alpha_prev;
  d.d = l.d;
  d.theta_offset = l.theta_offset;
  d.mass = l.mass;
  for (int k = 0; k < 3; ++k) d.com[k] = l.com(k);
  d.inertia_com[0] = l.inertia_com(0, 0);
  d.inertia_com[1] = l.inertia_com(1, 1);
  d.inertia_com[2] = l.inertia_com(2, 2);
  d.inertia_com[3] = l.inertia_com(0, 1);
  d.inertia_com[4] = l.inertia_com(0, 2);
  d.inertia_com[5] = l.inertia_com(1, 2);
  d.rotor_inertia = l.rotor_inertia;
  return d;
}

struct Reference {
  JointVector p, beta;
};
Reference reference(const jg::sim::ArmDynamics& arm, const JointVector& q, const JointVector& dq) {
  const JointVector h = arm.inverse_dynamics(q, dq, JointVector::Zero(q.size()));
  const double eps = 1e-6;
  const jg::sim::JointMatrix mdot = (arm.mass_matrix(q + eps * dq) - arm.mass_matrix(q - eps * dq)) / (2.0 * eps);
  return {arm.mass_matrix(q) * dq, h - mdot * dq};
}

template <class S>
void run_chain(const std::vector<jg::LinkConstants<S>>& links, const JointVector& q, const JointVector& dq,
               std::vector<jg::JointMomentum<S>>& out) {
  std::vector<S> qs, dqs;
  jg::NumericStatus st;
  for (int i = 0; i < q.size(); ++i) {
    qs.push_back(jg::convert<S>(q(i), st));
    dqs.push_back(jg::convert<S>(dq(i), st));
  }
  out.assign(links.size(), {});
  const jg::Vec3<S> g{S{}, S{}, jg::from_double<S>(-9.81)};
  jg::chain_momentum(links.data(), static_cast<int>(links.size()), qs.data(), dqs.data(), g, out.data());
}

template <class S>
std::vector<jg::LinkConstants<S>> constants(const std::vector<jg::sim::PlantLink>& plant) {
  std::vector<jg::LinkConstants<S>> out(plant.size());
  for (std::size_t i = 0; i < plant.size(); ++i) EXPECT_EQ(jg::convert_link(describe(plant[i]), out[i]), jg::Error::ok);
  return out;
}

TEST(MomentumRecursion, MatchesIndependentRigidBodyModel) {
  const auto arm_desc = jg::diag::default_test_arm();
  const jg::sim::ArmDynamics arm(arm_desc.links);
  const auto cd = constants<double>(arm_desc.links);
  const auto cf = constants<float>(arm_desc.links);
  const auto cq = constants<jg::q16>(arm_desc.links);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> uq(-3.0, 3.0), uv(-2.0, 2.0);
  double worst_d = 0.0, worst_f = 0.0, worst_q = 0.0;
  for (int trial = 0; trial < 3000; ++trial) {
    JointVector q(3), dq(3);
    for (int i = 0; i < 3; ++i) {
      q(i) = uq(rng);
      dq(i) = uv(rng);
    }
    const Reference ref = reference(arm, q, dq);
    std::vector<jg::JointMomentum<double>> od;
    std::vector<jg::JointMomentum<float>> of;
    std::vector<jg::JointMomentum<jg::q16>> oq;
    run_chain(cd, q, dq, od);
    run_chain(cf, q, dq, of);
    run_chain(cq, q, dq, oq);
    for (int i = 0; i < 3; ++i) {
      const auto u = static_cast<std::size_t>(i);
      const double scale = 1.0 + std::fabs(ref.beta(i));
      worst_d = std::max({worst_d, std::fabs(od[u].momentum - ref.p(i)) / (1.0 + std::fabs(ref.p(i))),
                          std::fabs(od[u].beta - ref.beta(i)) / scale});
      worst_f = std::max({worst_f, std::fabs(static_cast<double>(of[u].momentum) - ref.p(i)),
                          std::fabs(static_cast<double>(of[u].beta) - ref.beta(i))});
      worst_q = std::max({worst_q, std::fabs(oq[u].momentum.to_double() - ref.p(i)),
                          std::fabs(oq[u].beta.to_double() - ref.beta(i))});
    }
  }
  std::printf("worst error: double %.2e (relative), float %.2e, Q16.16 %.2e (N·m·s or N·m)\n", worst_d, worst_f, worst_q);
  EXPECT_LT(worst_d, 1e-8);  // limited by the reference's numerical M' (central differences)
  EXPECT_LT(worst_f, 2e-5);
  EXPECT_LT(worst_q, 1e-3);
}

TEST(MomentumRecursion, ChristoffelFactorisationMakesMdotMinus2CSkew) {
  // C dq from the recursion: C^T dq = dT/dq; with p' = tau - beta the Christoffel C
  // satisfies C + C^T = M'. Check (M' - 2C) skew via C = M' - C^T evaluated column-wise:
  // x^T (M' - 2C) x = 0 for x = dq means dq^T M' dq = 2 dq^T C dq = 2 dq^T C^T dq.
  const auto arm_desc = jg::diag::default_test_arm();
  const jg::sim::ArmDynamics arm(arm_desc.links);
  const auto cd = constants<double>(arm_desc.links);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uq(-3.0, 3.0), uv(-2.0, 2.0);
  for (int trial = 0; trial < 500; ++trial) {
    JointVector q(3), dq(3);
    for (int i = 0; i < 3; ++i) {
      q(i) = uq(rng);
      dq(i) = uv(rng);
    }
    std::vector<jg::JointMomentum<double>> od;
    run_chain(cd, q, dq, od);
    const JointVector g = arm.gravity_torque(q);
    JointVector ct_dq(3);
    for (int i = 0; i < 3; ++i) ct_dq(i) = g(i) - od[static_cast<std::size_t>(i)].beta;
    const double eps = 1e-6;
    const jg::sim::JointMatrix mdot = (arm.mass_matrix(q + eps * dq) - arm.mass_matrix(q - eps * dq)) / (2.0 * eps);
    EXPECT_NEAR(dq.dot(mdot * dq), 2.0 * dq.dot(ct_dq), 1e-6 * (1.0 + std::fabs(dq.dot(mdot * dq))));
  }
}
}  // namespace
