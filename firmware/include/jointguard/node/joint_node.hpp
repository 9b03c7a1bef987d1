// One joint drive's firmware node: its estimation cycle plus the CAN exchange with its
// neighbours, over any port that satisfies the HAL contract (bound statically).
//
// Timing choice: a node does not wait for its neighbours within a cycle. It uses the last
// messages received (sent by its neighbours in the previous cycle), then sends its own. The
// outward terms are therefore one cycle old, and the inward terms of link i+k reach joint i
// k cycles late; at 1 kHz this costs a few hundredths of a N·m (measured against the
// centralised chain in tests/can, docs/can.md), and no node ever blocks on the bus.
//
// Faults: frames with an unexpected identifier never reach the decoder; wrong length, bad
// CRC and stale sequence numbers are counted and dropped; a neighbour silent for
// `fault_cycles` cycles raises the communication fault (the arm's safe reaction). A restarted
// neighbour is accepted again from its first fresh frame (its counter restarts).
#pragma once

#include <cstdint>

#include "jointguard/hal/can.hpp"
#include "jointguard/node/joint_estimator.hpp"
#include "jointguard/protocol/frames.hpp"

namespace jg {

struct NodeConfig {
  std::uint8_t joint = 1;         ///< 1-based position in the chain
  std::uint8_t joints = 1;        ///< chain length
  std::uint8_t fault_cycles = 5;  ///< cycles without a fresh neighbour frame before the fault
  std::uint8_t max_age_cycles = 2;  ///< paced by a sync: older neighbour frames are late (never used)
};

struct NodeCounters {
  std::uint32_t wrong_length = 0, bad_crc = 0, stale = 0, foreign = 0, send_failures = 0, late = 0;
  /// Cycles run on a neighbour's previous message because no fresh one arrived (counted once
  /// that neighbour has been heard; one per cycle even when both neighbours missed).
  std::uint32_t missed_cycles = 0;
};

template <class S, class Port>
class JointNode {
  static_assert(hal::is_can_port_v<Port>, "the node needs a CAN port satisfying the HAL contract");
  /// The frames' CRC: the port's policy (a backend with a CRC unit), else the software table.
  using Crc = hal::crc8_policy_t<Port>;
  static_assert(hal::is_crc8_policy_v<Crc>, "the port's crc8_policy must satisfy the CRC-8 policy contract");

 public:
  JointNode(const NodeConfig& config, const JointEstimatorParams<S>& params, Port& port, const Vec3<S>& gravity) noexcept
      // Joint 1's parent is the base; the last joint has no child.
      : config_(config), params_(params), port_(port), from_parent_(base_message(gravity)), from_child_(tip_message<S>()) {}

  /// One control cycle with this joint's measurements. Returns the collision flag.
  /// `holding`: the drive's controller holds a constant setpoint (arms the change detector).
  /// `sample_valid` false: the sample is unusable (an input fault, as a NaN would be).
  bool cycle(S q, S dq, S motor_torque, bool holding = false, bool sample_valid = true) noexcept {
    receive_all();
    ++since_parent_;
    ++since_child_;
    const bool has_parent = config_.joint > 1U;
    const bool has_child = config_.joint < config_.joints;
    comm_fault_ = (has_parent && since_parent_ > config_.fault_cycles) || (has_child && since_child_ > config_.fault_cycles);
    if (comm_fault_) {
      rewarm();  // the estimate rests on stale neighbour terms: start afresh once they are back
    }
    if ((has_parent && parent_seq_.started && since_parent_ > 1U) || (has_child && child_seq_.started && since_child_ > 1U)) {
      ++counters_.missed_cycles;
    }
    // to_child_/to_parent_ are members: written whole every cycle, never zeroed per cycle.
    if (sample_valid) {
      (void)joint_outward(params_, state_, q, dq, holding, from_parent_, to_child_);
    } else {
      (void)joint_outward(params_, state_, q, dq, from_parent_, to_child_, false);
    }
    if (state_.input_fault) {
      rewarm();  // the observer misses this cycle's balance: start afresh once the inputs are good
    }
    const bool flag = joint_inward_and_estimate(params_, state_, dq, motor_torque, holding, from_child_, to_parent_);
    // Start-up: the chain's terms need one cycle per link to reach every node. Until then
    // the estimate is meaningless; the observer starts afresh once the chain is filled.
    // Warming up at the start of this cycle: the estimate just computed came from the observer
    // before its restart, so it is not reported even in the cycle the warm-up ends.
    const bool warming = warmup_left_ > 0U;
    const bool heard = (!has_parent || parent_seq_.started) && (!has_child || child_seq_.started);
    // MISRA C++ / C 13.5: no side effect in the right operand of && (the decrement is its
    // own statement, taken only on a cycle where the chain has been heard).
    if (warmup_left_ > 0U && heard) {
      --warmup_left_;
      if (warmup_left_ == 0U) {
        state_.observer = ObserverState<S>{};
        state_.detector = JointDetectorState{};
        state_.hold = HoldChangeState<S>{};  // the reference was taken on a meaningless estimate
        state_.flagged = false;
      }
    }
    if (warming) {
      state_.external_torque = S{};
    }
    if (has_child) {
      send(protocol::MessageKind::outward, [&](std::uint8_t* b) { return protocol::encode_outward<S, Crc>(to_child_, sequence_, b); });
    }
    if (has_parent) {
      send(protocol::MessageKind::inward, [&](std::uint8_t* b) { return protocol::encode_inward<S, Crc>(to_parent_, sequence_, b); });
    }
    ++sequence_;
    return !warming && flag;
  }

