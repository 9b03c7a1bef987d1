#include "diagnosis/model_out.hpp"

#include <algorithm>

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

}  // namespace jg::diag
