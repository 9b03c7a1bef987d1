// The joint-to-joint CAN protocol: identifiers, payload layout, CRC and sequence checks.
// Pure functions over caller-owned byte buffers (the node wraps them in CAN frames).
//
// Identifiers (11 bit, lower wins arbitration): (kind << 4) | joint, joint 1..7:
//   0x00j collision event   0x010 cycle sync (master)   0x02j outward momentum message
//   0x03j inward momentum message   0x04j joint state   0x05j observer/detector status
//   0x06j sensor sample (host-in-the-loop only: the simulated plant stands in for the
//         drive's own encoder and current ADC)
// Every payload: byte 0 a sequence counter (wraps at 256), then fields as Q16.16
// little-endian int32 (factor 2^-16, SI units) or bytes, then CRC-8/AUTOSAR over the bytes
// before it; the rest of the frame zero. Lengths:
//   momentum messages CAN FD 48 B (9 or 10 fields)   sensor sample CAN FD 16 B (3 fields,
//   CRC, then a flags byte and its copy: see SensorMessage)
//   status and collision event 8 B: seq, external torque, flags, rejected, CRC
//   cycle sync 8 B: seq, cycle counter (uint32 LE), reserved (2 B), CRC
// (the 8-byte frames go as CAN FD with bit-rate switch on an FD bus)
// Values are saturated into the int32 range on encoding (never wrapped); a frame with a
// wrong identifier, length, CRC or a stale sequence never reaches the estimator.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "jointguard/dynamics/momentum_recursion.hpp"
#include "jointguard/numeric/qmath.hpp"

namespace jg::protocol {

enum class MessageKind : std::uint8_t {
  collision_event = 0x0,
  cycle_sync = 0x1,
  outward = 0x2,
  inward = 0x3,
  joint_state = 0x4,
  status = 0x5,
  sensor = 0x6,
};

/// Frame errors (stable numbers: they are counted and reported in status frames).
enum class FrameError : std::uint8_t {
  ok = 0,
  wrong_id = 1,
  wrong_length = 2,
  bad_crc = 3,
  stale_sequence = 4,
  bad_padding = 5,  ///< bytes after the CRC not zero: corrupted where the CRC does not look
};

inline constexpr std::uint8_t kMomentumFrameLength = 48;
inline constexpr std::uint8_t kOutwardFields = 9;
inline constexpr std::uint8_t kInwardFields = 10;
inline constexpr std::uint8_t kSensorFrameLength = 16;
inline constexpr std::uint8_t kSensorFields = 3;
/// Sensor sample flags (byte 14, repeated in byte 15; stable bits).
inline constexpr std::uint8_t kSensorHolding = 0x01U;  ///< the drive's controller holds a constant setpoint
inline constexpr std::uint8_t kStatusFrameLength = 8;
inline constexpr std::uint8_t kSyncFrameLength = 8;
/// The master's cycle sync (one per bus, joint field 0).
inline constexpr std::uint16_t kSyncId = 0x010;

[[nodiscard]] constexpr std::uint16_t frame_id(MessageKind kind, std::uint8_t joint) noexcept {
  return static_cast<std::uint16_t>((static_cast<std::uint16_t>(kind) << 4U) | (joint & 0x0FU));
}
[[nodiscard]] constexpr MessageKind kind_of(std::uint32_t id) noexcept { return static_cast<MessageKind>((id >> 4U) & 0x7FU); }
[[nodiscard]] constexpr std::uint8_t joint_of(std::uint32_t id) noexcept { return static_cast<std::uint8_t>(id & 0x0FU); }

/// CRC-8/AUTOSAR: polynomial 0x2F, initial 0xFF, final XOR 0xFF (check("123456789") = 0xDF).
[[nodiscard]] constexpr std::uint8_t crc8_autosar(const std::uint8_t* data, std::uint8_t length) noexcept {
  std::uint8_t crc = 0xFFU;
  for (std::uint8_t i = 0; i < length; ++i) {
    crc = static_cast<std::uint8_t>(crc ^ data[i]);
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x80U) != 0U ? static_cast<std::uint8_t>((crc << 1U) ^ 0x2FU) : static_cast<std::uint8_t>(crc << 1U);
    }
  }
  return static_cast<std::uint8_t>(crc ^ 0xFFU);
}

