// Simulated CAN bus: arbitration order, frame timing with worst-case stuffing, bus load
// for the joint protocol, and each injected fault's observable effect.
#include <gtest/gtest.h>

#include <cstdio>

#include "can/sim_bus.hpp"
#include "jointguard/protocol/frames.hpp"

namespace {
using jg::can::BusTiming;
using jg::can::SimBus;
using jg::hal::CanFrame;

CanFrame frame(std::uint32_t id, std::uint8_t length, bool fd) {
  CanFrame f;
  f.id = id;
  f.length = length;
  f.fd = fd;
  return f;
}

TEST(SimBus, LowestIdentifierWinsArbitration) {
  SimBus bus(BusTiming{});
  auto& a = bus.attach();
  auto& b = bus.attach();
  auto& c = bus.attach();
  (void)a.send(frame(0x035, 8, false));
  (void)b.send(frame(0x001, 8, false));
  (void)c.send(frame(0x023, 8, false));
  bus.run_until(0.01);
  ASSERT_EQ(bus.transmit_order().size(), 3U);
  EXPECT_EQ(bus.transmit_order()[0], 0x001U);
  EXPECT_EQ(bus.transmit_order()[1], 0x023U);
  EXPECT_EQ(bus.transmit_order()[2], 0x035U);
  CanFrame r;
  int got = 0;
  while (a.receive(r)) ++got;
  EXPECT_EQ(got, 2) << "a node does not receive its own frame";
}

TEST(SimBus, FrameDurationsFollowTheWorstCaseFormulas) {
  // Classic CAN, 8 bytes at 1 Mbit/s: 47 + 64 + floor(97/4) = 135 bits.
  EXPECT_DOUBLE_EQ(jg::can::frame_bits(frame(0x10, 8, false)).nominal, 135.0);
  EXPECT_NEAR(jg::can::frame_duration_s(frame(0x10, 8, false), BusTiming{}), 135e-6, 1e-12);
  // CAN FD, 48 bytes: 34 nominal bits; data 1 + 4 + 384 + 4 + 21 + 6 + floor(388/4) = 517.
  const auto b = jg::can::frame_bits(frame(0x23, 48, true));
  EXPECT_DOUBLE_EQ(b.nominal, 34.0);
  EXPECT_DOUBLE_EQ(b.data, 517.0);
}

// Bus load of one control cycle: 2(n-1) momentum messages (outward to each child, inward
// to each parent), n status frames (8 bytes), one cycle sync. Classic CAN carries a 48-byte
// message as 7 frames of 8 bytes.
TEST(SimBus, BusLoadTableForTheJointProtocol) {
  std::printf("| joints | bus | frames per cycle | wire time per cycle [us] | highest cycle rate at 100 %% load [Hz] | at 70 %% [Hz] |\n|---|---|---|---|---|---|\n");
  for (const int n : {3, 7}) {
    for (const double data_bps : {1e6, 5e6, 8e6}) {
      const bool fd = data_bps > 1e6;
      const BusTiming timing{1e6, data_bps};
      double wire = 0.0;
      int frames = 0;
      const int momentum = 2 * (n - 1);
      if (fd) {
        wire += momentum * jg::can::frame_duration_s(frame(0x23, 48, true), timing);
        frames += momentum;
      } else {
        wire += momentum * 7 * jg::can::frame_duration_s(frame(0x23, 8, false), timing);
        frames += momentum * 7;
      }
      // Status frames and the sync: 8 bytes, in the data phase on an FD bus.
      wire += n * jg::can::frame_duration_s(frame(0x51, 8, fd), timing) + jg::can::frame_duration_s(frame(0x10, 8, fd), timing);
      frames += n + 1;
      const std::string bus_name = fd ? "CAN FD 1/" + std::to_string(static_cast<int>(data_bps / 1e6)) + " Mbit/s" : "classic 1 Mbit/s";
      std::printf("| %d | %s | %d | %.0f | %.0f | %.0f |\n", n, bus_name.c_str(), frames, wire * 1e6, 1.0 / wire, 0.7 / wire);
      if (n == 3 && data_bps == 5e6) {
        // tests/can/hil/hil_check.sh compares the SocketCAN capture with this figure.
        EXPECT_NEAR(wire * 1e6, 775.2, 0.5);
      }
      // Measured on the simulated bus: the same frames queued at once take that long.
      SimBus bus(timing);
      auto& p = bus.attach();
      (void)bus.attach();
      for (int k = 0; k < frames - n - 1; ++k) (void)p.send(fd ? frame(0x23, 48, true) : frame(0x23, 8, false));
      for (int k = 0; k < n; ++k) (void)p.send(frame(0x51, 8, fd));
      (void)p.send(frame(0x10, 8, fd));
      bus.run_until(1.0);
      EXPECT_NEAR(bus.busy_time(), wire, 1e-9);
    }
  }
}

TEST(SimBus, InjectedFaultsHaveTheirEffect) {
  jg::can::FaultPlan drop;
  drop.drop_probability = 1.0;
  SimBus lossy(BusTiming{}, drop);
  auto& s1 = lossy.attach();
  auto& r1 = lossy.attach();
  (void)s1.send(frame(0x23, 8, false));
  lossy.run_until(0.01);
  CanFrame got;
  EXPECT_FALSE(r1.receive(got)) << "dropped";

  jg::can::FaultPlan corrupt;
  corrupt.corrupt_probability = 1.0;
  SimBus noisy(BusTiming{}, corrupt);
  auto& s2 = noisy.attach();
  auto& r2 = noisy.attach();
  CanFrame f = frame(0x23, 48, true);
  jg::InwardMessage<jg::q16> m{};
  m.mass = jg::q16::from_double(3.0);
  f.length = jg::protocol::encode_inward(m, 1, f.data);
  (void)s2.send(f);
  noisy.run_until(0.01);
  ASSERT_TRUE(r2.receive(got));
  jg::InwardMessage<jg::q16> back{};
  std::uint8_t seq = 0;
  EXPECT_EQ(jg::protocol::decode_inward(got.data, got.length, back, seq), jg::protocol::FrameError::bad_crc);

  jg::can::FaultPlan dup;
  dup.duplicate_probability = 1.0;
  dup.extra_delay_s = 0.002;
  SimBus twice(BusTiming{}, dup);
  auto& s3 = twice.attach();
  auto& r3 = twice.attach();
  (void)s3.send(frame(0x23, 8, false));
  twice.run_until(0.01);
  ASSERT_TRUE(r3.receive(got));
  EXPECT_GE(got.timestamp_us, 2000U) << "delayed";
  EXPECT_TRUE(r3.receive(got)) << "duplicated";

  SimBus babble(BusTiming{});
  auto& good = babble.attach();
  (void)babble.attach();
  babble.set_babbler(1, frame(0x000, 8, false));
  (void)good.send(frame(0x23, 8, false));
  babble.run_until(0.01);
  for (const auto id : babble.transmit_order()) EXPECT_EQ(id, 0x000U) << "a babbling top-priority node starves the bus";

  SimBus off(BusTiming{});
  auto& dead = off.attach();
  (void)off.attach();
  dead.go_bus_off();
  EXPECT_EQ(dead.send(frame(0x23, 8, false)), jg::hal::CanStatus::bus_off);
  dead.recover();
  EXPECT_EQ(dead.send(frame(0x23, 8, false)), jg::hal::CanStatus::ok);
}
}  // namespace
