#include "can/cycle_budget.hpp"

namespace jg::can {

CycleBudget cycle_budget(std::size_t joints, const BusTiming& timing, bool sensors_over_can, std::uint8_t momentum_frame_length) {
  CycleBudget b;
  if (joints == 0) return b;
  const auto add = [&](std::size_t count, std::uint8_t length) {
    hal::CanFrame f{};
    f.fd = true;
    f.length = length;
    b.frames += count;
    b.wire_s += static_cast<double>(count) * frame_duration_s(f, timing);
  };
  add(1, protocol::kSyncFrameLength);
  add(2 * (joints - 1), momentum_frame_length);
  add(joints, protocol::kStatusFrameLength);
  if (sensors_over_can) add(joints, protocol::kSensorFrameLength);
  return b;
}

}  // namespace jg::can
