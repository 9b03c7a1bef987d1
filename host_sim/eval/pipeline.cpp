#include "eval/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <utility>

#include "io/atomic_write.hpp"
#include "eval/firmware_estimator.hpp"
#include "eval/calibration_region.hpp"
#include "eval/evaluate.hpp"
#include "eval/replay_contact.hpp"
#include "jointguard/detection/detector.hpp"
#include "jointguard/detection/hold_detector.hpp"
#include "robot/torque_kind.hpp"

namespace jg::eval {
namespace {
double sample_time(const io::Recording& r) {
  if (r.samples() < 3) throw std::invalid_argument("recording too short (fewer than 3 samples)");
  return (r.t.back() - r.t.front()) / static_cast<double>(r.samples() - 1);
}

}  // namespace

double sample_rate(const io::Recording& rec) { return 1.0 / sample_time(rec); }

using io::write_json_atomic;

void write_friction_json(const std::string& path, const std::vector<ident::IdentificationResult>& r,
                         const std::vector<int>& joint_ids, const nlohmann::json& extra) {
  nlohmann::json j = extra.is_object() ? extra : nlohmann::json::object();
  j["joints"] = nlohmann::json::array();
  for (std::size_t i = 0; i < r.size(); ++i) {
    const auto& p = r[i].params;
    nlohmann::json e{{"joint", joint_ids[i]}, {"sigma0", p.sigma0}, {"sigma1", p.sigma1}, {"sigma2", p.sigma2},
                     {"tau_c", p.tau_c},      {"tau_s", p.tau_s},   {"w_s", p.w_s},       {"rms", r[i].rms},
                     {"noise_rms", r[i].noise_rms}};
    nlohmann::json rep = nlohmann::json::object();
    for (std::size_t k = 0; k < 6; ++k) {
      const auto& pr = r[i].report[k];
      rep[ident::kParamNames[k]] = {{"ga_mean", pr.ga_mean}, {"ga_std", pr.ga_std}, {"sensitivity", pr.sensitivity},
                                    {"relative_std_error", pr.relative_std_error}, {"identifiable", pr.identifiable}};
    }
    e["report"] = rep;
    e["warnings"] = r[i].warnings;
    // What identify bounded so that the firmware runs the file, and why (nothing is hidden).
    e["bounded"] = nlohmann::json::array();
    for (const auto& b : r[i].bounded) {
      e["bounded"].push_back({{"parameter", b.parameter}, {"fitted", b.fitted}, {"written", b.written}, {"reason", b.reason}});
    }
    if (r[i].firmware_dt > 0.0) e["rms_unbounded"] = r[i].rms_unbounded;
    j["joints"].push_back(e);
  }
  write_json_atomic(path, j);
}

void write_threshold_json(const std::string& path, const Thresholds& t, const std::vector<int>& joint_ids,
                          const nlohmann::json& extra) {
  nlohmann::json j = extra.is_object() ? extra : nlohmann::json::object();
  j["margin"] = t.margin;
  j["joints"] = nlohmann::json::array();
  for (std::size_t i = 0; i < t.threshold.size(); ++i) {
    j["joints"].push_back({{"joint", joint_ids[i]}, {"threshold", t.threshold[i]},
                           {"low_speed_extra", t.low_speed_extra.empty() ? 0.0 : t.low_speed_extra[i]},
                           {"low_speed_width", t.low_speed_width},
                           {"threshold_uncompensated", t.threshold_uncompensated[i]}, {"band", t.band[i]},
                           {"band_uncompensated", t.band_uncompensated[i]},
                           {"shrink_factor", t.band[i] > 0 ? t.band_uncompensated[i] / t.band[i] : 0.0}});
    if (i < t.hold_change.size()) {
      auto& e = j["joints"].back();
      e["hold_change_threshold"] = t.hold_change[i];
      if (i < t.hold_band.size()) e["hold_band"] = t.hold_band[i];
      if (i < t.hold_seconds.size()) e["hold_seconds"] = t.hold_seconds[i];
      if (i < t.hold_source.size()) e["hold_change_source"] = t.hold_source[i];
    }
  }
  if (t.q_min.size() == t.threshold.size() && t.stop_gain.size() == t.threshold.size()) {
    for (std::size_t i = 0; i < t.threshold.size(); ++i) {
      j["joints"][i]["region"] = {{"q_min", t.q_min[i]}, {"q_max", t.q_max[i]}, {"dq_max", t.dq_max[i]}, {"ddq_max", t.ddq_max[i]}};
      j["joints"][i]["stop_gain"] = t.stop_gain[i];
    }
  }
  if (!t.hold_change.empty()) {
    j["hold_settle_s"] = t.hold_settle_s;
    j["hold_reference_s"] = t.hold_reference_s;
  }
  write_json_atomic(path, j);
}

std::vector<std::vector<double>> motor_torque(const io::Recording& rec, const robot::RobotModel& model) {
  if (rec.joints() != model.joints.size()) {
    throw std::invalid_argument("the recording has " + std::to_string(rec.joints()) + " joints, the model " +
                                std::to_string(model.joints.size()));
  }
  if (rec.torque_kind != io::TorqueKind::current) {
    const auto& tau = io::torque_columns(rec);
    if (tau.size() == rec.joints()) return tau;
  }
  // A recording built in code may fill columns without setting torque_kind.
  if (rec.current.size() != rec.joints()) {
    if (rec.tau_m.size() == rec.joints()) return rec.tau_m;
    throw std::invalid_argument(std::string("the recording has no ") + io::to_string(rec.torque_kind) + " columns");
  }
  std::vector<std::vector<double>> out = rec.current;
  for (std::size_t j = 0; j < out.size(); ++j) {
    for (auto& v : out[j]) v *= model.joints[j].link.torque_constant;
  }
  return out;
}

std::vector<std::vector<double>> observer_disturbance(const io::Recording& rec, const robot::RobotModel& model,
                                                     const ObserverGains& gains, bool compensate,
                                                     const std::vector<LuGreParams<double>>& friction,
                                                     const std::string& scalar, const std::vector<bool>& held,
                                                     double held_deadband_steps) {
  const auto tau = motor_torque(rec, model);
  FirmwareEstimatorConfig c;
  c.model = robot::for_torque_kind(model, rec.torque_kind);
  c.dt = sample_time(rec);
  c.observer = gains;
  c.compensate_friction = compensate;
  c.friction = friction;
  if (!held.empty() && held_deadband_steps > 0.0) {
    for (std::size_t j = 0; j < rec.joints(); ++j) {
      double step = 1e300;  // the smallest nonzero |dq|: one count per sample
      for (const double w : rec.dq[j]) {
        if (std::fabs(w) > 1e-12) step = std::min(step, std::fabs(w));
      }
      c.holding_velocity_deadband.push_back(step < 1e300 ? held_deadband_steps * step : 0.0);
    }
  }
  auto est = make_firmware_estimator(c, scalar);
  const std::size_t n = rec.joints();
  std::vector<std::vector<double>> out(n, std::vector<double>(rec.samples()));
  sim::JointVector mu;
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    EstimatorInput in{sim::JointVector(static_cast<Eigen::Index>(n)), sim::JointVector(static_cast<Eigen::Index>(n)),
                      sim::JointVector(static_cast<Eigen::Index>(n))};
    for (std::size_t j = 0; j < n; ++j) {
      in.q(static_cast<Eigen::Index>(j)) = rec.q[j][k];
      in.dq(static_cast<Eigen::Index>(j)) = rec.dq[j][k];
      in.tau_m(static_cast<Eigen::Index>(j)) = tau[j][k];
    }
    if (k < held.size() && held[k]) in.holding = static_cast<JointMask>((1U << n) - 1U);
    if (k == 0) est->reset(in);
    est->step(in, mu);
    // The observer estimates d - f = tau_f - tau_ext - f: report it as a disturbance.
    for (std::size_t j = 0; j < n; ++j) out[j][k] = -mu(static_cast<Eigen::Index>(j));
  }
  return out;
}

