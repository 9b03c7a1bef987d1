// One joint module's estimation cycle, as the node runs it on its MCU: its part of the
// outward pass, its part of the inward pass, then LuGre friction, the momentum observer
// (with the friction prediction inside the balance) and the detector. Parameters apart
// from state; the node code (CAN, HAL) calls these two functions in that order.
#pragma once

#include "jointguard/detection/detector.hpp"
#include "jointguard/dynamics/momentum_recursion.hpp"
#include "jointguard/friction/lugre.hpp"
#include "jointguard/observer/momentum_observer.hpp"

namespace jg {

template <class S>
struct JointEstimatorParams {
  LinkConstants<S> link{};
  LuGreDiscrete<S> friction{};
  ObserverCoeffs<S> observer{};
  JointThreshold<S> threshold{};
  DebounceSettings debounce{};
  bool compensate_friction = true;
};

template <class S>
struct JointEstimatorState {
  OutwardState<S> outward{};
  LuGreState<S> friction{};
  ObserverState<S> observer{};
  JointDetectorState detector{};
  JointMomentum<S> momentum{};
  S friction_torque{};
  S external_torque{};  ///< estimate of the contact's torque on this joint (J^T F) [N·m]
  bool flagged = false;
};

/// Phase 1: own joint state + the parent's outward message -> message for the child.
template <class S>
constexpr void joint_outward(const JointEstimatorParams<S>& p, JointEstimatorState<S>& s, S q, S dq,
                             const OutwardMessage<S>& from_parent, OutwardMessage<S>& to_child) noexcept {
  outward_step(p.link, q, dq, from_parent, s.outward, to_child);
}

/// Phase 2: the child's inward message -> message for the parent; then friction, observer
/// and detector. Returns the joint's (latched) collision flag.
template <class S>
constexpr bool joint_inward_and_estimate(const JointEstimatorParams<S>& p, JointEstimatorState<S>& s, S dq, S motor_torque,
                                         const InwardMessage<S>& from_child, InwardMessage<S>& to_parent,
                                         ObserverInputStatus* status = nullptr) noexcept {
  inward_step(p.link, dq, s.outward, from_child, to_parent, s.momentum);
  s.friction_torque = p.compensate_friction ? lugre_step(p.friction, s.friction, dq) : S{};
  const S r = observer_step(p.observer, s.observer, s.momentum.momentum, motor_torque, s.momentum.beta, s.friction_torque,
                            status);
  s.external_torque = -r;
  s.flagged = detector_step(p.threshold, p.debounce, s.detector, s.external_torque, dq);
  return s.flagged;
}

}  // namespace jg
