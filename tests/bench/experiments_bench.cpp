// Issue-6 experiments that are not part of the demo, printed as Markdown for docs/results.md:
//  1. validation of the identified LuGre by the reversed trajectory (paper Table 2);
//  2. the observer presets side by side at equal noise (delay, false alarms, sustained push);
//  3. peak contact force of a clamping collision with each reaction.
// Usage: jg_experiments_bench [all|reversed|presets|reactions]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "eval/experiments.hpp"
#include "identification/lugre_batch.hpp"
#include "models/paper_friction.hpp"
#include "tuning/observer_tuning.hpp"

using namespace jg;

namespace {
/// Threshold margin above the calibrated band: the default of `jointguard evaluate`.
constexpr double kMarginNm = 0.5;

void reversed_trajectory_validation(eval::ExperimentConfig c) {
  std::printf("\n### Reversed-trajectory validation (paper Table 2)\n\n");
  const auto prep = eval::prepare(c, kMarginNm);
  const std::size_t n = c.model.joints.size();
  sim::JointVector home = sim::JointVector::Zero(static_cast<Eigen::Index>(n));
  home(1) = 0.6;
  home(2) = -0.8;
  auto fwd = std::make_shared<sim::ExcitationTrajectory>(home, std::vector<bool>(n, true), sim::PaperExcitation(0.6, 0.2, 4, 2.5));
  auto rev = std::make_shared<sim::ReversedTrajectory>(fwd);
  const auto rf = sim::run_simulation(eval::base_setup(c, fwd, 101)).recording;
  const auto rr = sim::run_simulation(eval::base_setup(c, rev, 102)).recording;
  std::printf("| joint | RMS of identified LuGre vs extracted friction [N·m] | the plant's true LuGre vs extracted (floor of the method) [N·m] | paper [N·m] |\n|---|---|---|---|\n");
  const double paper[3] = {0.795, 1.02, 0.697};
  const std::size_t m = rf.samples();
  for (std::size_t j = 0; j < n; ++j) {
    // Friction extracted sample by sample: (tau_fwd(t) - tau_rev(T - t)) / 2, steady part.
    const auto pred = ident::lugre_predict(prep.identification[j].params, rf.dq[j], 1.0 / c.rate_hz);
    // The truth through the same measured velocity: what the extraction itself allows.
    const auto truth = ident::lugre_predict(sim::kPaperTable1[std::min<std::size_t>(j, 2)], rf.dq[j], 1.0 / c.rate_hz);
    double acc = 0.0, acc_truth = 0.0;
    std::size_t count = 0;
    for (std::size_t k = 0; k < m; ++k) {
      const double t = rf.t[k];
      if (t < 3.0 || t > rf.t.back() - 3.0) continue;
      const std::size_t kr = m - 1 - k;
      const double extracted = 0.5 * (rf.tau_m[j][k] - rr.tau_m[j][kr]);
      acc += (extracted - pred[k]) * (extracted - pred[k]);
      acc_truth += (extracted - truth[k]) * (extracted - truth[k]);
      ++count;
    }
    std::printf("| %zu | %.3f | %.3f | %.3f |\n", j + 1, std::sqrt(acc / static_cast<double>(count)),
                std::sqrt(acc_truth / static_cast<double>(count)), j < 3 ? paper[j] : 0.0);
  }
  std::printf("\nCommand: `./build/host/tests/bench/jg_experiments_bench reversed`. Both runs at 1 kHz with the sensors' noise and\n"
              "quantisation; the extracted friction also holds the two runs' independent noise and tracking differences.\n");
}

void presets_side_by_side(const eval::ExperimentConfig& base) {
  std::printf("\n### Observer presets at equal noise (1 kHz, float)\n\n");
  // Reference noise: first order, K = 150 for white motor-torque noise (0.12 N·m = 0.01 A x 12 N·m/A).
  const double torque_noise = 0.12;
  const double target = tuning::analyse({ObserverKind::first_order, 150.0, 0, 0}, 0.001).noise_gain * torque_noise;
  const ObserverGains shapes[] = {{ObserverKind::first_order, 150.0, 0, 0},
                                  {ObserverKind::lowpass2, 150.0, 300.0, 0},
                                  {ObserverKind::paper_bandpass, 150.0, 2.0, 0},
                                  {ObserverKind::paper_improved, 150.0, 300.0, 150.0}};
  std::printf("| preset | gains [1/s] | delay to 50 %% (open loop) | paper collisions: delays [ms] | false alarms (300 s) | sustained 0.6 s push: estimate at its end / true |\n|---|---|---|---|---|---|\n");
  for (const auto& shape : shapes) {
    const ObserverGains g = tuning::gains_for_noise(shape, 0.001, torque_noise, target);
    eval::ExperimentConfig c = base;
    c.gains = g;
    eval::prepare(c, kMarginNm);
    const auto runs = eval::paper_experiments(c, true);
    std::string delays;
    for (const auto& r : runs) delays += r.t_detected ? std::to_string(static_cast<int>(std::lround(1e3 * (*r.t_detected - r.t_collision)))) + " " : "missed ";
    // Sustained push: ratio of the estimate to the true torque just before the push ends.
    eval::ExperimentConfig hold = c;
    hold.reaction = Reaction::none;
    const auto traced = eval::paper_experiments(hold, true);
    const auto& r = traced[1];
    const std::size_t j = 1;
    double est = 0.0, truth = 0.0;
    for (std::size_t k = 0; k < r.trace.t.size(); ++k) {
      if (std::fabs(r.trace.t[k] - (r.t_collision + 0.55)) < 0.0005) {
        est = r.trace.mu[j][k];
        truth = r.trace.tau_ext[j][k];
      }
    }
    int alarms = 0;
    eval::false_alarms_per_hour(c, 300.0, alarms);
    std::printf("| %s | %.0f, %.0f, %.0f | %.1f ms | %s| %d | %.2f |\n", to_string(g.kind), g.k1, g.k2, g.k3,
                1e3 * tuning::analyse(g, 0.001).delay50_s, delays.c_str(), alarms, truth != 0.0 ? est / truth : 0.0);
  }
}

void reactions(eval::ExperimentConfig c) {
  std::printf("\n### Peak contact force of a clamping collision (shoulder, 1 kHz) by reaction\n\n");
  eval::prepare(c, kMarginNm);
  std::printf("| reaction | detected after [ms] | peak contact force [N] |\n|---|---|---|\n");
  for (const Reaction r : {Reaction::none, Reaction::stop, Reaction::zero_gravity}) {
    c.reaction = r;
    const auto home = [&] {
      sim::JointVector h = sim::JointVector::Zero(3);
      h << 0.0, 0.6, -0.8;
      return h;
    }();
    sim::JointVector work = home;
    work << 0.9, 1.05, -1.3;
    auto setup = eval::base_setup(c, std::shared_ptr<const sim::Trajectory>(sim::make_pick_task(home, work, 1)), 5);
    sim::CollisionEvent e;
    e.t_start = 1.0;  // the arm moves down towards the workpiece: an obstacle appears under link 3
    e.link = 3;
    e.point_in_link = {0.25, 0.0, 0.0};
    // The obstacle faces the point's motion: it pushes back against the velocity.
    const sim::ArmDynamics arm(setup.plant.links);
    const auto ref = setup.trajectory->at(e.t_start);
    const Eigen::Vector3d v = arm.point_jacobian(ref.q, 2, e.point_in_link) * ref.dq;
    e.direction_base = -v.normalized();
    e.profile = sim::CollisionProfile::clamp;
    e.peak_force_n = 400.0;
    e.duration_s = 2.0;
    setup.collisions = {e};
    setup.duration_s = 3.5;
    auto est = eval::estimator_for(c);
    const auto run = eval::run_detection(setup, *est, eval::detection_for(c), "clamp", false);
    const char* names[] = {"none", "stop", "zero_gravity", "retreat"};
    std::printf("| %s | %s | %.0f |\n", names[static_cast<int>(r)],
                run.t_detected ? std::to_string(static_cast<int>(std::lround(1e3 * (*run.t_detected - run.t_collision)))).c_str() : "-",
                run.peak_force_n);
  }
  std::printf("\nClamp: a stiff obstacle (25 kN/m, capped at 400 N) appears under the forearm while the arm moves down.\n");
}
// Traces around the paper's collisions: velocity, band, estimate and true torque of the
// collided joint (used to find what sets the delay).
void paper_traces(eval::ExperimentConfig c, double margin) {
  eval::prepare(c, margin);
  c.reaction = Reaction::none;
  const auto runs = eval::paper_experiments(c, true);
  for (const auto& r : runs) {
    const std::size_t j = static_cast<std::size_t>(r.link_true - 1);
    std::printf("\n%s: threshold %.3f + %.3f near standstill; detected %s\n", r.name.c_str(), c.thresholds[j], c.low_speed_extra[j],
                r.t_detected ? std::to_string(1e3 * (*r.t_detected - r.t_collision)).c_str() : "missed");
    std::printf("t_ms  mu  tau_ext  dq  band\n");
    const auto& rec = r.recording;
    for (std::size_t k = 0; k < r.trace.t.size(); ++k) {
      const double dtms = 1e3 * (r.trace.t[k] - r.t_collision);
      if (dtms < -300 || dtms > 40) continue;
      if (dtms < -5 && std::lround(dtms) % 20 != 0) continue;
      std::size_t kr = std::min(rec.samples() - 1, k * rec.samples() / r.trace.t.size());
      while (kr + 1 < rec.samples() && rec.t[kr] < r.trace.t[k] - 1e-9) ++kr;
      while (kr > 0 && rec.t[kr] > r.trace.t[k] + 1e-9) --kr;
      const double w = rec.dq[j][kr] * 1.0 / c.low_speed_width;
      std::printf("%6.1f %7.3f %7.3f %7.4f %6.3f\n", dtms, r.trace.mu[j][k], r.trace.tau_ext[j][k], rec.dq[j][kr],
                  c.thresholds[j] + c.low_speed_extra[j] * std::exp(-w * w));
    }
  }
}
// The calibrated band per joint: thresholds and the standstill allowance.
void calibration_dump(eval::ExperimentConfig c, double margin) {
  const auto prep = eval::prepare(c, margin);
  std::printf("low-speed width %.4f rad/s\n", c.low_speed_width);
  for (std::size_t j = 0; j < c.thresholds.size(); ++j) {
    const auto& p = prep.identification[j].params;
    std::printf("joint %zu: sigma0 %.0f sigma1 %.1f sigma2 %.3f tau_c %.3f tau_s %.3f w_s %.4f threshold %.3f extra %.3f band %.3f uncomp %.3f\n",
                j + 1, p.sigma0, p.sigma1, p.sigma2, p.tau_c, p.tau_s, p.w_s, c.thresholds[j], c.low_speed_extra[j],
                prep.thresholds.band[j], prep.thresholds.band_uncompensated[j]);
  }
}
// Identification from the observer's output (excitation run of prepare) against the truth.
void identification_errors(eval::ExperimentConfig c) {
  const auto prep = eval::prepare(c, kMarginNm);
  double worst = 0.0;
  for (std::size_t j = 0; j < prep.identification.size(); ++j) {
    const auto& p = prep.identification[j].params;
    const auto& t = sim::kPaperTable1[std::min<std::size_t>(j, 2)];
    const double e[4] = {p.tau_c / t.tau_c - 1, p.tau_s / t.tau_s - 1, p.sigma2 / t.sigma2 - 1, p.w_s / t.w_s - 1};
    std::printf("seed %llu rate %.0f joint %zu: tau_c %+.1f %% tau_s %+.1f %% sigma2 %+.1f %% w_s %+.1f %% (sigma0 %+.0f %%) rms %.3f ga_rms %.3f\n",
                c.seed, c.rate_hz, j + 1, 100 * e[0], 100 * e[1], 100 * e[2], 100 * e[3], 100 * (p.sigma0 / t.sigma0 - 1),
                prep.identification[j].rms, prep.identification[j].ga_rms);
    std::printf("| %zu | %.3f (%.3f) %+.1f %% | %.3f (%.3f) %+.1f %% | %.3f (%.3f) %+.1f %% | %.4f (%.4f) %+.1f %% |\n", j + 1, p.tau_c,
                t.tau_c, 100 * e[0], p.tau_s, t.tau_s, 100 * e[1], p.sigma2, t.sigma2, 100 * e[2], p.w_s, t.w_s, 100 * e[3]);
    for (const double x : e) worst = std::max(worst, std::fabs(x));
  }
  std::printf("seed %llu: worst %.1f %%\n", c.seed, 100 * worst);
}
// The collision-free run of false_alarms_per_hour (same seeds) with every sample over the
// band printed: joint, velocity, estimate, band.
void alarm_study(eval::ExperimentConfig c, double margin, double seconds) {
  eval::prepare(c, margin);
  std::printf("thresholds");
  for (std::size_t j = 0; j < c.thresholds.size(); ++j) std::printf(" %.3f(+%.3f)", c.thresholds[j], c.low_speed_extra[j]);
  std::printf(" width %.4f\n", c.low_speed_width);
  sim::JointVector home = sim::JointVector::Zero(3);
  home << 0.0, 0.6, -0.8;
  sim::JointVector lower = home.array() - 0.7, upper = home.array() + 0.7;
  auto moves = sim::make_random_moves(home, lower, upper, 0.8, seconds + 5.0, c.seed * 31 + 7);
  sim::SimulationSetup setup = eval::base_setup(c, std::shared_ptr<const sim::Trajectory>(std::move(moves)), c.seed * 37 + 11);
  setup.duration_s = seconds;
  setup.record = false;
  auto est = eval::estimator_for(c);
  bool started = false;
  sim::JointVector mu;
  double last = -1.0;
  const sim::ControlOverride hook = [&](const sim::CycleContext& ctx) -> std::optional<sim::JointVector> {
    const sim::Measurement& m = *ctx.measurement;
    const eval::EstimatorInput in{m.q, m.dq, m.tau_m};
    if (!started) {
      est->reset(in);
      started = true;
    }
    est->step(in, mu);
    for (Eigen::Index j = 0; j < mu.size(); ++j) {
      const double u = m.dq(j) / c.low_speed_width;
      const double band = c.thresholds[static_cast<std::size_t>(j)] + c.low_speed_extra[static_cast<std::size_t>(j)] * std::exp(-u * u);
      if (std::fabs(mu(j)) > band && ctx.t > 0.5) {
        if (ctx.t - last > 0.05) std::printf("t %.3f joint %ld dq %.5f mu %.3f band %.3f ref dq %.4f\n", ctx.t, j + 1, m.dq(j), mu(j), band, ctx.reference->dq(j));
        last = ctx.t;
      }
    }
    return std::nullopt;
  };
  (void)sim::run_simulation(setup, hook);
}
// One collision of eval::campaign (same draws and seeds) with its trace: per joint the
// velocity, the estimate, the band and the true external torque.
void campaign_trace(eval::ExperimentConfig c, int index) {
  eval::prepare(c, 0.5);
  c.reaction = Reaction::none;
  std::mt19937_64 rng(c.seed * 7919 + 5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  sim::JointVector home = sim::JointVector::Zero(3);
  home << 0.0, 0.6, -0.8;
  sim::JointVector lower = home.array() - 0.7, upper = home.array() + 0.7;
  sim::CampaignSpec spec;
  spec.links = {2, 3};
  spec.count = index + 1;
  spec.seed = c.seed;
  spec.t_min = 2.5;
  spec.t_max = 1e9;
  spec.spacing_s = 3.0;
  const auto events = sim::draw_campaign(spec, c.model.reaches());
  double t0 = 0.0;
  for (int i = 0; i <= index; ++i) t0 = 2.5 + 0.5 * unit(rng);
  sim::CollisionEvent e = events[static_cast<std::size_t>(index)];
  e.t_start = t0;
  auto moves = sim::make_random_moves(home, lower, upper, 0.8, 8.0, c.seed * 1000 + static_cast<unsigned long long>(index));
  sim::SimulationSetup setup = eval::base_setup(c, std::shared_ptr<const sim::Trajectory>(std::move(moves)), c.seed * 2000 + static_cast<unsigned long long>(index));
  setup.collisions = {e};
  setup.duration_s = e.t_start + std::max(1.0, e.duration_s + e.rise_s + 0.5);
  auto est = eval::estimator_for(c);
  const auto r = eval::run_detection(setup, *est, eval::detection_for(c), "trace", true);
  std::printf("%s link %d peak %.0f N, detected %s\n", sim::to_string(e.profile), e.link, r.peak_force_n,
              r.t_detected ? std::to_string(*r.t_detected - r.t_collision).c_str() : "no");
  for (std::size_t k = 0; k < r.trace.t.size(); ++k) {
    const double dt = r.trace.t[k] - r.t_collision;
    if (dt < -0.01 || dt > 0.15 || (dt > 0.03 && k % 5 != 0)) continue;
    std::printf("%6.1f", 1e3 * dt);
    for (std::size_t j = 0; j < 3; ++j) {
      const double u = r.recording.dq[j][k] / c.low_speed_width;
      std::printf(" | %7.4f %6.2f %6.2f %6.2f", r.recording.dq[j][k], r.trace.mu[j][k],
                  c.thresholds[j] + c.low_speed_extra[j] * std::exp(-u * u), r.trace.tau_ext[j][k]);
    }
    std::printf("\n");
  }
}
}  // namespace

int main(int argc, char** argv) {
  eval::ExperimentConfig c;
  c.model = robot::load_robot(JG_SOURCE_DIR "/models/ref3.yaml");
  const std::string only = argc > 1 ? argv[1] : "all";
  if (only == "all" || only == "reversed") reversed_trajectory_validation(c);
  if (only == "all" || only == "presets") presets_side_by_side(c);
  if (only == "all" || only == "reactions") reactions(c);
  if (only == "dump") {
    c.rate_hz = std::atof(argv[2]);
    c.gains.k1 = std::atof(argv[3]);
    c.scalar = argv[4];
    c.calibration_s = std::atof(argv[5]);
    calibration_dump(c, std::atof(argv[6]));
  }
  if (only == "ident") {
    c.seed = std::strtoull(argv[2], nullptr, 10);
    if (argc > 3) c.rate_hz = std::atof(argv[3]);
    c.gains = tuning::default_gains(c.rate_hz);
    c.calibration_s = 20.0;
    identification_errors(c);
  }
  if (only == "alarms") {
    c.rate_hz = std::atof(argv[2]);
    c.gains = tuning::default_gains(c.rate_hz);
    c.scalar = argv[3];
    c.calibration_s = std::atof(argv[4]);
    c.seed = std::strtoull(argv[6], nullptr, 10);
    alarm_study(c, std::atof(argv[5]), std::atof(argv[7]));
  }
  if (only == "campaign-trace") {
    campaign_trace(c, std::atoi(argv[2]));
  }
  if (only == "traces") {
    if (argc > 2) c.rate_hz = std::atof(argv[2]);
    if (argc > 3) c.gains.k1 = std::atof(argv[3]);
    paper_traces(c, argc > 4 ? std::atof(argv[4]) : 1.0);
  }
  return 0;
}
