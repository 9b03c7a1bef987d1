// CAN protocol: identifiers, CRC, round trips (float and Q16.16) including boundary values,
// every rejection path; the loopback port and the backend contract.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "jointguard/hal/loopback_can.hpp"
#include "jointguard/protocol/frames.hpp"

namespace {
using namespace jg::protocol;

static_assert(frame_id(MessageKind::outward, 3) == 0x023);
static_assert(frame_id(MessageKind::collision_event, 1) < frame_id(MessageKind::cycle_sync, 0), "events win arbitration");
static_assert(kind_of(0x035) == MessageKind::inward && joint_of(0x035) == 5);

TEST(Protocol, Crc8AutosarCheckValue) {
  const char* s = "123456789";
  EXPECT_EQ(crc8_autosar(reinterpret_cast<const std::uint8_t*>(s), 9), 0xDF);
}

TEST(Protocol, Crc8TableEqualsTheBitwiseDefinitionOnEveryLengthAndPattern) {
  // Pseudo-random bytes (LCG), every length 0..64 from every offset 0..3: the unrolled
  // table loop and its tail against the bit-by-bit definition.
  std::uint8_t buf[80];
  std::uint32_t x = 12345U;
  for (int round = 0; round < 50; ++round) {
    for (auto& b : buf) {
      x = x * 1664525U + 1013904223U;
      b = static_cast<std::uint8_t>(x >> 24U);
    }
    for (std::uint8_t offset = 0; offset < 4U; ++offset) {
      for (std::uint8_t n = 0; n <= 64U; ++n) {
        ASSERT_EQ(crc8_autosar(buf + offset, n), crc8_autosar_bitwise(buf + offset, n)) << "length " << int{n};
      }
    }
  }
  static_assert(kCrc8AutosarTable[0] == 0x00 && kCrc8AutosarTable[1] == 0x2F, "table entry = polynomial for 1");
}

TEST(Protocol, FloatToWireEqualsQ16FromFloatEverywhere) {
  // Every float pattern with a stride (all exponents, signs, both sides of each rounding
  // tie and of the saturation bound), plus the exact ties and bounds.
  const auto same = [](float v) {
    jg::NumericStatus ignored{};
    return jg::protocol::detail::float_to_wire(v) == jg::q16::from_float(v, ignored).raw();
  };
  for (std::uint64_t bits = 0; bits <= 0xFFFFFFFFULL; bits += 997ULL) {
    const auto b = static_cast<std::uint32_t>(bits);
    float v = 0.0F;
    std::memcpy(&v, &b, 4);
    ASSERT_TRUE(same(v)) << "bits " << std::hex << b;
  }
  for (const float v : {0.5F / 65536.0F, -0.5F / 65536.0F, 1.5F / 65536.0F, -1.5F / 65536.0F, 32767.99998F, 32768.0F,
                        -32768.0F, 1e30F, -1e30F, std::numeric_limits<float>::infinity(),
                        -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(),
                        std::numeric_limits<float>::denorm_min()}) {
    EXPECT_TRUE(same(v)) << v;
  }
}

TEST(Protocol, OutwardRoundTripQ16IsExactAndFloatWithinOneLsb) {
  jg::OutwardMessage<jg::q16> q{};
  q.angular_velocity = {jg::q16::from_double(1.5), jg::q16::from_double(-2.25), jg::q16::from_double(0.001)};
  q.origin_velocity = {jg::q16::from_raw(1), jg::q16::from_raw(-1), jg::q16{}};
  q.gravity = {std::numeric_limits<jg::q16>::max(), std::numeric_limits<jg::q16>::lowest(), jg::q16::from_double(-9.81)};
  std::uint8_t buf[64];
  ASSERT_EQ(encode_outward(q, 200, buf), kMomentumFrameLength);
  jg::OutwardMessage<jg::q16> back{};
  std::uint8_t seq = 0;
  ASSERT_EQ(decode_outward(buf, kMomentumFrameLength, back, seq), FrameError::ok);
  EXPECT_EQ(seq, 200);
  EXPECT_EQ(std::memcmp(&back, &q, sizeof q), 0) << "Q16.16 travels bit for bit";
  jg::OutwardMessage<float> f{};
  f.angular_velocity = {1.2345F, -3.5F, 1e6F};  // 1e6 saturates to the wire's range, never wraps
  f.gravity.z = -9.81F;
  ASSERT_EQ(encode_outward(f, 7, buf), kMomentumFrameLength);
  jg::OutwardMessage<float> fb{};
  ASSERT_EQ(decode_outward(buf, kMomentumFrameLength, fb, seq), FrameError::ok);
  EXPECT_NEAR(fb.angular_velocity.x, 1.2345F, 1.0F / 65536.0F);
  EXPECT_NEAR(fb.gravity.z, -9.81F, 1.0F / 65536.0F);
  EXPECT_GT(fb.angular_velocity.z, 32767.0F);
}

TEST(Protocol, InwardRoundTripAndEveryRejection) {
  jg::InwardMessage<jg::q16> m{};
  m.angular_momentum = {jg::q16::from_double(0.5), jg::q16::from_double(-0.1), jg::q16::from_double(3.0)};
  m.mass = jg::q16::from_double(5.5);
  std::uint8_t buf[64];
  ASSERT_EQ(encode_inward(m, 1, buf), kMomentumFrameLength);
  jg::InwardMessage<jg::q16> back{};
  std::uint8_t seq = 0;
  EXPECT_EQ(decode_inward(buf, 8, back, seq), FrameError::wrong_length);
  EXPECT_EQ(decode_inward(buf, kMomentumFrameLength, back, seq), FrameError::ok);
  EXPECT_EQ(back.mass.raw(), m.mass.raw());
  for (int byte = 0; byte < 42; ++byte) {  // any single corrupted byte is caught
    std::uint8_t bad[64];
    std::memcpy(bad, buf, 64);
    bad[byte] ^= 0x10U;
    EXPECT_EQ(decode_inward(bad, kMomentumFrameLength, back, seq), FrameError::bad_crc) << "byte " << byte;
  }
}

TEST(Protocol, SequenceTrackerRejectsDuplicatesAndReorderingAcrossTheWrap) {
  SequenceTracker t;
  EXPECT_EQ(t.accept(254), FrameError::ok);
  EXPECT_EQ(t.accept(255), FrameError::ok);
  EXPECT_EQ(t.accept(0), FrameError::ok) << "wraps";
  EXPECT_EQ(t.accept(0), FrameError::stale_sequence) << "duplicate";
  EXPECT_EQ(t.accept(255), FrameError::stale_sequence) << "reordered";
  EXPECT_EQ(t.accept(5), FrameError::ok) << "lost frames in between are allowed (counted by the node)";
}

TEST(Protocol, SensorStatusAndSyncRoundTripAtTheirBoundsAndEveryRejection) {
  const jg::q16 hi = std::numeric_limits<jg::q16>::max(), lo = std::numeric_limits<jg::q16>::lowest();
  std::uint8_t buf[64];
  std::uint8_t seq = 0;
  for (const std::uint8_t s : {std::uint8_t{0}, std::uint8_t{255}}) {
    const SensorMessage<jg::q16> m{hi, lo, jg::q16::from_raw(1)};
    ASSERT_EQ(encode_sensor(m, s, buf), kSensorFrameLength);
    SensorMessage<jg::q16> back{};
    ASSERT_EQ(decode_sensor(buf, kSensorFrameLength, back, seq), FrameError::ok);
    EXPECT_EQ(seq, s);
    EXPECT_EQ(back.position.raw(), hi.raw());
    EXPECT_EQ(back.velocity.raw(), lo.raw());
    EXPECT_EQ(back.motor_torque.raw(), 1);
  }
  SensorMessage<float> fs{1e9F, -1e9F, 0.5F};  // saturates on the wire, never wraps
  ASSERT_EQ(encode_sensor(fs, 1, buf), kSensorFrameLength);
  SensorMessage<float> fb{};
  ASSERT_EQ(decode_sensor(buf, kSensorFrameLength, fb, seq), FrameError::ok);
  EXPECT_GT(fb.position, 32767.0F);
  EXPECT_LT(fb.velocity, -32767.0F);
  EXPECT_EQ(fb.motor_torque, 0.5F);
  EXPECT_EQ(decode_sensor(buf, 8, fb, seq), FrameError::wrong_length);
  buf[3] ^= 0x01U;
  EXPECT_EQ(decode_sensor(buf, kSensorFrameLength, fb, seq), FrameError::bad_crc);
  buf[3] ^= 0x01U;
  buf[15] = 0x80U;
  EXPECT_EQ(decode_sensor(buf, kSensorFrameLength, fb, seq), FrameError::bad_padding);

  const StatusMessage<jg::q16> st{lo, 0xFF, 255};
  ASSERT_EQ(encode_status(st, 255, buf), kStatusFrameLength);
  StatusMessage<jg::q16> sb{};
  ASSERT_EQ(decode_status(buf, kStatusFrameLength, sb, seq), FrameError::ok);
  EXPECT_EQ(sb.external_torque.raw(), lo.raw());
  EXPECT_EQ(sb.flags, 0xFF);
  EXPECT_EQ(sb.rejected, 255);
  EXPECT_EQ(decode_status(buf, 7, sb, seq), FrameError::wrong_length);
  for (int byte = 0; byte < 8; ++byte) {
    std::uint8_t bad[8];
    std::memcpy(bad, buf, 8);
    bad[byte] ^= 0x20U;
    EXPECT_NE(decode_status(bad, 8, sb, seq), FrameError::ok) << "byte " << byte;
  }

  for (const std::uint32_t cycle : {0U, 255U, 256U, 0xFFFFFFFFU}) {
    ASSERT_EQ(encode_sync(cycle, buf), kSyncFrameLength);
    EXPECT_EQ(buf[0], cycle & 0xFFU) << "the sync's sequence is the cycle's low byte";
    std::uint32_t back = 1;
    ASSERT_EQ(decode_sync(buf, kSyncFrameLength, back), FrameError::ok);
    EXPECT_EQ(back, cycle);
  }
  std::uint32_t c = 0;
  EXPECT_EQ(decode_sync(buf, 12, c), FrameError::wrong_length);
  buf[6] = 1U;
  EXPECT_EQ(decode_sync(buf, kSyncFrameLength, c), FrameError::bad_crc) << "reserved bytes are inside the CRC";
}

TEST(Hal, LoopbackHonoursFiltersCapacityAndLengths) {
  jg::hal::LoopbackCan<2> port;
  jg::hal::CanFrame f;
  f.id = 0x023;
  f.length = 48;
  f.fd = true;
  EXPECT_EQ(port.send(f), jg::hal::CanStatus::ok);
  f.length = 9;
  EXPECT_EQ(port.send(f), jg::hal::CanStatus::invalid) << "9 bytes is not a CAN FD length";
  f.length = 8;
  f.fd = false;
  f.id = 0x800;
  EXPECT_EQ(port.send(f), jg::hal::CanStatus::invalid) << "11-bit identifiers only up to 0x7FF";
  f.id = 0x035;
  EXPECT_EQ(port.send(f), jg::hal::CanStatus::ok);
  EXPECT_EQ(port.send(f), jg::hal::CanStatus::queue_full);
  const jg::hal::CanFilter only_inward{0x030, 0x7F0};
  port.set_filters(&only_inward, 1);
  jg::hal::CanFrame r;
  ASSERT_TRUE(port.receive(r));
  EXPECT_EQ(r.id, 0x035U) << "the outward frame was filtered out";
  EXPECT_FALSE(port.receive(r));
}
TEST(Protocol, SensorHoldingFlagTravelsInTheFormerPaddingWithItsCopy) {
  std::uint8_t buf[64];
  std::uint8_t seq = 0;
  const SensorMessage<jg::q16> free{jg::q16::from_double(0.5), jg::q16::from_double(-0.25), jg::q16::from_double(3.0)};
  ASSERT_EQ(encode_sensor(free, 9, buf), kSensorFrameLength);
  EXPECT_EQ(buf[14], 0U) << "without the flag the frame is the former frame";
  EXPECT_EQ(buf[15], 0U);
  std::uint8_t held_buf[64];
  SensorMessage<jg::q16> held = free;
  held.holding = true;
  ASSERT_EQ(encode_sensor(held, 9, held_buf), kSensorFrameLength);
  for (int i = 0; i < 14; ++i) EXPECT_EQ(held_buf[i], buf[i]) << "fields and CRC unchanged, byte " << i;
  EXPECT_EQ(held_buf[14], kSensorHolding);
  EXPECT_EQ(held_buf[15], kSensorHolding);
  SensorMessage<float> back{};
  ASSERT_EQ(decode_sensor(held_buf, kSensorFrameLength, back, seq), FrameError::ok);
  EXPECT_TRUE(back.holding);
  EXPECT_EQ(back.motor_torque, 3.0F);
  ASSERT_EQ(decode_sensor(buf, kSensorFrameLength, back, seq), FrameError::ok);
  EXPECT_FALSE(back.holding);
  held_buf[15] = 0U;  // a flipped flag byte: the copy disagrees
  EXPECT_EQ(decode_sensor(held_buf, kSensorFrameLength, back, seq), FrameError::bad_padding);
  held_buf[14] = 0x03U;  // an unknown bit, copied
  held_buf[15] = 0x03U;
  EXPECT_EQ(decode_sensor(held_buf, kSensorFrameLength, back, seq), FrameError::bad_padding);
}

}  // namespace
