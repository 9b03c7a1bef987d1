// The torque that reaches a joint's motor, the isolation ceiling's ground truth
// (host_sim/eval/torque_reaching_motor.hpp): a joint standing still loses to its static
// friction what the friction's change takes along the push, nothing else does.
#include <gtest/gtest.h>

#include "eval/torque_reaching_motor.hpp"

namespace jg {
namespace {

constexpr double kDt = 0.001;
constexpr eval::StandstillRule kRule{0.02, 0.005};

/// Two joints, 20 cycles, a contact from cycle 10 on: joint 1 stands still throughout with
/// its friction rising by `change` per cycle of contact, joint 2 moves at 0.5 rad/s.
sim::SimulationResult two_joints(double push_nm, double change_per_cycle_nm) {
  sim::SimulationResult r;
  r.recording.resize(2, 20, true, true, true, true);
  r.plant_friction_nm.assign(2, std::vector<double>(20, 0.3));
  r.plant_speed_rad_s.assign(2, std::vector<double>(20, 0.0));
  for (std::size_t k = 0; k < 20; ++k) {
    r.recording.t[k] = static_cast<double>(k) * kDt;
    r.plant_speed_rad_s[1][k] = 0.5;
    if (k >= 10) {
      r.recording.tau_ext[0][k] = push_nm;
      r.recording.tau_ext[1][k] = 2.0 * push_nm;
      r.plant_friction_nm[0][k] = 0.3 + change_per_cycle_nm * static_cast<double>(k - 9);
      r.plant_friction_nm[1][k] = 0.3 + 0.5;  // a moving joint's friction change is the motion's
    }
  }
  return r;
}

TEST(TorqueReachingMotor, AStuckJointLosesWhatItsFrictionTakesAlongThePush) {
  const sim::SimulationResult r = two_joints(1.0, 0.25);
  const auto out = eval::torque_reaching_motor(r, kDt, kRule);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_DOUBLE_EQ(out[0][9], 0.0);
  EXPECT_NEAR(out[0][10], 0.75, 1e-12);  // 0.25 of the 1 N·m taken
  EXPECT_NEAR(out[0][12], 0.25, 1e-12);
  EXPECT_NEAR(out[0][13], 0.0, 1e-12);  // all of it: the current shows nothing
  EXPECT_NEAR(out[0][19], 0.0, 1e-12);  // never more than the push (the change reaches 2.5)
  for (std::size_t k = 0; k < 20; ++k) EXPECT_DOUBLE_EQ(out[1][k], r.recording.tau_ext[1][k]) << k;
}

TEST(TorqueReachingMotor, AFrictionChangeAgainstThePushTakesNothing) {
  const sim::SimulationResult pushed_down = two_joints(-1.0, 0.25);  // the friction rises, the push is negative
  const auto out = eval::torque_reaching_motor(pushed_down, kDt, kRule);
  for (std::size_t k = 10; k < 20; ++k) EXPECT_DOUBLE_EQ(out[0][k], -1.0) << k;
  const sim::SimulationResult along = two_joints(-1.0, -0.25);
  EXPECT_NEAR(eval::torque_reaching_motor(along, kDt, kRule)[0][11], -0.5, 1e-12);
}

TEST(TorqueReachingMotor, AJointThatSlipsShowsThePushFromThen) {
  sim::SimulationResult r = two_joints(1.0, 0.1);
  for (std::size_t k = 14; k < 20; ++k) r.plant_speed_rad_s[0][k] = 0.05;
  const auto out = eval::torque_reaching_motor(r, kDt, kRule);
  EXPECT_NEAR(out[0][13], 0.6, 1e-12);
  for (std::size_t k = 14; k < 20; ++k) EXPECT_DOUBLE_EQ(out[0][k], 1.0) << k;
}

TEST(TorqueReachingMotor, AJointMovingJustBeforeTheOnsetIsNotStuck) {
  sim::SimulationResult r = two_joints(1.0, 0.25);
  r.plant_speed_rad_s[0][6] = 0.03;  // within the 5 ms before the onset
  const auto out = eval::torque_reaching_motor(r, kDt, kRule);
  for (std::size_t k = 10; k < 20; ++k) EXPECT_DOUBLE_EQ(out[0][k], 1.0) << k;
  r.plant_speed_rad_s[0][6] = 0.0;
  r.plant_speed_rad_s[0][3] = 0.03;  // before that window: stuck again
  EXPECT_NEAR(eval::torque_reaching_motor(r, kDt, kRule)[0][10], 0.75, 1e-12);
}

TEST(TorqueReachingMotor, WithoutThePlantsFrictionThereIsNothingToCount) {
  sim::SimulationResult r = two_joints(1.0, 0.25);
  r.plant_friction_nm.clear();
  EXPECT_TRUE(eval::torque_reaching_motor(r, kDt, kRule).empty());
  sim::SimulationResult untouched = two_joints(0.0, 0.25);  // no contact: tau_ext as it is
  const auto out = eval::torque_reaching_motor(untouched, kDt, kRule);
  ASSERT_EQ(out.size(), 2U);
  for (std::size_t k = 0; k < 20; ++k) EXPECT_DOUBLE_EQ(out[0][k], 0.0);
}

}  // namespace
}  // namespace jg
