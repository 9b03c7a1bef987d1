// CI subset of the concealed-effect test set (the full set is the documented benchmark
// jg_diagnosis_testset): random effects, joints, amplitudes and concealments, seeded.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "diagnosis/testset.hpp"

namespace {
TEST(DiagnosisTestSet, NamesConcealedEffectsAndClaimsNothingOnMatchedPairs) {
  const auto arm = jg::diag::default_test_arm();
  const auto cases = jg::diag::draw_cases(18, 11, 0.17, 3);
  int effects = 0, named = 0, matched = 0, false_claims = 0, at_floor = 0;
  for (const auto& c : cases) {
    const auto o = jg::diag::run_case(c, arm);
    if (c.effect == jg::robot::Effect::none) {
      ++matched;
      false_claims += o.false_claim ? 1 : 0;
      continue;
    }
    ++effects;
    named += o.named ? 1 : 0;
    at_floor += jg::diag::at_noise_floor(o) ? 1 : 0;
    std::printf("%-24s joint %d %-13s -> %s\n", jg::robot::effect_cstr(c.effect), c.joint, c.concealment.c_str(), o.named ? "named" : "missed");
  }
  std::printf("named %d / %d, false claims %d / %d, held-out at noise floor %d / %d\n", named, effects, false_claims, matched,
              at_floor, effects);
  EXPECT_EQ(false_claims, 0);
  EXPECT_GE(named, static_cast<int>(0.8 * effects));  // the full benchmark reaches 90 %
  EXPECT_GE(at_floor, static_cast<int>(0.9 * effects));
}
}  // namespace

namespace {
// The effects that need the gear-deflection channel or the bristle dynamics: the first
// drawn case of each (seeded draw, filtered by effect, not chosen by hand).
TEST(DiagnosisTestSet, NamesPreslidingBacklashAndElasticity) {
  const auto arm = jg::diag::default_test_arm();
  const auto cases = jg::diag::draw_cases(200, 12, 0.17, 3);
  for (const jg::robot::Effect effect : {jg::robot::Effect::presliding, jg::robot::Effect::backlash, jg::robot::Effect::joint_elasticity}) {
    const auto it = std::find_if(cases.begin(), cases.end(), [&](const jg::diag::ConcealedCase& c) { return c.effect == effect; });
    ASSERT_NE(it, cases.end()) << effect;
    const auto o = jg::diag::run_case(*it, arm);
    std::printf("%-18s joint %d %-13s held-out %.3f -> %.3f (noise %.3f): %s\n", jg::robot::effect_cstr(effect), it->joint,
                it->concealment.c_str(), o.heldout_before, o.heldout_after, o.noise, o.named ? "named" : "missed");
    EXPECT_TRUE(o.named) << effect << " on joint " << it->joint;
    EXPECT_TRUE(jg::diag::at_noise_floor(o)) << effect;
  }
}
}  // namespace
