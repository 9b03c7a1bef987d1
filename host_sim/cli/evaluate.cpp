// `jointguard evaluate`: the paper's experiments or a campaign on the simulated arm with
// the firmware core in the loop; JSON per ../shared/CONTRACT.md.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/progress.hpp"
#include "eval/experiments.hpp"
#include "io/yaml_fields.hpp"
#include "sim/scenario.hpp"

#include <filesystem>

namespace jg::cli {
namespace {
struct EvaluateOptions {
  std::string scenario = "paper", model = JG_DEFAULT_MODEL, json, scalar = "float", reaction = "stop";
  double rate = 1000.0, margin = 0.5, free_run_s = 0.0, calibration_s = 3600.0, hold_calibration_s = 1200.0;
  double hold_settle_s = 0.15, isolation_window_s = 0.0;
  bool no_hold = false, free_run_without_holds = false;
  int count = 50, debounce = 1;
  unsigned long long seed = 1;
  ObserverOptions observer;
  robot::LoadOptions model_options;
};

Reaction reaction_of(const std::string& s) {
  if (s == "none") return Reaction::none;
  if (s == "zero_gravity") return Reaction::zero_gravity;
  return Reaction::stop;
}

nlohmann::json run_json(const eval::RunResult& r) {
  nlohmann::json j{{"name", r.name}, {"t_collision", r.t_collision}, {"link_true", r.link_true},
                   {"link_isolated", r.link_isolated}, {"peak_force", r.peak_force_n},
                   {"max_true_torque_over_threshold", r.max_true_ratio},
                   {"max_true_torque_over_moving_threshold", r.max_true_ratio_moving},
                   {"isolable", r.isolable}, {"link_first_cycle", r.link_first_cycle}, {"detected_by_hold", r.detected_by_hold},
                   {"peak_true_torque_held", r.peak_true_torque_held}, {"held_push", r.held_push_nm}};
  j["t_detected"] = r.t_detected ? nlohmann::json(*r.t_detected) : nlohmann::json(nullptr);
  j["delay"] = r.t_detected ? nlohmann::json(*r.t_detected - r.t_collision) : nlohmann::json(nullptr);
  j["t_threshold_crossed"] = r.t_threshold ? nlohmann::json(*r.t_threshold) : nlohmann::json(nullptr);
  j["delay_after_threshold_crossed"] =
      r.t_detected && r.t_threshold ? nlohmann::json(*r.t_detected - *r.t_threshold) : nlohmann::json(nullptr);
  return j;
}
}  // namespace

Command add_evaluate(CLI::App& app) {
  auto o = std::make_shared<EvaluateOptions>();
  auto* cmd = app.add_subcommand("evaluate",
                                 "Run the paper's three collisions (paper), a random campaign (campaign) or a scenario file\n"
                                 "on the simulated arm with the firmware core in the loop. Friction is identified from an\n"
                                 "excitation run and thresholds calibrated on collision-free motion first.\n"
                                 "Example: jointguard evaluate --scenario paper --rate 125 --scalar q --json out/paper125.json");
  cmd->add_option("--scenario", o->scenario,
                  "paper, campaign, held (pushes of 0.5-3 N·m on each link of a held arm) or a scenario file (YAML)")
      ->capture_default_str();
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->capture_default_str()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--rate", o->rate, "Control and observer rate [Hz]")->capture_default_str()->check(CLI::Range(50.0, 20000.0));
  cmd->add_option("--scalar", o->scalar, "Firmware scalar")->check(CLI::IsMember({"float", "q"}))->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of noise, campaign and motion")->capture_default_str();
  cmd->add_option("--count", o->count, "Collisions in a campaign")->capture_default_str()->check(CLI::Range(1, 100000));
  cmd->add_option("--free-run", o->free_run_s, "Collision-free run for false alarms [s] (default 120 s paper, 600 s campaign)");
  cmd->add_option("--calibration", o->calibration_s, "Collision-free run the thresholds are calibrated on [s]")->capture_default_str()->check(CLI::Range(10.0, 86400.0));
  cmd->add_option("--hold-calibration", o->hold_calibration_s,
                  "Collision-free motion with holds the holding detector is calibrated on [s]")
      ->capture_default_str()->check(CLI::Range(10.0, 86400.0));
  cmd->add_option("--hold-settle", o->hold_settle_s, "Held time before the holding detector takes its reference [s]")
      ->capture_default_str()->check(CLI::Range(0.0, 5.0));
  cmd->add_option("--isolation-window", o->isolation_window_s,
                  "Name the link from every joint taking part in the signature over this long from the detection [s] (0: the detection cycle)")
      ->capture_default_str()->check(CLI::Range(0.0, 0.1));
  cmd->add_flag("--no-hold", o->no_hold, "Band detector alone (no change detection while a joint holds)");
  cmd->add_flag("--free-run-without-holds", o->free_run_without_holds,
                "False-alarm run on random moves with short dwells only (the motion before holds were added)");
  cmd->add_option("--margin", o->margin, "Threshold margin above the observed band [N·m]")->capture_default_str()->check(finite_range(0.0, 1000.0));
  cmd->add_option("--debounce", o->debounce, "Cycles over threshold before a detection")->capture_default_str()->check(CLI::Range(1, 50));
  cmd->add_option("--reaction", o->reaction, "Reaction on detection")->check(CLI::IsMember({"none", "stop", "zero_gravity"}))->capture_default_str();
  cmd->add_option("--json", o->json, "Write the runs and summary here (contract format)");
  o->observer.add_to(cmd);
  return {cmd, [o]() {
            eval::ExperimentConfig c;
            std::string model_path = o->model;
            std::unique_ptr<sim::Scenario> scenario;
            if (o->scenario != "paper" && o->scenario != "campaign" && o->scenario != "held") {
              scenario = std::make_unique<sim::Scenario>(sim::load_scenario(o->scenario));
              model_path = (std::filesystem::path(o->scenario).parent_path() /
                            io::YamlFields::load_file(o->scenario).text("model")).string();
            }
            c.model = robot::load_robot(model_path, o->model_options);
            c.rate_hz = scenario ? scenario->setup.control_rate_hz : o->rate;
            c.scalar = o->scalar;
            c.seed = o->seed;
            c.gains = o->observer.to_gains(c.rate_hz);
            c.debounce_cycles = o->debounce;
            c.calibration_s = o->calibration_s;
            c.hold_calibration_s = o->no_hold ? 0.0 : o->hold_calibration_s;
            c.hold_settle_s = o->hold_settle_s;
            c.isolation_window_s = o->isolation_window_s;
            c.free_run_holds = !o->free_run_without_holds;
            c.reaction = reaction_of(o->reaction);
            Progress bar("evaluate");
            eval::prepare(c, o->margin, [&](double f) { bar.update(0.3 * f); });
            std::vector<eval::RunResult> runs;
            if (o->scenario == "paper") {
              runs = eval::paper_experiments(c, false);
            } else if (o->scenario == "held") {
              runs = eval::held_experiments(c);
            } else if (o->scenario == "campaign") {
              runs = eval::campaign(c, o->count, {2, 3}, [&](double f) { bar.update(0.3 + 0.5 * f); });
            } else {
              auto est = eval::estimator_for(c);
              const eval::DetectionConfig d = eval::detection_for(c);
              runs.push_back(eval::run_detection(scenario->setup, *est, d, scenario->setup.meta.scenario, false));
            }
            const double free_s = o->free_run_s > 0.0 ? o->free_run_s : (o->scenario == "campaign" ? 600.0 : 120.0);
            int alarms = 0;
            std::vector<double> alarm_times;
            const double per_hour = eval::false_alarms_per_hour(c, free_s, alarms, {}, &alarm_times);
            bar.finish();
            const eval::Summary sum = eval::summarize(runs);
            std::printf("%-28s %9s %9s %9s %6s %9s\n", "run", "t_coll", "t_det", "delay ms", "link", "peak N");
            for (const auto& r : runs) {
              std::printf("%-28s %9.3f %9s %9s %3d->%d %9.1f\n", r.name.c_str(), r.t_collision,
                          r.t_detected ? std::to_string(*r.t_detected).substr(0, 7).c_str() : "-",
                          r.t_detected ? std::to_string(1000.0 * (*r.t_detected - r.t_collision)).substr(0, 6).c_str() : "missed",
                          r.link_true, r.link_isolated, r.peak_force_n);
            }
            std::printf("detected %d/%d; of those whose true torque exceeds 1.5x the threshold in effect: %d/%d "
                        "(1.5x the moving threshold: %d/%d); isolation %d/%d\n",
                        sum.detected, sum.runs, sum.detectable_found, sum.detectable, sum.detectable_moving_found,
                        sum.detectable_moving, sum.isolated, sum.runs);
            std::printf("isolable (the true torques name the link: the highest joint over its moving threshold): %d/%d; "
                        "isolated of those %d/%d; detections first seen by the holding detector %d\n",
                        sum.isolable, sum.runs, sum.isolated_of_isolable, sum.isolable, sum.detected_by_hold);
            nlohmann::json held_smallest = nlohmann::json::array();
            if (o->scenario == "held") {
              // Per link: the smallest push detected such that every larger one was too.
              std::printf("smallest push detected on a held joint (every larger one detected too):");
              for (int link = 1; link <= 3; ++link) {
                double smallest = -1.0;
                for (auto it = runs.rbegin(); it != runs.rend(); ++it) {
                  if (it->link_true != link || it->held_push_nm <= 0.0) continue;
                  if (!it->t_detected) break;
                  smallest = it->held_push_nm;
                }
                std::printf(" link %d %s", link, smallest > 0.0 ? (std::to_string(smallest).substr(0, 4) + " N·m").c_str() : "none");
                held_smallest.push_back(smallest > 0.0 ? nlohmann::json(smallest) : nlohmann::json(nullptr));
              }
              int quiet_alarms = 0;
              for (const auto& r : runs) quiet_alarms += r.held_push_nm <= 0.0 ? static_cast<int>(r.false_alarm_times.size()) : 0;
              std::printf("; alarms in the hold without contact: %d\n", quiet_alarms);
            }
            if (!c.hold_threshold.empty()) {
              std::printf("holding detector: change threshold");
              for (const double h : c.hold_threshold) std::printf(" %.3f", h);
              std::printf(" N·m (settle %.0f ms, reference %.0f ms)\n", 1e3 * c.hold_settle_s, 1e3 * c.hold_reference_s);
            }
            std::printf("delay min/median/max %.1f/%.1f/%.1f ms; false alarms %d in %.0f s (%.2f per hour)", 1e3 * sum.delay_min,
                        1e3 * sum.delay_median, 1e3 * sum.delay_max, alarms, free_s, per_hour);
            for (const double t : alarm_times) std::printf(" %.3f", t);
            std::printf("\n");
            std::printf("after the true torque crosses the threshold in effect: %d of %d detections within 10 ms; "
                        "median/95th percentile/max %.1f/%.1f/%.1f ms\n",
                        sum.after_crossing_within_10ms, sum.after_crossing, 1e3 * sum.after_crossing_median,
                        1e3 * sum.after_crossing_p95, 1e3 * sum.after_crossing_max);
            if (!o->json.empty()) {
              nlohmann::json j;
              j["runs"] = nlohmann::json::array();
              for (const auto& r : runs) j["runs"].push_back(run_json(r));
              const double n = std::max(1, sum.runs);
              j["summary"] = {{"detection_rate", sum.detected / n},
                              {"isolation_accuracy", sum.isolated / n},
                              {"isolation_ceiling", sum.isolable / n},
                              {"held_smallest_detected", held_smallest},
                              {"isolable", sum.isolable},
                              {"isolated_of_isolable", sum.isolated_of_isolable},
                              {"detected_by_hold", sum.detected_by_hold},
                              {"hold_change_threshold", c.hold_threshold},
                              {"hold_settle_s", c.hold_settle_s}, {"hold_reference_s", c.hold_reference_s},
                              {"hold_calibration_s", c.hold_calibration_s}, {"isolation_window_s", c.isolation_window_s}, {"false_alarm_run_with_holds", c.free_run_holds},
                              {"detection_rate_over_1p5x_threshold", sum.detectable ? static_cast<double>(sum.detectable_found) / sum.detectable : 1.0},
                              {"over_1p5x_threshold", {{"collisions", sum.detectable}, {"detected", sum.detectable_found}}},
                              {"over_1p5x_moving_threshold", {{"collisions", sum.detectable_moving}, {"detected", sum.detectable_moving_found}}},
                              {"delay_min", sum.delay_min}, {"delay_median", sum.delay_median}, {"delay_max", sum.delay_max},
                              {"after_threshold_crossed", {{"detections", sum.after_crossing},
                                                           {"within_10ms", sum.after_crossing_within_10ms},
                                                           {"median", sum.after_crossing_median},
                                                           {"p95", sum.after_crossing_p95},
                                                           {"max", sum.after_crossing_max}}},
                              {"false_alarms_per_hour", per_hour}, {"false_alarm_run_s", free_s}, {"false_alarm_times", alarm_times}, {"threshold", c.thresholds},
                              {"threshold_low_speed_extra", c.low_speed_extra}, {"threshold_low_speed_width", c.low_speed_width},
                              {"calibration_s", c.calibration_s}, {"margin", o->margin}, {"rate", c.rate_hz}, {"scalar", c.scalar},
                              {"observer", to_string(c.gains.kind)}, {"gains", {c.gains.k1, c.gains.k2, c.gains.k3}}};
              std::ofstream(o->json) << j.dump(2) << '\n';
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

}  // namespace jg::cli
