// Accelerations from measured velocities: a zero-phase Gaussian-derivative filter whose
// width comes from the data. Standalone (plain vectors) so that identification and the
// diagnosis share it. Assumes uniform sampling (the recording is made uniform upstream).
#pragma once

#include <vector>

namespace jg::dyn {

/// Derivative of x (sampled every dt seconds) smoothed by a Gaussian of standard
/// deviation sigma_s [s]: at each sample, the slope of a Gaussian-weighted straight-line
/// fit over +/- 4 sigma. In the interior this is exactly the convolution with the
/// (normalised) derivative of a Gaussian, so it is zero-phase; near the ends the window
/// is cut and the local line fit stays unbiased for linear trends, where a truncated
/// kernel would not be. sigma_s <= 0 falls back to central differences.
[[nodiscard]] std::vector<double> smooth_derivative(const std::vector<double>& x, double dt, double sigma_s);

/// The matching zero-phase Gaussian smoothing (same window, weights renormalised at the ends).
[[nodiscard]] std::vector<double> smooth(const std::vector<double>& x, double dt, double sigma_s);

/// How the width was chosen, for reports.
struct SigmaChoice {
  double sigma_s = 0.0;        ///< chosen width [s]
  double cutoff_hz = 0.0;      ///< where the velocity spectrum meets its noise floor
  double noise_floor = 0.0;    ///< median band power above the spectral peak (periodogram units)
  int joint_index = -1;        ///< the joint whose (highest) signal band set the width
};

/// Width from the data: per series the periodogram of the velocity (Hann window,
/// averaged in 1/12-octave bands), its noise floor = the median band power above the
/// spectral peak, its signal band f_c = up to the first band above the peak that falls
/// below 10x that floor. The Gaussian passes f_c with 99 % gain (so the motion's own
/// accelerations are not biased by more than 1 %): sigma = sqrt(2 ln(1/0.99)) / (2 pi f_c); clamped to
/// [2 dt, duration / 20]. With several series (joints) the widest signal band (smallest
/// sigma) wins, so no joint's dynamics are smoothed away. Series that do not move are skipped.
[[nodiscard]] SigmaChoice choose_sigma_detail(const std::vector<std::vector<double>>& velocities, double dt);
[[nodiscard]] double choose_sigma(const std::vector<std::vector<double>>& velocities, double dt);

}  // namespace jg::dyn
