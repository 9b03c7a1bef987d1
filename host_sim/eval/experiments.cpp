#include "eval/experiments.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>

#include "detection/contact_point.hpp"
#include "eval/distributed_estimator.hpp"
#include "eval/firmware_estimator.hpp"
#include "eval/parallel.hpp"
#include "models/paper_friction.hpp"

namespace jg::eval {
namespace {
sim::JointVector home_of(const robot::RobotModel& m) {
  sim::JointVector h = sim::JointVector::Zero(static_cast<Eigen::Index>(m.joints.size()));
  if (h.size() >= 3) {
    h(1) = 0.6;
    h(2) = -0.8;
  }
  return h;
}
}  // namespace

sim::SimulationSetup base_setup(const ExperimentConfig& c, std::shared_ptr<const sim::Trajectory> trajectory,
                                unsigned long long seed) {
  sim::SimulationSetup s;
  robot::check_simulatable(c.model);  // a singular mass matrix would make NaN torques
  s.plant.links = c.model.plant_links();
  const std::size_t n = s.plant.links.size();
  if (!c.plant_friction.empty() && c.plant_friction.size() != n) {
    throw std::invalid_argument("the plant's friction has " + std::to_string(c.plant_friction.size()) + " joints, the model " +
                                std::to_string(n));
  }
  for (std::size_t j = 0; j < n; ++j) {
    s.plant.friction.push_back({c.plant_friction.empty() ? sim::kPaperTable1[std::min<std::size_t>(j, 2)] : c.plant_friction[j], {}});
  }
  s.plant.plant_rate_hz = std::max(2000.0, 2.0 * c.rate_hz);
  s.sensors.drives = c.model.drives();
  for (auto& d : s.sensors.drives) {
    d.current_noise_rms_a = c.current_noise_a;
    d.current_lsb_a = 0.0005;
  }
  s.sensors.seed = seed;
  const sim::ArmDynamics arm(s.plant.links);
  const auto M = arm.mass_matrix(trajectory->at(0.0).q);
  const double bandwidth = std::min(40.0, c.rate_hz / 8.0);
  for (std::size_t j = 0; j < n; ++j) {
    const double inertia = M(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j));
    s.controller.kp.push_back(inertia * bandwidth * bandwidth);
    s.controller.kd.push_back(2.0 * inertia * bandwidth);
  }
  s.trajectory = std::move(trajectory);
  s.control_rate_hz = c.rate_hz;
  s.meta.model = c.model.name;
  s.meta.seed = seed;
  if (c.plant_spec) sim::apply_plant_spec(*c.plant_spec, s);  // a second plant
  return s;
}

namespace {
FirmwareEstimatorConfig firmware_config_for(const ExperimentConfig& c) {
  FirmwareEstimatorConfig f;
  f.model = c.model;
  f.dt = 1.0 / c.rate_hz;
  f.observer = c.gains;
  f.compensate_friction = !c.friction.empty();
  f.friction = c.friction;
  if (c.hold_calibration_s > 0.0 || !c.hold_threshold.empty()) f.holding_velocity_deadband = holding_deadband(c.model, c.rate_hz);
  return f;
}

/// The estimator compared with the configured one on the same measurements: the other
/// scalar in process, or either scalar as the drives on the simulated bus.
struct OtherEstimator {
  std::unique_ptr<Estimator> estimator;
  DistributedEstimator* bus = nullptr;  ///< the same object when it runs on the bus
  [[nodiscard]] Estimator* get() const { return estimator.get(); }
  /// The bus's load over the run just made into `r`.
  void record(RunResult& r) const {
    if (bus == nullptr) return;
    const BusStatistics s = bus->statistics();
    r.bus = RunResult::BusLoad{s.frames, s.incomplete_cycles, s.busy_s, s.elapsed_s};
  }
};

OtherEstimator other_estimator_for(const ExperimentConfig& c) {
  OtherEstimator o;
  if (c.compare_on_bus) {
    // The drives run the host's estimator configuration; they never flag on their own
    // (no node bands): the host's detectors judge their estimates as they judge the other's.
    // Each drive samples its own joint, as on the arm: the bus carries what the arm's does.
    DistributedConfig dc;
    dc.estimator = firmware_config_for(c);
    dc.sensors_over_can = false;
    auto bus = make_distributed_estimator(dc, c.compare_scalar.empty() ? c.scalar : c.compare_scalar);
    o.bus = bus.get();
    o.estimator = std::move(bus);
  } else if (!c.compare_scalar.empty()) {
    ExperimentConfig other = c;
    other.scalar = c.compare_scalar;
    o.estimator = estimator_for(other);
  }
  return o;
}
}  // namespace

