#include "workflow/steps.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "eval/calibration_region.hpp"
#include "eval/firmware_estimator.hpp"
#include "io/trace_csv.hpp"
#include "report/contact_report.hpp"

namespace jg::workflow {

LoadedRecording load_recording(const std::string& path, const io::ReadOptions& read, const io::RegularizeOptions& regularize) {
  LoadedRecording out;
  out.path = path;
  const io::Recording rec = io::read_recording(path, read);
  out.torque = rec.torque_kind;
  out.data = io::regularize(rec, regularize, std::filesystem::path(path).filename().string());
  return out;
}

nlohmann::json resampling_json(const io::RegularizeReport& r) {
  nlohmann::json j{{"source", r.source},
                   {"method", r.method},
                   {"rate_hz", r.rate_hz},
                   {"step_s", r.step_s},
                   {"rate_given", r.rate_given},
                   {"median_step_in_s", r.median_step_in_s},
                   {"min_step_in_s", r.min_step_in_s},
                   {"max_step_in_s", r.max_step_in_s},
                   {"split_gap_s", r.split_gap_s},
                   {"rows_in", r.rows_in},
                   {"rows_out", r.rows_out},
                   {"repeats_dropped", r.repeats_dropped},
                   {"gaps_bridged", r.gaps_bridged},
                   {"longest_bridged_gap_s", r.longest_bridged_gap_s},
                   {"gaps_split", r.gaps_split}};
  auto spans = [](const std::vector<io::SegmentSpan>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& s : v) a.push_back({{"t_begin", s.t_begin}, {"t_end", s.t_end}, {"rows_in", s.rows_in}, {"samples", s.samples}});
    return a;
  };
  j["segments"] = spans(r.segments);
  j["dropped_segments"] = spans(r.dropped);
  j["summary"] = r.summary();
  return j;
}

nlohmann::json input_json(const LoadedRecording& in) {
  return {{"resampling", resampling_json(in.data.report)}, {"torque", io::to_string(in.torque)}};
}

IdentifyResult identify_friction(const LoadedRecording& in, const robot::RobotModel& model, const IdentifySettings& s,
                                 const std::function<void(double)>& progress) {
  // The GA fits one continuous run: the longest segment when gaps split the file.
  const auto& rec = in.longest();
  ident::GaSettings ga;
  ga.seed = s.seed;
  ga.runs = s.runs;
  // The file must run where the user runs it: calibrate, replay and the drive at this rate.
  ga.firmware.enabled = true;
  ga.firmware.dt = 1.0 / in.data.report.rate_hz;
  IdentifyResult r;
  r.joints = about_recording(in.path, [&] {
    const ObserverGains gains{ObserverKind::first_order, s.gain, 0, 0, s.align_motor_torque};
    return eval::identify_recording(rec, model, gains, ga, progress);
  });
  r.joint_ids = rec.joint_ids;
  r.t_begin = rec.t.front();
  r.t_end = rec.t.back();
  r.segments = in.data.segments.size();
  r.json = input_json(in);
  r.json["segment_used"] = {{"t_begin", r.t_begin}, {"t_end", r.t_end}};
  r.json["firmware_rate_hz"] = in.data.report.rate_hz;  // the parameters fit both scalars at this rate
  return r;
}

void write_friction(const std::string& path, const IdentifyResult& r) { eval::write_friction_json(path, r.joints, r.joint_ids, r.json); }

eval::ReplayOptions Holding::options() const {
  eval::ReplayOptions o = replay;
  o.holding = mode == "always"                     ? eval::HoldingSource::always
              : mode == "still" || mode == "auto" ? eval::HoldingSource::still
                                                  : eval::HoldingSource::none;
  return o;
}

