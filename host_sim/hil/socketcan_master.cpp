#include "hil/socketcan_master.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <deque>
#include <thread>

#include "eval/bus_reaction.hpp"
#include "jointguard/hal/socketcan.hpp"

namespace jg::hil {
namespace {

std::string joint_list(const std::vector<int>& joints) {
  std::string s;
  for (const int j : joints) s += (s.empty() ? "" : ", ") + std::to_string(j);
  return s;
}

/// A babbling node (`babble[:0xID]@START[:DURATION]`): its own socket on the interface,
/// sending the identifier with a garbage payload (fails every check) as fast as the host
/// lets it while `on` is set. On a real bus it would win every arbitration; a virtual CAN
/// interface has no arbitration, so its frames merely flood every receiver that accepts
/// them (the master: 0x000-0x00F are collision events), and the master's port emulates
/// the arbitration its controller loses (FaultyPort::bus_busy).
class Babbler {
 public:
  Babbler(const std::string& iface, std::uint32_t id) : port_(iface) {
    frame_.fd = true;
    frame_.id = id;
    frame_.length = 8;
    frame_.data[0] = 0xA5U;
    const hal::CanFilter none{0x1FFFFFFFU, 0x1FFFFFFFU};  // an extended identifier nobody sends: it hears nothing
    port_.set_filters(&none, 1);
    thread_ = std::thread([this] { run(); });
  }
  ~Babbler() {
    quit_ = true;
    thread_.join();
  }
  Babbler(const Babbler&) = delete;
  Babbler& operator=(const Babbler&) = delete;
  Babbler(Babbler&&) = delete;
  Babbler& operator=(Babbler&&) = delete;
  void set_on(bool on) { on_ = on; }
  [[nodiscard]] std::uint64_t sent() const { return sent_; }

 private:
  void run() {
    while (!quit_) {
      if (!on_) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        continue;
      }
      if (port_.send(frame_) == hal::CanStatus::ok) {
        sent_.fetch_add(1, std::memory_order_relaxed);
      } else {
        std::this_thread::yield();  // the interface's queue is full: the bus is saturated
      }
    }
  }
  hal::SocketCanPort port_;
  hal::CanFrame frame_{};
  std::atomic<bool> on_{false}, quit_{false};
  std::atomic<std::uint64_t> sent_{0};
  std::thread thread_;
};

/// The master's port with its own faults applied (plant time set each cycle): frames it
/// sends dropped, corrupted or duplicated; link down: nothing sent, nothing read. With a
/// babbler in the run it emulates arbitration, which a virtual CAN bus does not have: a
/// frame loses arbitration (refused: queue_full, the master drops it at the end of its
/// cycle) when, over this cycle and the previous one, the port has heard more frames with
/// a lower identifier than the protocol ever sends in that time (kBusyFrames: a cycle
/// carries at most n statuses and n collision events, n <= 7): the bus was never idle.
class FaultyPort {
 public:
  FaultyPort(const std::string& iface, const std::vector<FaultSpec>& faults) : port_(iface), faults_(faults) {
    for (const FaultSpec& f : faults) arbitrate_ = arbitrate_ || f.kind == FaultKind::babble;
  }
  /// A new cycle (plant time t): the arbitration window moves on by one cycle.
  void set_time(double t) {
    t_ = t;
    previous_ = std::move(current_);
    current_.clear();
  }
  [[nodiscard]] bool link_down() const { return active(FaultKind::link_down, 0); }
  hal::CanStatus send(const hal::CanFrame& f) {
    if (link_down()) return hal::CanStatus::bus_off;
    if (arbitrate_ && bus_busy(f.id)) {
      ++lost_arbitration_;
      return hal::CanStatus::queue_full;
    }
    if (active(FaultKind::drop, f.id)) return hal::CanStatus::ok;  // lost on the wire
    hal::CanFrame out = f;
    if (active(FaultKind::corrupt, f.id) && out.length > 0) out.data[out.length / 2U] ^= 0x04U;
    const hal::CanStatus st = port_.send(out);
    if (st == hal::CanStatus::ok && active(FaultKind::duplicate, f.id)) (void)port_.send(out);
    return st;
  }
  bool receive(hal::CanFrame& f) {
    if (link_down()) {
      rx_.clear();
      while (port_.receive(f)) {
      }  // deaf while the link is down: what arrives is lost
      return false;
    }
    if (!rx_.empty()) {
      f = rx_.front();
      rx_.pop_front();
      return true;
    }
    if (!port_.receive(f)) return false;
    if (arbitrate_) note(f.id);
    return true;
  }
  [[nodiscard]] hal::CanErrorState error_state() const { return port_.error_state(); }
  void set_filters(const hal::CanFilter* filters, std::size_t n) { port_.set_filters(filters, n); }
  [[nodiscard]] bool wait_readable(std::int64_t timeout_us) const { return !rx_.empty() || port_.wait_readable(timeout_us); }
  [[nodiscard]] std::uint64_t lost_arbitration() const { return lost_arbitration_; }

