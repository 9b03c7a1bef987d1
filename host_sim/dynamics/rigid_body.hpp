// Rigid-body dynamics of a serial revolute arm (host only, double), shared by the plant,
// detection and diagnosis, and the base of whole-arm identification (host_sim/dynamics/).
// Independent of the firmware's momentum recursion on purpose: the plant is the truth
// the firmware is tested against. Inverse dynamics by recursive Newton-Euler, the mass
// matrix by the composite-rigid-body algorithm, forward dynamics by Cholesky.
// Kinematics: modified Denavit-Hartenberg (Craig): frame i is reached from frame i-1 by
// RotX(alpha_{i-1}) TransX(a_{i-1}) RotZ(theta_i + offset_i) TransZ(d_i).
#pragma once

#include <Eigen/Dense>
#include <limits>
#include <vector>

namespace jg::sim {

inline constexpr int kPlantMaxJoints = 7;

struct PlantLink {
  double a_prev = 0.0, alpha_prev = 0.0, d = 0.0, theta_offset = 0.0;  ///< modified D-H [m, rad]
  double mass = 0.0;                                                  ///< [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();                      ///< in link frame [m]
  Eigen::Matrix3d inertia_com = Eigen::Matrix3d::Zero();              ///< about the CoM, link axes [kg m^2]
  double rotor_inertia = 0.0;  ///< reflected to the link side (J_m N^2) [kg m^2]
};

using JointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kPlantMaxJoints, 1>;
using JointMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kPlantMaxJoints, kPlantMaxJoints>;

/// Per-link pose in the base frame.
struct LinkPoses {
  Eigen::Matrix3d rotation[kPlantMaxJoints];  ///< base_R_i
  Eigen::Vector3d origin[kPlantMaxJoints];    ///< base p_i
};

class ArmDynamics {
 public:
  ArmDynamics(std::vector<PlantLink> links, Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.81));

  [[nodiscard]] int joints() const { return static_cast<int>(links_.size()); }
  [[nodiscard]] const PlantLink& link(int i) const { return links_[static_cast<std::size_t>(i)]; }
  [[nodiscard]] PlantLink& link(int i) { return links_[static_cast<std::size_t>(i)]; }
  [[nodiscard]] const Eigen::Vector3d& gravity() const { return gravity_; }

  /// tau = M(q) qdd + C(q,qd) qd + g(q) (rigid links; rotor inertia on the diagonal of M).
  [[nodiscard]] JointVector inverse_dynamics(const JointVector& q, const JointVector& qd,
                                             const JointVector& qdd, bool with_gravity = true) const;
  /// M(q) including the reflected rotor inertia.
  [[nodiscard]] JointMatrix mass_matrix(const JointVector& q) const;
  [[nodiscard]] JointVector gravity_torque(const JointVector& q) const;
  /// qdd = M^-1 (tau - C qd - g).
  [[nodiscard]] JointVector forward_dynamics(const JointVector& q, const JointVector& qd,
                                             const JointVector& tau) const;
  /// The same on plain arrays of joints() values (the plant's RK4 stages): the same
  /// operations in the same order, so the same doubles.
  void forward_dynamics(const double* q, const double* qd, const double* tau, double* qdd) const;
  /// gravity_torque(q) and mass_matrix(q) from one set of link transforms (the controller
  /// needs both every cycle): the same doubles as the two calls.
  void gravity_and_mass_matrix(const JointVector& q, JointVector& gravity, JointMatrix& mass) const;

  [[nodiscard]] LinkPoses poses(const JointVector& q) const;
  /// Geometric Jacobian rows 0-2 (linear velocity) of a point fixed on link `link`
  /// (0-based), given in that link's frame; columns beyond `link` are zero.
  [[nodiscard]] Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kPlantMaxJoints> point_jacobian(
      const JointVector& q, int link, const Eigen::Vector3d& point_in_link) const;
  [[nodiscard]] double kinetic_energy(const JointVector& q, const JointVector& qd) const;
  [[nodiscard]] double potential_energy(const JointVector& q) const;

 private:
  /// Parent-to-link transforms for one configuration, shared by the algorithms below.
  struct Transforms {
    Eigen::Matrix3d R[kPlantMaxJoints];
    Eigen::Vector3d p[kPlantMaxJoints];
  };
  template <int N>
  void transforms(const double* q, Transforms& t) const;
  void transforms(const JointVector& q, Transforms& t) const;
  JointVector gravity_from(const Transforms& t) const;
  JointMatrix mass_matrix_from(const Transforms& t) const;
  JointVector rnea(const Transforms& t, const JointVector& qd, const JointVector& qdd, bool with_gravity) const;
  /// The forward dynamics' hot path (the plant calls it four times per RK4 step) on plain
  /// fixed-capacity arrays, no Eigen dynamic-size temporaries: the bias torque (RNEA at
  /// qdd = 0) and the mass matrix (composite-rigid-body algorithm on symmetric 3x3
  /// inertias rotated by the joint's RotZ then the twist's RotX, 6 unique entries; also
  /// mass_matrix()). Same algorithm as rnea() for the bias, results equal up to rounding.
  /// N > 0: the joint count known at compile time (N == joints(), loops unrolled for the
  /// common arms); N == 0: joints() at run time; the same operations in the same order.
  template <int N>
  void bias_torque(const Transforms& t, const double* qd, double* bias) const;
  template <int N>
  void crba_into(const Transforms& t, double (*M)[kPlantMaxJoints]) const;
  template <int N>
  void forward_dynamics_n(const double* q, const double* qd, const double* tau, double* qdd) const;
  void link_transform(int i, double q, Eigen::Matrix3d& parent_R_i, Eigen::Vector3d& parent_p_i) const;
  std::vector<PlantLink> links_;
  Eigen::Vector3d gravity_;
  /// cos/sin of each link's alpha_prev, for the alpha they were computed from.
  struct AlphaTrig {
    double alpha = std::numeric_limits<double>::quiet_NaN(), cos = 1.0, sin = 0.0;
  };
  std::vector<AlphaTrig> alpha_trig_;
};

}  // namespace jg::sim
