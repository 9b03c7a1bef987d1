// The master's side of the joint bus (the arm controller; on the host: the plant process or
// the in-process simulation). Each cycle it publishes the joints' sensor samples (host-in-
// the-loop only: on the arm, each drive samples its own joint) and the cycle sync, then
// collects every drive's status frame of that cycle and the collision events. Every frame
// is validated before use; anything else on the bus is counted and ignored.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "jointguard/detection/detector.hpp"
#include "jointguard/hal/can.hpp"
#include "jointguard/protocol/frames.hpp"
#include "jointguard/protocol/reaction_frames.hpp"
#include "jointguard/protocol/sensor_validity.hpp"

namespace jg::hil {

struct NodeEvent {
  std::uint32_t cycle = 0;  ///< the master's cycle in which the event frame arrived
  int joint = 0;
  double external_torque = 0.0;
};

struct MasterCounters {
  std::uint64_t rejected = 0;      ///< status/event frames with wrong length or CRC
  std::uint64_t out_of_cycle = 0;  ///< status frames of another cycle (late or duplicated)
  std::uint64_t foreign = 0;       ///< identifiers the master does not read
  std::uint64_t send_failures = 0;
  std::uint64_t frames_received = 0;
  std::uint64_t restarts = 0;          ///< drives that announced themselves again mid-run (rebooted)
  std::uint64_t invalid_samples = 0;   ///< sensor frames sent marked invalid (the plant's value was not finite)
  std::uint64_t reaction_frames = 0;   ///< reaction status frames (status + reaction torque) received
};

/// A span of cycles in which a fault was raised: in the master's view (joint 0: what the
/// arm reacts to) or in one drive's own status flag (as its last status reported it).
struct FaultEpisode {
  enum class Kind : std::uint8_t { communication, input };
  Kind kind = Kind::communication;
  int joint = 0;                 ///< 0: the master's view; j: drive j's status flag
  std::uint32_t from_cycle = 0;  ///< first cycle it was raised (at the cycle's end)
  std::int64_t to_cycle = -1;    ///< first cycle it was clear again; -1: still raised at the end
};

template <class Port>
class BusMaster {
  static_assert(hal::is_can_port_v<Port>, "the master needs a CAN port satisfying the HAL contract");

 public:
  BusMaster(Port& port, std::size_t joints)
      : port_(port), torque_(joints, 0.0), flags_(joints, 0), have_(joints, false), announced_(joints, false),
        rejoining_(joints, false), answered_once_(joints, false), first_comm_fault_(joints, -1), reaction_torque_(joints, 0.0),
        have_reaction_(joints, false), open_episode_(2 * (joints + 1), -1) {
    const hal::CanFilter filters[] = {
        {protocol::frame_id(protocol::MessageKind::status, 0), 0x7F0U},
        {protocol::frame_id(protocol::MessageKind::collision_event, 0), 0x7F0U},
        {protocol::frame_id(protocol::MessageKind::joint_state, 0), 0x7F0U},  // the drives' reaction torques
    };
    port_.set_filters(static_cast<const hal::CanFilter*>(filters), 3);
  }

  /// The arm reacts: from the next send_cycle on, every cycle carries the reaction command
  /// (joint_reaction.hpp) before its sync. `retreat_target`: one position per joint [rad].
  void command_reaction(Reaction reaction, JointMask collided, const double* retreat_target) {
    command_ = protocol::ReactionCommandMessage<q16>{};
    command_.reaction = reaction;
    command_.collided = collided;
    for (std::size_t j = 0; j < torque_.size() && j < protocol::kReactionJoints; ++j) {
      command_.retreat_target[j] = q16::from_double(retreat_target[j]);
    }
    commanding_ = reaction != Reaction::none;
  }
  /// Every drive has sent a reaction torque (it runs the commanded reaction).
  [[nodiscard]] bool all_reacting() const {
    for (const bool h : have_reaction_) {
      if (!h) return false;
    }
    return true;
  }
  /// The drives' reaction torques [N·m] (the last each drive sent); false until every
  /// drive has sent one.
  [[nodiscard]] bool reaction_torques(std::vector<double>& out) const {
    if (!all_reacting()) return false;
    out = reaction_torque_;
    return true;
  }

