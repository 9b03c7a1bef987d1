#include "identification/identify.hpp"

#include <unsupported/Eigen/NonLinearOptimization>

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "identification/lugre_batch.hpp"

namespace jg::ident {
namespace {
using Genes = std::array<double, 6>;
constexpr double kOpenEnd = 1e-6;  // keep open lower bounds open

LuGreParams<double> to_params(const Genes& x, const SearchRanges& r) {
  std::array<double, 6> v{};
  for (std::size_t i = 0; i < 6; ++i) v[i] = r.lower[i] + x[i] * (r.upper[i] - r.lower[i]);
  return {v[0], v[1], v[2], v[3], v[4], v[5]};
}
std::array<double, 6> as_array(const LuGreParams<double>& p) { return {p.sigma0, p.sigma1, p.sigma2, p.tau_c, p.tau_s, p.w_s}; }
LuGreParams<double> from_array(const std::array<double, 6>& v) { return {v[0], v[1], v[2], v[3], v[4], v[5]}; }

double rms_of(const FrictionSeries& s, const std::vector<double>& pred) {
  double acc = 0.0;
  for (std::size_t k = s.skip; k < pred.size(); ++k) acc += (s.friction[k] - pred[k]) * (s.friction[k] - pred[k]);
  return std::sqrt(acc / static_cast<double>(pred.size() - s.skip));
}

/// Levenberg-Marquardt functor in log-parameters (keeps every parameter positive). With a
/// mask, only the free parameters move: the others keep `base`'s values, and `tie_static`
/// keeps tau_s = tau_c (a Stribeck curve without excess).
struct LogFit {
  using Scalar = double;
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  const FrictionSeries* s;
  std::array<double, 6> base{};
  std::array<bool, 6> free{true, true, true, true, true, true};
  bool tie_static = false;
  [[nodiscard]] int inputs() const { return static_cast<int>(std::count(free.begin(), free.end(), true)); }
  [[nodiscard]] int values() const { return static_cast<int>(s->velocity.size() - s->skip); }
  [[nodiscard]] std::array<double, 6> expand(const Eigen::VectorXd& x) const {
    std::array<double, 6> v = base;
    Eigen::Index n = 0;
    for (std::size_t i = 0; i < 6; ++i) {
      if (free[i]) v[i] = std::exp(x(n++));
    }
    if (tie_static) v[4] = v[3];
    return v;
  }
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& fvec) const {
    LuGreDiscrete<double> d{};
    if (discretize(from_array(expand(x)), s->dt, d) != Error::ok) {
      fvec.setConstant(1e6);
      return 0;
    }
    LuGreState<double> st{};
    const double a = s->observer_decay();
    double filtered = 0.0;
    for (std::size_t k = 0; k < s->velocity.size(); ++k) {
      filtered = a * filtered + (1.0 - a) * lugre_step(d, st, s->velocity[k]);
      if (k >= s->skip) fvec(static_cast<Eigen::Index>(k - s->skip)) = s->friction[k] - filtered;
    }
    return 0;
  }
};

/// LM from `start` over the free parameters of `fit`; the refined set when it is valid.
LuGreParams<double> refine_lm(LogFit fit, const LuGreParams<double>& start) {
  fit.base = as_array(start);
  if (fit.inputs() == 0) return start;
  Eigen::NumericalDiff<LogFit> nd(fit, 1e-6);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<LogFit>> lm(nd);
  Eigen::VectorXd x(fit.inputs());
  Eigen::Index n = 0;
  for (std::size_t i = 0; i < 6; ++i) {
    if (fit.free[i]) x(n++) = std::log(std::max(fit.base[i], 1e-9));
  }
  lm.parameters.maxfev = 400;
  lm.minimize(x);
  const LuGreParams<double> refined = from_array(fit.expand(x));
  return validate(refined) == Error::ok ? refined : start;
}
}  // namespace

