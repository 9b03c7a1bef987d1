// URDF import of any serial chain (host_sim/robot/urdf_import.*), checked against a second,
// independent reading of the same file: kdl_parser's KDL tree and KDL's recursive
// Newton-Euler. Inverse dynamics of the imported modified-D-H model (sim::ArmDynamics) and
// the firmware's momentum recursion must equal KDL's to 1e-9; the UR10e's gravity torques
// must equal the robot controller's. Bad files are refused with the field named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <map>
#include <random>

#include "dynamics/rigid_body.hpp"
#include "io/recording.hpp"
#include "jointguard/dynamics/momentum_recursion.hpp"
#include "robot/robot_model.hpp"
#include "robot/urdf_import_dh.hpp"

namespace {

using jg::sim::JointVector;

const std::string kData = std::string(JG_SOURCE_DIR) + "/tests/data/urdf/";
const std::string kUr10e = std::string(JG_SOURCE_DIR) + "/../shared/data/real/ur10e-static/ur10e.urdf";
constexpr double kG = 9.81;

/// KDL's inverse dynamics of the whole tree (joints off the chain held at zero, which is how
/// the import carries side branches), as tau(q, dq, ddq) of the chain's joints.
class KdlReference {
 public:
  KdlReference(const std::string& urdf, const jg::robot::RobotModel& m) {
    EXPECT_TRUE(kdl_parser::treeFromFile(urdf, tree_));
    for (const auto& [name, element] : tree_.getSegments()) {
      const KDL::Joint& j = element.segment.getJoint();
      if (j.getType() != KDL::Joint::None) q_nr_[j.getName()] = element.q_nr;
    }
    for (const auto& j : m.joints) index_.push_back(q_nr_.at(j.name));
  }
  [[nodiscard]] JointVector tau(const JointVector& q, const JointVector& dq, const JointVector& ddq, bool gravity) const {
    KDL::TreeIdSolver_RNE solver(tree_, gravity ? KDL::Vector(0.0, 0.0, -kG) : KDL::Vector::Zero());
    const unsigned nt = tree_.getNrOfJoints();
    KDL::JntArray Q(nt), DQ(nt), DDQ(nt), T(nt);
    for (std::size_t i = 0; i < index_.size(); ++i) {
      Q(index_[i]) = q(static_cast<Eigen::Index>(i));
      DQ(index_[i]) = dq(static_cast<Eigen::Index>(i));
      DDQ(index_[i]) = ddq(static_cast<Eigen::Index>(i));
    }
    EXPECT_GE(solver.CartToJnt(Q, DQ, DDQ, KDL::WrenchMap(), T), 0);
    JointVector out(static_cast<Eigen::Index>(index_.size()));
    for (std::size_t i = 0; i < index_.size(); ++i) out(static_cast<Eigen::Index>(i)) = T(index_[i]);
    return out;
  }
  [[nodiscard]] const KDL::Tree& tree() const { return tree_; }

