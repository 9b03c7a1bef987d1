// The simulated arm: rigid (or elastic) links, true friction, external contact forces.
// Integration: classical RK4 on the mechanical state at the plant rate, with friction and
// contact torques held over each plant step; the stiff LuGre bristle state is advanced by
// its exact exponential step (friction_truth.hpp), so the scheme stays stable for
// sigma0 ~ 1e5 at any plant rate that resolves the mechanics.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "plant/friction_truth.hpp"
#include "dynamics/rigid_body.hpp"

namespace jg::sim {

/// Joint elasticity (paper eq. 1): link and motor sides coupled by a spring-damper,
/// with an optional backlash dead zone; friction then acts on the motor side.
struct JointElasticity {
  double stiffness = 0.0;     ///< [N·m/rad], 0 = rigid joint
  double damping = 0.0;       ///< [N·m·s/rad]
  double backlash_rad = 0.0;  ///< total dead-zone width [rad] (link side)
  /// Hardening gear spring (default off): tau = k d (1 + (d / hardening_rad)^2), d the
  /// deflection beyond the dead zone; 0 = linear. Used by the second concealed-effect set.
  double hardening_rad = 0.0;
};

/// A mass added to the last link from `time_s` on (the payload effect).
struct PayloadChange {
  double time_s = 0.0;
  double mass = 0.0;  ///< [kg]
  Eigen::Vector3d com_in_last_link = Eigen::Vector3d::Zero();
  /// The payload's own inertia about its centre, last link's axes [kg m^2]; zero = a point
  /// mass (the default). A tool or a part is a rigid body (second concealed-effect set).
  Eigen::Matrix3d inertia_com = Eigen::Matrix3d::Zero();
};

/// How the rigid arm's mechanical state is stepped (elastic joints: always RK4).
enum class Integrator {
  rk4,                  ///< classical Runge-Kutta, four forward dynamics per step (the default)
  semi_implicit_euler,  ///< v += h a(q, v), q += h v: one forward dynamics per step (a second plant)
};

struct PlantConfig {
  std::vector<PlantLink> links;
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  std::vector<JointFrictionTruth> friction;  ///< one per joint (empty = frictionless)
  std::vector<JointElasticity> elasticity;   ///< one per joint (empty = rigid joints)
  std::optional<PayloadChange> payload;
  double plant_rate_hz = 2000.0;
  Integrator integrator = Integrator::rk4;
};

/// A force on a link: `force_base` [N] in the base frame, applied at `point_in_link` [m].
struct ContactForce {
  int link = -1;  ///< 0-based, -1 = no contact
  Eigen::Vector3d point_in_link = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_base = Eigen::Vector3d::Zero();
};

/// Called once per plant step with the time and the current state.
using ContactModel = std::function<ContactForce(double t, const ArmDynamics& arm, const JointVector& q,
                                                const JointVector& qd)>;

struct PlantState {
  double time = 0.0;
  JointVector q, qd;              ///< link side
  JointVector theta, theta_dot;   ///< motor side (link units); equal to q, qd when rigid
  std::vector<LuGreTruthState> bristles;
};

class Plant {
 public:
  explicit Plant(PlantConfig config);

  void reset(const JointVector& q0);
  /// Elastic joints: starts with the motor side at theta0 (e.g. pre-loaded springs).
  void reset(const JointVector& q0, const JointVector& theta0);
  /// Advances by `dt` (rounded to whole plant steps) with `motor_torque` (link side, N·m) held.
  void advance(double dt, const JointVector& motor_torque, const ContactModel& contact = {});

  [[nodiscard]] const PlantState& state() const { return state_; }
  [[nodiscard]] const ArmDynamics& arm() const { return arm_; }
  [[nodiscard]] const PlantConfig& config() const { return config_; }
  /// Over the last advance(): true friction torque and true external joint torque at its
  /// end, and the largest contact force magnitude seen.
  [[nodiscard]] const JointVector& friction_torque() const { return friction_; }
  [[nodiscard]] const JointVector& external_torque() const { return external_; }
  [[nodiscard]] double peak_contact_force() const { return peak_contact_force_; }
  [[nodiscard]] int contact_link() const { return contact_link_; }
  /// Kinetic + potential + spring + bristle energy [J].
  [[nodiscard]] double energy() const;
  [[nodiscard]] bool elastic() const { return !config_.elasticity.empty(); }
  /// Whether the friction is stepped linearly implicitly (chosen at reset() from
  /// stiffest_friction_mode() at the start pose; rigid joints only).
  [[nodiscard]] bool implicit_friction() const { return implicit_friction_; }
  /// The stiffest friction mode at the plant step, h D (M^-1)_jj with D = sigma0 h + sigma1
  /// + sigma2 the sticking friction's slope in the joint velocity; its joint (0-based) in
  /// `joint` when not null. Above kExplicitFrictionLimit the friction held over a step from
  /// its start (explicit) is unstable or nearly so: a light joint (a wrist) with friction
  /// sized for a heavy one.
  [[nodiscard]] double stiffest_friction_mode(const JointVector& q, int* joint = nullptr) const;

 private:
  void step(double h, const JointVector& motor_torque, const ContactModel& contact);
  /// step's parts: external_ (J^T F of the contact, held over the step), friction_ (held
  /// over the step), the state integrated over h with the rigid or the elastic arm.
  void contact_torque(const ContactModel& contact);
  void friction_torque(double h, const JointVector& motor_torque);
  void rk4_rigid(double h, const JointVector& motor_torque);
  void rk4_elastic(double h, const JointVector& motor_torque);
  /// The friction held over the step made linearly implicit in the joint velocities:
  /// F0 + D dv with (M + h D) dv = h (M a0), a0 the acceleration under F0 (rigid joints).
  void implicit_friction_correction(double h, const JointVector& motor_torque,
                                    const std::vector<LuGreTruthState>& bristles_before, const JointVector& w);
  void apply_payload_if_due();
  [[nodiscard]] JointVector spring_torque(const JointVector& q, const JointVector& qd, const JointVector& th,
                                          const JointVector& thd) const;

  PlantConfig config_;
  ArmDynamics arm_;
  PlantState state_;
  JointVector friction_, external_;
  double peak_contact_force_ = 0.0;
  int contact_link_ = 0;
  bool payload_applied_ = false;
  bool implicit_friction_ = false;
};

/// h D (M^-1)_jj above which the plant steps the friction implicitly (the explicit step's
/// stability ends at 2; models/ref3.yaml sits at 1.03 at 2 kHz, so its figures stay those
/// of the explicit step; the UR10e's vendor URDF, without rotors, at its wrist ~ 1e3).
inline constexpr double kExplicitFrictionLimit = 1.5;

}  // namespace jg::sim