void check_series(const FrictionSeries& s) {
  if (s.velocity.size() != s.friction.size()) {
    throw std::invalid_argument("velocity and friction series differ in length");
  }
  if (s.velocity.size() < s.skip + 100) {
    throw std::invalid_argument("recording too short: " + std::to_string(s.velocity.size()) +
                                " samples; identification needs at least 100 scored samples");
  }
  if (!(s.dt > 0.0) || s.dt > 0.1) {
    throw std::invalid_argument("sample time must be in (0, 0.1] s");
  }
  double vmax = 0.0;
  std::size_t positive = 0, negative = 0;
  for (std::size_t k = 0; k < s.velocity.size(); ++k) {
    if (!std::isfinite(s.velocity[k]) || !std::isfinite(s.friction[k])) {
      throw std::invalid_argument("non-finite value at sample " + std::to_string(k));
    }
    vmax = std::max(vmax, std::fabs(s.velocity[k]));
    positive += s.velocity[k] > 1e-3 ? 1U : 0U;
    negative += s.velocity[k] < -1e-3 ? 1U : 0U;
  }
  if (vmax < 1e-3) {
    throw std::invalid_argument("the joint never moves (|velocity| < 1e-3 rad/s throughout): nothing to identify");
  }
  if (positive < 20 || negative < 20) {
    throw std::invalid_argument("no excitation in both directions: the data must move the joint both ways "
                                "(found " + std::to_string(positive) + " samples moving forward, " +
                                std::to_string(negative) + " backward)");
  }
}

LuGreParams<double> run_ga(const FrictionSeries& s, const GaSettings& g, const SearchRanges& r,
                           unsigned long long seed, double& best_cost) {
  const auto n = static_cast<std::size_t>(g.population);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto clamp_gene = [](double x) { return std::clamp(x, kOpenEnd, 1.0); };
  std::vector<Genes> pop(n), next(n);
  for (auto& x : pop) {
    for (auto& v : x) v = clamp_gene(unit(rng));
  }
  LuGreBatch batch;
  batch.resize(n);
  std::vector<double> cost;
  auto evaluate = [&](const std::vector<Genes>& p) {
    for (std::size_t i = 0; i < n; ++i) batch.set(i, to_params(p[i], r));
    lugre_batch_cost(batch, s.velocity, s.friction, s.dt, s.skip, cost, s.observer_decay());
  };
  evaluate(pop);
  std::vector<std::size_t> order(n);
  auto tournament = [&]() -> const Genes& {
    const auto a = static_cast<std::size_t>(unit(rng) * static_cast<double>(n)) % n;
    const auto b = static_cast<std::size_t>(unit(rng) * static_cast<double>(n)) % n;
    return cost[a] <= cost[b] ? pop[a] : pop[b];
  };
  for (int gen = 0; gen < g.generations; ++gen) {
    std::iota(order.begin(), order.end(), 0U);
    const auto elite = static_cast<std::size_t>(std::clamp(g.elite, 0, g.population));
    std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(elite), order.end(),
                      [&](std::size_t a, std::size_t b) { return cost[a] < cost[b]; });
    std::size_t filled = 0;
    for (; filled < elite; ++filled) next[filled] = pop[order[filled]];
    // Mutation step shrinks over the generations: wide search first, then fine tuning.
    const double step = 0.15 * (1.0 - static_cast<double>(gen) / g.generations) + 0.005;
    while (filled < n) {
      Genes c1 = tournament(), c2 = tournament();
      if (unit(rng) < g.crossover_probability) {  // simulated binary crossover, eta = 15
        for (std::size_t i = 0; i < 6; ++i) {
          if (unit(rng) < 0.5) continue;
          const double u = unit(rng);
          const double beta = u <= 0.5 ? std::pow(2.0 * u, 1.0 / 16.0) : std::pow(1.0 / (2.0 * (1.0 - u)), 1.0 / 16.0);
          const double a = c1[i], b = c2[i];
          c1[i] = clamp_gene(0.5 * ((1.0 + beta) * a + (1.0 - beta) * b));
          c2[i] = clamp_gene(0.5 * ((1.0 - beta) * a + (1.0 + beta) * b));
        }
      }
      for (Genes* c : {&c1, &c2}) {
        if (unit(rng) < g.mutation_probability) {
          for (auto& v : *c) {
            if (unit(rng) < 0.5) v = clamp_gene(v + step * gauss(rng));
          }
        }
      }
      next[filled++] = c1;
      if (filled < n) next[filled++] = c2;
    }
    std::swap(pop, next);
    evaluate(pop);
  }
  const auto best = static_cast<std::size_t>(std::min_element(cost.begin(), cost.end()) - cost.begin());
  best_cost = cost[best];
  return to_params(pop[best], r);
}

namespace {
constexpr double kHeadroom = 0.5 * 32767.0;    // half of Q16.16's range for the step's terms
constexpr double kSmallest = 64.0 / 65536.0;   // 64 LSB of Q16.16: a constant resolved to 1.6 %

std::string fmt(double x) {
  std::ostringstream os;
  os.precision(3);
  os << x;
  return os.str();
}
}  // namespace

