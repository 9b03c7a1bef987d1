// Collision detection, isolation and the reaction request (READING.md section 6).
//
// Per joint: the compensated external torque mu (observer output with the friction
// prediction inside its momentum balance) is compared with a threshold band
//   eps(w) = eps0 + eps_per_speed |w| + eps_low_speed exp(-(w / w_band)^2)
// (eps_per_speed = eps_low_speed = 0 gives the paper's constant eps). The low-speed term
// exists because friction in stiction is not observable: at rest the bristles hold any
// torque up to tau_s, which no velocity-driven model can predict.
// `debounce_cycles` consecutive cycles over the band raise the joint's flag, which stays
// latched until reset. Across joints: a force on link i loads joints 1..i only, so the
// highest joint whose flag is up names the collided link (fault signature [1..1 0..0]).
//
// Scalar: any (float, double, Q16.16). Q16.16: thresholds and torques in N·m; the two
// growth terms of the band are one exact sum of products (rounded once), then the base
// is added; everything saturates.
#pragma once

#include <cstdint>

#include "jointguard/numeric/qmath.hpp"

namespace jg {

inline constexpr int kMaxDetectorJoints = 7;

template <class S>
struct JointThreshold {
  S base{};       ///< eps0 [N·m]
  S per_speed{};  ///< band growth with |velocity| [N·m·s/rad]; 0 = constant threshold
  S low_speed_extra{};      ///< extra allowance near standstill [N·m]
  S inv_low_speed_width{};  ///< 1 / w_band [s/rad]
};

struct DebounceSettings {
  std::uint8_t cycles = 1;  ///< consecutive cycles over threshold before the flag rises (>= 1)
};

struct JointDetectorState {
  std::uint8_t over_count = 0;
  bool flagged = false;  ///< latched until reset_detector()
};

/// The threshold in effect at `velocity`: eps(w) above.
template <class S>
[[nodiscard]] constexpr S threshold_at(const JointThreshold<S>& threshold, S velocity) noexcept {
  // u (only squared) and the growth terms (added to the base) are intermediate terms.
  const term_t<S> u = mul_term(velocity, threshold.inv_low_speed_width);
  return threshold.base +
         sum_of_products_term(threshold.per_speed, jg::abs(velocity), threshold.low_speed_extra, jg::exp(-square(u)));
}

/// One joint, one cycle: `over` (this cycle's estimate outside every bound in effect)
/// updates the debounce counter; returns the (latched) flag.
[[nodiscard]] constexpr bool debounce_step(DebounceSettings debounce, JointDetectorState& state, bool over) noexcept {
  if (over) {
    if (state.over_count < 255U) {
      ++state.over_count;
    }
  } else {
    state.over_count = 0U;
  }
  const std::uint8_t needed = debounce.cycles == 0U ? std::uint8_t{1} : debounce.cycles;
  if (state.over_count >= needed) {
    state.flagged = true;
  }
  return state.flagged;
}

/// One joint, one cycle against the band: updates the debounce counter and returns the
/// (latched) flag. `also_over`: another bound of this joint (the holding detector,
/// hold_detector.hpp) is exceeded this cycle; it shares the debounce.
template <class S>
[[nodiscard]] constexpr bool detector_step(const JointThreshold<S>& threshold, DebounceSettings debounce,
                                           JointDetectorState& state, S external_torque, S velocity,
                                           bool also_over = false) noexcept {
  return debounce_step(debounce, state, also_over || threshold_at(threshold, velocity) < jg::abs(external_torque));
}

constexpr void reset_detector(JointDetectorState& state) noexcept { state = JointDetectorState{}; }

/// Bit j (0-based) set when joint j+1 is flagged.
using JointMask = std::uint8_t;

/// The collided link (1-based) from the joints over threshold: the highest flagged joint.
/// 0 when no joint is flagged.
[[nodiscard]] constexpr int isolate_link(JointMask flagged) noexcept {
  int link = 0;
  for (int j = 0; j < kMaxDetectorJoints; ++j) {
    if ((flagged & (1U << static_cast<unsigned>(j))) != 0U) {
      link = j + 1;
    }
  }
  return link;
}

/// What the arm does once a collision is detected (stable numbers: they travel in frames).
enum class Reaction : std::uint8_t {
  none = 0,          ///< report only
  stop = 1,          ///< hold the position where the collision was detected
  zero_gravity = 2,  ///< torque mode: gravity and friction compensated, the arm yields
  retreat = 3,       ///< move back along the path for a short distance, then hold
  reflex = 4,        ///< the collided joints push along the estimated contact torque (away
                     ///< from the contact) for a moment, the others hold; then hold
};

}  // namespace jg
