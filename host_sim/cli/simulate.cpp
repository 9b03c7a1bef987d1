// `jointguard simulate SCENARIO --out REC.csv`: runs a scenario on the plant and writes a
// recording (CSV + JSON side file) in the contract's format.
#include <chrono>
#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/hil_common.hpp"
#include "cli/progress.hpp"
#include "io/recording.hpp"
#include "sim/scenario.hpp"

namespace jg::cli {
namespace {
struct SimulateOptions {
  std::string scenario;
  std::string out;
  unsigned long long seed = 0;
  double duration_s = 0.0;
  double plant_rate_hz = 0.0;
  HilOptions hil;
};
}  // namespace

Command add_simulate(CLI::App& app) {
  auto opt = std::make_shared<SimulateOptions>();
  auto* cmd = app.add_subcommand("simulate",
                                 "Run a scenario (YAML) on the simulated arm and write a recording.\n"
                                 "Example: jointguard simulate scenarios/paper_collision_shoulder.yaml --out out/shoulder.csv\n"
                                 "         jointguard simulate scenarios/paper_collision_shoulder.yaml --out out/shoulder_bus.csv --bus sim "
                                 "--friction out/friction.json --threshold out/threshold.json");
  cmd->add_option("scenario", opt->scenario, "Scenario file (YAML, see docs/scenarios.md)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", opt->out, "Recording to write (CSV; a .json side file is written beside it)")->check(recording_output_file())->required();
  auto* seed = cmd->add_option("--seed", opt->seed, "Override the scenario's seed");
  cmd->add_option("--duration", opt->duration_s, "Override the duration [s]")->check(CLI::Range(1e-6, 2592000.0));
  cmd->add_option("--plant-rate", opt->plant_rate_hz,
                  "Override the scenario's plant_rate_hz [Hz]: a robot file with stiffer friction or gears than the scenario "
                  "was written for (the divergence message names the joint)")
      ->check(CLI::Range(1.0, 1e6));
  cmd->add_option("--bus", opt->hil.bus,
                  "sim: run the joint drives' firmware in the loop on the simulated CAN FD bus (needs --threshold)")
      ->check(CLI::IsMember({"none", "sim"}))->capture_default_str();
  opt->hil.add_to(cmd, false);
  return {cmd, [opt, seed]() {
    // Another program's <stem>.json beside --out is refused before the work, not after it.
    io::check_side_file_writable(opt->out);
    if (opt->hil.bus == "sim") {
      HilOptions h = opt->hil;
      h.scenario = opt->scenario;
      h.out = opt->out;
      h.seed = opt->seed;
      h.has_seed = seed->count() > 0;
      h.duration_s = opt->duration_s;
      h.plant_rate_hz = opt->plant_rate_hz;
      return run_hil_command(h);
    }
    if (!opt->hil.faults.empty()) {
      std::fprintf(stderr, "error: --fault acts on the joint drives' bus: add --bus sim (and --threshold)\n");
      return 2;
    }
    // The robot file as the command line reads it (--base/--tip, --drive): for the plant too.
    sim::Scenario s = sim::load_scenario(opt->scenario, opt->seed, seed->count() > 0, opt->hil.model, opt->hil.model_options);
    for (const auto& a : s.effects.applied) std::printf("plant effect from the robot file: %s\n", a.c_str());
    for (const auto& a : s.effects.not_modelled) std::printf("plant effect not modelled: %s\n", a.c_str());
    if (opt->duration_s > 0.0) {
      s.setup.duration_s = opt->duration_s;
    }
    override_plant_rate(s, opt->plant_rate_hz, opt->scenario);
    Progress progress("simulate");
    const auto t0 = std::chrono::steady_clock::now();
    sim::SimulationResult r = sim::run_simulation(s.setup, {}, [&](double f) { progress.update(f); });
    progress.finish();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.recording.meta.identity_json = result_identity().dump();  // in the side file
    io::write_recording(opt->out, r.recording);
    std::printf("wrote %s: %zu samples, %.3f s at %.0f Hz, %zu collision(s), peak contact force %.1f N\n",
                opt->out.c_str(), r.recording.samples(), r.simulated_s, s.setup.control_rate_hz,
                s.setup.collisions.size(), r.peak_contact_force_n);
    std::printf("simulated %.1f s in %.2f s wall time (%.0fx real time)\n", r.simulated_s, wall,
                r.simulated_s / std::max(wall, 1e-9));
    return 0;
  }};
}

}  // namespace jg::cli