 private:
  KDL::Tree tree_;
  std::map<std::string, unsigned> q_nr_;
  std::vector<unsigned> index_;
};

/// A segment and everything below it in the tree, held at zero, in the segment's tip frame.
KDL::RigidBodyInertia subtree_inertia(const KDL::SegmentMap::const_iterator& e) {
  KDL::RigidBodyInertia I = e->second.segment.getInertia();
  for (const auto& c : e->second.children) I = I + c->second.segment.pose(0.0) * subtree_inertia(c);
  return I;
}

/// kdl_parser's chain from the root to `tip` (Tree::getChain), with the side branches the
/// arm carries added to their chain segment with KDL's own inertia algebra: getChain alone
/// drops them.
KDL::Chain carried_chain(const KDL::Tree& tree, const std::string& tip) {
  KDL::Chain chain;
  EXPECT_TRUE(tree.getChain(tree.getRootSegment()->first, tip, chain));
  std::vector<std::string> on_chain;
  for (const auto& s : chain.segments) on_chain.push_back(s.getName());
  for (auto& s : chain.segments) {
    const auto e = tree.getSegments().find(s.getName());
    KDL::RigidBodyInertia I = s.getInertia();
    for (const auto& c : e->second.children) {
      if (std::find(on_chain.begin(), on_chain.end(), c->first) == on_chain.end()) I = I + c->second.segment.pose(0.0) * subtree_inertia(c);
    }
    s.setInertia(I);
  }
  return chain;
}

double rel(const JointVector& a, const JointVector& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

struct Agreement {
  double id = 0.0, chain_id = 0.0, momentum = 0.0, beta = 0.0;
  double q16_abs = 0.0;  ///< the drives' Q16.16 recursion against double [N·m·s, N·m]
};

/// Random states: ArmDynamics against KDL's tree RNE and (with a chain tip, from the root)
/// KDL's chain RNE, the firmware recursion's p and beta against M dq and g - C^T dq from
/// KDL (C^T dq = M' dq - C dq, M' by central differences as in test_kdl), and the drives'
/// Q16.16 recursion against double.
Agreement compare(const std::string& urdf, const jg::robot::LoadOptions& opt, const std::string& chain_tip) {
  const bool chain_solver = !chain_tip.empty();
  const auto model = jg::robot::load_robot(urdf, opt);
  const auto n = static_cast<Eigen::Index>(model.joints.size());
  const KdlReference ref(urdf, model);
  const jg::sim::ArmDynamics arm(model.plant_links(), Eigen::Vector3d(model.gravity[0], model.gravity[1], model.gravity[2]) * (kG / 9.81));
  const KDL::Chain chain = chain_solver ? carried_chain(ref.tree(), chain_tip) : KDL::Chain();
  std::vector<jg::LinkConstants<double>> links(static_cast<std::size_t>(n));
  std::vector<jg::LinkConstants<jg::q16>> links_q(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < links.size(); ++i) {
    EXPECT_EQ(jg::convert_link(model.joints[i].link, links[i]), jg::Error::ok);
    // The drives' Q16.16 range holds the D-H constants.
    EXPECT_EQ(jg::convert_link(model.joints[i].link, links_q[i]), jg::Error::ok) << model.joints[i].name;
  }
  jg::NumericStatus status;
  const jg::Vec3<jg::q16> gravity_q{jg::q16::from_double(0.0, status), jg::q16::from_double(0.0, status),
                                    jg::q16::from_double(-kG, status)};
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Agreement worst;
  for (int trial = 0; trial < 300; ++trial) {
    JointVector q(n), dq(n), ddq(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      q(i) = u(rng);
      dq(i) = u(rng);
      ddq(i) = u(rng);
    }
    const JointVector tau = arm.inverse_dynamics(q, dq, ddq);
    worst.id = std::max(worst.id, rel(tau, ref.tau(q, dq, ddq, true)));
    if (chain_solver) {
      KDL::ChainIdSolver_RNE solver(chain, KDL::Vector(0.0, 0.0, -kG));
      const unsigned nc = chain.getNrOfJoints();
      KDL::JntArray Q(nc), DQ(nc), DDQ(nc), T(nc);
      for (unsigned i = 0; i < nc; ++i) {
        Q(i) = q(i);
        DQ(i) = dq(i);
        DDQ(i) = ddq(i);
      }
      EXPECT_GE(solver.CartToJnt(Q, DQ, DDQ, KDL::Wrenches(chain.getNrOfSegments(), KDL::Wrench::Zero()), T), 0);
      JointVector t(n);
      for (Eigen::Index i = 0; i < n; ++i) t(i) = T(static_cast<unsigned>(i));
      worst.chain_id = std::max(worst.chain_id, rel(tau, t));
    }
    // Firmware recursion.
    const JointVector zero = JointVector::Zero(n);
    JointVector p(n), cdq = ref.tau(q, dq, zero, false), g = ref.tau(q, zero, zero, true), mdot_dq = JointVector::Zero(n);
    jg::sim::JointMatrix M(n, n), Mp(n, n), Mm(n, n);
    const double eps = 1e-6;
    for (Eigen::Index k = 0; k < n; ++k) {
      const JointVector e = JointVector::Unit(n, k);
      M.col(k) = ref.tau(q, zero, e, false);
      Mp.col(k) = ref.tau(q + eps * dq, zero, e, false);
      Mm.col(k) = ref.tau(q - eps * dq, zero, e, false);
    }
    p = M * dq;
    mdot_dq = (Mp - Mm) / (2.0 * eps) * dq;
    const JointVector beta = g - (mdot_dq - cdq);
    double qs[7], dqs[7];
    for (Eigen::Index i = 0; i < n; ++i) {
      qs[i] = q(i);
      dqs[i] = dq(i);
    }
    jg::JointMomentum<double> out[7];
    jg::chain_momentum(links.data(), static_cast<int>(n), qs, dqs,
                       jg::Vec3<double>{arm.gravity()(0), arm.gravity()(1), arm.gravity()(2)}, out);
    JointVector fw_p(n), fw_beta(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      fw_p(i) = out[i].momentum - model.joints[static_cast<std::size_t>(i)].link.rotor_inertia * dq(i);
      fw_beta(i) = out[i].beta;
    }
    worst.momentum = std::max(worst.momentum, rel(fw_p, p));
    worst.beta = std::max(worst.beta, rel(fw_beta, beta));
    jg::q16 qq[7], dqq[7];
    for (Eigen::Index i = 0; i < n; ++i) {
      qq[i] = jg::q16::from_double(q(i), status);
      dqq[i] = jg::q16::from_double(dq(i), status);
    }
    jg::JointMomentum<jg::q16> out_q[7];
    jg::chain_momentum(links_q.data(), static_cast<int>(n), qq, dqq, gravity_q, out_q);
    for (Eigen::Index i = 0; i < n; ++i) {
      worst.q16_abs = std::max({worst.q16_abs, std::fabs(out_q[i].momentum.to_double() - out[i].momentum),
                                std::fabs(out_q[i].beta.to_double() - out[i].beta)});
    }
  }
  char chain_figure[32] = "n/a";
  if (chain_solver) std::snprintf(chain_figure, sizeof chain_figure, "%.2e", worst.chain_id);
  std::printf("%s%s%s: worst relative difference to KDL over 300 states: tree RNE %.2e, chain RNE %s, firmware p %.2e, beta %.2e; "
              "Q16.16 recursion vs double: %.2e absolute\n",
              std::filesystem::path(urdf).filename().c_str(), opt.base_link.empty() ? "" : " --base ", opt.base_link.c_str(),
              worst.id, chain_figure, worst.momentum, worst.beta, worst.q16_abs);
  EXPECT_TRUE(status.ok());
  EXPECT_LT(worst.q16_abs, 0.01);  // N·m and N·m·s; ref3 and Panda: 4e-4 and 1.4e-3 (test_kdl)
  return worst;
}

TEST(UrdfImport, Ur10eGravityMatchesTheController) {
  if (!std::filesystem::exists(kUr10e)) GTEST_SKIP() << "real data folder absent: " << kUr10e;
  const auto model = jg::robot::load_robot(kUr10e);
  ASSERT_EQ(model.joints.size(), 6U);
  const char* names[] = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(model.joints[i].name, names[i]);
  }
  const jg::sim::ArmDynamics arm(model.plant_links(), Eigen::Vector3d(model.gravity[0], model.gravity[1], model.gravity[2]) * (9.82 / 9.81));
  JointVector q(6);
  q << 0.030610, -1.096005, 2.333313, -1.245859, -1.046087, -0.517483;
  const JointVector g = arm.gravity_torque(q);
  // The robot controller's tau_des at rest (../shared/data/real/ur10e-static/README.md).
  const double expected[] = {0.0, -49.649, -12.129, 0.748, 0.004, 0.0};
  std::printf("UR10e gravity at the static posture, g = 9.82: %.3f %.3f %.3f %.3f %.3f %.3f N·m\n", g(0), g(1), g(2), g(3), g(4), g(5));
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(g(i), expected[i], 0.005) << "joint " << i + 1;
  }
}

