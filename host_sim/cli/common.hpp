// Helpers shared by the subcommands: options every command spells the same way.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "io/recording.hpp"
#include "io/regularize.hpp"
#include "jointguard/observer/momentum_observer.hpp"
#include "robot/robot_model.hpp"
#include "workflow/steps.hpp"

namespace jg::cli {

/// --observer first_order|lowpass2|paper_bandpass|paper_improved and --gains K1[,K2[,K3]].
/// Without --gains the first-order observer takes the default for the loop rate
/// (tuning::default_gains); the other presets need their gains.
struct ObserverOptions {
  std::string preset = "first_order";
  std::vector<double> gains;
  bool align_motor_torque = kAlignMotorTorqueDefault;  ///< --observer-torque-mean / --no-observer-torque-mean
  void add_to(CLI::App* cmd);
  [[nodiscard]] ObserverGains to_gains(double rate_hz) const;
};

void check_scalar(const std::string& scalar);

/// --base LINK, --tip LINK (a URDF's chain) and --drive FILE (drive parameters by joint
/// name), next to every --model.
void add_model_selection(CLI::App* cmd, robot::LoadOptions& o);

/// A finite number within [lo, hi] (CLI::Range lets NaN through: every comparison is false).
CLI::Validator finite_range(double lo, double hi);
/// An output file: its folder exists and is writable, and the path is not a folder. Checked
/// when the command line is read (exit 2, the option named), before any long run.
/// `creates_folders`: the writer creates missing folders (recordings, io::write_recording), so
/// the nearest existing folder must be writable and no file may stand in the way.
CLI::Validator output_file(bool creates_folders = false);
/// A recording's --out: output_file(true), and not a .json name (its side file <stem>.json
/// would be the recording itself).
CLI::Validator recording_output_file();

/// How a subcommand reads a recording: --torque-kind, --rate, --max-gap. Every recording
/// is regularized by time stamp (io/regularize.hpp) and the command says what was done.
struct RecordingOptions {
  std::string torque_kind = "auto";
  double rate_hz = 0.0;    ///< 0 = from the recording's median step
  double max_gap_s = 0.0;  ///< 0 = the default split threshold
  /// Adds the options; `rate_help` describes --rate for this command.
  void add_to(CLI::App* cmd, const std::string& rate_help = "Resample the recording to this rate [Hz] (default: "
                                                                 "its own median step, rounded)");
  [[nodiscard]] io::ReadOptions read_options() const;
  [[nodiscard]] io::RegularizeOptions regularize_options() const;
};

using workflow::LoadedRecording;

/// Reads and regularizes a recording; prints the resampling line and the torque used.
LoadedRecording load_recording(const std::string& path, const RecordingOptions& o);

/// {"method", "rate_hz", "rows_in", ...} (workflow/steps.hpp)
using workflow::resampling_json;
/// "i" | "tau_m" | "tau_j" and a description, for the stdout line.
std::string torque_description(io::TorqueKind kind);

/// The recording's file name in front of an std::invalid_argument (workflow/steps.hpp).
using workflow::about_recording;

/// SHA-256 (hex) of a file's bytes; throws naming the file when it cannot be read.
std::string file_sha256(const std::string& path);

/// What makes a result what it is: the tool's version, every option given on `cmd`'s command
/// line (except those named in `skip`: where the output goes, how the work is split), and the
/// SHA-256 of every option value that names a file. Parts of one result must agree on it.
nlohmann::json command_identity(const CLI::App& cmd, const std::vector<std::string>& skip);

/// The identity every JSON the tool writes carries (issue 29 item 2), one function for all:
/// main.cpp registers the command being run once its command line is read.
void set_running_command(const CLI::App& cmd);
/// command_identity of the running command without what does not change a figure: where the
/// outputs go (--json, --out, --model-out, --trace) and how the work is split (--jobs,
/// --shard). No time stamps and no paths but those given: the same command on the same
/// files gives the same bytes. An empty object when no command was registered.
nlohmann::json result_identity();

/// One console line for a JSON file this tool wrote that a command reads (`what`: "friction",
/// "threshold", "part", "recording side file", ...), e.g.
///   friction: out/f.json (jointguard 0.2.0 identify, sha256 ab12cd34ef56)
/// and a warning on stderr when the version that wrote it is not this one. Says nothing for a
/// file that is not JSON (its reader names the problem).
void report_input_identity(const std::string& what, const std::string& path);

/// Writes JSON to a temporary file renamed into place; throws when it cannot (a missing
/// folder, a full disk): success is only reported for a complete file. An object without
/// "identity" gets result_identity().
void write_json_file(const std::string& path, const nlohmann::json& j);

}  // namespace jg::cli