std::unique_ptr<Estimator> estimator_for(const ExperimentConfig& c) { return make_firmware_estimator(firmware_config_for(c), c.scalar); }

DetectionConfig detection_for(const ExperimentConfig& c) {
  DetectionConfig d;
  d.threshold = c.thresholds;
  d.low_speed_extra = c.low_speed_extra;
  d.low_speed_width = c.low_speed_width;
  d.debounce_cycles = c.debounce_cycles;
  d.hold_threshold = c.hold_threshold;
  d.isolation_window_s = c.isolation_window_s;
  d.isolation_aligned_s = c.isolation_aligned_s;
  d.isolation_standstill_change = c.isolation_standstill_change;
  d.observer_gain_per_s = c.gains.kind == ObserverKind::first_order ? c.gains.k1 : 0.0;
  d.observer_aligns_motor_torque = c.gains.align_motor_torque;
  d.hold_settle_s = c.hold_settle_s;
  d.hold_reference_s = c.hold_reference_s;
  d.residual_threshold = c.residual_threshold;
  d.residual_time_constant_s = c.residual_time_constant_s;
  d.reaction = c.reaction;
  d.friction = c.friction;
  d.contact.before_s = c.contact_before_s;
  d.contact.after_s = c.contact_after_s;
  d.contact.noise_band_sigmas = c.contact_noise_band_sigmas;
  d.contact.observer_gain_per_s = c.gains.kind == ObserverKind::first_order ? c.gains.k1 : 0.0;
  d.contact.estimator = detection::default_contact_params(c.model.reaches(), c.model.reach_axes());
  if (c.contact_surface_prior) {
    d.contact.estimator.axial_prior_ratio = detection::axial_prior_ratio(c.contact_prior_friction);
    d.contact.estimator.surface_radius_m = sim::kSurfaceRadius;
  }
  d.contact.point_over_the_contact = c.contact_point_over_the_contact;
  d.contact.link_from_isolation = c.contact_link_from_isolation;
  d.contact.estimator.profile_point_likelihood = c.contact_point_over_the_contact;
  d.contact.estimator.force_at_mean_point = c.contact_point_over_the_contact;
  d.contact.force_after_s = c.contact_force_after_s;
  d.contact.lag_correction = c.contact_lag_correction;
  return d;
}

namespace {
/// A run's comparison with the second estimator (another scalar, or the drives on the bus)
/// and its bus load into the summary; `lags` collects the other's detection time minus the
/// first's where both detected.
void tally_compared(const RunResult& r, Summary& s, std::vector<double>& lags) {
  if (r.bus) {
    ++s.bus_runs;
    s.bus_frames += r.bus->frames;
    s.bus_incomplete_cycles += r.bus->incomplete_cycles;
    s.bus_busy_s += r.bus->busy_s;
    s.bus_elapsed_s += r.bus->elapsed_s;
    if (r.bus->elapsed_s > 0.0) s.bus_busy_max_share = std::max(s.bus_busy_max_share, r.bus->busy_s / r.bus->elapsed_s);
  }
  if (!r.compared || (!r.t_detected && !r.t_detected_other)) {
    s.compared += r.compared ? 1 : 0;
    return;
  }
  ++s.compared;
  ++s.compared_detected;
  if (r.t_detected && r.t_detected_other) {
    // Same cycle: equal time stamps of one simulation's control clock.
    s.same_cycle += std::fabs(*r.t_detected - *r.t_detected_other) < 1e-9 ? 1 : 0;
    lags.push_back(*r.t_detected_other - *r.t_detected);
  }
}
}  // namespace

