// Do the contact estimate's spreads mean what they say? Over a campaign's runs (truth
// known): how often the truth lies within the stated set (the point's interval along the
// link, the force's interval), how sharp the estimate is where the torques determine the
// force, and each run's set in JSON (docs/contact-estimate.md, "Honest spreads").
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "eval/evaluate.hpp"

namespace jg::eval {

struct ContactCoverage {
  int estimated = 0;     ///< runs with a contact estimate
  int link_right = 0;    ///< of those, on the true link
  int point_covered = 0;  ///< link right and the true point's coordinate along it within [along_lo, along_hi]
  int force_covered = 0;  ///< the force the estimate aims at (force_true_target) within [force_lo, force_hi]
  int force_covered_link_right = 0;  ///< the same among the link-right estimates
  int force_within_2sigma = 0;       ///< |force - truth| <= 2 force_sigma
  int determined = 0;                ///< force_determined: the 2-sigma interval within +-20 %
  int determined_within_20pct = 0;   ///< of those, the force within 20 % of the truth it aims at
  int three_components = 0;          ///< all three force components determined (rank of J^T)
  int three_components_within_20pct = 0;
  /// All three components determined and a single link consistent with the torques
  /// (`links_consistent`): the torques name the link and fix the force on it. Where more links
  /// stay consistent, each gives its own force (the set the estimate reports), so the force is
  /// not determined whatever the rank at the chosen point.
  int three_components_one_link = 0;
  int three_components_one_link_within_20pct = 0;
  double median_sigma_over_force = 0.0;  ///< force_sigma / force, median over the estimates
};

ContactCoverage contact_coverage(const std::vector<RunResult>& runs);
nlohmann::json to_json(const ContactCoverage& c);
/// One console line (no newline): the figures above.
std::string describe(const ContactCoverage& c);
/// A run's estimate as a set (per-run JSON): the intervals, the line of action, the
/// consistent links, determined or not, and the truth it aims at.
nlohmann::json contact_set_json(const ContactOutcome& c);
/// Reads contact_set_json's fields back (absent ones left as they are).
void contact_set_from_json(const nlohmann::json& j, ContactOutcome& c);

}  // namespace jg::eval
