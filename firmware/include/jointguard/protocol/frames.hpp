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
#include <cstring>
#include <type_traits>

#include "jointguard/dynamics/momentum_recursion.hpp"
#include "jointguard/hal/crc8.hpp"
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
  return static_cast<std::uint16_t>((static_cast<unsigned>(kind) << 4U) | (static_cast<unsigned>(joint) & 0x0FU));
}
[[nodiscard]] constexpr MessageKind kind_of(std::uint32_t id) noexcept { return static_cast<MessageKind>((id >> 4U) & 0x7FU); }
[[nodiscard]] constexpr std::uint8_t joint_of(std::uint32_t id) noexcept { return static_cast<std::uint8_t>(id & 0x0FU); }

// CRC-8/AUTOSAR (polynomial 0x2F, initial 0xFF, final XOR 0xFF) comes from the HAL
// (jointguard/hal/crc8.hpp): the codecs take a CRC policy (template parameter Crc, checked
// with hal::is_crc8_policy_v, default the table-driven software CRC); a node and a drive
// use their port's (hal::crc8_policy_t<Port>), so an MCU backend can put a CRC unit behind
// the same frames. These names stay the protocol's:
using hal::crc8_autosar;
using hal::crc8_autosar_bitwise;
using hal::kCrc8AutosarTable;
using DefaultCrc8 = hal::Crc8AutosarTable;

/// Whether the float -> wire conversion runs as one assembler sequence (single-precision
/// VFP in Thumb-2: Cortex-M4F, M7, M33): the rounding mode is switched to round toward
/// minus infinity for the sequence, so floor(v 2^16 + 0.5) is one VADD and one VCVTR per
/// value (the addition rounds down, which leaves the floor unchanged: floor(fl(x)) =
/// floor(x) whenever floor(x) is a float, and above 2^24 every float is an integer), VCVTR
/// saturates and maps NaN to 0, and one range test gives from_float's saturation at
/// +/-2147483520 (the largest float below 2^31) to the symmetric range. The same value as
/// float_to_wire for every float (checked on the MCU by jg_golden over a dense sweep of
/// bit patterns, tests/mcu/mcu_main.cpp); elsewhere float_to_wire.
#if defined(__ARM_FP) && ((__ARM_FP & 4) != 0) && defined(__thumb2__) && !defined(__SOFTFP__)
#define JG_WIRE_FLOAT_ASM 1  // NOLINT(cppcoreguidelines-macro-usage): selects code with #if
#else
#define JG_WIRE_FLOAT_ASM 0  // NOLINT(cppcoreguidelines-macro-usage): selects code with #if
#endif

namespace detail {
/// Q16.16 wire word -> float, the same value as q16::from_raw(raw).to_float() (the int ->
/// float rounding followed by an exact scaling by 2^-16): on single-precision VFP one
/// fixed-point VCVT, which rounds raw 2^-16 once.
inline float wire_to_float(std::int32_t raw) noexcept {
#if JG_WIRE_FLOAT_ASM
  float f = 0.0F;
  __asm("vmov %0, %1\n\tvcvt.f32.s32 %0, %0, #16" : "=&t"(f) : "r"(raw));
  return f;
#else
  return q16::from_raw(raw).to_float();
#endif
}
}  // namespace detail