namespace detail {
template <class S>
constexpr std::int32_t to_wire(S v) noexcept {
  if constexpr (is_q_v<S>) {
    return q_cast<q16>(v).raw();
  } else {
    NumericStatus ignored{};  // saturates; non-finite values never reach here (node checks)
    return q16::from_float(static_cast<float>(v), ignored).raw();
  }
}
template <class S>
constexpr void from_wire(std::int32_t raw, S& out) noexcept {
  if constexpr (is_q_v<S>) {
    out = q_cast<S>(q16::from_raw(raw));
  } else {
    out = static_cast<S>(q16::from_raw(raw).to_float());
  }
}
constexpr void put_i32(std::uint8_t* p, std::int32_t v) noexcept {
  const auto u = static_cast<std::uint32_t>(v);
  for (unsigned i = 0; i < 4U; ++i) {
    p[i] = static_cast<std::uint8_t>(u >> (8U * i));
  }
}
constexpr std::int32_t get_i32(const std::uint8_t* p) noexcept {
  std::uint32_t u = 0;
  for (unsigned i = 0; i < 4U; ++i) {
    u |= static_cast<std::uint32_t>(p[i]) << (8U * i);
  }
  return static_cast<std::int32_t>(u);
}
/// CRC after the `used` payload bytes, zeros up to the frame length; returns the length.
constexpr std::uint8_t finish(std::uint8_t* buf, std::uint8_t used, std::uint8_t frame_length) noexcept {
  buf[used] = crc8_autosar(buf, used);
  for (auto i = static_cast<std::uint8_t>(used + 1U); i < frame_length; ++i) {
    buf[i] = 0U;
  }
  return frame_length;
}
constexpr FrameError check(const std::uint8_t* buf, std::uint8_t length, std::uint8_t used, std::uint8_t frame_length) noexcept {
  if (length != frame_length) {
    return FrameError::wrong_length;
  }
  if (crc8_autosar(buf, used) != buf[used]) {
    return FrameError::bad_crc;
  }
  for (auto i = static_cast<std::uint8_t>(used + 1U); i < frame_length; ++i) {
    if (buf[i] != 0U) {
      return FrameError::bad_padding;
    }
  }
  return FrameError::ok;
}
constexpr std::uint8_t field_bytes(std::uint8_t fields) noexcept { return static_cast<std::uint8_t>(1U + 4U * fields); }
}  // namespace detail

namespace detail {
template <class S>
constexpr std::uint8_t encode_fields(const S* values, std::uint8_t fields, std::uint8_t sequence, std::uint8_t* buf,
                                     std::uint8_t frame_length = kMomentumFrameLength) noexcept {
  buf[0] = sequence;
  for (std::uint8_t i = 0; i < fields; ++i) {
    put_i32(buf + 1 + (std::size_t{4} * i), to_wire(values[i]));
  }
  return finish(buf, field_bytes(fields), frame_length);
}
template <class S>
constexpr FrameError decode_fields(const std::uint8_t* buf, std::uint8_t length, std::uint8_t fields, S* values,
                                   std::uint8_t& sequence, std::uint8_t frame_length = kMomentumFrameLength) noexcept {
  if (const FrameError e = check(buf, length, field_bytes(fields), frame_length); e != FrameError::ok) {
    return e;
  }
  for (std::uint8_t i = 0; i < fields; ++i) {
    from_wire(get_i32(buf + 1 + (std::size_t{4} * i)), values[i]);
  }
  sequence = buf[0];
  return FrameError::ok;
}
}  // namespace detail

