// The plant's true joint friction: LuGre (integrated exactly for piecewise-constant
// velocity, independently of the firmware's implicit-Euler code) plus optional effects
// that the firmware's model lacks, used as hidden truth by identification and diagnosis.
#pragma once

#include "jointguard/friction/lugre.hpp"

namespace jg::sim {

struct FrictionEffects {
  // position_ripple: tau += A sin(periods_per_rev * q + phase)  (cogging / gear meshing)
  double ripple_amplitude = 0.0;        ///< [N·m]
  double ripple_periods_per_rev = 0.0;  ///< [1/rev]
  double ripple_phase = 0.0;            ///< [rad]
  // asymmetric_friction: Coulomb/static levels scaled by (1 + a) for w > 0, (1 - a) for w < 0
  double asymmetry = 0.0;
  // ... and a viscous slope that differs by direction: tau += viscous_asymmetry |w|
  double viscous_asymmetry = 0.0;  ///< [N·m·s/rad]
  // temperature_drift: all friction levels scaled by 1 + drift (1 - exp(-t / tau))
  double drift = 0.0;
  double drift_time_constant_s = 600.0;
  // load_dependent_friction: Coulomb level += mu |tau_load|, tau_load = the torque the gear
  // transmits (motor torque less friction)
  double load_coefficient = 0.0;
  // Shapes added to the friction as the diagnosis fits them (written back by `diagnose
  // --model-out`, sim/apply_effects.cpp), where they are not a change of a LuGre parameter:
  // Stribeck excess: tau += A sgn(w) exp(-(w / w_s)^2)
  double stribeck_extra_nm = 0.0;
  double stribeck_extra_w_s = 0.01;  ///< [rad/s]
  // presliding (Dahl): tau += A (zeta - sgn w), zeta -> sgn w over a displacement delta
  double dahl_extra_nm = 0.0;
  double dahl_displacement_rad = 1e-3;
  // temperature drift of the level: tau += D sgn(w) (1 - exp(-t / tau))
  double drift_extra_nm = 0.0;
  double drift_extra_time_constant_s = 600.0;
  // current_offset / torque_constant are sensor/actuator effects (see sensors.hpp).

  // Second shapes of the same causes, default off (outputs unchanged when off). Used by the
  // second concealed-effect generator (diagnosis/testset_second.cpp), whose shapes must
  // differ from the ones the diagnosis fits.
  // position_ripple, a second harmonic: tau += A2 sin(periods2 * q + phase2)
  double ripple2_amplitude = 0.0;        ///< [N·m]
  double ripple2_periods_per_rev = 0.0;  ///< [1/rev]
  double ripple2_phase = 0.0;            ///< [rad]
  // asymmetric_friction of the whole Stribeck curve: for w < 0 the Coulomb level, the
  // static level and the Stribeck velocity are scaled separately (1 = symmetric).
  double negative_tau_c_scale = 1.0;
  double negative_tau_s_scale = 1.0;
  double negative_w_s_scale = 1.0;
  // temperature_drift profile: a linear ramp over drift_ramp_s (> 0) instead of the first
  // exponential, and/or a second time constant carrying drift_second_fraction of the drift
  // (a two-stage warm-up: gear oil fast, housing slow).
  double drift_ramp_s = 0.0;                 ///< [s], 0 = exponential
  double drift_second_fraction = 0.0;        ///< [0, 1]
  double drift_second_time_constant_s = 1.0; ///< [s]
  // load_dependent_friction with a gear efficiency that depends on the power flow: the
  // coefficient when the load back-drives the gear (load torque against the velocity);
  // < 0 = the same as load_coefficient.
  double load_coefficient_backdriven = -1.0;
  // viscous: a shear-thinning term tau += c sgn(w) |w / (1 rad/s)|^p
  double viscous_power_nm = 0.0;  ///< c [N·m at 1 rad/s]
  double viscous_power_exponent = 1.0;
  // Stribeck excess law: exp(-|w / w_s|^exponent) (2 = Gaussian, 1 = exponential)
  double stribeck_extra_exponent = 2.0;
  // presliding law of the Dahl state: du/ds = -u^i / delta, u = 1 - sgn(w) zeta, s the
  // distance travelled (i = 1: exponential, the shape above; i = 2: Dahl's hyperbolic law)
  int dahl_exponent = 1;
};

struct JointFrictionTruth {
  LuGreParams<double> lugre{};
  FrictionEffects effects{};
};

struct LuGreTruthState {
  double z = 0.0;     ///< bristle deflection [rad]
  double dahl = 0.0;  ///< state of the added presliding shape (FrictionEffects::dahl_extra_nm)
};

/// Advances z over `dt` with velocity w held and returns the friction torque at the end.
/// z' = w - sigma0 |w| z / s(w) is linear in z for constant w: exact exponential step.
/// `time_s` and `load_torque` feed the drift and load effects; `q` the ripple.
double friction_truth_step(const JointFrictionTruth& truth, LuGreTruthState& state, double w, double q,
                           double load_torque, double time_s, double dt);

/// Energy stored in the bristles, 0.5 sigma0 z^2 [J] (for the plant's energy balance).
double bristle_energy(const JointFrictionTruth& truth, const LuGreTruthState& state);

}  // namespace jg::sim
