// Holding-aware detection in closed loop: a small push on a joint whose controller holds
// its setpoint is detected by the change from the estimate at arrival, with no alarm in a
// hold without contact (simulated arm, firmware core in the loop, both scalars).
#include <gtest/gtest.h>

#include <cstdio>

#include "eval/experiments.hpp"
#include "models/paper_friction.hpp"

namespace {
using namespace jg;

eval::ExperimentConfig config(const std::string& scalar) {
  eval::ExperimentConfig c;
  c.model = robot::load_robot(std::string(JG_SOURCE_DIR) + "/models/ref3.yaml");
  c.scalar = scalar;
  for (const auto& p : sim::kPaperTable1) c.friction.push_back(p);
  c.calibration_s = 60.0;
  c.hold_calibration_s = 120.0;
  const eval::Thresholds t = eval::calibrate(c, 0.5);
  c.thresholds = t.threshold;
  c.low_speed_extra = t.low_speed_extra;
  c.low_speed_width = t.low_speed_width;
  c.hold_threshold = t.hold_change;
  c.reaction = Reaction::none;
  return c;
}

/// The arm moves to a posture, then holds it for 6 s; with `torque_nm` > 0 a push on link
/// `link` at 3.5 s loads joint `link` with about that torque.
eval::RunResult held_push(const eval::ExperimentConfig& c, int link, double torque_nm) {
  sim::JointVector home(3), there(3);
  home << 0.0, 0.6, -0.8;
  there << 0.5, 0.9, -1.1;
  auto traj = std::make_shared<sim::WaypointTrajectory>(
      home, std::vector<sim::WaypointTrajectory::Waypoint>{{there, 1.5, 6.0}});
  sim::SimulationSetup s = eval::base_setup(c, traj, 77);
  s.duration_s = 7.0;
  if (torque_nm > 0.0) {
    sim::CollisionEvent e;
    e.t_start = 3.5;
    e.link = link;
    e.point_in_link = {0.2, 0.0, 0.0};
    const sim::ArmDynamics arm(s.plant.links);
    const auto poses = arm.poses(there);
    const Eigen::Vector3d axis = poses.rotation[link - 1].col(2);
    const Eigen::Vector3d lever = poses.rotation[link - 1] * e.point_in_link;
    const Eigen::Vector3d tangential = axis.cross(lever);
    e.direction_base = tangential.normalized();
    e.profile = sim::CollisionProfile::push;
    e.peak_force_n = torque_nm / tangential.norm();
    e.rise_s = 0.03;
    e.duration_s = 1.0;
    s.collisions = {e};
  }
  auto est = eval::estimator_for(c);
  return eval::run_detection(s, *est, eval::detection_for(c), "held push", true);
}

TEST(HoldingDetection, Probe) {
  const auto c = config("float");
  for (double h : c.hold_threshold) std::printf("hold threshold %.3f\n", h);
  const auto r = held_push(c, 1, 2.0);
  std::printf("detected %d at %.4f; held peak %.3f\n", r.t_detected ? 1 : 0, r.t_detected ? *r.t_detected : -1.0, r.peak_true_torque_held);
  for (std::size_t k = 3400; k < 3700 && k < r.trace.t.size(); k += 10) {
    std::printf("t %.3f mu %.3f %.3f %.3f ext %.3f tau_m1 %.3f\n", r.trace.t[k], r.trace.mu[0][k], r.trace.mu[1][k], r.trace.mu[2][k],
                r.trace.tau_ext[0][k], r.recording.tau_m[0][k]);
  }
}
}  // namespace
