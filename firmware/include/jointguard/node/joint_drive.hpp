// One joint drive as it runs on the bus: the cycle is paced by the master's sync frame;
// the drive samples its joint, runs its JointNode (neighbour exchange, estimation,
// detection) and publishes a status frame every cycle and a collision event on the
// detector's rising edge. The same code runs on the MCU (samples from its own encoder and
// current ADC via set_sample), in the in-process simulation and as a SocketCAN process
// (samples from the plant's sensor frames, `sensors_over_can`).
//
// Frame routing: the drive owns the port; neighbour momentum frames are handed to the node
// as they arrive (JointNode::deliver validates them and reads them in place), sensor and
// sync frames are validated here, every other identifier is counted as foreign and never
// decoded.
//
// Pairing sync and sample: on a real bus the sync (0x010) wins arbitration over sensor
// frames (0x06j) queued at the same time, so with sensors over CAN the cycle runs when both
// the sync and the sample carrying the same sequence number have arrived, in either order.
#pragma once

#include <cstddef>
#include <cstdint>

#include "jointguard/hal/can.hpp"
#include "jointguard/node/joint_node.hpp"
#include "jointguard/node/joint_reaction.hpp"
#include "jointguard/protocol/frames.hpp"
#include "jointguard/protocol/reaction_frames.hpp"
#include "jointguard/protocol/sensor_validity.hpp"

namespace jg {

/// The node's side of the drive's port: sends straight to the drive's port; receives from a
/// fixed-capacity inbox (the drive hands frames to the node directly, so its inbox stays
/// empty unless a caller pushes frames).
template <class Port, std::size_t Capacity = 8>
class RelayPort {
 public:
  /// The node's frames use the drive's port's CRC policy.
  using crc8_policy = hal::crc8_policy_t<Port>;
  explicit RelayPort(Port& out) noexcept : out_(out) {}
  hal::CanStatus send(const hal::CanFrame& f) noexcept { return out_.send(f); }
  bool receive(hal::CanFrame& f) noexcept {
    const hal::CanFrame* next = peek();
    if (next == nullptr) {
      return false;
    }
    hal::copy_frame(f, *next);
    pop();
    return true;
  }
  /// Zero-copy receive (hal::has_peek_v): the node decodes straight out of the inbox.
  [[nodiscard]] const hal::CanFrame* peek() const noexcept { return count_ == 0U ? nullptr : &inbox_[head_]; }
  void pop() noexcept {
    if (count_ > 0U) {
      head_ = (head_ + 1U) % Capacity;
      --count_;
    }
  }
  [[nodiscard]] hal::CanErrorState error_state() const noexcept { return out_.error_state(); }
  void set_filters(const hal::CanFilter* /*filters*/, std::size_t /*n*/) noexcept {}  // the drive routes
  /// False when the inbox is full (the frame is lost: counted by the drive as an overrun).
  bool push(const hal::CanFrame& f) noexcept {
    if (count_ == Capacity) {
      return false;
    }
    hal::copy_frame(inbox_[(head_ + count_) % Capacity], f);
    ++count_;
    return true;
  }

 private:
  Port& out_;
  hal::CanFrame inbox_[Capacity]{};
  std::size_t head_ = 0, count_ = 0;
};

struct DriveConfig {
  NodeConfig node{};
  bool sensors_over_can = false;  ///< host-in-the-loop: samples come as sensor frames
};

struct DriveCounters {
  std::uint32_t cycles = 0;             ///< cycles run
  std::uint32_t sensor_rejected = 0;    ///< sensor frames with wrong length or CRC
  std::uint32_t sync_rejected = 0;      ///< sync frames with wrong length or CRC
  std::uint32_t stale_syncs = 0;        ///< sync for a cycle not newer than the last one
  std::uint32_t inbox_overruns = 0;     ///< neighbour frames lost (inbox full); 0 since frames are delivered as they arrive
  std::uint32_t foreign = 0;            ///< identifiers not for this drive (never decoded)
  std::uint32_t send_failures = 0;      ///< status or event frames the port refused
  std::uint32_t command_rejected = 0;   ///< reaction commands with wrong length, CRC or values
};

template <class S, class Port>
class JointDrive {
  static_assert(hal::is_can_port_v<Port>, "the drive needs a CAN port satisfying the HAL contract");
  using Crc = hal::crc8_policy_t<Port>;  ///< the frames' CRC (the node's is the same, via RelayPort)
  static_assert(hal::is_crc8_policy_v<Crc>, "the port's crc8_policy must satisfy the CRC-8 policy contract");

