// Contact estimation on the master's side (host, double): from the estimated external joint
// torques of a short window, which link was touched, where on it, and with what force.
//
// Model: a single point force F (base frame, N) at a point p on link i gives the joint
// torques tau = J_i(p)^T F (J_i: the point's linear Jacobian; the columns of the joints
// beyond link i are zero, so those joints see no torque). The contact point is taken on
// the link's x axis (the segment towards the next joint: the links' bodies), p = (s, 0, 0)
// in the link frame, s on a grid over the link's segment.
//
// The link: the most proximal one whose weighted least-squares fit tau ~ J^T F leaves a
// residual within the noise (EvidenceGrid below): a more distal link explains a torque
// pattern with no torque on its own joints only by coincidence, so a joint whose torque
// stays within its noise is not taken as carrying the contact.
// The point and the force on that link: a linear-Gaussian model per s, F ~ N(0,
// force_prior_n^2 I) (isotropic: no preferred direction), tau | F ~ N(J^T F, diag(sigma^2));
// tau | s is Gaussian (covariance force_prior^2 J^T J + diag(sigma^2)), which weighs the
// points (uniform prior along the segment), and the force given s has a closed-form posterior.
//
// What the torques determine (n joint torques, here n = 3): given the point, the force
// components in the range of J_i(p) (rank min(i, 3) away from singularities): on the last
// link of a 3-joint arm all three, on the second link two (the component through both axes,
// along the link, gives no torque). The point along the link is NOT determined by one
// posture: every point of the force's line of action gives the same torques, and moving
// the point along the link rescales the force (a 3-D force plus a point are 4 unknowns for
// 3 equations). The estimate reports the posterior mean and spread over the segment; the
// spread (along_sigma_m, force_sigma_n) is the honest uncertainty, and force_at() gives
// the force for a point known otherwise.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "dynamics/rigid_body.hpp"

