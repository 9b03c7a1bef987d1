// Friction study on measured joint friction (e.g. ../shared/data/real/franka-joint-friction):
// identify LuGre on one recording, let the diagnosis find what LuGre leaves out, and
// evaluate LuGre alone and LuGre + the named effects on the other recordings (held out).
#pragma once

#include <string>
#include <vector>

#include "diagnosis/diagnose.hpp"
#include "identification/identify.hpp"
#include "io/recording.hpp"

namespace jg::diag {

struct StudyFile {
  std::string path;
  io::ReadOptions read;  ///< how to read it (time column, torque column pattern)
  /// The torque column was offset by its own value at the first sample, the arm at rest
  /// (e.g. the Franka data's "minus the initial offset"): every prediction is then offset
  /// the same way, by the model's torque at rest at the first position (JointSignals), and
  /// a constant fitted on the training file (current_offset) is taken as that file's own
  /// state at its first sample, not carried to the other files.
  bool offset_at_start = false;
};

struct StudyFileResult {
  std::string path;
  bool training = false;
  std::size_t samples = 0;
  double lugre_rms = 0.0;     ///< LuGre alone [N·m]
  double extended_rms = 0.0;  ///< LuGre + diagnosed effects [N·m]
};

struct StudyResult {
  int joint = 0;
  LuGreParams<double> lugre{};
  ident::IdentificationResult identification;
  JointDiagnosis diagnosis;
  std::vector<StudyFileResult> files;
};

/// Resamples a one-joint recording onto a uniform time base by time stamp (io::regularize:
/// linear, at its median step's nominal rate); refuses gaps longer than `max_gap_steps`
/// median steps.
io::Recording resample_uniform(const io::Recording& r, double max_gap_steps = 20.0);

StudyResult friction_study(const std::vector<StudyFile>& files, std::size_t train_index,
                           const ident::GaSettings& ga, const ident::SearchRanges& ranges);

}  // namespace jg::diag
