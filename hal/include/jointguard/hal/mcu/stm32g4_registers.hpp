// Register access for the STM32G4 backends, injectable: the backends are templates on a
// "register block" type with `read(address)` and `write(address, value)` on 32-bit words at
// absolute addresses. `Mmio` is the target's (volatile loads and stores at the fixed
// addresses); `FakeStm32g4` is plain memory behind the same addresses, so the register-level
// code compiles and runs on the host and in constant evaluation (the self-checks in
// hal/mcu/stm32g4/selfcheck.cpp).
//
// Addresses: RM0440 memory map, checked against ST's CMSIS device header stm32g474xx.h
// (FDCAN1_BASE = APB1PERIPH_BASE + 0x6400, FDCAN_CONFIG_BASE + 0x6500, FDCAN2 + 0x6800,
// FDCAN3 + 0x6C00, SRAMCAN_BASE + 0xA400, TIM2_BASE + 0x0000, RCC_BASE = AHB1PERIPH_BASE +
// 0x1000 with APB1PERIPH_BASE = 0x40000000 and AHB1PERIPH_BASE = 0x40020000).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace jg::hal::stm32g4 {

inline constexpr std::uint32_t kTim2Base = 0x40000000U;
inline constexpr std::uint32_t kFdcan1Base = 0x40006400U;
inline constexpr std::uint32_t kFdcanConfigBase = 0x40006500U;  ///< CKDIV, shared by the three instances
inline constexpr std::uint32_t kFdcan2Base = 0x40006800U;
inline constexpr std::uint32_t kFdcan3Base = 0x40006C00U;
inline constexpr std::uint32_t kSramcanBase = 0x4000A400U;  ///< message RAM, 0x350 bytes per instance
inline constexpr std::uint32_t kRccBase = 0x40021000U;

/// RCC registers and bits the backends touch (RM0440 "Reset and clock control").
namespace rcc {
inline constexpr std::uint32_t kApb1enr1 = kRccBase + 0x58U;
inline constexpr std::uint32_t kCcipr = kRccBase + 0x88U;
inline constexpr std::uint32_t kApb1enr1Tim2en = 1U << 0U;
inline constexpr std::uint32_t kApb1enr1Fdcanen = 1U << 25U;  ///< one clock gate for all FDCAN instances
inline constexpr std::uint32_t kCciprFdcanselShift = 24U;     ///< FDCANSEL[1:0]: 00 HSE, 01 PLL "Q", 10 PCLK1
inline constexpr std::uint32_t kCciprFdcanselMask = 3U << kCciprFdcanselShift;
}  // namespace rcc

/// The target's register block: every access is one 32-bit volatile load or store, in
/// program order (the peripheral region is Device memory on Cortex-M, so the core does not
/// reorder these accesses either).
struct Mmio {
  // An object, not static functions, so that a backend holds it by reference like the fake.
  // NOLINTNEXTLINE(readability-convert-member-functions-to-static): see above
  [[nodiscard]] std::uint32_t read(std::uint32_t address) const noexcept {
    // NOLINTNEXTLINE(performance-no-int-to-ptr): a peripheral register at its fixed address
    return *reinterpret_cast<const volatile std::uint32_t*>(std::uintptr_t{address});
  }
  // NOLINTNEXTLINE(readability-convert-member-functions-to-static): as read()
  void write(std::uint32_t address, std::uint32_t value) noexcept {
    // NOLINTNEXTLINE(performance-no-int-to-ptr): a peripheral register at its fixed address
    *reinterpret_cast<volatile std::uint32_t*>(std::uintptr_t{address}) = value;
  }
  /// One 8-bit store (the CRC unit's data register takes 8, 16 or 32-bit writes).
  // NOLINTNEXTLINE(readability-convert-member-functions-to-static): as read()
  void write8(std::uint32_t address, std::uint8_t value) noexcept {
    // NOLINTNEXTLINE(performance-no-int-to-ptr): a peripheral register at its fixed address
    *reinterpret_cast<volatile std::uint8_t*>(std::uintptr_t{address}) = value;
  }
};

/// Plain memory behind the addresses the STM32G4 backends use: TIM2, FDCAN1..3 (with CKDIV),
/// their message RAM and RCC. Reads return what was last written (no hardware behaviour:
/// a test sets the status registers itself). Any access outside these windows, or not
/// word-aligned, is remembered as a stray access.
class FakeStm32g4 {
  static constexpr std::uint32_t kWindowBytes = 0x400U;
  static constexpr std::uint32_t kMessageRamBytes = 3U * 0x350U;
  struct Window {
    std::uint32_t base, bytes;
  };
  // One array holds the windows back to back, in this order.
  static constexpr std::array<Window, 4> kWindows{{{kTim2Base, kWindowBytes},
                                                   {kFdcan1Base, 3U * kWindowBytes},
                                                   {kSramcanBase, kMessageRamBytes},
                                                   {kRccBase, kWindowBytes}}};
  static constexpr std::size_t kWords = (kWindowBytes + 3U * kWindowBytes + kMessageRamBytes + kWindowBytes) / 4U;
  static constexpr std::size_t kStray = kWords;

  [[nodiscard]] static constexpr std::size_t index_of(std::uint32_t address) noexcept {
    if ((address & 3U) != 0U) {
      return kStray;
    }
    std::size_t first = 0;
    for (const Window& w : kWindows) {
      if (address >= w.base && address - w.base < w.bytes) {
        return first + (address - w.base) / 4U;
      }
      first += w.bytes / 4U;
    }
    return kStray;
  }

 public:
  // Not const, unlike Mmio::read: a stray read is recorded. The backends hold their register
  // block by non-const reference, so their const members can still read through it.
  [[nodiscard]] constexpr std::uint32_t read(std::uint32_t address) noexcept {
    const std::size_t i = index_of(address);
    if (i == kStray) {
      stray_ = true;
      return 0U;
    }
    return words_[i];
  }
  constexpr void write(std::uint32_t address, std::uint32_t value) noexcept {
    const std::size_t i = index_of(address);
    if (i == kStray) {
      stray_ = true;
      return;
    }
    words_[i] = value;
  }
  /// What the hardware would have set (status registers, received elements).
  constexpr void poke(std::uint32_t address, std::uint32_t value) noexcept { write(address, value); }
  [[nodiscard]] constexpr std::uint32_t peek(std::uint32_t address) const noexcept {
    const std::size_t i = index_of(address);
    return i == kStray ? 0U : words_[i];
  }
  [[nodiscard]] constexpr bool stray_access() const noexcept { return stray_; }

 private:
  std::array<std::uint32_t, kWords> words_{};
  bool stray_ = false;
};

}  // namespace jg::hal::stm32g4
