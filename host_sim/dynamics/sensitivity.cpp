#include "dynamics/sensitivity.hpp"

#include <algorithm>

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

}  // namespace jg::sim
