// Collisions: a force on a chosen link at a chosen point, in a chosen direction, with a
// profile. The external joint torque it causes (J^T F) is the ground truth recorded.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "plant/plant.hpp"

namespace jg::sim {

enum class CollisionProfile {
  impact,  ///< half-sine pulse of `duration_s`
  push,    ///< linear ramp over `rise_s` to the peak, held until `duration_s`, released over `rise_s`
  clamp,   ///< a stiff obstacle appears at the contact point: force = stiffness x penetration
           ///< (plus damping), capped at the peak, for `duration_s`; depends on the arm's motion
  free,    ///< a free body part (effective mass `body_mass_kg`) through its tissue spring: the arm
           ///< pushes it away (transient contact, ISO/TS 15066); compressive only, capped at the peak
};

[[nodiscard]] const char* to_string(CollisionProfile p);
[[nodiscard]] bool parse_profile(const std::string& s, CollisionProfile& out);

struct CollisionEvent {
  double t_start = 0.0;     ///< [s]
  int link = 1;             ///< 1-based link number
  Eigen::Vector3d point_in_link = Eigen::Vector3d::Zero();  ///< [m], link frame
  Eigen::Vector3d direction_base{1.0, 0.0, 0.0};            ///< unit, base frame (force direction)
  CollisionProfile profile = CollisionProfile::impact;
  double peak_force_n = 100.0;
  double duration_s = 0.1;
  double rise_s = 0.1;
  double stiffness_n_per_m = 25000.0;  ///< clamp only (ISO/TS 15066 body-region order)
  double damping_n_s_per_m = 200.0;    ///< clamp only
  double body_mass_kg = 0.0;           ///< free only: the body part's effective mass [kg]
  std::string body_region;             ///< ISO/TS 15066 region the contact stands for ("" none)
  bool against_motion = false;         ///< clamp/free: the direction is set at the onset, against
                                       ///< the contact point's velocity (the body part in the way)
  /// clamp/free: at the onset a direction the contact point moves away from is mirrored
  /// across the plane normal to its velocity (d -> d - 2 (d.v^) v^ when d.v > 0), so the arm
  /// always moves into the body part; a direction uniform on the sphere stays uniform over
  /// the half-space against the motion. Below `standstill_speed_m_per_s` the arm would never
  /// press on anything: a clamp's obstacle (the body part against its support) then closes in
  /// at `approach_speed_m_per_s`, a person walking into the arm.
  bool into_motion = false;
  double standstill_speed_m_per_s = 0.0;  ///< [m/s] contact point speed below which the arm stands
  double approach_speed_m_per_s = 0.0;    ///< [m/s] the body part's speed into a standing arm
  /// Surface contact (a body part touching the link's cover, not its axis): when non-zero,
  /// the outward normal of the link's surface at `point_in_link` (link frame, unit, across
  /// the link's x axis). The force is then `direction_in_link` (link frame, unit, within the
  /// friction cone around -normal) turned into the base frame at the onset and fixed in the
  /// world from then on, and a clamp's or free body's compression is the travel along the
  /// normal (direction_base is not used). With `into_motion`, a contact on the side the
  /// point moves away from is mirrored at the onset to the side it moves into (normal,
  /// point and direction reflected across the plane through the link axis normal to the
  /// point's velocity across the axis): the body part is where the arm goes.
  Eigen::Vector3d surface_normal_in_link = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction_in_link = Eigen::Vector3d::Zero();
};

/// Where and how a surface contact acted (resolved at its onset): the point on the link
/// [m, link frame] and the force's unit direction [base frame].
struct ResolvedContact {
  int link = 0;  ///< 1-based, 0 = no contact happened
  Eigen::Vector3d point_in_link = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction_base = Eigen::Vector3d::Zero();
};

/// Applies a list of events (at most one active at a time: the earliest active wins).
class CollisionSchedule {
 public:
  explicit CollisionSchedule(std::vector<CollisionEvent> events);
  /// The contact model for Plant::advance. Stateful (clamp obstacles remember where they
  /// appeared); call reset() before reusing.
  ContactForce operator()(double t, const ArmDynamics& arm, const JointVector& q, const JointVector& qd);
  void reset();
  [[nodiscard]] const std::vector<CollisionEvent>& events() const { return events_; }
  /// Event k's point and direction as resolved at its onset (into_motion, surface contacts);
  /// before the onset, as drawn.
  [[nodiscard]] ResolvedContact resolved(std::size_t k) const;

