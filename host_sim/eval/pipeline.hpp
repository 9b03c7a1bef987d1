// The workflow on recordings: identify friction from observer output, calibrate the
// thresholds, replay through the firmware core. Shared by the CLI and the demo.
#pragma once

#include <functional>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "detection/contact_estimate.hpp"
#include "eval/estimator.hpp"
#include "identification/identify.hpp"
#include "io/recording.hpp"
#include "jointguard/detection/detector.hpp"
#include "jointguard/observer/momentum_observer.hpp"
#include "robot/robot_model.hpp"

namespace jg::eval {

/// Contract JSON (--friction): {"joints": [{"joint", "sigma0", ..., "w_s", "rms"}]}
/// `extra` fields (e.g. "resampling", "torque") are added at the top level. The file is
/// written to a temporary name and renamed: it exists complete or not at all.
void write_friction_json(const std::string& path, const std::vector<ident::IdentificationResult>& r,
                         const std::vector<int>& joint_ids, const nlohmann::json& extra = nlohmann::json::object());
std::vector<LuGreParams<double>> read_friction_json(const std::string& path);
/// The same, matched to `joint_ids` by each entry's "joint" number (file order when the
/// entries have none): a file for other joints, with fewer or more of them, or with a
/// joint twice is refused, naming the file and the joint.
std::vector<LuGreParams<double>> read_friction_json(const std::string& path, const std::vector<int>& joint_ids);
/// The same for a robot model of `joints` joints numbered 1..joints (evaluate --friction):
/// a file with another number of joints is refused naming the file, the field "joints" and
/// both counts.
std::vector<LuGreParams<double>> read_friction_json_for_model(const std::string& path, std::size_t joints);

struct Thresholds {
  std::vector<double> threshold;               ///< with friction compensation, while moving [N·m]
  std::vector<double> low_speed_extra;         ///< added near standstill (stiction) [N·m]
  double low_speed_width = 0.03;               ///< w_band [rad/s], one for all joints
  std::vector<double> threshold_uncompensated; ///< without [N·m]
  std::vector<double> band, band_uncompensated;  ///< observed max |mu| before the margin
  double margin = 0.0;
  /// Change detection while holding (hold_detector.hpp; empty: off): threshold per joint
  /// [N·m], the largest collision-free deviation from the reference seen while armed
  /// [N·m], the settle and reference windows [s] and the armed time seen per joint [s].
  std::vector<double> hold_change, hold_band, hold_seconds;
  /// Per joint, where hold_change came from: "holds" (the recording's own holds, armed
  /// long enough) or "friction" (no such holds: kHoldFrictionFraction x the joint's
  /// friction level); empty when unknown (older files).
  std::vector<std::string> hold_source;
  double hold_settle_s = 0.15, hold_reference_s = 0.016;
  /// Change detection against the estimate's slow baseline (residual_detector.hpp; empty:
  /// off): threshold per joint [N·m], the largest collision-free |mu - baseline| [N·m], and
  /// the baseline's time constant [s].
  std::vector<double> residual_change, residual_band;
  double residual_time_constant_s = 0.05;
  /// The region the calibration covered (calibration_region.hpp; empty: unknown), per
  /// joint: position range [rad], largest |velocity| [rad/s] and |acceleration| [rad/s^2]
  /// (difference of the velocity over kAccelBaselineS, calibration_region.hpp), and the band's growth per rad/s^2
  /// of acceleration beyond the largest seen (stops more abrupt than the calibration's).
  std::vector<double> q_min, q_max, dq_max, ddq_max, stop_gain;
};
/// Contract JSON (--threshold): {"joints": [{"joint", "threshold", "threshold_uncompensated"}]}
void write_threshold_json(const std::string& path, const Thresholds& t, const std::vector<int>& joint_ids,
                          const nlohmann::json& extra = nlohmann::json::object());
Thresholds read_threshold_json(const std::string& path);
/// Matched to `joint_ids` like read_friction_json.
Thresholds read_threshold_json(const std::string& path, const std::vector<int>& joint_ids);

/// The measured torque per joint, of the recording's torque kind (rec.torque_kind):
/// tau_j or tau_m columns, or currents x K_I of the model. Apply the model to it through
/// robot::for_torque_kind (a joint torque sensor sees no rotor inertia).
std::vector<std::vector<double>> motor_torque(const io::Recording& rec, const robot::RobotModel& model);

/// Mean sample rate of a recording [Hz]; throws when it has fewer than 3 samples.
/// Recordings from files go through io::regularize first (uniform segments).
double sample_rate(const io::Recording& rec);

/// Observer output per joint over a recording (firmware core, float, no compensation).
/// `held` (one per sample, or empty): the drive holds a setpoint then (every joint), and
/// the firmware's holding velocity deadband `held_deadband` [rad/s] applies
/// (JointEstimatorParams::holding_velocity_deadband), as on the drive.
std::vector<std::vector<double>> observer_disturbance(const io::Recording& rec, const robot::RobotModel& model,
                                                     const ObserverGains& gains, bool compensate,
                                                     const std::vector<LuGreParams<double>>& friction,
                                                     const std::string& scalar = "float", const std::vector<bool>& held = {},
                                                     double held_deadband_steps = 0.0);

std::vector<ident::IdentificationResult> identify_recording(const io::Recording& rec, const robot::RobotModel& model,
                                                            const ObserverGains& gains, const ident::GaSettings& ga,
                                                            const std::function<void(double)>& progress = {});

Thresholds calibrate_recording(const io::Recording& rec, const robot::RobotModel& model,
                               const std::vector<LuGreParams<double>>& friction, const ObserverGains& gains,
                               double margin, double settle_s = 0.5, const std::string& scalar = "float");
/// Calibration over uniform segments of one recording (io::regularize): each run from a
/// fresh observer state, its first settle_s skipped, the band gathered over all of them.
/// Throws when no segment lasts longer than settle_s (no sample to calibrate on).
Thresholds calibrate_segments(const std::vector<io::Recording>& segments, const robot::RobotModel& model,
                              const std::vector<LuGreParams<double>>& friction, const ObserverGains& gains,
                              double margin, double settle_s = 0.5, const std::string& scalar = "float");

/// Collision-free band statistics, gathered sample by sample (a long calibration run need
/// not be recorded): max |mu| per joint in velocity bins, then the band
///   eps(w) = eps0 + extra exp(-(w / w_band)^2)
/// fitted over them: eps0 = max |mu| while moving (|w| >= kMovingSpeed) + margin; near
/// standstill a Gaussian allowance whose height per joint and common width are the
/// smallest (least area extra * w_band) that cover every slower sample's excess over the
/// moving band, times kStandstillFactor, plus the margin; bins up to one encoder count per
/// sample (the smallest speed measured, dither at rest) get the largest standstill excess.
/// The factor: the standstill excess (stiction held where the arm stopped, which no
/// velocity-driven model predicts) has a long tail; one hour at 125 Hz reached 1.36x the
/// excess seen in 30 minutes (seed 2, chosen apart from the seed the figures are reported on).
class BandStatistics {
 public:
  static constexpr double kStandstillFactor = 1.5;
  static constexpr double kBin = 0.0005;         ///< velocity bin [rad/s]
  static constexpr double kMovingSpeed = 0.02;   ///< "moving" from here on [rad/s]
  static constexpr std::size_t kBins = 400;      ///< the last bin holds everything faster
  explicit BandStatistics(std::size_t joints);
  void add(std::size_t joint, double velocity, double mu, double mu_uncompensated);
  /// Adds another run's statistics (same joints): bin by bin maxima, exact in any order.
  void merge(const BandStatistics& other);
  [[nodiscard]] Thresholds fit(double margin) const;
  [[nodiscard]] double max_in(std::size_t joint, double w_lo, double w_hi) const;

