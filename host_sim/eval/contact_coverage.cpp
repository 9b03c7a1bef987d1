#include "eval/contact_coverage.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace jg::eval {
namespace {
bool within(double value, double lo, double hi) { return value >= lo - 1e-12 && value <= hi + 1e-12; }
nlohmann::json vec(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }
}  // namespace

ContactCoverage contact_coverage(const std::vector<RunResult>& runs) {
  ContactCoverage s;
  std::vector<double> ratios;
  for (const auto& r : runs) {
    if (!r.contact) continue;
    const ContactOutcome& c = *r.contact;
    const auto& e = c.estimate;
    const double truth = c.force_true_target_n;
    const bool right = e.link == r.link_true;
    const bool f_in = within(truth, e.force_lo_n, e.force_hi_n);
    const bool f20 = std::fabs(e.force_n - truth) <= 0.2 * truth;
    ++s.estimated;
    s.link_right += right ? 1 : 0;
    s.point_covered += right && within(c.along_true_m, e.along_lo_m, e.along_hi_m) ? 1 : 0;
    s.force_covered += f_in ? 1 : 0;
    s.force_covered_link_right += right && f_in ? 1 : 0;
    s.force_within_2sigma += std::fabs(e.force_n - truth) <= 2.0 * e.force_sigma_n ? 1 : 0;
    s.determined += e.force_determined ? 1 : 0;
    s.determined_within_20pct += e.force_determined && f20 ? 1 : 0;
    s.three_components += e.determined_components == 3 ? 1 : 0;
    s.three_components_within_20pct += e.determined_components == 3 && f20 ? 1 : 0;
    const bool one_link = e.determined_components == 3 && e.links_consistent.size() == 1;
    s.three_components_one_link += one_link ? 1 : 0;
    s.three_components_one_link_within_20pct += one_link && f20 ? 1 : 0;
    if (e.force_n > 0.0) ratios.push_back(e.force_sigma_n / e.force_n);
  }
  if (!ratios.empty()) {
    std::sort(ratios.begin(), ratios.end());
    const std::size_t m = ratios.size() / 2;
    s.median_sigma_over_force = ratios.size() % 2 == 1 ? ratios[m] : 0.5 * (ratios[m - 1] + ratios[m]);
  }
  return s;
}

nlohmann::json to_json(const ContactCoverage& c) {
  return {{"estimated", c.estimated}, {"link_right", c.link_right},
          {"point_within_interval_link_right", c.point_covered},
          {"force_within_interval", c.force_covered}, {"force_within_interval_link_right", c.force_covered_link_right},
          {"force_within_2sigma", c.force_within_2sigma},
          {"force_determined", c.determined}, {"force_determined_within_20pct", c.determined_within_20pct},
          {"three_components", c.three_components}, {"three_components_within_20pct", c.three_components_within_20pct},
          {"three_components_one_link", c.three_components_one_link},
          {"three_components_one_link_within_20pct", c.three_components_one_link_within_20pct},
          {"median_force_sigma_over_force", c.median_sigma_over_force}};
}

std::string describe(const ContactCoverage& c) {
  char line[800];
  std::snprintf(line, sizeof line,
                "contact estimate's spreads (truth within the stated ~2-sigma set): point %d of the %d on the right link "
                "(%d estimates), force %d/%d (%d of the %d on the right link; within 2 sigma %d/%d; median sigma %.0f %% "
                "of the force); force determined (2 sigma within 20 %%) %d, within 20 %% %d/%d; all 3 components "
                "determined %d, within 20 %% %d/%d; of those on a single consistent link %d, within 20 %% %d/%d",
                c.point_covered, c.link_right, c.estimated, c.force_covered, c.estimated, c.force_covered_link_right,
                c.link_right, c.force_within_2sigma, c.estimated, 100.0 * c.median_sigma_over_force, c.determined,
                c.determined_within_20pct, c.determined, c.three_components, c.three_components_within_20pct,
                c.three_components, c.three_components_one_link, c.three_components_one_link_within_20pct,
                c.three_components_one_link);
  return line;
}

nlohmann::json contact_set_json(const ContactOutcome& c) {
  const auto& e = c.estimate;
  return {{"along_link_interval", {e.along_lo_m, e.along_hi_m}},
          {"force_interval", {e.force_lo_n, e.force_hi_n}},
          {"force_determined", e.force_determined},
          {"line_of_action", {{"point_base", vec(e.point_base)}, {"direction_base", vec(e.line_direction_base)}}},
          {"links_consistent", e.links_consistent},
          {"force_true_target", c.force_true_target_n},
          {"torque_sigma_lag", c.torque_sigma_lag_nm}};
}

}  // namespace jg::eval

namespace jg::eval {

void contact_set_from_json(const nlohmann::json& j, ContactOutcome& c) {
  auto& e = c.estimate;
  if (j.contains("along_link_interval")) {
    e.along_lo_m = j.at("along_link_interval").at(0).get<double>();
    e.along_hi_m = j.at("along_link_interval").at(1).get<double>();
  }
  if (j.contains("force_interval")) {
    e.force_lo_n = j.at("force_interval").at(0).get<double>();
    e.force_hi_n = j.at("force_interval").at(1).get<double>();
  }
  e.force_determined = j.value("force_determined", false);
  if (j.contains("line_of_action")) {
    const auto& d = j.at("line_of_action").at("direction_base");
    e.line_direction_base = {d.at(0).get<double>(), d.at(1).get<double>(), d.at(2).get<double>()};
  }
  if (j.contains("links_consistent")) e.links_consistent = j.at("links_consistent").get<std::vector<int>>();
  c.force_true_target_n = j.value("force_true_target", 0.0);
  // Read back too: a merged result must be the bytes of the unsharded one.
  if (j.contains("torque_sigma_lag")) c.torque_sigma_lag_nm = j.at("torque_sigma_lag").get<std::vector<double>>();
}

}  // namespace jg::eval
