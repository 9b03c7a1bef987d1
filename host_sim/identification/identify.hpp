// LuGre identification from "measured friction" (observer output with no collision):
// the paper's genetic algorithm (population 200, 300 generations, crossover 0.8,
// mutation 0.2, several initial populations, result = mean of 10 runs), optionally
// refined by Levenberg-Marquardt from the GA's result, with per-parameter spread over
// the runs and identifiability from the sensitivity of the fit.
#pragma once

#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "jointguard/friction/lugre.hpp"

namespace jg::ident {

inline constexpr std::array<const char*, 6> kParamNames = {"sigma0", "sigma1", "sigma2", "tau_c", "tau_s", "w_s"};

/// Search ranges (paper section 3): sigma0 (6e4, 1e5], sigma1 (0, 500], sigma2 (0, 10],
/// tau_c (0, 10], tau_s (0, 10], w_s (0, 0.1]. Open lower ends are kept 1e-6 of the
/// range above the bound.
struct SearchRanges {
  std::array<double, 6> lower{60000.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  std::array<double, 6> upper{100000.0, 500.0, 10.0, 10.0, 10.0, 0.1};
};

struct GaSettings {
  int population = 200;
  int generations = 300;
  double crossover_probability = 0.8;
  double mutation_probability = 0.2;
  int runs = 10;  ///< independent runs from different initial populations; result = mean
  unsigned long long seed = 1;
  int threads = 2;
  int elite = 2;
  bool refine = true;  ///< Levenberg-Marquardt from the GA mean
};

struct FrictionSeries {
  std::vector<double> velocity;  ///< joint velocity [rad/s]
  std::vector<double> friction;  ///< measured friction torque [N·m]
  double dt = 0.0;               ///< sample time [s]
  std::size_t skip = 0;          ///< leading samples that only warm up the bristle state
  /// Measured by a first-order momentum observer of this gain [1/s]: candidates are seen
  /// through the same filter (0 = measured directly, e.g. by a torque sensor).
  double observer_gain = 0.0;
  [[nodiscard]] double observer_decay() const { return observer_gain > 0.0 ? std::exp(-observer_gain * dt) : 0.0; }
};

struct ParameterReport {
  double value = 0.0;            ///< identified (after refinement when enabled)
  double ga_mean = 0.0, ga_std = 0.0;  ///< over the runs
  double sensitivity = 0.0;      ///< RMS change of the prediction for a 10 % change [N·m]
  double relative_std_error = 0.0;  ///< from the fit's Fisher information
  bool identifiable = true;
  std::string note;
};

struct IdentificationResult {
  LuGreParams<double> params{};
  std::array<ParameterReport, 6> report{};
  std::vector<LuGreParams<double>> run_results;
  std::vector<double> run_costs;
  double rms = 0.0;       ///< RMS of measured - predicted over the scored samples [N·m]
  double ga_rms = 0.0;    ///< the same for the GA mean before refinement
  double noise_rms = 0.0; ///< high-frequency noise level estimated from the data [N·m]
  std::vector<std::string> warnings;
};

/// Refuses unusable data with a message saying what is missing (std::invalid_argument).
void check_series(const FrictionSeries& s);

/// One GA run (population x generations); returns the best candidate and its cost.
LuGreParams<double> run_ga(const FrictionSeries& s, const GaSettings& g, const SearchRanges& r,
                           unsigned long long seed, double& best_cost);

/// `fine`, when given, is the same data at a higher sample rate (e.g. `s` decimated for
/// the GA): the GA searches on `s`, the LM refinement and the report use `fine`, so the
/// result carries no error from the coarser discretisation of the LuGre and the observer.
IdentificationResult identify_lugre(const FrictionSeries& s, const GaSettings& g = {}, const SearchRanges& r = {},
                                    const std::function<void(double)>& progress = {},
                                    const FrictionSeries* fine = nullptr);

}  // namespace jg::ident
