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
#include "eval/firmware_estimator.hpp"
#include "eval/pipeline.hpp"
#include "report/contact_report.hpp"
#include "io/atomic_write.hpp"

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

/// --holding and its companions (calibrate, replay): how the drive's holding is known.
struct HoldingCliOptions {
  std::string holding = "auto";
  eval::ReplayOptions replay;
  double settle = 0.15, reference = 0.016, floor = 0.0;
  void add_to(CLI::App* cmd, bool for_replay) {
    cmd->add_option("--holding", holding,
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
  [[nodiscard]] eval::ReplayOptions options() const {
    eval::ReplayOptions o = replay;
    o.holding = holding == "always"                         ? eval::HoldingSource::always
                : holding == "still" || holding == "auto" ? eval::HoldingSource::still
                                                          : eval::HoldingSource::none;
    return o;
  }
  /// --holding always: the arm must not move; refused naming the file, time and joint.
  void check_held(const std::string& path, const std::vector<io::Recording>& segments, const std::vector<int>& ids) const {
    if (holding != "always") return;
    for (const auto& rec : segments) {
      if (const auto m = eval::first_move(rec, replay)) {
        throw std::invalid_argument(path + ": --holding always, but the arm moves: joint " + std::to_string(ids[m->joint]) +
                                    " is " + std::to_string(m->distance) + " rad from its first position at t = " +
                                    std::to_string(m->t) + " s (|dq| " + std::to_string(m->speed) +
                                    " rad/s there; a held arm stays within --hold-radius " + std::to_string(replay.hold_radius) +
                                    " rad). Use --holding auto (derived from the recording) for a moving arm");
      }
    }
  }
};

/// The "resampling" and "torque" fields every workflow JSON carries.
nlohmann::json input_json(const LoadedRecording& in) {
  return {{"resampling", resampling_json(in.data.report)}, {"torque", io::to_string(in.torque)}};
}
}  // namespace

/// Warnings where the replay left the calibration's region, into stdout and the JSON.
void report_region(const eval::ReplayResult& r, const eval::Thresholds& t, const std::vector<int>& ids, nlohmann::json& j) {
  if (t.q_min.size() != ids.size()) {
    std::printf("note: the threshold file states no calibrated region (calibrate again to get one)\n");
    return;
  }
  j["outside_region"] = nlohmann::json::array();
  for (std::size_t k = 0; k < ids.size(); ++k) {
    j["outside_region"].push_back({{"joint", ids[k]}, {"position_samples", r.outside_q[k]}, {"velocity_samples", r.outside_dq[k]},
                                   {"stop_widened_samples", r.stop_widened[k]}});
    if (r.outside_q[k] + r.outside_dq[k] == 0) continue;
    std::printf("warning: joint %d outside the calibrated region in %zu samples (position) and %zu (velocity): the band there "
                "was not calibrated; calibrate on a motion that covers it\n",
                ids[k], r.outside_q[k], r.outside_dq[k]);
  }
  if (r.gated_samples > 0) std::printf("stop gate: detector gated in %zu samples\n", r.gated_samples);
  j["stop_gated_samples"] = r.gated_samples;
  std::size_t widened = 0;
  for (const auto w : r.stop_widened) widened += w;
  if (widened > 0) {
    std::printf("stop allowance: band widened for accelerations beyond the calibration's in");
    for (std::size_t k = 0; k < ids.size(); ++k) std::printf(" %zu", r.stop_widened[k]);
    std::printf(" samples (joints in order)\n");
  }
}

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
            ident::GaSettings ga;
            ga.seed = o->seed;
            ga.runs = o->runs;
            // The file must run where the user runs it: calibrate, replay and the drive at this rate.
            ga.firmware.enabled = true;
            ga.firmware.dt = 1.0 / in.data.report.rate_hz;
            Progress bar("identify");
            const auto r = about_recording(o->recording, [&] {
              const ObserverGains gains{ObserverKind::first_order, o->observer.gains[0], 0, 0,
                                        o->observer.align_motor_torque};
              return eval::identify_recording(rec, model, gains, ga, [&](double f) { bar.update(f); });
            });
            bar.finish();
            std::printf("joint  sigma0      sigma1    sigma2   tau_c    tau_s    w_s      rms [N·m]\n");
            for (std::size_t j = 0; j < r.size(); ++j) {
              const auto& p = r[j].params;
              std::printf("%5d  %9.1f  %8.2f  %7.4f  %7.4f  %7.4f  %7.5f  %.4f\n", rec.joint_ids[j], p.sigma0, p.sigma1, p.sigma2,
                          p.tau_c, p.tau_s, p.w_s, r[j].rms);
              for (const auto& w : r[j].warnings) std::printf("       warning: %s\n", w.c_str());
              for (const auto& b : r[j].bounded) std::printf("       note: %s\n", b.reason.c_str());
            }
            if (!o->json.empty()) {
              auto extra = input_json(in);
              extra["segment_used"] = {{"t_begin", rec.t.front()}, {"t_end", rec.t.back()}};
              extra["firmware_rate_hz"] = in.data.report.rate_hz;  // the parameters fit both scalars at this rate
              eval::write_friction_json(o->json, r, rec.joint_ids, extra);
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
            const auto gains = o->observer.to_gains(in.data.report.rate_hz);
            constexpr double kSettleS = 0.5;  // calibrate_segments' default: the observer settling
            const auto t = about_recording(o->recording, [&] {
              auto segments = in.data.segments;
              if (!window->empty()) {
                const double t0 = segments.front().t.front();
                segments = eval::time_window(segments, t0 + (*window)[0], t0 + (*window)[1]);
                std::printf("calibrating on t = %.3f .. %.3f s (--time-window)\n", segments.front().t.front(), segments.back().t.back());
              }
              hold->check_held(o->recording, segments, rec.joint_ids);
              auto th = eval::calibrate_segments(segments, model, friction, gains, o->margin, kSettleS);
              eval::cover_region(th, segments, model, friction, gains, kSettleS);
              if (hold->holding != "none") {
                th.hold_settle_s = hold->settle;
                th.hold_reference_s = hold->reference;
                eval::calibrate_holds(th, segments, model, friction, gains, hold->options(), kSettleS, hold->holding != "auto");
                // A held joint may hold any friction up to its static level: a calibration on a
                // few holds (or none) saw only the levels they happened to keep. The band's
                // standstill allowance covers the whole range (a joint settling at rest after a
                // move never crosses it); small changes are the holding detector's job.
                for (std::size_t j = 0; j < th.low_speed_extra.size(); ++j) {
                  th.low_speed_extra[j] = std::max(th.low_speed_extra[j], eval::friction_level(friction[j]));
                  th.hold_change[j] = std::max(th.hold_change[j], hold->floor * friction[j].tau_s);
                }
              }
              return th;
            });
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
              eval::write_threshold_json(o->json, t, rec.joint_ids, input_json(in));
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
            const auto friction = eval::read_friction_json(o->friction, ids);
            const auto thresholds = eval::read_threshold_json(o->threshold, ids);
            eval::check_friction_fits(o->friction, friction, ids, 1.0 / in.data.report.rate_hz, o->scalar);
            // The holding detector needs its change thresholds from the threshold file.
            if (thresholds.hold_change.size() != ids.size()) {
              if (hold->holding == "always" || hold->holding == "still") {
                throw std::invalid_argument(o->threshold + ": --holding " + hold->holding +
                                            " needs the holding detector's change thresholds (hold_change_threshold), "
                                            "which this threshold file lacks: calibrate again (it writes them by default)");
              }
              if (hold->holding == "auto") {
                std::printf("note: %s has no holding detector thresholds (hold_change_threshold): the band alone; "
                            "calibrate again to get them\n",
                            o->threshold.c_str());
                hold->holding = "none";
              }
            }
            hold->check_held(o->recording, in.data.segments, ids);
            // Each segment runs from a fresh state; events keep the recording's time stamps.
            const auto r = about_recording(o->recording, [&] {
              return eval::replay_segments(in.data.segments, model, friction, thresholds, o->observer.to_gains(in.data.report.rate_hz),
                                           o->scalar, o->debounce, hold->options());
            });
            nlohmann::json j = input_json(in);
            report_region(r, thresholds, ids, j);
            if (hold->holding != "none") {
              std::printf("holding (%s): %zu of %zu samples held; holding detector re-armed %zu time(s)\n", hold->holding.c_str(),
                          r.held_samples, r.t.size(), r.rearms);
              j["holding"] = {{"source", hold->holding}, {"held_samples", r.held_samples}, {"rearms", r.rearms}};
            }
            std::printf("%zu detection(s)\n", r.events.size());
            j["events"] = nlohmann::json::array();
            for (const auto& e : r.events) {
              std::printf("  t = %.4f s: link %d (joints over threshold:", e.t, e.link);
              for (const int k : e.joints_over) std::printf(" %d", k);
              std::printf(")%s\n", e.by_hold ? " by the holding detector" : "");
              nlohmann::json event = {{"t", e.t}, {"link", e.link}, {"joints_over", e.joints_over}, {"by_hold", e.by_hold}};
              if (e.contact && e.contact->link >= 1) {
                const auto& c = *e.contact;
                const int link_id = ids[static_cast<std::size_t>(c.link - 1)];
                std::printf("    contact (at %.4f s): link %d, %.3f +- %.3f m along it, force %.1f +- %.1f N (%d of 3 components "
                            "determined), peak %.1f N at %.4f s\n",
                            e.contact_t, link_id, c.along_m, c.along_sigma_m, c.force_n, c.force_sigma_n, c.determined_components,
                            e.contact_peak_force_n, e.contact_t_peak);
                event["contact"] = {{"t", e.contact_t},
                                    {"link", link_id},
                                    {"along_m", c.along_m},
                                    {"along_sigma_m", c.along_sigma_m},
                                    {"point_base_m", {c.point_base.x(), c.point_base.y(), c.point_base.z()}},
                                    {"force_n", c.force_n},
                                    {"force_sigma_n", c.force_sigma_n},
                                    {"force_base_n", {c.force_base.x(), c.force_base.y(), c.force_base.z()}},
                                    {"determined_components", c.determined_components},
                                    {"peak_force_n", e.contact_peak_force_n},
                                    {"t_peak", e.contact_t_peak},
                                    {"along_interval_m", {c.along_lo_m, c.along_hi_m}},
                                    {"force_interval_n", {c.force_lo_n, c.force_hi_n}},
                                    {"force_determined", c.force_determined},
                                    {"line_direction_base", {c.line_direction_base.x(), c.line_direction_base.y(), c.line_direction_base.z()}}};
                // What the torques allow: a value where they determine the force, else the set.
                std::printf("    %s\n", report::describe_contact(c, link_id).c_str());
              }
              j["events"].push_back(event);
            }
            if (!trace->empty()) {
              std::string text = "t";
              for (const int id : ids) text += ",mu" + std::to_string(id);
              text += "\n";
              char buf[32];
              for (std::size_t k = 0; k < r.t.size(); ++k) {
                std::snprintf(buf, sizeof buf, "%.4f", r.t[k]);
                text += buf;
                for (const auto& m : r.mu) {
                  std::snprintf(buf, sizeof buf, ",%.4f", m[k]);
                  text += buf;
                }
                text += "\n";
              }
              io::write_text_atomic(*trace, text);
              std::printf("wrote %s\n", trace->c_str());
            }
            j["external_torque_max"] = r.external_torque_max;
            j["scalar"] = o->scalar;
            if (!o->json.empty()) {
              write_json_file(o->json, j);
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

}  // namespace jg::cli
