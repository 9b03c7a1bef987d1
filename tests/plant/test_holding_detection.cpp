// Holding-aware detection in closed loop: a small push on a joint whose controller holds
// its setpoint is detected by the change from the estimate at arrival, with no alarm in a
// hold without contact (simulated arm, firmware core in the loop, both scalars).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

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
    ASSERT_TRUE(r.t_detected.has_value()) << "link " << link;
    EXPECT_TRUE(r.detected_by_hold) << "link " << link << ": the band alone (standstill allowance) would not see it";
    EXPECT_LT(*r.t_detected - 3.5, 0.05) << "link " << link;
    EXPECT_TRUE(r.false_alarm_times.empty());
  }
}

INSTANTIATE_TEST_SUITE_P(Scalars, HoldingDetection, ::testing::Values(std::string("float"), std::string("q")));
}  // namespace
