#include "can/sim_bus.hpp"

#include <cmath>
#include <stdexcept>

namespace jg::can {

FrameBits frame_bits(const hal::CanFrame& f) {
  const double n = f.length;
  FrameBits b;
  if (!f.fd) {
    b.nominal = 47.0 + 8.0 * n + std::floor((34.0 + 8.0 * n - 1.0) / 4.0);
    return b;
  }
  const double crc = f.length <= 16 ? 17.0 : 21.0;
  b.nominal = 17.0 + 4.0 + 13.0;
  b.data = 1.0 + 4.0 + 8.0 * n + 4.0 + crc + std::ceil(crc / 4.0) + std::floor((5.0 + 8.0 * n - 1.0) / 4.0);
  return b;
}

double frame_duration_s(const hal::CanFrame& f, const BusTiming& t) {
  const FrameBits b = frame_bits(f);
  return b.nominal / t.nominal_bps + (f.fd ? b.data / t.data_bps : 0.0);
}

bool FaultWindow::affects(std::uint32_t id) const {
  if (ids.empty()) return true;
  for (const auto i : ids) {
    if (i == id) return true;
  }
  return false;
}

hal::CanStatus SimPort::send(const hal::CanFrame& f) {
  if (!hal::valid_length(f.length, f.fd) || f.id > (f.extended ? 0x1FFFFFFFU : 0x7FFU)) return hal::CanStatus::invalid;
  if (!powered_) return hal::CanStatus::bus_off;
  // The link down (SocketCAN: ENETDOWN) refuses frames as a bus-off controller does.
  if (state_ == hal::CanErrorState::bus_off || bus_->link_down(bus_->now())) return hal::CanStatus::bus_off;
  if (tx_.size() >= tx_capacity_) return hal::CanStatus::queue_full;
  tx_.emplace_back(bus_->now(), f);
  return hal::CanStatus::ok;
}

bool SimPort::receive(hal::CanFrame& out) {
  // A frame given extra latency reaches the port only once the bus clock passes its
  // delivery time; frames behind it that are due already are not held up.
  const auto now_us = static_cast<std::uint64_t>(std::llround(bus_->now() * 1e6));
  for (auto it = rx_.begin(); it != rx_.end(); ++it) {
    if (it->timestamp_us <= now_us) {
      out = *it;
      rx_.erase(it);
      return true;
    }
  }
  return false;
}

void SimPort::set_filters(const hal::CanFilter* filters, std::size_t n) { filters_.assign(filters, filters + n); }

SimBus::SimBus(BusTiming timing, FaultPlan faults) : timing_(timing), faults_(faults), rng_(faults.seed) {
  if (!(timing.nominal_bps > 0.0) || !(timing.data_bps > 0.0)) throw std::invalid_argument("SimBus: bit rates must be > 0");
}

SimPort& SimBus::attach() {
  ports_.push_back(std::make_unique<SimPort>());
  ports_.back()->bus_ = this;
  ports_.back()->index_ = ports_.size() - 1;
  return *ports_.back();
}

void SimBus::set_babbler(std::size_t port_index, const hal::CanFrame& frame) {
  babbling_ = true;
  babbler_ = port_index;
  babble_ = frame;
}

bool SimBus::link_down(double t) const {
  for (const auto& w : windows_) {
    if (w.effect == FaultWindow::Effect::link_down && w.active(t)) return true;
  }
  return false;
}

const FaultWindow* SimBus::active_babble(double t) const {
  for (const auto& w : windows_) {
    if (w.effect == FaultWindow::Effect::babble && w.active(t)) return &w;
  }
  return nullptr;
}

double SimBus::next_edge(double t, double limit) const {
  double next = limit;
  for (const auto& w : windows_) {
    if (w.start_s > t) next = std::min(next, w.start_s);
    if (w.end_s > t) next = std::min(next, w.end_s);
  }
  return next;
}

void SimBus::deliver(const hal::CanFrame& frame, const SimPort* sender, std::uniform_real_distribution<double>& unit) {
  // Windowed faults act on the frame by its identifier at the end of its transmission.
  bool w_drop = false, w_corrupt = false, w_duplicate = false;
  double w_delay = 0.0;
  for (const auto& w : windows_) {
    if (!w.active(now_) || !w.affects(frame.id)) continue;
    w_drop = w_drop || w.effect == FaultWindow::Effect::drop;
    w_corrupt = w_corrupt || w.effect == FaultWindow::Effect::corrupt;
    w_duplicate = w_duplicate || w.effect == FaultWindow::Effect::duplicate;
    if (w.effect == FaultWindow::Effect::delay) w_delay = std::max(w_delay, w.delay_s);
  }
  if (w_drop) return;
  const bool affected = (frame.id & faults_.affected_id_mask) == (faults_.affected_id_match & faults_.affected_id_mask);
  if (affected && unit(rng_) < faults_.drop_probability) return;
  hal::CanFrame delivered = frame;
  if (affected && frame.length > 0 && unit(rng_) < faults_.corrupt_probability) {
    delivered.data[static_cast<std::size_t>(unit(rng_) * frame.length) % frame.length] ^= 0x04U;
  }
  if (w_corrupt && frame.length > 0) delivered.data[frame.length / 2U] ^= 0x04U;  // one byte flipped: the CRC sees it
  delivered.timestamp_us =
      static_cast<std::uint64_t>(std::llround((now_ + (affected ? faults_.extra_delay_s : 0.0) + w_delay) * 1e6));
  const int copies = (affected && unit(rng_) < faults_.duplicate_probability) || w_duplicate ? 2 : 1;
  for (auto& p : ports_) {
    if (p.get() == sender || !p->powered_) continue;
    bool accept = p->filters_.empty();
    for (const auto& fl : p->filters_) accept = accept || (delivered.id & fl.mask) == (fl.match & fl.mask);
    if (!accept) continue;
    for (int c = 0; c < copies; ++c) p->rx_.push_back(delivered);
  }
}

void SimBus::run_until(double t) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  while (true) {
    if (link_down(now_)) {
      // Nothing gets on the bus; what was queued is lost (an interface going down flushes
      // its queues).
      for (auto& p : ports_) p->tx_.clear();
      const double until = next_edge(now_, t);
      now_ = std::max(now_, until);
      if (until >= t) return;
      continue;
    }
    const FaultWindow* window_babble = active_babble(now_);
    // Arbitration among frames queued by now: the lowest identifier wins.
    SimPort* winner = nullptr;
    std::uint32_t best = 0xFFFFFFFFU;
    for (auto& p : ports_) {
      if (p->state_ == hal::CanErrorState::bus_off || p->tx_.empty() || p->tx_.front().first > now_) continue;
      if (p->tx_.front().second.id < best) {
        best = p->tx_.front().second.id;
        winner = p.get();
      }
    }
    hal::CanFrame frame;
    SimPort* sender = winner;
    bool babbled = false;
    if (window_babble != nullptr && (winner == nullptr || window_babble->babble.id <= best)) {
      frame = window_babble->babble;
      sender = nullptr;  // a node not attached as a port: every port hears it
      babbled = true;
    } else if (babbling_ && (winner == nullptr || babble_.id <= best)) {
      frame = babble_;
      sender = ports_[babbler_].get();
      babbled = true;
    } else if (winner != nullptr) {
      frame = winner->tx_.front().second;
    } else {
      // Idle: jump to the next enqueue time or to t.
      double next = t;
      for (auto& p : ports_) {
        if (!p->tx_.empty() && p->state_ != hal::CanErrorState::bus_off) next = std::min(next, std::max(p->tx_.front().first, now_));
      }
      next = next_edge(now_, next);  // a window opening while idle (babble, link down)
      if (next >= t) {
        now_ = std::max(now_, t);
        return;
      }
      now_ = next;
      continue;
    }
    const double duration = frame_duration_s(frame, timing_);
    if (now_ + duration > t) return;  // finishes after t: transmitted in a later call
    now_ += duration;
    busy_s_ += duration;
    ++frames_;
    order_.push_back(frame.id);
    if (!babbled) winner->tx_.pop_front();
    deliver(frame, sender, unit);
  }
}

}  // namespace jg::can
