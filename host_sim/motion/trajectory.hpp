// Joint-space reference trajectories for the simulated controller.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "motion/excitation.hpp"
#include "dynamics/rigid_body.hpp"

namespace jg::sim {

struct TrajectorySample {
  JointVector q, dq, ddq;
};

class Trajectory {
 public:
  virtual ~Trajectory() = default;
  [[nodiscard]] virtual TrajectorySample at(double t) const = 0;
  [[nodiscard]] virtual double duration() const = 0;
  [[nodiscard]] virtual int joints() const = 0;
};

/// The holding flags the controller gives the drives: every bit set when the whole arm
/// holds its setpoint (every joint's reference velocity and acceleration exactly zero, as
/// in a dwell), else none. A joint held while others move is not flagged: the reaction
/// torques of the moving links load its held friction, so its estimate drifts by up to
/// 2 N·m without contact (measured in the holding calibration). At most 8 joints.
[[nodiscard]] inline std::uint8_t holding_mask(const TrajectorySample& r) {
  for (Eigen::Index j = 0; j < r.dq.size(); ++j) {
    if (r.dq(j) != 0.0 || r.ddq(j) != 0.0) return 0;
  }
  return static_cast<std::uint8_t>(r.dq.size() >= 8 ? 0xFFU : (1U << r.dq.size()) - 1U);
}

/// The paper's excitation on the selected joints about an offset posture; `direction`
/// -1 runs the same path with reversed velocity (paper Table 2 validation).
class ExcitationTrajectory final : public Trajectory {
 public:
  ExcitationTrajectory(JointVector offset, std::vector<bool> active, PaperExcitation excitation, double direction = 1.0);
  [[nodiscard]] TrajectorySample at(double t) const override;
  [[nodiscard]] double duration() const override { return excitation_.duration(); }
  [[nodiscard]] int joints() const override { return static_cast<int>(offset_.size()); }
  [[nodiscard]] const PaperExcitation& excitation() const { return excitation_; }

 private:
  JointVector offset_;
  std::vector<bool> active_;
  PaperExcitation excitation_;
  double direction_;
};

/// Rest-to-rest quintic moves through joint-space waypoints, with dwell times.
class WaypointTrajectory final : public Trajectory {
 public:
  struct Waypoint {
    JointVector q;
    double move_s = 1.0;   ///< duration of the move that reaches this waypoint
    double dwell_s = 0.0;  ///< rest at the waypoint afterwards
  };
  WaypointTrajectory(JointVector start, std::vector<Waypoint> waypoints);
  [[nodiscard]] TrajectorySample at(double t) const override;
  [[nodiscard]] double duration() const override { return duration_; }
  [[nodiscard]] int joints() const override { return static_cast<int>(start_.size()); }

 private:
  JointVector start_;
  std::vector<Waypoint> waypoints_;
  /// Waypoint k's move ends at move_end_[k] and its dwell at dwell_end_[k] [s], summed in
  /// the order the linear scan summed them (the same doubles): at(t) finds its waypoint by
  /// binary search instead of a scan from the start, which made a long run quadratic.
  std::vector<double> move_end_, dwell_end_;
  double duration_ = 0.0;
};

/// The same path run backwards in time: position q(T - t), velocity -dq(T - t),
/// acceleration ddq(T - t). At every position the velocity is reversed and gravity and
/// inertia are the same, so half the torque difference of the two runs is the friction
/// (the paper's Table 2 validation).
class ReversedTrajectory final : public Trajectory {
 public:
  explicit ReversedTrajectory(std::shared_ptr<const Trajectory> base) : base_(std::move(base)) {}
  [[nodiscard]] TrajectorySample at(double t) const override {
    TrajectorySample s = base_->at(base_->duration() - t);
    s.dq = -s.dq;
    return s;
  }
  [[nodiscard]] double duration() const override { return base_->duration(); }
  [[nodiscard]] int joints() const override { return base_->joints(); }

 private:
  std::shared_ptr<const Trajectory> base_;
};

/// The pick task's moves and dwells [s]: each move is followed by its dwell.
struct PickPhases {
  static constexpr double kToAboveMoveS = 2.0, kAboveDwellS = 0.2;
  static constexpr double kDownMoveS = 1.0, kGraspDwellS = 0.5;
  static constexpr double kUpMoveS = 1.0, kLiftedDwellS = 0.2;
  static constexpr double kHomeMoveS = 2.0, kHomeDwellS = 0.5;
};
/// One repetition's duration (7.4 s), summed from the phases make_pick_task uses.
constexpr double kPickCycleS = PickPhases::kToAboveMoveS + PickPhases::kAboveDwellS + PickPhases::kDownMoveS +
                               PickPhases::kGraspDwellS + PickPhases::kUpMoveS + PickPhases::kLiftedDwellS +
                               PickPhases::kHomeMoveS + PickPhases::kHomeDwellS;
/// Pick task: from `home` to above a workpiece lower left, down to it, dwell, up, home.
std::unique_ptr<Trajectory> make_pick_task(const JointVector& home, const JointVector& workpiece, int repetitions = 1);
/// Random smooth point-to-point moves within [lower, upper], seeded; each move's duration
/// keeps the peak joint speed (1.875 x mean for a quintic) under `max_speed`.
std::unique_ptr<Trajectory> make_random_moves(const JointVector& start, const JointVector& lower,
                                              const JointVector& upper, double max_speed, double total_s,
                                              unsigned long long seed);

/// Random moves in which joints hold: in each move every joint stays where it is with
/// probability `hold_probability` (at least one joint moves), and a dwell lasts
/// `long_dwell_min_s`..`long_dwell_max_s` with probability `long_dwell_probability`, else
/// up to 0.2 s (as make_random_moves). A joint that stays holds a constant setpoint while
/// the others move: what a cobot does when a person walks up to it.
struct HoldingMotion {
  double hold_probability = 0.4;
  double long_dwell_probability = 0.3;
  double long_dwell_min_s = 0.5, long_dwell_max_s = 4.0;
};
std::unique_ptr<Trajectory> make_random_moves_with_holds(const JointVector& start, const JointVector& lower,
                                                         const JointVector& upper, double max_speed, double total_s,
                                                         unsigned long long seed, const HoldingMotion& holds = {});

}  // namespace jg::sim
