// The demo report's contact-estimate section: what a campaign's detections say about the
// contact, each as a set where the torques do not determine it (the link, the line of
// action, the interval of the point along the link, the range of forces) and as a value
// with its spread where they do, beside the truth; and how often the truth lies within the
// stated set (eval/contact_coverage.hpp).
#pragma once

#include <string>
#include <vector>

#include "eval/evaluate.hpp"

namespace jg::report {

/// HTML: the coverage figures and a table of the first `rows` estimates.
std::string contact_section(const std::vector<eval::RunResult>& runs, std::size_t rows = 12);

/// One estimate as the console and the report state it: "link L, s = a +- b m along it,
/// force F +- dF N" where the force is determined, else "link L (links ... consistent), the
/// point anywhere in [lo, hi] m along it, on the line of action through (x, y, z) m along
/// (ux, uy, uz), force lo-hi N".
std::string describe_contact(const detection::ContactEstimate& e, int link_id);

}  // namespace jg::report
