// Arm-level diagnosis: causes that are one thing in the world (a payload on the last link,
// picked up at some time or carried throughout; a link's mass; a drive's torque constant,
// against the robot file) are fitted once, across every joint they load, before the
// per-joint diagnosis. Their parameters are shared by all joints; each
// joint's residual is weighted by its own noise level, and friction-like nuisance terms
// per joint (offset, Coulomb sign, viscous) are fitted beside them so that a per-joint
// friction error is not taken for a payload. A cause is claimed only with the same
// evidence the per-joint selection asks for (BIC on the training blocks, held-out gain),
// when it does not make any joint's held-out fit worse, and when its parameters are
// physically plausible (mass > 0, centre of mass within the last link's reach).
#pragma once

#include <vector>

#include "diagnosis/diagnose.hpp"
#include "diagnosis/signals.hpp"
#include "dynamics/rigid_body.hpp"

namespace jg::diag {

struct ArmDiagnosisOptions {
  DiagnoseOptions joint;          ///< blocks, held-out blocks, evidence thresholds
  double com_bound_m = 1.0;       ///< |centre of mass| of a payload, last link frame, at most this
  double min_mass_kg = 0.0;       ///< a payload lighter than this is not claimed
  /// A link's mass error within this share of its nominal mass, its first-moment change
  /// within this share of (nominal mass x com_bound_m).
  double max_link_mass_share = 0.5;
  int max_causes = 2;
  /// Share of a cause's columns (norm) that must lie outside what single joints add on their
  /// own (offset, Coulomb, viscous, rotor inertia). 0.4 (variance inflation ~6): on the test
  /// arm a link's gravity change has 30 % outside over +/-0.6 rad of motion (it is a rotor
  /// inertia there) and 52 % over +/-1.5 rad; a payload 51 %.
  double min_separable = 0.4;
  /// The arm's rated payload [kg] (RobotModel::rated_payload_kg): a heavier payload is not
  /// claimed but reported as an unexplained mismatch of that size. 0 = no rating given: the
  /// bound is then the arm's own mass (no arm carries more than itself).
  double max_payload_kg = 0.0;
  /// Offer a payload picked up during the recording (a step on a 5 % grid) besides one carried
  /// throughout. Off where the model's friction is unknown (against the robot file alone): the
  /// standstill before a motion, where static friction holds any torque, is then fitted as
  /// "not yet picked up".
  bool payload_picked_up = true;
  /// Offer each drive's torque constant (current data against the robot file: the measured
  /// torque a scale of the file's). Off for a joint torque sensor, and after the rigid-body
  /// refit (its base parameters take most of a scale).
  bool torque_constants = false;
  /// A drive's current-to-torque constant is known to +/-30 % (datasheet tolerance plus
  /// magnet temperature, as the per-joint effect's bound); beyond it: not claimed, unexplained.
  double max_torque_constant_error = 0.3;
};

struct ArmDiagnosis {
  std::vector<Finding> findings;             ///< arm-level causes, strongest first
  std::vector<FittedEffect> model;           ///< for prediction (shared coefficients)
  /// Torque each joint carries from the arm-level causes, over the recording [joint][sample].
  std::vector<std::vector<double>> explained;
  std::vector<double> explained_rms;         ///< per joint [N·m]
  /// Causes the data asked for but that are implausible by the robot's description (a
  /// payload above its rating): not claimed, reported with their size.
  std::vector<Finding> unexplained;
  std::vector<std::string> notes;
};

/// Fits the arm-level causes over all joints' signals (payload_columns must be present;
/// otherwise nothing is fitted and a note says so). With the nominal rigid-body model
/// (`arm`), a link's mass and first-moment error (`link_inertial_error`, links other than
/// the last, whose error is a payload) is offered too.
ArmDiagnosis diagnose_arm(const std::vector<JointSignals>& joints, const ArmDiagnosisOptions& o = {},
                          const sim::ArmDynamics* arm = nullptr);

/// The torque the arm-level causes of `model` (ArmDiagnosis::model: payload, link mass and
/// first-moment error, with their shared coefficients) add over other signals of the same
/// arm [joint][sample]. `arm` is needed for a link's error (nullptr: refused).
std::vector<std::vector<double>> predict_arm_causes(const std::vector<FittedEffect>& model,
                                                   const std::vector<JointSignals>& joints,
                                                   const sim::ArmDynamics* arm);

/// The signals with the arm-level causes' torque moved from the residual into the model's
/// torque, and the per-joint payload candidates withdrawn (the cause is fitted once).
std::vector<JointSignals> without_arm_causes(const std::vector<JointSignals>& joints, const ArmDiagnosis& arm);

}  // namespace jg::diag
