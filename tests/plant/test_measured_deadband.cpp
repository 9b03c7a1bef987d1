// The holding velocity deadband measured from the estimator's own input
// (FirmwareEstimatorConfig::holding_deadband_steps): the same estimate as with the encoder's
// step configured beforehand, for any encoder, and a deadband that does act (a joint at rest
// whose encoder dithers by one count reads as still).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "eval/firmware_estimator.hpp"
#include "models/paper_friction.hpp"
#include "robot/robot_model.hpp"

namespace {
using namespace jg;

/// Counts per sample per joint: at rest, a move whose first non-zero sample is one count,
/// faster samples of several counts, then a hold with one-count dither.
std::vector<std::vector<int>> count_pattern() {
  std::vector<std::vector<int>> out;
  for (int k = 0; k < 400; ++k) {
    std::vector<int> c(3, 0);
    if (k >= 20 && k < 200) {
      const int ramp = k < 60 ? 1 : (k < 120 ? 2 : 3);
      c = {ramp, k % 3 == 0 ? 1 : 2, k % 2 == 0 ? 1 : 0};
    } else if (k >= 250) {
      const int dither = (k % 7 == 0) ? 1 : ((k % 11 == 0) ? -1 : 0);
      c = {dither, -dither, dither};
    }
    out.push_back(c);
  }
  return out;
}

/// mu per cycle for an encoder of `counts_per_rev` counts per motor turn; the arm holds
/// from cycle 250 on (the holding flag, as the drive's controller gives it).
std::vector<double> run(const eval::FirmwareEstimatorConfig& c, const std::string& scalar, double counts_per_rev) {
  auto est = eval::make_firmware_estimator(c, scalar);
  const auto drives = c.model.drives();
  eval::EstimatorInput in;
  in.q = sim::JointVector::Zero(3);
  in.q(1) = 0.6;
  in.q(2) = -0.8;
  in.dq = sim::JointVector::Zero(3);
  in.tau_m = sim::JointVector::Zero(3);
  est->reset(in);
  std::vector<double> out;
  sim::JointVector mu;
  const auto pattern = count_pattern();
  for (std::size_t k = 0; k < pattern.size(); ++k) {
    for (Eigen::Index j = 0; j < 3; ++j) {
      const double step = 2.0 * M_PI / counts_per_rev / drives[static_cast<std::size_t>(j)].gear_ratio / c.dt;
      in.dq(j) = pattern[k][static_cast<std::size_t>(j)] * step;
      in.q(j) += in.dq(j) * c.dt;
      in.tau_m(j) = 0.5 * std::sin(0.01 * static_cast<double>(k) + static_cast<double>(j));
    }
    in.holding = k >= 250 ? JointMask{0x7} : JointMask{0};
    est->step(in, mu);
    for (Eigen::Index j = 0; j < 3; ++j) out.push_back(mu(j));
  }
  return out;
}

eval::FirmwareEstimatorConfig base() {
  eval::FirmwareEstimatorConfig c;
  c.model = robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/second3.yaml");
  c.dt = 0.001;
  for (const auto& p : sim::kPaperTable1) c.friction.push_back(p);
  return c;
}

class MeasuredDeadband : public ::testing::TestWithParam<std::string> {};

TEST_P(MeasuredDeadband, EqualsTheKnownStepForAnyEncoderAndActsOnDither) {
  for (const double counts : {10000.0, 4096.0}) {
    auto known = base();
    for (const auto& d : known.model.drives()) {
      known.holding_velocity_deadband.push_back(eval::kHoldingDeadbandSteps * 2.0 * M_PI / counts / d.gear_ratio / known.dt);
    }
    auto measured = base();
    measured.holding_deadband_steps = eval::kHoldingDeadbandSteps;
    const auto a = run(known, GetParam(), counts), b = run(measured, GetParam(), counts);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      ASSERT_EQ(a[k], b[k]) << counts << " counts, cycle " << k / 3 << " joint " << k % 3 + 1;
    }
    // Without a deadband the one-count dither of the hold reaches the friction model: the
    // estimate differs, so the comparison above is not between two runs that ignore it.
    const auto none = run(base(), GetParam(), counts);
    double differ = 0.0;
    for (std::size_t k = 250 * 3; k < none.size(); ++k) differ = std::max(differ, std::fabs(none[k] - b[k]));
    EXPECT_GT(differ, 0.01) << counts << " counts";
  }
  // The fixed deadband of an assumed 10,000-count encoder does nothing on a 4,096-count one
  // (below one count): what the measured step corrects.
  auto assumed = base();
  assumed.holding_velocity_deadband = eval::holding_deadband(assumed.model, 1.0 / assumed.dt);
  auto measured = base();
  measured.holding_deadband_steps = eval::kHoldingDeadbandSteps;
  EXPECT_EQ(run(assumed, GetParam(), 4096.0), run(base(), GetParam(), 4096.0));
  EXPECT_NE(run(assumed, GetParam(), 4096.0), run(measured, GetParam(), 4096.0));
}

INSTANTIATE_TEST_SUITE_P(Scalars, MeasuredDeadband, ::testing::Values(std::string("float"), std::string("q")));

}  // namespace
