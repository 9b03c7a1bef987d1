#include "plant/plant.hpp"

#include <cmath>
#include <stdexcept>

namespace jg::sim {
namespace {
std::vector<PlantLink> links_for_arm(const PlantConfig& c) {
  std::vector<PlantLink> links = c.links;
  if (!c.elasticity.empty()) {
    for (auto& l : links) {
      l.rotor_inertia = 0.0;  // the rotor is its own body on the motor side
    }
  }
  return links;
}
}  // namespace

Plant::Plant(PlantConfig config) : config_(std::move(config)), arm_(links_for_arm(config_), config_.gravity) {
  const auto n = config_.links.size();
  if (!config_.friction.empty() && config_.friction.size() != n) {
    throw std::invalid_argument("Plant: friction must be given for every joint or none");
  }
  if (!config_.elasticity.empty()) {
    if (config_.elasticity.size() != n) {
      throw std::invalid_argument("Plant: elasticity must be given for every joint or none");
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!(config_.elasticity[i].stiffness > 0.0) || !(config_.links[i].rotor_inertia > 0.0)) {
        throw std::invalid_argument("Plant: an elastic joint needs stiffness > 0 and rotor inertia > 0");
      }
    }
  }
  for (const auto& f : config_.friction) {
    if (validate(f.lugre) != Error::ok) {
      throw std::invalid_argument("Plant: invalid LuGre parameters");
    }
  }
  if (!(config_.plant_rate_hz > 0.0)) {
    throw std::invalid_argument("Plant: plant rate must be > 0 Hz");
  }
  reset(JointVector::Zero(static_cast<Eigen::Index>(n)));
}

void Plant::reset(const JointVector& q0) {
  const auto n = static_cast<Eigen::Index>(config_.links.size());
  if (q0.size() != n) {
    throw std::invalid_argument("Plant::reset: wrong number of joints");
  }
  state_ = PlantState{};
  state_.q = q0;
  state_.qd = JointVector::Zero(n);
  state_.theta = q0;
  state_.theta_dot = JointVector::Zero(n);
  state_.bristles.assign(static_cast<std::size_t>(n), LuGreTruthState{});
  friction_ = external_ = JointVector::Zero(n);
  // A light joint with stiff friction (the bristles of sigma0 ~ 1e5 N·m/rad at a wrist of
  // 0.01 kg m^2) is not resolved by friction held from the step's start: step it implicitly.
  implicit_friction_ = !elastic() && !config_.friction.empty() && stiffest_friction_mode(q0) > kExplicitFrictionLimit;
}

double Plant::stiffest_friction_mode(const JointVector& q, int* joint) const {
  if (config_.friction.empty()) return 0.0;
  const double h = 1.0 / config_.plant_rate_hz;
  const JointMatrix inverse = arm_.mass_matrix(q).inverse();
  double worst = 0.0;
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    const LuGreParams<double>& p = config_.friction[static_cast<std::size_t>(i)].lugre;
    const double slope = p.sigma0 * h + p.sigma1 + p.sigma2;
    const double mode = h * slope * inverse(i, i);
    if (mode > worst) {
      worst = mode;
      if (joint != nullptr) *joint = static_cast<int>(i);
    }
  }
  return worst;
}

