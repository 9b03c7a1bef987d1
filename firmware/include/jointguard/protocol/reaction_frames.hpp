// The reaction's two frames (kind 0x4, formerly reserved as "joint state"):
//
//   0x040 reaction command, master -> every drive, CAN FD 32 B, every cycle while the arm
//         reacts, sent before that cycle's sync:
//         seq, reaction (Reaction, 1..4), collided joints (bit j-1: joint j), retreat
//         target of joints 1..7 [rad] (Q16.16 int32 LE at byte 3 + 4(j-1); 0 for absent
//         joints), CRC (byte 31)
//   0x04j reaction status, drive j -> master, FD 12 B, every cycle the drive reacts, in
//         place of its status frame (0x05j): seq, external torque, flags, rejected (bytes
//         0-6 as the status), the reaction's torque term [N·m] (Q16.16), CRC. On the arm the
//         drive applies the term to its own motor and the 4 bytes are not needed; in
//         host-in-the-loop runs the plant stands in for the motors. Replacing the status
//         keeps the bus load of a reacting arm that of a running one (no extra frame).
//
// Layout rules as frames.hpp (sequence first, CRC-8/AUTOSAR after the fields, zero padding;
// the CRC by the port's policy Crc, as frames.hpp, so a drive with a CRC unit uses it here too);
// an unknown reaction value (or a collided bit beyond joint 7) is refused as bad_padding (a byte
// outside its defined values that the CRC does not make wrong). Values saturate on encoding.
#pragma once

#include <cstddef>
#include <cstdint>

#include "jointguard/detection/detector.hpp"
#include "jointguard/protocol/frames.hpp"

namespace jg::protocol {

inline constexpr std::uint16_t kReactionCommandId = 0x040;  ///< frame_id(MessageKind::joint_state, 0)
inline constexpr std::uint8_t kReactionCommandLength = 32;
inline constexpr std::uint8_t kReactionStatusLength = 12;
inline constexpr std::uint8_t kReactionJoints = 7;
inline constexpr std::uint8_t kTargetsOffset = 3;
/// seq, reaction, collided, 7 targets: 31 bytes, then the CRC fills the 32-byte frame.
inline constexpr std::uint8_t kCommandFieldBytes = kTargetsOffset + 4U * kReactionJoints;
static_assert(kCommandFieldBytes + 1U == kReactionCommandLength, "the command's CRC is its last byte");
/// Byte offset of joint j's retreat target (j 0-based).
[[nodiscard]] constexpr std::size_t target_offset(unsigned j) noexcept { return kTargetsOffset + std::size_t{4} * j; }

[[nodiscard]] constexpr bool known_reaction(std::uint8_t r) noexcept {
  return r >= static_cast<std::uint8_t>(Reaction::stop) && r <= static_cast<std::uint8_t>(Reaction::reflex);
}

/// The master's command (the whole arm's; each drive reads its own joint's part).
template <class S>
struct ReactionCommandMessage {
  Reaction reaction = Reaction::stop;
  std::uint8_t collided = 0;                ///< bit j-1: joint j is in the collision's signature
  S retreat_target[kReactionJoints]{};      ///< [rad]
};

template <class S, class Crc = DefaultCrc8>
constexpr std::uint8_t encode_reaction_command(const ReactionCommandMessage<S>& m, std::uint8_t sequence,
                                               std::uint8_t* buf) noexcept {
  buf[0] = sequence;
  buf[1] = static_cast<std::uint8_t>(m.reaction);
  buf[2] = m.collided;
  for (std::uint8_t j = 0; j < kReactionJoints; ++j) {
    detail::put_i32(buf + target_offset(j), detail::to_wire(m.retreat_target[j]));
  }
  return detail::finish<Crc>(buf, kCommandFieldBytes, kReactionCommandLength);
}

/// Checks the frame and reads joint `joint`'s part (1..7): the reaction, whether the
/// joint is collided and its retreat target.
template <class S, class Crc = DefaultCrc8>
constexpr FrameError decode_reaction_command(const std::uint8_t* buf, std::uint8_t length, std::uint8_t joint,
                                             Reaction& reaction, bool& collided, S& retreat_target) noexcept {
  if (const FrameError e = detail::check<Crc>(buf, length, kCommandFieldBytes, kReactionCommandLength); e != FrameError::ok) {
    return e;
  }
  if (!known_reaction(buf[1]) || (buf[2] & 0x80U) != 0U || joint < 1U || joint > kReactionJoints) {
    return FrameError::bad_padding;
  }
  reaction = static_cast<Reaction>(buf[1]);
  collided = ((buf[2] >> (joint - 1U)) & 1U) != 0U;
  detail::from_wire(detail::get_i32(buf + target_offset(joint - 1U)), retreat_target);
  return FrameError::ok;
}

/// All joints' parts of a command frame (the master's side and the decoder's).
template <class S, class Crc = DefaultCrc8>
constexpr FrameError decode_reaction_command(const std::uint8_t* buf, std::uint8_t length, ReactionCommandMessage<S>& m) noexcept {
  bool collided = false;
  S target{};
  const FrameError e = decode_reaction_command<S, Crc>(buf, length, 1U, m.reaction, collided, target);
  if (e == FrameError::ok) {
    m.collided = buf[2];
    for (std::uint8_t j = 0; j < kReactionJoints; ++j) {
      detail::from_wire(detail::get_i32(buf + target_offset(j)), m.retreat_target[j]);
    }
  }
  return e;
}

/// While a drive reacts its status goes out as this frame instead of 0x05j: the status
/// (same fields, same bytes 0-6) and the reaction's torque term.
template <class S>
struct ReactionStatusMessage {
  StatusMessage<S> status{};
  S torque{};  ///< [N·m] the reaction's term of the joint's motor torque
};

template <class S, class Crc = DefaultCrc8>
constexpr std::uint8_t encode_reaction_status(const ReactionStatusMessage<S>& m, std::uint8_t sequence, std::uint8_t* buf) noexcept {
  buf[0] = sequence;
  detail::put_i32(buf + 1, detail::to_wire(m.status.external_torque));
  buf[5] = m.status.flags;
  buf[6] = m.status.rejected;
  detail::put_i32(buf + 7, detail::to_wire(m.torque));
  return detail::finish<Crc>(buf, 11U, kReactionStatusLength);
}

template <class S, class Crc = DefaultCrc8>
constexpr FrameError decode_reaction_status(const std::uint8_t* buf, std::uint8_t length, ReactionStatusMessage<S>& m,
                                            std::uint8_t& sequence) noexcept {
  if (const FrameError e = detail::check<Crc>(buf, length, 11U, kReactionStatusLength); e != FrameError::ok) {
    return e;
  }
  detail::from_wire(detail::get_i32(buf + 1), m.status.external_torque);
  m.status.flags = buf[5];
  m.status.rejected = buf[6];
  detail::from_wire(detail::get_i32(buf + 7), m.torque);
  sequence = buf[0];
  return FrameError::ok;
}

}  // namespace jg::protocol