std::vector<ident::IdentificationResult> identify_recording(const io::Recording& rec, const robot::RobotModel& model,
                                                            const ObserverGains& gains, const ident::GaSettings& ga,
                                                            const std::function<void(double)>& progress) {
  if (gains.kind != ObserverKind::first_order) throw std::invalid_argument("identification uses the first-order observer");
  const auto d = observer_disturbance(rec, model, gains, false, {});
  const double dt = sample_time(rec);
  // Decimate to at most ~6000 samples (the paper used 1251 at 125 Hz): the bristle
  // dynamics need a few ms of resolution around reversals.
  const std::size_t step = std::max<std::size_t>(1, rec.samples() / 6000);
  std::vector<ident::IdentificationResult> out;
  for (std::size_t j = 0; j < rec.joints(); ++j) {
    ident::FrictionSeries s, full;
    s.dt = dt * static_cast<double>(step);
    for (std::size_t k = 0; k < rec.samples(); k += step) {
      s.velocity.push_back(rec.dq[j][k]);
      s.friction.push_back(d[j][k]);
    }
    s.skip = std::min<std::size_t>(s.velocity.size() / 10, static_cast<std::size_t>(0.5 / s.dt));
    s.observer_gain = gains.k1;
    // The GA searches the decimated series; LM refines on every sample (decimation shifts
    // the observer's filter and the bristle dynamics near reversals by up to a step).
    full.dt = dt;
    full.velocity = rec.dq[j];
    full.friction = d[j];
    full.skip = std::min<std::size_t>(full.velocity.size() / 10, static_cast<std::size_t>(0.5 / full.dt));
    full.observer_gain = gains.k1;
    try {
      out.push_back(ident::identify_lugre(s, ga, {}, [&](double f) {
        if (progress) progress((static_cast<double>(j) + f) / static_cast<double>(rec.joints()));
      }, step > 1 ? &full : nullptr));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("joint " + std::to_string(rec.joint_ids[j]) + ": " + e.what());
    }
  }
  return out;
}