namespace jg::detection {

/// Where a contact may lie on one link: along its body's axis from the link frame's origin
/// [m]. The axis points towards the next joint (RobotModel::reach_axes): the link frame's x
/// axis on the project's arms, along z or -x on links of vendor URDFs (the UR's forearm).
struct LinkSegment {
  double along_min_m = 0.0, along_max_m = 0.3;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  ///< unit, link frame
};

struct ContactEstimatorParams {
  std::vector<LinkSegment> segments;  ///< per link (index 0 = link 1)
  int points_per_link = 33;           ///< grid along each segment (>= 1)
  double force_prior_n = 60.0;        ///< rms per component of the isotropic force prior [N]
  double accept_chi2_per_dof = 9.0;   ///< a link explains the torques up to this residual per dof (3 sigma)
  /// The force prior's rms along the link's x axis over its rms across it (contact_point.hpp):
  /// 1 isotropic (no preferred direction); a contact on the link's cover pushes across the
  /// axis, within its friction cone: axial_prior_ratio(mu).
  double axial_prior_ratio = 1.0;
  double surface_radius_m = 0.0;  ///< the links' cover radius: the point reported on it (0: on the axis) [m]
  /// Over several cycles (add_point_evidence): each cycle scores a point by its best fit (the
  /// force's posterior mean: weighted residual and prior penalty) instead of its evidence,
  /// whose volume term favours the points where the torques are least sensitive to the force
  /// and adds up over the weak cycles at the contact's start.
  bool profile_point_likelihood = false;
  /// The force reported at the points' posterior mean, not averaged over the points (where
  /// the point is spread, |F| ~ 1/s averaged over it overstates the force).
  bool force_at_mean_point = false;
  /// The contact point lies on the link's body, up to this far off the candidate (the axis,
  /// or the cover where the force pushes in) [m]: a point off by r at a uniform azimuth
  /// changes each joint's torque by z_j . (r x F), rms r |F| / sqrt(2) at most. Taken as
  /// model noise per joint (honest_sigma). 0.04 m: the reference arm's cover radius
  /// (sim::kSurfaceRadius); the former draw's offsets are 0.03 m rms per axis across it.
  double point_offset_m = 0.04;
  /// A spread as wide as this share of the force (2 sigma over the force) or wider counts
  /// as "the torques do not determine the force" (ContactEstimate::force_determined: 2 sigma
  /// within 20 %): the answer is then given as its set (link, line of action, force range).
  double determined_rel_2sigma = 0.2;
};

/// Rank of the noise-weighted J^T (rows: joints, each divided by its sigma): how many force
/// components the torques determine.
int weighted_rank(const Eigen::MatrixXd& At, const Eigen::VectorXd& sigma);

/// The default segments of an arm: each link's body from 10 % of its reach to its reach
/// (reach: the distance to the next joint, robot::JointDescription::reach_m), at least 0.1 m,
/// along `axes` (unit, link frame: RobotModel::reach_axes(); none given: each link's x axis).
ContactEstimatorParams default_contact_params(const std::vector<double>& reaches_m,
                                              const std::vector<Eigen::Vector3d>& axes = {});

/// The point `along_m` along link `link0`'s (0-based) segment axis [m, link frame].
Eigen::Vector3d segment_point(const ContactEstimatorParams& params, int link0, double along_m);

/// The torques to explain: one posture, the external torque estimate and its 1-sigma
/// uncertainty per joint (> 0).
struct TorqueObservation {
  sim::JointVector q;         ///< [rad]
  sim::JointVector tau_nm;    ///< [N·m]
  sim::JointVector sigma_nm;  ///< [N·m]
};

struct ContactEstimate {
  int link = 0;                         ///< 1-based; 0 when nothing was estimated
  std::vector<double> link_chi2;        ///< largest residual over the observations at each link's best point (index 0 = link 1)
  double along_m = 0.0;                 ///< posterior mean of the point along the link's segment axis [m]
  double along_sigma_m = 0.0;           ///< its posterior standard deviation [m]
  Eigen::Vector3d point_in_link = Eigen::Vector3d::Zero();  ///< along_m x the segment's axis, on the cover [m]
  Eigen::Vector3d point_base = Eigen::Vector3d::Zero();     ///< [m]
  Eigen::Vector3d force_base = Eigen::Vector3d::Zero();     ///< posterior mean force [N]
  double force_n = 0.0;        ///< posterior mean of the determined force's magnitude [N]
  double force_sigma_n = 0.0;  ///< its spread: over the points and the undetermined components [N]
  /// Force components the torques determine at the estimated point (rank of J^T): 3 on the
  /// last link of a 3-joint arm, 2 on the second link, 1 on the first.
  int determined_components = 0;
  double residual_chi2 = 0.0;  ///< sum ((tau - J^T F) / sigma)^2 at the estimated point and force
  // The answer as a set (docs/contact-estimate.md, "Honest spreads"): what the torques allow
  // at about 95 % (2 sigma) once the torque noise, the observer's lag, the point's offset
  // from the candidate and the grid are counted.
  double along_lo_m = 0.0, along_hi_m = 0.0;  ///< the point's interval along the link [m]
  double force_lo_n = 0.0, force_hi_n = 0.0;  ///< the force magnitude's interval [N]
  /// The force's line of action (base frame): through point_base, along this unit direction
  /// (the posterior mean force's); every point of it gives the same torques.
  Eigen::Vector3d line_direction_base = Eigen::Vector3d::Zero();
  std::vector<int> links_consistent;  ///< every link (1-based) whose residual stays within the noise
  /// The torques determine the force: its 2-sigma interval lies within
  /// ContactEstimatorParams::determined_rel_2sigma of the estimate (a point, not a set).
  bool force_determined = false;
};

/// The residual of every (link, point) hypothesis over observations: the torques of several
/// cycles of one contact (one link and point, the force fitted per cycle); the largest
/// residual over the cycles is kept (a joint that carries the contact clears its noise at
/// some cycle, once the contact's force has built up; averaging would dilute it with the
/// cycles before). The link: the most proximal one whose largest residual stays within
/// accept_chi2_per_dof per residual degree of freedom (n - rank of its J^T): the joints it
/// cannot load, and the torque patterns it cannot make, carry no more than noise. The most
/// distal link always explains n <= 3 torques; a more proximal link that explains them is
/// preferred because a distal contact showing no torque on its own joints is a coincidence.
struct EvidenceGrid {
  std::vector<std::vector<double>> along_m;  ///< [link][point] the grid along each link's segment axis
  std::vector<Eigen::Vector3d> axis;         ///< [link] the segment's axis (LinkSegment::axis)
  std::vector<std::vector<double>> chi2;     ///< [link][point] largest ((tau - J^T F) / sigma)^2 over the observations
  double weight = 0.0;                       ///< sum of the weights added (observations)
};
EvidenceGrid make_grid(int joints, const ContactEstimatorParams& params);
/// Adds one observation's log evidence with `weight`. Throws as estimate_contact.
void accumulate(EvidenceGrid& grid, const sim::ArmDynamics& arm, const TorqueObservation& obs, double weight = 1.0);

/// Estimates the contact: the link from `evidence` (all observations of the contact so far;
/// nullptr: from `obs` alone), the point and the force from `obs` (the latest torques).
/// Throws std::invalid_argument on sizes that do not match the arm or a sigma <= 0.
ContactEstimate estimate_contact(const sim::ArmDynamics& arm, const TorqueObservation& obs,
                                 const ContactEstimatorParams& params, const EvidenceGrid* evidence = nullptr);

/// The force [N, base frame] that best explains the torques for a contact at a known point
/// on a known link (1-based): weighted least squares, minimum norm where J^T is rank-deficient.
Eigen::Vector3d force_at(const sim::ArmDynamics& arm, const TorqueObservation& obs, int link,
                         const Eigen::Vector3d& point_in_link);

/// A short window of torque estimates summarized as one observation: per joint, the value
/// at the window's last sample from a straight-line fit (less noise than one sample),
/// advanced by the observer's lag (a first-order observer of gain K follows a ramp 1/K
/// late: slope / K is added; K <= 0 leaves it out). Samples at times t (s, increasing).
struct WindowSample {
  double t = 0.0;
  sim::JointVector q, mu_nm, sigma_nm;
};
TorqueObservation summarize_window(const std::vector<WindowSample>& samples, double observer_gain_per_s);

/// How the window's value relates to the torque it estimates (summarize_window_honest).
struct WindowModel {
  double observer_gain_per_s = 0.0;  ///< first-order observer gain K: its noise is correlated over 1/K [1/s]
  bool lag_correction = true;        ///< the value advanced by the lag (slope / K)
  /// The lag correction is exact on a ramp; on a force whose slope changes within 1/K it is
  /// off by up to its own size: this share of it is counted as its 1-sigma error.
  double lag_uncertainty = 1.0;
  /// The samples' sigma (the threshold in effect / noise_band_sigmas) times this is the
  /// observer noise's marginal spread at the contact (the threshold is a maximum over a long
  /// collision-free run, several sigma: calibrated on a campaign, eval/contact_window.hpp).
  double noise_scale = 1.0;
};
/// As summarize_window, with each joint's sigma propagated honestly: the samples' sigma is
/// the marginal spread of the observer's noise, correlated as exp(-K |t_i - t_k|) (a
/// first-order observer's output, K > 0; white without K); the line fit and its
/// extrapolation are linear in the samples (weights c), so the value's noise variance is
/// sigma^2 c^T R c, plus (lag_uncertainty x the lag correction)^2.
/// `lag_sigma_nm` (if given): the lag correction's part of each joint's sigma [N·m].
TorqueObservation summarize_window_honest(const std::vector<WindowSample>& samples, const WindowModel& model,
                                          sim::JointVector* lag_sigma_nm = nullptr);

}  // namespace jg::detection
