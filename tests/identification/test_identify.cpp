// LuGre identification: the batch evaluator equals the firmware's step; the GA recovers
// the paper's parameters from noisy data; unusable data is refused with a reason.
#include <gtest/gtest.h>

#include <chrono>
#include <random>

#include "identification/identify.hpp"
#include "identification/lugre_batch.hpp"
#include "jointguard/numeric/q.hpp"
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

// A real arm logged at ~100 Hz (issue 31.1): the presliding regime is not observable and
// the Stribeck shape may be degenerate, so the fit runs away to values the firmware scalar
// cannot hold (sigma0 ~1e14, tau_s ~0, w_s ~6e-5). With a FirmwareTarget the result must
// fit both scalars at the drive's rate, and every bounded parameter must say why.
FrictionSeries slow_series(const jg::LuGreParams<double>& truth, unsigned seed) {
  const jg::sim::PaperExcitation traj(0.6, 0.4, 6, 1.0);
  FrictionSeries s;
  s.dt = 0.01;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (long k = 0; k < 1200; ++k) s.velocity.push_back(traj.at(traj.steady_begin() + 0.01 * static_cast<double>(k)).dq);
  s.friction = lugre_predict(truth, s.velocity, s.dt);
  for (auto& f : s.friction) f += noise(rng);
  s.skip = 50;
  return s;
}

bool runs_on_firmware(const jg::LuGreParams<double>& p, double dt) {
  jg::LuGreDiscrete<float> f{};
  jg::LuGreDiscrete<jg::q16> q{};
  return jg::discretize(p, dt, f) == jg::Error::ok && jg::discretize(p, dt, q) == jg::Error::ok;
}

TEST(Identify, UnobservableAndDegenerateFitsAreWrittenWithinTheFirmwareRange) {
  // Friction with no stiction at all (tau_s ~ 0: the level vanishes near standstill) and
  // a bristle far stiffer than 100 Hz resolves; then a Stribeck velocity below any
  // logged speed.
  const std::array<jg::LuGreParams<double>, 2> truths = {jg::LuGreParams<double>{1e12, 1e9, 2.0, 2.7, 1e-12, 0.036},
                                                         jg::LuGreParams<double>{1e9, 0.0, 3.0, 2.3, 0.0, 6.4e-5}};
  int out_of_range_fits = 0;
  for (std::size_t c = 0; c < truths.size(); ++c) {
    auto truth = truths[c];
    if (truth.tau_s <= 0.0) truth.tau_s = 1e-15;
    const auto s = slow_series(truth, static_cast<unsigned>(20 + c));
    GaSettings g;
    g.runs = 2;
    g.seed = 5;
    const auto unbounded = identify_lugre(s, g);
    out_of_range_fits += runs_on_firmware(unbounded.params, s.dt) ? 0 : 1;
    g.firmware.enabled = true;
    const auto r = identify_lugre(s, g);
    const auto& p = r.params;
    std::printf("case %zu: unbounded sigma0 %.3g sigma1 %.3g tau_c %.3g tau_s %.3g w_s %.3g -> sigma0 %.3g sigma1 %.3g tau_c %.3g "
                "tau_s %.3g w_s %.3g, rms %.4f -> %.4f\n",
                c, unbounded.params.sigma0, unbounded.params.sigma1, unbounded.params.tau_c, unbounded.params.tau_s,
                unbounded.params.w_s, p.sigma0, p.sigma1, p.tau_c, p.tau_s, p.w_s, r.rms_unbounded, r.rms);
    EXPECT_TRUE(runs_on_firmware(p, s.dt)) << "case " << c << ": the drive must run what identify writes";
    EXPECT_TRUE(runs_on_firmware(p, 0.5 * s.dt)) << "case " << c << ": and at twice the rate (headroom)";
    EXPECT_DOUBLE_EQ(r.firmware_dt, s.dt);
    for (const auto& b : r.bounded) {
      EXPECT_FALSE(b.reason.empty());
      EXPECT_NE(b.reason.find(b.parameter), std::string::npos) << b.reason;
      std::printf("  %s\n", b.reason.c_str());
    }
    EXPECT_FALSE(r.bounded.empty()) << "case " << c << ": a degenerate fit is bounded, and says so";
    EXPECT_LT(r.rms, 3.0 * r.rms_unbounded + 0.05) << "bounded, the fit still describes the friction";
  }
  EXPECT_GT(out_of_range_fits, 0) << "the unbounded fit of such data runs out of the firmware's range (the case guarded)";
}

TEST(Identify, AStribeckVelocityBelowWhatTheDataResolveIsWrittenWithoutExcess) {
  // The joint-4 case: the fit ends at w_s ~6e-5 rad/s (forced here by the search range).
  const auto s = slow_series({1e5, 300.0, 3.0, 2.3, 2.6, 6.4e-5}, 31);
  GaSettings g;
  g.runs = 2;
  g.firmware.enabled = true;
  SearchRanges r;
  r.upper[5] = 8e-5;
  const auto res = identify_lugre(s, g, r);
  const auto& p = res.params;
  const auto limits = firmware_limits(p, s.dt, 0.0);
  std::printf("w_s %.3g (least %.3g), tau_s %.4f tau_c %.4f\n", p.w_s, limits.w_s_min, p.tau_s, p.tau_c);
  EXPECT_TRUE(runs_on_firmware(p, s.dt));
  EXPECT_GE(p.w_s, limits.w_s_min);
  EXPECT_DOUBLE_EQ(p.tau_s, p.tau_c) << "the excess below the slowest resolved speed is not determined: none written";
  bool noted = false;
  for (const auto& b : res.bounded) {
    std::printf("  %s\n", b.reason.c_str());
    noted = noted || b.parameter == "w_s";
  }
  EXPECT_TRUE(noted) << "the JSON says w_s was bounded";
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
