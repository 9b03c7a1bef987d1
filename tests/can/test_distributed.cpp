// The joint nodes on a simulated CAN FD bus against the centralised chain (same firmware
// functions composed in-process) on the paper's collisions; and the node's fault handling.
#include <gtest/gtest.h>

#include "../common/unit_link.hpp"
#include "can/cycle_budget.hpp"
#include "eval/distributed_estimator.hpp"
#include "eval/firmware_estimator.hpp"
#include "jointguard/hal/loopback_can.hpp"
#include "jointguard/node/joint_node.hpp"
#include "models/paper_friction.hpp"
#include "robot/robot_model.hpp"
#include "sim/scenario.hpp"

namespace {
using namespace jg;

struct Trace {
  std::vector<std::vector<double>> mu;  // [sample][joint]
};

Trace run(eval::Estimator& e, const io::Recording& rec) {
  Trace t;
  sim::JointVector mu;
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    eval::EstimatorInput in{sim::JointVector(3), sim::JointVector(3), sim::JointVector(3)};
    for (int j = 0; j < 3; ++j) {
      in.q(j) = rec.q[static_cast<std::size_t>(j)][k];
      in.dq(j) = rec.dq[static_cast<std::size_t>(j)][k];
      in.tau_m(j) = rec.tau_m[static_cast<std::size_t>(j)][k];
    }
    if (k == 0) e.reset(in);
    e.step(in, mu);
    t.mu.push_back({mu(0), mu(1), mu(2)});
  }
  return t;
}

TEST(DistributedNodes, AgreeWithTheCentralisedChainOnThePaperCollisions) {
  const auto model = robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  for (const char* name : {"waist", "shoulder", "elbow"}) {
    auto scenario = sim::load_scenario(std::string(JG_SOURCE_DIR) + "/scenarios/paper_collision_" + name + ".yaml");
    const auto rec = sim::run_simulation(scenario.setup).recording;
    for (const char* scalar : {"float", "q"}) {
      eval::FirmwareEstimatorConfig fc;
      fc.model = model;
      fc.dt = 0.001;
      fc.observer = {ObserverKind::first_order, 150.0, 0.0, 0.0};
      fc.friction.assign(sim::kPaperTable1.begin(), sim::kPaperTable1.end());
      auto central = eval::make_firmware_estimator(fc, scalar);
      eval::DistributedConfig dc;
      dc.estimator = fc;
      auto distributed = eval::make_distributed_estimator(dc, scalar);
      const Trace a = run(*central, rec), b = run(*distributed, rec);
      double worst = 0.0;
      std::size_t first_a = 0, first_b = 0;
      for (std::size_t k = 0; k < a.mu.size(); ++k) {
        for (int j = 0; j < 3; ++j) {
          if (k < 200) continue;  // both settle from rest (the nodes also fill the chain first)
          worst = std::max(worst, std::fabs(a.mu[k][static_cast<std::size_t>(j)] - b.mu[k][static_cast<std::size_t>(j)]));
          if (first_a == 0 && std::fabs(a.mu[k][static_cast<std::size_t>(j)]) > 5.0) first_a = k;
          if (first_b == 0 && std::fabs(b.mu[k][static_cast<std::size_t>(j)]) > 5.0) first_b = k;
        }
      }
      std::printf("%s %s: distributed vs centralised worst |mu difference| %.3f N·m; 5 N·m crossed at sample %zu vs %zu\n",
                  name, scalar, worst, first_a, first_b);
      EXPECT_LT(worst, 1.5);  // the measured cost of previous-cycle terms (docs/can.md)
      // Inward terms of link i+k reach joint i k cycles late: at most joints - 1 = 2 cycles.
      EXPECT_LE(first_b > first_a ? first_b - first_a : first_a - first_b, 2U) << "same detection within two cycles";
    }
  }
}

