// Generalized-momentum disturbance observers per joint (READING.md section 3), first and
// second order, parameters apart from state, discretised on the host.
//
// The momentum balance over one sample gives the mean disturbance over that sample
// exactly, with no acceleration: d_k = tau_m - beta - f - (p_k - p_{k-1}) / dT
// (f: the friction prediction, fed into the balance so that the estimate's lag applies
// to the friction too — READING.md section 6). The observer filters d_k by D(s):
//   first order      D = K / (s + K)
//   second order     D = (b1 s + b0) / ((s + K1)(s + K2)), presets
//     lowpass2         b1 = 0,       b0 = K1 K2   (unit DC gain)
//     paper_bandpass   b1 = K1,      b0 = 0       (DC gain 0: a sustained contact fades)
//     paper_improved   b1 = K1 + K3, b0 = K2 K3   (DC gain K3 / K1)
// realised as a sum of first-order sections A_i / (s + K_i) (partial fractions), each
// discretised step-invariantly (exact at the samples for a disturbance constant over each
// sample). Every state is a low-pass of the bounded d_k: nothing integrates without
// bound, so a fixed-point state cannot run away (the textbook form integrates tau_m).
//
// The motor torque in the balance: tau_m of sample k is the torque held over [k-1, k], but
// the momentum difference p_k - p_{k-1} is built from encoder-difference velocities (mean
// velocities over [k-1, k] and [k-2, k-1]): it is the mean momentum change over [k-2, k],
// centred on k-1, half a sample behind that torque. A motor torque step dT between samples
// then leaves dT / 2 in d_k for one sample, an estimate blip of (1 - exp(-K dT)) dT / 2
// (0.07 dT at K = 150/s, 1 kHz) on every joint whose torque steps, contact or not (the
// stop reaction steps the torques by 21 N·m median: docs/history.md, "Isolation after the
// stop: the cause measured"). With align_motor_torque (off by default) the balance takes the
// mean of the last two motor torques, (tau_k + tau_{k-1}) / 2, centred on k-1 like the
// momentum difference: a torque step then balances against the motion it causes. One more
// state per joint (the last motor torque); the first balance (second sample) takes tau_k
// alone, the first sample's torque being no measure of the torque held before it. Off by
// default: the argument holds only for a velocity that is an encoder difference over the
// sample and a torque held over it (the simulated drives). On the real UR10e recordings
// (the controller's measured velocities, not position differences, and measured currents,
// ~94 Hz) the mean put five false alarms into motion_contacts (ctest -R
// cli.real_ur10e_detection): docs/history.md, "Motor torque aligned in the observer".
//
// Q16.16: d_k, section states and output in N·m; the torque mean is midpoint() (exact
// 64-bit sum, one rounding to 0.5 LSB, no overflow possible: the mean lies between its
// operands); decay in (0, 1) held in Q2.30 (a slow
// pole's decay 0.998 would be off by 0.8 % of its distance to 1 in Q16.16), input gains
// likewise in Q2.30 (|gain| < 2, else discretize() reports out_of_range); 1/dT <= 32767 Hz;
// momentum in N·m·s. Each operation rounds to 0.5 LSB and saturates; the disturbance
// (tau_m - beta - f + (p_{k-1} - p_k) / dT) and each section (decay * state + gain * d)
// are one exact 64-bit sum each, rounded once (mac, scale_sum).
#pragma once

#include <cstdint>

#include "jointguard/error.hpp"
#include "jointguard/numeric/qmath.hpp"