namespace detail {
/// float -> Q16.16 wire word, the same value as q16::from_float (round to nearest, ties
/// toward +inf; saturated to the symmetric int32 range; NaN -> 0) without its status
/// counting: one range test on the common path instead of nested compares (tests/can checks
/// the equality on a dense sweep of float patterns).
inline std::int32_t float_to_wire(float v) noexcept {
  constexpr float kMaxF = 2147483520.0F;  // largest float below 2^31
  const float scaled = v * 65536.0F;
  if (!(scaled < kMaxF && scaled > -kMaxF)) {  // rare: saturation or NaN
    if (jg::detail::is_nan(v)) {
      return 0;
    }
    return scaled > 0.0F ? jg::detail::kRawMax : jg::detail::kRawMin;
  }
  auto truncated = static_cast<std::int32_t>(scaled);             // toward zero
  const float fraction = scaled - static_cast<float>(truncated);  // exact
  truncated += fraction >= 0.5F ? 1 : 0;
  truncated -= fraction < -0.5F ? 1 : 0;
  return truncated;
}

template <class S>
constexpr std::int32_t to_wire(S v) noexcept {
  if constexpr (is_q_v<S>) {
    return q_cast<q16>(v).raw();
  } else {
    return float_to_wire(static_cast<float>(v));  // saturates; non-finite values never reach here (node checks)
  }
}
template <class S>
constexpr void from_wire(std::int32_t raw, S& out) noexcept {
  if constexpr (is_q_v<S>) {
    out = q_cast<S>(q16::from_raw(raw));
  } else {
    if constexpr (std::is_same_v<S, float>) {
      out = wire_to_float(raw);
    } else {
      out = static_cast<S>(q16::from_raw(raw).to_float());
    }
  }
}
/// Little-endian int32 at any alignment. On little-endian targets one (unaligned) store or
/// load: the Cortex-M3/M4/M7/M33 allow unaligned LDR/STR, and memcpy lets the compiler
/// pick byte accesses where they do not (M0).
inline void put_i32(std::uint8_t* p, std::int32_t v) noexcept {
  const auto u = static_cast<std::uint32_t>(v);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  std::memcpy(p, &u, 4);
#else
  for (unsigned i = 0; i < 4U; ++i) {
    p[i] = static_cast<std::uint8_t>(u >> (8U * i));
  }
#endif
}
inline std::int32_t get_i32(const std::uint8_t* p) noexcept {
  std::uint32_t u = 0;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  std::memcpy(&u, p, 4);
#else
  for (unsigned i = 0; i < 4U; ++i) {
    u |= static_cast<std::uint32_t>(p[i]) << (8U * i);
  }
#endif
  return static_cast<std::int32_t>(u);
}

/// N consecutive floats at `src` (an object made of N floats, e.g. Vec3<float> or a message
/// of them) -> N little-endian Q16.16 words at `dst` (any alignment).
template <unsigned N, class Floats>
inline void floats_to_wire(const Floats& src, std::uint8_t* dst) noexcept {
  static_assert(sizeof(Floats) == N * sizeof(float) && std::is_standard_layout_v<Floats>, "N packed floats");
#if JG_WIRE_FLOAT_ASM
  static_assert(N == 1U || N == 9U || N == 10U, "instantiated for the status, outward and inward frames");
  std::uint32_t fpscr = 0;
  std::uint32_t mode = 0;
  std::uint32_t word = 0;
  float value = 0.0F;
  float scale = 0.0F;
  float half = 0.0F;
  const void* from = &src;
  std::uint8_t* to = dst;
// The steps are spelled out (no .rept): GCC sizes an asm statement by its lines, and an
// underestimate pushes the function's literal pool out of VLDR's range.
// One range test per value on the common path: word + (2147483520 - 1) is below
// 2 (2147483520 - 1) + 1 (unsigned) exactly when |word| < 2147483520; the others (and the
// saturated VCVTR results) take the out-of-line fix-up k of step k, which puts kRawMax or
// kRawMin by the sign and returns to the store.
#define JG_WIRE_STEP(k)                                                                                      \
  "vldmia %[from]!, {%[value]}\n\t"                                                                          \
  "vmul.f32 %[value], %[value], %[scale]\n\t"                                                                \
  "vadd.f32 %[value], %[value], %[half]\n\t"                                                                 \
  "vcvtr.s32.f32 %[value], %[value]\n\t"                                                                     \
  "vmov %[word], %[value]\n\t"                                                                               \
  "add %[mode], %[word], %[bias]\n\t"                                                                        \
  "cmp %[mode], %[span]\n\t"                                                                                 \
  "bhs 9" #k "f\n\t"                                                                                         \
  "8" #k ":\n\t"                                                                                             \
  "str %[word], [%[to]], #4\n\t"
#define JG_WIRE_FIX(k)                                                                                       \
  "9" #k ":\n\t"                                                                                             \
  "cmp %[word], #0\n\t"                                                                                      \
  "ite ge\n\t"                                                                                               \
  "mvnge %[word], #0x80000000\n\t" /* kRawMax */                                                             \
  "movlt %[word], %[raw_min]\n\t"  /* kRawMin */                                                             \
  "b 8" #k "b\n\t"
#define JG_WIRE_ASM(steps, fixes)                                                                            \
  __asm volatile("vmrs %[fpscr], fpscr\n\t"                                                                  \
                 "orr %[mode], %[fpscr], #0x00800000\n\t" /* RMode (bits 23:22) = 10: toward -inf */         \
                 "bic %[mode], %[mode], #0x00400000\n\t"                                                     \
                 "vmsr fpscr, %[mode]\n\t"                                                                   \
                 "vmov %[scale], %[scale_bits]\n\t"                                                          \
                 "vmov.f32 %[half], #0.5\n\t" steps "vmsr fpscr, %[fpscr]\n\t"                              \
                 "b 7f\n\t" fixes "7:\n\t"                                                                   \
                 : [fpscr] "=&r"(fpscr), [mode] "=&r"(mode), [word] "=&r"(word), [value] "=&t"(value),       \
                   [scale] "=&t"(scale), [half] "=&t"(half), [from] "+&r"(from), [to] "+&r"(to),             \
                   "=m"(*reinterpret_cast<std::uint8_t(*)[4 * N]>(dst)) /* NOLINT: the bytes written */     \
                 : [scale_bits] "r"(0x47800000U) /* 65536.0F */, [bias] "r"(0x7FFFFF7FU),                    \
                   [span] "r"(0xFFFFFEFFU), [raw_min] "r"(jg::detail::kRawMin), "m"(src)                     \
                 : "cc")
  if constexpr (N == 1U) {
    JG_WIRE_ASM(JG_WIRE_STEP(0), JG_WIRE_FIX(0));
  } else if constexpr (N == 9U) {
    JG_WIRE_ASM(JG_WIRE_STEP(0) JG_WIRE_STEP(1) JG_WIRE_STEP(2) JG_WIRE_STEP(3) JG_WIRE_STEP(4) JG_WIRE_STEP(5)
                    JG_WIRE_STEP(6) JG_WIRE_STEP(7) JG_WIRE_STEP(8),
                JG_WIRE_FIX(0) JG_WIRE_FIX(1) JG_WIRE_FIX(2) JG_WIRE_FIX(3) JG_WIRE_FIX(4) JG_WIRE_FIX(5)
                    JG_WIRE_FIX(6) JG_WIRE_FIX(7) JG_WIRE_FIX(8));
  } else {
    JG_WIRE_ASM(JG_WIRE_STEP(0) JG_WIRE_STEP(1) JG_WIRE_STEP(2) JG_WIRE_STEP(3) JG_WIRE_STEP(4) JG_WIRE_STEP(5)
                    JG_WIRE_STEP(6) JG_WIRE_STEP(7) JG_WIRE_STEP(8) JG_WIRE_STEP(9),
                JG_WIRE_FIX(0) JG_WIRE_FIX(1) JG_WIRE_FIX(2) JG_WIRE_FIX(3) JG_WIRE_FIX(4) JG_WIRE_FIX(5)
                    JG_WIRE_FIX(6) JG_WIRE_FIX(7) JG_WIRE_FIX(8) JG_WIRE_FIX(9));
  }
#undef JG_WIRE_ASM
#undef JG_WIRE_FIX
#undef JG_WIRE_STEP
#else
  const auto* bytes = reinterpret_cast<const unsigned char*>(&src);  // NOLINT: the object's floats in order
  for (std::size_t i = 0; i < N; ++i) {
    float v = 0.0F;
    std::memcpy(&v, bytes + std::size_t{4} * i, 4);
    put_i32(dst + std::size_t{4} * i, float_to_wire(v));
  }
#endif
}

/// CRC after the `used` payload bytes, zeros up to the frame length; returns the length.
template <class Crc = DefaultCrc8>
inline std::uint8_t finish(std::uint8_t* buf, std::uint8_t used, std::uint8_t frame_length) noexcept {
  static_assert(hal::is_crc8_policy_v<Crc>, "Crc must satisfy the CRC-8 policy contract (hal/crc8.hpp)");
  buf[used] = Crc::crc8(buf, used);
  for (auto i = static_cast<std::uint8_t>(used + 1U); i < frame_length; ++i) {
    buf[i] = 0U;
  }
  return frame_length;
}
template <class Crc = DefaultCrc8>
inline FrameError check(const std::uint8_t* buf, std::uint8_t length, std::uint8_t used, std::uint8_t frame_length) noexcept {
  if (length != frame_length) {
    return FrameError::wrong_length;
  }
  static_assert(hal::is_crc8_policy_v<Crc>, "Crc must satisfy the CRC-8 policy contract (hal/crc8.hpp)");
  if (Crc::crc8(buf, used) != buf[used]) {
    return FrameError::bad_crc;
  }
  // Padding: OR of (unaligned) words, then the bytes left; lengths are constants where this
  // is inlined, so a 10-byte padding is three loads, not a byte loop.
  std::uint32_t padding = 0U;
  unsigned i = used + 1U;
  for (; i + 4U <= frame_length; i += 4U) {
    padding |= static_cast<std::uint32_t>(get_i32(buf + i));
  }
  for (; i < frame_length; ++i) {
    padding |= buf[i];
  }
  return padding == 0U ? FrameError::ok : FrameError::bad_padding;
}
constexpr std::uint8_t field_bytes(std::uint8_t fields) noexcept { return static_cast<std::uint8_t>(1U + 4U * fields); }
}  // namespace detail

