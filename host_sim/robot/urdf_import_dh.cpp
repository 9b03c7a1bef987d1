#include "robot/urdf_import_dh.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace jg::robot::dh {
namespace {

// Axes closer to parallel than this (sine of the angle) are taken as parallel: vendor URDFs
// write pi/2 with 10 digits (2e-10 off), and the model error of snapping is below this.
constexpr double kParallelSine = 1e-9;
// A common normal farther than this from the URDF joint origins means nearly parallel axes
// that D-H can only write with huge, cancelling offsets (and the firmware's Q16.16 range
// would not hold them).
constexpr double kFarFoot_m = 100.0;
// Rebuilt transforms must match to this (rad and m).
constexpr double kCheckTolerance = 1e-7;

Eigen::Vector3d perpendicular(const Eigen::Vector3d& z, const Eigen::Vector3d& hint) {
  Eigen::Vector3d x = hint - hint.dot(z) * z;
  if (x.norm() < 1e-6) {  // the hint is along z: any perpendicular will do
    x = Eigen::Vector3d::UnitX() - z.x() * z;
    if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitY() - z.y() * z;
  }
  return x.normalized();
}

Frame make_frame(const Eigen::Vector3d& x_hint, const Eigen::Vector3d& z, const Eigen::Vector3d& origin) {
  Frame f;
  const Eigen::Vector3d x = perpendicular(z, x_hint);
  f.rotation.col(0) = x;
  f.rotation.col(1) = z.cross(x);
  f.rotation.col(2) = z;
  f.origin = origin;
  return f;
}

bool parallel(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.cross(b).norm() < kParallelSine; }

[[noreturn]] void nearly_parallel(const AxisLine& a, const AxisLine& b, double distance) {
  std::ostringstream s;
  s << "the axes of joints '" << a.joint << "' and '" << b.joint << "' are nearly parallel (angle "
    << std::asin(std::min(1.0, a.direction.cross(b.direction).norm())) << " rad): their common normal lies "
    << distance << " m away, beyond what modified D-H can hold; make them parallel or clearly skew";
  throw std::domain_error(s.str());
}

}  // namespace

std::vector<Frame> place_frames(const std::vector<AxisLine>& axes, const Eigen::Vector3d& up, const Eigen::Vector3d& base_origin) {
  const std::size_t n = axes.size();
  std::vector<Eigen::Vector3d> z(n), x(n), origin(n);
  for (std::size_t i = 0; i < n; ++i) z[i] = axes[i].direction.normalized();
  // Where the previous common normal meets axis i (for the first axis: its URDF origin).
  Eigen::Vector3d foot = axes.empty() ? Eigen::Vector3d::Zero() : axes[0].point;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const Eigen::Vector3d& z1 = z[i];
    const Eigen::Vector3d& z2 = z[i + 1];
    if (parallel(z1, z2)) {
      origin[i] = foot;
      const Eigen::Vector3d v = axes[i + 1].point - foot;
      const Eigen::Vector3d v_perp = v - v.dot(z1) * z1;
      if (v_perp.norm() > 1e-12) {
        x[i] = v_perp.normalized();
      } else if (i > 0) {
        x[i] = x[i - 1];  // coincident axes: keep the previous x (no offset)
      } else {
        x[i] = perpendicular(z1, up.cross(z1));
      }
      foot = foot + v_perp;
    } else {
      // Closest points of the lines p1 + s z1 and p2 + t z2.
      const Eigen::Vector3d w = axes[i].point - axes[i + 1].point;
      const double b = z1.dot(z2), dw1 = z1.dot(w), dw2 = z2.dot(w), denom = 1.0 - b * b;
      const double s = (b * dw2 - dw1) / denom, t = (dw2 - b * dw1) / denom;
      if (std::fabs(s) > kFarFoot_m || std::fabs(t) > kFarFoot_m) nearly_parallel(axes[i], axes[i + 1], std::max(std::fabs(s), std::fabs(t)));
      origin[i] = axes[i].point + s * z1;
      x[i] = z1.cross(z2).normalized();
      foot = axes[i + 1].point + t * z2;
    }
  }
  if (n > 0) {
    origin[n - 1] = foot;
    x[n - 1] = n >= 2 ? x[n - 2] : perpendicular(z[0], up.cross(z[0]));
  }
  std::vector<Frame> frames;
  frames.reserve(n + 1);
  const Eigen::Vector3d u = up.normalized();
  // Base: z up; x along up x z_1 so that RotX(alpha_0) carries z up onto the first axis.
  Frame base = make_frame(n > 0 && !parallel(u, z[0]) ? u.cross(z[0]) : (n > 0 ? x[0] : Eigen::Vector3d::UnitX()), u,
                          n > 0 ? origin[0] : base_origin);
  if (n > 0) {  // slide along x_0 and z_1 towards the base link's origin (gravity does not care)
    const Eigen::Vector3d xb = base.rotation.col(0), offset = origin[0] - base_origin;
    base.origin = origin[0] - offset.dot(xb) * xb - offset.dot(z[0]) * z[0];
  }
  frames.push_back(base);
  for (std::size_t i = 0; i < n; ++i) frames.push_back(make_frame(x[i], z[i], origin[i]));
  return frames;
}

