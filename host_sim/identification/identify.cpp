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

/// Levenberg-Marquardt functor in log-parameters (keeps every parameter positive).
struct LogFit {
  using Scalar = double;
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  const FrictionSeries* s;
  [[nodiscard]] int inputs() const { return 6; }
  [[nodiscard]] int values() const { return static_cast<int>(s->velocity.size() - s->skip); }
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& fvec) const {
    std::array<double, 6> v{};
    for (int i = 0; i < 6; ++i) v[static_cast<std::size_t>(i)] = std::exp(x(i));
    LuGreDiscrete<double> d{};
    if (discretize(from_array(v), s->dt, d) != Error::ok) {
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

IdentificationResult identify_lugre(const FrictionSeries& s_ga, const GaSettings& g, const SearchRanges& r,
                                    const std::function<void(double)>& progress, const FrictionSeries* fine) {
  check_series(s_ga);
  if (fine != nullptr) check_series(*fine);
  const FrictionSeries& s = fine != nullptr ? *fine : s_ga;
  if (g.population < 4 || g.generations < 1 || g.runs < 1 || g.threads < 1) {
    throw std::invalid_argument("GA settings: population >= 4, generations >= 1, runs >= 1, threads >= 1");
  }
  IdentificationResult out;
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
  // Mean and spread over the runs.
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
  out.rms = out.ga_rms;
  if (g.refine) {
    LogFit f{&s};
    Eigen::NumericalDiff<LogFit> nd(f, 1e-6);
    Eigen::LevenbergMarquardt<Eigen::NumericalDiff<LogFit>> lm(nd);
    Eigen::VectorXd x(6);
    for (std::size_t i = 0; i < 6; ++i) x(static_cast<Eigen::Index>(i)) = std::log(std::max(mean[i], 1e-9));
    lm.parameters.maxfev = 400;
    lm.minimize(x);
    std::array<double, 6> v{};
    for (std::size_t i = 0; i < 6; ++i) v[i] = std::exp(x(static_cast<Eigen::Index>(i)));
    const LuGreParams<double> refined = from_array(v);
    if (validate(refined) == Error::ok) {
      const double rms = rms_of(s, lugre_predict(refined, s.velocity, s.dt, s.observer_decay()));
      if (rms < out.rms) {
        best = refined;
        out.rms = rms;
      }
    }
  }
  out.params = best;
  // Noise level from the data itself: the residual's sample-to-sample differences.
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
  return out;
}

}  // namespace jg::ident
