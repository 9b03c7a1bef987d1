#include "workflow/pipeline_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <system_error>

#include "eval/pipeline.hpp"
#include "io/atomic_write.hpp"
#include "workflow/pipeline_report.hpp"

namespace jg::workflow {
namespace fs = std::filesystem;

namespace {
/// The partial folder inside out_dir: removed (with out_dir when this run created it) unless
/// commit() moved its files into place.
class Staging {
 public:
  explicit Staging(const std::string& out_dir) : out_(out_dir) {
    std::error_code ec;
    if (fs::exists(out_, ec) && !fs::is_directory(out_, ec)) {
      throw std::invalid_argument("--out " + out_dir + ": is a file, not a folder");
    }
    created_ = !fs::exists(out_, ec);
    fs::create_directories(out_, ec);
    if (ec) throw std::invalid_argument("--out " + out_dir + ": cannot create the folder: " + ec.message());
    dir_ = out_ / (".pipeline.partial." + std::to_string(::getpid()));
    fs::remove_all(dir_, ec);
    if (!fs::create_directory(dir_, ec)) {
      throw std::invalid_argument("--out " + out_dir + ": cannot write into the folder: " + (ec ? ec.message() : "exists"));
    }
  }
  Staging(const Staging&) = delete;
  Staging& operator=(const Staging&) = delete;
  ~Staging() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
    if (!committed_ && created_) fs::remove(out_, ec);  // only when empty
  }
  [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }
  /// Moves every file into out_dir (each rename atomic); the summary last, so its presence
  /// says the run completed.
  void commit(const std::vector<std::string>& names) {
    for (const auto& n : names) fs::rename(dir_ / n, out_ / n);
    committed_ = true;
  }

 private:
  fs::path out_, dir_;
  bool created_ = false, committed_ = false;
};

void say(const PipelineOptions& o, const std::string& line) {
  if (o.log) o.log(line);
}

/// Every recording is read before any work: a bad file is named before minutes of
/// identification, and each is read once.
const LoadedRecording& loaded(std::map<std::string, LoadedRecording>& cache, const PipelineOptions& o, const std::string& path) {
  auto it = cache.find(path);
  if (it == cache.end()) {
    it = cache.emplace(path, load_recording(path, o.read, o.regularize)).first;
    say(o, it->second.data.report.summary());
  }
  return it->second;
}

nlohmann::json summary_json(const PipelineOptions& o, const PipelineResult& r) {
  nlohmann::json j;
  j["identity"] = o.identity;
  j["model"] = o.model;
  j["identification"] = {{"recording", o.identify},
                         {"file", "friction.json"},
                         {"firmware_rate_hz", r.friction.json.value("firmware_rate_hz", 0.0)},
                         {"segment_used", {{"t_begin", r.friction.t_begin}, {"t_end", r.friction.t_end}}}};
  auto& bounded = j["identification"]["bounded"] = nlohmann::json::array();
  for (std::size_t k = 0; k < r.friction.joints.size(); ++k) {
    for (const auto& b : r.friction.joints[k].bounded) {
      bounded.push_back({{"joint", r.joint_ids[k]}, {"parameter", b.parameter}, {"fitted", b.fitted}, {"written", b.written}});
    }
  }
  j["calibration"] = {{"recording", r.calibration_recording},
                      {"source", r.calibrated_on_identification ? "the identification recording (no --calibrate)" : "--calibrate"},
                      {"file", "threshold.json"}};
  j["warnings"] = r.warnings;
  j["thresholds"] = nlohmann::json::array();
  const auto& t = r.thresholds;
  for (std::size_t k = 0; k < r.joint_ids.size(); ++k) {
    nlohmann::json e{{"joint", r.joint_ids[k]}, {"threshold", t.threshold[k]}, {"low_speed_extra", t.low_speed_extra[k]}};
    if (k < t.hold_change.size()) e["hold_change_threshold"] = t.hold_change[k];
    if (k < t.hold_source.size()) e["hold_change_source"] = t.hold_source[k];
    j["thresholds"].push_back(e);
  }
  j["replays"] = nlohmann::json::array();
  std::size_t events = 0;
  for (const auto& rp : r.replays) {
    const auto& out = rp.outcome;
    nlohmann::json e{{"recording", rp.recording},   {"file", rp.file},
                     {"scalar", o.replay.scalar},   {"holding", out.holding},
                     {"events", out.json["events"]}, {"notes", out.notes}};
    events += out.result.events.size();
    j["replays"].push_back(e);
  }
  j["summary"] = {{"recordings", r.replays.size()}, {"events", events}};
  j["files"] = r.files;
  return j;
}
}  // namespace

