// The effect catalogue (robot/effect_catalogue.hpp): one row per Effect in the enum's order,
// words that parse back, and the catalogue's counts and settings what the robot file's check
// (robot::simulation_problem) and the diagnosis's candidates use.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "diagnosis/effects.hpp"
#include "diagnosis/testset.hpp"
#include "robot/effect_catalogue.hpp"
#include "robot/plant_effects.hpp"

namespace {
using jg::robot::Effect;

TEST(EffectCatalogue, OneRowPerEffectInTheEnumsOrder) {
  const auto& table = jg::robot::effect_catalogue();
  ASSERT_EQ(table.size(), static_cast<std::size_t>(Effect::none) + 1);
  std::set<std::string> words;
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_EQ(static_cast<std::size_t>(table[i].effect), i);
    EXPECT_TRUE(words.insert(std::string(table[i].name)).second) << table[i].name;
    EXPECT_EQ(jg::robot::parse_effect(table[i].name), table[i].effect);
    if (table[i].effect != Effect::none) {
      EXPECT_FALSE(table[i].parameters.empty()) << table[i].name;
      EXPECT_FALSE(table[i].plant.empty()) << table[i].name;
      EXPECT_FALSE(table[i].fit.empty()) << table[i].name;
    }
  }
  EXPECT_FALSE(jg::robot::parse_effect("Payload").has_value());  // words are exact
  EXPECT_FALSE(jg::robot::parse_effect("rigid_body").has_value());
  EXPECT_EQ(jg::robot::effect_words().rfind("none"), jg::robot::effect_words().size() - 4);
}

TEST(EffectCatalogue, WrittenAsItsWord) {
  EXPECT_EQ(nlohmann::json(Effect::payload).dump(), "\"payload\"");
  EXPECT_EQ(nlohmann::json::array({Effect::time_delay, Effect::none}).dump(), "[\"time_delay\",\"none\"]");
  EXPECT_EQ("joint 2: " + Effect::current_offset, "joint 2: current_offset");
}

/// The robot file's check takes its counts, settings and scope from the table: an entry with
/// the plain shape's coefficients and setting passes, one coefficient fewer or the wrong
/// scope does not.
TEST(EffectCatalogue, DrivesTheRobotFilesCheck) {
  for (const auto& row : jg::robot::effect_catalogue()) {
    jg::robot::PlantEffect e;
    e.effect = row.effect;
    e.joint = row.scope == jg::robot::EffectScope::arm ? 0 : 2;
    e.coefficients.assign(row.coefficients, 0.1);
    if (!row.setting.empty() && row.effect != Effect::backlash) e.setting[std::string(row.setting)] = row.setting == "link" ? 2.0 : 0.5;
    if (row.effect == Effect::none) {
      EXPECT_EQ(jg::robot::simulation_problem(e).field, "effect");
      continue;
    }
    EXPECT_EQ(jg::robot::simulation_problem(e).field, "") << row.name << ": " << jg::robot::simulation_problem(e).what;
    if (row.coefficients > 0) {
      auto fewer = e;
      fewer.coefficients.pop_back();
      EXPECT_EQ(jg::robot::simulation_problem(fewer).field, "coefficients") << row.name;
    }
    auto moved = e;
    moved.joint = e.joint == 0 ? 1 : 0;
    EXPECT_EQ(jg::robot::simulation_problem(moved).field, "joint") << row.name;
  }
}

/// Every group the diagnosis offers on a joint is a joint-level cause of the catalogue (the
/// arm's are fitted once for the arm, not per joint).
TEST(EffectCatalogue, JointCandidatesAreJointCauses) {
  jg::diag::JointSignals s;
  s.joint = 1;
  s.dt = 0.001;
  for (int k = 0; k < 3000; ++k) {
    const double t = k * s.dt;
    s.t.push_back(t);
    s.q.push_back(0.5 * std::sin(2.0 * t));
    s.dq.push_back(std::cos(2.0 * t));
    s.ddq.push_back(-2.0 * std::sin(2.0 * t));
  }
  s.tau_real.assign(s.t.size(), 0.1);
  s.tau_model.assign(s.t.size(), 0.1);
  s.residual.assign(s.t.size(), 0.0);
  s.load.assign(s.t.size(), 1.0);
  s.arm_level_fitted = true;
  const auto groups = jg::diag::build_candidates(s);
  ASSERT_FALSE(groups.empty());
  for (const auto& g : groups) {
    EXPECT_EQ(jg::robot::effect_info(g.front().effect).scope, jg::robot::EffectScope::joint) << g.front().effect;
  }
}

}  // namespace

namespace {
/// Both concealed-effect generators draw from every cause of the catalogue but `none`.
TEST(EffectCatalogue, GeneratorsCoverEveryCause) {
  const auto& drawn = jg::diag::producible_effects();
  const std::set<jg::robot::Effect> produced(drawn.begin(), drawn.end());
  EXPECT_EQ(produced.size(), drawn.size());
  for (const auto& row : jg::robot::effect_catalogue()) {
    EXPECT_EQ(produced.count(row.effect), row.effect == jg::robot::Effect::none ? 0U : 1U) << row.name;
  }
}
}  // namespace