  /// Sensor samples (link side, SI) of every joint, then the sync of `cycle`. `holding`:
  /// bit j set when joint j+1's controller holds a constant setpoint.
  void send_cycle(std::uint32_t cycle, const double* position, const double* velocity, const double* motor_torque,
                  JointMask holding = 0) {
    const auto seq = static_cast<std::uint8_t>(cycle & 0xFFU);
    send_command(seq);
    for (std::size_t j = 0; j < torque_.size(); ++j) {
      hal::CanFrame f{};
      f.fd = true;
      f.id = protocol::frame_id(protocol::MessageKind::sensor, static_cast<std::uint8_t>(j + 1));
      const protocol::SensorMessage<q16> m{q16::from_double(position[j]), q16::from_double(velocity[j]),
                                           q16::from_double(motor_torque[j]), ((holding >> j) & 1U) != 0U};
      f.length = protocol::encode_sensor(m, seq, static_cast<std::uint8_t*>(f.data));
      // A value that is not finite must not reach the drive as a number (Q16.16 would
      // turn NaN into 0): its field carries the invalid marker, the drive flags an input fault.
      const double values[] = {position[j], velocity[j], motor_torque[j]};
      bool marked = false;
      for (std::size_t i = 0; i < 3; ++i) {
        if (!std::isfinite(values[i])) {
          protocol::mark_sensor_field_invalid(static_cast<std::uint8_t*>(f.data), i);
          marked = true;
        }
      }
      if (marked) ++counters_.invalid_samples;
      send(f);
    }
    send_sync(cycle);
  }

  /// The cycle of drives that sample their own joints (as on the arm: encoder and current
  /// ADC on the drive's MCU, JointDrive::set_sample): the reaction command and the sync only.
  void send_sync_only(std::uint32_t cycle) {
    send_command(static_cast<std::uint8_t>(cycle & 0xFFU));
    send_sync(cycle);
  }

 private:
  /// Repeated until every drive has answered with its reaction torque (a lost command is
  /// sent again); then the bus carries only the drives' torque frames on top of the cycle.
  void send_command(std::uint8_t seq) {
    if (commanding_ && !all_reacting()) {
      hal::CanFrame c{};
      c.fd = true;
      c.id = protocol::kReactionCommandId;
      c.length = protocol::encode_reaction_command(command_, seq, static_cast<std::uint8_t*>(c.data));
      send(c);
    }
  }
  void send_sync(std::uint32_t cycle) {
    hal::CanFrame sync{};
    sync.fd = true;  // short frames ride the data phase (bit-rate switch)
    sync.id = protocol::kSyncId;
    sync.length = protocol::encode_sync(cycle, static_cast<std::uint8_t*>(sync.data));
    sync_sent_ = send(sync);
    cycle_ = cycle;
    started_ = true;
    have_.assign(have_.size(), false);
  }

