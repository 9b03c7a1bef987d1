// The workflow's steps on recordings as library functions: read a recording, identify the
// friction, calibrate the thresholds, replay through the firmware core. Each takes what the
// command line gave and returns a result struct with the JSON the step writes; the commands
// (cli/workflow.cpp: identify, calibrate, replay; cli/pipeline.cpp: all of them in one go,
// workflow/pipeline_run.hpp) parse, call these, and print.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/pipeline.hpp"
#include "identification/identify.hpp"
#include "io/loaded_recording.hpp"
#include "io/recording.hpp"
#include "io/regularize.hpp"
#include "jointguard/observer/momentum_observer.hpp"
#include "robot/robot_model.hpp"

namespace jg::workflow {

/// A recording read and regularized by time stamp (io/loaded_recording.hpp).
using io::LoadedRecording;
/// Reads and regularizes; prints nothing (the resampling line: data.report.summary()).
LoadedRecording load_recording(const std::string& path, const io::ReadOptions& read, const io::RegularizeOptions& regularize);

/// {"method", "rate_hz", "rows_in", "rows_out", "repeats_dropped", ..., "segments": [...]}
nlohmann::json resampling_json(const io::RegularizeReport& r);
/// The "resampling" and "torque" fields every workflow JSON carries.
nlohmann::json input_json(const LoadedRecording& in);

/// The recording's file name in front of an std::invalid_argument (io/loaded_recording.hpp).
using io::about_recording;

// ---- identify ------------------------------------------------------------------------
struct IdentifySettings {
  double gain = 60.0;  ///< first-order observer gain K [1/s] the friction is seen through
  bool align_motor_torque = kAlignMotorTorqueDefault;
  unsigned long long seed = 1;
  int runs = 10;
};
struct IdentifyResult {
  std::vector<ident::IdentificationResult> joints;
  std::vector<int> joint_ids;
  double t_begin = 0.0, t_end = 0.0;  ///< the segment fitted (the longest)
  std::size_t segments = 1;           ///< in the recording
  nlohmann::json json;                ///< the friction file's top-level fields besides "joints"
};
/// LuGre per joint on the recording's longest segment, bounded to what the firmware scalar
/// holds at the recording's (resampled) rate.
IdentifyResult identify_friction(const LoadedRecording& in, const robot::RobotModel& model, const IdentifySettings& s,
                                 const std::function<void(double)>& progress = {});
/// Writes the friction file (contract format; atomic).
void write_friction(const std::string& path, const IdentifyResult& r);

// ---- holding (calibrate, replay) -------------------------------------------------------
/// How the drive's holding is known: "auto" (the default), "still", "always" or "none", and
/// the holding detector's windows for calibrate.
struct Holding {
  std::string mode = "auto";
  eval::ReplayOptions replay;
  double settle = 0.15, reference = 0.016, floor = 0.0;
  [[nodiscard]] eval::ReplayOptions options() const;
  /// mode "always": the arm must not move; refused naming the file, time and joint.
  void check_held(const std::string& path, const std::vector<io::Recording>& segments, const std::vector<int>& ids) const;
};

// ---- calibrate -----------------------------------------------------------------------
/// The calibration's observer settling, skipped at each segment's start [s].
inline constexpr double kCalibrationSettleS = 0.5;
/// Thresholds from collision-free segments: the band, the calibrated region, and (mode other
/// than "none") the holding detector's change thresholds, its standstill allowance at least
/// each joint's friction level.
eval::Thresholds calibrate_thresholds(const std::string& path, const std::vector<io::Recording>& segments,
                                      const robot::RobotModel& model, const std::vector<LuGreParams<double>>& friction,
                                      const ObserverGains& gains, double margin, const Holding& holding);

// ---- replay --------------------------------------------------------------------------
struct ReplaySettings {
  std::string scalar = "float";
  int debounce = 1;
  Holding holding;
};
struct ReplayOutcome {
  eval::ReplayResult result;
  std::vector<int> joint_ids;
  std::string holding;              ///< the mode run ("none" when the file lacks change thresholds at "auto")
  std::vector<std::string> notes;   ///< what the user should know, one line each ("note: ...", "warning: ...")
  nlohmann::json json;              ///< the replay file (contract format), without "events"' order changed
};
/// Replays the recording's segments with the friction and threshold files (refused before
/// any run when the friction does not fit the scalar at the recording's rate, or the
/// holding mode needs change thresholds the file lacks: naming that file).
ReplayOutcome replay_files(const LoadedRecording& in, const robot::RobotModel& model, const std::string& friction_path,
                           const std::string& threshold_path, const ObserverGains& gains, const ReplaySettings& s);
/// One event as the console states it (several lines, no trailing newline).
std::string describe_event(const eval::ReplayEvent& e, const std::vector<int>& ids);
/// The estimate per sample as CSV: t, mu<j>.
std::string trace_csv(const eval::ReplayResult& r, const std::vector<int>& ids);

}  // namespace jg::workflow
