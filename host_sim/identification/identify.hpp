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

/// Where the identified friction will run: the firmware's LuGre step at sample time dt, in
/// float or Q16.16. With `enabled`, identify_lugre bounds the result to what both scalars
/// hold there (a file that calibrate, replay or a drive would refuse is never produced) and
/// says per parameter what it bounded and why (IdentificationResult::bounded).
struct FirmwareTarget {
  bool enabled = false;
  double dt = 0.0;         ///< [s] the drive's sample time; 0: the series' own
  double speed_max = 0.0;  ///< [rad/s] fastest the step must hold unsaturated; 0: twice the series' fastest, >= 1
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
  FirmwareTarget firmware{};
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

/// A parameter identify_lugre changed so that the firmware runs it (FirmwareTarget).
struct BoundedParameter {
  std::string parameter;  ///< one of kParamNames
  double fitted = 0.0;    ///< what the fit gave
  double written = 0.0;   ///< what the result holds
  std::string reason;
};

/// What the firmware's LuGre step holds at one sample time (firmware_limits): every bound
/// keeps the step's terms within half of Q16.16's range (float holds more).
struct FirmwareLimits {
  double dt = 0.0, speed_max = 0.0;       ///< [s], [rad/s] the limits hold for
  double sigma0_min = 0.0, sigma0_max = 0.0;  ///< [N·m/rad]
  double damping_max = 0.0;               ///< c1 = sigma1 / (sigma0 dt) [-]
  double sigma2_max = 0.0;                ///< [N·m·s/rad]
  double level_min = 0.0, level_max = 0.0;  ///< tau_c, tau_s [N·m]
  double w_s_min = 0.0;                   ///< [rad/s]
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
  std::vector<BoundedParameter> bounded;  ///< empty unless GaSettings::firmware.enabled bounded something
  double rms_unbounded = 0.0;             ///< rms before the bounds (= rms when nothing was bounded)
  double firmware_dt = 0.0;               ///< [s] the sample time the result was bounded for (0: not bounded)
};

/// Limits for the firmware's LuGre step at sample time dt [s] for speeds up to speed_max
/// [rad/s]; the damping limit depends on p's levels (tau_c, tau_s).
/// `speed_resolution` [rad/s]: the smallest speed the data resolve (a Stribeck velocity
/// below it is not determined by them).
FirmwareLimits firmware_limits(const LuGreParams<double>& p, double dt, double speed_max, double speed_resolution = 0.0);

/// True when both firmware scalars (float and Q16.16) accept p at dt (discretize).
bool fits_firmware(const LuGreParams<double>& p, double dt);

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
