// STM32G4 CRC calculation unit as the frames' CRC-8/AUTOSAR policy (hal/crc8.hpp).
//
// RM0440 "Cyclic redundancy check calculation unit (CRC)", base 0x40023000 (AHB1PERIPH_BASE
// + 0x3000 in ST's stm32g474xx.h): DR 0x00, IDR 0x04, CR 0x08, INIT 0x10, POL 0x14; clock
// gate RCC_AHB1ENR (0x48) bit 12, CRCEN. The unit takes a programmable polynomial of 7, 8,
// 16 or 32 bits (CR.POLYSIZE) and an initial value (INIT, loaded by CR.RESET); input and
// output bit reversal are off at reset (CR.REV_IN = 00, REV_OUT = 0), which is what
// CRC-8/AUTOSAR needs (not reflected). Data is shifted in most significant bit first, so a
// 32-bit write of a byte-reversed little-endian word (REV) feeds four payload bytes in
// order; the last 0..3 bytes go as 8-bit writes. The final XOR 0xFF is done here.
//
// A policy has a static crc8(): the register block is built on the spot (`Regs{}`), which
// for Mmio is free (no state) and for a host test is a model with static storage
// (tests/can/test_crc_policy.cpp models the unit's arithmetic from the reference manual).
// Not reentrant: one CRC at a time (the drive's cycle; an ISR using the unit must not
// interrupt it, or must save and restore INIT/POL/CR/DR).
#pragma once

#include <cstdint>
#include <cstring>

#include "jointguard/hal/crc8.hpp"
#include "jointguard/hal/mcu/stm32g4_registers.hpp"

namespace jg::hal::stm32g4 {

namespace crc {
inline constexpr std::uint32_t kBase = 0x40023000U;
inline constexpr std::uint32_t kDr = kBase + 0x00U;
inline constexpr std::uint32_t kCr = kBase + 0x08U;
inline constexpr std::uint32_t kInit = kBase + 0x10U;
inline constexpr std::uint32_t kPol = kBase + 0x14U;
inline constexpr std::uint32_t kCrReset = 1U << 0U;
inline constexpr std::uint32_t kCrPolysize8 = 2U << 3U;  ///< POLYSIZE[1:0] = 10: 8-bit polynomial
inline constexpr std::uint32_t kRccAhb1enr = kRccBase + 0x48U;
inline constexpr std::uint32_t kRccAhb1enrCrcen = 1U << 12U;
inline constexpr std::uint32_t kAutosarPolynomial = 0x2FU;
inline constexpr std::uint32_t kAutosarInit = 0xFFU;
inline constexpr std::uint8_t kAutosarXorOut = 0xFFU;
}  // namespace crc

/// Turns the unit's clock on (RCC_AHB1ENR.CRCEN): once at start-up, before the first frame.
template <class Regs>
void enable_crc_unit(Regs& regs) noexcept {
  regs.write(crc::kRccAhb1enr, regs.read(crc::kRccAhb1enr) | crc::kRccAhb1enrCrcen);
}

/// CRC-8/AUTOSAR on the CRC unit (policy for hal::crc8_policy_t: name it as a port's
/// `crc8_policy`, see PortWithCrcUnit below). The register block needs `write8` (an 8-bit
/// store: the last bytes of a frame) besides read/write.
template <class Regs = Mmio>
struct Crc8AutosarUnit {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "payload words are read little-endian");
  static std::uint8_t crc8(const std::uint8_t* data, std::uint8_t length) noexcept {
    Regs regs{};
    regs.write(crc::kPol, crc::kAutosarPolynomial);
    regs.write(crc::kInit, crc::kAutosarInit);
    regs.write(crc::kCr, crc::kCrPolysize8 | crc::kCrReset);  // RESET loads INIT into DR
    std::uint8_t i = 0;
    for (; static_cast<unsigned>(i) + 4U <= length; i = static_cast<std::uint8_t>(i + 4U)) {
      std::uint32_t w = 0;
      std::memcpy(&w, data + i, 4);  // little-endian payload bytes i..i+3
      regs.write(crc::kDr, __builtin_bswap32(w));  // MSB first: byte i first
    }
    for (; i < length; ++i) {
      regs.write8(crc::kDr, data[i]);
    }
    return static_cast<std::uint8_t>((regs.read(crc::kDr) & 0xFFU) ^ crc::kAutosarXorOut);
  }
};

/// A port that carries the CRC unit as its frames' policy: the same port, one extra name.
/// JointDrive<S, PortWithCrcUnit<FdcanPort<...>>> then encodes and checks every frame
/// on the unit; frames stay bit-identical to the software CRC's.
template <class Port, class Regs = Mmio>
class PortWithCrcUnit : public Port {
 public:
  using crc8_policy = Crc8AutosarUnit<Regs>;
  using Port::Port;
};

}  // namespace jg::hal::stm32g4
