// Self-checks of the STM32G4 FDCAN port and TIM2 clock against the fake register block,
// evaluated by the compiler (static_assert): a failure is a build error, in every build
// (host and cross). The expected register words are written out by hand from RM0440's field
// positions, not built with the backend's own constants, so a misplaced field shows here.
// What they cannot show: hardware behaviour (INIT synchronisation, bus integration, the
// FIFO indices moving); that needs a board (docs/porting.md).
#include <cstdint>

#include "jointguard/hal/mcu/stm32g4_clock.hpp"
#include "jointguard/hal/mcu/stm32g4_fdcan.hpp"
#include "jointguard/hal/mcu/stm32g4_registers.hpp"

namespace jg::hal::stm32g4 {
namespace {

using FakePort = FdcanPort<FakeStm32g4, ManualClock>;

constexpr std::uint32_t kRam = kSramcanBase;  // FDCAN1's block
constexpr std::uint32_t reg(std::uint32_t offset) { return kFdcan1Base + offset; }

constexpr CanFrame momentum_frame(std::uint32_t id) {
  CanFrame f{};
  f.id = id;
  f.fd = true;
  f.length = 48;
  for (std::uint32_t i = 0; i < 48U; ++i) {
    f.data[i] = static_cast<std::uint8_t>(i + 1U);
  }
  return f;
}

// start(): clocks, timing, filters and global filter, leaving INIT.
constexpr bool start_programs_the_registers() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FakePort port(regs, clock, FdcanConfig{});
  regs.poke(kRam + 0x10U, 0xDEADBEEFU);  // message RAM must be flushed
  if (port.start() != FdcanError::none || !port.started()) {
    return false;
  }
  return regs.peek(rcc::kApb1enr1) == 0x02000000U &&  // FDCANEN, bit 25
         regs.peek(rcc::kCcipr) == 0x01000000U &&     // FDCANSEL = 01, PLL "Q"
         regs.peek(reg(0x018U)) == 0x00000300U &&     // CCCR: FDOE | BRSE, INIT and CCE cleared
         regs.peek(reg(0x01CU)) == 0x1E003E0FU &&     // NBTP: NSJW 15, NBRP 0, NTSEG1 62, NTSEG2 15
         regs.peek(reg(0x00CU)) == 0x00800A33U &&     // DBTP: TDC, DBRP 0, DTSEG1 10, DTSEG2 3, DSJW 3
         regs.peek(reg(0x048U)) == 0x00000B00U &&     // TDCR: TDCO 11, TDCF 0
         regs.peek(reg(0x080U)) == 0x00000003U &&     // RXGFC: no filters, accept into FIFO 0, no remote frames
         regs.peek(reg(0x0C0U)) == 0U &&              // TXBC: FIFO mode
         regs.peek(reg(0x010U)) == 0U &&              // TEST: no loopback
         regs.peek(kFdcanConfigBase) == 0U &&         // CKDIV: undivided
         regs.peek(kRam + 0x10U) == 0U && !regs.stray_access();
}
static_assert(start_programs_the_registers());

constexpr bool loopback_mode_sets_test_bits() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FdcanConfig config{};
  config.test_mode = TestMode::internal_loopback;
  FakePort port(regs, clock, config);
  return port.start() == FdcanError::none && regs.peek(reg(0x018U)) == 0x000003A0U &&  // CCCR: TEST, MON, FDOE, BRSE
         regs.peek(reg(0x010U)) == 0x00000010U;                                         // TEST.LBCK
}
static_assert(loopback_mode_sets_test_bits());

constexpr bool second_instance_uses_its_own_blocks() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FdcanConfig config{};
  config.instance = kFdcan2;
  FakePort port(regs, clock, config);
  regs.poke(kRam + 0x350U + 0x10U, 1U);
  return port.start() == FdcanError::none && regs.peek(0x40006800U + 0x01CU) == 0x1E003E0FU &&
         regs.peek(kFdcan1Base + 0x01CU) == 0U && regs.peek(kRam + 0x350U + 0x10U) == 0U && !regs.stray_access();
}
static_assert(second_instance_uses_its_own_blocks());

constexpr bool invalid_timing_is_refused() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FdcanConfig config{};
  config.data.seg1 = 40;  // DTSEG1 holds 1..32
  FakePort port(regs, clock, config);
  return port.start() == FdcanError::invalid_timing && port.last_error() == FdcanError::invalid_timing &&
         !port.started() && regs.peek(rcc::kApb1enr1) == 0U;
}
static_assert(invalid_timing_is_refused());

