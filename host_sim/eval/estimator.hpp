// The estimation chain as the evaluation drives it: measurements in, compensated external
// torque out, one call per control cycle. Implementations: the host reference (double,
// centralised, from the plant's rigid-body model) and the firmware core (float or Q).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "jointguard/detection/detector.hpp"
#include "jointguard/friction/lugre.hpp"
#include "dynamics/rigid_body.hpp"

namespace jg::eval {

struct EstimatorInput {
  sim::JointVector q, dq, tau_m;  ///< measured position, velocity, motor torque (link side)
  JointMask holding = 0;          ///< bit j: joint j+1's controller holds a constant setpoint
};

class Estimator {
 public:
  virtual ~Estimator() = default;
  virtual void reset(const EstimatorInput& first) = 0;
  /// One cycle: writes the compensated external torque estimate mu [N·m] per joint
  /// (friction prediction removed inside the momentum balance when enabled).
  virtual void step(const EstimatorInput& in, sim::JointVector& mu) = 0;
  [[nodiscard]] virtual std::string name() const = 0;
  /// Joints whose own detector has flagged, as the estimator's nodes report it (distributed
  /// runs: the drives' status frames); 0 for estimators without detectors of their own.
  [[nodiscard]] virtual JointMask reported_flags() const { return 0; }
  /// A drive reports a communication fault (distributed runs): the arm's safe reaction.
  [[nodiscard]] virtual bool communication_fault() const { return false; }
  /// A drive reports an input fault (a sample it could not use, e.g. NaN): the arm holds.
  [[nodiscard]] virtual bool input_fault() const { return false; }
  /// Drives that run the reaction themselves (distributed runs): the master commands it
  /// (node/joint_reaction.hpp; sent before the next cycle's sync) and returns true; false
  /// for estimators without drives (the evaluation loop computes the reaction itself).
  virtual bool command_reaction(Reaction /*reaction*/, JointMask /*collided*/, const sim::JointVector& /*retreat_target*/) {
    return false;
  }
  /// The drives' reaction torques [N·m] (the last each sent); false until every drive has.
  [[nodiscard]] virtual bool reaction_torque(sim::JointVector& /*torque*/) const { return false; }
};

struct ReferenceEstimatorConfig {
  std::vector<sim::PlantLink> links;
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  double dt = 0.001;
  std::vector<double> gain;  ///< first-order observer gain K per joint [1/s]
  bool compensate_friction = true;
  std::vector<LuGreParams<double>> friction;  ///< identified LuGre per joint
};

/// Host reference: p = M(q) dq and beta = g - C^T dq from the rigid-body model (C^T dq by
/// M' dq - C dq, M' along dq by central differences), first-order observer
/// r = K (sum(tau_m - beta - f - r) dt - (p - p0)) with the LuGre prediction f fed into
/// the balance; mu = -r estimates the external torque J^T F. Double precision,
/// centralised: the yardstick for the firmware.
std::unique_ptr<Estimator> make_reference_estimator(const ReferenceEstimatorConfig& c);

}  // namespace jg::eval
