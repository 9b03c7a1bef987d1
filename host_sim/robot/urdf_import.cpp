#include "robot/urdf_import.hpp"

#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "io/recording.hpp"
#include "robot/urdf_import_dh.hpp"
#include "robot/urdf_read.hpp"

namespace jg::robot {
namespace {

[[noreturn]] void refuse(const std::string& path, const std::string& what) { throw io::FormatError(path + ": " + what); }

// --- The chain ------------------------------------------------------------------------

Eigen::Isometry3d pose_of(const urdf::Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).normalized().toRotationMatrix();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return t;
}

bool moving(const urdf::Joint& j) { return j.type != urdf::Joint::FIXED; }

const char* type_name(int type) {
  switch (type) {
    case urdf::Joint::REVOLUTE: return "revolute";
    case urdf::Joint::CONTINUOUS: return "continuous";
    case urdf::Joint::PRISMATIC: return "prismatic";
    case urdf::Joint::FLOATING: return "floating";
    case urdf::Joint::PLANAR: return "planar";
    case urdf::Joint::FIXED: return "fixed";
    default: return "unknown";
  }
}

/// Moving joints from `base` down to `link` (outermost last); empty when `link` is not
/// below `base`, `found` tells.
std::vector<urdf::JointConstSharedPtr> moving_joints_between(const urdf::ModelInterface& m, const std::string& base,
                                                               const std::string& link, bool& found) {
  std::vector<urdf::JointConstSharedPtr> out;
  found = false;
  urdf::LinkConstSharedPtr l = m.getLink(link);
  while (l) {
    if (l->name == base) {
      found = true;
      break;
    }
    const urdf::JointConstSharedPtr j = l->parent_joint;
    if (!j) break;
    if (moving(*j)) out.insert(out.begin(), j);
    l = m.getLink(j->parent_link_name);
  }
  return out;
}

void leaves_below(const urdf::Link& link, std::vector<std::string>& out) {
  if (link.child_links.empty()) out.push_back(link.name);
  for (const auto& c : link.child_links) leaves_below(*c, out);
}

std::string default_tip(const std::string& path, const urdf::ModelInterface& m, const std::string& base) {
  std::vector<std::string> leaves;
  leaves_below(*m.getLink(base), leaves);
  std::size_t depth = 0;
  std::vector<std::string> deepest;
  std::vector<std::vector<urdf::JointConstSharedPtr>> chains;
  for (const auto& leaf : leaves) {
    bool found = false;
    const auto c = moving_joints_between(m, base, leaf, found);
    if (c.size() > depth) {
      depth = c.size();
      deepest.clear();
      chains.clear();
    }
    if (c.size() == depth) {
      deepest.push_back(leaf);
      chains.push_back(c);
    }
  }
  // Leaves that end the same moving chain (flange, tool0, a sensor frame) are one tip.
  for (const auto& c : chains) {
    if (c != chains.front()) {
      std::string list;
      for (const auto& t : deepest) list += (list.empty() ? "" : ", ") + t;
      refuse(path, "several tips " + std::to_string(depth) + " moving joints below '" + base + "': " + list +
                       "; choose one with --tip");
    }
  }
  return deepest.front();
}

/// Poses of all links in the root frame with every joint at zero.
void zero_poses(const urdf::ModelInterface& m, const urdf::Link& link, const Eigen::Isometry3d& pose,
                std::map<std::string, Eigen::Isometry3d>& out) {
  out[link.name] = pose;
  for (const auto& j : link.child_joints) {
    zero_poses(m, *m.getLink(j->child_link_name), pose * pose_of(j->parent_to_joint_origin_transform), out);
  }
}

dh::Inertial root_inertial(const urdf::Link& link, const Eigen::Isometry3d& link_pose) {
  dh::Inertial b;
  if (!link.inertial) return b;
  const urdf::Inertial& in = *link.inertial;
  const Eigen::Isometry3d frame = link_pose * pose_of(in.origin);
  Eigen::Matrix3d I;
  I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  b.mass = in.mass;
  b.com = frame.translation();
  b.inertia_com = frame.linear() * I * frame.linear().transpose();
  return b;
}

/// Every link carried by chain link `start` (the child of a chain joint): itself and all
/// below it except the subtree of the next chain joint.
void carried_links(const urdf::ModelInterface& m, const urdf::Link& start, const std::string& next_chain_joint,
                   std::vector<const urdf::Link*>& out) {
  out.push_back(&start);
  for (const auto& j : start.child_joints) {
    if (j->name != next_chain_joint) carried_links(m, *m.getLink(j->child_link_name), next_chain_joint, out);
  }
}

/// The chain's joints: revolute or continuous, each with a non-zero axis.
void check_chain_joints(const std::string& path, const std::vector<urdf::JointConstSharedPtr>& chain) {
  for (const auto& j : chain) {
    if (j->type != urdf::Joint::REVOLUTE && j->type != urdf::Joint::CONTINUOUS) {
      refuse(path, "joint '" + j->name + "' is " + type_name(j->type) + ": only revolute and continuous joints are supported on the chain (choose another with --base/--tip)");
    }
    if (std::hypot(j->axis.x, j->axis.y, j->axis.z) < 1e-9) refuse(path, "joint '" + j->name + "': <axis xyz> is zero");
  }
}

}  // namespace

