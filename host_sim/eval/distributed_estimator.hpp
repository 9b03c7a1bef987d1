// The estimation as the joint drives run it: one JointDrive per joint on a simulated CAN FD
// bus, paced by the master's sync, with the plant's samples as sensor frames (as in the
// SocketCAN host-in-the-loop run) and each drive using its neighbours' previous-cycle
// messages. Same node code as on the MCU; the master collects the drives' status frames.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "can/bus_master.hpp"
#include "can/fault_spec.hpp"
#include "can/sim_bus.hpp"
#include "eval/estimator.hpp"
#include "eval/firmware_estimator.hpp"
#include "jointguard/node/joint_drive.hpp"

namespace jg::eval {

struct DistributedConfig {
  FirmwareEstimatorConfig estimator;
  /// 1 Mbit/s arbitration, 8 Mbit/s data: a 1 kHz cycle of three drives with sensor frames
  /// takes 0.76 ms of wire time (0.99 ms at 5 Mbit/s, too close to the period).
  can::BusTiming timing{1e6, 8e6};
  /// The plant's samples reach the drives as sensor frames on the bus (as in the SocketCAN
  /// host-in-the-loop run); false: each drive samples its own joint (JointDrive::set_sample,
  /// as on the arm, where encoder and current ADC are the drive's own), and the bus carries
  /// only what the arm's bus carries: sync, neighbour momentum terms, status (and reactions).
  bool sensors_over_can = true;
  can::FaultPlan faults{};
  /// Faults over windows of plant time (`--fault`): frame faults, babble and link down on
  /// the bus; bus-off, restart and NaN samples applied to the drives by the run.
  std::vector<hil::FaultSpec> fault_specs;
  /// The drives' own detector bands (empty: the drives never flag).
  std::vector<JointThreshold<double>> node_thresholds;
  int debounce_cycles = 1;
  /// The drives' holding detectors (empty: off), one per joint.
  std::vector<HoldChangeParams<double>> node_hold;
  std::uint8_t fault_cycles = 5;
  double retreat_s = 0.3, reflex_s = 0.3;  ///< the drives' reaction durations (joint_reaction.hpp)
};

struct DriveReport {
  DriveCounters drive{};
  NodeCounters node{};
  bool communication_fault = false, ready = false;
};

struct BusStatistics {
  std::size_t frames = 0;
  double busy_s = 0.0, elapsed_s = 0.0;
  hil::MasterCounters master{};
  std::size_t incomplete_cycles = 0;  ///< cycles whose status frames were not all in by the next cycle
  std::vector<hil::NodeEvent> events;
  std::vector<DriveReport> drives;
  std::vector<std::int64_t> first_comm_fault_cycle;  ///< per drive, as its status reported it (-1: never)
  std::vector<hil::FaultEpisode> fault_episodes;     ///< the master's and each drive's fault spans
};

class DistributedEstimator : public Estimator {
 public:
  [[nodiscard]] virtual BusStatistics statistics() const = 0;
  /// The simulated bus, for fault injection: port 0 is the master, port j drive j.
  virtual can::SimBus& bus() = 0;
};

/// scalar "float" or "q"; the bus runs one control period per step.
std::unique_ptr<DistributedEstimator> make_distributed_estimator(const DistributedConfig& c, const std::string& scalar);

}  // namespace jg::eval
