// The invalid-sample marker of the host-in-the-loop sensor frame (0x06j): a field whose
// wire value is INT32_MIN carries no number. Q16.16 on the wire is symmetric
// (-INT32_MAX..INT32_MAX, encoding saturates there), so INT32_MIN never encodes a value; the
// plant's side writes it for a NaN (Q16.16 has none and would otherwise send 0), and the
// drive treats a sample with such a field as an input fault (the estimator's state is not
// touched, the status carries kStatusInputFault). Kept apart from frames.hpp: the frame
// layout is unchanged (byte 0 sequence, fields from byte 1, CRC after the fields).
#pragma once

#include <cstddef>
#include <cstdint>

#include "jointguard/protocol/frames.hpp"

namespace jg::protocol {

inline constexpr std::uint32_t kInvalidFieldWire = 0x80000000U;  ///< INT32_MIN, little-endian on the wire

/// True when none of the sensor frame's fields carries the invalid marker. `buf` holds a
/// frame that decode_sensor accepted (length and CRC checked).
[[nodiscard]] constexpr bool sensor_fields_valid(const std::uint8_t* buf) noexcept {
  for (std::size_t i = 0; i < kSensorFields; ++i) {
    const std::uint8_t* p = &buf[1U + 4U * i];
    const std::uint32_t u = static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8U) |
                            (static_cast<std::uint32_t>(p[2]) << 16U) | (static_cast<std::uint32_t>(p[3]) << 24U);
    if (u == kInvalidFieldWire) {
      return false;
    }
  }
  return true;
}

/// Sender side: marks field `field` (0 position, 1 velocity, 2 motor torque) of an encoded
/// sensor frame invalid and recomputes its CRC.
inline void mark_sensor_field_invalid(std::uint8_t* buf, std::size_t field) noexcept {
  std::uint8_t* p = &buf[1U + 4U * field];
  for (std::size_t b = 0; b < 4U; ++b) {
    p[b] = static_cast<std::uint8_t>(kInvalidFieldWire >> (8U * b));
  }
  const auto used = static_cast<std::uint8_t>(1U + 4U * kSensorFields);
  buf[used] = crc8_autosar(buf, used);
}

}  // namespace jg::protocol
