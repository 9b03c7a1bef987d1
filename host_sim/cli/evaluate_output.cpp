#include "cli/evaluate_output.hpp"

#include "eval/contact_coverage.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <stdexcept>

namespace jg::cli {
namespace {
nlohmann::json optional_json(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

nlohmann::json vector_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }


nlohmann::json run_json(const eval::RunResult& r) {
  nlohmann::json j{{"name", r.name}, {"index", r.index}, {"t_collision", r.t_collision}, {"link_true", r.link_true},
                   {"link_isolated", r.link_isolated}, {"peak_force", r.peak_force_n},
                   {"max_true_torque_over_threshold", r.max_true_ratio},
                   {"max_true_torque_over_moving_threshold", r.max_true_ratio_moving},
                   {"isolable", r.isolable}, {"isolable_at_decision", r.isolable_at_decision},
                   {"link_first_cycle", r.link_first_cycle}, {"detected_by_hold", r.detected_by_hold},
                   {"peak_true_torque_held", r.peak_true_torque_held}, {"peak_true_torque_own", r.peak_true_torque_own}, {"peak_reaching_torque_own", r.peak_reaching_torque_own}, {"held_push", r.held_push_nm}};
  // Contract fields: the true contact force (peak over the run, N) and the estimate's force
  // magnitude (at the end of the estimate's window, N; null: no estimate). The estimate
  // compares with `contact_estimate.force_true_at_estimate` (the same cycle), not the peak.
  j["force_true"] = r.peak_force_n;
  j["force_estimate"] = r.contact ? nlohmann::json(r.contact->estimate.force_n) : nlohmann::json(nullptr);
  j["link_estimated"] = r.contact ? r.contact->estimate.link : 0;
  j["contact_estimate"] = r.contact ? contact_json(*r.contact) : nlohmann::json(nullptr);
  j["t_detected"] = optional_json(r.t_detected);
  j["delay"] = r.t_detected ? nlohmann::json(*r.t_detected - r.t_collision) : nlohmann::json(nullptr);
  j["t_threshold_crossed"] = optional_json(r.t_threshold);
  j["delay_after_threshold_crossed"] =
      r.t_detected && r.t_threshold ? nlohmann::json(*r.t_detected - *r.t_threshold) : nlohmann::json(nullptr);
  j["peak_joint"] = r.peak_joint;
  j["peak_true_torque"] = r.peak_true_torque_nm;
  j["speed_at_peak"] = r.speed_at_peak_rad_s;
  j["detected_by_residual"] = r.detected_by_residual;
  if (r.compared) j["t_detected_other_scalar"] = optional_json(r.t_detected_other);
  if (r.bus) {
    j["bus"] = {{"frames", r.bus->frames}, {"busy_s", r.bus->busy_s}, {"elapsed_s", r.bus->elapsed_s},
                {"incomplete_cycles", r.bus->incomplete_cycles}};
  }
  return j;
}


struct FreeRunTotals {
  int alarms = 0;
  std::vector<double> times;
};
/// Per link of a `held` evaluation (every link pushed): the smallest push detected such
/// that every larger one was detected too (null: none); empty when the runs are not held
/// pushes.
nlohmann::json held_smallest(const std::vector<eval::RunResult>& runs) {
  nlohmann::json out = nlohmann::json::array();
  int links = 0;
  for (const auto& r : runs) links = r.held_push_nm > 0.0 ? std::max(links, r.link_true) : links;
  for (int link = 1; link <= links; ++link) {
    double smallest = -1.0;
    for (auto it = runs.rbegin(); it != runs.rend(); ++it) {
      if (it->link_true != link || it->held_push_nm <= 0.0) continue;
      if (!it->t_detected) break;
      smallest = it->held_push_nm;
    }
    out.push_back(smallest > 0.0 ? nlohmann::json(smallest) : nlohmann::json(nullptr));
  }
  return out;
}

/// Per link of a `held` evaluation: at its largest push, the torque that reaches the own
/// joint's motor (RunResult::peak_reaching_torque_own) and the true torque there [N·m]; a
/// push its static friction takes cannot show in the currents. Empty when not held pushes.
nlohmann::json held_reaching(const std::vector<eval::RunResult>& runs) {
  nlohmann::json out = nlohmann::json::array();
  std::vector<const eval::RunResult*> largest;
  for (const auto& r : runs) {
    if (r.held_push_nm <= 0.0 || r.link_true < 1) continue;
    const auto link = static_cast<std::size_t>(r.link_true);
    if (largest.size() < link) largest.resize(link, nullptr);
    if (largest[link - 1] == nullptr || r.held_push_nm > largest[link - 1]->held_push_nm) largest[link - 1] = &r;
  }
  for (const auto* r : largest) {
    out.push_back(r == nullptr ? nlohmann::json(nullptr)
                               : nlohmann::json{{"push", r->held_push_nm}, {"true_own", r->peak_true_torque_own},
                                                {"reaching_own", r->peak_reaching_torque_own}});
  }
  return out;
}

FreeRunTotals totals_of(const std::vector<eval::FreeRunSegment>& segments) {
  FreeRunTotals t;
  for (const auto& s : segments) t.times.insert(t.times.end(), s.alarm_times.begin(), s.alarm_times.end());
  t.alarms = static_cast<int>(t.times.size());
  return t;
}
}  // namespace

nlohmann::json contact_json(const eval::ContactOutcome& c) {
  const auto& e = c.estimate;
  nlohmann::json j = {{"t", c.t}, {"link", e.link}, {"link_residual_chi2", e.link_chi2},
          {"along_link", e.along_m}, {"along_link_sigma", e.along_sigma_m},
          {"point_in_link", vector_json(e.point_in_link)}, {"point_base", vector_json(e.point_base)},
          {"force", e.force_n}, {"force_sigma", e.force_sigma_n}, {"force_base", vector_json(e.force_base)},
          {"determined_force_components", e.determined_components}, {"residual_chi2", e.residual_chi2},
          {"torque", std::vector<double>(c.observation.tau_nm.data(), c.observation.tau_nm.data() + c.observation.tau_nm.size())},
          {"torque_sigma", std::vector<double>(c.observation.sigma_nm.data(), c.observation.sigma_nm.data() + c.observation.sigma_nm.size())},
          {"force_true_at_estimate", c.force_true_n}, {"along_link_true", c.along_true_m},
          {"point_error", c.point_error_m >= 0.0 ? nlohmann::json(c.point_error_m) : nlohmann::json(nullptr)},
          {"force_given_true_point", c.force_at_true_point_n}, {"peak_force", c.peak_force_n}, {"t_peak_force", c.t_peak},
          {"torque_true", c.torque_true_nm}, {"force_true_observed", c.force_true_observed_n}, {"t_force", c.t_force},
          {"force_given_true_link", c.force_given_true_link_n}, {"along_link_given_true_link", c.along_given_true_link_m},
          {"point_error_given_true_link", c.point_error_given_true_link_m >= 0.0 ? nlohmann::json(c.point_error_given_true_link_m) : nlohmann::json(nullptr)},
          {"point_true", vector_json(c.point_true)}};
  j.update(eval::contact_set_json(c));  // the estimate as a set, and the truth it aims at
  return j;
}


nlohmann::json evaluate_json(const EvaluateFigures& f) {
  const eval::Summary sum = eval::summarize(f.runs);
  const FreeRunTotals fr = totals_of(f.free_run);
  nlohmann::json j;
  j["runs"] = nlohmann::json::array();
  for (const auto& r : f.runs) j["runs"].push_back(run_json(r));
  const double n = std::max(1, sum.runs);
  nlohmann::json s = f.config;
  s.update({{"detection_rate", sum.detected / n},
            {"isolation_accuracy", sum.isolated / n},
            {"isolation_ceiling", sum.isolable / n},
            // Named right where the true torques distinguish the link (<= the ceiling by
            // construction), its share of the ceiling, and right names where they do not (a
            // guess between links the torques cannot tell apart within the noise band).
            {"isolation_distinguished", sum.isolated_of_isolable / n},
            {"isolation_of_ceiling", sum.isolable > 0 ? static_cast<double>(sum.isolated_of_isolable) / sum.isolable : 1.0},
            {"isolated_not_distinguishable", sum.isolated - sum.isolated_of_isolable},
            {"isolable", sum.isolable},
            {"isolated_of_isolable", sum.isolated_of_isolable},
            {"isolation_ceiling_at_decision", sum.isolable_at_decision / n},
            {"isolable_at_decision", sum.isolable_at_decision},
            {"isolated_of_isolable_at_decision", sum.isolated_of_isolable_at_decision},
            // The comparable share: the decision against what the true torques allow up to the
            // same cycle (isolation_of_ceiling counts contacts nameable only after the decision).
            {"isolation_of_ceiling_at_decision",
             sum.isolable_at_decision > 0 ? static_cast<double>(sum.isolated_of_isolable_at_decision) / sum.isolable_at_decision : 1.0},
            {"detected_by_hold", sum.detected_by_hold},
            {"detected_by_residual", sum.detected_by_residual},
            {"held_smallest_detected", held_smallest(f.runs)},
            {"held_reaching_own_at_largest", held_reaching(f.runs)},
            {"detection_rate_over_1p5x_threshold", sum.detectable ? static_cast<double>(sum.detectable_found) / sum.detectable : 1.0},
            {"over_1p5x_threshold", {{"collisions", sum.detectable}, {"detected", sum.detectable_found}}},
            {"over_1p5x_moving_threshold", {{"collisions", sum.detectable_moving}, {"detected", sum.detectable_moving_found}}},
            {"isolation_accuracy_by_estimate", sum.estimated_link_right / n},
            {"isolated_of_isolable_by_estimate", sum.estimated_right_of_isolable},
            {"contact_estimate", {{"estimated", sum.estimated}, {"link_right", sum.estimated_link_right},
                                  {"link_right_of_isolable", sum.estimated_right_of_isolable},
                                  {"force_within_20pct", sum.force_within_20pct},
                                  {"force_within_20pct_given_true_point", sum.force_within_20pct_true_point},
                                  {"force_within_20pct_of_observed", sum.force_within_20pct_observed},
                                  {"force_within_20pct_of_observed_given_true_point", sum.force_within_20pct_observed_true_point},
                                  {"force_within_20pct_of_observed_given_true_link", sum.force_within_20pct_observed_true_link},
                                  {"point_within_5cm_given_true_link", sum.point_within_5cm_true_link},
                                  {"peak_force_within_20pct_of_true_peak", sum.peak_force_within_20pct},
                                  {"point_within_5cm", sum.point_within_5cm},
                                  {"along_link_within_5cm", sum.along_within_5cm},
                                  {"spreads", eval::to_json(eval::contact_coverage(f.runs))}}},
            {"delay_min", sum.delay_min}, {"delay_median", sum.delay_median}, {"delay_max", sum.delay_max},
            {"after_threshold_crossed", {{"detections", sum.after_crossing},
                                         {"within_10ms", sum.after_crossing_within_10ms},
                                         {"median", sum.after_crossing_median},
                                         {"p95", sum.after_crossing_p95},
                                         {"max", sum.after_crossing_max}}},
            {"false_alarms_per_hour", f.free_run_s > 0.0 ? static_cast<double>(fr.alarms) * 3600.0 / f.free_run_s : 0.0},
            {"false_alarm_run_s", f.free_run_s}, {"false_alarm_times", fr.times},
            {"false_alarm_segments", f.free_run.size()}, {"false_alarm_segment_s", eval::kFreeRunSegmentS},
            {"touched", {{"collisions", sum.touched}, {"detected", sum.touched_detected},
                         {"below_moving_threshold", sum.touched_below_moving}}}});
  if (sum.compared > 0) {
    s["same_cycle_other_scalar"] = {{"runs", sum.compared}, {"detected_by_either", sum.compared_detected},
                                    {"same_cycle", sum.same_cycle}, {"both_detected", sum.both_detected},
                                    {"other_minus_first_s", {{"min", sum.other_lag_min_s}, {"median", sum.other_lag_median_s},
                                                             {"max", sum.other_lag_max_s}}}};
    if (sum.bus_runs > 0) {
      s["same_cycle_other_scalar"]["on_bus"] = true;
      s["bus"] = {{"runs", sum.bus_runs}, {"frames", sum.bus_frames}, {"busy_s", sum.bus_busy_s}, {"elapsed_s", sum.bus_elapsed_s},
                  {"busy_share_max", sum.bus_busy_max_share}, {"incomplete_cycles", sum.bus_incomplete_cycles}};
    }
  }
  j["summary"] = s;
  for (const auto& [key, value] : f.extra.items()) j[key] = value;
  return j;
}

namespace {
/// The contact estimates' figures (when any run has one).
void print_contact_figures(const eval::Summary& sum, const std::vector<eval::RunResult>& runs) {
  std::printf("contact estimate (%d detections, window around the detection): link right %d/%d, of the isolable %d/%d; "
              "force within 20 %% of the truth at its cycle %d/%d (given the true point %d/%d), peak force within 20 %% "
              "of the true peak %d/%d; point within 5 cm (link right) %d/%d, along the link %d/%d\n",
              sum.estimated, sum.estimated_link_right, sum.estimated, sum.estimated_right_of_isolable, sum.isolable,
              sum.force_within_20pct, sum.estimated, sum.force_within_20pct_true_point, sum.estimated,
              sum.peak_force_within_20pct, sum.estimated, sum.point_within_5cm, sum.estimated, sum.along_within_5cm,
              sum.estimated);
  std::printf("contact force against the true force as the observer sees it (first-order filtered with its gain): "
              "within 20 %% %d/%d (given the true point %d/%d, given the true link %d/%d); point within 5 cm given the true "
              "link %d/%d\n",
              sum.force_within_20pct_observed, sum.estimated, sum.force_within_20pct_observed_true_point, sum.estimated,
              sum.force_within_20pct_observed_true_link, sum.estimated, sum.point_within_5cm_true_link, sum.estimated);
  std::printf("%s\n", eval::describe(eval::contact_coverage(runs)).c_str());
}

/// The held pushes (the smallest detected per link, alarms in the hold) and the residual
/// and holding detectors' thresholds.
void print_held_and_detectors(const EvaluateFigures& f, const eval::Summary& sum) {
  const nlohmann::json smallest = held_smallest(f.runs);
  if (!smallest.empty()) {
    std::printf("smallest push detected on a held joint (every larger one detected too):");
    for (std::size_t k = 0; k < smallest.size(); ++k) {
      std::printf(" link %zu %s", k + 1, smallest[k].is_null() ? "none" : (std::to_string(smallest[k].get<double>()).substr(0, 4) + " N·m").c_str());
    }
    int quiet_alarms = 0;
    for (const auto& r : f.runs) quiet_alarms += r.held_push_nm <= 0.0 ? static_cast<int>(r.false_alarm_times.size()) : 0;
    std::printf("; alarms in the hold without contact: %d\n", quiet_alarms);
    std::printf("at the largest push, the torque that reaches the own joint's motor (static friction takes the rest):");
    std::size_t link = 0;
    for (const auto& h : held_reaching(f.runs)) {
      ++link;
      if (!h.is_null()) {
        std::printf(" link %zu %.2f of %.2f N·m", link, h["reaching_own"].get<double>(), h["true_own"].get<double>());
      }
    }
    std::printf("\n");
  }
  if (f.config.contains("residual_change_threshold") && !f.config["residual_change_threshold"].empty()) {
    std::printf("residual detector (baseline time constant %.3f s): change threshold",
                f.config.value("residual_time_constant_s", 0.0));
    for (const auto& h : f.config["residual_change_threshold"]) std::printf(" %.3f", h.get<double>());
    std::printf(" N·m; detections first seen by it (not the band) %d\n", sum.detected_by_residual);
  }
  if (f.config.contains("hold_change_threshold") && !f.config["hold_change_threshold"].empty()) {
    std::printf("holding detector: change threshold");
    for (const auto& h : f.config["hold_change_threshold"]) std::printf(" %.3f", h.get<double>());
    std::printf(" N·m\n");
  }
}
}  // namespace

void print_figures(const EvaluateFigures& f) {
  const eval::Summary sum = eval::summarize(f.runs);
  const FreeRunTotals fr = totals_of(f.free_run);
  std::printf("%-28s %9s %9s %9s %6s %9s\n", "run", "t_coll", "t_det", "delay ms", "link", "peak N");
  for (const auto& r : f.runs) {
    std::printf("%-28s %9.3f %9s %9s %3d->%d %9.1f\n", r.name.c_str(), r.t_collision,
                r.t_detected ? std::to_string(*r.t_detected).substr(0, 7).c_str() : "-",
                r.t_detected ? std::to_string(1000.0 * (*r.t_detected - r.t_collision)).substr(0, 6).c_str() : "missed",
                r.link_true, r.link_isolated, r.peak_force_n);
  }
  std::printf("detected %d/%d; of those whose true torque exceeds 1.5x the threshold in effect: %d/%d "
              "(1.5x the moving threshold: %d/%d); isolation %d/%d\n",
              sum.detected, sum.runs, sum.detectable_found, sum.detectable, sum.detectable_moving_found,
              sum.detectable_moving, sum.isolated, sum.runs);
  std::printf("isolable (the torques that reach the motors name the link: the highest joint over its moving "
              "threshold, less what a stuck joint's static friction takes): %d/%d; "
              "isolated of those %d/%d; detections first seen by the holding detector %d\n",
              sum.isolable, sum.runs, sum.isolated_of_isolable, sum.isolable, sum.detected_by_hold);
  std::printf("isolation against its ceiling: %d/%d distinguished and named (ceiling %d/%d, %.1f %% of it); "
              "named right where the torques do not distinguish the link (a guess): %d\n",
              sum.isolated_of_isolable, sum.runs, sum.isolable, sum.runs,
              sum.isolable > 0 ? 100.0 * sum.isolated_of_isolable / sum.isolable : 100.0, sum.isolated - sum.isolated_of_isolable);
  std::printf("isolable at decision time (the same from the cycles up to the isolation decision only): %d/%d; "
              "isolated of those %d/%d (%.1f %% of the ceiling at the same time)\n",
              sum.isolable_at_decision, sum.runs, sum.isolated_of_isolable_at_decision, sum.isolable_at_decision,
              sum.isolable_at_decision > 0 ? 100.0 * sum.isolated_of_isolable_at_decision / sum.isolable_at_decision : 100.0);
  if (sum.runs > 0) {
    std::printf("touched (the contact exerted any force): %d/%d, "
                "detected %d/%d; touched with a true torque below the moving threshold on every joint: %d\n",
                sum.touched, sum.runs, sum.touched_detected, sum.touched, sum.touched_below_moving);
  }
  if (sum.compared > 0) {
    std::printf("the %s on the same measurements: %d of %d collisions detected by either detected by "
                "both on the same cycle; where both detected (%d), its detection minus the first's min/median/max "
                "%.1f/%.1f/%.1f ms\n",
                sum.bus_runs > 0 ? "drives on the simulated bus" : "other scalar", sum.same_cycle, sum.compared_detected,
                sum.both_detected, 1e3 * sum.other_lag_min_s, 1e3 * sum.other_lag_median_s, 1e3 * sum.other_lag_max_s);
  }
  if (sum.bus_runs > 0) {
    std::printf("simulated bus: %zu frames over %.1f s, wire busy %.1f %% (largest in a run %.1f %%); cycles whose status "
                "frames were not all in by the next: %zu\n",
                sum.bus_frames, sum.bus_elapsed_s, sum.bus_elapsed_s > 0.0 ? 100.0 * sum.bus_busy_s / sum.bus_elapsed_s : 0.0,
                100.0 * sum.bus_busy_max_share, sum.bus_incomplete_cycles);
  }
  if (sum.estimated > 0) print_contact_figures(sum, f.runs);
  print_held_and_detectors(f, sum);
  const double per_hour = f.free_run_s > 0.0 ? fr.alarms * 3600.0 / f.free_run_s : 0.0;
  std::printf("delay min/median/max %.1f/%.1f/%.1f ms; false alarms %d in %.0f s (%.2f per hour)", 1e3 * sum.delay_min,
              1e3 * sum.delay_median, 1e3 * sum.delay_max, fr.alarms, f.free_run_s, per_hour);
  for (const double t : fr.times) std::printf(" %.3f", t);
  std::printf("\n");
  std::printf("after the true torque crosses the threshold in effect: %d of %d detections within 10 ms; "
              "median/95th percentile/max %.1f/%.1f/%.1f ms\n",
              sum.after_crossing_within_10ms, sum.after_crossing, 1e3 * sum.after_crossing_median,
              1e3 * sum.after_crossing_p95, 1e3 * sum.after_crossing_max);
}

namespace {
std::string joints_of(JointMask m) {
  std::string s;
  for (int j = 0; j < 8; ++j) {
    if (((m >> j) & 1U) != 0U) s += (s.empty() ? "" : ",") + std::to_string(j + 1);
  }
  return s.empty() ? "-" : s;
}
}  // namespace

void print_false_alarms(const std::vector<eval::FreeRunSegment>& segments) {
  for (const auto& seg : segments) {
    for (const auto& a : seg.alarms) {
      std::printf("false alarm at %.3f s (segment %d): joints %s (band %s, residual %s, hold %s)\n", a.t_s, seg.index,
                  joints_of(a.flagged).c_str(), joints_of(a.by_band).c_str(), joints_of(a.by_residual).c_str(),
                  joints_of(a.by_hold).c_str());
      std::printf("  joint  q [rad]  dq [rad/s]  mu [N·m]  band [N·m]\n");
      for (std::size_t j = 0; j < a.mu_nm.size(); ++j) {
        std::printf("  %5zu  %7.3f  %10.4f  %8.3f  %10.3f\n", j + 1, a.q_rad[j], a.dq_rad_s[j], a.mu_nm[j], a.band_nm[j]);
      }
    }
  }
}

nlohmann::json partial_json(const EvaluateFigures& f, int shard, int shards, std::size_t runs_total,
                            std::size_t segments_total, const nlohmann::json& identity) {
  nlohmann::json p;
  p["jointguard_partial"] = {{"shard", shard}, {"shards", shards}, {"runs_total", runs_total},
                             {"segments_total", segments_total}, {"free_run_s", f.free_run_s},
                             {"identity", identity}, {"config", f.config}};
  // What one run adds beside the figures (a safety verdict), in the part that ran it.
  p["extra"] = f.extra.is_null() ? nlohmann::json::object() : f.extra;
  p["runs"] = nlohmann::json::array();
  for (const auto& r : f.runs) p["runs"].push_back(run_json(r));
  p["free_run"] = nlohmann::json::array();
  for (const auto& s : f.free_run) {
    p["free_run"].push_back({{"index", s.index}, {"seconds", s.seconds}, {"alarm_times", s.alarm_times}});
  }
  return p;
}

void parse_shard(const std::string& text, int& shard, int& shards) {
  const auto slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("no '/'");
    std::size_t used_k = 0, used_n = 0;
    const std::string k = text.substr(0, slash), n = text.substr(slash + 1);
    shard = std::stoi(k, &used_k);
    shards = std::stoi(n, &used_n);
    if (used_k != k.size() || used_n != n.size()) throw std::invalid_argument("trailing characters");
  } catch (const std::exception&) {
    throw std::invalid_argument("--shard: expected K/N (e.g. 2/8), got '" + text + "'");
  }
  if (shards < 1 || shards > 100000 || shard < 1 || shard > shards) {
    throw std::invalid_argument("--shard " + text + ": need 1 <= K <= N <= 100000");
  }
}

}  // namespace jg::cli
