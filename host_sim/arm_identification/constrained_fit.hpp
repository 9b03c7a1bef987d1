// The physically consistent least-squares estimate: minimise a convex quadratic subject
// to each link's consistency (pseudo-inertia minus a floor positive definite, mass above
// a floor, CoM inside a sphere: all convex) and non-negative rotor inertias, by a
// log-barrier interior-point method with Newton steps. The constraints are a 4x4 linear
// matrix inequality and a second-order cone per link, so log det and log barriers are
// exact and smooth; the problem has at most ~100 unknowns, so dense Newton is cheap.
// (Why not NLopt or Ceres: Ceres takes only bounds, not matrix inequalities; NLopt's
// SLSQP would need the smallest eigenvalue as a constraint, which is not smooth where
// eigenvalues cross. The barrier gives the exact constrained optimum of this convex problem.)
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "arm_identification/physical_consistency.hpp"

namespace jg::dyn {

struct LinkConstraint {
  int first = 0;  ///< index of the link's 10 parameters in x
  LinkBounds bounds;
};

struct BarrierResult {
  Eigen::VectorXd x;
  int newton_steps = 0;
  bool converged = false;
};

/// Minimises 0.5 x^T Q x - c^T x over the entries where `free` is true (the others stay
/// at `start`), subject to the link constraints and x_k > 0 for k in `positive`. `start`
/// must satisfy every constraint strictly.
[[nodiscard]] BarrierResult constrained_minimize(const Eigen::MatrixXd& Q, const Eigen::VectorXd& c,
                                                 const Eigen::VectorXd& start, const std::vector<bool>& free,
                                                 const std::vector<LinkConstraint>& links,
                                                 const std::vector<int>& positive);

/// True when `p` satisfies the barrier's constraints strictly (same conditions as check_link).
[[nodiscard]] bool strictly_feasible(const LinkParams& p, const LinkBounds& b);

}  // namespace jg::dyn
