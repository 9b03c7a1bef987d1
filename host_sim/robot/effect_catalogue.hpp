// The effect catalogue: every physical cause jointguard can simulate, inject and diagnose,
// as one enum and one table (name, where it lives, its parameters and units, its plausible
// range, how the plant applies it, how the diagnosis fits it). The diagnosis
// (diagnosis/effects.*), the robot file's `plant_effects` (robot/plant_effects.*), the
// plant (sim/apply_effects.*), injection (injection/effects_file.*) and both test-set
// generators (diagnosis/testset*.cpp) name effects through it: a word is parsed once, where
// it enters (a file, an option), and compared as an enum everywhere else.
// The names are the vocabulary of ../shared/CONTRACT.md; `jointguard diagnose --effects`
// prints the table, docs/diagnosis.md "The vocabulary" shows it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace jg::robot {

/// Stable order (the JSON and the docs list effects in it); never renumbered.
enum class Effect : std::uint8_t {
  coulomb = 0,
  viscous = 1,
  stribeck = 2,
  presliding = 3,
  asymmetric_friction = 4,
  position_ripple = 5,
  temperature_drift = 6,
  load_dependent_friction = 7,
  payload = 8,
  inertia_error = 9,
  torque_constant = 10,
  current_offset = 11,
  time_delay = 12,
  backlash = 13,
  joint_elasticity = 14,
  link_inertial_error = 15,
  none = 16,  ///< a diagnosis's "nothing missing"; not a cause, never simulated
};

/// Where the cause lives: one thing of the arm (fitted once across joints, joint 0 in a
/// robot file) or one joint's drive.
enum class EffectScope : std::uint8_t { arm, joint, neither };

/// The channel the cause acts on, as injection and the plant see it: friction and sensor
/// effects change the measured torque (or current) at the measured motion; `body` effects
/// change the rigid body; `deflection` ones the gear's motion itself.
enum class EffectChannel : std::uint8_t { friction, sensor, body, deflection, none };

struct EffectInfo {
  Effect effect;
  std::string_view name;        ///< the vocabulary word
  EffectScope scope;
  EffectChannel channel;
  std::size_t coefficients;     ///< amplitudes of its plain shape (richer shapes may add one)
  std::string_view setting;     ///< the nonlinear setting its plain shape needs ("": none)
  std::string_view parameters;  ///< reported parameters with units
  std::string_view plausible;   ///< the range the diagnosis accepts (docs/diagnosis.md)
  std::string_view plant;       ///< how the simulated plant applies it
  std::string_view fit;         ///< how the diagnosis fits it
  /// Instances at different settings are different components of the cause, each a cause of
  /// its own beside the others (a ripple at another period: a gear's meshing beside a motor's
  /// cogging), not another shape of one: where a robot file carries one, another setting is
  /// still offered (diagnosis keep_only_file_settings).
  bool components_at_settings = false;
};

/// The table, in the enum's order (every Effect has exactly one row; a test checks it).
const std::vector<EffectInfo>& effect_catalogue();
const EffectInfo& effect_info(Effect e);
std::string_view effect_name(Effect e);
/// The effect of a vocabulary word; nullopt for anything else (the caller names the field).
std::optional<Effect> parse_effect(std::string_view name);
/// The vocabulary in the table's order, "none" last, for messages and the CLI.
std::string effect_words();

/// The word as a std::string, for messages built with `+`.
inline std::string effect_word(Effect e) { return std::string(effect_name(e)); }
/// The word where text is built: an effect prints and concatenates as its name.
inline std::ostream& operator<<(std::ostream& os, Effect e) { return os << effect_name(e); }
inline std::string operator+(const std::string& s, Effect e) { return s + effect_word(e); }
inline std::string operator+(Effect e, const std::string& s) { return effect_word(e) + s; }
inline std::string operator+(const char* s, Effect e) { return s + effect_word(e); }
inline std::string operator+(Effect e, const char* s) { return effect_word(e) + s; }
/// nlohmann::json writes an effect as its word (found by argument-dependent lookup, and more
/// specialised than the library's enum-as-integer default; the robot layer stays free of it).
template <class Json>
void to_json(Json& j, const Effect& e) {
  j = effect_word(e);
}
/// For printf's %s (the table's names are string literals, so NUL-terminated).
inline const char* effect_cstr(Effect e) { return effect_name(e).data(); }

}  // namespace jg::robot