 private:
  static constexpr std::size_t kBusyFrames = 32;  ///< > 2 x (7 statuses + 7 events) + announcements
  static constexpr std::size_t kRxQueue = 4096;   ///< frames read ahead while checking the bus (then: overrun)
  static constexpr std::size_t kNoted = 1024;     ///< identifiers kept per cycle (the count saturates beyond)
  /// Reads what is queued on the socket (kept for receive()) and tells whether frames with
  /// an identifier below `id` kept the bus busy.
  bool bus_busy(std::uint32_t id) {
    hal::CanFrame f{};
    while (port_.receive(f)) {
      note(f.id);
      if (rx_.size() < kRxQueue) rx_.push_back(f);
    }
    std::size_t n = 0;
    for (const auto* ids : {&previous_, &current_}) {
      for (const std::uint32_t other : *ids) n += other < id ? 1U : 0U;
    }
    return n > kBusyFrames;
  }
  void note(std::uint32_t id) {
    if (current_.size() < kNoted) current_.push_back(id);
  }
  [[nodiscard]] bool active(FaultKind kind, std::uint32_t id) const {
    for (const FaultSpec& f : faults_) {
      if (f.kind != kind || !f.active(t_)) continue;
      if (f.has_id && f.id != id) continue;
      if (f.joint > 0 && id != protocol::frame_id(protocol::MessageKind::sensor, static_cast<std::uint8_t>(f.joint))) continue;
      return true;
    }
    return false;
  }
  hal::SocketCanPort port_;
  std::vector<FaultSpec> faults_;
  double t_ = 0.0;
  bool arbitrate_ = false;
  std::deque<hal::CanFrame> rx_;
  std::vector<std::uint32_t> previous_, current_;  ///< identifiers heard in the previous and this cycle
  std::uint64_t lost_arbitration_ = 0;
};

class SocketCanMasterImpl final : public SocketCanMaster {
 public:
  explicit SocketCanMasterImpl(const SocketCanMasterConfig& c)
      : config_(c), port_(c.interface, c.faults), master_(port_, c.joints), answered_(c.joints, true) {
    for (const FaultSpec& f : c.faults) {
      if (f.kind == FaultKind::babble && !babbler_) babbler_ = std::make_unique<Babbler>(c.interface, f.id);
    }
  }
  ~SocketCanMasterImpl() override {
    if (babbler_) {
      std::fprintf(stderr, "socketcan %s: babbler sent %llu frames; the master lost arbitration %llu times\n", config_.interface.c_str(),
                   static_cast<unsigned long long>(babbler_->sent()), static_cast<unsigned long long>(port_.lost_arbitration()));
    }
  }
  SocketCanMasterImpl(const SocketCanMasterImpl&) = delete;
  SocketCanMasterImpl& operator=(const SocketCanMasterImpl&) = delete;
  SocketCanMasterImpl(SocketCanMasterImpl&&) = delete;
  SocketCanMasterImpl& operator=(SocketCanMasterImpl&&) = delete;
  void reset(const eval::EstimatorInput&) override {}
  void step(const eval::EstimatorInput& in, sim::JointVector& mu) override {
    const hal::MonotonicClock clock;
    const double t = static_cast<double>(cycle_) * config_.period_s;
    port_.set_time(t);
    if (babbler_) {
      bool on = false;
      for (const FaultSpec& f : config_.faults) on = on || (f.kind == FaultKind::babble && f.active(t));
      babbler_->set_on(on);
    }
    if (cycle_ == 0) wait_for_announcements(clock);
    eval::EstimatorInput sample = in;
    for (const FaultSpec& f : config_.faults) {
      if (f.kind != FaultKind::nan_sensor || !f.active(t)) continue;
      for (Eigen::Index j = 0; j < sample.q.size(); ++j) {
        if (f.joint == 0 || f.joint == j + 1) sample.q(j) = sample.dq(j) = sample.tau_m(j) = std::numeric_limits<double>::quiet_NaN();
      }
    }
    master_.send_cycle(cycle_, sample.q.data(), sample.dq.data(), sample.tau_m.data(), in.holding);
    wait_for_statuses(clock);
    for (std::size_t j = 0; j < answered_.size(); ++j) answered_[j] = !contains(master_.missing(), static_cast<int>(j + 1));
    master_.end_cycle();
    if (!master_.complete() && master_.missing_run() == 1) {
      std::fprintf(stderr, "socketcan %s: cycle %u closed without joint(s) %s: the master keeps syncing (5 such cycles: communication fault, hold)\n",
                   config_.interface.c_str(), cycle_, joint_list(master_.missing()).c_str());
    }
    const auto& torque = master_.external_torque();
    mu.resize(static_cast<Eigen::Index>(torque.size()));
    for (std::size_t j = 0; j < torque.size(); ++j) mu(static_cast<Eigen::Index>(j)) = torque[j];
    ++cycle_;
  }
  [[nodiscard]] std::string name() const override { return "drives as processes on SocketCAN " + config_.interface; }