 public:
  /// Reads what has arrived; true when every drive's status of the current cycle is in.
  bool collect() {
    hal::CanFrame f{};
    while (port_.receive(f)) {
      ++counters_.frames_received;
      const protocol::MessageKind kind = protocol::kind_of(f.id);
      const std::size_t joint = protocol::joint_of(f.id);
      const bool ours = !f.extended && joint >= 1 && joint <= torque_.size() &&
                        (kind == protocol::MessageKind::status || kind == protocol::MessageKind::collision_event ||
                         kind == protocol::MessageKind::joint_state);
      if (!ours) {
        ++counters_.foreign;
        continue;
      }
      protocol::StatusMessage<q16> m{};
      std::uint8_t seq = 0;
      if (kind == protocol::MessageKind::joint_state) {
        // A reacting drive's status, with its reaction torque.
        protocol::ReactionStatusMessage<q16> r{};
        if (protocol::decode_reaction_status(static_cast<const std::uint8_t*>(f.data), f.length, r, seq) != protocol::FrameError::ok) {
          ++counters_.rejected;
          continue;
        }
        m = r.status;
        if (seq == static_cast<std::uint8_t>(cycle_ & 0xFFU)) {
          reaction_torque_[joint - 1] = r.torque.to_double();
          have_reaction_[joint - 1] = true;
          ++counters_.reaction_frames;
        }
      } else if (protocol::decode_status(static_cast<const std::uint8_t*>(f.data), f.length, m, seq) != protocol::FrameError::ok) {
        ++counters_.rejected;
        continue;
      }
      if ((m.flags & protocol::kStatusBooting) != 0U) {
        announced_[joint - 1] = true;  // listening, before the first sync
        // A drive that has answered a cycle and announces itself again has restarted. One
        // that has not answered yet sent this before it heard the first sync (a loaded host
        // delivers it late): the start-up, not a restart.
        if (started_ && answered_once_[joint - 1] && !rejoining_[joint - 1]) {
          // A drive booting mid-run has restarted: its estimate is void until it is ready
          // again; it runs from the next sync (it missed this cycle's).
          rejoining_[joint - 1] = true;
          ++counters_.restarts;
        }
        continue;
      }
      if (kind == protocol::MessageKind::collision_event) {
        events_.push_back({cycle_, static_cast<int>(joint), m.external_torque.to_double()});
        continue;
      }
      if (seq != static_cast<std::uint8_t>(cycle_ & 0xFFU)) {
        ++counters_.out_of_cycle;
        continue;
      }
      torque_[joint - 1] = m.external_torque.to_double();
      flags_[joint - 1] = m.flags;
      have_[joint - 1] = true;
      answered_once_[joint - 1] = true;
      if ((m.flags & protocol::kStatusReady) != 0U) rejoining_[joint - 1] = false;
      if ((m.flags & protocol::kStatusCommFault) != 0U && first_comm_fault_[joint - 1] < 0) first_comm_fault_[joint - 1] = cycle_;
    }
    return complete();
  }

  [[nodiscard]] bool complete() const {
    for (const bool h : have_) {
      if (!h) return false;
    }
    return true;
  }
  /// Every drive has announced itself (start-up, before the first sync).
  [[nodiscard]] bool all_announced() const {
    for (const bool a : announced_) {
      if (!a) return false;
    }
    return true;
  }
  [[nodiscard]] std::vector<int> not_announced() const {
    std::vector<int> out;
    for (std::size_t j = 0; j < announced_.size(); ++j) {
      if (!announced_[j]) out.push_back(static_cast<int>(j + 1));
    }
    return out;
  }
  /// Joints whose status of this cycle is missing (1-based).
  [[nodiscard]] std::vector<int> missing() const {
    std::vector<int> out;
    for (std::size_t j = 0; j < have_.size(); ++j) {
      if (!have_[j]) out.push_back(static_cast<int>(j + 1));
    }
    return out;
  }
  /// Last reported external torque per joint [N·m] (kept from earlier cycles when missing).
  [[nodiscard]] const std::vector<double>& external_torque() const { return torque_; }
  [[nodiscard]] const std::vector<std::uint8_t>& flags() const { return flags_; }
  /// Joints whose detector flag is up, as the detector's mask.
  [[nodiscard]] JointMask flagged() const {
    JointMask m = 0;
    for (std::size_t j = 0; j < flags_.size(); ++j) {
      if ((flags_[j] & protocol::kStatusCollision) != 0U) m = static_cast<JointMask>(m | (1U << j));
    }
    return m;
  }
  /// Closes the cycle's bookkeeping: a run of cycles without every drive's status is a
  /// communication fault on the master's side (the drives may be unable to report it).
  void end_cycle() {
    missing_run_ = complete() ? 0U : missing_run_ + 1U;
    note_episodes();
  }
  [[nodiscard]] bool any_comm_fault() const {
    if (missing_run_ >= kMissingCyclesForFault) return true;
    for (const auto f : flags_) {
      if ((f & protocol::kStatusCommFault) != 0U) return true;
    }
    for (const bool r : rejoining_) {
      if (r) return true;
    }
    return false;
  }
  /// A drive flagged this cycle's inputs as unusable (a non-finite or marked-invalid sample).
  [[nodiscard]] bool any_input_fault() const {
    for (const auto f : flags_) {
      if ((f & protocol::kStatusInputFault) != 0U) return true;
    }
    return false;
  }
  /// Drive j (1-based) rebooted mid-run and is not ready again yet.
  [[nodiscard]] bool rejoining(int joint) const { return rejoining_.at(static_cast<std::size_t>(joint - 1)); }
  /// The last send_cycle's sync went out (false: the port refused it, e.g. the link is down).
  [[nodiscard]] bool sync_sent() const { return sync_sent_; }
  /// Per drive, the first cycle whose status carried the communication fault (-1: never).
  [[nodiscard]] const std::vector<std::int64_t>& first_comm_fault_cycle() const { return first_comm_fault_; }
  /// Consecutive cycles so far without every drive's status.
  [[nodiscard]] unsigned missing_run() const { return missing_run_; }
  [[nodiscard]] const std::vector<NodeEvent>& events() const { return events_; }
  [[nodiscard]] const MasterCounters& counters() const { return counters_; }
  /// Every span a fault was raised, in the order they began (the first kMaxEpisodes).
  [[nodiscard]] const std::vector<FaultEpisode>& fault_episodes() const { return episodes_; }

