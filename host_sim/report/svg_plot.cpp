#include "report/svg_plot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>
#include <set>
#include <sstream>
#include <utility>

extern char** environ;

namespace jg::report {
namespace {
namespace fs = std::filesystem;

struct Ranges {
  double xlo, xhi, ylo, yhi;
};

/// Keeps min and max of each bucket so that short spikes survive decimation.
void decimate(const std::vector<double>& sx, const std::vector<double>& sy, std::vector<double>& xs, std::vector<double>& ys) {
  const std::size_t n = std::min(sx.size(), sy.size());
  const std::size_t buckets = 1000;
  if (n <= 2 * buckets) {
    xs.assign(sx.begin(), sx.begin() + static_cast<std::ptrdiff_t>(n));
    ys.assign(sy.begin(), sy.begin() + static_cast<std::ptrdiff_t>(n));
    return;
  }
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t lo = b * n / buckets, hi = std::max(lo + 1, (b + 1) * n / buckets);
    std::size_t imin = lo, imax = lo;
    for (std::size_t i = lo; i < hi; ++i) {
      if (sy[i] < sy[imin]) imin = i;
      if (sy[i] > sy[imax]) imax = i;
    }
    for (const std::size_t i : {std::min(imin, imax), std::max(imin, imax)}) {
      xs.push_back(sx[i]);
      ys.push_back(sy[i]);
    }
  }
}

/// The points of `s` inside [xlo, xhi] plus one on each side, so that the line reaches the
/// frame's edge (gnuplot clips it there) while the decimation spends its points on what is shown.
void window(const Series& s, double xlo, double xhi, std::vector<double>& xs, std::vector<double>& ys) {
  const std::size_t n = std::min(s.x.size(), s.y.size());
  std::size_t first = n, last = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (s.x[i] >= xlo && s.x[i] <= xhi) {
      first = std::min(first, i);
      last = i;
    }
  }
  if (first == n) return;
  first = first > 0 ? first - 1 : 0;
  last = std::min(n - 1, last + 1);
  const std::vector<double> wx(s.x.begin() + static_cast<std::ptrdiff_t>(first), s.x.begin() + static_cast<std::ptrdiff_t>(last + 1));
  const std::vector<double> wy(s.y.begin() + static_cast<std::ptrdiff_t>(first), s.y.begin() + static_cast<std::ptrdiff_t>(last + 1));
  decimate(wx, wy, xs, ys);
}

/// The x range (fixed or the data's), then the y range of what lies inside it and the
/// reference lines, 5 % padded: a trace outside the window does not flatten the one inside.
Ranges plot_ranges(const Plot& p) {
  const double inf = std::numeric_limits<double>::infinity();
  Ranges r{inf, -inf, inf, -inf};
  for (const auto& s : p.series) {
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) r.xlo = std::min(r.xlo, s.x[i]), r.xhi = std::max(r.xhi, s.x[i]);
    }
  }
  if (p.x_lo < p.x_hi) r.xlo = p.x_lo, r.xhi = p.x_hi;
  if (!(r.xhi > r.xlo)) r.xlo = (std::isfinite(r.xlo) ? r.xlo : 0.0) - 1.0, r.xhi = r.xlo + 2.0;
  for (const auto& s : p.series) {
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (std::isfinite(s.y[i]) && s.x[i] >= r.xlo && s.x[i] <= r.xhi) r.ylo = std::min(r.ylo, s.y[i]), r.yhi = std::max(r.yhi, s.y[i]);
    }
  }
  for (const auto& h : p.hlines) {
    if (std::isfinite(h.y)) r.ylo = std::min(r.ylo, h.y), r.yhi = std::max(r.yhi, h.y);
  }
  if (p.y_lo < p.y_hi) {
    r.ylo = p.y_lo, r.yhi = p.y_hi;
    return r;
  }
  if (!(r.yhi > r.ylo)) r.ylo = (std::isfinite(r.ylo) ? r.ylo : 0.0) - 1.0, r.yhi = r.ylo + 2.0;
  const double pad = 0.05 * (r.yhi - r.ylo);
  r.ylo -= pad, r.yhi += pad;
  return r;
}

