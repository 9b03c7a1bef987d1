// `jointguard node` and `jointguard plant`: the drives and the simulated arm as separate
// processes on a SocketCAN interface (host-in-the-loop), and the shared scenario runner
// behind `plant --bus sim` and `simulate --bus sim`.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/hil_common.hpp"
#include "eval/evaluate.hpp"
#include "eval/joint_params.hpp"
#include "eval/pipeline.hpp"
#include "eval/safety_experiments.hpp"
#include "hil/drive_fault_port.hpp"
#include "io/atomic_write.hpp"
#include "io/yaml_fields.hpp"
#include "jointguard/hal/socketcan.hpp"
#include "jointguard/node/joint_drive.hpp"

namespace jg::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int /*signal*/) { g_stop = true; }

struct NodeOptions {
  int joint = 1;
  std::string iface = "vcan0", model = JG_DEFAULT_MODEL, friction, threshold, scalar = "float", json;
  double rate = 1000.0, idle_exit_s = 0.0, startup_s = 30.0;
  int debounce = 1, fault_cycles = 5;
  std::vector<std::string> faults;  ///< --fault late|bus-off[:J]@START[:DURATION] (this drive's side)
  ObserverOptions observer;
  robot::LoadOptions model_options;
};

// run_node's stages: the estimator's parameters, the drive's loop, its counters at the end.

/// This joint's estimator parameters (friction, threshold band, holding detector) from the
/// files; fc: the estimator configuration they were made with.
template <class S>
JointEstimatorParams<S> node_params(const NodeOptions& o, const robot::RobotModel& model, std::size_t j,
                                    eval::FirmwareEstimatorConfig& fc) {
  const std::size_t n = model.joints.size();
  fc.model = model;
  fc.dt = 1.0 / o.rate;
  fc.observer = o.observer.to_gains(o.rate);
  if (!o.friction.empty()) {
    fc.friction = eval::read_friction_json(o.friction);
    report_input_identity("friction", o.friction);
  }
  fc.compensate_friction = !fc.friction.empty();
  std::vector<JointThreshold<double>> bands;
  eval::Thresholds thresholds;
  if (!o.threshold.empty()) {
    thresholds = eval::read_threshold_json(o.threshold);
    report_input_identity("threshold", o.threshold);
    bands = eval::threshold_bands(thresholds);
  }
  if (!bands.empty() && bands.size() != n) throw std::invalid_argument(o.threshold + ": one threshold per joint needed");
  // A threshold file with a holding detector: run it on the sensor frames' holding flag.
  std::optional<HoldChangeParams<double>> hold;
  if (thresholds.hold_change.size() == n) {
    fc.holding_velocity_deadband = eval::holding_deadband(model, o.rate);
    hold = eval::hold_params(thresholds.hold_change[j], thresholds.hold_settle_s, thresholds.hold_reference_s, fc.dt);
  }
  const JointEstimatorParams<S> p =
      eval::joint_params<S>(fc, j, bands.empty() ? nullptr : &bands[j], o.debounce, hold ? &*hold : nullptr);
  return p;
}

/// Polls the drive until SIGINT/SIGTERM or --idle-exit: it announces itself until the
/// master's first sync (none within --startup: an error), and prints its first collision flag.
template <class Drive>
void serve(const NodeOptions& o, Drive& drive, hil::DriveFaultPort& port) {
  const hal::MonotonicClock clock;
  const std::uint64_t t0 = clock.now_us();
  std::uint64_t last = t0;
  bool started = false, flagged_reported = false;
  std::uint64_t last_announce = 0;
  while (!g_stop) {
    if (!started && clock.now_us() - last_announce > 100000U) {
      drive.announce();  // until the master's first sync
      last_announce = clock.now_us();
    }
    if (port.wait_readable(20000) && drive.poll()) {
      started = true;
      last = clock.now_us();
      if (!flagged_reported && (drive.last_status().flags & protocol::kStatusCollision) != 0U) {
        std::printf("collision flagged at cycle %u: external torque %.3f N·m\n", drive.last_cycle(),
                    to_double(drive.last_status().external_torque));
        flagged_reported = true;
      }
    }
    const std::uint64_t now = clock.now_us();
    if (!started && now - t0 > static_cast<std::uint64_t>(o.startup_s * 1e6)) {
      throw std::runtime_error("no sync from the master on " + o.iface + " within " + std::to_string(static_cast<int>(o.startup_s)) +
                               " s (start `jointguard plant --iface " + o.iface + "`)");
    }
    if (started && o.idle_exit_s > 0.0 && now - last > static_cast<std::uint64_t>(o.idle_exit_s * 1e6)) break;
  }
}

