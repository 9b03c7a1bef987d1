// What a calibration covered (issue 15.3): the region in the threshold JSON, the holding flag
// derived from a recording, the rigid-body friction read as LuGre, and the calibration motion
// generator covering every slice of each joint's range with its abrupt stops.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>

#include "../common/expect_refused.hpp"
#include "eval/calibration_region.hpp"
#include "eval/pipeline.hpp"
#include "motion/calibration_motion.hpp"

namespace jg {
namespace {

/// The band near standstill, eps0 + extra exp(-(w / width)^2), at speed w [rad/s].
double band_at(const eval::Thresholds& t, std::size_t j, double w) {
  const double u = w / t.low_speed_width;
  return t.threshold[j] + t.low_speed_extra[j] * std::exp(-u * u);
}

/// A joint whose velocity comes in counts of 6.3 mrad/s per sample (the Panda's): 1 N·m while
/// moving, 5 N·m seen at rest and at one count, 1.5 N·m at two counts. A sample measured at
/// two counts may be one whose true speed is one count, where the calibration saw 5 N·m: the
/// band at two counts covers the rest's excess (with the standstill factor), not only the
/// 1.5 N·m seen there.
TEST(BandStatistics, ASpeedOneCountOffGetsTheSlowerBinsAllowance) {
  const double count = 0.0063, margin = 0.1;
  eval::BandStatistics st(1);
  for (int k = 0; k < 100; ++k) {
    st.add(0, 0.0, 5.0, 9.0);
    st.add(0, count, 5.0, 9.0);
    st.add(0, 2.0 * count, 1.5, 9.0);
    st.add(0, 0.05 + 0.01 * k, 1.0, 9.0);
  }
  const eval::Thresholds t = st.fit(margin);
  ASSERT_EQ(t.low_speed_extra.size(), 1U);
  const double rest_excess = eval::BandStatistics::kStandstillFactor * (5.0 - 1.0);
  EXPECT_GE(band_at(t, 0, 0.0), 1.0 + margin + rest_excess - 1e-9);
  // The bin of two counts is covered at its upper edge, as the rest bins are.
  const double two_counts_edge = (std::floor(2.0 * count / eval::BandStatistics::kBin) + 1.0) * eval::BandStatistics::kBin;
  EXPECT_GE(band_at(t, 0, two_counts_edge), 1.0 + margin + rest_excess - 1e-9);
  // Three counts and more: only what was seen there (the moving band) is required.
  EXPECT_LT(band_at(t, 0, 0.05), 1.0 + margin + rest_excess);
}

TEST(CalibrationRegionJson, RoundTripReorderedAndRefusals) {
  eval::Thresholds t;
  t.threshold = {1.8, 2.0, 1.2};
  t.threshold_uncompensated = {14.0, 14.5, 11.8};
  t.low_speed_extra = {7.7, 8.2, 8.7};
  t.band = {1.3, 1.5, 0.7};
  t.band_uncompensated = {13.5, 14.0, 11.3};
  t.q_min = {-0.7, -0.1, -1.5};
  t.q_max = {0.7, 1.3, -0.1};
  t.dq_max = {1.2, 1.1, 1.0};
  t.ddq_max = {20.0, 21.0, 19.0};
  t.stop_gain = {0.24, 0.23, 0.09};
  const std::string path = ::testing::TempDir() + "/jg_region_threshold.json";
  eval::write_threshold_json(path, t, {1, 2, 3});
  const eval::Thresholds back = eval::read_threshold_json(path, {3, 1, 2});
  ASSERT_EQ(back.q_min.size(), 3U);
  EXPECT_DOUBLE_EQ(back.q_min[0], -1.5) << "reordered to the joints asked for";
  EXPECT_DOUBLE_EQ(back.q_max[1], 0.7);
  EXPECT_DOUBLE_EQ(back.ddq_max[2], 21.0);
  EXPECT_DOUBLE_EQ(back.stop_gain[0], 0.09);
  auto refuse = [&](const std::string& text, const std::string& needle) {
    jg::test::expect_refused(path, text, needle, [](const std::string& p) { (void)eval::read_threshold_json(p); });
  };
  const std::string ok_region = R"("region": {"q_min": 0, "q_max": 1, "dq_max": 1, "ddq_max": 1})";
  refuse(R"({"joints": [{"threshold": 1, )" + ok_region + R"(}, {"threshold": 1}]})", "some joints only");
  refuse(R"({"joints": [{"threshold": 1, "region": {"q_min": 2, "q_max": 1, "dq_max": 1, "ddq_max": 1}}]})", "q_min");
  refuse(R"({"joints": [{"threshold": 1, "region": {"q_min": 0, "q_max": 1, "dq_max": -1, "ddq_max": 1}}]})", "region");
  refuse(R"({"joints": [{"threshold": 1, "region": [1, 2]}]})", "region");
  // A file without a region still loads (files written before it).
  { std::ofstream(path) << R"({"joints": [{"threshold": 1}]})"; }
  EXPECT_TRUE(eval::read_threshold_json(path).q_min.empty());
}

TEST(CalibrationRegionJson, RigidBodyFrictionReadAsLuGre) {
  const std::string path = ::testing::TempDir() + "/jg_rigid_friction.json";
  { std::ofstream(path) << R"({"joints": [{"joint": 1, "friction": {"coulomb": 12.5, "viscous": 25.0}}]})"; }
  const auto f = eval::read_friction_json(path, {1});
  ASSERT_EQ(f.size(), 1U);
  EXPECT_DOUBLE_EQ(f[0].tau_c, 12.5);
  EXPECT_DOUBLE_EQ(f[0].tau_s, 12.5);
  EXPECT_DOUBLE_EQ(f[0].sigma2, 25.0);
  EXPECT_DOUBLE_EQ(f[0].sigma0, 12.5e3) << "bristles deflect 1 mrad at tau_c";
  { std::ofstream(path) << R"({"joints": [{"joint": 1, "friction": {"coulomb": 0, "viscous": 25.0}}]})"; }
  EXPECT_THROW((void)eval::read_friction_json(path, {1}), std::exception);
}

TEST(HoldingFlags, StillArmHoldsWhileItYieldsWithinTheRadius) {
  io::Recording r;
  r.resize(2, 40, false, true, false, false);
  for (std::size_t k = 0; k < 40; ++k) {
    r.t[k] = 0.01 * static_cast<double>(k);
    // moving for 10 samples, then at rest; a push makes joint 1 yield 2 mrad at 25..29 and
    // 20 mrad at 35.. (beyond the 5 mrad radius: the arm was moved, no longer held)
    r.dq[0][k] = k < 10 ? 0.5 : (k >= 25 && k < 27 ? 0.1 : 0.0);
    r.q[0][k] = k < 10 ? 0.005 * static_cast<double>(k) : 0.05 + (k >= 25 && k < 30 ? 0.002 : 0.0) + (k >= 35 ? 0.02 : 0.0);
  }
  eval::ReplayOptions o;
  o.holding = eval::HoldingSource::still;
  o.arrive_s = 0.05;
  const auto h = eval::holding_flags(r, o);
  EXPECT_FALSE(h[9]);
  EXPECT_FALSE(h[14]) << "not before 0.05 s at rest";
  EXPECT_TRUE(h[17]);
  EXPECT_TRUE(h[26]) << "a held joint yields under a push and still holds";
  EXPECT_FALSE(h[36]) << "moved beyond the radius";
  o.holding = eval::HoldingSource::always;
  EXPECT_TRUE(eval::holding_flags(r, o)[3]);
}

TEST(HoldingFlags, AHoldEndsWhereTheMoveBeganNotWhereItLeftTheRadius) {
  // At rest (dq exactly 0) until sample 120, then a smooth start q = 1e-4 (k - 120)^2 that
  // leaves the 5 mrad radius at sample 128: replay looks back for the start (the recording
  // carries no command) and ends the hold where the position began to move, 50 ms before.
  io::Recording r;
  r.resize(1, 140, false, true, false, false);
  for (std::size_t k = 0; k < 140; ++k) {
    r.t[k] = 0.01 * static_cast<double>(k);
    const double s = k > 120 ? static_cast<double>(k - 120) : 0.0;
    r.q[0][k] = 1e-4 * s * s;
    r.dq[0][k] = 2e-2 * s;
  }
  eval::ReplayOptions o;
  o.holding = eval::HoldingSource::still;
  const auto h = eval::holding_flags(r, o);
  EXPECT_TRUE(h[110]);
  EXPECT_TRUE(h[116]);
  EXPECT_FALSE(h[117]) << "50 ms before the first position step that counts";
  EXPECT_FALSE(h[125]) << "moving, though still within the radius";
  EXPECT_FALSE(h[130]);
  // A logged velocity that dithers at rest: still by position (within 1 mrad over 50 ms).
  for (std::size_t k = 0; k < 140; ++k) r.dq[0][k] = k % 2 == 0 ? 1e-3 : -1e-3;
  for (std::size_t k = 0; k < 140; ++k) r.q[0][k] = 0.0;
  EXPECT_TRUE(eval::holding_flags(r, o)[20]);
  for (std::size_t k = 0; k < 140; ++k) r.q[0][k] = 1e-3 * static_cast<double>(k);  // 0.1 rad/s
  EXPECT_FALSE(eval::holding_flags(r, o)[20]) << "5 mrad in 50 ms: moving";
}

TEST(CalibrationMotion, CoversEverySliceAndStopsAtItsDeceleration) {
  sim::CalibrationMotion c;
  c.levels = 4;
  c.max_speed = 1.0;
  c.stop_decel = 30.0;
  c.stop_share = 0.5;
  const sim::JointVector lower = sim::JointVector::Constant(2, -1.0), upper = sim::JointVector::Constant(2, 1.0);
  const auto traj = sim::make_calibration_motion(sim::JointVector::Zero(2), lower, upper, c, 30.0, 3);
  std::set<int> slices[2];
  double peak_decel = 0.0, peak_speed = 0.0, q_prev = 0.0;
  const double dt = 1e-3;
  for (double t = 0.0; t < traj->duration(); t += dt) {
    const auto s = traj->at(t);
    for (int j = 0; j < 2; ++j) {
      ASSERT_GE(s.q(j), -1.0 - 1e-12);
      ASSERT_LE(s.q(j), 1.0 + 1e-12);
      if (s.dq(j) == 0.0) slices[j].insert(static_cast<int>(std::floor((s.q(j) + 1.0) / 0.5)));
      peak_decel = std::max(peak_decel, s.dq(j) * s.ddq(j) < 0.0 ? std::fabs(s.ddq(j)) : 0.0);
      peak_speed = std::max(peak_speed, std::fabs(s.dq(j)));
    }
    if (t > 0.0) {
      EXPECT_NEAR(s.q(0), q_prev, 1.5 * dt) << "continuous at " << t;
    }
    q_prev = s.q(0);
  }
  EXPECT_EQ(slices[0].size(), 4U);
  EXPECT_EQ(slices[1].size(), 4U);
  EXPECT_NEAR(peak_decel, 30.0, 1e-9) << "the abrupt stops decelerate at stop_decel on the farthest-moving joint";
  EXPECT_LE(peak_speed, 1.0 + 1e-9);
  EXPECT_THROW((void)sim::make_calibration_motion(sim::JointVector::Zero(2), upper, lower, c, 10.0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace jg
