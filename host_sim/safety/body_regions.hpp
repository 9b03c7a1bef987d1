// Body regions a collaborative robot may meet, with the biomechanical figures of
// ISO/TS 15066:2016 Annex A as they are commonly quoted from it (Table A.2: maximum
// permissible quasi-static force per body region; transient contact up to twice that where
// the specification allows transient contact at all, not on the skull, forehead or face;
// Table A.3: effective mass of the body region and effective spring constant). An
// integrator validating an application takes the figures from their own copy of the
// specification; the table here is what the simulation uses, in SI units.
#pragma once

#include <string>
#include <vector>

namespace jg::safety {

struct BodyRegion {
  const char* name;              ///< e.g. "hand", "lower_arm"
  double effective_mass_kg;      ///< Table A.3
  double spring_n_per_m;         ///< effective spring constant, Table A.3 (N/mm x 1000)
  double max_quasi_static_n;     ///< Table A.2
  double transient_factor;       ///< transient limit = factor x quasi-static (0: no transient contact allowed)
  /// Table A.2, maximum permissible quasi-static pressure [N/cm^2] of the region's most
  /// sensitive body area (named below); transient pressure: the same factor as the force.
  double max_pressure_n_per_cm2;
  const char* pressure_area;     ///< the Table A.2 body area the pressure limit is from
};

/// Every region of the table.
const std::vector<BodyRegion>& body_regions();
/// The region of that name; throws std::invalid_argument listing the names otherwise.
const BodyRegion& body_region(const std::string& name);

/// What a contact did to the person, from the contact force over time (one value per
/// control cycle, from the contact's onset): the transient phase is the first 0.5 s
/// (ISO/TS 15066's distinction between transient and quasi-static contact), the
/// quasi-static phase the rest of the contact.
struct ContactOutcome {
  double peak_transient_n = 0.0;
  double peak_quasi_static_n = 0.0;
  double limit_transient_n = 0.0;     ///< 0 when no transient contact is allowed
  double limit_quasi_static_n = 0.0;
  bool within_limits = false;         ///< transient <= its limit (or <= the quasi-static one when
                                      ///< no transient contact is allowed) and quasi-static <= its limit,
                                      ///< for the force and, with a contact area, the pressure
  double contact_area_cm2 = 0.0;      ///< 0: no area given, no pressures
  double peak_transient_pressure = 0.0, peak_quasi_static_pressure = 0.0;  ///< [N/cm^2]
  double limit_transient_pressure = 0.0, limit_quasi_static_pressure = 0.0;  ///< [N/cm^2] (transient 0: not allowed)
  bool force_within = false, pressure_within = true;  ///< the two parts of the verdict
};
/// `contact_area_cm2` > 0: the pressures (force / area) too, and the verdict includes them.
ContactOutcome assess(const BodyRegion& region, const std::vector<double>& force_n, double dt_s, double contact_area_cm2 = 0.0);

}  // namespace jg::safety