namespace detail {
template <class S>
constexpr void put_vec(std::uint8_t* p, const Vec3<S>& v) noexcept {
  put_i32(p, to_wire(v.x));
  put_i32(p + 4, to_wire(v.y));
  put_i32(p + 8, to_wire(v.z));
}
template <class S>
constexpr void get_vec(const std::uint8_t* p, Vec3<S>& v) noexcept {
  from_wire(get_i32(p), v.x);
  from_wire(get_i32(p + 4), v.y);
  from_wire(get_i32(p + 8), v.z);
}
}  // namespace detail

// Each message has encode_<kind> (written straight from the message into the caller's
// frame buffer), check_<kind> (length, CRC, padding), read_<kind> (fields of a checked
// frame straight into the message) and decode_<kind> (check, then read). The node checks,
// looks at the sequence (buf[0]) and reads only frames it accepts: no intermediate copies.

template <class S, class Crc = DefaultCrc8>
constexpr std::uint8_t encode_outward(const OutwardMessage<S>& m, std::uint8_t sequence, std::uint8_t* buf) noexcept {
  buf[0] = sequence;
  if constexpr (std::is_same_v<S, float>) {
    detail::floats_to_wire<kOutwardFields>(m, buf + 1);  // the nine fields in declaration order
  } else {
    detail::put_vec(buf + 1, m.angular_velocity);
    detail::put_vec(buf + 13, m.origin_velocity);
    detail::put_vec(buf + 25, m.gravity);
  }
  return detail::finish<Crc>(buf, detail::field_bytes(kOutwardFields), kMomentumFrameLength);
}

