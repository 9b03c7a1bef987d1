#include "sim/scenario.hpp"
#include "safety/body_regions.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "io/yaml_fields.hpp"
#include "motion/calibration_motion.hpp"
#include "models/paper_friction.hpp"
#include "robot/robot_model.hpp"
#include "sim/apply_effects.hpp"

namespace jg::sim {
namespace {
using io::YamlFields;

JointVector to_joint_vector(const std::vector<double>& v) {
  JointVector out(static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) out(static_cast<Eigen::Index>(i)) = v[i];
  return out;
}

/// A generated motion's length [s]: its moves are built in memory before the run (at least
/// one per 0.5 s), so it is bounded: 7 days (1.2 million moves, about 0.4 GB under the
/// sanitizers); 76 days ran the scenario fuzzer out of memory.
constexpr double kMaxGeneratedMotionS = 7.0 * 86400.0;
double generated_duration(const YamlFields& t) {
  const double d = t.number("duration_s");
  if (!(d > 0.0) || d > kMaxGeneratedMotionS) t.fail("duration_s", "expected > 0 and at most 604800 (7 days)");
  return d;
}

std::shared_ptr<const Trajectory> parse_trajectory(const YamlFields& t, std::size_t n, unsigned long long seed) {
  const std::string type = t.text("type");
  if (type == "excitation") {
    t.allow_only({"type", "offset_rad", "joints", "amplitude_rad", "frequency_hz", "periods", "blend_s", "direction"});
    std::vector<bool> active(n, false);
    for (const double j : t.numbers("joints")) {
      if (j < 1 || j > static_cast<double>(n) || j != std::floor(j)) t.fail("joints", "joint numbers are 1.." + std::to_string(n));
      active[static_cast<std::size_t>(j) - 1] = true;
    }
    const double direction = t.number("direction", 1.0);
    if (direction != 1.0 && direction != -1.0) t.fail("direction", "expected 1 or -1");
    const long periods = t.integer("periods", 4);
    if (periods < 1 || periods > 1000000) t.fail("periods", "expected 1..1000000");  // before the cast to int
    const double freq = t.number("frequency_hz", 0.2), blend = t.number("blend_s", 2.5);
    if (!(freq > 0.0)) t.fail("frequency_hz", "expected > 0");
    if (!(blend > 0.0)) t.fail("blend_s", "expected > 0");
    return std::make_shared<ExcitationTrajectory>(to_joint_vector(t.numbers("offset_rad", n)), active,
                                                  PaperExcitation(t.number("amplitude_rad", 0.6), freq,
                                                                  static_cast<int>(periods), blend),
                                                  direction);
  }
  if (type == "pick") {
    t.allow_only({"type", "home_rad", "workpiece_rad", "repetitions"});
    // Built in memory like a generated motion, so bounded alike (63 million repetitions ran
    // the scenario fuzzer out of memory): at most 7 days of its 7.4 s cycle.
    constexpr long kMaxPickRepetitions = static_cast<long>(kMaxGeneratedMotionS / kPickCycleS);
    const long reps = t.integer("repetitions", 1);
    if (reps < 1 || reps > kMaxPickRepetitions) {
      t.fail("repetitions", "expected 1.." + std::to_string(kMaxPickRepetitions) + " (7 days)");
    }
    return make_pick_task(to_joint_vector(t.numbers("home_rad", n)), to_joint_vector(t.numbers("workpiece_rad", n)),
                          static_cast<int>(reps));
  }
  if (type == "random") {
    t.allow_only({"type", "start_rad", "lower_rad", "upper_rad", "max_speed_rad_s", "duration_s"});
    const double speed = t.number("max_speed_rad_s");
    if (!(speed > 0.0)) t.fail("max_speed_rad_s", "expected > 0");
    return make_random_moves(to_joint_vector(t.numbers("start_rad", n)), to_joint_vector(t.numbers("lower_rad", n)),
                             to_joint_vector(t.numbers("upper_rad", n)), speed, generated_duration(t), seed);
  }
  if (type == "calibration") {
    // Covers the workspace and its stops (motion/calibration_motion.hpp).
    t.allow_only({"type", "start_rad", "lower_rad", "upper_rad", "max_speed_rad_s", "accel_rad_s2", "stop_decel_rad_s2",
                  "stop_share", "levels", "speed_steps", "dwell_max_s", "duration_s"});
    CalibrationMotion c;
    c.max_speed = t.number("max_speed_rad_s");
    c.accel = t.number("accel_rad_s2", c.accel);
    c.stop_decel = t.number("stop_decel_rad_s2", c.stop_decel);
    c.stop_share = t.number("stop_share", c.stop_share);
    // Passed on as read (long, never cast): make_calibration_motion checks their range.
    c.levels = t.integer("levels", c.levels);
    c.speed_steps = t.integer("speed_steps", c.speed_steps);
    c.dwell_max_s = t.number("dwell_max_s", c.dwell_max_s);
    try {
      return make_calibration_motion(to_joint_vector(t.numbers("start_rad", n)), to_joint_vector(t.numbers("lower_rad", n)),
                                     to_joint_vector(t.numbers("upper_rad", n)), c, generated_duration(t), seed);
    } catch (const CalibrationMotionError& e) {
      t.fail(e.field(), e.problem());  // at the field's line when the file set it
    }
  }
  if (type == "move") {
    // One rest-to-rest quintic move whose fastest joint peaks at peak_speed_rad_s (the
    // quintic's peak is 1.875 x its mean speed), then a dwell: the ISO/TS 15066 scenarios.
    t.allow_only({"type", "start_rad", "target_rad", "peak_speed_rad_s", "dwell_s"});
    const JointVector start = to_joint_vector(t.numbers("start_rad", n)), target = to_joint_vector(t.numbers("target_rad", n));
    const double speed = t.number("peak_speed_rad_s");
    if (!(speed > 0.0) || speed > 10.0) t.fail("peak_speed_rad_s", "expected in (0, 10]");
    const double travel = (target - start).cwiseAbs().maxCoeff();
    if (!(travel > 0.0)) t.fail("target_rad", "must differ from start_rad");
    const double dwell = t.number("dwell_s", 2.0);
    if (!(dwell >= 0.0) || dwell > 3600.0) t.fail("dwell_s", "expected in [0, 3600]");
    return std::make_unique<WaypointTrajectory>(start, std::vector<WaypointTrajectory::Waypoint>{{target, 1.875 * travel / speed, dwell}});
  }
  t.fail("type", "unknown trajectory type '" + type + "' (excitation, pick, random, move, calibration)");
}

JointFrictionTruth parse_friction(const YamlFields& f, const JointFrictionTruth& base) {
  f.allow_only({"joint", "sigma0", "sigma1", "sigma2", "tau_c", "tau_s", "w_s", "ripple_amplitude_nm",
                "ripple_periods_per_rev", "ripple_phase_rad", "asymmetry", "viscous_asymmetry", "drift", "drift_time_constant_s",
                "load_coefficient", "viscous_power_nm", "viscous_power_exponent", "stribeck_extra_nm", "stribeck_extra_w_s",
                "stribeck_extra_exponent"});
  JointFrictionTruth t = base;
  t.lugre.sigma0 = f.number("sigma0", t.lugre.sigma0);
  t.lugre.sigma1 = f.number("sigma1", t.lugre.sigma1);
  t.lugre.sigma2 = f.number("sigma2", t.lugre.sigma2);
  t.lugre.tau_c = f.number("tau_c", t.lugre.tau_c);
  t.lugre.tau_s = f.number("tau_s", t.lugre.tau_s);
  t.lugre.w_s = f.number("w_s", t.lugre.w_s);
  if (validate(t.lugre) != Error::ok) f.fail("", "LuGre parameters invalid (need sigma0, tau_c, tau_s, w_s > 0; sigma1, sigma2 >= 0)");
  auto& e = t.effects;
  e.ripple_amplitude = f.number("ripple_amplitude_nm", e.ripple_amplitude);
  e.ripple_periods_per_rev = f.number("ripple_periods_per_rev", e.ripple_periods_per_rev);
  e.ripple_phase = f.number("ripple_phase_rad", e.ripple_phase);
  e.asymmetry = f.number("asymmetry", e.asymmetry);
  if (std::fabs(e.asymmetry) >= 1.0) f.fail("asymmetry", "expected |asymmetry| < 1");
  e.viscous_asymmetry = f.number("viscous_asymmetry", e.viscous_asymmetry);
  e.drift = f.number("drift", e.drift);
  e.drift_time_constant_s = f.number("drift_time_constant_s", e.drift_time_constant_s);
  if (!(e.drift_time_constant_s > 0.0)) f.fail("drift_time_constant_s", "expected > 0");
  e.load_coefficient = f.number("load_coefficient", e.load_coefficient);
  // Shapes beyond LuGre (friction_truth.hpp): a shear-thinning viscous term and a Stribeck
  // excess of another law (1: exponential, 2: Gaussian).
  e.viscous_power_nm = f.number("viscous_power_nm", e.viscous_power_nm);
  if (e.viscous_power_nm < 0.0) f.fail("viscous_power_nm", "expected >= 0");
  e.viscous_power_exponent = f.number("viscous_power_exponent", e.viscous_power_exponent);
  if (!(e.viscous_power_exponent > 0.0) || e.viscous_power_exponent > 3.0) f.fail("viscous_power_exponent", "expected in (0, 3]");
  e.stribeck_extra_nm = f.number("stribeck_extra_nm", e.stribeck_extra_nm);
  e.stribeck_extra_w_s = f.number("stribeck_extra_w_s", e.stribeck_extra_w_s);
  if (!(e.stribeck_extra_w_s > 0.0) || e.stribeck_extra_w_s > 100.0) f.fail("stribeck_extra_w_s", "expected in (0, 100] rad/s");
  e.stribeck_extra_exponent = f.number("stribeck_extra_exponent", e.stribeck_extra_exponent);
  if (!(e.stribeck_extra_exponent > 0.0) || e.stribeck_extra_exponent > 4.0) f.fail("stribeck_extra_exponent", "expected in (0, 4]");
  return t;
}

CollisionEvent parse_collision(const YamlFields& c, std::size_t n) {
  c.allow_only({"t_s", "link", "point_m", "direction", "profile", "peak_force_n", "duration_s", "rise_s",
                "stiffness_n_per_m", "damping_n_s_per_m", "body_region"});
  CollisionEvent e;
  e.t_start = c.number("t_s");
  const long link = c.integer("link", -1);
  if (link < 1 || link > static_cast<long>(n)) c.fail("link", "expected a link number 1.." + std::to_string(n));
  e.link = static_cast<int>(link);
  const auto p = c.numbers("point_m", 3);
  e.point_in_link = {p[0], p[1], p[2]};
  const YAML::Node direction = c.has("direction") ? c.node()["direction"] : YAML::Node();
  if (direction.IsScalar() && direction.as<std::string>() == "against_motion") {
    e.against_motion = true;  // resolved at the onset: the body part stands in the way
  } else {
    const auto d = c.numbers("direction", 3);
    e.direction_base = {d[0], d[1], d[2]};
    if (!(e.direction_base.norm() > 0.0)) c.fail("direction", "must not be zero");
  }
  if (!parse_profile(c.text("profile", "impact"), e.profile)) c.fail("profile", "expected impact, push, clamp or free");
  // A body region (ISO/TS 15066 Annex A) gives a clamp or free contact its spring constant
  // and, for a free contact, the body part's effective mass; the force is then what the
  // arm's motion makes it (no cap unless peak_force_n is given).
  e.body_region = c.text("body_region", "");
  if (!e.body_region.empty()) {
    try {
      const safety::BodyRegion& r = safety::body_region(e.body_region);
      e.stiffness_n_per_m = r.spring_n_per_m;
      e.body_mass_kg = r.effective_mass_kg;
    } catch (const std::invalid_argument& err) {
      c.fail("body_region", err.what());
    }
    if (e.profile != CollisionProfile::clamp && e.profile != CollisionProfile::free) {
      c.fail("body_region", "applies to clamp and free contacts only");
    }
  } else if (e.profile == CollisionProfile::free) {
    c.fail("body_region", "a free contact needs a body region (its effective mass)");
  }
  e.peak_force_n = e.body_region.empty() ? c.number("peak_force_n") : c.number("peak_force_n", 1e4);
  if (!(e.peak_force_n > 0.0)) c.fail("peak_force_n", "expected > 0");
  e.duration_s = c.number("duration_s", e.duration_s);
  if (!(e.duration_s > 0.0)) c.fail("duration_s", "expected > 0");
  e.rise_s = c.number("rise_s", e.rise_s);
  if (e.rise_s < 0.0) c.fail("rise_s", "expected >= 0");
  e.stiffness_n_per_m = c.number("stiffness_n_per_m", e.stiffness_n_per_m);
  e.damping_n_s_per_m = c.number("damping_n_s_per_m", e.damping_n_s_per_m);
  return e;
}

// load_scenario's parts, in its order (a file's errors are found in the same order as
// before): each reads its keys into the setup.

/// The robot file: the scenario's `model` (relative to it) or the override.
void load_model(const YamlFields& root, const std::string& path, const std::string& model_override,
                const robot::LoadOptions& model_options, Scenario& s) {
  const std::filesystem::path model_path =
      model_override.empty() ? std::filesystem::path(path).parent_path() / std::filesystem::path(root.text("model"))
                             : std::filesystem::path(model_override);
  // A model that is not there or of no known type is the scenario's error (its `model`
  // line); errors inside the model file name that file.
  if (model_override.empty()) {
    std::error_code ec;
    const std::string ext = model_path.extension().string();
    if (!std::filesystem::is_regular_file(model_path, ec)) root.fail("model", "'" + model_path.string() + "' is not a file");
    if (ext != ".yaml" && ext != ".yml" && ext != ".urdf") root.fail("model", "unknown robot file type (expected .yaml, .yml or .urdf)");
  }
  try {
    s.model = load_plant_model(model_path.string(), model_options);
  } catch (const io::FormatError&) {
    throw;
  } catch (const std::exception& e) {
    root.fail("model", e.what());
  }
}

/// Seed, name, rates and duration into the setup; returns the seed used (the override's if given).
unsigned long long load_timing(const YamlFields& root, const std::string& path, unsigned long long seed_override,
                               bool has_seed_override, Scenario& s) {
  SimulationSetup& st = s.setup;
  const long seed = root.integer("seed", 1);
  if (seed < 0) root.fail("seed", "expected >= 0");
  const unsigned long long seed_used = has_seed_override ? seed_override : static_cast<unsigned long long>(seed);
  st.meta.model = s.model.name;
  st.meta.scenario = root.text("name", std::filesystem::path(path).stem().string());
  st.meta.seed = seed_used;
  st.control_rate_hz = root.number("control_rate_hz", 1000.0);
  if (!(st.control_rate_hz > 0.0) || st.control_rate_hz > 100000.0) root.fail("control_rate_hz", "expected 0 < rate <= 100000");
  st.plant.plant_rate_hz = root.number("plant_rate_hz", std::max(2000.0, 2.0 * st.control_rate_hz));
  if (!(st.plant.plant_rate_hz >= st.control_rate_hz)) root.fail("plant_rate_hz", "must be >= control_rate_hz");
  // Bounds that keep a run finite (a typo of 1e9 Hz or 1e12 s would hang or take GBs):
  // 1 MHz covers the stiffest elastic gear; 30 days of simulated time.
  if (st.plant.plant_rate_hz > 1e6) root.fail("plant_rate_hz", "expected <= 1000000");
  st.duration_s = root.number("duration_s", 0.0);
  if (st.duration_s < 0.0 || st.duration_s > 30.0 * 86400.0) root.fail("duration_s", "expected 0 .. 2592000 (30 days)");
  if (st.duration_s * st.control_rate_hz > 2e8) {
    root.fail("duration_s", "the recording would have more than 2e8 rows at control_rate_hz; shorten it or lower the rate");
  }
  return seed_used;
}

void load_true_friction(const YamlFields& root, std::size_t n, SimulationSetup& st) {
  // True friction: the paper's Table 1 for the first three joints by default.
  std::vector<JointFrictionTruth> friction(n);
  for (std::size_t j = 0; j < n; ++j) friction[j].lugre = kPaperTable1[std::min<std::size_t>(j, 2)];
  if (root.has("friction")) {
    for (const auto& f : root.sequence("friction")) {
      const long j = f.integer("joint", -1);
      if (j < 1 || j > static_cast<long>(n)) f.fail("joint", "expected a joint number 1.." + std::to_string(n));
      friction[static_cast<std::size_t>(j - 1)] = parse_friction(f, friction[static_cast<std::size_t>(j - 1)]);
    }
  }
  if (root.boolean("friction_enabled", true)) st.plant.friction = friction;
}

/// The drives' sensors: the model's, with the scenario's `sensors` on top.
void load_sensors(const YamlFields& root, const std::vector<JointDriveConfig>& drives, unsigned long long seed_used,
                  SimulationSetup& st) {
  st.sensors.drives = drives;
  st.sensors.seed = seed_used;
  if (root.has("sensors")) {
    const YamlFields se = root.child("sensors");
    se.allow_only({"current_noise_rms_a", "current_lsb_a", "current_offset_a", "torque_constant_error", "delay_samples",
                   "link_encoder_bits", "motor_encoder_counts_per_rev"});
    for (auto& d : st.sensors.drives) {
      d.current_noise_rms_a = se.number("current_noise_rms_a", d.current_noise_rms_a);
      d.current_lsb_a = se.number("current_lsb_a", d.current_lsb_a);
      d.current_offset_a = se.number("current_offset_a", d.current_offset_a);
      d.torque_constant_error = se.number("torque_constant_error", d.torque_constant_error);
    }
    if (st.sensors.drives.front().current_noise_rms_a < 0.0) se.fail("current_noise_rms_a", "expected >= 0");
    st.sensors.delay_samples = static_cast<int>(se.integer("delay_samples", 0));
    if (st.sensors.delay_samples < 0 || st.sensors.delay_samples > 100) se.fail("delay_samples", "expected 0..100");
    st.sensors.link_encoder_bits = static_cast<int>(se.integer("link_encoder_bits", 19));
    st.sensors.motor_encoder_counts_per_rev = static_cast<int>(se.integer("motor_encoder_counts_per_rev", 10000));
  }
}

void load_controller(const YamlFields& root, const std::vector<PlantLink>& links, std::size_t n, SimulationSetup& st) {
  // Controller: defaults scaled by the reflected inertia of each joint.
  st.controller.kp.assign(n, 0.0);
  st.controller.kd.assign(n, 0.0);
  const ArmDynamics arm(links);
  const auto M = arm.mass_matrix(st.trajectory->at(0.0).q);
  for (std::size_t j = 0; j < n; ++j) {
    const double inertia = M(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j));
    const double bandwidth = 40.0;  // [rad/s]
    st.controller.kp[j] = inertia * bandwidth * bandwidth;
    st.controller.kd[j] = 2.0 * inertia * bandwidth;
  }
  if (root.has("controller")) {
    const YamlFields c = root.child("controller");
    c.allow_only({"kp", "kd", "inertia_feedforward"});
    if (c.has("kp")) st.controller.kp = c.numbers("kp", n);
    if (c.has("kd")) st.controller.kd = c.numbers("kd", n);
    st.controller.inertia_feedforward = c.boolean("inertia_feedforward", true);
  }
}

void load_elasticity(const YamlFields& root, std::size_t n, SimulationSetup& st) {
  const YamlFields e = root.child("elasticity");
  e.allow_only({"stiffness_nm_per_rad", "damping_nm_s_per_rad", "backlash_rad"});
  const auto k = e.numbers("stiffness_nm_per_rad", n);
  const auto d = e.has("damping_nm_s_per_rad") ? e.numbers("damping_nm_s_per_rad", n) : std::vector<double>(n, 0.0);
  const auto b = e.has("backlash_rad") ? e.numbers("backlash_rad", n) : std::vector<double>(n, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    if (!(k[j] > 0.0)) e.fail("stiffness_nm_per_rad", "expected > 0 for every joint");
    st.plant.elasticity.push_back({k[j], d[j], b[j]});
  }
}

void load_payload(const YamlFields& root, SimulationSetup& st) {
  const YamlFields p = root.child("payload");
  p.allow_only({"t_s", "mass_kg", "com_m"});
  const auto c = p.numbers("com_m", 3);
  st.plant.payload = PayloadChange{p.number("t_s"), p.number("mass_kg"), {c[0], c[1], c[2]}};
  if (!(st.plant.payload->mass > 0.0)) p.fail("mass_kg", "expected > 0");
}

/// A random campaign's collisions, drawn from the seed.
void load_campaign(const YamlFields& root, unsigned long long seed_used, const std::vector<double>& link_lengths,
                   std::size_t n, SimulationSetup& st) {
  const YamlFields c = root.child("campaign");
  c.allow_only({"count", "links", "t_min_s", "t_max_s", "spacing_s", "force_min_n", "force_max_n", "profiles"});
  CampaignSpec spec;
  spec.seed = seed_used;
  spec.count = static_cast<int>(c.integer("count", 50));
  if (c.has("links")) {
    spec.links.clear();
    for (const double l : c.numbers("links")) {
      if (l < 1 || l > static_cast<double>(n)) c.fail("links", "link numbers are 1.." + std::to_string(n));
      spec.links.push_back(static_cast<int>(l));
    }
  }
  spec.t_min = c.number("t_min_s", spec.t_min);
  spec.t_max = c.number("t_max_s", st.duration_s > 0.0 ? st.duration_s - 2.0 : st.trajectory->duration() - 2.0);
  spec.spacing_s = c.number("spacing_s", spec.spacing_s);
  spec.force_min_n = c.number("force_min_n", spec.force_min_n);
  spec.force_max_n = c.number("force_max_n", spec.force_max_n);
  if (!(spec.t_max > spec.t_min)) c.fail("t_max_s", "must be after t_min_s");
  const auto drawn = draw_campaign(spec, link_lengths);
  st.collisions.insert(st.collisions.end(), drawn.begin(), drawn.end());
}

/// The simulated arm's friction, sensors, controller and integration from a plant file
/// (relative to the scenario), which then owns them: the scenario may not set them too.
void load_plant_file(const YamlFields& root, const std::string& path, std::size_t n, SimulationSetup& st) {
  for (const char* key : {"friction", "sensors", "controller", "plant_rate_hz"}) {
    if (root.has(key)) root.fail(key, "set by the plant file ('plant'); give it there");
  }
  const std::filesystem::path plant_path = std::filesystem::path(path).parent_path() / root.text("plant");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(plant_path, ec)) root.fail("plant", "'" + plant_path.string() + "' is not a file");
  const PlantSpec spec = load_plant_spec(plant_path.string(), n);
  apply_plant_spec(spec, st);
  if (!root.boolean("friction_enabled", true)) st.plant.friction.clear();
  if (!(st.plant.plant_rate_hz >= st.control_rate_hz)) root.fail("plant", "the plant file's plant_rate_hz must be >= control_rate_hz");
}
}  // namespace