TEST(UrdfImport, Ur10eEqualsKdl) {
  if (!std::filesystem::exists(kUr10e)) GTEST_SKIP() << "real data folder absent: " << kUr10e;
  const Agreement a = compare(kUr10e, {}, "tool0");
  EXPECT_LT(a.id, 1e-9);
  EXPECT_LT(a.chain_id, 1e-9);
  EXPECT_LT(a.momentum, 1e-9);
  EXPECT_LT(a.beta, 1e-8);  // limited by the central-difference M' of the reference
}

TEST(UrdfImport, SkewAxesFixedLinksAndBranchesEqualKdl) {
  const std::string f = kData + "skew_branch.urdf";
  const auto model = jg::robot::load_robot(f);
  ASSERT_EQ(model.joints.size(), 6U);  // fan_joint (a side branch) is not on the chain
  EXPECT_EQ(model.joints[4].name, "j5");
  EXPECT_TRUE(std::isinf(model.joints[4].upper_rad));  // continuous: no limits
  // Base side (world joint, base_link, camera_mount) carries no dynamics; the tool and the
  // sensor are lumped into their links.
  const Agreement a = compare(f, {}, "tool0");
  EXPECT_LT(a.id, 1e-9);
  EXPECT_LT(a.chain_id, 1e-9);
  EXPECT_LT(a.momentum, 1e-9);
  EXPECT_LT(a.beta, 1e-8);
}

