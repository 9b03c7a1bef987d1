// CAN port on the STM32G4's FDCAN (Bosch M_CAN derived), register level, no vendor HAL.
// Satisfies the HAL contract (is_can_port_v), so a JointNode binds to it statically.
//
// Status: compiled for Cortex-M4/M7 and checked against a fake register block (plain memory,
// hal/mcu/stm32g4/selfcheck.cpp); NOT yet run on hardware. docs/porting.md lists what to
// verify on a board first.
//
// Sources (facts only): RM0440 (STM32G4 reference manual), FDCAN chapter: register map,
// "Message RAM" (fixed layout per instance), CCCR/NBTP/DBTP/TDCR/RXGFC/RXF0S/TXFQS
// descriptions; cross-checked against ST's CMSIS header stm32g474xx.h (offsets, bit
// positions) and the layout constants of ST's stm32g4xx_hal_fdcan.c (SRAMCAN_FLSSA...).
//
// Choices:
// - Polled, no interrupts: the node drains the Rx FIFO at the start of each cycle and never
//   waits on the bus, so an interrupt would only add a context that touches the FIFO.
// - Tx in FIFO mode (TXBC.TFQM = 0): frames leave in the order the node queued them.
// - Rx FIFO 0 in blocking mode (the reset default): when it is full the newest frame is
//   lost and counted (RF0L); overwrite mode would race with the element being read.
// - Receive timestamps come from the injected clock at read-out: the FDCAN's internal
//   timestamp counter counts nominal bit times and is not a constant time base in CAN FD
//   (RM0440, TSCC.TCP), and the node does not use timestamps for freshness (it uses the
//   sequence counters), so a read-out time is enough.
// - Acceptance filters apply to 11-bit identifiers (the protocol's); with filters set,
//   extended frames are rejected, with none everything is accepted (as LoopbackCan).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "jointguard/hal/can.hpp"
#include "jointguard/hal/mcu/stm32g4_clock.hpp"
#include "jointguard/hal/mcu/stm32g4_registers.hpp"

