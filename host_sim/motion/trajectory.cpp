#include "motion/trajectory.hpp"

#include <algorithm>
#include <random>
#include <stdexcept>

namespace jg::sim {

ExcitationTrajectory::ExcitationTrajectory(JointVector offset, std::vector<bool> active, PaperExcitation excitation,
                                           double direction)
    : offset_(std::move(offset)), active_(std::move(active)), excitation_(excitation), direction_(direction) {
  if (active_.size() != static_cast<std::size_t>(offset_.size())) {
    throw std::invalid_argument("ExcitationTrajectory: one active flag per joint");
  }
}

TrajectorySample ExcitationTrajectory::at(double t) const {
  const Eigen::Index n = offset_.size();
  TrajectorySample s{offset_, JointVector::Zero(n), JointVector::Zero(n)};
  const JointSample e = excitation_.at(t);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (active_[static_cast<std::size_t>(j)]) {
      s.q(j) += direction_ * e.q;
      s.dq(j) = direction_ * e.dq;
      s.ddq(j) = direction_ * e.ddq;
    }
  }
  return s;
}

WaypointTrajectory::WaypointTrajectory(JointVector start, std::vector<Waypoint> waypoints)
    : start_(std::move(start)), waypoints_(std::move(waypoints)) {
  move_end_.reserve(waypoints_.size());
  dwell_end_.reserve(waypoints_.size());
  double t0 = 0.0;
  for (const auto& w : waypoints_) {
    if (w.q.size() != start_.size() || !(w.move_s > 0.0) || w.dwell_s < 0.0) {
      throw std::invalid_argument("WaypointTrajectory: waypoint size or timing invalid");
    }
    duration_ += w.move_s + w.dwell_s;
    t0 += w.move_s;
    move_end_.push_back(t0);
    t0 += w.dwell_s;
    dwell_end_.push_back(t0);
  }
}

TrajectorySample WaypointTrajectory::at(double t) const {
  const Eigen::Index n = start_.size();
  // The first waypoint whose dwell ends after t (the ends never decrease): t is in its
  // move or its dwell; none: past the last waypoint.
  const auto k = static_cast<std::size_t>(std::upper_bound(dwell_end_.begin(), dwell_end_.end(), t) - dwell_end_.begin());
  if (k == waypoints_.size()) {
    return {waypoints_.empty() ? start_ : waypoints_.back().q, JointVector::Zero(n), JointVector::Zero(n)};
  }
  const Waypoint& w = waypoints_[k];
  const JointVector& from = k == 0 ? start_ : waypoints_[k - 1].q;
  if (!(t < move_end_[k])) {
    return {w.q, JointVector::Zero(n), JointVector::Zero(n)};  // dwelling at it
  }
  const double t0 = k == 0 ? 0.0 : dwell_end_[k - 1];
  TrajectorySample s{JointVector(n), JointVector(n), JointVector(n)};
  // Rest-to-rest quintic: s(u) = 10u^3 - 15u^4 + 6u^5.
  const double u = std::clamp((t - t0) / w.move_s, 0.0, 1.0);
  const double pos = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
  const double vel = 30.0 * u * u * (1.0 - u) * (1.0 - u) / w.move_s;
  const double acc = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / (w.move_s * w.move_s);
  const JointVector delta = w.q - from;
  s.q = from + pos * delta;
  s.dq = vel * delta;
  s.ddq = acc * delta;
  return s;
}

std::unique_ptr<Trajectory> make_pick_task(const JointVector& home, const JointVector& workpiece, int repetitions) {
  JointVector above = workpiece;
  if (above.size() >= 3) {
    above(1) -= 0.15;  // shoulder back and elbow in: above the workpiece
    above(2) -= 0.10;
  }
  std::vector<WaypointTrajectory::Waypoint> wps;
  using P = PickPhases;
  for (int r = 0; r < repetitions; ++r) {
    wps.push_back({above, P::kToAboveMoveS, P::kAboveDwellS});
    wps.push_back({workpiece, P::kDownMoveS, P::kGraspDwellS});
    wps.push_back({above, P::kUpMoveS, P::kLiftedDwellS});
    wps.push_back({home, P::kHomeMoveS, P::kHomeDwellS});
  }
  return std::make_unique<WaypointTrajectory>(home, std::move(wps));
}

namespace {
/// Every random move lasts at least 0.5 s: the most moves a motion of `total_s` holds (a
/// reservation only, none beyond 10^7 s: the vector then grows as it must).
std::size_t moves_upper_bound(double total_s) {
  return total_s > 0.0 && total_s < 1.0e7 ? static_cast<std::size_t>(total_s / 0.5) + 1U : 0U;
}
}  // namespace

std::unique_ptr<Trajectory> make_random_moves(const JointVector& start, const JointVector& lower,
                                              const JointVector& upper, double max_speed, double total_s,
                                              unsigned long long seed) {
  if (!(max_speed > 0.0) || lower.size() != start.size() || upper.size() != start.size()) {
    throw std::invalid_argument("make_random_moves: bounds or speed invalid");
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<WaypointTrajectory::Waypoint> wps;
  wps.reserve(moves_upper_bound(total_s));
  JointVector from = start;
  double t = 0.0;
  while (t < total_s) {
    JointVector target(start.size());
    for (Eigen::Index j = 0; j < start.size(); ++j) target(j) = lower(j) + (upper(j) - lower(j)) * unit(rng);
    const double distance = (target - from).cwiseAbs().maxCoeff();
    const double move = std::max(0.5, 1.875 * distance / max_speed);
    const double dwell = 0.2 * unit(rng);
    from = target;
    wps.push_back({std::move(target), move, dwell});  // one allocation per move, not two
    t += move + dwell;
  }
  return std::make_unique<WaypointTrajectory>(start, std::move(wps));
}

std::unique_ptr<Trajectory> make_random_moves_with_holds(const JointVector& start, const JointVector& lower,
                                                         const JointVector& upper, double max_speed, double total_s,
                                                         unsigned long long seed, const HoldingMotion& holds) {
  if (!(max_speed > 0.0) || lower.size() != start.size() || upper.size() != start.size() || start.size() < 1 ||
      !(holds.long_dwell_min_s >= 0.0) || !(holds.long_dwell_max_s >= holds.long_dwell_min_s)) {
    throw std::invalid_argument("make_random_moves_with_holds: bounds, speed or dwell invalid");
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<WaypointTrajectory::Waypoint> wps;
  wps.reserve(moves_upper_bound(total_s));
  JointVector from = start;
  double t = 0.0;
  while (t < total_s) {
    JointVector target = from;
    const auto keep_moving = static_cast<Eigen::Index>(unit(rng) * static_cast<double>(start.size())) % start.size();
    for (Eigen::Index j = 0; j < start.size(); ++j) {
      const double draw = lower(j) + (upper(j) - lower(j)) * unit(rng);
      if (j == keep_moving || unit(rng) >= holds.hold_probability) target(j) = draw;
    }
    const double distance = (target - from).cwiseAbs().maxCoeff();
    const double move = std::max(0.5, 1.875 * distance / max_speed);
    const double dwell = unit(rng) < holds.long_dwell_probability
                             ? holds.long_dwell_min_s + (holds.long_dwell_max_s - holds.long_dwell_min_s) * unit(rng)
                             : 0.2 * unit(rng);
    from = target;
    wps.push_back({std::move(target), move, dwell});
    t += move + dwell;
  }
  return std::make_unique<WaypointTrajectory>(start, std::move(wps));
}

}  // namespace jg::sim
