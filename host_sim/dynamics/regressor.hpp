// The arm's inverse dynamics as a linear function of its inertial parameters:
// tau = Y(q, qd, qdd) pi, built exactly by Newton-Euler with the parameters entering
// linearly (each link's wrench is linear in its own 10 parameters; carrying it down the
// chain is linear too). Kinematics are those of sim::ArmDynamics (modified D-H).
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "dynamics/rigid_body.hpp"

namespace jg::dyn {

/// Standard inertial parameters of one link, about the link-frame origin, link axes:
/// [m, m c_x, m c_y, m c_z, I_xx, I_yy, I_zz, I_xy, I_xz, I_yz] (tensor entries:
/// I_xy is the (0,1) entry of the inertia matrix, as in the robot file).
inline constexpr int kLinkParams = 10;
using LinkParams = Eigen::Matrix<double, kLinkParams, 1>;

/// From a link's mass, CoM and inertia about the CoM (parallel-axis theorem).
[[nodiscard]] LinkParams link_params(const sim::PlantLink& link);
/// Back into mass, CoM and inertia about the CoM (kinematics and rotor inertia of `link`
/// kept). A zero mass leaves the CoM at zero and the inertia about the origin.
[[nodiscard]] sim::PlantLink with_params(const sim::PlantLink& link, const LinkParams& p);

/// Inertia about the origin (3x3) of a parameter vector, and about the CoM.
[[nodiscard]] Eigen::Matrix3d inertia_origin(const LinkParams& p);
[[nodiscard]] Eigen::Matrix3d inertia_com(const LinkParams& p);

/// Regressor of the link parameters for one sample: n x 10n, column block i belongs to
/// link i (0-based). Uses only the kinematics of `arm` and its gravity.
[[nodiscard]] Eigen::MatrixXd link_regressor(const sim::ArmDynamics& arm, const sim::JointVector& q,
                                             const sim::JointVector& qd, const sim::JointVector& qdd);

/// All parameters of the arm stacked [pi_1 .. pi_n] (10n).
[[nodiscard]] Eigen::VectorXd arm_params(const sim::ArmDynamics& arm);

}  // namespace jg::dyn