DhParameters dh_between(const Frame& prev, const Frame& next) {
  const Eigen::Vector3d xp = prev.rotation.col(0), zp = prev.rotation.col(2);
  const Eigen::Vector3d xn = next.rotation.col(0), zn = next.rotation.col(2);
  const Eigen::Vector3d dp = next.origin - prev.origin;
  DhParameters p;
  p.alpha_prev = std::atan2(zp.cross(zn).dot(xp), zp.dot(zn));
  p.a_prev = dp.dot(xp);
  p.theta_offset = std::atan2(xp.cross(xn).dot(zn), xp.dot(xn));
  p.d = dp.dot(zn);
  // Rebuild prev^-1 next = RotX(alpha) TransX(a) RotZ(theta) TransZ(d) and compare.
  const Eigen::Matrix3d r_alpha = Eigen::AngleAxisd(p.alpha_prev, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d r = r_alpha * Eigen::AngleAxisd(p.theta_offset, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t = Eigen::Vector3d(p.a_prev, 0.0, 0.0) + r_alpha * Eigen::Vector3d(0.0, 0.0, p.d);
  const Eigen::Matrix3d r_true = prev.rotation.transpose() * next.rotation;
  const Eigen::Vector3d t_true = prev.rotation.transpose() * dp;
  if ((r - r_true).cwiseAbs().maxCoeff() > kCheckTolerance || (t - t_true).cwiseAbs().maxCoeff() > kCheckTolerance) {
    throw std::domain_error("frames are not related by RotX(alpha) TransX(a) RotZ(theta) TransZ(d)");
  }
  return p;
}

Inertial to_frame(const Inertial& in, const Frame& frame) {
  Inertial out;
  out.mass = in.mass;
  out.com = frame.rotation.transpose() * (in.com - frame.origin);
  out.inertia_com = frame.rotation.transpose() * in.inertia_com * frame.rotation;
  return out;
}

Inertial lump(const Inertial& a, const Inertial& b) {
  Inertial out;
  out.mass = a.mass + b.mass;
  if (!(out.mass > 0.0)) {  // massless parts: only their rotational inertia adds
    out.inertia_com = a.inertia_com + b.inertia_com;
    return out;
  }
  out.com = (a.mass * a.com + b.mass * b.com) / out.mass;
  // Parallel-axis theorem: each part's inertia moved from its CoM to the common one.
  const auto shifted = [&out](const Inertial& p) {
    const Eigen::Vector3d r = p.com - out.com;
    return Eigen::Matrix3d(p.inertia_com + p.mass * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose()));
  };
  out.inertia_com = shifted(a) + shifted(b);
  return out;
}

}  // namespace jg::robot::dh