TEST(UrdfImport, BaseAndTipSelectASubChain) {
  const std::string f = kData + "skew_branch.urdf";
  jg::robot::LoadOptions o;
  o.base_link = "link1";
  o.tip_link = "link4";
  const auto model = jg::robot::load_robot(f, o);
  ASSERT_EQ(model.joints.size(), 3U);
  EXPECT_EQ(model.joints.front().name, "j2");
  EXPECT_EQ(model.joints.back().name, "j4");
  // The first axis (j2) is tilted: its tilt becomes alpha_0, gravity stays along -z. What
  // lies beyond the tip (j5, j6, the tool) is carried locked at zero.
  const Agreement a = compare(f, o, "");
  EXPECT_LT(a.id, 1e-9);
  EXPECT_LT(a.momentum, 1e-9);
  EXPECT_LT(a.beta, 1e-8);
  o.tip_link = "fan";
  EXPECT_EQ(jg::robot::load_robot(f, o).joints.back().name, "fan_joint");
  o.tip_link = "camera_mount";
  EXPECT_THROW((void)jg::robot::load_robot(f, o), jg::io::FormatError);
  o.tip_link = "nowhere";
  EXPECT_THROW((void)jg::robot::load_robot(f, o), jg::io::FormatError);
}

std::string refusal(const std::string& file, const jg::robot::LoadOptions& o = {}) {
  try {
    (void)jg::robot::load_robot(kData + file, o);
  } catch (const jg::io::FormatError& e) {
    return e.what();
  }
  return "";
}

TEST(UrdfImport, BadNumbersAreRefusedNamingTheField) {
  for (const char* f : {"bad_mass_word.urdf", "bad_mass_nan.urdf", "bad_mass_unit.urdf"}) {
    const std::string e = refusal(f);
    EXPECT_NE(e.find(f), std::string::npos) << e;
    EXPECT_NE(e.find("mass"), std::string::npos) << e;
  }
}

TEST(UrdfImport, FormatCharactersNeverReachPrintf) {
  // Before: urdfdom passed "%s%s%s%s" on to console_bridge as a printf format (crash), "%n" aborted.
  for (const char* f : {"bad_format_s.urdf", "bad_format_n.urdf", "bad_format_entity.urdf"}) {
    const std::string e = refusal(f);
    EXPECT_NE(e.find(f), std::string::npos) << e;
    EXPECT_NE(e.find("inertial"), std::string::npos) << e;
  }
}

TEST(UrdfImport, PrismaticJointIsRefusedByName) {
  const std::string e = refusal("bad_prismatic.urdf");
  EXPECT_NE(e.find("'j1' is prismatic"), std::string::npos) << e;
  EXPECT_NE(e.find("bad_prismatic.urdf"), std::string::npos) << e;
}

TEST(UrdfImport, AmbiguousTipIsRefusedListingTheTips) {
  const std::string e = refusal("two_arms.urdf");
  EXPECT_NE(e.find("left_hand"), std::string::npos) << e;
  EXPECT_NE(e.find("right_hand"), std::string::npos) << e;
  jg::robot::LoadOptions o;
  o.tip_link = "left_hand";
  EXPECT_EQ(jg::robot::load_robot(kData + "two_arms.urdf", o).joints.size(), 2U);
}