namespace jg {

enum class ObserverKind : std::uint8_t { first_order = 0, lowpass2 = 1, paper_bandpass = 2, paper_improved = 3 };

[[nodiscard]] constexpr const char* to_string(ObserverKind k) noexcept {
  switch (k) {
    case ObserverKind::first_order: return "first_order";
    case ObserverKind::lowpass2: return "lowpass2";
    case ObserverKind::paper_bandpass: return "paper_bandpass";
    case ObserverKind::paper_improved: return "paper_improved";
  }
  return "unknown";
}

/// Whether the observer balances the momentum difference with the mean of the last two
/// motor torques by default (header comment).
inline constexpr bool kAlignMotorTorqueDefault = false;

/// Continuous-time gains (host side) [1/s].
struct ObserverGains {
  ObserverKind kind = ObserverKind::first_order;
  double k1 = 60.0, k2 = 0.0, k3 = 0.0;
  /// Balance with the mean of the last two motor torques (header comment); false: tau_k.
  bool align_motor_torque = kAlignMotorTorqueDefault;
};

/// Numerator b1 s + b0 and poles K1, K2 of the preset (first order: b1 = 0, b0 = K, one pole).
struct ObserverTransfer {
  double b1 = 0.0, b0 = 0.0, pole1 = 0.0, pole2 = 0.0;
  int order = 1;
};

[[nodiscard]] constexpr ObserverTransfer transfer_of(const ObserverGains& g) noexcept {
  switch (g.kind) {
    case ObserverKind::first_order: return {0.0, g.k1, g.k1, 0.0, 1};
    case ObserverKind::lowpass2: return {0.0, g.k1 * g.k2, g.k1, g.k2, 2};
    case ObserverKind::paper_bandpass: return {g.k1, 0.0, g.k1, g.k2, 2};
    case ObserverKind::paper_improved: return {g.k1 + g.k3, g.k2 * g.k3, g.k1, g.k2, 2};
  }
  return {};
}

template <class S>
struct ObserverCoeffs {
  std::uint8_t sections = 1;
  precise_coefficient_t<S> decay[2]{};  ///< exp(-K_i dT) (Q2.30 when S is fixed point)
  precise_coefficient_t<S> input_gain[2]{};  ///< (A_i / K_i)(1 - exp(-K_i dT)), |.| < 2
  S inv_dt{};         ///< 1 / dT [1/s]
  bool align_motor_torque = kAlignMotorTorqueDefault;  ///< balance with (tau_k + tau_{k-1}) / 2
};

template <class S>
struct ObserverState {
  S section[2]{};
  S last_momentum{};
  S last_motor_torque{};  ///< tau_{k-1} (used with align_motor_torque)
  S last_output{};
  bool primed = false;
  bool balanced = false;  ///< a balance has been made (the first one has no tau_{k-1})
};

/// Host side: partial fractions and step-invariant discretisation in double, converted to
/// S with a range check. Poles closer than 1 % are separated by 1 % (documented: the
/// response changes by far less than the noise). `out` written only on success.
template <class S>
[[nodiscard]] Error discretize(const ObserverGains& g, double dt, ObserverCoeffs<S>& out) noexcept {
  if (!(dt > 0.0) || dt > 0.1) {
    return Error::invalid_parameter;
  }
  ObserverTransfer t = transfer_of(g);
  if (!detail::is_finite(t.b0) || !detail::is_finite(t.b1) || !(t.pole1 > 0.0) || (t.order == 2 && !(t.pole2 > 0.0))) {
    return Error::invalid_parameter;
  }
  double poles[2] = {t.pole1, t.pole2};
  double residues[2] = {t.b0, 0.0};  // first order: A = K
  if (t.order == 2) {
    if (std::fabs(poles[1] - poles[0]) < 0.01 * poles[0]) {
      poles[1] = poles[0] * 1.01;
    }
    residues[0] = (t.b0 - t.b1 * poles[0]) / (poles[1] - poles[0]);
    residues[1] = (t.b1 * poles[1] - t.b0) / (poles[1] - poles[0]);
  }
  NumericStatus st{};
  ObserverCoeffs<S> c{};
  c.sections = static_cast<std::uint8_t>(t.order);
  for (int i = 0; i < t.order; ++i) {
    const double a = std::exp(-poles[i] * dt);
    c.decay[i] = convert<precise_coefficient_t<S>>(a, st);
    c.input_gain[i] = convert<precise_coefficient_t<S>>(residues[i] / poles[i] * (1.0 - a), st);
  }
  c.inv_dt = convert<S>(1.0 / dt, st);
  c.align_motor_torque = g.align_motor_torque;
  if (!st.ok()) {
    return Error::out_of_range;
  }
  out = c;
  return Error::ok;
}

struct ObserverInputStatus {
  Error error = Error::ok;  ///< not_finite: inputs rejected, last output repeated
};

namespace detail {
/// (tau_k + tau_{k-1}) / 2 after the first balance, tau_k before it; remembers tau_k. Out of
/// line and cold: with align_motor_torque off (the default) the cycle pays one flag test
/// only, not the registers this path would hold (docs/mcu.md: 43 instructions inline).
template <class S>
[[gnu::noinline, gnu::cold]] S aligned_motor_torque(ObserverState<S>& st, S motor_torque) noexcept {
  const S mean = st.balanced ? midpoint(motor_torque, st.last_motor_torque) : motor_torque;
  st.last_motor_torque = motor_torque;
  st.balanced = true;
  return mean;
}
}  // namespace detail

/// One sample. Returns the estimate r of the disturbance d - f (d = tau_f - tau_ext with
/// the plant's sign: the external torque estimate is -r). Non-finite inputs (float) are
/// rejected: the state is untouched and the last output is returned with the error set.
template <class S>
[[nodiscard]] constexpr S observer_step(const ObserverCoeffs<S>& c, ObserverState<S>& st, S momentum, S motor_torque,
                                        S beta, S friction, ObserverInputStatus* status = nullptr) noexcept {
  if constexpr (!is_q_v<S>) {
    if (!detail::all_finite(momentum, motor_torque, beta, friction)) {
      if (status != nullptr) {
        status->error = Error::not_finite;
      }
      return st.last_output;
    }
  }
  if (status != nullptr) {
    status->error = Error::ok;
  }
  if (!st.primed) {  // the first sample has no momentum difference yet
    st.last_momentum = momentum;
    st.primed = true;
    return st.last_output;
  }
  // The torque held over [k-1, k], or its mean with the one before, centred on k-1 like
  // the momentum difference (header comment). The first balance takes tau_k alone, as the
  // former balance: the first velocity is no encoder difference (no earlier position), and
  // the first sample's torque need not be the one held before it (a drive starting, or a
  // simulation started at rest, measures no torque yet while the arm is held: half the
  // holding torque would read as a disturbance; measured: a false alarm at the second
  // sample of the paper scenario at 125 Hz).
  // Off: one flag test and nothing else (the Q16.16 estimator's budget).
  const S balance_torque = c.align_motor_torque ? detail::aligned_motor_torque(st, motor_torque) : motor_torque;
  // One product and one rounding: (p_k - p_{k-1}) / dT enters the balance exactly.
  // The balance's differences and the disturbance are intermediate terms (QTerm in fixed
  // point): an addend, factors of the filter sections' products.
  const term_t<S> disturbance =
      mac_term(sub_term(sub_term(balance_torque, beta), friction), sub_term(st.last_momentum, momentum), c.inv_dt);
  st.last_momentum = momentum;
  if (c.sections == 0U) {  // no section: the estimate is 0
    st.last_output = S{};
    return st.last_output;
  }
  st.section[0] = scale_sum(c.decay[0], st.section[0], c.input_gain[0], disturbance);
  S out = st.section[0];
  if (c.sections > 1U) {
    st.section[1] = scale_sum(c.decay[1], st.section[1], c.input_gain[1], disturbance);
    out = out + st.section[1];
  }
  st.last_output = out;
  return out;
}

}  // namespace jg
