// Closed-loop simulation: tracking, collisions recorded as ground truth, determinism.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "models/paper_friction.hpp"
#include "sim/simulation.hpp"
#include "test_arm.hpp"

namespace {
using namespace jg::sim;

SimulationSetup paper_setup(double rate_hz) {
  SimulationSetup s;
  s.plant.links = jg::test::three_joint_links();
  for (const auto& p : kPaperTable1) s.plant.friction.push_back({p, {}});
  s.sensors.drives.assign(3, JointDriveConfig{100.0, 12.0, 0.0, 15.0, 0.0, 0.01, 0.001});
  s.sensors.seed = 5;
  s.controller.kp = {3000.0, 3000.0, 2000.0};
  s.controller.kd = {120.0, 120.0, 80.0};
  JointVector offset(3);
  offset << 0.0, 0.6, -0.8;
  s.trajectory = std::make_shared<ExcitationTrajectory>(offset, std::vector<bool>{true, true, true},
                                                        PaperExcitation(0.6, 0.2, 1, 2.5));
  s.control_rate_hz = rate_hz;
  return s;
}

TEST(Simulation, TracksThePaperExcitation) {
  const auto setup = paper_setup(1000.0);
  const auto r = run_simulation(setup);
  const auto& rec = r.recording;
  double worst = 0.0;
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    const auto ref = setup.trajectory->at(rec.t[k]);
    for (int j = 0; j < 3; ++j) worst = std::max(worst, std::fabs(rec.q[static_cast<std::size_t>(j)][k] - ref.q(j)));
  }
  std::printf("worst tracking error: %.4f rad\n", worst);
  EXPECT_LT(worst, 0.02);
  EXPECT_EQ(rec.samples(), static_cast<std::size_t>(std::floor(setup.trajectory->duration() * 1000.0)) + 1U);
}

TEST(Simulation, CollisionIsRecordedAsGroundTruthOnJointsUpToTheLink) {
  auto setup = paper_setup(1000.0);
  CollisionEvent e;
  e.t_start = 4.0;
  e.link = 2;
  e.point_in_link = {0.3, 0.0, 0.0};
  e.direction_base = {0.0, 0.0, -1.0};
  e.profile = CollisionProfile::push;
  e.peak_force_n = 80.0;
  e.duration_s = 0.5;
  e.rise_s = 0.1;
  setup.collisions = {e};
  const auto r = run_simulation(setup);
  const auto& rec = r.recording;
  double max_ext[3] = {0, 0, 0};
  int flagged = 0;
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    for (std::size_t j = 0; j < 3; ++j) max_ext[j] = std::max(max_ext[j], std::fabs(rec.tau_ext[j][k]));
    if (rec.collision[k] != 0) {
      EXPECT_EQ(rec.collision[k], 2);
      EXPECT_GE(rec.t[k], 4.0);
      EXPECT_LE(rec.t[k], 4.0 + 0.6 + 0.002);
      ++flagged;
    }
  }
  EXPECT_GT(max_ext[1], 5.0);
  EXPECT_EQ(max_ext[2], 0.0) << "a force on link 2 does not load joint 3";
  EXPECT_NEAR(r.peak_contact_force_n, 80.0, 1e-9);
  EXPECT_NEAR(flagged, 600, 3);
}

TEST(Simulation, SameSeedGivesByteIdenticalRecording) {
  const auto dir = std::filesystem::temp_directory_path() / ("jg_det_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name) {
    auto setup = paper_setup(125.0);
    setup.meta.seed = 5;
    jg::io::write_recording((dir / name).string(), run_simulation(setup).recording);
    std::ifstream in(dir / name);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  const std::string a = write("a.csv"), b = write("b.csv");
  std::filesystem::remove_all(dir);
  EXPECT_GT(a.size(), 1000U);
  EXPECT_TRUE(a == b);
}
}  // namespace