  /// Paced by the master's sync (JointDrive): this cycle's sequence number, which the
  /// node's own frames carry; a neighbour frame older than `max_age_cycles` is late.
  void set_cycle(std::uint8_t sequence) noexcept {
    sequence_ = sequence;
    paced_ = true;
  }

  /// A frame handed over as it arrives (JointDrive routes neighbour frames here instead of
  /// queueing them): checked and, when accepted, read straight into the neighbour's
  /// message, exactly as the frames this node receives from its port at the next cycle.
  /// Between cycles the node's sequence number is already the next cycle's (cycle() ends
  /// with ++sequence_), so a frame's age is judged as it would be at that cycle.
  void deliver(const hal::CanFrame& f) noexcept { take(f); }

  /// Warm up again (estimate held at zero, no flag, not ready) until the chain is refilled:
  /// after a communication fault or a gap in the cycles (missed syncs), the observer's
  /// integral no longer matches the joint's momentum.
  void rewarm() noexcept { warmup_left_ = static_cast<std::uint8_t>(config_.joints + 1U); }

  [[nodiscard]] const JointEstimatorState<S>& state() const noexcept { return state_; }
  [[nodiscard]] bool communication_fault() const noexcept { return comm_fault_; }
  [[nodiscard]] bool ready() const noexcept { return warmup_left_ == 0U; }
  [[nodiscard]] const NodeCounters& counters() const noexcept { return counters_; }

 private:
  template <class Encode>
  void send(protocol::MessageKind kind, Encode&& encode) noexcept {
    // tx_ is reused: every frame it carries is 48 bytes, all written by the encoder.
    tx_.id = protocol::frame_id(kind, config_.joint);
    tx_.fd = true;
    tx_.length = encode(static_cast<std::uint8_t*>(tx_.data));
    if (port_.send(tx_) != hal::CanStatus::ok) {
      ++counters_.send_failures;
    }
  }

  void receive_all() noexcept {
    if constexpr (hal::has_peek_v<Port>) {
      for (const hal::CanFrame* f = port_.peek(); f != nullptr; f = port_.peek()) {
        take(*f);
        port_.pop();
      }
    } else {
      while (port_.receive(rx_)) {
        take(rx_);
      }
    }
  }

  /// Checks a frame in place and, when it is accepted, reads it straight into the
  /// neighbour's message (a rejected frame leaves the last good message untouched).
  void take(const hal::CanFrame& f) noexcept {
    const std::uint32_t parent_id = protocol::frame_id(protocol::MessageKind::outward, static_cast<std::uint8_t>(config_.joint - 1U));
    const std::uint32_t child_id = protocol::frame_id(protocol::MessageKind::inward, static_cast<std::uint8_t>(config_.joint + 1U));
    const auto* data = static_cast<const std::uint8_t*>(f.data);
    if (config_.joint > 1U && f.id == parent_id) {
      if (accept(protocol::check_outward<Crc>(data, f.length), data[0], parent_seq_)) {
        protocol::read_outward(data, from_parent_);
        since_parent_ = 0;
      }
    } else if (config_.joint < config_.joints && f.id == child_id) {
      if (accept(protocol::check_inward<Crc>(data, f.length), data[0], child_seq_)) {
        protocol::read_inward(data, from_child_);
        since_child_ = 0;
      }
    } else {
      ++counters_.foreign;  // not for this node: never decoded
    }
  }

  bool accept(protocol::FrameError e, std::uint8_t seq, protocol::SequenceTracker& tracker) noexcept {
    if (e == protocol::FrameError::wrong_length) {
      ++counters_.wrong_length;
    }
    if (e == protocol::FrameError::bad_crc || e == protocol::FrameError::bad_padding) {
      ++counters_.bad_crc;
    }
    if (e != protocol::FrameError::ok) {
      return false;
    }
    if (paced_ && static_cast<std::uint8_t>(sequence_ - seq) > config_.max_age_cycles) {
      ++counters_.late;  // delayed on the bus: using it would mix cycles
      return false;
    }
    // A neighbour silent for a while has restarted: accept its new counter from scratch.
    if (&tracker == &parent_seq_ ? since_parent_ > config_.fault_cycles : since_child_ > config_.fault_cycles) {
      tracker.started = false;
    }
    if (tracker.accept(seq) != protocol::FrameError::ok) {
      ++counters_.stale;
      return false;
    }
    return true;
  }

  NodeConfig config_;
  JointEstimatorParams<S> params_;
  JointEstimatorState<S> state_{};
  Port& port_;
  OutwardMessage<S> from_parent_{};
  InwardMessage<S> from_child_{};
  OutwardMessage<S> to_child_{};
  InwardMessage<S> to_parent_{};
  protocol::SequenceTracker parent_seq_{}, child_seq_{};
  std::uint32_t since_parent_ = 0, since_child_ = 0;
  std::uint8_t sequence_ = 0;
  std::uint8_t warmup_left_ = static_cast<std::uint8_t>(config_.joints + 1U);
  bool comm_fault_ = false, paced_ = false;
  NodeCounters counters_{};
  hal::CanFrame rx_{}, tx_{};  ///< frame buffers kept across cycles: no per-frame zeroing
};

}  // namespace jg
