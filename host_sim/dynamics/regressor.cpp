#include "dynamics/regressor.hpp"

namespace jg::dyn {
namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

/// L(v) with L(v) [Ixx Iyy Izz Ixy Ixz Iyz]^T = I v.
Eigen::Matrix<double, 3, 6> inertia_times(const Eigen::Vector3d& v) {
  Eigen::Matrix<double, 3, 6> L;
  L << v.x(), 0.0, 0.0, v.y(), v.z(), 0.0,  //
      0.0, v.y(), 0.0, v.x(), 0.0, v.z(),   //
      0.0, 0.0, v.z(), 0.0, v.x(), v.y();
  return L;
}

void link_transform(const sim::PlantLink& l, double q, Eigen::Matrix3d& R, Eigen::Vector3d& p) {
  // Same convention as ArmDynamics: RotX(alpha_prev) TransX(a_prev) RotZ(q + offset) TransZ(d).
  const double ca = std::cos(l.alpha_prev), sa = std::sin(l.alpha_prev);
  const double th = q + l.theta_offset;
  const double ct = std::cos(th), st = std::sin(th);
  R << ct, -st, 0.0, ca * st, ca * ct, -sa, sa * st, sa * ct, ca;
  p << l.a_prev, -sa * l.d, ca * l.d;
}

}  // namespace

Eigen::Matrix3d inertia_origin(const LinkParams& p) {
  Eigen::Matrix3d I;
  I << p(4), p(7), p(8), p(7), p(5), p(9), p(8), p(9), p(6);
  return I;
}

Eigen::Matrix3d inertia_com(const LinkParams& p) {
  const Eigen::Matrix3d Io = inertia_origin(p);
  if (!(p(0) > 0.0)) return Io;
  const Eigen::Vector3d c = p.segment<3>(1) / p(0);
  // I_o = I_c - m [c]x^2  =>  I_c = I_o + m [c]x^2
  return Io + p(0) * skew(c) * skew(c);
}

LinkParams link_params(const sim::PlantLink& link) {
  LinkParams p;
  p(0) = link.mass;
  p.segment<3>(1) = link.mass * link.com;
  const Eigen::Matrix3d sc = skew(link.com);
  const Eigen::Matrix3d Io = link.inertia_com - link.mass * sc * sc;
  p(4) = Io(0, 0);
  p(5) = Io(1, 1);
  p(6) = Io(2, 2);
  p(7) = Io(0, 1);
  p(8) = Io(0, 2);
  p(9) = Io(1, 2);
  return p;
}

sim::PlantLink with_params(const sim::PlantLink& link, const LinkParams& p) {
  sim::PlantLink out = link;
  out.mass = p(0);
  out.com = p(0) > 0.0 ? Eigen::Vector3d(p.segment<3>(1) / p(0)) : Eigen::Vector3d::Zero();
  out.inertia_com = inertia_com(p);
  return out;
}

Eigen::VectorXd arm_params(const sim::ArmDynamics& arm) {
  const int n = arm.joints();
  Eigen::VectorXd pi(kLinkParams * n);
  for (int i = 0; i < n; ++i) pi.segment<kLinkParams>(kLinkParams * i) = link_params(arm.link(i));
  return pi;
}

Eigen::MatrixXd link_regressor(const sim::ArmDynamics& arm, const sim::JointVector& q, const sim::JointVector& qd,
                               const sim::JointVector& qdd) {
  const int n = arm.joints();
  const Eigen::Vector3d z(0.0, 0.0, 1.0);
  Eigen::Matrix3d R[sim::kPlantMaxJoints];
  Eigen::Vector3d p[sim::kPlantMaxJoints];
  Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(n, kLinkParams * n);
  // Forward pass: angular velocity/acceleration and origin acceleration of each link in
  // its own frame; gravity enters as an upward acceleration of the base.
  Eigen::Vector3d w = Eigen::Vector3d::Zero(), wd = Eigen::Vector3d::Zero();
  Eigen::Vector3d vd = -arm.gravity();
  for (int i = 0; i < n; ++i) {
    link_transform(arm.link(i), q(i), R[i], p[i]);
    const Eigen::Matrix3d Rt = R[i].transpose();
    vd = Rt * (wd.cross(p[i]) + w.cross(w.cross(p[i])) + vd);
    const Eigen::Vector3d w_in = Rt * w;
    w = w_in + qd(i) * z;
    wd = Rt * wd + w_in.cross(qd(i) * z) + qdd(i) * z;
    // Wrench of link i about its origin, linear in pi_i:
    //   f = m vd + [wd]x h + [w]x[w]x h,   n = I_o wd + w x (I_o w) + h x vd.
    Eigen::Matrix<double, 6, kLinkParams> A = Eigen::Matrix<double, 6, kLinkParams>::Zero();
    A.block<3, 1>(0, 0) = vd;
    A.block<3, 3>(0, 1) = skew(wd) + skew(w) * skew(w);
    A.block<3, 3>(3, 1) = -skew(vd);
    A.block<3, 6>(3, 4) = inertia_times(wd) + skew(w) * inertia_times(w);
    // Carry it down the chain: joint j's torque is the z moment about origin j.
    Eigen::Matrix<double, 3, kLinkParams> F = A.topRows<3>(), N = A.bottomRows<3>();
    for (int j = i; j >= 0; --j) {
      Y.block(j, kLinkParams * i, 1, kLinkParams) = N.row(2);
      if (j == 0) break;
      const Eigen::Matrix<double, 3, kLinkParams> Fp = R[j] * F;
      N = R[j] * N + skew(p[j]) * Fp;
      F = Fp;
    }
  }
  return Y;
}

}  // namespace jg::dyn
