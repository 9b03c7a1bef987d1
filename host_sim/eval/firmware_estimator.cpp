#include "eval/firmware_estimator.hpp"

#include "eval/joint_params.hpp"

#include <cmath>
#include <stdexcept>

#include "plant/sensors.hpp"
#include <vector>

namespace jg::eval {
namespace {

template <class S>
class FirmwareEstimator final : public Estimator {
 public:
  explicit FirmwareEstimator(const FirmwareEstimatorConfig& c) : n_(c.model.joints.size()) {
    params_.resize(n_);
    state_.resize(n_);
    for (std::size_t j = 0; j < n_; ++j) {
      params_[j] = joint_params<S>(c, j);  // detection is done by the evaluation
    }
    gravity_ = gravity_of<S>(c.model);
    deadband_steps_ = c.holding_deadband_steps;
    velocity_step_.assign(n_, 0.0);
  }
  void reset(const EstimatorInput&) override {
    for (auto& s : state_) s = JointEstimatorState<S>{};
  }
  void step(const EstimatorInput& in, sim::JointVector& mu) override {
    if (deadband_steps_ > 0.0) measure_velocity_step(in.dq);
    NumericStatus st;
    OutwardMessage<S> msg = base_message(gravity_);
    for (std::size_t j = 0; j < n_; ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      OutwardMessage<S> next{};
      (void)joint_outward(params_[j], state_[j], from_float<S>(static_cast<float>(in.q(i)), st),
                          from_float<S>(static_cast<float>(in.dq(i)), st), ((in.holding >> j) & 1U) != 0U, msg, next);
      msg = next;
    }
    InwardMessage<S> back = tip_message<S>();
    mu.resize(static_cast<Eigen::Index>(n_));
    for (std::size_t j = n_; j-- > 0;) {
      const auto i = static_cast<Eigen::Index>(j);
      InwardMessage<S> up{};
      (void)joint_inward_and_estimate(params_[j], state_[j], from_float<S>(static_cast<float>(in.dq(i)), st),
                                      from_float<S>(static_cast<float>(in.tau_m(i)), st), ((in.holding >> j) & 1U) != 0U,
                                      back, up);
      back = up;
      mu(i) = to_double(state_[j].external_torque);
    }
  }
  [[nodiscard]] std::string name() const override { return is_q_v<S> ? "firmware core (Q16.16)" : "firmware core (float)"; }

 private:
  /// The velocity step per joint, the smallest non-zero |dq| given so far (kept across
  /// resets: the encoder's), and the deadband as that many steps. The sample that first
  /// shows a smaller step is already judged against it, so a first single-count sample is
  /// zeroed exactly as with the step known beforehand.
  void measure_velocity_step(const sim::JointVector& dq) {
    for (std::size_t j = 0; j < n_; ++j) {
      const double w = std::fabs(dq(static_cast<Eigen::Index>(j)));
      if (!(w > 0.0) || (velocity_step_[j] > 0.0 && w >= velocity_step_[j])) continue;
      velocity_step_[j] = w;
      NumericStatus st;
      params_[j].holding_velocity_deadband = convert<S>(deadband_steps_ * w, st);
      if (!st.ok()) throw std::invalid_argument("joint " + std::to_string(j + 1) + ": holding velocity deadband does not fit the scalar");
    }
  }

  std::size_t n_;
  std::vector<JointEstimatorParams<S>> params_;
  std::vector<JointEstimatorState<S>> state_;
  Vec3<S> gravity_{};
  double deadband_steps_ = 0.0;
  std::vector<double> velocity_step_;  ///< [rad/s] per joint; 0 until the joint has moved
};

}  // namespace

std::vector<double> holding_deadband(const robot::RobotModel& model, double rate_hz) {
  const sim::SensorConfig sensors;
  const auto drives = model.drives();
  std::vector<double> out;
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const double gear = j < drives.size() ? drives[j].gear_ratio : 100.0;
    out.push_back(1.5 * 2.0 * M_PI / sensors.motor_encoder_counts_per_rev / gear * rate_hz);
  }
  return out;
}

std::unique_ptr<Estimator> make_firmware_estimator(const FirmwareEstimatorConfig& c, const std::string& scalar) {
  if (scalar == "float") return std::make_unique<FirmwareEstimator<float>>(c);
  if (scalar == "q") return std::make_unique<FirmwareEstimator<q16>>(c);
  throw std::invalid_argument("scalar must be 'float' or 'q', got '" + scalar + "'");
}

namespace {
template <class S>
void check_friction_fits_in(const std::string& path, const std::vector<LuGreParams<double>>& friction,
                            const std::vector<int>& joint_ids, double dt, const char* scalar) {
  for (std::size_t j = 0; j < friction.size(); ++j) {
    LuGreDiscrete<S> d{};
    if (const Error e = discretize(friction[j], dt, d); e != Error::ok) {
      const auto& f = friction[j];
      const int id = j < joint_ids.size() ? joint_ids[j] : static_cast<int>(j + 1);
      throw std::invalid_argument(path + ": joint " + std::to_string(id) + ": LuGre parameters (sigma0 " + std::to_string(f.sigma0) +
                                  ", sigma1 " + std::to_string(f.sigma1) + ", sigma2 " + std::to_string(f.sigma2) + ", tau_c " +
                                  std::to_string(f.tau_c) + ", tau_s " + std::to_string(f.tau_s) + ", w_s " + std::to_string(f.w_s) +
                                  ") do not fit the firmware scalar " + scalar + " at dt = " + std::to_string(dt) + " s: " +
                                  to_string(e));
    }
  }
}
}  // namespace

void check_friction_fits(const std::string& path, const std::vector<LuGreParams<double>>& friction,
                         const std::vector<int>& joint_ids, double dt, const std::string& scalar) {
  if (scalar == "float") return check_friction_fits_in<float>(path, friction, joint_ids, dt, "float");
  if (scalar == "q") return check_friction_fits_in<q16>(path, friction, joint_ids, dt, "q (Q16.16)");
  throw std::invalid_argument("scalar must be 'float' or 'q', got '" + scalar + "'");
}

}  // namespace jg::eval
