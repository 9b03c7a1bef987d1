#include "motion/excitation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace jg::sim {

QuinticSegment::QuinticSegment(JointSample from, JointSample to, double duration)
    : duration_(duration) {
  if (!(duration > 0.0)) {
    throw std::invalid_argument("QuinticSegment: duration must be > 0 s");
  }
  const double T = duration, T2 = T * T, T3 = T2 * T, T4 = T3 * T, T5 = T4 * T;
  const double h = to.q - from.q;
  c_[0] = from.q;
  c_[1] = from.dq;
  c_[2] = from.ddq / 2.0;
  c_[3] = (20.0 * h - (8.0 * to.dq + 12.0 * from.dq) * T - (3.0 * from.ddq - to.ddq) * T2) / (2.0 * T3);
  c_[4] = (-30.0 * h + (14.0 * to.dq + 16.0 * from.dq) * T + (3.0 * from.ddq - 2.0 * to.ddq) * T2) /
          (2.0 * T4);
  c_[5] = (12.0 * h - 6.0 * (to.dq + from.dq) * T + (to.ddq - from.ddq) * T2) / (2.0 * T5);
}

JointSample QuinticSegment::at(double t) const {
  const double s = std::clamp(t, 0.0, duration_);
  JointSample out;
  out.q = c_[0] + s * (c_[1] + s * (c_[2] + s * (c_[3] + s * (c_[4] + s * c_[5]))));
  out.dq = c_[1] + s * (2.0 * c_[2] + s * (3.0 * c_[3] + s * (4.0 * c_[4] + s * 5.0 * c_[5])));
  out.ddq = 2.0 * c_[2] + s * (6.0 * c_[3] + s * (12.0 * c_[4] + s * 20.0 * c_[5]));
  return out;
}

namespace {
JointSample sine_start(double amplitude, double omega) { return {0.0, amplitude * omega, 0.0}; }
}  // namespace

PaperExcitation::PaperExcitation(double amplitude_rad, double frequency_hz, int periods, double blend_s)
    : amplitude_(amplitude_rad),
      omega_(2.0 * M_PI * frequency_hz),
      blend_s_(blend_s),
      periods_(periods),
      lead_in_({-amplitude_rad * 2.0 * M_PI * frequency_hz * blend_s / 2.0, 0.0, 0.0},
               sine_start(amplitude_rad, 2.0 * M_PI * frequency_hz), blend_s),
      lead_out_(sine_start(amplitude_rad, 2.0 * M_PI * frequency_hz),
                {amplitude_rad * 2.0 * M_PI * frequency_hz * blend_s / 2.0, 0.0, 0.0}, blend_s) {
  if (periods < 1 || !(frequency_hz > 0.0)) {
    throw std::invalid_argument("PaperExcitation: need >= 1 period and frequency > 0 Hz");
  }
}

double PaperExcitation::steady_end() const { return blend_s_ + periods_ * 2.0 * M_PI / omega_; }
double PaperExcitation::duration() const { return steady_end() + blend_s_; }

JointSample PaperExcitation::at(double t) const {
  if (t < blend_s_) {
    return lead_in_.at(t);
  }
  if (t >= steady_end()) {
    return lead_out_.at(t - steady_end());
  }
  const double s = t - blend_s_;
  return {amplitude_ * std::sin(omega_ * s), amplitude_ * omega_ * std::cos(omega_ * s),
          -amplitude_ * omega_ * omega_ * std::sin(omega_ * s)};
}

}  // namespace jg::sim
