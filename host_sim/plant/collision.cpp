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
  const Eigen::Vector3d x = P.origin[i] + P.rotation[i] * e.point_in_link;
  const Eigen::Vector3d v = arm.point_jacobian(q, i, e.point_in_link) * qd;
  if (!anchored_[k]) {  // the onset: where the contact is, and (against_motion, into_motion) its direction
    anchor_[k] = x;
    anchored_[k] = true;
    onset_t_[k] = t;
    if (e.against_motion && v.norm() > 1e-9) direction_[k] = -v.normalized();
    if (e.into_motion) resolve_into_motion(k, v);
  }
  last_t_[k] = t;
  // The body part's own approach (into_motion at a standing arm) adds to the arm's travel.
  const double own = approach_[k];
  return {-(x - anchor_[k]).dot(direction_[k]) + own * (t - onset_t_[k]), -v.dot(direction_[k]) + own};
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
    f.point_in_link = e.point_in_link;
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
    t = e.t_start + spec.spacing_s;
    if (e.t_start > spec.t_max) {
      break;
    }
    out.push_back(e);
  }
  return out;
}

}  // namespace jg::sim
