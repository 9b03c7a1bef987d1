// identify, calibrate, replay: the workflow on recordings.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/identify_rigid.hpp"
#include "cli/progress.hpp"
#include "eval/calibration_region.hpp"
#include "io/atomic_write.hpp"
#include "workflow/steps.hpp"

namespace jg::cli {
namespace {
struct WorkflowOptions {
  std::string recording, model, json, friction, threshold, scalar = "float";
  double margin = 0.5;
  int debounce = 1, runs = 10;
  unsigned long long seed = 1;
  ObserverOptions observer;
  robot::LoadOptions model_options;
  RecordingOptions input;
};

/// --holding and its companions (calibrate, replay): how the drive's holding is known
/// (workflow::Holding), as options.
struct HoldingCliOptions : workflow::Holding {
  void add_to(CLI::App* cmd, bool for_replay) {
    cmd->add_option("--holding", mode,
                    for_replay ? "When the drive holds a setpoint (holding-aware change detection): auto (still when the "
                                 "threshold file has the holding detector's thresholds, calibrate writes them; else the "
                                 "band alone); still (derived: at rest, then within --hold-radius of where it stopped); "
                                 "always (the arm is held the whole recording); none (the band alone)"
                               : "The holding detector's change thresholds: auto (from the recording's holds where they "
                                 "last long enough, else half the joint's friction level; no holds needed); still (from "
                                 "its holds only: refused without any); always (the arm is held the whole recording: "
                                 "refused when it moves); none (not written)")
        ->check(CLI::IsMember({"auto", "none", "always", "still"}))
        ->capture_default_str();
    cmd->add_option("--hold-radius", replay.hold_radius, "[rad] a held joint may yield this far and still be held (--holding still)")
        ->capture_default_str()
        ->check(finite_range(0.0, 1.0));
    if (for_replay) {
      cmd->add_option("--rearm", replay.rearm_s, "[s] after an event on a held arm, estimates steady this long: new reference")
          ->capture_default_str()
          ->check(finite_range(0.0, 60.0));
      cmd->add_flag("!--no-stop-allowance", replay.stop_allowance,
                    "Do not widen the band outside the calibrated region (speeds and accelerations, e.g. stops, beyond "
                    "the calibration's largest): the band alone");
      cmd->add_option("--stop-gate", replay.stop_gate_s,
                      "[s] gate the detector this long from an acceleration beyond the calibration's (a stop), "
                      "instead of widening the band; 0: widen")
          ->capture_default_str()
          ->check(finite_range(0.0, 5.0));
    } else {
      cmd->add_option("--hold-settle", settle, "[s] held time skipped before the holding detector's reference")
          ->capture_default_str()
          ->check(finite_range(0.0, 10.0));
      cmd->add_option("--hold-reference", reference, "[s] held time averaged into the reference")
          ->capture_default_str()
          ->check(finite_range(0.0, 10.0));
      cmd->add_option("--hold-floor", floor,
                      "Change threshold at least this fraction of the joint's static friction tau_s (the held "
                      "friction relaxes after a push by part of it)")
          ->capture_default_str()
          ->check(finite_range(0.0, 10.0));
    }
  }
};

/// The "resampling" and "torque" fields every workflow JSON carries.
nlohmann::json input_with_identity(const LoadedRecording& in) {
  // The identity of the result (cli/common.hpp) in every JSON identify, calibrate and replay write.
  nlohmann::json j = workflow::input_json(in);
  j["identity"] = result_identity();
  return j;
}
}  // namespace

Command add_identify(CLI::App& app) {
  auto o = std::make_shared<WorkflowOptions>();
  o->observer.gains = {60.0};
  auto* cmd = app.add_subcommand("identify",
                                 "Identify LuGre friction per joint from the observer's output on a collision-free\n"
                                 "excitation recording (paper's GA, 10 runs, then Levenberg-Marquardt).\n"
                                 "Example: jointguard identify out/excitation.csv --model models/ref3.yaml --json out/friction.json");
  cmd->add_option("recording", o->recording, "Recording (CSV)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--json", o->json, "Write the identified parameters here (contract format)")->check(output_file());
  cmd->add_option("--seed", o->seed, "GA seed")->capture_default_str();
  cmd->add_option("--runs", o->runs, "GA runs (result = mean)")->capture_default_str()->check(CLI::Range(1, 100));
  o->input.add_to(cmd, "The rate [Hz] the drive will run the friction model at: the recording is resampled to it by time "
                      "stamp and the parameters are bounded to what the firmware scalar holds there (default: the "
                      "recording's own median step, rounded)");
  cmd->add_option("--gain", o->observer.gains[0], "First-order observer gain K [1/s]")->capture_default_str();
  auto rigid = std::make_shared<RigidBodyCliOptions>();
  add_rigid_body_options(cmd, *rigid);
  return {cmd, [o, rigid]() {
            const auto model = robot::load_robot(o->model, o->model_options);
            const auto in = load_recording(o->recording, o->input);
            // Rigid-body identification and the GA both fit one continuous run: the longest
            // segment when gaps split the file.
            const auto& rec = in.longest();
            if (in.data.segments.size() > 1) {
              std::printf("identify: using the longest of %zu segments, t = %.3f .. %.3f s\n", in.data.segments.size(),
                          rec.t.front(), rec.t.back());
            }
            if (rigid->enabled) {
              return run_identify_rigid(rec, o->recording, resampling_json(in.data.report), model, o->model, o->json, *rigid);
            }
            workflow::IdentifySettings settings;
            settings.gain = o->observer.gains[0];
            settings.align_motor_torque = o->observer.align_motor_torque;
            settings.seed = o->seed;
            settings.runs = o->runs;
            Progress bar("identify");
            auto id = workflow::identify_friction(in, model, settings, [&](double f) { bar.update(f); });
            bar.finish();
            const auto& r = id.joints;
            std::printf("joint  sigma0      sigma1    sigma2   tau_c    tau_s    w_s      rms [N·m]\n");
            for (std::size_t j = 0; j < r.size(); ++j) {
              const auto& p = r[j].params;
              std::printf("%5d  %9.1f  %8.2f  %7.4f  %7.4f  %7.4f  %7.5f  %.4f\n", rec.joint_ids[j], p.sigma0, p.sigma1, p.sigma2,
                          p.tau_c, p.tau_s, p.w_s, r[j].rms);
              for (const auto& w : r[j].warnings) std::printf("       warning: %s\n", w.c_str());
              for (const auto& b : r[j].bounded) std::printf("       note: %s\n", b.reason.c_str());
            }
            if (!o->json.empty()) {
              id.json["identity"] = result_identity();
              workflow::write_friction(o->json, id);
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

Command add_calibrate(CLI::App& app) {
  auto o = std::make_shared<WorkflowOptions>();
  auto* cmd = app.add_subcommand("calibrate",
                                 "Thresholds from a collision-free recording: max |mu| + margin per joint, with and\n"
                                 "without friction compensation, plus a stiction allowance near standstill.\n"
                                 "Example: jointguard calibrate out/free.csv --model models/ref3.yaml --friction out/friction.json --json out/threshold.json");
  cmd->add_option("recording", o->recording, "Collision-free recording (CSV)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--friction", o->friction, "Friction JSON from identify")->required()->check(CLI::ExistingFile);
  cmd->add_option("--json", o->json, "Write the thresholds here (contract format)")->check(output_file());
  cmd->add_option("--margin", o->margin, "Safety margin added to the band [N·m]")->capture_default_str()->check(finite_range(0.0, 1000.0));
  o->input.add_to(cmd);
  o->observer.add_to(cmd);
  auto hold = std::make_shared<HoldingCliOptions>();
  hold->add_to(cmd, false);
  auto window = std::make_shared<std::vector<double>>();
  cmd->add_option("--time-window", *window, "FROM TO [s from the recording's first time stamp]: calibrate on this part only")
      ->expected(2)
      ->check(finite_range(-1e9, 1e9));
  return {cmd, [o, hold, window]() {
            if (!window->empty() && !((*window)[0] < (*window)[1])) {
              std::fprintf(stderr, "jointguard calibrate: error: --time-window %g %g: FROM must be before TO\n", (*window)[0], (*window)[1]);
              return 2;
            }
            const auto model = robot::load_robot(o->model, o->model_options);
            const auto in = load_recording(o->recording, o->input);
            const auto& rec = in.data.segments.front();
            const auto friction = eval::read_friction_json(o->friction, rec.joint_ids);
            report_input_identity("friction", o->friction);
            const auto gains = o->observer.to_gains(in.data.report.rate_hz);
            auto segments = in.data.segments;
            if (!window->empty()) {
              const double t0 = segments.front().t.front();
              segments = about_recording(o->recording, [&] { return eval::time_window(segments, t0 + (*window)[0], t0 + (*window)[1]); });
              std::printf("calibrating on t = %.3f .. %.3f s (--time-window)\n", segments.front().t.front(), segments.back().t.back());
            }
            const auto t = workflow::calibrate_thresholds(o->recording, segments, model, friction, gains, o->margin, *hold);
            std::printf("joint  band without / with compensation [N·m]  shrink  threshold (moving)  + at standstill\n");
            for (std::size_t j = 0; j < t.threshold.size(); ++j) {
              // The band without compensation over the band with it, as the JSON's shrink_factor;
              // no sample while moving (a held arm): no band, no ratio.
              char shrink[16] = "     -";
              if (t.band[j] > 0.0) std::snprintf(shrink, sizeof shrink, "%5.1fx", t.band_uncompensated[j] / t.band[j]);
              std::printf("%5d  %12.3f / %-12.3f              %s  %10.3f          %+.3f\n", rec.joint_ids[j], t.band_uncompensated[j],
                          t.band[j], shrink, t.threshold[j], t.low_speed_extra[j]);
            }
            std::printf("joint  region covered: q [rad]         |dq| max [rad/s]  |ddq| max [rad/s^2]  stop gain [N·m s^2/rad]%s\n",
                        t.hold_change.empty() ? "" : "  hold change [N·m] (largest seen, armed s)");
            for (std::size_t j = 0; j < t.threshold.size(); ++j) {
              std::printf("%5d  %8.3f .. %-8.3f        %8.3f          %9.3f            %8.3f", rec.joint_ids[j], t.q_min[j], t.q_max[j],
                          t.dq_max[j], t.ddq_max[j], t.stop_gain[j]);
              if (!t.hold_change.empty()) {
                std::printf("              %6.3f (%.3f, %.1f)%s", t.hold_change[j], t.hold_band[j], t.hold_seconds[j],
                            j < t.hold_source.size() && t.hold_source[j] == "friction" ? " from the friction level" : "");
              }
              std::printf("\n");
            }
            if (!o->json.empty()) {
              eval::write_threshold_json(o->json, t, rec.joint_ids, input_with_identity(in));
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

Command add_replay(CLI::App& app) {
  auto o = std::make_shared<WorkflowOptions>();
  auto* cmd = app.add_subcommand("replay",
                                 "Run a recording through the firmware core (float or Q16.16) and print detections.\n"
                                 "Example: jointguard replay out/shoulder.csv --model models/ref3.yaml --friction out/friction.json --threshold out/threshold.json --scalar q");
  cmd->add_option("recording", o->recording, "Recording (CSV)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--friction", o->friction, "Friction JSON from identify")->required()->check(CLI::ExistingFile);
  cmd->add_option("--threshold", o->threshold, "Threshold JSON from calibrate")->required()->check(CLI::ExistingFile);
  cmd->add_option("--scalar", o->scalar, "Firmware scalar")->check(CLI::IsMember({"float", "q"}))->capture_default_str();
  o->input.add_to(cmd, "Control/observer rate [Hz]: the recording is resampled to it by time stamp (default: its own median step, rounded)");
  cmd->add_option("--debounce", o->debounce, "Cycles over threshold before a detection")->capture_default_str()->check(CLI::Range(1, 50));
  cmd->add_option("--json", o->json, "Write the events here (contract format)")->check(output_file());
  o->observer.add_to(cmd);
  auto hold = std::make_shared<HoldingCliOptions>();
  hold->add_to(cmd, true);
  auto trace = std::make_shared<std::string>();
  cmd->add_option("--trace", *trace, "Write t and the estimate mu<j> per sample here (CSV, for plots)")->check(output_file());
  return {cmd, [o, hold, trace]() {
            const auto model = robot::load_robot(o->model, o->model_options);
            const auto in = load_recording(o->recording, o->input);
            const auto& ids = in.data.segments.front().joint_ids;
            report_input_identity("friction", o->friction);
            report_input_identity("threshold", o->threshold);
            const workflow::ReplaySettings settings{o->scalar, o->debounce, *hold};
            const auto out = workflow::replay_files(in, model, o->friction, o->threshold, o->observer.to_gains(in.data.report.rate_hz),
                                                    settings);
            const auto& r = out.result;
            for (const auto& n : out.notes) std::printf("%s\n", n.c_str());
            if (out.holding != "none") {
              std::printf("holding (%s): %zu of %zu samples held; holding detector re-armed %zu time(s)\n", out.holding.c_str(),
                          r.held_samples, r.t.size(), r.rearms);
            }
            std::printf("%zu detection(s)\n", r.events.size());
            for (const auto& e : r.events) std::printf("  %s\n", workflow::describe_event(e, ids).c_str());
            if (!trace->empty()) {
              io::write_text_atomic(*trace, workflow::trace_csv(r, ids));
              std::printf("wrote %s\n", trace->c_str());
            }
            nlohmann::json j = out.json;
            j["identity"] = result_identity();
            if (!o->json.empty()) {
              write_json_file(o->json, j);
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

}  // namespace jg::cli
