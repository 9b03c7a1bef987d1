#include "plant/friction_truth.hpp"

#include <algorithm>
#include <cmath>

namespace jg::sim {
namespace {
/// 0 -> 1 over the warm-up; the plain exponential unless the second shapes are set.
double drift_profile(const FrictionEffects& e, double time_s) {
  double profile = e.drift_ramp_s > 0.0 ? std::min(time_s / e.drift_ramp_s, 1.0)
                                        : 1.0 - std::exp(-time_s / e.drift_time_constant_s);
  if (e.drift_second_fraction > 0.0) {
    profile = (1.0 - e.drift_second_fraction) * profile +
              e.drift_second_fraction * (1.0 - std::exp(-time_s / e.drift_second_time_constant_s));
  }
  return profile;
}

/// Dahl state after travelling |dx| towards sgn: exponential (i = 1) or hyperbolic (i = 2).
double dahl_step(double zeta, double sgn, double dx_abs, double delta, int exponent) {
  if (exponent != 2) return sgn + (zeta - sgn) * std::exp(-dx_abs / delta);
  const double u = 1.0 - sgn * zeta;  // in [0, 2]: 0 = fully developed
  return sgn * (1.0 - u / (1.0 + u * dx_abs / delta));
}
}  // namespace

double friction_truth_step(const JointFrictionTruth& truth, LuGreTruthState& state, double w, double q,
                           double load_torque, double time_s, double dt) {
  const LuGreParams<double>& p = truth.lugre;
  const FrictionEffects& e = truth.effects;
  const double drift_scale = e.drift != 0.0 ? 1.0 + e.drift * drift_profile(e, time_s) : 1.0;
  const double direction_scale = w > 0.0 ? 1.0 + e.asymmetry : (w < 0.0 ? 1.0 - e.asymmetry : 1.0);
  // Back-driven (load torque against the motion): the gear's other efficiency.
  const double mu = e.load_coefficient_backdriven >= 0.0 && w * load_torque < 0.0 ? e.load_coefficient_backdriven
                                                                                  : e.load_coefficient;
  double tau_c = (p.tau_c + mu * std::fabs(load_torque)) * drift_scale * direction_scale;
  double tau_s = (p.tau_s + mu * std::fabs(load_torque)) * drift_scale * direction_scale;
  double w_s = p.w_s;
  if (w < 0.0) {  // x 1.0 is exact: unchanged when symmetric
    tau_c *= e.negative_tau_c_scale;
    tau_s *= e.negative_tau_s_scale;
    w_s *= e.negative_w_s_scale;
  }
  const double u = w / w_s;
  const double level = tau_c + (tau_s - tau_c) * std::exp(-u * u);
  const double rate = p.sigma0 * std::fabs(w) / level;  // [1/s]
  if (rate > 0.0) {
    const double z_steady = w / rate;  // = s sign(w) / sigma0
    state.z = z_steady + (state.z - z_steady) * std::exp(-rate * dt);
  }
  const double zdot = w - rate * state.z;
  double tau = p.sigma0 * state.z + p.sigma1 * zdot + p.sigma2 * drift_scale * w;
  tau += e.viscous_asymmetry * std::fabs(w);
  const double sgn = w > 0.0 ? 1.0 : (w < 0.0 ? -1.0 : 0.0);
  if (e.stribeck_extra_nm != 0.0) {
    const double v = w / e.stribeck_extra_w_s;
    const double decay = e.stribeck_extra_exponent == 2.0 ? v * v : std::pow(std::fabs(v), e.stribeck_extra_exponent);
    tau += e.stribeck_extra_nm * sgn * std::exp(-decay);
  }
  if (e.dahl_extra_nm != 0.0) {
    const double dx = w * dt;
    if (sgn != 0.0) state.dahl = dahl_step(state.dahl, sgn, std::fabs(dx), e.dahl_displacement_rad, e.dahl_exponent);
    tau += e.dahl_extra_nm * (state.dahl - sgn);
  }
  if (e.drift_extra_nm != 0.0) tau += e.drift_extra_nm * sgn * (1.0 - std::exp(-time_s / e.drift_extra_time_constant_s));
  if (e.ripple_amplitude != 0.0) {
    tau += e.ripple_amplitude * std::sin(e.ripple_periods_per_rev * q + e.ripple_phase);
  }
  if (e.ripple2_amplitude != 0.0) tau += e.ripple2_amplitude * std::sin(e.ripple2_periods_per_rev * q + e.ripple2_phase);
  if (e.viscous_power_nm != 0.0) tau += e.viscous_power_nm * sgn * std::pow(std::fabs(w), e.viscous_power_exponent);
  return tau;
}

double bristle_energy(const JointFrictionTruth& truth, const LuGreTruthState& state) {
  return 0.5 * truth.lugre.sigma0 * state.z * state.z;
}

}  // namespace jg::sim
