// Monotonic microsecond clock for the STM32G4 (is_clock_v): TIM2, the G4's 32-bit
// general-purpose timer, free-running at 1 MHz, extended to 64 bits in software.
//
// Why TIM2 and not the DWT cycle counter: at 160-170 MHz CYCCNT wraps every ~26 s and turning
// cycles into microseconds needs a 64-bit division per call; TIM2 counts microseconds
// directly, wraps every 2^32 us (71.6 min) and keeps counting while a debugger halts the core
// unless DBGMCU freezes it. The extension is correct as long as now_us() is called at least
// once per wrap (the 1 kHz cycle calls it every millisecond through the CAN port).
//
// Not reentrant: the extension state is updated without a lock, so call now_us() from one
// execution context (the cycle), or mask interrupts around calls from several.
// Status: compiled for Cortex-M4/M7 and checked against the fake register block; NOT yet run
// on hardware.
#pragma once

#include <cstdint>

#include "jointguard/hal/can.hpp"
#include "jointguard/hal/mcu/stm32g4_registers.hpp"

namespace jg::hal::stm32g4 {

/// TIM2 register offsets (RM0440 general-purpose timers; same as TIM_TypeDef).
namespace tim {
inline constexpr std::uint32_t kCr1 = 0x00U, kEgr = 0x14U, kCnt = 0x24U, kPsc = 0x28U, kArr = 0x2CU;
inline constexpr std::uint32_t kCr1Cen = 1U << 0U;
inline constexpr std::uint32_t kEgrUg = 1U << 0U;
}  // namespace tim

/// The 64-bit extension of a 32-bit counter: a smaller reading than the last one means
/// one wrap since (hence: at least one reading per wrap period).
struct CounterExtension {
  std::uint64_t high = 0;
  std::uint32_t last = 0;
};
[[nodiscard]] constexpr std::uint64_t extend(CounterExtension& e, std::uint32_t count) noexcept {
  if (count < e.last) {
    e.high += std::uint64_t{1} << 32U;
  }
  e.last = count;
  return e.high | count;
}

template <class Regs>
class Tim2Clock {
 public:
  explicit constexpr Tim2Clock(Regs& regs) noexcept : regs_(regs) {}

  /// `timer_clock_hz`: TIM2's input clock (PCLK1, doubled by RCC when the APB1 prescaler is
  /// not 1). False when it is not a whole number of MHz that the 16-bit prescaler can divide.
  [[nodiscard]] constexpr bool start(std::uint32_t timer_clock_hz) noexcept {
    constexpr std::uint32_t kTickHz = 1'000'000U;
    if (timer_clock_hz % kTickHz != 0U || timer_clock_hz / kTickHz == 0U || timer_clock_hz / kTickHz > 65536U) {
      return false;
    }
    regs_.write(rcc::kApb1enr1, regs_.read(rcc::kApb1enr1) | rcc::kApb1enr1Tim2en);
    (void)regs_.read(rcc::kApb1enr1);  // RCC needs a few cycles before the timer's registers respond
    regs_.write(kTim2Base + tim::kCr1, 0U);
    regs_.write(kTim2Base + tim::kPsc, timer_clock_hz / kTickHz - 1U);
    regs_.write(kTim2Base + tim::kArr, 0xFFFFFFFFU);
    regs_.write(kTim2Base + tim::kCnt, 0U);
    regs_.write(kTim2Base + tim::kEgr, tim::kEgrUg);  // PSC is buffered: the update event loads it
    regs_.write(kTim2Base + tim::kCr1, tim::kCr1Cen);
    extension_ = CounterExtension{};
    return true;
  }

  /// Reading the clock updates the extension: state behind a const contract, hence mutable.
  [[nodiscard]] std::uint64_t now_us() const noexcept { return extend(extension_, regs_.read(kTim2Base + tim::kCnt)); }

 private:
  Regs& regs_;
  mutable CounterExtension extension_{};
};

/// A clock whose time the caller sets (checks and host tests).
struct ManualClock {
  std::uint64_t now = 0;
  [[nodiscard]] constexpr std::uint64_t now_us() const noexcept { return now; }
};

static_assert(is_clock_v<Tim2Clock<Mmio>>, "TIM2 clock satisfies the clock contract");
static_assert(is_clock_v<Tim2Clock<FakeStm32g4>>, "TIM2 clock over the fake registers satisfies the clock contract");
static_assert(is_clock_v<ManualClock>);

}  // namespace jg::hal::stm32g4
