// LuGre identification: the batch evaluator equals the firmware's step; the GA recovers
// the paper's parameters from noisy data; unusable data is refused with a reason.
#include <gtest/gtest.h>

#include <chrono>
#include <random>

#include "identification/identify.hpp"
#include "identification/lugre_batch.hpp"
#include "models/paper_friction.hpp"
#include "motion/excitation.hpp"

namespace {
using namespace jg::ident;

FrictionSeries paper_series(const jg::LuGreParams<double>& truth, double noise_rms, unsigned seed) {
  const jg::sim::PaperExcitation traj(0.6, 0.2, 4, 2.5);
  FrictionSeries s;
  s.dt = 0.008;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_rms);
  // The paper's 1251 samples from the steady middle cycles, after a warm-up.
  for (long k = 0; k < 1251 + 250; ++k) s.velocity.push_back(traj.at(traj.steady_begin() + 0.008 * static_cast<double>(k)).dq);
  s.friction = lugre_predict(truth, s.velocity, s.dt);
  for (auto& f : s.friction) f += noise(rng);
  s.skip = 250;
  return s;
}

TEST(LuGreBatch, MatchesFirmwareStepExactly) {
  const auto s = paper_series(jg::sim::kPaperTable1[0], 0.0, 1);
  LuGreBatch b;
  b.resize(3);
  for (std::size_t i = 0; i < 3; ++i) b.set(i, jg::sim::kPaperTable1[i]);
  std::vector<double> cost;
  lugre_batch_cost(b, s.velocity, s.friction, s.dt, s.skip, cost);
  EXPECT_LT(cost[0], 1e-20) << "same parameters -> zero error";
  for (std::size_t i = 1; i < 3; ++i) {
    const auto pred = lugre_predict(jg::sim::kPaperTable1[i], s.velocity, s.dt);
    double ref = 0.0;
    for (std::size_t k = s.skip; k < pred.size(); ++k) ref += (s.friction[k] - pred[k]) * (s.friction[k] - pred[k]);
    ref /= static_cast<double>(pred.size() - s.skip);
    EXPECT_NEAR(cost[i], ref, 1e-12 * ref);
  }
}

TEST(Identify, RecoversPaperParametersFromNoisyData) {
  for (std::size_t j = 0; j < 3; ++j) {
    const auto& truth = jg::sim::kPaperTable1[j];
    const auto s = paper_series(truth, 0.3, static_cast<unsigned>(10 + j));
    GaSettings g;
    g.runs = 4;  // the test keeps time short; the default is the paper's 10
    g.seed = 3;
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = identify_lugre(s, g);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("joint %zu: tau_c %.4f (%.4f) tau_s %.4f (%.4f) sigma2 %.4f (%.4f) w_s %.5f (%.5f) sigma0 %.0f sigma1 %.1f rms %.4f noise %.4f, %.2f s\n",
                j + 1, r.params.tau_c, truth.tau_c, r.params.tau_s, truth.tau_s, r.params.sigma2, truth.sigma2,
                r.params.w_s, truth.w_s, r.params.sigma0, r.params.sigma1, r.rms, r.noise_rms, secs);
    EXPECT_NEAR(r.params.tau_c, truth.tau_c, 0.05 * truth.tau_c);
    EXPECT_NEAR(r.params.tau_s, truth.tau_s, 0.05 * truth.tau_s);
    EXPECT_NEAR(r.params.sigma2, truth.sigma2, 0.05 * truth.sigma2);
    EXPECT_NEAR(r.params.w_s, truth.w_s, 0.05 * truth.w_s);
    EXPECT_LT(r.rms, 0.32) << "fit down to the noise";
    EXPECT_NEAR(r.noise_rms, 0.3, 0.05) << "noise estimated from the data";
  }
}

TEST(Identify, WarnsThatSigma0CannotBeIdentifiedFromSlowSampledData) {
  const auto s = paper_series(jg::sim::kPaperTable1[1], 0.3, 4);
  GaSettings g;
  g.runs = 2;
  const auto r = identify_lugre(s, g);
  EXPECT_FALSE(r.report[0].identifiable) << "sigma0 at 125 Hz hardly changes the prediction";
  EXPECT_FALSE(r.warnings.empty());
}

TEST(Identify, RefusesUnusableData) {
  FrictionSeries s;
  s.dt = 0.008;
  s.velocity.assign(50, 0.1);
  s.friction.assign(50, 1.0);
  EXPECT_THROW(
      {
        try {
          check_series(s);
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("too short"), std::string::npos);
          throw;
        }
      },
      std::invalid_argument);
  s.velocity.assign(1000, 0.0);
  s.friction.assign(1000, 0.0);
  try {
    check_series(s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("never moves"), std::string::npos);
  }
  s.velocity.assign(1000, 0.3);
  try {
    check_series(s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("both ways"), std::string::npos);
  }
}
}  // namespace
