#include "diagnosis/testset.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <stdexcept>

#include "diagnosis/pairing.hpp"
#include "identification/lugre_batch.hpp"
#include "models/paper_friction.hpp"
#include "sim/simulation.hpp"

namespace jg::diag {
namespace {
constexpr double kRate = 500.0;
constexpr double kBacklashStiffness = 2e4;  ///< [N·m/rad] the gear's stiffness in the backlash cases
}  // namespace

sim::SimulationSetup nominal_setup(const TestArm& arm, unsigned long long noise_seed) {
  sim::SimulationSetup s;
  s.plant.links = arm.links;
  const std::size_t n = arm.links.size();
  for (std::size_t j = 0; j < n; ++j) s.plant.friction.push_back({sim::kPaperTable1[std::min<std::size_t>(j, 2)], {}});
  s.sensors.drives = arm.drives;
  s.sensors.seed = noise_seed;
  const sim::ArmDynamics dyn(arm.links);
  const auto M = dyn.mass_matrix(arm.posture);
  for (std::size_t j = 0; j < n; ++j) {
    const double inertia = M(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j));
    s.controller.kp.push_back(inertia * 1600.0);
    s.controller.kd.push_back(inertia * 80.0);
  }
  s.trajectory = std::make_shared<sim::ExcitationTrajectory>(arm.posture, std::vector<bool>(n, true),
                                                             sim::PaperExcitation(arm.excitation_amplitude_rad, 0.2, 3, 2.5));
  s.control_rate_hz = kRate;
  return s;
}

namespace {

/// Bristle stiffness ratio (real / nominal) whose friction differs from the nominal one by
/// `amplitude` RMS over the reference motion: softer bristles, a longer presliding regime
/// after each reversal. Bisection on the ratio (the RMS falls as the ratio rises to 1).
double presliding_ratio(const sim::SimulationSetup& s, std::size_t j, double amplitude) {
  const double dt = 1.0 / s.control_rate_hz;
  std::vector<double> w;
  for (double t = 0.0; t <= s.trajectory->duration(); t += dt) w.push_back(s.trajectory->at(t).dq(static_cast<Eigen::Index>(j)));
  const auto& p = s.plant.friction[j].lugre;
  const auto nominal = ident::lugre_predict(p, w, dt);
  auto rms_at = [&](double ratio) {
    auto q = p;
    q.sigma0 *= ratio;
    const auto f = ident::lugre_predict(q, w, dt);
    double acc = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) acc += (f[k] - nominal[k]) * (f[k] - nominal[k]);
    return std::sqrt(acc / static_cast<double>(f.size()));
  };
  double lo = std::log(1e-3), hi = 0.0;  // rms(lo) > amplitude > rms(hi) = 0
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (lo + hi);
    (rms_at(std::exp(mid)) > amplitude ? lo : hi) = mid;
  }
  return std::exp(0.5 * (lo + hi));
}

}  // namespace

/// Elastic joints in the plant: joint `j` with the given stiffness and backlash, the others
/// so stiff that their deflection stays below one link-encoder count; plant rate raised so
/// that RK4 resolves the stiff modes.
void make_elastic(sim::SimulationSetup& s, std::size_t j, double stiffness, double backlash_rad) {
  const std::size_t n = s.plant.links.size();
  s.plant.elasticity.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double rotor = s.plant.links[i].rotor_inertia;
    const double k = i == j ? stiffness : 2e6;
    const double zeta = i == j ? 0.1 : 0.7;  // gear damping (stiff joints well damped)
    s.plant.elasticity[i] = sim::JointElasticity{k, 2.0 * zeta * std::sqrt(k * rotor), i == j ? backlash_rad : 0.0};
  }
  s.plant.plant_rate_hz = 24000.0;  // 8 kHz is not enough for the stiff joints near rest
}

