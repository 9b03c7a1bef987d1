#include "sim/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace jg::sim {
namespace {
/// Names the joint and parameter of the plant's stiffest mode at the plant step (for the
/// message of a run that diverged).
std::string stiffest_mode(const PlantConfig& config, const Plant& plant, const JointVector& q) {
  const double h = 1.0 / config.plant_rate_hz;
  int friction_joint = 0;
  const double friction_mode = plant.stiffest_friction_mode(q, &friction_joint);
  double elastic_mode = 0.0;
  std::size_t elastic_joint = 0;
  for (std::size_t j = 0; j < config.elasticity.size(); ++j) {
    const double omega_h = h * std::sqrt(config.elasticity[j].stiffness / config.links[j].rotor_inertia);
    if (omega_h > elastic_mode) {
      elastic_mode = omega_h;
      elastic_joint = j;
    }
  }
  char text[400];
  if (elastic_mode >= friction_mode) {
    std::snprintf(text, sizeof text,
                  "joint %zu's elasticity (stiffness %g N·m/rad on rotor_inertia %g kg m^2) oscillates at %.3g rad per plant "
                  "step of %g s (RK4 resolves < 2.8)",
                  elastic_joint + 1, config.elasticity[elastic_joint].stiffness, config.links[elastic_joint].rotor_inertia,
                  elastic_mode, h);
  } else {
    const auto& p = config.friction[static_cast<std::size_t>(friction_joint)].lugre;
    std::snprintf(text, sizeof text,
                  "joint %d's friction (sigma0 %g, sigma1 %g, sigma2 %g) is the stiffest mode, h D / inertia = %.3g at the plant "
                  "step of %g s%s",
                  friction_joint + 1, p.sigma0, p.sigma1, p.sigma2, friction_mode, h,
                  plant.implicit_friction() ? " (stepped implicitly)" : "");
  }
  return text;
}

/// The setup's checks against the plant's n joints: the trajectory's joints, controller
/// gains for every joint.
void check_setup(const SimulationSetup& setup, int n) {
  if (setup.trajectory->joints() != n) {
    throw std::invalid_argument("simulation: trajectory has " + std::to_string(setup.trajectory->joints()) +
                                " joints, the model " + std::to_string(n));
  }
  if (setup.controller.kp.size() != static_cast<std::size_t>(n) || setup.controller.kd.size() != static_cast<std::size_t>(n)) {
    throw std::invalid_argument("simulation: controller gains needed for every joint");
  }
  const bool integral = !setup.controller.ki.empty();
  if (integral && (setup.controller.ki.size() != static_cast<std::size_t>(n) ||
                   (!setup.controller.integral_limit_nm.empty() &&
                    setup.controller.integral_limit_nm.size() != static_cast<std::size_t>(n)))) {
    throw std::invalid_argument("simulation: integral gains (and limits) needed for every joint");
  }
}

/// The plant at the trajectory's start; an elastic gear pre-wound by gravity so the run
/// does not start with a swing.
void reset_at_start(Plant& plant, const SimulationSetup& setup, const TrajectorySample& start, int n) {
  if (plant.elastic()) {
    JointVector theta0 = start.q;
    const JointVector g = plant.arm().gravity_torque(start.q);
    for (int j = 0; j < n; ++j) theta0(j) += g(j) / setup.plant.elasticity[static_cast<std::size_t>(j)].stiffness;
    plant.reset(start.q, theta0);
  } else {
    plant.reset(start.q);
  }
}

/// The controller's torque demand from one cycle's measurement: gravity (and, with
/// inertia feedforward, M ddq_ref) of the nominal model, PD, and the integral term (clamped
/// to its limit). mass: a workspace kept across cycles.
JointVector control_demand(const SimulationSetup& setup, const ArmDynamics& nominal, const Measurement& m,
                           const TrajectorySample& ref, double dt, std::vector<double>& integral_term, JointMatrix& mass) {
  const int n = static_cast<int>(integral_term.size());
  const bool integral = !setup.controller.ki.empty();
  JointVector demand;
  if (setup.controller.inertia_feedforward) {
    nominal.gravity_and_mass_matrix(m.q, demand, mass);  // one set of link transforms for both
    demand += mass * ref.ddq;
  } else {
    demand = nominal.gravity_torque(m.q);
  }
  for (int j = 0; j < n; ++j) {
    const auto u = static_cast<std::size_t>(j);
    demand(j) += setup.controller.kp[u] * (ref.q(j) - m.q(j)) + setup.controller.kd[u] * (ref.dq(j) - m.dq(j));
    if (integral) {
      double& acc = integral_term[u];
      acc += setup.controller.ki[u] * (ref.q(j) - m.q(j)) * dt;
      if (!setup.controller.integral_limit_nm.empty()) {
        const double lim = setup.controller.integral_limit_nm[u];
        acc = std::clamp(acc, -lim, lim);
      }
      demand(j) += acc;
    }
  }
  return demand;
}

/// Cycle k's measurement, the external torque and the link in contact, into the recording.
void record_cycle(io::Recording& rec, long k, double t, const Measurement& m, const JointVector& external, int contact_link,
                  int n) {
  const auto uk = static_cast<std::size_t>(k);
  rec.t[uk] = t;
  for (int j = 0; j < n; ++j) {
    const auto u = static_cast<std::size_t>(j);
    rec.q[u][uk] = m.q(j);
    rec.dq[u][uk] = m.dq(j);
    rec.current[u][uk] = m.current(j);
    rec.tau_m[u][uk] = m.tau_m(j);
    rec.tau_ext[u][uk] = external(j);
  }
  rec.collision[uk] = contact_link;
}

/// Cycle k's plant friction and true speed (SimulationResult::plant_friction_nm), aligned as
/// tau_ext: the friction over the step that ended at the cycle's time (zero before the first).
void record_plant_truth(SimulationResult& result, const Plant& plant, long k, long cycles) {
  const auto n = static_cast<std::size_t>(plant.state().qd.size());
  if (result.plant_friction_nm.size() != n) {
    result.plant_friction_nm.assign(n, std::vector<double>(static_cast<std::size_t>(cycles), 0.0));
    result.plant_speed_rad_s = result.plant_friction_nm;
  }
  const auto uk = static_cast<std::size_t>(k);
  for (std::size_t j = 0; j < n; ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    result.plant_friction_nm[j][uk] = k > 0 ? plant.friction_torque()(i) : 0.0;
    // The speed the friction acts at: the motor side's on an elastic joint (plant.cpp).
    result.plant_speed_rad_s[j][uk] = plant.elastic() ? plant.state().theta_dot(i) : plant.state().qd(i);
  }
}

/// A run that diverges (a gear stiffer than the plant rate resolves, an unphysical model)
/// must not write NaN rows and report success: stop with the reason.
void check_finite(const Plant& plant, const SimulationSetup& setup, const TrajectorySample& start, double t_next) {
  const auto& st = plant.state();
  if (!st.q.allFinite() || !st.qd.allFinite() || !st.theta.allFinite() || !st.theta_dot.allFinite()) {
    throw std::runtime_error("the simulation diverged at t = " + std::to_string(t_next) +
                             " s (the plant's state is not finite): " + stiffest_mode(setup.plant, plant, start.q) +
                             "; raise plant_rate_hz (the scenario's, or simulate --plant-rate) or check the robot file");
  }
}
}  // namespace

