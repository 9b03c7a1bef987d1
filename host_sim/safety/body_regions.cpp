#include "safety/body_regions.hpp"

#include <algorithm>
#include <stdexcept>

namespace jg::safety {

const std::vector<BodyRegion>& body_regions() {
  // ISO/TS 15066:2016, Annex A: Table A.2 (quasi-static force limits) and Table A.3
  // (effective masses and spring constants), per body region.
  static const std::vector<BodyRegion> regions = {
      {"skull_forehead", 4.4, 150e3, 130.0, 0.0},
      {"face", 4.4, 75e3, 65.0, 0.0},
      {"neck", 1.2, 50e3, 150.0, 2.0},
      {"back_shoulders", 40.0, 35e3, 210.0, 2.0},
      {"chest", 40.0, 25e3, 140.0, 2.0},
      {"abdomen", 40.0, 10e3, 110.0, 2.0},
      {"pelvis", 40.0, 25e3, 180.0, 2.0},
      {"upper_arm", 3.0, 30e3, 150.0, 2.0},
      {"lower_arm", 2.0, 40e3, 160.0, 2.0},
      {"hand", 0.6, 75e3, 140.0, 2.0},
      {"thigh", 75.0, 50e3, 220.0, 2.0},
      {"lower_leg", 75.0, 60e3, 130.0, 2.0},
  };
  return regions;
}

const BodyRegion& body_region(const std::string& name) {
  for (const auto& r : body_regions()) {
    if (name == r.name) return r;
  }
  std::string names;
  for (const auto& r : body_regions()) names += (names.empty() ? "" : ", ") + std::string(r.name);
  throw std::invalid_argument("unknown body region '" + name + "' (known: " + names + ")");
}

ContactOutcome assess(const BodyRegion& region, const std::vector<double>& force_n, double dt_s) {
  ContactOutcome o;
  const auto transient_samples = static_cast<std::size_t>(0.5 / dt_s + 0.5);
  for (std::size_t k = 0; k < force_n.size(); ++k) {
    double& peak = k < transient_samples ? o.peak_transient_n : o.peak_quasi_static_n;
    peak = std::max(peak, force_n[k]);
  }
  o.limit_quasi_static_n = region.max_quasi_static_n;
  o.limit_transient_n = region.transient_factor * region.max_quasi_static_n;
  const double transient_limit = region.transient_factor > 0.0 ? o.limit_transient_n : o.limit_quasi_static_n;
  o.within_limits = o.peak_transient_n <= transient_limit && o.peak_quasi_static_n <= o.limit_quasi_static_n;
  return o;
}

}  // namespace jg::safety
