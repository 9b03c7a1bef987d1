#include "sim/apply_effects.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "dynamics/sensitivity.hpp"

namespace jg::sim {
namespace {

std::string joint_text(int joint, const std::string& what) { return "joint " + std::to_string(joint) + ": " + what; }

/// Keeps a LuGre level physical (the friction truth refuses non-positive levels).
double positive(double v) { return std::max(v, 1e-6); }

/// One direction's Coulomb and static levels changed by b[0], b[1] N·m. The plant scales the
/// negative direction's levels; the positive direction's change is the levels' change with
/// the negative direction scaled back.
void apply_one_sided(const robot::PlantEffect& e, JointFrictionTruth& f, std::ostringstream& os) {
  auto& lugre = f.lugre;
  const auto& b = e.coefficients;
  const double tc = lugre.tau_c, ts = lugre.tau_s;
  if (e.setting.at("side") < 0.0) {
    f.effects.negative_tau_c_scale *= positive(tc + b[0]) / tc;
    f.effects.negative_tau_s_scale *= positive(ts + b[1]) / ts;
  } else {
    lugre.tau_c = positive(tc + b[0]);
    lugre.tau_s = positive(ts + b[1]);
    f.effects.negative_tau_c_scale *= tc / lugre.tau_c;
    f.effects.negative_tau_s_scale *= ts / lugre.tau_s;
  }
  os << "asymmetric_friction: " << (e.setting.at("side") < 0.0 ? "negative" : "positive") << " direction's Coulomb level "
     << b[0] << " N·m, static level " << b[1] << " N·m off";
}

/// A friction effect of joint j into its friction truth f (what was set, into os); false:
/// not a friction effect.
bool apply_friction_effect(const robot::PlantEffect& e, JointFrictionTruth& f, std::ostringstream& os) {
  auto& lugre = f.lugre;
  const auto& b = e.coefficients;
  const bool model_curve = e.setting.count("model_curve") != 0U;
  if (e.effect == robot::Effect::coulomb) {
    // The model's Coulomb level alone, or (the generic sign shape) the whole level curve.
    os << "coulomb: tau_c " << lugre.tau_c;
    lugre.tau_c = positive(lugre.tau_c + b[0]);
    if (!model_curve) lugre.tau_s = positive(lugre.tau_s + b[0]);
    os << " -> " << lugre.tau_c << " N·m";
  } else if (e.effect == robot::Effect::viscous) {
    os << "viscous: sigma2 " << lugre.sigma2;
    lugre.sigma2 = std::max(0.0, lugre.sigma2 + b[0]);
    os << " -> " << lugre.sigma2 << " N·m·s/rad";
  } else if (e.effect == robot::Effect::stribeck && model_curve) {
    os << "stribeck: tau_s " << lugre.tau_s;
    lugre.tau_s = positive(lugre.tau_s + b[0]);
    os << " -> " << lugre.tau_s << " N·m";
  } else if (e.effect == robot::Effect::stribeck) {
    // The fitted shape itself: an excess at low speed with its own Stribeck velocity.
    f.effects.stribeck_extra_nm = b[0];
    f.effects.stribeck_extra_w_s = e.setting.at("w_s");
    os << "stribeck: " << b[0] << " N·m extra below " << f.effects.stribeck_extra_w_s << " rad/s";
  } else if (e.effect == robot::Effect::presliding && e.setting.count("sigma0_ratio") != 0U) {
    os << "presliding: sigma0 " << lugre.sigma0;
    lugre.sigma0 = positive(lugre.sigma0 * (e.setting.at("sigma0_ratio") * b[0] + (1.0 - b[0])));
    os << " -> " << lugre.sigma0 << " N·m/rad";
  } else if (e.effect == robot::Effect::presliding) {
    // The fitted Dahl shape itself (a LuGre bristle stiffness would change the whole curve),
    // with its law (1 exponential, 2 hyperbolic).
    f.effects.dahl_extra_nm = b[0];
    f.effects.dahl_displacement_rad = e.setting.at("displacement_rad");
    f.effects.dahl_exponent = e.setting.count("law") != 0U ? static_cast<int>(e.setting.at("law")) : 1;
    os << "presliding: Dahl shape " << b[0] << " N·m over " << f.effects.dahl_displacement_rad << " rad"
       << (f.effects.dahl_exponent == 2 ? " (hyperbolic law)" : "");
  } else if (e.effect == robot::Effect::asymmetric_friction && e.setting.count("side") != 0U) {
    apply_one_sided(e, f, os);
  } else if (e.effect == robot::Effect::asymmetric_friction) {
    // The plant scales the Coulomb/static levels by 1 +/- a: a level difference b0 is a = b0 / tau_c.
    f.effects.asymmetry = std::clamp(f.effects.asymmetry + b[0] / lugre.tau_c, -0.95, 0.95);
    if (b.size() > 1) f.effects.viscous_asymmetry += b[1];
    os << "asymmetric_friction: asymmetry " << f.effects.asymmetry << ", viscous " << f.effects.viscous_asymmetry
       << " N·m·s/rad";
  } else if (e.effect == robot::Effect::position_ripple) {
    f.effects.ripple_periods_per_rev = e.setting.at("periods_per_rev");
    f.effects.ripple_amplitude = std::hypot(b[0], b[1]);
    f.effects.ripple_phase = std::atan2(b[1], b[0]);
    os << "position_ripple: " << f.effects.ripple_amplitude << " N·m, " << f.effects.ripple_periods_per_rev << " per turn";
  } else if (e.effect == robot::Effect::temperature_drift) {
    // The fitted shape itself: the level, not the viscous term, drifts.
    f.effects.drift_extra_nm = b[0];
    f.effects.drift_extra_time_constant_s = e.setting.at("time_constant_s");
    os << "temperature_drift: level + " << b[0] << " N·m (1 - exp(-t / " << f.effects.drift_extra_time_constant_s << " s))";
  } else if (e.effect == robot::Effect::load_dependent_friction) {
    // By the power flow: the back-driven coefficient of its own (before: the driving one's).
    const double backdriven = f.effects.load_coefficient_backdriven >= 0.0 ? f.effects.load_coefficient_backdriven
                                                                           : f.effects.load_coefficient;
    f.effects.load_coefficient += b[0];
    if (e.setting.count("power_flow") != 0U) f.effects.load_coefficient_backdriven = std::max(0.0, backdriven + b[1]);
    os << "load_dependent_friction: " << f.effects.load_coefficient << " N·m per N·m";
    if (e.setting.count("power_flow") != 0U) os << " (back-driven " << f.effects.load_coefficient_backdriven << ")";
  } else {
    return false;
  }
  return true;
}

/// A rotor or drive effect of joint j (0-based) into the setup (what was set, into os);
/// false: not one.
bool apply_drive_effect(const robot::PlantEffect& e, std::size_t j, SimulationSetup& s, std::ostringstream& os) {
  auto& drive = s.sensors.drives[j];
  const auto& b = e.coefficients;
  if (e.effect == robot::Effect::inertia_error) {
    auto& link = s.plant.links[j];
    os << "inertia_error: rotor inertia " << link.rotor_inertia;
    link.rotor_inertia = std::max(0.0, link.rotor_inertia + b[0]);
    os << " -> " << link.rotor_inertia << " kg·m²";
  } else if (e.effect == robot::Effect::torque_constant) {
    // Measured = (1 + b) x true torque; the drive's true K_I = nominal (1 + error) and the
    // measurement is true / (1 + error).
    drive.torque_constant_error = (1.0 + drive.torque_constant_error) / (1.0 + b[0]) - 1.0;
    os << "torque_constant: true K_I = nominal x " << 1.0 + drive.torque_constant_error;
    if (e.setting.count("saturation") != 0U) {
      // Measured / true = 1 + c |tau|, tau = K i: the true K falls by c K per ampere.
      auto& sat = s.sensors.torque_constant_saturation_per_a;
      sat.resize(s.sensors.drives.size(), 0.0);
      sat[j] += b[1] * drive.torque_constant_nominal;
      os << ", saturating " << sat[j] << " per A";
    }
  } else if (e.effect == robot::Effect::current_offset) {
    drive.current_offset_a += b[0] / drive.torque_constant_nominal;
    os << "current_offset: " << drive.current_offset_a << " A";
  } else {
    return false;
  }
  return true;
}

/// One torque-channel effect of joint j (0-based) into the setup.
void apply_effect(const robot::PlantEffect& e, std::size_t j, int joint, SimulationSetup& s, std::vector<double>& delays,
                  EffectsReport& r) {
  auto& f = s.plant.friction[j];
  const auto& b = e.coefficients;
  // Effects made in memory (the diagnosis's) are checked as the file reader checks them.
  if (const robot::EffectProblem problem = robot::simulation_problem(e); !problem.field.empty()) {
    r.not_modelled.push_back(joint_text(joint, problem.what));
    return;
  }
  std::ostringstream os;
  os.precision(4);
  if (!apply_friction_effect(e, f, os) && !apply_drive_effect(e, j, s, os)) {
    if (e.effect == robot::Effect::time_delay && b[0] > 0.0) {
      // A lead is the recording's motion signals being older than its torques (delay_s < 0):
      // the simulation's motion is exact, and its current channel cannot read ahead.
      os << "time_delay: the torque leads the motion by " << 1000.0 * b[0] << " ms (old motion signals): the simulated current channel cannot read ahead";
      r.not_modelled.push_back(joint_text(joint, os.str()));
      return;
    }
    if (e.effect == robot::Effect::time_delay) {
      delays.push_back(-b[0]);
      return;  // one delay for all drives' current channels, set below
    }
    r.not_modelled.push_back(joint_text(joint, e.effect + ": the plant has no setting for it"));
    return;
  }
  r.applied.push_back(joint_text(joint, os.str()));
}

/// Elastic gear of joint j (0-based) from the deflection channel's findings. Without an
/// elastic model in the setup, the other joints get a stiff gear (deflection below one
/// link-encoder count) and the plant rate is raised so that RK4 resolves the stiff modes.
void apply_gear(const robot::PlantEffect& e, std::size_t j, SimulationSetup& s, EffectsReport& r) {
  const bool has_k = e.params.count("stiffness_nm_per_rad") != 0U;
  const bool has_gap = e.params.count("gap_rad") != 0U;
  if (!has_k && !has_gap) return;
  const std::size_t n = s.plant.links.size();
  if (s.plant.elasticity.empty()) {
    if (!has_k) {
      r.not_modelled.push_back(joint_text(e.joint, "backlash: a dead zone needs the gear's stiffness, which was not found"));
      return;
    }
    s.plant.elasticity.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double k = 2e6;
      s.plant.elasticity[i] = {k, 2.0 * 0.7 * std::sqrt(k * std::max(s.plant.links[i].rotor_inertia, 1e-6)), 0.0};
    }
    s.plant.plant_rate_hz = std::max(s.plant.plant_rate_hz, 24000.0);
  }
  auto& g = s.plant.elasticity[j];
  std::ostringstream os;
  os.precision(4);
  if (has_k) {
    g.stiffness = e.params.at("stiffness_nm_per_rad");
    // Damping is not identified from the deflection: a lightly damped gear (ratio 0.1).
    g.damping = 2.0 * 0.1 * std::sqrt(g.stiffness * std::max(s.plant.links[j].rotor_inertia, 1e-6));
    os << "joint_elasticity: stiffness " << g.stiffness << " N·m/rad (damping ratio 0.1 assumed)";
  } else {
    g.backlash_rad = std::max(0.0, e.params.at("gap_rad"));
    os << "backlash: " << g.backlash_rad << " rad";
  }
  r.applied.push_back(joint_text(e.joint, os.str()));
}

/// A payload or a link's mass error (arm level).
void apply_arm_effect(const robot::PlantEffect& e, SimulationSetup& s, EffectsReport& r) {
  std::ostringstream os;
  os.precision(4);
  if (e.effect == robot::Effect::link_inertial_error && e.coefficients.size() >= 4 && e.setting.count("link") != 0U) {
    // Mass and first moment changed, the rotational inertia about the link origin kept.
    const auto l = static_cast<std::size_t>(e.setting.at("link")) - 1;
    if (l >= s.plant.links.size()) {
      r.not_modelled.push_back("arm: link_inertial_error on a link the simulation does not have");
      return;
    }
    auto& link = s.plant.links[l];
    os << "arm: link " << l + 1 << " mass " << link.mass;
    link = with_mass_first_moment_change(link, e.coefficients[0],
                                         Eigen::Vector3d(e.coefficients[1], e.coefficients[2], e.coefficients[3]));
    os << " -> " << link.mass << " kg";
  } else if (e.effect == robot::Effect::payload && e.coefficients.size() >= 4 && e.coefficients[0] > 0.0) {
    const double m = e.coefficients[0];
    const auto it = e.setting.find("picked_up_at_s");
    const double t_s = it != e.setting.end() ? it->second : 0.0;
    s.plant.payload = PayloadChange{t_s, m, Eigen::Vector3d(e.coefficients[1], e.coefficients[2], e.coefficients[3]) / m};
    os << "arm: payload " << m << " kg from t = " << t_s << " s";
  } else {
    r.not_modelled.push_back("arm: " + e.effect + ": the plant has no setting for it");
    return;
  }
  r.applied.push_back(os.str());
}
}  // namespace


