// A simulated CAN bus, in-process and deterministic: ports that satisfy the HAL contract,
// arbitration by identifier (lowest wins) whenever the bus is idle, frame durations from the
// bit timing with worst-case bit stuffing, per-frame latency, and fault injection.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "jointguard/hal/can.hpp"

namespace jg::can {

struct BusTiming {
  double nominal_bps = 1e6;  ///< arbitration (and classic CAN) bit rate
  double data_bps = 5e6;     ///< CAN FD data-phase bit rate
};

/// Worst-case bits on the wire of a frame with an 11-bit identifier.
///  Classic: 47 + 8n + floor((34 + 8n - 1) / 4) (header, data and CRC stuffed worst case).
///  FD (BRS): nominal phase 17 stuffable header bits + 4 stuff + 13 trailer (CRC delimiter,
///  ACK, EOF, IFS); data phase ESI + DLC + 8n + stuff count (4) + CRC (17 for n <= 16, else
///  21) + fixed stuff bits (ceil(CRC/4)) + worst dynamic stuffing floor((5 + 8n - 1) / 4).
struct FrameBits {
  double nominal = 0, data = 0;
};
FrameBits frame_bits(const hal::CanFrame& f);
double frame_duration_s(const hal::CanFrame& f, const BusTiming& t);

struct FaultPlan {
  double drop_probability = 0.0;       ///< frame lost (not delivered to anyone)
  double corrupt_probability = 0.0;    ///< one payload byte flipped on delivery
  double duplicate_probability = 0.0;  ///< delivered twice
  double extra_delay_s = 0.0;          ///< added latency on delivery
  std::uint32_t affected_id_mask = 0, affected_id_match = 0;  ///< which identifiers (mask 0 = all)
  unsigned long long seed = 1;
};

/// A fault over a window of bus time [start_s, end_s): injected mid-run (`--fault`).
struct FaultWindow {
  enum class Effect { drop, delay, corrupt, duplicate, babble, link_down };
  Effect effect = Effect::drop;
  double start_s = 0.0, end_s = std::numeric_limits<double>::infinity();
  std::vector<std::uint32_t> ids;  ///< frames affected by identifier (empty: every frame)
  double delay_s = 0.010;          ///< Effect::delay: added latency
  hal::CanFrame babble{};          ///< Effect::babble: what the babbling node sends whenever the bus is idle
  [[nodiscard]] bool active(double t) const { return t >= start_s && t < end_s; }
  [[nodiscard]] bool affects(std::uint32_t id) const;
};

class SimBus;

/// One node's attachment to the bus (HAL port contract).
class SimPort {
 public:
  hal::CanStatus send(const hal::CanFrame& f);
  bool receive(hal::CanFrame& out);
  [[nodiscard]] hal::CanErrorState error_state() const { return state_; }
  void set_filters(const hal::CanFilter* filters, std::size_t n);
  /// Fault injection: the controller goes bus-off (sends nothing) until recover().
  void go_bus_off() { state_ = hal::CanErrorState::bus_off; }
  void recover() { state_ = hal::CanErrorState::error_active; }
  /// Fault injection: the node loses power (queues cleared, receives nothing) until
  /// power_on() (a rebooted controller starts with empty queues and default filters).
  void power_off() {
    powered_ = false;
    tx_.clear();
    rx_.clear();
  }
  void power_on() {
    powered_ = true;
    filters_.clear();
    state_ = hal::CanErrorState::error_active;
  }

 private:
  friend class SimBus;
  SimBus* bus_ = nullptr;
  std::size_t index_ = 0;
  std::deque<std::pair<double, hal::CanFrame>> tx_;  ///< (enqueue time, frame)
  std::deque<hal::CanFrame> rx_;
  std::vector<hal::CanFilter> filters_;
  hal::CanErrorState state_ = hal::CanErrorState::error_active;
  bool powered_ = true;
  std::size_t tx_capacity_ = 256;
};
static_assert(hal::is_can_port_v<SimPort>, "SimPort satisfies the CAN port contract");

class SimBus {
 public:
  explicit SimBus(BusTiming timing, FaultPlan faults = {});
  SimPort& attach();
  /// The i-th attached port (fault injection: bus-off, babbling).
  SimPort& port(std::size_t i) { return *ports_.at(i); }
  /// Runs arbitration and transmission up to time t [s]; frames finishing by then are
  /// delivered to every other port (timestamp = end of frame + latency).
  void run_until(double t);
  [[nodiscard]] double now() const { return now_; }
  [[nodiscard]] double busy_time() const { return busy_s_; }
  [[nodiscard]] std::size_t frames_sent() const { return frames_; }
  /// A babbling node: the given port re-sends `frame` whenever the bus is idle.
  void set_babbler(std::size_t port_index, const hal::CanFrame& frame);
  [[nodiscard]] const std::vector<std::uint32_t>& transmit_order() const { return order_; }
  /// A fault over a window of bus time (drop, delay, corrupt, duplicate by identifier; a
  /// babbling node not attached as a port; the link down: nothing sent, queues flushed).
  void add_fault(const FaultWindow& w) { windows_.push_back(w); }
  [[nodiscard]] bool link_down(double t) const;

 private:
  friend class SimPort;
  BusTiming timing_;
  FaultPlan faults_;
  std::mt19937_64 rng_;
  std::vector<std::unique_ptr<SimPort>> ports_;
  double now_ = 0.0, busy_s_ = 0.0;
  std::size_t frames_ = 0;
  bool babbling_ = false;
  std::size_t babbler_ = 0;
  hal::CanFrame babble_{};
  std::vector<std::uint32_t> order_;
  std::vector<FaultWindow> windows_;
  const FaultWindow* active_babble(double t) const;
  /// Earliest window edge (start or end) after t, or `limit`.
  double next_edge(double t, double limit) const;
  /// A frame at the end of its transmission (now_) through the faults (windowed, by its
  /// identifier; random, drawing from unit) to every powered port but the sender whose
  /// filters accept it.
  void deliver(const hal::CanFrame& frame, const SimPort* sender, std::uniform_real_distribution<double>& unit);
};

}  // namespace jg::can
