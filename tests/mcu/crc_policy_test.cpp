// The frames' CRC as a HAL policy: a stand-in "hardware" policy (the bit-by-bit definition)
// gives byte-identical frames through the codecs and through a whole drive cycle, and the
// STM32G4 CRC unit's register sequence computes CRC-8/AUTOSAR on a model of the unit
// (RM0440: programmable polynomial, INIT loaded by CR.RESET, data shifted in MSB first).
#include <gtest/gtest.h>

#include <cstdint>
#include <deque>
#include <vector>

#include "jointguard/hal/crc8.hpp"
#include "jointguard/hal/loopback_can.hpp"
#include "jointguard/hal/mcu/stm32g4_crc.hpp"
#include "jointguard/node/joint_drive.hpp"
#include "jointguard/protocol/frames.hpp"
#include "jointguard/protocol/reaction_frames.hpp"

namespace {

// Counts its calls: proves the drive really used the port's policy.
struct CountingBitwise {
  static inline unsigned calls = 0;
  static std::uint8_t crc8(const std::uint8_t* data, std::uint8_t length) noexcept {
    ++calls;
    return jg::hal::crc8_autosar_bitwise(data, length);
  }
};
struct NotAPolicy {
  static int crc8(const std::uint8_t*, std::uint8_t) noexcept { return 0; }
};
static_assert(jg::hal::is_crc8_policy_v<CountingBitwise>);
static_assert(!jg::hal::is_crc8_policy_v<NotAPolicy>, "wrong return type is refused at compile time");
static_assert(!jg::hal::is_crc8_policy_v<int>);
static_assert(std::is_same_v<jg::hal::crc8_policy_t<jg::hal::LoopbackCan<4>>, jg::hal::Crc8AutosarTable>,
              "a port without a policy gets the table");

/// A port that records what it sends and hands out what the test queues.
template <class Policy>
class RecordingPort {
 public:
  using crc8_policy = Policy;
  jg::hal::CanStatus send(const jg::hal::CanFrame& f) noexcept {
    sent.push_back(f);
    return jg::hal::CanStatus::ok;
  }
  bool receive(jg::hal::CanFrame& f) noexcept {
    if (inbox.empty()) {
      return false;
    }
    f = inbox.front();
    inbox.pop_front();
    return true;
  }
  [[nodiscard]] jg::hal::CanErrorState error_state() const noexcept { return jg::hal::CanErrorState::error_active; }
  void set_filters(const jg::hal::CanFilter*, std::size_t) noexcept {}
  std::vector<jg::hal::CanFrame> sent;
  std::deque<jg::hal::CanFrame> inbox;
};

TEST(CrcPolicy, CodecsGiveTheSameFramesWithTheReferencePolicy) {
  using jg::hal::Crc8AutosarBitwise;
  namespace p = jg::protocol;
  jg::OutwardMessage<float> out{};
  out.angular_velocity = {0.1F, -0.2F, 0.3F};
  out.gravity = {0.0F, 0.0F, -9.81F};
  jg::InwardMessage<float> in{};
  in.first_moment = {0.36F, 0.01F, -0.02F};
  in.mass = 2.0F;
  std::uint8_t a[64] = {}, b[64] = {};
  for (std::uint8_t seq = 0; seq < 200; seq = static_cast<std::uint8_t>(seq + 7U)) {
    out.origin_velocity.x = 0.01F * seq;
    in.linear_momentum.y = -0.03F * seq;
    ASSERT_EQ(p::encode_outward(out, seq, a), (p::encode_outward<float, Crc8AutosarBitwise>(out, seq, b)));
    ASSERT_EQ(std::memcmp(a, b, p::kMomentumFrameLength), 0);
    EXPECT_EQ(p::check_outward<Crc8AutosarBitwise>(a, p::kMomentumFrameLength), p::FrameError::ok);
    ASSERT_EQ(p::encode_inward(in, seq, a), (p::encode_inward<float, Crc8AutosarBitwise>(in, seq, b)));
    ASSERT_EQ(std::memcmp(a, b, p::kMomentumFrameLength), 0);
    a[9] ^= 0x10U;  // a corrupted byte fails either policy's check
    EXPECT_EQ(p::check_inward<Crc8AutosarBitwise>(a, p::kMomentumFrameLength), p::FrameError::bad_crc);
    EXPECT_EQ(p::check_inward(a, p::kMomentumFrameLength), p::FrameError::bad_crc);
    ASSERT_EQ(p::encode_sync(1000U + seq, a), p::encode_sync<Crc8AutosarBitwise>(1000U + seq, b));
    ASSERT_EQ(std::memcmp(a, b, p::kSyncFrameLength), 0);
    const p::StatusMessage<float> st{1.5F * seq, p::kStatusReady, 3U};
    ASSERT_EQ(p::encode_status(st, seq, a), (p::encode_status<float, Crc8AutosarBitwise>(st, seq, b)));
    ASSERT_EQ(std::memcmp(a, b, p::kStatusFrameLength), 0);
  }
}

// A CRC other than CRC-8/AUTOSAR (its complement-like variant): frames encoded with it fail
// the table's check and the other way round, so a codec that ignored the port's policy shows.
struct OtherCrc {
  static std::uint8_t crc8(const std::uint8_t* data, std::uint8_t length) noexcept {
    return static_cast<std::uint8_t>(jg::hal::crc8_autosar_bitwise(data, length) ^ 0xA5U);
  }
};
static_assert(jg::hal::is_crc8_policy_v<OtherCrc>);

// The neighbours' frames and the sync of cycle c, as the bus delivers them (CRC by Policy).
template <class Policy = jg::hal::Crc8AutosarTable, class Port>
void deliver(Port& port, std::uint32_t c) {
  namespace p = jg::protocol;
  jg::hal::CanFrame f{};
  f.fd = true;
  jg::OutwardMessage<float> parent{};
  parent.angular_velocity.z = 0.3F;
  parent.gravity.z = -9.81F;
  f.id = p::frame_id(p::MessageKind::outward, 1U);
  f.length = p::encode_outward<float, Policy>(parent, static_cast<std::uint8_t>(c - 1U), static_cast<std::uint8_t*>(f.data));
  port.inbox.push_back(f);
  jg::InwardMessage<float> child{};
  child.mass = 2.0F;
  child.first_moment = {0.36F, 0.0F, 0.0F};
  f.id = p::frame_id(p::MessageKind::inward, 3U);
  f.length = p::encode_inward<float, Policy>(child, static_cast<std::uint8_t>(c - 1U), static_cast<std::uint8_t*>(f.data));
  port.inbox.push_back(f);
  f.id = p::kSyncId;
  f.length = p::encode_sync<Policy>(c, static_cast<std::uint8_t*>(f.data));
  port.inbox.push_back(f);
}

// A one-section observer at 1 kHz and a 2 N·m threshold: enough for frames to flow.
jg::JointEstimatorParams<float> drive_params() {
  jg::JointEstimatorParams<float> params{};
  params.observer.sections = 1;
  params.observer.decay[0] = 0.86F;
  params.observer.input_gain[0] = 0.14F;
  params.observer.inv_dt = 1000.0F;
  params.threshold = {2.0F, 0.0F, 0.0F, 1.0F};
  params.debounce = {2};
  return params;
}

template <class Policy>
std::vector<jg::hal::CanFrame> run_drive(RecordingPort<Policy>& port) {
  const jg::JointEstimatorParams<float> params = drive_params();
  jg::JointDrive<float, RecordingPort<Policy>> drive(jg::DriveConfig{jg::NodeConfig{2, 3, 5, 2}, false}, params, port,
                                                     {0.0F, 0.0F, -9.81F});
  for (std::uint32_t c = 1; c <= 12; ++c) {
    deliver(port, c);
    drive.set_sample(0.6F + 0.001F * c, 0.4F, c > 8 ? 60.0F : 20.0F);
    EXPECT_TRUE(drive.poll());
  }
  const jg::NodeCounters& n = drive.node().counters();
  EXPECT_EQ(n.bad_crc + n.wrong_length + n.stale + drive.counters().sync_rejected, 0U) << "every frame accepted";
  return port.sent;
}

TEST(CrcPolicy, DriveSendsIdenticalFramesWithAStandInHardwarePolicy) {
  RecordingPort<jg::hal::Crc8AutosarTable> table_port;
  RecordingPort<CountingBitwise> bitwise_port;
  CountingBitwise::calls = 0;
  const auto with_table = run_drive(table_port);
  const auto with_bitwise = run_drive(bitwise_port);
  // 12 cycles: 3 frames checked (sync, outward, inward) and 3 encoded (outward, inward, status)
  // per cycle, plus the collision event once it is raised.
  EXPECT_GE(CountingBitwise::calls, 12U * 6U) << "the drive and its node use the port's policy";
  ASSERT_EQ(with_table.size(), with_bitwise.size());
  ASSERT_GE(with_table.size(), 36U);
  for (std::size_t i = 0; i < with_table.size(); ++i) {
    ASSERT_EQ(with_table[i].id, with_bitwise[i].id) << "frame " << i;
    ASSERT_EQ(with_table[i].length, with_bitwise[i].length) << "frame " << i;
    ASSERT_EQ(std::memcmp(with_table[i].data, with_bitwise[i].data, with_table[i].length), 0) << "frame " << i;
  }
}

// The reaction's frames (command in, reaction status out) use the port's policy too: a
// drive on another CRC takes a command encoded with it, refuses one with the table's CRC,
// and its reaction status checks with its own CRC only.
TEST(CrcPolicy, ReactionFramesUseThePortPolicy) {
  namespace p = jg::protocol;
  RecordingPort<OtherCrc> port;
  const jg::JointEstimatorParams<float> params = drive_params();
  jg::JointDrive<float, RecordingPort<OtherCrc>> drive(jg::DriveConfig{jg::NodeConfig{2, 3, 5, 2}, false}, params, port,
                                                      {0.0F, 0.0F, -9.81F});
  const auto command = [&](bool own_policy) {
    p::ReactionCommandMessage<float> m{};
    m.reaction = jg::Reaction::stop;
    m.collided = 0x02U;
    jg::hal::CanFrame f{};
    f.fd = true;
    f.id = p::kReactionCommandId;
    f.length = own_policy ? p::encode_reaction_command<float, OtherCrc>(m, 7U, static_cast<std::uint8_t*>(f.data))
                          : p::encode_reaction_command(m, 7U, static_cast<std::uint8_t*>(f.data));
    port.inbox.push_back(f);
  };
  for (std::uint32_t c = 1; c <= 6; ++c) {
    if (c == 3) command(false);  // the table's CRC: refused
    if (c == 5) command(true);
    deliver<OtherCrc>(port, c);
    drive.set_sample(0.6F, 0.0F, 20.0F);
    EXPECT_TRUE(drive.poll()) << "cycle " << c;
  }
  EXPECT_EQ(drive.counters().command_rejected, 1U);
  const jg::NodeCounters& n = drive.node().counters();
  EXPECT_EQ(n.bad_crc + drive.counters().sync_rejected, 0U) << "the neighbours' frames pass the port's policy";
  unsigned reaction_status = 0;
  for (const jg::hal::CanFrame& f : port.sent) {
    if (f.id != p::frame_id(p::MessageKind::joint_state, 2U)) continue;
    ++reaction_status;
    p::ReactionStatusMessage<float> m{};
    std::uint8_t seq = 0;
    EXPECT_EQ((p::decode_reaction_status<float, OtherCrc>(f.data, f.length, m, seq)), p::FrameError::ok);
    EXPECT_EQ(p::decode_reaction_status(f.data, f.length, m, seq), p::FrameError::bad_crc);
  }
  EXPECT_GE(reaction_status, 1U) << "the drive reacted to the command with its own CRC";
}

// A model of the STM32G4 CRC unit's arithmetic (RM0440): POL, INIT, CR.POLYSIZE and
// CR.RESET (loads INIT), data written to DR shifted in most significant bit first, 8 or 32
// bits a write; no reversal (the reset values of REV_IN/REV_OUT, checked to stay 0).
struct CrcUnitModel {
  static inline std::uint32_t pol = 0x04C11DB7U, init = 0xFFFFFFFFU, cr = 0, dr = 0xFFFFFFFFU;
  static inline unsigned word_writes = 0, byte_writes = 0;
  static inline bool stray = false;
  static unsigned width() {
    constexpr unsigned kWidths[4] = {32U, 16U, 8U, 7U};  // POLYSIZE 00, 01, 10, 11
    return kWidths[(cr >> 3U) & 3U];
  }
  static void shift_in(std::uint32_t data, unsigned bits) {
    const unsigned w = width();
    const std::uint32_t top = 1U << (w - 1U);
    const std::uint32_t mask = w == 32U ? 0xFFFFFFFFU : (1U << w) - 1U;
    for (unsigned i = bits; i-- > 0U;) {
      const bool feedback = ((dr & top) != 0U) != (((data >> i) & 1U) != 0U);
      dr = (dr << 1U) & mask;
      if (feedback) {
        dr ^= pol & mask;
      }
    }
  }
  [[nodiscard]] std::uint32_t read(std::uint32_t address) const {
    if (address == jg::hal::stm32g4::crc::kDr) {
      return dr;
    }
    stray = true;
    return 0U;
  }
  void write(std::uint32_t address, std::uint32_t value) {
    namespace crc = jg::hal::stm32g4::crc;
    if (address == crc::kPol) {
      pol = value;
    } else if (address == crc::kInit) {
      init = value;
    } else if (address == crc::kCr) {
      cr = value & ~crc::kCrReset;
      if ((value & 0xE0U) != 0U) {
        stray = true;  // reversal bits: not CRC-8/AUTOSAR
      }
      if ((value & crc::kCrReset) != 0U) {
        dr = init;
      }
    } else if (address == crc::kDr) {
      ++word_writes;
      shift_in(value, 32U);
    } else {
      stray = true;
    }
  }
  void write8(std::uint32_t address, std::uint8_t value) {
    if (address != jg::hal::stm32g4::crc::kDr) {
      stray = true;
      return;
    }
    ++byte_writes;
    shift_in(value, 8U);
  }
};

TEST(CrcPolicy, Stm32g4CrcUnitSequenceGivesCrc8Autosar) {
  using Unit = jg::hal::stm32g4::Crc8AutosarUnit<CrcUnitModel>;
  static_assert(jg::hal::is_crc8_policy_v<Unit>);
  const char* check = "123456789";
  EXPECT_EQ(Unit::crc8(reinterpret_cast<const std::uint8_t*>(check), 9), 0xDF);  // the catalogue's check value
  std::uint8_t buf[80];
  std::uint32_t x = 12345U;
  for (auto& b : buf) {
    x = x * 1103515245U + 12345U;
    b = static_cast<std::uint8_t>(x >> 16U);
  }
  for (unsigned offset = 0; offset < 4U; ++offset) {
    for (std::uint8_t n = 0; n <= 64U; ++n) {
      ASSERT_EQ(Unit::crc8(buf + offset, n), jg::hal::crc8_autosar_bitwise(buf + offset, n))
          << "length " << int{n} << " offset " << offset;
    }
  }
  EXPECT_FALSE(CrcUnitModel::stray);
  EXPECT_GT(CrcUnitModel::word_writes, 0U) << "whole words go as 32-bit writes";
  EXPECT_GT(CrcUnitModel::byte_writes, 0U);
  // A frame encoded on the unit is the frame encoded with the table.
  jg::InwardMessage<float> in{};
  in.angular_momentum = {0.5F, -0.25F, 1.0F};
  in.mass = 3.5F;
  std::uint8_t a[64] = {}, b[64] = {};
  jg::protocol::encode_inward(in, 42U, a);
  jg::protocol::encode_inward<float, Unit>(in, 42U, b);
  EXPECT_EQ(std::memcmp(a, b, jg::protocol::kMomentumFrameLength), 0);
  EXPECT_EQ(jg::protocol::check_inward<Unit>(a, jg::protocol::kMomentumFrameLength), jg::protocol::FrameError::ok);
}

}  // namespace
