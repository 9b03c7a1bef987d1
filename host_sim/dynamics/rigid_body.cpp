#include "dynamics/rigid_body.hpp"

#include <cmath>
#include <stdexcept>

namespace jg::sim {
namespace {
const Eigen::Vector3d kAxis(0.0, 0.0, 1.0);

/// A symmetric 3x3 matrix (an inertia) by its 6 unique entries [kg m^2].
struct Sym3 {
  double xx = 0.0, yy = 0.0, zz = 0.0, xy = 0.0, xz = 0.0, yz = 0.0;
};

/// Rz S Rz^T for Rz = RotZ with cos c, sin s.
inline Sym3 rotate_z(const Sym3& S, double c, double s) {
  const double cc = c * c, ss = s * s, cs = c * s;
  Sym3 o;
  o.xx = cc * S.xx - 2.0 * cs * S.xy + ss * S.yy;
  o.yy = ss * S.xx + 2.0 * cs * S.xy + cc * S.yy;
  o.zz = S.zz;
  o.xy = cs * (S.xx - S.yy) + (cc - ss) * S.xy;
  o.xz = c * S.xz - s * S.yz;
  o.yz = s * S.xz + c * S.yz;
  return o;
}

/// Rx S Rx^T for Rx = RotX with cos c, sin s (rotate_z with the axes cycled x->y->z).
inline Sym3 rotate_x(const Sym3& S, double c, double s) {
  const double cc = c * c, ss = s * s, cs = c * s;
  Sym3 o;
  o.xx = S.xx;
  o.yy = cc * S.yy - 2.0 * cs * S.yz + ss * S.zz;
  o.zz = ss * S.yy + 2.0 * cs * S.yz + cc * S.zz;
  o.yz = cs * (S.yy - S.zz) + (cc - ss) * S.yz;
  o.xy = c * S.xy - s * S.xz;
  o.xz = s * S.xy + c * S.xz;
  return o;
}
/// Cholesky M = L L^T in place (lower triangle; M is symmetric positive definite for a
/// physical arm, robot::check_simulatable), then L y = rhs, L^T x = y. A matrix that is not
/// positive definite gives NaN, which the simulation's divergence check reports. N > 0: the
/// joint count known at compile time (n == N); N == 0: n at run time.
template <int N>
inline void cholesky_solve(int n_runtime, double (*L)[kPlantMaxJoints], const double* rhs, double* x) {
  const int n = N > 0 ? N : n_runtime;
  for (int j = 0; j < n; ++j) {
    double d = L[j][j];
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    L[j][j] = std::sqrt(d);
    for (int i = j + 1; i < n; ++i) {
      double v = L[i][j];
      for (int k = 0; k < j; ++k) v -= L[i][k] * L[j][k];
      L[i][j] = v / L[j][j];
    }
  }
  double y[kPlantMaxJoints];
  for (int i = 0; i < n; ++i) {
    double v = rhs[i];
    for (int k = 0; k < i; ++k) v -= L[i][k] * y[k];
    y[i] = v / L[i][i];
  }
  for (int i = n - 1; i >= 0; --i) {
    double v = y[i];
    for (int k = i + 1; k < n; ++k) v -= L[k][i] * x[k];
    x[i] = v / L[i][i];
  }
}
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

template <int J>
void ArmDynamics::transforms(const double* q, Transforms& t) const {
  const int n = J > 0 ? J : joints();
  #pragma GCC unroll 7
  for (int i = 0; i < n; ++i) link_transform(i, q[i], t.R[i], t.p[i]);
}

void ArmDynamics::transforms(const JointVector& q, Transforms& t) const { transforms<0>(q.data(), t); }

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
  return mass_matrix_from(t);
}

JointMatrix ArmDynamics::mass_matrix_from(const Transforms& t) const {
  const int n = joints();
  double M[kPlantMaxJoints][kPlantMaxJoints];
  switch (n) {  // the controller's every cycle: unrolled for the common arms, as forward_dynamics
    case 3: crba_into<3>(t, M); break;
    case 6: crba_into<6>(t, M); break;
    default: crba_into<0>(t, M); break;
  }
  JointMatrix out(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) out(i, j) = M[i][j];
  }
  return out;
}

JointVector ArmDynamics::gravity_torque(const JointVector& q) const {
  Transforms t;
  transforms(q, t);
  return gravity_from(t);
}

void ArmDynamics::gravity_and_mass_matrix(const JointVector& q, JointVector& gravity, JointMatrix& mass) const {
  Transforms t;
  transforms(q, t);
  gravity = gravity_from(t);
  mass = mass_matrix_from(t);
}

