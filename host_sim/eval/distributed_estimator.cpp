#include "eval/distributed_estimator.hpp"

#include <stdexcept>
#include <vector>

#include "eval/joint_params.hpp"
#include "jointguard/node/joint_drive.hpp"

namespace jg::eval {
namespace {

/// Drives poll their ports this many times per period (an interrupt-driven MCU reacts
/// within a fraction of the period; the exact instant only shifts frames within the cycle).
constexpr int kPollsPerCycle = 20;

template <class S>
class BusEstimator final : public DistributedEstimator {
 public:
  explicit BusEstimator(const DistributedConfig& c)
      : config_(c), bus_(c.timing, c.faults), master_port_(bus_.attach()),
        master_(master_port_, c.estimator.model.joints.size()) {
    const auto& fc = c.estimator;
    const std::size_t n = fc.model.joints.size();
    if (!c.node_thresholds.empty() && c.node_thresholds.size() != n) {
      throw std::invalid_argument("distributed nodes: one threshold band per joint required");
    }
    const Vec3<S> gravity = gravity_of<S>(fc.model);
    for (std::size_t j = 0; j < n; ++j) {
      const JointThreshold<double>* band = c.node_thresholds.empty() ? nullptr : &c.node_thresholds[j];
      const HoldChangeParams<double>* hold = j < c.node_hold.size() ? &c.node_hold[j] : nullptr;
      const JointEstimatorParams<S> p = joint_params<S>(fc, j, band, c.debounce_cycles, hold);
      DriveConfig dc{NodeConfig{static_cast<std::uint8_t>(j + 1), static_cast<std::uint8_t>(n), c.fault_cycles}, true};
      // A drive's node refers to the drive's relay port: drives never move.
      drives_.push_back(std::make_unique<JointDrive<S, can::SimPort>>(dc, p, bus_.attach(), gravity));
    }
  }
  void reset(const EstimatorInput&) override {}
  void step(const EstimatorInput& in, sim::JointVector& mu) override {
    const double dt = config_.estimator.dt;
    bus_.run_until(time_);
    master_.send_cycle(cycle_, in.q.data(), in.dq.data(), in.tau_m.data(), in.holding);
    for (int k = 1; k <= kPollsPerCycle; ++k) {
      bus_.run_until(time_ + dt * k / kPollsPerCycle);
      for (auto& d : drives_) (void)d->poll();
      if (master_.collect()) break;
    }
    if (!master_.complete()) ++incomplete_;
    master_.end_cycle();
    const auto& torque = master_.external_torque();
    mu.resize(static_cast<Eigen::Index>(torque.size()));
    for (std::size_t j = 0; j < torque.size(); ++j) mu(static_cast<Eigen::Index>(j)) = torque[j];
    ++cycle_;
    time_ += dt;
  }
  [[nodiscard]] std::string name() const override {
    return std::string("drives on a simulated CAN FD bus (") + (is_q_v<S> ? "Q16.16" : "float") + ")";
  }
  [[nodiscard]] JointMask reported_flags() const override { return master_.flagged(); }
  can::SimBus& bus() override { return bus_; }
  [[nodiscard]] bool communication_fault() const override { return master_.any_comm_fault(); }
  [[nodiscard]] BusStatistics statistics() const override {
    BusStatistics s{bus_.frames_sent(), bus_.busy_time(), time_, master_.counters(), incomplete_, master_.events(), {}};
    for (const auto& d : drives_) {
      s.drives.push_back({d->counters(), d->node().counters(), d->node().communication_fault(), d->node().ready()});
    }
    return s;
  }

 private:
  DistributedConfig config_;
  can::SimBus bus_;
  can::SimPort& master_port_;
  hil::BusMaster<can::SimPort> master_;
  std::vector<std::unique_ptr<JointDrive<S, can::SimPort>>> drives_;
  std::uint32_t cycle_ = 0;
  std::size_t incomplete_ = 0;
  double time_ = 0.0;
};

}  // namespace

std::unique_ptr<DistributedEstimator> make_distributed_estimator(const DistributedConfig& c, const std::string& scalar) {
  if (scalar == "float") return std::make_unique<BusEstimator<float>>(c);
  if (scalar == "q") return std::make_unique<BusEstimator<q16>>(c);
  throw std::invalid_argument("scalar must be 'float' or 'q', got '" + scalar + "'");
}

}  // namespace jg::eval
