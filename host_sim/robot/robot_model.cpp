#include "robot/robot_model.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>

#include "io/yaml_fields.hpp"
#include "robot/drive_params.hpp"
#include "robot/urdf_import.hpp"

namespace jg::robot {
namespace {

/// Whether {xx, yy, zz, xy, xz, yz} [kg m^2] about the centre of mass is a body's inertia:
/// the second moment of its mass, S = tr(I)/2 * 1 - I, positive semi-definite (every
/// principal minor >= 0, to a rounding tolerance). That holds I positive semi-definite and
/// each principal moment at most the sum of the other two.
bool physical_inertia(const double (&i)[6]) {
  const double tol = 1e-12 * (std::abs(i[0]) + std::abs(i[1]) + std::abs(i[2]) + 1e-300);
  const double h = 0.5 * (i[0] + i[1] + i[2]);
  const double s[3][3] = {{h - i[0], -i[3], -i[4]}, {-i[3], h - i[1], -i[5]}, {-i[4], -i[5], h - i[2]}};
  for (int k = 0; k < 3; ++k) {
    if (s[k][k] < -tol) return false;
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = a + 1; b < 3; ++b) {
      if (s[a][a] * s[b][b] - s[a][b] * s[a][b] < -tol * tol) return false;
    }
  }
  const double det = s[0][0] * (s[1][1] * s[2][2] - s[1][2] * s[1][2]) - s[0][1] * (s[0][1] * s[2][2] - s[1][2] * s[0][2]) +
                     s[0][2] * (s[0][1] * s[1][2] - s[1][1] * s[0][2]);
  return det >= -tol * tol * tol;
}
}  // namespace

double read_rated_payload(const io::YamlFields& root) {
  if (!root.has("rated_payload_kg")) return 0.0;
  const double kg = root.number("rated_payload_kg", 0.0);
  // Beyond any arm's rating: a unit slip (grams) or a typo.
  if (!(kg > 0.0 && kg <= kMaxRatedPayloadKg)) {
    root.fail("rated_payload_kg", "must be > 0 and at most " + std::to_string(static_cast<int>(kMaxRatedPayloadKg)) + " kg");
  }
  return kg;
}

