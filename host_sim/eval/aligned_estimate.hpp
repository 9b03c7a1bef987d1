// The external torque estimate with the motor torque aligned to the observer's momentum
// difference, on the master's side (used by the isolation decision after the detection).
//
// Why: the observer's balance (observer/momentum_observer.hpp) takes the motor torque of
// sample k, the torque held over [k-1, k], with the momentum difference p_k - p_{k-1}. The
// velocities are position differences (mean velocities over [k-1, k] and [k-2, k-1]), so
// that difference is the mean acceleration over [k-2, k] centred on k-1: half a sample
// behind the torque. A torque that steps by dT between samples k-1 and k then puts dT / 2
// into the disturbance for one sample, which the first-order observer turns into an
// estimate step of (1 - exp(-K dt)) dT / 2 decaying with 1/K (0.07 dT at K = 150/s, 1 kHz),
// on every joint whose own torque steps. The stop reaction steps every joint's torque by
// its damping term (21 N·m median, 60 N·m at the 95th percentile over a 200-collision
// campaign), so the estimate of a joint without any contact torque jumps by several
// newton-metres in the cycle after the detection (docs/history.md, "Isolation after the
// stop: the cause measured").
//
// The aligned estimate pairs the momentum difference with the mean of the last two motor
// torques, (tau_k + tau_{k-1}) / 2. The first-order observer being linear, it is the
// firmware's estimate plus the observer's response to (tau_k - tau_{k-1}) / 2:
//   c_k = a c_{k-1} + (1 - a) (tau_k - tau_{k-1}) / 2,  a = exp(-K dt),  mu_aligned = mu + c_k
// computed from the measured motor torques the master already has. Double precision, host
// side (the firmware's own estimate is unchanged).
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

namespace jg::eval {

class AlignedEstimate {
 public:
  /// `observer_gain_per_s`: the first-order observer's K [1/s]; <= 0 (another observer
  /// kind): the correction stays 0 (enabled() false).
  AlignedEstimate(std::size_t joints, double observer_gain_per_s, double dt)
      : decay_(observer_gain_per_s > 0.0 ? std::exp(-observer_gain_per_s * dt) : 1.0),
        enabled_(observer_gain_per_s > 0.0),
        last_(joints, 0.0),
        correction_(joints, 0.0) {}

  /// One cycle with the measured motor torques [N·m] of this sample (the ones the observer
  /// was fed). The first call only primes (the observer's first sample has no output).
  template <class Vector>
  void step(const Vector& motor_torque) {
    for (std::size_t j = 0; j < last_.size(); ++j) {
      const double tau = motor_torque(static_cast<decltype(motor_torque.size())>(j));
      if (primed_ && enabled_) correction_[j] = decay_ * correction_[j] + (1.0 - decay_) * 0.5 * (tau - last_[j]);
      last_[j] = tau;
    }
    primed_ = true;
  }
  /// What to add to the firmware's external torque estimate of joint j [N·m].
  [[nodiscard]] double correction(std::size_t j) const { return correction_[j]; }
  [[nodiscard]] bool enabled() const { return enabled_; }

 private:
  double decay_;
  bool enabled_;
  bool primed_ = false;
  std::vector<double> last_, correction_;
};

}  // namespace jg::eval
