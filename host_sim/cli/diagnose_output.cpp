#include "cli/diagnose_output.hpp"

#include <cstdio>
#include <filesystem>
#include <utility>

#include "cli/common.hpp"
#include "io/atomic_write.hpp"
#include "report/svg_plot.hpp"
#include "robot/robot_writer.hpp"

namespace jg::cli {
namespace {

/// The rigid-body identification as an arm-level finding: held-out RMS per joint of the
/// robot file's rigid body (with friction fitted) against the identified model's.
void report_rigid_body(const dyn::RigidBodyIdResult& r, const robot::RobotModel& prior, nlohmann::json& arm) {
  nlohmann::json f{{"effect", "rigid_body"}, {"confidence", r.accepted ? 1.0 : 0.0}};
  nlohmann::json p = nlohmann::json::object();
  p["base_parameters"] = r.base_parameters;
  p["heldout_mse_ratio"] = r.heldout_mse_ratio;
  p["acceleration_sigma_s"] = r.acceleration.sigma_s;
  for (std::size_t j = 0; j < r.heldout_rms_after.size(); ++j) {
    const std::string n = std::to_string(j + 1);
    p["heldout_rms_file_rigid_body_joint" + n] = r.heldout_rms_prior_rigid[j];
    p["heldout_rms_file_with_friction_joint" + n] = r.heldout_rms_prior[j];
    p["heldout_rms_identified_joint" + n] = r.heldout_rms_after[j];
  }
  for (std::size_t l = 0; l < r.links.size() && l < prior.joints.size(); ++l) {
    p["link" + std::to_string(l + 1) + "_mass_kg_before"] = r.links[l].before(0);
    p["link" + std::to_string(l + 1) + "_mass_kg_after"] = r.links[l].after(0);
  }
  f["params"] = p;
  f["description"] = r.accepted ? "the arm's rigid-body parameters identified (base parameters, physically consistent), "
                                  "better on the held-out blocks than the robot file's"
                                : "identified rigid body not better on the held-out blocks: the robot file's is kept";
  std::printf("arm: rigid body %s (%d base parameters, acceleration filter %.1f ms); held-out RMS per joint, robot file + "
              "fitted friction -> identified:",
              r.accepted ? "identified" : "kept", r.base_parameters, 1e3 * r.acceleration.sigma_s);
  for (std::size_t j = 0; j < r.heldout_rms_after.size(); ++j) std::printf(" %.3f->%.3f", r.heldout_rms_prior[j], r.heldout_rms_after[j]);
  std::printf(" N·m\n");
  if (r.accepted) arm["findings"].push_back(f);
  for (const auto& n : r.notes) arm["notes"].push_back(n);
}

/// The rigid-body stage: its finding, or why it was not identified (nothing when not tried).
void report_refit(const diag::DiagnosisResult& r, const robot::RobotModel& prior, nlohmann::json& arm) {
  if (!r.rigid_body_refused.empty()) {
    std::printf("arm: rigid body not identified (%s): the robot file's is used\n", r.rigid_body_refused.c_str());
    arm["notes"].push_back("rigid body not identified: " + r.rigid_body_refused);
  }
  if (r.rigid_body) report_rigid_body(*r.rigid_body, prior, arm);
  if (r.file_baseline) {
    const std::string note =
        "rigid body and friction: the robot file's, identified by an earlier diagnosis (friction_baseline), taken as "
        "the model; neither refitted nor named against";
    std::printf("arm: %s\n", note.c_str());
    arm["notes"].push_back(note);
    arm["baseline"] = "robot_file";
  }
}

/// One finding in the contract's form, with its evidence against the recording's own
/// variation (the null the tool computes: docs/diagnosis.md).
nlohmann::json finding_json(const diag::Finding& f) {
  nlohmann::json out{{"effect", f.effect}, {"params", f.params}, {"confidence", f.confidence}, {"delta_bic", f.delta_bic},
                     {"description", f.text}};
  if (f.params.count("centred_on_last_axis") != 0) {
    // A payload centred on the last joint's axis: its sideways offset was not resolved (the
    // centred fit won), so it is unknown, not zero with zero spread.
    for (const char* k : {"com_x_m", "com_y_m", "com_x_m_sigma", "com_y_m_sigma"}) out["params"][k] = nullptr;
  }
  for (const auto& a : f.alternatives) {
    out["alternatives"].push_back({{"effect", a.effect}, {"params", a.params}, {"evidence", {{"null", "delete-one-block jackknife of what tells the two apart"}, {"z", a.null_z}}}, {"description", a.text}});
  }
  if (f.null_z > 0.0) {
    out["evidence"] = {{"null", "delete-one-block jackknife over the recording's contiguous blocks"},
                       {"z", f.null_z},
                       {"needed", diag::DiagnoseOptions{}.min_null_z}};
  }
  return out;
}

/// The signals' sources: the simulated recordings, the segments, the file's own effects.
void report_signals(const diag::DiagnosisInputs& in, const diag::DiagnosisResult& r, nlohmann::json& j) {
  if (!in.sims.empty()) {
    j["simulated"] = {{"resampling", resampling_json(in.sims.front().data.report)}, {"torque", io::to_string(in.sims.front().torque)}};
  }
  if (r.segments > 1) std::printf("diagnosis over all %zu segments, one after the other\n", r.segments);
  if (r.file_effects) {
    std::printf("the robot file's plant_effects are in the model's prediction (%zu)\n", r.file_effects->count);
    j["model_plant_effects"] = {{"count", r.file_effects->count}, {"notes", r.file_effects->notes}};
  }
  j["segments_used"] = r.segments;
}

/// Leave-one-recording-out: each fold's RMS per joint, fitted on the others.
void report_cross_motion(const std::vector<diag::CrossMotionFold>& folds, const std::vector<io::LoadedRecording>& reals,
                         nlohmann::json& j) {
  nlohmann::json cm = nlohmann::json::array();
  for (const auto& f : folds) {
    const std::string& name = reals[f.left_out].path;
    nlohmann::json jf{{"left_out", name}, {"arm_causes", f.arm_causes}, {"arm_mse_ratio", f.arm_mse_ratio}};
    jf["joints"] = nlohmann::json::array();
    std::printf("cross-motion: fitted on the others, %s: RMS per joint before -> after", name.c_str());
    for (const auto& cj : f.joints) {
      jf["joints"].push_back({{"joint", cj.joint}, {"rms_before", cj.rms_before}, {"rms_after_arm", cj.rms_after_arm},
                              {"rms_after", cj.rms_after}, {"effects", cj.effects}, {"worse_effects", cj.worse_effects}});
      std::printf(" %.3f->%.3f", cj.rms_before, cj.rms_after);
    }
    std::printf(" N·m\n");
    cm.push_back(jf);
  }
  j["cross_motion"] = cm;
}

/// The arm-level causes named against the robot file, fold by fold (JSON only).
nlohmann::json named_folds_json(const std::vector<diag::CrossMotionFold>& folds, const std::vector<io::LoadedRecording>& reals) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& f : folds) {
    out.push_back({{"left_out", reals[f.left_out].path}, {"arm_causes", f.arm_causes}, {"arm_mse_ratio", f.arm_mse_ratio}});
  }
  return out;
}