namespace {

void apply(robot::Effect effect, int joint, double a, double partial_time, sim::SimulationSetup& s,
           std::mt19937_64& rng) {
  const auto j = static_cast<std::size_t>(joint - 1);
  auto& f = s.plant.friction[j];
  auto& d = s.sensors.drives[j];
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  if (effect == robot::Effect::position_ripple) {
    f.effects.ripple_amplitude = a;
    f.effects.ripple_periods_per_rev = std::floor(10.0 + 110.0 * unit(rng));
    f.effects.ripple_phase = 6.283 * unit(rng);
  } else if (effect == robot::Effect::asymmetric_friction) {
    f.effects.asymmetry = a / f.lugre.tau_c;
  } else if (effect == robot::Effect::temperature_drift) {
    f.effects.drift = a / f.lugre.tau_c;
    f.effects.drift_time_constant_s = 5.0 + 15.0 * unit(rng);
  } else if (effect == robot::Effect::load_dependent_friction) {
    f.effects.load_coefficient = a / 15.0;
  } else if (effect == robot::Effect::payload) {
    s.plant.payload = sim::PayloadChange{partial_time, a / 3.0, Eigen::Vector3d(0.25, 0.0, 0.0)};
  } else if (effect == robot::Effect::link_inertial_error) {
    // The link heavier than modelled and its centre of mass off sideways (link y), each
    // about half the amplitude in gravity torque on its own joint. A pure mass change with
    // the centre kept would be a mass at the next joint's axis, the same torques as a
    // payload there: not the same cause, but not one the torques can tell apart.
    auto& link = s.plant.links[j];
    const double lever = std::max(std::hypot(link.com.x(), link.com.y()), 0.05);
    const double dm = 0.5 * a / (9.81 * lever);
    link.inertia_com *= (link.mass + dm) / link.mass;  // the same body, denser: its inertia scales too
    link.mass += dm;
    link.com.y() += 0.5 * a / (9.81 * link.mass);
  } else if (effect == robot::Effect::torque_constant) {
    d.torque_constant_error = a / 15.0;
  } else if (effect == robot::Effect::current_offset) {
    d.current_offset_a = a / d.torque_constant_nominal;
  } else if (effect == robot::Effect::time_delay) {
    s.sensors.current_delay_samples = 1 + static_cast<int>(3.0 * unit(rng));
  } else if (effect == robot::Effect::coulomb) {
    f.lugre.tau_c += a;
  } else if (effect == robot::Effect::viscous) {
    f.lugre.sigma2 += a / 0.75;
  } else if (effect == robot::Effect::stribeck) {
    f.lugre.tau_s += 2.0 * a;
  } else if (effect == robot::Effect::inertia_error) {
    s.plant.links[j].rotor_inertia += a / 2.0;  // ~2 rad/s^2 peak acceleration
  } else if (effect == robot::Effect::presliding) {
    // Softer bristles: friction builds up over a longer displacement after each reversal.
    f.lugre.sigma0 *= presliding_ratio(s, j, a);
  } else if (effect == robot::Effect::joint_elasticity) {
    // Gear compliance: 3e4 N·m/rad at an amplitude equal to the noise (0.17 N·m), stiffer
    // (harder to see) below it, softer above it; 1e4 N·m/rad at 3x the noise.
    make_elastic(s, j, 5100.0 / a, 0.0);
  } else if (effect == robot::Effect::backlash) {
    // Dead zone in an elastic gear (the nominal model knows the stiffness, see run_case):
    // 1 arcmin (2.9e-4 rad) at an amplitude equal to the noise.
    make_elastic(s, j, kBacklashStiffness, 2.9e-4 * a / 0.17);
  } else if (effect != robot::Effect::none) {
    throw std::invalid_argument("the test plant cannot produce effect '" + effect + "'");
  }
}
}  // namespace

const std::vector<robot::Effect>& producible_effects() {
  // The draw's order (cases are drawn by index into it: reordering changes every set).
  using E = robot::Effect;
  static const std::vector<E> v = {E::position_ripple, E::asymmetric_friction, E::temperature_drift, E::load_dependent_friction,
                                   E::payload,         E::torque_constant,     E::current_offset,    E::time_delay,
                                   E::coulomb,         E::viscous,             E::stribeck,          E::inertia_error,
                                   E::presliding,      E::backlash,            E::joint_elasticity,  E::link_inertial_error};
  return v;
}

std::vector<ConcealedCase> draw_cases(int count, unsigned long long seed, double noise_rms_nm, int joints) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto& effects = producible_effects();
  const char* concealments[] = {"low_amplitude", "partial", "mixed", "masked"};
  std::vector<ConcealedCase> out;
  for (int i = 0; i < count; ++i) {
    ConcealedCase c;
    c.seed = seed * 1000003ULL + static_cast<unsigned long long>(i);
    if (i % 6 == 5) {  // one case in six is a matched pair
      c.effect = robot::Effect::none;
      c.concealment = "matched";
      out.push_back(c);
      continue;
    }
    c.effect = effects[static_cast<std::size_t>(unit(rng) * static_cast<double>(effects.size())) % effects.size()];
    c.joint = 1 + static_cast<int>(unit(rng) * joints) % joints;
    if (c.effect == robot::Effect::payload) c.joint = joints;  // carried by the last link
    // A link's mass error on an inner link that carries gravity (not the first, whose
    // axis is vertical in the test arm, nor the last, whose error is a payload).
    if (c.effect == robot::Effect::link_inertial_error) c.joint = joints > 2 ? 2 + static_cast<int>(unit(rng) * (joints - 2)) % (joints - 2) : joints;
    c.concealment = concealments[static_cast<std::size_t>(unit(rng) * 4.0) % 4];
    // At or below the noise for low_amplitude; otherwise up to three times the noise.
    c.amplitude_nm = noise_rms_nm * (c.concealment == std::string("low_amplitude") ? 0.5 + 0.5 * unit(rng) : 1.0 + 2.0 * unit(rng));
    out.push_back(c);
  }
  return out;
}

