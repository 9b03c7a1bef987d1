#include "dynamics/uniform_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace jg::dyn {
namespace {

double median_step(const std::vector<double>& t) {
  std::vector<double> s;
  for (std::size_t k = 1; k < t.size(); ++k) s.push_back(t[k] - t[k - 1]);
  if (s.empty()) return 0.0;
  std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(s.size() / 2), s.end());
  return s[s.size() / 2];
}

std::vector<double> pick(const std::vector<double>& x, const std::vector<std::size_t>& rows) {
  std::vector<double> out;
  out.reserve(rows.size());
  for (std::size_t r : rows) out.push_back(x[r]);
  return out;
}

}  // namespace

bool is_uniform(const io::Recording& rec) {
  const double dt = median_step(rec.t);
  if (!(dt > 0.0)) return false;
  for (std::size_t k = 1; k < rec.t.size(); ++k) {
    if (!(std::abs(rec.t[k] - rec.t[k - 1] - dt) <= 0.01 * dt)) return false;
  }
  return true;
}

io::Recording to_uniform_grid(const io::Recording& rec, double dt, std::string* note) {
  const std::size_t S = rec.samples(), n = rec.joints();
  // Rows kept: strictly later than the last kept one and not a repeat of its state.
  std::vector<std::size_t> rows;
  std::size_t repeats = 0;
  for (std::size_t k = 0; k < S; ++k) {
    if (!rows.empty()) {
      const std::size_t p = rows.back();
      bool same = true;
      for (std::size_t j = 0; j < n && same; ++j) same = rec.q[j][k] == rec.q[j][p] && rec.dq[j][k] == rec.dq[j][p];
      if (same || !(rec.t[k] > rec.t[p])) {
        ++repeats;
        continue;
      }
    }
    rows.push_back(k);
  }
  if (rows.size() < 2) throw std::invalid_argument("fewer than two distinct rows: cannot resample");
  const std::vector<double> tk = pick(rec.t, rows);
  const double typical = median_step(tk);
  if (!(dt > 0.0)) dt = typical;
  // Interpolating across a long gap would invent motion: refuse it (segments are io's job).
  for (std::size_t k = 1; k < tk.size(); ++k) {
    if (tk[k] - tk[k - 1] > std::max(20.0 * typical, 0.05)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "gap of %.3f s after t = %.6f s (typical step %.4f s): split the recording first",
                    tk[k] - tk[k - 1], tk[k - 1], typical);
      throw std::invalid_argument(buf);
    }
  }
  const double t0 = tk.front();
  const auto m = static_cast<std::size_t>(std::floor((tk.back() - t0) / dt + 1e-9)) + 1;
  io::Recording out;
  out.joint_ids = rec.joint_ids;
  out.meta = rec.meta;
  out.meta.sample_time = dt;
  out.t.resize(m);
  // Interpolation index and weight per grid point.
  std::vector<std::size_t> lo(m);
  std::vector<double> frac(m);
  std::size_t a = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const double t = t0 + static_cast<double>(k) * dt;
    out.t[k] = t;
    while (a + 2 < tk.size() && tk[a + 1] <= t) ++a;
    lo[k] = a;
    frac[k] = std::clamp((t - tk[a]) / (tk[a + 1] - tk[a]), 0.0, 1.0);
  }
  const auto interp = [&](const std::vector<double>& x) {
    const std::vector<double> xs = pick(x, rows);
    std::vector<double> y(m);
    for (std::size_t k = 0; k < m; ++k) y[k] = xs[lo[k]] + frac[k] * (xs[lo[k] + 1] - xs[lo[k]]);
    return y;
  };
  const auto each = [&](const std::vector<std::vector<double>>& in, std::vector<std::vector<double>>& o) {
    o.clear();
    for (const auto& x : in) o.push_back(interp(x));
  };
  each(rec.q, out.q);
  each(rec.dq, out.dq);
  each(rec.current, out.current);
  each(rec.tau_m, out.tau_m);
  each(rec.tau_ext, out.tau_ext);
  for (const auto& [name, x] : rec.extra) out.extra[name] = interp(x);
  if (!rec.collision.empty()) {
    const std::vector<std::size_t> rk = rows;
    out.collision.resize(m);
    for (std::size_t k = 0; k < m; ++k) out.collision[k] = rec.collision[rk[lo[k]]];
  }
  if (note) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "resampled by time stamp: %zu repeated rows dropped, linear interpolation onto a %.3f ms grid (%zu samples)",
                  repeats, dt * 1e3, m);
    *note = buf;
  }
  return out;
}

}  // namespace jg::dyn
