// Compile-only: the STM32G4 FDCAN port and TIM2 clock on the real register block (fixed
// addresses), and the joint node bound to that port for both firmware scalars, built with
// the firmware flags for every cross build. Board code, not HAL: it uses the core, which the
// HAL may not (boards/stm32g4/CMakeLists.txt). Nothing links this object (in
// particular not the qemu golden ELF, whose mps2-an386 has no FDCAN): it is here so that the
// target code is compiled, warning-free, on every cross build until a board build uses it.
#include "jointguard/hal/mcu/stm32g4_clock.hpp"
#include "jointguard/hal/mcu/stm32g4_fdcan.hpp"
#include "jointguard/node/joint_node.hpp"
#include "jointguard/numeric/q.hpp"

namespace jg {
namespace hal::stm32g4 {
template class Tim2Clock<Mmio>;
template class FdcanPort<Mmio, Tim2Clock<Mmio>>;
}  // namespace hal::stm32g4

template class JointNode<float, hal::stm32g4::FdcanPort<hal::stm32g4::Mmio, hal::stm32g4::Tim2Clock<hal::stm32g4::Mmio>>>;
template class JointNode<q16, hal::stm32g4::FdcanPort<hal::stm32g4::Mmio, hal::stm32g4::Tim2Clock<hal::stm32g4::Mmio>>>;
}  // namespace jg
