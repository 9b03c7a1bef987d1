// The paper's experiments and the campaigns on the simulated arm, with the firmware core
// (float or Q16.16) as the estimator: set-up (excitation run -> identification from
// observer output -> calibration on a collision-free run), the three collisions, random
// campaigns, and the collision-free false-alarm run.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "eval/evaluate.hpp"
#include "eval/pipeline.hpp"
#include "robot/robot_model.hpp"
#include "sim/scenario.hpp"

namespace jg::eval {

struct ExperimentConfig {
  robot::RobotModel model;
  double rate_hz = 1000.0;
  std::string scalar = "float";
  ObserverGains gains{ObserverKind::first_order, 150.0, 0.0, 0.0};
  std::vector<LuGreParams<double>> friction;  ///< identified (the plant's truth is plant_friction)
  /// `friction` was given (evaluate --friction, a file identify wrote): prepare takes it as is
  /// instead of identifying it from a simulated excitation run (the GA, the cost of a
  /// preparation on six or seven joints).
  bool friction_given = false;
  /// The plant's true LuGre per joint (e.g. identified on a real arm); empty: the paper's
  /// Table 1 (its joint 3 for every joint beyond the third).
  std::vector<LuGreParams<double>> plant_friction;
  /// A second plant (evaluate --plant FILE): the simulated arm's friction, sensors,
  /// controller and integration (sim::PlantSpec); null: the reference arm's.
  std::shared_ptr<const sim::PlantSpec> plant_spec;
  std::vector<double> thresholds;
  std::vector<double> low_speed_extra;
  double low_speed_width = 0.03;
  int debounce_cycles = 1;
  Reaction reaction = Reaction::stop;
  double current_noise_a = 0.01;
  unsigned long long seed = 1;
  /// Collision-free random motion the thresholds are calibrated on [s].
  double calibration_s = 3600.0;
  /// Threads for the identification's independent GA runs (the result does not depend on it).
  int jobs = 2;
  /// Change detection while holding: threshold per joint [N·m] (empty: off), windows [s],
  /// and the collision-free motion with holds it is calibrated on [s] (0: no holding detector).
  std::vector<double> hold_threshold;
  double hold_settle_s = 0.15, hold_reference_s = 0.016;
  double hold_calibration_s = 1200.0;
  /// Change detection against the estimate's slow baseline (residual_detector.hpp):
  /// threshold per joint [N·m] (empty: off), the baseline's time constant [s], and whether
  /// calibrate() fits it (on the same collision-free motion as the band).
  std::vector<double> residual_threshold;
  double residual_time_constant_s = 0.05;
  bool residual_detector = true;
  double isolation_window_s = 0.0;  ///< DetectionConfig::isolation_window_s
  double isolation_aligned_s = 0.001;  ///< DetectionConfig::isolation_aligned_s
  bool isolation_standstill_change = true;  ///< DetectionConfig::isolation_standstill_change
  /// The false-alarm run's motion includes holds (make_random_moves_with_holds).
  bool free_run_holds = true;
  /// Campaign and paper runs: the other firmware scalar ("float" or "q"; empty: none) runs
  /// beside `scalar` on the same measurements with the same thresholds, and its detection
  /// cycle is recorded (RunResult::t_detected_other).
  std::string compare_scalar;
  /// Campaign and paper runs: the compared estimator (compare_scalar, or `scalar` when none)
  /// runs as the joint drives' firmware on the simulated CAN FD bus, one drive per joint
  /// using its neighbours' previous-cycle messages, and each run records the bus's load
  /// (RunResult::bus).
  bool compare_on_bus = false;
  /// The contact estimate (ContactWindowConfig): samples before the detection, the decision
  /// after it [s], noise per threshold.
  double contact_before_s = 0.005, contact_after_s = 0.020, contact_noise_band_sigmas = 3.0;
  /// Surface contacts (docs/contact-estimate.md): the campaign draws points on the links'
  /// cover and forces within the friction cone (sim::CampaignSpec::surface_contacts), and
  /// the contact estimate's force prior knows the cone and reports the point on the cover.
  bool campaign_surface_contacts = false;
  bool contact_surface_prior = false;
  bool contact_point_over_the_contact = false;
  bool contact_link_from_isolation = true;  ///< ContactWindowConfig::link_from_isolation
  double contact_prior_friction = 0.5;  ///< the friction coefficient the surface prior assumes (sim::kSkinFriction)
  double contact_force_after_s = 0.0;  ///< ContactWindowConfig::force_after_s
  bool contact_lag_correction = true;  ///< ContactWindowConfig::lag_correction
};

/// The holding detector's threshold from the largest collision-free deviation seen while
/// armed: kHoldFactor x it + kHoldMargin [N·m].
inline constexpr double kHoldFactor = 1.5;
inline constexpr double kHoldMargin = 0.2;
/// The residual detector's threshold from the largest collision-free |mu - baseline| seen
/// on the calibration motion: kResidualFactor x it + kResidualMargin [N·m].
inline constexpr double kResidualFactor = 1.5;
inline constexpr double kResidualMargin = 0.2;

/// A simulation set-up on the model at the configured rate with realistic sensors and the
/// paper's friction as truth.
sim::SimulationSetup base_setup(const ExperimentConfig& c, std::shared_ptr<const sim::Trajectory> trajectory,
                                unsigned long long seed);

/// Excitation run -> LuGre from observer output; collision-free run -> thresholds.
struct Preparation {
  std::vector<ident::IdentificationResult> identification;
  Thresholds thresholds;
  io::Recording excitation;
};
/// Thresholds from `c.calibration_s` of collision-free random motion with the configured
/// estimator (rate, scalar, friction): BandStatistics::fit; then, when
/// `c.hold_calibration_s` > 0, the holding detector's threshold from that long a
/// collision-free motion with holds (its own seed). Both runs are made of independent
/// segments of kCalibrationSegmentS (from rest at home, seeded from their index; segment 0
/// has the seeds of the single run they replaced), run over `c.jobs` threads; their
/// statistics merge exactly (maxima; the hold time summed in segment order).
inline constexpr double kCalibrationSegmentS = 600.0;
Thresholds calibrate(const ExperimentConfig& c, double margin_nm);

Preparation prepare(ExperimentConfig& c, double margin_nm, const std::function<void(double)>& progress = {});

/// Which of a campaign's independent runs this process does, and on how many threads.
/// Shard k of n (1-based) takes the indices i with i % n == k - 1 (campaign collisions and
/// free-run segments alike); every run is seeded from its index, so the union of the shards'
/// runs is the whole campaign whatever the split and the thread count.
struct RunSplit {
  int jobs = 1;
  int shard = 1, shards = 1;
  [[nodiscard]] bool takes(std::size_t index) const {
    return static_cast<int>(index % static_cast<std::size_t>(shards)) == shard - 1;
  }
};

/// The paper's three collisions (waist, shoulder, elbow) during the pick task.
std::vector<RunResult> paper_experiments(const ExperimentConfig& c, bool traces, const RunSplit& split = {});

/// The arm moves for 1.5 s to a posture and holds it for 6 s; with `torque_nm` > 0 a push
/// (30 ms rise, 1 s) on link `link` at 3.5 s, tangential at 0.2 m on the link, loads that
/// link's own joint with `torque_nm` (the joints below carry their own share).
RunResult held_push(const ExperimentConfig& c, int link, double torque_nm, bool traces);
/// held_push's simulation set-up (for other estimators).
sim::SimulationSetup held_push_setup(const ExperimentConfig& c, int link, double torque_nm);
/// held_push on every link with 0.5, 1, 1.5, 2 and 3 N·m, and one hold without contact.
std::vector<RunResult> held_experiments(const ExperimentConfig& c);

/// The links a campaign collides with: 2 and 3 on a 3-joint arm (the reference figures),
/// every link but the base's first on a longer chain (2..n: upper arm, forearm and wrist).
std::vector<int> campaign_links(std::size_t joints);

/// Random collisions (seeded) on `links`, each in its own short run from random motion.
/// Runs of other shards are left out; the result is in index order.
std::vector<RunResult> campaign(const ExperimentConfig& c, int count, const std::vector<int>& links,
                                const std::function<void(double)>& progress = {}, const RunSplit& split = {});

/// The collision-free run is made of independent segments of kFreeRunSegmentS (the last one
/// shorter), each from rest at home with its own motion and noise seeded from its index
/// (segment 0 is the run a free run up to one segment long always was).
inline constexpr double kFreeRunSegmentS = 600.0;
struct FreeRunSegment {
  int index = 0;
  double seconds = 0.0;
  std::vector<double> alarm_times;  ///< [s] from the start of the whole free run
  std::vector<FalseAlarm> alarms;    ///< the same in detail (t_s from the start of the whole run)
};
std::vector<FreeRunSegment> free_run_segments(const ExperimentConfig& c, double seconds, const RunSplit& split = {},
                                              const std::function<void(double)>& progress = {});

/// Collision-free random motion for `seconds` (all segments): detections per hour.
double false_alarms_per_hour(const ExperimentConfig& c, double seconds, int& alarms,
                             const std::function<void(double)>& progress = {}, std::vector<double>* times = nullptr,
                             int jobs = 1);

std::unique_ptr<Estimator> estimator_for(const ExperimentConfig& c);
/// The detector settings of a configuration (thresholds, band, debounce, reaction).
DetectionConfig detection_for(const ExperimentConfig& c);

/// Campaign figures over runs.
struct Summary {
  int runs = 0, detected = 0, isolated = 0;
  /// Runs whose true torques make the collided link nameable (RunResult::isolable), and how
  /// many of those were isolated.
  int isolable = 0, isolated_of_isolable = 0;
  /// The same against the ceiling at decision time (RunResult::isolable_at_decision).
  int isolable_at_decision = 0, isolated_of_isolable_at_decision = 0;
  /// Detections whose first cycle over came from the holding detector alone.
  int detected_by_hold = 0;
  /// Detections whose first cycle over came from the residual detector, not the band.
  int detected_by_residual = 0;
  /// Collisions whose true torque exceeds 1.5x the threshold in effect on some joint, and
  /// how many of them were detected; the same against the moving threshold (stricter).
  int detectable = 0, detectable_found = 0, detectable_moving = 0, detectable_moving_found = 0;
  double delay_min = 0, delay_median = 0, delay_max = 0;  ///< [s], over detected runs
  /// Detected runs whose true torque crossed the threshold in effect, and their delay after
  /// that crossing [s]: how many within 10 ms, median, 95th percentile, max.
  int after_crossing = 0, after_crossing_within_10ms = 0;
  double after_crossing_median = 0, after_crossing_p95 = 0, after_crossing_max = 0;
  /// The physical ceiling: runs whose contact exerted any force at all (a clamp obstacle
  /// the arm moves away from is never touched), how many of those were detected, and how
  /// many touched with a true torque that never reaches the moving threshold on any joint.
  int touched = 0, touched_detected = 0, touched_below_moving = 0;
  /// Runs with a second estimator (compare_scalar, or the drives on the bus: compare_on_bus):
  /// how many, how many either detected, and of those how many both detected on the same cycle.
  int compared = 0, compared_detected = 0, same_cycle = 0;
  /// Of the runs both detected: the other's detection time minus the first's [s] (min,
  /// median, max; positive: the other later).
  int both_detected = 0;
  double other_lag_min_s = 0.0, other_lag_median_s = 0.0, other_lag_max_s = 0.0;
  /// Runs compared on the simulated bus (RunResult::bus): how many, their frames, wire
  /// time and run time summed [s], the largest share of a run's time the wire was busy, and
  /// the cycles whose status frames were not all in by the next cycle.
  int bus_runs = 0;
  std::size_t bus_frames = 0, bus_incomplete_cycles = 0;
  double bus_busy_s = 0.0, bus_elapsed_s = 0.0, bus_busy_max_share = 0.0;
  /// The contact estimate (RunResult::contact): runs with one; its link right (in all, and
  /// among the isolable); its force magnitude within 20 % of the true force at the estimate's
  /// cycle (and the same given the true point); the point within 5 cm of the true one (3-D,
  /// and along the link's axis), the link right.
  int estimated = 0, estimated_link_right = 0, estimated_right_of_isolable = 0;
  int force_within_20pct = 0, force_within_20pct_true_point = 0, point_within_5cm = 0, along_within_5cm = 0;
  int peak_force_within_20pct = 0;  ///< the force followed after the decision: its peak against the run's true peak
  /// The force within 20 % of the true force as the observer sees it (ContactOutcome::
  /// force_true_observed_n), and the same given the true point.
  int force_within_20pct_observed = 0, force_within_20pct_observed_true_point = 0;
  /// On the true link (ContactOutcome::*_given_true_link): force within 20 % of the observed
  /// truth, point within 5 cm (3-D).
  int force_within_20pct_observed_true_link = 0, point_within_5cm_true_link = 0;
};
Summary summarize(const std::vector<RunResult>& runs);

}  // namespace jg::eval
