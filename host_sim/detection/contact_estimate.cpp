#include "detection/contact_estimate.hpp"

#include "detection/contact_point.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace jg::detection {
namespace {
using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

/// J^T of a point (s, 0, 0) on link `link` (0-based): n x 3.
Matrix jacobian_transposed(const sim::ArmDynamics& arm, const sim::JointVector& q, int link, const Eigen::Vector3d& point) {
  return arm.point_jacobian(q, link, point).transpose();
}

void check(const sim::ArmDynamics& arm, const TorqueObservation& obs) {
  const auto n = static_cast<Eigen::Index>(arm.joints());
  if (obs.q.size() != n || obs.tau_nm.size() != n || obs.sigma_nm.size() != n) {
    throw std::invalid_argument("contact estimate: q, tau and sigma need one value per joint (" + std::to_string(n) + ")");
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!(obs.sigma_nm(j) > 0.0) || !std::isfinite(obs.tau_nm(j)) || !std::isfinite(obs.q(j))) {
      throw std::invalid_argument("contact estimate: joint " + std::to_string(j + 1) + ": sigma must be > 0, tau and q finite");
    }
  }
}

}  // namespace

int weighted_rank(const Eigen::MatrixXd& At, const Eigen::VectorXd& sigma) {
  // Singular values below 1e-6 of the largest count as zero.
  Matrix W = At;
  for (Eigen::Index j = 0; j < W.rows(); ++j) W.row(j) /= sigma(j);
  Eigen::JacobiSVD<Matrix> svd(W);
  svd.setThreshold(1e-6);
  return static_cast<int>(svd.rank());
}

ContactEstimatorParams default_contact_params(const std::vector<double>& reaches_m,
                                              const std::vector<Eigen::Vector3d>& axes) {
  ContactEstimatorParams p;
  for (std::size_t i = 0; i < reaches_m.size(); ++i) {
    const double length = std::max(reaches_m[i], 0.1);
    const Eigen::Vector3d axis = i < axes.size() && axes[i].norm() > 1e-9 ? axes[i].normalized() : Eigen::Vector3d::UnitX();
    p.segments.push_back({0.1 * length, length, axis});
  }
  return p;
}

Eigen::Vector3d segment_point(const ContactEstimatorParams& params, int link0, double along_m) {
  const auto i = static_cast<std::size_t>(link0);
  return (link0 >= 0 && i < params.segments.size() ? params.segments[i].axis : Eigen::Vector3d::UnitX()) * along_m;
}

EvidenceGrid make_grid(int joints, const ContactEstimatorParams& params) {
  if (static_cast<int>(params.segments.size()) < joints || params.points_per_link < 1 || !(params.force_prior_n > 0.0)) {
    throw std::invalid_argument("contact estimate: one segment per link, at least one point and a force prior > 0 N required");
  }
  EvidenceGrid g;
  const int points = params.points_per_link;
  for (int i = 0; i < joints; ++i) {
    const LinkSegment seg = params.segments[static_cast<std::size_t>(i)];
    std::vector<double> along;
    for (int k = 0; k < points; ++k) {
      along.push_back(points == 1 ? 0.5 * (seg.along_min_m + seg.along_max_m)
                                  : seg.along_min_m + (seg.along_max_m - seg.along_min_m) * k / (points - 1));
    }
    g.along_m.push_back(along);
    g.axis.push_back(seg.axis);
    g.chi2.emplace_back(along.size(), 0.0);
  }
  return g;
}

void accumulate(EvidenceGrid& grid, const sim::ArmDynamics& arm, const TorqueObservation& obs, double weight) {
  check(arm, obs);
  for (std::size_t i = 0; i < grid.along_m.size(); ++i) {
    for (std::size_t k = 0; k < grid.along_m[i].size(); ++k) {
      const Eigen::Vector3d point = grid.axis[i] * grid.along_m[i][k];
      const Matrix At = jacobian_transposed(arm, obs.q, static_cast<int>(i), point);
      const Vector r = (obs.tau_nm - At * force_at(arm, obs, static_cast<int>(i) + 1, point)).cwiseQuotient(obs.sigma_nm);
      grid.chi2[i][k] = std::max(grid.chi2[i][k], r.squaredNorm());
    }
  }
  grid.weight += weight;
}

ContactEstimate estimate_contact(const sim::ArmDynamics& arm, const TorqueObservation& obs,
                                 const ContactEstimatorParams& params, const EvidenceGrid* evidence) {
  check(arm, obs);
  const int n = arm.joints();
  EvidenceGrid own;
  if (evidence == nullptr) {
    own = make_grid(n, params);
    accumulate(own, arm, obs);
    evidence = &own;
  }
  if (static_cast<int>(evidence->along_m.size()) != n || !(evidence->weight > 0.0)) {
    throw std::invalid_argument("contact estimate: evidence of another arm, or empty");
  }
  ContactEstimate e;
  std::size_t best = static_cast<std::size_t>(n) - 1;
  bool found = false;
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
    const auto& c = evidence->chi2[i];
    const std::size_t k = static_cast<std::size_t>(std::min_element(c.begin(), c.end()) - c.begin());
    const double mean = c[k];
    e.link_chi2.push_back(mean);
    const Matrix At = jacobian_transposed(arm, obs.q, static_cast<int>(i), evidence->axis[i] * evidence->along_m[i][k]);
    const int dof = n - weighted_rank(At, obs.sigma_nm);
    const bool consistent = mean <= params.accept_chi2_per_dof * std::max(dof, 0) + 1e-12;
    if (consistent) e.links_consistent.push_back(static_cast<int>(i) + 1);
    if (!found && consistent) {
      best = i;
      found = true;
    }
  }
  e.link = static_cast<int>(best) + 1;
  // Within the link: the posterior over the points from the latest torques (linear-Gaussian
  // model, uniform prior along the segment), and the force there (contact_point.hpp).
  estimate_point_and_force(arm, obs, params, nullptr, e);
  return e;
}

