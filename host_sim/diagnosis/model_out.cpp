#include "diagnosis/model_out.hpp"

#include <algorithm>
#include <stdexcept>

#include "dynamics/sensitivity.hpp"

namespace jg::diag {

std::vector<robot::PlantEffect> plant_effects_of(const ArmDiagnosis& arm, const std::vector<JointDiagnosis>& joints) {
  std::vector<robot::PlantEffect> out;
  for (std::size_t i = 0; i < arm.model.size(); ++i) {
    const auto& m = arm.model[i];
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
      if (m.effect == "backlash" && m.setting.count("gap_rad") != 0U) p.params["gap_rad"] = m.setting.at("gap_rad");
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

std::vector<std::string> fold_arm_effects(robot::RobotModel& m) {
  std::vector<std::string> notes;
  const auto links = m.plant_links();
  std::vector<robot::PlantEffect> kept;
  for (const auto& e : m.plant_effects) {
    const bool payload = e.effect == "payload" && e.setting.count("picked_up_at_s") == 0U;
    const bool link = e.effect == "link_inertial_error" && e.setting.count("link") != 0U;
    if (e.joint != 0 || !(payload || link) || e.coefficients.size() < 4) {
      if (e.joint == 0) notes.push_back("arm: " + e.effect + " (picked up during the recording) stays out of the prediction");
      kept.push_back(e);
      continue;
    }
    const std::size_t l = payload ? links.size() - 1 : static_cast<std::size_t>(e.setting.at("link")) - 1;
    if (l >= links.size()) {
      notes.push_back("arm: " + e.effect + " on a link the model does not have");
      continue;
    }
    const sim::PlantLink changed = sim::with_mass_first_moment_change(
        links[l], e.coefficients[0], Eigen::Vector3d(e.coefficients[1], e.coefficients[2], e.coefficients[3]));
    auto& d = m.joints[l].link;
    d.mass = changed.mass;
    for (int k = 0; k < 3; ++k) d.com[k] = changed.com(k);
    const Eigen::Matrix3d& I = changed.inertia_com;
    const double six[6] = {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)};
    for (int k = 0; k < 6; ++k) d.inertia_com[k] = six[k];
  }
  m.plant_effects = kept;
  return notes;
}

std::vector<std::string> add_joint_effects(const std::vector<robot::PlantEffect>& effects, std::vector<JointSignals>& signals) {
  std::vector<std::string> notes;
  for (auto& s : signals) {
    std::vector<FittedEffect> model;
    for (const auto& e : effects) {
      // Gear effects live in the deflection channel, with no torque coefficients.
      if (e.joint != s.joint || e.effect == "joint_elasticity" || (e.effect == "backlash" && e.coefficients.empty())) continue;
      model.push_back({e.effect, e.setting, e.coefficients});
    }
    if (model.empty()) continue;
    std::vector<double> extra;
    try {
      extra = predict_effects(model, s);
    } catch (const std::invalid_argument& err) {
      notes.push_back("joint " + std::to_string(s.joint) + ": " + err.what());
      continue;
    }
    for (std::size_t k = 0; k < s.size(); ++k) {
      s.tau_model[k] += extra[k];
      s.residual[k] -= extra[k];
    }
  }
  return notes;
}

}  // namespace jg::diag
