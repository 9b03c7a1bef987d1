#include "eval/distributed_estimator.hpp"

#include <stdexcept>
#include <vector>

#include "jointguard/node/joint_node.hpp"

namespace jg::eval {
namespace {

template <class S>
class DistributedEstimator final : public Estimator {
 public:
  DistributedEstimator(const DistributedConfig& c) : config_(c), bus_(c.timing, c.faults) {
    const auto& fc = c.estimator;
    const std::size_t n = fc.model.joints.size();
    NumericStatus st;
    const Vec3<S> gravity{convert<S>(fc.model.gravity[0], st), convert<S>(fc.model.gravity[1], st), convert<S>(fc.model.gravity[2], st)};
    for (std::size_t j = 0; j < n; ++j) {
      JointEstimatorParams<S> p{};
      if (convert_link(fc.model.joints[j].link, p.link) != Error::ok) throw std::invalid_argument("link constants do not fit the scalar");
      p.compensate_friction = fc.compensate_friction && j < fc.friction.size();
      if (p.compensate_friction && discretize(fc.friction[j], fc.dt, p.friction) != Error::ok) throw std::invalid_argument("LuGre does not fit");
      if (discretize(fc.observer, fc.dt, p.observer) != Error::ok) throw std::invalid_argument("observer does not fit");
      p.threshold = {from_double<S>(1e4), S{}};
      ports_.push_back(&bus_.attach());
      nodes_.emplace_back(NodeConfig{static_cast<std::uint8_t>(j + 1), static_cast<std::uint8_t>(n), 5}, p, *ports_.back(), gravity);
    }
  }
  void reset(const EstimatorInput&) override {}
  void step(const EstimatorInput& in, sim::JointVector& mu) override {
    NumericStatus st;
    bus_.run_until(time_);  // deliver what was sent during the previous cycle
    mu.resize(static_cast<Eigen::Index>(nodes_.size()));
    for (std::size_t j = 0; j < nodes_.size(); ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      (void)nodes_[j].cycle(from_float<S>(static_cast<float>(in.q(i)), st), from_float<S>(static_cast<float>(in.dq(i)), st),
                            from_float<S>(static_cast<float>(in.tau_m(i)), st));
      mu(i) = to_double(nodes_[j].state().external_torque);
    }
    time_ += config_.estimator.dt;
  }
  [[nodiscard]] std::string name() const override { return "distributed nodes on a simulated CAN FD bus"; }
  [[nodiscard]] const std::vector<JointNode<S, can::SimPort>>& nodes() const { return nodes_; }

 private:
  DistributedConfig config_;
  can::SimBus bus_;
  std::vector<can::SimPort*> ports_;
  std::vector<JointNode<S, can::SimPort>> nodes_;
  double time_ = 0.0;
};

}  // namespace

std::unique_ptr<Estimator> make_distributed_estimator(const DistributedConfig& c, const std::string& scalar) {
  if (scalar == "float") return std::make_unique<DistributedEstimator<float>>(c);
  if (scalar == "q") return std::make_unique<DistributedEstimator<q16>>(c);
  throw std::invalid_argument("scalar must be 'float' or 'q'");
}

}  // namespace jg::eval
