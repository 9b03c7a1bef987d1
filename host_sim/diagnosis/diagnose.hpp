// Model-mismatch diagnosis of one joint: locate where the residual is significant and
// what it depends on, select the physical effects that explain it (forward selection of
// effect groups by the Bayesian information criterion, each addition confirmed on held-out
// blocks of the recording), fit them, and report before/after figures.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/effects.hpp"
#include "diagnosis/signals.hpp"

namespace jg::diag {

/// Another effect the data explain as well as a claim: named beside it, not instead.
struct Alternative {
  robot::Effect effect = robot::Effect::none;
  std::map<std::string, double> params;
  /// Jackknife z of what tells the claim from this alternative (below
  /// DiagnoseOptions::min_null_z the recording does not tell them apart).
  double null_z = 0.0;
  std::string text;
};

struct Finding {
  robot::Effect effect = robot::Effect::none;
  std::map<std::string, double> params;
  double confidence = 0.0;   ///< 0..1, from the evidence for keeping it (information criterion)
  double delta_bic = 0.0;    ///< BIC increase when it is removed from the final model
  std::string text;          ///< human description
  /// Evidence against the recording's own variation: the effect's size over the standard
  /// error of its refits with one block of the recording left out at a time (delete-one-block
  /// jackknife); claimed only at DiagnoseOptions::min_null_z or more. 0: not computed.
  double null_z = 0.0;
  /// Effects these data cannot tell from this one (a current offset and a friction level the
  /// same in both directions differ only at rest): each could be the cause instead.
  std::vector<Alternative> alternatives;
};

/// A selected effect with its setting and fitted coefficients: enough to predict it on
/// other data of the same joint (predict_effects).
struct FittedEffect {
  robot::Effect effect = robot::Effect::none;
  std::map<std::string, double> setting;
  std::vector<double> coefficients;
};

struct Segment {
  double t_begin = 0.0, t_end = 0.0;
  double rms = 0.0;
};

/// Where the residual lives: significant segments, what it depends on, periodicity, lag.
struct Location {
  std::vector<Segment> segments;               ///< smoothed |residual| above 3 sigma
  std::map<std::string, double> dependence;     ///< variable -> share of residual variance it explains (binned)
  double best_periods_per_rev = 0.0;            ///< strongest periodicity in position
  double lag_s = 0.0;                           ///< lag maximising correlation with the model torque
  double reversal_rms = 0.0, elsewhere_rms = 0.0;  ///< residual near velocity reversals vs elsewhere
};

struct JointDiagnosis {
  int joint = 1;
  std::vector<Finding> findings;  ///< ranked, strongest first; empty = "none"
  double noise_rms = 0.0;          ///< estimated from the data itself
  double rms_before = 0.0, rms_after = 0.0;
  double heldout_rms_before = 0.0, heldout_rms_after = 0.0;
  double whiteness_q = 0.0;        ///< Ljung-Box statistic of the final residual (20 lags)
  double whiteness_p = 0.0;        ///< its p-value (chi-square, 20 dof)
  Location location;
  std::vector<double> fitted;      ///< the fitted effects' torque over the recording
  std::vector<FittedEffect> model; ///< the selected effects, for predict_effects
  std::vector<std::string> notes;
};

struct DiagnoseOptions {
  int blocks = 10;            ///< the recording is cut in this many blocks ...
  std::vector<int> heldout{1, 4, 7};  ///< ... and these are held out
  double min_delta_bic = 25.0;  ///< evidence an effect must bring (strong, Kass-Raftery)
  double min_heldout_gain = 0.005;  ///< relative held-out RMS reduction an effect must bring
  /// The same for a second component of a cause the robot file carries on the joint (a ripple
  /// at another period than the file's): an earlier diagnosis of this arm fitted the first,
  /// and a small remainder beside it would be added one a round by the loop (measured on the
  /// real Panda: 120 a turn on joint 3, 2 % of its held-out residual, in the second round;
  /// an injected ripple at 3x the noise brings 20 % or more).
  double min_heldout_gain_beside_file = 0.05;
  int max_effects = 5;
  /// Replacement passes after the forward selection (0 = greedy forward selection only).
  int replacement_passes = 2;
  /// Share of an effect's regressor norm that must lie outside the span of the effects
  /// already chosen (1/sqrt(variance inflation)); below it the effect is not separable.
  double min_independence = 0.14;
  /// An effect in the gear-deflection channel must move the deflection by at least this
  /// many noise levels of that channel (RMS of its fitted contribution).
  double min_deflection_snr = 3.0;
  /// A claim's size over its block-jackknife standard error (Finding::null_z) at least this.
  double min_null_z = 3.0;
  /// A recording shorter than this is too short to tell an effect from the recording's own
  /// variation (each of the blocks a fraction of a second): nothing is claimed, and it says so.
  double min_duration_s = 2.0;
  /// Effects not offered (e.g. they did not transfer between recordings of the same arm).
  std::vector<robot::Effect> excluded_effects;
  /// Effects offered only at the given settings (the robot file carries them there, an
  /// earlier diagnosis wrote them): what is found is a change of their size, never a second
  /// component of the same cause at another setting.
  std::vector<std::pair<robot::Effect, std::map<std::string, double>>> only_at_setting;
  /// Each selection step to stderr (the caller decides: `diagnose --trace`); the algorithms
  /// read no environment. (The test-set bench's JG_DIAG_TRACE prints only its own lines.)
  bool trace = false;
};

/// Why a recording is too short to judge (empty: long enough).
std::string too_short_to_judge(const std::vector<double>& t, const DiagnoseOptions& o);

/// Per sample: true where it lies in a held-out block.
std::vector<bool> heldout_mask(std::size_t n, const DiagnoseOptions& o);

JointDiagnosis diagnose_joint(const JointSignals& s, const DiagnoseOptions& o = {});

/// `d` (diagnose_joint(s, o)) taken on to where the loop settles: the joint diagnosed again on
/// what its effects leave, with them held fixed and offered again only at their settings (as
/// the next round of `diagnose --model-out`, then `--model`, has them in the robot file), and
/// what that claims added to `d`, until a pass claims nothing; at most `max_passes` in all.
/// Fitted together in one selection, the chosen effects take part of a small remainder (each
/// candidate is judged refitted with them); held fixed, it shows: on the real Panda, a
/// 10-a-turn ripple on joint 5 was the loop's second round's one claim. Returns the diagnoses run
/// in all, the first included.
int diagnose_joint_to_convergence(const JointSignals& s, DiagnoseOptions o, JointDiagnosis& d, int max_passes = 3);

/// The torque the fitted effects add over other signals of the same joint.
std::vector<double> predict_effects(const std::vector<FittedEffect>& model, const JointSignals& s);

}  // namespace jg::diag