Scenario load_scenario(const std::string& path, unsigned long long seed_override, bool has_seed_override,
                       const std::string& model_override, const robot::LoadOptions& model_options) {
  const YamlFields root = YamlFields::load_file(path);
  root.allow_only({"name", "model", "duration_s", "control_rate_hz", "plant_rate_hz", "seed", "trajectory",
                   "friction", "friction_enabled", "sensors", "controller", "collisions", "campaign", "elasticity",
                   "payload", "plant"});
  Scenario s;
  s.file = path;
  load_model(root, path, model_override, model_options, s);
  const std::size_t n = s.model.links.size();
  SimulationSetup& st = s.setup;
  const unsigned long long seed_used = load_timing(root, path, seed_override, has_seed_override, s);
  st.plant.links = s.model.links;
  st.trajectory = parse_trajectory(root.child("trajectory"), n, seed_used);
  load_true_friction(root, n, st);
  load_sensors(root, s.model.drives, seed_used, st);
  load_controller(root, s.model.links, n, st);
  if (root.has("elasticity")) load_elasticity(root, n, st);
  if (root.has("payload")) load_payload(root, st);
  if (root.has("collisions")) {
    for (const auto& c : root.sequence("collisions")) st.collisions.push_back(parse_collision(c, n));
  }
  if (root.has("campaign")) load_campaign(root, seed_used, s.model.link_lengths, n, st);
  if (root.has("plant")) load_plant_file(root, path, n, st);
  if (!s.model.plant_effects.empty()) {
    // What `diagnose --model-out` found in the real arm, on top of the scenario's setting.
    s.effects = apply_plant_effects(s.model.plant_effects, 1.0 / st.control_rate_hz, st);
  }
  return s;
}

}  // namespace jg::sim

