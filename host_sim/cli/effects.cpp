// `jointguard effects`: the effect catalogue (robot/effect_catalogue.hpp), every cause
// jointguard can simulate, inject and diagnose, with its parameters, units, plausible range,
// how the plant applies it and how the diagnosis fits it. The one table the docs show.
#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "robot/effect_catalogue.hpp"

namespace jg::cli {
namespace {

const char* scope_word(robot::EffectScope s) {
  switch (s) {
    case robot::EffectScope::arm: return "arm";
    case robot::EffectScope::joint: return "joint";
    case robot::EffectScope::neither: break;
  }
  return "-";
}

const char* channel_word(robot::EffectChannel c) {
  switch (c) {
    case robot::EffectChannel::friction: return "friction";
    case robot::EffectChannel::sensor: return "sensor";
    case robot::EffectChannel::body: return "body";
    case robot::EffectChannel::deflection: return "deflection";
    case robot::EffectChannel::none: break;
  }
  return "-";
}

nlohmann::json catalogue_json() {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : robot::effect_catalogue()) {
    rows.push_back({{"effect", r.effect},
                    {"number", static_cast<int>(r.effect)},
                    {"scope", scope_word(r.scope)},
                    {"channel", channel_word(r.channel)},
                    {"coefficients", r.coefficients},
                    {"setting", std::string(r.setting)},
                    {"parameters", std::string(r.parameters)},
                    {"plausible", std::string(r.plausible)},
                    {"plant", std::string(r.plant)},
                    {"fit", std::string(r.fit)}});
  }
  return {{"effects", rows}};
}

/// A Markdown table (docs/diagnosis.md "The vocabulary" is this output).
void print_markdown() {
  std::printf("| effect | where | parameters | plausible | the plant applies | the diagnosis fits |\n|---|---|---|---|---|---|\n");
  for (const auto& r : robot::effect_catalogue()) {
    if (r.effect == robot::Effect::none) continue;
    std::printf("| `%s` | %s, %s | %.*s | %.*s | %.*s | %.*s |\n", robot::effect_cstr(r.effect), scope_word(r.scope),
                channel_word(r.channel), static_cast<int>(r.parameters.size()), r.parameters.data(),
                static_cast<int>(r.plausible.size()), r.plausible.data(), static_cast<int>(r.plant.size()), r.plant.data(),
                static_cast<int>(r.fit.size()), r.fit.data());
  }
}

}  // namespace

Command add_effects(CLI::App& app) {
  auto json_path = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("effects",
                                 "The effect catalogue: every cause jointguard simulates, injects and diagnoses (name, arm or joint,\n"
                                 "parameters and units, plausible range, how the plant applies it, how the diagnosis fits it).\n"
                                 "Example: jointguard effects --json out/effects.json");
  cmd->add_option("--json", *json_path, "Also write the catalogue as JSON")->check(output_file());
  return {cmd, [json_path] {
            print_markdown();
            if (!json_path->empty()) {
              write_json_file(*json_path, catalogue_json());
              std::printf("wrote %s\n", json_path->c_str());
            }
            return 0;
          }};
}

}  // namespace jg::cli
