#include "diagnosis/effects.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>
#include <sstream>
#include <stdexcept>

#include "identification/lugre_batch.hpp"

namespace jg::diag {
namespace {
// Velocity sign with a small linear band so that noise around zero does not toggle it.
double soft_sign(double w, double band) { return std::fabs(w) >= band ? (w > 0.0 ? 1.0 : -1.0) : w / band; }

double velocity_band(const JointSignals& s) {
  double vmax = 0.0;
  for (const double w : s.dq) vmax = std::max(vmax, std::fabs(w));
  return std::max(1e-4, 0.005 * vmax);
}

std::vector<double> column(std::size_t n) { return std::vector<double>(n, 0.0); }

/// (x(t) - x(t - d)) / d on uniform samples, x between samples linear, held at the ends (before
/// the first sample, after the last); d != 0 [s], < 0 for a lead.
std::vector<double> delayed_difference(const std::vector<double>& x, double dt, double d) {
  std::vector<double> out(x.size(), 0.0);
  if (x.empty()) return out;
  const double last = static_cast<double>(x.size() - 1);
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double at = std::clamp(static_cast<double>(k) - d / dt, 0.0, last);
    const auto i = static_cast<std::size_t>(std::floor(at));
    const double frac = at - static_cast<double>(i);
    const double shifted = i + 1 < x.size() ? x[i] + frac * (x[i + 1] - x[i]) : x[i];
    out[k] = (x[k] - shifted) / d;
  }
  return out;
}

/// Slope of a local linear fit over +/-half_window_s (uniform dt): a derivative with far
/// less noise than derivative()'s +/-10 ms, for signals much slower than the window.
std::vector<double> slow_derivative(const std::vector<double>& x, double dt, double half_window_s) {
  const auto h = static_cast<std::size_t>(std::max(2.0, std::round(half_window_s / dt)));
  return x.size() < 2 * h + 1 ? derivative(x, dt) : derivative(x, dt, half_window_s);
}

/// Change of the nominal LuGre friction over the recorded velocity when one parameter is
/// changed (per unit of the change for `per_unit`).
std::vector<double> lugre_change(const JointSignals& s, const std::function<void(LuGreParams<double>&)>& change,
                                 double per_unit) {
  LuGreParams<double> p = *s.friction;
  change(p);
  const auto f0 = ident::lugre_predict(*s.friction, s.dq, s.dt);
  const auto f1 = ident::lugre_predict(p, s.dq, s.dt);
  std::vector<double> d(f0.size());
  for (std::size_t k = 0; k < d.size(); ++k) d[k] = (f1[k] - f0[k]) / per_unit;
  return d;
}

/// The model's torque without a recording's noise, for the saturating torque constant's
/// columns: with a rigid-body model and the nominal friction, their prediction over the real
/// motion (what signals_from_model calls the model's torque); otherwise the model's torque as
/// given. A simulated recording's torque carries that recording's own noise (its current
/// noise; and the correction for the two runs' motions evaluates the friction model on the
/// simulated run's velocity too); in tau |tau| the noise is multiplied by the torque itself,
/// and on the waist (10 N·m of mostly friction) the noisy column lost to a viscous change.
std::vector<double> noise_free_model_torque(const JointSignals& s) {
  if (s.load.size() != s.size() || !s.friction) return s.tau_model;
  auto tau = ident::lugre_predict(*s.friction, s.dq, s.dt);
  for (std::size_t k = 0; k < tau.size(); ++k) tau[k] += s.load[k];
  return tau;
}

JointSignals at_rest_at_start(const JointSignals& s) {
  // Long enough for every filter window (slow_derivative's +/-30 ms) to see a constant.
  constexpr std::size_t kRest = 256;
  JointSignals r;
  r.joint = s.joint;
  r.dt = s.dt;
  r.t.resize(kRest);
  for (std::size_t k = 0; k < kRest; ++k) r.t[k] = s.t.front() + static_cast<double>(k) * s.dt;
  r.q.assign(kRest, s.q.front());
  r.dq.assign(kRest, 0.0);
  r.ddq.assign(kRest, 0.0);
  r.tau_real.assign(kRest, 0.0);
  // The model's torque at rest: friction relaxed (LuGre bristles z = 0 at zero velocity).
  r.tau_model.assign(kRest, 0.0);
  if (!s.load.empty()) r.load.assign(kRest, s.load.front());
  r.residual.assign(kRest, 0.0);
  for (const auto& col : s.payload_columns) r.payload_columns.emplace_back(kRest, col.front());
  if (!s.velocity_mismatch.empty()) r.velocity_mismatch.assign(kRest, 0.0);
  if (!s.deflection.empty()) r.deflection.assign(kRest, s.deflection.front());
  r.friction = s.friction;
  return r;
}

/// Dahl's hyperbolic presliding law (du/ds = -u²/delta, u = 1 - sgn(w) zeta): the state
/// after travelling |dx| towards `dir` (the plant's FrictionEffects::dahl_exponent = 2).
double hyperbolic_dahl_step(double zeta, double dir, double dx_abs, double delta) {
  const double u = 1.0 - dir * zeta;
  return dir * (1.0 - u / (1.0 + u * dx_abs / delta));
}

/// One direction's friction curve changed alone (side +1: w > 0, -1: w < 0): the nominal
/// LuGre curve's Coulomb level and its static level, each raised on that side only (per N·m).
Candidate one_sided_levels(const JointSignals& s, double side) {
  Candidate c;
  c.effect = robot::Effect::asymmetric_friction;
  c.setting = {{"side", side}};
  c.nonlinear_params = 0;  // two instances (one per side), like the model-curve instances
  if (!s.friction) return c;
  const double eps_c = 0.01 * std::max(s.friction->tau_c, 1e-3), eps_s = 0.01 * std::max(std::fabs(s.friction->tau_s), 1e-3);
  auto dc = lugre_change(s, [eps_c](LuGreParams<double>& p) { p.tau_c += eps_c; }, eps_c);
  auto ds = lugre_change(s, [eps_s](LuGreParams<double>& p) { p.tau_s += eps_s; }, eps_s);
  for (std::size_t k = 0; k < dc.size(); ++k) {
    if (!(s.dq[k] * side > 0.0)) dc[k] = ds[k] = 0.0;
  }
  c.columns = {std::move(dc), std::move(ds)};
  return c;
}

// The effect's columns as computed from the signals, without the start offset.
Candidate raw_candidate(robot::Effect effect, const std::map<std::string, double>& setting,
                        const JointSignals& s) {
  const std::size_t n = s.size();
  const double band = velocity_band(s);
  auto sgn = [&](std::size_t k) { return soft_sign(s.dq[k], band); };
  auto get = [&](const char* key) {
    const auto it = setting.find(key);
    if (it == setting.end()) throw std::invalid_argument("effect '" + effect + "' needs setting '" + key + "'");
    return it->second;
  };
  Candidate c;
  c.effect = effect;
  c.setting = setting;
  c.nonlinear_params = static_cast<int>(setting.size());
  auto col = column(n);
  if (setting.count("rotor_acceleration") != 0U) {
    // Elastic gear or backlash seen in the torque: the rotor's acceleration relative to
    // the link, the second derivative of the measured deflection (coefficient: J_rotor).
    if (s.deflection.size() != n) return c;
    c.nonlinear_params = 0;
    c.columns.push_back(derivative(derivative(s.deflection, s.dt), s.dt));
    return c;
  }
  if (effect == robot::Effect::coulomb && setting.count("model_curve") != 0U) {
    // The model's Coulomb level raised alone: its static level and Stribeck curve kept.
    if (!s.friction) return c;
    c.nonlinear_params = 0;
    const double eps = 0.01 * std::max(s.friction->tau_c, 1e-3);
    col = lugre_change(s, [eps](LuGreParams<double>& p) { p.tau_c += eps; }, eps);
  } else if (effect == robot::Effect::stribeck && setting.count("model_curve") != 0U) {
    // The model's static (breakaway) level raised alone: its Coulomb level, Stribeck
    // velocity and bristles kept.
    if (!s.friction) return c;
    c.nonlinear_params = 0;
    const double eps = 0.01 * std::max(std::fabs(s.friction->tau_s), 1e-3);
    col = lugre_change(s, [eps](LuGreParams<double>& p) { p.tau_s += eps; }, eps);
  } else if (effect == robot::Effect::presliding && setting.count("sigma0_ratio") != 0U) {
    // The model's bristles softer by this ratio: a longer presliding regime after reversals.
    if (!s.friction) return c;
    const double ratio = get("sigma0_ratio");
    col = lugre_change(s, [ratio](LuGreParams<double>& p) { p.sigma0 *= ratio; }, 1.0);
  } else if (effect == robot::Effect::coulomb) {
    for (std::size_t k = 0; k < n; ++k) col[k] = sgn(k);
  } else if (effect == robot::Effect::viscous) {
    col = s.dq;
  } else if (effect == robot::Effect::stribeck) {
    const double ws = get("w_s");
    for (std::size_t k = 0; k < n; ++k) col[k] = sgn(k) * std::exp(-(s.dq[k] / ws) * (s.dq[k] / ws));
  } else if (effect == robot::Effect::presliding) {
    // The bristles' smooth transition after a reversal: a Dahl state with characteristic
    // displacement delta, minus the sign it tends to. Its law: exponential (Dahl's
    // exponent 1, the default) or hyperbolic (`law` 2: a sharper onset, a longer tail).
    const double delta = get("displacement_rad");
    const bool hyperbolic = setting.count("law") != 0U && setting.at("law") == 2.0;
    if (hyperbolic) c.nonlinear_params = 1;  // the law is a structure choice, like model_curve
    double zeta = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const double dx = s.dq[k] * s.dt;
      const double dir = dx > 0.0 ? 1.0 : (dx < 0.0 ? -1.0 : 0.0);
      if (dir != 0.0) {
        zeta = hyperbolic ? hyperbolic_dahl_step(zeta, dir, std::fabs(dx), delta)
                          : dir + (zeta - dir) * std::exp(-std::fabs(dx) / delta);
      }
      col[k] = zeta - sgn(k);
    }
  } else if (effect == robot::Effect::asymmetric_friction && setting.count("side") != 0U) {
    return one_sided_levels(s, get("side"));
  } else if (effect == robot::Effect::asymmetric_friction) {
    // Friction levels that differ by direction: a Coulomb level (|sgn w|, constant while
    // moving, zero at rest: that tells it from an offset) and a viscous slope (|w|: the
    // difference grows with speed) of their own in each direction.
    auto slope = column(n);
    for (std::size_t k = 0; k < n; ++k) {
      col[k] = std::fabs(sgn(k));
      slope[k] = std::fabs(s.dq[k]);
    }
    c.columns = {std::move(col), std::move(slope)};
    return c;
  } else if (effect == robot::Effect::position_ripple) {
    const double per_rev = get("periods_per_rev");
    auto cs = column(n);
    for (std::size_t k = 0; k < n; ++k) {
      col[k] = std::sin(per_rev * s.q[k]);
      cs[k] = std::cos(per_rev * s.q[k]);
    }
    c.columns = {std::move(col), std::move(cs)};
    return c;
  } else if (effect == robot::Effect::temperature_drift) {
    const double tc = get("time_constant_s");
    for (std::size_t k = 0; k < n; ++k) col[k] = sgn(k) * (1.0 - std::exp(-(s.t[k] - s.t.front()) / tc));
  } else if (effect == robot::Effect::load_dependent_friction) {
    // Gear-tooth friction grows with the torque the gear transmits: the rigid-body torque.
    // With `power_flow`, one coefficient where the motor drives the load (power from the
    // motor to the link, w load > 0) and one where the load back-drives the gear: a
    // gear's efficiency differs with the direction of the power through it.
    if (s.load.empty()) return c;
    for (std::size_t k = 0; k < n; ++k) col[k] = sgn(k) * std::fabs(s.load[k]);
    if (setting.count("power_flow") != 0U) {
      c.nonlinear_params = 0;
      auto back = column(n);
      for (std::size_t k = 0; k < n; ++k) {
        if (s.dq[k] * s.load[k] < 0.0) std::swap(col[k], back[k]);
      }
      c.columns = {std::move(col), std::move(back)};
      return c;
    }
  } else if (effect == robot::Effect::payload) {
    // Mass and first moment along the link: what a payload at the tool changes most.
    // (The other first moments are rarely excited enough to be told apart.)
    if (s.payload_columns.size() < 2) return c;
    c.columns = {s.payload_columns[0], s.payload_columns[1]};
    return c;
  } else if (effect == robot::Effect::inertia_error) {
    // The acceleration from the motor-encoder velocity over +/-30 ms: an inertia error
    // acts on the motion's acceleration, and a regressor carrying the differentiation
    // noise would fit it with a bias and a worse likelihood than shapes of the (nearly
    // noise-free) position.
    col = slow_derivative(s.dq, s.dt, 0.03);
  } else if (effect == robot::Effect::torque_constant) {
    // A scale error of current to torque scales the whole modelled torque. The model's
    // torque, not the measured one, is the regressor: the prediction must never use the
    // signal it predicts.
    // The plain scale keeps the model's torque as given: its noise enters linearly.
    const bool saturating = setting.count("saturation") != 0U;
    const std::vector<double> tau_model = saturating ? noise_free_model_torque(s) : s.tau_model;
    col = tau_model;
    if (saturating) {
      // A constant that falls with the current (magnetic saturation): K (1 + e - c' |i|).
      // Measured over true torque 1 + e + c |tau|, c per N·m: the second column.
      c.nonlinear_params = 0;
      auto sat = column(n);
      for (std::size_t k = 0; k < n; ++k) sat[k] = tau_model[k] * std::fabs(tau_model[k]);
      c.columns = {std::move(col), std::move(sat)};
      return c;
    }
  } else if (effect == robot::Effect::current_offset) {
    col.assign(n, 1.0);
  } else if (effect == robot::Effect::time_delay) {
    // First order: the torque rate (tau(t - d) - tau(t) ~ -d dtau/dt). With a delay_s setting
    // (a claimed delay refined: refine_settings), the exact difference over it, which the first
    // order approximates: its coefficient is minus the delay at any size.
    const double d = setting.count("delay_s") != 0U ? setting.at("delay_s") : 0.0;
    col = std::fabs(d) > 0.25 * s.dt ? delayed_difference(s.tau_model, s.dt, d) : derivative(s.tau_model, s.dt);
  } else if (effect == robot::Effect::backlash) {
    // After a reversal the link is not driven until the motor has crossed the gap.
    if (s.load.empty()) return c;
    const double gap = get("gap_rad");
    double travelled = 1e9, last_dir = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const double dir = s.dq[k] > band ? 1.0 : (s.dq[k] < -band ? -1.0 : last_dir);
      if (dir != last_dir && last_dir != 0.0) travelled = 0.0;
      last_dir = dir;
      travelled += std::fabs(s.dq[k]) * s.dt;
      col[k] = travelled < gap ? -s.load[k] : 0.0;
    }
  } else {
    throw std::invalid_argument("unknown effect '" + effect + "'");
  }
  c.columns.push_back(std::move(col));
  return c;
}

