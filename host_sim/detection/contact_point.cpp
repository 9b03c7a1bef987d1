#include "detection/contact_point.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace jg::detection {
namespace {
using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

Matrix jacobian_transposed(const sim::ArmDynamics& arm, const sim::JointVector& q, const ContactEstimatorParams& params,
                           int link0, double along_m) {
  return arm.point_jacobian(q, link0, segment_point(params, link0, along_m)).transpose();
}

/// The linear-Gaussian model at one point: log evidence of tau, the force's posterior.
struct Candidate {
  double log_evidence = 0.0;
  double log_profile = 0.0;  ///< -0.5 (weighted residual^2 + prior penalty) at the posterior mean (MAP)
  double log_fit = 0.0;      ///< -0.5 weighted residual^2 there
  Eigen::Vector3d force_mean = Eigen::Vector3d::Zero();
  double force_trace_cov = 0.0;  ///< trace of the force's posterior covariance [N^2]
  Eigen::Matrix3d force_cov = Eigen::Matrix3d::Zero();  ///< the force's posterior covariance [N^2]
};

Candidate candidate(const Matrix& At, const Vector& tau, const Vector& sigma, const Eigen::Matrix3d& P) {
  const auto n = tau.size();
  const Matrix AP = At * P;  // n x 3
  Matrix S = AP * At.transpose();
  for (Eigen::Index j = 0; j < n; ++j) S(j, j) += sigma(j) * sigma(j);
  const Eigen::LLT<Matrix> llt(S);  // positive definite: sigma > 0
  const Vector alpha = llt.solve(tau);
  double log_det = 0.0;
  const Matrix L = llt.matrixL();
  for (Eigen::Index j = 0; j < n; ++j) log_det += 2.0 * std::log(L(j, j));
  Candidate c;
  c.log_evidence = -0.5 * (tau.dot(alpha) + log_det + static_cast<double>(n) * std::log(2.0 * M_PI));
  c.force_mean = AP.transpose() * alpha;
  const Vector r = (tau - At * c.force_mean).cwiseQuotient(sigma);
  c.log_fit = -0.5 * r.squaredNorm();
  c.log_profile = c.log_fit - 0.5 * c.force_mean.dot(P.ldlt().solve(c.force_mean));
  const Matrix cov = P - AP.transpose() * llt.solve(AP);
  c.force_trace_cov = std::max(0.0, cov.trace());
  c.force_cov = 0.5 * (cov + cov.transpose());
  return c;
}

void check_link(const sim::ArmDynamics& arm, int link) {
  if (link < 1 || link > arm.joints()) throw std::invalid_argument("contact estimate: no link " + std::to_string(link));
}

/// The torques fix only the moment s x F on this link: J(s) = (s / s1) J(s1) over the segment
/// (the joints' axes meet on the link's axis at s = 0, as at link 2 of the reference arm).
bool moment_only(const sim::ArmDynamics& arm, const sim::JointVector& q, const ContactEstimatorParams& params, int link0,
                 const std::vector<double>& along) {
  const double a = along.front(), b = along.back();
  if (!(a > 0.0) || !(b > a)) return false;
  const Matrix Ja = jacobian_transposed(arm, q, params, link0, a), Jb = jacobian_transposed(arm, q, params, link0, b);
  return (Jb * a - Ja * b).norm() <= 1e-9 * (Jb * a).norm();
}

}  // namespace

double axial_prior_ratio(double friction_coefficient) {
  const double mu = std::max(0.0, friction_coefficient);
  return 0.5 * mu / std::sqrt(0.5 * (1.0 + 0.25 * mu * mu));
}

Eigen::Matrix3d force_prior(const sim::ArmDynamics& arm, const sim::JointVector& q, int link,
                            const ContactEstimatorParams& params) {
  check_link(arm, link);
  const double across2 = params.force_prior_n * params.force_prior_n;
  const double along2 = across2 * params.axial_prior_ratio * params.axial_prior_ratio;
  const Eigen::Vector3d x = arm.poses(q).rotation[link - 1] * segment_point(params, link - 1, 1.0);
  return across2 * (Eigen::Matrix3d::Identity() - x * x.transpose()) + along2 * x * x.transpose();
}

PointEvidence make_point_evidence(int joints, const ContactEstimatorParams& params) {
  const EvidenceGrid g = make_grid(joints, params);
  PointEvidence p;
  p.along_m = g.along_m;
  for (const auto& a : g.along_m) p.log_evidence.emplace_back(a.size(), 0.0);
  return p;
}