BandStatistics::BandStatistics(std::size_t joints)
    : max_(joints, std::vector<double>(kBins, 0.0)), uncompensated_(joints, 0.0) {}

void BandStatistics::add(std::size_t joint, double velocity, double mu, double mu_uncompensated) {
  const double w = std::fabs(velocity);
  const auto bin = w >= kBin * static_cast<double>(kBins) ? kBins - 1 : static_cast<std::size_t>(w / kBin);
  max_[joint][bin] = std::max(max_[joint][bin], std::fabs(mu));
  uncompensated_[joint] = std::max(uncompensated_[joint], std::fabs(mu_uncompensated));
}

void BandStatistics::merge(const BandStatistics& other) {
  if (other.max_.size() != max_.size()) throw std::invalid_argument("BandStatistics::merge: different joint counts");
  for (std::size_t j = 0; j < max_.size(); ++j) {
    for (std::size_t b = 0; b < kBins; ++b) max_[j][b] = std::max(max_[j][b], other.max_[j][b]);
    uncompensated_[j] = std::max(uncompensated_[j], other.uncompensated_[j]);
  }
}

double BandStatistics::max_in(std::size_t joint, double w_lo, double w_hi) const {
  double m = 0.0;
  for (std::size_t b = 0; b < kBins; ++b) {
    const double lo = kBin * static_cast<double>(b);
    if (lo >= w_lo && lo < w_hi) m = std::max(m, max_[joint][b]);
  }
  return m;
}