EffectsReport apply_plant_effects(const std::vector<robot::PlantEffect>& effects, double dt, SimulationSetup& s) {
  EffectsReport r;
  // The controller keeps the nominal model: what the diagnosis found is the plant's truth.
  if (s.nominal_links.empty()) s.nominal_links = s.plant.links;
  std::vector<double> delays;
  for (const auto& e : effects) {
    if (e.joint == 0) {
      apply_arm_effect(e, s, r);
      continue;
    }
    const auto j = static_cast<std::size_t>(e.joint - 1);
    if (j >= s.plant.links.size() || j >= s.plant.friction.size() || j >= s.sensors.drives.size()) {
      r.not_modelled.push_back(joint_text(e.joint, e.effect + ": no such joint (or no friction model) in the simulation"));
      continue;
    }
    if (e.effect == robot::Effect::joint_elasticity || e.effect == robot::Effect::backlash) {
      apply_gear(e, j, s, r);
    } else {
      apply_effect(e, j, e.joint, s, delays, r);
    }
  }
  if (!delays.empty()) {
    // One delay of the current channel for all drives (one clock): the median of the joints'.
    std::nth_element(delays.begin(), delays.begin() + static_cast<std::ptrdiff_t>(delays.size() / 2), delays.end());
    const double delay = delays[delays.size() / 2];
    s.sensors.current_delay_samples = std::max(0, static_cast<int>(std::lround(delay / dt)));
    std::ostringstream os;
    os.precision(4);
    os << "time_delay: current channel " << s.sensors.current_delay_samples << " samples (" << 1000.0 * delay << " ms fitted)";
    r.applied.push_back(os.str());
  }
  return r;
}

}  // namespace jg::sim
