#include "report/contact_report.hpp"

#include <cstdio>
#include <sstream>

#include "eval/contact_coverage.hpp"
#include "report/svg_plot.hpp"

namespace jg::report {
namespace {
std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0) {
  char buf[128];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}
}  // namespace

std::string describe_contact(const detection::ContactEstimate& e, int link_id) {
  std::string s = "link " + std::to_string(link_id);
  if (e.force_determined) {
    return s + fmt(", %.3f +- %.3f m along it", e.along_m, e.along_sigma_m) +
           fmt(", force %.1f +- %.1f N (determined)", e.force_n, e.force_sigma_n);
  }
  if (e.links_consistent.size() > 1) {
    s += " (consistent with the torques: links";
    for (const int l : e.links_consistent) s += " " + std::to_string(l);
    s += ")";
  }
  s += fmt(", the point anywhere in %.3f-%.3f m along it", e.along_lo_m, e.along_hi_m);
  s += fmt(", on the line of action through (%.3f, %.3f, %.3f) m", e.point_base.x(), e.point_base.y(), e.point_base.z());
  s += fmt(" along (%.2f, %.2f, %.2f)", e.line_direction_base.x(), e.line_direction_base.y(), e.line_direction_base.z());
  return s + fmt(", force %.0f-%.0f N (not determined: a set)", e.force_lo_n, e.force_hi_n);
}

std::string contact_section(const std::vector<eval::RunResult>& runs, std::size_t rows) {
  const eval::ContactCoverage c = eval::contact_coverage(runs);
  std::ostringstream h;
  h << "<h2>Contact estimate: link, point and force, as a set where the torques do not determine them</h2>\n"
    << "<p class=\"note\">" << escape(eval::describe(c)) << ". Spreads: the torque estimate's noise through the window's "
       "line fit and lag correction, the correction's own uncertainty, the point's offset from the link's axis, the grid; "
       "docs/contact-estimate.md, \"Honest spreads\".</p>\n"
    << "<table><tr><th>run</th><th>true link, point along it [m], force [N]</th><th>estimate</th><th>truth within the set</th></tr>\n";
  std::size_t shown = 0;
  for (const auto& r : runs) {
    if (!r.contact || shown >= rows) continue;
    ++shown;
    const auto& o = *r.contact;
    const auto& e = o.estimate;
    const bool point_in = e.link == r.link_true && o.along_true_m >= e.along_lo_m && o.along_true_m <= e.along_hi_m;
    const bool force_in = o.force_true_target_n >= e.force_lo_n && o.force_true_target_n <= e.force_hi_n;
    h << "<tr><td>" << escape(r.name) << "</td><td>" << r.link_true << fmt(", %.3f, %.1f", o.along_true_m, o.force_true_target_n)
      << "</td><td>" << escape(describe_contact(e, e.link)) << "</td><td>point " << (point_in ? "yes" : "no") << ", force "
      << (force_in ? "yes" : "no") << "</td></tr>\n";
  }
  h << "</table>\n";
  return h.str();
}

}  // namespace jg::report