/// Whether the effect's columns are a function of one sample's own position and velocity (a
/// drift's, of its time too).
bool of_the_sample_alone(robot::Effect effect, const std::map<std::string, double>& setting) {
  const bool model_curve = setting.count("model_curve") != 0U;
  return ((effect == robot::Effect::coulomb || effect == robot::Effect::stribeck) && !model_curve) ||
         (effect == robot::Effect::asymmetric_friction && setting.count("side") == 0U) || effect == robot::Effect::position_ripple ||
         effect == robot::Effect::temperature_drift;
}

/// Whether the rows the samples were resampled from span them, in time order.
bool rows_span_the_samples(const JointSignals& s) {
  const std::size_t m = s.rows_t.size();
  if (m < 2 || s.rows_q.size() != m || s.rows_dq.size() != m || s.t.empty()) return false;
  for (std::size_t i = 1; i < m; ++i) {
    if (!(s.rows_t[i] > s.rows_t[i - 1])) return false;
  }
  for (std::size_t k = 1; k < s.t.size(); ++k) {
    if (s.t[k] < s.t[k - 1]) return false;
  }
  const double slack = 1e-6 * s.dt;
  return s.rows_t.front() <= s.t.front() + slack && s.rows_t.back() >= s.t.back() - slack;
}

/// The columns of an effect of one sample's own state computed at the rows the samples were
/// resampled from, then interpolated at the samples' times as the torque was: a sharp function
/// of the velocity (a Stribeck excess at w_s 0.05 rad/s) differs from itself over the
/// interpolated velocity on a recording sampled off the grid (the UR10e's 10-12 ms steps:
/// 0.87x its injected size at its own w_s, 0.95x on a uniform copy of the same rows).
Candidate at_rows_interpolated(robot::Effect effect, const std::map<std::string, double>& setting, const JointSignals& s) {
  // The rows that span the samples (a slice of a recording keeps all of its rows): a drift
  // counts from the first of them, at most a row before the first sample.
  const double slack = 1e-6 * s.dt;
  const auto first = std::upper_bound(s.rows_t.begin(), s.rows_t.end(), s.t.front() + slack) - s.rows_t.begin() - 1;
  const auto last = std::lower_bound(s.rows_t.begin(), s.rows_t.end(), s.t.back() - slack) - s.rows_t.begin();
  auto b = static_cast<std::size_t>(std::max<std::ptrdiff_t>(first, 0));
  const auto e = std::max(std::min(static_cast<std::size_t>(last) + 1, s.rows_t.size()), std::size_t{2});
  b = std::min(b, e - 2);  // two rows at least, to interpolate between
  const auto span = [&](const std::vector<double>& v) {
    return std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(b), v.begin() + static_cast<std::ptrdiff_t>(e));
  };
  JointSignals rows;
  rows.joint = s.joint;
  rows.dt = s.dt;
  rows.t = span(s.rows_t);
  rows.q = span(s.rows_q);
  rows.dq = span(s.rows_dq);
  Candidate c = raw_candidate(effect, setting, rows);
  for (auto& col : c.columns) {
    std::vector<double> out(s.size());
    std::size_t i = 0;
    for (std::size_t k = 0; k < s.size(); ++k) {
      while (i + 2 < rows.t.size() && rows.t[i + 1] <= s.t[k]) ++i;
      const double a = std::clamp((s.t[k] - rows.t[i]) / (rows.t[i + 1] - rows.t[i]), 0.0, 1.0);
      out[k] = col[i] + a * (col[i + 1] - col[i]);
    }
    col = std::move(out);
  }
  return c;
}

