// The isolation decision's joints by the size of their estimate (eval/decision_signature.hpp).
#include <gtest/gtest.h>

#include "eval/decision_signature.hpp"

using jg::eval::DecisionSignature;

// The UR10e's upper-arm push (campaign 43 of the 200-collision run): the elbow's estimate rings
// +3.95 then -3.98 N·m with no contact torque on it, its bar 2.41 N·m; the shoulder carries the
// push. Taken at its largest, the elbow was named; by its mean, the shoulder is.
TEST(DecisionSignature, TheCouplingsRingingAcrossZeroDoesNotTakePart) {
  DecisionSignature d(3);
  const double first[] = {1.11, 25.53, 3.95}, second[] = {-0.13, 7.08, -3.98};
  for (std::size_t j = 0; j < 3; ++j) d.add(j, first[j]);
  for (std::size_t j = 0; j < 3; ++j) d.add(j, second[j]);
  const std::vector<double> bar{4.37, 5.10, 2.41};
  EXPECT_NEAR(d.size(2), 0.015, 1e-9);
  EXPECT_EQ(d.mask(bar), 0b010);
  EXPECT_EQ(jg::isolate_link(d.mask(bar)), 2);
}

// A contact's own torque builds with one sign: taken at its largest even when its mean is
// below the bar (the UR10e's campaign 33: joint 4 at 0.12 then 0.57 N·m, the bar 0.357).
TEST(DecisionSignature, AContactBuildingWithOneSignTakesPartByItsLargestValue) {
  DecisionSignature d(1);
  d.add(0, 0.12);
  d.add(0, 0.57);
  EXPECT_DOUBLE_EQ(d.size(0), 0.57);
  EXPECT_EQ(d.mask({0.357}), 0b1);
  DecisionSignature n(1);
  n.add(0, -0.12);
  n.add(0, -0.57);
  EXPECT_EQ(n.mask({0.357}), 0b1);
}

// One sign change with a real contact under it: the mean keeps it when it is large enough.
TEST(DecisionSignature, ASignChangeKeepsAJointWhoseMeanClearsTheBar) {
  DecisionSignature d(1);
  d.add(0, -0.5);
  d.add(0, 4.5);
  EXPECT_DOUBLE_EQ(d.size(0), 2.0);
  EXPECT_EQ(d.mask({1.9}), 0b1);
  EXPECT_EQ(d.mask({2.1}), 0b0);
}

TEST(DecisionSignature, AJointNotLookedAtHasNoSize) {
  DecisionSignature d(2);
  d.add(0, 1.0);
  EXPECT_EQ(d.size(1), 0.0);
  EXPECT_EQ(d.mask({0.5, 0.0}), 0b01);
}
