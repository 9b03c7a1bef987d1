#include "robot/effect_catalogue.hpp"

#include <cstdlib>

namespace jg::robot {

const std::vector<EffectInfo>& effect_catalogue() {
  using C = EffectChannel;
  using S = EffectScope;
  // One row per cause. `plausible` is what the diagnosis accepts (diagnosis/effects.cpp
  // implausible(), which names these ranges in its notes); `plant` what sim/apply_effects.cpp
  // does with an entry; `fit` the regressor of diagnosis/effects.cpp raw_candidate().
  static const std::vector<EffectInfo> table = {
      {Effect::coulomb, "coulomb", S::joint, C::friction, 1, "", "delta_tau_c [N·m]",
       "the resulting level (the model's plus the change) >= 0; the level at most the largest torque measured",
       "the LuGre Coulomb level (and, for the plain shape, the static level) raised by the change",
       "sgn(w) with a small linear band; or the nominal LuGre curve's tau_c changed alone (model_curve)"},
      {Effect::viscous, "viscous", S::joint, C::friction, 1, "", "delta_sigma2 [N·m·s/rad]",
       "the resulting coefficient >= 0; the slope x the largest speed at most the largest torque measured",
       "the LuGre viscous coefficient sigma2 changed", "the velocity w"},
      {Effect::stribeck, "stribeck", S::joint, C::friction, 1, "w_s", "amplitude [N·m], w_s [rad/s] (or delta_tau_s [N·m])",
       "the static excess (or the model's plus the change) >= 0",
       "an excess sgn(w) a exp(-(w/w_s)^2) beside the LuGre curve; or the static level tau_s changed (model_curve)",
       "sgn(w) exp(-(w/w_s)^2) on a grid of w_s, the chosen one refined between its neighbours; or the nominal curve's tau_s changed alone"},
      {Effect::presliding, "presliding", S::joint, C::friction, 1, "displacement_rad",
       "level [N·m], displacement_rad [rad], sigma0 [N·m/rad] (or sigma0_ratio)",
       "with sigma0_ratio: the resulting bristle stiffness ratio > 0",
       "a Dahl shape of its own (exponential or hyperbolic law); or the LuGre bristle stiffness sigma0 scaled",
       "a Dahl state minus its sign on a grid of displacements, both laws; or softer nominal bristles"},
      {Effect::asymmetric_friction, "asymmetric_friction", S::joint, C::friction, 1, "",
       "tau_c_positive_minus_negative [N·m], viscous_positive_minus_negative [N·m·s/rad] (or one side's levels)",
       "one side's Coulomb and static levels >= 0; twice the level at most the largest torque measured",
       "the negative direction's Coulomb/static levels scaled, a viscous asymmetry; or one side's levels",
       "|sgn w| and |w| (a level and slope per direction); or one direction's nominal levels changed"},
      {Effect::position_ripple, "position_ripple", S::joint, C::friction, 2, "periods_per_rev",
       "amplitude [N·m], period_rad [rad], periods_per_rev, phase_rad",
       "the amplitude at most the largest torque measured; at least 1.5 periods over the range with a rigid body",
       "a ripple a sin(k q + phase) added to the friction", "sin(k q), cos(k q) on a grid of whole k per turn", true},
      {Effect::temperature_drift, "temperature_drift", S::joint, C::friction, 1, "time_constant_s",
       "level_change [N·m], time_constant_s [s]", "time constant within [max(50 dt, 1 s), 3 x the recording]",
       "the friction level rising by a (1 - exp(-t/T))", "sgn(w) (1 - exp(-t/T)) on a grid of T over the recording"},
      {Effect::load_dependent_friction, "load_dependent_friction", S::joint, C::friction, 1, "",
       "coefficient [N·m per N·m] (and coefficient_backdriven)", "coefficient(s) within [0, 0.5] N·m per N·m",
       "friction growing with the gear's transmitted torque (by the power flow: driving and back-driven)",
       "sgn(w) |rigid-body torque|; with power_flow one column where the motor drives, one where the load does"},
      {Effect::payload, "payload", S::arm, C::body, 4, "", "mass_kg [kg], com_x_m, com_y_m, com_z_m [m], picked_up_at_s [s]",
       "0 < mass <= the robot's rated payload (or its own mass); centre within 0.5 m of the flange",
       "a point mass at the flange from picked_up_at_s on (the rigid body's own regressor)",
       "the arm's rigid-body regressor of the last link's mass and first moment, once for all joints (arm level)"},
      {Effect::inertia_error, "inertia_error", S::joint, C::body, 1, "", "delta_inertia [kg·m²]", "+/-1e4 kg·m² (a file)",
       "the joint's reflected rotor inertia changed", "the acceleration from the velocity over +/-30 ms"},
      {Effect::torque_constant, "torque_constant", S::joint, C::sensor, 1, "",
       "scale_error, torque_constant_ratio (and saturation_per_nm [1/N·m], scale_error_equivalent)",
       "error within +/-30 %; with saturation c >= 0 and |e| + c x the largest torque <= 30 %; current data only",
       "the drive's true current-to-torque constant K_I differs from the nominal (and falls with the current)",
       "the model's torque (measured = (1 + e) x true); with saturation also tau |tau|"},
      {Effect::current_offset, "current_offset", S::joint, C::sensor, 1, "", "offset_nm [N·m]",
       "at most the largest torque measured", "a constant offset of the current sensor (amperes through K_I)",
       "a constant column (also what differs at the recording's start)"},
      {Effect::time_delay, "time_delay", S::joint, C::sensor, 1, "", "delay_s [s]", "the torque lags (delay_s > 0) or leads (< 0: old motion signals) the motion by dt/2 to 50 ms, fitted and as the best whole-sample shift; a lead only where told from an inertia error",
       "one delay of all drives' current channels (the median of the joints' lags), in whole samples; a lead is not simulated",
       "the derivative of the model's torque (a first-order delay); once claimed, the exact difference over the delay (setting delay_s)"},
      {Effect::backlash, "backlash", S::joint, C::deflection, 0, "gap_rad", "gap_rad [rad], fraction",
       "torque channel: fraction within [0, 1.5]", "a dead zone in the elastic gear (needs the gear's stiffness)",
       "the load not driven for gap_rad after reversals (torque), or the link/motor deflection itself"},
      {Effect::joint_elasticity, "joint_elasticity", S::joint, C::deflection, 0, "", "stiffness_nm_per_rad [N·m/rad]",
       "stiffness within [1, 1e9] N·m/rad (a file)", "an elastic gear (stiffness, damping ratio 0.1 assumed)",
       "the deflection between motor and link encoders against the load"},
      {Effect::link_inertial_error, "link_inertial_error", S::arm, C::body, 4, "link",
       "link, delta_mass_kg [kg], first moment [kg·m]", "a mass change within the link's own mass; centre within 10 m",
       "the link's mass and first moment changed, its inertia about the origin kept",
       "the rigid-body regressor of one link's mass and first moment (arm level)"},
      {Effect::none, "none", S::neither, C::none, 0, "", "", "", "nothing", "nothing missing beyond the noise"},
  };
  return table;
}

const EffectInfo& effect_info(Effect e) {
  const auto& t = effect_catalogue();
  const auto i = static_cast<std::size_t>(e);
  // The table is in the enum's order (tests/robot/test_effect_catalogue.cpp); an Effect
  // outside it can only come from a cast of a bad number, a programming error.
  if (i >= t.size() || t[i].effect != e) std::abort();
  return t[i];
}

std::string_view effect_name(Effect e) { return effect_info(e).name; }

std::optional<Effect> parse_effect(std::string_view name) {
  for (const auto& row : effect_catalogue()) {
    if (row.name == name) return row.effect;
  }
  return std::nullopt;
}

std::string effect_words() {
  std::string out;
  for (const auto& row : effect_catalogue()) out += (out.empty() ? "" : ", ") + std::string(row.name);
  return out;
}

}  // namespace jg::robot
