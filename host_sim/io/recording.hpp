// Recordings: the CSV format of ../shared/CONTRACT.md (plus an optional JSON side file).
// One header line, one row per sample, SI units:
//   t, q<j>, dq<j>, i<j> and/or tau_m<j> and/or tau_j<j>, [tau_ext<j>], [collision],
//   any other columns.
// The reader accepts extra columns (kept by name) and missing optional ones, so real
// recordings go through the same code. Every error names file, line and field.
// Time stamps need only increase: real loggers jitter, repeat rows and skip samples;
// io/regularize.hpp turns such a recording into uniform segments.
#pragma once

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace jg::io {

/// Thrown for malformed input; what() is "file:line: field 'name': problem".
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Which torque a recording's consumers use. The model applies rotor inertia and other
/// motor-side terms only to the first two (robot/torque_kind.hpp).
enum class TorqueKind {
  current,  ///< i<j> [A], times the model's torque constant K_I
  tau_m,    ///< motor torque at the link side, K_I * i [N·m]
  tau_j,    ///< link-side joint torque from a torque sensor after the gear [N·m]
};
/// "i", "tau_m", "tau_j": the column prefix, also used in the JSON outputs.
[[nodiscard]] const char* to_string(TorqueKind kind);

/// What the user says the torque columns are (--torque-kind).
enum class TorqueChoice {
  automatic,  ///< tau_j<j> when present, else tau_m<j>, else i<j>
  current,    ///< use i<j> (required)
  motor,      ///< use tau_m<j> as a motor torque (required)
  joint,      ///< use tau_j<j>, or tau_m<j> re-read as a joint-torque-sensor reading
};
/// Parses "auto" | "current" | "motor" | "joint"; throws std::invalid_argument otherwise.
[[nodiscard]] TorqueChoice parse_torque_choice(const std::string& text);

struct RecordingMeta {
  std::string model;        ///< robot model name or file
  double sample_time = 0.0; ///< [s], 0 when unknown
  std::optional<unsigned long long> seed;
  std::string scenario;
  /// What made the recording (the writing command's identity, cli/common.hpp) as JSON text;
  /// written to and read from the side file's "identity" when not empty.
  std::string identity_json;
};

/// Column-major storage: signal[joint][sample]. Joint numbers are those of the column
/// names (usually 1..n); joint_ids[k] is the number of the k-th joint.
struct Recording {
  std::vector<int> joint_ids;
  std::vector<double> t;
  std::vector<std::vector<double>> q, dq;
  std::vector<std::vector<double>> current;   ///< [A], empty when absent
  std::vector<std::vector<double>> tau_m;     ///< [N·m] motor torque at the link side, empty when absent
  std::vector<std::vector<double>> tau_j;     ///< [N·m] joint torque sensor, empty when absent
  std::vector<std::vector<double>> tau_ext;   ///< [N·m] ground truth, empty when absent
  std::vector<int> collision;                 ///< 0 or collided link, empty when absent
  std::map<std::string, std::vector<double>> extra;  ///< other numeric columns
  /// Where regularize resampled rows sampled off its grid (io/regularize.hpp): the rows it
  /// interpolated from, their time and each joint's position and velocity; empty when the
  /// samples are the rows as recorded. An effect of one row's own state is computed at them
  /// and interpolated as the torque was (diagnosis/effects.cpp).
  std::vector<double> rows_t;
  std::vector<std::vector<double>> rows_q, rows_dq;
  RecordingMeta meta;
  /// The torque consumers use (set by the reader from the columns and ReadOptions::torque).
  TorqueKind torque_kind = TorqueKind::tau_m;
  /// Rows dropped by the reader because they repeated the previous row exactly, time
  /// stamp included (a logger writing the same sample twice).
  std::size_t duplicate_rows_dropped = 0;
  /// What the reader noticed and did without refusing (also printed to stderr as "note: ...").
  std::vector<std::string> notes;

  [[nodiscard]] std::size_t joints() const { return joint_ids.size(); }
  [[nodiscard]] std::size_t samples() const { return t.size(); }
  /// Allocates the per-joint vectors for n joints numbered 1..n with `samples` rows.
  void resize(std::size_t n_joints, std::size_t n_samples, bool with_current, bool with_tau_m,
              bool with_tau_ext, bool with_collision);
};

struct ReadOptions {
  std::string time_column = "t";
  /// Column holding the link-side motor torque when it is not tau_m<j>; "{j}" is
  /// replaced by the joint number (e.g. "q{j}_tau_J_compensate" for torque-sensor data).
  std::string torque_column_pattern;
  /// Which torque to use; `joint` moves tau_m<j> columns to tau_j when there is no tau_j<j>.
  TorqueChoice torque = TorqueChoice::automatic;
};

/// The columns `rec.torque_kind` names: tau_j, tau_m, or the currents [A] (which the
/// caller multiplies by its model's K_I).
[[nodiscard]] const std::vector<std::vector<double>>& torque_columns(const Recording& rec);

/// Reads a recording; the JSON side file <stem>.json is read when present.
[[nodiscard]] Recording read_recording(const std::string& path, const ReadOptions& options = {});

/// Writes CSV (and <stem>.json with the metadata) atomically: to temporary files (names
/// unique to the writer) renamed into place together under the folder's lock, so a failure
/// leaves nothing half-written and two writers of one path leave one complete pair. Refuses
/// (FormatError) to overwrite a <stem>.json that is not a jointguard side file.
void write_recording(const std::string& path, const Recording& rec);

/// The value of "format" in the JSON side files jointguard writes beside a recording.
inline constexpr const char* kSideFileFormat = "jointguard-recording";
/// `<folder>/<stem>.json` of a recording's path: its side file.
[[nodiscard]] std::string side_file_path(const std::string& csv_path);
/// A side file is ours when it carries "format": kSideFileFormat, or (files written before
/// that key) is an object of only the keys jointguard wrote; any other file of that name is
/// another program's: ignored when reading (a note), never overwritten.
enum class SideFile { absent, ours, foreign };
/// Classifies the file at json_path; `why` receives the reason for `foreign`.
[[nodiscard]] SideFile classify_side_file(const std::string& json_path, std::string* why = nullptr);
/// Throws FormatError naming the side file when writing the recording at csv_path would
/// overwrite another program's <stem>.json.
void check_side_file_writable(const std::string& csv_path);

}  // namespace jg::io
