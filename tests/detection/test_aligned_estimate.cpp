// The aligned estimate (host_sim/eval/aligned_estimate.hpp): the firmware's first-order
// observer on a single rigid joint whose motor torque steps (the stop reaction's damping
// term) reads half the step as a disturbance for one sample; the correction removes it.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "eval/aligned_estimate.hpp"
#include "jointguard/observer/momentum_observer.hpp"

namespace {

struct StepRun {
  double largest_estimate = 0.0;          ///< max |mu| of the firmware's observer [N·m]
  double largest_aligned_estimate = 0.0;  ///< max |mu + correction| [N·m]
};

/// A joint of inertia I [kg m^2] with no friction, gravity or contact: the true external
/// torque is 0 throughout. The motor torque is held over each sample (zero-order hold) and
/// steps from `before` to `after` [N·m] at sample 200; positions are integrated exactly,
/// velocities are position differences over one sample (as the motor encoder gives them).
/// The observer balances with the torque of the sample (the former firmware balance, which
/// the correction is for); `torque_mean` also runs the firmware's balance with the torque
/// mean, whose estimate the corrected one must equal.
StepRun run_step(double before, double after, double* largest_difference_to_torque_mean = nullptr) {
  constexpr double kInertia = 0.8, kDt = 0.001, kGain = 150.0;
  jg::ObserverGains former{jg::ObserverKind::first_order, kGain, 0.0, 0.0};
  former.align_motor_torque = false;
  jg::ObserverGains mean_gains = former;
  mean_gains.align_motor_torque = true;
  jg::ObserverCoeffs<double> coeffs{}, mean_coeffs{};
  EXPECT_EQ(jg::discretize(former, kDt, coeffs), jg::Error::ok);
  EXPECT_EQ(jg::discretize(mean_gains, kDt, mean_coeffs), jg::Error::ok);
  jg::ObserverState<double> state{}, mean_state{};
  jg::eval::AlignedEstimate aligned(1, kGain, kDt);
  double q = 0.0, v = 0.3, q_last = -v * kDt, held = before;
  StepRun out;
  for (int k = 0; k < 400; ++k) {
    // Sample k: the torque measured is the one held over [k-1, k].
    const double velocity = (q - q_last) / kDt;
    const double mu = -jg::observer_step(coeffs, state, kInertia * velocity, held, 0.0, 0.0);
    const double mu_mean = -jg::observer_step(mean_coeffs, mean_state, kInertia * velocity, held, 0.0, 0.0);
    Eigen::VectorXd tau(1);
    tau(0) = held;
    aligned.step(tau);
    if (k > 150) {  // the start-up transient (velocity differences from rest) has decayed
      out.largest_estimate = std::max(out.largest_estimate, std::fabs(mu));
      out.largest_aligned_estimate = std::max(out.largest_aligned_estimate, std::fabs(mu + aligned.correction(0)));
      if (largest_difference_to_torque_mean != nullptr) {
        *largest_difference_to_torque_mean =
            std::max(*largest_difference_to_torque_mean, std::fabs(mu + aligned.correction(0) - mu_mean));
      }
    }
    // The command for [k, k+1].
    held = k + 1 >= 200 ? after : before;
    const double a = held / kInertia;
    q_last = q;
    q += v * kDt + 0.5 * a * kDt * kDt;
    v += a * kDt;
  }
  return out;
}

TEST(AlignedEstimate, TakesTheTorqueStepOutOfTheEstimateOfAJointWithoutContact) {
  // A 50 N·m step: the firmware's estimate jumps by (1 - exp(-0.15)) x 25 = 3.48 N·m, three
  // times the ref3 elbow's moving threshold (1.2 N·m) with no contact at all.
  const StepRun r = run_step(0.0, -50.0);
  EXPECT_NEAR(r.largest_estimate, (1.0 - std::exp(-0.15)) * 25.0, 0.05);
  EXPECT_LT(r.largest_aligned_estimate, 1e-6);
}

TEST(AlignedEstimate, EqualsTheFirmwareObserverBalancedWithTheTorqueMean) {
  // The correction is what the firmware's torque mean (align_motor_torque) does at the source.
  double difference = 0.0;
  (void)run_step(5.0, -45.0, &difference);
  EXPECT_LT(difference, 1e-9);
}

TEST(AlignedEstimate, ConstantTorqueNeedsNoCorrection) {
  const StepRun r = run_step(10.0, 10.0);
  EXPECT_LT(r.largest_estimate, 1e-6);
  EXPECT_LT(r.largest_aligned_estimate, 1e-6);
}

TEST(AlignedEstimate, OffForOtherObserverKinds) {
  jg::eval::AlignedEstimate aligned(2, 0.0, 0.001);
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(2);
  aligned.step(tau);
  tau(0) = 40.0;
  aligned.step(tau);
  EXPECT_FALSE(aligned.enabled());
  EXPECT_EQ(aligned.correction(0), 0.0);
}

}  // namespace
