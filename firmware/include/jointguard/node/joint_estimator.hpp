// One joint module's estimation cycle, as the node runs it on its MCU: its part of the
// outward pass, its part of the inward pass, then LuGre friction, the momentum observer
// (with the friction prediction inside the balance) and the detector. Parameters apart
// from state; the node code (CAN, HAL) calls these two functions in that order.
#pragma once

#include "jointguard/detection/detector.hpp"
#include "jointguard/detection/hold_detector.hpp"
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
  HoldChangeParams<S> hold{};  ///< change detection while holding (threshold 0: off)
  bool compensate_friction = true;
  /// While the drive holds, a measured |velocity| up to this [rad/s] is taken as 0: the
  /// one-count dither of the velocity (position differences) of a joint at rest. Fed to the
  /// estimate it would swing the LuGre bristles between +-tau_s and put a momentum step of
  /// inertia x one count into the observer each time (about 1 N·m at 1 kHz), while the
  /// joint, and the friction it holds, stand still. 0: off. Set it to 1-2 counts per sample.
  S holding_velocity_deadband{};
};

template <class S>
struct JointEstimatorState {
  OutwardState<S> outward{};
  LuGreState<S> friction{};
  ObserverState<S> observer{};
  JointDetectorState detector{};
  HoldChangeState<S> hold{};
  JointMomentum<S> momentum{};
  S friction_torque{};
  S external_torque{};  ///< estimate of the contact's torque on this joint (J^T F) [N·m]
  bool flagged = false;
  InwardMessage<S> last_to_parent{};  ///< repeated on a faulty cycle (the last good outward
                                      ///< message is kept in `outward`, see last_to_child())
  bool input_fault = false;           ///< this cycle's inputs were rejected
  std::uint32_t rejected_cycles = 0;  ///< cycles with rejected inputs since start
};

/// The last good outward message: the outward step leaves exactly its three vectors in
/// the state (updated on good cycles only), so no separate copy is kept.
template <class S>
[[nodiscard]] constexpr OutwardMessage<S> last_to_child(const JointEstimatorState<S>& s) noexcept {
  return {s.outward.angular_velocity, s.outward.parent_point_velocity, s.outward.gravity};
}

namespace detail {
/// x - x is 0 for every finite x and NaN for +/-inf and NaN, and NaN survives every sum:
/// one subtraction and one addition per value and a single NaN test per message, instead
/// of two compares and branches per value (IEEE arithmetic: no -ffast-math in the core).
template <class S>
constexpr S not_finite_residue(S x) noexcept {
  return x - x;  // NOLINT(misc-redundant-expression): 0 or NaN, by design
}
template <class S>
constexpr S not_finite_residue(const Vec3<S>& v) noexcept {
  return not_finite_residue(v.x) + not_finite_residue(v.y) + not_finite_residue(v.z);
}
/// Non-finite joint states or neighbour messages (float builds) must never reach the
/// estimator's state. Q16.16 values are finite by construction (conversion saturates).
template <class S>
constexpr bool finite_inputs(S a, S b, const OutwardMessage<S>& m) noexcept {
  if constexpr (is_q_v<S>) {
    return true;
  } else {
    return !is_nan(not_finite_residue(a) + not_finite_residue(b) + not_finite_residue(m.angular_velocity) +
                   not_finite_residue(m.origin_velocity) + not_finite_residue(m.gravity));
  }
}
template <class S>
constexpr bool finite_inputs(S a, S b, const InwardMessage<S>& m) noexcept {
  if constexpr (is_q_v<S>) {
    return true;
  } else {
    return !is_nan(not_finite_residue(a) + not_finite_residue(b) + not_finite_residue(m.angular_momentum) +
                   not_finite_residue(m.linear_momentum) + not_finite_residue(m.first_moment) +
                   not_finite_residue(m.mass));
  }
}
}  // namespace detail

/// The velocity the estimate uses: 0 while holding within the dither deadband, else dq.
template <class S>
[[nodiscard]] constexpr S estimate_velocity(const JointEstimatorParams<S>& p, S dq, bool holding) noexcept {
  return holding && !(p.holding_velocity_deadband < jg::abs(dq)) ? S{} : dq;
}