TEST(UrdfImport, SingularMassMatrixIsRefusedForSimulation) {
  const auto model = jg::robot::load_robot(kData + "massless_tip.urdf");  // fine for detection
  try {
    jg::robot::check_simulatable(model);
    FAIL() << "a massless last link was accepted for simulation";
  } catch (const jg::io::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("'j2'"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(jg::robot::check_simulatable(jg::robot::load_robot(kData + "skew_branch.urdf")));
}

TEST(UrdfImport, NonPhysicalInertiaIsRefused) {
  const std::string e = refusal("bad_inertia.urdf");
  EXPECT_NE(e.find("link1"), std::string::npos) << e;
  EXPECT_NE(e.find("<inertia>"), std::string::npos) << e;
}

TEST(DhFrames, CoincidentAxesAndNearlyParallelAxes) {
  namespace dh = jg::robot::dh;
  // Two joints on one axis: no offset, no length; a third parallel one 0.2 m away.
  const std::vector<dh::AxisLine> axes = {{"a", {0, 0, 0}, {0, 0, 1}}, {"b", {0, 0, 0.5}, {0, 0, 1}}, {"c", {0.2, 0, 0.7}, {0, 0, 1}}};
  const auto f = dh::place_frames(axes, Eigen::Vector3d::UnitZ());
  const dh::DhParameters b = dh::dh_between(f[1], f[2]), c = dh::dh_between(f[2], f[3]);
  EXPECT_NEAR(b.alpha_prev, 0.0, 1e-12);
  EXPECT_NEAR(b.a_prev, 0.0, 1e-12);
  EXPECT_NEAR(b.d, 0.0, 1e-12);
  EXPECT_NEAR(c.a_prev, 0.2, 1e-12);
  // Tilted by 1e-6 rad towards a 0.1 m offset: the axes meet 1e5 m away.
  const std::vector<dh::AxisLine> skew = {{"p", {0, 0, 0}, {0, 0, 1}}, {"q", {0.1, 0, 0}, Eigen::Vector3d(-1e-6, 0, 1).normalized()}};
  try {
    (void)dh::place_frames(skew, Eigen::Vector3d::UnitZ());
    FAIL() << "nearly parallel axes accepted";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("'p' and 'q'"), std::string::npos) << e.what();
  }
}

TEST(DhFrames, LumpingTwoPointMassesGivesTheirInertia) {
  namespace dh = jg::robot::dh;
  dh::Inertial a, b;
  a.mass = 1.0;
  a.com = {1.0, 0.0, 0.0};
  b.mass = 3.0;
  b.com = {-1.0, 0.0, 0.0};
  const dh::Inertial s = dh::lump(a, b);
  EXPECT_DOUBLE_EQ(s.mass, 4.0);
  EXPECT_DOUBLE_EQ(s.com.x(), -0.5);
  // About the common CoM: 1 kg at 1.5 m and 3 kg at 0.5 m -> 3 kg m^2 about y and z.
  EXPECT_NEAR(s.inertia_com(1, 1), 3.0, 1e-12);
  EXPECT_NEAR(s.inertia_com(2, 2), 3.0, 1e-12);
  EXPECT_NEAR(s.inertia_com(0, 0), 0.0, 1e-12);
}

TEST(DriveFile, GivesDriveParametersByJointName) {
  jg::robot::LoadOptions o;
  o.drive_file = kData + "skew_branch_drive.yaml";
  const auto model = jg::robot::load_robot(kData + "skew_branch.urdf", o);
  EXPECT_DOUBLE_EQ(model.joints[0].link.torque_constant, 11.0);  // listed in another order
  EXPECT_DOUBLE_EQ(model.joints[5].link.torque_constant, 16.0);
  EXPECT_DOUBLE_EQ(model.joints[0].link.current_limit, 100.0 / 11.0);  // effort 100 N·m
  EXPECT_DOUBLE_EQ(model.joints[2].gear_ratio, 80.0);
  EXPECT_DOUBLE_EQ(model.joints[3].link.rotor_inertia, 0.04);
  for (const char* bad : {"drive_missing_joint.yaml", "drive_unknown_joint.yaml"}) {
    o.drive_file = kData + bad;
    EXPECT_THROW((void)jg::robot::load_robot(kData + "skew_branch.urdf", o), jg::io::FormatError) << bad;
  }
  // Beyond any drive (the drive fuzzer's rotor inertia of 5e37 kg m^2): refused naming the
  // drive file, line, field and joint.
  o.drive_file = std::string(JG_SOURCE_DIR) + "/tests/fuzz/regressions/drive/huge_rotor_inertia.yaml";
  try {
    (void)jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml", o);
    ADD_FAILURE() << "a rotor inertia of 5e37 kg m^2 was accepted";
  } catch (const jg::io::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("huge_rotor_inertia.yaml:4:22: field 'rotor_inertia_kg_m2': joint 'elbow'"), std::string::npos)
        << e.what();
  }
}