FirmwareLimits firmware_limits(const LuGreParams<double>& p, double dt, double speed_max, double speed_resolution) {
  FirmwareLimits l;
  l.dt = dt;
  l.speed_max = std::max(speed_max, 1.0);
  l.level_min = kSmallest;
  l.level_max = kHeadroom / 8.0;
  const double hi = std::clamp(std::max(p.tau_c, p.tau_s), l.level_min, l.level_max);
  // a = sigma0 dt: the step's denominator s + a|w| within the headroom up to the top speed.
  // The implicit step is stable for any a; beyond this Q16.16 saturates it (and the bristle
  // settles within one sample anyway). Its gain a / (s + a|w|) may saturate near standstill
  // only where it multiplies a change of order |w|: it then settles slower, never overshoots.
  l.sigma0_max = kHeadroom / l.speed_max / dt;
  l.sigma0_min = kSmallest / dt;
  // At a reversal the bristle torque steps by up to 2 s in one sample and the damping adds
  // c1 times that: the friction output stays within the headroom.
  l.damping_max = std::max(0.0, kHeadroom / (2.0 * hi) - 1.0);
  l.sigma2_max = kHeadroom / (2.0 * l.speed_max);
  l.w_s_min = std::max(2.0 / kHeadroom, speed_resolution);  // 1 / w_s within the headroom
  return l;
}

bool fits_firmware(const LuGreParams<double>& p, double dt) {
  LuGreDiscrete<float> f{};
  LuGreDiscrete<q16> q{};
  return discretize(p, dt, f) == Error::ok && discretize(p, dt, q) == Error::ok;
}

namespace {
/// The bounding of one fit (bound_for_firmware): the data, the target and what changed.
struct Bounding {
  const FrictionSeries* s = nullptr;
  double dt = 0.0, speed_max = 0.0, resolution = 0.0;
  bool tie_inverted = true;  ///< write tau_s <= tau_c as tau_s = tau_c (else keep a representable inverted curve)
  std::array<double, 6> fitted{};
  std::vector<BoundedParameter> notes;
  LogFit fit{};

  void set(std::array<double, 6>& v, std::size_t i, double value, const std::string& reason) {
    if (value == v[i]) return;
    v[i] = value;
    fit.free[i] = false;  // the data do not move it back: later refits keep it
    for (auto& n : notes) {
      if (n.parameter == kParamNames[i]) {
        n.written = value;
        return;
      }
    }
    notes.push_back({kParamNames[i], fitted[i], value, reason});
  }

  /// tau_c, tau_s, w_s: levels the scalar resolves, a Stribeck curve the drive runs.
  void bound_shape(std::array<double, 6>& v) {
    const auto l = firmware_limits(from_array(v), dt, speed_max, resolution);
    if (v[3] < l.level_min || v[3] > l.level_max) {
      set(v, 3, std::clamp(v[3], l.level_min, l.level_max),
          "tau_c outside the levels Q16.16 resolves and holds (" + fmt(l.level_min) + " .. " + fmt(l.level_max) + " N·m)");
    }
    if (v[5] < l.w_s_min) {
      set(v, 5, l.w_s_min,
          "w_s below the slowest speed the recording resolves and Q16.16 holds as 1 / w_s (" + fmt(l.w_s_min) +
              " rad/s): the Stribeck excess lives below it, where these data say nothing; w_s raised to it, tau_s = tau_c");
      fit.tie_static = true;
    }
    if (!tie_inverted && v[4] < l.level_min) {
      set(v, 4, l.level_min, "tau_s below the level Q16.16 resolves: raised to " + fmt(l.level_min) + " N·m");
    }
    if (v[4] <= v[3] && tie_inverted) {
      fit.tie_static = true;
      set(v, 4, v[3], "no Stribeck excess (tau_s " + fmt(fitted[4]) + " <= tau_c " + fmt(fitted[3]) +
                          " N·m): written as tau_s = tau_c, the Coulomb level at every speed");
    }
    if (fit.tie_static) set(v, 4, v[3], "tau_s = tau_c: the Stribeck excess is not determined by these data");
    if (v[4] > l.level_max) set(v, 4, l.level_max, "tau_s above the level Q16.16 holds (" + fmt(l.level_max) + " N·m)");
  }

