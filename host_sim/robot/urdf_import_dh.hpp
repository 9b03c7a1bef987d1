// Any serial chain of revolute joints written in modified Denavit-Hartenberg (Craig), the
// form the firmware's LinkConstants and the host plant use, plus one fixed rotation of the
// base that leaves gravity along -z.
//
// Construction (all geometry taken in the URDF root frame with every joint at zero):
// - z_i is joint i's axis, pointing along the URDF <axis> so that q maps one to one.
// - x_i is the common normal from axis i to axis i+1: z_i x z_{i+1} for skew or intersecting
//   axes, with the frame origin O_i at the normal's foot on axis i; for parallel axes the
//   normal through the foot of the previous normal (d = 0); for coincident axes the previous
//   x. The last joint keeps the previous x (offset 0).
// - The base frame 0 has z along "up" (the root's +z), so gravity stays (0, 0, -g), and x
//   along up x z_1: any tilt of the first axis becomes alpha_0, any turn about the vertical
//   is free (gravity does not see it).
// - alpha, a, theta_offset, d follow from consecutive frames; the result is checked by
//   rebuilding each transform.
// Link inertials are then re-expressed in their link's frame (dh_inertial).
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace jg::robot::dh {

/// A joint axis in the root frame at the zero configuration.
struct AxisLine {
  std::string joint;          ///< for messages
  Eigen::Vector3d point;      ///< a point on the axis (the URDF joint origin) [m]
  Eigen::Vector3d direction;  ///< unit, the URDF axis direction
};

/// A frame in the root frame: columns of `rotation` are x, y, z.
struct Frame {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
};

struct DhParameters {
  double alpha_prev = 0.0, a_prev = 0.0, theta_offset = 0.0, d = 0.0;  ///< [rad, m, rad, m]
};

/// Mass properties: mass [kg], centre of mass [m] and inertia about it [kg m^2], all in
/// one frame.
struct Inertial {
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_com = Eigen::Matrix3d::Zero();
};

/// Frame 0 (base) followed by one frame per joint; throws std::domain_error naming the
/// joints when two axes are so nearly parallel that their common normal lies far away.
/// The base frame's origin is the point nearest `base_origin` (the base link's) from which
/// frame 1 is reached by TransX(a_0) TransZ(d_1), so chains already written in D-H keep
/// their parameters.
std::vector<Frame> place_frames(const std::vector<AxisLine>& axes, const Eigen::Vector3d& up,
                                const Eigen::Vector3d& base_origin = Eigen::Vector3d::Zero());

/// D-H parameters from frame i-1 to frame i; throws std::domain_error when the pair is not
/// RotX(alpha) TransX(a) RotZ(theta) TransZ(d) (only when place_frames was bypassed).
DhParameters dh_between(const Frame& prev, const Frame& next);

/// `in` (root frame) re-expressed in `frame`.
Inertial to_frame(const Inertial& in, const Frame& frame);

/// Two bodies in the same frame as one (parallel-axis theorem).
Inertial lump(const Inertial& a, const Inertial& b);

}  // namespace jg::robot::dh
