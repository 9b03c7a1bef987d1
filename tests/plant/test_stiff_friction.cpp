// The plant on a light joint with stiff friction (issue 31: the UR10e diverged at 6 ms with
// the paper's friction on its wrist): the friction is stepped implicitly when the explicit
// step would not resolve it, and the reference arm keeps its explicit step.
#include <gtest/gtest.h>

#include <cmath>

#include <fstream>
#include <string>

#include "models/paper_friction.hpp"
#include "robot/robot_model.hpp"
#include "plant/plant.hpp"
#include "test_arm.hpp"

namespace {
using jg::sim::JointVector;
using jg::sim::Plant;
using jg::sim::PlantConfig;

/// The test arm with a light last link (a wrist: 1 kg, 4.5e-3 kg m^2 about its axis, no rotor), the paper's friction.
PlantConfig light_wrist(double plant_rate_hz) {
  PlantConfig c;
  c.links = jg::test::three_joint_links();
  c.links[2].mass = 1.0;
  c.links[2].com = {0.05, 0.0, 0.0};
  c.links[2].inertia_com = Eigen::Vector3d(1e-3, 2e-3, 2e-3).asDiagonal();
  c.links[2].rotor_inertia = 0.0;
  for (const auto& p : jg::sim::kPaperTable1) c.friction.push_back({p, {}});
  c.plant_rate_hz = plant_rate_hz;
  return c;
}

/// 1 s under a gravity-compensating PD at 1 kHz moving every joint, from rest.
JointVector run(const PlantConfig& c, bool& implicit, bool& finite) {
  Plant plant(c);
  JointVector q0(3);
  q0 << 0.0, 0.6, -0.8;
  plant.reset(q0);
  implicit = plant.implicit_friction();
  finite = true;
  for (int k = 0; k < 1000 && finite; ++k) {
    const double t = 0.001 * k;
    const auto& s = plant.state();
    JointVector target = q0;
    for (int j = 0; j < 3; ++j) target(j) += 0.3 * std::sin(2.0 * t);
    JointVector tau = plant.arm().gravity_torque(s.q);
    const double kp[3] = {400.0, 400.0, 60.0}, kd[3] = {40.0, 40.0, 0.6};
    for (int j = 0; j < 3; ++j) tau(j) += kp[j] * (target(j) - s.q(j)) - kd[j] * s.qd(j);
    plant.advance(0.001, tau);
    finite = plant.state().q.allFinite() && plant.state().qd.allFinite();
  }
  return plant.state().q;
}
}  // namespace

TEST(StiffFriction, ReferenceArmKeepsTheExplicitStep) {
  PlantConfig c;
  c.links = jg::test::three_joint_links();
  for (const auto& p : jg::sim::kPaperTable1) c.friction.push_back({p, {}});
  Plant plant(c);
  JointVector q0(3);
  q0 << 0.0, 0.6, -0.8;
  plant.reset(q0);
  std::printf("reference arm: stiffest friction mode h D / inertia = %.3f at 2 kHz\n", plant.stiffest_friction_mode(q0));
  EXPECT_FALSE(plant.implicit_friction());
}

TEST(StiffFriction, LightWristStaysFiniteAndMatchesAResolvedExplicitStep) {
  bool implicit = false, finite = false;
  const JointVector coarse = run(light_wrist(2000.0), implicit, finite);
  EXPECT_TRUE(implicit) << "a 1 kg wrist with sigma1 ~ 500 N·m·s/rad is beyond the explicit step at 2 kHz";
  ASSERT_TRUE(finite) << "the plant diverged";
  // The same arm at a plant rate that resolves the friction explicitly (h D / inertia < 1.5).
  bool implicit_fine = true, finite_fine = false;
  const JointVector fine = run(light_wrist(400000.0), implicit_fine, finite_fine);
  EXPECT_FALSE(implicit_fine);
  ASSERT_TRUE(finite_fine);
  std::printf("after 1 s: implicit at 2 kHz %.5f %.5f %.5f, explicit at 400 kHz %.5f %.5f %.5f rad\n", coarse(0), coarse(1),
              coarse(2), fine(0), fine(1), fine(2));
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(coarse(j), fine(j), 5e-3) << "joint " << j + 1;
}

TEST(StiffFriction, ReferenceModelFileKeepsTheExplicitStep) {
  // models/ref3.yaml at the campaigns' and the paper runs' start pose, the plant rate of
  // evaluate at 1 kHz and at 125 Hz: its published figures come from the explicit step.
  const auto model = jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  PlantConfig c;
  c.links = model.plant_links();
  for (const auto& p : jg::sim::kPaperTable1) c.friction.push_back({p, {}});
  Plant plant(c);
  JointVector home(3);
  home << 0.0, 0.6, -0.8;
  plant.reset(home);
  std::printf("models/ref3.yaml: stiffest friction mode h D / inertia = %.3f at 2 kHz\n", plant.stiffest_friction_mode(home));
  EXPECT_FALSE(plant.implicit_friction());
  const char* ur = JG_SOURCE_DIR "/../shared/data/real/ur10e-static/ur10e.urdf";
  if (std::ifstream(ur).good()) {
    const auto arm = jg::robot::load_robot(ur);
    const jg::sim::ArmDynamics dyn(arm.plant_links());
    JointVector q = JointVector::Zero(6);
    q(1) = 0.6;
    q(2) = -0.8;
    const auto m = dyn.mass_matrix(q);
    const auto inv = m.inverse();
    for (int j = 0; j < 6; ++j) std::printf("UR10e joint %d: M_jj %.5f, 1/(M^-1)_jj %.5f kg m^2\n", j + 1, m(j, j), 1.0 / inv(j, j));
  }
}
