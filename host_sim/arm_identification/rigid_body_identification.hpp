// Whole-arm rigid-body identification: all links' inertial parameters jointly over all
// joints, with per-joint friction, regularised towards the robot file's values, made
// physically consistent, validated on held-out blocks (docs/identification.md).
#pragma once

#include <string>
#include <vector>

#include "arm_identification/physical_consistency.hpp"
#include "dynamics/acceleration.hpp"
#include "dynamics/regressor.hpp"
#include "io/recording.hpp"
#include "robot/robot_model.hpp"

namespace jg::dyn {

/// Per-joint friction, linear in its parameters:
///   f = f_c tanh(dq / eps) + f_v dq + f_o   (symmetric), or with asymmetric Coulomb
///   f = f_c+ max(tanh, 0) + f_c- min(tanh, 0) + f_v dq   (f_c holds (f_c+ + f_c-)/2; no
///   offset: while moving it is the same column as the difference of the two levels).
struct FrictionFit {
  double coulomb = 0.0;      ///< f_c [N·m]
  double coulomb_pos = 0.0;  ///< f_c+ [N·m] (= f_c when symmetric)
  double coulomb_neg = 0.0;  ///< f_c- [N·m] (= f_c when symmetric)
  double viscous = 0.0;      ///< f_v [N·m·s/rad]
  double offset = 0.0;       ///< f_o [N·m]
  double eps = 0.01;         ///< tanh velocity scale [rad/s]
  [[nodiscard]] double torque(double dq) const;
};

/// A rigid body fixed to the last link, read as the change of the last link's parameters
/// against the prior (not separable from the link itself).
struct PayloadEstimate {
  double mass = 0.0;                  ///< [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  ///< in the last link frame [m]
  Eigen::Matrix3d inertia_com = Eigen::Matrix3d::Zero();  ///< about its CoM [kg m^2]
  bool claimed = false;               ///< mass >= 0 and CoM inside the last link's bound
  std::string reason;                 ///< why not claimed
};

struct LinkReport {
  LinkParams before = LinkParams::Zero(), after = LinkParams::Zero();
  double rotor_before = 0.0, rotor_after = 0.0;
  double com_bound_m = 0.0;
  double step = 1.0;       ///< largest feasible fraction of the way from the prior to the unconstrained estimate
  Consistency consistency;  ///< of `after`
};

struct RigidBodyIdOptions {
  bool joint_torque_sensor = false;  ///< torques are link-side torque-sensor readings: no rotor inertia
  bool identify_links = true;        ///< false: friction only, rigid body at the prior
  bool payload_only = false;         ///< only the last link's 10 parameters (the payload) + friction
  bool asymmetric_coulomb = false;
  /// A constant per joint in the friction (f_o). The diagnosis fits without it: a constant
  /// torque on a joint is a cause of its own (a current sensor's offset, `current_offset`)
  /// that must be named and must beat its null, not vanish into the friction baseline.
  bool friction_offset = true;
  std::vector<bool> train_mask;      ///< per sample; empty: hold out blocks 1, 4, 7 of 10
  double com_margin_m = 0.1;         ///< CoM bound = max(reach, |prior CoM|) + margin
  double sigma_s = 0.0;              ///< acceleration filter width [s]; 0: choose_sigma
  double friction_eps = 0.0;         ///< tanh scale [rad/s]; 0: 3x the velocity noise (min 1e-3)
  /// A joint's rows are left out of the fit while its smoothed speed is below this (the
  /// joint may stick; stiction is not a function of the state); < 0: 3 eps, and a joint's
  /// slow rows go back in when they fit within 2x of its moving rows (it does not stick); 0: keep all.
  double slow_speed_rad_s = -1.0;
  double prior_weight = 10.0;        ///< prior std = parameter scale / sqrt(prior_weight) (~30 %), rows in noise units
  /// Torque of causes already known per joint (a robot file's per-joint plant_effects) [N·m],
  /// [joint][sample]; taken off the measured torque before anything is fitted, so that the
  /// links and the friction are identified on top of those causes, never absorbing them a
  /// second time. Empty: none.
  std::vector<std::vector<double>> known_torque;
};

struct RigidBodyIdResult {
  robot::RobotModel model;            ///< the prior with the identified links
  std::vector<FrictionFit> friction;  ///< per joint
  PayloadEstimate payload;
  std::vector<LinkReport> links;
  int base_parameters = 0;            ///< identifiable rigid-body (+ rotor) parameters
  bool accepted = true;               ///< identified links kept (held-out MSE ratio <= 0.98), else the prior's
  double heldout_mse_ratio = 1.0;     ///< mean over joints of held-out MSE identified / prior + friction
  int free_parameters = 0;            ///< rigid-body (+ rotor) parameters estimated
  double feasibility_step = 1.0;      ///< smallest per-link line-search step from the prior to the unconstrained estimate (1: feasible as is; then the constrained optimum was solved for)
  SigmaChoice acceleration;           ///< the derivative filter used
  std::vector<double> noise_weight;   ///< per-joint residual std used to weight the rows [N·m]
  int train_samples = 0, heldout_samples = 0;
  // RMS of measured minus predicted torque per joint [N·m]:
  std::vector<double> rms_prior_rigid;      ///< whole file, prior rigid body only
  std::vector<double> rms_before;           ///< whole file, prior + friction fitted to it
  std::vector<double> rms_after;            ///< whole file, identified model
  std::vector<double> heldout_rms_prior_rigid, heldout_rms_prior, heldout_rms_after;  ///< held-out samples
  /// Held-out RMS over the rows where the joint moves faster than slow_speed_rad_s.
  std::vector<double> heldout_moving_rms_prior, heldout_moving_rms_after;
  std::vector<double> slow_speed_rad_s;  ///< per joint: slower rows were left out of the fit (0: none)
  std::vector<std::vector<double>> measured;   ///< [joint][sample] torque used
  std::vector<std::vector<double>> predicted;  ///< [joint][sample] identified model
  std::vector<std::vector<double>> ddq;        ///< [joint][sample] filtered acceleration
  std::vector<std::string> notes;              ///< what was assumed or clamped
};

/// Default held-out split: 10 equal blocks, blocks 1, 4 and 7 (0-based) held out.
[[nodiscard]] std::vector<bool> default_train_mask(std::size_t samples);

/// io::torque_columns(rec), currents times each joint's K_I; *joint_sensor = the recording
/// carries a joint torque sensor's reading (tau_j).
[[nodiscard]] std::vector<std::vector<double>> recording_torque(const io::Recording& rec,
                                                                const robot::RobotModel& model, bool* joint_sensor);

/// Throws std::invalid_argument for unusable input (joint count, too few samples,
/// non-uniform steps, no motion).
[[nodiscard]] RigidBodyIdResult identify_rigid_body(const io::Recording& rec, const robot::RobotModel& prior,
                                                    const RigidBodyIdOptions& options);

/// Model torque per joint: rigid body (rotor inertia only when !joint_torque_sensor) plus friction.
[[nodiscard]] std::vector<std::vector<double>> predict_torque(const robot::RobotModel& model,
                                                              const std::vector<FrictionFit>& friction,
                                                              const std::vector<std::vector<double>>& q,
                                                              const std::vector<std::vector<double>>& dq,
                                                              const std::vector<std::vector<double>>& ddq,
                                                              bool joint_torque_sensor);

}  // namespace jg::dyn