/// Phase 1: own joint state + the parent's outward message -> message for the child.
/// Non-finite inputs: the last good message is repeated and the cycle is marked faulty
/// (Error::not_finite); the estimator's state is not touched.
template <class S>
constexpr Error joint_outward(const JointEstimatorParams<S>& p, JointEstimatorState<S>& s, S q, S dq,
                              const OutwardMessage<S>& from_parent, OutwardMessage<S>& to_child) noexcept {
  s.input_fault = !detail::finite_inputs(q, dq, from_parent);
  if (s.input_fault) {
    ++s.rejected_cycles;
    to_child = last_to_child(s);
    return Error::not_finite;
  }
  outward_step(p.link, q, dq, from_parent, s.outward, to_child);
  return Error::ok;
}

/// Phase 1 with a sample the drive could flag unusable (`sample_valid` false, e.g. the
/// plant's invalid marker in a sensor frame): treated as a non-finite input.
template <class S>
constexpr Error joint_outward(const JointEstimatorParams<S>& p, JointEstimatorState<S>& s, S q, S dq,
                              const OutwardMessage<S>& from_parent, OutwardMessage<S>& to_child, bool sample_valid) noexcept {
  if (!sample_valid) {
    s.input_fault = true;
    ++s.rejected_cycles;
    to_child = last_to_child(s);
    return Error::not_finite;
  }
  return joint_outward(p, s, q, dq, from_parent, to_child);
}

/// Phase 1 of a drive that reports holding (`holding`: its controller holds a constant
/// setpoint; the velocity within the deadband is then taken as 0, estimate_velocity()).
template <class S>
constexpr Error joint_outward(const JointEstimatorParams<S>& p, JointEstimatorState<S>& s, S q, S dq, bool holding,
                              const OutwardMessage<S>& from_parent, OutwardMessage<S>& to_child) noexcept {
  return joint_outward(p, s, q, estimate_velocity(p, dq, holding), from_parent, to_child);
}

/// Phase 2: the child's inward message -> message for the parent; then friction, observer
/// and detector. `holding`: the drive's controller holds a constant setpoint this cycle
/// (arms the change detector, hold_detector.hpp). Returns the joint's (latched) collision
/// flag. A faulty cycle (here or in phase 1) keeps the last good outputs, flag and hold state.
template <class S>
constexpr bool joint_inward_and_estimate(const JointEstimatorParams<S>& p, JointEstimatorState<S>& s, S dq, S motor_torque,
                                         bool holding, const InwardMessage<S>& from_child, InwardMessage<S>& to_parent,
                                         ObserverInputStatus* status = nullptr) noexcept {
  if (s.input_fault || !detail::finite_inputs(dq, motor_torque, from_child)) {
    if (!s.input_fault) {
      ++s.rejected_cycles;
    }
    s.input_fault = true;
    to_parent = s.last_to_parent;
    if (status != nullptr) {
      status->error = Error::not_finite;
    }
    return s.flagged;
  }
  dq = estimate_velocity(p, dq, holding);
  inward_step(p.link, dq, s.outward, from_child, to_parent, s.momentum);
  s.last_to_parent = to_parent;
  s.friction_torque = p.compensate_friction ? lugre_step(p.friction, s.friction, dq) : S{};
  const S r = observer_step(p.observer, s.observer, s.momentum.momentum, motor_torque, s.momentum.beta, s.friction_torque,
                            status);
  s.external_torque = -r;
  const bool changed = hold_change_step(p.hold, s.hold, holding, s.external_torque);
  s.flagged = detector_step(p.threshold, p.debounce, s.detector, s.external_torque, dq, changed);
  return s.flagged;
}

/// The same for a drive that does not report holding (the band alone).
template <class S>
constexpr bool joint_inward_and_estimate(const JointEstimatorParams<S>& p, JointEstimatorState<S>& s, S dq, S motor_torque,
                                         const InwardMessage<S>& from_child, InwardMessage<S>& to_parent,
                                         ObserverInputStatus* status = nullptr) noexcept {
  return joint_inward_and_estimate(p, s, dq, motor_torque, false, from_child, to_parent, status);
}

}  // namespace jg
