#include "dynamics/rigid_body.hpp"

#include <cmath>
#include <stdexcept>

namespace jg::sim {
namespace {
const Eigen::Vector3d kAxis(0.0, 0.0, 1.0);
}  // namespace

ArmDynamics::ArmDynamics(std::vector<PlantLink> links, Eigen::Vector3d gravity)
    : links_(std::move(links)), gravity_(std::move(gravity)), alpha_trig_(links_.size()) {
  if (links_.empty() || links_.size() > static_cast<std::size_t>(kPlantMaxJoints)) {
    throw std::invalid_argument("ArmDynamics: 1 to 7 links supported");
  }
  for (const auto& l : links_) {
    if (!(l.mass >= 0.0) || !(l.rotor_inertia >= 0.0)) {
      throw std::invalid_argument("ArmDynamics: negative mass or rotor inertia");
    }
  }
  for (std::size_t i = 0; i < links_.size(); ++i) {
    alpha_trig_[i] = {links_[i].alpha_prev, std::cos(links_[i].alpha_prev), std::sin(links_[i].alpha_prev)};
  }
}

void ArmDynamics::link_transform(int i, double q, Eigen::Matrix3d& R, Eigen::Vector3d& p) const {
  const PlantLink& l = links_[static_cast<std::size_t>(i)];
  // cos/sin of the constant twist once per link (constructor), not per call; computed here
  // only when a caller has changed the twist through link(i) since (no cache written on a
  // const path: one ArmDynamics may be read from several threads).
  const AlphaTrig& a = alpha_trig_[static_cast<std::size_t>(i)];
  const bool fresh = a.alpha == l.alpha_prev;
  const double ca = fresh ? a.cos : std::cos(l.alpha_prev), sa = fresh ? a.sin : std::sin(l.alpha_prev);
  const double th = q + l.theta_offset;
  const double ct = std::cos(th), st = std::sin(th);
  // RotX(alpha) * RotZ(theta)
  R << ct, -st, 0.0, ca * st, ca * ct, -sa, sa * st, sa * ct, ca;
  p << l.a_prev, -sa * l.d, ca * l.d;
}

void ArmDynamics::transforms(const JointVector& q, Transforms& t) const {
  for (int i = 0; i < joints(); ++i) link_transform(i, q(i), t.R[i], t.p[i]);
}

JointVector ArmDynamics::inverse_dynamics(const JointVector& q, const JointVector& qd, const JointVector& qdd,
                                          bool with_gravity) const {
  Transforms t;
  transforms(q, t);
  return rnea(t, qd, qdd, with_gravity);
}

JointVector ArmDynamics::rnea(const Transforms& t, const JointVector& qd, const JointVector& qdd,
                              bool with_gravity) const {
  const int n = joints();
  const Eigen::Matrix3d* R = t.R;
  const Eigen::Vector3d* p = t.p;
  Eigen::Vector3d F[kPlantMaxJoints], N[kPlantMaxJoints];
  Eigen::Vector3d w = Eigen::Vector3d::Zero(), wd = Eigen::Vector3d::Zero();
  // Gravity as a fictitious upward acceleration of the base.
  Eigen::Vector3d vd = with_gravity ? Eigen::Vector3d(-gravity_) : Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d Rt = R[i].transpose();
    const Eigen::Vector3d w_parent = w;
    const Eigen::Vector3d wd_parent = wd;
    vd = Rt * (wd_parent.cross(p[i]) + w_parent.cross(w_parent.cross(p[i])) + vd);
    w = Rt * w_parent + qd(i) * kAxis;
    wd = Rt * wd_parent + (Rt * w_parent).cross(qd(i) * kAxis) + qdd(i) * kAxis;
    const PlantLink& l = links_[static_cast<std::size_t>(i)];
    const Eigen::Vector3d vdc = wd.cross(l.com) + w.cross(w.cross(l.com)) + vd;
    F[i] = l.mass * vdc;
    N[i] = l.inertia_com * wd + w.cross(l.inertia_com * w);
  }
  JointVector tau(n);
  Eigen::Vector3d f = Eigen::Vector3d::Zero(), nm = Eigen::Vector3d::Zero();
  for (int i = n - 1; i >= 0; --i) {
    const PlantLink& l = links_[static_cast<std::size_t>(i)];
    Eigen::Vector3d f_child = Eigen::Vector3d::Zero(), n_child = Eigen::Vector3d::Zero();
    if (i + 1 < n) {
      f_child = R[i + 1] * f;
      n_child = R[i + 1] * nm + p[i + 1].cross(f_child);
    }
    nm = N[i] + n_child + l.com.cross(F[i]);
    f = F[i] + f_child;
    tau(i) = nm.z() + l.rotor_inertia * qdd(i);
  }
  return tau;
}

