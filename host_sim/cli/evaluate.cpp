// `jointguard evaluate`: the paper's experiments or a campaign on the simulated arm with
// the firmware core in the loop; JSON per ../shared/CONTRACT.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "can/cycle_budget.hpp"
#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/evaluate_output.hpp"
#include "cli/progress.hpp"
#include "eval/distributed_estimator.hpp"
#include "eval/experiments.hpp"
#include "eval/firmware_estimator.hpp"
#include "eval/parallel.hpp"
#include "eval/pipeline.hpp"
#include "eval/safety_experiments.hpp"
#include "io/yaml_fields.hpp"
#include "safety/body_regions.hpp"
#include "sim/scenario.hpp"

#include <filesystem>

namespace jg::cli {
namespace {
struct EvaluateOptions {
  std::string scenario = "paper", model = JG_DEFAULT_MODEL, json, scalar = "float", reaction = "stop";
  double rate = 1000.0, margin = 0.5, free_run_s = 0.0, calibration_s = 3600.0, hold_calibration_s = 1200.0;
  double hold_settle_s = 0.15, isolation_window_s = 0.0;
  double isolation_aligned_s = 0.001;
  bool isolation_standstill_level = false;
  bool no_hold = false, free_run_without_holds = false, no_residual = false;
  double residual_time_constant_s = 0.05;
  double contact_before_s = 0.005, contact_after_s = 0.020;
  bool surface_contacts = false, surface_prior = false, point_over_contact = false, observed_force = false, contact_link_from_isolation = true;
  double contact_force_after_s = 0.0, contact_prior_friction = 0.5;
  int count = 50, debounce = 1, jobs = 0;
  double speed = 0.8;
  bool sweep = false;
  double contact_area_cm2 = 1.0;
  std::vector<std::string> regions;  ///< safety: only these (empty: all)
  std::string kind;                  ///< safety: free or clamp only (empty: both)
  bool compare_bus = false;
  std::string shard, compare_scalar, plant_friction, plant_file, friction;
  unsigned long long seed = 1;
  ObserverOptions observer;
  robot::LoadOptions model_options;
};

Reaction reaction_of(const std::string& s) {
  if (s == "none") return Reaction::none;
  if (s == "zero_gravity") return Reaction::zero_gravity;
  if (s == "retreat") return Reaction::retreat;
  if (s == "reflex") return Reaction::reflex;
  return Reaction::stop;
}

nlohmann::json outcome_json(const safety::ContactOutcome& out) {
  nlohmann::json j = {{"peak_transient_n", out.peak_transient_n}, {"peak_quasi_static_n", out.peak_quasi_static_n},
                      {"limit_transient_n", out.limit_transient_n}, {"limit_quasi_static_n", out.limit_quasi_static_n},
                      {"force_within_limits", out.force_within}, {"within_limits", out.within_limits}};
  if (out.contact_area_cm2 > 0.0) {
    j["contact_area_cm2"] = out.contact_area_cm2;
    j["peak_transient_pressure_n_per_cm2"] = out.peak_transient_pressure;
    j["peak_quasi_static_pressure_n_per_cm2"] = out.peak_quasi_static_pressure;
    j["limit_transient_pressure_n_per_cm2"] = out.limit_transient_pressure;
    j["limit_quasi_static_pressure_n_per_cm2"] = out.limit_quasi_static_pressure;
    j["pressure_within_limits"] = out.pressure_within;
  }
  return j;
}

/// The cases of --scenario safety: every region, kind (or --kind) and reaction at --speed;
/// with --compare-bus every case again on the simulated bus (after the in-process ones).
std::vector<eval::SafetyCase> safety_cases(const EvaluateOptions& o, const std::vector<std::string>& regions,
                                           const std::vector<Reaction>& reactions) {
  std::vector<eval::SafetyCase> cases;
  for (const auto& region : regions) {
    for (const auto kind : {sim::CollisionProfile::free, sim::CollisionProfile::clamp}) {
      if (!o.kind.empty() && o.kind != sim::to_string(kind)) continue;
      for (const Reaction r : reactions) cases.push_back({region, kind, r, o.speed, false, o.contact_area_cm2});
    }
  }
  // --compare-bus: every case again with the joint drives' firmware on the simulated bus,
  // which run the reaction the master commands (node/joint_reaction.hpp).
  const std::size_t in_process = cases.size();
  if (o.compare_bus) {
    for (std::size_t i = 0; i < in_process; ++i) {
      eval::SafetyCase b = cases[i];
      b.on_bus = true;
      cases.push_back(b);
    }
  }
  return cases;
}

/// The in-process cases' table (and, with --compare-bus, each one's bus figures beside it)
/// into the console and j["safety"]["cases"].
void safety_table(const EvaluateOptions& o, const std::vector<eval::SafetyResult>& results, std::size_t in_process,
                  nlohmann::json& j) {
  std::printf("%-16s %-6s %-13s %9s %9s %8s %8s %8s %9s %8s %8s %s\n", "region", "kind", "reaction", "v [m/s]", "det [ms]",
              "F_tr [N]", "F_est[N]", "F_qs [N]", "limit", "p_tr", "p_qs", "verdict");
  for (std::size_t i = 0; i < in_process; ++i) {
    const auto& r = results[i];
    const auto& out = r.outcome;
    // #17.4: the contact force the estimator followed at its decided point (peak, N) beside
    // the simulated truth ("-": nothing detected, no estimate).
    const auto& est = r.run.contact;
    std::printf("%-16s %-6s %-13s %9.3f %9s %8.1f %8s %8.1f %4.0f/%-4.0f %8.1f %8.1f %s", r.c.region.c_str(), sim::to_string(r.c.kind),
                eval::to_string(r.c.reaction), r.contact_speed_m_s,
                r.detection_delay_s ? std::to_string(1e3 * *r.detection_delay_s).substr(0, 5).c_str() : "-",
                out.peak_transient_n, est ? std::to_string(est->peak_force_n).substr(0, 6).c_str() : "-", out.peak_quasi_static_n,
                out.limit_transient_n, out.limit_quasi_static_n, out.peak_transient_pressure, out.peak_quasi_static_pressure,
                out.within_limits ? "within" : "EXCEEDS");
    nlohmann::json cj = {{"region", r.c.region}, {"kind", sim::to_string(r.c.kind)}, {"reaction", eval::to_string(r.c.reaction)},
                         {"contact_speed_m_s", r.contact_speed_m_s},
                         {"detection_delay_s", r.detection_delay_s ? nlohmann::json(*r.detection_delay_s) : nlohmann::json(nullptr)},
                         {"link_isolated", r.run.link_isolated},
                         {"force_estimate_peak_n", est ? nlohmann::json(est->peak_force_n) : nlohmann::json(nullptr)},
                         {"force_estimate_at_decision_n", est ? nlohmann::json(est->estimate.force_n) : nlohmann::json(nullptr)},
                         {"link_estimated", est ? est->estimate.link : 0}};
    cj.update(outcome_json(out));
    if (o.compare_bus) {
      const auto& b = results[in_process + i];
      cj["bus"] = outcome_json(b.outcome);
      cj["bus"]["detection_delay_s"] = b.detection_delay_s ? nlohmann::json(*b.detection_delay_s) : nlohmann::json(nullptr);
      std::printf("   bus: %8.1f %8.1f %s", b.outcome.peak_transient_n, b.outcome.peak_quasi_static_n,
                  b.outcome.within_limits ? "within" : "EXCEEDS");
    }
    std::printf("\n");
    j["safety"]["cases"].push_back(cj);
  }
}

/// --sweep: the largest waist speed each region and reaction allow.
void safety_sweep(const eval::ExperimentConfig& c, const EvaluateOptions& o, const std::vector<std::string>& regions,
                  const std::vector<Reaction>& reactions, int jobs, nlohmann::json& j) {
  const std::vector<double> speeds = {0.1, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0, 1.25, 1.5, 2.0};
  const auto allowed = eval::allowed_speeds(c, regions, reactions, speeds, jobs, o.contact_area_cm2);
  j["safety"]["allowed_speed"] = nlohmann::json::array();
  j["safety"]["sweep_speeds_rad_s"] = speeds;
  std::printf("\nlargest waist speed [rad/s] (contact point [m/s]) within the limits, free and clamped:\n%-16s", "region");
  for (const Reaction r : reactions) std::printf(" %-18s", eval::to_string(r));
  std::printf("\n");
  for (std::size_t k = 0; k < allowed.size(); ++k) {
    const auto& a = allowed[k];
    if (k % reactions.size() == 0) std::printf("%-16s", a.region.c_str());
    std::printf(" %-18s", a.joint_speed_rad_s ? (std::to_string(*a.joint_speed_rad_s).substr(0, 4) + " (" +
                                                  std::to_string(*a.contact_speed_m_s).substr(0, 4) + ")").c_str()
                                               : "below 0.1");
    if (k % reactions.size() == reactions.size() - 1) std::printf("\n");
    j["safety"]["allowed_speed"].push_back(
        {{"region", a.region}, {"reaction", eval::to_string(a.reaction)},
         {"joint_speed_rad_s", a.joint_speed_rad_s ? nlohmann::json(*a.joint_speed_rad_s) : nlohmann::json(nullptr)},
         {"contact_speed_m_s", a.contact_speed_m_s ? nlohmann::json(*a.contact_speed_m_s) : nlohmann::json(nullptr)}});
  }
}

void write_safety(const eval::ExperimentConfig& c, const EvaluateOptions& o, int jobs) {
  const std::vector<Reaction> reactions = {Reaction::none, Reaction::stop, Reaction::zero_gravity, Reaction::retreat,
                                           Reaction::reflex};
  std::vector<std::string> regions = o.regions;
  if (regions.empty()) {
    for (const auto& r : safety::body_regions()) regions.emplace_back(r.name);
  }
  for (const auto& r : regions) (void)safety::body_region(r);  // an unknown name: the list of known ones
  std::vector<eval::SafetyCase> cases = safety_cases(o, regions, reactions);
  const std::size_t in_process = o.compare_bus ? cases.size() / 2 : cases.size();
  std::vector<eval::SafetyResult> results(cases.size());
  eval::parallel_for(cases.size(), jobs, [&](std::size_t i) { results[i] = eval::run_safety_case(c, cases[i]); });
  nlohmann::json j;
  j["safety"]["speed_rad_s"] = o.speed;
  j["safety"]["scalar"] = c.scalar;
  j["safety"]["cases"] = nlohmann::json::array();
  safety_table(o, results, in_process, j);
  if (o.sweep) safety_sweep(c, o, regions, reactions, jobs, j);
  j["safety"]["model"] = c.model.name;
  j["safety"]["source"] = "ISO/TS 15066:2016 Annex A, Tables A.2 and A.3 (as commonly quoted; check against your copy)";
  if (!o.json.empty()) {
    write_json_file(o.json, j);
    std::printf("wrote %s\n", o.json.c_str());
  }
}
/// evaluate --friction: the file's LuGre per joint as the estimator's friction, checked as
/// calibrate checks it (one entry per model joint; each fits every firmware scalar the run
/// uses at its rate), so a file the run cannot use stops it before any work (exit 1).
void use_friction_file(eval::ExperimentConfig& c, const std::string& path, const std::vector<std::string>& scalars) {
  c.friction = eval::read_friction_json_for_model(path, c.model.joints.size());
  std::vector<int> ids(c.friction.size());
  for (std::size_t j = 0; j < ids.size(); ++j) ids[j] = static_cast<int>(j + 1);
  for (const auto& scalar : scalars) {
    if (!scalar.empty()) eval::check_friction_fits(path, c.friction, ids, 1.0 / c.rate_hz, scalar);
  }
  c.friction_given = true;
  report_input_identity("friction", path);
}

/// --shard's conditions, before any work (exit 2 when one fails, else 0).
int check_shard(const EvaluateOptions& o) {
  if (!o.shard.empty() && o.json.empty()) {
    std::fprintf(stderr, "jointguard evaluate: error: --shard needs --json (the part's file)\n");
    return 2;
  }
  if (o.scenario == "safety" && !o.shard.empty()) {
    // Its verdicts come from one pass over every body region: there is no part to run.
    std::fprintf(stderr, "jointguard evaluate: error: --shard: --scenario safety is not split into parts; run it whole\n");
    return 2;
  }
  return 0;
}

/// The model (a scenario file's own, or --model), a scenario file, --plant-friction and
/// --plant into c; exit 2 for a plant given twice, else 0.
int load_inputs(const EvaluateOptions& o, eval::ExperimentConfig& c, std::string& model_path,
                std::unique_ptr<sim::Scenario>& scenario) {
  if (o.scenario != "paper" && o.scenario != "campaign" && o.scenario != "safety" && o.scenario != "held") {
    // The plant read as the estimator's model is (--base/--tip, --drive).
    scenario = std::make_unique<sim::Scenario>(sim::load_scenario(o.scenario, 0, false, "", o.model_options));
    model_path = (std::filesystem::path(o.scenario).parent_path() /
                  io::YamlFields::load_file(o.scenario).text("model")).string();
  }
  c.model = robot::load_robot(model_path, o.model_options);
  if (!o.plant_friction.empty()) {
    c.plant_friction = eval::read_friction_json(o.plant_friction);
    report_input_identity("plant friction", o.plant_friction);
  }
  if (!o.plant_file.empty()) {
    if (scenario) {
      std::fprintf(stderr, "jointguard evaluate: error: --plant: a scenario file names its plant file itself (its 'plant' key)\n");
      return 2;
    }
    auto spec = std::make_shared<sim::PlantSpec>(sim::load_plant_spec(o.plant_file, c.model.joints.size()));
    if (!spec->friction.empty() && !c.plant_friction.empty()) {
      std::fprintf(stderr, "jointguard evaluate: error: --plant-friction and a plant file with friction: give one\n");
      return 2;
    }
    c.plant_spec = std::move(spec);
  }
  return 0;
}

/// The run's settings from the options (the rate a scenario file's own), and --friction.
void apply_options(const EvaluateOptions& o, const sim::Scenario* scenario, eval::ExperimentConfig& c) {
  c.rate_hz = scenario ? scenario->setup.control_rate_hz : o.rate;
  if (!o.friction.empty()) use_friction_file(c, o.friction, {o.scalar, o.compare_scalar});
  c.scalar = o.scalar;
  c.seed = o.seed;
  c.gains = o.observer.to_gains(c.rate_hz);
  c.debounce_cycles = o.debounce;
  c.calibration_s = o.calibration_s;
  c.hold_calibration_s = o.no_hold ? 0.0 : o.hold_calibration_s;
  c.hold_settle_s = o.hold_settle_s;
  c.isolation_window_s = o.isolation_window_s;
  c.isolation_aligned_s = o.isolation_aligned_s;
  c.isolation_standstill_change = !o.isolation_standstill_level;
  c.contact_before_s = o.contact_before_s;
  c.contact_after_s = o.contact_after_s;
  c.campaign_surface_contacts = o.surface_contacts;
  c.contact_surface_prior = o.surface_prior;
  c.contact_point_over_the_contact = o.point_over_contact;
  c.contact_link_from_isolation = o.contact_link_from_isolation;
  c.contact_force_after_s = o.contact_force_after_s;
  c.contact_prior_friction = o.contact_prior_friction;
  c.contact_lag_correction = !o.observed_force;
  c.free_run_holds = !o.free_run_without_holds;
  c.residual_detector = !o.no_residual;
  c.residual_time_constant_s = o.residual_time_constant_s;
  c.compare_scalar = o.compare_scalar == o.scalar ? std::string() : o.compare_scalar;
  c.compare_on_bus = o.compare_bus && (o.scenario == "paper" || o.scenario == "campaign");
  c.reaction = reaction_of(o.reaction);
}

/// --compare-bus on paper/campaign: the drives' frames of one cycle must fit its period, or
/// the momentum terms arrive cycles late and the comparison measures a bus that cannot work.
int check_bus_budget(const eval::ExperimentConfig& c) {
  if (!c.compare_on_bus) return 0;
  const eval::DistributedConfig bus;
  const can::CycleBudget b = can::cycle_budget(c.model.joints.size(), bus.timing, false);
  const double period_s = 1.0 / c.rate_hz;
  if (b.wire_s <= period_s) {
    std::printf("simulated bus: %zu drives, %zu frames per cycle, %.3f ms of wire time (worst case, %.0f / %.0f Mbit/s) of "
                "the %.3f ms period\n",
                c.model.joints.size(), b.frames, 1e3 * b.wire_s, 1e-6 * bus.timing.nominal_bps, 1e-6 * bus.timing.data_bps,
                1e3 * period_s);
    return 0;
  }
  std::fprintf(stderr,
               "jointguard evaluate: error: --compare-bus: %zu drives put %zu frames, %.3f ms of wire time (worst case, CAN FD "
               "%.0f / %.0f Mbit/s), on the bus each cycle: more than the %.3f ms period at --rate %.0f, so the neighbours' "
               "momentum terms could not arrive every cycle. The bus fits this arm at --rate %.0f or below.\n",
               c.model.joints.size(), b.frames, 1e3 * b.wire_s, 1e-6 * bus.timing.nominal_bps, 1e-6 * bus.timing.data_bps,
               1e3 * period_s, c.rate_hz, std::floor(b.max_rate_hz()));
  return 2;
}

/// A scenario file's run; with a body region named in its collision, the ISO/TS 15066
/// outcome of the contact printed and added to the result (fig.extra["safety"]).
void run_scenario_file(const eval::ExperimentConfig& c, const EvaluateOptions& o, const sim::Scenario& scenario,
                       EvaluateFigures& fig) {
  auto est = eval::estimator_for(c);
  const eval::DetectionConfig d = eval::detection_for(c);
  fig.runs.push_back(eval::run_detection(scenario.setup, *est, d, scenario.setup.meta.scenario, false));
  const auto& events = scenario.setup.collisions;
  if (!events.empty() && !events.front().body_region.empty()) {
    // ISO/TS 15066: the force the body part felt, from the contact's onset.
    const auto& f = fig.runs.back().contact_force_n;
    const auto onset = std::find_if(f.begin(), f.end(), [](double x) { return x > 0.0; });
    const safety::BodyRegion& region = safety::body_region(events.front().body_region);
    const safety::ContactOutcome out =
        safety::assess(region, std::vector<double>(onset, f.end()), 1.0 / c.rate_hz, o.contact_area_cm2);
    std::printf("%s (%s contact), reaction %s: peak transient %.1f N (limit %.0f N), quasi-static %.1f N "
                "(limit %.0f N): %s\n",
                region.name, sim::to_string(events.front().profile), o.reaction.c_str(), out.peak_transient_n,
                region.transient_factor > 0.0 ? out.limit_transient_n : out.limit_quasi_static_n,
                out.peak_quasi_static_n, out.limit_quasi_static_n, out.within_limits ? "within the limits" : "EXCEEDS the limits");
    fig.extra["safety"] = outcome_json(out);
    fig.extra["safety"]["region"] = region.name;
    fig.extra["safety"]["kind"] = sim::to_string(events.front().profile);
    fig.extra["safety"]["reaction"] = o.reaction;
    if (out.contact_area_cm2 > 0.0) {
      std::printf("pressure on %.2f cm^2: transient %.1f N/cm^2, quasi-static %.1f N/cm^2 (limits %.0f/%.0f N/cm^2, %s)\n",
                  out.contact_area_cm2, out.peak_transient_pressure, out.peak_quasi_static_pressure,
                  region.transient_factor > 0.0 ? out.limit_transient_pressure : out.limit_quasi_static_pressure,
                  out.limit_quasi_static_pressure, region.pressure_area);
    }
  }
}

/// The runs of --scenario (paper, held, campaign or a file) into fig.runs; returns how many
/// the whole run has (the shards together).
std::size_t run_experiments(const eval::ExperimentConfig& c, const EvaluateOptions& o, const eval::RunSplit& split,
                            const sim::Scenario* scenario, Progress& bar, EvaluateFigures& fig) {
  std::size_t runs_total = 1;
  if (o.scenario == "paper") {
    fig.runs = eval::paper_experiments(c, false, split);
    runs_total = std::min<std::size_t>(3, c.model.joints.size());
  } else if (o.scenario == "held") {
    // A short fixed set: the first shard runs all of it, the others none.
    runs_total = 5 * c.model.joints.size() + 1;
    if (split.shard == 1) fig.runs = eval::held_experiments(c);
    for (std::size_t i = 0; i < fig.runs.size(); ++i) fig.runs[i].index = static_cast<int>(i);
  } else if (o.scenario == "campaign") {
    fig.runs = eval::campaign(c, o.count, eval::campaign_links(c.model.joints.size()),
                              [&](double f) { bar.update(0.3 + 0.5 * f); }, split);
    runs_total = static_cast<std::size_t>(o.count);
  } else if (split.takes(0)) {
    run_scenario_file(c, o, *scenario, fig);
  }
  return runs_total;
}

/// The settings every figure depends on, as the result's "config".
nlohmann::json config_json(const eval::ExperimentConfig& c, const EvaluateOptions& o) {
  return {{"threshold", c.thresholds}, {"threshold_low_speed_extra", c.low_speed_extra},
         {"threshold_low_speed_width", c.low_speed_width}, {"calibration_s", c.calibration_s},
         {"margin", o.margin}, {"rate", c.rate_hz}, {"scalar", c.scalar},
         {"observer", to_string(c.gains.kind)}, {"gains", {c.gains.k1, c.gains.k2, c.gains.k3}},
         {"hold_change_threshold", c.hold_threshold}, {"hold_settle_s", c.hold_settle_s},
         {"hold_reference_s", c.hold_reference_s}, {"hold_calibration_s", c.hold_calibration_s},
         {"isolation_window_s", c.isolation_window_s}, {"isolation_aligned_s", c.isolation_aligned_s},
         {"isolation_standstill_change", c.isolation_standstill_change}, {"false_alarm_run_with_holds", c.free_run_holds},
         {"compare_scalar", c.compare_scalar}, {"compare_bus", c.compare_on_bus}, {"residual_change_threshold", c.residual_threshold},
         {"residual_time_constant_s", c.residual_time_constant_s},
         {"contact_window_before_s", c.contact_before_s}, {"contact_window_after_s", c.contact_after_s},
         {"campaign_surface_contacts", c.campaign_surface_contacts}, {"contact_surface_prior", c.contact_surface_prior},
         {"contact_point_over_the_contact", c.contact_point_over_the_contact},
         {"contact_force_after_s", c.contact_force_after_s}, {"contact_lag_correction", c.contact_lag_correction},
         {"contact_link_from_isolation", c.contact_link_from_isolation},
         {"friction", c.friction_given ? "given (--friction)" : "identified from a simulated excitation"}};
}

/// The result: a shard's partial JSON, or the figures printed and the JSON written.
int write_result(const eval::ExperimentConfig& c, const EvaluateOptions& o, const eval::RunSplit& split,
                 const std::string& model_path, const EvaluateFigures& fig, std::size_t runs_total, double free_s) {
  // Every option that changes a figure, the inputs' content and the version: parts
  // made otherwise do not merge; the whole run and the merged parts carry the same.
  nlohmann::json identity = result_identity();
  identity["model"] = c.model.name;
  identity["model_sha256"] = file_sha256(model_path);
  if (!o.shard.empty()) {
    const auto segments = static_cast<std::size_t>(std::max(1.0, std::ceil(free_s / eval::kFreeRunSegmentS - 1e-9)));
    write_json_file(o.json, partial_json(fig, split.shard, split.shards, runs_total, segments, identity));
    std::printf("part %d/%d: %zu runs, %zu free-run segments; wrote %s (combine the parts with jointguard merge)\n",
                split.shard, split.shards, fig.runs.size(), fig.free_run.size(), o.json.c_str());
    return 0;
  }
  print_figures(fig);
  if (!o.json.empty()) {
    nlohmann::json out = evaluate_json(fig);
    out["identity"] = identity;
    write_json_file(o.json, out);
    std::printf("wrote %s\n", o.json.c_str());
  }
  return 0;
}

/// --scenario safety: the swing, the regions and contacts, the bus comparison.
void add_safety_options(CLI::App* cmd, EvaluateOptions* o) {
  cmd->add_option("--speed", o->speed, "safety: peak waist speed of the test swing [rad/s]")->capture_default_str()->check(finite_range(0.05, 3.0));
  cmd->add_flag("--sweep", o->sweep, "safety: also the largest speed each region and reaction allow");
  cmd->add_option("--contact-area", o->contact_area_cm2,
                  "safety and body-region scenarios: the arm's contact face [cm^2] for the pressures against ISO/TS 15066 "
                  "Table A.2 (0: forces only)")
      ->capture_default_str()
      ->check(finite_range(0.0, 1000.0));
  cmd->add_option("--region", o->regions, "safety: only these body regions (repeatable; default all)");
  cmd->add_option("--kind", o->kind, "safety: only free or only clamp contacts")->check(CLI::IsMember({"free", "clamp"}));
  cmd->add_flag("--compare-bus", o->compare_bus,
                "safety: every case also with the joint drives' firmware on the simulated CAN FD bus running the reaction "
                "(JSON: cases[].bus); paper/campaign: the compared estimator (--compare-scalar, or --scalar) runs as the "
                "drives on the simulated bus, judged by the same detectors (JSON: runs[].bus, summary.bus)");
}

/// The arm: its model, the simulated plant and the estimator's friction.
void add_arm_options(CLI::App* cmd, EvaluateOptions* o) {
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->capture_default_str()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--plant-friction", o->plant_friction,
                  "The simulated arm's true friction: a friction JSON (identify --json), e.g. identified on the real arm "
                  "(default: the paper's Table 1, its joint 3 beyond the third)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--friction", o->friction,
                  "The estimator's friction: a friction JSON (identify --json, as calibrate and replay read it) used as is, "
                  "instead of identifying it from a simulated excitation run (default; the GA is most of a preparation's "
                  "cost on six or seven joints)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--plant", o->plant_file,
                  "paper/campaign/held/safety: the simulated arm's friction, sensors, controller and integrator from a plant file "
                  "(YAML, docs/scenarios.md; e.g. models/second3_plant.yaml), the hidden truth detection never reads "
                  "(default: the reference arm's)")
      ->check(CLI::ExistingFile);
}

/// The run: rate, scalar, seed, campaign size, run lengths, the holding detector's timing.
void add_run_options(CLI::App* cmd, EvaluateOptions* o) {
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
}

/// Isolation: which joints name the collided link.
void add_isolation_options(CLI::App* cmd, EvaluateOptions* o) {
  cmd->add_option("--isolation-window", o->isolation_window_s,
                  "Name the link from every joint taking part in the signature over this long from the detection [s] (0: the detection cycle)")
      ->capture_default_str()->check(CLI::Range(0.0, 0.1));
  cmd->add_option("--isolation-aligned", o->isolation_aligned_s,
                  "The cycles up to this long after the detection [s] whose estimate, with the motor torque aligned to its "
                  "momentum difference (the reaction's torque step taken out), joins the signature (0: the detection cycle alone)")
      ->capture_default_str()->check(CLI::Range(0.0, 0.1));
  cmd->add_flag("--isolation-standstill-level", o->isolation_standstill_level,
                "A joint at standstill joins the signature by the level of its estimate (the former rule) instead of its "
                "change from a 50 ms baseline (the level there is mostly the friction it came to rest with)");
}

/// The contact estimate: its windows, priors and where the force is taken.
void add_contact_options(CLI::App* cmd, EvaluateOptions* o) {
  cmd->add_option("--contact-window-before", o->contact_before_s,
                  "Contact estimate: torque estimates kept from before the detection [s]")
      ->capture_default_str()->check(CLI::Range(0.0, 0.1));
  cmd->add_option("--contact-window-after", o->contact_after_s,
                  "Contact estimate: the link and point decided this long after the detection [s]")
      ->capture_default_str()->check(CLI::Range(0.0, 0.2));
  cmd->add_flag("--surface-contacts", o->surface_contacts,
                "campaign: contacts on the links' cover (0.04 m radius) with the force within the friction cone of skin "
                "(mu 0.5) around the inward normal, instead of a point near the axis and a direction uniform on the sphere");
  cmd->add_flag("--contact-surface-prior", o->surface_prior,
                "Contact estimate: the force prior of a surface contact (across the link, within the friction cone) and the "
                "point reported on the link's cover");
  cmd->add_option("--contact-prior-friction", o->contact_prior_friction,
                  "Contact estimate with --contact-surface-prior: the friction coefficient of the cone it assumes")
      ->capture_default_str()->check(finite_range(0.0, 2.0));
  cmd->add_option("--contact-force-after", o->contact_force_after_s,
                  "Contact estimate: the point and the force estimated this long after the detection [s] (0: with the link, "
                  "--contact-window-after)")
      ->capture_default_str()->check(CLI::Range(0.0, 0.2));
  cmd->add_flag("--contact-observed-force", o->observed_force,
                "Contact estimate: the force as the observer sees it (no extrapolation over its lag)");
  cmd->add_flag("--contact-link-from-isolation,!--contact-own-link", o->contact_link_from_isolation,
                "Contact estimate: the point and the force on the link the isolation named (the default, as replay "
                "does); --contact-own-link: on the estimate's own link (the most proximal one whose fit leaves a "
                "residual within the noise)");
  cmd->add_flag("--contact-point-over-contact", o->point_over_contact,
                "Contact estimate: the point along the link from every clean cycle of the contact, not the decision's window");
}

/// The detectors beside the band and the false-alarm motion.
void add_detector_options(CLI::App* cmd, EvaluateOptions* o) {
  cmd->add_flag("--no-hold", o->no_hold, "Band detector alone (no change detection while a joint holds)");
  cmd->add_flag("--no-residual", o->no_residual, "No change detection against the estimate's slow baseline while moving");
  cmd->add_option("--residual-time-constant", o->residual_time_constant_s,
                  "Time constant of the residual detector's baseline [s]")
      ->capture_default_str()
      ->check(finite_range(0.005, 10.0));
  cmd->add_flag("--free-run-without-holds", o->free_run_without_holds,
                "False-alarm run on random moves with short dwells only (the motion before holds were added)");
}

/// Thresholds, reaction, output and how the work is split.
void add_output_options(CLI::App* cmd, EvaluateOptions* o) {
  cmd->add_option("--compare-scalar", o->compare_scalar,
                  "paper/campaign: also run this firmware scalar's estimator on the same measurements and thresholds "
                  "and count the collisions both detect on the same cycle")
      ->check(CLI::IsMember({"float", "q"}));
  cmd->add_option("--margin", o->margin, "Threshold margin above the observed band [N·m]")->capture_default_str()->check(finite_range(0.0, 1000.0));
  cmd->add_option("--debounce", o->debounce, "Cycles over threshold before a detection")->capture_default_str()->check(CLI::Range(1, 50));
  cmd->add_option("--reaction", o->reaction, "Reaction on detection")->check(CLI::IsMember({"none", "stop", "zero_gravity", "retreat", "reflex"}))->capture_default_str();
  cmd->add_option("--json", o->json, "Write the runs and summary here (contract format; with --shard: this part)")->check(output_file());
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
                  "paper, campaign, held (pushes of 0.5-3 N·m on each link of a held arm), safety (ISO/TS 15066 body "
                  "regions) or a scenario file (YAML)")
      ->capture_default_str();
  // In this order in --help.
  add_safety_options(cmd, o.get());
  add_arm_options(cmd, o.get());
  add_run_options(cmd, o.get());
  add_isolation_options(cmd, o.get());
  add_contact_options(cmd, o.get());
  add_detector_options(cmd, o.get());
  add_output_options(cmd, o.get());
  o->observer.add_to(cmd);
  return {cmd, [o, cmd]() {
            if (const int rc = check_shard(*o)) return rc;
            eval::ExperimentConfig c;
            std::string model_path = o->model;
            std::unique_ptr<sim::Scenario> scenario;
            if (const int rc = load_inputs(*o, c, model_path, scenario)) return rc;
            apply_options(*o, scenario.get(), c);
            if (const int rc = check_bus_budget(c)) return rc;
            eval::RunSplit split;
            split.jobs = o->jobs == 0 ? eval::default_jobs() : o->jobs;
            if (!o->shard.empty()) parse_shard(o->shard, split.shard, split.shards);
            c.jobs = split.jobs;

            const double free_s = o->free_run_s > 0.0 ? o->free_run_s : (o->scenario == "campaign" ? 600.0 : 120.0);
            Progress bar("evaluate");
            eval::prepare(c, o->margin, [&](double f) { bar.update(0.3 * f); });
            if (o->scenario == "safety") {
              bar.finish();
              write_safety(c, *o, split.jobs);
              return 0;
            }
            EvaluateFigures fig;
            const std::size_t runs_total = run_experiments(c, *o, split, scenario.get(), bar, fig);
            fig.free_run = eval::free_run_segments(c, free_s, split, [&](double f) { bar.update(0.8 + 0.2 * f); });
            fig.free_run_s = free_s;
            bar.finish();
            print_false_alarms(fig.free_run);
            fig.config = config_json(c, *o);
            return write_result(c, *o, split, model_path, fig, runs_total, free_s);
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
  cmd->add_option("--json", *json, "Write the combined JSON here")->check(output_file())->required();
  return {cmd, [paths, json]() {
            for (const auto& part : *paths) {
              std::error_code ec;
              if (std::filesystem::equivalent(part, *json, ec)) {
                std::fprintf(stderr, "jointguard merge: error: --json %s is one of the parts: it would be overwritten\n", json->c_str());
                return 2;
              }
            }
            const EvaluateFigures fig = merge_partials(*paths);
            for (const auto& part : *paths) report_input_identity("part", part);
            print_figures(fig);
            // The parts' identity (equal in all of them): the merged file is the bytes of the
            // unsharded run.
            nlohmann::json out = evaluate_json(fig);
            if (fig.identity.is_object()) out["identity"] = fig.identity;
            write_json_file(*json, out);
            std::printf("merged %zu parts; wrote %s\n", paths->size(), json->c_str());
            return 0;
          }};
}

}  // namespace jg::cli