Summary summarize(const std::vector<RunResult>& runs) {
  Summary s;
  s.runs = static_cast<int>(runs.size());
  std::vector<double> delays, after, other_lags;
  for (const auto& r : runs) {
    if (r.t_detected) {
      ++s.detected;
      delays.push_back(*r.t_detected - r.t_collision);
      if (r.t_threshold) after.push_back(*r.t_detected - *r.t_threshold);
    }
    s.isolated += r.link_isolated == r.link_true ? 1 : 0;
    s.isolable += r.isolable ? 1 : 0;
    s.isolated_of_isolable += r.isolable && r.link_isolated == r.link_true ? 1 : 0;
    s.isolable_at_decision += r.isolable_at_decision ? 1 : 0;
    s.isolated_of_isolable_at_decision += r.isolable_at_decision && r.link_isolated == r.link_true ? 1 : 0;
    s.detected_by_hold += r.t_detected && r.detected_by_hold ? 1 : 0;
    s.detected_by_residual += r.t_detected && r.detected_by_residual ? 1 : 0;
    if (r.contact) {
      const ContactOutcome& c = *r.contact;
      const bool right = c.estimate.link == r.link_true;
      ++s.estimated;
      s.estimated_link_right += right ? 1 : 0;
      s.estimated_right_of_isolable += right && r.isolable ? 1 : 0;
      const auto within = [&c](double f) { return std::fabs(f - c.force_true_n) <= 0.2 * c.force_true_n; };
      s.force_within_20pct += within(c.estimate.force_n) ? 1 : 0;
      s.force_within_20pct_true_point += within(c.force_at_true_point_n) ? 1 : 0;
      s.peak_force_within_20pct += std::fabs(c.peak_force_n - r.peak_force_n) <= 0.2 * r.peak_force_n ? 1 : 0;
      const auto within_observed = [&c](double f) { return std::fabs(f - c.force_true_observed_n) <= 0.2 * c.force_true_observed_n; };
      s.force_within_20pct_observed += within_observed(c.estimate.force_n) ? 1 : 0;
      s.force_within_20pct_observed_true_point += within_observed(c.force_at_true_point_n) ? 1 : 0;
      s.force_within_20pct_observed_true_link += within_observed(c.force_given_true_link_n) ? 1 : 0;
      s.point_within_5cm_true_link += c.point_error_given_true_link_m >= 0.0 && c.point_error_given_true_link_m <= 0.05 ? 1 : 0;
      s.point_within_5cm += right && c.point_error_m >= 0.0 && c.point_error_m <= 0.05 ? 1 : 0;
      s.along_within_5cm += right && std::fabs(c.estimate.along_m - c.along_true_m) <= 0.05 ? 1 : 0;
    }
    if (r.max_true_ratio > 1.5) {
      ++s.detectable;
      s.detectable_found += r.t_detected ? 1 : 0;
    }
    if (r.max_true_ratio_moving > 1.5) {
      ++s.detectable_moving;
      s.detectable_moving_found += r.t_detected ? 1 : 0;
    }
    if (r.peak_force_n > 0.0) {
      ++s.touched;
      s.touched_detected += r.t_detected ? 1 : 0;
      s.touched_below_moving += r.max_true_ratio_moving < 1.0 ? 1 : 0;
    }
    tally_compared(r, s, other_lags);
  }
  std::sort(other_lags.begin(), other_lags.end());
  s.both_detected = static_cast<int>(other_lags.size());
  if (!other_lags.empty()) {
    s.other_lag_min_s = other_lags.front();
    s.other_lag_median_s = other_lags[other_lags.size() / 2];
    s.other_lag_max_s = other_lags.back();
  }
  std::sort(delays.begin(), delays.end());
  if (!delays.empty()) {
    s.delay_min = delays.front();
    s.delay_median = delays[delays.size() / 2];
    s.delay_max = delays.back();
  }
  std::sort(after.begin(), after.end());
  s.after_crossing = static_cast<int>(after.size());
  if (!after.empty()) {
    for (const double a : after) s.after_crossing_within_10ms += a <= 0.010 + 1e-9 ? 1 : 0;
    s.after_crossing_median = after[after.size() / 2];
    s.after_crossing_p95 = after[std::min(after.size() - 1, after.size() * 95 / 100)];
    s.after_crossing_max = after.back();
  }
  return s;
}