SimulationResult run_simulation(const SimulationSetup& setup, const ControlOverride& override,
                                const std::function<void(double)>& progress) {
  if (!setup.trajectory) {
    throw std::invalid_argument("simulation: no trajectory");
  }
  if (!(setup.control_rate_hz > 0.0)) {
    throw std::invalid_argument("simulation: control rate must be > 0 Hz");
  }
  Plant plant(setup.plant);
  const int n = plant.arm().joints();
  check_setup(setup, n);
  std::vector<double> integral_term(static_cast<std::size_t>(n), 0.0);
  const ArmDynamics nominal(setup.nominal_links.empty() ? setup.plant.links : setup.nominal_links,
                            setup.plant.gravity);
  JointSensors sensors(setup.sensors, n);
  CollisionSchedule schedule(setup.collisions);
  // No collisions scheduled: no contact model at all (the schedule would return "no
  // contact" each plant step through a std::function call).
  const ContactModel contact =
      setup.collisions.empty()
          ? ContactModel{}
          : ContactModel([&schedule](double t, const ArmDynamics& arm, const JointVector& q, const JointVector& qd) {
              return schedule(t, arm, q, qd);
            });

  const double dt = 1.0 / setup.control_rate_hz;
  const double duration = setup.duration_s > 0.0 ? setup.duration_s : setup.trajectory->duration();
  const long cycles = static_cast<long>(std::floor(duration * setup.control_rate_hz + 1e-9)) + 1;

  const TrajectorySample start = setup.trajectory->at(0.0);
  reset_at_start(plant, setup, start, n);

  SimulationResult result;
  io::Recording& rec = result.recording;
  if (setup.record) {
    rec.resize(static_cast<std::size_t>(n), static_cast<std::size_t>(cycles), true, true, true, true);
    rec.meta = setup.meta;
    rec.meta.sample_time = dt;
  }
  const bool record_friction = setup.record && !setup.collisions.empty();
  JointVector current_cmd = JointVector::Zero(n);
  JointVector external = JointVector::Zero(n);
  int contact_link = 0;
  JointMatrix mass;
  const long progress_every = std::max(1L, cycles / 200);
  for (long k = 0; k < cycles; ++k) {
    const double t = static_cast<double>(k) * dt;
    const auto& s = plant.state();
    const Measurement m = sensors.sample(s.q, s.theta, current_cmd, dt);
    const TrajectorySample ref = setup.trajectory->at(t);
    JointVector demand = control_demand(setup, nominal, m, ref, dt, integral_term, mass);
    if (override) {
      const CycleContext ctx{t, &m, &ref, &demand};
      if (const auto replaced = override(ctx)) {
        demand = *replaced;
      }
    }
    current_cmd = sensors.current_command(demand);
    if (setup.record) record_cycle(rec, k, t, m, external, contact_link, n);
    if (record_friction) record_plant_truth(result, plant, k, cycles);
    plant.advance(dt, sensors.produced_torque(current_cmd), contact);
    check_finite(plant, setup, start, t + dt);
    external = plant.external_torque();
    contact_link = plant.contact_link();
    result.peak_contact_force_n = std::max(result.peak_contact_force_n, plant.peak_contact_force());
    if (!setup.collisions.empty()) result.contact_force_n.push_back(plant.peak_contact_force());
    if (progress && k % progress_every == 0) {
      progress(static_cast<double>(k) / static_cast<double>(cycles));
    }
  }
  if (!setup.collisions.empty()) result.first_contact = schedule.resolved(0);
  result.simulated_s = static_cast<double>(cycles) * dt;
  result.cycles = cycles;
  return result;
}

}  // namespace jg::sim
