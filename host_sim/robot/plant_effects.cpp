#include "robot/plant_effects.hpp"

#include <cmath>
#include <cstdio>
#include <optional>

#include "io/yaml_fields.hpp"
#include "robot/robot_model.hpp"

namespace jg::robot {
namespace {
constexpr double kMaxPayloadKg = kMaxRatedPayloadKg;  ///< beyond it a unit slip (grams) or a typo
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

std::string exact(double v);

/// Fails naming the entry's field, or the key inside `setting`/`params` (its own line).
void fail_at(const io::YamlFields& e, const EffectProblem& problem) {
  if (problem.field.empty()) return;
  const auto dot = problem.field.find('.');
  if (dot != std::string::npos && e.has(problem.field.substr(0, dot))) {
    e.child(problem.field.substr(0, dot)).fail(problem.field.substr(dot + 1), problem.what);
  }
  e.fail(problem.field, problem.what);
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

/// A value's allowed range [lo, hi] (finite), with its unit and why, for the message.
struct Range {
  const char* key;
  double lo, hi;
  const char* what;
};

EffectProblem out_of_range(const std::string& field, double v, const Range& r) {
  if (std::isfinite(v) && v >= r.lo && v <= r.hi) return {};
  return {field, exact(v) + " is outside " + r.what};
}

/// The settings and params the plant reads; each must lie in its physical range (a zero
/// Stribeck velocity or time constant divides by zero, a link 1.5 would be truncated).
EffectProblem setting_range_problem(const PlantEffect& p, std::size_t joints) {
  static const Range settings[] = {
      {"w_s", 1e-6, 100.0, "(0, 100] rad/s (a Stribeck velocity)"},
      {"displacement_rad", 1e-9, 1.0, "(0, 1] rad (a presliding displacement)"},
      {"sigma0_ratio", 1e-6, 1e3, "(0, 1000] (a bristle stiffness ratio)"},
      {"periods_per_rev", 1e-6, 1e4, "(0, 10000] periods per turn"},
      {"time_constant_s", 1e-6, 1e9, "(0, 1e9] s (a thermal time constant)"},
      {"picked_up_at_s", 0.0, 1e9, "[0, 1e9] s (a time in the recording)"},
      {"model_curve", 1.0, 1.0, "{1} (a flag: the nominal LuGre curve's parameter)"},
      {"saturation", 1.0, 1.0, "{1} (a flag: a torque constant falling with the current, coefficients [scale, per N·m])"},
      {"power_flow", 1.0, 1.0, "{1} (a flag: load coefficients [driving, back-driven])"},
      {"law", 1.0, 2.0, "{1, 2} (presliding law: 1 exponential, 2 hyperbolic)"},
      {"delay_s", -1.0, 1.0, "[-1, 1] s (the delay a time_delay's exact difference is taken over; < 0: a lead)"},
  };
  for (const auto& [key, value] : p.setting) {
    if (key == "link") {
      const double n = static_cast<double>(joints);
      if (!(value >= 1.0 && value <= n && value == std::floor(value))) {
        return {"setting.link", effect_word(p.effect) + " needs setting link in 1.." + std::to_string(joints) + " (a whole number: a link of the "
                                "arm), got " + exact(value)};
      }
      continue;
    }
    for (const auto& r : settings) {
      if (key != r.key) continue;
      if (auto e = out_of_range("setting." + key, value, r); !e.field.empty()) return e;
    }
    if ((key == "law" && value != std::floor(value)) || (key == "side" && value != 1.0 && value != -1.0)) {
      return {"setting." + key, exact(value) + (key == "law" ? " is not a presliding law (1 or 2)" : " is not a direction (1 or -1)")};
    }
  }
  static const Range params[] = {
      {"stiffness_nm_per_rad", 1.0, 1e9, "[1, 1e9] N·m/rad (a gear stiffness)"},
      {"gap_rad", 0.0, 0.5, "[0, 0.5] rad (a backlash gap)"},
      {"delay_s", -1.0, 1.0, "[-1, 1] s (a measurement delay; < 0: the torque leads the motion)"},
      {"mass_kg", 1e-9, kMaxPayloadKg, "(0, 5000] kg (a payload)"},
  };
  for (const auto& r : params) {
    const auto it = p.params.find(r.key);
    if (it == p.params.end() || (std::string(r.key) == "mass_kg" && p.effect != Effect::payload)) continue;
    if (auto e = out_of_range(std::string("params.") + r.key, it->second, r); !e.field.empty()) return e;
  }
  return {};
}

/// The coefficients the plant applies: each effect's within what a real arm can have.
EffectProblem coefficient_range_problem(const PlantEffect& p) {
  const auto& b = p.coefficients;
  if (b.empty()) return {};
  if (p.effect == Effect::payload) {
    if (auto e = out_of_range("coefficients", b[0], {"", 1e-9, kMaxPayloadKg, "(0, 5000] kg: a payload's mass "
                                                                              "(coefficients[0]; a lighter link is link_inertial_error)"});
        !e.field.empty()) {
      return e;
    }
  }
  if (p.effect == Effect::payload || p.effect == Effect::link_inertial_error) {
    // The first moment m·c: the centre of mass within 10 m of the link frame.
    const double m = std::max(std::fabs(b[0]), 1e-3);
    for (std::size_t i = 1; i < b.size() && i < 4; ++i) {
      if (auto e = out_of_range("coefficients", b[i], {"", -10.0 * m, 10.0 * m, "the first moment m·c of a centre of mass within "
                                                                                "10 m (kg·m)"});
          !e.field.empty()) {
        return e;
      }
    }
    return out_of_range("coefficients", b[0], {"", -kMaxPayloadKg, kMaxPayloadKg, "[-5000, 5000] kg (a mass change)"});
  }
  if (p.effect == Effect::torque_constant) {
    if (p.setting.count("saturation") != 0U && b.size() > 1) {
      if (auto e = out_of_range("coefficients", b[1], {"", 0.0, 1.0, "[0, 1] per N·m: a saturation (coefficients[1]) lowers the "
                                                                     "constant as the current grows"});
          !e.field.empty()) {
        return e;
      }
    }
    return out_of_range("coefficients", b[0], {"", -0.9, 9.0, "[-0.9, 9]: the measured torque's scale 1 + b (0.1 to 10 times "
                                                              "the true torque; <= 0 would flip or erase it)"});
  }
  if (p.effect == Effect::time_delay) {
    return out_of_range("coefficients", -b[0], {"", -1.0, 1.0, "[-1, 1] s as a delay (-coefficients[0]; < 0: the torque leads the motion)"});
  }
  if (p.effect == Effect::inertia_error) return out_of_range("coefficients", b[0], {"", -kMaxRotorInertiaKgM2, kMaxRotorInertiaKgM2, "+/-1e4 kg·m²"});
  if (p.effect == Effect::load_dependent_friction) {
    for (const double v : b) {
      if (auto e = out_of_range("coefficients", v, {"", -1.0, 1.0, "[-1, 1] N·m per N·m"}); !e.field.empty()) return e;
    }
    return {};
  }
  for (const double v : b) {  // friction levels, offsets, ripple: torques an arm's drive can hold
    if (auto e = out_of_range("coefficients", v, {"", -1e5, 1e5, "+/-1e5 (N·m or N·m·s/rad)"}); !e.field.empty()) return e;
  }
  if (p.effect == Effect::presliding && p.setting.count("sigma0_ratio") != 0U && !(p.setting.at("sigma0_ratio") * b[0] + (1.0 - b[0]) > 0.0)) {
    return {"coefficients", "the bristle stiffness would not stay positive (sigma0_ratio x b + 1 - b <= 0)"};
  }
  return {};
}
}  // namespace

EffectProblem simulation_problem(const PlantEffect& p) {
  const EffectInfo& info = effect_info(p.effect);
  const std::string word = "'" + effect_word(p.effect) + "'";
  if (info.channel == EffectChannel::none) return {"effect", word + " is not an effect the plant can simulate"};
  // The plain shape's counts and setting (the catalogue); richer shapes add a coefficient,
  // and the model-curve instances (changes of the nominal LuGre) need no setting of their own.
  const bool model_curve = p.setting.count("model_curve") != 0U;
  std::size_t coefficients = info.coefficients;
  if ((p.effect == Effect::asymmetric_friction && p.setting.count("side") != 0U) ||
      (p.effect == Effect::load_dependent_friction && p.setting.count("power_flow") != 0U) ||
      (p.effect == Effect::torque_constant && p.setting.count("saturation") != 0U)) {
    coefficients = 2;
  }
  std::string setting(info.setting);
  if ((p.effect == Effect::stribeck && model_curve) || (p.effect == Effect::presliding && p.setting.count("sigma0_ratio") != 0U) ||
      p.effect == Effect::backlash) {
    setting.clear();  // backlash's gap is a reported parameter (params.gap_rad), not a grid setting
  }
  if (p.coefficients.size() < coefficients) return {"coefficients", word + " needs " + std::to_string(coefficients) + " coefficient(s)"};
  if (!setting.empty() && p.setting.count(setting) == 0U) return {"setting", word + " needs setting '" + setting + "'"};
  if ((info.scope == EffectScope::arm) != (p.joint == 0)) {
    return {"joint", word + " belongs to " + (p.joint == 0 ? "a joint (1..n)" : "the arm (joint 0)")};
  }
  return {};
}

std::vector<PlantEffect> read_plant_effects(const io::YamlFields& root, std::size_t joints) {
  std::vector<PlantEffect> out;
  if (!root.has("plant_effects")) return out;
  for (const auto& e : root.sequence("plant_effects")) {
    e.allow_only({"effect", "joint", "setting", "coefficients", "params"});
    PlantEffect p;
    const std::string word = e.text("effect");
    const std::optional<Effect> effect = parse_effect(word);
    if (!effect || *effect == Effect::none) e.fail("effect", "'" + word + "' is not an effect the plant can simulate (one of: " + effect_words() + ", without none)");
    p.effect = *effect;
    const long j = e.integer("joint", 0);
    if (j < 0 || j > static_cast<long>(joints)) e.fail("joint", "expected 0 (the arm) or a joint 1.." + std::to_string(joints));
    p.joint = static_cast<int>(j);
    p.setting = number_map(e, "setting");
    if (e.has("coefficients")) p.coefficients = e.numbers("coefficients");
    p.params = number_map(e, "params");
    EffectProblem problem = simulation_problem(p);
    if (problem.field.empty()) problem = coefficient_range_problem(p);
    if (problem.field.empty()) problem = setting_range_problem(p, joints);
    fail_at(e, problem);
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