template <class Crc = DefaultCrc8>
[[nodiscard]] inline FrameError check_outward(const std::uint8_t* buf, std::uint8_t length) noexcept {
  return detail::check<Crc>(buf, length, detail::field_bytes(kOutwardFields), kMomentumFrameLength);
}

/// Fields of a frame check_outward accepted.
template <class S>
constexpr void read_outward(const std::uint8_t* buf, OutwardMessage<S>& m) noexcept {
  detail::get_vec(buf + 1, m.angular_velocity);
  detail::get_vec(buf + 13, m.origin_velocity);
  detail::get_vec(buf + 25, m.gravity);
}

template <class S, class Crc = DefaultCrc8>
constexpr FrameError decode_outward(const std::uint8_t* buf, std::uint8_t length, OutwardMessage<S>& m,
                                    std::uint8_t& sequence) noexcept {
  const FrameError e = check_outward<Crc>(buf, length);
  if (e == FrameError::ok) {
    read_outward(buf, m);
    sequence = buf[0];
  }
  return e;
}

template <class S, class Crc = DefaultCrc8>
constexpr std::uint8_t encode_inward(const InwardMessage<S>& m, std::uint8_t sequence, std::uint8_t* buf) noexcept {
  buf[0] = sequence;
  if constexpr (std::is_same_v<S, float>) {
    detail::floats_to_wire<kInwardFields>(m, buf + 1);  // the ten fields in declaration order
  } else {
    detail::put_vec(buf + 1, m.angular_momentum);
    detail::put_vec(buf + 13, m.linear_momentum);
    detail::put_vec(buf + 25, m.first_moment);
    detail::put_i32(buf + 37, detail::to_wire(m.mass));
  }
  return detail::finish<Crc>(buf, detail::field_bytes(kInwardFields), kMomentumFrameLength);
}

template <class Crc = DefaultCrc8>
[[nodiscard]] inline FrameError check_inward(const std::uint8_t* buf, std::uint8_t length) noexcept {
  return detail::check<Crc>(buf, length, detail::field_bytes(kInwardFields), kMomentumFrameLength);
}

