// The firmware constants of one joint (link, LuGre, observer, detector band) from the
// host's double-precision configuration, with the range check of the conversion: shared by
// the centralised chain, the distributed nodes and the `jointguard node` process.
#pragma once

#include <stdexcept>
#include <string>

#include "eval/firmware_estimator.hpp"
#include "jointguard/node/joint_estimator.hpp"

namespace jg::eval {

/// `threshold` null: the node never flags (detection is done by the evaluation).
/// `hold` null: no change detection while holding.
template <class S>
JointEstimatorParams<S> joint_params(const FirmwareEstimatorConfig& c, std::size_t j,
                                     const JointThreshold<double>* threshold = nullptr, int debounce_cycles = 1,
                                     const HoldChangeParams<double>* hold = nullptr) {
  JointEstimatorParams<S> p{};
  const std::string joint = "joint " + std::to_string(j + 1) + ": ";
  if (const Error e = convert_link(c.model.joints[j].link, p.link); e != Error::ok) {
    throw std::invalid_argument(joint + "link constants do not fit the scalar: " + to_string(e));
  }
  p.compensate_friction = c.compensate_friction && j < c.friction.size();
  if (p.compensate_friction) {
    if (const Error e = discretize(c.friction[j], c.dt, p.friction); e != Error::ok) {
      // Name the values: the user fixes them in the friction file's entry for this joint.
      const auto& f = c.friction[j];
      throw std::invalid_argument(joint + "the friction file's LuGre parameters (sigma0 " + std::to_string(f.sigma0) + ", sigma1 " +
                                  std::to_string(f.sigma1) + ", sigma2 " + std::to_string(f.sigma2) + ", tau_c " +
                                  std::to_string(f.tau_c) + ", tau_s " + std::to_string(f.tau_s) + ", w_s " + std::to_string(f.w_s) +
                                  ") do not fit the firmware scalar at dt = " + std::to_string(c.dt) + " s: " + to_string(e));
    }
  }
  if (discretize(c.observer, c.dt, p.observer) != Error::ok) {
    throw std::invalid_argument("observer gains do not fit the scalar at this sample time");
  }
  if (threshold == nullptr) {
    p.threshold = {from_double<S>(1e4), S{}};
  } else {
    NumericStatus st;
    p.threshold = {convert<S>(threshold->base, st), convert<S>(threshold->per_speed, st),
                   convert<S>(threshold->low_speed_extra, st), convert<S>(threshold->inv_low_speed_width, st)};
    if (!st.ok()) throw std::invalid_argument(joint + "threshold band does not fit the scalar");
  }
  if (j < c.holding_velocity_deadband.size()) {
    NumericStatus st;
    p.holding_velocity_deadband = convert<S>(c.holding_velocity_deadband[j], st);
    if (!st.ok()) throw std::invalid_argument(joint + "holding velocity deadband does not fit the scalar");
  }
  if (hold != nullptr) {
    NumericStatus st;
    p.hold = {convert<S>(hold->change_threshold, st), hold->settle_cycles, hold->reference_cycles,
              convert<S>(hold->inv_reference_cycles, st)};
    if (!st.ok()) throw std::invalid_argument(joint + "holding change threshold does not fit the scalar");
  }
  p.debounce.cycles = static_cast<std::uint8_t>(debounce_cycles < 1 ? 1 : (debounce_cycles > 255 ? 255 : debounce_cycles));
  return p;
}

template <class S>
Vec3<S> gravity_of(const robot::RobotModel& model) {
  NumericStatus st;
  return {convert<S>(model.gravity[0], st), convert<S>(model.gravity[1], st), convert<S>(model.gravity[2], st)};
}

}  // namespace jg::eval
