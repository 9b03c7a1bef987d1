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
    master_.send_cycle(cycle_, in.q.data(), in.dq.data(), in.tau_m.data());
    const hal::MonotonicClock clock;
    const std::uint64_t start = clock.now_us();
    const bool first = cycle_ == 0;
    const std::uint64_t limit = 1000ULL * static_cast<std::uint64_t>(first ? config_.startup_timeout_ms : config_.cycle_timeout_ms);
    std::uint64_t last_send = start;
    while (!master_.collect()) {
      const std::uint64_t now = clock.now_us();
      if (now - start > limit) {
        throw std::runtime_error("socketcan " + config_.interface + ": no status from joint(s) " + joint_list(master_.missing()) +
                                 " for cycle " + std::to_string(cycle_) + " within " + std::to_string(limit / 1000) +
                                 " ms (is `jointguard node --joint J --iface " + config_.interface + "` running for each joint?)");
      }
      if (first && now - last_send > 200000ULL) {  // drives that start after the plant
        master_.send_cycle(cycle_, in.q.data(), in.dq.data(), in.tau_m.data(), true);
        last_send = now;
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
