#include "diagnosis/signals.hpp"

#include <algorithm>
#include <cmath>

namespace jg::diag {

std::vector<double> derivative(const std::vector<double>& x, double dt, double half_window_s) {
  // Savitzky-Golay first derivative (local quadratic = local linear fit for the slope)
  // over +/-h samples, h covering about 10 ms by default: robot motion is far slower than
  // that, the encoder and current quantisation noise is not.
  const std::size_t n = x.size();
  std::vector<double> d(n, 0.0);
  const auto h = static_cast<std::size_t>(std::max(2.0, std::round(half_window_s / dt)));
  if (n < 2 * h + 1) {
    return d;
  }
  double denom = 0.0;
  for (std::size_t i = 1; i <= h; ++i) denom += 2.0 * static_cast<double>(i * i);
  for (std::size_t k = h; k + h < n; ++k) {
    double acc = 0.0;
    for (std::size_t i = 1; i <= h; ++i) acc += static_cast<double>(i) * (x[k + i] - x[k - i]);
    d[k] = acc / (denom * dt);
  }
  for (std::size_t k = 0; k < h; ++k) {
    d[k] = d[h];
    d[n - 1 - k] = d[n - 1 - h];
  }
  return d;
}

double noise_level(const std::vector<double>& x) {
  if (x.size() < 8) {
    return 0.0;
  }
  std::vector<double> d2;
  d2.reserve(x.size());
  for (std::size_t k = 1; k + 1 < x.size(); ++k) d2.push_back(std::fabs(x[k + 1] - 2.0 * x[k] + x[k - 1]));
  auto mid = d2.begin() + static_cast<std::ptrdiff_t>(d2.size() / 2);
  std::nth_element(d2.begin(), mid, d2.end());
  return 1.4826 * *mid / std::sqrt(6.0);
}

double rms(const std::vector<double>& x) {
  double acc = 0.0;
  for (const double v : x) acc += v * v;
  return x.empty() ? 0.0 : std::sqrt(acc / static_cast<double>(x.size()));
}

JointSignals with_fitted_in_model(JointSignals s, const std::vector<double>& fitted_nm) {
  if (fitted_nm.size() != s.size()) return s;
  for (std::size_t k = 0; k < s.size(); ++k) {
    s.residual[k] -= fitted_nm[k];
    s.tau_model[k] += fitted_nm[k];
  }
  return s;
}

const std::vector<double>& gear_torque(const JointSignals& s) { return s.load.size() == s.size() ? s.load : s.tau_real; }

double backlash_shape(double gear_torque_nm, double share, double tau_rms) { return std::tanh(gear_torque_nm / (share * tau_rms)); }

}  // namespace jg::diag