void add_point_evidence(PointEvidence& evidence, const sim::ArmDynamics& arm, const TorqueObservation& obs,
                        const ContactEstimatorParams& params, double weight) {
  if (static_cast<int>(evidence.along_m.size()) != arm.joints()) throw std::invalid_argument("contact estimate: evidence of another arm");
  for (std::size_t i = 0; i < evidence.along_m.size(); ++i) {
    const int link = static_cast<int>(i) + 1;
    const Eigen::Matrix3d P = force_prior(arm, obs.q, link, params);
    // Where the torques fix only s x F, the force prior's penalty would pick the point (the
    // largest s, the smallest force): the fit alone leaves the points' prior (uniform).
    const bool fit_only = moment_only(arm, obs.q, params, static_cast<int>(i), evidence.along_m[i]);
    for (std::size_t k = 0; k < evidence.along_m[i].size(); ++k) {
      const Matrix At = jacobian_transposed(arm, obs.q, params, static_cast<int>(i), evidence.along_m[i][k]);
      const Candidate c = candidate(At, obs.tau_nm, obs.sigma_nm, P);
      const double profile = fit_only ? c.log_fit : c.log_profile;
      evidence.log_evidence[i][k] += weight * (params.profile_point_likelihood ? profile : c.log_evidence);
    }
  }
  evidence.weight += weight;
}

Eigen::Vector3d surface_point(const sim::ArmDynamics& arm, const sim::JointVector& q, int link, const Eigen::Vector3d& axis,
                              double along_m, const Eigen::Vector3d& force_base, double radius_m) {
  check_link(arm, link);
  Eigen::Vector3d f = arm.poses(q).rotation[link - 1].transpose() * force_base;  // link frame
  f -= axis * axis.dot(f);  // across the axis only
  const Eigen::Vector3d axis_point = axis * along_m;
  if (!(radius_m > 0.0) || !(f.norm() > 1e-9)) return axis_point;
  return axis_point - radius_m * f.normalized();
}

namespace {
/// The points' posterior on one link and the force's posterior at each point.
struct PointPosterior {
  std::vector<double> along, w;
  std::vector<Candidate> cands;
};

PointPosterior point_posterior(const sim::ArmDynamics& arm, const TorqueObservation& obs, const ContactEstimatorParams& params,
                               const PointEvidence* evidence, int link) {
  const auto i = static_cast<std::size_t>(link - 1);
  const bool summed = evidence != nullptr && evidence->weight > 0.0;
  PointPosterior p;
  p.along = summed ? evidence->along_m.at(i) : make_grid(arm.joints(), params).along_m.at(i);
  const Eigen::Matrix3d P = force_prior(arm, obs.q, link, params);
  std::vector<double> logs;
  for (std::size_t k = 0; k < p.along.size(); ++k) {
    p.cands.push_back(candidate(jacobian_transposed(arm, obs.q, params, link - 1, p.along[k]), obs.tau_nm, obs.sigma_nm, P));
    logs.push_back(summed ? evidence->log_evidence[i][k] : p.cands.back().log_evidence);
  }
  const double top = *std::max_element(logs.begin(), logs.end());
  double wsum = 0.0;
  for (const double l : logs) wsum += std::exp(l - top);
  for (const double l : logs) p.w.push_back(std::exp(l - top) / wsum);
  return p;
}

/// The force's magnitude over the posterior (points and force components): 2.5 %, 50 % and
/// 97.5 % quantiles and the standard deviation, from a fixed-seed sample (reproducible).
struct MagnitudeSpread {
  double lo = 0.0, hi = 0.0, sigma = 0.0;
};
MagnitudeSpread magnitude_spread(const PointPosterior& p) {
  constexpr int kDraws = 2000;
  std::mt19937_64 rng(20261127);
  std::normal_distribution<double> gauss;
  std::discrete_distribution<std::size_t> pick(p.w.begin(), p.w.end());
  std::vector<Eigen::Matrix3d> roots;
  for (const auto& c : p.cands) roots.push_back(Eigen::LLT<Eigen::Matrix3d>(c.force_cov + 1e-9 * Eigen::Matrix3d::Identity()).matrixL());
  std::vector<double> m;
  double mean = 0.0;
  for (int d = 0; d < kDraws; ++d) {
    const std::size_t k = pick(rng);
    const Eigen::Vector3d z(gauss(rng), gauss(rng), gauss(rng));
    m.push_back((p.cands[k].force_mean + roots[k] * z).norm());
    mean += m.back() / kDraws;
  }
  double var = 0.0;
  for (const double v : m) var += (v - mean) * (v - mean) / kDraws;
  std::sort(m.begin(), m.end());
  return {m[static_cast<std::size_t>(0.025 * kDraws)], m[static_cast<std::size_t>(0.975 * kDraws)], std::sqrt(var)};
}

/// The torques' noise with the point's offset from its candidate added per joint: up to
/// r |F| / sqrt(2) rms (ContactEstimatorParams::point_offset_m), F the force's first estimate.
TorqueObservation with_point_offset(const TorqueObservation& obs, const ContactEstimatorParams& params, double force_n) {
  TorqueObservation o = obs;
  const double model = params.point_offset_m * force_n / std::sqrt(2.0);
  for (Eigen::Index j = 0; j < o.sigma_nm.size(); ++j) o.sigma_nm(j) = std::hypot(o.sigma_nm(j), model);
  return o;
}

double mean_magnitude(const PointPosterior& p) {
  double f = 0.0;
  for (std::size_t k = 0; k < p.w.size(); ++k) f += p.w[k] * p.cands[k].force_mean.norm();
  return f;
}
}  // namespace

