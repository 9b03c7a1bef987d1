#include "diagnosis/testset_second.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

#include "plant/friction_truth.hpp"

namespace jg::diag {
namespace {
constexpr double kBacklashGearStiffness = 1.5e4;  ///< [N·m/rad] small-deflection stiffness, known to the model
constexpr double kBacklashGearHardening = 2e-3;   ///< [rad] deflection where the stiffness has doubled

/// The joint's reference motion as the plant will see it: position, velocity, the load the
/// gear transmits (rigid-body inverse dynamics: the motor torque less the friction, as the
/// plant feeds load-dependent friction) and the motor torque (the load plus Coulomb and
/// viscous friction: what the current carries).
struct ReferenceMotion {
  std::vector<double> t, q, w, load, motor;
  double dt = 0.0;
};

ReferenceMotion reference_motion(const sim::SimulationSetup& s, std::size_t j) {
  ReferenceMotion m;
  m.dt = 1.0 / s.control_rate_hz;
  const sim::ArmDynamics dyn(s.plant.links, s.plant.gravity);
  const auto& p = s.plant.friction[j].lugre;
  const auto jj = static_cast<Eigen::Index>(j);
  for (double t = 0.0; t <= s.trajectory->duration(); t += m.dt) {
    const auto x = s.trajectory->at(t);
    const double w = x.dq(jj);
    m.t.push_back(t);
    m.q.push_back(x.q(jj));
    m.w.push_back(w);
    m.load.push_back(dyn.inverse_dynamics(x.q, x.dq, x.ddq)(jj));
    m.motor.push_back(m.load.back() + p.tau_c * (w > 0.0 ? 1.0 : (w < 0.0 ? -1.0 : 0.0)) + p.sigma2 * w);
  }
  return m;
}

/// RMS of the friction difference between two truths over the reference motion, by the
/// plant's own friction code (so every shape is measured as the plant will apply it).
double friction_difference_rms(const sim::JointFrictionTruth& base, const sim::JointFrictionTruth& changed,
                               const ReferenceMotion& m) {
  sim::LuGreTruthState sa, sb;
  double acc = 0.0;
  for (std::size_t k = 0; k < m.w.size(); ++k) {
    const double fa = sim::friction_truth_step(base, sa, m.w[k], m.q[k], m.load[k], m.t[k], m.dt);
    const double fb = sim::friction_truth_step(changed, sb, m.w[k], m.q[k], m.load[k], m.t[k], m.dt);
    acc += (fb - fa) * (fb - fa);
  }
  return std::sqrt(acc / static_cast<double>(std::max<std::size_t>(1, m.w.size())));
}

/// Scales the shape's size `x` until its friction difference has RMS `target` (exact in one
/// step for shapes linear in x; three steps for the mildly nonlinear ones).
template <class Set>
void calibrate(sim::JointFrictionTruth& truth, const ReferenceMotion& m, double target, double x0, Set set) {
  const sim::JointFrictionTruth base = truth;
  double x = x0;
  for (int it = 0; it < 3; ++it) {
    sim::JointFrictionTruth trial = base;
    set(trial, x);
    const double rms = friction_difference_rms(base, trial, m);
    if (!(rms > 0.0)) break;
    x *= target / rms;
  }
  set(truth, x);
}

/// Dahl's hyperbolic presliding law (exponent 2) at 40 % of the Coulomb level; the
/// displacement over which it develops is bisected so that its RMS is `target`.
void hyperbolic_presliding(sim::JointFrictionTruth& truth, const ReferenceMotion& m, double target) {
  const sim::JointFrictionTruth base = truth;
  auto with = [&](double delta) {
    sim::JointFrictionTruth t = base;
    t.effects.dahl_extra_nm = 0.4 * base.lugre.tau_c;
    t.effects.dahl_exponent = 2;
    t.effects.dahl_displacement_rad = delta;
    return t;
  };
  double lo = std::log(1e-6), hi = std::log(0.5);  // rms rises with the displacement
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (lo + hi);
    (friction_difference_rms(base, with(std::exp(mid)), m) < target ? lo : hi) = mid;
  }
  truth = with(std::exp(0.5 * (lo + hi)));
}

/// Friction shapes: the amplitude is the RMS of the friction change over the reference motion.
bool apply_friction_shape(robot::Effect effect, sim::JointFrictionTruth& f, const ReferenceMotion& m, double a,
                          std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto& e = f.effects;
  if (effect == robot::Effect::coulomb) {  // the whole curve scaled (Coulomb and static level together)
    const double c0 = f.lugre.tau_c, s0 = f.lugre.tau_s;
    calibrate(f, m, a, 0.05, [&](sim::JointFrictionTruth& t, double r) { t.lugre.tau_c = c0 * (1.0 + r); t.lugre.tau_s = s0 * (1.0 + r); });
  } else if (effect == robot::Effect::viscous) {  // shear-thinning grease: c sgn(w) |w|^p, p in [0.5, 0.8]
    e.viscous_power_exponent = 0.5 + 0.3 * unit(rng);
    calibrate(f, m, a, 1.0, [](sim::JointFrictionTruth& t, double c) { t.effects.viscous_power_nm = c; });
  } else if (effect == robot::Effect::stribeck) {  // exponential law, 1.5-3x wider than the nominal curve
    e.stribeck_extra_exponent = 1.0;
    e.stribeck_extra_w_s = f.lugre.w_s * (1.5 + 1.5 * unit(rng));
    calibrate(f, m, a, 1.0, [](sim::JointFrictionTruth& t, double s) { t.effects.stribeck_extra_nm = s; });
  } else if (effect == robot::Effect::presliding) {
    hyperbolic_presliding(f, m, a);
  } else if (effect == robot::Effect::asymmetric_friction) {  // the negative direction's whole Stribeck curve
    const double s_share = 0.3 + 1.2 * unit(rng), w_scale = 0.6 + 1.0 * unit(rng);
    calibrate(f, m, a, 0.05, [&](sim::JointFrictionTruth& t, double r) {
      t.effects.negative_tau_c_scale = 1.0 + r;
      t.effects.negative_tau_s_scale = 1.0 + s_share * r;
      t.effects.negative_w_s_scale = w_scale;
    });
  } else if (effect == robot::Effect::position_ripple) {  // gear meshing: fundamental and second harmonic
    e.ripple_periods_per_rev = std::floor(10.0 + 60.0 * unit(rng));
    e.ripple2_periods_per_rev = 2.0 * e.ripple_periods_per_rev;
    e.ripple_phase = 6.283 * unit(rng);
    e.ripple2_phase = 6.283 * unit(rng);
    const double share = 0.4 + 0.4 * unit(rng);  // second harmonic relative to the first
    calibrate(f, m, a, 1.0, [&](sim::JointFrictionTruth& t, double x) {
      t.effects.ripple_amplitude = x;
      t.effects.ripple2_amplitude = share * x;
    });
  } else if (effect == robot::Effect::temperature_drift) {  // a linear ramp, or a two-stage warm-up
    const double span = m.t.empty() ? 1.0 : m.t.back();
    if (unit(rng) < 0.5) {
      e.drift_ramp_s = span * (0.5 + unit(rng));
    } else {
      e.drift_time_constant_s = 2.0 + 4.0 * unit(rng);
      e.drift_second_fraction = 0.3 + 0.4 * unit(rng);
      e.drift_second_time_constant_s = span * (1.0 + 2.0 * unit(rng));
    }
    calibrate(f, m, a, 0.05, [](sim::JointFrictionTruth& t, double d) { t.effects.drift = d; });
  } else if (effect == robot::Effect::load_dependent_friction) {  // efficiency by power flow: back-driven 20-50 %
    const double backdriven_share = 0.2 + 0.3 * unit(rng);
    calibrate(f, m, a, 0.01, [&](sim::JointFrictionTruth& t, double mu) {
      t.effects.load_coefficient = mu;
      t.effects.load_coefficient_backdriven = backdriven_share * mu;
    });
  } else {
    return false;
  }
  return true;
}

/// Mass `dm` added at `p` (link frame) to a link: centre and inertia by the parallel-axis theorem.
void add_point_mass(sim::PlantLink& link, double dm, const Eigen::Vector3d& p) {
  const double m0 = link.mass;
  const Eigen::Vector3d c = (m0 * link.com + dm * p) / (m0 + dm);
  auto shift = [](double m, const Eigen::Vector3d& d) {
    return m * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  };
  link.inertia_com = link.inertia_com + shift(m0, link.com - c) + shift(dm, p - c);
  link.com = c;
  link.mass = m0 + dm;
}

/// The arm's bodies: payload, link mass, link inertia.
bool apply_body_shape(robot::Effect effect, std::size_t j, double a, sim::SimulationSetup& s, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  if (effect == robot::Effect::payload) {  // a rigid body (a box), centre off the flange's axis
    const double mass = a / 3.0;
    const Eigen::Vector3d dims(0.08 + 0.12 * unit(rng), 0.05 + 0.1 * unit(rng), 0.05 + 0.1 * unit(rng));
    const Eigen::Vector3d centre(0.1 + 0.1 * unit(rng), 0.03 + 0.07 * unit(rng), -0.05 + 0.1 * unit(rng));
    sim::PayloadChange p{0.0, mass, centre};
    p.inertia_com = (mass / 12.0 * Eigen::Vector3d(dims.y() * dims.y() + dims.z() * dims.z(),
                                                   dims.x() * dims.x() + dims.z() * dims.z(),
                                                   dims.x() * dims.x() + dims.y() * dims.y())).asDiagonal();
    s.plant.payload = p;
  } else if (effect == robot::Effect::link_inertial_error) {
    // A local mass the CAD lacks (cable bundle, heavier housing) near the joint, off the
    // link's x axis: the centre moves towards it, the inertia by the parallel-axis term.
    auto& link = s.plant.links[j];
    const Eigen::Vector3d p(0.05 + 0.1 * unit(rng), 0.03 + 0.04 * unit(rng), 0.04 * unit(rng));
    add_point_mass(link, a / (9.81 * std::hypot(p.x(), p.y())), p);
  } else if (effect == robot::Effect::inertia_error) {  // the link's own inertia about its joint axis, not the rotor's
    s.plant.links[j].inertia_com(2, 2) += a / 2.0;
  } else {
    return false;
  }
  return true;
}

/// Drive and sensor shapes; the amplitude is the RMS torque error where it has one.
bool apply_sensor_shape(robot::Effect effect, std::size_t j, double a, sim::SimulationSetup& s,
                        const ReferenceMotion& m, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::size_t n = s.plant.links.size();
  const double k = s.sensors.drives[j].torque_constant_nominal;
  if (effect == robot::Effect::torque_constant) {  // saturation: K falls with |i|, RMS of -s K i |i| = a
    double acc = 0.0, peak = 0.0;
    for (const double tau : m.motor) {
      acc += tau * tau * tau * tau;
      peak = std::max(peak, std::fabs(tau) / k);
    }
    const double rms_sq = std::sqrt(acc / static_cast<double>(std::max<std::size_t>(1, m.motor.size())));
    const double sat = std::min(a * k / std::max(rms_sq, 1e-9), 0.2 / std::max(peak, 1e-9));  // K at most 20 % low
    s.sensors.torque_constant_saturation_per_a.assign(n, 0.0);
    s.sensors.torque_constant_saturation_per_a[j] = sat;
  } else if (effect == robot::Effect::current_offset) {  // drifts from 0.4 a to 1.6 a over the recording
    const double span = m.t.empty() ? 1.0 : m.t.back();
    s.sensors.drives[j].current_offset_a = 0.4 * a / k;
    s.sensors.current_offset_drift_a_per_s.assign(n, 0.0);
    s.sensors.current_offset_drift_a_per_s[j] = 1.2 * a / k / span;
  } else if (effect == robot::Effect::time_delay) {  // 0.25-2.75 samples, never a whole one
    const int whole = static_cast<int>(3.0 * unit(rng)) % 3;
    s.sensors.current_delay_samples = whole;
    s.sensors.current_delay_fraction = 0.25 + 0.5 * unit(rng);
  } else {
    return false;
  }
  return true;
}

void apply_second(robot::Effect effect, int joint, double a, sim::SimulationSetup& s, std::mt19937_64& rng) {
  if (effect == robot::Effect::none) return;  // a matched pair without a shared shape
  const auto j = static_cast<std::size_t>(joint - 1);
  const ReferenceMotion m = reference_motion(s, j);
  if (apply_friction_shape(effect, s.plant.friction[j], m, a, rng)) return;
  if (apply_body_shape(effect, j, a, s, rng)) return;
  if (apply_sensor_shape(effect, j, a, s, m, rng)) return;
  if (effect == robot::Effect::joint_elasticity) {
    // A hardening gear: softer than the first set's at small deflection, stiffening as it
    // winds up (the stiffness doubles at 4e-4 rad).
    make_elastic(s, j, 0.7 * 5100.0 / a, 0.0);
    s.plant.elasticity[j].hardening_rad = 4e-4;
  } else if (effect == robot::Effect::backlash) {  // the dead zone (see run_case_second for the gear)
    s.plant.elasticity[j].backlash_rad = 3.5e-4 * a / 0.17;
  } else if (effect != robot::Effect::none) {
    throw std::invalid_argument("the second generator cannot produce effect '" + effect + "'");
  }
}

/// A matched pair's shared shape: "matched:<effect>" -> effect, "matched" -> none.
robot::Effect shared_shape(const ConcealedCase& c) {
  const auto colon = c.concealment.find(':');
  if (c.effect != robot::Effect::none || colon == std::string::npos) return c.effect;
  return robot::parse_effect(c.concealment.substr(colon + 1)).value_or(robot::Effect::none);
}
}  // namespace