Eigen::Vector3d force_at(const sim::ArmDynamics& arm, const TorqueObservation& obs, int link,
                         const Eigen::Vector3d& point_in_link) {
  check(arm, obs);
  if (link < 1 || link > arm.joints()) throw std::invalid_argument("contact estimate: no link " + std::to_string(link));
  Matrix W = jacobian_transposed(arm, obs.q, link - 1, point_in_link);
  Vector b = obs.tau_nm;
  for (Eigen::Index j = 0; j < W.rows(); ++j) {
    W.row(j) /= obs.sigma_nm(j);
    b(j) /= obs.sigma_nm(j);
  }
  Eigen::JacobiSVD<Matrix> svd(W, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(1e-6);  // minimum norm: the undetermined components are left at zero
  return svd.solve(b);
}

TorqueObservation summarize_window(const std::vector<WindowSample>& samples, double observer_gain_per_s) {
  if (samples.empty()) throw std::invalid_argument("contact estimate: empty window");
  const WindowSample& last = samples.back();
  TorqueObservation o{last.q, last.mu_nm, sim::JointVector::Zero(last.mu_nm.size())};
  const auto count = static_cast<double>(samples.size());
  double t_mean = 0.0;
  for (const auto& s : samples) t_mean += s.t / count;
  double stt = 0.0;
  for (const auto& s : samples) stt += (s.t - t_mean) * (s.t - t_mean);
  for (Eigen::Index j = 0; j < o.tau_nm.size(); ++j) {
    double mean = 0.0, sigma = 0.0;
    for (const auto& s : samples) {
      mean += s.mu_nm(j) / count;
      sigma += s.sigma_nm(j) / count;
    }
    double slope = 0.0;
    if (stt > 0.0) {
      for (const auto& s : samples) slope += (s.t - t_mean) * (s.mu_nm(j) - mean) / stt;
    }
    o.tau_nm(j) = mean + slope * (last.t - t_mean) + (observer_gain_per_s > 0.0 ? slope / observer_gain_per_s : 0.0);
    o.sigma_nm(j) = sigma;
  }
  return o;
}

}  // namespace jg::detection

namespace jg::detection {
namespace {
/// The weights c of the window's value in its samples: value = sum c_i mu_i (the line fit
/// at the last sample, advanced by `lead` [s]).
std::vector<double> window_weights(const std::vector<WindowSample>& samples, double lead) {
  const auto count = static_cast<double>(samples.size());
  double t_mean = 0.0;
  for (const auto& s : samples) t_mean += s.t / count;
  double stt = 0.0;
  for (const auto& s : samples) stt += (s.t - t_mean) * (s.t - t_mean);
  std::vector<double> c;
  const double at = samples.back().t - t_mean + lead;
  for (const auto& s : samples) c.push_back(1.0 / count + (stt > 0.0 ? (s.t - t_mean) * at / stt : 0.0));
  return c;
}

/// c^T R c with R_ik = exp(-K |t_i - t_k|) (K <= 0: white, R = I): the value's noise
/// variance over one sample's.
double noise_gain(const std::vector<WindowSample>& samples, const std::vector<double>& c, double gain_per_s) {
  double v = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const double r = gain_per_s > 0.0 ? std::exp(-gain_per_s * std::fabs(samples[i].t - samples[k].t)) : (i == k ? 1.0 : 0.0);
      v += c[i] * c[k] * r;
    }
  }
  return std::max(v, 0.0);
}
}  // namespace

TorqueObservation summarize_window_honest(const std::vector<WindowSample>& samples, const WindowModel& model,
                                          sim::JointVector* lag_sigma_nm) {
  const double K = model.observer_gain_per_s;
  const bool lag = model.lag_correction && K > 0.0;
  TorqueObservation o = summarize_window(samples, lag ? K : 0.0);
  const std::vector<double> c = window_weights(samples, lag ? 1.0 / K : 0.0);
  const double gain = noise_gain(samples, c, K);
  const std::vector<double> at_last = window_weights(samples, 0.0);
  sim::JointVector lags = sim::JointVector::Zero(o.tau_nm.size());
  for (Eigen::Index j = 0; j < o.tau_nm.size(); ++j) {
    // The lag correction: (value advanced by 1/K) - (value at the last sample) = slope / K.
    double correction = 0.0;
    for (std::size_t i = 0; lag && i < samples.size(); ++i) correction += (c[i] - at_last[i]) * samples[i].mu_nm(j);
    const double lag_sigma = model.lag_uncertainty * std::fabs(correction);
    const double noise = model.noise_scale * o.sigma_nm(j);
    o.sigma_nm(j) = std::sqrt(noise * noise * gain + lag_sigma * lag_sigma);
    lags(j) = lag_sigma;
  }
  if (lag_sigma_nm != nullptr) *lag_sigma_nm = lags;
  return o;
}

}  // namespace jg::detection
