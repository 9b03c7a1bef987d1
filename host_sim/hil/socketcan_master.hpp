// The master over SocketCAN, as an estimator for the closed-loop evaluation: each cycle it
// sends the plant's samples and the sync to the `jointguard node` processes and waits for
// their status frames (lock-step: the simulated plant waits for the drives, so the run is
// deterministic whatever the host's scheduling).
#pragma once

#include <memory>
#include <string>

#include "can/bus_master.hpp"
#include "can/fault_spec.hpp"
#include "eval/estimator.hpp"

namespace jg::hil {

struct SocketCanMasterConfig {
  std::string interface = "vcan0";
  std::size_t joints = 3;
  /// How long a cycle waits for a drive that answered the previous cycle; then the cycle
  /// closes without it (counted missing: 5 such cycles in a row are a communication fault).
  /// A drive already silent is waited for a tenth of it (at least one plant period).
  int cycle_timeout_ms = 2000;
  int startup_timeout_ms = 20000;  ///< waiting for every drive's first status (fails the run, naming the joints)
  double period_s = 0.001;         ///< plant period: the wait for a drive already silent, and the fault clock
  /// Master-side faults (plant time): drop, corrupt and duplicate act on the master's own
  /// frames (sensor frames of a joint target, or every frame), link-down silences the
  /// master (sends and reads nothing), nan-sensor marks samples invalid, babble starts a
  /// flooding socket and arbitration emulation on the master's port. late and bus-off are
  /// the drives' (`jointguard node --fault`, DriveFaultPort), restart is the node process
  /// itself: refused by check_socketcan_faults.
  std::vector<FaultSpec> faults;
};

/// Throws std::invalid_argument for a fault the master cannot inject on SocketCAN.
void check_socketcan_faults(const std::vector<FaultSpec>& faults);

class SocketCanMaster : public eval::Estimator {
 public:
  [[nodiscard]] virtual const std::vector<NodeEvent>& events() const = 0;
  [[nodiscard]] virtual MasterCounters counters() const = 0;
  /// Per drive, the first cycle its status carried the communication fault (-1: never).
  [[nodiscard]] virtual std::vector<std::int64_t> first_comm_fault_cycle() const = 0;
  [[nodiscard]] virtual std::vector<FaultEpisode> fault_episodes() const = 0;
};

/// Throws std::runtime_error naming the interface when it cannot be opened.
std::unique_ptr<SocketCanMaster> make_socketcan_master(const SocketCanMasterConfig& c);

}  // namespace jg::hil