 private:
  std::vector<std::vector<double>> max_;  ///< [joint][bin] max |mu|
  std::vector<double> uncompensated_;     ///< [joint] max |mu| without compensation
};

struct ReplayEvent {
  double t = 0.0;
  int link = 0;
  std::vector<int> joints_over;
  bool by_hold = false;  ///< raised by the holding detector alone (no joint over its band)
  /// The contact that explains the joints' torques (eval/replay_contact.hpp), decided at
  /// contact_t [s]; none when the recording ended first, the next event came before, or a
  /// threshold in effect of 0 left the torques without a noise scale.
  std::optional<detection::ContactEstimate> contact;
  double contact_t = 0.0;
  /// The largest force at the decided point until the detector re-armed [N], and when [s].
  double contact_peak_force_n = 0.0, contact_t_peak = 0.0;
};
struct ReplayResult {
  std::vector<ReplayEvent> events;
  /// Per joint: samples outside the calibrated position range, faster than its largest
  /// velocity, and with the band widened for an acceleration beyond its largest (stops).
  std::vector<std::size_t> outside_q, outside_dq, stop_widened;
  std::size_t held_samples = 0, rearms = 0, gated_samples = 0;
  std::vector<double> external_torque_max;
  std::vector<double> t;
  std::vector<std::vector<double>> mu;  ///< [joint][sample]
};
/// The detector's band per joint from calibrated thresholds.
std::vector<JointThreshold<double>> threshold_bands(const Thresholds& t);

/// How replay knows that the drive holds a setpoint (holding-aware change detection).
enum class HoldingSource {
  none,    ///< never: the band alone (the former behaviour)
  always,  ///< the drive holds one setpoint for the whole recording (the user says so)
  still,   ///< derived: the arm came to rest (every |dq| <= still_speed for arrive_s) and
           ///< every joint stays within hold_radius of where it stopped
};
struct ReplayOptions {
  HoldingSource holding = HoldingSource::none;
  /// "At rest" for HoldingSource::still: every joint's |dq| <= still_speed [rad/s], or its
  /// position within still_span [rad] over the last arrive_s (a measured velocity dithers by
  /// a count or a logged digit at rest; 1 mrad in 50 ms is the band's "moving" 0.02 rad/s).
  double still_speed = 1e-9;
  double still_span = 0.001;
  double arrive_s = 0.05;      ///< [s] at rest this long before holding starts
  /// While held, a measured |velocity| up to this many of the recording's velocity steps
  /// (per joint, its smallest nonzero |dq|: a count per sample) is taken as 0 by the
  /// estimate, as the firmware's holding_velocity_deadband (1.5 counts): at rest the velocity
  /// dithers by a count, which swings the LuGre bristles through their static range.
  double held_deadband_steps = 1.5;
  double hold_radius = 0.005;  ///< [rad] a held joint yields this far under a push and still holds
  /// After an event the holding detector re-arms (new reference) once every joint's
  /// estimate has stayed within its change threshold of its own 0.1 s average for rearm_s:
  /// the friction held after a push differs from before it (static friction).
  double rearm_s = 0.5;
  bool stop_allowance = true;  ///< widen the band at accelerations beyond the calibration's
  /// > 0: instead of widening, gate the detector for this long [s] from the first sample
  /// whose acceleration exceeds the calibration's (the drive's knowledge that it commanded
  /// a stop, derived from the recording, which carries no command; a contact that
  /// decelerates the arm harder than the calibration also opens the gate).
  double stop_gate_s = 0.0;
};
/// Per sample: the whole arm held (true) or not, from the options.
std::vector<bool> holding_flags(const io::Recording& rec, const ReplayOptions& o);

/// Where an arm said to be held the whole recording (HoldingSource::always) moves: the
/// first sample at which a joint is farther than o.hold_radius from its first position.
struct HoldViolation {
  double t = 0.0;         ///< the recording's time stamp [s]
  std::size_t joint = 0;  ///< 0-based
  double distance = 0.0;  ///< [rad] from the first position
  double speed = 0.0;     ///< |dq| there [rad/s]
};
std::optional<HoldViolation> first_move(const io::Recording& rec, const ReplayOptions& o);

/// The friction a held joint can hold: its static level, at least the Coulomb level
/// (identification may leave tau_s undetermined, bounded to the least level).
[[nodiscard]] inline double friction_level(const LuGreParams<double>& f) { return f.tau_s > f.tau_c ? f.tau_s : f.tau_c; }
/// The holding detector's change threshold when the calibration recording holds too
/// little to measure the held estimate's collision-free change: this fraction of the
/// joint's friction level. Why the whole level: once the drive holds, the friction the joint
/// came to rest with (anywhere within +-the level) relaxes toward what gravity and the
/// controller leave it, by up to the level itself (from the breakaway to 0); on the real
/// UR10e it moved by 0.5 of it within 2 s after motion_contacts' abrupt stop (J4) and by 6
/// N·m of J1's 14 N·m between pushes on the held arm.
inline constexpr double kHoldFrictionFraction = 1.0;
/// Armed time [s] a joint's holds must add up to for their largest change to set its
/// change threshold (less: kHoldFrictionFraction of its friction level). The largest
/// change has a long tail: 3.9 s of holds in 40 s of scenarios/calibration_motion.yaml gave
/// 2.9 / 2.2 / 0.8 N·m, and a minute of other holds (dwells up to 4 s) crossed that twice;
/// the simulated calibration holds for 1200 s (experiments.hpp).
inline constexpr double kHoldMinArmedS = 60.0;

ReplayResult replay_recording(const io::Recording& rec, const robot::RobotModel& model,
                              const std::vector<LuGreParams<double>>& friction, const Thresholds& thresholds,
                              const ObserverGains& gains, const std::string& scalar, int debounce_cycles,
                              const ReplayOptions& options = {});
/// Replay of uniform segments, each from a fresh state; events, t and mu merged in time
/// order (events keep the recording's time stamps).
ReplayResult replay_segments(const std::vector<io::Recording>& segments, const robot::RobotModel& model,
                             const std::vector<LuGreParams<double>>& friction, const Thresholds& thresholds,
                             const ObserverGains& gains, const std::string& scalar, int debounce_cycles,
                             const ReplayOptions& options = {});

}  // namespace jg::eval