namespace {
/// Calibration runs are independent segments of kCalibrationSegmentS (the last one
/// shorter): how many for `seconds` of motion. Depends on the length alone, never on the
/// number of threads, so the thresholds are the same on any --jobs.
std::size_t calibration_segments(double seconds) {
  return static_cast<std::size_t>(std::max(1.0, std::ceil(seconds / kCalibrationSegmentS - 1e-9)));
}

double calibration_segment_length(double seconds, std::size_t k) {
  return std::min(kCalibrationSegmentS, seconds - kCalibrationSegmentS * static_cast<double>(k));
}

/// Seed offset of segment k: segment 0 keeps the seeds of the single run the segments
/// replaced; the others are apart from it by a large odd stride (as the free run's).
unsigned long long segment_stride(std::size_t k) { return 1000003ULL * k; }

/// The holding detector's statistics over one segment: largest deviation while armed and
/// the time armed, per joint.
struct HoldSegmentStatistics {
  std::vector<double> band, seconds;
};

HoldSegmentStatistics calibrate_holding_segment(const ExperimentConfig& c, std::size_t k) {
  // Collision-free moves in which joints hold (alone and while others move) and the arm
  // dwells for up to 4 s: the holding detector's reference and deviations, as it runs in
  // detection (armed while the whole arm holds, sim::holding_mask).
  const double length = calibration_segment_length(c.hold_calibration_s, k);
  const auto home = home_of(c.model);
  sim::JointVector lower = home, upper = home;
  for (Eigen::Index j = 0; j < lower.size(); ++j) {
    lower(j) -= 0.7;
    upper(j) += 0.7;
  }
  auto moves = sim::make_random_moves_with_holds(home, lower, upper, 0.8, length + 5.0, c.seed * 19 + 4 + segment_stride(k));
  sim::SimulationSetup free =
      base_setup(c, std::shared_ptr<const sim::Trajectory>(std::move(moves)), c.seed * 23 + 5 + segment_stride(k));
  free.meta.scenario = "calibration_holds";
  free.duration_s = length;
  free.record = false;
  auto est = estimator_for(c);
  const std::size_t n = c.model.joints.size();
  // A threshold never reached: the detector arms and takes its reference as in detection.
  const HoldChangeParams<double> p = hold_params(1e9, c.hold_settle_s, c.hold_reference_s, 1.0 / c.rate_hz);
  std::vector<HoldChangeState<double>> states(n);
  HoldSegmentStatistics out;
  out.band.assign(n, 0.0);
  out.seconds.assign(n, 0.0);
  bool started = false;
  sim::JointVector mu;
  constexpr double kSettleS = 0.5;
  const sim::ControlOverride hook = [&](const sim::CycleContext& ctx) -> std::optional<sim::JointVector> {
    const sim::Measurement& m = *ctx.measurement;
    const JointMask holding = sim::holding_mask(*ctx.reference);
    const EstimatorInput in{m.q, m.dq, m.tau_m, holding};
    if (!started) {
      est->reset(in);
      started = true;
    }
    est->step(in, mu);
    for (std::size_t j = 0; j < n; ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      const bool held = ctx.t >= kSettleS && ((holding >> j) & 1U) != 0U;
      (void)hold_change_step(p, states[j], held, mu(i));
      if (states[j].armed) {
        out.band[j] = std::max(out.band[j], hold_deviation(states[j], mu(i)));
        out.seconds[j] += 1.0 / c.rate_hz;
      }
    }
    return std::nullopt;
  };
  (void)sim::run_simulation(free, hook);
  return out;
}

/// The band statistics over one segment of collision-free random moves, and the residual
/// detector's largest collision-free deviation per joint (merged by maximum).
struct BandSegmentStatistics {
  BandStatistics band;
  std::vector<double> residual_band;
};

BandSegmentStatistics calibrate_band_segment(const ExperimentConfig& c, std::size_t k) {
  // Collision-free motion unlike the identification run: random moves. Not recorded: the
  // compensated and uncompensated observers run in the loop and feed the band statistics.
  const double length = calibration_segment_length(c.calibration_s, k);
  const auto home = home_of(c.model);
  sim::JointVector lower = home, upper = home;
  for (Eigen::Index j = 0; j < lower.size(); ++j) {
    lower(j) -= 0.7;
    upper(j) += 0.7;
  }
  auto moves = sim::make_random_moves(home, lower, upper, 0.8, length + 5.0, c.seed * 13 + 2 + segment_stride(k));
  sim::SimulationSetup free =
      base_setup(c, std::shared_ptr<const sim::Trajectory>(std::move(moves)), c.seed * 17 + 3 + segment_stride(k));
  free.meta.scenario = "calibration_free_run";
  free.duration_s = length;
  free.record = false;
  auto with = estimator_for(c);
  ExperimentConfig bare = c;
  bare.friction.clear();
  auto without = estimator_for(bare);
  const std::size_t n = c.model.joints.size();
  BandStatistics stats(n);
  bool started = false;
  sim::JointVector mu, mu0;
  // The residual detector as it runs in detection (baseline from the first cycle), with a
  // threshold never reached: its largest collision-free |mu - baseline| per joint.
  const ResidualChangeParams<double> rp = residual_params(1e9, c.residual_time_constant_s, 1.0 / c.rate_hz);
  std::vector<ResidualChangeState<double>> residual(n);
  std::vector<double> residual_band(n, 0.0);
  constexpr double kSettleS = 0.5;
  const sim::ControlOverride hook = [&](const sim::CycleContext& ctx) -> std::optional<sim::JointVector> {
    const sim::Measurement& m = *ctx.measurement;
    const EstimatorInput in{m.q, m.dq, m.tau_m, sim::holding_mask(*ctx.reference)};
    if (!started) {
      with->reset(in);
      without->reset(in);
      started = true;
    }
    with->step(in, mu);
    without->step(in, mu0);
    for (std::size_t j = 0; j < n; ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      if (ctx.t >= kSettleS) {
        stats.add(j, m.dq(i), mu(i), mu0(i));
        residual_band[j] = std::max(residual_band[j], residual_deviation(residual[j], mu(i)));
      }
      (void)residual_change_step(rp, residual[j], mu(i));
    }
    return std::nullopt;
  };
  (void)sim::run_simulation(free, hook);
  return BandSegmentStatistics{std::move(stats), std::move(residual_band)};
}
}  // namespace

