// The point and the force with the surface-contact prior (issue 15 item 2): on the last link
// of the reference arm a force across the link determines the point from one posture; on
// link 2 (its joints' axes meet at its start) only the moment s x F is determined, in every
// posture; and the contact window estimates the force the observer sees.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "detection/contact_point.hpp"
#include "eval/contact_window.hpp"
#include "ref3_arm.hpp"

namespace {
using jg::detection::ContactEstimatorParams;
using jg::detection::TorqueObservation;

struct Arm : jg::test::Ref3Arm {
  ContactEstimatorParams surface = [this] {
    ContactEstimatorParams p = params;
    p.axial_prior_ratio = jg::detection::axial_prior_ratio(0.5);
    p.surface_radius_m = 0.04;
    // The synthetic contacts lie exactly on the cover where the force pushes in: no offset
    // from the candidate to count as model noise (ContactEstimatorParams::point_offset_m).
    p.point_offset_m = 0.0;
    return p;
  }();
};

using jg::test::posture;

/// A force straight into the cover of `link` at `along` on the side at `azimuth` [rad].
struct SurfaceForce {
  Eigen::Vector3d point_in_link, force_base;
};
SurfaceForce surface_force(const Arm& a, const jg::sim::JointVector& q, int link, double along, double azimuth, double newton) {
  const Eigen::Vector3d normal(0.0, std::cos(azimuth), std::sin(azimuth));
  return {Eigen::Vector3d(along, 0.0, 0.0) + 0.04 * normal, -newton * (a.arm.poses(q).rotation[link - 1] * normal)};
}

TorqueObservation observe(const Arm& a, const jg::sim::JointVector& q, int link, const SurfaceForce& f, double sigma) {
  return {q, a.arm.point_jacobian(q, link - 1, f.point_in_link).transpose() * f.force_base, jg::sim::JointVector::Constant(3, sigma)};
}

TEST(ContactPoint, AxialPriorRatioOfTheFrictionCone) {
  EXPECT_DOUBLE_EQ(jg::detection::axial_prior_ratio(0.0), 0.0);
  // mu 0.5: along 0.25 F_n, across sqrt((1 + 0.0625) / 2) F_n per component.
  EXPECT_NEAR(jg::detection::axial_prior_ratio(0.5), 0.25 / std::sqrt(0.53125), 1e-12);
}

TEST(ContactPoint, TheSurfacePriorLocatesThePointOnTheLastLinkFromOnePosture) {
  const Arm a;
  ContactEstimatorParams frictionless = a.surface;
  frictionless.axial_prior_ratio = 0.01;
  const auto q = posture(0.3, 0.7, -0.9);
  for (const double along : {0.12, 0.2, 0.26}) {
    const SurfaceForce f = surface_force(a, q, 3, along, 0.7, 60.0);
    const TorqueObservation o = observe(a, q, 3, f, 0.05);
    // A force across the link (no friction along it): three torques for the point and two
    // force components, the point is determined by one posture.
    jg::detection::ContactEstimate exact;
    exact.link = 3;
    jg::detection::estimate_point_and_force(a.arm, o, frictionless, nullptr, exact);
    EXPECT_NEAR(exact.along_m, along, 0.01);
    EXPECT_NEAR(exact.force_n, 60.0, 2.0);
    EXPECT_LT((exact.point_in_link - f.point_in_link).norm(), 0.015) << "on the cover where the force pushes in";
    // Friction of mu 0.5 allows a force along the link: the point is narrowed, not fixed.
    jg::detection::ContactEstimate with;
    with.link = 3;
    jg::detection::estimate_point_and_force(a.arm, o, a.surface, nullptr, with);
    EXPECT_NEAR(with.along_m, along, 0.04);
    EXPECT_NEAR(with.force_n, 60.0, 12.0);
    // Without the prior (any direction) every point explains the torques: the point spreads.
    jg::detection::ContactEstimate without;
    without.link = 3;
    jg::detection::estimate_point_and_force(a.arm, o, a.params, nullptr, without);
    EXPECT_LE(with.along_sigma_m, without.along_sigma_m + 1e-9);
    EXPECT_LT(exact.along_sigma_m, 0.2 * without.along_sigma_m);
  }
}

TEST(ContactPoint, OnLinkTwoOnlyTheMomentIsDetermined) {
  const Arm a;
  for (const auto& q : {posture(0.0, 0.6, -0.8), posture(-1.0, 1.2, 0.4), posture(2.0, -0.3, -1.5)}) {
    // The shoulder's and the waist's axes meet at link 2's origin: J(s) = s J(1).
    const SurfaceForce near = surface_force(a, q, 2, 0.15, 1.1, 80.0);
    SurfaceForce far = surface_force(a, q, 2, 0.30, 1.1, 40.0);
    const TorqueObservation o_near = observe(a, q, 2, near, 0.05), o_far = observe(a, q, 2, far, 0.05);
    EXPECT_LT((o_near.tau_nm - o_far.tau_nm).norm(), 1e-9 * o_near.tau_nm.norm());
    jg::detection::ContactEstimate e;
    e.link = 2;
    jg::detection::estimate_point_and_force(a.arm, o_near, a.surface, nullptr, e);
    EXPECT_GT(e.along_sigma_m, 0.05) << "the point's spread says it is not determined";
    EXPECT_GT(e.force_sigma_n, 0.2 * e.force_n);
  }
}

TEST(ContactPoint, OverTheContactThePointComesFromEveryCycle) {
  const Arm a;
  ContactEstimatorParams p = a.surface;
  p.profile_point_likelihood = true;
  auto evidence = jg::detection::make_point_evidence(3, p);
  const double along = 0.2;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.6);
  TorqueObservation last;
  for (int k = 0; k < 30; ++k) {
    const auto q = posture(0.3, 0.7 + 0.002 * k, -0.9);
    TorqueObservation o = observe(a, q, 3, surface_force(a, q, 3, along, 2.0, 20.0 + 2.0 * k), 0.6);
    for (int j = 0; j < 3; ++j) o.tau_nm(j) += noise(rng);
    jg::detection::add_point_evidence(evidence, a.arm, o, p, 0.15);
    last = o;
  }
  jg::detection::ContactEstimate all, one;
  all.link = one.link = 3;
  jg::detection::estimate_point_and_force(a.arm, last, p, &evidence, all);
  jg::detection::estimate_point_and_force(a.arm, last, p, nullptr, one);
  EXPECT_NEAR(all.along_m, along, 0.04);
  EXPECT_LT(all.along_sigma_m, one.along_sigma_m);
}

