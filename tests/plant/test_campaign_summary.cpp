// Campaign figures: which collisions count as visible (true torque over 1.5x the threshold
// in effect, and over 1.5x the moving threshold alone), delays and isolation.
#include <gtest/gtest.h>

#include "eval/experiments.hpp"

namespace {
jg::eval::RunResult run(double ratio_in_effect, double ratio_moving, bool detected, int link_true, int link_isolated) {
  jg::eval::RunResult r;
  r.t_collision = 1.0;
  if (detected) r.t_detected = 1.0 + 0.001 * ratio_moving;
  if (ratio_in_effect > 1.0) r.t_threshold = 1.0 + 0.0001;
  r.max_true_ratio = ratio_in_effect;
  r.max_true_ratio_moving = ratio_moving;
  r.link_true = link_true;
  r.link_isolated = link_isolated;
  return r;
}

TEST(CampaignSummary, CountsVisibleCollisionsAgainstBothThresholds) {
  const std::vector<jg::eval::RunResult> runs = {
      run(3.0, 3.0, true, 2, 2),   // seen everywhere, detected
      run(0.5, 2.0, false, 3, 0),  // an impact on a joint at rest: under the standstill allowance
      run(1.2, 1.2, true, 3, 2),   // weak, detected anyway, isolated one link low
      run(1.6, 1.6, false, 2, 0),  // visible and missed
  };
  const jg::eval::Summary s = jg::eval::summarize(runs);
  EXPECT_EQ(s.runs, 4);
  EXPECT_EQ(s.detected, 2);
  EXPECT_EQ(s.isolated, 1);
  EXPECT_EQ(s.detectable, 2);
  EXPECT_EQ(s.detectable_found, 1);
  EXPECT_EQ(s.detectable_moving, 3);
  EXPECT_EQ(s.detectable_moving_found, 1);
  EXPECT_NEAR(s.delay_min, 0.0012, 1e-12);
  EXPECT_NEAR(s.delay_max, 0.003, 1e-12);
  // Detected runs whose true torque crossed the threshold in effect: the first and third.
  EXPECT_EQ(s.after_crossing, 2);
  EXPECT_EQ(s.after_crossing_within_10ms, 2);
  EXPECT_NEAR(s.after_crossing_max, 0.0029, 1e-12);
}

TEST(CampaignSummary, IsolationAgainstItsCeiling) {
  std::vector<jg::eval::RunResult> runs = {
      run(3.0, 3.0, true, 2, 2),   // isolable, isolated
      run(3.0, 3.0, true, 3, 2),   // isolable, named one link low
      run(1.2, 1.2, true, 3, 3),   // not isolable (own joint under its band), named right anyway
      run(0.5, 0.5, false, 2, 0),  // not isolable, missed
  };
  runs[0].isolable = runs[1].isolable = true;
  runs[2].detected_by_hold = true;
  const jg::eval::Summary s = jg::eval::summarize(runs);
  EXPECT_EQ(s.isolated, 2);
  EXPECT_EQ(s.isolable, 2);
  EXPECT_EQ(s.isolated_of_isolable, 1);
  EXPECT_EQ(s.detected_by_hold, 1);
}
}  // namespace