void report_arm(const diag::ArmDiagnosis& arm_diag, nlohmann::json& j) {
  for (const auto& n : arm_diag.notes) j["arm"]["notes"].push_back(n);
  j["arm"]["unexplained"] = nlohmann::json::array();
  for (const auto& f : arm_diag.unexplained) {
    j["arm"]["unexplained"].push_back({{"effect", f.effect}, {"params", f.params}, {"description", f.text}});
    std::printf("arm: unexplained: %s\n", f.text.c_str());
  }
  for (const auto& f : arm_diag.findings) {
    j["arm"]["findings"].push_back(finding_json(f));
    std::printf("arm: %s: %s\n", robot::effect_cstr(f.effect), f.text.c_str());
  }
  if (arm_diag.findings.empty()) std::printf("arm: no payload or link mass error found\n");
}

/// The primary recording's resampling and torque; with several, each one's.
void report_recordings(const diag::DiagnosisInputs& in, const diag::DiagnosisResult& r, nlohmann::json& j) {
  const io::LoadedRecording& real = diag::primary(in.reals);
  j["resampling"] = resampling_json(real.data.report);
  j["torque"] = io::to_string(real.torque);
  if (in.reals.size() > 1) {
    j["recordings"] = nlohmann::json::array();
    for (std::size_t k = 0; k < in.reals.size(); ++k) {
      j["recordings"].push_back({{"file", in.reals[k].path}, {"samples", r.spans[k].end - r.spans[k].begin},
                                 {"resampling", resampling_json(in.reals[k].data.report)}});
    }
  }
}