Thresholds calibrate(const ExperimentConfig& c, double margin_nm) {
  // Both calibrations as independent segments, all of them over c.jobs threads at once
  // (the holding calibration does not depend on the band). Their statistics merge
  // exactly: the band's and the hold's are maxima, the hold's time a sum taken in segment
  // order, so the thresholds do not depend on the number of threads.
  const std::size_t n = c.model.joints.size();
  const std::size_t band_segments = calibration_segments(c.calibration_s);
  const std::size_t hold_segments = c.hold_calibration_s > 0.0 ? calibration_segments(c.hold_calibration_s) : 0;
  std::vector<BandSegmentStatistics> band(band_segments, BandSegmentStatistics{BandStatistics(n), {}});
  std::vector<HoldSegmentStatistics> hold(hold_segments);
  parallel_for(band_segments + hold_segments, std::max(1, c.jobs), [&](std::size_t i) {
    if (i < band_segments) {
      band[i] = calibrate_band_segment(c, i);
    } else {
      hold[i - band_segments] = calibrate_holding_segment(c, i - band_segments);
    }
  });
  BandStatistics stats(n);
  std::vector<double> residual_band(n, 0.0);
  for (const auto& b : band) {
    stats.merge(b.band);
    for (std::size_t j = 0; j < n; ++j) residual_band[j] = std::max(residual_band[j], b.residual_band[j]);
  }
  Thresholds t = stats.fit(margin_nm);
  if (c.residual_detector) {
    t.residual_band = residual_band;
    t.residual_time_constant_s = c.residual_time_constant_s;
    for (const double b : residual_band) t.residual_change.push_back(kResidualFactor * b + kResidualMargin);
  }
  if (hold_segments > 0) {
    t.hold_band.assign(n, 0.0);
    t.hold_seconds.assign(n, 0.0);
    for (const auto& h : hold) {
      for (std::size_t j = 0; j < n; ++j) {
        t.hold_band[j] = std::max(t.hold_band[j], h.band[j]);
        t.hold_seconds[j] += h.seconds[j];
      }
    }
    t.hold_settle_s = c.hold_settle_s;
    t.hold_reference_s = c.hold_reference_s;
    t.hold_change.assign(n, 0.0);
    for (std::size_t j = 0; j < n; ++j) t.hold_change[j] = kHoldFactor * t.hold_band[j] + kHoldMargin;
  }
  return t;
}

namespace {
/// The friction identified from a simulated excitation run, as `identify` would write it.
void identify_friction(ExperimentConfig& c, Preparation& p, const std::function<void(double)>& progress) {
  const std::size_t n = c.model.joints.size();
  auto excitation = std::make_shared<sim::ExcitationTrajectory>(home_of(c.model), std::vector<bool>(n, true),
                                                                sim::PaperExcitation(0.6, 0.2, 4, 2.5));
  sim::SimulationSetup ex = base_setup(c, excitation, c.seed * 11 + 1);
  ex.meta.scenario = "paper_excitation";
  p.excitation = sim::run_simulation(ex).recording;
  ident::GaSettings ga;
  ga.seed = c.seed;
  ga.threads = std::max(1, c.jobs);
  // The same balance as the estimator's (the torque mean or not): the friction identified
  // from the observer's output is the one the estimator then predicts inside that balance.
  const ObserverGains identification_gains{ObserverKind::first_order, c.gains.k1, 0, 0, c.gains.align_motor_torque};
  p.identification = identify_recording(p.excitation, c.model, identification_gains, ga,
                                        [&](double f) { if (progress) progress(0.8 * f); });
  // A joint whose fit the firmware scalar does not hold at this rate (the second plant's
  // narrow Stribeck velocity at 125 Hz: w_s ~0) is identified again bounded to what it holds,
  // as `identify` writes it (FirmwareTarget); a fit that runs is kept as it was.
  bool all_fit = true;
  for (const auto& r : p.identification) all_fit = all_fit && ident::fits_firmware(r.params, 1.0 / c.rate_hz);
  if (!all_fit) {
    ident::GaSettings bounded = ga;
    bounded.firmware.enabled = true;
    bounded.firmware.dt = 1.0 / c.rate_hz;
    const auto again = identify_recording(p.excitation, c.model, identification_gains, bounded);
    for (std::size_t j = 0; j < p.identification.size() && j < again.size(); ++j) {
      if (!ident::fits_firmware(p.identification[j].params, 1.0 / c.rate_hz)) p.identification[j] = again[j];
    }
  }
  c.friction.clear();
  for (const auto& r : p.identification) c.friction.push_back(r.params);
}
}  // namespace