/// Fields of a frame check_inward accepted.
template <class S>
constexpr void read_inward(const std::uint8_t* buf, InwardMessage<S>& m) noexcept {
  detail::get_vec(buf + 1, m.angular_momentum);
  detail::get_vec(buf + 13, m.linear_momentum);
  detail::get_vec(buf + 25, m.first_moment);
  detail::from_wire(detail::get_i32(buf + 37), m.mass);
}

template <class S, class Crc = DefaultCrc8>
constexpr FrameError decode_inward(const std::uint8_t* buf, std::uint8_t length, InwardMessage<S>& m,
                                   std::uint8_t& sequence) noexcept {
  const FrameError e = check_inward<Crc>(buf, length);
  if (e == FrameError::ok) {
    read_inward(buf, m);
    sequence = buf[0];
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

template <class S, class Crc = DefaultCrc8>
constexpr std::uint8_t encode_sensor(const SensorMessage<S>& m, std::uint8_t sequence, std::uint8_t* buf) noexcept {
  buf[0] = sequence;
  detail::put_i32(buf + 1, detail::to_wire(m.position));
  detail::put_i32(buf + 5, detail::to_wire(m.velocity));
  detail::put_i32(buf + 9, detail::to_wire(m.motor_torque));
  // The fields and their CRC fill the frame less its last two bytes, which carry the flags
  // twice (a mismatched copy or an unknown bit is refused: the CRC does not cover them).
  constexpr auto kFieldsLength = static_cast<std::uint8_t>(kSensorFrameLength - 2U);
  (void)detail::finish<Crc>(buf, detail::field_bytes(kSensorFields), kFieldsLength);
  const std::uint8_t flags = m.holding ? kSensorHolding : std::uint8_t{0};
  buf[kSensorFrameLength - 2U] = flags;
  buf[kSensorFrameLength - 1U] = flags;
  return kSensorFrameLength;
}

template <class S, class Crc = DefaultCrc8>
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
  const FrameError e = detail::check<Crc>(buf, kFieldsLength, detail::field_bytes(kSensorFields), kFieldsLength);
  if (e == FrameError::ok) {
    detail::from_wire(detail::get_i32(buf + 1), m.position);
    detail::from_wire(detail::get_i32(buf + 5), m.velocity);
    detail::from_wire(detail::get_i32(buf + 9), m.motor_torque);
    m.holding = flags != 0U;
    sequence = buf[0];
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

template <class S, class Crc = DefaultCrc8>
constexpr std::uint8_t encode_status(const StatusMessage<S>& m, std::uint8_t sequence, std::uint8_t* buf) noexcept {
  buf[0] = sequence;
  if constexpr (std::is_same_v<S, float>) {
    detail::floats_to_wire<1>(m.external_torque, buf + 1);
  } else {
    detail::put_i32(buf + 1, detail::to_wire(m.external_torque));
  }
  buf[5] = m.flags;
  buf[6] = m.rejected;
  return detail::finish<Crc>(buf, 7U, kStatusFrameLength);
}

template <class S, class Crc = DefaultCrc8>
constexpr FrameError decode_status(const std::uint8_t* buf, std::uint8_t length, StatusMessage<S>& m,
                                   std::uint8_t& sequence) noexcept {
  if (const FrameError e = detail::check<Crc>(buf, length, 7U, kStatusFrameLength); e != FrameError::ok) {
    return e;
  }
  detail::from_wire(detail::get_i32(buf + 1), m.external_torque);
  m.flags = buf[5];
  m.rejected = buf[6];
  sequence = buf[0];
  return FrameError::ok;
}

/// Cycle sync from the master (0x010): starts cycle `cycle` on every node.
template <class Crc = DefaultCrc8>
inline std::uint8_t encode_sync(std::uint32_t cycle, std::uint8_t* buf) noexcept {
  buf[0] = static_cast<std::uint8_t>(cycle & 0xFFU);
  detail::put_i32(buf + 1, static_cast<std::int32_t>(cycle));
  buf[5] = 0U;
  buf[6] = 0U;
  return detail::finish<Crc>(buf, 7U, kSyncFrameLength);
}

template <class Crc = DefaultCrc8>
inline FrameError decode_sync(const std::uint8_t* buf, std::uint8_t length, std::uint32_t& cycle) noexcept {
  if (const FrameError e = detail::check<Crc>(buf, length, 7U, kSyncFrameLength); e != FrameError::ok) {
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
