#include "eval/distributed_estimator.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "eval/bus_reaction.hpp"
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
    for (std::size_t j = 0; j < n; ++j) {
      ports_.push_back(&bus_.attach());
      drives_.push_back(make_drive(j));
    }
    for (const hil::FaultSpec& f : c.fault_specs) add_bus_fault(f);
  }
  void reset(const EstimatorInput&) override {}
  void step(const EstimatorInput& in, sim::JointVector& mu) override {
    const double dt = config_.estimator.dt;
    bus_.run_until(time_);
    apply_drive_faults();
    if (nan_samples_) {
      EstimatorInput bad = in;
      for (const hil::FaultSpec& f : config_.fault_specs) {
        if (f.kind != hil::FaultKind::nan_sensor || !f.active(time_)) continue;
        for (Eigen::Index j = 0; j < bad.q.size(); ++j) {
          if (f.joint == 0 || f.joint == j + 1) bad.q(j) = bad.dq(j) = bad.tau_m(j) = std::numeric_limits<double>::quiet_NaN();
        }
      }
      send_cycle(bad);
    } else {
      send_cycle(in);
    }
    for (int k = 1; k <= kPollsPerCycle; ++k) {
      bus_.run_until(time_ + dt * k / kPollsPerCycle);
      for (auto& d : drives_) {
        if (d) (void)d->poll();
      }
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
  [[nodiscard]] bool input_fault() const override { return master_.any_input_fault(); }
  bool command_reaction(Reaction reaction, JointMask collided, const sim::JointVector& retreat_target) override {
    return command_bus_reaction(master_, reaction, collided, retreat_target);
  }
  [[nodiscard]] bool reaction_torque(sim::JointVector& torque) const override { return bus_reaction_torque(master_, torque); }
  [[nodiscard]] BusStatistics statistics() const override {
    BusStatistics s{bus_.frames_sent(), bus_.busy_time(), time_, master_.counters(), incomplete_, master_.events(), {}, {}, {}};
    for (const auto& d : drives_) {
      if (d) {
        s.drives.push_back({d->counters(), d->node().counters(), d->node().communication_fault(), d->node().ready()});
      } else {
        s.drives.push_back({});  // off (a restart under way)
      }
    }
    s.first_comm_fault_cycle = master_.first_comm_fault_cycle();
    s.fault_episodes = master_.fault_episodes();
    return s;
  }

 private:
  std::unique_ptr<JointDrive<S, can::SimPort>> make_drive(std::size_t j) const {
    const auto& fc = config_.estimator;
    const std::size_t n = fc.model.joints.size();
    const JointThreshold<double>* band = config_.node_thresholds.empty() ? nullptr : &config_.node_thresholds[j];
    const HoldChangeParams<double>* hold = j < config_.node_hold.size() ? &config_.node_hold[j] : nullptr;
    const JointEstimatorParams<S> p = joint_params<S>(fc, j, band, config_.debounce_cycles, hold);
    const DriveConfig dc{NodeConfig{static_cast<std::uint8_t>(j + 1), static_cast<std::uint8_t>(n), config_.fault_cycles},
                         config_.sensors_over_can};
    // A drive's node refers to the drive's relay port: drives never move.
    auto d = std::make_unique<JointDrive<S, can::SimPort>>(dc, p, *ports_[j], gravity_of<S>(fc.model));
    d->set_reaction_gains(reaction_gains<S>(fc.dt, config_.retreat_s, config_.reflex_s));
    return d;
  }

  /// The cycle's samples (as sensor frames, or into each drive) and its sync.
  void send_cycle(const EstimatorInput& in) {
    if (config_.sensors_over_can) {
      master_.send_cycle(cycle_, in.q.data(), in.dq.data(), in.tau_m.data(), in.holding);
      return;
    }
    for (std::size_t j = 0; j < drives_.size(); ++j) {
      const auto i = static_cast<Eigen::Index>(j);
      if (drives_[j]) {
        drives_[j]->set_sample(from_double<S>(in.q(i)), from_double<S>(in.dq(i)), from_double<S>(in.tau_m(i)),
                               ((in.holding >> j) & 1U) != 0U);
      }
    }
    master_.send_sync_only(cycle_);
  }

  /// Frame faults, babble and link down act on the bus itself over their windows.
  void add_bus_fault(const hil::FaultSpec& f) {
    can::FaultWindow w;
    w.start_s = f.start_s;
    w.end_s = f.end_s();
    if (f.has_id) w.ids = {f.id};
    if (f.joint > 0) w.ids = hil::drive_identifiers(f.joint);
    switch (f.kind) {
      case hil::FaultKind::drop: w.effect = can::FaultWindow::Effect::drop; break;
      case hil::FaultKind::late:
        w.effect = can::FaultWindow::Effect::delay;
        w.delay_s = hil::kLateDelayS;
        break;
      case hil::FaultKind::corrupt: w.effect = can::FaultWindow::Effect::corrupt; break;
      case hil::FaultKind::duplicate: w.effect = can::FaultWindow::Effect::duplicate; break;
      case hil::FaultKind::babble:
        w.effect = can::FaultWindow::Effect::babble;
        w.babble.id = f.id;
        w.babble.length = 8;
        w.babble.data[0] = 0xA5U;  // garbage: fails every check
        break;
      case hil::FaultKind::link_down: w.effect = can::FaultWindow::Effect::link_down; break;
      case hil::FaultKind::nan_sensor: nan_samples_ = true; return;
      case hil::FaultKind::bus_off:
      case hil::FaultKind::restart: return;  // applied to the drive each cycle (apply_drive_faults)
    }
    bus_.add_fault(w);
  }

  /// Bus-off and restart at the cycle boundary: a drive goes off the bus (or loses power)
  /// when its window opens and comes back when it closes; a restarted drive is a new drive
  /// object (RAM lost) that announces itself as booting, as the `jointguard node` process does.
  void apply_drive_faults() {
    for (const hil::FaultSpec& f : config_.fault_specs) {
      const auto j = static_cast<std::size_t>(f.joint - 1);
      if (f.kind == hil::FaultKind::bus_off) {
        if (f.active(time_)) {
          ports_[j]->go_bus_off();
        } else if (f.ended(time_) && ports_[j]->error_state() == hal::CanErrorState::bus_off) {
          ports_[j]->recover();
        }
      } else if (f.kind == hil::FaultKind::restart && f.started(time_) && !restarted_[&f - config_.fault_specs.data()]) {
        if (drives_[j]) {
          drives_[j].reset();
          ports_[j]->power_off();
        }
        if (f.ended(time_)) {
          ports_[j]->power_on();
          drives_[j] = make_drive(j);
          drives_[j]->announce();
          restarted_[&f - config_.fault_specs.data()] = true;
        }
      }
    }
  }

  DistributedConfig config_;
  can::SimBus bus_;
  can::SimPort& master_port_;
  hil::BusMaster<can::SimPort> master_;
  std::vector<can::SimPort*> ports_;
  std::vector<std::unique_ptr<JointDrive<S, can::SimPort>>> drives_;
  std::vector<bool> restarted_ = std::vector<bool>(config_.fault_specs.size(), false);
  bool nan_samples_ = false;
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