Preparation prepare(ExperimentConfig& c, double margin_nm, const std::function<void(double)>& progress) {
  Preparation p;
  if (c.friction_given) {
    if (c.friction.size() != c.model.joints.size()) {
      throw std::invalid_argument("the given friction has " + std::to_string(c.friction.size()) + " joints, the model " +
                                  std::to_string(c.model.joints.size()));
    }
  } else {
    identify_friction(c, p, progress);
  }
  p.thresholds = calibrate(c, margin_nm);
  c.thresholds = p.thresholds.threshold;
  c.low_speed_extra = p.thresholds.low_speed_extra;
  c.low_speed_width = p.thresholds.low_speed_width;
  c.hold_threshold = p.thresholds.hold_change;
  c.residual_threshold = p.thresholds.residual_change;
  if (progress) progress(1.0);
  return p;
}

std::vector<RunResult> paper_experiments(const ExperimentConfig& c, bool traces, const RunSplit& split) {
  // The paper's occurrence times: waist 7.104 s, shoulder 5.872 s, elbow 5.912 s, during
  // a pick task (move to a workpiece lower left and back).
  struct Spec {
    const char* name;
    int link;
    double t;
    Eigen::Vector3d point, direction;
  };
  const Spec specs[] = {{"collision 1 (waist)", 1, 7.104, {0.1, 0.0, 0.0}, {0.0, 1.0, 0.0}},
                        {"collision 2 (shoulder)", 2, 5.872, {0.25, 0.0, 0.05}, {0.0, 0.0, 1.0}},
                        {"collision 3 (elbow)", 3, 5.912, {0.2, 0.0, 0.04}, {0.0, 0.0, 1.0}}};
  std::vector<RunResult> out;
  const auto home = home_of(c.model);
  sim::JointVector work = home;
  if (work.size() >= 3) {
    work(0) += 0.9;  // to the left
    work(1) += 0.45;  // lower
    work(2) -= 0.5;
  }
  std::vector<std::size_t> chosen;
  for (std::size_t k = 0; k < std::size(specs); ++k) {
    if (specs[k].link <= static_cast<int>(c.model.joints.size()) && split.takes(k)) chosen.push_back(k);
  }
  std::vector<RunResult> slots(chosen.size());
  parallel_for(chosen.size(), split.jobs, [&](std::size_t slot) {
    const Spec& s = specs[chosen[slot]];
    auto traj = sim::make_pick_task(home, work, 2);
    sim::SimulationSetup setup = base_setup(c, std::shared_ptr<const sim::Trajectory>(std::move(traj)), c.seed * 101 + static_cast<unsigned long long>(s.link));
    sim::CollisionEvent e;
    e.t_start = s.t;
    e.link = s.link;
    e.point_in_link = s.point;
    // Push against the joint's motion, tangentially: the direction that loads the
    // collided link's own joint (a person standing in the way).
    const sim::ArmDynamics arm(setup.plant.links);
    const auto ref = setup.trajectory->at(s.t);
    const auto poses = arm.poses(ref.q);
    const int i = s.link - 1;
    const Eigen::Vector3d axis = poses.rotation[i].col(2);
    const Eigen::Vector3d lever = poses.rotation[i] * s.point;
    Eigen::Vector3d tangential = axis.cross(lever);
    if (tangential.norm() < 1e-6) tangential = s.direction;
    const double moving = ref.dq(i) >= 0.0 ? -1.0 : 1.0;
    e.direction_base = moving * tangential.normalized();
    e.profile = sim::CollisionProfile::push;
    e.peak_force_n = 60.0;
    e.rise_s = 0.03;
    e.duration_s = 0.6;
    setup.collisions = {e};
    setup.duration_s = s.t + 1.5;
    auto est = estimator_for(c);
    auto other = other_estimator_for(c);
    const DetectionConfig d = detection_for(c);
    slots[slot] = run_detection(setup, *est, d, s.name, traces, other.get());
    other.record(slots[slot]);
    slots[slot].index = static_cast<int>(chosen[slot]);
  });
  for (auto& r : slots) out.push_back(std::move(r));
  return out;
}

