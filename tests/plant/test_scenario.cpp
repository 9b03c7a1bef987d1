// Scenario and robot files: the shipped ones load; bad ones are refused naming file,
// line and field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/recording.hpp"
#include "robot/robot_model.hpp"
#include "sim/scenario.hpp"

namespace {
namespace fs = std::filesystem;
const std::string kSrc = JG_SOURCE_DIR;

std::string error_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const jg::io::FormatError& e) {
    return e.what();
  }
  return "no error";
}

std::string write_temp(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / ("jg_scn_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / name) << text;
  return (dir / name).string();
}

TEST(Scenario, ShippedScenariosAndModelsLoad) {
  for (const auto& entry : fs::directory_iterator(kSrc + "/scenarios")) {
    const auto s = jg::sim::load_scenario(entry.path().string());
    // The Panda's scenarios run its 7-joint model, the others the 3-joint arms.
    const bool panda = entry.path().filename().string().rfind("panda_", 0) == 0;
    EXPECT_EQ(s.model.links.size(), panda ? 7U : 3U) << entry.path();
  }
  EXPECT_EQ(jg::robot::load_robot(kSrc + "/models/panda.yaml").joints.size(), 7U);
}

TEST(Scenario, BadFilesNameFileLineAndField) {
  const std::string base = "model: " + kSrc + "/models/ref3.yaml\ntrajectory:\n  type: pick\n  home_rad: [0, 0.6, -0.8]\n  workpiece_rad: [0.5, 1.0, -1.2]\n";
  auto p = write_temp("unit.yaml", base + "duration_ms: 20\n");
  std::string e = error_of([&] { (void)jg::sim::load_scenario(p); });
  EXPECT_NE(e.find("unit.yaml:6:14: field 'duration_ms': unknown key"), std::string::npos) << e;
  p = write_temp("text.yaml", base + "duration_s: 20 ms\n");
  e = error_of([&] { (void)jg::sim::load_scenario(p); });
  EXPECT_NE(e.find("text.yaml:6:13: field 'duration_s': '20 ms' is not a number"), std::string::npos) << e;
  p = write_temp("nan.yaml", base + "control_rate_hz: .nan\n");
  e = error_of([&] { (void)jg::sim::load_scenario(p); });
  EXPECT_NE(e.find("field 'control_rate_hz'"), std::string::npos) << e;
  p = write_temp("coll.yaml", base + "collisions:\n  - {t_s: 1, link: 5, point_m: [0,0,0], direction: [1,0,0], peak_force_n: 50}\n");
  e = error_of([&] { (void)jg::sim::load_scenario(p); });
  EXPECT_NE(e.find("field 'collisions[0].link'"), std::string::npos) << e;
  p = write_temp("arm.yaml", "name: x\njoints:\n  - {mass_kg: -1, com_m: [0,0,0], inertia_kg_m2: {xx: 1, yy: 1, zz: 1}}\n");
  e = error_of([&] { (void)jg::robot::load_robot(p); });
  EXPECT_NE(e.find("arm.yaml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("mass_kg"), std::string::npos) << e;
}
}  // namespace