/// Backlash only shows when the torque the gear transmits changes sign. A user looking for
/// it records a motion that reverses that torque: about a posture where the joint's
/// gravity load is zero (the nearest one), so that the sinusoid crosses it.
TestArm backlash_arm(const TestArm& arm, int joint) {
  TestArm a = arm;
  const sim::ArmDynamics dyn(arm.links);
  const auto j = static_cast<Eigen::Index>(joint - 1);
  auto g = [&](double x) {
    sim::JointVector q = arm.posture;
    q(j) = x;
    return dyn.gravity_torque(q)(j);
  };
  const double x0 = arm.posture(j);
  if (std::fabs(g(x0)) < 1e-9) return a;
  double best = x0, best_dist = 1e9;
  for (int i = -628; i < 628; ++i) {  // scan in 5 mrad steps, bisect the sign change
    double lo = x0 + 0.005 * i, hi = lo + 0.005;
    if ((g(lo) > 0.0) == (g(hi) > 0.0)) continue;
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (lo + hi);
      ((g(mid) > 0.0) == (g(lo) > 0.0) ? lo : hi) = mid;
    }
    if (std::fabs(lo - x0) < best_dist) {
      best_dist = std::fabs(lo - x0);
      best = lo;
    }
  }
  a.posture(j) = best;
  return a;
}

namespace {
/// RMS of a residual over the diagnosis's held-out blocks.
double heldout_rms_of(const std::vector<double>& residual) {
  const auto held = heldout_mask(residual.size(), DiagnoseOptions{});
  double acc = 0.0;
  std::size_t cnt = 0;
  for (std::size_t k = 0; k < residual.size(); ++k) {
    if (held[k]) {
      acc += residual[k] * residual[k];
      ++cnt;
    }
  }
  return cnt ? std::sqrt(acc / static_cast<double>(cnt)) : 0.0;
}
}  // namespace

CaseOutcome run_case(const ConcealedCase& c, const TestArm& arm_in, const CaseTrace& trace) {
  std::mt19937_64 rng(c.seed);
  TestArm arm = c.effect == robot::Effect::backlash ? backlash_arm(arm_in, c.joint) : arm_in;
  // A link's mass error shows as a gravity torque a cos(q + phi) on the joints it loads;
  // over the default +/-0.6 rad that is a payload at the next joint's axis plus a constant.
  // A user identifying link masses records a wide motion: +/-1.5 rad.
  if (c.effect == robot::Effect::link_inertial_error) arm.excitation_amplitude_rad = 1.5;
  sim::SimulationSetup real = nominal_setup(arm, c.seed * 2 + 1);
  sim::SimulationSetup nominal = nominal_setup(arm, c.seed * 2 + 2);
  if (c.effect == robot::Effect::backlash) make_elastic(nominal, static_cast<std::size_t>(c.joint - 1), kBacklashStiffness, 0.0);
  const double span = real.trajectory->duration();
  const double partial_time = c.concealment == "partial" ? 0.5 * span : 0.0;
  apply(c.effect, c.joint, c.amplitude_nm, partial_time, real, rng);
  if (c.concealment == "partial" && c.effect == robot::Effect::temperature_drift) {
    real.plant.friction[static_cast<std::size_t>(c.joint - 1)].effects.drift_time_constant_s = span;  // slow: half hidden
  }
  if (c.concealment == "mixed") {  // a second, known effect in both: it must not be claimed
    const int other = c.joint % static_cast<int>(arm.links.size()) + 1;
    std::mt19937_64 r1(c.seed + 7), r2(c.seed + 7);
    apply(robot::Effect::asymmetric_friction, other, 0.5, 0.0, real, r1);
    apply(robot::Effect::asymmetric_friction, other, 0.5, 0.0, nominal, r2);
  }
  if (c.concealment == "masked") {  // a benign model error: the real last link is 3 % heavier
    real.plant.links.back().mass *= 1.03;
  }
  return diagnose_pair(c, arm, real, nominal, trace);
}

