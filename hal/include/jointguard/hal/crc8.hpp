// CRC-8/AUTOSAR for the frame codecs, as a policy the HAL provides: polynomial 0x2F,
// initial value 0xFF, final XOR 0xFF, no reflection (check("123456789") = 0xDF).
//
// Contract (checked at compile time with is_crc8_policy_v; a static function, so the hot
// path has no virtual call and no object to pass around):
//   static std::uint8_t crc8(const std::uint8_t* data, std::uint8_t length) noexcept
// Policies here: Crc8AutosarTable (the default: 256-byte table in flash, about 3
// instructions a byte on the Cortex-M4) and Crc8AutosarBitwise (the definition, eight
// shift-and-XOR steps a byte: the reference the others are tested against). A hardware CRC
// unit is another policy (hal/include/jointguard/hal/mcu/stm32g4_crc.hpp).
//
// Which policy a node's frames use: its port's `crc8_policy` member type when the port
// names one (a backend that owns a CRC unit), else the table (crc8_policy_t<Port>).
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>

namespace jg::hal {

/// CRC-8/AUTOSAR: polynomial 0x2F, initial 0xFF, final XOR 0xFF (check("123456789") = 0xDF),
/// bit by bit: the reference the table is built from and checked against (tests/can).
[[nodiscard]] constexpr std::uint8_t crc8_autosar_bitwise(const std::uint8_t* data, std::uint8_t length) noexcept {
  std::uint8_t crc = 0xFFU;
  for (std::uint8_t i = 0; i < length; ++i) {
    crc = static_cast<std::uint8_t>(crc ^ data[i]);
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x80U) != 0U ? static_cast<std::uint8_t>((static_cast<unsigned>(crc) << 1U) ^ 0x2FU)
                              : static_cast<std::uint8_t>(static_cast<unsigned>(crc) << 1U);
    }
  }
  return static_cast<std::uint8_t>(crc ^ 0xFFU);
}

namespace detail {
/// The register after shifting the byte v through it (no initial value, no final XOR).
constexpr std::array<std::uint8_t, 256> crc8_autosar_table() noexcept {
  std::array<std::uint8_t, 256> t{};
  for (unsigned v = 0; v < 256U; ++v) {
    auto crc = static_cast<std::uint8_t>(v);
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x80U) != 0U ? static_cast<std::uint8_t>((static_cast<unsigned>(crc) << 1U) ^ 0x2FU)
                              : static_cast<std::uint8_t>(static_cast<unsigned>(crc) << 1U);
    }
    t[v] = crc;
  }
  return t;
}
}  // namespace detail

/// 256 bytes of constant data (flash on the MCU): one lookup per byte instead of eight
/// shift-and-XOR steps (about 3 instructions a byte on the Cortex-M4 instead of about 44).
inline constexpr std::array<std::uint8_t, 256> kCrc8AutosarTable = detail::crc8_autosar_table();

/// CRC-8/AUTOSAR, table-driven; the same value as crc8_autosar_bitwise for every input.
/// Four bytes per iteration: on little-endian targets one (unaligned) word load, then the
/// four bytes taken from the register low byte first (about 3.5 instructions a byte on the
/// Cortex-M4 with the loop); elsewhere byte by byte.
inline std::uint8_t crc8_autosar(const std::uint8_t* data, std::uint8_t length) noexcept {
  unsigned crc = 0xFFU;
  const std::uint8_t* p = data;
  const std::uint8_t* const end = data + length;
  const unsigned words = length / 4U;
  // Frame lengths are constants where this is inlined: fully unrolled, no loop overhead.
#pragma GCC unroll 16
  for (unsigned i = 0; i < words; ++i, p += 4) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    std::uint32_t w = 0;
    std::memcpy(&w, p, 4);
    crc = kCrc8AutosarTable[(crc ^ w) & 0xFFU];
    crc = kCrc8AutosarTable[(crc ^ (w >> 8U)) & 0xFFU];
    crc = kCrc8AutosarTable[(crc ^ (w >> 16U)) & 0xFFU];
    crc = kCrc8AutosarTable[crc ^ (w >> 24U)];
#else
    crc = kCrc8AutosarTable[crc ^ p[0]];
    crc = kCrc8AutosarTable[crc ^ p[1]];
    crc = kCrc8AutosarTable[crc ^ p[2]];
    crc = kCrc8AutosarTable[crc ^ p[3]];
#endif
  }
#pragma GCC unroll 3
  for (; p != end; ++p) {
    crc = kCrc8AutosarTable[crc ^ *p];
  }
  return static_cast<std::uint8_t>(crc ^ 0xFFU);
}

/// The table-driven software CRC (the default policy).
struct Crc8AutosarTable {
  static std::uint8_t crc8(const std::uint8_t* data, std::uint8_t length) noexcept { return crc8_autosar(data, length); }
};

/// The bit-by-bit definition as a policy (tests: a stand-in for a hardware unit that must
/// give the same frames).
struct Crc8AutosarBitwise {
  static std::uint8_t crc8(const std::uint8_t* data, std::uint8_t length) noexcept {
    return crc8_autosar_bitwise(data, length);
  }
};

template <class T, class = void>
struct is_crc8_policy : std::false_type {};
template <class T>
struct is_crc8_policy<T, std::void_t<decltype(T::crc8(std::declval<const std::uint8_t*>(), std::uint8_t{}))>>
    : std::is_same<decltype(T::crc8(std::declval<const std::uint8_t*>(), std::uint8_t{})), std::uint8_t> {};
template <class T>
inline constexpr bool is_crc8_policy_v = is_crc8_policy<T>::value;

/// A port's CRC policy: Port::crc8_policy when declared, else the table.
template <class Port, class = void>
struct crc8_policy_of {
  using type = Crc8AutosarTable;
};
template <class Port>
struct crc8_policy_of<Port, std::void_t<typename Port::crc8_policy>> {
  using type = typename Port::crc8_policy;
};
template <class Port>
using crc8_policy_t = typename crc8_policy_of<Port>::type;

static_assert(is_crc8_policy_v<Crc8AutosarTable> && is_crc8_policy_v<Crc8AutosarBitwise>, "the software policies");

}  // namespace jg::hal
