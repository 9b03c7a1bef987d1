// Loopback CAN port for unit tests and single-MCU bring-up: what is sent is received, in
// order, through the acceptance filters. Fixed capacity, no allocation (firmware-safe).
// The filters apply when a frame is sent (as a controller's filters do on reception): a
// frame they reject is sent (CanStatus::ok) but never queued, so a node's own frames cost
// no copy; new filters also drop the queued frames they reject (as filtering on receive would).
#pragma once

#include <cstddef>

#include "jointguard/hal/can.hpp"

namespace jg::hal {

template <std::size_t Capacity>
class LoopbackCan {
 public:
  static constexpr std::size_t kMaxFilters = 8;

  CanStatus send(const CanFrame& f) noexcept {
    if (!valid_length(f.length, f.fd) || f.id > (f.extended ? 0x1FFFFFFFU : 0x7FFU)) {
      return CanStatus::invalid;
    }
    if (!accepts(f.id)) {
      return CanStatus::ok;  // on the bus, not for this receiver
    }
    if (count_ == Capacity) {
      return CanStatus::queue_full;
    }
    copy_frame(queue_[(head_ + count_) % Capacity], f);
    ++count_;
    return CanStatus::ok;
  }
  bool receive(CanFrame& out) noexcept {
    const CanFrame* f = peek();
    if (f == nullptr) {
      return false;
    }
    copy_frame(out, *f);
    pop();
    return true;
  }
  /// Zero-copy receive (has_peek_v).
  [[nodiscard]] const CanFrame* peek() const noexcept { return count_ == 0U ? nullptr : &queue_[head_]; }
  void pop() noexcept {
    if (count_ > 0U) {
      head_ = (head_ + 1U) % Capacity;
      --count_;
    }
  }
  [[nodiscard]] CanErrorState error_state() const noexcept { return CanErrorState::error_active; }
  void set_filters(const CanFilter* filters, std::size_t n) noexcept {
    const std::size_t count = n < kMaxFilters ? n : kMaxFilters;
    // cppcheck-suppress knownConditionTrueFalse ; false positive: count follows the caller's n
    for (std::size_t i = 0; i < count; ++i) {
      // Stored with the match already masked: one AND and one compare per filter on send.
      filters_[i] = {filters[i].match & filters[i].mask, filters[i].mask};
    }
    n_filters_ = count;
    // Standard identifiers: the filters' verdict for all 2048 of them, as a controller
    // decides in hardware (one bit test on send instead of a loop over the filters).
    for (std::uint32_t id = 0; id < kStandardIds; ++id) {
      const std::uint32_t bit = 1U << (id % 32U);
      standard_accepted_[id / 32U] = filter_loop(id) ? (standard_accepted_[id / 32U] | bit) : (standard_accepted_[id / 32U] & ~bit);
    }
    std::size_t kept = 0;
    for (std::size_t i = 0; i < count_; ++i) {
      const std::size_t from = (head_ + i) % Capacity;
      if (accepts(queue_[from].id)) {
        const std::size_t to = (head_ + kept) % Capacity;
        if (to != from) {
          copy_frame(queue_[to], queue_[from]);
        }
        ++kept;
      }
    }
    count_ = kept;
  }

 private:
  static constexpr std::uint32_t kStandardIds = 2048U;
  [[nodiscard]] bool accepts(std::uint32_t id) const noexcept {
    if (id < kStandardIds) {
      return ((standard_accepted_[id / 32U] >> (id % 32U)) & 1U) != 0U;
    }
    return filter_loop(id);
  }
  [[nodiscard]] bool filter_loop(std::uint32_t id) const noexcept {
    if (n_filters_ == 0U) {
      return true;
    }
    for (std::size_t i = 0; i < n_filters_; ++i) {
      if ((id & filters_[i].mask) == filters_[i].match) {  // match stored masked (set_filters)
        return true;
      }
    }
    return false;
  }
  CanFrame queue_[Capacity]{};
  std::size_t head_ = 0, count_ = 0;
  CanFilter filters_[kMaxFilters]{};
  std::size_t n_filters_ = 0;
  std::uint32_t standard_accepted_[kStandardIds / 32U] = {
      0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU,
      0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU,
      0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU,
      0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU,
      0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU,
      0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU,
      0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU,
      0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU, 0xFFFFFFFFU};  ///< no filters: all pass
};

static_assert(is_can_port_v<LoopbackCan<4>>, "LoopbackCan satisfies the CAN port contract");
static_assert(has_peek_v<LoopbackCan<4>>, "LoopbackCan offers zero-copy receive");

}  // namespace jg::hal