 public:
  JointDrive(const DriveConfig& config, const JointEstimatorParams<S>& params, Port& port, const Vec3<S>& gravity) noexcept
      : config_(config), port_(port), relay_(port), node_(config.node, params, relay_, gravity) {
    // Kernel/controller filters keep the rest of the bus out of this drive's queue; the
    // routing below still rejects anything else that gets through.
    const std::uint8_t j = config.node.joint;
    const hal::CanFilter filters[] = {
        {protocol::kSyncId, 0x7FFU},
        {protocol::frame_id(protocol::MessageKind::sensor, j), 0x7FFU},
        {protocol::frame_id(protocol::MessageKind::outward, static_cast<std::uint8_t>(j - 1U)), 0x7FFU},
        {protocol::frame_id(protocol::MessageKind::inward, static_cast<std::uint8_t>(j + 1U)), 0x7FFU},
        {protocol::kReactionCommandId, 0x7FFU},
    };
    port_.set_filters(static_cast<const hal::CanFilter*>(filters), sizeof filters / sizeof filters[0]);
  }
  // The node refers to this drive's relay port: a copy or move would leave it dangling.
  JointDrive(const JointDrive&) = delete;
  JointDrive& operator=(const JointDrive&) = delete;
  JointDrive(JointDrive&&) = delete;
  JointDrive& operator=(JointDrive&&) = delete;
  ~JointDrive() = default;

  /// The drive's own sample (MCU: from the encoder and current ADC before the sync) and
  /// its controller's state (`holding`: the setpoint is constant).
  void set_sample(S position, S velocity, S motor_torque, bool holding = false) noexcept {
    sample_ = {position, velocity, motor_torque, holding};
    has_sample_ = true;
    sample_valid_ = true;  // a NaN from the drive's own sensors is caught by the estimator
  }

  /// Before its first cycle the drive announces itself (a status frame with the booting
  /// flag, sequence 0), repeated by the caller until the first sync arrives, so that the
  /// master starts the bus only once every drive listens: then no drive misses its
  /// neighbours' first messages and a start-up is the same whatever order the drives boot in.
  void announce() noexcept {
    if (!synced_) {
      const protocol::StatusMessage<S> booting{S{}, protocol::kStatusBooting, 0U};
      publish(protocol::MessageKind::status, 0U, booting);
    }
  }

  /// Reads every received frame and runs the cycle once its sync (and, with sensors over
  /// CAN, its sample) are in. Returns true when a cycle ran.
  bool poll() noexcept {
    bool ran = false;
    if constexpr (hal::has_peek_v<Port>) {
      // Zero-copy: routed (and relayed, once) straight out of the port's queue.
      for (const hal::CanFrame* f = port_.peek(); f != nullptr; f = port_.peek()) {
        route(*f);
        port_.pop();
        ran = run_if_ready() || ran;
      }
    } else {
      while (port_.receive(rx_)) {
        route(rx_);
        ran = run_if_ready() || ran;
      }
    }
    return ran;
  }

  /// The reaction's gains (joint_reaction.hpp; defaults: 1 kHz). Set before the first cycle.
  void set_reaction_gains(const ReactionGains<S>& gains) noexcept { reaction_gains_ = gains; }
  /// The reaction under way (kind none: not reacting) and this cycle's reaction torque.
  [[nodiscard]] const JointReactionState<S>& reaction() const noexcept { return reaction_; }
  [[nodiscard]] S reaction_torque() const noexcept { return reaction_torque_; }

