#include "safety/body_regions.hpp"

#include <algorithm>
#include <stdexcept>

namespace jg::safety {

const std::vector<BodyRegion>& body_regions() {
  // ISO/TS 15066:2016, Annex A: Table A.2 (quasi-static force limits; quasi-static
  // pressure limits per body area, of which the lowest of the region's areas is taken) and
  // Table A.3 (effective masses and spring constants), per body region.
  static const std::vector<BodyRegion> regions = {
      {"skull_forehead", 4.4, 150e3, 130.0, 0.0, 110.0, "temple"},
      {"face", 4.4, 75e3, 65.0, 0.0, 110.0, "masticatory muscle"},
      {"neck", 1.2, 50e3, 150.0, 2.0, 140.0, "neck muscle"},
      {"back_shoulders", 40.0, 35e3, 210.0, 2.0, 160.0, "shoulder joint"},
      {"chest", 40.0, 25e3, 140.0, 2.0, 120.0, "sternum"},
      {"abdomen", 40.0, 10e3, 110.0, 2.0, 140.0, "abdominal muscle"},
      {"pelvis", 40.0, 25e3, 180.0, 2.0, 210.0, "pelvic bone"},
      {"upper_arm", 3.0, 30e3, 150.0, 2.0, 190.0, "deltoid muscle"},
      {"lower_arm", 2.0, 40e3, 160.0, 2.0, 180.0, "forearm muscle, arm nerve"},
      {"hand", 0.6, 75e3, 140.0, 2.0, 190.0, "back of the non-dominant hand"},
      {"thigh", 75.0, 50e3, 220.0, 2.0, 220.0, "kneecap"},
      {"lower_leg", 75.0, 60e3, 130.0, 2.0, 210.0, "calf muscle"},
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

ContactOutcome assess(const BodyRegion& region, const std::vector<double>& force_n, double dt_s, double contact_area_cm2) {
  ContactOutcome o;
  const auto transient_samples = static_cast<std::size_t>(0.5 / dt_s + 0.5);
  for (std::size_t k = 0; k < force_n.size(); ++k) {
    double& peak = k < transient_samples ? o.peak_transient_n : o.peak_quasi_static_n;
    peak = std::max(peak, force_n[k]);
  }
  o.limit_quasi_static_n = region.max_quasi_static_n;
  o.limit_transient_n = region.transient_factor * region.max_quasi_static_n;
  const double transient_limit = region.transient_factor > 0.0 ? o.limit_transient_n : o.limit_quasi_static_n;
  o.force_within = o.peak_transient_n <= transient_limit && o.peak_quasi_static_n <= o.limit_quasi_static_n;
  if (contact_area_cm2 > 0.0) {
    o.contact_area_cm2 = contact_area_cm2;
    o.peak_transient_pressure = o.peak_transient_n / contact_area_cm2;
    o.peak_quasi_static_pressure = o.peak_quasi_static_n / contact_area_cm2;
    o.limit_quasi_static_pressure = region.max_pressure_n_per_cm2;
    o.limit_transient_pressure = region.transient_factor * region.max_pressure_n_per_cm2;
    const double transient_pressure_limit =
        region.transient_factor > 0.0 ? o.limit_transient_pressure : o.limit_quasi_static_pressure;
    o.pressure_within = o.peak_transient_pressure <= transient_pressure_limit &&
                        o.peak_quasi_static_pressure <= o.limit_quasi_static_pressure;
  }
  o.within_limits = o.force_within && o.pressure_within;
  return o;
}

}  // namespace jg::safety
