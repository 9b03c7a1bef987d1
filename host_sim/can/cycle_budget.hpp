// What one control cycle of the drives puts on the bus, and whether it fits the period: the
// frames of the protocol (firmware/include/jointguard/protocol/frames.hpp) at their fixed
// lengths and their worst-case wire time (frame_duration_s). A chain of n drives sends per
// cycle: the master's sync, n-1 outward and n-1 inward momentum frames (48 bytes each), n
// status frames and, in the host-in-the-loop layout only, n sensor frames from the plant.
#pragma once

#include <cstddef>

#include "can/sim_bus.hpp"
#include "jointguard/protocol/frames.hpp"

namespace jg::can {

struct CycleBudget {
  std::size_t frames = 0;
  double wire_s = 0.0;  ///< worst-case wire time of one cycle's frames [s]
  /// The highest control rate at which one cycle's frames fit its period [Hz].
  [[nodiscard]] double max_rate_hz() const { return wire_s > 0.0 ? 1.0 / wire_s : 0.0; }
};

/// One cycle of `joints` drives (reaction commands and collision events, sent on events
/// only, left out). `momentum_frame_length` [bytes, a valid CAN FD length]: the protocol's,
/// or another to weigh a shorter encoding of the same messages (16-bit fields: 24 bytes).
CycleBudget cycle_budget(std::size_t joints, const BusTiming& timing, bool sensors_over_can,
                         std::uint8_t momentum_frame_length = protocol::kMomentumFrameLength);

}  // namespace jg::can