/// raw_candidate, at the rows resampled from where the effect is of one sample's state.
Candidate sampled_candidate(robot::Effect effect, const std::map<std::string, double>& setting, const JointSignals& s) {
  return of_the_sample_alone(effect, setting) && rows_span_the_samples(s) ? at_rows_interpolated(effect, setting, s)
                                                                          : raw_candidate(effect, setting, s);
}

}  // namespace

Candidate make_candidate(robot::Effect effect, const std::map<std::string, double>& setting,
                         const JointSignals& s) {
  if (s.offset_at_start) {
    // The data are f(t) - f(t0): so is every column, f(t0) taken with the arm at rest at
    // its first position with the friction relaxed. The friction state the arm really
    // held at t0 is unknown and differs from one recording to the next: a constant
    // (current_offset, kept as it is) stands for it, a property of the recording only.
    Candidate c = sampled_candidate(effect, setting, s);
    if (effect == robot::Effect::current_offset || c.columns.empty()) return c;
    const Candidate rest = raw_candidate(effect, setting, at_rest_at_start(s));
    if (rest.columns.size() != c.columns.size()) return c;
    for (std::size_t j = 0; j < c.columns.size(); ++j) {
      const double ref = rest.columns[j].back();
      for (double& v : c.columns[j]) v -= ref;
    }
    return c;
  }
  return sampled_candidate(effect, setting, s);
}

