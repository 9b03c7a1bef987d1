#include "motion/calibration_motion.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace jg::sim {
namespace {

/// One move from `from` to `to` along a scalar path s(t) in [0, 1], then a dwell.
struct Move {
  JointVector from, to;
  bool abrupt = false;
  double duration = 0.0;  ///< of the motion [s]
  double dwell = 0.0;     ///< [s]
  // Trapezoid in path units (1/s, 1/s^2): accelerate for ta, cruise for tc, decelerate for td.
  double v = 0.0, ta = 0.0, tc = 0.0, td = 0.0;

  /// s, ds/dt, d2s/dt2 at time t from the move's start.
  void path(double t, double& s, double& ds, double& dds) const {
    if (!abrupt) {  // quintic rest to rest
      const double u = std::clamp(t / duration, 0.0, 1.0);
      s = u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
      ds = 30.0 * u * u * (1.0 - u) * (1.0 - u) / duration;
      dds = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / (duration * duration);
      if (t >= duration) ds = dds = 0.0;
      return;
    }
    const double a = v / ta, d = v / td;
    if (t < ta) {
      s = 0.5 * a * t * t, ds = a * t, dds = a;
    } else if (t < ta + tc) {
      s = 0.5 * v * ta + v * (t - ta), ds = v, dds = 0.0;
    } else if (t < duration) {
      const double r = t - ta - tc;
      s = 0.5 * v * ta + v * tc + v * r - 0.5 * d * r * r, ds = v - d * r, dds = -d;
    } else {
      s = 1.0, ds = dds = 0.0;
    }
  }
};

class CalibrationTrajectory final : public Trajectory {
 public:
  CalibrationTrajectory(JointVector start, std::vector<Move> moves) : start_(std::move(start)), moves_(std::move(moves)) {
    for (const auto& m : moves_) duration_ += m.duration + m.dwell;
  }
  [[nodiscard]] TrajectorySample at(double t) const override {
    const auto n = start_.size();
    TrajectorySample out{start_, JointVector::Zero(n), JointVector::Zero(n)};
    double t0 = 0.0;
    for (const auto& m : moves_) {
      if (t < t0 + m.duration + m.dwell) {
        double s = 0.0, ds = 0.0, dds = 0.0;
        m.path(t - t0, s, ds, dds);
        const JointVector delta = m.to - m.from;
        out.q = m.from + s * delta;
        out.dq = ds * delta;
        out.ddq = dds * delta;
        return out;
      }
      t0 += m.duration + m.dwell;
      out.q = m.to;
    }
    return out;
  }
  [[nodiscard]] double duration() const override { return duration_; }
  [[nodiscard]] int joints() const override { return static_cast<int>(start_.size()); }

 private:
  JointVector start_;
  std::vector<Move> moves_;
  double duration_ = 0.0;
};

void check(bool ok, const char* name, const char* what) {
  if (!ok) throw CalibrationMotionError(name, what);
}
}  // namespace

std::unique_ptr<Trajectory> make_calibration_motion(const JointVector& start, const JointVector& lower,
                                                    const JointVector& upper, const CalibrationMotion& c,
                                                    double total_s, unsigned long long seed) {
  const auto n = start.size();
  check(n >= 1 && lower.size() == n && upper.size() == n, "lower_rad/upper_rad", "one value per joint");
  for (Eigen::Index j = 0; j < n; ++j) check(lower(j) < upper(j), "lower_rad", "must be below upper_rad on every joint");
  check(c.levels >= 2 && c.levels <= 100, "levels", "expected 2..100");
  check(c.speed_steps >= 1 && c.speed_steps <= 10, "speed_steps", "expected 1..10");
  check(c.max_speed > 0.0 && c.max_speed <= 10.0, "max_speed_rad_s", "expected in (0, 10]");
  check(c.accel > 0.0 && c.accel <= 1000.0, "accel_rad_s2", "expected in (0, 1000]");
  check(c.stop_decel > 0.0 && c.stop_decel <= 1000.0, "stop_decel_rad_s2", "expected in (0, 1000]");
  check(c.stop_share >= 0.0 && c.stop_share <= 1.0, "stop_share", "expected in [0, 1]");
  check(c.dwell_max_s >= 0.1 && c.dwell_max_s <= 60.0, "dwell_max_s", "expected in [0.1, 60]");
  check(total_s > 0.0 && total_s <= 30.0 * 86400.0, "duration_s", "expected in (0, 30 days]");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto levels = static_cast<std::size_t>(c.levels);
  std::vector<std::vector<std::size_t>> order(static_cast<std::size_t>(n), std::vector<std::size_t>(levels));
  std::vector<Move> moves;
  JointVector from = start;
  double t = 0.0;
  for (std::size_t k = 0; t < total_s; ++k) {
    if (k % levels == 0) {  // a new round: every joint visits each of its slices once
      for (auto& o : order) {
        std::iota(o.begin(), o.end(), std::size_t{0});
        std::shuffle(o.begin(), o.end(), rng);
      }
    }
    Move m;
    m.from = from;
    m.to = from;
    for (Eigen::Index j = 0; j < n; ++j) {
      const double slice = (upper(j) - lower(j)) / static_cast<double>(levels);
      m.to(j) = lower(j) + slice * (static_cast<double>(order[static_cast<std::size_t>(j)][k % levels]) + unit(rng));
    }
    const double distance = (m.to - m.from).cwiseAbs().maxCoeff();
    const double speed = c.max_speed * static_cast<double>(k % static_cast<std::size_t>(c.speed_steps) + 1) /
                         static_cast<double>(c.speed_steps);
    m.abrupt = unit(rng) < c.stop_share && distance > 1e-6;
    if (m.abrupt) {
      // Path units: joint quantities divided by the largest joint travel.
      m.v = speed / distance;
      const double a = c.accel / distance, d = c.stop_decel / distance;
      m.ta = m.v / a;
      m.td = m.v / d;
      double cruise = 1.0 - 0.5 * m.v * (m.ta + m.td);
      if (cruise < 0.0) {  // too short to reach the speed: a triangle
        m.v = std::sqrt(2.0 / (1.0 / a + 1.0 / d));
        m.ta = m.v / a;
        m.td = m.v / d;
        cruise = 0.0;
      }
      m.tc = cruise / m.v;
      m.duration = m.ta + m.tc + m.td;
    } else {
      m.duration = std::max(0.5, 1.875 * distance / speed);
    }
    m.dwell = 0.1 + (c.dwell_max_s - 0.1) * unit(rng);
    t += m.duration + m.dwell;
    from = m.to;
    moves.push_back(std::move(m));
  }
  return std::make_unique<CalibrationTrajectory>(start, std::move(moves));
}

}  // namespace jg::sim
