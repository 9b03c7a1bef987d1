#include "cli/identify_rigid.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "arm_identification/rigid_body_identification.hpp"
#include "cli/common.hpp"
#include "diagnosis/model_out.hpp"
#include "dynamics/uniform_grid.hpp"
#include "io/atomic_write.hpp"
#include "io/recording.hpp"
#include "robot/robot_model.hpp"
#include "robot/robot_writer.hpp"

namespace jg::cli {
namespace {

nlohmann::json link_json(const dyn::LinkParams& p) {
  const Eigen::Matrix3d Ic = dyn::inertia_com(p);
  const double m = p(0);
  const Eigen::Vector3d c = m > 0.0 ? Eigen::Vector3d(p.segment<3>(1) / m) : Eigen::Vector3d::Zero();
  return {{"mass_kg", m},
          {"com_m", {c.x(), c.y(), c.z()}},
          {"first_moment_kg_m", {p(1), p(2), p(3)}},
          {"inertia_com_kg_m2", {{"xx", Ic(0, 0)}, {"yy", Ic(1, 1)}, {"zz", Ic(2, 2)}, {"xy", Ic(0, 1)}, {"xz", Ic(0, 2)}, {"yz", Ic(1, 2)}}},
          {"inertia_origin_kg_m2", {{"xx", p(4)}, {"yy", p(5)}, {"zz", p(6)}, {"xy", p(7)}, {"xz", p(8)}, {"yz", p(9)}}}};
}

/// The robot file's per-joint plant_effects (a friction change, an offset, a delay) predicted
/// on the recording's motion: the links and the friction are then identified on top of them,
/// and the file written keeps them as read, once (dyn::RigidBodyIdOptions::known_torque).
std::vector<std::vector<double>> per_joint_effects_torque(const io::Recording& rec, const robot::RobotModel& start) {
  std::vector<std::string> notes;
  auto known = diag::known_joint_torque(start, start, rec, &notes);
  for (const auto& n : notes) std::printf("note: %s (not in the fit's prediction)\n", n.c_str());
  std::printf("%zu per-joint plant_effects of the robot file are in the fit's prediction: the links and friction are identified on top of them\n",
              start.plant_effects.size());
  return known;
}

/// The identification's options from the command line's.
dyn::RigidBodyIdOptions id_options(const io::Recording& rec, const RigidBodyCliOptions& o) {
  dyn::RigidBodyIdOptions opt;
  // The torque kind was chosen when the recording was read (--torque-kind).
  opt.joint_torque_sensor = rec.torque_kind == io::TorqueKind::tau_j;
  opt.payload_only = o.payload_only;
  opt.asymmetric_coulomb = o.asymmetric_coulomb;
  opt.com_margin_m = o.com_margin_m;
  opt.sigma_s = o.sigma_ms * 1e-3;
  opt.prior_weight = o.prior_weight;
  opt.friction_eps = o.friction_eps;
  opt.slow_speed_rad_s = o.slow_speed;
  return opt;
}

/// The result on the console: the filter, the base parameters, per joint the held-out RMS
/// and friction, per link the mass, the payload and the notes.
void print_result(const io::Recording& rec, const dyn::RigidBodyIdOptions& opt, const dyn::RigidBodyIdResult& r) {
  const char* kind = opt.joint_torque_sensor ? "joint (torque sensor: no rotor inertia)" : "motor (rotor inertia identified)";
  std::printf("torque kind: %s\n", kind);
  std::printf("acceleration: zero-phase Gaussian derivative of dq, sigma = %.1f ms (velocity band %.2f Hz)\n",
              r.acceleration.sigma_s * 1e3, r.acceleration.cutoff_hz);
  std::printf("base parameters: %d of %d rigid-body parameters estimated; line-search step from the prior %.3f\n",
              r.base_parameters, r.free_parameters, r.feasibility_step);
  std::printf("held-out RMS (blocks 1, 4, 7 of 10) [N·m]:\n joint  prior rigid  prior+friction  identified   f_c     f_v     f_o\n");
  for (std::size_t j = 0; j < r.friction.size(); ++j) {
    const auto& f = r.friction[j];
    std::printf("%5d  %10.4f  %14.4f  %10.4f  %7.4f %7.4f %7.4f\n", rec.joint_ids[j], r.heldout_rms_prior_rigid[j],
                r.heldout_rms_prior[j], r.heldout_rms_after[j], f.coulomb, f.viscous, f.offset);
  }
  std::printf("identified links %s (held-out MSE ratio against the prior + friction %.3f)\n",
              r.accepted ? "kept" : "NOT kept: prior's links written", r.heldout_mse_ratio);
  for (std::size_t i = 0; i < r.links.size(); ++i) {
    const auto& l = r.links[i];
    std::printf("link %zu: mass %.4f -> %.4f kg, %s\n", i + 1, l.before(0), l.after(0),
                l.consistency.ok ? "physically consistent" : l.consistency.reason.c_str());
  }
  if (r.payload.claimed) {
    std::printf("payload (last link's change): %.3f kg at (%.3f, %.3f, %.3f) m\n", r.payload.mass, r.payload.com.x(),
                r.payload.com.y(), r.payload.com.z());
  } else {
    std::printf("payload: not claimed (%s)\n", r.payload.reason.c_str());
  }
  for (const auto& n : r.notes) std::printf("note: %s\n", n.c_str());
}

/// The JSON's "rigid_body": the inputs, the filter, the figures, per link before and after,
/// the payload.
nlohmann::json rigid_body_json(const std::string& recording, const nlohmann::json& resampling, const std::string& model_path,
                               const dyn::RigidBodyIdOptions& opt, const dyn::RigidBodyIdResult& r) {
  nlohmann::json rb = {{"recording", recording},
                       {"prior_model", model_path},
                       {"torque_kind", opt.joint_torque_sensor ? "joint" : "motor"},
                       {"resampling", resampling},
                       {"acceleration_filter",
                        {{"type", "zero-phase Gaussian derivative of dq"},
                         {"sigma_s", r.acceleration.sigma_s},
                         {"velocity_band_hz", r.acceleration.cutoff_hz}}},
                       {"base_parameters", r.base_parameters},
                       {"free_parameters", r.free_parameters},
                       {"feasibility_step", r.feasibility_step},
                       {"accepted", r.accepted},
                       {"heldout_mse_ratio", r.heldout_mse_ratio},
                       {"train_samples", r.train_samples},
                       {"heldout_samples", r.heldout_samples},
                       {"heldout_blocks", {1, 4, 7}},
                       {"notes", r.notes}};
  for (std::size_t i = 0; i < r.links.size(); ++i) {
    const auto& l = r.links[i];
    rb["links"].push_back({{"link", i + 1},
                           {"before", link_json(l.before)},
                           {"after", link_json(l.after)},
                           {"rotor_inertia_before", l.rotor_before},
                           {"rotor_inertia_after", l.rotor_after},
                           {"consistent", l.consistency.ok},
                           {"com_bound_m", l.com_bound_m},
                           {"line_search_step", l.step}});
  }
  const auto& p = r.payload;
  rb["payload"] = {{"mass_kg", p.mass},
                   {"com_m", {p.com.x(), p.com.y(), p.com.z()}},
                   {"inertia_com_kg_m2",
                    {{"xx", p.inertia_com(0, 0)}, {"yy", p.inertia_com(1, 1)}, {"zz", p.inertia_com(2, 2)},
                     {"xy", p.inertia_com(0, 1)}, {"xz", p.inertia_com(0, 2)}, {"yz", p.inertia_com(1, 2)}}},
                   {"claimed", p.claimed},
                   {"reason", p.reason}};
  return rb;
}

/// The JSON's "joints": per joint the friction and the residual figures.
nlohmann::json joints_json(const io::Recording& rec, const dyn::RigidBodyIdResult& r) {
  nlohmann::json joints;
  for (std::size_t j = 0; j < r.friction.size(); ++j) {
    const auto& f = r.friction[j];
    joints.push_back({{"joint", rec.joint_ids[j]},
                             {"friction",
                              {{"coulomb", f.coulomb},
                               {"coulomb_pos", f.coulomb_pos},
                               {"coulomb_neg", f.coulomb_neg},
                               {"viscous", f.viscous},
                               {"offset", f.offset},
                               {"tanh_eps_rad_s", f.eps}}},
                             {"rms_prior_rigid", r.rms_prior_rigid[j]},
                             {"rms_before", r.rms_before[j]},
                             {"rms_after", r.rms_after[j]},
                             {"heldout_rms_prior_rigid", r.heldout_rms_prior_rigid[j]},
                             {"heldout_rms_before", r.heldout_rms_prior[j]},
                             {"heldout_rms_after", r.heldout_rms_after[j]},
                             {"heldout_moving_rms_before", r.heldout_moving_rms_prior[j]},
                             {"heldout_moving_rms_after", r.heldout_moving_rms_after[j]},
                             {"slow_speed_rad_s", r.slow_speed_rad_s[j]},
                             {"noise_std", r.noise_weight[j]}});
  }
  return joints;
}
}  // namespace

void add_rigid_body_options(CLI::App* cmd, RigidBodyCliOptions& o) {
  cmd->add_flag("--rigid-body", o.enabled,
                "Identify the whole arm's rigid-body parameters (+ payload, + per-joint friction) instead of LuGre;\n"
                "example: jointguard identify rec.csv --model models/panda.yaml --rigid-body --torque-kind joint --model-out out/panda_id.yaml --json out/rbid.json");
  cmd->add_option("--model-out", o.model_out, "With --rigid-body: write the corrected robot file here (YAML)")->check(output_file());
  cmd->add_option("--com-margin", o.com_margin_m,
                  "With --rigid-body: CoM bound = max(reach, |prior CoM|) + this [m]")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--sigma-ms", o.sigma_ms, "With --rigid-body: acceleration filter width [ms] (default: from the data)")
      ->check(CLI::Range(0.0, 10000.0));
  cmd->add_option("--prior-weight", o.prior_weight,
                  "With --rigid-body: weight of the robot file's values (prior std = parameter scale / sqrt(w))")
      ->capture_default_str()
      ->check(CLI::Range(1e-9, 1e9));
  cmd->add_option("--friction-eps", o.friction_eps,
                  "With --rigid-body: Coulomb tanh velocity scale [rad/s] (default: 3x the velocity noise)")
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--slow-speed", o.slow_speed,
                  "With --rigid-body: rows slower than this [rad/s] are left out of the fit (default: 3x the tanh scale; 0: keep all)");
  cmd->add_flag("--payload-only", o.payload_only, "With --rigid-body: only the payload (last link) + friction, arm at the prior");
  cmd->add_flag("--asymmetric-coulomb", o.asymmetric_coulomb, "With --rigid-body: separate Coulomb levels per direction");
}