  /// The drive's node: its port only sends (frames are delivered), a one-frame inbox.
  using Node = JointNode<S, RelayPort<Port, 1>>;
  [[nodiscard]] const Node& node() const noexcept { return node_; }
  [[nodiscard]] const DriveCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] std::uint32_t last_cycle() const noexcept { return last_cycle_; }
  [[nodiscard]] const protocol::StatusMessage<S>& last_status() const noexcept { return status_; }

 private:
  void route(const hal::CanFrame& f) noexcept {
    const std::uint8_t j = config_.node.joint;
    std::uint8_t seq = 0;
    if (f.id == protocol::kSyncId && !f.extended) {
      std::uint32_t cycle = 0;
      if (protocol::decode_sync<Crc>(static_cast<const std::uint8_t*>(f.data), f.length, cycle) != protocol::FrameError::ok) {
        ++counters_.sync_rejected;
      } else if (synced_ && static_cast<std::int32_t>(cycle - last_cycle_) <= 0 && stale_run_ < config_.node.fault_cycles) {
        ++counters_.stale_syncs;  // a repeated or reordered sync; a run of them means the master restarted
        ++stale_run_;
      } else {
        stale_run_ = 0;
        pending_cycle_ = cycle;
        sync_pending_ = true;
      }
    } else if (config_.sensors_over_can && f.id == protocol::frame_id(protocol::MessageKind::sensor, j) && !f.extended) {
      protocol::SensorMessage<S> m{};
      if (protocol::decode_sensor<S, Crc>(static_cast<const std::uint8_t*>(f.data), f.length, m, seq) != protocol::FrameError::ok) {
        ++counters_.sensor_rejected;
      } else {
        sample_ = m;
        sample_seq_ = seq;
        has_sample_ = true;
        // A field marked invalid (the plant's value was NaN): an input fault, never a number.
        sample_valid_ = protocol::sensor_fields_valid(static_cast<const std::uint8_t*>(f.data));
      }
    } else if (!f.extended && (f.id == protocol::frame_id(protocol::MessageKind::outward, static_cast<std::uint8_t>(j - 1U)) ||
                               f.id == protocol::frame_id(protocol::MessageKind::inward, static_cast<std::uint8_t>(j + 1U)))) {
      node_.deliver(f);  // checked and read in place, no copy into an inbox
    } else if (f.id == protocol::kReactionCommandId && !f.extended) {
      take_command(f);
    } else {
      ++counters_.foreign;
    }
  }

  bool run_if_ready() noexcept {
    if (!ready_to_run()) {
      return false;
    }
    run_cycle();
    return true;
  }

  [[nodiscard]] bool ready_to_run() const noexcept {
    if (!sync_pending_ || !has_sample_) {
      return false;
    }
    return !config_.sensors_over_can || sample_seq_ == static_cast<std::uint8_t>(pending_cycle_ & 0xFFU);
  }

  void run_cycle() noexcept {
    sync_pending_ = false;
    if (synced_ && pending_cycle_ != last_cycle_ + 1U) {
      node_.rewarm();  // syncs were missed (bus silent, master restarted): the observer starts afresh
    }
    synced_ = true;
    last_cycle_ = pending_cycle_;
    node_.set_cycle(static_cast<std::uint8_t>(last_cycle_ & 0xFFU));
    const bool flag =
        node_.cycle(sample_.position, sample_.velocity, sample_.motor_torque, sample_.holding, sample_valid_);
    ++counters_.cycles;
    const NodeCounters& nc = node_.counters();
    const std::uint32_t rejected =
        nc.wrong_length + nc.bad_crc + nc.stale + nc.late + counters_.sensor_rejected + counters_.sync_rejected;
    status_.external_torque = node_.state().external_torque;
    const std::uint8_t none = 0U;
    status_.flags = static_cast<std::uint8_t>((flag ? protocol::kStatusCollision : none) |
                                              (node_.communication_fault() ? protocol::kStatusCommFault : none) |
                                              (node_.ready() ? protocol::kStatusReady : none) |
                                              (node_.state().input_fault ? protocol::kStatusInputFault : none));
    status_.rejected = static_cast<std::uint8_t>(rejected > 255U ? 255U : rejected);
    const auto seq = static_cast<std::uint8_t>(last_cycle_ & 0xFFU);
    if (flag && !event_sent_) {
      publish(protocol::MessageKind::collision_event, seq, status_);
      event_sent_ = true;
    }
    if (react_) {  // the only cost of the reaction while no collision is raised: this test
      react(seq);
      return;
    }
    publish(protocol::MessageKind::status, seq, status_);
  }