Thresholds BandStatistics::fit(double margin) const {
  Thresholds t;
  t.margin = margin;
  const std::size_t n = max_.size();
  const auto first_moving = static_cast<std::size_t>(std::lround(kMovingSpeed / kBin));
  std::vector<double> moving(n, 0.0), all(n, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t b = 0; b < kBins; ++b) {
      all[j] = std::max(all[j], max_[j][b]);
      if (b >= first_moving) moving[j] = std::max(moving[j], max_[j][b]);
    }
  }
  // Height needed per joint for a width: every slower bin, taken at its upper edge (the
  // Gaussian falls with speed, so the bin's fastest sample needs the most).
  // One encoder count per sample is the smallest speed measured: up to it the joint may
  // be dithering at rest, so those bins get the largest standstill excess of any of them.
  std::size_t first_count = 1;
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t b = 1; b < first_moving; ++b) {
      if (max_[j][b] > 0.0) {
        first_count = std::max(first_count, b);
        break;
      }
    }
  }
  std::vector<double> rest(n, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t b = 0; b <= first_count && b < first_moving; ++b) rest[j] = std::max(rest[j], max_[j][b]);
  }
  auto heights = [&](double width, std::vector<double>& extra) {
    double area = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      extra[j] = 0.0;
      for (std::size_t b = 0; b < first_moving; ++b) {
        const double seen = b <= first_count ? rest[j] : max_[j][b];
        const double excess = kStandstillFactor * (seen - moving[j]);
        if (excess <= 0.0) continue;
        const double u = kBin * static_cast<double>(b + 1) / width;
        extra[j] = std::max(extra[j], excess * std::exp(std::min(u * u, 50.0)));
      }
      area += extra[j] * width;
    }
    return area;
  };
  std::vector<double> extra(n), best_extra(n);
  double best_area = 1e300, best_width = t.low_speed_width;
  for (int i = 0; i <= 200; ++i) {
    const double width = 0.002 * std::pow(50.0, static_cast<double>(i) / 200.0);  // 2 mrad/s .. 0.1 rad/s
    const double area = heights(width, extra);
    if (area < best_area - 1e-12) {
      best_area = area;
      best_width = width;
      best_extra = extra;
    }
  }
  t.low_speed_width = best_width;
  for (std::size_t j = 0; j < n; ++j) {
    t.band.push_back(all[j]);
    t.band_uncompensated.push_back(uncompensated_[j]);
    t.threshold.push_back(moving[j] + margin);
    t.low_speed_extra.push_back(best_extra[j]);
    t.threshold_uncompensated.push_back(uncompensated_[j] + margin);
  }
  return t;
}

Thresholds calibrate_recording(const io::Recording& rec, const robot::RobotModel& model,
                               const std::vector<LuGreParams<double>>& friction, const ObserverGains& gains,
                               double margin, double settle_s, const std::string& scalar) {
  return calibrate_segments({rec}, model, friction, gains, margin, settle_s, scalar);
}

Thresholds calibrate_segments(const std::vector<io::Recording>& segments, const robot::RobotModel& model,
                              const std::vector<LuGreParams<double>>& friction, const ObserverGains& gains,
                              double margin, double settle_s, const std::string& scalar) {
  if (segments.empty()) throw std::invalid_argument("calibration: no recording to calibrate on");
  if (friction.size() != segments.front().joints()) {
    throw std::invalid_argument("calibration: " + std::to_string(friction.size()) + " friction parameter sets for " +
                                std::to_string(segments.front().joints()) + " joints");
  }
  for (const auto& rec : segments) {
    for (const int c : rec.collision) {
      if (c != 0) throw std::invalid_argument("calibration needs a collision-free recording (its collision column is not all 0)");
    }
  }
  BandStatistics stats(segments.front().joints());
  std::size_t used = 0;
  double longest = 0.0;
  for (const auto& rec : segments) {
    longest = std::max(longest, rec.t.back() - rec.t.front());
    if (rec.t.back() - rec.t.front() < settle_s) continue;  // nothing after the observer settles
    const auto with = observer_disturbance(rec, model, gains, true, friction, scalar);
    const auto without = observer_disturbance(rec, model, gains, false, friction, scalar);
    for (std::size_t j = 0; j < rec.joints(); ++j) {
      for (std::size_t k = 0; k < rec.samples(); ++k) {
        if (rec.t[k] - rec.t.front() < settle_s) continue;
        stats.add(j, rec.dq[j][k], with[j][k], without[j][k]);
        used += j == 0 ? 1 : 0;
      }
    }
  }
  if (used == 0) {
    throw std::invalid_argument("calibration: no sample after the observer's " + std::to_string(settle_s) +
                                " s settling time (the longest continuous part lasts " + std::to_string(longest) +
                                " s); record a longer collision-free motion");
  }
  return stats.fit(margin);
}