template <class S>
constexpr std::uint8_t encode_outward(const OutwardMessage<S>& m, std::uint8_t sequence, std::uint8_t* buf) noexcept {
  const std::array<S, kOutwardFields> v = {m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z,
                               m.origin_velocity.x,  m.origin_velocity.y,  m.origin_velocity.z,
                               m.gravity.x,          m.gravity.y,          m.gravity.z};
  return detail::encode_fields(v.data(), kOutwardFields, sequence, buf);
}

template <class S>
constexpr FrameError decode_outward(const std::uint8_t* buf, std::uint8_t length, OutwardMessage<S>& m,
                                    std::uint8_t& sequence) noexcept {
  std::array<S, kOutwardFields> v{};
  const FrameError e = detail::decode_fields(buf, length, kOutwardFields, v.data(), sequence);
  if (e == FrameError::ok) {
    m = {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, {v[6], v[7], v[8]}};
  }
  return e;
}

template <class S>
constexpr std::uint8_t encode_inward(const InwardMessage<S>& m, std::uint8_t sequence, std::uint8_t* buf) noexcept {
  const std::array<S, kInwardFields> v = {m.angular_momentum.x, m.angular_momentum.y, m.angular_momentum.z,
                              m.linear_momentum.x,  m.linear_momentum.y,  m.linear_momentum.z,
                              m.first_moment.x,     m.first_moment.y,     m.first_moment.z, m.mass};
  return detail::encode_fields(v.data(), kInwardFields, sequence, buf);
}

template <class S>
constexpr FrameError decode_inward(const std::uint8_t* buf, std::uint8_t length, InwardMessage<S>& m,
                                   std::uint8_t& sequence) noexcept {
  std::array<S, kInwardFields> v{};
  const FrameError e = detail::decode_fields(buf, length, kInwardFields, v.data(), sequence);
  if (e == FrameError::ok) {
    m = {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, {v[6], v[7], v[8]}, v[9]};
  }
  return e;
}

/// Host-in-the-loop sensor sample for joint j (plant -> node): what the drive's own encoder
/// and current ADC would give, link side, SI units, and the drive's controller state (what
/// the drive knows itself on the MCU). Its sequence equals the cycle sync's.
/// Layout: seq, 3 fields, CRC (byte 13, over bytes 0-12 as before), flags (byte 14,
/// kSensor* bits, the rest zero), the flags again (byte 15). The flags sit in what was zero
/// padding, so a frame without flags is the former frame; the copy catches a corrupted
/// flags byte, which the CRC does not cover (a mismatch or an unknown bit: bad_padding).
template <class S>
struct SensorMessage {
  S position{};         ///< [rad]
  S velocity{};         ///< [rad/s]
  S motor_torque{};     ///< [N·m] (K_I i)
  bool holding = false; ///< the setpoint is constant (kSensorHolding)
};

template <class S>
constexpr std::uint8_t encode_sensor(const SensorMessage<S>& m, std::uint8_t sequence, std::uint8_t* buf) noexcept {
  const std::array<S, kSensorFields> v = {m.position, m.velocity, m.motor_torque};
  const std::uint8_t length = detail::encode_fields(v.data(), kSensorFields, sequence, buf, kSensorFrameLength);
  const std::uint8_t flags = m.holding ? kSensorHolding : std::uint8_t{0};
  buf[kSensorFrameLength - 2U] = flags;
  buf[kSensorFrameLength - 1U] = flags;
  return length;
}

template <class S>
constexpr FrameError decode_sensor(const std::uint8_t* buf, std::uint8_t length, SensorMessage<S>& m,
                                   std::uint8_t& sequence) noexcept {
  if (length != kSensorFrameLength) {
    return FrameError::wrong_length;
  }
  const std::uint8_t flags = buf[kSensorFrameLength - 2U];
  if (flags != buf[kSensorFrameLength - 1U] || (flags & static_cast<std::uint8_t>(~kSensorHolding)) != 0U) {
    return FrameError::bad_padding;
  }
  // The fields and their CRC: the frame less its two flag bytes (nothing left to pad).
  constexpr auto kFieldsLength = static_cast<std::uint8_t>(kSensorFrameLength - 2U);
  std::array<S, kSensorFields> v{};
  const FrameError e = detail::decode_fields(buf, kFieldsLength, kSensorFields, v.data(), sequence, kFieldsLength);
  if (e == FrameError::ok) {
    m = {v[0], v[1], v[2], flags != 0U};
  }
  return e;
}

