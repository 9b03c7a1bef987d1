// Holding-aware detection in closed loop: a small push on a joint whose controller holds
// its setpoint is detected by the change from the estimate at arrival, with no alarm in a
// hold without contact (simulated arm, firmware core in the loop, both scalars).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "../common/expect_refused.hpp"
#include "eval/distributed_estimator.hpp"
#include "eval/experiments.hpp"
#include "models/paper_friction.hpp"

namespace {
using namespace jg;

eval::ExperimentConfig config(const std::string& scalar) {
  eval::ExperimentConfig c;
  c.model = robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  c.scalar = scalar;
  for (const auto& p : sim::kPaperTable1) c.friction.push_back(p);
  c.calibration_s = 60.0;
  c.hold_calibration_s = 120.0;
  const eval::Thresholds t = eval::calibrate(c, 0.5);
  c.thresholds = t.threshold;
  c.low_speed_extra = t.low_speed_extra;
  c.low_speed_width = t.low_speed_width;
  c.hold_threshold = t.hold_change;
  c.reaction = Reaction::none;
  return c;
}

eval::RunResult held_push(const eval::ExperimentConfig& c, int link, double torque_nm) {
  return eval::held_push(c, link, torque_nm, true);
}

class HoldingDetection : public ::testing::TestWithParam<std::string> {};

TEST_P(HoldingDetection, TwoNewtonMetrePushOnAHeldJointIsDetectedAndAQuietHoldIsNot) {
  const auto c = config(GetParam());
  ASSERT_EQ(c.hold_threshold.size(), 3U);
  for (const double h : c.hold_threshold) {
    EXPECT_GT(h, 0.2) << "calibrated above the margin alone";
    EXPECT_LT(h, 1.5) << "the change threshold sits well under the standstill allowance";
  }
  // Without contact: the whole 6 s hold passes without an alarm.
  const auto quiet = held_push(c, 1, 0.0);
  EXPECT_FALSE(quiet.t_detected.has_value());
  EXPECT_TRUE(quiet.false_alarm_times.empty());
  for (const int link : {1, 2, 3}) {
    const auto r = held_push(c, link, 2.0);
    double own = 0.0;
    for (const double t : r.trace.tau_ext[static_cast<std::size_t>(link - 1)]) own = std::max(own, std::fabs(t));
    EXPECT_NEAR(own, 2.0, 0.05) << "link " << link << ": the push loads its own joint with 2 N·m";
    EXPECT_GE(r.peak_true_torque_held, own - 1e-9);
    // What reaches the own joint's motor (eval/torque_reaching_motor.hpp): never more than
    // the push; on the held elbow its static friction takes most of it (0.27 of 3 N·m in the
    // default held sweep), on the waist none of it.
    EXPECT_NEAR(r.peak_true_torque_own, own, 1e-9);
    EXPECT_LE(r.peak_reaching_torque_own, r.peak_true_torque_own + 1e-12);
    if (link == 1) {
      EXPECT_GT(r.peak_reaching_torque_own, 0.9 * own);
    }
    if (link == 3) {
      EXPECT_LT(r.peak_reaching_torque_own, 0.5 * own);
    }
    std::printf("link %d: %.3f of %.3f N·m reach the motor\n", link, r.peak_reaching_torque_own, r.peak_true_torque_own);
    ASSERT_TRUE(r.t_detected.has_value()) << "link " << link;
    EXPECT_TRUE(r.detected_by_hold) << "link " << link << ": the band alone (standstill allowance) would not see it";
    EXPECT_LT(*r.t_detected - 3.5, 0.05) << "link " << link;
    EXPECT_TRUE(r.false_alarm_times.empty());
  }
}

INSTANTIATE_TEST_SUITE_P(Scalars, HoldingDetection, ::testing::Values(std::string("float"), std::string("q")));
TEST(HoldingThresholdJson, RoundTripAndRefusals) {
  eval::Thresholds t;
  t.threshold = {1.8, 2.0, 1.2};
  t.threshold_uncompensated = {14.0, 14.5, 11.8};
  t.low_speed_extra = {7.7, 8.2, 8.7};
  t.band = {1.3, 1.5, 0.7};
  t.band_uncompensated = {13.5, 14.0, 11.3};
  t.hold_change = {0.93, 0.95, 0.94};
  t.hold_band = {0.49, 0.5, 0.49};
  t.hold_seconds = {500.0, 500.0, 500.0};
  t.hold_settle_s = 0.2;
  const std::string path = ::testing::TempDir() + "/jg_hold_threshold.json";
  eval::write_threshold_json(path, t, {1, 2, 3});
  const eval::Thresholds back = eval::read_threshold_json(path, {3, 1, 2});
  ASSERT_EQ(back.hold_change.size(), 3U);
  EXPECT_DOUBLE_EQ(back.hold_change[0], 0.94) << "reordered to the joints asked for";
  EXPECT_DOUBLE_EQ(back.hold_change[1], 0.93);
  EXPECT_DOUBLE_EQ(back.hold_settle_s, 0.2);
  EXPECT_DOUBLE_EQ(back.hold_reference_s, t.hold_reference_s);
  auto refuse = [&](const std::string& text, const std::string& needle) {
    jg::test::expect_refused(path, text, needle, [](const std::string& p) { (void)eval::read_threshold_json(p); });
  };
  refuse(R"({"joints": [{"threshold": 1, "hold_change_threshold": -1}]})", "hold_change_threshold");
  refuse(R"({"joints": [{"threshold": 1, "hold_change_threshold": 1}, {"threshold": 1}]})", "some joints only");
  refuse(R"({"hold_settle_s": "x", "joints": [{"threshold": 1}]})", "hold_settle_s");
}

TEST(HoldingDetection, DrivesOnTheBusDetectFromTheSensorFramesHoldingFlag) {
  // The same 2 N·m push on the held waist, estimated by the drives on a simulated CAN FD
  // bus: the holding flag reaches them in the sensor frames and their own detectors flag.
  const auto c = config("q");
  eval::DistributedConfig dc;
  dc.estimator.model = c.model;
  dc.estimator.dt = 1.0 / c.rate_hz;
  dc.estimator.observer = c.gains;
  dc.estimator.friction = c.friction;
  dc.estimator.holding_velocity_deadband = eval::holding_deadband(c.model, c.rate_hz);
  for (std::size_t j = 0; j < 3; ++j) {
    dc.node_thresholds.push_back({c.thresholds[j], 0.0, c.low_speed_extra[j], 1.0 / c.low_speed_width});
  }
  auto run = [&](bool with_hold, double torque) {  // with_hold false: the drives' band alone
    eval::DistributedConfig d = dc;
    if (with_hold) {
      for (const double h : c.hold_threshold) d.node_hold.push_back(eval::hold_params(h, c.hold_settle_s, c.hold_reference_s, d.estimator.dt));
    }
    auto est = eval::make_distributed_estimator(d, "q");
    auto detection = eval::detection_for(c);
    detection.hold_threshold.clear();  // only the drives' own detectors hold the change threshold
    return eval::run_detection(eval::held_push_setup(c, 1, torque), *est, detection, "bus", false);
  };
  const auto with_hold = run(true, 2.0);
  ASSERT_TRUE(with_hold.t_node_flagged.has_value());
  EXPECT_LT(*with_hold.t_node_flagged - 3.5, 0.06);
  EXPECT_EQ(with_hold.link_node_isolated, 1);
  EXPECT_FALSE(run(true, 0.0).t_node_flagged.has_value()) << "a quiet hold";
  const auto band_only = run(false, 2.0);
  EXPECT_TRUE(!band_only.t_node_flagged || *band_only.t_node_flagged > *with_hold.t_node_flagged)
      << "the holding detector flags before the drives' band (if the band sees it at all)";
}

}  // namespace