std::vector<JointThreshold<double>> threshold_bands(const Thresholds& t) {
  std::vector<JointThreshold<double>> out;
  for (std::size_t j = 0; j < t.threshold.size(); ++j) {
    out.push_back({t.threshold[j], 0.0, j < t.low_speed_extra.size() ? t.low_speed_extra[j] : 0.0,
                   1.0 / t.low_speed_width});
  }
  return out;
}

std::vector<bool> holding_flags(const io::Recording& rec, const ReplayOptions& o) {
  const std::size_t n = rec.joints(), samples = rec.samples();
  std::vector<bool> out(samples, o.holding == HoldingSource::always);
  if (o.holding != HoldingSource::still || samples == 0) return out;
  const double dt = samples > 1 ? (rec.t.back() - rec.t.front()) / static_cast<double>(samples - 1) : 1.0;
  const auto arrive = static_cast<std::size_t>(std::ceil(o.arrive_s / dt - 1e-9));
  std::size_t at_rest = 0;
  bool holding = false;
  std::vector<double> rest(n, 0.0);
  // Per joint, the smallest position step of the recording (its resolution).
  std::vector<double> resolution(n, 1e300);
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t k = 1; k < samples; ++k) {
      const double step = std::fabs(rec.q[j][k] - rec.q[j][k - 1]);
      if (step > 1e-12) resolution[j] = std::min(resolution[j], step);
    }
    if (resolution[j] > 1.0) resolution[j] = 0.0;  // never moves
  }
  for (std::size_t k = 0; k < samples; ++k) {
    bool still = true;
    for (std::size_t j = 0; j < n && still; ++j) {
      if (std::fabs(rec.dq[j][k]) <= o.still_speed) continue;
      // Or its position within still_span over the last `arrive` samples.
      if (k < arrive) {
        still = false;
        continue;
      }
      double lo = rec.q[j][k], hi = lo;
      for (std::size_t i = k - arrive; i < k; ++i) {
        lo = std::min(lo, rec.q[j][i]);
        hi = std::max(hi, rec.q[j][i]);
      }
      still = hi - lo <= o.still_span;
    }
    at_rest = still ? at_rest + 1 : 0;
    if (holding) {
      // A held joint yields a little under a push and comes back: the drive still holds.
      for (std::size_t j = 0; j < n; ++j) holding = holding && std::fabs(rec.q[j][k] - rest[j]) <= o.hold_radius;
      if (!holding) {
        at_rest = 0;  // moved away: it holds again only after arriving anew
        // The drive stopped holding when it started this move, not when the arm left the
        // radius: the samples before, back to the last one every joint was slower than the
        // deadband, were moving (a recording carries no command; replay looks back for it).
        // A smooth move creeps off for a while (a quintic's first 13 % of its time moves it
        // one count in 400) with the drive's torque already rising: back to the last sample
        // at which every joint had moved by at most two position steps of the recording
        // (its resolution) over the arrive_s before, and arrive_s before that.
        std::size_t i = k;
        while (i > arrive && out[i - 1]) {
          bool off = false;
          for (std::size_t j = 0; j < n; ++j) off = off || std::fabs(rec.q[j][i - 1] - rec.q[j][i - 1 - arrive]) > 2.0 * resolution[j];
          if (!off) break;
          out[--i] = false;
        }
        for (std::size_t m = 0; m < arrive && i > 0 && out[i - 1]; ++m) out[--i] = false;
      }
    }
    if (!holding && at_rest > arrive) {
      holding = true;
      for (std::size_t j = 0; j < n; ++j) rest[j] = rec.q[j][k];
    }
    out[k] = holding;
  }
  return out;
}

