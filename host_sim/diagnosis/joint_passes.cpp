// A joint's diagnosis taken on to where the loop (diagnose --model-out, then diagnose --model
// with that file) would settle, in one diagnosis.
#include <algorithm>

#include "diagnosis/diagnose.hpp"

namespace jg::diag {
namespace {

/// `s` with `d`'s fitted effects taken off the residual and put into the model's prediction,
/// as the next round of the loop has them (written into the robot file). The gear-deflection
/// channel is left out: its findings are `d`'s already and its signal is not reduced by them.
JointSignals what_effects_leave(const JointSignals& s, const JointDiagnosis& d) {
  JointSignals rest = with_fitted_in_model(s, d.fitted);
  rest.deflection.clear();
  return rest;
}

/// `more`, found on what `d`'s effects leave, added to `d`: its findings and fitted effects
/// after d's; the held-out and whole-recording figures, and the whiteness, those after both.
void add_pass(JointDiagnosis more, JointDiagnosis& d) {
  for (std::size_t k = 0; k < d.fitted.size() && k < more.fitted.size(); ++k) d.fitted[k] += more.fitted[k];
  for (auto& f : more.findings) d.findings.push_back(std::move(f));
  for (auto& m : more.model) d.model.push_back(std::move(m));
  d.rms_after = more.rms_after;
  d.heldout_rms_after = more.heldout_rms_after;
  d.whiteness_q = more.whiteness_q;
  d.whiteness_p = more.whiteness_p;
}
}  // namespace

int diagnose_joint_to_convergence(const JointSignals& s, DiagnoseOptions o, JointDiagnosis& d, int max_passes) {
  int passes = 1;
  while (passes < max_passes && !d.findings.empty()) {
    ++passes;
    // The effects chosen so far are offered again only at their settings, as those the robot
    // file carries are in the next round (a ripple at another period beside them): fitted on
    // all samples, a change of their size is nothing, and another shape of them is not claimed.
    for (const auto& m : d.model) {
      if (m.setting.count("rotor_acceleration") != 0U) continue;  // the deflection channel's torque side
      const std::pair<robot::Effect, std::map<std::string, double>> held{m.effect, m.setting};
      if (std::find(o.only_at_setting.begin(), o.only_at_setting.end(), held) == o.only_at_setting.end()) o.only_at_setting.push_back(held);
    }
    JointDiagnosis more = diagnose_joint(what_effects_leave(s, d), o);
    if (more.findings.empty()) break;
    add_pass(std::move(more), d);
  }
  return passes;
}

}  // namespace jg::diag