namespace {
// The grids the selection offers a continuous setting on: coarse (steps of 1.5-3x), for the
// selection's sake; a Stribeck velocity, whose size trades against it, is refined between its
// neighbours once chosen (refinable_setting).
const std::vector<double>& stribeck_w_s_grid() {
  static const std::vector<double> g{0.003, 0.006, 0.01, 0.02, 0.04, 0.07, 0.1, 0.15, 0.25, 0.4};
  return g;
}
const std::vector<double>& presliding_displacement_grid() {
  static const std::vector<double> g{2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2};
  return g;
}
std::vector<double> drift_time_constant_grid(const JointSignals& s) {
  const double span = s.t.back() - s.t.front();
  return {0.1 * span, 0.25 * span, 0.5 * span, span, 3.0 * span};
}

/// The neighbours of `v` on `grid` (sorted), or v / 2 and 2 v beyond its ends.
std::pair<double, double> grid_neighbours(const std::vector<double>& grid, double v) {
  const auto above = std::upper_bound(grid.begin(), grid.end(), v * (1.0 + 1e-9));
  const auto at_or_below = std::lower_bound(grid.begin(), grid.end(), v * (1.0 - 1e-9));
  const double lo = at_or_below == grid.begin() ? 0.5 * v : *(at_or_below - 1);
  const double hi = above == grid.end() ? 2.0 * v : *above;
  return {lo, hi};
}
}  // namespace