JointVector ArmDynamics::gravity_from(const Transforms& t) const {
  // rnea() at rest (qd = qdd = 0): no angular velocity or acceleration anywhere, each
  // link's CoM accelerates with its frame's fictitious upward acceleration -g, and the
  // terms that are zero are not computed (the controller calls this every cycle).
  const int n = joints();
  Eigen::Vector3d F[kPlantMaxJoints];
  Eigen::Vector3d vd = -gravity_;
  for (int i = 0; i < n; ++i) {
    vd = t.R[i].transpose() * vd;
    F[i] = links_[static_cast<std::size_t>(i)].mass * vd;
  }
  JointVector tau(n);
  Eigen::Vector3d f = Eigen::Vector3d::Zero(), nm = Eigen::Vector3d::Zero();
  for (int i = n - 1; i >= 0; --i) {
    const PlantLink& l = links_[static_cast<std::size_t>(i)];
    if (i + 1 < n) {
      const Eigen::Vector3d f_child = t.R[i + 1] * f;
      nm = t.R[i + 1] * nm + t.p[i + 1].cross(f_child) + l.com.cross(F[i]);
      f = F[i] + f_child;
    } else {
      nm = l.com.cross(F[i]);
      f = F[i];
    }
    tau(i) = nm.z();
  }
  return tau;
}

JointVector ArmDynamics::forward_dynamics(const JointVector& q, const JointVector& qd, const JointVector& tau) const {
  JointVector qdd(joints());
  forward_dynamics(q.data(), qd.data(), tau.data(), qdd.data());
  return qdd;
}

void ArmDynamics::forward_dynamics(const double* q, const double* qd, const double* tau, double* qdd) const {
  // The joint count as a compile-time constant for the common arms (loops unrolled, the
  // small arrays in registers); the same operations in the same order for any count.
  switch (joints()) {
    case 3: forward_dynamics_n<3>(q, qd, tau, qdd); break;
    case 6: forward_dynamics_n<6>(q, qd, tau, qdd); break;
    default: forward_dynamics_n<0>(q, qd, tau, qdd); break;
  }
}

template <int J>
void ArmDynamics::forward_dynamics_n(const double* q, const double* qd, const double* tau, double* qdd) const {
  Transforms t;
  transforms<J>(q, t);
  const int n = J > 0 ? J : joints();
  // The mass matrix first: it needs q alone, so it overlaps with the end of the previous
  // RK4 stage's solution, on which qd (and the bias torque) waits.
  double L[kPlantMaxJoints][kPlantMaxJoints];
  crba_into<J>(t, L);
  double b[kPlantMaxJoints];
  bias_torque<J>(t, qd, b);
  double rhs[kPlantMaxJoints];
  for (int i = 0; i < n; ++i) rhs[i] = tau[i] - b[i];
  cholesky_solve<J>(n, L, rhs, qdd);
}

template <int J>
void ArmDynamics::bias_torque(const Transforms& t, const double* qd, double* bias) const {
  // rnea() with qdd = 0 and gravity: C(q,qd) qd + g(q).
  const int n = J > 0 ? J : joints();
  const Eigen::Matrix3d* R = t.R;
  const Eigen::Vector3d* p = t.p;
  Eigen::Vector3d F[kPlantMaxJoints], N[kPlantMaxJoints];
  Eigen::Vector3d w = Eigen::Vector3d::Zero(), wd = Eigen::Vector3d::Zero();
  Eigen::Vector3d vd = -gravity_;
  #pragma GCC unroll 7
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d a = R[i].transpose() * w;  // parent's angular velocity in frame i
    vd = R[i].transpose() * (wd.cross(p[i]) + w.cross(w.cross(p[i])) + vd);
    const double s = qd[i];
    w = Eigen::Vector3d(a.x(), a.y(), a.z() + s);
    // (R^T wd) + a x (s z) = R^T wd + (a_y s, -a_x s, 0)
    wd = R[i].transpose() * wd;
    wd.x() += a.y() * s;
    wd.y() -= a.x() * s;
    const PlantLink& l = links_[static_cast<std::size_t>(i)];
    const Eigen::Vector3d vdc = wd.cross(l.com) + w.cross(w.cross(l.com)) + vd;
    F[i] = l.mass * vdc;
    N[i] = l.inertia_com * wd + w.cross(l.inertia_com * w);
  }
  Eigen::Vector3d f = Eigen::Vector3d::Zero(), nm = Eigen::Vector3d::Zero();
  #pragma GCC unroll 7
  for (int i = n - 1; i >= 0; --i) {
    const PlantLink& l = links_[static_cast<std::size_t>(i)];
    if (i + 1 < n) {
      const Eigen::Vector3d f_child = R[i + 1] * f;
      const Eigen::Vector3d n_child = R[i + 1] * nm + p[i + 1].cross(f_child);
      nm = N[i] + n_child + l.com.cross(F[i]);
      f = F[i] + f_child;
    } else {
      nm = N[i] + l.com.cross(F[i]);
      f = F[i];
    }
    bias[i] = nm.z();
  }
}

