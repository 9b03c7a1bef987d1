// The demo report's ISO/TS 15066 section: the safety outcome per body region, contact kind
// and reaction (peak transient and quasi-static force and pressure against the limits of
// ISO/TS 15066 Annex A), and the contact force against time per reaction for one scenario.
#pragma once

#include <string>

#include "eval/safety_experiments.hpp"

namespace jg::report {

struct SafetySectionOptions {
  double joint_speed_rad_s = 0.8;   ///< the test swing's peak waist speed
  double contact_area_cm2 = 1.0;    ///< the arm's contact face for the pressures
  std::string plot_region = "chest";
  sim::CollisionProfile plot_kind = sim::CollisionProfile::clamp;
  int jobs = 2;
};

/// Runs every region x {free, clamp} x reaction on the prepared configuration `c`
/// (thresholds and friction set) and returns the HTML (a table and an inline SVG plot).
std::string safety_section(const eval::ExperimentConfig& c, const SafetySectionOptions& o);

}  // namespace jg::report