  /// sigma0, sigma1, sigma2 after the levels: what the step holds at dt.
  void bound_bristle(std::array<double, 6>& v) {
    const auto l = firmware_limits(from_array(v), dt, speed_max, resolution);
    if (v[0] > l.sigma0_max) {
      const double scale = l.sigma0_max / v[0];
      set(v, 0, l.sigma0_max,
          "the stiffest the drive's step holds at dt = " + fmt(dt) +
              " s (sigma0 dt |w| within half of Q16.16 up to " + fmt(l.speed_max) +
              " rad/s): presliding is not observable at this rate");
      // Damping that matters (c1 at the new stiffness above 1e-3) keeps its ratio to the
      // stiffness; a negligible one stays as fitted.
      const double c1 = v[1] / (v[0] / scale * dt);
      if (v[1] / (v[0] * dt) > 1e-3) {
        set(v, 1, v[1] * scale, "scaled with sigma0: keeps the fit's damping ratio c1 = sigma1 / (sigma0 dt) = " + fmt(c1));
      }
    } else if (v[0] < l.sigma0_min) {
      set(v, 0, l.sigma0_min, "sigma0 dt below what Q16.16 resolves at dt = " + fmt(dt) + " s");
    }
    if (v[1] > l.damping_max * v[0] * dt) {
      set(v, 1, l.damping_max * v[0] * dt,
          "set to c1 = sigma1 / (sigma0 dt) = " + fmt(l.damping_max) +
              ", the most damping whose torque step at a reversal stays within half of Q16.16");
    }
    if (v[2] > l.sigma2_max) {
      set(v, 2, l.sigma2_max, "sigma2 |w| beyond half of Q16.16 at " + fmt(l.speed_max) + " rad/s");
    }
  }
};

/// What a stage of bounds cost the fit: "not determined" when (almost) nothing.
std::string cost_text(double rms_before, double rms_after) {
  if (rms_after <= 1.01 * rms_before + 1e-12) {
    return "; not determined by this recording: the fit's rms stays " + fmt(rms_after) + " N·m (" + fmt(rms_before) + " before)";
  }
  return "; the fit's rms rises from " + fmt(rms_before) + " to " + fmt(rms_after) + " N·m";
}

double top_speed(const FrictionSeries& s) {
  double top = 0.0;
  for (const double w : s.velocity) top = std::max(top, std::fabs(w));
  return top;
}

/// The smallest speed the data resolve: the least non-zero |w| (a quantised log's step).
double speed_resolution(const FrictionSeries& s) {
  double least = 0.0;
  for (const double w : s.velocity) {
    if (w != 0.0 && (least == 0.0 || std::fabs(w) < least)) least = std::fabs(w);
  }
  return least;
}

/// One way of bounding a fit: the parameters, what was bounded and the fit's cost.
struct Bounded {
  LuGreParams<double> p{};
  std::vector<BoundedParameter> notes;
  double rms = 0.0;
};

/// Bounds `fitted` in two stages (the Stribeck shape, then the bristle), each followed by a
/// refit of the parameters left free; each note is told what its stage cost the fit.
/// `tie_inverted`: a curve with tau_s <= tau_c is written without excess (tau_s = tau_c).
Bounded bound_candidate(const FrictionSeries& s, const GaSettings& g, const LuGreParams<double>& fitted, double rms_fitted,
                        bool tie_inverted) {
  Bounding b;
  b.s = &s;
  b.dt = g.firmware.dt > 0.0 ? g.firmware.dt : s.dt;
  b.speed_max = g.firmware.speed_max > 0.0 ? g.firmware.speed_max : 2.0 * top_speed(s);
  b.resolution = speed_resolution(s);
  b.tie_inverted = tie_inverted;
  b.fitted = as_array(fitted);
  b.fit.s = &s;
  std::array<double, 6> v = b.fitted;
  const auto rms = [&] { return rms_of(s, lugre_predict(from_array(v), s.velocity, s.dt, s.observer_decay())); };
  const auto stage = [&](auto&& apply, double rms_before) {
    const std::size_t first = b.notes.size();
    apply(v);
    if (b.notes.size() > first && g.refine) v = as_array(refine_lm(b.fit, from_array(v)));
    const double after = rms();
    for (std::size_t k = first; k < b.notes.size(); ++k) b.notes[k].reason += cost_text(rms_before, after);
    return after;
  };
  const double rms_shape = stage([&](auto& x) { b.bound_shape(x); }, rms_fitted);
  stage([&](auto& x) { b.bound_bristle(x); }, rms_shape);
  // A refit may have moved a free parameter past its bound: clamp, no refit.
  b.bound_shape(v);
  b.bound_bristle(v);
  Bounded out{from_array(v), b.notes, rms()};
  std::ostringstream rate_text;  // 1000, not 1e+03
  rate_text.precision(6);
  rate_text << 1.0 / b.dt;
  const std::string rate = rate_text.str();
  for (auto& n : out.notes) {
    n.reason = n.parameter + " (fitted " + fmt(n.fitted) + ", written " + fmt(n.written) + " for the drive at " + rate + " Hz): " + n.reason;
  }
  if (!fits_firmware(out.p, b.dt)) {
    throw std::invalid_argument("the identified LuGre parameters cannot be bounded to what the firmware scalar holds at dt = " +
                                fmt(b.dt) + " s");
  }
  return out;
}

/// Bounds the fit for the firmware (FirmwareTarget). A curve with tau_s <= tau_c is written
/// without excess (tau_s = tau_c) unless keeping its shape fits clearly better (1 %).
LuGreParams<double> bound_for_firmware(const FrictionSeries& s, const GaSettings& g, const LuGreParams<double>& fitted,
                                       IdentificationResult& out) {
  Bounded chosen = bound_candidate(s, g, fitted, out.rms, true);
  if (fitted.tau_s <= fitted.tau_c) {
    Bounded kept = bound_candidate(s, g, fitted, out.rms, false);
    if (kept.rms < 0.99 * chosen.rms) chosen = std::move(kept);
  }
  out.firmware_dt = g.firmware.dt > 0.0 ? g.firmware.dt : s.dt;
  out.rms = chosen.rms;
  out.bounded = std::move(chosen.notes);
  return chosen.p;
}
}  // namespace

