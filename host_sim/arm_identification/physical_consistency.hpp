// Physical consistency of one link's inertial parameters (about the link origin):
// mass above a floor, the second moment of mass about the CoM positive definite (the
// 4x4 pseudo-inertia matrix positive definite, which is the same as a positive-definite
// inertia about the CoM obeying the triangle inequalities strictly), and the CoM inside a
// sphere around the link origin. Each condition is convex in the parameters, so the
// feasible set is convex: along the segment from a feasible point to any other point the
// feasible part is one interval that starts at the feasible point.
#pragma once

#include <string>

#include "dynamics/regressor.hpp"

namespace jg::dyn {

struct LinkBounds {
  double min_mass_kg = 1e-3;          ///< mass floor
  double min_second_moment = 1e-7;    ///< smallest eigenvalue of the CoM second moment [kg m^2]
  double com_radius_m = 1.0;          ///< |c| <= this
};

struct Consistency {
  bool ok = false;
  double mass = 0.0, com_distance = 0.0, min_second_moment = 0.0;
  double min_triangle = 0.0;  ///< min over axes of (I_a + I_b - I_c) about the CoM [kg m^2]
  std::string reason;         ///< the first condition that fails, empty when ok
};

[[nodiscard]] Consistency check_link(const LinkParams& p, const LinkBounds& bounds);

/// Largest s in [0, 1] with from + s (to - from) feasible (bisection, 40 steps); `from`
/// must be feasible (returns 0 otherwise).
[[nodiscard]] double feasible_step(const LinkParams& from, const LinkParams& to, const LinkBounds& bounds);

}  // namespace jg::dyn