TEST(ContactPoint, OverTheContactOnLinkTwoThePointStaysAtItsPrior) {
  // The fit alone scores link 2's points (the force prior's penalty would pick the far end):
  // every point fits, the posterior is the segment's uniform prior, whatever the true point.
  const Arm a;
  ContactEstimatorParams p = a.surface;
  p.profile_point_likelihood = true;
  p.force_at_mean_point = true;
  const auto& seg = p.segments[1];
  for (const double along : {0.12, 0.34}) {
    auto evidence = jg::detection::make_point_evidence(3, p);
    TorqueObservation last;
    for (int k = 0; k < 20; ++k) {
      const auto q = posture(0.2, 0.6 + 0.003 * k, -0.8);
      last = observe(a, q, 2, surface_force(a, q, 2, along, 0.9, 30.0 + 2.0 * k), 0.5);
      jg::detection::add_point_evidence(evidence, a.arm, last, p, 0.15);
    }
    jg::detection::ContactEstimate e;
    e.link = 2;
    jg::detection::estimate_point_and_force(a.arm, last, p, &evidence, e);
    EXPECT_NEAR(e.along_m, 0.5 * (seg.along_min_m + seg.along_max_m), 0.025);  // the prior's shrinkage of the force leaves a trace
    // The force at the mean point: the moment over that point.
    EXPECT_NEAR(e.force_n, (30.0 + 38.0) * along / e.along_m, 0.02 * (30.0 + 38.0) * along / e.along_m);
  }
}

TEST(ContactWindowTruth, TheForceIsComparedWithTheForceTheObserverSees) {
  // An ideal first-order observer (gain K) of a contact whose force ramps: its estimate lags
  // the force by about 1/K. Without the lag correction the window's force is the observer's
  // filtered force, and force_true_observed_n is that force; the instant force is larger.
  const Arm a;
  const double dt = 1e-3, K = 150.0;
  jg::eval::ContactWindowConfig c;
  c.observer_gain_per_s = K;
  c.lag_correction = false;
  c.force_after_s = 0.04;
  c.estimator = a.surface;
  jg::eval::ContactWindow w(c, dt);
  const auto q = posture(0.3, 0.7, -0.9);
  const SurfaceForce unit = surface_force(a, q, 3, 0.2, 0.7, 1.0);
  const Eigen::VectorXd tau_unit = a.arm.point_jacobian(q, 2, unit.point_in_link).transpose() * unit.force_base;
  std::vector<double> force;
  double seen = 0.0;
  const double keep = std::exp(-K * dt);
  std::optional<double> detected;
  for (int k = 0; k < 120; ++k) {
    const double t = k * dt;
    if (seen * tau_unit.norm() > 2.0 && !detected) detected = t;
    w.add(a.arm, t, q, seen * tau_unit, jg::sim::JointVector::Constant(3, 0.3), detected);
    force.push_back(k < 10 ? 0.0 : 2000.0 * (k - 10) * dt);  // 2 kN/s from 10 ms
    seen = keep * seen + (1.0 - keep) * force.back();
  }
  std::vector<std::vector<double>> tau_ext(3, std::vector<double>(force.size(), 0.0));
  jg::sim::CollisionEvent e;
  e.link = 3;
  e.point_in_link = unit.point_in_link;
  w.set_truth(a.arm, e, force, tau_ext);
  ASSERT_TRUE(w.outcome());
  const auto& o = *w.outcome();
  EXPECT_NEAR(o.estimate.force_n, o.force_true_observed_n, 0.03 * o.force_true_observed_n);
  EXPECT_GT(o.force_true_n, 1.1 * o.force_true_observed_n) << "the instant force is ahead of what the observer saw";
  EXPECT_NEAR(o.force_given_true_link_n, o.force_true_observed_n, 0.03 * o.force_true_observed_n);
}

