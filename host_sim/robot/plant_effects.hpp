// Physical effects that `jointguard diagnose` found and fitted, written back into the robot
// file (`--model-out`, key `plant_effects`) so that `simulate --model` includes them in the
// plant: the loop from a real recording back to the simulation. Each entry is one effect
// of the diagnosis vocabulary with its fitted setting and coefficients, as the diagnosis
// predicts it (diagnosis/model_out.hpp turns it into the plant's settings).
#pragma once

#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "robot/effect_catalogue.hpp"

namespace jg::io {
class YamlFields;
}

namespace jg::robot {

struct PlantEffect {
  Effect effect = Effect::none;             ///< the cause (robot/effect_catalogue.hpp)
  int joint = 0;                            ///< 1-based joint; 0 = the arm (payload, a link's mass)
  std::map<std::string, double> setting;    ///< nonlinear settings (grid values)
  std::vector<double> coefficients;         ///< fitted amplitudes (the diagnosis's regression)
  std::map<std::string, double> params;     ///< physical parameters, as reported
};

/// What keeps an effect from being simulated: the field at fault and why (an empty field:
/// nothing). One check for the file reader and for sim/apply_effects.cpp.
struct EffectProblem {
  std::string field;
  std::string what;
};
[[nodiscard]] EffectProblem simulation_problem(const PlantEffect& effect);

/// Reads the `plant_effects` list of a robot file (strict: unknown keys, non-finite numbers
/// and joints outside 0..n refused with file, line and field).
std::vector<PlantEffect> read_plant_effects(const io::YamlFields& root, std::size_t joints);

/// Writes `plant_effects:` as YAML (numbers with full precision, read back identically).
void write_plant_effects(std::ostream& out, const std::vector<PlantEffect>& effects);

}  // namespace jg::robot