namespace {
/// g.runs independent GA runs (seeded from g.seed) on g.threads threads into
/// out.run_results and out.run_costs; progress polled every 100 ms.
void run_ga_runs(const FrictionSeries& s_ga, const GaSettings& g, const SearchRanges& r,
                 const std::function<void(double)>& progress, IdentificationResult& out) {
  out.run_results.resize(static_cast<std::size_t>(g.runs));
  out.run_costs.resize(static_cast<std::size_t>(g.runs));
  std::atomic<int> next_run{0}, done{0};
  auto worker = [&]() {
    for (int k = next_run++; k < g.runs; k = next_run++) {
      double c = 0.0;
      out.run_results[static_cast<std::size_t>(k)] = run_ga(s_ga, g, r, g.seed * 7919ULL + static_cast<unsigned long long>(k), c);
      out.run_costs[static_cast<std::size_t>(k)] = c;
      ++done;
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min(g.threads, g.runs); ++t) pool.emplace_back(worker);
  if (progress) {
    std::thread watcher([&]() {
      while (done.load() < g.runs) {
        progress(static_cast<double>(done.load()) / g.runs);
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
    });
    worker();
    for (auto& t : pool) t.join();
    watcher.join();
    progress(1.0);
  } else {
    worker();
    for (auto& t : pool) t.join();
  }
}

/// The mean of the runs (the GA's estimate, its RMS in out.ga_rms) and their spread per
/// parameter (out.report[].ga_mean, ga_std).
LuGreParams<double> mean_of_runs(const FrictionSeries& s, const GaSettings& g, IdentificationResult& out) {
  std::array<double, 6> mean{}, sq{};
  for (const auto& p : out.run_results) {
    const auto v = as_array(p);
    for (std::size_t i = 0; i < 6; ++i) mean[i] += v[i] / g.runs;
  }
  for (const auto& p : out.run_results) {
    const auto v = as_array(p);
    for (std::size_t i = 0; i < 6; ++i) sq[i] += (v[i] - mean[i]) * (v[i] - mean[i]);
  }
  LuGreParams<double> best = from_array(mean);
  out.ga_rms = rms_of(s, lugre_predict(best, s.velocity, s.dt, s.observer_decay()));
  for (std::size_t i = 0; i < 6; ++i) {
    out.report[i].ga_mean = mean[i];
    out.report[i].ga_std = g.runs > 1 ? std::sqrt(sq[i] / (g.runs - 1)) : 0.0;
  }
  return best;
}

/// Whether each parameter is identifiable from these data: the noise level from the data
/// itself (the residual's sample-to-sample differences), the sensitivity of the prediction
/// to a 10 % change and the Fisher information in log-parameters; a warning per parameter
/// that is not.
void identifiability(const FrictionSeries& s, const LuGreParams<double>& best, IdentificationResult& out) {
  const std::vector<double> pred = lugre_predict(best, s.velocity, s.dt, s.observer_decay());
  double d2 = 0.0;
  for (std::size_t k = s.skip + 1; k < pred.size(); ++k) {
    const double e1 = s.friction[k] - pred[k], e0 = s.friction[k - 1] - pred[k - 1];
    d2 += (e1 - e0) * (e1 - e0);
  }
  out.noise_rms = std::sqrt(d2 / static_cast<double>(pred.size() - s.skip - 1) / 2.0);
  // Sensitivity and Fisher information in log-parameters.
  const auto base = as_array(best);
  const auto m = static_cast<Eigen::Index>(pred.size() - s.skip);
  Eigen::MatrixXd J(m, 6);
  for (std::size_t i = 0; i < 6; ++i) {
    auto up = base, down = base;
    up[i] *= 1.01;
    down[i] /= 1.01;
    const auto pu = lugre_predict(from_array(up), s.velocity, s.dt, s.observer_decay());
    const auto pd = lugre_predict(from_array(down), s.velocity, s.dt, s.observer_decay());
    for (Eigen::Index k = 0; k < m; ++k) {
      J(k, static_cast<Eigen::Index>(i)) = (pu[static_cast<std::size_t>(k) + s.skip] - pd[static_cast<std::size_t>(k) + s.skip]) / (2.0 * std::log(1.01));
    }
    out.report[i].sensitivity = 0.1 * J.col(static_cast<Eigen::Index>(i)).norm() / std::sqrt(static_cast<double>(m));
  }
  const double sigma2 = out.rms * out.rms;
  const Eigen::MatrixXd fisher = J.transpose() * J / std::max(sigma2, 1e-12);
  const Eigen::MatrixXd cov = fisher.completeOrthogonalDecomposition().pseudoInverse();
  for (std::size_t i = 0; i < 6; ++i) {
    ParameterReport& rep = out.report[i];
    rep.value = base[i];
    rep.relative_std_error = std::sqrt(std::max(0.0, cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i))));
    const double spread = rep.ga_mean > 0.0 ? rep.ga_std / rep.ga_mean : 0.0;
    if (rep.relative_std_error > 0.3 || rep.sensitivity < 0.05 * std::max(out.noise_rms, 1e-3)) {
      rep.identifiable = false;
      std::ostringstream os;
      os << kParamNames[i] << " is not identifiable from these data: a 10 % change moves the prediction by "
         << rep.sensitivity << " N·m RMS (noise " << out.noise_rms << " N·m), relative standard error "
         << rep.relative_std_error << ", spread over runs " << spread;
      if (i == 0 || i == 1) os << " (presliding dynamics need slow motion through velocity reversals at a high sample rate)";
      if (i == 5) os << " (the Stribeck velocity needs samples at low speed)";
      rep.note = os.str();
      out.warnings.push_back(rep.note);
    }
  }
}
}  // namespace

