#include "plant/friction_truth.hpp"

#include <cmath>

namespace jg::sim {

double friction_truth_step(const JointFrictionTruth& truth, LuGreTruthState& state, double w, double q,
                           double load_torque, double time_s, double dt) {
  const LuGreParams<double>& p = truth.lugre;
  const FrictionEffects& e = truth.effects;
  const double drift_scale =
      e.drift != 0.0 ? 1.0 + e.drift * (1.0 - std::exp(-time_s / e.drift_time_constant_s)) : 1.0;
  const double direction_scale = w > 0.0 ? 1.0 + e.asymmetry : (w < 0.0 ? 1.0 - e.asymmetry : 1.0);
  const double tau_c = (p.tau_c + e.load_coefficient * std::fabs(load_torque)) * drift_scale * direction_scale;
  const double tau_s = (p.tau_s + e.load_coefficient * std::fabs(load_torque)) * drift_scale * direction_scale;
  const double u = w / p.w_s;
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
    tau += e.stribeck_extra_nm * sgn * std::exp(-v * v);
  }
  if (e.dahl_extra_nm != 0.0) {
    const double dx = w * dt;
    if (sgn != 0.0) state.dahl = sgn + (state.dahl - sgn) * std::exp(-std::fabs(dx) / e.dahl_displacement_rad);
    tau += e.dahl_extra_nm * (state.dahl - sgn);
  }
  if (e.drift_extra_nm != 0.0) tau += e.drift_extra_nm * sgn * (1.0 - std::exp(-time_s / e.drift_extra_time_constant_s));
  if (e.ripple_amplitude != 0.0) {
    tau += e.ripple_amplitude * std::sin(e.ripple_periods_per_rev * q + e.ripple_phase);
  }
  return tau;
}

double bristle_energy(const JointFrictionTruth& truth, const LuGreTruthState& state) {
  return 0.5 * truth.lugre.sigma0 * state.z * state.z;
}

}  // namespace jg::sim
