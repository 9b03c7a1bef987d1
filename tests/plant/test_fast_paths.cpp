// The plant's fast paths (issue 18) against the straightforward forms they replaced: the
// same doubles, compared bit for bit, so the campaign's results cannot move.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "motion/trajectory.hpp"
#include "test_arm.hpp"

namespace {
using namespace jg::sim;

/// The linear scan WaypointTrajectory::at used before the binary search.
TrajectorySample scan_at(const JointVector& start, const std::vector<WaypointTrajectory::Waypoint>& wps, double t) {
  const Eigen::Index n = start.size();
  JointVector from = start;
  double t0 = 0.0;
  for (const auto& w : wps) {
    if (t < t0 + w.move_s) {
      const double u = std::clamp((t - t0) / w.move_s, 0.0, 1.0);
      const double pos = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
      const double vel = 30.0 * u * u * (1.0 - u) * (1.0 - u) / w.move_s;
      const double acc = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / (w.move_s * w.move_s);
      const JointVector delta = w.q - from;
      return {from + pos * delta, vel * delta, acc * delta};
    }
    t0 += w.move_s;
    from = w.q;
    if (t < t0 + w.dwell_s) break;
    t0 += w.dwell_s;
  }
  return {from, JointVector::Zero(n), JointVector::Zero(n)};
}

void expect_same_bits(const JointVector& a, const JointVector& b, double t) {
  ASSERT_EQ(a.size(), b.size());
  for (Eigen::Index j = 0; j < a.size(); ++j) EXPECT_EQ(a(j), b(j)) << "t = " << t << ", joint " << j;
}

TEST(FastPaths, WaypointLookupMatchesTheLinearScanAtEveryTime) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  JointVector start(3);
  start << 0.1, -0.2, 0.3;
  std::vector<WaypointTrajectory::Waypoint> wps;
  for (int k = 0; k < 40; ++k) {
    JointVector q(3);
    q << unit(rng), -unit(rng), unit(rng);
    // Dwell times of zero included: a move's end is then the next move's start.
    wps.push_back({q, 0.3 + unit(rng), k % 3 == 0 ? 0.0 : 0.2 * unit(rng)});
  }
  const WaypointTrajectory traj(start, wps);
  std::vector<double> times{-1.0, 0.0, traj.duration(), traj.duration() + 1.0};
  double t0 = 0.0;
  for (const auto& w : wps) {  // the boundaries themselves, and either side of them
    t0 += w.move_s;
    times.insert(times.end(), {t0, std::nextafter(t0, -1.0), std::nextafter(t0, 1e9)});
    t0 += w.dwell_s;
    times.insert(times.end(), {t0, std::nextafter(t0, -1.0), std::nextafter(t0, 1e9)});
  }
  for (double t = 0.0; t < traj.duration() + 0.5; t += 0.001) times.push_back(t);
  for (const double t : times) {
    const TrajectorySample a = traj.at(t), b = scan_at(start, wps, t);
    expect_same_bits(a.q, b.q, t);
    expect_same_bits(a.dq, b.dq, t);
    expect_same_bits(a.ddq, b.ddq, t);
  }
  const WaypointTrajectory none(start, {});
  expect_same_bits(none.at(0.5).q, start, 0.5);
}

TEST(FastPaths, ArrayForwardDynamicsAndSharedTransformsGiveTheSameDoubles) {
  const ArmDynamics arm(jg::test::three_joint_links());
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), speed(-2.0, 2.0), torque(-50.0, 50.0);
  for (int k = 0; k < 200; ++k) {
    JointVector q(3), qd(3), tau(3);
    for (int j = 0; j < 3; ++j) {
      q(j) = angle(rng);
      qd(j) = speed(rng);
      tau(j) = torque(rng);
    }
    const JointVector a = arm.forward_dynamics(q, qd, tau);
    double b[3];
    arm.forward_dynamics(q.data(), qd.data(), tau.data(), b);
    for (int j = 0; j < 3; ++j) EXPECT_EQ(a(j), b[j]);
    // M qdd + bias = tau up to rounding: the fast path solves the right equations.
    const JointVector back = arm.inverse_dynamics(q, qd, a);
    EXPECT_LT((back - tau).norm(), 1e-9 * (1.0 + tau.norm()));
    JointVector g;
    JointMatrix M;
    arm.gravity_and_mass_matrix(q, g, M);
    expect_same_bits(g, arm.gravity_torque(q), 0.0);
    const JointMatrix M_alone = arm.mass_matrix(q);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) EXPECT_EQ(M(i, j), M_alone(i, j));
    }
  }
}

}  // namespace
