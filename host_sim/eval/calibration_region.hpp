// What a calibration covered (issue 15.3): the region of positions, velocities and
// accelerations of its collision-free motion, the band's growth beyond its hardest
// acceleration (stops more abrupt than the calibration's), and the holding detector's
// change threshold from the recording's own holds. Written into the threshold JSON
// (calibrate) and used by replay (pipeline.hpp, ReplayOptions).
#pragma once

#include <string>
#include <vector>

#include "eval/pipeline.hpp"

namespace jg::eval {

/// The acceleration is taken over this long: (dq_k - dq_{k-m}) / (m dt), m = baseline/dt.
inline constexpr double kAccelBaselineS = 0.01;
/// m above for sample time dt (at least 1).
[[nodiscard]] inline std::size_t accel_baseline(double dt) {
  const double m = kAccelBaselineS / dt;
  return m < 1.5 ? 1 : static_cast<std::size_t>(m + 0.5);
}
/// |acceleration| of joint j at sample k >= m [rad/s^2].
[[nodiscard]] inline double accel_at(const io::Recording& r, std::size_t j, std::size_t k, std::size_t m, double dt) {
  const double d = r.dq[j][k] - r.dq[j][k - m];
  return (d < 0 ? -d : d) / (static_cast<double>(m) * dt);
}

/// Fills t.q_min, q_max, dq_max, ddq_max and stop_gain from the segments (after settle_s
/// of each): the acceleration is the difference of the measured velocity over
/// kAccelBaselineS (accel_baseline: at 1 kHz the velocity from encoder differences steps
/// by a count per sample, which a one-sample difference turns into 12 rad/s^2); stop_gain is the largest
/// |mu| / |ddq| over the samples at half the largest acceleration or more: how much
/// estimate the model leaves per rad/s^2 where the calibration accelerated hardest,
/// extended linearly beyond it.
void cover_region(Thresholds& t, const std::vector<io::Recording>& segments, const robot::RobotModel& model,
                  const std::vector<LuGreParams<double>>& friction, const ObserverGains& gains, double settle_s,
                  const std::string& scalar = "float");

/// The holding detector's change threshold from the recording's holds (holding_flags with
/// `o`): the largest change from the reference while armed (t.hold_band), times
/// kHoldFactor plus kHoldMargin (experiments.hpp), as the simulated calibration does.
/// `required` (the user asked for holds): every joint so, and it throws when the recording
/// holds nowhere long enough to arm. Otherwise (the default calibration of any recording) a
/// joint armed less than kHoldMinArmedS gets kHoldFrictionFraction x its friction level
/// (pipeline.hpp) instead; t.hold_source says which.
void calibrate_holds(Thresholds& t, const std::vector<io::Recording>& segments, const robot::RobotModel& model,
                     const std::vector<LuGreParams<double>>& friction, const ObserverGains& gains, const ReplayOptions& o,
                     double settle_s, bool required, const std::string& scalar = "float");

/// The segments cut to [t_begin, t_end] (recording time stamps); empty pieces dropped.
std::vector<io::Recording> time_window(const std::vector<io::Recording>& segments, double t_begin, double t_end);

}  // namespace jg::eval