std::optional<HoldViolation> first_move(const io::Recording& rec, const ReplayOptions& o) {
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    for (std::size_t j = 0; j < rec.joints(); ++j) {
      const double distance = std::fabs(rec.q[j][k] - rec.q[j].front());
      if (distance > o.hold_radius) return HoldViolation{rec.t[k], j, distance, std::fabs(rec.dq[j][k])};
    }
  }
  return std::nullopt;
}

ReplayResult replay_recording(const io::Recording& rec, const robot::RobotModel& model,
                              const std::vector<LuGreParams<double>>& friction, const Thresholds& thresholds_in,
                              const ObserverGains& gains, const std::string& scalar, int debounce_cycles,
                              const ReplayOptions& opt) {
  const std::size_t n = rec.joints();
  const auto bands = threshold_bands(thresholds_in);
  const std::vector<double>& thresholds = thresholds_in.threshold;
  if (thresholds.size() != n) throw std::invalid_argument("one threshold per joint needed");
  if (friction.size() != n) throw std::invalid_argument("one friction parameter set per joint needed");
  const bool use_hold = opt.holding != HoldingSource::none;
  if (use_hold && thresholds_in.hold_change.size() != n) {
    throw std::invalid_argument("holding-aware replay needs the threshold file's hold_change_threshold "
                                "(calibrate again: it writes one by default)");
  }
  const auto held = holding_flags(rec, opt);
  const auto d = observer_disturbance(rec, model, gains, true, friction, scalar, held, opt.held_deadband_steps);
  const double dt = sample_time(rec);
  std::vector<HoldChangeParams<double>> hold(n);
  std::vector<HoldChangeState<double>> hold_state(n);
  for (std::size_t j = 0; j < n && use_hold; ++j) {
    hold[j] = hold_params(thresholds_in.hold_change[j], thresholds_in.hold_settle_s, thresholds_in.hold_reference_s, dt);
  }
  const bool region = thresholds_in.q_min.size() == n && thresholds_in.ddq_max.size() == n && thresholds_in.stop_gain.size() == n;
  // Stop allowance: when the arm accelerates harder than anything in the calibration
  // (an abrupt stop), each joint's band grows to s times what the model left there,
  // s = the arm's largest |ddq_i| / ddq_max_i (difference of the measured velocity over
  // kAccelBaselineS, calibration_region.hpp): the model's error in a braking transient
  // scales with it, and joints couple (at the UR10e's stops the waist's current spikes
  // while the waist itself decelerates less than in the calibration). The extra decays with kStopDecayS (the drive's braking
  // current and the stiction it takes up last a few samples after the velocity has dropped).
  constexpr double kStopDecayS = 0.1;
  const double stop_decay = std::exp(-dt / kStopDecayS);
  std::vector<double> stop_extra(n, 0.0);
  double gate_until = -1e300;
  const std::size_t accel_m = accel_baseline(dt);
  // Re-arming the holding detector after an event: each joint's estimate steady around
  // its own 0.1 s average for rearm_s.
  const double ema_gain = std::min(1.0, dt / 0.1);
  const auto rearm_cycles = static_cast<std::size_t>(std::ceil(opt.rearm_s / dt - 1e-9));
  std::vector<double> ema(n, 0.0);
  std::vector<std::size_t> steady(n, 0);
  ReplayResult r;
  r.t = rec.t;
  r.external_torque_max.assign(n, 0.0);
  r.outside_q.assign(n, 0);
  r.outside_dq.assign(n, 0);
  r.stop_widened.assign(n, 0);
  r.mu.assign(n, std::vector<double>(rec.samples()));
  std::vector<JointDetectorState> st(n);
  JointMask previous = 0;
  double quiet_since = -1.0;
  ReplayContact contact(model, gains, dt);
  sim::JointVector q_now(static_cast<Eigen::Index>(n)), contact_tau(static_cast<Eigen::Index>(n)),
      contact_threshold(static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    JointMask mask = 0, by_band = 0;
    r.held_samples += held[k] ? 1 : 0;
    double stop_ratio = 0.0;  // s above
    for (std::size_t j = 0; j < n && region && k >= accel_m; ++j) {
      if (thresholds_in.ddq_max[j] > 0.0) {
        stop_ratio = std::max(stop_ratio, accel_at(rec, j, k, accel_m, dt) / thresholds_in.ddq_max[j]);
      }
    }
    if (opt.stop_gate_s > 0.0 && stop_ratio > 1.0) gate_until = rec.t[k] + opt.stop_gate_s;
    const bool gated = rec.t[k] < gate_until;
    r.gated_samples += gated ? 1 : 0;
    for (std::size_t j = 0; j < n; ++j) {
      const double mu = -d[j][k];
      const double w = rec.dq[j][k];
      r.mu[j][k] = mu;
      r.external_torque_max[j] = std::max(r.external_torque_max[j], std::fabs(mu));
      JointThreshold<double> band = bands[j];
      if (region) {
        const double q = rec.q[j][k];
        if (q < thresholds_in.q_min[j] || q > thresholds_in.q_max[j]) ++r.outside_q[j];
        if (std::fabs(w) > thresholds_in.dq_max[j]) ++r.outside_dq[j];
        stop_extra[j] *= stop_decay;
        if (opt.stop_allowance && opt.stop_gate_s <= 0.0 && stop_ratio > 1.0) {
          stop_extra[j] = std::max(stop_extra[j], thresholds_in.stop_gain[j] * thresholds_in.ddq_max[j] * stop_ratio);
        }
        if (stop_extra[j] > 0.01 * band.base) ++r.stop_widened[j];
        // Faster than the calibration: the moving band grows in proportion to the speed
        // ratio (the model's errors grow at least linearly with speed: viscous friction's
        // error with w, the Coriolis terms' with w^2; linear is the cautious lower bound).
        if (opt.stop_allowance && thresholds_in.dq_max[j] > 0.0 && std::fabs(w) > thresholds_in.dq_max[j]) {
          band.base *= std::fabs(w) / thresholds_in.dq_max[j];
        }
        band.base += stop_extra[j];
      }
      if (gated) band.base += 1e12;  // nothing is over while the gate is open
      const bool changed = use_hold && hold_change_step(hold[j], hold_state[j], held[k] && !gated, mu);
      const double band_now = threshold_at(band, w);
      if (band_now < std::fabs(mu)) by_band |= static_cast<JointMask>(1U << j);
      // As in run_detection: a held joint's change since arrival is what the contact adds
      // (its estimate there is mostly the friction it holds).
      const auto i = static_cast<Eigen::Index>(j);
      q_now(i) = rec.q[j][k];
      contact_tau(i) = use_hold && hold_state[j].armed ? mu - hold_state[j].reference : mu;
      contact_threshold(i) = use_hold && hold_state[j].armed ? std::min(band_now, hold[j].change_threshold) : band_now;
      if (detector_step(band, DebounceSettings{static_cast<std::uint8_t>(debounce_cycles)}, st[j], mu, w, changed)) {
        mask |= static_cast<JointMask>(1U << j);
      }
      ema[j] = k == 0 ? mu : ema[j] + ema_gain * (mu - ema[j]);
      const double still_within = use_hold ? std::max(hold[j].change_threshold, 1e-9) : thresholds[j];
      steady[j] = std::fabs(mu - ema[j]) <= still_within ? steady[j] + 1 : 0;
    }
    if (mask != 0 && previous == 0) {
      ReplayEvent e;
      e.t = rec.t[k];
      e.by_hold = by_band == 0;
      JointMask signature = mask;  // as in run_detection: joints above 30 % of their threshold
      for (std::size_t j = 0; j < n; ++j) {
        const bool part = use_hold && hold_state[j].armed
                              ? hold_deviation(hold_state[j], r.mu[j][k]) > 0.6 * hold[j].change_threshold
                              : std::fabs(r.mu[j][k]) > 0.3 * thresholds[j];
        if (part) signature |= static_cast<JointMask>(1U << j);
      }
      const int isolated = isolate_link(signature);
      e.link = rec.joint_ids[static_cast<std::size_t>(isolated - 1)];
      contact.event(r.events.size(), e.t, isolated);
      for (std::size_t j = 0; j < n; ++j) {
        if ((mask & (1U << j)) != 0U) e.joints_over.push_back(rec.joint_ids[j]);
      }
      r.events.push_back(e);
      std::fill(steady.begin(), steady.end(), std::size_t{0});  // re-arm only after steady from here
    }
    const bool held_rearm = use_hold && held[k];
    if (mask != 0 && held_rearm) {
      // Holding-aware: the push has ended when every estimate is steady again, at whatever
      // level the static friction now holds, and no joint is over its band: new reference.
      bool rearm = by_band == 0;
      for (std::size_t j = 0; j < n; ++j) rearm = rearm && steady[j] >= rearm_cycles;
      if (rearm) {
        for (auto& s : st) reset_detector(s);
        for (auto& h : hold_state) h = HoldChangeState<double>{};
        mask = 0;
        ++r.rearms;
      }
    }
    // Re-arm once every joint is back under its threshold for 0.2 s (a new event can follow).
    bool all_quiet = true;
    for (std::size_t j = 0; j < n; ++j) all_quiet = all_quiet && std::fabs(r.mu[j][k]) < thresholds[j];
    if (mask != 0 && all_quiet && !held_rearm) {
      if (quiet_since < 0.0) quiet_since = rec.t[k];
      if (rec.t[k] - quiet_since > 0.2) {
        for (auto& s : st) reset_detector(s);
        for (auto& h : hold_state) h = HoldChangeState<double>{};
        mask = 0;
        quiet_since = -1.0;
      }
    }
    if (mask == 0 && previous != 0) contact.end();  // re-armed: the contact is over
    previous = mask;
    contact.add(rec.t[k], q_now, contact_tau, contact_threshold);
  }
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    if (const auto& o = contact.outcome(i)) {
      r.events[i].contact = o->estimate;
      r.events[i].contact_t = o->t;
      r.events[i].contact_peak_force_n = o->peak_force_n;
      r.events[i].contact_t_peak = o->t_peak;
    }
  }
  return r;
}