std::vector<ConcealedCase> draw_cases_second(int count, unsigned long long seed, double noise_rms_nm, int joints) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + 0x5EC0DULL);  // a stream of its own
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto& effects = producible_effects();
  const char* concealments[] = {"low_amplitude", "plain", "mixed"};
  auto pick_effect = [&] { return effects[static_cast<std::size_t>(unit(rng) * static_cast<double>(effects.size())) % effects.size()]; };
  auto pick_joint = [&](robot::Effect effect) {
    int joint = 1 + static_cast<int>(unit(rng) * joints) % joints;
    if (effect == robot::Effect::payload) joint = joints;
    if (effect == robot::Effect::link_inertial_error) joint = joints > 2 ? 2 + static_cast<int>(unit(rng) * (joints - 2)) % (joints - 2) : joints;
    return joint;
  };
  std::vector<ConcealedCase> out;
  for (int i = 0; i < count; ++i) {
    ConcealedCase c;
    c.seed = seed * 2000003ULL + 17ULL * static_cast<unsigned long long>(i) + 5ULL;
    const robot::Effect effect = pick_effect();
    c.joint = pick_joint(effect);
    const double u = unit(rng), v = unit(rng);
    if (i % 6 == 5) {  // one case in six is a matched pair; half of them share a shape
      c.effect = robot::Effect::none;
      c.concealment = u < 0.5 ? "matched" : "matched:" + effect;
      c.amplitude_nm = noise_rms_nm * (1.0 + 2.0 * v);
      out.push_back(c);
      continue;
    }
    c.effect = effect;
    c.concealment = concealments[static_cast<std::size_t>(u * 3.0) % 3];
    c.amplitude_nm = noise_rms_nm * (c.concealment == std::string("low_amplitude") ? 0.5 + 0.5 * v : 1.0 + 2.0 * v);
    out.push_back(c);
  }
  return out;
}

