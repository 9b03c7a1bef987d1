#include "report/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace jg::report {
namespace {
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string tick_label(double v, double step) {
  char buf[32];
  const int decimals = step >= 1.0 ? 0 : std::min(6, static_cast<int>(std::ceil(-std::log10(step))));
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

double nice_step(double span, int target) {
  const double raw = span / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (m * mag >= raw) return m * mag;
  }
  return 10.0 * mag;
}

/// Keeps min and max of each bucket so that short spikes survive decimation.
void decimate(const Series& s, std::vector<double>& xs, std::vector<double>& ys) {
  const std::size_t n = std::min(s.x.size(), s.y.size());
  const std::size_t buckets = 1000;
  if (n <= 2 * buckets) {
    xs.assign(s.x.begin(), s.x.begin() + static_cast<std::ptrdiff_t>(n));
    ys.assign(s.y.begin(), s.y.begin() + static_cast<std::ptrdiff_t>(n));
    return;
  }
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t lo = b * n / buckets, hi = std::max(lo + 1, (b + 1) * n / buckets);
    std::size_t imin = lo, imax = lo;
    for (std::size_t i = lo; i < hi; ++i) {
      if (s.y[i] < s.y[imin]) imin = i;
      if (s.y[i] > s.y[imax]) imax = i;
    }
    for (const std::size_t i : {std::min(imin, imax), std::max(imin, imax)}) {
      xs.push_back(s.x[i]);
      ys.push_back(s.y[i]);
    }
  }
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
  double xlo = std::numeric_limits<double>::max(), xhi = -xlo, ylo = xlo, yhi = -xlo;
  for (const auto& s : p.series) {
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xlo = std::min(xlo, s.x[i]);
      xhi = std::max(xhi, s.x[i]);
      ylo = std::min(ylo, s.y[i]);
      yhi = std::max(yhi, s.y[i]);
    }
  }
  for (const auto& h : p.hlines) {
    ylo = std::min(ylo, h.y);
    yhi = std::max(yhi, h.y);
  }
  if (p.x_lo < p.x_hi) { xlo = p.x_lo; xhi = p.x_hi; }
  if (p.y_lo < p.y_hi) { ylo = p.y_lo; yhi = p.y_hi; }
  if (!(xhi > xlo)) { xlo -= 1.0; xhi += 1.0; }
  if (!(yhi > ylo)) { ylo -= 1.0; yhi += 1.0; }
  const double pad = 0.05 * (yhi - ylo);
  ylo -= pad;
  yhi += pad;
  const double L = 64, R = 16, T = 28, B = 44;
  const double W = p.width - L - R, H = p.height - T - B;
  auto X = [&](double x) { return L + (x - xlo) / (xhi - xlo) * W; };
  auto Y = [&](double y) { return T + (yhi - y) / (yhi - ylo) * H; };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" width=\"" << p.width << "\" height=\"" << p.height
    << "\" viewBox=\"0 0 " << p.width << ' ' << p.height << "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  o << "<rect x=\"0\" y=\"0\" width=\"" << p.width << "\" height=\"" << p.height << "\" fill=\"white\"/>\n";
  o << "<text x=\"" << L << "\" y=\"16\" font-size=\"13\" font-weight=\"bold\">" << escape(p.title) << "</text>\n";
  const double xs = nice_step(xhi - xlo, 8), ys = nice_step(yhi - ylo, 5);
  for (double v = std::ceil(xlo / xs) * xs; v <= xhi + 1e-9 * xs; v += xs) {
    o << "<line x1=\"" << num(X(v)) << "\" y1=\"" << num(T) << "\" x2=\"" << num(X(v)) << "\" y2=\"" << num(T + H)
      << "\" stroke=\"#eee\"/><text x=\"" << num(X(v)) << "\" y=\"" << num(T + H + 14) << "\" text-anchor=\"middle\">"
      << tick_label(v, xs) << "</text>\n";
  }
  for (double v = std::ceil(ylo / ys) * ys; v <= yhi + 1e-9 * ys; v += ys) {
    o << "<line x1=\"" << num(L) << "\" y1=\"" << num(Y(v)) << "\" x2=\"" << num(L + W) << "\" y2=\"" << num(Y(v))
      << "\" stroke=\"#eee\"/><text x=\"" << num(L - 4) << "\" y=\"" << num(Y(v) + 4) << "\" text-anchor=\"end\">"
      << tick_label(v, ys) << "</text>\n";
  }
  o << "<rect x=\"" << L << "\" y=\"" << T << "\" width=\"" << W << "\" height=\"" << H << "\" fill=\"none\" stroke=\"#444\"/>\n";
  o << "<text x=\"" << num(L + W / 2) << "\" y=\"" << p.height - 8 << "\" text-anchor=\"middle\">" << escape(p.x_label) << "</text>\n";
  o << "<text transform=\"translate(14," << num(T + H / 2) << ") rotate(-90)\" text-anchor=\"middle\">" << escape(p.y_label) << "</text>\n";
  o << "<g clip-path=\"inset(0)\">\n";
  for (const auto& h : p.hlines) {
    o << "<line x1=\"" << num(L) << "\" y1=\"" << num(Y(h.y)) << "\" x2=\"" << num(L + W) << "\" y2=\"" << num(Y(h.y))
      << "\" stroke=\"" << h.color << "\" stroke-dasharray=\"6 4\"/>";
    if (!h.label.empty()) o << "<text x=\"" << num(L + W - 4) << "\" y=\"" << num(Y(h.y) - 3) << "\" text-anchor=\"end\" fill=\"" << h.color << "\">" << escape(h.label) << "</text>";
    o << '\n';
  }
  for (const auto& s : p.series) {
    std::vector<double> x, y;
    decimate(s, x, y);
    if (x.empty()) continue;
    o << "<polyline fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\"" << s.width << '"'
      << (s.dashed ? " stroke-dasharray=\"4 3\"" : "") << " points=\"";
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (std::isfinite(x[i]) && std::isfinite(y[i])) o << num(X(x[i])) << ',' << num(Y(std::clamp(y[i], ylo, yhi))) << ' ';
    }
    o << "\"/>\n";
  }
  for (const auto& m : p.markers) {
    if (m.x < xlo || m.x > xhi) continue;
    o << "<line x1=\"" << num(X(m.x)) << "\" y1=\"" << num(T) << "\" x2=\"" << num(X(m.x)) << "\" y2=\"" << num(T + H)
      << "\" stroke=\"" << m.color << "\" stroke-width=\"1.2\"/><text x=\"" << num(X(m.x) + 3) << "\" y=\"" << num(T + 12)
      << "\" fill=\"" << m.color << "\">" << escape(m.label) << "</text>\n";
  }
  o << "</g>\n";
  // Legend on the title line, after the title.
  double lx = L + 8.0 * static_cast<double>(p.title.size()) + 24.0;
  for (const auto& s : p.series) {
    o << "<line x1=\"" << num(lx) << "\" y1=\"12\" x2=\"" << num(lx + 18) << "\" y2=\"12\" stroke=\"" << s.color
      << "\" stroke-width=\"2\"/><text x=\"" << num(lx + 22) << "\" y=\"16\">" << escape(s.label) << "</text>\n";
    lx += 30 + 6.5 * static_cast<double>(s.label.size());
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace jg::report