nlohmann::json joint_json(const diag::JointDiagnosis& d) {
  nlohmann::json jj{{"joint", d.joint}, {"rms_before", d.rms_before}, {"rms_after", d.rms_after},
                    {"heldout_rms_before", d.heldout_rms_before}, {"heldout_rms_after", d.heldout_rms_after},
                    {"noise_rms", d.noise_rms}, {"whiteness_ljung_box", d.whiteness_q}, {"whiteness_p", d.whiteness_p}};
  jj["findings"] = nlohmann::json::array();
  for (const auto& f : d.findings) jj["findings"].push_back(finding_json(f));
  if (d.findings.empty()) jj["findings"].push_back({{"effect", robot::Effect::none}, {"params", nlohmann::json::object()}, {"confidence", 1.0}});
  jj["location"] = {{"segments", d.location.segments.size()}, {"dependence", d.location.dependence},
                    {"best_periods_per_rev", d.location.best_periods_per_rev}, {"lag_s", d.location.lag_s},
                    {"reversal_rms", d.location.reversal_rms}, {"elsewhere_rms", d.location.elsewhere_rms}};
  jj["notes"] = d.notes;
  if (const double r = diag::unexplained_over_noise(d); r > diag::kUnexplainedOverNoise) {
    jj["unexplained"] = {{"heldout_rms", diag::heldout_rms_left(d)},
                         {"over_noise", r},
                         {"description", "a mismatch no effect of the vocabulary explains"}};
  }
  return jj;
}

void print_joint(const diag::JointDiagnosis& d) {
  std::printf("joint %d: ", d.joint);
  const double unexplained = diag::unexplained_over_noise(d);
  if (d.findings.empty()) {
    if (unexplained > diag::kUnexplainedOverNoise) {
      std::printf("unexplained: held-out RMS %.3f N·m, %.1fx the noise (%.3f N·m), and no effect of the vocabulary "
                  "explains it\n",
                  d.heldout_rms_before, unexplained, d.noise_rms);
    } else {
      std::printf("nothing missing beyond the noise (%.3f N·m); RMS %.3f N·m\n", d.noise_rms, d.rms_before);
    }
    return;
  }
  for (std::size_t i = 0; i < d.findings.size(); ++i) {
    std::printf("%s%s: %s", i ? "; " : "missing ", robot::effect_cstr(d.findings[i].effect), d.findings[i].text.c_str());
  }
  std::printf("; RMS %.3f -> %.3f N·m on held-out data (noise %.3f)", d.heldout_rms_before, d.heldout_rms_after, d.noise_rms);
  if (unexplained > diag::kUnexplainedOverNoise) std::printf("; %.1fx the noise remains unexplained", unexplained);
  std::printf("\n");
}

