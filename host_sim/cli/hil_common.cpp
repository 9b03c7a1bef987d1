#include "cli/hil_common.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <nlohmann/json.hpp>

#include "can/fault_spec.hpp"
#include "cli/common.hpp"
#include "cli/evaluate_output.hpp"
#include "hil/hil_run.hpp"
#include "hil/socketcan_master.hpp"
#include "io/atomic_write.hpp"
#include "io/recording.hpp"
#include "io/yaml_fields.hpp"

namespace jg::cli {

void HilOptions::add_to(CLI::App* cmd, bool plant) {
  if (plant) {
    cmd->add_option("scenario", scenario, "Scenario file (YAML, see docs/scenarios.md)")->required()->check(CLI::ExistingFile);
    auto* i = cmd->add_option("--iface", iface, "SocketCAN interface the `jointguard node` processes listen on");
    auto* b = cmd->add_option("--bus", bus, "sim: the drives in-process on the simulated CAN FD bus")->check(CLI::IsMember({"sim"}));
    i->excludes(b);
    cmd->add_option("--out", out, "Also write the recording (CSV + JSON side file)")->check(recording_output_file());
  }
  cmd->add_option("--model", model, "Robot file for the drives (default: the scenario's model); without --bus, the plant's robot file, "
                   "with the plant_effects `diagnose --model-out` wrote")->check(CLI::ExistingFile);
  add_model_selection(cmd, model_options);
  cmd->add_option("--friction", friction, "Identified LuGre (identify's JSON); none: no compensation")->check(CLI::ExistingFile);
  cmd->add_option("--threshold", threshold, "Calibrated thresholds (calibrate's JSON; required with a bus)")->check(CLI::ExistingFile);
  cmd->add_option("--scalar", scalar, "Drives' scalar on the in-process bus")->check(CLI::IsMember({"float", "q"}))->capture_default_str();
  cmd->add_option("--debounce", debounce, "Cycles over threshold before a detection")->capture_default_str()->check(CLI::Range(1, 50));
  cmd->add_option("--reaction", reaction, "Reaction on detection")->check(CLI::IsMember({"none", "stop", "zero_gravity", "retreat", "reflex"}))->capture_default_str();
  cmd->add_option("--timeout-ms", timeout_ms,
                  "SocketCAN: how long a cycle waits for a drive's status before closing without it (5 such cycles: "
                  "communication fault, the arm holds); a drive already silent is waited for a tenth of it")->capture_default_str()->check(CLI::Range(10, 600000));
  cmd->add_option("--fault", faults, hil::fault_syntax_help())
      ->check(CLI::Validator(
          [](std::string& v) {
            try {
              (void)hil::parse_fault(v);
            } catch (const std::invalid_argument& e) {
              return std::string(e.what());
            }
            return std::string();
          },
          "KIND[:TARGET]@START[:DURATION]"));
  cmd->add_option("--trace", trace, "Write the drives' estimates per cycle here (CSV: t, mu1..n)")->check(output_file());
  cmd->add_option("--json", json, "Write the run, the drives' events and the bus counters here")->check(output_file());
  observer.add_to(cmd);
}

namespace {

/// The drives' configuration: the model (the scenario's, or --model), friction, thresholds,
/// observer, scalar, debounce, reaction, interface.
hil::HilConfig hil_config(const HilOptions& o, const sim::Scenario& scenario) {
  hil::HilConfig c;
  const std::string model_path =
      !o.model.empty() ? o.model
                       : (std::filesystem::path(o.scenario).parent_path() / io::YamlFields::load_file(o.scenario).text("model")).string();
  c.model = robot::load_robot(model_path, o.model_options);
  if (!o.friction.empty()) c.friction = eval::read_friction_json(o.friction);
  c.thresholds = eval::read_threshold_json(o.threshold);
  if (!o.friction.empty()) report_input_identity("friction", o.friction);
  report_input_identity("threshold", o.threshold);
  c.gains = o.observer.to_gains(scenario.setup.control_rate_hz);
  c.scalar = o.scalar;
  c.debounce_cycles = o.debounce;
  c.reaction = o.reaction == "none"           ? Reaction::none
               : o.reaction == "zero_gravity" ? Reaction::zero_gravity
               : o.reaction == "retreat"      ? Reaction::retreat
               : o.reaction == "reflex"       ? Reaction::reflex
                                              : Reaction::stop;
  c.interface = o.iface;
  c.cycle_timeout_ms = o.timeout_ms;
  return c;
}

/// The run on the console: detection, contact estimate, faults, the drives' and the
/// master's counters, the simulated bus.
void print_hil_result(const sim::Scenario& scenario, const hil::HilResult& r) {
  const eval::RunResult& run = r.run;
  std::printf("%s: %zu cycles on %s\n", run.name.c_str(), run.trace.t.size(), r.bus.c_str());
  if (!scenario.setup.collisions.empty()) {
    std::printf("collision at %.3f s on link %d; ", run.t_collision, run.link_true);
  }
  if (run.t_detected) {
    std::printf("detected at %.3f s (delay %.1f ms), isolated link %d; drives flagged at %s s, link %d; peak force %.1f N\n",
                *run.t_detected, 1e3 * (*run.t_detected - run.t_collision), run.link_isolated,
                run.t_node_flagged ? std::to_string(*run.t_node_flagged).c_str() : "-", run.link_node_isolated, run.peak_force_n);
  } else {
    std::printf("no detection\n");
  }
  if (run.contact) {  // the master's contact estimate from the drives' estimates (eval/contact_window.hpp)
    const auto& e = run.contact->estimate;
    std::printf("contact estimate (at %.3f s): link %d, %.3f +- %.3f m along it, force %.1f +- %.1f N, peak %.1f N\n",
                run.contact->t, e.link, e.along_m, e.along_sigma_m, e.force_n, e.force_sigma_n, run.contact->peak_force_n);
  }
  if (run.t_comm_fault) std::printf("communication fault at %.3f s: the arm holds\n", *run.t_comm_fault);
  if (run.t_input_fault) std::printf("input fault at %.3f s: the arm holds\n", *run.t_input_fault);
  if (r.master.restarts > 0) std::printf("drives restarted mid-run: %llu\n", static_cast<unsigned long long>(r.master.restarts));
  for (const hil::FaultEpisode& e : r.fault_episodes) {
    const char* kind = e.kind == hil::FaultEpisode::Kind::input ? "input" : "communication";
    const std::string who = e.joint == 0 ? std::string("master") : "drive " + std::to_string(e.joint);
    const std::string to = e.to_cycle < 0 ? std::string("the end") : "cycle " + std::to_string(e.to_cycle);
    std::printf("%s fault (%s) from cycle %u to %s\n", kind, who.c_str(), e.from_cycle, to.c_str());
  }
  for (std::size_t j = 0; j < r.drives.size(); ++j) {
    const eval::DriveReport& d = r.drives[j];
    std::printf("drive %zu at the end: %s, %s; rejected: crc %u, sequence %u, late %u, sensor %u, sync %u\n", j + 1,
                d.communication_fault ? "communication fault" : "no communication fault", d.ready ? "ready" : "not ready", d.node.bad_crc,
                d.node.stale, d.node.late, d.drive.sensor_rejected, d.drive.sync_rejected);
  }
  for (const auto& e : r.events) std::printf("collision event from joint %d at cycle %u (%.3f N·m)\n", e.joint, e.cycle, e.external_torque);
  std::printf("master: %llu frames received, %llu rejected, %llu out of cycle, %llu foreign\n",
              static_cast<unsigned long long>(r.master.frames_received), static_cast<unsigned long long>(r.master.rejected),
              static_cast<unsigned long long>(r.master.out_of_cycle), static_cast<unsigned long long>(r.master.foreign));
  if (r.bus_frames > 0) {
    std::printf("simulated bus: %zu frames, load %.1f %%, %zu incomplete cycles\n", r.bus_frames,
                100.0 * r.bus_busy_s / std::max(1e-9, r.bus_elapsed_s),
                r.incomplete_cycles);
  }
}

/// The --json result: the run, the drives' events, the bus counters, the faults and their
/// episodes, the drives at the end, the largest estimate per joint.
nlohmann::json hil_json(const HilOptions& o, const hil::HilResult& r) {
  const eval::RunResult& run = r.run;
  nlohmann::json j;
  nlohmann::json jr{{"name", run.name}, {"t_collision", run.t_collision}, {"link_true", run.link_true},
                    {"link_isolated", run.link_isolated}, {"peak_force", run.peak_force_n}};
  jr["t_detected"] = run.t_detected ? nlohmann::json(*run.t_detected) : nlohmann::json(nullptr);
  jr["delay"] = run.t_detected ? nlohmann::json(*run.t_detected - run.t_collision) : nlohmann::json(nullptr);
  jr["t_drives_flagged"] = run.t_node_flagged ? nlohmann::json(*run.t_node_flagged) : nlohmann::json(nullptr);
  jr["link_drives_isolated"] = run.link_node_isolated;
  jr["t_comm_fault"] = run.t_comm_fault ? nlohmann::json(*run.t_comm_fault) : nlohmann::json(nullptr);
  jr["t_input_fault"] = run.t_input_fault ? nlohmann::json(*run.t_input_fault) : nlohmann::json(nullptr);
  jr["force_estimate"] = run.contact ? nlohmann::json(run.contact->estimate.force_n) : nlohmann::json(nullptr);
  jr["contact_estimate"] = run.contact ? contact_json(*run.contact) : nlohmann::json(nullptr);
  j["runs"] = nlohmann::json::array({jr});
  j["events"] = nlohmann::json::array();
  for (const auto& e : r.events) j["events"].push_back({{"joint", e.joint}, {"cycle", e.cycle}, {"external_torque", e.external_torque}});
  j["bus"] = {{"kind", r.bus}, {"cycles", run.trace.t.size()}, {"frames_received_by_master", r.master.frames_received},
              {"rejected", r.master.rejected}, {"out_of_cycle", r.master.out_of_cycle}, {"foreign", r.master.foreign},
              {"simulated_frames", r.bus_frames}, {"simulated_busy_s", r.bus_busy_s}, {"incomplete_cycles", r.incomplete_cycles},
              {"restarts", r.master.restarts}, {"invalid_samples_sent", r.master.invalid_samples},
              {"communication_fault_at_end", r.master_comm_fault_end}, {"input_fault_at_end", r.master_input_fault_end},
              {"first_comm_fault_cycle", r.first_comm_fault_cycle}};
  j["faults"] = o.faults;
  // Each span a fault was raised: joint 0 the master's view (what the arm reacts to), j
  // drive j's own status flag; to_cycle: first cycle clear again (null: raised at the end).
  j["fault_episodes"] = nlohmann::json::array();
  for (const hil::FaultEpisode& e : r.fault_episodes) {
    j["fault_episodes"].push_back({{"fault", e.kind == hil::FaultEpisode::Kind::input ? "input" : "communication"},
                                   {"joint", e.joint}, {"from_cycle", e.from_cycle},
                                   {"to_cycle", e.to_cycle < 0 ? nlohmann::json(nullptr) : nlohmann::json(e.to_cycle)}});
  }
  j["drives_end"] = nlohmann::json::array();
  for (std::size_t k = 0; k < r.drives.size(); ++k) {
    j["drives_end"].push_back({{"joint", k + 1}, {"communication_fault", r.drives[k].communication_fault}, {"ready", r.drives[k].ready}});
  }
  std::vector<double> mu_max;
  for (const auto& m : run.trace.mu) {
    double v = 0.0;
    for (const double x : m) v = std::max(v, std::fabs(x));
    mu_max.push_back(v);
  }
  j["external_torque_max"] = mu_max;
  return j;
}
}  // namespace

void override_plant_rate(sim::Scenario& scenario, double plant_rate_hz, const std::string& scenario_path) {
  if (plant_rate_hz <= 0.0) return;
  if (plant_rate_hz < scenario.setup.control_rate_hz) {
    char text[120];
    std::snprintf(text, sizeof text, "--plant-rate %g Hz is below ", plant_rate_hz);
    char rate[60];
    std::snprintf(rate, sizeof rate, "'s control_rate_hz %g Hz", scenario.setup.control_rate_hz);
    throw std::invalid_argument(text + scenario_path + rate);
  }
  scenario.setup.plant.plant_rate_hz = plant_rate_hz;
}

int run_hil_command(const HilOptions& o) {
  if (o.iface.empty() && o.bus != "sim") throw std::invalid_argument("say where the drives are: --iface IFACE (SocketCAN) or --bus sim");
  if (o.threshold.empty()) throw std::invalid_argument("--threshold is required: the drives need their detection bands (jointguard calibrate)");
  sim::Scenario scenario = sim::load_scenario(o.scenario, o.seed, o.has_seed);
  if (o.duration_s > 0.0) scenario.setup.duration_s = o.duration_s;
  override_plant_rate(scenario, o.plant_rate_hz, o.scenario);
  hil::HilConfig c = hil_config(o, scenario);
  try {
    // Bad fault specs are usage errors (exit 2), refused before anything runs.
    for (const auto& f : o.faults) c.faults.push_back(hil::parse_fault(f));
    hil::check_faults(c.faults, c.model.joints.size(), scenario.setup.duration_s);
    if (!c.interface.empty()) hil::check_socketcan_faults(c.faults);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  for (const auto& f : c.faults) {
    std::printf("fault injected: %s from %.3f s %s\n", hil::to_string(f.kind), f.start_s,
                std::isfinite(f.duration_s) ? ("for " + std::to_string(f.duration_s) + " s").c_str() : "to the end");
  }
  const hil::HilResult r = hil::run_hil(scenario, c);
  const eval::RunResult& run = r.run;
  print_hil_result(scenario, r);
  if (!o.trace.empty()) hil::write_trace_csv(o.trace, run.trace);
  if (!o.out.empty()) {
    io::Recording rec = run.recording;
    rec.meta.identity_json = result_identity().dump();  // in the side file
    io::write_recording(o.out, rec);
    std::printf("wrote %s\n", o.out.c_str());
  }
  if (!o.json.empty()) {
    write_json_file(o.json, hil_json(o, r));  // with the identity
    std::printf("wrote %s\n", o.json.c_str());
  }
  return 0;
}

}  // namespace jg::cli
