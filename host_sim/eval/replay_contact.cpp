#include "eval/replay_contact.hpp"

#include <cmath>
#include <stdexcept>

namespace jg::eval {
namespace {
ContactWindowConfig replay_config(const robot::RobotModel& model, const ObserverGains& gains) {
  ContactWindowConfig c;
  c.estimator = detection::default_contact_params(model.reaches(), model.reach_axes());
  c.observer_gain_per_s = gains.kind == ObserverKind::first_order ? gains.k1 : 0.0;
  // The point and the force on the link the replay reports (the campaign's best link
  // figure: docs/history.md, "the contact estimate on the isolated link").
  c.link_from_isolation = true;
  return c;
}
}  // namespace

ReplayContact::ReplayContact(const robot::RobotModel& model, const ObserverGains& gains, double dt)
    : arm_(model.dynamics()),
      config_(replay_config(model, gains)),
      dt_(dt),
      keep_(static_cast<std::size_t>(std::ceil(config_.before_s / dt - 1e-9)) + 1) {}

void ReplayContact::event(std::size_t index, double t, int isolated_link) {
  followed_ = index;
  t_event_ = t;
  link_ = isolated_link;
  if (outcomes_.size() <= index) outcomes_.resize(index + 1);
  window_.emplace(config_, dt_);
  for (const Sample& s : recent_) window_->add(arm_, s.t, s.q, s.tau_nm, s.threshold_nm, std::nullopt, link_);
}

void ReplayContact::add(double t, const sim::JointVector& q, const sim::JointVector& tau_nm,
                        const sim::JointVector& threshold_nm) {
  recent_.push_back({t, q, tau_nm, threshold_nm});
  while (recent_.size() > keep_) recent_.pop_front();
  if (!followed_ || !window_) return;
  try {
    window_->add(arm_, t, q, tau_nm, threshold_nm, t_event_, link_);
  } catch (const std::invalid_argument&) {
    // Torques the estimate cannot weigh (a threshold in effect of 0 gives no noise scale):
    // the event keeps its detection and link, without a contact estimate.
    followed_.reset();
    return;
  }
  if (window_->outcome()) outcomes_[*followed_] = window_->outcome();
}

const std::optional<ContactOutcome>& ReplayContact::outcome(std::size_t index) const {
  static const std::optional<ContactOutcome> none;
  return index < outcomes_.size() ? outcomes_[index] : none;
}

}  // namespace jg::eval