// send(): element at the put index, T0/T1/data words, then the add request.
constexpr bool send_writes_the_put_element() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FakePort port(regs, clock, FdcanConfig{});
  if (port.start() != FdcanError::none) {
    return false;
  }
  regs.poke(reg(0x0C4U), 2U << 16U);  // TXFQS: put index 2
  if (port.send(momentum_frame(0x021U)) != CanStatus::ok) {
    return false;
  }
  constexpr std::uint32_t kElement = kRam + 0x278U + 2U * 72U;
  return regs.peek(kElement) == 0x00840000U &&           // T0: 0x021 << 18
         regs.peek(kElement + 4U) == 0x003E0000U &&      // T1: FDF | BRS | DLC 14 (48 bytes)
         regs.peek(kElement + 8U) == 0x04030201U &&      // bytes 1..4, little endian
         regs.peek(kElement + 8U + 44U) == 0x302F2E2DU &&  // bytes 45..48
         regs.peek(kElement + 8U + 48U) == 0U &&         // nothing past the length
         regs.peek(reg(0x0CCU)) == 0x4U && !regs.stray_access();  // TXBAR: buffer 2
}
static_assert(send_writes_the_put_element());

constexpr bool send_extended_classic() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FakePort port(regs, clock, FdcanConfig{});
  (void)port.start();
  CanFrame f{};
  f.id = 0x1ABCDEF0U;
  f.extended = true;
  f.length = 3;
  f.data[0] = 0xAA;
  f.data[1] = 0xBB;
  f.data[2] = 0xCC;
  return port.send(f) == CanStatus::ok && regs.peek(kRam + 0x278U) == 0x5ABCDEF0U &&  // XTD | id
         regs.peek(kRam + 0x278U + 4U) == 0x00030000U &&                              // classic, DLC 3
         regs.peek(kRam + 0x278U + 8U) == 0x00CCBBAAU && regs.peek(reg(0x0CCU)) == 0x1U;
}
static_assert(send_extended_classic());

constexpr bool send_refusals() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FakePort port(regs, clock, FdcanConfig{});
  CanFrame f = momentum_frame(0x021U);
  if (port.send(f) != CanStatus::bus_off) {  // not started: not on the bus
    return false;
  }
  (void)port.start();
  CanFrame bad_length = f;
  bad_length.length = 10;
  CanFrame bad_id = f;
  bad_id.id = 0x800U;
  if (port.send(bad_length) != CanStatus::invalid || port.send(bad_id) != CanStatus::invalid) {
    return false;
  }
  regs.poke(reg(0x0C4U), 1U << 21U);  // TXFQS.TFQF
  if (port.send(f) != CanStatus::queue_full) {
    return false;
  }
  regs.poke(reg(0x044U), 1U << 7U);  // PSR.BO
  return port.send(f) == CanStatus::bus_off && regs.peek(reg(0x0CCU)) == 0U;
}
static_assert(send_refusals());

constexpr bool classic_only_refuses_fd() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FdcanConfig config{};
  config.fd = false;
  FakePort port(regs, clock, config);
  return port.start() == FdcanError::none && regs.peek(reg(0x018U)) == 0U &&
         port.send(momentum_frame(0x021U)) == CanStatus::invalid;
}
static_assert(classic_only_refuses_fd());

// receive(): element at the get index, acknowledge, timestamp from the clock.
constexpr bool receive_reads_the_get_element() {
  FakeStm32g4 regs{};
  ManualClock clock{};
  FakePort port(regs, clock, FdcanConfig{});
  (void)port.start();
  constexpr std::uint32_t kElement = kRam + 0x0B0U + 1U * 72U;
  regs.poke(kElement, 0x031U << 18U);                    // R0: standard id 0x031
  regs.poke(kElement + 4U, 0x003E0000U | 0x1234U);        // R1: FDF | BRS | DLC 14 | RXTS
  for (std::uint32_t w = 0; w < 12U; ++w) {
    regs.poke(kElement + 8U + 4U * w, 0x01010101U * (w + 1U));
  }
  regs.poke(reg(0x090U), (1U << 8U) | 1U);  // RXF0S: get index 1, fill level 1
  clock.now = 123456U;
  CanFrame f{};
  f.data[60] = 0x55;  // stale byte from an earlier frame
  if (!port.receive(f)) {
    return false;
  }
  const bool header = f.id == 0x031U && !f.extended && f.fd && f.length == 48U && f.timestamp_us == 123456U;
  const bool payload = f.data[0] == 1U && f.data[4] == 2U && f.data[47] == 12U && f.data[48] == 0U && f.data[60] == 0U;
  const bool acknowledged = regs.peek(reg(0x094U)) == 1U;  // RXF0A = get index
  regs.poke(reg(0x090U), 0U);
  return header && payload && acknowledged && !port.receive(f) && !regs.stray_access();
}
static_assert(receive_reads_the_get_element());

constexpr bool receive_extended_classic_and_lost() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FakePort port(regs, clock, FdcanConfig{});
  (void)port.start();
  regs.poke(kRam + 0x0B0U, 0x40000000U | 0x0ABCDEU);  // XTD
  regs.poke(kRam + 0x0B0U + 4U, 0x000F0000U);        // classic, DLC 15: 8 bytes
  regs.poke(kRam + 0x0B0U + 8U, 0x44332211U);
  regs.poke(kRam + 0x0B0U + 12U, 0x88776655U);
  regs.poke(reg(0x090U), (1U << 25U) | 3U);  // RF0L, fill 3, get 0
  CanFrame f{};
  return port.receive(f) && f.extended && f.id == 0x0ABCDEU && !f.fd && f.length == 8U && f.data[0] == 0x11U &&
         f.data[7] == 0x88U && port.rx_lost() == 1U && regs.peek(reg(0x050U)) == 0x4U;  // IR.RF0L cleared
}
static_assert(receive_extended_classic_and_lost());

