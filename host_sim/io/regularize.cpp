#include "io/regularize.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace jg::io {
namespace {

using Signals = std::vector<std::vector<double>>;

/// Every per-joint signal of a recording, in one list (absent ones are empty).
std::vector<const Signals*> signals_of(const Recording& r) {
  return {&r.q, &r.dq, &r.current, &r.tau_m, &r.tau_j, &r.tau_ext};
}
std::vector<Signals*> signals_of(Recording& r) { return {&r.q, &r.dq, &r.current, &r.tau_m, &r.tau_j, &r.tau_ext}; }

/// Row k repeats row k - 1: q, dq and every torque/current column equal.
bool repeats_previous(const Recording& r, std::size_t k) {
  for (const Signals* sig : signals_of(r)) {
    for (const auto& v : *sig) {
      if (v[k] != v[k - 1]) return false;
    }
  }
  return true;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// A logger's nominal rate from its jittered median: the nearest of the usual rates
/// (1, 1.25, 2, 2.5, 4, 5, 8 x 10^k Hz: 1000, 125, 100, ...) when within 2 %, else 3
/// significant digits (991 Hz of a jittered 1 kHz log -> 1000 Hz; 333.4 Hz -> 333 Hz).
double round_rate(double rate) {
  const double decade = std::pow(10.0, std::floor(std::log10(rate)));
  double best = 0.0;
  for (const double m : {1.0, 1.25, 2.0, 2.5, 4.0, 5.0, 8.0, 10.0}) {
    const double nice = m * decade;
    if (std::fabs(rate / nice - 1.0) < 0.02 && (best == 0.0 || std::fabs(nice - rate) < std::fabs(best - rate))) best = nice;
  }
  if (best > 0.0) return best;
  const double scale = decade / 100.0;
  return std::round(rate / scale) * scale;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// Linear interpolation of x (known at the rows `nodes`) at the times `grid`.
std::vector<double> interpolate(const std::vector<double>& t, const std::vector<double>& x,
                                const std::vector<std::size_t>& nodes, const std::vector<double>& grid) {
  std::vector<double> out(grid.size());
  std::size_t i = 0;
  for (std::size_t k = 0; k < grid.size(); ++k) {
    while (i + 2 < nodes.size() && t[nodes[i + 1]] <= grid[k]) ++i;
    if (nodes.size() == 1) {
      out[k] = x[nodes[0]];
      continue;
    }
    const double t0 = t[nodes[i]], t1 = t[nodes[i + 1]];
    const double a = std::clamp((grid[k] - t0) / (t1 - t0), 0.0, 1.0);
    out[k] = x[nodes[i]] + a * (x[nodes[i + 1]] - x[nodes[i]]);
  }
  return out;
}

/// Rows [begin, end) of `rec` resampled at `step` from the row `begin`'s time.
Recording resample_rows(const Recording& rec, std::size_t begin, std::size_t end, const std::vector<bool>& keep,
                        double step) {
  std::vector<std::size_t> nodes;
  for (std::size_t k = begin; k < end; ++k) {
    if (keep[k]) nodes.push_back(k);
  }
  const double t0 = rec.t[nodes.front()], t1 = rec.t[nodes.back()];
  // The last grid point may fall up to a millionth of a step after the last row (rounding).
  const auto n = static_cast<std::size_t>(std::floor((t1 - t0) / step + 1e-6)) + 1;
  std::vector<double> grid(n);
  for (std::size_t k = 0; k < n; ++k) grid[k] = t0 + static_cast<double>(k) * step;
  Recording out;
  out.joint_ids = rec.joint_ids;
  out.meta = rec.meta;
  out.meta.sample_time = step;
  out.torque_kind = rec.torque_kind;
  out.t = grid;
  const auto in_sigs = signals_of(rec);
  const auto out_sigs = signals_of(out);
  for (std::size_t s = 0; s < in_sigs.size(); ++s) {
    for (const auto& v : *in_sigs[s]) out_sigs[s]->push_back(interpolate(rec.t, v, nodes, grid));
  }
  for (const auto& [name, v] : rec.extra) {
    if (v.size() == rec.samples()) out.extra[name] = interpolate(rec.t, v, nodes, grid);
  }
  for (const std::size_t k : nodes) out.rows_t.push_back(rec.t[k]);
  for (std::size_t j = 0; j < rec.joints(); ++j) {
    out.rows_q.emplace_back();
    out.rows_dq.emplace_back();
    for (const std::size_t k : nodes) {
      out.rows_q.back().push_back(rec.q[j][k]);
      out.rows_dq.back().push_back(rec.dq[j][k]);
    }
  }
  if (!rec.collision.empty()) {
    // A contact flag is not interpolated: each sample takes the last row at or before it.
    out.collision.resize(n);
    std::size_t i = begin;
    for (std::size_t k = 0; k < n; ++k) {
      while (i + 1 < end && rec.t[i + 1] <= grid[k]) ++i;
      out.collision[k] = rec.collision[i];
    }
  }
  return out;
}

}  // namespace

std::string RegularizeReport::summary() const {
  std::ostringstream os;
  const std::string rate = fmt("%.4g", rate_hz);
  if (method.rfind("none", 0) == 0) {
    os << source << ": " << rows_in << " rows at " << rate << " Hz, uniform: used as recorded";
    return os.str();
  }
  os << "resampled " << source << ": " << rows_in << " rows -> " << rows_out << " at " << rate << " Hz"
     << (rate_given ? " (given)" : "") << ", " << method << "; " << repeats_dropped << " repeated rows dropped; "
     << gaps_bridged << " gaps bridged";
  if (gaps_bridged > 0) os << " (longest " << fmt("%.1f", longest_bridged_gap_s * 1e3) << " ms)";
  os << "; " << gaps_split << " gaps split (> " << fmt("%.3g", split_gap_s) << " s)";
  if (segments.size() > 1) {
    os << " into " << segments.size() << " segments";
  }
  if (!dropped.empty()) os << "; " << dropped.size() << " segment(s) too short to use dropped";
  return os.str();
}

std::size_t RegularizeReport::longest() const {
  std::size_t best = 0;
  for (std::size_t k = 1; k < segments.size(); ++k) {
    if (segments[k].samples > segments[best].samples) best = k;
  }
  return best;
}

namespace {
/// The rows that carry a new state (keep), and whether the clock is uniform. On a uniform
/// clock every row is its own sample (a state at rest repeats honestly); only a jittering
/// logger stamps the same state twice: a run of repeats is dropped, but for its last row
/// when the state was held for longer than hold_steps. Fills the report's step figures.
struct Rows {
  std::vector<bool> keep;
  bool uniform_clock = false;
};

Rows rows_to_keep(const Recording& rec, const RegularizeOptions& o, RegularizeReport& rep) {
  const std::size_t m = rec.samples();
  std::vector<double> all_steps;
  for (std::size_t k = 1; k < m; ++k) all_steps.push_back(rec.t[k] - rec.t[k - 1]);
  rep.min_step_in_s = *std::min_element(all_steps.begin(), all_steps.end());
  rep.max_step_in_s = *std::max_element(all_steps.begin(), all_steps.end());
  const double median_all = median(all_steps);
  const bool uniform_clock = rep.min_step_in_s > 0.99 * median_all && rep.max_step_in_s < 1.01 * median_all;
  // Which rows carry a new state.
  std::vector<bool> repeat(m, false);
  for (std::size_t k = 1; k < m && o.drop_repeats && !uniform_clock; ++k) repeat[k] = repeats_previous(rec, k);
  std::vector<double> state_steps;
  for (std::size_t k = 1; k < m; ++k) {
    if (!repeat[k] && !repeat[k - 1]) state_steps.push_back(rec.t[k] - rec.t[k - 1]);
  }
  rep.median_step_in_s = state_steps.size() >= 2 ? median(state_steps) : median_all;
  const double med = rep.median_step_in_s;
  rep.split_gap_s = o.max_gap_s > 0.0 ? o.max_gap_s : std::max(o.gap_steps * med, o.gap_min_s);
  std::vector<bool> keep(m, true);
  for (std::size_t k = 1; k < m; ++k) {
    if (!repeat[k]) continue;
    std::size_t end = k;  // the run of repeats is [k, end)
    while (end < m && repeat[end]) ++end;
    const bool held = rec.t[end - 1] - rec.t[k - 1] > o.hold_steps * med;
    for (std::size_t i = k; i < end; ++i) keep[i] = false;
    if (held) keep[end - 1] = true;
    k = end - 1;
  }
  for (std::size_t k = 0; k < m; ++k) rep.repeats_dropped += keep[k] ? 0 : 1;
  return {keep, uniform_clock};
}

/// The kept rows resampled segment by segment (split at steps longer than the split gap);
/// a segment shorter than min_segment_samples is dropped (rep.dropped).
void resample_segments(const Recording& rec, const RegularizeOptions& o, const std::vector<bool>& keep, Regularized& out) {
  RegularizeReport& rep = out.report;
  const std::size_t m = rec.samples();
  const double med = rep.median_step_in_s;
  std::size_t begin = 0;
  for (std::size_t k = 1; k <= m; ++k) {
    const bool split = k < m && rec.t[k] - rec.t[k - 1] > rep.split_gap_s;
    if (k < m && !split) {
      const double step = rec.t[k] - rec.t[k - 1];
      if (step > 1.5 * med) {
        ++rep.gaps_bridged;
        rep.longest_bridged_gap_s = std::max(rep.longest_bridged_gap_s, step);
      }
      continue;
    }
    if (split) ++rep.gaps_split;
    SegmentSpan span{rec.t[begin], rec.t[k - 1], k - begin, 0};
    std::size_t nodes = 0;
    for (std::size_t i = begin; i < k; ++i) nodes += keep[i] ? 1 : 0;
    if (nodes >= 2) {
      Recording seg = resample_rows(rec, begin, k, keep, rep.step_s);
      span.samples = seg.samples();
      if (seg.samples() >= o.min_segment_samples) {
        rep.rows_out += seg.samples();
        rep.segments.push_back(span);
        out.segments.push_back(std::move(seg));
        begin = k;
        continue;
      }
    } else {
      span.samples = nodes;
    }
    rep.dropped.push_back(span);
    begin = k;
  }
}
}  // namespace

Regularized regularize(const Recording& rec, const RegularizeOptions& o, const std::string& source) {
  Regularized out;
  RegularizeReport& rep = out.report;
  rep.source = source;
  rep.rows_in = rec.samples() + rec.duplicate_rows_dropped;
  rep.repeats_dropped = rec.duplicate_rows_dropped;
  rep.rate_given = o.rate_hz > 0.0;
  const std::size_t m = rec.samples();
  auto refuse = [&](const std::string& why) {
    throw FormatError(source + ": field 't': " + why);
  };
  if (m < 2) {
    refuse(std::to_string(m) + " distinct row(s): at least " + std::to_string(std::max<std::size_t>(2, o.min_segment_samples)) +
           " samples are needed; record for longer");
  }
  const Rows rows = rows_to_keep(rec, o, rep);
  const double med = rep.median_step_in_s;
  const bool uniform_clock = rows.uniform_clock;
  const double data_rate = 1.0 / med;
  rep.rate_hz = rep.rate_given ? o.rate_hz : round_rate(data_rate);
  rep.step_s = 1.0 / rep.rate_hz;

  const bool uniform = uniform_clock && rec.duplicate_rows_dropped == 0;
  const double mean_step = (rec.t.back() - rec.t.front()) / static_cast<double>(m - 1);
  if (uniform && (!rep.rate_given || std::fabs(mean_step * o.rate_hz - 1.0) < 1e-3) && m >= o.min_segment_samples) {
    rep.method = "none (uniform)";
    rep.rate_hz = 1.0 / mean_step;
    rep.step_s = mean_step;
    rep.rows_out = m;
    rep.segments.push_back({rec.t.front(), rec.t.back(), m, m});
    out.segments.push_back(rec);
    return out;
  }
  rep.method = "linear by time stamp";
  const double expected = (rec.t.back() - rec.t.front()) * rep.rate_hz;
  if (!(expected < static_cast<double>(o.max_samples))) {
    refuse("resampling " + fmt("%.6g", rec.t.back() - rec.t.front()) + " s at " + fmt("%.6g", rep.rate_hz) +
           " Hz would make more than " + std::to_string(o.max_samples) + " samples; give a lower --rate");
  }
  resample_segments(rec, o, rows.keep, out);
  if (out.segments.empty()) {
    std::string why = "no segment of at least " + std::to_string(o.min_segment_samples) + " samples at " +
                      fmt("%.4g", rep.rate_hz) + " Hz";
    if (rep.gaps_split > 0) why += " between gaps longer than " + fmt("%.3g", rep.split_gap_s) + " s (--max-gap)";
    why += " (" + std::to_string(rep.rows_in) + " rows over " + fmt("%.6g", rec.t.back() - rec.t.front()) +
           " s); record for longer";
    if (!rep.rate_given) why += " or give a higher --rate";
    refuse(why);
  }
  return out;
}

}  // namespace jg::io