/// The drive's and its port's counters at the end, printed and (--json) written.
template <class Drive>
void report_node(const NodeOptions& o, Drive& drive, hil::DriveFaultPort& port, bool any_faults) {
  const DriveCounters& c = drive.counters();
  const NodeCounters& nc = drive.node().counters();
  const hil::DriveFaultCounters& fault_counts = port.fault_counters();
  if (any_faults) {
    std::printf("joint %d faults: %llu frames delayed, bus-off %llu time(s), recovered %llu time(s), %llu sends refused while bus-off\n",
                o.joint, static_cast<unsigned long long>(fault_counts.frames_delayed), static_cast<unsigned long long>(fault_counts.bus_off_entries),
                static_cast<unsigned long long>(fault_counts.bus_off_recoveries), static_cast<unsigned long long>(fault_counts.refused_bus_off));
  }
  std::printf("joint %d: %u cycles, last cycle %u; rejected: sensor %u, sync %u, stale sync %u, length %u, crc %u, sequence %u; "
              "late %u; foreign %u; cycles without a fresh neighbour frame %u; communication fault %s\n",
              o.joint, c.cycles, drive.last_cycle(), c.sensor_rejected, c.sync_rejected, c.stale_syncs, nc.wrong_length, nc.bad_crc,
              nc.stale, nc.late, c.foreign, nc.missed_cycles, drive.node().communication_fault() ? "yes" : "no");
  if (!o.json.empty()) {
    nlohmann::json js{{"joint", o.joint}, {"cycles", c.cycles}, {"last_cycle", drive.last_cycle()},
                      {"flagged", (drive.last_status().flags & protocol::kStatusCollision) != 0U},
                      {"rejected", {{"sensor", c.sensor_rejected}, {"sync", c.sync_rejected}, {"stale_sync", c.stale_syncs},
                                    {"wrong_length", nc.wrong_length}, {"bad_crc", nc.bad_crc}, {"stale", nc.stale}, {"late", nc.late}}},
                      {"foreign", c.foreign}, {"missed_cycles", nc.missed_cycles}, {"communication_fault", drive.node().communication_fault()},
                      {"send_failures", c.send_failures},
                      // The reaction the master commanded (none: never commanded) and this drive's torque term.
                      {"reaction", {{"kind", eval::to_string(drive.reaction().kind)},
                                    {"cycles", drive.reaction().cycles},
                                    {"torque_nm", to_double(drive.reaction_torque())},
                                    {"commands_rejected", c.command_rejected}}},
                      {"faults", {{"frames_delayed", fault_counts.frames_delayed}, {"bus_off_entries", fault_counts.bus_off_entries},
                                  {"bus_off_recoveries", fault_counts.bus_off_recoveries}, {"refused_bus_off", fault_counts.refused_bus_off},
                                  {"bus_off_at_end", port.error_state() == hal::CanErrorState::bus_off}}}};
    write_json_file(o.json, js);  // every write checked: no exit 0 without the file; with the identity
  }
}

