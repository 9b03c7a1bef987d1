#include "tuning/observer_tuning.hpp"

#include <cmath>
#include <vector>
#include <stdexcept>

namespace jg::tuning {

ObserverFigures analyse(const ObserverGains& g, double dt) {
  ObserverCoeffs<double> c{};
  if (discretize(g, dt, c) != Error::ok) throw std::invalid_argument("observer gains cannot be discretised");
  ObserverState<double> step{}, impulse{};
  (void)observer_step(c, step, 0.0, 0.0, 0.0, 0.0);  // prime
  (void)observer_step(c, impulse, 0.0, 0.0, 0.0, 0.0);
  const auto n = static_cast<long>(std::ceil(10.0 / dt));
  std::vector<double> y(static_cast<std::size_t>(n));
  double h2 = 0.0;
  for (long k = 0; k < n; ++k) {
    y[static_cast<std::size_t>(k)] = observer_step(c, step, 0.0, 1.0, 0.0, 0.0);
    const double h = observer_step(c, impulse, 0.0, k == 0 ? 1.0 : 0.0, 0.0, 0.0);
    h2 += h * h;
  }
  ObserverFigures f;
  f.dc_gain = y.back();
  for (const double v : y) f.peak = std::max(f.peak, v);
  bool got50 = false, got90 = false;
  for (long k = 0; k < n; ++k) {
    const double v = y[static_cast<std::size_t>(k)];
    const double t = static_cast<double>(k + 1) * dt;
    if (!got50 && v >= 0.5 * f.peak) { f.delay50_s = t; got50 = true; }
    if (!got90 && v >= 0.9 * f.peak) { f.delay90_s = t; got90 = true; }
  }
  f.overshoot = f.dc_gain > 0.05 ? std::max(0.0, (f.peak - f.dc_gain) / f.dc_gain) : 0.0;
  f.noise_gain = std::sqrt(h2);
  return f;
}

ObserverGains gains_for_noise(const ObserverGains& shape, double dt, double torque_noise_rms, double target_noise_rms) {
  if (!(torque_noise_rms > 0.0) || !(target_noise_rms > 0.0)) throw std::invalid_argument("noise levels must be > 0");
  auto scaled = [&](double s) {
    ObserverGains g = shape;
    g.k1 *= s;
    g.k2 *= s;
    g.k3 *= s;
    return g;
  };
  auto noise = [&](double s) { return analyse(scaled(s), dt).noise_gain * torque_noise_rms; };
  double lo = 1e-3, hi = 1.0;
  while (noise(hi) < target_noise_rms && hi < 1e3 && scaled(hi * 2.0).k1 * dt < 2.0) hi *= 2.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = std::sqrt(lo * hi);
    (noise(mid) < target_noise_rms ? lo : hi) = mid;
  }
  return scaled(lo);
}

}  // namespace jg::tuning
