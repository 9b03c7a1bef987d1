#include "injection/effects_file.hpp"

#include <cmath>
#include <cstdio>

#include "io/yaml_fields.hpp"
#include "robot/effect_catalogue.hpp"

namespace jg::inject {
namespace {

/// What inject adds to the catalogue's row of an effect: the channel of the recording it
/// writes into, the coefficients its richer shape may add to the catalogue's count, and the
/// setting keys it takes. The scope (arm or joint) and the coefficient count are the
/// catalogue's (robot/effect_catalogue.hpp): exact counts, as predict_effects needs as many as
/// the effect has columns, and an extra number is a typo, not something to ignore.
struct Rule {
  robot::Effect effect;
  Channel channel;
  std::size_t optional_coefficients;
  std::vector<const char*> settings;  ///< allowed setting keys (a typo such as picked_up_at would act silently)
};

const std::vector<Rule>& rules() {
  static const std::vector<Rule> r = {
      {robot::Effect::payload, Channel::arm, 0, {"link", "picked_up_at_s"}},
      {robot::Effect::link_inertial_error, Channel::arm, 0, {"link"}},
      {robot::Effect::coulomb, Channel::joint, 0, {"model_curve"}},
      {robot::Effect::viscous, Channel::joint, 0, {}},
      {robot::Effect::stribeck, Channel::joint, 0, {"w_s", "model_curve"}},
      {robot::Effect::presliding, Channel::joint, 0, {"displacement_rad", "sigma0_ratio"}},
      {robot::Effect::asymmetric_friction, Channel::joint, 1, {}},  // level, and optionally the viscous slope
      {robot::Effect::position_ripple, Channel::joint, 0, {"periods_per_rev"}},
      {robot::Effect::temperature_drift, Channel::joint, 0, {"time_constant_s"}},
      {robot::Effect::load_dependent_friction, Channel::joint, 0, {}},
      {robot::Effect::inertia_error, Channel::joint, 0, {}},
      {robot::Effect::torque_constant, Channel::scale, 0, {}},
      {robot::Effect::current_offset, Channel::offset, 0, {}},
      {robot::Effect::time_delay, Channel::delay, 0, {"delay_s"}},  // the diagnosis's linearisation point; inject shifts by -coefficients[0]
  };
  return r;
}

const Rule* rule_of(robot::Effect effect) {
  for (const auto& r : rules()) {
    if (effect == r.effect) return &r;
  }
  return nullptr;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

/// Settings: only the rule's keys; nonlinear settings that divide must be > 0.
robot::EffectProblem setting_problem(const robot::PlantEffect& e, const Rule& r) {
  for (const auto& [key, value] : e.setting) {
    bool known = false;
    for (const char* k : r.settings) known = known || key == k;
    if (!known) return {"setting." + key, "'" + e.effect + "' has no setting '" + key + "'"};
    const bool divides = key == "w_s" || key == "displacement_rad" || key == "time_constant_s" || key == "sigma0_ratio" ||
                         key == "periods_per_rev";
    if (divides && !(value > 0.0)) return {"setting." + key, "must be > 0 (got " + number(value) + ")"};
  }
  return {};
}

/// Arm-level effects: a payload on the last link with a positive mass; a link's change on a
/// link of the arm that leaves it a mass.
robot::EffectProblem arm_problem(const robot::PlantEffect& e, const InjectTarget& t) {
  const double n = static_cast<double>(t.joints);
  const auto link = e.setting.find("link");
  if (e.effect == robot::Effect::payload) {
    if (!(e.coefficients[0] > 0.0)) {
      return {"coefficients", "a payload's mass (coefficients[0]) must be > 0 kg (a lighter link is link_inertial_error)"};
    }
    if (link != e.setting.end() && link->second != n) {
      return {"setting.link", "a payload is carried by the last link (" + number(n) + "); a mass on link " +
                                  number(link->second) + " is link_inertial_error"};
    }
    const auto mass = e.params.find("mass_kg");
    if (mass != e.params.end() && std::fabs(mass->second - e.coefficients[0]) > 1e-9 * std::fabs(e.coefficients[0])) {
      return {"params.mass_kg", number(mass->second) + " kg differs from coefficients[0] = " + number(e.coefficients[0]) +
                                    " kg, the mass injected"};
    }
    return {};
  }
  if (link == e.setting.end() || link->second < 1.0 || link->second > n || link->second != std::floor(link->second)) {
    return {"setting.link", "link_inertial_error needs setting link in 1.." + number(n)};
  }
  const auto l = static_cast<std::size_t>(link->second) - 1;
  if (l < t.link_mass_kg.size() && !(t.link_mass_kg[l] + e.coefficients[0] > 0.0)) {
    return {"coefficients", "a mass change of " + number(e.coefficients[0]) + " kg leaves link " + number(link->second) +
                                " (" + number(t.link_mass_kg[l]) + " kg) without mass"};
  }
  return {};
}

}  // namespace

robot::EffectProblem injection_problem(const robot::PlantEffect& e, const InjectTarget& t, Channel* channel) {
  const robot::EffectInfo& info = robot::effect_info(e.effect);
  if (info.channel == robot::EffectChannel::deflection) {
    return {"effect", "'" + e.effect + "' changes the gear's deflection, i.e. the motion itself (the motor-side dq against "
                      "the link-side q), which the recording fixes: a torque column cannot carry it"};
  }
  const Rule* r = rule_of(e.effect);
  if (r == nullptr) return {"effect", "'" + e.effect + "' is not an effect inject knows"};
  if ((info.scope == robot::EffectScope::arm) != (e.joint == 0)) {
    return {"joint", "'" + e.effect + "' belongs to " + (e.joint == 0 ? "a joint (1..n)" : "the arm (joint 0)")};
  }
  if (e.joint < 0 || static_cast<std::size_t>(e.joint) > t.joints) {
    return {"joint", "joint " + std::to_string(e.joint) + " is outside the arm (1.." + std::to_string(t.joints) + ")"};
  }
  const std::size_t least = info.coefficients, most = info.coefficients + r->optional_coefficients;
  if (e.coefficients.size() < least || e.coefficients.size() > most) {
    return {"coefficients", "'" + e.effect + "' takes " + std::to_string(least) + (most > least ? " or " + std::to_string(most) : "") +
                                " coefficient(s), got " + std::to_string(e.coefficients.size())};
  }
  if (auto p = setting_problem(e, *r); !p.field.empty()) return p;
  const bool sensor = t.torque == io::TorqueKind::tau_j;
  if (sensor && (e.effect == robot::Effect::torque_constant || e.effect == robot::Effect::current_offset)) {
    return {"effect", "'" + e.effect + "' is an error of the motor current's channel; the recording's torque is a joint torque "
                      "sensor's (tau_j), which has none"};
  }
  if (sensor && e.effect == robot::Effect::inertia_error) {
    return {"effect", "'inertia_error' is the rotor's inertia, which a joint torque sensor after the gear (tau_j) does not see"};
  }
  const bool model_curve = e.setting.count("model_curve") != 0U || e.setting.count("sigma0_ratio") != 0U;
  if (model_curve && !t.has_friction) {
    return {"setting", "'" + e.effect + "' here is a change of the nominal LuGre friction's parameters: give that friction "
                       "with --friction F.json (identify's JSON)"};
  }
  if (e.effect == robot::Effect::stribeck && !model_curve && e.setting.count("w_s") == 0U) return {"setting", "'stribeck' needs setting 'w_s'"};
  if (e.effect == robot::Effect::presliding && !model_curve && e.setting.count("displacement_rad") == 0U) {
    return {"setting", "'presliding' needs setting 'displacement_rad' (or sigma0_ratio with --friction)"};
  }
  if (e.effect == robot::Effect::position_ripple && e.setting.count("periods_per_rev") == 0U) return {"setting", "needs 'periods_per_rev'"};
  if (e.effect == robot::Effect::temperature_drift && e.setting.count("time_constant_s") == 0U) return {"setting", "needs 'time_constant_s'"};
  if (e.effect == robot::Effect::torque_constant && !(1.0 + e.coefficients[0] > 0.0)) {
    return {"coefficients", "a scale of 1 + " + number(e.coefficients[0]) + " <= 0 would flip or erase the reading"};
  }
  if (r->channel == Channel::arm) {
    if (auto p = arm_problem(e, t); !p.field.empty()) return p;
  }
  if (channel != nullptr) *channel = r->channel;
  return {};
}

Channel channel_of(const robot::PlantEffect& effect) {
  const Rule* r = rule_of(effect.effect);
  return r != nullptr ? r->channel : Channel::joint;
}

std::vector<robot::PlantEffect> read_effects_file(const std::string& path, const InjectTarget& target) {
  const io::YamlFields root = io::YamlFields::load_file(path);
  if (!root.node().IsMap() || !root.has("plant_effects")) {
    root.fail("plant_effects", "expected a document with a plant_effects: list (the robot file's schema; [] for none)");
  }
  root.allow_only({"plant_effects"});
  // The robot file's reader first (keys, types, finite numbers, joints 0..n), then what a
  // recording's torque column can carry, each refusal at the entry's line.
  std::vector<robot::PlantEffect> effects = robot::read_plant_effects(root, target.joints);
  const std::vector<io::YamlFields> entries = root.sequence("plant_effects");
  for (std::size_t i = 0; i < effects.size() && i < entries.size(); ++i) {
    const robot::EffectProblem p = injection_problem(effects[i], target);
    if (p.field.empty()) continue;
    const auto dot = p.field.find('.');
    if (dot != std::string::npos && entries[i].has(p.field.substr(0, dot))) {
      entries[i].child(p.field.substr(0, dot)).fail(p.field.substr(dot + 1), p.what);
    }
    entries[i].fail(p.field, p.what);
  }
  return effects;
}

}  // namespace jg::inject