std::optional<SettingBracket> refinable_setting(const Candidate& c, const std::vector<double>& coefficients, double dt) {
  const auto has = [&](const char* key) { return c.setting.count(key) != 0U; };
  if (c.effect == robot::Effect::stribeck && has("w_s") && !has("model_curve")) {
    const auto [lo, hi] = grid_neighbours(stribeck_w_s_grid(), c.setting.at("w_s"));
    return SettingBracket{"w_s", lo, hi, 1.0};
  }
  if (c.effect == robot::Effect::time_delay && !has("delay_s") && !coefficients.empty()) {
    // The first-order column reads a long delay short (47.5 ms injected into the UR10e's
    // currents at 100 Hz read 15-36 ms): the exact difference is searched from the first
    // order's size to 4 times it, up to three times the plausible 50 ms (implausible()), so
    // that a delay beyond it reads beyond it (and is not claimed) instead of at the edge.
    const double first_order = -coefficients[0];
    const double lo = std::max(0.5 * std::fabs(first_order), 0.5 * dt), hi = std::min(4.0 * std::fabs(first_order), 0.15);
    if (!(hi > lo)) return std::nullopt;
    return SettingBracket{"delay_s", lo, hi, first_order > 0.0 ? 1.0 : -1.0};
  }
  // Not a presliding displacement: its level is not what a user compares, and refined it
  // moved what the loop's next pass finds on the untouched UR10e recording (an inertia error on
  // joint 6 beside a presliding refined from 5e-5 to 1e-4 rad).
  // Not a drift's time constant either: its level trades against it both ways, and refined, an
  // injected drift's level on the UR10e's joint 3 came out 1.34x the injected one (0.93x at the
  // grid's).
  return std::nullopt;
}

std::vector<std::vector<Candidate>> build_candidates(const JointSignals& s) {
  std::vector<std::vector<Candidate>> all;
  auto group = [&](robot::Effect effect, const char* key, const std::vector<double>& grid) {
    std::vector<Candidate> g;
    if (key == nullptr) {
      g.push_back(make_candidate(effect, {}, s));
    } else {
      for (const double v : grid) g.push_back(make_candidate(effect, {{key, v}}, s));
    }
    // An empty grid (no ripple period fits the recorded range: a held arm) offers nothing.
    if (!g.empty() && !g.front().columns.empty()) all.push_back(std::move(g));
  };
  // With the nominal friction model, friction effects are also its parameters' changes:
  // further instances of the same group (they compete with the generic shapes by BIC).
  auto model_instances = [&](robot::Effect effect, const char* key, const std::vector<double>& grid) {
    if (!s.friction) return;
    auto it = std::find_if(all.begin(), all.end(), [&](const std::vector<Candidate>& g) { return g.front().effect == effect; });
    if (it == all.end()) return;
    for (const double v : grid) {
      Candidate c = make_candidate(effect, {{key, v}}, s);
      if (!c.columns.empty()) it->push_back(std::move(c));
    }
  };
  // Richer shapes of the same cause: further instances of its group (same name, chosen
  // over the plain shape by the same criterion).
  auto richer = [&](robot::Effect effect, const std::map<std::string, double>& setting) {
    auto it = std::find_if(all.begin(), all.end(), [&](const std::vector<Candidate>& g) { return g.front().effect == effect; });
    if (it == all.end()) return;
    Candidate c = make_candidate(effect, setting, s);
    if (!c.columns.empty()) it->push_back(std::move(c));
  };
  group(robot::Effect::coulomb, nullptr, {});
  group(robot::Effect::viscous, nullptr, {});
  group(robot::Effect::stribeck, "w_s", stribeck_w_s_grid());
  group(robot::Effect::presliding, "displacement_rad", presliding_displacement_grid());
  model_instances(robot::Effect::coulomb, "model_curve", {1.0});
  model_instances(robot::Effect::stribeck, "model_curve", {1.0});
  model_instances(robot::Effect::presliding, "sigma0_ratio", {0.5, 0.3, 0.2, 0.1, 0.05, 0.02});
  for (const double d : presliding_displacement_grid()) richer(robot::Effect::presliding, {{"displacement_rad", d}, {"law", 2.0}});
  group(robot::Effect::asymmetric_friction, nullptr, {});
  richer(robot::Effect::asymmetric_friction, {{"side", 1.0}});
  richer(robot::Effect::asymmetric_friction, {{"side", -1.0}});
  // Once per turn, a ripple cannot be told from a gravity-model error on one joint; with
  // a rigid-body model at hand that is the payload effect's job, so ripple starts at 2.
  // Nor can a ripple of which the motion covers less than 1.5 periods: over that range a
  // sine is just a smooth function of the position, as the gravity torque of a payload
  // is. With a rigid-body model, a ripple must show at least 1.5 periods over the
  // recorded range of position.
  std::vector<double> per_rev;
  const auto [q_lo, q_hi] = std::minmax_element(s.q.begin(), s.q.end());
  const double q_range = s.q.empty() ? 0.0 : *q_hi - *q_lo;
  const int k_min = s.payload_columns.empty()
                        ? 1
                        : std::max(2, static_cast<int>(std::ceil(1.5 * 2.0 * M_PI / std::max(q_range, 1e-6))));
  for (int k = k_min; k <= 200; ++k) per_rev.push_back(k);
  group(robot::Effect::position_ripple, "periods_per_rev", per_rev);
  group(robot::Effect::temperature_drift, "time_constant_s", drift_time_constant_grid(s));
  group(robot::Effect::load_dependent_friction, nullptr, {});
  richer(robot::Effect::load_dependent_friction, {{"power_flow", 1.0}});
  if (!s.arm_level_fitted) group(robot::Effect::payload, nullptr, {});  // else fitted once for the arm (arm.hpp)
  group(robot::Effect::inertia_error, nullptr, {});
  if (!s.joint_torque_sensor) {
    group(robot::Effect::torque_constant, nullptr, {});
    richer(robot::Effect::torque_constant, {{"saturation", 1.0}});
  }
  group(robot::Effect::current_offset, nullptr, {});
  group(robot::Effect::time_delay, nullptr, {});
  // Backlash from the torque alone (the load not driven after velocity reversals) only when
  // there is no gear-deflection channel: with motor and link encoders, backlash is judged
  // on the deflection itself (diagnose.cpp), far more directly.
  if (s.deflection.size() != s.size()) group(robot::Effect::backlash, "gap_rad", {0.0005, 0.001, 0.002, 0.004, 0.008, 0.016});
  return all;
}