TEST(JointNodeFaults, SilentNeighbourRaisesTheFaultAndARestartResynchronises) {
  using Port = hal::LoopbackCan<16>;
  Port parent_port, child_port;
  const JointEstimatorParams<float> p = test::unit_link_params(1e4F);  // never flags: the bus is under test
  // Joint 2 of 3 listens on child_port; we play its neighbours by hand.
  JointNode<float, Port> node(NodeConfig{2, 3, 3}, p, child_port, Vec3<float>{0.0F, 0.0F, -9.81F});
  auto feed = [&](std::uint8_t seq, bool corrupt, std::uint32_t id) {
    hal::CanFrame f{};
    f.fd = true;
    f.id = id;
    OutwardMessage<float> m{};
    m.gravity.z = -9.81F;
    f.length = protocol::encode_outward(m, seq, f.data);
    if (corrupt) f.data[3] ^= 1U;
    (void)child_port.send(f);
  };
  auto feed_child = [&](std::uint8_t seq) {
    hal::CanFrame f{};
    f.fd = true;
    f.id = protocol::frame_id(protocol::MessageKind::inward, 3);
    InwardMessage<float> m{};
    f.length = protocol::encode_inward(m, seq, f.data);
    (void)child_port.send(f);
  };
  const auto parent_id = protocol::frame_id(protocol::MessageKind::outward, 1);
  for (std::uint8_t k = 0; k < 10; ++k) {
    feed(k, false, parent_id);
    feed_child(k);
    (void)node.cycle(0.1F, 0.0F, 0.0F);
    EXPECT_FALSE(node.communication_fault());
  }
  for (int k = 0; k < 4; ++k) {  // the parent falls silent (child still talks)
    feed_child(static_cast<std::uint8_t>(10 + k));
    (void)node.cycle(0.1F, 0.0F, 0.0F);
  }
  EXPECT_TRUE(node.communication_fault()) << "silent for more than 3 cycles";
  EXPECT_EQ(node.counters().missed_cycles, 4U) << "each silent cycle ran on the parent's last message";
  feed(0, false, parent_id);  // the parent restarted: its counter starts again at 0
  feed_child(14);
  (void)node.cycle(0.1F, 0.0F, 0.0F);
  EXPECT_FALSE(node.communication_fault()) << "resynchronised without restarting the others";
  const auto foreign_before = node.counters().foreign;
  feed(0, false, parent_id);  // duplicate
  feed(1, true, parent_id);   // corrupt
  feed(2, false, protocol::frame_id(protocol::MessageKind::outward, 5));  // someone else's
  feed_child(15);
  (void)node.cycle(0.1F, 0.0F, 0.0F);
  EXPECT_EQ(node.counters().stale, 1U);
  EXPECT_EQ(node.counters().bad_crc, 1U);
  EXPECT_EQ(node.counters().missed_cycles, 5U) << "a duplicate and a corrupt frame are not fresh";
  // The loopback port also returns the node's own two frames of the previous cycle.
  EXPECT_EQ(node.counters().foreign - foreign_before, 3U) << "someone else's frame is never decoded";
  (void)parent_port;
}
}  // namespace

namespace {
// The drives with their own samples (as on the arm) or the plant's sensor frames, on the
// recording of the paper's shoulder collision: what the bus carried over the run.
struct BusRun {
  Trace trace;
  eval::BusStatistics stats;
};
BusRun run_on_bus(bool sensors_over_can, const char* scalar) {
  const auto model = robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  auto scenario = sim::load_scenario(std::string(JG_SOURCE_DIR) + "/scenarios/paper_collision_shoulder.yaml");
  const auto rec = sim::run_simulation(scenario.setup).recording;
  eval::DistributedConfig dc;
  dc.estimator.model = model;
  dc.estimator.dt = 0.001;
  dc.estimator.observer = {ObserverKind::first_order, 150.0, 0.0, 0.0};
  dc.estimator.friction.assign(sim::kPaperTable1.begin(), sim::kPaperTable1.end());
  dc.sensors_over_can = sensors_over_can;
  auto bus = eval::make_distributed_estimator(dc, scalar);
  BusRun r;
  r.trace = run(*bus, rec);
  r.stats = bus->statistics();
  return r;
}
}  // namespace

