#include "eval/calibration_region.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "eval/evaluate.hpp"
#include "eval/experiments.hpp"
#include "jointguard/detection/hold_detector.hpp"

namespace jg::eval {
namespace {
double step_of(const io::Recording& r) {
  return r.samples() > 1 ? (r.t.back() - r.t.front()) / static_cast<double>(r.samples() - 1) : 1.0;
}

/// Cuts every per-sample vector of `r` to [a, b) (sample indices).
io::Recording cut(const io::Recording& r, std::size_t a, std::size_t b) {
  io::Recording o = r;
  const auto span = [a, b](std::vector<double>& v) {
    if (!v.empty()) v = std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(a), v.begin() + static_cast<std::ptrdiff_t>(b));
  };
  span(o.t);
  for (auto* group : {&o.q, &o.dq, &o.current, &o.tau_m, &o.tau_j, &o.tau_ext}) {
    for (auto& v : *group) span(v);
  }
  for (auto& [name, v] : o.extra) span(v);
  if (!o.collision.empty()) {
    o.collision = std::vector<int>(r.collision.begin() + static_cast<std::ptrdiff_t>(a), r.collision.begin() + static_cast<std::ptrdiff_t>(b));
  }
  return o;
}
}  // namespace

std::vector<io::Recording> time_window(const std::vector<io::Recording>& segments, double t_begin, double t_end) {
  std::vector<io::Recording> out;
  for (const auto& r : segments) {
    std::size_t a = 0;
    while (a < r.samples() && r.t[a] < t_begin) ++a;
    std::size_t b = a;
    while (b < r.samples() && r.t[b] <= t_end) ++b;
    if (b - a >= 3) out.push_back(cut(r, a, b));
  }
  if (out.empty()) {
    throw std::invalid_argument("no 3 samples inside the time window " + std::to_string(t_begin) + " .. " + std::to_string(t_end) + " s");
  }
  return out;
}

void cover_region(Thresholds& t, const std::vector<io::Recording>& segments, const robot::RobotModel& model,
                  const std::vector<LuGreParams<double>>& friction, const ObserverGains& gains, double settle_s,
                  const std::string& scalar) {
  const std::size_t n = segments.front().joints();
  t.q_min.assign(n, 1e300);
  t.q_max.assign(n, -1e300);
  t.dq_max.assign(n, 0.0);
  t.ddq_max.assign(n, 0.0);
  t.stop_gain.assign(n, 0.0);
  std::vector<std::vector<double>> mu;
  for (const auto& rec : segments) {
    const double dt = step_of(rec);
    const std::size_t m = accel_baseline(dt);
    for (std::size_t j = 0; j < n; ++j) {
      for (std::size_t k = m; k < rec.samples(); ++k) {
        if (rec.t[k] - rec.t.front() < settle_s) continue;
        t.q_min[j] = std::min(t.q_min[j], rec.q[j][k]);
        t.q_max[j] = std::max(t.q_max[j], rec.q[j][k]);
        t.dq_max[j] = std::max(t.dq_max[j], std::fabs(rec.dq[j][k]));
        t.ddq_max[j] = std::max(t.ddq_max[j], accel_at(rec, j, k, m, dt));
      }
    }
  }
  for (const auto& rec : segments) {
    if (rec.t.back() - rec.t.front() < settle_s) continue;
    const double dt = step_of(rec);
    const auto d = observer_disturbance(rec, model, gains, true, friction, scalar);
    const std::size_t m = accel_baseline(dt);
    for (std::size_t j = 0; j < n; ++j) {
      for (std::size_t k = m; k < rec.samples(); ++k) {
        if (rec.t[k] - rec.t.front() < settle_s) continue;
        const double accel = accel_at(rec, j, k, m, dt);
        if (accel > 0.0 && accel >= 0.5 * t.ddq_max[j]) t.stop_gain[j] = std::max(t.stop_gain[j], std::fabs(d[j][k]) / accel);
      }
    }
  }
  for (std::size_t j = 0; j < n; ++j) {
    if (t.q_min[j] > t.q_max[j]) t.q_min[j] = t.q_max[j] = 0.0;  // nothing after settling (refused upstream)
  }
}

void calibrate_holds(Thresholds& t, const std::vector<io::Recording>& segments, const robot::RobotModel& model,
                     const std::vector<LuGreParams<double>>& friction, const ObserverGains& gains, const ReplayOptions& o,
                     double settle_s, bool required, const std::string& scalar) {
  const std::size_t n = segments.front().joints();
  t.hold_band.assign(n, 0.0);
  t.hold_seconds.assign(n, 0.0);
  for (const auto& rec : segments) {
    if (rec.t.back() - rec.t.front() < settle_s) continue;
    const double dt = step_of(rec);
    const auto held = holding_flags(rec, o);
    const auto d = observer_disturbance(rec, model, gains, true, friction, scalar, held, o.held_deadband_steps);
    // A threshold never reached: the detector arms and takes its reference as in replay.
    const HoldChangeParams<double> p = hold_params(1e9, t.hold_settle_s, t.hold_reference_s, dt);
    std::vector<HoldChangeState<double>> s(n);
    for (std::size_t k = 0; k < rec.samples(); ++k) {
      const bool h = held[k] && rec.t[k] - rec.t.front() >= settle_s;
      for (std::size_t j = 0; j < n; ++j) {
        const double mu = -d[j][k];
        (void)hold_change_step(p, s[j], h, mu);
        if (s[j].armed) {
          t.hold_band[j] = std::max(t.hold_band[j], hold_deviation(s[j], mu));
          t.hold_seconds[j] += dt;
        }
      }
    }
  }
  if (required && *std::max_element(t.hold_seconds.begin(), t.hold_seconds.end()) <= 0.0) {
    throw std::invalid_argument("calibration: the recording never holds long enough to arm the holding detector (" +
                                std::to_string(t.hold_settle_s + t.hold_reference_s) + " s at rest after the observer's " +
                                std::to_string(settle_s) + " s)");
  }
  t.hold_change.assign(n, 0.0);
  t.hold_source.assign(n, "holds");
  for (std::size_t j = 0; j < n; ++j) {
    if (required || t.hold_seconds[j] >= kHoldMinArmedS) {
      t.hold_change[j] = kHoldFactor * t.hold_band[j] + kHoldMargin;
    } else {
      // Too little held time to measure how far a collision-free hold moves: the part of
      // the friction level a held joint's friction relaxes by.
      t.hold_change[j] = kHoldFrictionFraction * friction_level(friction[j]);
      t.hold_source[j] = "friction";
    }
  }
}

}  // namespace jg::eval