namespace {
/// The largest torque an effect's coefficients `b` stand for (a level, a ripple's amplitude, a
/// viscous slope at the largest speed `w_max`), 0 for an effect without one.
double level_of(const Candidate& c, const std::vector<double>& b, double w_max) {
  const robot::Effect e = c.effect;
  const bool model_curve = c.setting.count("model_curve") != 0U;
  const bool one_sided = e == robot::Effect::asymmetric_friction && c.setting.count("side") != 0U;
  return e == robot::Effect::position_ripple && b.size() > 1 ? std::hypot(b[0], b[1])
                          : one_sided && b.size() > 1 ? std::max(std::fabs(b[0]), std::fabs(b[1]))
                          : e == robot::Effect::asymmetric_friction
                              ? std::max(std::fabs(2.0 * b[0]), b.size() > 1 ? std::fabs(2.0 * b[1]) * w_max : 0.0)
                          : e == robot::Effect::viscous ? std::fabs(b[0]) * w_max
                          : e == robot::Effect::coulomb || e == robot::Effect::current_offset || e == robot::Effect::temperature_drift ||
                                    (e == robot::Effect::stribeck && !model_curve)
                              ? std::fabs(b[0])
                              : 0.0;
}

/// implausible()'s reason; `beyond` set when it is a size beyond the plausible range.
std::string implausible_why(const Candidate& c, const std::vector<double>& b, const JointSignals& s, bool& beyond) {
  if (b.empty()) return {};
  std::ostringstream os;
  os.precision(3);
  const robot::Effect e = c.effect;
  const bool model_curve = c.setting.count("model_curve") != 0U;
  const bool one_sided = e == robot::Effect::asymmetric_friction && c.setting.count("side") != 0U;
  const double span = s.t.empty() ? 0.0 : s.t.back() - s.t.front();
  // No effect's torque can exceed everything the joint measured: the drive saw it.
  double tau_max = 0.0;
  for (const double v : s.tau_real) tau_max = std::max(tau_max, std::fabs(v));
  double w_max = 0.0;
  for (const double w : s.dq) w_max = std::max(w_max, std::fabs(w));
  if (const double level = level_of(c, b, w_max); tau_max > 0.0 && level > tau_max) {
    beyond = true;
    os << e << " of " << level << " N·m exceeds the largest torque the joint measured (" << tau_max << " N·m)";
    return os.str();
  }
  // Friction levels stay non-negative: the model's level (0 without a friction model) plus
  // the change.
  if (e == robot::Effect::coulomb) {
    const double level = (s.friction ? s.friction->tau_c : 0.0) + b[0];
    if (level < 0.0) os << "Coulomb level would be negative (" << level << " N·m)";
  } else if (e == robot::Effect::viscous) {
    const double level = (s.friction ? s.friction->sigma2 : 0.0) + b[0];
    if (level < 0.0) os << "viscous coefficient would be negative (" << level << " N·m·s/rad)";
  } else if (e == robot::Effect::stribeck) {
    const double level = model_curve ? (s.friction ? s.friction->tau_s : 0.0) + b[0] : b[0];
    if (level < 0.0) os << "static friction excess would be negative (" << level << " N·m)";
  } else if (e == robot::Effect::temperature_drift) {
    // A thermal time constant between the sample time (x50) and three times the recording.
    const double tc = c.setting.at("time_constant_s");
    if (tc < std::max(50.0 * s.dt, 1.0) || tc > 3.0 * span) os << "drift time constant " << tc << " s outside [max(50 dt, 1 s), 3 x recording]";
  } else if (one_sided && b.size() > 1) {
    const double side = c.setting.at("side");
    const double tc = (s.friction ? s.friction->tau_c : 0.0) + b[0], ts = (s.friction ? s.friction->tau_s : 0.0) + b[1];
    if (tc < 0.0 || ts < 0.0) os << (side > 0.0 ? "positive" : "negative") << "-direction friction level would be negative (Coulomb " << tc << ", static " << ts << " N·m)";
  } else if (e == robot::Effect::load_dependent_friction) {
    for (const double mu : b) {
      if (mu < 0.0 || mu > 0.5) {
        beyond = mu > 0.5;
        os << "load coefficient " << mu << " outside [0, 0.5] N·m per N·m";
        break;
      }
    }
  } else if (e == robot::Effect::torque_constant) {
    // A drive's current-to-torque constant is known to +/-30 % (datasheet tolerance plus
    // magnet temperature); beyond that the drive or the model is wrong, not the constant.
    // Saturation only lowers it as the current grows, to at most 30 % off at the largest
    // torque measured.
    beyond = std::fabs(b[0]) > 0.3 || (b.size() > 1 && b[1] >= 0.0 && std::fabs(b[0]) + b[1] * tau_max > 0.3);
    if (std::fabs(b[0]) > 0.3) os << "torque constant error " << 100.0 * b[0] << " % beyond +/-30 %";
    else if (b.size() > 1 && b[1] < 0.0) os << "torque constant rising with the current (saturation " << b[1] << " per N·m < 0)";
    else if (b.size() > 1 && std::fabs(b[0]) + b[1] * tau_max > 0.3) os << "torque constant " << 100.0 * (std::fabs(b[0]) + b[1] * tau_max) << " % off at the largest torque, beyond 30 %";
  } else if (e == robot::Effect::time_delay) {
    // Short, either way: the torque lags the motion (a current channel filtered or sampled
    // late) or leads it (motion signals older than the torque's: a filtered velocity, or a
    // logger that reads the arm's state and its torques at different times; the Panda's
    // recording repeats q and dq in 107 rows where the torques change) by half a sample to 50 ms.
    const double delay = -b[0];
    beyond = std::fabs(delay) > 0.05;
    if (std::fabs(delay) < 0.5 * s.dt || std::fabs(delay) > 0.05) os << "delay " << 1000.0 * delay << " ms outside +/-[dt/2, 50 ms]";
  } else if (e == robot::Effect::backlash) {
    beyond = b[0] > 1.5;
    if (b[0] < 0.0 || b[0] > 1.5) os << "backlash fraction " << b[0] << " outside [0, 1.5]";
  } else if (e == robot::Effect::presliding && c.setting.count("sigma0_ratio") != 0U) {
    const double ratio = c.setting.at("sigma0_ratio") * b[0] + (1.0 - b[0]);
    if (!(ratio > 0.0)) os << "bristle stiffness ratio " << ratio << " not positive";
  } else if (e == robot::Effect::payload && b.size() >= 2) {
    if (!(b[0] > 0.0)) os << "payload mass " << b[0] << " kg not positive";
    else if (std::fabs(b[1] / b[0]) > 0.5) os << "payload centre of mass " << b[1] / b[0] << " m from the last link's origin";
  }
  return os.str();
}
}  // namespace