template <int J>
void ArmDynamics::crba_into(const Transforms& t, double (*M)[kPlantMaxJoints]) const {
  // Composite-rigid-body algorithm on Sym3: the composite of links i..n-1 in frame i, mass m, first moment h,
  // rotational inertia I about the origin of frame i. R[i+1] = RotX(alpha_i) RotZ(theta_{i+1}),
  // so R I R^T is two plane rotations of a symmetric matrix.
  const int n = J > 0 ? J : joints();
  const Eigen::Matrix3d* R = t.R;
  const Eigen::Vector3d* p = t.p;
  double m = 0.0;
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  Sym3 I;
  #pragma GCC unroll 7
  for (int i = n - 1; i >= 0; --i) {
    if (i + 1 < n) {  // move the composite of i+1.. into frame i
      // Parallel-axis shift by p of a body with first moment Rh and mass m, with
      // [a]x[b]x = b a^T - (a.b) 1 instead of products of skew matrices:
      //   -[Rh]x[p]x - [p]x[Rh]x - m [p]x[p]x = 2 (p.Rh) 1 - p Rh^T - Rh p^T + m (|p|^2 1 - p p^T)
      const Eigen::Matrix3d& Rn = R[i + 1];
      // R = RotX(alpha) RotZ(theta): R(0,0) = cos theta, R(0,1) = -sin theta,
      // R(2,2) = cos alpha, R(1,2) = -sin alpha.
      I = rotate_x(rotate_z(I, Rn(0, 0), -Rn(0, 1)), Rn(2, 2), -Rn(1, 2));
      const Eigen::Vector3d& pi = p[i + 1];
      const Eigen::Vector3d Rh = Rn * h;
      const double diag = 2.0 * pi.dot(Rh) + m * pi.squaredNorm();
      I.xx += diag - 2.0 * pi.x() * Rh.x() - m * pi.x() * pi.x();
      I.yy += diag - 2.0 * pi.y() * Rh.y() - m * pi.y() * pi.y();
      I.zz += diag - 2.0 * pi.z() * Rh.z() - m * pi.z() * pi.z();
      I.xy -= pi.x() * Rh.y() + Rh.x() * pi.y() + m * pi.x() * pi.y();
      I.xz -= pi.x() * Rh.z() + Rh.x() * pi.z() + m * pi.x() * pi.z();
      I.yz -= pi.y() * Rh.z() + Rh.y() * pi.z() + m * pi.y() * pi.z();
      h = Rh + m * pi;
    }
    const PlantLink& l = links_[static_cast<std::size_t>(i)];
    // Own link about its origin: I_com + m (|c|^2 1 - c c^T).
    const Eigen::Vector3d& c = l.com;
    const Eigen::Matrix3d& Ic = l.inertia_com;
    const double mc2 = l.mass * c.squaredNorm();
    I.xx += Ic(0, 0) + mc2 - l.mass * c.x() * c.x();
    I.yy += Ic(1, 1) + mc2 - l.mass * c.y() * c.y();
    I.zz += Ic(2, 2) + mc2 - l.mass * c.z() * c.z();
    I.xy += Ic(0, 1) - l.mass * c.x() * c.y();
    I.xz += Ic(0, 2) - l.mass * c.x() * c.z();
    I.yz += Ic(1, 2) - l.mass * c.y() * c.z();
    h += l.mass * c;
    m += l.mass;
    // Force and moment (about origin i) on the composite for a unit acceleration of joint i.
    Eigen::Vector3d f(-h.y(), h.x(), 0.0);  // z x h
    Eigen::Vector3d nmom(I.xz, I.yz, I.zz);  // I z
    M[i][i] = I.zz + l.rotor_inertia;
    #pragma GCC unroll 7
    for (int j = i - 1; j >= 0; --j) {  // carry it down to frame j
      const Eigen::Vector3d f_j = R[j + 1] * f;
      nmom = R[j + 1] * nmom + p[j + 1].cross(f_j);
      f = f_j;
      M[j][i] = M[i][j] = nmom.z();
    }
  }
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
