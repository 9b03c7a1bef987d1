#include "hil/socketcan_master.hpp"

#include <stdexcept>

#include "jointguard/hal/socketcan.hpp"

namespace jg::hil {
namespace {

std::string joint_list(const std::vector<int>& joints) {
  std::string s;
  for (const int j : joints) s += (s.empty() ? "" : ", ") + std::to_string(j);
  return s;
}

class SocketCanMasterImpl final : public SocketCanMaster {
 public:
  explicit SocketCanMasterImpl(const SocketCanMasterConfig& c) : config_(c), port_(c.interface), master_(port_, c.joints) {}
  void reset(const eval::EstimatorInput&) override {}
  void step(const eval::EstimatorInput& in, sim::JointVector& mu) override {
    const hal::MonotonicClock clock;
    if (cycle_ == 0) wait_for_announcements(clock);
    master_.send_cycle(cycle_, in.q.data(), in.dq.data(), in.tau_m.data(), in.holding);
    const std::uint64_t start = clock.now_us();
    const std::uint64_t limit = 1000ULL * static_cast<std::uint64_t>(config_.cycle_timeout_ms);
    while (!master_.collect()) {
      if (clock.now_us() - start > limit) {
        throw std::runtime_error("socketcan " + config_.interface + ": no status from joint(s) " + joint_list(master_.missing()) +
                                 " for cycle " + std::to_string(cycle_) + " within " + std::to_string(limit / 1000) + " ms");
      }
      (void)port_.wait_readable(50000);
    }
    master_.end_cycle();
    const auto& torque = master_.external_torque();
    mu.resize(static_cast<Eigen::Index>(torque.size()));
    for (std::size_t j = 0; j < torque.size(); ++j) mu(static_cast<Eigen::Index>(j)) = torque[j];
    ++cycle_;
  }
  [[nodiscard]] std::string name() const override { return "drives as processes on SocketCAN " + config_.interface; }

  /// The bus starts only when every drive listens (each announces itself until the first
  /// sync), so a start-up does not depend on the order the processes came up in.
  void wait_for_announcements(const hal::MonotonicClock& clock) {
    const std::uint64_t start = clock.now_us();
    while (!(master_.collect(), master_.all_announced())) {
      if (clock.now_us() - start > 1000ULL * static_cast<std::uint64_t>(config_.startup_timeout_ms)) {
        throw std::runtime_error("socketcan " + config_.interface + ": joint(s) " + joint_list(master_.not_announced()) +
                                 " did not announce themselves within " + std::to_string(config_.startup_timeout_ms / 1000) +
                                 " s (is `jointguard node --joint J --iface " + config_.interface + "` running for each joint?)");
      }
      (void)port_.wait_readable(50000);
    }
  }
  [[nodiscard]] JointMask reported_flags() const override { return master_.flagged(); }
  [[nodiscard]] bool communication_fault() const override { return master_.any_comm_fault(); }
  [[nodiscard]] const std::vector<NodeEvent>& events() const override { return master_.events(); }
  [[nodiscard]] MasterCounters counters() const override { return master_.counters(); }

 private:
  SocketCanMasterConfig config_;
  hal::SocketCanPort port_;
  BusMaster<hal::SocketCanPort> master_;
  std::uint32_t cycle_ = 0;
};

}  // namespace

std::unique_ptr<SocketCanMaster> make_socketcan_master(const SocketCanMasterConfig& c) {
  return std::make_unique<SocketCanMasterImpl>(c);
}

}  // namespace jg::hil