void estimate_point_and_force(const sim::ArmDynamics& arm, const TorqueObservation& measured,
                              const ContactEstimatorParams& params, const PointEvidence* evidence, ContactEstimate& e) {
  check_link(arm, e.link);
  const auto i = static_cast<std::size_t>(e.link - 1);
  const TorqueObservation latest = with_point_offset(measured, params, mean_magnitude(point_posterior(arm, measured, params, evidence, e.link)));
  const PointPosterior post = point_posterior(arm, latest, params, evidence, e.link);
  const Eigen::Matrix3d P = force_prior(arm, latest.q, e.link, params);
  double mean_s = 0.0;
  e.force_base = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < post.w.size(); ++k) {
    mean_s += post.w[k] * post.along[k];
    e.force_base += post.w[k] * post.cands[k].force_mean;
  }
  // The grid's own resolution: a posterior on one point still spans its cell.
  const double cell = post.along.size() > 1 ? (post.along.back() - post.along.front()) / static_cast<double>(post.along.size() - 1) : 0.0;
  double var_s = cell * cell / 12.0;
  for (std::size_t k = 0; k < post.w.size(); ++k) var_s += post.w[k] * (post.along[k] - mean_s) * (post.along[k] - mean_s);
  e.along_m = mean_s;
  e.along_sigma_m = std::sqrt(var_s);
  e.along_lo_m = std::max(post.along.front() - 0.5 * cell, mean_s - 2.0 * e.along_sigma_m);
  e.along_hi_m = std::min(post.along.back() + 0.5 * cell, mean_s + 2.0 * e.along_sigma_m);
  // The force at the posterior mean point: where the point is spread over the link (the
  // torques fix s x F), the mean of |F| ~ 1/s over the points would overstate it.
  e.force_n = mean_magnitude(post);
  if (params.force_at_mean_point) {
    const Candidate at_mean = candidate(jacobian_transposed(arm, latest.q, params, e.link - 1, mean_s), latest.tau_nm, latest.sigma_nm, P);
    e.force_n = at_mean.force_mean.norm();
    e.force_base = at_mean.force_mean;
  }
  const MagnitudeSpread spread = magnitude_spread(post);
  e.force_sigma_n = spread.sigma;
  e.force_lo_n = std::min(spread.lo, e.force_n);
  e.force_hi_n = std::max(spread.hi, e.force_n);
  e.force_determined = e.force_n > 0.0 && std::max(e.force_hi_n - e.force_n, e.force_n - e.force_lo_n) <= params.determined_rel_2sigma * e.force_n;
  e.line_direction_base = e.force_base.norm() > 1e-9 ? Eigen::Vector3d(e.force_base.normalized()) : Eigen::Vector3d::Zero();
  e.point_in_link = surface_point(arm, latest.q, e.link, segment_point(params, e.link - 1, 1.0), mean_s, e.force_base,
                                  params.surface_radius_m);
  const sim::LinkPoses poses = arm.poses(latest.q);
  e.point_base = poses.origin[i] + poses.rotation[i] * e.point_in_link;
  const Matrix At = jacobian_transposed(arm, latest.q, params, e.link - 1, mean_s);
  e.determined_components = weighted_rank(At, latest.sigma_nm);
  const Vector r = (latest.tau_nm - At * force_at(arm, latest, e.link, segment_point(params, e.link - 1, mean_s))).cwiseQuotient(latest.sigma_nm);
  e.residual_chi2 = r.squaredNorm();
}

Eigen::Vector3d force_with_prior(const sim::ArmDynamics& arm, const TorqueObservation& obs, int link,
                                 const Eigen::Vector3d& point_in_link, const ContactEstimatorParams& params) {
  check_link(arm, link);
  const Matrix At = arm.point_jacobian(obs.q, link - 1, point_in_link).transpose();
  return candidate(At, obs.tau_nm, obs.sigma_nm, force_prior(arm, obs.q, link, params)).force_mean;
}

}  // namespace jg::detection
