// libFuzzer target: any bytes as any frame of the protocol must decode to an error code or to a
// message, never crash, read out of bounds or invoke undefined behaviour.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "jointguard/protocol/frames.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::uint8_t buf[64] = {};
  const std::size_t n = size < 64 ? size : 64;
  std::memcpy(buf, data, n);
  const auto length = static_cast<std::uint8_t>(n);
  std::uint8_t seq = 0;
  jg::OutwardMessage<float> of{};
  jg::OutwardMessage<jg::q16> oq{};
  jg::InwardMessage<float> inf{};
  jg::InwardMessage<jg::q16> inq{};
  (void)jg::protocol::decode_outward(buf, length, of, seq);
  (void)jg::protocol::decode_outward(buf, length, oq, seq);
  (void)jg::protocol::decode_inward(buf, length, inf, seq);
  (void)jg::protocol::decode_inward(buf, length, inq, seq);
  jg::protocol::SensorMessage<float> sf{};
  jg::protocol::SensorMessage<jg::q16> sq{};
  jg::protocol::StatusMessage<float> stf{};
  jg::protocol::StatusMessage<jg::q16> stq{};
  std::uint32_t cycle = 0;
  (void)jg::protocol::decode_sensor(buf, length, sf, seq);
  (void)jg::protocol::decode_sensor(buf, length, sq, seq);
  (void)jg::protocol::decode_status(buf, length, stf, seq);
  (void)jg::protocol::decode_status(buf, length, stq, seq);
  (void)jg::protocol::decode_sync(buf, length, cycle);
  jg::protocol::SequenceTracker t;
  for (std::size_t i = 0; i < n; ++i) (void)t.accept(buf[i]);
  return 0;
}