std::string calibration_warning(const std::string& identification_recording) {
  return "warning: no --calibrate recording: the thresholds are calibrated on the identification recording " +
         identification_recording +
         " (collision-free by design). They may be optimistic: the friction was fitted to this very motion, and they cover "
         "only its speeds and postures. Record a collision-free motion like the task and pass it as --calibrate";
}

std::string replay_file_name(const std::string& recording, const std::vector<std::string>& taken) {
  const std::string stem = fs::path(recording).stem().string();
  std::string name = "replay_" + stem + ".json";
  for (int n = 2; std::find(taken.begin(), taken.end(), name) != taken.end(); ++n) {
    name = "replay_" + stem + "_" + std::to_string(n) + ".json";
  }
  return name;
}

PipelineResult run_pipeline(const PipelineOptions& o) {
  if (!o.gains) throw std::invalid_argument("run_pipeline: no observer gains given");
  if (o.recordings.empty()) throw std::invalid_argument("no recording to replay");
  const auto model = robot::load_robot(o.model, o.model_options);
  PipelineResult r;
  // Read everything first: a bad file stops the run before any work.
  std::map<std::string, LoadedRecording> cache;
  const auto& ident = loaded(cache, o, o.identify);
  r.calibrated_on_identification = o.calibrate.empty();
  r.calibration_recording = r.calibrated_on_identification ? o.identify : o.calibrate;
  const auto& calib = loaded(cache, o, r.calibration_recording);
  for (const auto& p : o.recordings) loaded(cache, o, p);
  r.joint_ids = ident.longest().joint_ids;
  for (const auto& [path, rec] : cache) {
    if (rec.data.segments.front().joint_ids != r.joint_ids) {
      throw std::invalid_argument(path + ": its joints differ from the identification recording " + o.identify +
                                  "'s: one arm's recordings, with the same q<j> columns, are needed");
    }
  }
  if (r.calibrated_on_identification) {
    r.warnings.push_back(calibration_warning(o.identify));
    say(o, r.warnings.back());
  }
  Staging stage(o.out_dir);

  // 1. identify
  say(o, "identify: " + o.identify + (ident.data.segments.size() > 1 ? " (its longest segment)" : ""));
  r.friction = identify_friction(ident, model, o.ident, o.progress);
  r.friction.json["identity"] = o.identity;  // each file says what made it (here: this pipeline command)
  const std::string friction_file = stage.path("friction.json");
  write_friction(friction_file, r.friction);
  r.files.emplace_back("friction.json");
  for (std::size_t k = 0; k < r.friction.joints.size(); ++k) {
    for (const auto& b : r.friction.joints[k].bounded) say(o, "  joint " + std::to_string(r.joint_ids[k]) + ": " + b.reason);
  }

  // 2. calibrate (from the file identify wrote, as `jointguard calibrate` reads it)
  say(o, "calibrate: " + r.calibration_recording);
  const auto friction = eval::read_friction_json(friction_file, r.joint_ids);
  r.thresholds = calibrate_thresholds(calib.path, calib.data.segments, model, friction, o.gains(calib.data.report.rate_hz),
                                      o.margin, o.replay.holding);
  const std::string threshold_file = stage.path("threshold.json");
  auto threshold_extra = input_json(calib);
  threshold_extra["identity"] = o.identity;
  eval::write_threshold_json(threshold_file, r.thresholds, r.joint_ids, threshold_extra);
  r.files.emplace_back("threshold.json");

  // 3. replay each recording
  for (const auto& p : o.recordings) {
    const auto& in = cache.at(p);
    ReplayedRecording rp;
    rp.recording = p;
    rp.file = replay_file_name(p, r.files);
    say(o, "replay: " + p + " -> " + rp.file);
    rp.outcome = replay_files(in, model, friction_file, threshold_file, o.gains(in.data.report.rate_hz), o.replay);
    rp.outcome.json["identity"] = o.identity;
    io::write_json_atomic(stage.path(rp.file), rp.outcome.json);
    r.files.push_back(rp.file);
    r.replays.push_back(std::move(rp));
  }

  // 4. report and summary
  r.files.emplace_back("report.html");
  r.files.emplace_back("pipeline.json");
  io::write_text_atomic(stage.path("report.html"), pipeline_report_html(o, r));
  r.summary = summary_json(o, r);
  io::write_json_atomic(stage.path("pipeline.json"), r.summary);
  stage.commit(r.files);
  return r;
}

}  // namespace jg::workflow
