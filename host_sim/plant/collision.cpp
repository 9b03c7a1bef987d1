#include "plant/collision.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace jg::sim {

const char* to_string(CollisionProfile p) {
  switch (p) {
    case CollisionProfile::impact: return "impact";
    case CollisionProfile::push: return "push";
    case CollisionProfile::clamp: return "clamp";
    case CollisionProfile::free: return "free";
  }
  return "unknown";
}

bool parse_profile(const std::string& s, CollisionProfile& out) {
  for (const auto p : {CollisionProfile::impact, CollisionProfile::push, CollisionProfile::clamp, CollisionProfile::free}) {
    if (s == to_string(p)) {
      out = p;
      return true;
    }
  }
  return false;
}

CollisionSchedule::CollisionSchedule(std::vector<CollisionEvent> events) : events_(std::move(events)) {
  for (auto& e : events_) {
    const double n = e.direction_base.norm();
    if (!(n > 0.0) || e.link < 1 || !(e.peak_force_n >= 0.0) || !(e.duration_s > 0.0) || e.rise_s < 0.0) {
      throw std::invalid_argument("CollisionSchedule: invalid collision event (direction, link, force or timing)");
    }
    e.direction_base /= n;
    if (e.surface_normal_in_link.norm() > 0.0) {
      if (!(e.direction_in_link.norm() > 0.0)) {
        throw std::invalid_argument("CollisionSchedule: a surface contact needs its direction in the link frame");
      }
      e.surface_normal_in_link.normalize();
      e.direction_in_link.normalize();
    }
    if (e.profile == CollisionProfile::free && !(e.body_mass_kg > 0.0)) {
      throw std::invalid_argument("CollisionSchedule: a free contact needs the body part's mass (> 0 kg)");
    }
  }
  reset();
}

void CollisionSchedule::reset() {
  anchored_.assign(events_.size(), false);
  anchor_.assign(events_.size(), Eigen::Vector3d::Zero());
  body_position_.assign(events_.size(), 0.0);
  body_velocity_.assign(events_.size(), 0.0);
  last_t_.assign(events_.size(), 0.0);
  direction_.clear();
  for (const auto& e : events_) direction_.push_back(e.direction_base);
  onset_t_.assign(events_.size(), 0.0);
  approach_.assign(events_.size(), 0.0);
  point_.clear();
  for (const auto& e : events_) point_.push_back(e.point_in_link);
  axis_ = direction_;
}

ResolvedContact CollisionSchedule::resolved(std::size_t k) const {
  ResolvedContact c;
  if (k >= events_.size()) return c;
  c.link = anchored_[k] ? events_[k].link : 0;
  c.point_in_link = point_[k];
  c.direction_base = direction_[k];
  return c;
}

namespace {
/// Tissue or obstacle spring: compressive only, capped at the event's peak.
double spring_force(const CollisionEvent& e, double compression, double rate) {
  return compression > 0.0 ? std::clamp(e.stiffness_n_per_m * compression + e.damping_n_s_per_m * rate, 0.0, e.peak_force_n)
                           : 0.0;
}
}  // namespace

CollisionSchedule::ContactMotion CollisionSchedule::contact_motion(std::size_t k, double t, const ArmDynamics& arm,
                                                                   const JointVector& q, const JointVector& qd) {
  const CollisionEvent& e = events_[k];
  const int i = e.link - 1;
  const LinkPoses P = arm.poses(q);
  if (!anchored_[k]) {  // the onset: where the contact is, and (against_motion, into_motion) its direction
    const Eigen::Vector3d v0 = arm.point_jacobian(q, i, point_[k]) * qd;
    anchored_[k] = true;
    onset_t_[k] = t;
    if (e.surface_normal_in_link.norm() > 0.0) {
      resolve_surface(k, P.rotation[i], v0);
    } else {
      if (e.against_motion && v0.norm() > 1e-9) direction_[k] = -v0.normalized();
      if (e.into_motion) resolve_into_motion(k, v0);
      axis_[k] = direction_[k];
    }
    anchor_[k] = P.origin[i] + P.rotation[i] * point_[k];
  }
  const Eigen::Vector3d x = P.origin[i] + P.rotation[i] * point_[k];
  const Eigen::Vector3d v = arm.point_jacobian(q, i, point_[k]) * qd;
  last_t_[k] = t;
  // The body part's own approach (into_motion at a standing arm) adds to the arm's travel.
  const double own = approach_[k];
  return {-(x - anchor_[k]).dot(axis_[k]) + own * (t - onset_t_[k]), -v.dot(axis_[k]) + own};
}

