// The whole diagnosis of real recordings against a robot file, as `jointguard diagnose`
// runs it (cli/diagnose.cpp parses and reads the files, cli/diagnose_output.cpp writes):
//   1. the robot file's own plant_effects folded into the prediction (a file written by
//      --model-out carries what an earlier diagnosis found);
//   2. without a simulated recording: causes named against the robot file itself (a payload,
//      a link's mass, a drive's torque constant), then the whole arm's rigid body identified
//      on what they leave (unless the file carries the links and friction an earlier
//      diagnosis identified: DiagnosisResult::file_baseline);
//   3. the per-joint signals (real against simulated, or against the model's prediction);
//   4. the arm-level causes, once for the arm; with several recordings, what transfers
//      between them (leave-one-recording-out);
//   5. each joint's diagnosis;
//   6. on request, the robot file to write back (the named physics as plant_effects).
// Prints nothing: everything the command reports is in DiagnosisResult, handed to
// DiagnosisSettings::on_stage as each stage ends (a run that stops on an error has been
// reported up to there).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "arm_identification/rigid_body_identification.hpp"
#include "diagnosis/arm.hpp"
#include "diagnosis/cross_motion.hpp"
#include "diagnosis/diagnose.hpp"
#include "diagnosis/signals.hpp"
#include "io/loaded_recording.hpp"
#include "jointguard/friction/lugre.hpp"
#include "robot/plant_effects.hpp"
#include "robot/robot_model.hpp"

namespace jg::diag {

/// What the diagnosis works on, as the command read it.
struct DiagnosisInputs {
  robot::RobotModel nominal;                  ///< the robot file as read (any torque kind)
  std::vector<io::LoadedRecording> reals;     ///< recordings of one arm (check_recording)
  /// Simulated recordings of the same motions, one per real one in their order; empty: the
  /// model predicts the torque over the real motion.
  std::vector<io::LoadedRecording> sims;
  std::vector<LuGreParams<double>> friction;  ///< nominal friction per joint of the prediction; empty: none
};

/// A stage just ended (DiagnosisSettings::on_stage): what DiagnosisResult holds from it.
enum class DiagnosisStage {
  rigid_body,  ///< rigid_body, rigid_body_refused, named_folds (also when not tried: all empty)
  signals,     ///< segments, file_effects, spans
  arm,         ///< folds, arm, signals
  joint,       ///< joints.back() (one call per joint, in order)
};

struct DiagnosisResult;

struct DiagnosisSettings {
  /// Without sims: name causes against the robot file and identify the arm's rigid body
  /// before the per-joint diagnosis (off: `--no-rigid-body`, the file's rigid body is kept).
  bool identify_rigid_body = true;
  bool trace = false;      ///< each selection step to stderr
  bool model_out = false;  ///< compute the robot file to write back (DiagnosisResult::model_out)
  /// Called as each stage ends, with the result so far (may be empty).
  std::function<void(DiagnosisStage, const DiagnosisResult&)> on_stage;
};

/// The robot file with what was found: identified links and the named effects.
struct ModelOut {
  robot::RobotModel model;
  std::vector<std::string> notes;      ///< arm notes: effects that could not be taken back out of a link
  bool rigid_body_identified = false;  ///< the identified links are written
};

/// The robot file's plant_effects put into the model's prediction.
struct FileEffectsInPrediction {
  std::size_t count = 0;           ///< plant_effects of the file (after folding)
  std::vector<std::string> notes;  ///< what stays out of the prediction
};

struct DiagnosisResult {
  // Stage 2 (without sims, unless switched off).
  std::optional<dyn::RigidBodyIdResult> rigid_body;  ///< identified (accepted or not)
  std::string rigid_body_refused;                   ///< why it could not be identified (empty: it was, or not tried)
  /// The robot file carries the links and friction an earlier diagnosis identified
  /// (`friction_baseline`): taken as the model, neither named against nor refitted, so that
  /// the loop's next round starts from the residual the last one left.
  bool file_baseline = false;
  /// Several recordings and causes named against the file: each fold's arm-level fit.
  std::optional<std::vector<CrossMotionFold>> named_folds;
  // Stage 3.
  std::size_t segments = 0;  ///< uniform segments over all recordings
  std::optional<FileEffectsInPrediction> file_effects;
  std::vector<SampleSpan> spans;      ///< each recording's samples in `signals`
  std::vector<JointSignals> signals;  ///< per joint, the arm-level causes taken out (what the joints were diagnosed on)
  // Stage 4: the arm (the causes named against the file first, then those found after).
  std::optional<std::vector<CrossMotionFold>> folds;  ///< several recordings: leave-one-recording-out
  ArmDiagnosis arm;
  // Stages 5 and 6.
  std::vector<JointDiagnosis> joints;
  std::optional<ModelOut> model_out;  ///< with DiagnosisSettings::model_out
};

/// The recording whose longest segment is the longest of all (rigid-body identification,
/// joint names, the friction file's joints).
const io::LoadedRecording& primary(const std::vector<io::LoadedRecording>& reals);

/// Refuses (std::invalid_argument naming the file) a recording that does not fit the model's
/// `model_joints` or whose torque kind differs from `first`'s (the recordings of one arm).
void check_recording(const io::LoadedRecording& r, const io::LoadedRecording& first, std::size_t model_joints);

/// Runs the stages above (the header). Throws std::invalid_argument naming the recording
/// when the data cannot give what is asked, or when a simulated recording does not cover
/// its real one.
DiagnosisResult run_diagnosis(const DiagnosisInputs& in, const DiagnosisSettings& settings);

/// What the diagnosis leaves unexplained on a joint, as a multiple of its noise: the held-out
/// RMS after the findings over the noise estimated from the data. Above kUnexplainedOverNoise a
/// mismatch remains that no effect of the vocabulary explains; said so, never "nothing missing".
inline constexpr double kUnexplainedOverNoise = 1.5;
/// The held-out RMS the joint's findings leave [N·m] (the one before them without findings).
double heldout_rms_left(const JointDiagnosis& d);
double unexplained_over_noise(const JointDiagnosis& d);

}  // namespace jg::diag
