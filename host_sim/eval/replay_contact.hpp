// The contact estimate of each replay event: a recording's detections get the link, the
// point on it and the force in newtons that explain the joints' torques, with their
// uncertainty, as the campaign's runs do on the master's side (eval/contact_window.hpp,
// docs/contact-estimate.md). Fed every sample of the replay. An event starts an estimate on
// the samples from before_s (5 ms) before it, decided after_s (20 ms) after it; from then on
// the force at the decided point is followed until the detector re-arms (the contact is
// over) or the next event: its peak is the figure ISO/TS 15066 compares.
#pragma once

#include <cstddef>
#include <deque>
#include <optional>

#include "eval/contact_window.hpp"
#include "jointguard/observer/momentum_observer.hpp"
#include "robot/robot_model.hpp"

namespace jg::eval {

class ReplayContact {
 public:
  /// `gains`: the replay's observer (its first-order gain corrects the estimate's lag);
  /// `dt`: the replay's sample time [s].
  ReplayContact(const robot::RobotModel& model, const ObserverGains& gains, double dt);
  /// Event number `index` raised at `t` [s], its link isolated as `isolated_link` (1-based,
  /// the model's joint order): ends the previous event's following and starts its estimate.
  void event(std::size_t index, double t, int isolated_link);
  /// The detector re-armed: the followed contact is over.
  void end() { followed_.reset(); }
  /// Every sample, after event(): the posture [rad], each joint's torque to explain [N·m]
  /// (the estimate, or its change since arrival for a joint whose holding detector is
  /// armed) and its threshold in effect [N·m].
  void add(double t, const sim::JointVector& q, const sim::JointVector& tau_nm, const sim::JointVector& threshold_nm);
  /// The estimate of event `index` (as decided, peak force followed since), if decided.
  [[nodiscard]] const std::optional<ContactOutcome>& outcome(std::size_t index) const;

 private:
  struct Sample {
    double t;
    sim::JointVector q, tau_nm, threshold_nm;
  };
  sim::ArmDynamics arm_;
  ContactWindowConfig config_;
  double dt_;
  std::size_t keep_;
  std::deque<Sample> recent_;  ///< the last before_s of samples, for the next event's window
  std::optional<ContactWindow> window_;
  std::optional<std::size_t> followed_;  ///< the event whose window is fed
  double t_event_ = 0.0;
  int link_ = 0;
  std::vector<std::optional<ContactOutcome>> outcomes_;
};

}  // namespace jg::eval
