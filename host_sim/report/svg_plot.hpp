// SVG line plots for reports, drawn by gnuplot (Debian `gnuplot-nox`, its `svg` terminal):
// series, horizontal reference lines (thresholds), vertical markers (collision, detection).
// gnuplot lays out the axes, ticks and legend and clips every line to the plot frame; the
// hand-written SVG it replaces let traces run outside the frame, cut legends off and drew
// marker labels over threshold labels (issue 29). Every label is in the legend (below the
// frame), so none is drawn over the data or over another. The SVG is returned inline, so a
// report holding it stays one self-contained file. It carries where gnuplot put the frame and
// the ranges drawn (data-frame, data-range), which plot_script's hover readout and zoom read.
#pragma once

#include <string>
#include <vector>

namespace jg::report {

struct Series {
  std::string label;
  std::vector<double> x, y;
  std::string color = "#1f77b4";
  double width = 1.2;
  bool dashed = false;
};

struct Marker {
  double x = 0.0;
  std::string label;
  std::string color = "#d62728";
};

struct HLine {
  double y = 0.0;
  std::string label;
  std::string color = "#7f7f7f";
};

struct Plot {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  std::vector<Marker> markers;
  std::vector<HLine> hlines;
  int width = 760, height = 300;
  /// Optional fixed ranges (used when lo < hi).
  double x_lo = 0.0, x_hi = 0.0, y_lo = 0.0, y_hi = 0.0;
};

/// Renders the plot as a standalone <svg> element (long series are decimated to about
/// 2000 points per series, keeping each bucket's extremes so spikes stay visible). Runs
/// `gnuplot` (or $JG_GNUPLOT) on a script and data in a temporary folder. Without gnuplot
/// the element says so in place of the plot ("plot not drawn: ...") and a warning goes to
/// stderr: the figures in the tables stay right, only the picture is missing.
std::string render_svg(const Plot& plot);

/// The page script that makes render_svg's plots readable (once per HTML page, before
/// </body>): hovering a plot shows the pointer's x and y and the nearest trace's value;
/// dragging across a frame (or Shift + wheel) zooms its x range, a double-click shows the
/// whole range again.
/// Inline and self-contained (plot_script.cpp), so the page stays one offline file.
std::string plot_script();
/// Escapes text for HTML/SVG.
std::string escape(const std::string& s);

}  // namespace jg::report
