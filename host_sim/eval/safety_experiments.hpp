// What a contact does to a person (ISO/TS 15066): the arm swings its waist through a body
// part standing in the way of its last link's tip, the body part either free (transient
// contact: it is pushed away) or clamped (against something behind it), with the body
// region's effective mass and spring constant; the detector and the chosen reaction run in
// the loop. Outcome: peak transient and quasi-static force against the region's limits,
// and the largest speed each region and reaction allow.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "eval/experiments.hpp"
#include "safety/body_regions.hpp"

namespace jg::eval {

struct SafetyCase {
  std::string region;
  sim::CollisionProfile kind = sim::CollisionProfile::free;  ///< free (transient) or clamp
  Reaction reaction = Reaction::stop;
  double joint_speed_rad_s = 0.8;  ///< peak waist speed of the swing
  /// false: the estimator and the reaction in-process (the evaluation loop); true: the
  /// joint drives' firmware on the simulated CAN FD bus, which run the reaction the
  /// master commands (node/joint_reaction.hpp), in the configured scalar.
  bool on_bus = false;
  /// The arm's contact face [cm^2] for the pressures (ISO/TS 15066 Table A.2); 0: forces only.
  double contact_area_cm2 = 0.0;
};

struct SafetyResult {
  SafetyCase c;
  double contact_speed_m_s = 0.0;  ///< speed of the contact point at the onset
  std::optional<double> detection_delay_s;
  safety::ContactOutcome outcome;
  RunResult run;
  std::vector<double> contact_force_n;  ///< per control cycle from the onset (kept with keep_force)
};

SafetyResult run_safety_case(const ExperimentConfig& c, const SafetyCase& sc, bool keep_force = false);

[[nodiscard]] const char* to_string(Reaction r);

/// The largest of `speeds` (ascending) at which every slower speed and it keep both the
/// free and the clamped contact within the region's limits; nullopt when even the
/// slowest does not. Runs in parallel on `jobs` threads.
struct AllowedSpeed {
  std::string region;
  Reaction reaction = Reaction::stop;
  std::optional<double> joint_speed_rad_s, contact_speed_m_s;
};
std::vector<AllowedSpeed> allowed_speeds(const ExperimentConfig& c, const std::vector<std::string>& regions,
                                         const std::vector<Reaction>& reactions, const std::vector<double>& speeds, int jobs,
                                         double contact_area_cm2 = 0.0);

}  // namespace jg::eval