/// A gnuplot single-quoted string: only a quote needs doubling; line breaks would end the command.
std::string gp_str(const std::string& s) {
  std::string out = "'";
  for (const char c : s) {
    if (c == '\'') out += "''";
    else out += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return out + "'";
}

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

/// One data file per series ("x y" rows; a blank row where a value is not finite, which
/// gnuplot draws as a break in the line). Returns the files in series order.
std::vector<fs::path> write_data(const fs::path& dir, const Plot& p, const Ranges& r) {
  std::vector<fs::path> files;
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    std::vector<double> x, y;
    window(p.series[k], r.xlo, r.xhi, x, y);
    files.push_back(dir / ("series" + std::to_string(k) + ".dat"));
    std::ofstream f(files.back());
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (std::isfinite(x[i]) && std::isfinite(y[i])) f << num(x[i]) << ' ' << num(y[i]) << '\n';
      else f << '\n';
    }
    if (x.empty()) f << "\n";  // an empty series still gets its legend entry
  }
  return files;
}

/// The plot clauses: series, reference lines (constant functions), then one legend entry
/// per distinct marker (the vertical lines themselves are arrows, drawn in the script).
std::vector<std::string> plot_clauses(const Plot& p, const std::vector<fs::path>& files) {
  std::vector<std::string> c;
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    const Series& s = p.series[k];
    c.push_back(gp_str(files[k].string()) + " using 1:2 with lines lw " + num(s.width) + " lc rgb " + gp_str(s.color) +
                (s.dashed ? " dt 2" : " dt 1") + " title " + gp_str(s.label));
  }
  for (const auto& h : p.hlines) {
    if (!std::isfinite(h.y)) continue;
    c.push_back(num(h.y) + " with lines lw 1 dt 3 lc rgb " + gp_str(h.color) + (h.label.empty() ? " notitle" : " title " + gp_str(h.label)));
  }
  std::set<std::pair<std::string, std::string>> shown;
  for (const auto& m : p.markers) {
    if (m.label.empty() || !shown.insert({m.label, m.color}).second) continue;
    c.push_back("keyentry with lines lw 1.2 lc rgb " + gp_str(m.color) + " title " + gp_str(m.label));
  }
  return c;
}

/// The legend's entries, as plot_clauses makes them: a labelled series, a labelled reference
/// line, a distinct marker.
std::vector<std::string> legend_labels(const Plot& p) {
  std::vector<std::string> l;
  for (const auto& s : p.series) l.push_back(s.label);
  for (const auto& h : p.hlines) {
    if (std::isfinite(h.y) && !h.label.empty()) l.push_back(h.label);
  }
  std::set<std::pair<std::string, std::string>> shown;
  for (const auto& m : p.markers) {
    if (!m.label.empty() && shown.insert({m.label, m.color}).second) l.push_back(m.label);
  }
  return l;
}

/// Where the legend goes: below the frame, its columns as many as entries of the longest
/// label fit across (7 px a character at 11 px sans in Chromium, plus sample and gaps),
/// the canvas taller by its rows, so the frame keeps the height the caller asked for.
struct LegendLayout {
  int cols = 0, rows = 0;
  double height_px = 0.0;
};

LegendLayout legend_layout(const Plot& p) {
  LegendLayout k;
  const auto labels = legend_labels(p);
  if (labels.empty()) return k;
  std::size_t longest = 1;
  for (const auto& l : labels) longest = std::max(longest, l.size());
  const double entry_px = 7.0 * static_cast<double>(longest) + 70.0;
  const int n = static_cast<int>(labels.size());
  k.cols = std::clamp(static_cast<int>((p.width - 40) / entry_px), 1, n);
  k.rows = (n + k.cols - 1) / k.cols;
  k.height_px = 16.5 * k.rows + 6.0;
  return k;
}

/// The file the gnuplot script prints the frame and ranges to, beside its SVG.
fs::path frame_file(const fs::path& svg) { return svg.parent_path() / "frame.txt"; }

/// The canvas' height in px: the frame's share the caller asked for plus the legend's rows.
double canvas_height(const Plot& p) { return std::round(p.height + legend_layout(p).height_px); }

