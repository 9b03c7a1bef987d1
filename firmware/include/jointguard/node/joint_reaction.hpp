// One joint's reaction to a detected collision, as its drive runs it (the master decides
// that the arm reacts and how; every drive then computes its own motor torque term).
//
//   stop          hold where the reaction started: K (q_hold - q) - D dq
//   zero_gravity  the drive's friction prediction only (the master adds gravity): the
//                 joint yields to the contact
//   retreat       hold a reference that moves in a straight line (per joint: the arm's
//                 path in joint space) from where the reaction started to the master's
//                 retreat target over `retreat_cycles`, then holds it
//   reflex        a collided joint (named by the master) pushes along its estimated
//                 external torque, G mu - D_r dq, for `reflex_cycles`, following the motion
//                 with its hold point; every other joint holds; then all hold
// The torque returned is the reaction's term of the joint's motor torque; the master adds
// the arm's gravity torque (it has the whole arm's model). Gains are parameters apart
// from the state; nothing allocates, nothing throws.
//
// Scalar: float, double or Q16.16. Q16.16 formats: positions [rad], velocities [rad/s],
// torques [N·m], stiffness [N·m/rad], damping [N·m·s/rad], the reflex gain [-] and the
// retreat step 1/retreat_cycles [-] are Q16.16; every product and sum saturates (a hold
// error of 1 rad at K = 2000 N·m/rad gives 2000 N·m, far inside the range; a saturated
// torque is the drive's current limit's business anyway). The retreat fraction is
// cycles x (1/retreat_cycles), clamped to 1, so the reference ends exactly on the target.
#pragma once

#include <cstdint>

#include "jointguard/detection/detector.hpp"
#include "jointguard/numeric/qmath.hpp"

namespace jg {

namespace detail {
/// A cycle count as a scalar (Q16.16: exact up to 32767, saturated above).
template <class S>
[[nodiscard]] constexpr S cycles_as(std::uint16_t cycles) noexcept {
  if constexpr (is_q_v<S>) {
    const std::int64_t raw = static_cast<std::int64_t>(cycles) << S::frac_bits;
    return S::from_raw(raw > jg::detail::kRawMax ? jg::detail::kRawMax : static_cast<std::int32_t>(raw));
  } else {
    return static_cast<S>(cycles);
  }
}
}  // namespace detail

template <class S>
struct ReactionGains {
  S hold_stiffness = from_double<S>(2000.0);   ///< K [N·m/rad]
  S hold_damping = from_double<S>(60.0);       ///< D [N·m·s/rad]
  S reflex_gain = from_double<S>(1.0);         ///< G [-]: torque per estimated external torque
  S reflex_damping = from_double<S>(5.0);      ///< D_r [N·m·s/rad]
  std::uint16_t retreat_cycles = 300;          ///< cycles to go back to the target (0.3 s at 1 kHz)
  S retreat_step = from_double<S>(1.0 / 300);  ///< 1 / retreat_cycles
  std::uint16_t reflex_cycles = 300;           ///< cycles of the reflex push (0.3 s at 1 kHz)
};

/// The gains for a control period: retreat and reflex durations in seconds rounded to
/// whole cycles (at least one). Host-side set-up (double arithmetic, not on the hot path).
template <class S>
[[nodiscard]] inline ReactionGains<S> reaction_gains(double dt, double retreat_s = 0.3, double reflex_s = 0.3) noexcept {
  const auto cycles = [dt](double s) {
    const double c = s / dt + 0.5;
    return static_cast<std::uint16_t>(c < 1.0 ? 1.0 : (c > 65535.0 ? 65535.0 : c));
  };
  ReactionGains<S> g;
  g.retreat_cycles = cycles(retreat_s);
  g.retreat_step = from_double<S>(1.0 / g.retreat_cycles);
  g.reflex_cycles = cycles(reflex_s);
  return g;
}

/// What the master commands (it has seen every drive's flag and every joint's path).
template <class S>
struct ReactionCommand {
  Reaction kind = Reaction::none;
  bool collided = false;  ///< this joint takes part in the collision's signature (reflex)
  S retreat_target{};     ///< [rad] this joint's point on the path to go back to (retreat)
};

template <class S>
struct JointReactionState {
  Reaction kind = Reaction::none;  ///< none: not reacting
  bool collided = false;
  S start{}, hold{}, target{};     ///< [rad]
  std::uint16_t cycles = 0;        ///< cycles since the reaction started (saturates)
};

/// Starts the reaction where the joint is (`position`); a reaction under way is kept
/// (the first command wins: the master repeats it every cycle).
template <class S>
constexpr void start_reaction(JointReactionState<S>& st, const ReactionCommand<S>& cmd, S position) noexcept {
  if (st.kind != Reaction::none || cmd.kind == Reaction::none) {
    return;
  }
  st.kind = cmd.kind;
  st.collided = cmd.collided;
  st.start = position;
  st.hold = position;
  st.target = cmd.retreat_target;
  st.cycles = 0;
}

/// One cycle of a started reaction: the joint's reaction torque [N·m] from its measured
/// position and velocity, its estimated external torque and its friction prediction.
/// 0 when not reacting.
template <class S>
[[nodiscard]] constexpr S reaction_torque(const ReactionGains<S>& g, JointReactionState<S>& st, S position, S velocity,
                                          S external_torque, S friction_torque) noexcept {
  S ref = st.hold;
  S out{};
  switch (st.kind) {
    case Reaction::none:
      return S{};
    case Reaction::zero_gravity:
      out = friction_torque;
      break;
    case Reaction::retreat: {
      const S one = from_double<S>(1.0);
      const S fraction = st.cycles >= g.retreat_cycles ? one : jg::min(one, static_cast<S>(g.retreat_step * detail::cycles_as<S>(st.cycles)));
      ref = st.start + fraction * (st.target - st.start);
      out = g.hold_stiffness * (ref - position) - g.hold_damping * velocity;
      break;
    }
    case Reaction::reflex:
      if (st.collided && st.cycles <= g.reflex_cycles) {
        st.hold = position;  // the hold point follows the push: the joint holds where it ends
        out = g.reflex_gain * external_torque - g.reflex_damping * velocity;
        break;
      }
      out = g.hold_stiffness * (ref - position) - g.hold_damping * velocity;
      break;
    case Reaction::stop:
    default:
      out = g.hold_stiffness * (ref - position) - g.hold_damping * velocity;
      break;
  }
  if (st.cycles < 65535U) {
    ++st.cycles;
  }
  return out;
}

}  // namespace jg
