// jointguard pipeline: identify, calibrate, replay and report on a user's recordings in one
// command. Parses, calls workflow::run_pipeline (workflow/pipeline_run.hpp), prints.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/progress.hpp"
#include "workflow/pipeline_run.hpp"

namespace jg::cli {
namespace {
/// --out: a folder (created when missing) where output_file's checks hold for a file in it:
/// the nearest existing folder writable, no file in the way. Checked when the command line is
/// read (exit 2, the option named).
CLI::Validator output_folder() {
  const CLI::Validator file_in_it = output_file(true);
  return CLI::Validator(
      [file_in_it](std::string& path) {
        std::error_code ec;
        if (path.empty()) return std::string("an empty path");
        if (std::filesystem::exists(path, ec) && !std::filesystem::is_directory(path, ec)) return "'" + path + "' is a file, not a folder";
        std::string summary = (std::filesystem::path(path) / "pipeline.json").string();
        return file_in_it(summary);
      },
      "DIR (created when missing)");
}

struct PipelineCli {
  workflow::PipelineOptions run;
  RecordingOptions input;
  ObserverOptions observer;
};
}  // namespace

Command add_pipeline(CLI::App& app) {
  auto o = std::make_shared<PipelineCli>();
  auto& r = o->run;
  auto* cmd = app.add_subcommand(
      "pipeline",
      "The whole workflow on one arm's recordings: identify the friction (--identify), calibrate the thresholds\n"
      "(--calibrate; default: the identification recording, with a warning), replay each RECORDING through the\n"
      "firmware core, and report. Writes into --out the files identify, calibrate and replay write (friction.json,\n"
      "threshold.json, replay_<name>.json: rerun any step by hand from them), report.html and pipeline.json (the\n"
      "summary with the command's identity). Defaults as the separate commands' (holding-aware detection on).\n"
      "Nothing is written unless every step succeeds.\n"
      "Example: jointguard pipeline --model arm.urdf --drive drive.yaml --identify excitation.csv --calibrate free.csv "
      "pushes.csv --out out/arm");
  cmd->add_option("recordings", r.recordings, "Recordings to replay (CSV)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", r.model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  add_model_selection(cmd, r.model_options);
  cmd->add_option("--identify", r.identify, "Collision-free excitation recording the friction is identified on (CSV)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--calibrate", r.calibrate,
                  "Collision-free recording the thresholds are calibrated on (CSV; default: the --identify recording, "
                  "with a warning: thresholds calibrated on the motion the friction was fitted to may be optimistic)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", r.out_dir, "Folder for the outputs")->required()->check(output_folder());
  cmd->add_option("--scalar", r.replay.scalar, "Firmware scalar of the replays")->check(CLI::IsMember({"float", "q"}))->capture_default_str();
  o->input.add_to(cmd, "Rate [Hz] for every step: the friction is bounded to what the firmware holds there and each "
                       "recording is resampled to it by time stamp (default: each recording's own median step, rounded)");
  o->observer.add_to(cmd);
  cmd->add_option("--identify-gain", r.ident.gain, "identify's first-order observer gain K [1/s] (identify --gain)")
      ->capture_default_str()
      ->check(finite_range(1.0, 10000.0));
  cmd->add_option("--seed", r.ident.seed, "identify's GA seed")->capture_default_str();
  cmd->add_option("--runs", r.ident.runs, "identify's GA runs (result = mean)")->capture_default_str()->check(CLI::Range(1, 100));
  cmd->add_option("--margin", r.margin, "calibrate's safety margin added to the band [N·m]")
      ->capture_default_str()
      ->check(finite_range(0.0, 1000.0));
  cmd->add_option("--debounce", r.replay.debounce, "replay's cycles over threshold before a detection")
      ->capture_default_str()
      ->check(CLI::Range(1, 50));
  return {cmd, [o, cmd]() {
            auto& run = o->run;
            run.read = o->input.read_options();
            run.regularize = o->input.regularize_options();
            const ObserverOptions observer = o->observer;
            run.gains = [observer](double rate_hz) { return observer.to_gains(rate_hz); };
            run.identity = command_identity(*cmd, {"--out"});
            run.log = [](const std::string& line) { std::printf("%s\n", line.c_str()); };
            Progress bar("identify");
            run.progress = [&bar](double f) { bar.update(f); };
            const auto res = workflow::run_pipeline(run);
            bar.finish();
            std::printf("\njoint  threshold (moving)  + at standstill  holding change [N·m]\n");
            const auto& t = res.thresholds;
            for (std::size_t k = 0; k < res.joint_ids.size(); ++k) {
              char hold[24] = "-";
              if (k < t.hold_change.size()) std::snprintf(hold, sizeof hold, "%.3f", t.hold_change[k]);
              std::printf("%5d  %10.3f          %+8.3f        %s\n", res.joint_ids[k], t.threshold[k], t.low_speed_extra[k], hold);
            }
            for (const auto& rp : res.replays) {
              std::printf("%s (%s): %zu detection(s)\n", rp.recording.c_str(), rp.file.c_str(), rp.outcome.result.events.size());
              for (const auto& n : rp.outcome.notes) std::printf("  %s\n", n.c_str());
              for (const auto& e : rp.outcome.result.events) {
                std::printf("  %s\n", workflow::describe_event(e, rp.outcome.joint_ids).c_str());
              }
            }
            for (const auto& w : res.warnings) std::printf("%s\n", w.c_str());
            std::printf("wrote");
            for (const auto& f : res.files) std::printf(" %s", (std::filesystem::path(run.out_dir) / f).c_str());
            std::printf("\n");
            return 0;
          }};
}

}  // namespace jg::cli