namespace {
std::function<void(const RobotModel&)>& read_observer() {
  static std::function<void(const RobotModel&)> observer;
  return observer;
}

/// The `identity` robot_writer.hpp writes: a mapping with the version and command (strings);
/// its other entries (options, input_sha256) are provenance and not checked here, so a file
/// a later version wrote with more of them still reads.
void read_identity(const io::YamlFields& root, RobotModel& m) {
  if (!root.has("identity")) return;
  const io::YamlFields id = root.child("identity");
  m.written_by_version = id.text("version");
  m.written_by_command = id.text("command");
  if (m.written_by_version.empty()) id.fail("version", "empty (expected the jointguard version that wrote the file)");
}

/// The optional `friction_baseline` list: one entry per joint, every number finite, the
/// tanh scale > 0 and every level within what a drive can hold (kMaxFrictionNm).
std::vector<FrictionBaseline> read_friction_baseline(const io::YamlFields& root, std::size_t joints) {
  std::vector<FrictionBaseline> out;
  if (!root.has("friction_baseline")) return out;
  const auto entries = root.sequence("friction_baseline");
  if (entries.size() != joints) {
    root.fail("friction_baseline", std::to_string(entries.size()) + " entries, the file has " + std::to_string(joints) + " joints");
  }
  for (const auto& e : entries) {
    e.allow_only({"coulomb_pos_nm", "coulomb_neg_nm", "viscous_nms_rad", "offset_nm", "eps_rad_s"});
    FrictionBaseline f;
    const auto level = [&](const char* key) {
      const double v = e.number(key, 0.0);
      if (!(std::abs(v) <= kMaxFrictionNm)) e.fail(key, "beyond any drive's friction (|value| at most 1e5)");
      return v;
    };
    f.coulomb_pos_nm = level("coulomb_pos_nm");
    f.coulomb_neg_nm = level("coulomb_neg_nm");
    f.viscous_nms_rad = level("viscous_nms_rad");
    f.offset_nm = level("offset_nm");
    f.eps_rad_s = e.number("eps_rad_s");
    if (!(f.eps_rad_s > 0.0 && f.eps_rad_s <= 10.0)) e.fail("eps_rad_s", "must be > 0 and at most 10 rad/s");
    out.push_back(f);
  }
  return out;
}

RobotModel load_yaml(const std::string& path) {
  const io::YamlFields root = io::YamlFields::load_file(path);
  root.allow_only({"name", "description", "gravity_m_s2", "joints", "sources", "plant_effects", "rated_payload_kg", "identity",
                   "friction_baseline"});
  RobotModel m;
  m.source = path;
  read_identity(root, m);
  m.name = root.text("name");
  m.rated_payload_kg = read_rated_payload(root);
  if (root.has("gravity_m_s2")) {
    const auto g = root.numbers("gravity_m_s2", 3);
    for (int k = 0; k < 3; ++k) m.gravity[k] = g[static_cast<std::size_t>(k)];
  }
  const auto joints = root.sequence("joints");
  if (joints.empty() || joints.size() > static_cast<std::size_t>(kMaxJoints)) {
    root.fail("joints", "expected 1 to " + std::to_string(kMaxJoints) + " joints");
  }
  for (const auto& j : joints) {
    j.allow_only({"name", "a_prev_m", "alpha_prev_rad", "d_m", "theta_offset_rad", "mass_kg", "com_m", "inertia_kg_m2",
                  "rotor_inertia_kg_m2", "gear_ratio", "torque_constant_nm_per_a", "current_limit_a", "limits_rad",
                  "reach_m"});
    JointDescription d;
    d.name = j.text("name", "joint" + std::to_string(m.joints.size() + 1));
    d.link.a_prev = j.number("a_prev_m", 0.0);
    d.link.alpha_prev = j.number("alpha_prev_rad", 0.0);
    d.link.d = j.number("d_m", 0.0);
    d.link.theta_offset = j.number("theta_offset_rad", 0.0);
    d.link.mass = j.number("mass_kg");
    if (d.link.mass < 0.0) j.fail("mass_kg", "must be >= 0");
    const auto com = j.numbers("com_m", 3);
    for (int k = 0; k < 3; ++k) d.link.com[k] = com[static_cast<std::size_t>(k)];
    const io::YamlFields in = j.child("inertia_kg_m2");
    in.allow_only({"xx", "yy", "zz", "xy", "xz", "yz"});
    const char* keys[] = {"xx", "yy", "zz", "xy", "xz", "yz"};
    for (int k = 0; k < 6; ++k) d.link.inertia_com[k] = in.number(keys[k], 0.0);
    for (int k = 0; k < 3; ++k) {
      if (d.link.inertia_com[k] < 0.0) in.fail(keys[k], "diagonal inertia must be >= 0");
    }
    if (!physical_inertia(d.link.inertia_com)) {
      j.fail("inertia_kg_m2", "not the inertia of a body (not positive semi-definite, or a principal moment larger than the other two together)");
    }
    d.link.rotor_inertia = j.number("rotor_inertia_kg_m2", 0.0);
    if (d.link.rotor_inertia < 0.0) j.fail("rotor_inertia_kg_m2", "must be >= 0");
    if (!(d.link.rotor_inertia <= kMaxRotorInertiaKgM2)) j.fail("rotor_inertia_kg_m2", "beyond any drive (at most 10000)");
    d.gear_ratio = j.number("gear_ratio", 100.0);
    if (!(d.gear_ratio > 0.0)) j.fail("gear_ratio", "must be > 0");
    d.link.torque_constant = j.number("torque_constant_nm_per_a", 10.0);
    if (!(d.link.torque_constant > 0.0)) j.fail("torque_constant_nm_per_a", "must be > 0");
    d.link.current_limit = j.number("current_limit_a", 10.0);
    if (!(d.link.current_limit > 0.0)) j.fail("current_limit_a", "must be > 0");
    if (j.has("limits_rad")) {
      const auto lim = j.numbers("limits_rad", 2);
      if (!(lim[0] < lim[1])) j.fail("limits_rad", "lower must be below upper");
      d.lower_rad = lim[0];
      d.upper_rad = lim[1];
    }
    d.reach_m = j.number("reach_m", 0.3);
    m.joints.push_back(d);
  }
  m.plant_effects = read_plant_effects(root, m.joints.size());
  m.friction_baseline = read_friction_baseline(root, m.joints.size());
  return m;
}

}  // namespace

sim::ArmDynamics RobotModel::dynamics() const {
  return sim::ArmDynamics(plant_links(), Eigen::Vector3d(gravity[0], gravity[1], gravity[2]));
}

