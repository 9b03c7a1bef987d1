// `jointguard diagnose`: where simulation and a real recording differ, which physics is
// missing, its fitted parameters, and the held-out improvement. JSON per the contract,
// a human summary, and SVG plots. A shell: reads the files the command line names, runs
// diag::run_diagnosis (diagnosis/run_diagnosis.hpp) and hands its result to
// a DiagnosisWriter (cli/diagnose_output.hpp), stage by stage as it goes.
#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/diagnose_output.hpp"
#include "diagnosis/run_diagnosis.hpp"
#include "eval/pipeline.hpp"
#include "robot/robot_model.hpp"

namespace jg::cli {
namespace {
struct DiagnoseCliOptions {
  std::string model, json, friction, out, model_out;
  std::vector<std::string> real, sim;  ///< several recordings of one arm; --sim one per --real when given
  bool no_rigid_body = false;
  bool trace = false;  ///< each selection step to stderr
  robot::LoadOptions model_options;
  RecordingOptions input;  ///< for --real; --sim is read as it is (its torque is what the simulation wrote)
};

/// The comment on top of the --model-out file: the command that wrote it.
std::string model_out_header(const DiagnoseCliOptions& o) {
  std::string how = "Written by jointguard diagnose --model " + o.model;
  for (const auto& r : o.real) how += " --real " + r;
  for (const auto& s : o.sim) how += " --sim " + s;
  return how + " --model-out " + o.model_out;
}

/// The files the command line names, read in the order their lines are printed: the robot
/// file, each --real (checked against the first and the model as it is read), --friction,
/// each --sim.
diag::DiagnosisInputs read_inputs(const DiagnoseCliOptions& o) {
  diag::DiagnosisInputs in;
  in.nominal = robot::load_robot(o.model, o.model_options);
  for (const auto& path : o.real) {
    in.reals.push_back(load_recording(path, o.input));
    diag::check_recording(in.reals.back(), in.reals.front(), in.nominal.joints.size());
  }
  if (!o.friction.empty() && !in.nominal.friction_baseline.empty() && o.sim.empty()) {
    // One friction per joint: the file's, identified with its links, or the friction file's.
    throw io::FormatError(o.model + ": carries a friction_baseline (identified with its links by an earlier diagnosis), and "
                          "--friction " + o.friction + " gives another friction for the same joints: give one of them");
  }
  if (!o.friction.empty()) {
    in.friction = eval::read_friction_json(o.friction, diag::primary(in.reals).longest().joint_ids);
    report_input_identity("friction", o.friction);
  }
  // A simulated recording is read as it is (its torque is what the simulation wrote).
  RecordingOptions sim_input;
  sim_input.max_gap_s = o.input.max_gap_s;
  for (const auto& path : o.sim) in.sims.push_back(load_recording(path, sim_input));
  return in;
}

int run_diagnose(const DiagnoseCliOptions& o) {
  if (!o.sim.empty() && o.sim.size() != o.real.size()) {
    std::fprintf(stderr, "jointguard diagnose: error: --sim: give one per --real (%zu, in their order), or none; got %zu\n",
                 o.real.size(), o.sim.size());
    return 2;
  }
  const diag::DiagnosisInputs in = read_inputs(o);
  diag::DiagnosisSettings settings;
  settings.identify_rigid_body = !o.no_rigid_body;
  settings.trace = o.trace;
  settings.model_out = !o.model_out.empty();
  DiagnosisWriter writer(in, {o.json, o.out, o.model_out, model_out_header(o)});
  settings.on_stage = [&writer](diag::DiagnosisStage stage, const diag::DiagnosisResult& r) { writer.stage(stage, r); };
  writer.finish(diag::run_diagnosis(in, settings));
  return 0;
}

}  // namespace

Command add_diagnose(CLI::App& app) {
  auto o = std::make_shared<DiagnoseCliOptions>();
  auto* cmd = app.add_subcommand("diagnose",
                                 "Locate where a real recording and the simulation disagree, name the missing physics,\n"
                                 "fit it and show the held-out improvement. Without --sim the model predicts the torque\n"
                                 "over the real motion (inverse dynamics + --friction). Several --real recordings of one\n"
                                 "arm: one fit across them, and each recording in turn predicted from the others (what does\n"
                                 "not transfer is not claimed).\n"
                                 "Example: jointguard diagnose --model models/ref3.yaml --real out/real.csv --sim out/sim.csv --json out/diagnosis.json --out out/diagnosis");
  cmd->add_option("--model", o->model, "Robot file (YAML or URDF)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--real", o->real, "Real recording (CSV); repeat for several recordings of the same arm")
      ->required()
      ->check(CLI::ExistingFile)
      ->take_all()
      ->allow_extra_args(false);
  cmd->add_option("--sim", o->sim, "Simulated recording of the same motion (CSV); one per --real, in their order")
      ->check(CLI::ExistingFile)
      ->allow_extra_args(false);
  cmd->add_option("--friction", o->friction, "Nominal friction JSON (identify) for the model's prediction")->check(CLI::ExistingFile);
  cmd->add_option("--json", o->json, "Write findings here (contract format)")->check(output_file());
  cmd->add_option("--out", o->out, "Folder for the plots (SVG) and summary");
  cmd->add_option("--model-out", o->model_out,
                  "Write the robot file with what was found: identified links (model vs real) and the named effects as\n"
                  "plant_effects, so that `simulate --model` and a new diagnosis include them")
      ->check(output_file());
  cmd->add_flag("--no-rigid-body", o->no_rigid_body,
                "Without --sim: keep the robot file's rigid body (default: identify the whole arm's rigid body and\n"
                "friction on the training blocks first, an arm-level finding, then diagnose what remains)");
  cmd->add_flag("--trace", o->trace, "Print each selection step (candidates, evidence, rejections) to stderr");
  add_model_selection(cmd, o->model_options);
  o->input.add_to(cmd);
  return {cmd, [o]() { return run_diagnose(*o); }};
}

}  // namespace jg::cli