namespace jg::hal::stm32g4 {

/// FDCAN register offsets (RM0440 FDCAN register map; same as FDCAN_GlobalTypeDef).
namespace fdcan {
inline constexpr std::uint32_t kDbtp = 0x00CU;
inline constexpr std::uint32_t kTest = 0x010U;
inline constexpr std::uint32_t kCccr = 0x018U;
inline constexpr std::uint32_t kNbtp = 0x01CU;
inline constexpr std::uint32_t kTscc = 0x020U;
inline constexpr std::uint32_t kEcr = 0x040U;
inline constexpr std::uint32_t kPsr = 0x044U;
inline constexpr std::uint32_t kTdcr = 0x048U;
inline constexpr std::uint32_t kIr = 0x050U;
inline constexpr std::uint32_t kIe = 0x054U;
inline constexpr std::uint32_t kIls = 0x058U;
inline constexpr std::uint32_t kIle = 0x05CU;
inline constexpr std::uint32_t kRxgfc = 0x080U;
inline constexpr std::uint32_t kRxf0s = 0x090U;
inline constexpr std::uint32_t kRxf0a = 0x094U;
inline constexpr std::uint32_t kTxbc = 0x0C0U;
inline constexpr std::uint32_t kTxfqs = 0x0C4U;
inline constexpr std::uint32_t kTxbar = 0x0CCU;
inline constexpr std::uint32_t kCkdiv = kFdcanConfigBase;  ///< absolute; writable only through FDCAN1's INIT+CCE

// CCCR
inline constexpr std::uint32_t kCccrInit = 1U << 0U;
inline constexpr std::uint32_t kCccrCce = 1U << 1U;
inline constexpr std::uint32_t kCccrCsa = 1U << 3U;
inline constexpr std::uint32_t kCccrCsr = 1U << 4U;
inline constexpr std::uint32_t kCccrMon = 1U << 5U;
inline constexpr std::uint32_t kCccrTest = 1U << 7U;
inline constexpr std::uint32_t kCccrFdoe = 1U << 8U;
inline constexpr std::uint32_t kCccrBrse = 1U << 9U;
// TEST
inline constexpr std::uint32_t kTestLbck = 1U << 4U;
// DBTP / TDCR
inline constexpr std::uint32_t kDbtpTdc = 1U << 23U;
inline constexpr std::uint32_t kTdcMax = 0x7FU;  ///< TDCO and TDCF are 7-bit fields (minimum time quanta)
// PSR / ECR
inline constexpr std::uint32_t kPsrEp = 1U << 5U;
inline constexpr std::uint32_t kPsrBo = 1U << 7U;
// IR (write 1 to clear), 24 flags on the G4
inline constexpr std::uint32_t kIrRf0l = 1U << 2U;
inline constexpr std::uint32_t kIrAll = 0x00FFFFFFU;
// RXGFC
inline constexpr std::uint32_t kRxgfcRrfe = 1U << 0U;  ///< reject remote frames, extended
inline constexpr std::uint32_t kRxgfcRrfs = 1U << 1U;  ///< reject remote frames, standard
inline constexpr std::uint32_t kRxgfcAnfeReject = 2U << 2U;
inline constexpr std::uint32_t kRxgfcAnfsReject = 2U << 4U;
inline constexpr std::uint32_t kRxgfcLssShift = 16U;
// RXF0S / TXFQS
inline constexpr std::uint32_t kRxf0sFillMask = 0xFU;
inline constexpr std::uint32_t kRxf0sGetShift = 8U;
inline constexpr std::uint32_t kRxf0sRf0l = 1U << 25U;
inline constexpr std::uint32_t kTxfqsPutShift = 16U;
inline constexpr std::uint32_t kTxfqsFull = 1U << 21U;
inline constexpr std::uint32_t kIndexMask = 3U;  ///< put/get indices are 2 bits (3 elements)

// Message RAM elements (R0/T0, R1/T1, data from word 2)
inline constexpr std::uint32_t kElementXtd = 1U << 30U;
inline constexpr std::uint32_t kElementRtr = 1U << 29U;
inline constexpr std::uint32_t kElementStdIdShift = 18U;
inline constexpr std::uint32_t kElementDlcShift = 16U;
inline constexpr std::uint32_t kElementBrs = 1U << 20U;
inline constexpr std::uint32_t kElementFdf = 1U << 21U;
// Standard filter element: SFT[31:30], SFEC[29:27], SFID1[26:16], SFID2[10:0]
inline constexpr std::uint32_t kFilterClassic = 2U << 30U;  ///< SFID1 = filter, SFID2 = mask
inline constexpr std::uint32_t kFilterToFifo0 = 1U << 27U;
inline constexpr std::uint32_t kFilterId1Shift = 16U;
}  // namespace fdcan

/// The G4's fixed message RAM layout per instance (RM0440 "Message RAM"; no SIDFC/XIDFC/
/// RXF0C... registers as on the full M_CAN: the layout is not configurable).
namespace message_ram {
inline constexpr std::uint32_t kStandardFilters = 28, kExtendedFilters = 8, kRxFifoElements = 3,
                               kTxEventElements = 3, kTxBuffers = 3;
inline constexpr std::uint32_t kElementBytes = 18U * 4U;  ///< header (2 words) + 64 data bytes
inline constexpr std::uint32_t kStandardFilterOffset = 0U;
inline constexpr std::uint32_t kExtendedFilterOffset = kStandardFilterOffset + kStandardFilters * 4U;
inline constexpr std::uint32_t kRxFifo0Offset = kExtendedFilterOffset + kExtendedFilters * 8U;
inline constexpr std::uint32_t kRxFifo1Offset = kRxFifo0Offset + kRxFifoElements * kElementBytes;
inline constexpr std::uint32_t kTxEventOffset = kRxFifo1Offset + kRxFifoElements * kElementBytes;
inline constexpr std::uint32_t kTxBufferOffset = kTxEventOffset + kTxEventElements * 8U;
inline constexpr std::uint32_t kBytes = kTxBufferOffset + kTxBuffers * kElementBytes;
// The same numbers as ST's SRAMCAN_FLESA, _RF0SA, _RF1SA, _TEFSA, _TFQSA, _SIZE.
static_assert(kExtendedFilterOffset == 0x070U && kRxFifo0Offset == 0x0B0U && kRxFifo1Offset == 0x188U &&
              kTxEventOffset == 0x260U && kTxBufferOffset == 0x278U && kBytes == 0x350U);
}  // namespace message_ram

struct FdcanInstance {
  std::uint32_t registers = kFdcan1Base;
  std::uint32_t message_ram = kSramcanBase;  ///< instance n's block follows instance n-1's
};
inline constexpr FdcanInstance kFdcan1{kFdcan1Base, kSramcanBase};
inline constexpr FdcanInstance kFdcan2{kFdcan2Base, kSramcanBase + message_ram::kBytes};
inline constexpr FdcanInstance kFdcan3{kFdcan3Base, kSramcanBase + 2U * message_ram::kBytes};

/// RCC_CCIPR.FDCANSEL: the kernel clock the bit timing is derived from.
enum class KernelClock : std::uint8_t { hse = 0, pll_q = 1, pclk1 = 2 };

/// One phase's bit timing in time quanta (tq); the registers hold each value minus one.
struct BitTiming {
  std::uint16_t prescaler = 1;  ///< kernel clock periods per tq
  std::uint16_t seg1 = 1;       ///< tq between the sync segment and the sample point (prop + phase 1)
  std::uint8_t seg2 = 1;        ///< tq after the sample point (phase 2)
  std::uint8_t sjw = 1;         ///< resynchronisation jump width
};

[[nodiscard]] constexpr std::uint32_t tq_per_bit(const BitTiming& t) noexcept { return 1U + t.seg1 + t.seg2; }
[[nodiscard]] constexpr std::uint32_t bit_rate(std::uint32_t kernel_hz, const BitTiming& t) noexcept {
  return kernel_hz / (std::uint32_t{t.prescaler} * tq_per_bit(t));
}
/// Sample point in per mille of the bit time.
[[nodiscard]] constexpr std::uint32_t sample_point_permille(const BitTiming& t) noexcept {
  return 1000U * (1U + t.seg1) / tq_per_bit(t);
}
/// NBTP field ranges: NBRP 1..512, NTSEG1 1..256, NTSEG2 1..128, NSJW 1..128 (and SJW <= phase 2).
[[nodiscard]] constexpr bool nominal_fits(const BitTiming& t) noexcept {
  return t.prescaler >= 1U && t.prescaler <= 512U && t.seg1 >= 1U && t.seg1 <= 256U && t.seg2 >= 1U && t.seg2 <= 128U &&
         t.sjw >= 1U && t.sjw <= t.seg2;
}
/// DBTP field ranges: DBRP 1..32, DTSEG1 1..32, DTSEG2 1..16, DSJW 1..16 (and SJW <= phase 2).
[[nodiscard]] constexpr bool data_fits(const BitTiming& t) noexcept {
  return t.prescaler >= 1U && t.prescaler <= 32U && t.seg1 >= 1U && t.seg1 <= 32U && t.seg2 >= 1U && t.seg2 <= 16U &&
         t.sjw >= 1U && t.sjw <= t.seg2;
}

/// 80 MHz kernel clock (PLL "Q" output), prescaler 1 in both phases (same tq, 12.5 ns):
/// nominal 1 + 63 + 16 = 80 tq -> 1 Mbit/s, sample point 64/80 = 80 %, SJW 16;
/// data    1 + 11 +  4 = 16 tq -> 5 Mbit/s, sample point 12/16 = 75 %, SJW 4.
inline constexpr std::uint32_t kKernelClock80MHz = 80'000'000U;
inline constexpr BitTiming kNominal1M80MHz{1, 63, 16, 16};
inline constexpr BitTiming kData5M80MHz{1, 11, 4, 4};
static_assert(bit_rate(kKernelClock80MHz, kNominal1M80MHz) * tq_per_bit(kNominal1M80MHz) == kKernelClock80MHz);
static_assert(bit_rate(kKernelClock80MHz, kNominal1M80MHz) == 1'000'000U && sample_point_permille(kNominal1M80MHz) == 800U);
static_assert(bit_rate(kKernelClock80MHz, kData5M80MHz) * tq_per_bit(kData5M80MHz) == kKernelClock80MHz);
static_assert(bit_rate(kKernelClock80MHz, kData5M80MHz) == 5'000'000U && sample_point_permille(kData5M80MHz) == 750U);
static_assert(nominal_fits(kNominal1M80MHz) && data_fits(kData5M80MHz));

/// The same rates from a 160 or 170 MHz kernel clock (PLL "Q" = SYSCLK), prescaler 2 in both
/// phases: 160 MHz gives the same segments as 80 MHz; 170 MHz gives 1 + 67 + 17 = 85 tq
/// (80 %) and 1 + 12 + 4 = 17 tq (76.5 %).
inline constexpr BitTiming kNominal1M160MHz{2, 63, 16, 16};
inline constexpr BitTiming kData5M160MHz{2, 11, 4, 4};
inline constexpr BitTiming kNominal1M170MHz{2, 67, 17, 17};
inline constexpr BitTiming kData5M170MHz{2, 12, 4, 4};
static_assert(bit_rate(160'000'000U, kNominal1M160MHz) == 1'000'000U && bit_rate(160'000'000U, kData5M160MHz) == 5'000'000U);
static_assert(bit_rate(170'000'000U, kNominal1M170MHz) == 1'000'000U && bit_rate(170'000'000U, kData5M170MHz) == 5'000'000U);
static_assert(170'000'000U % (2U * tq_per_bit(kNominal1M170MHz)) == 0U && 170'000'000U % (2U * tq_per_bit(kData5M170MHz)) == 0U);
static_assert(sample_point_permille(kNominal1M170MHz) == 800U && sample_point_permille(kData5M170MHz) == 764U);
static_assert(nominal_fits(kNominal1M170MHz) && data_fits(kData5M170MHz) && nominal_fits(kNominal1M160MHz) &&
              data_fits(kData5M160MHz));

/// Transmitter delay compensation offset in minimum time quanta: the data sample point
/// minus the sync segment (ST's recommended default for the G4, DataPrescaler x
/// DataTimeSeg1); the secondary sample point is then the measured loop delay plus this.
[[nodiscard]] constexpr std::uint32_t tdc_offset(const BitTiming& data) noexcept {
  return std::uint32_t{data.prescaler} * data.seg1;
}
static_assert(tdc_offset(kData5M80MHz) == 11U);

/// Bring-up modes (CCCR.TEST + TEST.LBCK; internal also CCCR.MON: nothing reaches the pin).
enum class TestMode : std::uint8_t { normal = 0, external_loopback = 1, internal_loopback = 2 };

struct FdcanConfig {
  FdcanInstance instance = kFdcan1;
  KernelClock kernel_clock = KernelClock::pll_q;  ///< must run at the rate the timings assume
  BitTiming nominal = kNominal1M80MHz;
  BitTiming data = kData5M80MHz;
  bool fd = true;                      ///< FDOE + BRSE; false: classic CAN only (FD frames are invalid)
  bool delay_compensation = true;      ///< DBTP.TDC; needed once the data bit is shorter than the loop delay
  TestMode test_mode = TestMode::normal;
};

/// Backend errors (stable numbers: they may be reported in status frames).
enum class FdcanError : std::uint8_t {
  none = 0,
  init_timeout = 1,      ///< CCCR.INIT (or CSA) did not follow within the bounded wait: kernel clock off?
  invalid_timing = 2,    ///< a bit timing outside its register fields, or a TDC offset above 127
  too_many_filters = 3,  ///< more than 28 filters requested: the first 28 are programmed
};

struct FdcanErrorCounters {
  std::uint8_t transmit = 0;  ///< ECR.TEC
  std::uint8_t receive = 0;   ///< ECR.REC (127 max; receive_passive above)
  bool receive_passive = false;
};

/// Payload bytes for each DLC code (ISO 11898-1); the inverse for the valid FD lengths.
inline constexpr std::array<std::uint8_t, 16> kDlcLength{0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
[[nodiscard]] constexpr std::uint32_t dlc_of(std::uint8_t length) noexcept {
  std::uint32_t dlc = 0;
  while (dlc < 15U && kDlcLength[dlc] < length) {
    ++dlc;
  }
  return dlc;
}
[[nodiscard]] constexpr bool dlc_round_trips() noexcept {
  for (std::uint32_t dlc = 0; dlc < kDlcLength.size(); ++dlc) {
    if (dlc_of(kDlcLength[dlc]) != dlc) {
      return false;
    }
  }
  return true;
}
static_assert(dlc_round_trips());

/// One standard (11-bit) acceptance filter element: classic filter, match stored in FIFO 0.
/// A filter that needs identifier bits above bit 10 never matches an 11-bit identifier:
/// its element is left disabled (SFEC = 000), which keeps CanFilter's meaning exactly.
[[nodiscard]] constexpr std::uint32_t standard_filter_element(const CanFilter& f) noexcept {
  constexpr std::uint32_t kStdId = 0x7FFU;
  if ((f.match & f.mask & ~kStdId) != 0U) {
    return 0U;
  }
  return fdcan::kFilterClassic | fdcan::kFilterToFifo0 | ((f.match & kStdId) << fdcan::kFilterId1Shift) | (f.mask & kStdId);
}

/// The port. `Regs`: Mmio on the target, FakeStm32g4 in checks; `Clock`: receive timestamps.
template <class Regs, class Clock>
class FdcanPort {
  static_assert(is_clock_v<Clock>, "receive timestamps need a clock satisfying the HAL contract");

 public:
  static constexpr std::size_t kMaxFilters = message_ram::kStandardFilters;
  /// Bounded wait for INIT/CSA to follow a write (a few kernel clock cycles when clocked):
  /// a missing kernel clock gives init_timeout instead of a hang.
  static constexpr std::uint32_t kPollLimit = 100'000U;

  constexpr FdcanPort(Regs& regs, const Clock& clock, const FdcanConfig& config) noexcept
      : regs_(regs), clock_(clock), config_(config) {}

  /// Clocks on, configuration, filters, then onto the bus. Not on the hot path; call once
  /// (after set_filters, or before: filters set later are programmed at once).
  constexpr FdcanError start() noexcept {
    started_ = false;
    if (!nominal_fits(config_.nominal) || (config_.fd && !data_fits(config_.data)) ||
        (config_.fd && config_.delay_compensation && tdc_offset(config_.data) > fdcan::kTdcMax)) {
      return fail(FdcanError::invalid_timing);
    }
    // Kernel clock selection first, then the bus clock gate; the read-back gives the gate
    // the cycles RCC needs before the peripheral's registers may be accessed. FDCANSEL and
    // the gate are shared by the three instances: a second port must select the same clock.
    const std::uint32_t ccipr = regs_.read(rcc::kCcipr) & ~rcc::kCciprFdcanselMask;
    regs_.write(rcc::kCcipr, ccipr | (static_cast<std::uint32_t>(config_.kernel_clock) << rcc::kCciprFdcanselShift));
    regs_.write(rcc::kApb1enr1, regs_.read(rcc::kApb1enr1) | rcc::kApb1enr1Fdcanen);
    (void)regs_.read(rcc::kApb1enr1);

    // Out of clock stop (power-down), then into initialization with configuration access.
    write_reg(fdcan::kCccr, read_reg(fdcan::kCccr) & ~fdcan::kCccrCsr);
    if (!wait_until([&] { return (read_reg(fdcan::kCccr) & fdcan::kCccrCsa) == 0U; })) {
      return fail(FdcanError::init_timeout);
    }
    if (!enter_configuration()) {
      return fail(FdcanError::init_timeout);
    }
    if (config_.instance.registers == kFdcan1Base) {
      // CKDIV = 0, kernel clock undivided: the reset value, written so that earlier code
      // cannot change the bit timing.
      regs_.write(fdcan::kCkdiv, 0U);
    }
    // DAR = 0 (automatic retransmission), PXHD = 0, NISO = 0: ISO CAN FD as specified.
    std::uint32_t cccr = fdcan::kCccrInit | fdcan::kCccrCce | (config_.fd ? fdcan::kCccrFdoe | fdcan::kCccrBrse : 0U);
    if (config_.test_mode != TestMode::normal) {
      cccr |= fdcan::kCccrTest | (config_.test_mode == TestMode::internal_loopback ? fdcan::kCccrMon : 0U);
    }
    write_reg(fdcan::kCccr, cccr);
    if (config_.test_mode != TestMode::normal) {
      write_reg(fdcan::kTest, fdcan::kTestLbck);  // writable only while CCCR.TEST is set
    }
    write_reg(fdcan::kNbtp, nbtp(config_.nominal));
    if (config_.fd) {
      write_reg(fdcan::kDbtp, dbtp(config_.data, config_.delay_compensation));
      write_reg(fdcan::kTdcr, config_.delay_compensation ? tdc_offset(config_.data) << 8U : 0U);  // TDCF = 0: no minimum SSP
    }
    write_reg(fdcan::kTscc, 0U);  // timestamps come from the clock (see the header comment)
    for (std::uint32_t offset = 0; offset < message_ram::kBytes; offset += 4U) {
      regs_.write(config_.instance.message_ram + offset, 0U);  // RAM content is undefined after reset
    }
    program_filters();
    write_reg(fdcan::kTxbc, 0U);  // Tx FIFO mode: transmission in queuing order
    write_reg(fdcan::kIe, 0U);    // polled
    write_reg(fdcan::kIls, 0U);
    write_reg(fdcan::kIle, 0U);
    write_reg(fdcan::kIr, fdcan::kIrAll);
    if (!leave_configuration()) {
      return fail(FdcanError::init_timeout);
    }
    started_ = true;
    return FdcanError::none;
  }

  /// Queue one frame in the Tx FIFO (never blocks).
  constexpr CanStatus send(const CanFrame& f) noexcept {
    if (!valid_length(f.length, f.fd) || f.id > (f.extended ? 0x1FFFFFFFU : 0x7FFU) || (f.fd && !config_.fd)) {
      return CanStatus::invalid;
    }
    if (!started_ || (read_reg(fdcan::kPsr) & fdcan::kPsrBo) != 0U) {
      return CanStatus::bus_off;
    }
    const std::uint32_t txfqs = read_reg(fdcan::kTxfqs);
    if ((txfqs & fdcan::kTxfqsFull) != 0U) {
      return CanStatus::queue_full;
    }
    const std::uint32_t put = (txfqs >> fdcan::kTxfqsPutShift) & fdcan::kIndexMask;
    const std::uint32_t element = config_.instance.message_ram + message_ram::kTxBufferOffset + put * message_ram::kElementBytes;
    regs_.write(element, f.extended ? fdcan::kElementXtd | f.id : f.id << fdcan::kElementStdIdShift);
    // T1: DLC, FDF and BRS together (every FD frame switches bit rate); EFC = 0, MM = 0.
    const std::uint32_t format = f.fd ? fdcan::kElementFdf | fdcan::kElementBrs : 0U;
    regs_.write(element + 4U, (dlc_of(f.length) << fdcan::kElementDlcShift) | format);
    const std::uint32_t words = (std::uint32_t{f.length} + 3U) / 4U;
    for (std::uint32_t w = 0; w < words; ++w) {
      std::uint32_t word = 0;
      for (std::uint32_t b = 0; b < 4U; ++b) {
        const std::uint32_t i = 4U * w + b;
        word |= i < f.length ? static_cast<std::uint32_t>(f.data[i]) << (8U * b) : 0U;
      }
      regs_.write(element + 8U + 4U * w, word);
    }
    // The element is complete before its add request: both are Device-memory stores, in order.
    write_reg(fdcan::kTxbar, 1U << put);
    return CanStatus::ok;
  }

  /// Next accepted frame from Rx FIFO 0, false when none. Bounded: at most one FIFO's worth.
  constexpr bool receive(CanFrame& out) noexcept {
    if (!started_) {
      return false;
    }
    for (std::uint32_t attempt = 0; attempt < message_ram::kRxFifoElements; ++attempt) {
      const std::uint32_t rxf0s = read_reg(fdcan::kRxf0s);
      if ((rxf0s & fdcan::kRxf0sRf0l) != 0U) {
        ++rx_lost_;
        write_reg(fdcan::kIr, fdcan::kIrRf0l);  // RXF0S.RF0L mirrors IR.RF0L
      }
      if ((rxf0s & fdcan::kRxf0sFillMask) == 0U) {
        return false;
      }
      const std::uint32_t get = (rxf0s >> fdcan::kRxf0sGetShift) & fdcan::kIndexMask;
      const std::uint32_t element = config_.instance.message_ram + message_ram::kRxFifo0Offset + get * message_ram::kElementBytes;
      const std::uint32_t r0 = regs_.read(element);
      const std::uint32_t r1 = regs_.read(element + 4U);
      if ((r0 & fdcan::kElementRtr) != 0U) {
        write_reg(fdcan::kRxf0a, get);  // remote frames are rejected by RXGFC; none should get here
        continue;
      }
      out.extended = (r0 & fdcan::kElementXtd) != 0U;
      out.id = out.extended ? r0 & 0x1FFFFFFFU : (r0 >> fdcan::kElementStdIdShift) & 0x7FFU;
      out.fd = (r1 & fdcan::kElementFdf) != 0U;
      const std::uint32_t dlc = (r1 >> fdcan::kElementDlcShift) & 0xFU;
      out.length = !out.fd && dlc > 8U ? std::uint8_t{8} : kDlcLength[dlc];  // classic DLC 9..15 means 8 bytes
      for (std::uint32_t w = 0; w < 16U; ++w) {
        const std::uint32_t word = 4U * w < out.length ? regs_.read(element + 8U + 4U * w) : 0U;
        for (std::uint32_t b = 0; b < 4U; ++b) {
          const std::uint32_t i = 4U * w + b;
          out.data[i] = i < out.length ? static_cast<std::uint8_t>(word >> (8U * b)) : std::uint8_t{0};
        }
      }
      out.timestamp_us = clock_.now_us();
      write_reg(fdcan::kRxf0a, get);
      return true;
    }
    return false;
  }

  /// Not started: bus_off (the controller is not on the bus), as send() reports it.
  [[nodiscard]] constexpr CanErrorState error_state() const noexcept {
    if (!started_) {
      return CanErrorState::bus_off;
    }
    const std::uint32_t psr = read_reg(fdcan::kPsr);  // side effect: LEC/DLEC read back as "no change" afterwards
    if ((psr & fdcan::kPsrBo) != 0U) {
      return CanErrorState::bus_off;
    }
    return (psr & fdcan::kPsrEp) != 0U ? CanErrorState::error_passive : CanErrorState::error_active;
  }

  /// Standard-identifier acceptance filters (n = 0: accept everything). More than 28: the
  /// first 28 are programmed and too_many_filters is recorded. While running, the controller
  /// passes through initialization: it leaves the bus for a moment and pending transmissions
  /// are dropped (CCE resets TXBRP), so this is a configuration call, not a cycle call.
  constexpr void set_filters(const CanFilter* filters, std::size_t n) noexcept {
    if (n > kMaxFilters) {
      last_error_ = FdcanError::too_many_filters;
    }
    const std::size_t count = n < kMaxFilters ? n : kMaxFilters;
    filter_count_ = 0;
    if (filters != nullptr) {
      for (std::size_t i = 0; i < count; ++i) {
        filter_elements_[i] = standard_filter_element(filters[i]);
      }
      filter_count_ = count;
    }
    if (started_) {
      if (!enter_configuration()) {
        started_ = false;
        last_error_ = FdcanError::init_timeout;
        return;
      }
      program_filters();
      if (!leave_configuration()) {
        started_ = false;
        last_error_ = FdcanError::init_timeout;
      }
    }
  }

  /// After bus-off the FDCAN has set INIT itself; clearing it starts the recovery sequence
  /// (the controller rejoins after 129 x 11 recessive bits; PSR.BO stays set until then).
  /// Left to the application: a node off the bus raises its neighbours' communication fault,
  /// and when to try again is a system decision (docs/porting.md).
  constexpr void recover_from_bus_off() noexcept {
    if ((read_reg(fdcan::kPsr) & fdcan::kPsrBo) != 0U) {
      write_reg(fdcan::kCccr, read_reg(fdcan::kCccr) & ~(fdcan::kCccrInit | fdcan::kCccrCce));
    }
  }

  [[nodiscard]] constexpr FdcanErrorCounters error_counters() const noexcept {
    const std::uint32_t ecr = read_reg(fdcan::kEcr);
    return {static_cast<std::uint8_t>(ecr & 0xFFU), static_cast<std::uint8_t>((ecr >> 8U) & 0x7FU),
            (ecr & (1U << 15U)) != 0U};
  }
  [[nodiscard]] constexpr FdcanError last_error() const noexcept { return last_error_; }
  [[nodiscard]] constexpr std::uint32_t rx_lost() const noexcept { return rx_lost_; }
  [[nodiscard]] constexpr bool started() const noexcept { return started_; }

 private:
  [[nodiscard]] constexpr std::uint32_t read_reg(std::uint32_t offset) const noexcept {
    return regs_.read(config_.instance.registers + offset);
  }
  constexpr void write_reg(std::uint32_t offset, std::uint32_t value) noexcept {
    regs_.write(config_.instance.registers + offset, value);
  }
  template <class Done>
  static constexpr bool wait_until(Done done) noexcept {
    for (std::uint32_t i = 0; i < kPollLimit; ++i) {
      if (done()) {
        return true;
      }
    }
    return false;
  }
  constexpr FdcanError fail(FdcanError e) noexcept {
    last_error_ = e;
    return e;
  }
  /// INIT, then CCE: configuration registers are writable only with both set. INIT is
  /// read back because the write crosses into the kernel clock domain.
  constexpr bool enter_configuration() noexcept {
    write_reg(fdcan::kCccr, read_reg(fdcan::kCccr) | fdcan::kCccrInit);
    if (!wait_until([&] { return (read_reg(fdcan::kCccr) & fdcan::kCccrInit) != 0U; })) {
      return false;
    }
    write_reg(fdcan::kCccr, read_reg(fdcan::kCccr) | fdcan::kCccrCce);
    return true;
  }
  /// Clearing INIT also clears CCE; the controller then integrates (11 recessive bits).
  constexpr bool leave_configuration() noexcept {
    write_reg(fdcan::kCccr, read_reg(fdcan::kCccr) & ~(fdcan::kCccrInit | fdcan::kCccrCce));
    return wait_until([&] { return (read_reg(fdcan::kCccr) & fdcan::kCccrInit) == 0U; });
  }
  /// Elements first, then the list size and the global filter (RXGFC needs INIT + CCE).
  constexpr void program_filters() noexcept {
    for (std::size_t i = 0; i < kMaxFilters; ++i) {
      const std::uint32_t word = i < filter_count_ ? filter_elements_[i] : 0U;
      regs_.write(config_.instance.message_ram + message_ram::kStandardFilterOffset + static_cast<std::uint32_t>(4U * i), word);
    }
    const std::uint32_t reject_others = filter_count_ > 0U ? fdcan::kRxgfcAnfsReject | fdcan::kRxgfcAnfeReject : 0U;
    write_reg(fdcan::kRxgfc, (static_cast<std::uint32_t>(filter_count_) << fdcan::kRxgfcLssShift) | reject_others |
                                 fdcan::kRxgfcRrfs | fdcan::kRxgfcRrfe);
  }
  [[nodiscard]] static constexpr std::uint32_t nbtp(const BitTiming& t) noexcept {
    return ((std::uint32_t{t.sjw} - 1U) << 25U) | ((std::uint32_t{t.prescaler} - 1U) << 16U) |
           ((std::uint32_t{t.seg1} - 1U) << 8U) | (std::uint32_t{t.seg2} - 1U);
  }
  [[nodiscard]] static constexpr std::uint32_t dbtp(const BitTiming& t, bool delay_compensation) noexcept {
    return (delay_compensation ? fdcan::kDbtpTdc : 0U) | ((std::uint32_t{t.prescaler} - 1U) << 16U) |
           ((std::uint32_t{t.seg1} - 1U) << 8U) | ((std::uint32_t{t.seg2} - 1U) << 4U) | (std::uint32_t{t.sjw} - 1U);
  }

  Regs& regs_;
  const Clock& clock_;
  FdcanConfig config_;
  std::array<std::uint32_t, kMaxFilters> filter_elements_{};
  std::size_t filter_count_ = 0;
  std::uint32_t rx_lost_ = 0;
  FdcanError last_error_ = FdcanError::none;
  bool started_ = false;
};

static_assert(is_can_port_v<FdcanPort<Mmio, Tim2Clock<Mmio>>>, "the target port satisfies the CAN port contract");
static_assert(is_can_port_v<FdcanPort<FakeStm32g4, ManualClock>>, "the port over the fake registers satisfies it too");

}  // namespace jg::hal::stm32g4
