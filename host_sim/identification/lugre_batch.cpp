#include "identification/lugre_batch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace jg::ident {

void LuGreBatch::resize(std::size_t n) {
  for (auto* v : {&sigma0, &sigma1, &sigma2, &tau_c, &tau_s, &w_s}) v->resize(n);
}

void LuGreBatch::set(std::size_t i, const LuGreParams<double>& p) {
  sigma0[i] = p.sigma0;
  sigma1[i] = p.sigma1;
  sigma2[i] = p.sigma2;
  tau_c[i] = p.tau_c;
  tau_s[i] = p.tau_s;
  w_s[i] = p.w_s;
}

LuGreParams<double> LuGreBatch::get(std::size_t i) const {
  return {sigma0[i], sigma1[i], sigma2[i], tau_c[i], tau_s[i], w_s[i]};
}

namespace {
// exp(x) for x <= 0, branch-free so that the candidate loop vectorises: x log2(e) = n + f
// with n = round(y) by the 1.5 * 2^52 trick (|f| <= 0.5), e^(f ln 2) by a degree-10
// Taylor polynomial (relative error < 2e-13 for |f ln 2| <= 0.35), and 2^n assembled in
// the exponent bits. Inputs below -700 are clamped (the result is ~1e-304 instead of 0).
inline double exp_nonpositive(double x) {
  constexpr double kRound = 6755399441055744.0;  // 1.5 * 2^52
  x = std::max(x, -700.0);
  const double y = x * 1.4426950408889634;
  const double shifted = y + kRound;
  const double n = shifted - kRound;
  const double f = (y - n) * 0.6931471805599453;
  double p = 1.0 / 3628800.0;
  p = p * f + 1.0 / 362880.0;
  p = p * f + 1.0 / 40320.0;
  p = p * f + 1.0 / 5040.0;
  p = p * f + 1.0 / 720.0;
  p = p * f + 1.0 / 120.0;
  p = p * f + 1.0 / 24.0;
  p = p * f + 1.0 / 6.0;
  p = p * f + 0.5;
  p = p * f + 1.0;
  p = p * f + 1.0;
  // The low mantissa bits of `shifted` hold n (two's complement); n + 1023 shifted into
  // the exponent field is 2^n.
  std::uint64_t bits = 0;
  std::memcpy(&bits, &shifted, sizeof bits);
  bits = (bits + 1023U) << 52U;
  double scale = 0.0;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

// One sample for all candidates; the loop body has no branches and no calls.
__attribute__((target_clones("avx512f", "avx2", "default")))
void candidates_step(std::size_t nc, double w, double r, double score, double decay, const double* __restrict gain,
                     const double* __restrict damping, const double* __restrict coulomb,
                     const double* __restrict drop, const double* __restrict inv_ws,
                     const double* __restrict viscous, double* __restrict z, double* __restrict filtered,
                     double* __restrict acc) {
  const double speed = std::fabs(w);
  for (std::size_t c = 0; c < nc; ++c) {
    const double u = w * inv_ws[c];
    const double level = coulomb[c] + drop[c] * exp_nonpositive(-u * u);
    const double g = gain[c] / (level + gain[c] * speed);
    const double previous = z[c];
    const double next = previous + (w * level - previous * speed) * g;
    z[c] = next;
    const double tau = next + damping[c] * (next - previous) + viscous[c] * w;
    filtered[c] = decay * filtered[c] + (1.0 - decay) * tau;
    const double e = r - filtered[c];
    acc[c] += score * e * e;
  }
}
}  // namespace

void lugre_batch_cost(const LuGreBatch& b, const std::vector<double>& velocity, const std::vector<double>& measured,
                      double dt, std::size_t skip, std::vector<double>& cost, double observer_decay) {
  const std::size_t nc = b.size();
  const std::size_t ns = velocity.size();
  if (measured.size() != ns || skip >= ns) {
    throw std::invalid_argument("lugre_batch_cost: series sizes differ or nothing to score");
  }
  // Per-candidate coefficients, folded with dt exactly as discretize() does.
  std::vector<double> gain(nc), damping(nc), coulomb(nc), drop(nc), inv_ws(nc), viscous(nc), zeta(nc, 0.0),
      filtered(nc, 0.0);
  cost.assign(nc, 0.0);
  for (std::size_t c = 0; c < nc; ++c) {
    gain[c] = b.sigma0[c] * dt;
    damping[c] = b.sigma1[c] / gain[c];
    coulomb[c] = b.tau_c[c];
    drop[c] = b.tau_s[c] - b.tau_c[c];
    inv_ws[c] = 1.0 / b.w_s[c];
    viscous[c] = b.sigma2[c];
  }
  for (std::size_t k = 0; k < ns; ++k) {
    candidates_step(nc, velocity[k], measured[k], k >= skip ? 1.0 : 0.0, observer_decay, gain.data(), damping.data(),
                    coulomb.data(), drop.data(), inv_ws.data(), viscous.data(), zeta.data(), filtered.data(), cost.data());
  }
  const double inv_n = 1.0 / static_cast<double>(ns - skip);
  for (std::size_t c = 0; c < nc; ++c) cost[c] *= inv_n;
}

std::vector<double> lugre_predict(const LuGreParams<double>& p, const std::vector<double>& velocity, double dt,
                                  double observer_decay) {
  LuGreDiscrete<double> d{};
  if (const Error e = discretize(p, dt, d); e != Error::ok) {
    throw std::invalid_argument(std::string("lugre_predict: invalid parameters: ") + to_string(e));
  }
  LuGreState<double> s{};
  std::vector<double> out(velocity.size());
  double filtered = 0.0;
  for (std::size_t k = 0; k < velocity.size(); ++k) {
    const double tau = lugre_step(d, s, velocity[k]);
    filtered = observer_decay * filtered + (1.0 - observer_decay) * tau;
    out[k] = filtered;
  }
  return out;
}

}  // namespace jg::ident
