#include "diagnosis/model_out.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "diagnosis/pairing.hpp"
#include "dynamics/sensitivity.hpp"

namespace jg::diag {

std::vector<robot::PlantEffect> plant_effects_of(const ArmDiagnosis& arm, const std::vector<JointDiagnosis>& joints) {
  std::vector<robot::PlantEffect> out;
  for (std::size_t i = 0; i < arm.model.size(); ++i) {
    const auto& m = arm.model[i];
    if (m.effect == robot::Effect::torque_constant) {  // named for the arm, but a drive's own: its joint's entry
      robot::PlantEffect p{m.effect, static_cast<int>(m.setting.at("joint")), {}, m.coefficients, {}};
      for (const auto& f : arm.findings) {
        const auto j = f.params.find("joint");
        if (f.effect == m.effect && j != f.params.end() && j->second == m.setting.at("joint")) p.params = f.params;
      }
      out.push_back(std::move(p));
      continue;
    }
    robot::PlantEffect p{m.effect, 0, m.setting, m.coefficients, {}};
    for (const auto& f : arm.findings) {
      const auto l = f.params.find("link");
      if (f.effect == m.effect && l != f.params.end() && m.setting.count("link") != 0U && l->second == m.setting.at("link")) p.params = f.params;
    }
    out.push_back(std::move(p));
  }
  for (const auto& d : joints) {
    for (const auto& m : d.model) {
      // The torque-channel image of a gear effect (the rotor's acceleration) is the same
      // physics as the deflection channel's finding, written once from the latter.
      if (m.setting.count("rotor_acceleration") != 0U) continue;
      robot::PlantEffect p{m.effect, d.joint, m.setting, m.coefficients, {}};
      for (const auto& f : d.findings) {
        if (f.effect == m.effect) p.params = f.params;
      }
      if (m.effect == robot::Effect::backlash && m.setting.count("gap_rad") != 0U) p.params["gap_rad"] = m.setting.at("gap_rad");
      out.push_back(std::move(p));
    }
    for (const auto& f : d.findings) {
      const bool deflection = f.params.count("deflection_noise_rad") != 0U;
      const bool in_model = std::any_of(out.begin(), out.end(), [&](const robot::PlantEffect& p) { return p.joint == d.joint && p.effect == f.effect; });
      if (deflection && !in_model) out.push_back({f.effect, d.joint, {}, {}, f.params});
    }
  }
  return out;
}

sim::EffectsReport apply_findings(const ArmDiagnosis& arm, const std::vector<JointDiagnosis>& joints, double dt,
                              sim::SimulationSetup& s) {
  return sim::apply_plant_effects(plant_effects_of(arm, joints), dt, s);
}

namespace {
/// Link `l`'s description set from a plant link's mass, centre and inertia.
void set_link(robot::JointDescription& j, const sim::PlantLink& changed) {
  auto& d = j.link;
  d.mass = changed.mass;
  for (int k = 0; k < 3; ++k) d.com[k] = changed.com(k);
  const Eigen::Matrix3d& I = changed.inertia_com;
  const double six[6] = {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)};
  for (int k = 0; k < 6; ++k) d.inertia_com[k] = six[k];
}

/// An arm-level effect a link's parameters can hold: a payload carried throughout, a link's
/// mass error. Its link (0-based), or -1.
int foldable_link(const robot::PlantEffect& e, std::size_t links) {
  const bool payload = e.effect == robot::Effect::payload && e.setting.count("picked_up_at_s") == 0U;
  const bool link = e.effect == robot::Effect::link_inertial_error && e.setting.count("link") != 0U;
  if (e.joint != 0 || !(payload || link) || e.coefficients.size() < 4 || links == 0) return -1;
  if (payload) return !(e.coefficients[0] > 0.0) ? -1 : static_cast<int>(links) - 1;
  const double at = e.setting.at("link");
  return at >= 1.0 && at <= static_cast<double>(links) && at == std::floor(at) ? static_cast<int>(at) - 1 : -1;
}

/// The link with the effect added (sign +1) or taken back out (-1): a payload as a point mass
/// (as the plant applies it), a link's mass error with the inertia about its origin kept (as
/// the diagnosis fits it).
sim::PlantLink changed_link(const sim::PlantLink& link, const robot::PlantEffect& e, double sign) {
  const Eigen::Vector3d h(e.coefficients[1], e.coefficients[2], e.coefficients[3]);
  if (e.effect == robot::Effect::payload) return sim::with_point_mass(link, sign * e.coefficients[0], h / e.coefficients[0]);
  return sim::with_mass_first_moment_change(link, sign * e.coefficients[0], sign * h);
}

bool same_cause(const robot::PlantEffect& a, const robot::PlantEffect& b) {
  return a.effect == b.effect && a.joint == b.joint && a.setting == b.setting && a.coefficients.size() == b.coefficients.size();
}
}  // namespace