std::string implausible(const Candidate& c, const std::vector<double>& b, const JointSignals& s, bool* beyond_size) {
  bool beyond = false;
  std::string why = implausible_why(c, b, s, beyond);
  if (beyond_size != nullptr) *beyond_size = !why.empty() && beyond;
  return why;
}

std::map<std::string, double> describe(const Candidate& c, const std::vector<double>& b, const JointSignals& s,
                                       std::string& text) {
  std::ostringstream os;
  os.precision(3);
  std::map<std::string, double> p;
  const robot::Effect e = c.effect;
  if (e == robot::Effect::coulomb) {
    p["delta_tau_c"] = b[0];
    os << "Coulomb friction level off by " << b[0] << " N·m";
  } else if (e == robot::Effect::viscous) {
    p["delta_sigma2"] = b[0];
    os << "viscous friction off by " << b[0] << " N·m·s/rad";
  } else if (e == robot::Effect::stribeck && c.setting.count("model_curve") != 0U) {
    p["delta_tau_s"] = b[0];
    if (s.friction) p["w_s"] = s.friction->w_s;
    os << "Stribeck effect off: static (breakaway) friction level " << b[0] << " N·m above the model's";
  } else if (e == robot::Effect::stribeck) {
    p["amplitude"] = b[0];
    p["w_s"] = c.setting.at("w_s");
    os << "Stribeck effect missing: " << b[0] << " N·m extra friction at low speed, w_s " << p["w_s"] << " rad/s";
  } else if (e == robot::Effect::presliding && c.setting.count("sigma0_ratio") != 0U) {
    p["sigma0_ratio"] = c.setting.at("sigma0_ratio") * b[0] + (1.0 - b[0]);
    p["level"] = b[0];
    os << "presliding (bristle) dynamics off: the bristles are softer than modelled, stiffness x"
       << c.setting.at("sigma0_ratio") << " (fit " << b[0] << " of that change)";
  } else if (e == robot::Effect::presliding) {
    if (c.setting.count("law") != 0U) p["law"] = c.setting.at("law");
    p["level"] = -b[0];
    p["displacement_rad"] = c.setting.at("displacement_rad");
    p["sigma0"] = std::fabs(b[0]) / p["displacement_rad"];
    os << "presliding (bristle) dynamics missing: friction builds up over " << p["displacement_rad"]
       << " rad after each reversal (stiffness ~" << p["sigma0"] << " N·m/rad"
       << (c.setting.count("law") != 0U ? ", Dahl's hyperbolic law)" : ")");
  } else if (e == robot::Effect::asymmetric_friction && c.setting.count("side") != 0U && b.size() > 1) {
    const bool positive = c.setting.at("side") > 0.0;
    p["side"] = c.setting.at("side");
    p["delta_tau_c_one_side"] = b[0];
    p["delta_tau_s_one_side"] = b[1];
    os << "friction differs with direction: the " << (positive ? "positive" : "negative")
       << " direction's Coulomb level off by " << b[0] << " N·m and its static level by " << b[1] << " N·m (the other direction as modelled)";
  } else if (e == robot::Effect::asymmetric_friction) {
    p["tau_c_positive_minus_negative"] = 2.0 * b[0];
    if (b.size() > 1) p["viscous_positive_minus_negative"] = 2.0 * b[1];
    os << "friction differs with direction: positive minus negative Coulomb level " << 2.0 * b[0] << " N·m";
    if (b.size() > 1) os << ", viscous " << 2.0 * b[1] << " N·m·s/rad";
  } else if (e == robot::Effect::position_ripple) {
    const double k = c.setting.at("periods_per_rev");
    p["periods_per_rev"] = k;
    p["period_rad"] = 2.0 * M_PI / k;
    p["amplitude"] = std::hypot(b[0], b[1]);
    p["phase_rad"] = std::atan2(b[1], b[0]);
    os << "position ripple (cogging or gear meshing): period " << p["period_rad"] << " rad (" << k
       << " per turn), amplitude " << p["amplitude"] << " N·m";
  } else if (e == robot::Effect::temperature_drift) {
    p["level_change"] = b[0];
    p["time_constant_s"] = c.setting.at("time_constant_s");
    os << "friction drifts with time (temperature): level changes by " << b[0] << " N·m with time constant "
       << p["time_constant_s"] << " s";
  } else if (e == robot::Effect::load_dependent_friction && b.size() > 1) {
    p["coefficient"] = b[0];
    p["coefficient_backdriven"] = b[1];
    os << "friction grows with the joint load, by the power flow: " << b[0] << " N·m per N·m where the motor drives, "
       << b[1] << " where the load back-drives the gear";
  } else if (e == robot::Effect::load_dependent_friction) {
    p["coefficient"] = b[0];
    os << "friction grows with the joint load: " << b[0] << " N·m per N·m of load";
  } else if (e == robot::Effect::payload) {
    const double m = b[0];
    p["mass_kg"] = m;
    if (std::fabs(m) > 1e-6) p["com_x_m"] = b[1] / m;
    os << "payload / last-link mass error: " << m << " kg";
  } else if (e == robot::Effect::inertia_error) {
    p["delta_inertia"] = b[0];
    os << "inertia (reflected rotor or link) off by " << b[0] << " kg·m²";
  } else if (e == robot::Effect::torque_constant) {
    // tau_real = (1 + b) tau_model: the measured torque per unit of true torque.
    p["scale_error"] = b[0];
    p["torque_constant_ratio"] = 1.0 / (1.0 + b[0]);
    os << "torque constant (current to torque) off: measured torque is " << 100.0 * b[0]
       << " % off the true torque (true/nominal K_I " << 1.0 / (1.0 + b[0]) << ")";
    if (b.size() > 1) {
      p["saturation_per_nm"] = b[1];
      os << ", and it saturates: " << 100.0 * b[1] << " % more per N·m of torque";
      // The plain scale that acts the same on this recording's torques (least squares of the
      // scale-and-saturation torque on the scale's column): what a user compares with a
      // datasheet's constant, as scale_error alone is the error at zero torque.
      if (c.columns.size() > 1) {
        double tt = 0.0, ts = 0.0;
        for (std::size_t k = 0; k < c.columns[0].size(); ++k) {
          tt += c.columns[0][k] * c.columns[0][k];
          ts += c.columns[0][k] * c.columns[1][k];
        }
        if (tt > 0.0) {
          p["scale_error_equivalent"] = b[0] + b[1] * ts / tt;
          os << " (" << 100.0 * p["scale_error_equivalent"] << " % on this recording's torques)";
        }
      }
    }
  } else if (e == robot::Effect::current_offset) {
    p["offset_nm"] = b[0];
    os << "current sensor offset worth " << b[0] << " N·m";
  } else if (e == robot::Effect::time_delay) {
    p["delay_s"] = -b[0];
    if (b[0] > 0.0) {
      os << "the torque leads the motion by " << b[0] * 1000.0 << " ms (delay_s < 0): the motion signals are older than the torque's "
         << "(a filtered velocity, or the state and the torques read at different times)";
    } else {
      os << "measurement delay of " << -b[0] * 1000.0 << " ms between motion and torque";
    }
  } else if (c.setting.count("rotor_acceleration") != 0U) {
    p["deflection_acceleration_gain"] = b[0];
    os << "torque transients where the gear deflection accelerates (" << e << "): " << b[0] << " N·m per rad/s²";
  } else if (e == robot::Effect::backlash) {
    p["gap_rad"] = c.setting.at("gap_rad");
    p["fraction"] = b[0];
    os << "backlash: the load is not driven for " << p["gap_rad"] << " rad after reversals";
  } else if (e == robot::Effect::joint_elasticity) {
    p["stiffness_nm_per_rad"] = b.empty() || b[0] == 0.0 ? 0.0 : 1.0 / b[0];
    os << "joint elasticity: stiffness ~" << p["stiffness_nm_per_rad"] << " N·m/rad";
  }
  (void)s;
  text = os.str();
  return p;
}

}  // namespace jg::diag
