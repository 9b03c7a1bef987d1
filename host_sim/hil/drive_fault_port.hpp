// The faults a drive injects on its own side of a SocketCAN bus (`jointguard node --fault`,
// docs/can.md "Faults"): its frames held back (late) and its controller bus-off. The
// fault clock is the bus's: plant time = the cycle counter of the last sync heard x the
// period, so a window means the same cycles as on the simulated bus whatever the host's
// speed. A port over SocketCanPort satisfying the HAL contract (the drive binds to it
// statically, as to the plain port).
#pragma once

#include <cstdint>
#include <deque>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "can/fault_spec.hpp"
#include "jointguard/hal/socketcan.hpp"
#include "jointguard/protocol/frames.hpp"

namespace jg::hil {

struct DriveFaultCounters {
  std::uint64_t frames_delayed = 0;   ///< frames held back by `late`
  std::uint64_t refused_bus_off = 0;  ///< sends the bus-off controller refused
  std::uint64_t bus_off_entries = 0, bus_off_recoveries = 0;
};

/// Checks node-side specs: only `late` and `bus-off`, targeting this drive or none.
inline void check_drive_faults(const std::vector<FaultSpec>& faults, int joint) {
  for (const FaultSpec& f : faults) {
    if (f.kind != FaultKind::late && f.kind != FaultKind::bus_off) {
      throw std::invalid_argument("--fault '" + f.text + "': a drive injects only late and bus-off on its own side (the other kinds: `jointguard plant --fault`)");
    }
    if (f.has_id || (f.joint != 0 && f.joint != joint)) {
      throw std::invalid_argument("--fault '" + f.text + "': a drive delays or stops only its own frames: target none or " + std::to_string(joint));
    }
  }
}

class DriveFaultPort {
 public:
  /// `period_s`: the plant period (sync counter -> plant time); `late` holds a frame for
  /// kLateDelayS of bus time, i.e. until the sync that many periods later.
  DriveFaultPort(const std::string& iface, std::vector<FaultSpec> faults, double period_s)
      : port_(iface), faults_(std::move(faults)), period_s_(period_s),
        delay_cycles_(static_cast<std::uint32_t>(kLateDelayS / period_s + 0.5)) {}

  hal::CanStatus send(const hal::CanFrame& f) noexcept {
    if (port_.error_state() == hal::CanErrorState::bus_off) {
      ++counters_.refused_bus_off;  // the backend refuses it too: counted here as the fault's effect
      return port_.send(f);
    }
    if (active(FaultKind::late) && synced_) {
      held_.emplace_back(cycle_ + delay_cycles_, f);
      ++counters_.frames_delayed;
      return hal::CanStatus::ok;  // queued in the controller; it goes out late
    }
    return port_.send(f);
  }
  bool receive(hal::CanFrame& out) noexcept {
    if (!port_.receive(out)) return false;
    std::uint32_t cycle = 0;
    if (!out.extended && out.id == protocol::kSyncId &&
        protocol::decode_sync(static_cast<const std::uint8_t*>(out.data), out.length, cycle) == protocol::FrameError::ok) {
      on_sync(cycle);
    }
    return true;
  }
  [[nodiscard]] hal::CanErrorState error_state() const noexcept { return port_.error_state(); }
  void set_filters(const hal::CanFilter* filters, std::size_t n) const noexcept { port_.set_filters(filters, n); }
  [[nodiscard]] bool wait_readable(std::int64_t timeout_us) const noexcept { return port_.wait_readable(timeout_us); }
  [[nodiscard]] const DriveFaultCounters& fault_counters() const noexcept { return counters_; }
  [[nodiscard]] const hal::SocketCanPort& socket() const noexcept { return port_; }

 private:
  [[nodiscard]] double time_s() const { return static_cast<double>(cycle_) * period_s_; }
  [[nodiscard]] bool active(FaultKind kind) const {
    for (const FaultSpec& f : faults_) {
      if (f.kind == kind && f.active(time_s())) return true;
    }
    return false;
  }
  /// The bus clock advanced: held frames due by now go out (before the drive sees this
  /// sync), the controller goes bus-off when a window opens and restarts when it closes.
  void on_sync(std::uint32_t cycle) {
    cycle_ = cycle;
    synced_ = true;
    while (!held_.empty() && held_.front().first <= cycle_) {
      (void)port_.send(held_.front().second);
      held_.pop_front();
    }
    const bool off = active(FaultKind::bus_off);
    const bool is_off = port_.error_state() == hal::CanErrorState::bus_off;
    if (off && !is_off) {
      port_.inject_controller_state(hal::CanErrorState::bus_off);
      ++counters_.bus_off_entries;
    } else if (!off && is_off && bus_off_by_fault()) {
      port_.inject_controller_state(hal::CanErrorState::error_active);
      ++counters_.bus_off_recoveries;
    }
  }
  [[nodiscard]] bool bus_off_by_fault() const { return counters_.bus_off_entries > counters_.bus_off_recoveries; }

  hal::SocketCanPort port_;
  std::vector<FaultSpec> faults_;
  double period_s_;
  std::uint32_t delay_cycles_;
  std::uint32_t cycle_ = 0;
  bool synced_ = false;
  std::deque<std::pair<std::uint32_t, hal::CanFrame>> held_;
  DriveFaultCounters counters_{};
};

static_assert(hal::is_can_port_v<DriveFaultPort>, "DriveFaultPort satisfies the CAN port contract");

}  // namespace jg::hil
