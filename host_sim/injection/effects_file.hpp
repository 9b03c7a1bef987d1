// The effects `jointguard inject` adds to a recording: a YAML document with a
// `plant_effects:` list in the robot file's schema (robot/plant_effects.hpp), checked for
// what a recording's torque column can carry.
#pragma once

#include <string>
#include <vector>

#include "io/recording.hpp"
#include "robot/plant_effects.hpp"

namespace jg::inject {

/// Where an effect acts in the reading, which decides how it is injected.
enum class Channel {
  arm,     ///< payload, link_inertial_error: inverse dynamics of the changed arm minus the nominal
  joint,   ///< friction, ripple, drift, rotor inertia: the diagnosis's own columns (predict_effects)
  scale,   ///< torque_constant: the reading scaled by 1 + b
  offset,  ///< current_offset: b [N·m] added to the reading
  delay,   ///< time_delay: the reading delayed by -b [s]
};

/// What the recording and the command line give, on which an effect's injection depends.
struct InjectTarget {
  std::size_t joints = 0;                   ///< joints of the recording (= the model's)
  io::TorqueKind torque = io::TorqueKind::tau_m;
  bool has_friction = false;                ///< nominal LuGre friction given (--friction)
  std::vector<double> link_mass_kg;         ///< the model's link masses (a mass change must leave them > 0)
};

/// Why `effect` cannot be injected into that target: the field at fault and why (empty
/// field: it can). `channel` is set when it can.
robot::EffectProblem injection_problem(const robot::PlantEffect& effect, const InjectTarget& target, Channel* channel = nullptr);

/// The channel of an effect that passed injection_problem.
Channel channel_of(const robot::PlantEffect& effect);

/// Reads the effects file: only the key `plant_effects` (a list, `[]` allowed), each entry
/// checked by the robot file's reader and by injection_problem; refused with io::FormatError
/// naming the file, line and field.
std::vector<robot::PlantEffect> read_effects_file(const std::string& path, const InjectTarget& target);

}  // namespace jg::inject