  /// The master's reaction command: latched once, run from this drive's next cycle. Out of
  /// line and cold (as react): the routing and the cycle of a drive that is not reacting
  /// keep their code and registers.
  [[gnu::noinline, gnu::cold]] void take_command(const hal::CanFrame& f) noexcept {
    if (protocol::decode_reaction_command<S, Crc>(static_cast<const std::uint8_t*>(f.data), f.length, config_.node.joint,
                                          command_.kind, command_.collided, command_.retreat_target) != protocol::FrameError::ok) {
      ++counters_.command_rejected;
    } else {
      react_ = true;
    }
  }

  /// The reaction's cycle: started on the first command; its torque term goes to the
  /// master with the status (on the MCU it is also the drive's own motor torque term).
  [[gnu::noinline, gnu::cold]] void react(std::uint8_t seq) noexcept {
    start_reaction(reaction_, command_, sample_.position);
    const JointEstimatorState<S>& st = node_.state();
    reaction_torque_ = jg::reaction_torque(reaction_gains_, reaction_, sample_.position, sample_.velocity,
                                           st.external_torque, st.friction_torque);
    tx_.fd = true;
    tx_.id = protocol::frame_id(protocol::MessageKind::joint_state, config_.node.joint);
    tx_.length = protocol::encode_reaction_status<S, Crc>(protocol::ReactionStatusMessage<S>{status_, reaction_torque_}, seq,
                                                  static_cast<std::uint8_t*>(tx_.data));
    if (port_.send(tx_) != hal::CanStatus::ok) {
      ++counters_.send_failures;
    }
  }

  void publish(protocol::MessageKind kind, std::uint8_t seq, const protocol::StatusMessage<S>& status) noexcept {
    // tx_ is reused: every frame it carries is 8 bytes, all written here (no zeroing).
    tx_.fd = true;  // 8 bytes in the data phase: a third of the classic frame's wire time
    tx_.id = protocol::frame_id(kind, config_.node.joint);
    tx_.length = protocol::encode_status<S, Crc>(status, seq, static_cast<std::uint8_t*>(tx_.data));
    if (port_.send(tx_) != hal::CanStatus::ok) {
      ++counters_.send_failures;
    }
  }

  DriveConfig config_;
  Port& port_;
  RelayPort<Port, 1> relay_;
  Node node_;
  protocol::SensorMessage<S> sample_{};
  protocol::StatusMessage<S> status_{};
  std::uint8_t sample_seq_ = 0, stale_run_ = 0;
  std::uint32_t pending_cycle_ = 0, last_cycle_ = 0;
  bool has_sample_ = false, sync_pending_ = false, synced_ = false, event_sent_ = false, sample_valid_ = true;
  DriveCounters counters_{};
  hal::CanFrame rx_{}, tx_{};  ///< frame buffers kept across cycles: no per-frame zeroing
  // The reaction last: the members the cycle uses keep their offsets (cheaper addressing).
  bool react_ = false;  ///< a reaction command has arrived
  ReactionGains<S> reaction_gains_{};
  ReactionCommand<S> command_{};
  JointReactionState<S> reaction_{};
  S reaction_torque_{};
};

}  // namespace jg