void CollisionSchedule::resolve_into_motion(std::size_t k, const Eigen::Vector3d& v) {
  const CollisionEvent& e = events_[k];
  if (v.norm() < e.standstill_speed_m_per_s || v.norm() <= 0.0) {
    // The arm stands: the obstacle of a clamp closes in (a free body part has no support).
    approach_[k] = e.profile == CollisionProfile::clamp ? e.approach_speed_m_per_s : 0.0;
    return;
  }
  // The arm's travel against d compresses the body part: the arm must move along -d.
  const Eigen::Vector3d u = v.normalized();
  const double along = direction_[k].dot(u);
  if (along > 0.0) direction_[k] -= 2.0 * along * u;
}

void CollisionSchedule::resolve_surface(std::size_t k, const Eigen::Matrix3d& R, const Eigen::Vector3d& v) {
  const CollisionEvent& e = events_[k];
  Eigen::Vector3d normal = e.surface_normal_in_link, direction = e.direction_in_link;
  if (e.into_motion) {
    const Eigen::Vector3d v_link = R.transpose() * v;
    const Eigen::Vector3d across(0.0, v_link.y(), v_link.z());  // the velocity across the link's x axis
    if (v.norm() < e.standstill_speed_m_per_s || across.norm() < 1e-9) {
      approach_[k] = e.profile == CollisionProfile::clamp ? e.approach_speed_m_per_s : 0.0;
    } else if (across.dot(normal) < 0.0) {
      // The point moves away from this side: the body part is on the side it moves into.
      const Eigen::Vector3d u = across.normalized();
      const Eigen::Matrix3d mirror = Eigen::Matrix3d::Identity() - 2.0 * u * u.transpose();
      normal = mirror * normal;
      direction = mirror * direction;
      point_[k] = mirror * point_[k];  // u has no x component: the point stays at its place along the link
    }
  }
  direction_[k] = R * direction;
  axis_[k] = -(R * normal);
}

ContactForce CollisionSchedule::operator()(double t, const ArmDynamics& arm, const JointVector& q,
                                           const JointVector& qd) {
  for (std::size_t k = 0; k < events_.size(); ++k) {
    const CollisionEvent& e = events_[k];
    const double tau = t - e.t_start;
    if (tau < 0.0 || tau > e.duration_s + (e.profile == CollisionProfile::push ? e.rise_s : 0.0)) {
      continue;
    }
    if (e.link > arm.joints()) {
      throw std::invalid_argument("collision on link " + std::to_string(e.link) + " of a " +
                                  std::to_string(arm.joints()) + "-link arm");
    }
    // A surface contact's side and direction are resolved at its onset whatever its profile.
    if (!anchored_[k] && e.surface_normal_in_link.norm() > 0.0) (void)contact_motion(k, t, arm, q, qd);
    double magnitude = 0.0;
    switch (e.profile) {
      case CollisionProfile::impact: magnitude = e.peak_force_n * std::sin(M_PI * tau / e.duration_s); break;
      case CollisionProfile::push: {
        const double up = e.rise_s > 0.0 ? std::min(1.0, tau / e.rise_s) : 1.0;
        const double down = e.rise_s > 0.0 ? std::clamp((e.duration_s + e.rise_s - tau) / e.rise_s, 0.0, 1.0)
                                           : (tau <= e.duration_s ? 1.0 : 0.0);
        magnitude = e.peak_force_n * std::min(up, down);
        break;
      }
      case CollisionProfile::free: {
        // The body part stands where the contact point was at the onset and is pushed along
        // -direction; its displacement x_b follows m_b x_b'' = F (free, no support).
        const double h = anchored_[k] ? std::max(0.0, t - last_t_[k]) : 0.0;  // no step before the onset
        const ContactMotion m = contact_motion(k, t, arm, q, qd);
        magnitude = spring_force(e, m.travel - body_position_[k], m.speed - body_velocity_[k]);
        // Semi-implicit Euler over the interval since the last call (the plant's step).
        body_velocity_[k] += h * magnitude / e.body_mass_kg;
        body_position_[k] += h * body_velocity_[k];
        break;
      }
      case CollisionProfile::clamp: {
        // The obstacle stays where the contact point was at the onset: the arm's travel
        // against `direction` is the penetration.
        const ContactMotion m = contact_motion(k, t, arm, q, qd);
        magnitude = spring_force(e, m.travel, m.speed);
        break;
      }
    }
    ContactForce f;
    f.link = e.link - 1;
    f.point_in_link = point_[k];
    f.force_base = std::max(0.0, magnitude) * direction_[k];
    return f;
  }
  return {};
}