/// The gnuplot script: svg terminal, labels taken literally (no enhanced-text markup: "x_1"
/// stays "x_1"), the legend at a fixed place below the x label (gnuplot's own "key below"
/// drew it over the x label), markers as vertical lines spanning the frame.
std::string script(const Plot& p, const Ranges& r, const std::vector<fs::path>& files, const fs::path& out) {
  const LegendLayout k = legend_layout(p);
  const double h = canvas_height(p);
  std::ostringstream s;
  s << "set encoding utf8\n"
    << "set terminal svg size " << p.width << ',' << num(h) << " font 'sans,11' background '#ffffff'\n"
    << "set output " << gp_str(out.string()) << "\nset termoption noenhanced\n"
    << "set title " << gp_str(p.title) << " font 'sans,13'\nset xlabel " << gp_str(p.x_label) << "\nset ylabel " << gp_str(p.y_label) << '\n'
    << "set xrange [" << num(r.xlo) << ':' << num(r.xhi) << "]\nset yrange [" << num(r.ylo) << ':' << num(r.yhi) << "]\n"
    << "set grid lc rgb '#dddddd'\nset samples 2\nset border lc rgb '#444444'\n";
  if (k.rows == 0) {
    s << "unset key\n";
  } else {
    // 46 px between the frame and the legend: the tick labels and the x label.
    s << "set bmargin at screen " << num((k.height_px + 46.0) / h) << "\nset key at screen 0.5, screen " << num((k.height_px - 2.0) / h)
      << " center top horizontal Left reverse noautotitle maxcols " << k.cols << " maxrows " << k.rows << " width 3 samplen 3\n";
  }
  int arrow = 0;
  for (const auto& m : p.markers) {
    if (!std::isfinite(m.x) || m.x < r.xlo || m.x > r.xhi) continue;
    s << "set arrow " << ++arrow << " from " << num(m.x) << ", graph 0 to " << num(m.x) << ", graph 1 nohead lw 1.2 lc rgb "
      << gp_str(m.color) << '\n';
  }
  const auto clauses = plot_clauses(p, files);
  s << "plot ";
  for (std::size_t i = 0; i < clauses.size(); ++i) s << (i ? ", \\\n     " : "") << clauses[i];
  if (clauses.empty()) s << "NaN notitle";
  // Where gnuplot put the frame (px from the canvas' left and bottom) and the ranges it drew:
  // the page's script (plot_script) maps the pointer to data units with them.
  s << "\nset print " << gp_str(frame_file(out).string()) << "\nprint sprintf('%.10g %.10g %.10g %.10g %.10g %.10g %.10g %.10g', "
    << "GPVAL_TERM_XMIN, GPVAL_TERM_XMAX, GPVAL_TERM_YMIN, GPVAL_TERM_YMAX, GPVAL_X_MIN, GPVAL_X_MAX, GPVAL_Y_MIN, GPVAL_Y_MAX)\n";
  return s.str();
}

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// Runs gnuplot on `gp`; "" when it succeeded, else why not (its first error line).
std::string run_gnuplot(const fs::path& gp, const fs::path& err) {
  const char* env = std::getenv("JG_GNUPLOT");
  const std::string exe = env && *env ? env : "gnuplot";
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  std::string a0 = exe, a1 = gp.string();
  char* argv[] = {a0.data(), a1.data(), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, exe.c_str(), &fa, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return "cannot run '" + exe + "' (" + std::strerror(rc) + "; install the Debian package gnuplot-nox)";
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  std::string msg = read_file(err);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127) return "'" + exe + "' not found (install the Debian package gnuplot-nox)";
  msg.erase(std::remove(msg.begin(), msg.end(), '\r'), msg.end());
  while (!msg.empty() && msg.front() == '\n') msg.erase(0, 1);
  return "'" + exe + "' failed: " + msg.substr(0, msg.find('\n'));
}

/// Removes every piece of `s` from `open` up to and including the next `close`.
void erase_all(std::string& s, const std::string& open, const std::string& close) {
  for (std::size_t a = s.find(open); a != std::string::npos; a = s.find(open, a)) {
    const std::size_t b = s.find(close, a + open.size());
    if (b == std::string::npos) return;
    s.erase(a, b + close.size() - a);
  }
}