namespace jg::sim {

PlantSpec load_plant_spec(const std::string& path, std::size_t joints) {
  const YamlFields root = YamlFields::load_file(path);
  root.allow_only({"name", "description", "plant_rate_hz", "integrator", "friction", "sensors", "controller"});
  PlantSpec p;
  p.file = path;
  p.plant_rate_hz = root.number("plant_rate_hz", 0.0);
  if (p.plant_rate_hz < 0.0 || p.plant_rate_hz > 1e6) root.fail("plant_rate_hz", "expected 0 (the default) .. 1000000");
  const std::string integrator = root.text("integrator", "rk4");
  if (integrator == "rk4") {
    p.integrator = Integrator::rk4;
  } else if (integrator == "semi_implicit_euler") {
    p.integrator = Integrator::semi_implicit_euler;
  } else {
    root.fail("integrator", "expected rk4 or semi_implicit_euler");
  }
  if (root.has("friction")) {
    p.friction.resize(joints);
    for (std::size_t j = 0; j < joints; ++j) p.friction[j].lugre = kPaperTable1[std::min<std::size_t>(j, 2)];
    std::vector<bool> given(joints, false);
    for (const auto& f : root.sequence("friction")) {
      const long j = f.integer("joint", -1);
      if (j < 1 || j > static_cast<long>(joints)) f.fail("joint", "expected a joint number 1.." + std::to_string(joints));
      if (given[static_cast<std::size_t>(j - 1)]) f.fail("joint", "joint " + std::to_string(j) + " given twice");
      given[static_cast<std::size_t>(j - 1)] = true;
      p.friction[static_cast<std::size_t>(j - 1)] = parse_friction(f, p.friction[static_cast<std::size_t>(j - 1)]);
    }
    for (std::size_t j = 0; j < joints; ++j) {
      if (!given[j]) root.fail("friction", "joint " + std::to_string(j + 1) + " missing (a plant file gives every joint's friction)");
    }
  }
  if (root.has("sensors")) {
    const YamlFields se = root.child("sensors");
    se.allow_only({"current_noise_rms_a", "current_lsb_a", "current_offset_a", "torque_constant_error", "delay_samples",
                   "link_encoder_bits", "motor_encoder_counts_per_rev"});
    p.has_sensors = true;
    p.current_noise_rms_a = se.number("current_noise_rms_a");
    if (!(p.current_noise_rms_a >= 0.0) || p.current_noise_rms_a > 10.0) se.fail("current_noise_rms_a", "expected 0 .. 10 A");
    p.current_lsb_a = se.number("current_lsb_a");
    if (!(p.current_lsb_a >= 0.0) || p.current_lsb_a > 1.0) se.fail("current_lsb_a", "expected 0 .. 1 A");
    p.current_offset_a = se.number("current_offset_a", 0.0);
    if (std::fabs(p.current_offset_a) > 10.0) se.fail("current_offset_a", "expected within +-10 A");
    p.torque_constant_error = se.number("torque_constant_error", 0.0);
    if (!(p.torque_constant_error > -0.9) || p.torque_constant_error > 9.0) se.fail("torque_constant_error", "expected in (-0.9, 9]");
    const long delay = se.integer("delay_samples", 0);
    if (delay < 0 || delay > 100) se.fail("delay_samples", "expected 0..100");
    p.delay_samples = static_cast<int>(delay);
    const long bits = se.integer("link_encoder_bits", 19);
    if (bits < 8 || bits > 32) se.fail("link_encoder_bits", "expected 8..32");
    p.link_encoder_bits = static_cast<int>(bits);
    const long counts = se.integer("motor_encoder_counts_per_rev", 10000);
    if (counts < 4 || counts > 100000000) se.fail("motor_encoder_counts_per_rev", "expected 4..1e8");
    p.motor_encoder_counts_per_rev = static_cast<int>(counts);
  }
  if (root.has("controller")) {
    const YamlFields c = root.child("controller");
    c.allow_only({"bandwidth_rad_s", "damping_ratio", "integral_rad_s", "integral_limit_nm", "inertia_feedforward"});
    p.has_controller = true;
    p.bandwidth_rad_s = c.number("bandwidth_rad_s");
    if (!(p.bandwidth_rad_s > 0.0) || p.bandwidth_rad_s > 1000.0) c.fail("bandwidth_rad_s", "expected in (0, 1000]");
    p.damping_ratio = c.number("damping_ratio", 1.0);
    if (!(p.damping_ratio > 0.0) || p.damping_ratio > 10.0) c.fail("damping_ratio", "expected in (0, 10]");
    p.integral_rad_s = c.number("integral_rad_s", 0.0);
    if (!(p.integral_rad_s >= 0.0) || p.integral_rad_s > 100.0) c.fail("integral_rad_s", "expected 0 .. 100");
    p.integral_limit_nm = c.number("integral_limit_nm", 0.0);
    if (!(p.integral_limit_nm >= 0.0) || p.integral_limit_nm > 1e5) c.fail("integral_limit_nm", "expected 0 .. 1e5");
    if (p.integral_rad_s > 0.0 && !(p.integral_limit_nm > 0.0)) c.fail("integral_limit_nm", "integral action needs a limit > 0 (anti-windup)");
    p.inertia_feedforward = c.boolean("inertia_feedforward", true);
  }
  return p;
}

void apply_plant_spec(const PlantSpec& spec, SimulationSetup& st) {
  const std::size_t n = st.plant.links.size();
  if (spec.plant_rate_hz > 0.0) st.plant.plant_rate_hz = spec.plant_rate_hz;
  st.plant.integrator = spec.integrator;
  if (!spec.friction.empty()) {
    if (spec.friction.size() != n) throw std::invalid_argument(spec.file + ": friction for " + std::to_string(spec.friction.size()) +
                                                               " joints, the model has " + std::to_string(n));
    st.plant.friction = spec.friction;
  }
  if (spec.has_sensors) {
    for (auto& d : st.sensors.drives) {
      d.current_noise_rms_a = spec.current_noise_rms_a;
      d.current_lsb_a = spec.current_lsb_a;
      d.current_offset_a = spec.current_offset_a;
      d.torque_constant_error = spec.torque_constant_error;
    }
    st.sensors.delay_samples = spec.delay_samples;
    st.sensors.link_encoder_bits = spec.link_encoder_bits;
    st.sensors.motor_encoder_counts_per_rev = spec.motor_encoder_counts_per_rev;
  }
  if (spec.has_controller) {
    if (!st.trajectory) throw std::invalid_argument(spec.file + ": the controller needs the set-up's trajectory");
    const ArmDynamics arm(st.plant.links, st.plant.gravity);
    const auto M = arm.mass_matrix(st.trajectory->at(0.0).q);
    const double bandwidth = std::min(spec.bandwidth_rad_s, st.control_rate_hz / 8.0);
    st.controller = ControllerConfig{};
    st.controller.inertia_feedforward = spec.inertia_feedforward;
    for (std::size_t j = 0; j < n; ++j) {
      const double inertia = M(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j));
      const double kp = inertia * bandwidth * bandwidth;
      st.controller.kp.push_back(kp);
      st.controller.kd.push_back(2.0 * spec.damping_ratio * inertia * bandwidth);
      if (spec.integral_rad_s > 0.0) {
        st.controller.ki.push_back(kp * spec.integral_rad_s);
        st.controller.integral_limit_nm.push_back(spec.integral_limit_nm);
      }
    }
  }
}

PlantModel load_plant_model(const std::string& path, const robot::LoadOptions& options) {
  const robot::RobotModel r = robot::load_robot(path, options);
  robot::check_simulatable(r);  // a singular mass matrix would fill the recording with NaN
  PlantModel m;
  m.name = r.name;
  m.links = r.plant_links();
  m.drives = r.drives();
  m.link_lengths = r.reaches();
  m.plant_effects = r.plant_effects;
  return m;
}

}  // namespace jg::sim
