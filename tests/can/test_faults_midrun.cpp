// Every row of docs/can.md's fault table injected MID-RUN on the simulated bus (the
// `--fault` specs the CLI takes), in the 2.2 s shoulder scenario at 1 kHz (collision at
// 1.5 s): the fault raised within its stated number of cycles from its start, the arm
// holding from then on, and recovery where the table states it. Printed lines give the
// measured detection cycles for the table.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "can/fault_spec.hpp"
#include "jointguard/protocol/sensor_validity.hpp"
#include "hil/hil_run.hpp"
#include "models/paper_friction.hpp"
#include "robot/robot_model.hpp"
#include "sim/scenario.hpp"

namespace {
using namespace jg;

enum class Raised { communication, input, none };

struct Row {
  const char* spec;
  Raised raised;
  int max_cycles;       ///< fault raised at most this many cycles after its start
  bool recovers;        ///< at the end: no drive or master fault left, every drive ready
  bool neighbours;      ///< drives 1 and 3 themselves report the communication fault
  bool no_false_events = false;  ///< no drive sends a collision event before the push
};

struct ShoulderRun {
  sim::Scenario scenario = sim::load_scenario(std::string(JG_SOURCE_DIR) + "/tests/can/hil/hil_shoulder.yaml", 0, false,
                                              std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  hil::HilConfig config(const char* scalar) const {
    hil::HilConfig c;
    c.model = robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
    c.friction.assign(sim::kPaperTable1.begin(), sim::kPaperTable1.end());
    c.thresholds.threshold = {2.5, 2.5, 2.0};
    c.thresholds.low_speed_extra = {3.0, 3.0, 3.0};
    c.scalar = scalar;
    return c;
  }
  hil::HilResult run(const char* scalar, const std::vector<std::string>& specs) const {
    hil::HilConfig c = config(scalar);
    for (const auto& s : specs) c.faults.push_back(hil::parse_fault(s));
    return hil::run_hil(scenario, c);
  }
};

/// Largest joint excursion [rad] from t0 to the end of the run.
double drift_after(const io::Recording& rec, double t0) {
  std::size_t k0 = 0;
  while (k0 < rec.samples() && rec.t[k0] < t0) ++k0;
  double drift = 0.0;
  for (std::size_t k = k0; k < rec.samples(); ++k) {
    for (const auto& q : rec.q) drift = std::max(drift, std::fabs(q[k] - q[k0]));
  }
  return drift;
}

const Row kRows[] = {
    {"drop:2@0.5:0.2", Raised::communication, 5, true, true, true},       // every frame drive 2 sends lost
    {"drop:0x022@0.5:0.2", Raised::communication, 6, true, false},   // only its outward messages: joint 3 reports it
    {"late:2@0.5:0.2", Raised::communication, 5, true, true},
    {"corrupt:2@0.5:0.2", Raised::communication, 5, true, true, true},
    {"duplicate:2@0.5:0.2", Raised::none, 0, true, false, true},
    {"bus-off:2@0.5:0.2", Raised::communication, 5, true, true, true},
    {"babble@0.5:0.2", Raised::communication, 5, true, false},
    {"restart:2@0.5:0.3", Raised::communication, 5, true, true, true},
    {"restart:2@0.5", Raised::communication, 1, true, false},
    {"link-down@0.5:0.5", Raised::communication, 5, true, false},
    {"nan-sensor:2@0.5:0.2", Raised::input, 0, true, false},
    {"corrupt:0x062@0.5:0.2", Raised::communication, 5, true, true},  // drive 2's samples: no cycle runs on them
    {"corrupt:0x010@0.5:0.2", Raised::communication, 5, true, false},  // the sync: no drive runs
};

TEST(FaultsMidRun, EveryTableRowEndsInItsStatedState) {
  const ShoulderRun s;
  const double dt = 1.0 / s.scenario.setup.control_rate_hz;
  for (const char* scalar : {"float", "q"}) {
    const hil::HilResult clean = s.run(scalar, {});
    ASSERT_TRUE(clean.run.t_detected.has_value());
    ASSERT_FALSE(clean.run.t_comm_fault.has_value());
    for (const Row& row : kRows) {
      SCOPED_TRACE(std::string(row.spec) + " " + scalar);
      const hil::FaultSpec spec = hil::parse_fault(row.spec);
      const hil::HilResult r = s.run(scalar, {row.spec});
      const std::optional<double> raised = row.raised == Raised::input ? r.run.t_input_fault : r.run.t_comm_fault;
      const double cycles = raised ? std::round((*raised - spec.start_s) / dt) : -1.0;
      std::printf("%-24s %-5s %s at %s s (%+.0f cycles after the start); drift after hold %.4f rad; end: master fault %s, drives",
                  row.spec, scalar, row.raised == Raised::input ? "input fault" : "communication fault",
                  raised ? std::to_string(*raised).c_str() : "never", cycles,
                  raised ? drift_after(r.run.recording, *raised + 0.1) : 0.0, r.master_comm_fault_end ? "yes" : "no");
      for (const auto& d : r.drives) std::printf(" [%s%s]", d.communication_fault ? "comm fault " : "", d.ready ? "ready" : "not ready");
      std::size_t early_events = 0;  // collision events from the drives before the push at 1.5 s
      for (const auto& e : r.events) early_events += static_cast<double>(e.cycle) * dt < 1.5 ? 1U : 0U;
      std::printf("; events before the push %zu", early_events);
      if (row.no_false_events) {
        EXPECT_EQ(early_events, 0U) << "no drive reports a collision it did not see";
      }
      std::printf("; restarts %llu; drives' own fault at cycles", static_cast<unsigned long long>(r.master.restarts));
      for (const auto c : r.first_comm_fault_cycle) std::printf(" %+lld", c < 0 ? -1LL : static_cast<long long>(c) - static_cast<long long>(std::llround(spec.start_s / dt)));
      std::printf("\n");
      if (row.neighbours) {
        for (const std::size_t j : {std::size_t{0}, std::size_t{2}}) {
          ASSERT_GE(r.first_comm_fault_cycle[j], 0) << "drive " << j + 1 << " reports the fault itself";
          EXPECT_LE(static_cast<double>(r.first_comm_fault_cycle[j]) - std::round(spec.start_s / dt), 6.0);
        }
      }
      for (const auto& m : r.run.trace.mu) {
        for (const double v : m) ASSERT_TRUE(std::isfinite(v)) << "no NaN ever reaches an estimate";
      }
      if (row.raised == Raised::none) {
        EXPECT_FALSE(r.run.t_comm_fault.has_value());
        EXPECT_FALSE(r.run.t_input_fault.has_value());
        ASSERT_TRUE(r.run.t_detected.has_value()) << "the collision is still detected";
        EXPECT_EQ(*r.run.t_detected, *clean.run.t_detected) << "duplicates are absorbed: same estimates";
        EXPECT_EQ(r.run.trace.mu, clean.run.trace.mu);
        EXPECT_GT(r.drives[0].node.stale + r.drives[2].node.stale, 100U) << "every duplicate recognised by its sequence number";
      } else {
        ASSERT_TRUE(raised.has_value()) << "fault raised";
        EXPECT_GE(*raised, spec.start_s) << "nothing before the fault starts";
        EXPECT_LE(cycles, row.max_cycles) << "raised within the stated cycles";
        if (row.raised == Raised::input) {
          EXPECT_FALSE(r.run.t_comm_fault.has_value()) << "the neighbours keep running on the drive's repeated messages";
        }
        // The arm holds: from 0.1 s after the fault (the hold settling) to the end of the
        // run, including the push at 1.5 s.
        EXPECT_LT(drift_after(r.run.recording, *raised + 0.1), 0.01) << "the arm holds";
        EXPECT_GT(drift_after(clean.run.recording, *raised + 0.1), 0.1) << "the fault-free arm moves on";
      }
      if (row.recovers) {
        EXPECT_FALSE(r.master_comm_fault_end) << "the master sees every drive again";
        EXPECT_FALSE(r.master_input_fault_end) << "the samples are usable again";
        ASSERT_EQ(r.drives.size(), 3U);
        for (const auto& d : r.drives) {
          EXPECT_FALSE(d.communication_fault) << "neighbours accept each other again";
          EXPECT_TRUE(d.ready);
          EXPECT_FALSE(d.drive.cycles == 0U);
        }
      }
      if (spec.kind == hil::FaultKind::restart) {
        EXPECT_EQ(r.master.restarts, 1U) << "the master saw the rebooted drive announce itself";
        EXPECT_GT(r.drives[1].drive.cycles, 1000U) << "the new drive 2 ran from the next sync on";
      }
      if (spec.kind == hil::FaultKind::late) {
        EXPECT_GT(r.drives[0].node.late + r.drives[2].node.late, 100U);
      }
      if (spec.kind == hil::FaultKind::corrupt && spec.joint == 2) {
        EXPECT_GT(r.drives[0].node.bad_crc + r.drives[2].node.bad_crc, 100U);
      }
      if (spec.kind == hil::FaultKind::nan_sensor) {
        EXPECT_GT(r.master.invalid_samples, 100U);
      }
    }
  }
}

TEST(FaultsMidRun, FaultsOutsideTheirWindowLeaveTheRunUnchanged) {
  // A fault whose window opens after the run: byte-identical estimates to a fault-free run.
  const ShoulderRun s;
  const hil::HilResult clean = s.run("float", {});
  hil::HilConfig c = s.config("float");
  c.faults.push_back(hil::parse_fault("drop@3.0:0.1"));
  const hil::HilResult later = hil::run_hil(s.scenario, c);
  EXPECT_EQ(later.run.trace.mu, clean.run.trace.mu);
}

TEST(FaultsMidRun, TheMastersFrameFaultsInFourWindowsOfOneRun) {
  // The run of can.hil_socketcan's "frames" step (the specs the SocketCAN master injects,
  // tests/can/hil/hil_payload.sh), on the simulated bus: each window's fault spans, as the
  // VM test expects them on SocketCAN (it compares the two runs' spans and estimates).
  const ShoulderRun s;
  for (const char* scalar : {"float", "q"}) {
    SCOPED_TRACE(scalar);
    const hil::HilResult r = s.run(scalar, {"duplicate:0x010@0.3:0.05", "duplicate:0x062@0.3:0.05", "drop:0x062@0.5:0.05",
                                            "corrupt:0x062@0.8:0.05", "nan-sensor:2@1.1:0.05"});
    using Kind = hil::FaultEpisode::Kind;
    std::vector<std::string> spans;
    for (const auto& e : r.fault_episodes) {
      spans.push_back(std::string(e.kind == Kind::input ? "input" : "comm") + " " + std::to_string(e.joint) + " " +
                      std::to_string(e.from_cycle) + "-" + std::to_string(e.to_cycle));
    }
    // Duplicates absorbed (no span before 500); drive 2 without samples (drop, corrupt): the
    // master in the 5th cycle, drives 1 and 3 in the 6th, clear 2 cycles after the window;
    // NaN samples: an input fault in the window's cycles only, no communication fault.
    const std::vector<std::string> expected = {"comm 0 504-551", "comm 1 505-551", "comm 3 505-551", "comm 0 804-851",
                                               "comm 1 805-851", "comm 3 805-851", "input 0 1100-1150", "input 2 1100-1150"};
    EXPECT_EQ(spans, expected);
    ASSERT_EQ(r.drives.size(), 3U);
    EXPECT_EQ(r.drives[1].drive.sensor_rejected, 50U) << "every corrupted sample rejected";
    EXPECT_EQ(r.drives[0].drive.cycles, 2201U);
    EXPECT_EQ(r.drives[1].drive.cycles, 2101U) << "no cycle without a sample";
    EXPECT_EQ(r.master.invalid_samples, 50U);
    EXPECT_FALSE(r.master_comm_fault_end || r.master_input_fault_end);
  }
}

TEST(FaultSpec, AWindowCoversTheSameCyclesWhetherTimeIsCountedOrSummed) {
  // The simulated bus sums the period (1100 cycles: 1.0999999999999897 s), the SocketCAN
  // master and drives count cycles (1100 x 0.001 = 1.1); 0.8 + 0.05 rounds up to
  // 0.8500000000000001. Either way a 0.05 s window at 1 kHz is cycles START..START+49.
  for (const char* text : {"nan-sensor:2@1.1:0.05", "corrupt:0x062@0.8:0.05", "drop@0.5:0.05", "bus-off:2@1.45:0.2"}) {
    const hil::FaultSpec f = hil::parse_fault(text);
    const auto first = static_cast<int>(std::lround(f.start_s / 0.001));
    const auto last = static_cast<int>(std::lround(f.end_s() / 0.001)) - 1;
    double summed = 0.0;
    for (int k = 0; k < 2200; ++k, summed += 0.001) {
      const bool in = k >= first && k <= last;
      EXPECT_EQ(f.active(static_cast<double>(k) * 0.001), in) << text << " counted, cycle " << k;
      EXPECT_EQ(f.active(summed), in) << text << " summed, cycle " << k;
    }
  }
}

TEST(FaultSpec, ParsesTheDocumentedSyntaxAndRefusesTheRest) {
  const hil::FaultSpec a = hil::parse_fault("drop:2@0.5:0.2");
  EXPECT_EQ(a.kind, hil::FaultKind::drop);
  EXPECT_EQ(a.joint, 2);
  EXPECT_DOUBLE_EQ(a.start_s, 0.5);
  EXPECT_DOUBLE_EQ(a.duration_s, 0.2);
  const hil::FaultSpec b = hil::parse_fault("babble@1");
  EXPECT_EQ(b.id, 0x001U);
  EXPECT_TRUE(std::isinf(b.duration_s));
  EXPECT_EQ(hil::parse_fault("corrupt:0x062@0:1").id, 0x062U);
  EXPECT_DOUBLE_EQ(hil::parse_fault("restart:3@0.5").duration_s, 0.0);
  for (const char* bad : {"drop", "drop@", "drop@x", "drop@-1", "drop@nan", "drop@inf", "drop@0.5:0", "drop@0.5:-1", "flood@0.5",
                          "drop:0@1", "drop:8@1", "drop:0x800@1", "drop:@1", "restart@0.5", "bus-off@1", "babble:2@1",
                          "link-down:1@1", "drop@1@2", "drop@0x10", "drop@1e999", "nan-sensor:abc@1"}) {
    EXPECT_THROW((void)hil::parse_fault(bad), std::invalid_argument) << bad;
  }
  EXPECT_THROW(hil::check_faults({hil::parse_fault("drop:4@0.5")}, 3, 2.2), std::invalid_argument);
  EXPECT_THROW(hil::check_faults({hil::parse_fault("drop@2.2")}, 3, 2.2), std::invalid_argument);
  EXPECT_NO_THROW(hil::check_faults({hil::parse_fault("drop:3@2.1")}, 3, 2.2));
}

TEST(SensorValidity, TheInvalidMarkerIsNoValueAndSaturationNeverProducesIt) {
  std::uint8_t buf[protocol::kSensorFrameLength]{};
  // The most negative value a sender can encode saturates to -INT32_MAX, not the marker.
  const protocol::SensorMessage<q16> lowest{q16::from_double(-1e9), q16::from_double(-1e300), q16::from_double(0.5)};
  ASSERT_EQ(protocol::encode_sensor(lowest, 7, buf), protocol::kSensorFrameLength);
  EXPECT_TRUE(protocol::sensor_fields_valid(buf));
  protocol::mark_sensor_field_invalid(buf, 1);
  protocol::SensorMessage<float> m{};
  std::uint8_t seq = 0;
  ASSERT_EQ(protocol::decode_sensor(buf, protocol::kSensorFrameLength, m, seq), protocol::FrameError::ok) << "CRC recomputed";
  EXPECT_EQ(seq, 7U);
  EXPECT_FALSE(protocol::sensor_fields_valid(buf));
}

}  // namespace
