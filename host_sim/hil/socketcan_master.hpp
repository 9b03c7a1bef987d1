// The master over SocketCAN, as an estimator for the closed-loop evaluation: each cycle it
// sends the plant's samples and the sync to the `jointguard node` processes and waits for
// their status frames (lock-step: the simulated plant waits for the drives, so the run is
// deterministic whatever the host's scheduling).
#pragma once

#include <memory>
#include <string>

#include "eval/estimator.hpp"
#include "hil/bus_master.hpp"

namespace jg::hil {

struct SocketCanMasterConfig {
  std::string interface = "vcan0";
  std::size_t joints = 3;
  int cycle_timeout_ms = 2000;    ///< a drive silent this long fails the run (names the joints)
  int startup_timeout_ms = 20000;  ///< waiting for every drive's first status
};

class SocketCanMaster : public eval::Estimator {
 public:
  [[nodiscard]] virtual const std::vector<NodeEvent>& events() const = 0;
  [[nodiscard]] virtual MasterCounters counters() const = 0;
};

/// Throws std::runtime_error naming the interface when it cannot be opened.
std::unique_ptr<SocketCanMaster> make_socketcan_master(const SocketCanMasterConfig& c);

}  // namespace jg::hil