sim::SimulationSetup held_push_setup(const ExperimentConfig& c, int link, double torque_nm) {
  const std::size_t n = c.model.joints.size();
  const sim::JointVector home = home_of(c.model);
  sim::JointVector there = home;
  if (there.size() >= 3) {
    there(0) += 0.5;
    there(1) += 0.3;
    there(2) -= 0.3;
  }
  auto traj = std::make_shared<sim::WaypointTrajectory>(home, std::vector<sim::WaypointTrajectory::Waypoint>{{there, 1.5, 6.0}});
  sim::SimulationSetup s = base_setup(c, traj, c.seed * 41 + static_cast<unsigned long long>(link));
  s.duration_s = 7.0;
  if (torque_nm > 0.0) {
    if (link < 1 || link > static_cast<int>(n)) throw std::invalid_argument("held_push: no link " + std::to_string(link));
    sim::CollisionEvent e;
    e.t_start = 3.5;
    e.link = link;
    e.point_in_link = {0.2, 0.0, 0.0};
    const sim::ArmDynamics arm(s.plant.links);
    const auto poses = arm.poses(there);
    const Eigen::Vector3d axis = poses.rotation[link - 1].col(2);
    const Eigen::Vector3d lever = poses.rotation[link - 1] * e.point_in_link;
    const Eigen::Vector3d tangential = axis.cross(lever);
    e.direction_base = tangential.normalized();
    e.profile = sim::CollisionProfile::push;
    e.peak_force_n = torque_nm / tangential.norm();
    e.rise_s = 0.03;
    e.duration_s = 1.0;
    s.collisions = {e};
  }
  return s;
}

RunResult held_push(const ExperimentConfig& c, int link, double torque_nm, bool traces) {
  const sim::SimulationSetup s = held_push_setup(c, link, torque_nm);
  auto est = estimator_for(c);
  char name[64];
  std::snprintf(name, sizeof name, torque_nm > 0.0 ? "held, %.1f N·m on link %d" : "held, no contact", torque_nm, link);
  RunResult r = run_detection(s, *est, detection_for(c), name, traces);
  r.held_push_nm = torque_nm;
  return r;
}

std::vector<RunResult> held_experiments(const ExperimentConfig& c) {
  // Every link of the chain (a wrist joint's sensitivity is a figure of its own on six and
  // seven joints); the runs are independent and seeded by link, so threads change nothing.
  static constexpr std::array<double, 5> kPushesNm{0.5, 1.0, 1.5, 2.0, 3.0};
  const std::size_t links = c.model.joints.size();
  std::vector<RunResult> out(links * kPushesNm.size() + 1);
  parallel_for(out.size(), c.jobs, [&](std::size_t i) {
    if (i + 1 == out.size()) {
      out[i] = held_push(c, 1, 0.0, false);
    } else {
      out[i] = held_push(c, static_cast<int>(i / kPushesNm.size()) + 1, kPushesNm[i % kPushesNm.size()], false);
    }
  });
  return out;
}

std::vector<int> campaign_links(std::size_t joints) {
  std::vector<int> links{2, 3};
  for (int link = 4; link <= static_cast<int>(joints); ++link) links.push_back(link);
  return links;
}