CaseOutcome run_case_second(const ConcealedCase& c, const TestArm& arm_in, const CaseTrace& trace) {
  const robot::Effect shape = shared_shape(c);
  TestArm arm = arm_in;
  if (shape == robot::Effect::backlash) {  // a user's motion about the zero of the gravity load, not exactly on it
    arm = backlash_arm(arm_in, c.joint);
    arm.posture(c.joint - 1) += 0.05;
  }
  if (shape == robot::Effect::link_inertial_error) arm.excitation_amplitude_rad = 1.5;  // a user identifying link masses
  sim::SimulationSetup real = nominal_setup(arm, c.seed * 2 + 1);
  sim::SimulationSetup nominal = nominal_setup(arm, c.seed * 2 + 2);
  const auto j = static_cast<std::size_t>(c.joint - 1);
  if (shape == robot::Effect::backlash) {  // the hardening gear is known to the model: only the dead zone is not
    for (auto* s : {&real, &nominal}) {
      make_elastic(*s, j, kBacklashGearStiffness, 0.0);
      s->plant.elasticity[j].hardening_rad = kBacklashGearHardening;
    }
  }
  std::mt19937_64 r1(c.seed), r2(c.seed);
  apply_second(shape, c.joint, c.amplitude_nm, real, r1);
  if (c.effect == robot::Effect::none) apply_second(shape, c.joint, c.amplitude_nm, nominal, r2);  // known: in both
  if (c.concealment == "mixed") {  // a second, known effect in both: the other joint's friction 8 % higher
    const auto other = static_cast<std::size_t>(c.joint % static_cast<int>(arm.links.size()));
    for (auto* s : {&real, &nominal}) {
      s->plant.friction[other].lugre.tau_c *= 1.08;
      s->plant.friction[other].lugre.tau_s *= 1.08;
    }
  }
  return diagnose_pair(c, arm, real, nominal, trace);
}