void Plant::implicit_friction_correction(double h, const JointVector& motor_torque,
                                         const std::vector<LuGreTruthState>& bristles_before, const JointVector& w) {
  const Eigen::Index n = state_.q.size();
  // D: the slope of the stepped friction in the held velocity (central difference on
  // copies of the bristle state before the step), >= 0 so that M + h D stays positive.
  JointVector slope(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double eps = 1e-6 * std::max(1.0, std::fabs(w(i)));
    const double transmitted = motor_torque(i) - friction_(i);
    LuGreTruthState up = bristles_before[k], down = bristles_before[k];
    const double f_up = friction_truth_step(config_.friction[k], up, w(i) + eps, state_.q(i), transmitted, state_.time, h);
    const double f_down = friction_truth_step(config_.friction[k], down, w(i) - eps, state_.q(i), transmitted, state_.time, h);
    slope(i) = std::max(0.0, (f_up - f_down) / (2.0 * eps));
  }
  const JointVector drive = motor_torque - friction_ + external_;
  const JointVector a0 = arm_.forward_dynamics(state_.q, state_.qd, drive);
  const JointMatrix mass = arm_.mass_matrix(state_.q);
  JointMatrix system = mass;
  for (Eigen::Index i = 0; i < n; ++i) system(i, i) += h * slope(i);
  const JointVector dv = system.ldlt().solve(h * (mass * a0));
  friction_ += slope.cwiseProduct(dv);
}

void Plant::reset(const JointVector& q0, const JointVector& theta0) {
  reset(q0);
  if (theta0.size() != q0.size()) {
    throw std::invalid_argument("Plant::reset: wrong number of joints");
  }
  state_.theta = theta0;
}

JointVector Plant::spring_torque(const JointVector& q, const JointVector& qd, const JointVector& th,
                                 const JointVector& thd) const {
  JointVector tau(q.size());
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    const JointElasticity& e = config_.elasticity[static_cast<std::size_t>(i)];
    const double half = 0.5 * e.backlash_rad;
    const double dx = th(i) - q(i);
    const double deflection = dx > half ? dx - half : (dx < -half ? dx + half : 0.0);
    const bool engaged = deflection != 0.0 || half == 0.0;
    const double hardening = e.hardening_rad > 0.0 ? 1.0 + (deflection / e.hardening_rad) * (deflection / e.hardening_rad) : 1.0;
    tau(i) = e.stiffness * deflection * hardening + (engaged ? e.damping * (thd(i) - qd(i)) : 0.0);
  }
  return tau;
}

void Plant::apply_payload_if_due() {
  if (!config_.payload || payload_applied_ || state_.time < config_.payload->time_s) {
    return;
  }
  PlantLink& last = arm_.link(arm_.joints() - 1);
  const double m0 = last.mass, m1 = config_.payload->mass;
  const Eigen::Vector3d c1 = config_.payload->com_in_last_link;
  const Eigen::Vector3d c = (m0 * last.com + m1 * c1) / (m0 + m1);
  auto shift = [](double m, const Eigen::Vector3d& d) {  // parallel-axis term
    return m * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  };
  last.inertia_com = last.inertia_com + shift(m0, last.com - c) + shift(m1, c1 - c);  // point mass payload
  if (!config_.payload->inertia_com.isZero(0.0)) last.inertia_com += config_.payload->inertia_com;  // a rigid body
  last.com = c;
  last.mass = m0 + m1;
  payload_applied_ = true;
}

// Plant::step's parts: the contact's torque, the friction, and the integration of the rigid
// arm (RK4 on plain arrays) or of the elastic one (link and rotor).

void Plant::contact_torque(const ContactModel& contact) {
  const Eigen::Index n = state_.q.size();
  // Contact: external joint torque J^T F, held over the step.
  external_ = JointVector::Zero(n);
  if (contact) {
    const ContactForce f = contact(state_.time, arm_, state_.q, state_.qd);
    if (f.link >= 0) {
      external_ = arm_.point_jacobian(state_.q, f.link, f.point_in_link).transpose() * f.force_base;
      const double magnitude = f.force_base.norm();
      peak_contact_force_ = std::max(peak_contact_force_, magnitude);
      if (magnitude > 0.0) {
        contact_link_ = f.link + 1;
      }
    }
  }
}