/// What plot_script reads off the <svg> element: the frame (left top right bottom, px), the
/// x and y ranges drawn and the axes' names; "" when gnuplot printed no frame (the plot then
/// stays a still picture).
std::string frame_attributes(const Plot& p, const fs::path& frame_txt) {
  std::ifstream f(frame_txt);
  double v[8];
  for (double& x : v) {
    if (!(f >> x)) return "";
  }
  const double h = canvas_height(p);  // gnuplot counts y up from the bottom, SVG down from the top
  return " data-frame=\"" + num(v[0]) + ' ' + num(h - v[3]) + ' ' + num(v[1]) + ' ' + num(h - v[2]) + "\" data-range=\"" + num(v[4]) + ' ' +
         num(v[5]) + ' ' + num(v[6]) + ' ' + num(v[7]) + "\" data-x-label=\"" + escape(p.x_label) + "\" data-y-label=\"" + escape(p.y_label) + '"';
}

/// gnuplot's file as an inline element: no XML prolog, and no ids, which would repeat across
/// the plots of one page (its <defs> hold point symbols and text boxes these plots never use).
/// Each plotted item's group (gnuplot's id "gnuplot_plot_N") keeps its number as data-series,
/// for plot_script to name the trace nearest the pointer.
std::string inline_svg(std::string svg, const std::string& attributes) {
  const std::size_t start = svg.find("<svg");
  if (start == std::string::npos) return "";
  svg.erase(0, start);
  svg.insert(4, " class=\"plot\"" + attributes);
  erase_all(svg, "<title>", "</title>");
  erase_all(svg, "<desc>", "</desc>");
  const std::size_t defs_end = svg.find("</defs>");
  if (defs_end != std::string::npos && svg.find("url(#", defs_end) == std::string::npos &&
      svg.find("href='#", defs_end) == std::string::npos) {
    erase_all(svg, "<defs>", "</defs>");
  }
  const std::string series_id = " id=\"gnuplot_plot_";
  for (std::size_t a = svg.find(series_id); a != std::string::npos; a = svg.find(series_id, a)) svg.replace(a, series_id.size(), " data-series=\"");
  erase_all(svg, " id=\"gnuplot_", "\"");
  return svg;
}

/// What stands in for a plot gnuplot did not draw: the reason, where the plot would be.
std::string placeholder(const Plot& p, const std::string& why) {
  static std::once_flag warned;
  std::call_once(warned, [&] { std::fprintf(stderr, "warning: report plots not drawn: %s\n", why.c_str()); });
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" width=\"" << p.width << "\" height=\"60\" font-family=\"sans-serif\" "
    << "font-size=\"12\"><text x=\"4\" y=\"20\">plot not drawn: " << escape(p.title) << "</text><text x=\"4\" y=\"40\" fill=\"#d62728\">"
    << escape(why) << "</text></svg>\n";
  return o.str();
}

/// A fresh private folder for one plot's script and data (plots may be drawn in parallel).
fs::path make_work_dir() {
  std::string tmpl = (fs::temp_directory_path() / "jointguard-plot-XXXXXX").string();
  if (mkdtemp(tmpl.data()) == nullptr) return {};
  return tmpl;
}
}  // namespace

std::string escape(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string render_svg(const Plot& p) {
  const fs::path dir = make_work_dir();
  if (dir.empty()) return placeholder(p, std::string("cannot create a temporary folder: ") + std::strerror(errno));
  const Ranges r = plot_ranges(p);
  const auto files = write_data(dir, p, r);
  const fs::path gp = dir / "plot.gp", out = dir / "plot.svg";
  std::ofstream(gp) << script(p, r, files, out);
  const std::string why = run_gnuplot(gp, dir / "gnuplot.err");
  std::string svg = why.empty() ? inline_svg(read_file(out), frame_attributes(p, frame_file(out))) : "";
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (!why.empty()) return placeholder(p, why);
  if (svg.empty()) return placeholder(p, "gnuplot wrote no SVG");
  return svg;
}

}  // namespace jg::report
