#include "workflow/pipeline_report.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "identification/identify.hpp"
#include "report/contact_report.hpp"
#include "report/svg_plot.hpp"

namespace jg::workflow {
namespace {
using report::escape;

std::string num(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

const char* const kColors[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};

/// The estimate per joint over the recording, the detections as markers.
report::Plot estimate_plot(const ReplayedRecording& rp) {
  const auto& res = rp.outcome.result;
  report::Plot p;
  p.title = std::filesystem::path(rp.recording).filename().string() + ": estimated external torque per joint";
  p.x_label = "t [s]";
  p.y_label = "torque [N·m]";
  p.width = 960;  // room for a legend of seven joints
  for (std::size_t j = 0; j < res.mu.size(); ++j) {
    p.series.push_back({"joint " + std::to_string(rp.outcome.joint_ids[j]), res.t, res.mu[j], kColors[j % 8], 1.0});
  }
  for (const auto& e : res.events) p.markers.push_back({e.t, "link " + std::to_string(e.link), "#d62728"});
  return p;
}

void identity_section(std::ostringstream& h, const PipelineOptions& o) {
  h << "<h2>Command</h2>\n<table><tr><th>version</th><td>" << escape(o.identity.value("version", "")) << "</td></tr>\n";
  if (o.identity.contains("options")) {
    for (const auto& [name, values] : o.identity["options"].items()) {
      std::string v;
      for (const auto& x : values) v += (v.empty() ? "" : " ") + x.get<std::string>();
      h << "<tr><th>" << escape(name) << "</th><td>" << escape(v) << "</td></tr>\n";
    }
  }
  if (o.identity.contains("input_sha256")) {
    for (const auto& [file, sha] : o.identity["input_sha256"].items()) {
      h << "<tr><th>sha256</th><td>" << escape(file) << ": <code>" << escape(sha.get<std::string>()) << "</code></td></tr>\n";
    }
  }
  h << "</table>\n";
}

void friction_section(std::ostringstream& h, const PipelineOptions& o, const PipelineResult& r) {
  h << "<h2>Friction identified</h2>\n<p class=\"note\">From <code>" << escape(o.identify) << "</code>, t = "
    << num("%.3f", r.friction.t_begin) << " .. " << num("%.3f", r.friction.t_end)
    << " s (LuGre per joint, file <code>friction.json</code>).</p>\n<table><tr><th>joint</th>";
  for (const auto* name : ident::kParamNames) h << "<th>" << name << "</th>";
  h << "<th>rms [N·m]</th><th>bounded for the firmware</th></tr>\n";
  for (std::size_t k = 0; k < r.friction.joints.size(); ++k) {
    const auto& j = r.friction.joints[k];
    const auto& p = j.params;
    std::string bounded;
    for (const auto& b : j.bounded) bounded += (bounded.empty() ? "" : ", ") + b.parameter;
    h << "<tr><td>" << r.joint_ids[k] << "</td><td>" << num("%.4g", p.sigma0) << "</td><td>" << num("%.4g", p.sigma1) << "</td><td>"
      << num("%.4g", p.sigma2) << "</td><td>" << num("%.4g", p.tau_c) << "</td><td>" << num("%.4g", p.tau_s) << "</td><td>"
      << num("%.4g", p.w_s) << "</td><td>" << num("%.4f", j.rms) << "</td><td>" << escape(bounded.empty() ? "-" : bounded)
      << "</td></tr>\n";
  }
  h << "</table>\n";
}

void threshold_section(std::ostringstream& h, const PipelineResult& r) {
  const auto& t = r.thresholds;
  h << "<h2>Thresholds</h2>\n<p class=\"note\">Calibrated on <code>" << escape(r.calibration_recording) << "</code>"
    << (r.calibrated_on_identification ? " (the identification recording: no --calibrate given)" : "")
    << ", file <code>threshold.json</code>.</p>\n";
  for (const auto& w : r.warnings) h << "<p class=\"warn\">" << escape(w) << "</p>\n";
  h << "<table><tr><th>joint</th><th>while moving [N·m]</th><th>+ at standstill [N·m]</th><th>without compensation [N·m]</th>"
       "<th>holding change [N·m]</th><th>from</th></tr>\n";
  for (std::size_t k = 0; k < r.joint_ids.size(); ++k) {
    h << "<tr><td>" << r.joint_ids[k] << "</td><td>" << num("%.3f", t.threshold[k]) << "</td><td>" << num("%.3f", t.low_speed_extra[k])
      << "</td><td>" << num("%.3f", t.threshold_uncompensated[k]) << "</td><td>"
      << (k < t.hold_change.size() ? num("%.3f", t.hold_change[k]) : "-") << "</td><td>"
      << escape(k < t.hold_source.size() ? t.hold_source[k] : "-") << "</td></tr>\n";
  }
  h << "</table>\n";
}

void replay_section(std::ostringstream& h, const ReplayedRecording& rp) {
  const auto& out = rp.outcome;
  const auto& res = out.result;
  h << "<h2>" << escape(std::filesystem::path(rp.recording).filename().string()) << ": " << res.events.size()
    << " detection(s)</h2>\n<p class=\"note\"><code>" << escape(rp.recording) << "</code>, file <code>" << escape(rp.file)
    << "</code>; holding " << escape(out.holding);
  if (out.holding != "none") h << ": " << res.held_samples << " of " << res.t.size() << " samples held";
  h << ".</p>\n";
  for (const auto& n : out.notes) h << "<p class=\"warn\">" << escape(n) << "</p>\n";
  if (!res.events.empty()) {
    h << "<table><tr><th>t [s]</th><th>link</th><th>joints over</th><th>by</th><th>contact</th></tr>\n";
    for (const auto& e : res.events) {
      std::string over;
      for (const int k : e.joints_over) over += (over.empty() ? "" : " ") + std::to_string(k);
      std::string contact = "-";
      if (e.contact && e.contact->link >= 1) {
        contact = report::describe_contact(*e.contact, out.joint_ids[static_cast<std::size_t>(e.contact->link - 1)]);
      }
      h << "<tr><td>" << num("%.4f", e.t) << "</td><td>" << e.link << "</td><td>" << over << "</td><td>"
        << (e.by_hold ? "holding detector" : "band") << "</td><td class=\"l\">" << escape(contact) << "</td></tr>\n";
    }
    h << "</table>\n";
  }
  h << report::render_svg(estimate_plot(rp));
}
}  // namespace

std::string pipeline_report_html(const PipelineOptions& o, const PipelineResult& r) {
  std::ostringstream h;
  h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>jointguard pipeline</title><style>"
       "body{font-family:sans-serif;max-width:1000px;margin:20px auto;color:#222}table{border-collapse:collapse}"
       "td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}td.l{text-align:left}.note{color:#555}"
       ".warn{color:#a33}</style></head><body>\n";
  std::size_t events = 0;
  for (const auto& rp : r.replays) events += rp.outcome.result.events.size();
  h << "<h1>jointguard pipeline: " << escape(std::filesystem::path(o.model).filename().string()) << "</h1>\n<p>"
    << r.replays.size() << " recording(s) replayed, " << events << " detection(s) in all (" << escape(o.replay.scalar)
    << " firmware scalar).</p>\n";
  identity_section(h, o);
  friction_section(h, o, r);
  threshold_section(h, r);
  for (const auto& rp : r.replays) replay_section(h, rp);
  h << report::plot_script() << "</body></html>\n";
  return h.str();
}

}  // namespace jg::workflow