std::string second_shape_description(robot::Effect effect) {
  static const std::map<robot::Effect, std::string> d = {
      {robot::Effect::coulomb, "Coulomb and static level scaled together (1 + r)"},
      {robot::Effect::viscous, "shear-thinning c sgn(w) |w|^p, p 0.5-0.8"},
      {robot::Effect::stribeck, "excess with an exponential law exp(-|w|/w_s'), w_s' 1.5-3x nominal"},
      {robot::Effect::presliding, "Dahl hyperbolic law (exponent 2) at 0.4 tau_c, displacement bisected"},
      {robot::Effect::asymmetric_friction, "negative direction: tau_c, tau_s, w_s scaled separately"},
      {robot::Effect::position_ripple, "two harmonics (n and 2n per rev, second 40-80 %)"},
      {robot::Effect::temperature_drift, "linear ramp, or two-time-constant warm-up"},
      {robot::Effect::load_dependent_friction, "efficiency by power flow: back-driven 20-50 % of driving"},
      {robot::Effect::payload, "rigid box with its own inertia, centre off the flange axis"},
      {robot::Effect::link_inertial_error, "local point mass near the joint, off the link's x axis"},
      {robot::Effect::inertia_error, "the link's own inertia about its joint axis (not the rotor's)"},
      {robot::Effect::torque_constant, "saturation: K falls with |i| (at most 20 %)"},
      {robot::Effect::current_offset, "offset drifting linearly from 0.4 A to 1.6 A (torque units)"},
      {robot::Effect::time_delay, "fractional delay 0.25-2.75 samples (interpolated current)"},
      {robot::Effect::backlash, "dead zone in a hardening gear, motion 0.05 rad off the gravity zero"},
      {robot::Effect::joint_elasticity, "hardening spring k0 (1 + (d / 4e-4 rad)^2)"},
  };
  const auto it = d.find(effect);
  return it == d.end() ? std::string("none") : it->second;
}

}  // namespace jg::diag
