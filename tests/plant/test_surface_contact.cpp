// Surface contacts (issue 15 item 2): a body part touches the link's cover and pushes into
// it, its force within the friction cone around the inward normal; the campaign's surface
// draw changes only the point's place around the axis and the direction.
#include <gtest/gtest.h>

#include <cmath>

#include "dynamics/rigid_body.hpp"
#include "plant/collision.hpp"
#include "test_arm.hpp"

namespace {
using namespace jg::sim;

const std::vector<double> kLengths{0.3, 0.4, 0.35};

TEST(SurfaceContact, TheDrawChangesOnlyThePointAroundTheAxisAndTheDirection) {
  CampaignSpec spec;
  spec.count = 300;
  spec.t_max = 1e9;
  spec.seed = 11;
  const auto former = draw_campaign(spec, kLengths);
  spec.surface_contacts = true;
  const auto now = draw_campaign(spec, kLengths);
  ASSERT_EQ(now.size(), former.size());
  const double cone = std::atan(kSkinFriction);
  double largest_angle = 0.0;
  for (std::size_t i = 0; i < now.size(); ++i) {
    const CollisionEvent& a = now[i];
    const CollisionEvent& b = former[i];
    EXPECT_EQ(a.link, b.link);
    EXPECT_EQ(a.profile, b.profile);
    EXPECT_EQ(a.point_in_link.x(), b.point_in_link.x());
    EXPECT_EQ(a.peak_force_n, b.peak_force_n);
    EXPECT_EQ(a.duration_s, b.duration_s);
    EXPECT_EQ(a.rise_s, b.rise_s);
    EXPECT_EQ(a.t_start, b.t_start);
    // On the cover, the normal across the axis, the force within the cone pushing in.
    const Eigen::Vector3d n = a.surface_normal_in_link;
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
    EXPECT_NEAR(n.x(), 0.0, 1e-12);
    EXPECT_NEAR((a.point_in_link - Eigen::Vector3d(a.point_in_link.x(), 0.0, 0.0) - kSurfaceRadius * n).norm(), 0.0, 1e-12);
    const double angle = std::acos(std::clamp(-a.direction_in_link.normalized().dot(n), -1.0, 1.0));
    EXPECT_LE(angle, cone + 1e-9);
    largest_angle = std::max(largest_angle, angle);
  }
  EXPECT_GT(largest_angle, 0.8 * cone) << "the whole cone is drawn";
}

struct Kinematic {
  ArmDynamics arm{jg::test::three_joint_links()};
  JointVector q = (JointVector(3) << 0.0, 0.6, -0.8).finished();
};

/// A contact on link 3 at 0.2 m, on the side `normal` (link frame), force straight in.
CollisionEvent surface_event(CollisionProfile profile, const Eigen::Vector3d& normal) {
  CollisionEvent e;
  e.link = 3;
  e.profile = profile;
  e.point_in_link = Eigen::Vector3d(0.2, 0.0, 0.0) + kSurfaceRadius * normal;
  e.surface_normal_in_link = normal;
  e.direction_in_link = -normal;
  e.peak_force_n = 100.0;
  e.duration_s = 0.5;
  e.rise_s = 0.05;
  return e;
}

TEST(SurfaceContact, APushActsInTheLinkFrameDirectionAtTheOnsetFixedInTheWorld) {
  Kinematic k;
  const Eigen::Vector3d normal(0.0, 0.0, 1.0);
  CollisionSchedule s({surface_event(CollisionProfile::push, normal)});
  const Eigen::Vector3d expected = -(k.arm.poses(k.q).rotation[2] * normal);
  const JointVector qd = (JointVector(3) << 0.0, 0.0, 1.0).finished();
  const ContactForce first = s(0.0, k.arm, k.q, qd);
  ASSERT_EQ(first.link, 2);
  k.q += 0.1 * qd;  // the link turns; the body part's push stays where it was
  const ContactForce later = s(0.1, k.arm, k.q, qd);
  EXPECT_NEAR((later.force_base.normalized() - expected).norm(), 0.0, 1e-12);
  EXPECT_GT(later.force_base.norm(), 99.0);
  EXPECT_EQ(s.resolved(0).link, 3);
}

TEST(SurfaceContact, AClampIsOnTheSideTheArmMovesInto) {
  Kinematic k;
  const JointVector qd = (JointVector(3) << 0.0, 0.0, 0.5).finished();  // the elbow turns: link 3 moves in its plane
  const Eigen::Matrix3d R = k.arm.poses(k.q).rotation[2];
  const Eigen::Vector3d v_link = R.transpose() * (k.arm.point_jacobian(k.q, 2, Eigen::Vector3d(0.2, 0.0, 0.0)) * qd);
  const Eigen::Vector3d across = Eigen::Vector3d(0.0, v_link.y(), v_link.z()).normalized();
  CollisionEvent e = surface_event(CollisionProfile::clamp, -across);  // drawn on the side the point leaves
  e.into_motion = true;
  e.standstill_speed_m_per_s = kClampStandstillSpeed;
  e.approach_speed_m_per_s = kClampApproachSpeed;
  CollisionSchedule s({e});
  double largest = 0.0;
  Eigen::Vector3d last = Eigen::Vector3d::Zero();
  for (int n = 0; n <= 100; ++n) {
    const ContactForce f = s(n * 1e-3, k.arm, k.q, qd);
    largest = std::max(largest, f.force_base.norm());
    last = f.force_base;
    k.q += 1e-3 * qd;
  }
  EXPECT_GT(largest, 50.0) << "the arm presses on the body part";
  const ResolvedContact r = s.resolved(0);
  EXPECT_NEAR((r.point_in_link - (Eigen::Vector3d(0.2, 0.0, 0.0) + kSurfaceRadius * across)).norm(), 0.0, 1e-9)
      << "mirrored to the side the point moves into";
  EXPECT_NEAR((last.normalized() + R * across).norm(), 0.0, 1e-9) << "pushing into the cover there";
  // Drawn on the side it moves into already: kept.
  CollisionEvent kept = surface_event(CollisionProfile::clamp, across);
  kept.into_motion = true;
  kept.standstill_speed_m_per_s = kClampStandstillSpeed;
  CollisionSchedule t({kept});
  (void)t(0.0, Kinematic{}.arm, Kinematic{}.q, qd);
  EXPECT_NEAR((t.resolved(0).point_in_link - kept.point_in_link).norm(), 0.0, 1e-12);
}

}  // namespace
