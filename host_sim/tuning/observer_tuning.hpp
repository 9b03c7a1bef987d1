// Observer tuning helper: figures of merit of a preset's discrete realisation and gains
// chosen for a target noise level, so presets can be compared at equal noise.
#pragma once

#include "jointguard/observer/momentum_observer.hpp"

namespace jg::tuning {

struct ObserverFigures {
  double delay50_s = 0.0;   ///< first time the step response reaches 50 % of its peak
  double delay90_s = 0.0;   ///< ... 90 % of its peak
  double overshoot = 0.0;   ///< (peak - final) / final for unit-DC presets, else 0
  double dc_gain = 0.0;     ///< response after 10 s (0 for the band-pass)
  double peak = 0.0;        ///< peak of the unit step response
  double noise_gain = 0.0;  ///< output RMS per unit RMS of white motor-torque noise
};

/// Simulates the discrete realisation (double) for a unit step of the disturbance and
/// for its impulse response (noise gain = sqrt(sum h^2)).
ObserverFigures analyse(const ObserverGains& g, double dt);

/// Scales all gains of `shape` by one factor so that the output noise RMS equals
/// `target_noise_rms` for white motor-torque noise of `torque_noise_rms` (bisection).
ObserverGains gains_for_noise(const ObserverGains& shape, double dt, double torque_noise_rms, double target_noise_rms);

/// The default observer for a loop rate: first order, K = 150 1/s from 500 Hz up and
/// K = 250 1/s below. At 125 Hz one sample's momentum balance already averages the
/// disturbance over 8 ms, and K = 150 adds about one more sample of lag; the sweep in
/// docs/observers.md (paper collisions, false alarms) picked 250 there.
[[nodiscard]] constexpr ObserverGains default_gains(double rate_hz) noexcept {
  return {ObserverKind::first_order, rate_hz < 500.0 ? 250.0 : 150.0, 0.0, 0.0};
}

}  // namespace jg::tuning
