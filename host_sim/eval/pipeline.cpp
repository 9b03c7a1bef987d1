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
  // A measured speed may be one count per sample off the true one (a count more or fewer in
  // the sample's window): where friction changes steeply with speed, the stiction
  // transition, a sample measured at k counts may carry what the calibration saw at k - 1.
  // Each slow bin must cover the excess of every bin up to one count below it. (Without
  // this, the Panda and the UR10e each raised a false alarm in hours of motion at two
  // counts per sample, 12.6 mrad/s, with an excess the calibration had seen only at one.)
  const std::size_t count_bins = first_count + 1;
  std::vector<std::vector<double>> seen(n, std::vector<double>(first_moving, 0.0));
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t b = 0; b < first_moving; ++b) {
      for (std::size_t b2 = b >= count_bins ? b - count_bins : 0; b2 <= b; ++b2) {
        seen[j][b] = std::max(seen[j][b], b2 <= first_count ? rest[j] : max_[j][b2]);
      }
    }
  }
  auto heights = [&](double width, std::vector<double>& extra) {
    double area = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      extra[j] = 0.0;
      for (std::size_t b = 0; b < first_moving; ++b) {
        const double excess = kStandstillFactor * (seen[j][b] - moving[j]);
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

namespace {
/// What a replay reads and never changes: the threshold file's bands and holding detector at
/// the recording's sample time, and the stop allowance's and re-arming's constants.
struct ReplayParams {
  const Thresholds& thresholds;
  const ReplayOptions& opt;
  std::vector<JointThreshold<double>> bands;
  std::vector<HoldChangeParams<double>> hold;  ///< per joint, with use_hold
  bool use_hold = false;
  bool region = false;  ///< the file has the calibrated region (stop allowance, outside counts)
  DebounceSettings debounce;
  double dt = 0.0;          ///< sample time [s]
  double stop_decay = 0.0;  ///< per sample
  std::size_t accel_m = 0;  ///< samples of the acceleration baseline
  double ema_gain = 0.0;    ///< per sample, of the estimate's 0.1 s average
  std::size_t rearm_cycles = 0;
};

/// What a replay carries from one sample to the next.
struct ReplayState {
  std::vector<HoldChangeState<double>> hold;
  std::vector<JointDetectorState> detector;
  std::vector<double> stop_extra;  ///< per joint, the stop allowance's extra band [N·m]
  double gate_until = -1e300;      ///< [s]
  std::vector<double> ema;         ///< per joint, the estimate's 0.1 s average [N·m]
  std::vector<std::size_t> steady; ///< per joint, samples steady around `ema` in a row
  JointMask previous = 0;
  double quiet_since = -1.0;  ///< [s]; < 0: not quiet
  sim::JointVector q_now, contact_tau, contact_threshold;
};

/// One sample's detector outcome: the joints over (debounced) and those over their band.
struct SampleFlags {
  JointMask mask = 0, by_band = 0;
};

/// Refuses a threshold or friction file that does not fit the recording's joints, and a
/// holding-aware replay without the file's change thresholds.
void check_replay_inputs(std::size_t n, const std::vector<LuGreParams<double>>& friction, const Thresholds& t,
                         const ReplayOptions& opt) {
  if (t.threshold.size() != n) throw std::invalid_argument("one threshold per joint needed");
  if (friction.size() != n) throw std::invalid_argument("one friction parameter set per joint needed");
  if (opt.holding != HoldingSource::none && t.hold_change.size() != n) {
    throw std::invalid_argument("holding-aware replay needs the threshold file's hold_change_threshold "
                                "(calibrate again: it writes one by default)");
  }
}

ReplayParams replay_params(const Thresholds& t, const ReplayOptions& opt, std::size_t n, double dt, int debounce_cycles) {
  const bool use_hold = opt.holding != HoldingSource::none;
  std::vector<HoldChangeParams<double>> hold(n);
  for (std::size_t j = 0; j < n && use_hold; ++j) hold[j] = hold_params(t.hold_change[j], t.hold_settle_s, t.hold_reference_s, dt);
  const bool region = t.q_min.size() == n && t.ddq_max.size() == n && t.stop_gain.size() == n;
  // Stop allowance: when the arm accelerates harder than anything in the calibration
  // (an abrupt stop), each joint's band grows to s times what the model left there,
  // s = the arm's largest |ddq_i| / ddq_max_i (difference of the measured velocity over
  // kAccelBaselineS, calibration_region.hpp): the model's error in a braking transient
  // scales with it, and joints couple (at the UR10e's stops the waist's current spikes
  // while the waist itself decelerates less than in the calibration). The extra decays with kStopDecayS (the drive's braking
  // current and the stiction it takes up last a few samples after the velocity has dropped).
  constexpr double kStopDecayS = 0.1;
  // Re-arming the holding detector after an event: each joint's estimate steady around
  // its own 0.1 s average for rearm_s.
  const double ema_gain = std::min(1.0, dt / 0.1);
  const auto rearm_cycles = static_cast<std::size_t>(std::ceil(opt.rearm_s / dt - 1e-9));
  return ReplayParams{t,      opt, threshold_bands(t), std::move(hold), use_hold, region,
                      DebounceSettings{static_cast<std::uint8_t>(debounce_cycles)},
                      dt,     std::exp(-dt / kStopDecayS), accel_baseline(dt), ema_gain, rearm_cycles};
}

ReplayState replay_state(std::size_t n) {
  ReplayState s;
  s.hold.resize(n);
  s.detector.resize(n);
  s.stop_extra.assign(n, 0.0);
  s.ema.assign(n, 0.0);
  s.steady.assign(n, 0);
  const auto size = static_cast<Eigen::Index>(n);
  s.q_now.resize(size);
  s.contact_tau.resize(size);
  s.contact_threshold.resize(size);
  return s;
}

ReplayResult empty_result(const io::Recording& rec) {
  const std::size_t n = rec.joints();
  ReplayResult r;
  r.t = rec.t;
  r.external_torque_max.assign(n, 0.0);
  r.outside_q.assign(n, 0);
  r.outside_dq.assign(n, 0);
  r.stop_widened.assign(n, 0);
  r.mu.assign(n, std::vector<double>(rec.samples()));
  return r;
}

/// s of the stop allowance at sample k: the arm's largest |ddq_i| / ddq_max_i (0 without the
/// calibrated region, or before the acceleration baseline is filled).
double stop_ratio_at(const ReplayParams& p, const io::Recording& rec, std::size_t k) {
  double stop_ratio = 0.0;
  for (std::size_t j = 0; j < rec.joints() && p.region && k >= p.accel_m; ++j) {
    if (p.thresholds.ddq_max[j] > 0.0) {
      stop_ratio = std::max(stop_ratio, accel_at(rec, j, k, p.accel_m, p.dt) / p.thresholds.ddq_max[j]);
    }
  }
  return stop_ratio;
}

/// Joint j's band at sample k within the calibrated region's allowances: widened after a stop
/// and beyond the calibrated speed; counts the samples outside the region.
JointThreshold<double> band_in_region(const ReplayParams& p, ReplayState& s, const io::Recording& rec, std::size_t j,
                                      std::size_t k, double stop_ratio, ReplayResult& r) {
  const Thresholds& t = p.thresholds;
  JointThreshold<double> band = p.bands[j];
  const double w = rec.dq[j][k];
  const double q = rec.q[j][k];
  if (q < t.q_min[j] || q > t.q_max[j]) ++r.outside_q[j];
  if (std::fabs(w) > t.dq_max[j]) ++r.outside_dq[j];
  s.stop_extra[j] *= p.stop_decay;
  if (p.opt.stop_allowance && p.opt.stop_gate_s <= 0.0 && stop_ratio > 1.0) {
    s.stop_extra[j] = std::max(s.stop_extra[j], t.stop_gain[j] * t.ddq_max[j] * stop_ratio);
  }
  if (s.stop_extra[j] > 0.01 * band.base) ++r.stop_widened[j];
  // Faster than the calibration: the moving band grows in proportion to the speed
  // ratio (the model's errors grow at least linearly with speed: viscous friction's
  // error with w, the Coriolis terms' with w^2; linear is the cautious lower bound).
  if (p.opt.stop_allowance && t.dq_max[j] > 0.0 && std::fabs(w) > t.dq_max[j]) {
    band.base *= std::fabs(w) / t.dq_max[j];
  }
  band.base += s.stop_extra[j];
  return band;
}

/// Every joint's detector at sample k on the estimate `d` (its negative), with the holding
/// flags `held`; fills the contact estimate's inputs and the re-arming's steadiness.
SampleFlags detect_sample(const ReplayParams& p, ReplayState& s, const io::Recording& rec,
                          const std::vector<std::vector<double>>& d, const std::vector<bool>& held, std::size_t k,
                          double stop_ratio, ReplayResult& r) {
  SampleFlags f;
  if (p.opt.stop_gate_s > 0.0 && stop_ratio > 1.0) s.gate_until = rec.t[k] + p.opt.stop_gate_s;
  const bool gated = rec.t[k] < s.gate_until;
  r.gated_samples += gated ? 1 : 0;
  for (std::size_t j = 0; j < rec.joints(); ++j) {
    const double mu = -d[j][k];
    const double w = rec.dq[j][k];
    r.mu[j][k] = mu;
    r.external_torque_max[j] = std::max(r.external_torque_max[j], std::fabs(mu));
    JointThreshold<double> band = p.region ? band_in_region(p, s, rec, j, k, stop_ratio, r) : p.bands[j];
    if (gated) band.base += 1e12;  // nothing is over while the gate is open
    const bool changed = p.use_hold && hold_change_step(p.hold[j], s.hold[j], held[k] && !gated, mu);
    const double band_now = threshold_at(band, w);
    if (band_now < std::fabs(mu)) f.by_band |= static_cast<JointMask>(1U << j);
    // As in run_detection: a held joint's change since arrival is what the contact adds
    // (its estimate there is mostly the friction it holds).
    const auto i = static_cast<Eigen::Index>(j);
    s.q_now(i) = rec.q[j][k];
    s.contact_tau(i) = p.use_hold && s.hold[j].armed ? mu - s.hold[j].reference : mu;
    s.contact_threshold(i) = p.use_hold && s.hold[j].armed ? std::min(band_now, p.hold[j].change_threshold) : band_now;
    if (detector_step(band, p.debounce, s.detector[j], mu, w, changed)) f.mask |= static_cast<JointMask>(1U << j);
    s.ema[j] = k == 0 ? mu : s.ema[j] + p.ema_gain * (mu - s.ema[j]);
    const double still_within = p.use_hold ? std::max(p.hold[j].change_threshold, 1e-9) : p.thresholds.threshold[j];
    s.steady[j] = std::fabs(mu - s.ema[j]) <= still_within ? s.steady[j] + 1 : 0;
  }
  return f;
}

/// A new event at sample k (the detector's rising edge): its link isolated from the joints
/// above 30 % of their threshold, as in run_detection.
void open_event(const ReplayParams& p, ReplayState& s, const io::Recording& rec, std::size_t k, const SampleFlags& f,
                ReplayContact& contact, ReplayResult& r) {
  ReplayEvent e;
  e.t = rec.t[k];
  e.by_hold = f.by_band == 0;
  JointMask signature = f.mask;
  for (std::size_t j = 0; j < rec.joints(); ++j) {
    const bool part = p.use_hold && s.hold[j].armed
                          ? hold_deviation(s.hold[j], r.mu[j][k]) > 0.6 * p.hold[j].change_threshold
                          : std::fabs(r.mu[j][k]) > 0.3 * p.thresholds.threshold[j];
    if (part) signature |= static_cast<JointMask>(1U << j);
  }
  const int isolated = isolate_link(signature);
  e.link = rec.joint_ids[static_cast<std::size_t>(isolated - 1)];
  contact.event(r.events.size(), e.t, isolated);
  for (std::size_t j = 0; j < rec.joints(); ++j) {
    if ((f.mask & (1U << j)) != 0U) e.joints_over.push_back(rec.joint_ids[j]);
  }
  r.events.push_back(e);
  std::fill(s.steady.begin(), s.steady.end(), std::size_t{0});  // re-arm only after steady from here
}

void reset_detectors(ReplayState& s) {
  for (auto& d : s.detector) reset_detector(d);
  for (auto& h : s.hold) h = HoldChangeState<double>{};
}

/// Re-arms the detectors once an event is over; returns the mask left (0 when re-armed).
JointMask rearm(const ReplayParams& p, ReplayState& s, const io::Recording& rec, std::size_t k, bool held,
                const SampleFlags& f, ReplayResult& r) {
  JointMask mask = f.mask;
  const bool held_rearm = p.use_hold && held;
  if (mask != 0 && held_rearm) {
    // Holding-aware: the push has ended when every estimate is steady again, at whatever
    // level the static friction now holds, and no joint is over its band: new reference.
    bool steady = f.by_band == 0;
    for (std::size_t j = 0; j < rec.joints(); ++j) steady = steady && s.steady[j] >= p.rearm_cycles;
    if (steady) {
      reset_detectors(s);
      mask = 0;
      ++r.rearms;
    }
  }
  // Re-arm once every joint is back under its threshold for 0.2 s (a new event can follow).
  bool all_quiet = true;
  for (std::size_t j = 0; j < rec.joints(); ++j) all_quiet = all_quiet && std::fabs(r.mu[j][k]) < p.thresholds.threshold[j];
  if (mask != 0 && all_quiet && !held_rearm) {
    if (s.quiet_since < 0.0) s.quiet_since = rec.t[k];
    if (rec.t[k] - s.quiet_since > 0.2) {
      reset_detectors(s);
      mask = 0;
      s.quiet_since = -1.0;
    }
  }
  return mask;
}

/// Each event's contact estimate, once the replay is through.
void attach_contacts(const ReplayContact& contact, ReplayResult& r) {
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    if (const auto& o = contact.outcome(i)) {
      r.events[i].contact = o->estimate;
      r.events[i].contact_t = o->t;
      r.events[i].contact_peak_force_n = o->peak_force_n;
      r.events[i].contact_t_peak = o->t_peak;
    }
  }
}
}  // namespace

ReplayResult replay_recording(const io::Recording& rec, const robot::RobotModel& model,
                              const std::vector<LuGreParams<double>>& friction, const Thresholds& thresholds_in,
                              const ObserverGains& gains, const std::string& scalar, int debounce_cycles,
                              const ReplayOptions& opt) {
  const std::size_t n = rec.joints();
  check_replay_inputs(n, friction, thresholds_in, opt);
  const auto held = holding_flags(rec, opt);
  const auto d = observer_disturbance(rec, model, gains, true, friction, scalar, held, opt.held_deadband_steps);
  const double dt = sample_time(rec);
  const ReplayParams p = replay_params(thresholds_in, opt, n, dt, debounce_cycles);
  ReplayState s = replay_state(n);
  ReplayResult r = empty_result(rec);
  ReplayContact contact(model, gains, dt);
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    r.held_samples += held[k] ? 1 : 0;
    const SampleFlags f = detect_sample(p, s, rec, d, held, k, stop_ratio_at(p, rec, k), r);
    if (f.mask != 0 && s.previous == 0) open_event(p, s, rec, k, f, contact, r);
    const JointMask mask = rearm(p, s, rec, k, held[k], f, r);
    if (mask == 0 && s.previous != 0) contact.end();  // re-armed: the contact is over
    s.previous = mask;
    contact.add(rec.t[k], s.q_now, s.contact_tau, s.contact_threshold);
  }
  attach_contacts(contact, r);
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
