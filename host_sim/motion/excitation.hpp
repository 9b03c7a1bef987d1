// Joint-space reference trajectories (host side, double).
#pragma once

namespace jg::sim {

struct JointSample {
  double q = 0.0;    ///< [rad]
  double dq = 0.0;   ///< [rad/s]
  double ddq = 0.0;  ///< [rad/s^2]
};

/// Fifth-degree polynomial from (q0, v0, a0) to (q1, v1, a1) over `duration` seconds.
class QuinticSegment {
 public:
  QuinticSegment(JointSample from, JointSample to, double duration);
  [[nodiscard]] JointSample at(double t) const;  ///< t clamped to [0, duration]
  [[nodiscard]] double duration() const { return duration_; }

 private:
  double c_[6]{};
  double duration_;
};

/// The paper's identification excitation: q = A sin(2 pi f t) for a whole number of
/// periods, joined to rest at both ends by quintic blends (position, velocity and
/// acceleration continuous). The blend from rest starts at q = -A w Tb / 2 so that the
/// blend's mean velocity matches.
class PaperExcitation {
 public:
  explicit PaperExcitation(double amplitude_rad = 0.6, double frequency_hz = 0.2, int periods = 4,
                           double blend_s = 2.5);
  [[nodiscard]] JointSample at(double t) const;
  [[nodiscard]] double duration() const;
  /// Start and end time of the steady sinusoidal part.
  [[nodiscard]] double steady_begin() const { return blend_s_; }
  [[nodiscard]] double steady_end() const;

 private:
  double amplitude_, omega_, blend_s_;
  int periods_;
  QuinticSegment lead_in_, lead_out_;
};

}  // namespace jg::sim