TEST(DriveFile, AcceptsTheUr10eVendorStyleFile) {
  const std::string drive = std::string(JG_SOURCE_DIR) + "/../shared/data/real/ur10e-static/drive.yaml";
  if (!std::filesystem::exists(kUr10e) || !std::filesystem::exists(drive)) GTEST_SKIP() << "real data folder absent";
  jg::robot::LoadOptions o;
  o.drive_file = drive;
  const auto model = jg::robot::load_robot(kUr10e, o);
  EXPECT_DOUBLE_EQ(model.joints[1].link.torque_constant, 10.6956);
  EXPECT_DOUBLE_EQ(model.joints[1].link.current_limit, 330.0 / 10.6956);
}

}  // namespace

namespace {
/// Each link's reach axis, from the link's origin, points at the next joint's origin in every
/// posture: where the contact estimate places the link's body (detection/contact_estimate.hpp).
/// Returns the links whose axis is not +x (vendor frames: the body along z or -x).
int expect_reach_axes_point_to_the_next_joint(const jg::robot::RobotModel& model) {
  const jg::sim::ArmDynamics arm = model.dynamics();
  const auto axes = model.reach_axes();
  const auto n = static_cast<Eigen::Index>(model.joints.size());
  EXPECT_EQ(axes.size(), model.joints.size());
  int not_x = 0;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    EXPECT_NEAR(axes[i].norm(), 1.0, 1e-12) << model.source << " link " << i + 1;
    not_x += (axes[i] - Eigen::Vector3d::UnitX()).norm() > 1e-9 ? 1 : 0;
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-2.0, 2.0);
  for (int trial = 0; trial < 3; ++trial) {
    JointVector q(n);
    for (Eigen::Index i = 0; i < n; ++i) q(i) = angle(rng);
    const jg::sim::LinkPoses poses = arm.poses(q);
    for (std::size_t i = 0; i + 1 < axes.size(); ++i) {
      const Eigen::Vector3d to_next = poses.origin[i + 1] - poses.origin[i];
      if (to_next.norm() < 1e-6) continue;  // the next joint at the link's origin: +x kept
      EXPECT_LT((poses.rotation[i] * axes[i] - to_next.normalized()).norm(), 1e-9) << model.source << " link " << i + 1;
    }
  }
  return not_x;
}
}  // namespace

TEST(ReachAxes, PointToTheNextJointOnTheProjectsArmsAndVendorUrdfs) {
  // The project's arms: their links lie along x (the contact estimate's former assumption).
  EXPECT_EQ(expect_reach_axes_point_to_the_next_joint(jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml")), 0);
  EXPECT_GT(expect_reach_axes_point_to_the_next_joint(jg::robot::load_robot(kData + "skew_branch.urdf")), 0);
  (void)expect_reach_axes_point_to_the_next_joint(jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/panda.yaml"));
  if (!std::filesystem::exists(kUr10e)) GTEST_SKIP() << "real data folder absent: " << kUr10e;
  const auto ur = jg::robot::load_robot(kUr10e);
  // The UR10e's upper arm and forearm (links 2 and 3) do not lie along +x of their frames.
  EXPECT_GT(expect_reach_axes_point_to_the_next_joint(ur), 0);
  const auto axes = ur.reach_axes();
  std::printf("UR10e reach axes:");
  for (const auto& a : axes) std::printf(" (%.2f %.2f %.2f)", a.x(), a.y(), a.z());
  std::printf("\n");
}