std::vector<std::string> fold_arm_effects(robot::RobotModel& m, std::vector<robot::PlantEffect>* folded) {
  std::vector<std::string> notes;
  std::vector<robot::PlantEffect> kept;
  for (const auto& e : m.plant_effects) {
    const int l = foldable_link(e, m.joints.size());
    if (l < 0) {
      if (e.joint == 0) notes.push_back("arm: " + e.effect + " (picked up during the recording, or on a link the model does not have) stays out of the prediction");
      kept.push_back(e);
      continue;
    }
    set_link(m.joints[static_cast<std::size_t>(l)], changed_link(m.plant_links()[static_cast<std::size_t>(l)], e, 1.0));
    if (folded != nullptr) folded->push_back(e);
  }
  m.plant_effects = kept;
  return notes;
}

void fold_drive_effects(robot::RobotModel& m, std::vector<robot::PlantEffect>* folded) {
  std::vector<robot::PlantEffect> kept;
  for (const auto& e : m.plant_effects) {
    const bool drive = e.effect == robot::Effect::torque_constant && e.joint >= 1 && e.joint <= static_cast<int>(m.joints.size()) &&
                       e.coefficients.size() == 1 && 1.0 + e.coefficients[0] > 0.0;
    if (!drive) {
      kept.push_back(e);
      continue;
    }
    m.joints[static_cast<std::size_t>(e.joint - 1)].link.torque_constant /= 1.0 + e.coefficients[0];
    if (folded != nullptr) folded->push_back(e);
  }
  m.plant_effects = kept;
}

std::vector<std::string> unfold_arm_effects(robot::RobotModel& m, const std::vector<robot::PlantEffect>& folded) {
  std::vector<std::string> notes;
  for (auto it = folded.rbegin(); it != folded.rend(); ++it) {
    if (it->effect == robot::Effect::torque_constant) {  // back into the file as an effect: K_I as the file had it
      m.joints[static_cast<std::size_t>(it->joint - 1)].link.torque_constant *= 1.0 + it->coefficients[0];
      m.plant_effects = merge_plant_effects(m.plant_effects, {*it});
      continue;
    }
    const int l = foldable_link(*it, m.joints.size());
    if (l < 0) continue;
    const sim::PlantLink back = changed_link(m.plant_links()[static_cast<std::size_t>(l)], *it, -1.0);
    if (!(back.mass > 1e-6) || !sim::physical_link_inertia(back)) {
      notes.push_back("arm: " + it->effect + " kept inside link " + std::to_string(l + 1) +
                      " (taken back out, the identified link would not be a body)");
      continue;
    }
    set_link(m.joints[static_cast<std::size_t>(l)], back);
    m.plant_effects.push_back(*it);
  }
  return notes;
}

std::vector<robot::PlantEffect> merge_plant_effects(std::vector<robot::PlantEffect> existing, const std::vector<robot::PlantEffect>& found) {
  for (const auto& f : found) {
    const auto it = std::find_if(existing.begin(), existing.end(), [&](const robot::PlantEffect& e) { return same_cause(e, f); });
    if (it == existing.end()) {
      existing.push_back(f);
      continue;
    }
    // The same cause found again on top of itself: one entry, coefficients added (exact for
    // a payload's mass and first moment; a scale such as K_I compounds).
    if (it->effect == robot::Effect::torque_constant && f.coefficients.size() == 1) {
      it->coefficients[0] = (1.0 + it->coefficients[0]) * (1.0 + f.coefficients[0]) - 1.0;  // scales compound
    } else {
      for (std::size_t k = 0; k < f.coefficients.size(); ++k) it->coefficients[k] += f.coefficients[k];
    }
    it->params = f.params;
    if (it->effect == robot::Effect::payload && it->coefficients.size() >= 4 && it->coefficients[0] != 0.0) {
      it->params["mass_kg"] = it->coefficients[0];
      it->params["com_x_m"] = it->coefficients[1] / it->coefficients[0];
      it->params["com_y_m"] = it->coefficients[2] / it->coefficients[0];
      it->params["com_z_m"] = it->coefficients[3] / it->coefficients[0];
    }
  }
  return existing;
}

