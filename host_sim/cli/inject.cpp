// `jointguard inject`: known effects added to a recording's torque (or current) columns over
// its measured motion, every other field left as it is (host_sim/injection/).
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "eval/pipeline.hpp"
#include "injection/effects_file.hpp"
#include "injection/inject.hpp"
#include "io/atomic_write.hpp"
#include "io/recording.hpp"
#include "io/yaml_fields.hpp"
#include "robot/torque_kind.hpp"

namespace jg::cli {
namespace {
namespace fs = std::filesystem;

struct InjectCliOptions {
  std::string recording, model, effects, out, friction;
  robot::LoadOptions model_options;
  RecordingOptions input;
};

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

/// The output (or its side file) that would overwrite an input, as a message; "" when none.
std::string overwrites_input(const InjectCliOptions& o) {
  const std::pair<const char*, std::string> inputs[] = {{"the recording", o.recording},
                                                        {"the recording's side file", inject::side_file_path(o.recording)},
                                                        {"--effects", o.effects},
                                                        {"--model", o.model},
                                                        {"--drive", o.model_options.drive_file},
                                                        {"--friction", o.friction}};
  for (const std::string& out : {o.out, inject::side_file_path(o.out)}) {
    for (const auto& [name, in] : inputs) {
      if (!in.empty() && same_file(out, in)) {
        return "--out '" + o.out + "': " + (out == o.out ? "" : "its side file '" + out + "' ") + "would overwrite " + name +
               " '" + in + "': write the injected recording to a new file";
      }
    }
  }
  return {};
}

/// A URDF has no current-to-torque constant (1 until a drive file's k_i gives it).
bool torque_constant_known(const InjectCliOptions& o) {
  std::string ext = fs::path(o.model).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".urdf") return true;
  return !o.model_options.drive_file.empty() && io::YamlFields::load_file(o.model_options.drive_file).has("k_i");
}

void print_result(const inject::InjectRequest& r, const inject::InjectResult& res) {
  for (const auto& e : r.effects) {
    std::printf("effect: %s on %s, coefficients", robot::effect_cstr(e.effect), e.joint == 0 ? "the arm" : ("joint " + std::to_string(e.joint)).c_str());
    for (const double b : e.coefficients) std::printf(" %.6g", b);
    std::printf("\n");
  }
  if (r.effects.empty()) std::printf("no effects: the recording copied unchanged\n");
  for (const auto& c : res.joints) {
    std::printf("%s: %zu of %zu rows changed, max |change| %.4g %s, RMS %.4g %s\n", c.column.c_str(), c.rows_changed, res.data_rows,
                c.max_abs_change, res.unit.c_str(), c.rms_change, res.unit.c_str());
    if (c.delay_on_model_rms > 0.0) {
      std::printf("  its delay against the model's torque (delay x d tau_model/dt, what the diagnosis can see): RMS %.4g %s; "
                  "the rest is the reading's own noise and fast content, shifted\n",
                  c.delay_on_model_rms, res.unit.c_str());
    }
  }
  if (res.rows_outside > 0) std::printf("%zu rows outside every uniform segment (too short to use): left unchanged\n", res.rows_outside);
  if (res.repeats_follow_state) std::printf("rows repeating the previous row's state got its new reading (they stay repeats)\n");
}

/// The side file first, then the recording; a failure leaves neither.
void write_outputs(const std::string& out, const std::string& text, const nlohmann::json& side) {
  if (fs::path(out).has_parent_path()) fs::create_directories(fs::path(out).parent_path());
  const std::string side_path = inject::side_file_path(out);
  io::check_side_file_writable(out);  // another program's <stem>.json is never overwritten
  // This command's identity; the source recording's (copied with its metadata) kept beside it.
  nlohmann::json j = side;
  if (j.contains("identity")) j["source_identity"] = j["identity"];
  j["identity"] = result_identity();
  write_json_file(side_path, j);
  try {
    io::write_text_atomic(out, text);
  } catch (...) {
    std::error_code ignored;
    fs::remove(side_path, ignored);
    throw;
  }
}

int run(const InjectCliOptions& o) {
  if (const std::string why = overwrites_input(o); !why.empty()) {
    std::fprintf(stderr, "jointguard inject: error: %s\n", why.c_str());
    return 2;
  }
  const LoadedRecording rec = load_recording(o.recording, o.input);
  const robot::RobotModel model = robot::for_torque_kind(robot::load_robot(o.model, o.model_options), rec.torque);
  const auto& first = rec.data.segments.front();
  if (first.joints() != model.joints.size()) {
    throw std::invalid_argument(o.recording + ": " + std::to_string(first.joints()) + " joints, the model " + o.model + " has " +
                                std::to_string(model.joints.size()));
  }
  inject::InjectTarget target{first.joints(), rec.torque, !o.friction.empty(), {}};
  for (const auto& j : model.joints) target.link_mass_kg.push_back(j.link.mass);
  inject::InjectRequest r;
  r.recording_path = o.recording;
  r.data = &rec.data;
  // Its rows as read: an effect of a row's own state acts there (inject.hpp).
  const io::Recording as_read = io::read_recording(o.recording, o.input.read_options());
  r.rows = &as_read;
  r.torque = rec.torque;
  r.model.model = &model;
  for (const auto& j : model.joints) r.model.torque_constant.push_back(j.link.torque_constant);
  if (!o.friction.empty()) {
    r.model.friction = eval::read_friction_json(o.friction, first.joint_ids);
    report_input_identity("friction", o.friction);
  }
  r.torque_constant_known = torque_constant_known(o);
  r.effects = inject::read_effects_file(o.effects, target);
  const inject::InjectResult res = about_recording(o.recording, [&] { return inject::inject(r); });
  print_result(r, res);
  const auto side = inject::side_file(r, res, {{"effects", o.effects}, {"model", o.model}, {"drive", o.model_options.drive_file},
                                               {"friction", o.friction}});
  write_outputs(o.out, res.text, side);
  std::printf("wrote %s and %s\n", o.out.c_str(), inject::side_file_path(o.out).c_str());
  return 0;
}
}  // namespace

Command add_inject(CLI::App& app) {
  auto o = std::make_shared<InjectCliOptions>();
  auto* cmd = app.add_subcommand(
      "inject",
      "Add known effects (a plant_effects: list, the robot file's schema) to a recording's torque or current columns\n"
      "over its measured motion; every other field stays as it is. A recording with a known answer for diagnose.\n"
      "Example: jointguard inject real.csv --model models/panda.yaml --torque-kind joint --effects payload.yaml --out out/real_payload.csv");
  cmd->add_option("recording", o->recording, "Recording (CSV)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--effects", o->effects,
                  "YAML with a plant_effects: list, e.g. - {effect: payload, joint: 0, setting: {link: 7}, coefficients: "
                  "[mass_kg, m*cx, m*cy, m*cz]}")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", o->out, "Recording to write (CSV; OUT.json beside it records what was injected)")
      ->required()
      ->check(recording_output_file());
  cmd->add_option("--friction", o->friction, "Nominal friction JSON (identify), for friction changes given as model_curve/sigma0_ratio")
      ->check(CLI::ExistingFile);
  add_model_selection(cmd, o->model_options);
  o->input.add_to(cmd);
  return {cmd, [o]() { return run(*o); }};
}

}  // namespace jg::cli
