// `jointguard inject`: a real (or simulated) recording with known effects added to its
// torque or current columns over its own measured motion, every other field left as it is:
// a recording with a known answer for the diagnosis (docs/diagnosis.md, "Injection into real
// recordings").
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "injection/added_torque.hpp"
#include "io/regularize.hpp"

namespace jg::inject {

struct InjectRequest {
  std::string recording_path;             ///< read again as text: only its torque fields change
  const io::Regularized* data = nullptr;  ///< the same recording as the CLI's reader made it uniform
  /// The recording as read, before it was made uniform (optional): where given, the effects of
  /// a row's own state (acts_on_the_row_alone) are computed at each row, not interpolated from
  /// the uniform grid. Not with a time_delay among the effects (it delays what the grid adds).
  const io::Recording* rows = nullptr;
  io::TorqueKind torque = io::TorqueKind::tau_m;
  InjectModel model;
  /// False for currents with a URDF and no drive file's k_i: N·m cannot be turned into A.
  bool torque_constant_known = true;
  std::vector<robot::PlantEffect> effects;
};

struct JointChange {
  int joint = 1;
  std::string column;           ///< e.g. "tau_j3", "i2"
  std::size_t rows_changed = 0;
  double max_abs_change = 0.0;  ///< [column units]
  double rms_change = 0.0;      ///< over the rows changed [column units]
  /// A time_delay's share the model predicts, delay x d tau_model/dt, RMS over the segments'
  /// samples [column units] (0 without a delay): the size of a delay as the diagnosis can see
  /// it (rms_change also counts the reading's own noise and fast content, shifted).
  double delay_on_model_rms = 0.0;
};

struct InjectResult {
  std::string text;             ///< the new CSV
  std::string source_sha256;    ///< of the recording's text
  std::string unit;             ///< "A" for currents, else "N·m"
  std::vector<JointChange> joints;
  std::size_t data_rows = 0;
  std::size_t rows_outside = 0; ///< rows in no segment (left as they are)
  bool repeats_follow_state = false;  ///< rows repeating a state got the previous row's reading
};

/// The recording's text with the effects added (nothing changed for no effects). Throws
/// std::invalid_argument (what cannot be done) or io::FormatError (file, line, field).
InjectResult inject(const InjectRequest& r);

/// The output's side file: the source's own (model, sample time, seed kept, so the output
/// reads as the source did) with this injection appended to "injections": source and its
/// SHA-256, the effects as injected, the inputs by name with their SHA-256, what changed.
nlohmann::json side_file(const InjectRequest& r, const InjectResult& result,
                         const std::vector<std::pair<std::string, std::string>>& inputs);

/// The side file a recording has (<stem>.json beside it), or "" when it has none.
std::string side_file_path(const std::string& csv_path);

}  // namespace jg::inject