void Plant::friction_torque(double h, const JointVector& motor_torque) {
  const Eigen::Index n = state_.q.size();
  // Friction on the side that slides (motor side when elastic), held over the step.
  const JointVector& w = elastic() ? state_.theta_dot : state_.qd;
  // The gear carries the motor torque less the friction: that load drives load-dependent
  // friction (previous step's friction: the load is not known before the step).
  // Joint by joint, the load read before the joint's friction is replaced.
  const bool previous = friction_.size() == n;
  const std::vector<LuGreTruthState> bristles_before = implicit_friction_ ? state_.bristles : std::vector<LuGreTruthState>{};
  friction_.conservativeResize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double transmitted = motor_torque(i) - (previous ? friction_(i) : 0.0);
    const auto k = static_cast<std::size_t>(i);
    friction_(i) = config_.friction.empty() ? 0.0
                                            : friction_truth_step(config_.friction[k], state_.bristles[k], w(i),
                                                                  state_.q(i), transmitted, state_.time, h);
  }
  if (implicit_friction_) implicit_friction_correction(h, motor_torque, bristles_before, w);
}

void Plant::rk4_rigid(double h, const JointVector& motor_torque) {
  const Eigen::Index n = state_.q.size();
  // Classical RK4 on plain arrays (four forward dynamics per step, the plant's hot path):
  // element for element the operations of the vector form
  //   a1 = f(q0, v0), v1 = v0 + h/2 a1, a2 = f(q0 + h/2 v0, v1), v2 = v0 + h/2 a2,
  //   a3 = f(q0 + h/2 v1, v2), v3 = v0 + h a3, a4 = f(q0 + h v2, v3),
  //   q = q0 + h/6 (v0 + 2 v1 + 2 v2 + v3), qd = v0 + h/6 (a1 + 2 a2 + 2 a3 + a4)
  // in the same order, so the same doubles, without temporaries of run-time size.
  constexpr int kMax = kPlantMaxJoints;
  double drive[kMax], q0[kMax], v0[kMax], qs[kMax];
  double a1[kMax], a2[kMax], a3[kMax], a4[kMax], v1[kMax], v2[kMax], v3[kMax];
  for (Eigen::Index i = 0; i < n; ++i) {
    drive[i] = motor_torque(i) - friction_(i) + external_(i);
    q0[i] = state_.q(i);
    v0[i] = state_.qd(i);
  }
  arm_.forward_dynamics(q0, v0, drive, a1);
  for (Eigen::Index i = 0; i < n; ++i) {
    v1[i] = v0[i] + 0.5 * h * a1[i];
    qs[i] = q0[i] + 0.5 * h * v0[i];
  }
  arm_.forward_dynamics(qs, v1, drive, a2);
  for (Eigen::Index i = 0; i < n; ++i) {
    v2[i] = v0[i] + 0.5 * h * a2[i];
    qs[i] = q0[i] + 0.5 * h * v1[i];
  }
  arm_.forward_dynamics(qs, v2, drive, a3);
  for (Eigen::Index i = 0; i < n; ++i) {
    v3[i] = v0[i] + h * a3[i];
    qs[i] = q0[i] + h * v2[i];
  }
  arm_.forward_dynamics(qs, v3, drive, a4);
  for (Eigen::Index i = 0; i < n; ++i) {
    state_.q(i) = q0[i] + h / 6.0 * (v0[i] + 2.0 * v1[i] + 2.0 * v2[i] + v3[i]);
    state_.qd(i) = v0[i] + h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
  }
  state_.theta = state_.q;
  state_.theta_dot = state_.qd;
}

