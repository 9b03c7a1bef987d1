#include "robot/urdf_import.hpp"

#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <cmath>

#include "io/recording.hpp"

namespace jg::robot {
namespace {
Eigen::Matrix3d rotation(const urdf::Rotation& r) {
  return Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized().toRotationMatrix();
}
[[noreturn]] void refuse(const std::string& path, const std::string& joint, const std::string& why) {
  throw io::FormatError(path + ": joint '" + joint + "': " + why);
}
}  // namespace

RobotModel import_urdf(const std::string& path) {
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  if (!model) throw io::FormatError(path + ": not a readable URDF (urdfdom could not parse it)");
  RobotModel m;
  m.source = path;
  m.name = model->getName();
  urdf::LinkConstSharedPtr link = model->getRoot();
  while (link && !link->child_joints.empty()) {
    if (link->child_joints.size() > 1) refuse(path, link->name, "the chain branches here: only serial arms are supported");
    const urdf::JointSharedPtr j = link->child_joints.front();
    if (j->type == urdf::Joint::FIXED) break;  // tool flange / hand: the arm ends here
    if (j->type != urdf::Joint::REVOLUTE && j->type != urdf::Joint::CONTINUOUS) {
      refuse(path, j->name, "only revolute joints are supported");
    }
    if (std::fabs(j->axis.x) > 1e-9 || std::fabs(j->axis.y) > 1e-9 || std::fabs(std::fabs(j->axis.z) - 1.0) > 1e-9) {
      refuse(path, j->name, "joint axis must be the z axis of its frame (modified D-H)");
    }
    const Eigen::Matrix3d R = rotation(j->parent_to_joint_origin_transform.rotation);
    const urdf::Vector3& p = j->parent_to_joint_origin_transform.position;
    // RotX(alpha): R(0,0) = 1, R(0,1) = R(0,2) = R(1,0) = R(2,0) = 0.
    if (std::fabs(R(0, 0) - 1.0) > 1e-6 || std::fabs(R(0, 1)) > 1e-6 || std::fabs(R(0, 2)) > 1e-6) {
      refuse(path, j->name, "origin rotation is not a rotation about x: not modified-D-H representable");
    }
    JointDescription d;
    d.name = j->name;
    d.link.alpha_prev = std::atan2(R(2, 1), R(1, 1));
    d.link.a_prev = p.x;
    const double sa = std::sin(d.link.alpha_prev), ca = std::cos(d.link.alpha_prev);
    d.link.d = -sa * p.y + ca * p.z;  // the component along the rotated z axis
    if (std::fabs(ca * p.y + sa * p.z) > 1e-6) refuse(path, j->name, "origin offset has a component off the D-H axes");
    if (j->axis.z < 0.0) refuse(path, j->name, "axis -z: flip the joint in the URDF (positive z expected)");
    if (j->limits) {
      d.lower_rad = j->limits->lower;
      d.upper_rad = j->limits->upper;
      if (j->limits->effort > 0.0) d.link.current_limit = j->limits->effort / d.link.torque_constant;
    }
    link = model->getLink(j->child_link_name);
    if (link && link->inertial) {
      const auto& in = *link->inertial;
      const Eigen::Matrix3d Ri = rotation(in.origin.rotation);
      Eigen::Matrix3d I;
      I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
      const Eigen::Matrix3d Il = Ri * I * Ri.transpose();
      d.link.mass = in.mass;
      d.link.com[0] = in.origin.position.x;
      d.link.com[1] = in.origin.position.y;
      d.link.com[2] = in.origin.position.z;
      const double v[6] = {Il(0, 0), Il(1, 1), Il(2, 2), Il(0, 1), Il(0, 2), Il(1, 2)};
      for (int k = 0; k < 6; ++k) d.link.inertia_com[k] = v[k];
    }
    m.joints.push_back(d);
    if (m.joints.size() > static_cast<std::size_t>(kMaxJoints)) refuse(path, j->name, "more than 7 joints");
  }
  if (m.joints.empty()) throw io::FormatError(path + ": no revolute joint found from the root link");
  for (std::size_t i = 0; i + 1 < m.joints.size(); ++i) {
    m.joints[i].reach_m = std::max(0.05, std::hypot(m.joints[i + 1].link.a_prev, m.joints[i + 1].link.d));
  }
  return m;
}

}  // namespace jg::robot