CaseOutcome diagnose_pair(const ConcealedCase& c, const TestArm& arm, const sim::SimulationSetup& real,
                          const sim::SimulationSetup& nominal, const CaseTrace& trace) {
  CaseOutcome out;
  out.c = c;
  const auto r = sim::run_simulation(real).recording;
  const auto s = sim::run_simulation(nominal).recording;
  if (trace.non_finite) {
    for (const auto* rec : {&r, &s}) {
      for (std::size_t j = 0; j < rec->joints(); ++j) {
        for (std::size_t k = 0; k < rec->samples(); ++k) {
          if (!std::isfinite(rec->q[j][k]) || !std::isfinite(rec->dq[j][k]) || !std::isfinite(rec->tau_m[j][k])) {
            std::fprintf(stderr, "%s joint %zu non-finite at t %.3f\n", rec == &r ? "real" : "nominal", j + 1, rec->t[k]);
            break;
          }
        }
      }
    }
  }
  const sim::ArmDynamics model(arm.links);
  ModelContext m;
  m.arm = &model;
  for (const auto& f : nominal.plant.friction) m.friction.push_back(f.lugre);
  const auto signals = signals_from_pair(r, s, m);
  out.arm = diagnose_arm(signals, {}, &model);
  out.heldout_raw = heldout_rms_of(signals[static_cast<std::size_t>(std::max(1, c.joint) - 1)].residual);
  DiagnoseOptions joint_options;
  joint_options.trace = trace.selection;
  for (const auto& sig : without_arm_causes(signals, out.arm)) out.joints.push_back(diagnose_joint(sig, joint_options));
  if (c.effect == robot::Effect::none && !out.arm.findings.empty()) out.false_claim = true;
  // A payload belongs to the last link but shows on every joint it loads: it is named
  // once, at the arm level. Every other effect must be named on its joint.
  for (const auto& f : out.arm.findings) {
    const auto link = f.params.find("link");
    const bool on_link = c.effect != robot::Effect::link_inertial_error || (link != f.params.end() && link->second == c.joint);
    out.named = out.named || (f.effect == c.effect && on_link);
  }
  for (const auto& j : out.joints) {
    if (c.effect == robot::Effect::none && !j.findings.empty()) out.false_claim = true;
    if (j.joint == c.joint) {
      for (const auto& f : j.findings) out.named = out.named || f.effect == c.effect;
      out.heldout_before = j.heldout_rms_before;
      out.heldout_after = j.heldout_rms_after;
      out.noise = j.noise_rms;
    }
  }
  // The loop closed: the findings written into the nominal simulation, re-run with fresh
  // sensor noise, against the real recording on the effect's joint.
  sim::SimulationSetup resim = nominal;
  resim.sensors.seed = c.seed * 2 + 3;
  const auto report = apply_findings(out.arm, out.joints, 1.0 / resim.control_rate_hz, resim);
  out.resim_applied = report.applied;
  out.resim_not_modelled = report.not_modelled;
  const auto again = sim::run_simulation(resim).recording;
  const auto sig2 = signals_from_pair(r, again, m);
  const auto& sj = sig2[static_cast<std::size_t>(std::max(1, c.joint) - 1)];
  out.resim_heldout = heldout_rms_of(sj.residual);
  out.resim_noise = noise_level(sj.residual);
  return out;
}

bool resim_at_noise_floor(const CaseOutcome& o) {
  return o.resim_heldout <= 1.1 * o.resim_noise ||
         (o.heldout_before >= 3.0 * o.noise && o.resim_heldout <= 0.5 * o.heldout_before);
}

TestArm default_test_arm() {
  TestArm a;
  a.name = "test3";
  a.links.resize(3);
  a.links[0].d = 0.3;
  a.links[0].mass = 4.0;
  a.links[0].com = {0.0, 0.01, -0.05};
  a.links[0].inertia_com = Eigen::Vector3d(0.03, 0.03, 0.02).asDiagonal();
  a.links[0].rotor_inertia = 0.4;
  a.links[1].alpha_prev = M_PI / 2;
  a.links[1].mass = 3.5;
  a.links[1].com = {0.2, 0.0, 0.02};
  a.links[1].inertia_com = Eigen::Vector3d(0.01, 0.06, 0.06).asDiagonal();
  a.links[1].rotor_inertia = 0.4;
  a.links[2].a_prev = 0.4;
  a.links[2].mass = 2.0;
  a.links[2].com = {0.18, 0.01, 0.0};
  a.links[2].inertia_com = Eigen::Vector3d(0.005, 0.03, 0.03).asDiagonal();
  a.links[2].rotor_inertia = 0.2;
  a.drives.assign(3, sim::JointDriveConfig{100.0, 12.0, 0.0, 15.0, 0.0, 0.01, 0.0005});
  a.posture = sim::JointVector(3);
  a.posture << 0.0, 0.6, -0.8;
  return a;
}

}  // namespace jg::diag
