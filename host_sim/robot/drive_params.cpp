#include "robot/drive_params.hpp"

#include <cstdio>

#include "io/yaml_fields.hpp"

namespace jg::robot {

void apply_drive_file(RobotModel& model, const std::string& path) {
  const io::YamlFields root = io::YamlFields::load_file(path);
  // `robot` and `controller_ratio` are informational in vendor-style files (see
  // ../shared/data/real/ur10e-static/drive.yaml) and are not used.
  root.allow_only({"robot", "joints", "k_i", "gear_ratio", "rotor_inertia_kg_m2", "current_limit_a", "controller_ratio",
                   "rated_payload_kg"});
  if (root.has("rated_payload_kg")) model.rated_payload_kg = read_rated_payload(root);
  const std::vector<io::YamlFields> listed = root.sequence("joints");
  std::vector<std::string> names;
  for (const auto& j : listed) {
    if (!j.node().IsScalar() || j.node().Scalar().empty()) root.fail("joints", "expected a list of joint names");
    names.push_back(j.node().Scalar());
  }
  const std::size_t n = names.size();
  std::vector<int> index(n, -1);
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < model.joints.size(); ++i) {
      if (model.joints[i].name == names[k]) index[k] = static_cast<int>(i);
    }
    if (index[k] < 0) root.fail("joints", "joint '" + names[k] + "' is not in the model " + model.source);
    for (std::size_t p = 0; p < k; ++p) {
      if (names[p] == names[k]) root.fail("joints", "joint '" + names[k] + "' is listed twice");
    }
  }
  for (const auto& j : model.joints) {
    bool listed_here = false;
    for (const auto& name : names) listed_here = listed_here || name == j.name;
    if (!listed_here) root.fail("joints", "the model's joint '" + j.name + "' is missing");
  }
  if (!root.has("k_i") && !root.has("gear_ratio") && !root.has("rotor_inertia_kg_m2") && !root.has("current_limit_a") &&
      !root.has("rated_payload_kg")) {
    root.fail("", "no drive parameter given (k_i, gear_ratio, rotor_inertia_kg_m2, current_limit_a)");
  }
  const auto apply = [&](const char* key, bool positive, double max, auto set) {
    if (!root.has(key)) return;
    const std::vector<double> v = root.numbers(key, n);
    for (std::size_t k = 0; k < n; ++k) {
      if (positive ? !(v[k] > 0.0) : v[k] < 0.0) root.fail(key, positive ? "every value must be > 0" : "every value must be >= 0");
      // Beyond any drive (robot_model.hpp): a typo or a unit slip, and a rotor inertia of
      // 5e37 made the arm's mass matrix look singular at another joint of the robot file.
      if (!(v[k] <= max)) {
        char text[64];
        std::snprintf(text, sizeof text, "%.3g is beyond any drive (at most %g)", v[k], max);
        root.fail(key, "joint '" + names[k] + "': " + text);
      }
      set(model.joints[static_cast<std::size_t>(index[k])], v[k]);
    }
  };
  // A URDF's <limit effort> is a torque: with a new K_I it becomes a new current limit.
  if (root.has("k_i")) model.torque_constant_assumed = false;
  apply("k_i", true, kMaxTorqueConstantNmPerA, [](JointDescription& j, double k) {
    j.link.torque_constant = k;
    if (j.effort_limit_nm > 0.0) j.link.current_limit = j.effort_limit_nm / k;
  });
  apply("gear_ratio", true, kMaxGearRatio, [](JointDescription& j, double g) { j.gear_ratio = g; });
  apply("rotor_inertia_kg_m2", false, kMaxRotorInertiaKgM2, [](JointDescription& j, double r) { j.link.rotor_inertia = r; });
  apply("current_limit_a", true, kMaxCurrentLimitA, [](JointDescription& j, double c) { j.link.current_limit = c; });
}

}  // namespace jg::robot