/// Status flags (bits of byte 5 of status and collision-event frames; stable).
inline constexpr std::uint8_t kStatusCollision = 0x01U;   ///< the joint's detector flag (latched)
inline constexpr std::uint8_t kStatusCommFault = 0x02U;   ///< a neighbour has been silent for too long
inline constexpr std::uint8_t kStatusReady = 0x04U;       ///< the chain is filled: the estimate is valid
inline constexpr std::uint8_t kStatusInputFault = 0x08U;  ///< this cycle's inputs were rejected
inline constexpr std::uint8_t kStatusBooting = 0x10U;     ///< announcement before the first sync: the drive is listening

/// Observer/detector status of joint j, every cycle (0x05j); the same layout, sent once on
/// the detector's rising edge, is the collision event (0x00j, highest priority).
template <class S>
struct StatusMessage {
  S external_torque{};         ///< [N·m]
  std::uint8_t flags = 0;      ///< kStatus* bits
  std::uint8_t rejected = 0;   ///< frames rejected so far (length, CRC, sequence), saturating
};

template <class S>
constexpr std::uint8_t encode_status(const StatusMessage<S>& m, std::uint8_t sequence, std::uint8_t* buf) noexcept {
  buf[0] = sequence;
  detail::put_i32(buf + 1, detail::to_wire(m.external_torque));
  buf[5] = m.flags;
  buf[6] = m.rejected;
  return detail::finish(buf, 7U, kStatusFrameLength);
}

template <class S>
constexpr FrameError decode_status(const std::uint8_t* buf, std::uint8_t length, StatusMessage<S>& m,
                                   std::uint8_t& sequence) noexcept {
  if (const FrameError e = detail::check(buf, length, 7U, kStatusFrameLength); e != FrameError::ok) {
    return e;
  }
  detail::from_wire(detail::get_i32(buf + 1), m.external_torque);
  m.flags = buf[5];
  m.rejected = buf[6];
  sequence = buf[0];
  return FrameError::ok;
}

/// Cycle sync from the master (0x010): starts cycle `cycle` on every node.
constexpr std::uint8_t encode_sync(std::uint32_t cycle, std::uint8_t* buf) noexcept {
  buf[0] = static_cast<std::uint8_t>(cycle & 0xFFU);
  detail::put_i32(buf + 1, static_cast<std::int32_t>(cycle));
  buf[5] = 0U;
  buf[6] = 0U;
  return detail::finish(buf, 7U, kSyncFrameLength);
}

constexpr FrameError decode_sync(const std::uint8_t* buf, std::uint8_t length, std::uint32_t& cycle) noexcept {
  if (const FrameError e = detail::check(buf, length, 7U, kSyncFrameLength); e != FrameError::ok) {
    return e;
  }
  cycle = static_cast<std::uint32_t>(detail::get_i32(buf + 1));
  return FrameError::ok;
}

/// Sequence tracking per neighbour: a frame is fresh when its counter is ahead of the last
/// accepted one by 1..127 (modulo 256); equal or behind is stale (duplicate, reordered).
struct SequenceTracker {
  std::uint8_t last = 0;
  bool started = false;
  constexpr FrameError accept(std::uint8_t sequence) noexcept {
    const auto ahead = static_cast<std::uint8_t>(sequence - last);
    if (started && (ahead == 0U || ahead >= 128U)) {
      return FrameError::stale_sequence;
    }
    last = sequence;
    started = true;
    return FrameError::ok;
  }
};

}  // namespace jg::protocol
