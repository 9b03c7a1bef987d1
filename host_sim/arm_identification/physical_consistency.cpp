#include "arm_identification/physical_consistency.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace jg::dyn {

Consistency check_link(const LinkParams& p, const LinkBounds& bounds) {
  Consistency c;
  c.mass = p(0);
  if (!p.allFinite()) {
    c.reason = "not finite";
    return c;
  }
  if (!(p(0) >= bounds.min_mass_kg)) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "mass %.4g kg below %.3g kg", p(0), bounds.min_mass_kg);
    c.reason = buf;
    return c;
  }
  const Eigen::Vector3d com = p.segment<3>(1) / p(0);
  c.com_distance = com.norm();
  const Eigen::Matrix3d Ic = inertia_com(p);
  // Second moment of mass about the CoM: Sigma = tr(I)/2 1 - I; its eigenvalues are
  // (I_b + I_c - I_a)/2 over the principal axes, so Sigma > 0 <=> I > 0 with strict
  // triangle inequalities.
  const Eigen::Matrix3d Sigma = 0.5 * Ic.trace() * Eigen::Matrix3d::Identity() - Ic;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(Sigma, Eigen::EigenvaluesOnly);
  c.min_second_moment = es.eigenvalues().minCoeff();
  c.min_triangle = 2.0 * c.min_second_moment;
  if (!(c.min_second_moment >= bounds.min_second_moment)) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "inertia about the CoM not physical (smallest second moment %.3g kg m^2)",
                  c.min_second_moment);
    c.reason = buf;
    return c;
  }
  if (!(c.com_distance <= bounds.com_radius_m)) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "CoM %.3f m from the link origin (bound %.3f m)", c.com_distance, bounds.com_radius_m);
    c.reason = buf;
    return c;
  }
  c.ok = true;
  return c;
}

double feasible_step(const LinkParams& from, const LinkParams& to, const LinkBounds& bounds) {
  if (!check_link(from, bounds).ok) return 0.0;
  if (check_link(to, bounds).ok) return 1.0;
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 40; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (check_link(from + mid * (to - from), bounds).ok) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return lo;
}

}  // namespace jg::dyn
