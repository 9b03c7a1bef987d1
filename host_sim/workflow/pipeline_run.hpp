// The whole workflow on a user's recordings in one call (jointguard pipeline): identify the
// friction, calibrate the thresholds, replay each recording through the firmware core, and
// report. Writes into one folder the files the separate commands write (friction.json,
// threshold.json, replay_<name>.json: any step can be rerun by hand from them), plus
// report.html and pipeline.json (the summary with the command's identity). Everything is
// written to a partial folder inside it first and moved into place once every step has
// succeeded: a failed run leaves the folder as it was.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "robot/robot_model.hpp"
#include "workflow/steps.hpp"

namespace jg::workflow {

struct PipelineOptions {
  std::string model;                   ///< robot file (YAML or URDF)
  robot::LoadOptions model_options;    ///< --base, --tip, --drive
  std::string identify;                ///< the excitation recording friction is identified on
  /// The collision-free recording the thresholds are calibrated on; empty: the identification
  /// recording (it is collision-free too), with a warning (calibration_warning()).
  std::string calibrate;
  std::vector<std::string> recordings;  ///< replayed, each into replay_<name>.json
  std::string out_dir;                  ///< created when missing
  io::ReadOptions read;                 ///< every recording: torque kind
  io::RegularizeOptions regularize;     ///< every recording: --rate, --max-gap
  IdentifySettings ident;
  /// The observer calibrate and replay run at a recording's rate [Hz] (the CLI's --observer,
  /// --gains; required).
  std::function<ObserverGains(double rate_hz)> gains;
  double margin = 0.5;
  ReplaySettings replay;  ///< scalar, debounce, holding (calibrate uses the same holding)
  nlohmann::json identity = nlohmann::json::object();  ///< the command's identity, into pipeline.json
  std::function<void(const std::string&)> log;         ///< one line per message (may be empty)
  std::function<void(double)> progress;                ///< identification's progress 0..1 (may be empty)
};

struct ReplayedRecording {
  std::string recording;  ///< as given
  std::string file;       ///< the replay JSON's name in out_dir
  ReplayOutcome outcome;
};

struct PipelineResult {
  IdentifyResult friction;
  eval::Thresholds thresholds;
  std::vector<int> joint_ids;
  std::string calibration_recording;
  bool calibrated_on_identification = false;
  std::vector<std::string> warnings;
  std::vector<ReplayedRecording> replays;
  /// Files written into out_dir (names), in the order written.
  std::vector<std::string> files;
  nlohmann::json summary;  ///< pipeline.json
};

/// The warning printed (and stored) when no calibration recording is given.
std::string calibration_warning(const std::string& identification_recording);

/// Runs the pipeline; throws (std::invalid_argument, io::FormatError, ...) naming the file or
/// option at fault, leaving out_dir without any of this run's files.
PipelineResult run_pipeline(const PipelineOptions& o);

/// The file name a recording's replay JSON gets: replay_<stem>.json, made unique among `taken`.
std::string replay_file_name(const std::string& recording, const std::vector<std::string>& taken);

}  // namespace jg::workflow
