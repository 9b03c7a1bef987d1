#include <cmath>
#include <stdexcept>

#include "eval/estimator.hpp"

namespace jg::eval {
namespace {

class ReferenceEstimator final : public Estimator {
 public:
  explicit ReferenceEstimator(ReferenceEstimatorConfig c) : c_(std::move(c)), arm_(c_.links, c_.gravity) {
    const auto n = static_cast<std::size_t>(arm_.joints());
    if (c_.gain.size() != n) throw std::invalid_argument("reference estimator: one observer gain per joint");
    if (c_.compensate_friction && c_.friction.size() != n) throw std::invalid_argument("reference estimator: friction per joint needed");
    lugre_.resize(n);
    state_.resize(n);
    for (std::size_t j = 0; j < n && c_.compensate_friction; ++j) {
      if (discretize(c_.friction[j], c_.dt, lugre_[j]) != Error::ok) throw std::invalid_argument("reference estimator: invalid LuGre");
    }
  }
  void reset(const EstimatorInput& first) override {
    const Eigen::Index n = first.q.size();
    integral_ = sim::JointVector::Zero(n);
    r_ = sim::JointVector::Zero(n);
    p0_ = momentum(first.q, first.dq);
    for (auto& s : state_) s = LuGreState<double>{};
  }
  void step(const EstimatorInput& in, sim::JointVector& mu) override {
    const Eigen::Index n = in.q.size();
    const sim::JointVector p = momentum(in.q, in.dq);
    const sim::JointVector beta = beta_of(in.q, in.dq);
    sim::JointVector friction = sim::JointVector::Zero(n);
    for (Eigen::Index j = 0; j < n && c_.compensate_friction; ++j) {
      friction(j) = lugre_step(lugre_[static_cast<std::size_t>(j)], state_[static_cast<std::size_t>(j)], in.dq(j));
    }
    // p' = tau_m - beta - d with d = tau_f - tau_ext (tau_ext: torque the contact exerts
    // on the arm, J^T F). r = K (integral(tau_m - beta - f - r) - (p - p0)) gives
    // r' = K (d - f - r): r follows d - f = -tau_ext when the prediction f matches tau_f.
    integral_ += (in.tau_m - beta - friction - r_) * c_.dt;
    for (Eigen::Index j = 0; j < n; ++j) r_(j) = c_.gain[static_cast<std::size_t>(j)] * (integral_(j) - (p(j) - p0_(j)));
    mu = -r_;
  }
  [[nodiscard]] std::string name() const override { return "reference (double, centralised)"; }

 private:
  sim::JointVector momentum(const sim::JointVector& q, const sim::JointVector& dq) const { return arm_.mass_matrix(q) * dq; }
  sim::JointVector beta_of(const sim::JointVector& q, const sim::JointVector& dq) const {
    // beta = g - C^T dq = h - M' dq with h = C dq + g (RNEA at zero acceleration).
    const sim::JointVector h = arm_.inverse_dynamics(q, dq, sim::JointVector::Zero(q.size()));
    const double eps = 1e-6;
    const sim::JointMatrix mdot = (arm_.mass_matrix(q + eps * dq) - arm_.mass_matrix(q - eps * dq)) / (2.0 * eps);
    return h - mdot * dq;
  }
  ReferenceEstimatorConfig c_;
  sim::ArmDynamics arm_;
  std::vector<LuGreDiscrete<double>> lugre_;
  std::vector<LuGreState<double>> state_;
  sim::JointVector integral_, r_, p0_;
};

}  // namespace

std::unique_ptr<Estimator> make_reference_estimator(const ReferenceEstimatorConfig& c) {
  return std::make_unique<ReferenceEstimator>(c);
}

}  // namespace jg::eval
