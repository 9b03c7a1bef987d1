// Plant physics: consistency of the rigid-body algorithms, energy conservation and
// dissipation, contact torque = J^T F, elasticity, determinism.
#include <gtest/gtest.h>

#include <random>

#include "models/paper_friction.hpp"
#include "test_arm.hpp"

namespace {
using jg::sim::ArmDynamics;
using jg::sim::JointVector;
using jg::sim::Plant;
using jg::sim::PlantConfig;

JointVector random_vector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  JointVector v(n);
  for (int i = 0; i < n; ++i) v(i) = u(rng);
  return v;
}

TEST(RigidBody, MassMatrixMatchesInverseDynamicsColumnsAndForwardInvertsInverse) {
  const ArmDynamics arm(jg::test::three_joint_links());
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const JointVector q = random_vector(rng, 3, 3.0), qd = random_vector(rng, 3, 2.0), qdd = random_vector(rng, 3, 5.0);
    const auto M = arm.mass_matrix(q);
    const JointVector zero = JointVector::Zero(3);
    for (int j = 0; j < 3; ++j) {
      JointVector e = JointVector::Zero(3);
      e(j) = 1.0;
      const JointVector col = arm.inverse_dynamics(q, zero, e, false);
      EXPECT_LT((col - M.col(j)).norm(), 1e-12);
    }
    EXPECT_LT((M - M.transpose()).norm(), 1e-12);
    const JointVector tau = arm.inverse_dynamics(q, qd, qdd);
    EXPECT_LT((arm.forward_dynamics(q, qd, tau) - qdd).norm(), 1e-9);
  }
}

TEST(RigidBody, GravityIsGradientOfPotentialEnergy) {
  const ArmDynamics arm(jg::test::three_joint_links());
  std::mt19937 rng(3);
  for (int trial = 0; trial < 100; ++trial) {
    const JointVector q = random_vector(rng, 3, 3.0);
    const JointVector g = arm.gravity_torque(q);
    for (int j = 0; j < 3; ++j) {
      JointVector dq = JointVector::Zero(3);
      dq(j) = 1e-6;
      const double grad = (arm.potential_energy(q + dq) - arm.potential_energy(q - dq)) / 2e-6;
      EXPECT_NEAR(g(j), grad, 1e-6);
    }
  }
}

TEST(RigidBody, ContactTorqueIsJacobianTransposeForceByVirtualWork) {
  const ArmDynamics arm(jg::test::three_joint_links());
  std::mt19937 rng(11);
  for (int trial = 0; trial < 100; ++trial) {
    const JointVector q = random_vector(rng, 3, 3.0);
    const int link = trial % 3;
    const Eigen::Vector3d point(0.1, -0.02, 0.03), force(30.0, -50.0, 80.0);
    const auto J = arm.point_jacobian(q, link, point);
    const JointVector tau = J.transpose() * force;
    for (int j = 0; j < 3; ++j) {  // tau_j = F . dx/dq_j (numerically)
      JointVector dq = JointVector::Zero(3);
      dq(j) = 1e-6;
      const auto Pp = arm.poses(q + dq), Pm = arm.poses(q - dq);
      const Eigen::Vector3d xp = Pp.origin[link] + Pp.rotation[link] * point;
      const Eigen::Vector3d xm = Pm.origin[link] + Pm.rotation[link] * point;
      EXPECT_NEAR(tau(j), force.dot((xp - xm) / 2e-6), 1e-6) << "joint " << j << " link " << link;
    }
    for (int j = link + 1; j < 3; ++j) EXPECT_EQ(tau(j), 0.0) << "a force on link i loads joints 1..i only";
  }
}

TEST(Plant, EnergyIsConservedWithoutFrictionAndControl) {
  PlantConfig c;
  c.links = jg::test::three_joint_links();
  Plant plant(c);
  JointVector q0(3);
  q0 << 0.3, 0.8, -0.5;
  plant.reset(q0);
  const double e0 = plant.energy();
  double worst = 0.0;
  const JointVector zero = JointVector::Zero(3);
  for (int k = 0; k < 10000; ++k) {  // 10 s at 1 kHz control, 2 kHz plant
    plant.advance(0.001, zero);
    worst = std::max(worst, std::fabs(plant.energy() - e0));
  }
  const double scale = std::fabs(e0) + plant.arm().kinetic_energy(plant.state().q, plant.state().qd);
  std::printf("energy drift over 10 s: %.3e J (relative %.3e)\n", worst, worst / scale);
  EXPECT_LT(worst / scale, 1e-6);
  EXPECT_GT(plant.state().qd.norm(), 0.1) << "the arm must actually swing";
}

TEST(Plant, EnergyOnlyDecreasesWithFriction) {
  PlantConfig c;
  c.links = jg::test::three_joint_links();
  for (const auto& p : jg::sim::kPaperTable1) c.friction.push_back({p, {}});
  Plant plant(c);
  JointVector q0(3);
  q0 << 0.0, 1.2, -1.0;
  plant.reset(q0);
  double previous = plant.energy();
  const JointVector zero = JointVector::Zero(3);
  double total_rise = 0.0;
  for (int k = 0; k < 5000; ++k) {
    plant.advance(0.001, zero);
    const double e = plant.energy();
    total_rise += std::max(0.0, e - previous);
    ASSERT_LE(e, previous + 1e-6) << "energy rose at t = " << plant.state().time;
    previous = e;
  }
  std::printf("summed energy rises (numerical) over 5 s: %.3e J\n", total_rise);
}

TEST(Plant, SameInputsGiveBitIdenticalTrajectories) {
  PlantConfig c;
  c.links = jg::test::three_joint_links();
  for (const auto& p : jg::sim::kPaperTable1) c.friction.push_back({p, {}});
  auto run = [&] {
    Plant plant(c);
    JointVector tau(3);
    for (int k = 0; k < 2000; ++k) {
      tau << 10.0 * std::sin(0.01 * k), 30.0, 5.0 * std::cos(0.02 * k);
      plant.advance(0.001, tau);
    }
    return plant.state().q;
  };
  const JointVector a = run(), b = run();
  for (int i = 0; i < 3; ++i) EXPECT_EQ(a(i), b(i));
}

TEST(Plant, ElasticJointTransmitsTorqueThroughSpring) {
  PlantConfig c;
  c.links = jg::test::three_joint_links();
  c.elasticity.assign(3, {20000.0, 20.0, 0.0});
  c.plant_rate_hz = 10000.0;
  Plant plant(c);
  // Springs pre-loaded by the gravity torque and motors holding it: the arm stays at rest,
  // and each spring carries exactly its joint's gravity torque.
  JointVector q0(3);
  q0 << 0.0, 0.5, -0.3;
  const JointVector g = plant.arm().gravity_torque(q0);
  plant.reset(q0, q0 + g / 20000.0);
  for (int k = 0; k < 1000; ++k) plant.advance(0.001, g);
  const auto& s = plant.state();
  EXPECT_LT((s.q - q0).norm(), 1e-9);
  EXPECT_LT(s.qd.norm(), 1e-8);
  // And a torque step on the motor reaches the link through the spring.
  JointVector tau = g;
  tau(0) += 5.0;
  for (int k = 0; k < 200; ++k) plant.advance(0.001, tau);
  EXPECT_GT(plant.state().q(0) - q0(0), 0.01);
}
}  // namespace