void Holding::check_held(const std::string& path, const std::vector<io::Recording>& segments, const std::vector<int>& ids) const {
  if (mode != "always") return;
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

eval::Thresholds calibrate_thresholds(const std::string& path, const std::vector<io::Recording>& segments,
                                      const robot::RobotModel& model, const std::vector<LuGreParams<double>>& friction,
                                      const ObserverGains& gains, double margin, const Holding& holding) {
  return about_recording(path, [&] {
    holding.check_held(path, segments, segments.front().joint_ids);
    auto th = eval::calibrate_segments(segments, model, friction, gains, margin, kCalibrationSettleS);
    eval::cover_region(th, segments, model, friction, gains, kCalibrationSettleS);
    if (holding.mode != "none") {
      th.hold_settle_s = holding.settle;
      th.hold_reference_s = holding.reference;
      eval::calibrate_holds(th, segments, model, friction, gains, holding.options(), kCalibrationSettleS, holding.mode != "auto");
      // A held joint may hold any friction up to its static level: a calibration on a few
      // holds (or none) saw only the levels they happened to keep. The band's standstill
      // allowance covers the whole range (a joint settling at rest after a move never
      // crosses it); small changes are the holding detector's job.
      for (std::size_t j = 0; j < th.low_speed_extra.size(); ++j) {
        th.low_speed_extra[j] = std::max(th.low_speed_extra[j], eval::friction_level(friction[j]));
        th.hold_change[j] = std::max(th.hold_change[j], holding.floor * friction[j].tau_s);
      }
    }
    return th;
  });
}

namespace {
std::string format(const char* f, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* f, ...) {
  char buf[512];
  va_list args;
  va_start(args, f);
  std::vsnprintf(buf, sizeof buf, f, args);
  va_end(args);
  return buf;
}

/// Where the replay left the calibration's region: notes for the user, fields in the JSON.
void region(const eval::ReplayResult& r, const eval::Thresholds& t, const std::vector<int>& ids, nlohmann::json& j,
            std::vector<std::string>& notes) {
  if (t.q_min.size() != ids.size()) {
    notes.emplace_back("note: the threshold file states no calibrated region (calibrate again to get one)");
    return;
  }
  j["outside_region"] = nlohmann::json::array();
  for (std::size_t k = 0; k < ids.size(); ++k) {
    j["outside_region"].push_back({{"joint", ids[k]}, {"position_samples", r.outside_q[k]}, {"velocity_samples", r.outside_dq[k]},
                                   {"stop_widened_samples", r.stop_widened[k]}});
    if (r.outside_q[k] + r.outside_dq[k] == 0) continue;
    notes.push_back(format("warning: joint %d outside the calibrated region in %zu samples (position) and %zu (velocity): the band "
                           "there was not calibrated; calibrate on a motion that covers it",
                           ids[k], r.outside_q[k], r.outside_dq[k]));
  }
  if (r.gated_samples > 0) notes.push_back(format("stop gate: detector gated in %zu samples", r.gated_samples));
  j["stop_gated_samples"] = r.gated_samples;
  std::size_t widened = 0;
  for (const auto w : r.stop_widened) widened += w;
  if (widened > 0) {
    std::string line = "stop allowance: band widened for accelerations beyond the calibration's in";
    for (std::size_t k = 0; k < ids.size(); ++k) line += format(" %zu", r.stop_widened[k]);
    notes.push_back(line + " samples (joints in order)");
  }
}

nlohmann::json event_json(const eval::ReplayEvent& e, const std::vector<int>& ids) {
  nlohmann::json event = {{"t", e.t}, {"link", e.link}, {"joints_over", e.joints_over}, {"by_hold", e.by_hold}};
  if (!e.contact || e.contact->link < 1) return event;
  const auto& c = *e.contact;
  event["contact"] = {{"t", e.contact_t},
                      {"link", ids[static_cast<std::size_t>(c.link - 1)]},
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
  return event;
}
}  // namespace

std::string describe_event(const eval::ReplayEvent& e, const std::vector<int>& ids) {
  std::string s = format("t = %.4f s: link %d (joints over threshold:", e.t, e.link);
  for (const int k : e.joints_over) s += format(" %d", k);
  s += std::string(")") + (e.by_hold ? " by the holding detector" : "");
  if (e.contact && e.contact->link >= 1) {
    const auto& c = *e.contact;
    const int link_id = ids[static_cast<std::size_t>(c.link - 1)];
    s += format("\n    contact (at %.4f s): link %d, %.3f +- %.3f m along it, force %.1f +- %.1f N (%d of 3 components "
                "determined), peak %.1f N at %.4f s",
                e.contact_t, link_id, c.along_m, c.along_sigma_m, c.force_n, c.force_sigma_n, c.determined_components,
                e.contact_peak_force_n, e.contact_t_peak);
    // What the torques allow: a value where they determine the force, else the set.
    s += "\n    " + report::describe_contact(c, link_id);
  }
  return s;
}

ReplayOutcome replay_files(const LoadedRecording& in, const robot::RobotModel& model, const std::string& friction_path,
                           const std::string& threshold_path, const ObserverGains& gains, const ReplaySettings& s) {
  ReplayOutcome out;
  const auto& ids = in.data.segments.front().joint_ids;
  out.joint_ids = ids;
  const auto friction = eval::read_friction_json(friction_path, ids);
  const auto thresholds = eval::read_threshold_json(threshold_path, ids);
  eval::check_friction_fits(friction_path, friction, ids, 1.0 / in.data.report.rate_hz, s.scalar);
  Holding holding = s.holding;
  // The holding detector needs its change thresholds from the threshold file.
  if (thresholds.hold_change.size() != ids.size()) {
    if (holding.mode == "always" || holding.mode == "still") {
      throw std::invalid_argument(threshold_path + ": --holding " + holding.mode +
                                  " needs the holding detector's change thresholds (hold_change_threshold), "
                                  "which this threshold file lacks: calibrate again (it writes them by default)");
    }
    if (holding.mode == "auto") {
      out.notes.push_back("note: " + threshold_path +
                          " has no holding detector thresholds (hold_change_threshold): the band alone; calibrate again to get them");
      holding.mode = "none";
    }
  }
  holding.check_held(in.path, in.data.segments, ids);
  out.holding = holding.mode;
  // Each segment runs from a fresh state; events keep the recording's time stamps.
  out.result = about_recording(in.path, [&] {
    return eval::replay_segments(in.data.segments, model, friction, thresholds, gains, s.scalar, s.debounce, holding.options());
  });
  const auto& r = out.result;
  out.json = input_json(in);
  region(r, thresholds, ids, out.json, out.notes);
  if (holding.mode != "none") {
    out.json["holding"] = {{"source", holding.mode}, {"held_samples", r.held_samples}, {"rearms", r.rearms}};
  }
  out.json["events"] = nlohmann::json::array();
  for (const auto& e : r.events) out.json["events"].push_back(event_json(e, ids));
  out.json["external_torque_max"] = r.external_torque_max;
  out.json["scalar"] = s.scalar;
  return out;
}

std::string trace_csv(const eval::ReplayResult& r, const std::vector<int>& ids) { return io::trace_csv(r.t, r.mu, ids); }

}  // namespace jg::workflow
