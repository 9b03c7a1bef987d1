#include "dynamics/sensitivity.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace jg::sim {

std::array<JointVector, 4> mass_first_moment_sensitivity(const ArmDynamics& arm, int link, const JointVector& q,
                                                          const JointVector& qd, const JointVector& qdd,
                                                          JointVector* tau0_out) {
  // Linear in (m, m c, I_origin): the difference of two parameter sets does not depend on
  // where it is taken, so take it about a reference link of 1 kg with its centre at the
  // origin (well defined for a massless link too).
  const Eigen::Matrix3d eye = Eigen::Matrix3d::Identity();
  PlantLink ref = arm.link(link);
  ref.mass = 1.0;
  ref.com.setZero();
  ref.inertia_com = 0.01 * eye;
  const Eigen::Matrix3d inertia_origin = ref.inertia_com;
  constexpr double kStep = 0.01;
  ArmDynamics plus = arm;
  if (tau0_out != nullptr) *tau0_out = arm.inverse_dynamics(q, qd, qdd);
  plus.link(link) = ref;
  const JointVector tau_ref = plus.inverse_dynamics(q, qd, qdd);
  std::array<JointVector, 4> out;
  for (int p = 0; p < 4; ++p) {
    double mass = ref.mass;
    Eigen::Vector3d first = Eigen::Vector3d::Zero();
    if (p == 0) {
      mass += kStep;
    } else {
      first(p - 1) += kStep;
    }
    PlantLink l = ref;
    l.mass = mass;
    l.com = first / mass;
    l.inertia_com = inertia_origin - mass * (l.com.squaredNorm() * eye - l.com * l.com.transpose());
    plus.link(link) = l;
    out[static_cast<std::size_t>(p)] = (plus.inverse_dynamics(q, qd, qdd) - tau_ref) / kStep;
  }
  return out;
}

PlantLink with_mass_first_moment_change(const PlantLink& link, double dm, const Eigen::Vector3d& dh) {
  const Eigen::Matrix3d eye = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d inertia_origin =
      link.inertia_com + link.mass * (link.com.squaredNorm() * eye - link.com * link.com.transpose());
  PlantLink out = link;
  out.mass = std::max(1e-9, link.mass + dm);
  out.com = (link.mass * link.com + dh) / out.mass;
  out.inertia_com = inertia_origin - out.mass * (out.com.squaredNorm() * eye - out.com * out.com.transpose());
  return out;
}

PlantLink with_point_mass(const PlantLink& link, double mass_kg, const Eigen::Vector3d& at_m) {
  const Eigen::Matrix3d eye = Eigen::Matrix3d::Identity();
  auto about_origin = [&](double m, const Eigen::Vector3d& c) { return Eigen::Matrix3d(m * (c.squaredNorm() * eye - c * c.transpose())); };
  const Eigen::Matrix3d inertia_origin = link.inertia_com + about_origin(link.mass, link.com) + about_origin(mass_kg, at_m);
  PlantLink out = link;
  out.mass = std::max(1e-9, link.mass + mass_kg);
  out.com = (link.mass * link.com + mass_kg * at_m) / out.mass;
  out.inertia_com = inertia_origin - about_origin(out.mass, out.com);
  return out;
}

bool physical_link_inertia(const PlantLink& link) {
  const Eigen::Matrix3d& i = link.inertia_com;
  const double tol = 1e-12 * (std::abs(i.trace()) + 1e-300);
  // The second moment of the mass, tr(I)/2 - I, is positive semi-definite exactly for a body.
  const Eigen::Matrix3d second = 0.5 * i.trace() * Eigen::Matrix3d::Identity() - i;
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(second).eigenvalues().minCoeff() >= -tol;
}

}  // namespace jg::sim