void plot_joint(const std::string& out, const diag::JointSignals& s, const diag::JointDiagnosis& d) {
  report::Plot p;
  p.title = "joint " + std::to_string(d.joint) + ": residual and fitted effects";
  p.x_label = "t [s]";
  p.y_label = "torque [N·m]";
  p.series.push_back({"residual (real - model)", s.t, s.residual, "#9aa7b8", 0.8});
  p.series.push_back({"fitted effects", s.t, d.fitted, "#d62728", 1.4});
  io::write_text_atomic((std::filesystem::path(out) / ("joint" + std::to_string(d.joint) + "_residual.svg")).string(),
                        report::render_svg(p));
  if (d.findings.empty()) return;
  report::Plot v;  // residual against the strongest finding's variable
  v.title = "joint " + std::to_string(d.joint) + ": residual against velocity";
  v.x_label = "dq [rad/s]";
  v.y_label = "torque [N·m]";
  std::vector<double> after(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) after[k] = s.residual[k] - d.fitted[k];
  v.series.push_back({"before", s.dq, s.residual, "#9aa7b8", 0.6});
  v.series.push_back({"after", s.dq, after, "#2ca02c", 0.6});
  io::write_text_atomic((std::filesystem::path(out) / ("joint" + std::to_string(d.joint) + "_velocity.svg")).string(),
                        report::render_svg(v));
}

/// The joint just diagnosed (the last of r.joints): its JSON, its console line and (with a
/// plot folder) its plots.
void report_joint(const diag::DiagnosisResult& r, const std::string& plots, nlohmann::json& j) {
  const std::size_t k = r.joints.size() - 1;
  j["joints"].push_back(joint_json(r.joints[k]));
  print_joint(r.joints[k]);
  if (!plots.empty()) plot_joint(plots, r.signals[k], r.joints[k]);
}

/// The robot file written back, and what could not be taken back out of a link.
void write_model_out(const diag::ModelOut& m, const DiagnoseOutputs& out, nlohmann::json& j) {
  for (const auto& n : m.notes) j["arm"]["notes"].push_back(n);
  robot::write_robot(out.model_out, m.model, out.model_out_header);
  j["model_out"] = {{"file", out.model_out}, {"plant_effects", m.model.plant_effects.size()}, {"rigid_body_identified", m.rigid_body_identified}};
  std::printf("wrote %s: %zu plant effect(s)%s\n", out.model_out.c_str(), m.model.plant_effects.size(),
              m.rigid_body_identified ? ", identified rigid body" : "");
}

}  // namespace

DiagnosisWriter::DiagnosisWriter(const diag::DiagnosisInputs& in, DiagnoseOutputs out) : in_(in), out_(std::move(out)) {
  j_["arm"] = {{"findings", nlohmann::json::array()}, {"notes", nlohmann::json::array()}};
}

void DiagnosisWriter::stage(diag::DiagnosisStage stage, const diag::DiagnosisResult& r) {
  switch (stage) {
    case diag::DiagnosisStage::rigid_body:
      report_refit(r, in_.nominal, j_["arm"]);
      if (r.named_folds) j_["cross_motion_named"] = named_folds_json(*r.named_folds, in_.reals);
      break;
    case diag::DiagnosisStage::signals: report_signals(in_, r, j_); break;
    case diag::DiagnosisStage::arm:
      if (r.folds) report_cross_motion(*r.folds, in_.reals, j_);
      report_arm(r.arm, j_);
      report_recordings(in_, r, j_);
      j_["joints"] = nlohmann::json::array();
      if (!out_.plots.empty()) std::filesystem::create_directories(out_.plots);
      break;
    case diag::DiagnosisStage::joint: report_joint(r, out_.plots, j_); break;
  }
}

void DiagnosisWriter::finish(const diag::DiagnosisResult& r) {
  if (!out_.model_out.empty() && r.model_out) write_model_out(*r.model_out, out_, j_);
  if (!out_.json.empty()) {
    write_json_file(out_.json, j_);
    std::printf("wrote %s\n", out_.json.c_str());
  }
}

}  // namespace jg::cli