 private:
  /// Opens or closes the episodes of this cycle's fault states (the master's, each drive's).
  void note_episodes() {
    for (std::size_t j = 0; j <= flags_.size(); ++j) {
      const std::uint8_t f = j == 0 ? 0U : flags_[j - 1];
      note_episode(FaultEpisode::Kind::communication, j, j == 0 ? any_comm_fault() : (f & protocol::kStatusCommFault) != 0U);
      note_episode(FaultEpisode::Kind::input, j, j == 0 ? any_input_fault() : (f & protocol::kStatusInputFault) != 0U);
    }
  }
  void note_episode(FaultEpisode::Kind kind, std::size_t joint, bool raised) {
    std::int64_t& open = open_episode_[2 * joint + (kind == FaultEpisode::Kind::input ? 1U : 0U)];
    if (raised && open < 0 && episodes_.size() < kMaxEpisodes) {
      open = static_cast<std::int64_t>(episodes_.size());
      episodes_.push_back({kind, static_cast<int>(joint), cycle_, -1});
    } else if (!raised && open >= 0) {
      episodes_[static_cast<std::size_t>(open)].to_cycle = cycle_;
      open = -1;
    }
  }
  bool send(const hal::CanFrame& f) {
    if (port_.send(f) == hal::CanStatus::ok) return true;
    ++counters_.send_failures;
    return false;
  }
  Port& port_;
  std::uint32_t cycle_ = 0;
  std::vector<double> torque_;
  std::vector<std::uint8_t> flags_;
  std::vector<bool> have_, announced_, rejoining_, answered_once_;
  std::vector<std::int64_t> first_comm_fault_;
  bool started_ = false, sync_sent_ = false;
  std::vector<NodeEvent> events_;
  std::vector<double> reaction_torque_;
  std::vector<bool> have_reaction_;
  protocol::ReactionCommandMessage<q16> command_{};
  bool commanding_ = false;
  MasterCounters counters_{};
  unsigned missing_run_ = 0;
  std::vector<FaultEpisode> episodes_;
  std::vector<std::int64_t> open_episode_;  ///< per (joint 0..n, kind): index of its open episode, -1: none
  static constexpr unsigned kMissingCyclesForFault = 5;
  static constexpr std::size_t kMaxEpisodes = 1024;  ///< a flapping fault cannot grow the list without bound
};

}  // namespace jg::hil
