#include "robot/robot_writer.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include "io/atomic_write.hpp"
#include "io/recording.hpp"

namespace jg::robot {
namespace {

/// Shortest of 15 or 17 significant digits that reads back as the same double.
std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  if (std::strtod(buf, nullptr) != v) std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::function<nlohmann::json()>& identity_source() {
  static std::function<nlohmann::json()> source;
  return source;
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

std::string robot_yaml(const RobotModel& m, const std::string& header) {
  std::ostringstream o;
  std::istringstream h(header);
  for (std::string line; std::getline(h, line);) o << "# " << line << "\n";
  o << "name: " << quoted(m.name) << "\n";
  o << "gravity_m_s2: [" << num(m.gravity[0]) << ", " << num(m.gravity[1]) << ", " << num(m.gravity[2]) << "]\n";
  if (m.rated_payload_kg > 0.0) o << "rated_payload_kg: " << num(m.rated_payload_kg) << "\n";
  o << "joints:\n";
  for (const auto& j : m.joints) {
    const LinkDescription& l = j.link;
    o << "  - name: " << quoted(j.name) << "\n";
    o << "    a_prev_m: " << num(l.a_prev) << "\n";
    o << "    alpha_prev_rad: " << num(l.alpha_prev) << "\n";
    o << "    d_m: " << num(l.d) << "\n";
    o << "    theta_offset_rad: " << num(l.theta_offset) << "\n";
    o << "    mass_kg: " << num(l.mass) << "\n";
    o << "    com_m: [" << num(l.com[0]) << ", " << num(l.com[1]) << ", " << num(l.com[2]) << "]\n";
    o << "    inertia_kg_m2: {xx: " << num(l.inertia_com[0]) << ", yy: " << num(l.inertia_com[1])
      << ", zz: " << num(l.inertia_com[2]) << ", xy: " << num(l.inertia_com[3]) << ", xz: " << num(l.inertia_com[4])
      << ", yz: " << num(l.inertia_com[5]) << "}\n";
    o << "    rotor_inertia_kg_m2: " << num(l.rotor_inertia) << "\n";
    o << "    gear_ratio: " << num(j.gear_ratio) << "\n";
    o << "    torque_constant_nm_per_a: " << num(l.torque_constant) << "\n";
    o << "    current_limit_a: " << num(l.current_limit) << "\n";
    if (std::isfinite(j.lower_rad) && std::isfinite(j.upper_rad)) {
      o << "    limits_rad: [" << num(j.lower_rad) << ", " << num(j.upper_rad) << "]\n";
    } else {
      // The YAML format refuses non-finite numbers: a continuous joint (URDF) has no key.
      o << "    # continuous joint: no limits_rad\n";
    }
    o << "    reach_m: " << num(j.reach_m) << "\n";
  }
  if (!m.friction_baseline.empty()) {
    o << "friction_baseline:   # identified with the links above by jointguard diagnose; a later diagnosis takes it as is\n";
    for (const auto& f : m.friction_baseline) {
      o << "  - {coulomb_pos_nm: " << num(f.coulomb_pos_nm) << ", coulomb_neg_nm: " << num(f.coulomb_neg_nm)
        << ", viscous_nms_rad: " << num(f.viscous_nms_rad) << ", offset_nm: " << num(f.offset_nm)
        << ", eps_rad_s: " << num(f.eps_rad_s) << "}\n";
    }
  }
  write_plant_effects(o, m.plant_effects);
  return o.str();
}

std::string identity_yaml(const nlohmann::json& identity) {
  if (!identity.is_object() || identity.empty()) return "";
  // JSON with its escapes (and any invalid UTF-8 in an option replaced): valid YAML flow.
  const auto json = [](const nlohmann::json& v) { return v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace); };
  std::string out = "# what wrote this file (read back and reported by every command that loads it)\nidentity:\n";
  for (const auto& [key, value] : identity.items()) out += "  " + json(key) + ": " + json(value) + "\n";
  return out;
}

void set_identity_source(std::function<nlohmann::json()> source) { identity_source() = std::move(source); }

void write_robot(const std::string& path, const RobotModel& model, const std::string& header) {
  std::string text = robot_yaml(model, header);
  if (identity_source()) text += identity_yaml(identity_source()());
  io::write_text_atomic(path, text);
}

}  // namespace jg::robot