namespace {
double param_or(const robot::PlantEffect& e, const char* name, double fallback) {
  const auto it = e.params.find(name);
  return it == e.params.end() ? fallback : it->second;
}

/// A gear effect in the deflection channel (no torque coefficients of its own): joint
/// elasticity, and backlash as the deflection's jump.
bool in_deflection_channel(const robot::PlantEffect& e) {
  return e.effect == robot::Effect::joint_elasticity || (e.effect == robot::Effect::backlash && e.coefficients.empty());
}

/// A gear effect's deflection (the deflection channel's own shapes, signals.hpp) taken off
/// the joint's measured deflection: an elastic gear deflects by the gear torque over its
/// stiffness; backlash jumps by its gap where that torque changes sign. Without this, the
/// file's gear would be found again in every round of the loop.
void remove_gear_deflection(const robot::PlantEffect& e, JointSignals& s, std::vector<std::string>& notes) {
  const std::size_t n = s.size();
  if (s.deflection.size() != n || n == 0U) return;
  const std::vector<double>& torque = gear_torque(s);
  const double tau_rms = rms(torque);
  const double stiffness = param_or(e, "stiffness_nm_per_rad", 0.0);
  const double gap = param_or(e, "gap_rad", 0.0), share = param_or(e, "transition_share_of_torque_rms", 0.0);
  const std::string joint = "joint " + std::to_string(s.joint) + ": ";
  if (e.effect == robot::Effect::joint_elasticity) {
    if (!(stiffness > 0.0)) {
      notes.push_back(joint + "joint_elasticity without a positive stiffness_nm_per_rad: not in the deflection's prediction");
      return;
    }
    for (std::size_t k = 0; k < n; ++k) s.deflection[k] -= torque[k] / stiffness;
  } else if (e.effect == robot::Effect::backlash) {
    if (!(gap > 0.0) || !(share > 0.0) || !(tau_rms > 0.0)) {
      notes.push_back(joint + "backlash without gap_rad and transition_share_of_torque_rms: not in the deflection's prediction");
      return;
    }
    for (std::size_t k = 0; k < n; ++k) s.deflection[k] -= 0.5 * gap * backlash_shape(torque[k], share, tau_rms);
  }
}
}  // namespace

std::vector<std::vector<double>> joint_effects_torque(const std::vector<robot::PlantEffect>& effects,
                                                      const std::vector<JointSignals>& signals, std::vector<std::string>* notes) {
  std::vector<std::vector<double>> out;
  for (const auto& s : signals) {
    out.emplace_back(s.size(), 0.0);
    std::vector<FittedEffect> model;
    for (const auto& e : effects) {
      if (e.joint != s.joint || in_deflection_channel(e)) continue;
      model.push_back({e.effect, e.setting, e.coefficients});
    }
    if (model.empty()) continue;
    try {
      out.back() = predict_effects(model, s);
    } catch (const std::invalid_argument& err) {
      if (notes != nullptr) notes->push_back("joint " + std::to_string(s.joint) + ": " + err.what());
    }
  }
  return out;
}

std::vector<std::vector<double>> known_joint_torque(const robot::RobotModel& model, const robot::RobotModel& nominal,
                                                    const io::Recording& rec, std::vector<std::string>* notes) {
  const sim::ArmDynamics arm = model.dynamics();
  ModelContext ctx;
  ctx.arm = &arm;
  for (const auto& jd : model.joints) ctx.torque_constant.push_back(jd.link.torque_constant);
  for (const auto& jd : nominal.joints) ctx.rotor_inertia.push_back(jd.link.rotor_inertia);
  return joint_effects_torque(model.plant_effects, signals_from_model(rec, ctx), notes);
}

std::vector<std::string> add_joint_effects(const std::vector<robot::PlantEffect>& effects, std::vector<JointSignals>& signals) {
  std::vector<std::string> notes;
  const auto extra = joint_effects_torque(effects, signals, &notes);
  for (std::size_t j = 0; j < signals.size(); ++j) {
    auto& s = signals[j];
    for (const auto& e : effects) {
      if (e.joint == s.joint && in_deflection_channel(e)) remove_gear_deflection(e, s, notes);
    }
    for (std::size_t k = 0; k < s.size(); ++k) {
      s.tau_model[k] += extra[j][k];
      s.residual[k] -= extra[j][k];
    }
  }
  return notes;
}

}  // namespace jg::diag
