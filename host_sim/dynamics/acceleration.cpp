#include "dynamics/acceleration.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

namespace jg::dyn {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Gaussian-weighted local line fit at every sample: returns slope (derivative) or level.
std::vector<double> local_line(const std::vector<double>& x, double dt, double sigma_s, bool slope) {
  const std::size_t n = x.size();
  std::vector<double> out(n, 0.0);
  if (n == 0) return out;
  if (n == 1) {
    out[0] = slope ? 0.0 : x[0];
    return out;
  }
  const double sigma_samples = sigma_s / dt;
  if (!(sigma_samples > 0.5)) {  // too narrow for a window: central differences / identity
    for (std::size_t k = 0; k < n; ++k) {
      if (!slope) {
        out[k] = x[k];
        continue;
      }
      const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < n ? k + 1 : n - 1;
      out[k] = (x[b] - x[a]) / (static_cast<double>(b - a) * dt);
    }
    return out;
  }
  const auto half = static_cast<std::ptrdiff_t>(std::ceil(4.0 * sigma_samples));
  std::vector<double> w(static_cast<std::size_t>(half) + 1);
  for (std::ptrdiff_t m = 0; m <= half; ++m) {
    const double u = static_cast<double>(m) / sigma_samples;
    w[static_cast<std::size_t>(m)] = std::exp(-0.5 * u * u);
  }
  const auto N = static_cast<std::ptrdiff_t>(n);
  for (std::ptrdiff_t k = 0; k < N; ++k) {
    const std::ptrdiff_t a = std::max<std::ptrdiff_t>(0, k - half), b = std::min<std::ptrdiff_t>(N - 1, k + half);
    // Weighted means of offset u (in samples) and x, then the weighted slope.
    double sw = 0.0, su = 0.0, sx = 0.0;
    for (std::ptrdiff_t m = a; m <= b; ++m) {
      const double wi = w[static_cast<std::size_t>(std::abs(m - k))];
      sw += wi;
      su += wi * static_cast<double>(m - k);
      sx += wi * x[static_cast<std::size_t>(m)];
    }
    const double ub = su / sw, xb = sx / sw;
    double suu = 0.0, sux = 0.0;
    for (std::ptrdiff_t m = a; m <= b; ++m) {
      const double wi = w[static_cast<std::size_t>(std::abs(m - k))];
      const double du = static_cast<double>(m - k) - ub;
      suu += wi * du * du;
      sux += wi * du * (x[static_cast<std::size_t>(m)] - xb);
    }
    // The local line's slope, or its level at u = 0 (not the plain weighted mean: unbiased
    // at the ends).
    if (slope) {
      out[static_cast<std::size_t>(k)] = suu > 0.0 ? sux / suu / dt : 0.0;
    } else {
      out[static_cast<std::size_t>(k)] = suu > 0.0 ? xb - (sux / suu) * ub : xb;
    }
  }
  return out;
}

void fft(std::vector<std::complex<double>>& a) {
  const std::size_t n = a.size();
  for (std::size_t i = 1, j = 0; i < n; ++i) {
    std::size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  for (std::size_t len = 2; len <= n; len <<= 1) {
    const double ang = -2.0 * kPi / static_cast<double>(len);
    const std::complex<double> wl(std::cos(ang), std::sin(ang));
    for (std::size_t i = 0; i < n; i += len) {
      std::complex<double> w(1.0, 0.0);
      for (std::size_t j = 0; j < len / 2; ++j) {
        const std::complex<double> u = a[i + j], v = a[i + j + len / 2] * w;
        a[i + j] = u + v;
        a[i + j + len / 2] = u - v;
        w *= wl;
      }
    }
  }
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

std::vector<double> smooth_derivative(const std::vector<double>& x, double dt, double sigma_s) {
  return local_line(x, dt, sigma_s, true);
}

std::vector<double> smooth(const std::vector<double>& x, double dt, double sigma_s) {
  return local_line(x, dt, sigma_s, false);
}

SigmaChoice choose_sigma_detail(const std::vector<std::vector<double>>& velocities, double dt) {
  SigmaChoice best;
  std::size_t n_max = 0;
  for (const auto& v : velocities) n_max = std::max(n_max, v.size());
  const double duration = static_cast<double>(n_max) * dt;
  const double lo = 2.0 * dt, hi = std::max(lo, duration / 20.0);
  const double gain_at_cutoff = 0.99;
  const double k_sigma = std::sqrt(2.0 * std::log(1.0 / gain_at_cutoff)) / (2.0 * kPi);
  best.sigma_s = std::clamp(0.02, lo, hi);  // nothing usable: a neutral 20 ms within the bounds
  for (std::size_t j = 0; j < velocities.size(); ++j) {
    const auto& x = velocities[j];
    const std::size_t n = x.size();
    if (n < 64) continue;
    double mean = 0.0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(n);
    double var = 0.0;
    for (double v : x) var += (v - mean) * (v - mean);
    if (!(var / static_cast<double>(n) > 1e-12)) continue;  // joint at rest
    std::size_t m = 1;
    while (m < n) m <<= 1;
    std::vector<std::complex<double>> a(m, 0.0);
    for (std::size_t k = 0; k < n; ++k) {
      const double hann = 0.5 - 0.5 * std::cos(2.0 * kPi * static_cast<double>(k) / static_cast<double>(n - 1));
      a[k] = (x[k] - mean) * hann;
    }
    fft(a);
    const double df = 1.0 / (static_cast<double>(m) * dt);
    std::vector<double> power(m / 2 + 1);
    for (std::size_t k = 0; k <= m / 2; ++k) power[k] = std::norm(a[k]);
    // Log-spaced (1/12-octave) band powers from the lowest resolved frequency to Nyquist.
    std::vector<double> f_lo, band;
    for (double f0 = df; f0 < 0.5 / dt; f0 *= std::pow(2.0, 1.0 / 12.0)) {
      const double f1 = f0 * std::pow(2.0, 1.0 / 12.0);
      double sum = 0.0;
      int cnt = 0;
      for (auto k = static_cast<std::size_t>(std::ceil(f0 / df)); k <= m / 2 && static_cast<double>(k) * df < f1; ++k) {
        sum += power[k];
        ++cnt;
      }
      if (cnt > 0) {
        f_lo.push_back(f0);
        band.push_back(sum / cnt);
      }
    }
    if (band.size() < 8) continue;
    const auto peak = static_cast<std::size_t>(std::max_element(band.begin(), band.end()) - band.begin());
    if (band.size() - peak < 6) continue;
    // Noise floor: the median band above the peak (log spacing: the plateau dominates the
    // count even when interpolation or a sensor's own filter bends the top octaves down).
    const double noise = median(std::vector<double>(band.begin() + static_cast<std::ptrdiff_t>(peak) + 1, band.end()));
    // Signal band: up to the first band above the peak that falls below 10x the floor.
    double cutoff = 0.0;
    for (std::size_t b = peak + 1; b < band.size(); ++b) {
      if (band[b] < 10.0 * noise) {
        cutoff = f_lo[b];
        break;
      }
    }
    if (!(cutoff > 0.0)) continue;
    const double sigma = std::clamp(k_sigma / cutoff, lo, hi);
    if (best.joint_index < 0 || sigma < best.sigma_s) {
      best.sigma_s = sigma;
      best.cutoff_hz = cutoff;
      best.noise_floor = noise * dt / static_cast<double>(n);  // periodogram scaling to a density (approx.)
      best.joint_index = static_cast<int>(j);
    }
  }
  return best;
}

double choose_sigma(const std::vector<std::vector<double>>& velocities, double dt) {
  return choose_sigma_detail(velocities, dt).sigma_s;
}

}  // namespace jg::dyn
