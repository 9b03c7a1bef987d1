#include "robot/plant_effects.hpp"

#include <cstdio>

#include "io/yaml_fields.hpp"

namespace jg::robot {
namespace {
std::map<std::string, double> number_map(const io::YamlFields& f, const std::string& key) {
  std::map<std::string, double> out;
  if (!f.has(key)) return out;
  const io::YamlFields m = f.child(key);
  if (!m.node().IsMap()) f.fail(key, "expected a mapping of names to numbers");
  for (const auto& kv : m.node()) {
    const auto name = kv.first.as<std::string>();
    out[name] = m.number(name);
  }
  return out;
}

std::string exact(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

void write_map(std::ostream& out, const char* key, const std::map<std::string, double>& m) {
  out << ", " << key << ": {";
  bool first = true;
  for (const auto& [k, v] : m) {
    out << (first ? "" : ", ") << k << ": " << exact(v);
    first = false;
  }
  out << '}';
}
}  // namespace

EffectProblem simulation_problem(const PlantEffect& p) {
  const bool model_curve = p.setting.count("model_curve") != 0U;
  struct Needs {
    const char* effect;
    std::size_t coefficients;
    const char* setting;  ///< nullptr: none
  };
  // The generic Stribeck and Dahl shapes carry their nonlinear setting; the model-curve
  // instances (changes of the nominal LuGre) do not.
  const Needs needs[] = {
      {"coulomb", 1, nullptr},
      {"viscous", 1, nullptr},
      {"stribeck", 1, model_curve ? nullptr : "w_s"},
      {"presliding", 1, p.setting.count("sigma0_ratio") != 0U ? nullptr : "displacement_rad"},
      {"asymmetric_friction", 1, nullptr},
      {"position_ripple", 2, "periods_per_rev"},
      {"temperature_drift", 1, "time_constant_s"},
      {"load_dependent_friction", 1, nullptr},
      {"inertia_error", 1, nullptr},
      {"torque_constant", 1, nullptr},
      {"current_offset", 1, nullptr},
      {"time_delay", 1, nullptr},
      {"backlash", 0, nullptr},
      {"joint_elasticity", 0, nullptr},
      {"payload", 4, nullptr},
      {"link_inertial_error", 4, "link"}};
  const Needs* need = nullptr;
  for (const auto& n : needs) {
    if (p.effect == n.effect) need = &n;
  }
  if (need == nullptr) return {"effect", "'" + p.effect + "' is not an effect the plant can simulate"};
  if (p.coefficients.size() < need->coefficients) {
    return {"coefficients", "'" + p.effect + "' needs " + std::to_string(need->coefficients) + " coefficient(s)"};
  }
  if (need->setting != nullptr && p.setting.count(need->setting) == 0U) {
    return {"setting", "'" + p.effect + "' needs setting '" + need->setting + "'"};
  }
  if ((p.effect == "payload" || p.effect == "link_inertial_error") != (p.joint == 0)) {
    return {"joint", "'" + p.effect + "' belongs to " + (p.joint == 0 ? "a joint (1..n)" : "the arm (joint 0)")};
  }
  return {};
}

std::vector<PlantEffect> read_plant_effects(const io::YamlFields& root, std::size_t joints) {
  std::vector<PlantEffect> out;
  if (!root.has("plant_effects")) return out;
  for (const auto& e : root.sequence("plant_effects")) {
    e.allow_only({"effect", "joint", "setting", "coefficients", "params"});
    PlantEffect p;
    p.effect = e.text("effect");
    const long j = e.integer("joint", 0);
    if (j < 0 || j > static_cast<long>(joints)) e.fail("joint", "expected 0 (the arm) or a joint 1.." + std::to_string(joints));
    p.joint = static_cast<int>(j);
    p.setting = number_map(e, "setting");
    if (e.has("coefficients")) p.coefficients = e.numbers("coefficients");
    p.params = number_map(e, "params");
    const EffectProblem problem = simulation_problem(p);
    if (!problem.field.empty()) e.fail(problem.field, problem.what);
    out.push_back(std::move(p));
  }
  return out;
}

void write_plant_effects(std::ostream& out, const std::vector<PlantEffect>& effects) {
  if (effects.empty()) return;
  out << "plant_effects:   # found by jointguard diagnose; simulate --model applies them to the plant\n";
  for (const auto& e : effects) {
    out << "  - {effect: " << e.effect << ", joint: " << e.joint;
    write_map(out, "setting", e.setting);
    out << ", coefficients: [";
    for (std::size_t i = 0; i < e.coefficients.size(); ++i) out << (i ? ", " : "") << exact(e.coefficients[i]);
    out << ']';
    write_map(out, "params", e.params);
    out << "}\n";
  }
}

}  // namespace jg::robot