std::vector<sim::PlantLink> RobotModel::plant_links() const {
  std::vector<sim::PlantLink> out;
  for (const auto& j : joints) {
    sim::PlantLink l;
    l.a_prev = j.link.a_prev;
    l.alpha_prev = j.link.alpha_prev;
    l.d = j.link.d;
    l.theta_offset = j.link.theta_offset;
    l.mass = j.link.mass;
    l.com = Eigen::Vector3d(j.link.com[0], j.link.com[1], j.link.com[2]);
    const double* I = j.link.inertia_com;
    l.inertia_com << I[0], I[3], I[4], I[3], I[1], I[5], I[4], I[5], I[2];
    l.rotor_inertia = j.link.rotor_inertia;
    out.push_back(l);
  }
  return out;
}

std::vector<sim::JointDriveConfig> RobotModel::drives() const {
  std::vector<sim::JointDriveConfig> out;
  for (const auto& j : joints) {
    sim::JointDriveConfig d;
    d.gear_ratio = j.gear_ratio;
    d.torque_constant_nominal = j.link.torque_constant;
    d.current_limit_a = j.link.current_limit;
    out.push_back(d);
  }
  return out;
}

std::vector<double> RobotModel::reaches() const {
  std::vector<double> out;
  for (const auto& j : joints) out.push_back(j.reach_m);
  return out;
}

std::vector<Eigen::Vector3d> RobotModel::reach_axes() const {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
    if (i + 1 < joints.size()) {
      // Frame i+1's origin in frame i: RotX(alpha_prev) TransX(a_prev) RotZ(theta) TransZ(d) applied to 0.
      const LinkDescription& next = joints[i + 1].link;
      const Eigen::Vector3d origin(next.a_prev, -std::sin(next.alpha_prev) * next.d, std::cos(next.alpha_prev) * next.d);
      if (origin.norm() > 1e-6) axis = origin.normalized();
    }
    out.push_back(axis);
  }
  return out;
}

void check_simulatable(const RobotModel& model) {
  const sim::ArmDynamics arm(model.plant_links());
  const auto n = static_cast<Eigen::Index>(model.joints.size());
  // A few fixed configurations: zero and spread-out angles (singular at every q is what
  // a missing body causes; a configuration-dependent singularity cannot occur with
  // positive link inertias).
  for (int k = 0; k < 3; ++k) {
    sim::JointVector q(n);
    for (Eigen::Index i = 0; i < n; ++i) q(i) = k == 0 ? 0.0 : std::sin(1.7 * static_cast<double>(k) + 0.9 * static_cast<double>(i));
    sim::JointMatrix M = arm.mass_matrix(q);
    const double scale = std::max(1e-300, M.diagonal().cwiseAbs().maxCoeff());
    // Unpivoted Cholesky: the first vanishing pivot names the joint without inertia.
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index p = 0; p < i; ++p) M(i, i) -= M(i, p) * M(i, p);
      if (!(M(i, i) > 1e-12 * scale)) {
        throw io::FormatError(model.source + ": joint '" + model.joints[static_cast<std::size_t>(i)].name +
                              "': the mass matrix is singular (nothing with mass or inertia moves about this joint, "
                              "and no rotor inertia): cannot simulate; give the link a mass or inertia (URDF "
                              "<inertial>) or the joint a rotor inertia");
      }
      M(i, i) = std::sqrt(M(i, i));
      for (Eigen::Index r = i + 1; r < n; ++r) {
        for (Eigen::Index p = 0; p < i; ++p) M(r, i) -= M(r, p) * M(i, p);
        M(r, i) /= M(i, i);
      }
    }
  }
}

RobotModel load_robot(const std::string& path, const LoadOptions& options) {
  const std::string ext = std::filesystem::path(path).extension().string();
  RobotModel m;
  if (ext == ".urdf") {
    m = import_urdf(path, options.base_link, options.tip_link);
    m.torque_constant_assumed = true;  // until a drive file's k_i gives them
  } else if (ext == ".yaml" || ext == ".yml") {
    if (!options.base_link.empty() || !options.tip_link.empty()) {
      throw io::FormatError(path + ": --base/--tip select a chain in a URDF; a robot YAML is one chain already");
    }
    m = load_yaml(path);
  } else {
    throw io::FormatError(path + ": unknown robot file type '" + ext + "' (expected .yaml, .yml or .urdf)");
  }
  if (!options.drive_file.empty()) apply_drive_file(m, options.drive_file);
  if (read_observer()) read_observer()(m);
  return m;
}

void set_read_observer(std::function<void(const RobotModel&)> observer) { read_observer() = std::move(observer); }

}  // namespace jg::robot