// set_filters(): classic elements, list size, reject non-matching; overflow recorded.
constexpr bool filters_are_programmed() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FakePort port(regs, clock, FdcanConfig{});
  const CanFilter filters[] = {{0x021U, 0x7FFU}, {0x030U, 0x7F0U}, {0x1000U, 0x1FFFFFFFU}};
  port.set_filters(static_cast<const CanFilter*>(filters), 3);  // before start: kept, programmed by start()
  (void)port.start();
  const bool elements = regs.peek(kRam) == 0x882107FFU &&  // SFT 10 (classic), SFEC 001 (FIFO 0), SFID1 0x021, SFID2 0x7FF
                        regs.peek(kRam + 4U) == 0x883007F0U &&
                        regs.peek(kRam + 8U) == 0U;  // needs bits above bit 10: never matches, disabled
  const bool global = regs.peek(reg(0x080U)) == 0x0003002BU;  // LSS 3, ANFS 10, ANFE 10, RRFS, RRFE
  port.set_filters(nullptr, 0);  // while running: back to accept-all
  const bool cleared = regs.peek(reg(0x080U)) == 0x00000003U && regs.peek(kRam) == 0U &&
                       (regs.peek(reg(0x018U)) & 0x3U) == 0U;  // INIT and CCE left again
  return elements && global && cleared && port.last_error() == FdcanError::none && !regs.stray_access();
}
static_assert(filters_are_programmed());

constexpr bool too_many_filters_is_recorded() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FakePort port(regs, clock, FdcanConfig{});
  CanFilter filters[30]{};
  for (std::uint32_t i = 0; i < 30U; ++i) {
    filters[i] = {i, 0x7FFU};
  }
  port.set_filters(static_cast<const CanFilter*>(filters), 30);
  (void)port.start();
  return port.last_error() == FdcanError::too_many_filters && regs.peek(reg(0x080U)) == 0x001C002BU &&  // LSS 28
         regs.peek(kRam + 27U * 4U) == 0x881B07FFU && regs.peek(kRam + 28U * 4U) == 0U;  // 28th set; extended list untouched
}
static_assert(too_many_filters_is_recorded());

// error_state(), counters, bus-off recovery.
constexpr bool error_state_follows_psr() {
  FakeStm32g4 regs{};
  const ManualClock clock{};
  FakePort port(regs, clock, FdcanConfig{});
  const bool stopped = port.error_state() == CanErrorState::bus_off;
  (void)port.start();
  const bool active = port.error_state() == CanErrorState::error_active;
  regs.poke(reg(0x044U), 1U << 5U);  // EP
  const bool passive = port.error_state() == CanErrorState::error_passive;
  regs.poke(reg(0x044U), (1U << 7U) | (1U << 5U));  // BO
  const bool off = port.error_state() == CanErrorState::bus_off;
  regs.poke(reg(0x040U), (1U << 15U) | (0x7FU << 8U) | 0xF8U);  // ECR: RP, REC 127, TEC 248
  const FdcanErrorCounters c = port.error_counters();
  regs.poke(reg(0x018U), 0x00000301U);  // the controller set INIT on bus-off
  port.recover_from_bus_off();
  return stopped && active && passive && off && c.transmit == 248U && c.receive == 127U && c.receive_passive &&
         regs.peek(reg(0x018U)) == 0x00000300U;
}
static_assert(error_state_follows_psr());

// TIM2 clock: 1 MHz from the timer clock; the 64-bit extension across the 32-bit wrap (now_us
// itself keeps its extension in a mutable member, which C++17 constant evaluation cannot read).
constexpr bool tim2_runs_at_1mhz() {
  FakeStm32g4 regs{};
  Tim2Clock<FakeStm32g4> clock(regs);
  if (clock.start(7'500'000U) || !clock.start(160'000'000U)) {  // 7.5 MHz is not a whole number of MHz
    return false;
  }
  return regs.peek(kTim2Base + 0x28U) == 159U && regs.peek(kTim2Base + 0x2CU) == 0xFFFFFFFFU &&  // PSC, ARR
         regs.peek(kTim2Base + 0x14U) == 1U && regs.peek(kTim2Base + 0x00U) == 1U &&              // UG, CEN
         (regs.peek(rcc::kApb1enr1) & 1U) == 1U && !regs.stray_access();                          // TIM2EN
}
static_assert(tim2_runs_at_1mhz());

constexpr bool extension_counts_wraps() {
  CounterExtension e{};
  const std::uint64_t a = extend(e, 0xFFFFFFF0U);
  const std::uint64_t b = extend(e, 0x10U);
  const std::uint64_t c = extend(e, 0x10U);
  const std::uint64_t d = extend(e, 0x5U);
  return a == 0xFFFFFFF0U && b == 0x100000010ULL && c == b && d == 0x200000005ULL;
}
static_assert(extension_counts_wraps());

}  // namespace
}  // namespace jg::hal::stm32g4