TEST(CycleBudget, CountsWhatTheSimulatedBusCarriesPerCycle) {
  for (const bool sensors : {true, false}) {
    const BusRun r = run_on_bus(sensors, "float");
    const can::CycleBudget b = can::cycle_budget(3, eval::DistributedConfig{}.timing, sensors);
    const double cycles = static_cast<double>(r.trace.mu.size());
    // The drives' boot announcements and the collision events on a detector's rising edge
    // come on top of the cycle; they are a handful in a whole run.
    EXPECT_NEAR(static_cast<double>(r.stats.frames) / cycles, static_cast<double>(b.frames), 0.01) << "sensors " << sensors;
    EXPECT_NEAR(r.stats.busy_s / cycles, b.wire_s, 0.01 * b.wire_s) << "sensors " << sensors;
    EXPECT_EQ(r.stats.incomplete_cycles, 0U);
  }
  // A chain of n: sync, 2 (n - 1) momentum frames, n status frames (and n sensor frames).
  EXPECT_EQ(can::cycle_budget(7, {}, false).frames, 1U + 12U + 7U);
  EXPECT_EQ(can::cycle_budget(7, {}, true).frames, 1U + 12U + 7U + 7U);
  // Seven drives at 1 / 8 Mbit/s do not fit a 1 kHz cycle (the momentum frames alone are
  // 12 x 48 bytes); three do.
  EXPECT_GT(can::cycle_budget(7, {1e6, 8e6}, false).wire_s, 1e-3);
  EXPECT_LT(can::cycle_budget(3, {1e6, 8e6}, true).wire_s, 1e-3);
}

TEST(CycleBudget, ShorterMomentumFramesAloneDoNotFitSixOrSevenDrivesInOneKilohertz) {
  // The same messages with 16-bit fields (24-byte frames) save the data phase's bits, but a
  // frame's nominal-rate part (header, ACK, end of frame: 34 bits, 34 us at 1 Mbit/s) stays:
  // per cycle six drives still need more than 1 ms at 1 / 8 Mbit/s, seven clearly more.
  const can::BusTiming fd{1e6, 8e6};
  for (const std::size_t n : {6U, 7U}) {
    const can::CycleBudget full = can::cycle_budget(n, fd, false), short16 = can::cycle_budget(n, fd, false, 24);
    std::printf("%zu drives: 48-byte momentum frames %.3f ms (%.0f Hz), 24-byte %.3f ms (%.0f Hz)\n", n, 1e3 * full.wire_s,
                full.max_rate_hz(), 1e3 * short16.wire_s, short16.max_rate_hz());
    EXPECT_EQ(short16.frames, full.frames);
    EXPECT_LT(short16.wire_s, full.wire_s);
    EXPECT_GT(short16.wire_s, 1e-3) << n << " drives";
  }
  // The saving is the data phase only: 24 bytes fewer, with their worst-case stuffing.
  const double per_frame = (can::cycle_budget(7, fd, false).wire_s - can::cycle_budget(7, fd, false, 24).wire_s) / 12.0;
  EXPECT_NEAR(per_frame, (24.0 * 8.0 + 48.0) / 8e6, 1e-9);
}

TEST(DistributedNodes, OwnSamplesGiveTheEstimatesOfSensorFrames) {
  // Float drives: sensor frames carry Q16.16 samples, their own samples are exact; the
  // estimates agree to that quantisation.
  for (const char* scalar : {"float", "q"}) {
    const BusRun frames = run_on_bus(true, scalar), own = run_on_bus(false, scalar);
    ASSERT_EQ(frames.trace.mu.size(), own.trace.mu.size());
    double worst = 0.0, largest = 0.0;
    for (std::size_t k = 200; k < own.trace.mu.size(); ++k) {
      for (std::size_t j = 0; j < 3; ++j) {
        worst = std::max(worst, std::fabs(frames.trace.mu[k][j] - own.trace.mu[k][j]));
        largest = std::max(largest, std::fabs(own.trace.mu[k][j]));
      }
    }
    std::printf("%s: own samples against sensor frames, worst |mu difference| %.4f N·m (largest |mu| %.1f N·m)\n", scalar,
                worst, largest);
    EXPECT_GT(largest, 10.0);  // the collision is in the estimate
    EXPECT_LT(worst, 0.05);
    EXPECT_LT(own.stats.frames, frames.stats.frames);
  }
}
