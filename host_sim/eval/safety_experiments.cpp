#include "eval/safety_experiments.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "eval/distributed_estimator.hpp"
#include "eval/parallel.hpp"

namespace jg::eval {
namespace {
constexpr double kSwingRad = 1.2;  ///< waist swing of the test motion
}

const char* to_string(Reaction r) {
  switch (r) {
    case Reaction::none: return "none";
    case Reaction::stop: return "stop";
    case Reaction::zero_gravity: return "zero_gravity";
    case Reaction::retreat: return "retreat";
    case Reaction::reflex: return "reflex";
  }
  return "unknown";
}

namespace {
/// The drives on the simulated bus, with their own detector bands (the paper's constant
/// threshold plus the standstill allowance) and the configured estimator.
std::unique_ptr<Estimator> bus_estimator(const ExperimentConfig& c, const DetectionConfig& d) {
  DistributedConfig dc;
  dc.estimator.model = c.model;
  dc.estimator.dt = 1.0 / c.rate_hz;
  dc.estimator.observer = c.gains;
  dc.estimator.compensate_friction = !c.friction.empty();
  dc.estimator.friction = c.friction;
  if (c.hold_calibration_s > 0.0 || !c.hold_threshold.empty()) dc.estimator.holding_velocity_deadband = holding_deadband(c.model, c.rate_hz);
  for (std::size_t j = 0; j < d.threshold.size(); ++j) {
    dc.node_thresholds.push_back({d.threshold[j], 0.0, d.low_speed_extra.empty() ? 0.0 : d.low_speed_extra[j], 1.0 / d.low_speed_width});
  }
  dc.debounce_cycles = d.debounce_cycles;
  dc.retreat_s = d.retreat_s;
  dc.reflex_s = d.reflex_s;
  return make_distributed_estimator(dc, c.scalar);
}
}  // namespace

SafetyResult run_safety_case(const ExperimentConfig& c, const SafetyCase& sc, bool keep_force) {
  const safety::BodyRegion& region = safety::body_region(sc.region);
  if (!(sc.joint_speed_rad_s > 0.0)) throw std::invalid_argument("safety case: joint speed must be > 0");
  const int n = static_cast<int>(c.model.joints.size());
  sim::JointVector home = sim::JointVector::Zero(n);
  if (n >= 3) {
    home(1) = 0.6;
    home(2) = -0.8;
  }
  // A rest-to-rest quintic swing of the waist; its peak speed (1.875 x the mean) is the
  // case's speed, reached halfway, where the body part stands.
  sim::JointVector target = home;
  target(0) += kSwingRad;
  const double move_s = 1.875 * kSwingRad / sc.joint_speed_rad_s;
  auto traj = std::make_shared<sim::WaypointTrajectory>(home, std::vector<sim::WaypointTrajectory::Waypoint>{{target, move_s, 3.0}});
  ExperimentConfig cc = c;
  cc.reaction = sc.reaction;
  sim::SimulationSetup setup = base_setup(cc, traj, c.seed * 4099 + 17);
  const double t_contact = 0.5 * move_s;
  // The contact point: the last link's tip (its reach along x), and the direction the body
  // part pushes back: against the point's velocity there.
  const int link = n;
  const auto reaches = c.model.reaches();
  const Eigen::Vector3d point(reaches.empty() ? 0.2 : std::max(0.05, reaches.back()), 0.0, 0.0);
  const sim::ArmDynamics arm(setup.plant.links);
  const auto ref = traj->at(t_contact);
  const Eigen::Vector3d v = arm.point_jacobian(ref.q, link - 1, point) * ref.dq;
  sim::CollisionEvent e;
  e.t_start = t_contact;
  e.link = link;
  e.point_in_link = point;
  e.direction_base = -v.normalized();
  e.profile = sc.kind;
  e.body_region = sc.region;
  e.stiffness_n_per_m = region.spring_n_per_m;
  e.body_mass_kg = region.effective_mass_kg;
  e.damping_n_s_per_m = 200.0;
  e.peak_force_n = 1e4;  // no cap: the force is what the arm's motion makes it
  e.duration_s = 2.0;
  e.rise_s = 0.0;
  setup.collisions = {e};
  setup.duration_s = t_contact + 2.0;
  const DetectionConfig d = detection_for(cc);
  auto est = sc.on_bus ? bus_estimator(cc, d) : estimator_for(cc);
  SafetyResult r;
  r.c = sc;
  r.contact_speed_m_s = v.norm();
  r.run = run_detection(setup, *est, d, sc.region + " " + sim::to_string(sc.kind) + " " + to_string(sc.reaction), false);
  if (r.run.t_detected) r.detection_delay_s = *r.run.t_detected - t_contact;
  // The force from the onset on (the first cycle with a force), per control cycle.
  const auto& f = r.run.contact_force_n;
  const auto onset = std::find_if(f.begin(), f.end(), [](double x) { return x > 0.0; });
  r.outcome = safety::assess(region, std::vector<double>(onset, f.end()), 1.0 / c.rate_hz, sc.contact_area_cm2);
  if (keep_force) r.contact_force_n.assign(onset, f.end());
  r.run.contact_force_n.clear();
  return r;
}

std::vector<AllowedSpeed> allowed_speeds(const ExperimentConfig& c, const std::vector<std::string>& regions,
                                         const std::vector<Reaction>& reactions, const std::vector<double>& speeds, int jobs,
                                         double contact_area_cm2) {
  struct Task {
    std::size_t pair;
    double speed;
    sim::CollisionProfile kind;
  };
  std::vector<Task> tasks;
  const std::size_t pairs = regions.size() * reactions.size();
  for (std::size_t p = 0; p < pairs; ++p) {
    for (const double s : speeds) {
      for (const auto kind : {sim::CollisionProfile::free, sim::CollisionProfile::clamp}) tasks.push_back({p, s, kind});
    }
  }
  std::vector<SafetyResult> results(tasks.size());
  parallel_for(tasks.size(), jobs, [&](std::size_t i) {
    const Task& t = tasks[i];
    SafetyCase sc{regions[t.pair / reactions.size()], t.kind, reactions[t.pair % reactions.size()], t.speed, false, contact_area_cm2};
    results[i] = run_safety_case(c, sc);
  });
  std::vector<AllowedSpeed> out;
  for (std::size_t p = 0; p < pairs; ++p) {
    AllowedSpeed a;
    a.region = regions[p / reactions.size()];
    a.reaction = reactions[p % reactions.size()];
    for (std::size_t i = 0; i < tasks.size(); i += 2) {  // free and clamp of one speed are adjacent
      if (tasks[i].pair != p) continue;
      if (!results[i].outcome.within_limits || !results[i + 1].outcome.within_limits) break;
      a.joint_speed_rad_s = tasks[i].speed;
      a.contact_speed_m_s = std::max(results[i].contact_speed_m_s, results[i + 1].contact_speed_m_s);
    }
    out.push_back(a);
  }
  return out;
}

}  // namespace jg::eval
