// eval/contact_coverage: what the campaign's contact figures count, on hand-made outcomes.
#include <gtest/gtest.h>

#include "eval/contact_coverage.hpp"
#include "eval/evaluate.hpp"

namespace {

/// A run on link 3 whose estimate has `components` determined, `links` consistent and a force
/// of `force` N against a truth of 100 N.
jg::eval::RunResult run(int components, std::vector<int> links, double force) {
  jg::eval::RunResult r;
  r.link_true = 3;
  jg::eval::ContactOutcome c;
  c.force_true_target_n = 100.0;
  c.estimate.link = 3;
  c.estimate.force_n = force;
  c.estimate.force_sigma_n = 30.0;
  c.estimate.determined_components = components;
  c.estimate.links_consistent = std::move(links);
  r.contact = c;
  return r;
}

// All three components determined counts whatever the links; on a single consistent link is
// its part where the torques also name the link; within 20 % of the truth in each.
TEST(ContactCoverage, ThreeComponentsOnASingleConsistentLink) {
  const std::vector<jg::eval::RunResult> runs{run(3, {3}, 110.0), run(3, {3}, 130.0), run(3, {2, 3}, 105.0),
                                              run(2, {3}, 100.0), jg::eval::RunResult{}};
  const auto c = jg::eval::contact_coverage(runs);
  EXPECT_EQ(c.estimated, 4);
  EXPECT_EQ(c.three_components, 3);
  EXPECT_EQ(c.three_components_within_20pct, 2);
  EXPECT_EQ(c.three_components_one_link, 2);
  EXPECT_EQ(c.three_components_one_link_within_20pct, 1);
  const auto j = jg::eval::to_json(c);
  EXPECT_EQ(j.at("three_components_one_link").get<int>(), 2);
  EXPECT_EQ(j.at("three_components_one_link_within_20pct").get<int>(), 1);
  EXPECT_NE(jg::eval::describe(c).find("of those on a single consistent link 2, within 20 % 1/2"), std::string::npos) << jg::eval::describe(c);
}

}  // namespace
