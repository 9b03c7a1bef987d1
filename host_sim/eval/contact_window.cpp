#include "eval/contact_window.hpp"

#include <algorithm>
#include <cmath>

namespace jg::eval {

ContactWindow::ContactWindow(ContactWindowConfig config, double dt)
    : config_(std::move(config)), dt_(dt),
      keep_(static_cast<std::size_t>(std::ceil(std::max(config_.before_s, config_.fit_s) / dt - 1e-9)) + 1) {
  // No link segments (a DetectionConfig left at its defaults): no contact estimate.
  if (config_.estimator.segments.empty()) config_.enabled = false;
}

detection::TorqueObservation ContactWindow::observe() const {
  const double from = samples_.back().t - config_.fit_s - 1e-9;
  std::vector<detection::WindowSample> w;
  for (const auto& s : samples_) {
    if (s.t >= from) w.push_back(s);
  }
  return detection::summarize_window(w, config_.observer_gain_per_s);
}

void ContactWindow::add(const sim::ArmDynamics& arm, double t, const sim::JointVector& q, const sim::JointVector& tau_nm,
                        const sim::JointVector& threshold_nm, const std::optional<double>& t_detected) {
  ++cycle_;
  if (!config_.enabled) return;
  const double since = t_detected ? t - *t_detected : -1.0;
  // The reaction's transient: not a sample of the contact.
  if (since > 1e-9 && since + 1e-9 < config_.settle_s) return;
  const detection::WindowSample sample{t, q, tau_nm, threshold_nm / config_.noise_band_sigmas};
  samples_.push_back(sample);
  while (samples_.size() > keep_) samples_.pop_front();
  if (!t_detected) return;
  // Errors of neighbouring cycles are correlated over about the observer's time constant.
  const double weight = config_.observer_gain_per_s > 0.0 ? std::min(1.0, dt_ * config_.observer_gain_per_s) : 0.2;
  if (!grid_) {
    grid_ = detection::make_grid(arm.joints(), config_.estimator);
    for (const auto& s : samples_) {
      if (s.t + 1e-9 >= *t_detected - config_.before_s) {
        detection::accumulate(*grid_, arm, {s.q, s.mu_nm, s.sigma_nm}, weight);
      }
    }
  } else if (!outcome_) {
    detection::accumulate(*grid_, arm, {q, tau_nm, sample.sigma_nm}, weight);
  }
  const detection::TorqueObservation obs = observe();
  if (outcome_) {
    // Decided: follow the force at the decided point.
    const double f = detection::force_at(arm, obs, outcome_->estimate.link, outcome_->estimate.point_in_link).norm();
    if (f > outcome_->peak_force_n) {
      outcome_->peak_force_n = f;
      outcome_->t_peak = t;
    }
    return;
  }
  if (since + 1e-9 < config_.after_s) return;
  const detection::ContactEstimate e = detection::estimate_contact(arm, obs, config_.estimator, &*grid_);
  ContactOutcome o;
  o.t = t;
  o.estimate = e;
  o.observation = obs;
  o.peak_force_n = e.force_n;
  o.t_peak = t;
  decision_cycle_ = cycle_ - 1;  // 0-based index of this cycle
  outcome_ = o;
}

void ContactWindow::set_truth(const sim::ArmDynamics& arm, const sim::CollisionEvent& event,
                              const std::vector<double>& contact_force_n,
                              const std::vector<std::vector<double>>& tau_ext) {
  if (!outcome_) return;
  ContactOutcome& o = *outcome_;
  // The measurement of cycle k reflects the force of the interval before it (cycle k - 1).
  const long k = std::max(0L, decision_cycle_ - 1);
  if (k < static_cast<long>(contact_force_n.size())) o.force_true_n = contact_force_n[static_cast<std::size_t>(k)];
  o.along_true_m = event.point_in_link.x();
  o.point_error_m = o.estimate.link == event.link ? (o.estimate.point_in_link - event.point_in_link).norm() : -1.0;
  for (const auto& joint : tau_ext) {
    if (static_cast<std::size_t>(decision_cycle_) < joint.size()) o.torque_true_nm.push_back(joint[static_cast<std::size_t>(decision_cycle_)]);
  }
  if (event.link >= 1 && event.link <= arm.joints()) {
    o.force_at_true_point_n = detection::force_at(arm, o.observation, event.link, event.point_in_link).norm();
  }
}

}  // namespace jg::eval
