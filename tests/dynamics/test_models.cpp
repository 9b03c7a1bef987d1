// Robot descriptions: a URDF serial chain reads into the same constants as the equivalent
// YAML; and the firmware chain on the reference arm in Q16.16 stays within a stated bound
// of float over a 60 s run (observer output, friction compensated).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "eval/pipeline.hpp"
#include "models/paper_friction.hpp"
#include "robot/robot_model.hpp"
#include "sim/scenario.hpp"
#include "sim/simulation.hpp"

namespace {
TEST(RobotModel, UrdfChainMatchesModifiedDh) {
  const auto path = std::filesystem::temp_directory_path() / ("jg_arm_" + std::to_string(::getpid()) + ".urdf");
  std::ofstream(path) << R"(<?xml version="1.0"?>
<robot name="two">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0.01 -0.05" rpy="0 0 0"/><mass value="4"/>
    <inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.02"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.2 0 0.02" rpy="0 0 0"/><mass value="3.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.06" iyz="0" izz="0.06"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.3" rpy="0 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2.9" upper="2.9" effort="100" velocity="2"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0" rpy="1.5707963267948966 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-1.6" upper="2.6" effort="100" velocity="2"/></joint>
</robot>)";
  const auto urdf = jg::robot::load_robot(path.string());
  const auto yaml = jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  ASSERT_EQ(urdf.joints.size(), 2U);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_NEAR(urdf.joints[j].link.alpha_prev, yaml.joints[j].link.alpha_prev, 1e-12);
    EXPECT_NEAR(urdf.joints[j].link.d, yaml.joints[j].link.d, 1e-12);
    EXPECT_NEAR(urdf.joints[j].link.a_prev, yaml.joints[j].link.a_prev, 1e-12);
    EXPECT_NEAR(urdf.joints[j].link.mass, yaml.joints[j].link.mass, 1e-12);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(urdf.joints[j].link.com[k], yaml.joints[j].link.com[k], 1e-12);
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(urdf.joints[j].link.inertia_com[k], yaml.joints[j].link.inertia_com[k], 1e-12);
  }
  std::filesystem::remove(path);
}

TEST(FirmwareChain, Q16WithinBoundOfFloatOverSixtySecondsOfTheReferenceArm) {
  auto scenario = jg::sim::load_scenario(std::string(JG_SOURCE_DIR) + "/scenarios/free_motion.yaml");
  scenario.setup.duration_s = 60.0;
  const auto rec = jg::sim::run_simulation(scenario.setup).recording;
  const auto model = jg::robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  const std::vector<jg::LuGreParams<double>> friction(jg::sim::kPaperTable1.begin(), jg::sim::kPaperTable1.end());
  const jg::ObserverGains gains{jg::ObserverKind::first_order, 150.0, 0.0, 0.0};
  const auto f = jg::eval::observer_disturbance(rec, model, gains, true, friction, "float");
  const auto q = jg::eval::observer_disturbance(rec, model, gains, true, friction, "q");
  double worst = 0.0;
  for (std::size_t j = 0; j < f.size(); ++j) {
    for (std::size_t k = 0; k < f[j].size(); ++k) worst = std::max(worst, std::fabs(f[j][k] - q[j][k]));
  }
  std::printf("Q16.16 vs float, 60 s of the reference arm, 1 kHz: worst |difference| of the estimate %.4f N·m\n", worst);
  EXPECT_LT(worst, 0.02);
}
}  // namespace
