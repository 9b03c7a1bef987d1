// The reaction on the drives (issue 17): the reaction law of node/joint_reaction.hpp in
// float and Q16.16 against double, its two frames (round trip, refusals, the DBC), and
// the drive's hook: no reaction frame before the master's command, then its status goes
// out every cycle as the reaction status (status + torque term from the joint's hold point).
#include <gtest/gtest.h>

#include <cmath>

#include "../common/unit_link.hpp"
#include "can/dbc.hpp"
#include "can/sim_bus.hpp"
#include "jointguard/node/joint_drive.hpp"
#include "jointguard/node/joint_reaction.hpp"
#include "jointguard/protocol/reaction_frames.hpp"

namespace {
using namespace jg;

template <class S>
double run_law(Reaction kind, bool collided, int cycles, double q0, double target, double mu, double friction, double dq_of_k) {
  const ReactionGains<S> g = reaction_gains<S>(0.001);
  JointReactionState<S> st{};
  start_reaction(st, ReactionCommand<S>{kind, collided, from_double<S>(target)}, from_double<S>(q0));
  double out = 0.0;
  for (int k = 0; k < cycles; ++k) {
    out = to_double(reaction_torque(g, st, from_double<S>(q0), from_double<S>(dq_of_k), from_double<S>(mu), from_double<S>(friction)));
  }
  return out;
}

TEST(ReactionLaw, EachReactionGivesItsTorqueInEveryScalar) {
  for (int scalar = 0; scalar < 3; ++scalar) {
    auto law = [scalar](Reaction r, bool collided, int cycles, double q0, double target, double mu, double fr, double dq) {
      if (scalar == 0) return run_law<double>(r, collided, cycles, q0, target, mu, fr, dq);
      if (scalar == 1) return run_law<float>(r, collided, cycles, q0, target, mu, fr, dq);
      return run_law<q16>(r, collided, cycles, q0, target, mu, fr, dq);
    };
    const double tol = scalar == 2 ? 0.05 : 1e-3;
    // Stop: a joint still at its hold point moving at 0.1 rad/s: -D dq = -6 N·m.
    EXPECT_NEAR(law(Reaction::stop, false, 1, 0.5, 0.0, 3.0, 1.0, 0.1), -6.0, tol) << scalar;
    // Zero gravity: the friction prediction only.
    EXPECT_NEAR(law(Reaction::zero_gravity, false, 5, 0.5, 0.0, 3.0, 1.25, 0.1), 1.25, tol) << scalar;
    // Retreat: halfway (cycle 150 of 300) the reference is halfway to the target:
    // K x (-0.05) = -100 N·m at rest; after 300 cycles the whole way: -200 N·m.
    EXPECT_NEAR(law(Reaction::retreat, false, 151, 0.5, 0.4, 0.0, 0.0, 0.0), -100.0, scalar == 2 ? 0.5 : 0.01) << scalar;
    EXPECT_NEAR(law(Reaction::retreat, false, 400, 0.5, 0.4, 0.0, 0.0, 0.0), -200.0, scalar == 2 ? 0.05 : 0.01) << scalar;
    // Reflex: a collided joint pushes along its estimate for 0.3 s (G mu - D_r dq), then
    // holds where it is; a joint outside the signature holds from the start.
    EXPECT_NEAR(law(Reaction::reflex, true, 10, 0.5, 0.0, 3.0, 0.0, 0.2), 3.0 - 1.0, tol) << scalar;
    EXPECT_NEAR(law(Reaction::reflex, true, 302, 0.5, 0.0, 3.0, 0.0, 0.2), -12.0, tol) << scalar;
    EXPECT_NEAR(law(Reaction::reflex, false, 10, 0.5, 0.0, 3.0, 0.0, 0.2), -12.0, tol) << scalar;
    EXPECT_EQ(law(Reaction::none, false, 10, 0.5, 0.0, 3.0, 1.0, 0.2), 0.0) << scalar;
  }
}

TEST(ReactionLaw, FirstCommandWinsAndQ16SaturatesInsteadOfWrapping) {
  JointReactionState<q16> st{};
  start_reaction(st, ReactionCommand<q16>{Reaction::stop, false, q16{}}, q16::from_double(1.0));
  start_reaction(st, ReactionCommand<q16>{Reaction::retreat, false, q16::from_double(5.0)}, q16::from_double(2.0));
  EXPECT_EQ(st.kind, Reaction::stop);
  EXPECT_EQ(st.hold.to_double(), 1.0);
  // 2000 N·m/rad x 30 rad is beyond Q16.16: the torque saturates at the range's end.
  const q16 t = reaction_torque(ReactionGains<q16>{}, st, q16::from_double(-29.0), q16{}, q16{}, q16{});
  EXPECT_GT(t.to_double(), 32767.0);
}

TEST(ReactionFrames, RoundTripAndRefusals) {
  protocol::ReactionCommandMessage<q16> c{};
  c.reaction = Reaction::retreat;
  c.collided = 0x06U;
  for (int j = 0; j < 7; ++j) c.retreat_target[j] = q16::from_double(0.1 * (j + 1) - 0.35);
  std::uint8_t buf[64]{};
  const std::uint8_t len = protocol::encode_reaction_command(c, 42, buf);
  ASSERT_EQ(len, protocol::kReactionCommandLength);
  Reaction r{};
  bool collided = false;
  float target = 0.0F;
  ASSERT_EQ(protocol::decode_reaction_command(buf, len, 3, r, collided, target), protocol::FrameError::ok);
  EXPECT_EQ(r, Reaction::retreat);
  EXPECT_TRUE(collided);
  EXPECT_NEAR(target, -0.05F, 1e-4F);
  ASSERT_EQ(protocol::decode_reaction_command(buf, len, 1, r, collided, target), protocol::FrameError::ok);
  EXPECT_FALSE(collided);
  std::uint8_t bad[64]{};
  std::copy(buf, buf + 64, bad);
  bad[10] ^= 0x10U;
  EXPECT_EQ(protocol::decode_reaction_command(bad, len, 1, r, collided, target), protocol::FrameError::bad_crc);
  EXPECT_EQ(protocol::decode_reaction_command(buf, 8, 1, r, collided, target), protocol::FrameError::wrong_length);
  protocol::ReactionCommandMessage<q16> none = c;
  none.reaction = Reaction::none;  // "no reaction" is never commanded: refused
  (void)protocol::encode_reaction_command(none, 1, bad);
  EXPECT_EQ(protocol::decode_reaction_command(bad, len, 1, r, collided, target), protocol::FrameError::bad_padding);

  const protocol::ReactionStatusMessage<float> m{{2.25F, protocol::kStatusCollision | protocol::kStatusReady, 3}, -12.5F};
  const std::uint8_t tl = protocol::encode_reaction_status(m, 9, buf);
  ASSERT_EQ(tl, protocol::kReactionStatusLength);
  protocol::ReactionStatusMessage<q16> back{};
  std::uint8_t seq = 0;
  ASSERT_EQ(protocol::decode_reaction_status(buf, tl, back, seq), protocol::FrameError::ok);
  EXPECT_EQ(back.torque.to_double(), -12.5);
  EXPECT_EQ(back.status.external_torque.to_double(), 2.25);
  EXPECT_EQ(back.status.flags, protocol::kStatusCollision | protocol::kStatusReady);
  EXPECT_EQ(back.status.rejected, 3);
  EXPECT_EQ(seq, 9);
  // Bytes 0-6 are the status frame's: a status decoder reads the same fields.
  std::uint8_t st[8]{};
  (void)protocol::encode_status(m.status, 9, st);
  EXPECT_TRUE(std::equal(st, st + 7, buf));
  EXPECT_EQ(protocol::decode_reaction_status(buf, 8, back, seq), protocol::FrameError::wrong_length);

  // The DBC describes both frames as sent.
  const can::Dbc dbc = can::read_dbc(std::string(JG_SOURCE_DIR) + "/docs/can/jointguard.dbc");
  ASSERT_EQ(dbc.messages.count(protocol::kReactionCommandId), 1U);
  EXPECT_EQ(dbc.messages.at(protocol::kReactionCommandId).length, protocol::kReactionCommandLength);
  const auto tid = protocol::frame_id(protocol::MessageKind::joint_state, 2);
  ASSERT_EQ(dbc.messages.count(tid), 1U);
  EXPECT_EQ(dbc.messages.at(tid).length, protocol::kReactionStatusLength);
  for (const auto& s : dbc.messages.at(tid).signals) {
    if (s.name == "reaction_torque") {
      EXPECT_DOUBLE_EQ(can::decode_signal(s, buf, tl), -12.5);
    }
    if (s.name == "external_torque") {
      EXPECT_DOUBLE_EQ(can::decode_signal(s, buf, tl), 2.25);
    }
  }
  (void)protocol::encode_reaction_command(c, 42, buf);
  for (const auto& s : dbc.messages.at(protocol::kReactionCommandId).signals) {
    if (s.name == "retreat_target_j3") {
      EXPECT_NEAR(can::decode_signal(s, buf, len), -0.05, 1e-4);
    }
    if (s.name == "collided") {
      EXPECT_EQ(can::decode_signal(s, buf, len), 6.0);
    }
  }
}

hal::CanFrame sensor_frame(std::uint8_t seq, double q, double dq) {
  hal::CanFrame f{};
  f.fd = true;
  f.id = protocol::frame_id(protocol::MessageKind::sensor, 1);
  f.length = protocol::encode_sensor(protocol::SensorMessage<q16>{q16::from_double(q), q16::from_double(dq), q16{}}, seq, f.data);
  return f;
}

TEST(ReactionDrive, TorqueFramesOnlyAfterTheCommandFromTheHoldPoint) {
  can::SimBus bus({1e6, 8e6});
  can::SimPort& master = bus.attach();
  JointDrive<float, can::SimPort> drive(DriveConfig{NodeConfig{1, 1, 5}, true}, test::unit_link_params(1e4F), bus.attach(),
                                        Vec3<float>{0.0F, 0.0F, -9.81F});
  double t = 0.0;
  std::size_t torque_frames = 0, statuses = 0;
  double last_torque = 0.0;
  auto cycle = [&](std::uint32_t k, double q, double dq, bool command) {
    if (command) {
      protocol::ReactionCommandMessage<q16> c{};
      c.reaction = Reaction::stop;
      hal::CanFrame f{};
      f.fd = true;
      f.id = protocol::kReactionCommandId;
      f.length = protocol::encode_reaction_command(c, static_cast<std::uint8_t>(k), f.data);
      ASSERT_EQ(master.send(f), hal::CanStatus::ok);
    }
    ASSERT_EQ(master.send(sensor_frame(static_cast<std::uint8_t>(k), q, dq)), hal::CanStatus::ok);
    hal::CanFrame s{};
    s.fd = true;
    s.id = protocol::kSyncId;
    s.length = protocol::encode_sync(k, s.data);
    ASSERT_EQ(master.send(s), hal::CanStatus::ok);
    bus.run_until(t += 0.0005);
    (void)drive.poll();
    bus.run_until(t += 0.0005);  // the drive's frames reach the master
    hal::CanFrame f{};
    while (master.receive(f)) {
      if (protocol::kind_of(f.id) == protocol::MessageKind::status) ++statuses;
      if (protocol::kind_of(f.id) != protocol::MessageKind::joint_state) continue;
      protocol::ReactionStatusMessage<q16> m{};
      std::uint8_t seq = 0;
      ASSERT_EQ(protocol::decode_reaction_status(f.data, f.length, m, seq), protocol::FrameError::ok);
      EXPECT_EQ(seq, static_cast<std::uint8_t>(k));
      ++torque_frames;
      last_torque = m.torque.to_double();
    }
  };
  for (std::uint32_t k = 0; k < 5; ++k) cycle(k, 0.1 * k, 0.0, false);
  EXPECT_EQ(torque_frames, 0U) << "no reaction frame while no collision is raised";
  EXPECT_EQ(statuses, 5U);
  EXPECT_EQ(drive.reaction().kind, Reaction::none);
  cycle(5, 0.5, 0.0, true);  // the command: the drive holds where it is (0.5 rad)
  EXPECT_EQ(torque_frames, 1U);
  EXPECT_EQ(drive.reaction().kind, Reaction::stop);
  cycle(6, 0.51, 0.0, false);  // pushed 0.01 rad away: K x -0.01 = -20 N·m
  EXPECT_EQ(torque_frames, 2U);
  EXPECT_NEAR(last_torque, -20.0, 0.05);
  EXPECT_EQ(statuses, 5U) << "a reacting drive's status goes out as the reaction status frame";  // positions travel as Q16.16: 2000 x 2^-16 rad steps
  EXPECT_EQ(drive.counters().command_rejected, 0U);
}

}  // namespace
