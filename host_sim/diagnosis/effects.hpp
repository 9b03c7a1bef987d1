// The library of candidate physical effects. Each effect is a small parametric model of
// the torque it adds to the residual, written as regressor columns (linear in its
// amplitude parameters) for each value of its nonlinear parameter (scanned on a grid).
// The effects are the catalogue's (robot/effect_catalogue.hpp).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "diagnosis/signals.hpp"
#include "robot/effect_catalogue.hpp"

namespace jg::diag {

/// One instance of an effect: its columns over the samples, for one setting of its
/// nonlinear parameter (if any).
struct Candidate {
  robot::Effect effect = robot::Effect::none;
  std::vector<std::vector<double>> columns;
  std::map<std::string, double> setting;  ///< nonlinear parameter(s) of this instance
  int nonlinear_params = 0;               ///< counted in the information criterion
};

/// One instance of `effect` at the given nonlinear setting over the signals (empty
/// columns when the signals cannot support it, e.g. payload without a model).
Candidate make_candidate(robot::Effect effect, const std::map<std::string, double>& setting,
                         const JointSignals& s);

/// A continuous setting that the reported size trades against, refined once the effect is
/// claimed: a Stribeck velocity (offered on a coarse grid: between its grid neighbours), a
/// delay (offered as its first-order column, fitted `coefficients`: the exact difference over
/// it, from the first order's size up to 4 times it). Its key and the interval of its magnitude,
/// `sign` its sign; nullopt for anything else. `dt` the sample time [s].
struct SettingBracket {
  std::string key;
  double lo = 0.0, hi = 0.0;
  double sign = 1.0;
};
std::optional<SettingBracket> refinable_setting(const Candidate& c, const std::vector<double>& coefficients, double dt);

/// All instances of all effects that the signals can support (an effect that needs a
/// model, e.g. payload, is skipped when the model's columns are absent).
std::vector<std::vector<Candidate>> build_candidates(const JointSignals& s);

/// Why the fitted coefficients of an effect are not physically plausible (empty when they
/// are): the ranges per effect are listed in docs/diagnosis.md ("Plausible parameters").
/// `beyond_size` (when given) says whether the reason is a size beyond the plausible range (a
/// torque constant more than 30 % off, a delay beyond 50 ms, a torque larger than the joint
/// measured): a mismatch of that size that the data show and no plausible cause explains,
/// rather than a fit of the wrong sign (less friction than none) or an odd setting.
std::string implausible(const Candidate& c, const std::vector<double>& coefficients, const JointSignals& s,
                        bool* beyond_size = nullptr);

/// Physical parameters of an effect from its fitted coefficients, in words a robotics
/// engineer uses, plus a one-line description.
std::map<std::string, double> describe(const Candidate& c, const std::vector<double>& coefficients,
                                       const JointSignals& s, std::string& text);

}  // namespace jg::diag