/// The window's outcome for a steady contact torque seen from 10 ms on, with the isolation
/// naming `isolated_link` (0: none) and the link taken from it or not.
jg::eval::ContactOutcome steady_outcome(const Arm& a, const jg::sim::JointVector& q, const Eigen::VectorXd& tau,
                                        int isolated_link, bool link_from_isolation) {
  const double dt = 1e-3;
  jg::eval::ContactWindowConfig c;
  c.observer_gain_per_s = 150.0;
  c.estimator = a.params;
  c.link_from_isolation = link_from_isolation;
  jg::eval::ContactWindow w(c, dt);
  std::optional<double> detected;
  for (int k = 0; k < 60; ++k) {
    const double t = k * dt;
    if (k == 10) detected = t;
    w.add(a.arm, t, q, k < 10 ? Eigen::VectorXd::Zero(3) : tau, jg::sim::JointVector::Constant(3, 0.3), detected, isolated_link);
  }
  EXPECT_TRUE(w.outcome());
  return w.outcome() ? *w.outcome() : jg::eval::ContactOutcome{};
}

TEST(ContactWindowLink, OnTheIsolationsLinkTheForceSpreadCoversEveryLinkTheTorquesAllow) {
  // A force on link 2 puts no torque on joint 3; a force on link 3 through joint 3's axis
  // gives the same torques, so both links explain them and the fit takes the proximal one.
  // When the isolation names link 3, the estimate goes there, where the same torques need a
  // smaller force (a longer lever). Its force spread must then reach the force on link 2,
  // or the truth would lie outside 2 sigma whenever the isolation is one link too high.
  const Arm a;
  const auto q = posture(0.3, 0.7, -0.9);
  const Eigen::Vector3d point(0.2, 0.0, 0.0);
  const Eigen::Vector3d force_base = a.arm.poses(q).rotation[1] * Eigen::Vector3d(0.0, -40.0, 0.0);
  const Eigen::VectorXd tau = a.arm.point_jacobian(q, 1, point).transpose() * force_base;
  ASSERT_NEAR(tau(2), 0.0, 1e-9);
  const auto own = steady_outcome(a, q, tau, 3, false);
  const auto iso = steady_outcome(a, q, tau, 3, true);
  ASSERT_EQ(own.estimate.link, 2);
  ASSERT_EQ(iso.estimate.link, 3);
  const auto& consistent = iso.estimate.links_consistent;
  ASSERT_NE(std::find(consistent.begin(), consistent.end(), 2), consistent.end());
  ASSERT_LT(iso.estimate.force_n, 0.9 * own.estimate.force_n) << "link 3 needs a smaller force";
  // Link 2's force lies within 2 sigma of the estimate and within its interval.
  EXPECT_LE(std::fabs(own.estimate.force_n - iso.estimate.force_n), 2.0 * iso.estimate.force_sigma_n + 1e-9);
  EXPECT_LE(iso.estimate.force_lo_n, own.estimate.force_n);
  EXPECT_GE(iso.estimate.force_hi_n, own.estimate.force_n);
  EXPECT_FALSE(iso.estimate.force_determined);
  // Without a switch (the isolation names the fit's own link) nothing is widened.
  const auto same = steady_outcome(a, q, tau, 2, true);
  EXPECT_EQ(same.estimate.link, 2);
  EXPECT_DOUBLE_EQ(same.estimate.force_sigma_n, own.estimate.force_sigma_n);
  EXPECT_DOUBLE_EQ(same.estimate.force_hi_n, own.estimate.force_hi_n);
}

}  // namespace
