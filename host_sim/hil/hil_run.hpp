// A scenario with the drives in the loop, on the simulated CAN FD bus in-process
// (`jointguard simulate --bus sim`, `jointguard plant --bus sim`) or as separate
// `jointguard node` processes over SocketCAN (`jointguard plant --iface vcan0`). The plant
// and the arm's reaction are the same in both; only the bus differs, so both give the same
// estimates cycle for cycle.
#pragma once

#include <string>
#include <vector>

#include "can/bus_master.hpp"
#include "can/fault_spec.hpp"
#include "eval/distributed_estimator.hpp"
#include "eval/evaluate.hpp"
#include "eval/pipeline.hpp"
#include "sim/scenario.hpp"

namespace jg::hil {

struct HilConfig {
  robot::RobotModel model;
  std::vector<LuGreParams<double>> friction;  ///< identified (contract JSON); empty: no compensation
  eval::Thresholds thresholds;                ///< calibrated (contract JSON)
  ObserverGains gains{ObserverKind::first_order, 150.0, 0.0, 0.0};
  std::string scalar = "float";               ///< the drives' scalar (in-process bus only; processes choose their own)
  int debounce_cycles = 1;
  Reaction reaction = Reaction::stop;
  std::string interface;                      ///< empty: simulated bus in-process; else a SocketCAN interface
  int cycle_timeout_ms = 2000;
  std::vector<FaultSpec> faults;              ///< injected mid-run (`--fault`)
};

struct HilResult {
  eval::RunResult run;                        ///< with the per-cycle trace of the drives' estimates
  std::vector<NodeEvent> events;              ///< collision-event frames the master received
  MasterCounters master{};
  std::size_t bus_frames = 0;                 ///< simulated bus only
  double bus_busy_s = 0.0;                    ///< simulated bus only
  double bus_elapsed_s = 0.0;                 ///< simulated bus only
  std::size_t incomplete_cycles = 0;          ///< simulated bus only
  std::string bus;
  /// In-process only: each drive's counters and state at the end of the run.
  std::vector<eval::DriveReport> drives;
  bool master_comm_fault_end = false;         ///< the master's view at the end of the run
  bool master_input_fault_end = false;
  std::vector<std::int64_t> first_comm_fault_cycle;  ///< in-process: per drive, first cycle its status carried the fault
  std::vector<FaultEpisode> fault_episodes;          ///< spans a fault was raised (master's view, each drive's flags)
};

HilResult run_hil(const sim::Scenario& scenario, const HilConfig& c);

/// Writes the per-cycle estimates as CSV (t, mu1..n); the in-process and SocketCAN runs
/// of one scenario write identical files.
void write_trace_csv(const std::string& path, const eval::Trace& trace);

}  // namespace jg::hil
