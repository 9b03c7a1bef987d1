// SocketCAN backend (Linux host): a raw CAN socket on one interface (vcan0, can0, ...),
// CAN FD enabled, kernel or hardware receive timestamps, controller error frames mapped to
// the HAL's error state. Satisfies the same port contract as the MCU and simulated ports, so
// the drive and master code bind to it statically. Host only: it throws on open failure
// (naming the interface and the system error) and never on the hot path. Linux headers
// stay in hal/socketcan/socketcan_port.cpp.
#pragma once

#include <cstdint>
#include <string>

#include "jointguard/hal/can.hpp"

namespace jg::hal {

struct SocketCanOptions {
  bool fd = true;              ///< CAN FD frames (needs an FD-capable interface: `ip link set vcan0 mtu 72`)
  bool receive_own = false;    ///< also receive the frames this socket sent
};

struct SocketCanCounters {
  std::uint64_t error_frames = 0;   ///< controller error frames received (not returned as data)
  std::uint64_t dropped_fd = 0;     ///< FD frames received on a socket opened without FD
  std::uint64_t send_errors = 0;    ///< sends refused by the kernel other than a full queue
};

class SocketCanPort {
 public:
  /// Throws std::runtime_error("socketcan vcan0: ...") when the interface cannot be used.
  explicit SocketCanPort(const std::string& interface, SocketCanOptions options = {});
  ~SocketCanPort();
  SocketCanPort(const SocketCanPort&) = delete;
  SocketCanPort& operator=(const SocketCanPort&) = delete;
  SocketCanPort(SocketCanPort&& other) noexcept;
  SocketCanPort& operator=(SocketCanPort&&) = delete;

  CanStatus send(const CanFrame& frame) noexcept;
  /// Next data frame, without blocking; error frames update error_state() and are skipped.
  bool receive(CanFrame& out) noexcept;
  [[nodiscard]] CanErrorState error_state() const noexcept { return state_; }
  /// Kernel acceptance filters (n = 0: accept all). Standard identifiers when match and
  /// mask fit 11 bits, extended otherwise.
  void set_filters(const CanFilter* filters, std::size_t n) const noexcept;  // the kernel holds the filters

  /// Blocks until a frame can be read or `timeout_us` passes (negative: forever).
  [[nodiscard]] bool wait_readable(std::int64_t timeout_us) const noexcept;
  [[nodiscard]] const SocketCanCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const std::string& interface() const noexcept { return interface_; }

  /// Fault injection (`jointguard node --fault bus-off:J@START:DURATION`, docs/can.md): a
  /// virtual CAN interface has no controller that could go bus-off, so this feeds the port
  /// the error frame a real adapter's driver delivers, through the same mapping as received
  /// ones: bus_off = CAN_ERR_BUSOFF (sends refused with CanStatus::bus_off, error_state()
  /// bus_off), error_active = CAN_ERR_RESTARTED (the controller restarted, e.g. by the
  /// driver's `restart-ms`), error_passive = CAN_ERR_CRTL with the passive bits.
  void inject_controller_state(CanErrorState state) noexcept;

 private:
  int fd_ = -1;
  std::string interface_;
  SocketCanOptions options_;
  CanErrorState state_ = CanErrorState::error_active;
  bool link_down_ = false;  ///< bus_off came from ENETDOWN (interface down), not from the controller
  SocketCanCounters counters_{};
  void on_error_frame(std::uint32_t can_id, const std::uint8_t* data) noexcept;
};

static_assert(is_can_port_v<SocketCanPort>, "SocketCanPort satisfies the CAN port contract");

/// Monotonic clock for host processes (CLOCK_MONOTONIC) [us].
struct MonotonicClock {
  // NOLINTNEXTLINE(readability-convert-member-functions-to-static): the clock contract is a const member
  [[nodiscard]] std::uint64_t now_us() const noexcept;
};
static_assert(is_clock_v<MonotonicClock>, "MonotonicClock satisfies the clock contract");

}  // namespace jg::hal