  /// Lock-step: the cycle closes when every drive's status is in. A drive that answered the
  /// previous cycle is waited for up to cycle_timeout_ms (a loaded host may be slow); one
  /// already silent, rebooting (it missed this sync), or a sync that never went out only
  /// briefly, so the master keeps syncing while it holds and a restarted drive rejoins from
  /// the next sync.
  void wait_for_statuses(const hal::MonotonicClock& clock) {
    const std::uint64_t start = clock.now_us();
    const std::uint64_t full = 1000ULL * static_cast<std::uint64_t>(config_.cycle_timeout_ms);
    // A drive already silent gets a tenth of the full wait (at least a plant period): long
    // enough for a loaded host to catch up, short enough to keep syncing while holding.
    const auto brief = static_cast<std::uint64_t>(std::max(config_.period_s * 1e6, static_cast<double>(full) / 10.0));
    while (!master_.collect()) {
      bool wait_long = master_.sync_sent() && !port_.link_down();
      bool any_expected = false;
      for (const int j : master_.missing()) {
        const bool expected = answered_[static_cast<std::size_t>(j - 1)] && !master_.rejoining(j);
        any_expected = any_expected || expected;
      }
      wait_long = wait_long && any_expected;
      const std::uint64_t elapsed = clock.now_us() - start;
      if (elapsed > (wait_long ? full : brief)) return;
      (void)port_.wait_readable(static_cast<std::int64_t>(std::min<std::uint64_t>(wait_long ? 50000 : brief, 50000)));
    }
  }
  static bool contains(const std::vector<int>& v, int x) {
    for (const int e : v) {
      if (e == x) return true;
    }
    return false;
  }

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
  [[nodiscard]] bool input_fault() const override { return master_.any_input_fault(); }
  bool command_reaction(Reaction reaction, JointMask collided, const sim::JointVector& retreat_target) override {
    return eval::command_bus_reaction(master_, reaction, collided, retreat_target);
  }
  [[nodiscard]] bool reaction_torque(sim::JointVector& torque) const override { return eval::bus_reaction_torque(master_, torque); }
  [[nodiscard]] const std::vector<NodeEvent>& events() const override { return master_.events(); }
  [[nodiscard]] MasterCounters counters() const override { return master_.counters(); }
  [[nodiscard]] std::vector<std::int64_t> first_comm_fault_cycle() const override { return master_.first_comm_fault_cycle(); }
  [[nodiscard]] std::vector<FaultEpisode> fault_episodes() const override { return master_.fault_episodes(); }

 private:
  SocketCanMasterConfig config_;
  FaultyPort port_;
  std::unique_ptr<Babbler> babbler_;
  BusMaster<FaultyPort> master_;
  std::vector<bool> answered_;
  std::uint32_t cycle_ = 0;
};

}  // namespace

void check_socketcan_faults(const std::vector<FaultSpec>& faults) {
  for (const FaultSpec& f : faults) {
    const char* why = nullptr;
    switch (f.kind) {
      case FaultKind::late: why = "a drive's frames are held back by the drive: `jointguard node --joint J --fault late@START:DURATION`"; break;
      case FaultKind::bus_off: why = "a drive's controller is in its own process: `jointguard node --joint J --fault bus-off:J@START:DURATION`"; break;
      case FaultKind::restart:
        why = "restart the `jointguard node --joint J` process itself: the master keeps syncing and the drive rejoins from the next sync";
        break;
      default: break;
    }
    if (why != nullptr) throw std::invalid_argument("--fault '" + f.text + "': not injectable by the SocketCAN master: " + why);
    if ((f.kind == FaultKind::drop || f.kind == FaultKind::corrupt || f.kind == FaultKind::duplicate) && f.has_id &&
        f.id != protocol::kSyncId && protocol::kind_of(f.id) != protocol::MessageKind::sensor) {
      throw std::invalid_argument("--fault '" + f.text + "': on SocketCAN the master acts only on the frames it sends (sync 0x010, sensor 0x06j)");
    }
  }
}

std::unique_ptr<SocketCanMaster> make_socketcan_master(const SocketCanMasterConfig& c) {
  return std::make_unique<SocketCanMasterImpl>(c);
}

}  // namespace jg::hil
