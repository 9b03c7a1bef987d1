// Sensitivity of the joint torques to one link's mass and first moment (m, m c_x, m c_y,
// m c_z), its rotational inertia about the link origin held fixed. The dynamics are linear
// in (m, m c, I_origin), so a finite step divided by its size is the exact column. Used by
// the diagnosis to fit a payload or a link's mass error once for the whole arm.
#pragma once

#include <array>

#include "dynamics/rigid_body.hpp"

namespace jg::sim {

/// d tau / d (m, m c_x, m c_y, m c_z) of link `link` (0-based) at one state; `tau0` (the
/// unperturbed torque) is returned too since every caller needs it.
std::array<JointVector, 4> mass_first_moment_sensitivity(const ArmDynamics& arm, int link, const JointVector& q,
                                                          const JointVector& qd, const JointVector& qdd,
                                                          JointVector* tau0 = nullptr);

/// The link with its mass and first moment changed by (dm, dh) and its rotational inertia
/// about the link origin kept: what the columns above fit (a payload, a link's mass error).
[[nodiscard]] PlantLink with_mass_first_moment_change(const PlantLink& link, double dm, const Eigen::Vector3d& dh);

/// The link with a point mass added at `at_m` [link frame] (a negative mass takes one back
/// out): mass, centre of mass and the inertia about the new centre by the parallel-axis
/// theorem, as the plant applies a payload. Adding keeps a physical inertia physical.
[[nodiscard]] PlantLink with_point_mass(const PlantLink& link, double mass_kg, const Eigen::Vector3d& at_m);

/// Whether the link's inertia about its centre of mass is a body's (positive semi-definite,
/// each principal moment at most the sum of the other two), to a rounding tolerance.
[[nodiscard]] bool physical_link_inertia(const PlantLink& link);

}  // namespace jg::sim