std::vector<CollisionEvent> draw_campaign(const CampaignSpec& spec, const std::vector<double>& link_lengths) {
  if (spec.links.empty() || spec.count < 0 || !(spec.t_max > spec.t_min) || spec.profiles.empty()) {
    throw std::invalid_argument("draw_campaign: empty link set, negative count or empty time window");
  }
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  // Surface contacts from a stream of their own: every other draw stays as it was.
  std::mt19937_64 surface_rng(spec.seed * 6364136223846793005ULL + 1442695040888963407ULL);
  if (spec.surface_contacts && (!(spec.surface_radius_m >= 0.0) || !(spec.friction_coefficient >= 0.0))) {
    throw std::invalid_argument("draw_campaign: surface radius and friction coefficient must be >= 0");
  }
  const double cos_cone = 1.0 / std::sqrt(1.0 + spec.friction_coefficient * spec.friction_coefficient);
  std::vector<CollisionEvent> out;
  double t = spec.t_min;
  for (int k = 0; k < spec.count; ++k) {
    CollisionEvent e;
    e.link = spec.links[static_cast<std::size_t>(unit(rng) * static_cast<double>(spec.links.size())) % spec.links.size()];
    const double len = e.link - 1 < static_cast<int>(link_lengths.size()) ? link_lengths[static_cast<std::size_t>(e.link - 1)] : 0.3;
    e.point_in_link = Eigen::Vector3d((0.3 + 0.6 * unit(rng)) * std::max(len, 0.05), 0.03 * gauss(rng), 0.03 * gauss(rng));
    Eigen::Vector3d d(gauss(rng), gauss(rng), gauss(rng));
    e.direction_base = d.normalized();
    e.profile = spec.profiles[static_cast<std::size_t>(unit(rng) * static_cast<double>(spec.profiles.size())) % spec.profiles.size()];
    e.peak_force_n = spec.force_min_n + (spec.force_max_n - spec.force_min_n) * unit(rng);
    e.duration_s = e.profile == CollisionProfile::impact ? 0.03 + 0.07 * unit(rng) : 0.5 + unit(rng);
    e.rise_s = 0.05 + 0.25 * unit(rng);
    e.t_start = t + 0.5 * spec.spacing_s * unit(rng);
    if (e.profile == CollisionProfile::clamp && spec.clamps_into_motion) {  // no draw: the others stay as they were
      e.into_motion = true;
      e.standstill_speed_m_per_s = spec.clamp_standstill_speed_m_per_s;
      e.approach_speed_m_per_s = spec.clamp_approach_speed_m_per_s;
    }
    if (spec.surface_contacts) {
      // A point on the cover at a uniform azimuth; the force within the friction cone around
      // the inward normal, uniform over the cone's solid angle (cos of the angle uniform).
      const double azimuth = 2.0 * M_PI * unit(surface_rng);
      const Eigen::Vector3d normal(0.0, std::cos(azimuth), std::sin(azimuth));
      e.point_in_link = Eigen::Vector3d(e.point_in_link.x(), 0.0, 0.0) + spec.surface_radius_m * normal;
      const double cos_angle = 1.0 - (1.0 - cos_cone) * unit(surface_rng);
      const double sin_angle = std::sqrt(std::max(0.0, 1.0 - cos_angle * cos_angle));
      const double around = 2.0 * M_PI * unit(surface_rng);
      const Eigen::Vector3d tangent1(1.0, 0.0, 0.0), tangent2 = normal.cross(tangent1);
      e.surface_normal_in_link = normal;
      e.direction_in_link = -cos_angle * normal + sin_angle * (std::cos(around) * tangent1 + std::sin(around) * tangent2);
    }
    t = e.t_start + spec.spacing_s;
    if (e.t_start > spec.t_max) {
      break;
    }
    out.push_back(e);
  }
  return out;
}

}  // namespace jg::sim
