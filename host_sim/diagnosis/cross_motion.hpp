// Several recordings of one arm: the diagnosis's findings fitted on some recordings must
// improve the others (cross-motion validation). Each recording in turn is left out; the
// arm-level causes and each joint's effects are selected and fitted on the rest and
// predicted over the left-out recording's motion, and its residual is compared before and
// after. A cause that holds for the arm (a payload, a link's mass) transfers; an effect fitted
// to one motion's particulars (an offset that drifted, a shape that only one motion excites)
// does not, and is not claimed.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "diagnosis/arm.hpp"
#include "diagnosis/signals.hpp"

namespace jg::diag {

/// Samples [begin, end) of the concatenated signals that came from one recording.
struct SampleSpan {
  std::size_t begin = 0, end = 0;
};

/// The signals restricted to the given spans, in their order.
std::vector<JointSignals> slice_signals(const std::vector<JointSignals>& joints, const std::vector<SampleSpan>& spans);

/// One joint of the left-out recording: residual RMS as the model leaves it, with the arm-level
/// causes fitted on the other recordings, and with those and the joint's own effects [N·m].
struct CrossMotionJoint {
  int joint = 1;
  double rms_before = 0.0, rms_after_arm = 0.0, rms_after = 0.0;
  std::vector<robot::Effect> effects;  ///< the joint's effects selected on the other recordings
  /// Those of `effects` without which the left-out recording's RMS is lower by more than
  /// kCrossMotionWorseShare: fitted on the others, they make this one worse.
  std::vector<robot::Effect> worse_effects;
};

struct CrossMotionFold {
  std::size_t left_out = 0;                  ///< index of the recording predicted
  std::vector<std::string> arm_causes;       ///< "payload@7", "link_inertial_error@3" fitted on the others
  std::vector<CrossMotionJoint> joints;
  /// Mean over joints of (after / before)^2 of the arm-level causes alone: < 1 they improve it.
  double arm_mse_ratio = 1.0;
};

/// Leave-one-recording-out over `recordings` (spans of `joints`, at least 2); `arm` as for
/// diagnose_arm. Payloads picked up during a recording are not offered (each recording has
/// its own clock; a cause carried in all of them is the one that transfers). Without
/// `with_joints`, the arm-level causes alone (CrossMotionFold::joints holds their RMS only).
std::vector<CrossMotionFold> cross_motion_folds(const std::vector<JointSignals>& joints,
                                                const std::vector<SampleSpan>& recordings,
                                                const ArmDiagnosisOptions& options, const sim::ArmDynamics* arm,
                                                bool with_joints = true);

/// Tolerance of "made worse": an effect without which a left-out recording's RMS is lower by
/// more than this share is withdrawn; the arm-level causes when their mean MSE ratio on a
/// left-out recording exceeds 1 + this.
inline constexpr double kCrossMotionWorseShare = 0.01;

/// A joint's effect that, fitted on the other recordings, made some left-out recording worse.
struct NotTransferring {
  int joint = 1;
  robot::Effect effect = robot::Effect::none;
  std::string why;
};

/// Every (joint, effect) that made some left-out recording worse, once, with a reason.
std::vector<NotTransferring> effects_not_transferring(const std::vector<CrossMotionFold>& folds,
                                                                 const std::vector<std::string>& names);

/// "effect@link" of each arm-level cause in `model` (as CrossMotionFold::arm_causes).
std::vector<std::string> cause_names(const std::vector<FittedEffect>& model);

/// Why the arm-level causes `claimed` (cause_names of the fit on all recordings) do not
/// transfer (empty: they do, or no fold fitted any): a fold that fitted causes must have
/// fitted the same ones (which link carries a mass error must not depend on the motion), and
/// they must improve the recording it left out.
std::string arm_not_transferring(const std::vector<CrossMotionFold>& folds, const std::vector<std::string>& names,
                                 const std::vector<std::string>& claimed);

}  // namespace jg::diag