IdentificationResult identify_lugre(const FrictionSeries& s_ga, const GaSettings& g, const SearchRanges& r,
                                    const std::function<void(double)>& progress, const FrictionSeries* fine) {
  check_series(s_ga);
  if (fine != nullptr) check_series(*fine);
  const FrictionSeries& s = fine != nullptr ? *fine : s_ga;
  if (g.population < 4 || g.generations < 1 || g.runs < 1 || g.threads < 1) {
    throw std::invalid_argument("GA settings: population >= 4, generations >= 1, runs >= 1, threads >= 1");
  }
  IdentificationResult out;
  run_ga_runs(s_ga, g, r, progress, out);
  LuGreParams<double> best = mean_of_runs(s, g, out);
  out.rms = out.ga_rms;
  if (g.refine) {
    const LuGreParams<double> refined = refine_lm(LogFit{&s}, best);
    const double rms = rms_of(s, lugre_predict(refined, s.velocity, s.dt, s.observer_decay()));
    if (rms < out.rms) {
      best = refined;
      out.rms = rms;
    }
  }
  out.rms_unbounded = out.rms;
  if (g.firmware.enabled) best = bound_for_firmware(s, g, best, out);
  out.params = best;
  identifiability(s, best, out);
  return out;
}

}  // namespace jg::ident
