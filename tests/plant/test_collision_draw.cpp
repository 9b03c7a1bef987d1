// Campaign clamps are real contacts (issue 15): a clamp drawn `into_motion` presses on the
// arm whichever way its direction was drawn, a standing arm is walked into, and the draw of
// every other collision is the same as before.
#include <gtest/gtest.h>

#include "dynamics/rigid_body.hpp"
#include "plant/collision.hpp"
#include "test_arm.hpp"

namespace {
using namespace jg::sim;

struct Kinematic {
  ArmDynamics arm{jg::test::three_joint_links()};
  JointVector q = (JointVector(3) << 0.0, 0.6, -0.8).finished();
  Eigen::Vector3d point{0.3, 0.0, 0.0};  // on link 3 [m]
  /// The contact point's velocity [m/s] at the joint speeds qd [rad/s].
  Eigen::Vector3d velocity(const JointVector& qd) const { return arm.point_jacobian(q, 2, point) * qd; }
};

CollisionEvent clamp_on_link3(const Kinematic& k, const Eigen::Vector3d& direction) {
  CollisionEvent e;
  e.t_start = 0.0;
  e.link = 3;
  e.point_in_link = k.point;
  e.direction_base = direction;
  e.profile = CollisionProfile::clamp;
  e.peak_force_n = 100.0;
  e.duration_s = 0.5;
  return e;
}

/// Moves the arm at constant joint speeds for `seconds` (1 ms steps) and returns the largest
/// contact force and the last force vector.
std::pair<double, Eigen::Vector3d> drive(CollisionSchedule& s, Kinematic k, const JointVector& qd, double seconds) {
  double largest = 0.0;
  Eigen::Vector3d last = Eigen::Vector3d::Zero();
  const double h = 1e-3;
  for (int n = 0; n * h <= seconds + 1e-12; ++n) {
    const ContactForce f = s(n * h, k.arm, k.q, qd);
    if (f.link >= 0) {
      largest = std::max(largest, f.force_base.norm());
      last = f.force_base;
    }
    k.q += h * qd;
  }
  return {largest, last};
}

const JointVector kWaistMoving = (JointVector(3) << 0.5, 0.0, 0.0).finished();  // [rad/s]

TEST(CampaignClamp, DrawnAsBeforeAClampTheArmMovesAwayFromIsNeverTouched) {
  const Kinematic k;
  const Eigen::Vector3d v = k.velocity(kWaistMoving);
  ASSERT_GT(v.norm(), 0.05);
  CollisionSchedule s({clamp_on_link3(k, v.normalized())});  // the former draw's defect
  EXPECT_EQ(drive(s, k, kWaistMoving, 0.3).first, 0.0);
}

TEST(CampaignClamp, IntoMotionMirrorsTheDirectionAgainstTheMotion) {
  const Kinematic k;
  const Eigen::Vector3d v = k.velocity(kWaistMoving);
  const Eigen::Vector3d drawn = (v.normalized() + Eigen::Vector3d(0.0, 0.0, 0.5)).normalized();
  CollisionEvent e = clamp_on_link3(k, drawn);
  e.into_motion = true;
  e.standstill_speed_m_per_s = kClampStandstillSpeed;
  e.approach_speed_m_per_s = kClampApproachSpeed;
  CollisionSchedule s({e});
  const auto [largest, last] = drive(s, k, kWaistMoving, 0.3);
  EXPECT_GT(largest, 50.0) << "the arm moves into the obstacle";
  const Eigen::Vector3d d = last.normalized();
  // Mirrored across the plane normal to v: the part along v flips, the rest stays.
  EXPECT_NEAR(d.dot(v.normalized()), -drawn.dot(v.normalized()), 1e-9);
  EXPECT_NEAR((d - d.dot(v.normalized()) * v.normalized()).z(), drawn.z(), 1e-9);
}

TEST(CampaignClamp, IntoMotionKeepsADirectionAlreadyAgainstTheMotion) {
  const Kinematic k;
  const Eigen::Vector3d v = k.velocity(kWaistMoving);
  const Eigen::Vector3d drawn = (-v.normalized() + Eigen::Vector3d(0.0, 0.0, 0.5)).normalized();
  CollisionEvent e = clamp_on_link3(k, drawn);
  e.into_motion = true;
  e.standstill_speed_m_per_s = kClampStandstillSpeed;
  CollisionSchedule s({e});
  const auto [largest, last] = drive(s, k, kWaistMoving, 0.3);
  EXPECT_GT(largest, 50.0);
  EXPECT_NEAR((last.normalized() - drawn).norm(), 0.0, 1e-9);
}

TEST(CampaignClamp, AStandingArmIsWalkedIntoAtTheApproachSpeed) {
  const Kinematic k;
  const JointVector still = JointVector::Zero(3);
  CollisionEvent e = clamp_on_link3(k, Eigen::Vector3d(0.0, 1.0, 0.0));
  e.into_motion = true;
  e.standstill_speed_m_per_s = kClampStandstillSpeed;
  e.approach_speed_m_per_s = kClampApproachSpeed;
  CollisionSchedule s({e});
  // After 10 ms the obstacle has closed in by approach x 10 ms: spring plus damping.
  const auto [largest, last] = drive(s, k, still, 0.010);
  const double expected = e.stiffness_n_per_m * kClampApproachSpeed * 0.010 + e.damping_n_s_per_m * kClampApproachSpeed;
  EXPECT_NEAR(largest, expected, 1e-9);
  EXPECT_NEAR((last.normalized() - Eigen::Vector3d(0.0, 1.0, 0.0)).norm(), 0.0, 1e-12) << "direction as drawn";
  // Without into_motion the standing arm never presses on the obstacle.
  CollisionSchedule former({clamp_on_link3(k, Eigen::Vector3d(0.0, 1.0, 0.0))});
  EXPECT_EQ(drive(former, k, still, 0.3).first, 0.0);
}

TEST(CampaignClamp, TheDrawOfEveryCollisionIsAsBeforeOnlyClampsGetIntoMotion) {
  CampaignSpec spec;
  spec.count = 300;
  spec.t_max = 1e9;
  spec.seed = 7;
  const std::vector<double> lengths{0.3, 0.4, 0.35};
  const auto now = draw_campaign(spec, lengths);
  spec.clamps_into_motion = false;
  const auto former = draw_campaign(spec, lengths);
  ASSERT_EQ(now.size(), former.size());
  int clamps = 0;
  for (std::size_t i = 0; i < now.size(); ++i) {
    const CollisionEvent& a = now[i];
    const CollisionEvent& b = former[i];
    EXPECT_EQ(a.link, b.link);
    EXPECT_EQ(a.profile, b.profile);
    EXPECT_EQ(a.point_in_link, b.point_in_link);
    EXPECT_EQ(a.direction_base, b.direction_base);
    EXPECT_EQ(a.peak_force_n, b.peak_force_n);
    EXPECT_EQ(a.duration_s, b.duration_s);
    EXPECT_EQ(a.t_start, b.t_start);
    EXPECT_FALSE(b.into_motion);
    EXPECT_EQ(a.into_motion, a.profile == CollisionProfile::clamp);
    clamps += a.profile == CollisionProfile::clamp ? 1 : 0;
  }
  EXPECT_GT(clamps, 50);
}

}  // namespace