std::vector<RunResult> campaign(const ExperimentConfig& c, int count, const std::vector<int>& links,
                                const std::function<void(double)>& progress, const RunSplit& split) {
  std::mt19937_64 rng(c.seed * 7919 + 5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto home = home_of(c.model);
  sim::JointVector lower = home, upper = home;
  for (Eigen::Index j = 0; j < lower.size(); ++j) {
    lower(j) -= 0.7;
    upper(j) += 0.7;
  }
  sim::CampaignSpec spec;
  spec.links = links;
  spec.count = count;
  spec.seed = c.seed;
  spec.t_min = 2.5;
  spec.t_max = 1e9;  // each collision gets its own run; only the draw order matters
  spec.spacing_s = 3.0;
  spec.surface_contacts = c.campaign_surface_contacts;
  const auto events = sim::draw_campaign(spec, c.model.reaches());
  // Every draw in index order first, so that run i is the same whoever runs it.
  std::vector<double> t_start(events.size());
  for (double& t : t_start) t = 2.5 + 0.5 * unit(rng);
  std::vector<std::size_t> chosen;
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (split.takes(i)) chosen.push_back(i);
  }
  std::vector<RunResult> out(chosen.size());
  parallel_for(chosen.size(), split.jobs, [&](std::size_t slot) {
    const std::size_t i = chosen[slot];
    sim::CollisionEvent e = events[i];
    e.t_start = t_start[i];
    auto moves = sim::make_random_moves(home, lower, upper, 0.8, 8.0, c.seed * 1000 + i);
    sim::SimulationSetup setup = base_setup(c, std::shared_ptr<const sim::Trajectory>(std::move(moves)), c.seed * 2000 + i);
    setup.collisions = {e};
    setup.duration_s = e.t_start + std::max(1.0, e.duration_s + e.rise_s + 0.5);
    auto est = estimator_for(c);
    auto other = other_estimator_for(c);
    const DetectionConfig d = detection_for(c);
    out[slot] = run_detection(setup, *est, d, "campaign " + std::to_string(i + 1) + " (" + sim::to_string(e.profile) + ")", false,
                              other.get());
    other.record(out[slot]);
    out[slot].index = static_cast<int>(i);
  }, progress);
  return out;
}

std::vector<FreeRunSegment> free_run_segments(const ExperimentConfig& c, double seconds, const RunSplit& split,
                                              const std::function<void(double)>& progress) {
  const auto home = home_of(c.model);
  sim::JointVector lower = home, upper = home;
  for (Eigen::Index j = 0; j < lower.size(); ++j) {
    lower(j) -= 0.7;
    upper(j) += 0.7;
  }
  const auto segments = static_cast<std::size_t>(std::max(1.0, std::ceil(seconds / kFreeRunSegmentS - 1e-9)));
  std::vector<std::size_t> chosen;
  for (std::size_t k = 0; k < segments; ++k) {
    if (split.takes(k)) chosen.push_back(k);
  }
  std::vector<FreeRunSegment> out(chosen.size());
  parallel_for(chosen.size(), split.jobs, [&](std::size_t slot) {
    const std::size_t k = chosen[slot];
    const double start = kFreeRunSegmentS * static_cast<double>(k);
    const double length = std::min(kFreeRunSegmentS, seconds - start);
    // Segment 0 keeps the seeds of the single run this replaced; the others are apart from
    // every other seed of the evaluation (a large odd stride).
    const unsigned long long stride = 1000003ULL * k;
    auto moves = c.free_run_holds ? sim::make_random_moves_with_holds(home, lower, upper, 0.8, length + 5.0, c.seed * 31 + 7 + stride)
                                  : sim::make_random_moves(home, lower, upper, 0.8, length + 5.0, c.seed * 31 + 7 + stride);
    sim::SimulationSetup setup = base_setup(c, std::shared_ptr<const sim::Trajectory>(std::move(moves)), c.seed * 37 + 11 + stride);
    setup.duration_s = length;
    auto est = estimator_for(c);
    DetectionConfig d = detection_for(c);
    d.reaction = Reaction::none;
    const RunResult r = run_detection(setup, *est, d, "collision-free", false);
    FreeRunSegment& seg = out[slot];
    seg.index = static_cast<int>(k);
    seg.seconds = length;
    for (const double t : r.false_alarm_times) seg.alarm_times.push_back(start + t);
    for (FalseAlarm a : r.false_alarms) {
      a.t_s += start;
      seg.alarms.push_back(std::move(a));
    }
  }, progress);
  return out;
}

double false_alarms_per_hour(const ExperimentConfig& c, double seconds, int& alarms,
                             const std::function<void(double)>& progress, std::vector<double>* times, int jobs) {
  RunSplit split;
  split.jobs = jobs;
  std::vector<double> all;
  for (const auto& seg : free_run_segments(c, seconds, split, progress)) all.insert(all.end(), seg.alarm_times.begin(), seg.alarm_times.end());
  alarms = static_cast<int>(all.size());
  if (times != nullptr) *times = all;
  return static_cast<double>(alarms) * 3600.0 / seconds;
}

}  // namespace jg::eval
