#include "report/safety_report.hpp"

#include <cstdio>
#include <sstream>
#include <vector>

#include "eval/parallel.hpp"
#include "report/svg_plot.hpp"

namespace jg::report {
namespace {

const std::vector<Reaction>& all_reactions() {
  static const std::vector<Reaction> r = {Reaction::none, Reaction::stop, Reaction::zero_gravity, Reaction::retreat, Reaction::reflex};
  return r;
}

std::string num(const char* f, double v) {
  char b[48];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

const char* color_of(Reaction r) {
  switch (r) {
    case Reaction::none: return "#7f7f7f";
    case Reaction::stop: return "#1f77b4";
    case Reaction::zero_gravity: return "#2ca02c";
    case Reaction::retreat: return "#ff7f0e";
    case Reaction::reflex: return "#9467bd";
  }
  return "#000000";
}

std::string cell(const safety::ContactOutcome& out) {
  const std::string mark = out.within_limits ? "" : " style=\"background:#f8d7da\"";
  return "<td" + mark + ">" + num("%.0f", out.peak_transient_n) + " / " + num("%.0f", out.peak_quasi_static_n) +
         (out.within_limits ? "" : " &#x2717;") + "</td>";
}

}  // namespace

std::string safety_section(const eval::ExperimentConfig& c, const SafetySectionOptions& o) {
  const auto& reactions = all_reactions();
  std::vector<eval::SafetyCase> cases;
  for (const auto& region : safety::body_regions()) {
    for (const auto kind : {sim::CollisionProfile::free, sim::CollisionProfile::clamp}) {
      for (const Reaction r : reactions) cases.push_back({region.name, kind, r, o.joint_speed_rad_s, false, o.contact_area_cm2});
    }
  }
  std::vector<eval::SafetyResult> results(cases.size());
  eval::parallel_for(cases.size(), o.jobs, [&](std::size_t i) {
    const bool plotted = cases[i].region == o.plot_region && cases[i].kind == o.plot_kind;
    results[i] = eval::run_safety_case(c, cases[i], plotted);
  });

  std::ostringstream h;
  h << "<h2>What a contact does to a person (ISO/TS 15066)</h2>\n"
    << "<p class=\"note\">The waist swings at " << num("%.1f", o.joint_speed_rad_s)
    << " rad/s peak (about 0.5 m/s at the contact point on link 3) through a body part, free (pushed away) or clamped, "
       "with the region's effective mass and spring constant (ISO/TS 15066:2016 Annex A, Table A.3); each cell: peak transient "
       "/ quasi-static force [N] (transient: the first 0.5 s of the contact). Limits: Table A.2 (transient twice the "
       "quasi-static where transient contact is allowed; skull and face: none). Pressure on a "
    << num("%.0f", o.contact_area_cm2)
    << " cm^2 contact face against the region's lowest Table A.2 pressure limit is part of the verdict; red with &#x2717;: "
       "a limit exceeded. Reproduce: <code>jointguard evaluate --scenario safety --json out/safety.json</code>; the reactions "
       "on the drives over the bus: add <code>--compare-bus</code>.</p>\n";
  h << "<table><tr><th>region</th><th>contact</th><th>limits force [N]</th><th>limits pressure [N/cm^2]</th>";
  for (const Reaction r : reactions) h << "<th>" << eval::to_string(r) << "</th>";
  h << "</tr>\n";
  for (std::size_t i = 0; i < results.size(); i += reactions.size()) {
    const auto& first = results[i];
    const safety::BodyRegion& region = safety::body_region(first.c.region);
    const auto& out = first.outcome;
    const std::string transient = region.transient_factor > 0.0 ? num("%.0f", out.limit_transient_n) : std::string("none");
    const std::string transient_p =
        region.transient_factor > 0.0 ? num("%.0f", region.transient_factor * region.max_pressure_n_per_cm2) : std::string("none");
    h << "<tr><td style=\"text-align:left\">" << region.name << "</td><td>" << sim::to_string(first.c.kind) << "</td><td>"
      << transient << " / " << num("%.0f", out.limit_quasi_static_n) << "</td><td>" << transient_p << " / "
      << num("%.0f", region.max_pressure_n_per_cm2) << " (" << region.pressure_area << ")</td>";
    for (std::size_t k = 0; k < reactions.size(); ++k) h << cell(results[i + k].outcome);
    h << "</tr>\n";
  }
  h << "</table>\n";

  Plot p;
  p.title = "Contact force by reaction: " + o.plot_region + ", " + sim::to_string(o.plot_kind);
  p.width = 900;
  p.x_label = "time from the contact's onset [s]";
  p.y_label = "contact force [N]";
  const double dt = 1.0 / c.rate_hz;
  for (const auto& r : results) {
    if (r.c.region != o.plot_region || r.c.kind != o.plot_kind) continue;
    Series s;
    s.label = eval::to_string(r.c.reaction);
    s.color = color_of(r.c.reaction);
    s.dashed = r.c.reaction == Reaction::none;
    for (std::size_t k = 0; k < r.contact_force_n.size() && k * dt <= 1.0; ++k) {
      s.x.push_back(static_cast<double>(k) * dt);
      s.y.push_back(r.contact_force_n[k]);
    }
    p.series.push_back(std::move(s));
  }
  const safety::BodyRegion& region = safety::body_region(o.plot_region);
  p.hlines = {{region.max_quasi_static_n, "quasi-static limit", "#d62728"}};
  if (region.transient_factor > 0.0) p.hlines.push_back({region.transient_factor * region.max_quasi_static_n, "transient limit", "#ff9896"});
  p.markers.push_back({0.5, "end of the transient phase", "#7f7f7f"});
  p.x_lo = 0.0;
  p.x_hi = 1.0;
  h << render_svg(p);
  return h.str();
}

}  // namespace jg::report