int run_identify_rigid(const io::Recording& rec, const std::string& recording, const nlohmann::json& resampling,
                       const robot::RobotModel& prior, const std::string& model_path, const std::string& json,
                       const RigidBodyCliOptions& o) {
  dyn::RigidBodyIdOptions opt = id_options(rec, o);
  dyn::RigidBodyIdResult r;
  // The prior's arm-level plant_effects (a payload, a link's mass) are part of the arm the
  // fit starts from, and are written back as themselves, once: never fitted as if absent and
  // then added on top.
  robot::RobotModel start = prior;
  std::vector<robot::PlantEffect> folded;
  for (const auto& n : diag::fold_arm_effects(start, &folded)) std::printf("%s\n", n.c_str());
  try {
    if (!start.plant_effects.empty()) opt.known_torque = per_joint_effects_torque(rec, start);
    r = dyn::identify_rigid_body(rec, start, opt);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "%s: %s\n", recording.c_str(), e.what());
    return 1;
  }
  print_result(rec, opt, r);
  nlohmann::json out;
  out["rigid_body"] = rigid_body_json(recording, resampling, model_path, opt, r);
  out["joints"] = joints_json(rec, r);
  // Write only after everything is computed: model first, then the JSON, each atomically.
  if (!o.model_out.empty()) {
    robot::RobotModel m = r.model;
    m.plant_effects = start.plant_effects;
    for (const auto& n : diag::unfold_arm_effects(m, folded)) std::printf("%s\n", n.c_str());
    robot::write_robot(o.model_out, m,
                       "Identified by: jointguard identify " + recording + " --model " + model_path +
                           " --rigid-body (torque kind " + (opt.joint_torque_sensor ? "joint" : "motor") +
                           ")\nFormat: docs/robot-model.md. Per-joint friction and figures: the --json output.");
    std::printf("wrote %s\n", o.model_out.c_str());
  }
  if (!json.empty()) {
    out["identity"] = result_identity();
    io::write_text_atomic(json, out.dump(2) + "\n");
    std::printf("wrote %s\n", json.c_str());
  }
  return 0;
}

}  // namespace jg::cli