ReplayResult replay_segments(const std::vector<io::Recording>& segments, const robot::RobotModel& model,
                             const std::vector<LuGreParams<double>>& friction, const Thresholds& thresholds,
                             const ObserverGains& gains, const std::string& scalar, int debounce_cycles,
                             const ReplayOptions& options) {
  if (segments.empty()) throw std::invalid_argument("replay: no recording to replay");
  ReplayResult all;
  for (const auto& rec : segments) {
    ReplayResult r = replay_recording(rec, model, friction, thresholds, gains, scalar, debounce_cycles, options);
    for (auto [dst, src] : {std::pair{&all.outside_q, &r.outside_q}, {&all.outside_dq, &r.outside_dq}, {&all.stop_widened, &r.stop_widened}}) {
      if (dst->empty()) dst->assign(src->size(), 0);
      for (std::size_t j = 0; j < src->size(); ++j) (*dst)[j] += (*src)[j];
    }
    all.held_samples += r.held_samples;
    all.rearms += r.rearms;
    all.gated_samples += r.gated_samples;
    all.events.insert(all.events.end(), r.events.begin(), r.events.end());
    if (all.external_torque_max.empty()) all.external_torque_max.assign(r.external_torque_max.size(), 0.0);
    for (std::size_t j = 0; j < r.external_torque_max.size(); ++j) {
      all.external_torque_max[j] = std::max(all.external_torque_max[j], r.external_torque_max[j]);
    }
    all.t.insert(all.t.end(), r.t.begin(), r.t.end());
    if (all.mu.empty()) all.mu.resize(r.mu.size());
    for (std::size_t j = 0; j < r.mu.size(); ++j) all.mu[j].insert(all.mu[j].end(), r.mu[j].begin(), r.mu[j].end());
  }
  return all;
}

}  // namespace jg::eval