void Plant::rk4_elastic(double h, const JointVector& motor_torque) {
  const Eigen::Index n = state_.q.size();
  JointVector rotor(n);
  for (Eigen::Index i = 0; i < n; ++i) rotor(i) = config_.links[static_cast<std::size_t>(i)].rotor_inertia;
  struct D { JointVector dq, ddq, dth, ddth; };
  auto f = [&](const JointVector& q, const JointVector& qd, const JointVector& th, const JointVector& thd) {
    const JointVector spring = spring_torque(q, qd, th, thd);
    D d;
    d.dq = qd;
    d.ddq = arm_.forward_dynamics(q, qd, spring + external_);
    d.dth = thd;
    d.ddth = (motor_torque - spring - friction_).cwiseQuotient(rotor);
    return d;
  };
  const PlantState s0 = state_;
  const D k1 = f(s0.q, s0.qd, s0.theta, s0.theta_dot);
  const D k2 = f(s0.q + 0.5 * h * k1.dq, s0.qd + 0.5 * h * k1.ddq, s0.theta + 0.5 * h * k1.dth,
                 s0.theta_dot + 0.5 * h * k1.ddth);
  const D k3 = f(s0.q + 0.5 * h * k2.dq, s0.qd + 0.5 * h * k2.ddq, s0.theta + 0.5 * h * k2.dth,
                 s0.theta_dot + 0.5 * h * k2.ddth);
  const D k4 = f(s0.q + h * k3.dq, s0.qd + h * k3.ddq, s0.theta + h * k3.dth, s0.theta_dot + h * k3.ddth);
  state_.q += h / 6.0 * (k1.dq + 2.0 * k2.dq + 2.0 * k3.dq + k4.dq);
  state_.qd += h / 6.0 * (k1.ddq + 2.0 * k2.ddq + 2.0 * k3.ddq + k4.ddq);
  state_.theta += h / 6.0 * (k1.dth + 2.0 * k2.dth + 2.0 * k3.dth + k4.dth);
  state_.theta_dot += h / 6.0 * (k1.ddth + 2.0 * k2.ddth + 2.0 * k3.ddth + k4.ddth);
}

void Plant::step(double h, const JointVector& motor_torque, const ContactModel& contact) {
  apply_payload_if_due();
  contact_torque(contact);
  friction_torque(h, motor_torque);
  if (!elastic() && config_.integrator == Integrator::semi_implicit_euler) {
    // Semi-implicit (symplectic) Euler: the velocity first, then the position with it.
    const JointVector a = arm_.forward_dynamics(state_.q, state_.qd, motor_torque - friction_ + external_);
    state_.qd += h * a;
    state_.q += h * state_.qd;
    state_.theta = state_.q;
    state_.theta_dot = state_.qd;
  } else if (!elastic()) {
    rk4_rigid(h, motor_torque);
  } else {
    rk4_elastic(h, motor_torque);
  }
  state_.time += h;
}

void Plant::advance(double dt, const JointVector& motor_torque, const ContactModel& contact) {
  const long steps = std::max(1L, std::lround(dt * config_.plant_rate_hz));
  const double h = dt / static_cast<double>(steps);
  peak_contact_force_ = 0.0;
  contact_link_ = 0;
  for (long k = 0; k < steps; ++k) {
    step(h, motor_torque, contact);
  }
}

double Plant::energy() const {
  double e = arm_.kinetic_energy(state_.q, state_.qd) + arm_.potential_energy(state_.q);
  for (std::size_t i = 0; i < config_.friction.size(); ++i) {
    e += bristle_energy(config_.friction[i], state_.bristles[i]);
  }
  if (elastic()) {
    for (Eigen::Index i = 0; i < state_.q.size(); ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double half = 0.5 * config_.elasticity[k].backlash_rad;
      const double dx = state_.theta(i) - state_.q(i);
      const double defl = dx > half ? dx - half : (dx < -half ? dx + half : 0.0);
      const double h = config_.elasticity[k].hardening_rad;
      const double quartic = h > 0.0 ? 0.5 * defl * defl / (h * h) : 0.0;  // integral of k d (d / h)^2
      e += 0.5 * config_.elasticity[k].stiffness * defl * defl * (1.0 + quartic) +
           0.5 * config_.links[k].rotor_inertia * state_.theta_dot(i) * state_.theta_dot(i);
    }
  }
  return e;
}

}  // namespace jg::sim