 private:
  /// The contact point's travel since the onset and its speed, both against the event's
  /// direction [m, m/s]; anchors the point (and an against_motion direction) at the onset.
  struct ContactMotion {
    double travel = 0.0, speed = 0.0;
  };
  ContactMotion contact_motion(std::size_t k, double t, const ArmDynamics& arm, const JointVector& q, const JointVector& qd);
  /// into_motion at the onset: mirrors direction_[k] against the contact point's velocity
  /// `v` [m/s, base frame], or at a standing arm sets the body part's own approach.
  void resolve_into_motion(std::size_t k, const Eigen::Vector3d& v);
  /// Surface contacts at the onset: the side of the link (into_motion) and the link-frame
  /// direction turned into the base frame with the link's rotation `R`.
  void resolve_surface(std::size_t k, const Eigen::Matrix3d& R, const Eigen::Vector3d& v);
  std::vector<CollisionEvent> events_;
  std::vector<bool> anchored_;
  std::vector<Eigen::Vector3d> anchor_;
  std::vector<double> body_position_, body_velocity_, last_t_;
  std::vector<Eigen::Vector3d> direction_;  ///< per event, fixed at the onset when against_motion or into_motion
  std::vector<double> onset_t_;             ///< [s] per event, the first call inside it
  std::vector<double> approach_;            ///< [m/s] per event, the body part's own speed into the arm
  std::vector<Eigen::Vector3d> point_;      ///< per event, the point on the link (mirrored at the onset)
  std::vector<Eigen::Vector3d> axis_;       ///< per event, the compression axis: the force direction, or -normal
};

/// Campaign clamps at a standing arm (contact point slower than kClampStandstillSpeed at the
/// onset; in the 1,000-collision campaign 34 clamps start below 0.0085 m/s, the moving ones
/// from 0.011 m/s): the obstacle closes in at kClampApproachSpeed, the median closing speed
/// |v.d| of the moving clamps at their onset there (0.062 m/s), so that a person walking
/// into a standing arm presses like the typical clamp of a moving one.
inline constexpr double kClampStandstillSpeed = 0.01;  // [m/s]
inline constexpr double kClampApproachSpeed = 0.06;    // [m/s]
/// Surface contacts: the reference arm's link cover radius (a design value, like the rest
/// of models/ref3.yaml: a 0.08 m tube) and the friction coefficient of skin or clothing on
/// it (docs/contact-estimate.md, "Surface contacts").
inline constexpr double kSurfaceRadius = 0.04;  // [m]
inline constexpr double kSkinFriction = 0.5;

/// Draws a random campaign (seeded): link from `links`, point along the link, direction
/// (random, unit), profile, time within [t_min, t_max] at least `spacing_s` apart, force.
/// Clamps are drawn `into_motion` (every clamp a real contact, docs/history.md "Campaign
/// draw: every clamp a contact"); the draws themselves, and so every impact and push, are the
/// same as before that change.
struct CampaignSpec {
  std::vector<int> links{2, 3};
  int count = 50;
  double t_min = 2.0, t_max = 60.0, spacing_s = 3.0;
  double force_min_n = 60.0, force_max_n = 150.0;
  std::vector<CollisionProfile> profiles{CollisionProfile::impact, CollisionProfile::push, CollisionProfile::clamp};
  unsigned long long seed = 1;
  bool clamps_into_motion = true;           ///< false: the former draw (a clamp may never be touched)
  double clamp_standstill_speed_m_per_s = kClampStandstillSpeed;
  double clamp_approach_speed_m_per_s = kClampApproachSpeed;
  /// Surface contacts (CollisionEvent::surface_normal_in_link): the point on a link cover of
  /// `surface_radius_m` around the link's x axis at an azimuth drawn uniformly, the force
  /// within the friction cone of `friction_coefficient` around the inward normal (uniform
  /// over the cone's solid angle). Drawn from a stream of its own: link, point along the
  /// link, profile, force, durations and onsets are those of the former draw.
  bool surface_contacts = false;
  double surface_radius_m = kSurfaceRadius;
  double friction_coefficient = kSkinFriction;
};
/// `link_lengths[i]` is the distance along link i's x axis to the next joint (or the
/// tool), used to place the contact point on the link's body.
[[nodiscard]] std::vector<CollisionEvent> draw_campaign(const CampaignSpec& spec, const std::vector<double>& link_lengths);

}  // namespace jg::sim