JointMatrix ArmDynamics::mass_matrix(const JointVector& q) const {
  Transforms t;
  transforms(q, t);
  return crba(t);
}

JointMatrix ArmDynamics::crba(const Transforms& t) const {
  // Composite-rigid-body algorithm. Composite body of links i..n-1 in frame i: mass m,
  // first moment h = m c, rotational inertia I about the origin of frame i.
  const int n = joints();
  const Eigen::Matrix3d* R = t.R;
  const Eigen::Vector3d* p = t.p;
  JointMatrix M = JointMatrix::Zero(n, n);
  double m = 0.0;
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  for (int i = n - 1; i >= 0; --i) {
    if (i + 1 < n) {  // move the composite of i+1.. into frame i
      // Parallel-axis shift by p of a body with first moment Rh and mass m, with
      // [a]x[b]x = b a^T - (a.b) 1 instead of products of skew matrices:
      //   -[Rh]x[p]x - [p]x[Rh]x - m [p]x[p]x = 2 (p.Rh) 1 - p Rh^T - Rh p^T + m (|p|^2 1 - p p^T)
      const Eigen::Vector3d& pi = p[i + 1];
      const Eigen::Vector3d Rh = R[i + 1] * h;
      const Eigen::Matrix3d pRh = pi * Rh.transpose();
      I = R[i + 1] * I * R[i + 1].transpose() - pRh - pRh.transpose() - m * (pi * pi.transpose());
      I.diagonal().array() += 2.0 * pi.dot(Rh) + m * pi.squaredNorm();
      h = Rh + m * pi;
    }
    const PlantLink& l = links_[static_cast<std::size_t>(i)];
    // Own link about its origin: I_com - m [c]x[c]x = I_com + m (|c|^2 1 - c c^T).
    I += l.inertia_com - l.mass * (l.com * l.com.transpose());
    I.diagonal().array() += l.mass * l.com.squaredNorm();
    h += l.mass * l.com;
    m += l.mass;
    // Force and moment (about origin i) on the composite for a unit acceleration of joint i.
    Eigen::Vector3d f = kAxis.cross(h);  // m * (z x c)
    Eigen::Vector3d nmom = I * kAxis;
    M(i, i) = nmom.z() + l.rotor_inertia;
    for (int j = i - 1; j >= 0; --j) {  // carry it down to frame j
      const Eigen::Vector3d f_j = R[j + 1] * f;
      nmom = R[j + 1] * nmom + p[j + 1].cross(f_j);
      f = f_j;
      M(j, i) = M(i, j) = nmom.z();
    }
  }
  return M;
}

JointVector ArmDynamics::gravity_torque(const JointVector& q) const {
  const JointVector zero = JointVector::Zero(joints());
  JointVector g = inverse_dynamics(q, zero, zero, true);
  return g;
}

JointVector ArmDynamics::forward_dynamics(const JointVector& q, const JointVector& qd, const JointVector& tau) const {
  Transforms t;
  transforms(q, t);
  const JointVector bias = rnea(t, qd, JointVector::Zero(joints()), true);
  return crba(t).llt().solve(tau - bias);
}

LinkPoses ArmDynamics::poses(const JointVector& q) const {
  LinkPoses out;
  Eigen::Matrix3d Rb = Eigen::Matrix3d::Identity();
  Eigen::Vector3d pb = Eigen::Vector3d::Zero();
  for (int i = 0; i < joints(); ++i) {
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    link_transform(i, q(i), R, p);
    pb = pb + Rb * p;
    Rb = Rb * R;
    out.rotation[i] = Rb;
    out.origin[i] = pb;
  }
  return out;
}

Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kPlantMaxJoints> ArmDynamics::point_jacobian(
    const JointVector& q, int link, const Eigen::Vector3d& point_in_link) const {
  const LinkPoses P = poses(q);
  const Eigen::Vector3d x = P.origin[link] + P.rotation[link] * point_in_link;
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kPlantMaxJoints> J =
      Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kPlantMaxJoints>::Zero(3, joints());
  for (int j = 0; j <= link; ++j) {
    J.col(j) = (P.rotation[j] * kAxis).cross(x - P.origin[j]);
  }
  return J;
}

double ArmDynamics::kinetic_energy(const JointVector& q, const JointVector& qd) const {
  return 0.5 * qd.dot(mass_matrix(q) * qd);
}

double ArmDynamics::potential_energy(const JointVector& q) const {
  const LinkPoses P = poses(q);
  double v = 0.0;
  for (int i = 0; i < joints(); ++i) {
    const PlantLink& l = links_[static_cast<std::size_t>(i)];
    v -= l.mass * gravity_.dot(P.origin[i] + P.rotation[i] * l.com);
  }
  return v;
}

}  // namespace jg::sim
