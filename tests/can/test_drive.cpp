// The joint drive on a bus: cycle pacing by the master's sync and sensor frames in either
// arrival order, rejection of bad sync/sensor/foreign frames, status and collision-event
// frames; the drives in the loop of the simulated arm against the centralised chain on the
// paper's collisions; every bus fault of issue 5 ending in its documented state.
#include <gtest/gtest.h>

#include "../common/unit_link.hpp"
#include "can/bus_master.hpp"
#include "can/sim_bus.hpp"
#include "eval/distributed_estimator.hpp"
#include "eval/experiments.hpp"
#include "eval/firmware_estimator.hpp"
#include "hil/hil_run.hpp"
#include "jointguard/node/joint_drive.hpp"
#include "models/paper_friction.hpp"
#include "robot/robot_model.hpp"
#include "sim/scenario.hpp"

namespace {
using namespace jg;

using test::unit_link_params;

hal::CanFrame sensor_frame(std::uint8_t joint, std::uint8_t seq, double q, double dq, double tau) {
  hal::CanFrame f{};
  f.fd = true;
  f.id = protocol::frame_id(protocol::MessageKind::sensor, joint);
  f.length = protocol::encode_sensor(protocol::SensorMessage<q16>{q16::from_double(q), q16::from_double(dq), q16::from_double(tau)}, seq,
                                     f.data);
  return f;
}
hal::CanFrame sync_frame(std::uint32_t cycle) {
  hal::CanFrame f{};
  f.fd = true;
  f.id = protocol::kSyncId;
  f.length = protocol::encode_sync(cycle, f.data);
  return f;
}

TEST(JointDrive, RunsOnceSyncAndItsSampleAreInWhateverTheirOrder) {
  can::SimBus bus({1e6, 5e6});
  can::SimPort& master = bus.attach();
  JointDrive<float, can::SimPort> drive(DriveConfig{NodeConfig{1, 1, 5}, true}, unit_link_params(1e4F), bus.attach(),
                                        Vec3<float>{0.0F, 0.0F, -9.81F});
  double t = 0.0;
  auto deliver = [&] { bus.run_until(t += 0.001); };
  // Sync first (it wins arbitration over sensor frames on a real bus), then the sample.
  ASSERT_EQ(master.send(sync_frame(0)), hal::CanStatus::ok);
  deliver();
  EXPECT_FALSE(drive.poll()) << "no sample for cycle 0 yet";
  ASSERT_EQ(master.send(sensor_frame(1, 0, 0.1, 0.0, 0.0)), hal::CanStatus::ok);
  deliver();
  EXPECT_TRUE(drive.poll());
  EXPECT_EQ(drive.counters().cycles, 1U);
  // Sample first, then sync.
  (void)master.send(sensor_frame(1, 1, 0.1, 0.0, 0.0));
  deliver();
  EXPECT_FALSE(drive.poll());
  (void)master.send(sync_frame(1));
  deliver();
  EXPECT_TRUE(drive.poll());
  // A repeated sync, a corrupt sync, a corrupt sample and someone else's frames: no cycle.
  hal::CanFrame bad_sync = sync_frame(2);
  bad_sync.data[2] ^= 0x40U;
  hal::CanFrame bad_sample = sensor_frame(1, 2, 0.1, 0.0, 0.0);
  bad_sample.data[5] ^= 0x01U;
  hal::CanFrame short_sample = sensor_frame(1, 2, 0.1, 0.0, 0.0);
  short_sample.length = 12;
  for (const auto& f : {sync_frame(1), bad_sync, bad_sample, short_sample, sensor_frame(2, 2, 0.0, 0.0, 0.0)}) (void)master.send(f);
  deliver();
  EXPECT_FALSE(drive.poll());
  EXPECT_EQ(drive.counters().stale_syncs, 1U);
  EXPECT_EQ(drive.counters().sync_rejected, 1U);
  EXPECT_EQ(drive.counters().sensor_rejected, 2U) << "corrupt and short samples; joint 2's sample is filtered out";
  EXPECT_EQ(drive.counters().cycles, 2U);
  // The master saw one status per cycle, with the cycle's sequence number.
  std::size_t statuses = 0;
  hal::CanFrame f{};
  while (master.receive(f)) {
    protocol::StatusMessage<q16> s{};
    std::uint8_t seq = 0;
    if (f.id == protocol::frame_id(protocol::MessageKind::status, 1)) {
      ASSERT_EQ(protocol::decode_status(f.data, f.length, s, seq), protocol::FrameError::ok);
      EXPECT_EQ(seq, statuses);
      ++statuses;
    }
  }
  EXPECT_EQ(statuses, 2U);
}

TEST(JointDrive, CorruptSamplesAreCountedAndNeverUsed) {
  can::SimBus bus({1e6, 5e6});
  can::SimPort& master = bus.attach();
  JointDrive<float, can::SimPort> drive(DriveConfig{NodeConfig{1, 1, 5}, true}, unit_link_params(1e4F), bus.attach(),
                                        Vec3<float>{0.0F, 0.0F, -9.81F});
  hal::CanFrame bad = sensor_frame(1, 0, 100.0, 0.0, 0.0);
  bad.data[3] ^= 0x08U;
  (void)master.send(bad);
  (void)master.send(sync_frame(0));
  bus.run_until(0.001);
  EXPECT_FALSE(drive.poll());
  EXPECT_EQ(drive.counters().sensor_rejected, 1U);
}

TEST(JointDrive, ARestartedMasterIsFollowedAfterARunOfStaleSyncs) {
  can::SimBus bus({1e6, 5e6});
  can::SimPort& master = bus.attach();
  JointDrive<float, can::SimPort> drive(DriveConfig{NodeConfig{1, 1, 3}, true}, unit_link_params(1e4F), bus.attach(),
                                        Vec3<float>{0.0F, 0.0F, -9.81F});
  double t = 0.0;
  auto cycle = [&](std::uint32_t k) {
    (void)master.send(sensor_frame(1, static_cast<std::uint8_t>(k & 0xFFU), 0.1, 0.0, 0.0));
    (void)master.send(sync_frame(k));
    bus.run_until(t += 0.001);
    return drive.poll();
  };
  for (std::uint32_t k = 100; k < 110; ++k) ASSERT_TRUE(cycle(k));
  // The master restarts and counts from 0 again: stale at first, followed after
  // fault_cycles (3) stale syncs in a row.
  EXPECT_FALSE(cycle(0));
  EXPECT_FALSE(cycle(1));
  EXPECT_FALSE(cycle(2));
  EXPECT_TRUE(cycle(3));
  EXPECT_EQ(drive.last_cycle(), 3U);
  EXPECT_EQ(drive.counters().stale_syncs, 3U);
  EXPECT_TRUE(cycle(4));
}

struct PaperSetup {
  robot::RobotModel model = robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  hil::HilConfig config() const {
    hil::HilConfig c;
    c.model = model;
    c.friction.assign(sim::kPaperTable1.begin(), sim::kPaperTable1.end());
    c.thresholds.threshold = {2.5, 2.5, 2.0};
    c.thresholds.low_speed_extra = {3.0, 3.0, 3.0};
    return c;
  }
  /// The drives of config() on the simulated bus at 1 kHz, with `faults` injected.
  eval::DistributedConfig bus_config(const can::FaultPlan& faults = {}) const {
    const hil::HilConfig c = config();
    eval::DistributedConfig dc;
    dc.estimator.model = c.model;
    dc.estimator.dt = 0.001;
    dc.estimator.friction = c.friction;
    dc.node_thresholds = eval::threshold_bands(c.thresholds);
    dc.faults = faults;
    return dc;
  }
};

TEST(DrivesInTheLoop, DetectAsTheCentralisedChainOnThePaperCollisions) {
  const PaperSetup ps;
  for (const char* name : {"waist", "shoulder", "elbow"}) {
    const auto scenario = sim::load_scenario(std::string(JG_SOURCE_DIR) + "/scenarios/paper_collision_" + name + ".yaml");
    for (const char* scalar : {"float", "q"}) {
      hil::HilConfig c = ps.config();
      c.scalar = scalar;
      const hil::HilResult bus = hil::run_hil(scenario, c);
      // The centralised chain: the same firmware functions composed in one process.
      eval::FirmwareEstimatorConfig fc;
      fc.model = c.model;
      fc.dt = 1.0 / scenario.setup.control_rate_hz;
      fc.observer = c.gains;
      fc.friction = c.friction;
      auto central = eval::make_firmware_estimator(fc, scalar);
      eval::DetectionConfig d;
      d.threshold = c.thresholds.threshold;
      d.low_speed_extra = c.thresholds.low_speed_extra;
      d.contact.enabled = false;  // the detection is compared here, not the contact estimate
      const eval::RunResult ref = eval::run_detection(scenario.setup, *central, d, name, false);
      ASSERT_TRUE(ref.t_detected && bus.run.t_detected) << name << ' ' << scalar;
      const double cycles = (*bus.run.t_detected - *ref.t_detected) * scenario.setup.control_rate_hz;
      std::printf("%s %s: centralised %.3f s link %d, drives on the bus %.3f s link %d (%+.0f cycles), drives' own flag %.3f s link %d\n",
                  name, scalar, *ref.t_detected, ref.link_isolated, *bus.run.t_detected, bus.run.link_isolated, cycles,
                  bus.run.t_node_flagged ? *bus.run.t_node_flagged : -1.0, bus.run.link_node_isolated);
      // Previous-cycle neighbour terms put the estimates up to 1.2 N·m apart while the
      // torque rises (docs/can.md): the crossing moves by a few cycles.
      EXPECT_LE(std::fabs(cycles), 5.0);
      EXPECT_EQ(bus.run.link_isolated, bus.run.link_true);
      ASSERT_TRUE(bus.run.t_node_flagged.has_value()) << "the drives' own detectors flag too";
      EXPECT_DOUBLE_EQ(*bus.run.t_node_flagged, *bus.run.t_detected) << "same band, same estimate, same cycle";
      EXPECT_EQ(bus.incomplete_cycles, 0U) << "every status frame in within its cycle at 1/8 Mbit/s";
      EXPECT_EQ(bus.master.rejected, 0U);
      EXPECT_FALSE(bus.run.t_comm_fault.has_value());
      ASSERT_FALSE(bus.events.empty());
    }
  }
}

/// One fault on the simulated bus during the shoulder scenario: the run must end with the
/// drives reporting a communication fault and the arm holding (or, for faults the protocol
/// absorbs, with no fault and the collision still detected).
struct FaultCase {
  const char* name;
  can::FaultPlan plan;
  bool expect_fault;
};

TEST(DrivesInTheLoop, EveryBusFaultEndsInItsDocumentedState) {
  const PaperSetup ps;
  const auto scenario = sim::load_scenario(std::string(JG_SOURCE_DIR) + "/scenarios/paper_collision_shoulder.yaml");
  const std::uint32_t outward_j2 = protocol::frame_id(protocol::MessageKind::outward, 2);
  auto plan = [&](double drop, double corrupt, double dup, double delay) {
    can::FaultPlan p;
    p.drop_probability = drop;
    p.corrupt_probability = corrupt;
    p.duplicate_probability = dup;
    p.extra_delay_s = delay;
    p.affected_id_mask = 0x7FF;
    p.affected_id_match = outward_j2;
    return p;
  };
  const FaultCase cases[] = {
      {"missing (dropped) neighbour frames", plan(1.0, 0, 0, 0), true},
      {"late neighbour frames (10 cycles)", plan(0, 0, 0, 0.010), true},
      {"corrupt neighbour frames", plan(0, 1.0, 0, 0), true},
      {"duplicated (out-of-sequence) neighbour frames", plan(0, 0, 1.0, 0), false},
  };
  for (const FaultCase& fc : cases) {
    const hil::HilConfig c = ps.config();
    auto est = eval::make_distributed_estimator(ps.bus_config(fc.plan), "float");
    eval::DetectionConfig d;
    d.threshold = c.thresholds.threshold;
    d.low_speed_extra = c.thresholds.low_speed_extra;
    d.contact.enabled = false;  // the detection and the faults are tested here, not the contact estimate
    const eval::RunResult r = eval::run_detection(scenario.setup, *est, d, fc.name, true);
    const eval::BusStatistics s = est->statistics();
    const eval::DriveReport& j3 = s.drives[2];
    std::printf("%s: comm fault %s at %.3f s; joint 3 rejected crc %u, stale %u, late %u; detection %s\n", fc.name,
                j3.communication_fault ? "yes" : "no", r.t_comm_fault ? *r.t_comm_fault : -1.0, j3.node.bad_crc, j3.node.stale, j3.node.late,
                r.t_detected ? std::to_string(*r.t_detected).c_str() : "none");
    if (fc.expect_fault) {
      ASSERT_TRUE(r.t_comm_fault.has_value()) << fc.name;
      EXPECT_LT(*r.t_comm_fault, 0.02) << "raised within fault_cycles (5) of the start";
      EXPECT_FALSE(j3.ready) << "joint 3 never trusted its estimate";
      // The arm holds: its joints stay where they were once the reaction settled.
      const auto& rec = r.recording;
      double drift = 0.0;
      std::size_t k0 = 0;
      while (k0 < rec.samples() && rec.t[k0] < 0.5) ++k0;
      for (std::size_t k = k0; k < rec.samples(); ++k) {
        for (const auto& q : rec.q) drift = std::max(drift, std::fabs(q[k] - q[k0]));
      }
      EXPECT_LT(drift, 0.01) << fc.name << ": the arm holds after the communication fault";
    } else {
      EXPECT_FALSE(r.t_comm_fault.has_value()) << fc.name;
      EXPECT_GT(j3.node.stale, 1000U) << "every duplicate recognised by its sequence number";
      ASSERT_TRUE(r.t_detected.has_value());
    }
    if (std::string(fc.name).find("late") != std::string::npos) {
      EXPECT_GT(j3.node.late, 1000U);
    }
    if (std::string(fc.name).find("corrupt") != std::string::npos) {
      EXPECT_GT(j3.node.bad_crc, 1000U);
    }
  }
}

TEST(DrivesInTheLoop, BusOffAndBabblingNodeRaiseTheCommunicationFault) {
  const PaperSetup ps;
  const auto scenario = sim::load_scenario(std::string(JG_SOURCE_DIR) + "/scenarios/paper_collision_shoulder.yaml");
  for (const char* fault : {"bus-off", "babbling"}) {
    const hil::HilConfig c = ps.config();
    auto est = eval::make_distributed_estimator(ps.bus_config(), "q");
    if (std::string(fault) == "bus-off") {
      est->bus().port(2).go_bus_off();  // drive 2's controller leaves the bus
    } else {
      hal::CanFrame babble{};
      babble.id = 0x001;  // highest priority: starves everyone else
      babble.length = 8;
      est->bus().set_babbler(2, babble);
    }
    eval::DetectionConfig d;
    d.threshold = c.thresholds.threshold;
    d.low_speed_extra = c.thresholds.low_speed_extra;
    d.contact.enabled = false;  // the detection and the faults are tested here, not the contact estimate
    const eval::RunResult r = eval::run_detection(scenario.setup, *est, d, fault, false);
    const eval::BusStatistics s = est->statistics();
    std::printf("%s: comm fault at %s s, incomplete cycles %zu\n", fault, r.t_comm_fault ? std::to_string(*r.t_comm_fault).c_str() : "never",
                s.incomplete_cycles);
    if (std::string(fault) == "bus-off") {
      ASSERT_TRUE(r.t_comm_fault.has_value()) << "drives 1 and 3 lose drive 2";
      EXPECT_TRUE(s.drives[0].communication_fault && s.drives[2].communication_fault);
    } else {
      // Nothing else gets on the bus: the master hears no status at all, which it treats
      // as a communication fault after 5 cycles (the drives cannot report it).
      EXPECT_GT(s.incomplete_cycles, 7000U);
      ASSERT_TRUE(r.t_comm_fault.has_value());
      EXPECT_LT(*r.t_comm_fault, 0.01);
    }
  }
}

}  // namespace
