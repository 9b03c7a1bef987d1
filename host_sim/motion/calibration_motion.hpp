// A calibration motion that covers the workspace and its stops (issue 15.3): what the
// thresholds are calibrated on must contain every posture, speed and deceleration the arm
// will see, or replay warns and widens its band there (eval/calibration_region.hpp).
//
// Waypoints: each joint's range is cut into `levels` equal slices; every `levels` moves each
// joint visits every slice once, in a shuffled order per joint (a Latin hypercube over the
// joint space, seeded), so the positions cover the whole box however short the run.
// Moves: the peak joint speed cycles through max_speed x (1, 2, ..., speed_steps) /
// speed_steps, so slow and fast motion are both in the calibration. A share `stop_share`
// of the moves ends in an abrupt stop: a trapezoidal velocity profile whose deceleration
// is stop_decel (the largest the arm will do, e.g. a protective stop), the others are
// rest-to-rest quintics (smooth). Each move is followed by a dwell of 0.1..`dwell_max_s`.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "motion/trajectory.hpp"

namespace jg::sim {

struct CalibrationMotion {
  long levels = 5;                 ///< slices per joint range (2..100; long so a reader passes what it read, one check)
  long speed_steps = 3;            ///< peak speeds max_speed x k / speed_steps, k = 1..speed_steps
  double max_speed = 1.0;          ///< [rad/s] the fastest joint's peak speed, fastest moves
  double accel = 4.0;              ///< [rad/s^2] acceleration of the trapezoidal (stop) moves
  double stop_decel = 20.0;        ///< [rad/s^2] deceleration of the abrupt stops
  double stop_share = 0.3;         ///< share of the moves that end in an abrupt stop
  double dwell_max_s = 1.0;        ///< [s] dwell after each move: 0.1 .. this
};

/// A parameter out of range. `field` is its name in a scenario file, so a reader can point at
/// the line that set it; `problem` says what was expected.
class CalibrationMotionError : public std::invalid_argument {
 public:
  CalibrationMotionError(const std::string& field, const std::string& problem)
      : std::invalid_argument("calibration motion: " + field + ": " + problem), field_(field), problem_(problem) {}
  [[nodiscard]] const std::string& field() const noexcept { return field_; }
  [[nodiscard]] const std::string& problem() const noexcept { return problem_; }

 private:
  std::string field_, problem_;
};

/// Throws CalibrationMotionError naming the parameter when one is out of range.
std::unique_ptr<Trajectory> make_calibration_motion(const JointVector& start, const JointVector& lower,
                                                    const JointVector& upper, const CalibrationMotion& c,
                                                    double total_s, unsigned long long seed);

}  // namespace jg::sim
