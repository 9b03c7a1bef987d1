// The point along a decided link and the force there (master's side, host, double), from
// the torques of every clean cycle of the contact, with a force prior that knows where a
// surface contact can push (docs/contact-estimate.md, "Surface contacts").
//
// Linear-Gaussian model per candidate point s on the link's x axis: tau = J(s)^T F + noise,
// F ~ N(0, P), P = sigma_across^2 (I - x x^T) + sigma_along^2 x x^T (x: the link's axis in
// the base frame). Isotropic (ratio 1) is "no preferred direction". A body part touching the
// link's cover pushes into it: its force lies in the friction cone around the inward
// surface normal, which is across the axis, so the component along the axis is at most
// mu / sqrt(1 + mu^2) of the force; axial_prior_ratio(mu) is the matching rms ratio. On a
// last link of a 3-joint arm this makes the point along the link determined by one posture
// (3 torques for the point and two force components); on a link whose joints' axes meet on
// it (link 2 of the reference arm: J(s) = s J(1)) the torques fix only s x F, in every
// posture, and the point's and the force's spread say so.
// Each cycle's force is free (it changes over the contact); the points' log evidence is
// summed over the cycles with a weight (neighbouring cycles' noise is correlated).
#pragma once

#include <vector>

#include "detection/contact_estimate.hpp"

namespace jg::detection {

/// The rms of a surface contact's force component along the link over its rms across the
/// link (per component), for a force uniform in the friction cone's disc of tangential
/// forces of radius mu F_n: along mu F_n / 2, across sqrt((1 + mu^2 / 4) / 2) F_n.
double axial_prior_ratio(double friction_coefficient);

/// The force prior's covariance [N^2, base frame] on link `link` (1-based) at posture q.
Eigen::Matrix3d force_prior(const sim::ArmDynamics& arm, const sim::JointVector& q, int link,
                            const ContactEstimatorParams& params);

/// Per link and candidate point: the log evidence summed over the cycles added.
struct PointEvidence {
  std::vector<std::vector<double>> along_m;       ///< [link][point] as EvidenceGrid
  std::vector<std::vector<double>> log_evidence;  ///< [link][point] weighted sum over the cycles
  double weight = 0.0;
};
PointEvidence make_point_evidence(int joints, const ContactEstimatorParams& params);
/// Adds one cycle's torques with `weight`. Throws as estimate_contact.
void add_point_evidence(PointEvidence& evidence, const sim::ArmDynamics& arm, const TorqueObservation& obs,
                        const ContactEstimatorParams& params, double weight);

/// Fills e's point and force on e.link (1-based, set): the posterior over the points from
/// `evidence` (nullptr or empty: from `latest` alone) and the force at `latest`'s cycle (its
/// posterior mean at each point, averaged over the points' posterior). The point reported
/// lies on the link's cover (params.surface_radius_m) where the force pushes in.
void estimate_point_and_force(const sim::ArmDynamics& arm, const TorqueObservation& latest,
                              const ContactEstimatorParams& params, const PointEvidence* evidence, ContactEstimate& e);

/// The force's posterior mean [N, base frame] at a known point on a known link (1-based)
/// under the prior of `params`.
Eigen::Vector3d force_with_prior(const sim::ArmDynamics& arm, const TorqueObservation& obs, int link,
                                 const Eigen::Vector3d& point_in_link, const ContactEstimatorParams& params);

/// The point on the cover [m, link frame] at `along_m` along `axis` (unit, link frame: the
/// segment's) where a force `force_base` pushes in (opposite its component across the axis),
/// `radius_m` from the axis; on the axis when the radius is 0 or the force has no component
/// across.
Eigen::Vector3d surface_point(const sim::ArmDynamics& arm, const sim::JointVector& q, int link, const Eigen::Vector3d& axis,
                              double along_m, const Eigen::Vector3d& force_base, double radius_m);

}  // namespace jg::detection
