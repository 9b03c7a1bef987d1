// `jointguard evaluate`: the paper's experiments or a campaign on the simulated arm with
// the firmware core in the loop; JSON per ../shared/CONTRACT.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/evaluate_output.hpp"
#include "cli/progress.hpp"
#include "eval/experiments.hpp"
#include "eval/parallel.hpp"
#include "io/yaml_fields.hpp"
#include "sim/scenario.hpp"

#include <filesystem>

namespace jg::cli {
namespace {
struct EvaluateOptions {
  std::string scenario = "paper", model = JG_DEFAULT_MODEL, json, scalar = "float", reaction = "stop";
  double rate = 1000.0, margin = 0.5, free_run_s = 0.0, calibration_s = 3600.0;
  int count = 50, debounce = 1, jobs = 0;
  std::string shard;
  unsigned long long seed = 1;
  ObserverOptions observer;
  robot::LoadOptions model_options;
};

Reaction reaction_of(const std::string& s) {
  if (s == "none") return Reaction::none;
  if (s == "zero_gravity") return Reaction::zero_gravity;
  return Reaction::stop;
}

}  // namespace

Command add_evaluate(CLI::App& app) {
  auto o = std::make_shared<EvaluateOptions>();
  auto* cmd = app.add_subcommand("evaluate",
                                 "Run the paper's three collisions (paper), a random campaign (campaign) or a scenario file\n"
                                 "on the simulated arm with the firmware core in the loop. Friction is identified from an\n"
                                 "excitation run and thresholds calibrated on collision-free motion first.\n"
                                 "Example: jointguard evaluate --scenario paper --rate 125 --scalar q --json out/paper125.json");
  cmd->add_option("--scenario", o->scenario, "paper, campaign or a scenario file (YAML)")->capture_default_str();
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->capture_default_str()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--rate", o->rate, "Control and observer rate [Hz]")->capture_default_str()->check(CLI::Range(50.0, 20000.0));
  cmd->add_option("--scalar", o->scalar, "Firmware scalar")->check(CLI::IsMember({"float", "q"}))->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of noise, campaign and motion")->capture_default_str();
  cmd->add_option("--count", o->count, "Collisions in a campaign")->capture_default_str()->check(CLI::Range(1, 100000));
  cmd->add_option("--free-run", o->free_run_s, "Collision-free run for false alarms [s] (default 120 s paper, 600 s campaign)");
  cmd->add_option("--calibration", o->calibration_s, "Collision-free run the thresholds are calibrated on [s]")->capture_default_str()->check(CLI::Range(10.0, 86400.0));
  cmd->add_option("--margin", o->margin, "Threshold margin above the observed band [N·m]")->capture_default_str()->check(finite_range(0.0, 1000.0));
  cmd->add_option("--debounce", o->debounce, "Cycles over threshold before a detection")->capture_default_str()->check(CLI::Range(1, 50));
  cmd->add_option("--reaction", o->reaction, "Reaction on detection")->check(CLI::IsMember({"none", "stop", "zero_gravity"}))->capture_default_str();
  cmd->add_option("--json", o->json, "Write the runs and summary here (contract format; with --shard: this part)");
  cmd->add_option("--jobs", o->jobs, "Threads for the independent runs (0: all cores); the output does not depend on it")
      ->capture_default_str()->check(CLI::Range(0, 1024));
  cmd->add_option("--shard", o->shard, "K/N: run only the K-th of N disjoint parts and write a partial JSON "
                                       "for `jointguard merge` (every part prepares the same thresholds)")
      ->check([](const std::string& text) {
        int k = 0, n = 0;
        try {
          parse_shard(text, k, n);
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
        return std::string();
      });
  o->observer.add_to(cmd);
  return {cmd, [o]() {
            eval::ExperimentConfig c;
            std::string model_path = o->model;
            std::unique_ptr<sim::Scenario> scenario;
            if (o->scenario != "paper" && o->scenario != "campaign") {
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
            c.reaction = reaction_of(o->reaction);
            eval::RunSplit split;
            split.jobs = o->jobs == 0 ? eval::default_jobs() : o->jobs;
            if (!o->shard.empty()) parse_shard(o->shard, split.shard, split.shards);
            c.jobs = split.jobs;
            if (!o->shard.empty() && o->json.empty()) throw std::invalid_argument("--shard needs --json (the part's file)");
            const double free_s = o->free_run_s > 0.0 ? o->free_run_s : (o->scenario == "campaign" ? 600.0 : 120.0);
            Progress bar("evaluate");
            eval::prepare(c, o->margin, [&](double f) { bar.update(0.3 * f); });
            EvaluateFigures fig;
            std::size_t runs_total = 1;
            if (o->scenario == "paper") {
              fig.runs = eval::paper_experiments(c, false, split);
              runs_total = std::min<std::size_t>(3, c.model.joints.size());
            } else if (o->scenario == "campaign") {
              fig.runs = eval::campaign(c, o->count, {2, 3}, [&](double f) { bar.update(0.3 + 0.5 * f); }, split);
              runs_total = static_cast<std::size_t>(o->count);
            } else if (split.takes(0)) {
              auto est = eval::estimator_for(c);
              const eval::DetectionConfig d = eval::detection_for(c);
              fig.runs.push_back(eval::run_detection(scenario->setup, *est, d, scenario->setup.meta.scenario, false));
            }
            fig.free_run = eval::free_run_segments(c, free_s, split, [&](double f) { bar.update(0.8 + 0.2 * f); });
            fig.free_run_s = free_s;
            bar.finish();
            fig.config = {{"threshold", c.thresholds}, {"threshold_low_speed_extra", c.low_speed_extra},
                          {"threshold_low_speed_width", c.low_speed_width}, {"calibration_s", c.calibration_s},
                          {"margin", o->margin}, {"rate", c.rate_hz}, {"scalar", c.scalar},
                          {"observer", to_string(c.gains.kind)}, {"gains", {c.gains.k1, c.gains.k2, c.gains.k3}}};
            if (!o->shard.empty()) {
              const auto segments = static_cast<std::size_t>(std::max(1.0, std::ceil(free_s / eval::kFreeRunSegmentS - 1e-9)));
              const nlohmann::json identity = {{"scenario", o->scenario}, {"count", o->count}, {"seed", o->seed},
                                               {"model", c.model.name}, {"debounce", o->debounce}, {"reaction", o->reaction}};
              write_json_file(o->json, partial_json(fig, split.shard, split.shards, runs_total, segments, identity));
              std::printf("part %d/%d: %zu runs, %zu free-run segments; wrote %s (combine the parts with jointguard merge)\n",
                          split.shard, split.shards, fig.runs.size(), fig.free_run.size(), o->json.c_str());
              return 0;
            }
            print_figures(fig);
            if (!o->json.empty()) {
              write_json_file(o->json, evaluate_json(fig));
              std::printf("wrote %s\n", o->json.c_str());
            }
            return 0;
          }};
}

Command add_merge(CLI::App& app) {
  auto paths = std::make_shared<std::vector<std::string>>();
  auto json = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("merge",
                                 "Combine the partial JSON files of `evaluate --shard K/N` (one per shard) into the JSON\n"
                                 "of one run: the same bytes as the unsharded command writes.\n"
                                 "Example: jointguard merge out/part1.json out/part2.json --json out/campaign.json");
  cmd->add_option("parts", *paths, "The parts (every shard once)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--json", *json, "Write the combined JSON here")->required();
  return {cmd, [paths, json]() {
            const EvaluateFigures fig = merge_partials(*paths);
            print_figures(fig);
            write_json_file(*json, evaluate_json(fig));
            std::printf("merged %zu parts; wrote %s\n", paths->size(), json->c_str());
            return 0;
          }};
}

}  // namespace jg::cli
