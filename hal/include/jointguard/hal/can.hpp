// One CAN interface, several backends (loopback here, simulated bus and SocketCAN on the
// host, an MCU peripheral on the target). The binding is static: a node is a template on its
// port type, so the hot path has no virtual calls. The contract a backend must satisfy is
// written down here and checked at compile time with is_can_port_v.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>

namespace jg::hal {

/// A classic CAN (<= 8 bytes) or CAN FD (<= 64 bytes) frame; caller-owned storage. The
/// bytes past `length` are not part of the frame: a backend may leave anything there.
struct CanFrame {
  std::uint32_t id = 0;            ///< 11-bit (standard) or 29-bit (extended) identifier
  std::uint8_t length = 0;         ///< payload bytes (FD lengths: 0..8, 12, 16, 20, 24, 32, 48, 64)
  bool fd = false;                 ///< CAN FD frame (bit-rate switch on)
  bool extended = false;           ///< 29-bit identifier
  std::uint64_t timestamp_us = 0;  ///< receive time (backend clock)
  std::uint8_t data[64]{};
};

/// Valid CAN FD payload lengths (a DLC code maps to one of these).
[[nodiscard]] constexpr bool valid_length(std::uint8_t length, bool fd) noexcept {
  if (!fd) {
    return length <= 8U;
  }
  return length <= 8U || length == 12U || length == 16U || length == 20U || length == 24U || length == 32U ||
         length == 48U || length == 64U;
}

/// Copies a frame's header and its payload rounded up to 8, 16, 48 or 64 bytes, not always
/// the whole buffer (a momentum frame is 48 bytes, a status frame 8): fixed-size copies the
/// compiler turns into a few load/store-multiple instructions instead of a memcpy call.
inline void copy_frame(CanFrame& to, const CanFrame& from) noexcept {
  to.id = from.id;
  to.length = from.length;
  to.fd = from.fd;
  to.extended = from.extended;
  to.timestamp_us = from.timestamp_us;
  auto* dst = static_cast<std::uint8_t*>(to.data);
  const auto* src = static_cast<const std::uint8_t*>(from.data);
  if (from.length <= 8U) {
    std::memcpy(dst, src, 8);
  } else if (from.length <= 16U) {
    std::memcpy(dst, src, 16);
  } else if (from.length <= 48U) {
    std::memcpy(dst, src, 48);
  } else {
    std::memcpy(dst, src, 64);
  }
}

/// Error state of a CAN controller (ISO 11898-1 fault confinement). Stable numbers.
enum class CanErrorState : std::uint8_t { error_active = 0, error_passive = 1, bus_off = 2 };

enum class CanStatus : std::uint8_t {
  ok = 0,
  queue_full = 1,   ///< transmit queue full: frame not sent
  bus_off = 2,      ///< controller off the bus: nothing sent until recovery
  invalid = 3,      ///< frame rejected (length, identifier)
};

/// Acceptance filter: a frame passes when (id & mask) == (match & mask).
struct CanFilter {
  std::uint32_t match = 0, mask = 0;
};

/// The backend contract, checked at compile time:
///   CanStatus send(const CanFrame&)        queue a frame (never blocks)
///   bool receive(CanFrame&)                 next accepted frame, false when none
///   CanErrorState error_state() const
///   void set_filters(const CanFilter*, n)   acceptance filters (n = 0: accept all)
template <class T, class = void>
struct is_can_port : std::false_type {};
template <class T>
struct is_can_port<T, std::void_t<decltype(std::declval<T&>().send(std::declval<const CanFrame&>())),
                                  decltype(std::declval<T&>().receive(std::declval<CanFrame&>())),
                                  decltype(std::declval<const T&>().error_state()),
                                  decltype(std::declval<T&>().set_filters(std::declval<const CanFilter*>(), std::size_t{}))>>
    : std::bool_constant<std::is_same_v<decltype(std::declval<T&>().send(std::declval<const CanFrame&>())), CanStatus> &&
                         std::is_same_v<decltype(std::declval<T&>().receive(std::declval<CanFrame&>())), bool> &&
                         std::is_same_v<decltype(std::declval<const T&>().error_state()), CanErrorState>> {};
template <class T>
inline constexpr bool is_can_port_v = is_can_port<T>::value;

/// Optional zero-copy receive, on top of the contract (queues in RAM: loopback, relay):
///   const CanFrame* peek()   the next accepted frame in place, nullptr when none
///   void pop()               drops the frame peek() returned
/// Nodes decode straight out of such a port's queue instead of copying each frame out.
template <class T, class = void>
struct has_peek : std::false_type {};
template <class T>
struct has_peek<T, std::void_t<decltype(std::declval<T&>().peek()), decltype(std::declval<T&>().pop())>>
    : std::is_same<decltype(std::declval<T&>().peek()), const CanFrame*> {};
template <class T>
inline constexpr bool has_peek_v = has_peek<T>::value;

/// Monotonic clock contract: `std::uint64_t now_us() const`.
template <class T, class = void>
struct is_clock : std::false_type {};
template <class T>
struct is_clock<T, std::void_t<decltype(std::declval<const T&>().now_us())>>
    : std::is_same<decltype(std::declval<const T&>().now_us()), std::uint64_t> {};
template <class T>
inline constexpr bool is_clock_v = is_clock<T>::value;

}  // namespace jg::hal