RobotModel import_urdf(const std::string& path, const std::string& base_link, const std::string& tip_link) {
  const urdf::ModelInterfaceSharedPtr model = read_urdf(path);
  const urdf::LinkConstSharedPtr root = model->getRoot();
  if (!root) refuse(path, "no root link");
  const std::string base = base_link.empty() ? root->name : base_link;
  if (!model->getLink(base)) refuse(path, "--base: no link named '" + base + "'");
  if (!tip_link.empty() && !model->getLink(tip_link)) refuse(path, "--tip: no link named '" + tip_link + "'");
  const std::string tip = tip_link.empty() ? default_tip(path, *model, base) : tip_link;
  bool below = false;
  const auto chain = moving_joints_between(*model, base, tip, below);
  if (!below) refuse(path, "--tip: link '" + tip + "' is not below the base link '" + base + "'");
  if (chain.empty()) refuse(path, "no moving joint between the base link '" + base + "' and the tip link '" + tip + "'");
  if (chain.size() > static_cast<std::size_t>(kMaxJoints)) {
    refuse(path, std::to_string(chain.size()) + " moving joints between '" + base + "' and '" + tip + "': at most " +
                     std::to_string(kMaxJoints) + " (choose --base/--tip)");
  }
  check_chain_joints(path, chain);

  std::map<std::string, Eigen::Isometry3d> pose;
  zero_poses(*model, *root, Eigen::Isometry3d::Identity(), pose);
  std::vector<dh::AxisLine> axes;
  for (const auto& j : chain) {
    const Eigen::Isometry3d jp = pose.at(j->parent_link_name) * pose_of(j->parent_to_joint_origin_transform);
    axes.push_back({j->name, jp.translation(), jp.linear() * Eigen::Vector3d(j->axis.x, j->axis.y, j->axis.z).normalized()});
  }
  std::vector<dh::Frame> frames;
  try {
    frames = dh::place_frames(axes, Eigen::Vector3d::UnitZ(), pose.at(base).translation());
  } catch (const std::domain_error& e) {
    refuse(path, e.what());
  }

  RobotModel m;
  m.source = path;
  m.name = model->getName();
  for (std::size_t i = 0; i < chain.size(); ++i) {
    const urdf::Joint& j = *chain[i];
    JointDescription d;
    d.name = j.name;
    dh::DhParameters p;
    try {
      p = dh::dh_between(frames[i], frames[i + 1]);
    } catch (const std::domain_error& e) {
      refuse(path, "joint '" + j.name + "': " + e.what());
    }
    d.link.alpha_prev = p.alpha_prev;
    d.link.a_prev = p.a_prev;
    d.link.theta_offset = p.theta_offset;
    d.link.d = p.d;
    if (j.type == urdf::Joint::CONTINUOUS) {
      d.lower_rad = -std::numeric_limits<double>::infinity();
      d.upper_rad = std::numeric_limits<double>::infinity();
    } else if (j.limits) {
      d.lower_rad = j.limits->lower;
      d.upper_rad = j.limits->upper;
    }
    if (j.limits && j.limits->effort > 0.0) {
      d.effort_limit_nm = j.limits->effort;
      d.link.current_limit = j.limits->effort / d.link.torque_constant;  // K_I unknown (1) until --drive gives it
    }
    // The link's mass properties: its own and everything it carries, in its D-H frame.
    std::vector<const urdf::Link*> carried;
    carried_links(*model, *model->getLink(j.child_link_name), i + 1 < chain.size() ? chain[i + 1]->name : std::string(), carried);
    dh::Inertial body;
    for (const urdf::Link* l : carried) body = dh::lump(body, dh::to_frame(root_inertial(*l, pose.at(l->name)), frames[i + 1]));
    d.link.mass = body.mass;
    for (int k = 0; k < 3; ++k) d.link.com[k] = body.com(k);
    const Eigen::Matrix3d& I = body.inertia_com;
    const double v[6] = {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)};
    for (int k = 0; k < 6; ++k) d.link.inertia_com[k] = v[k];
    // Reach (to place contacts): to the next joint's frame, or to the tip for the last link.
    const Eigen::Vector3d next = i + 1 < chain.size() ? frames[i + 2].origin : pose.at(tip).translation();
    d.reach_m = std::max(0.05, (next - frames[i + 1].origin).norm());
    m.joints.push_back(d);
  }
  return m;
}

}  // namespace jg::robot