template <class S>
int run_node(const NodeOptions& o) {
  const robot::RobotModel model = robot::load_robot(o.model, o.model_options);
  const std::size_t n = model.joints.size();
  if (o.joint < 1 || static_cast<std::size_t>(o.joint) > n) {
    throw std::invalid_argument("--joint " + std::to_string(o.joint) + ": the robot " + o.model + " has joints 1.." + std::to_string(n));
  }
  const auto j = static_cast<std::size_t>(o.joint - 1);
  eval::FirmwareEstimatorConfig fc;
  const JointEstimatorParams<S> p = node_params<S>(o, model, j, fc);
  std::vector<hil::FaultSpec> faults;
  try {
    // Bad fault specs are usage errors (exit 2), refused before the drive opens its port.
    for (const auto& f : o.faults) faults.push_back(hil::parse_fault(f));
    hil::check_drive_faults(faults, o.joint);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "jointguard node: error: %s\n", e.what());
    return 2;
  }
  hil::DriveFaultPort port(o.iface, faults, 1.0 / o.rate);
  const DriveConfig dc{NodeConfig{static_cast<std::uint8_t>(o.joint), static_cast<std::uint8_t>(n), static_cast<std::uint8_t>(o.fault_cycles)},
                       true};
  JointDrive<S, hil::DriveFaultPort> drive(dc, p, port, eval::gravity_of<S>(model));
  drive.set_reaction_gains(reaction_gains<S>(fc.dt));  // the reaction the master commands (0.3 s retreat/reflex)
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::fprintf(stderr, "jointguard node: joint %d of %zu (%s) on %s, waiting for the master's sync\n", o.joint, n,
               is_q_v<S> ? "Q16.16" : "float", o.iface.c_str());
  serve(o, drive, port);
  report_node(o, drive, port, !faults.empty());
  return 0;
}

}  // namespace

Command add_node(CLI::App& app) {
  auto o = std::make_shared<NodeOptions>();
  auto* cmd = app.add_subcommand("node",
                                 "Run one joint drive's firmware node on a SocketCAN interface: it waits for the master's\n"
                                 "sync, exchanges momentum terms with its neighbours, estimates, detects and reports.\n"
                                 "Example: jointguard node --joint 2 --iface vcan0 --friction out/friction.json --threshold out/threshold.json");
  cmd->add_option("--joint", o->joint, "This drive's joint (1-based)")->required();
  cmd->add_option("--iface", o->iface, "SocketCAN interface (CAN FD capable: mtu 72)")->capture_default_str();
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->capture_default_str()->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  cmd->add_option("--friction", o->friction, "Identified LuGre (identify's JSON); none: no compensation")->check(CLI::ExistingFile);
  cmd->add_option("--threshold", o->threshold, "Calibrated thresholds (calibrate's JSON); none: never flags")->check(CLI::ExistingFile);
  cmd->add_option("--rate", o->rate, "Control and observer rate [Hz]")->capture_default_str()->check(CLI::Range(50.0, 20000.0));
  cmd->add_option("--scalar", o->scalar, "Firmware scalar")->check(CLI::IsMember({"float", "q"}))->capture_default_str();
  cmd->add_option("--debounce", o->debounce, "Cycles over threshold before the flag")->capture_default_str()->check(CLI::Range(1, 50));
  cmd->add_option("--fault-cycles", o->fault_cycles, "Cycles without a neighbour frame before the communication fault")
      ->capture_default_str()->check(CLI::Range(1, 255));
  cmd->add_option("--idle-exit", o->idle_exit_s, "Exit after this long without a sync once started [s] (0: run until SIGINT/SIGTERM)")
      ->capture_default_str();
  cmd->add_option("--startup-timeout", o->startup_s, "Fail when no sync arrives within this time [s]")->capture_default_str();
  cmd->add_option("--json", o->json, "Write the node's counters here on exit")->check(output_file());
  cmd->add_option("--fault", o->faults,
                  "Fault on this drive's side (repeatable; times in s of plant time = sync counter / rate): late[:J]@START[:DURATION] "
                  "(its frames go out 10 ms of bus time late), bus-off[:J]@START[:DURATION] (its controller off the bus, then "
                  "restarted). Example: --joint 2 --fault bus-off:2@0.5:0.2");
  o->observer.add_to(cmd);
  return {cmd, [o]() { return o->scalar == "q" ? run_node<q16>(*o) : run_node<float>(*o); }};
}

Command add_plant(CLI::App& app) {
  auto o = std::make_shared<HilOptions>();
  auto* cmd = app.add_subcommand("plant",
                                 "Run a scenario's simulated arm as the bus master: it sends the joints' sensor frames and\n"
                                 "the cycle sync on a SocketCAN interface, waits for every `jointguard node`'s status and\n"
                                 "reacts to detections; --bus sim runs the drives in-process on the simulated bus instead.\n"
                                 "Example: jointguard plant scenarios/paper_collision_shoulder.yaml --iface vcan0 --friction out/friction.json "
                                 "--threshold out/threshold.json --json out/hil.json");
  o->add_to(cmd, true);
  return {cmd, [o]() { return run_hil_command(*o); }};
}

}  // namespace jg::cli
