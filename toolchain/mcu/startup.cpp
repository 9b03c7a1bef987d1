// Vector table and reset handler for the Cortex-M targets (our own, no vendor startup).
// Reset: enable the FPU (CP10/CP11 full access) before any float code runs, copy .data,
// zero .bss, run static constructors, call main, and report main's status to the host
// through semihosting (so qemu exits with it).
#include <cstdint>

#include "semihosting.hpp"

extern "C" {
extern std::uint32_t _stack_top;
extern std::uint32_t _data_load, _data_start, _data_end, _bss_start, _bss_end;
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();
int jg_app_main();  // the application entry (calling ::main is not allowed in C++)
void jg_reset_handler();
void jg_fault_handler();
}

#if defined(__ARM_FP)
namespace {
constexpr std::uintptr_t kCpacr = 0xE000ED88U;  // Coprocessor Access Control Register
}
#endif

extern "C" void jg_reset_handler() {
#if defined(__ARM_FP)  // an FPU to enable (not on the Cortex-M3 or soft-float builds)
  // NOLINTNEXTLINE(performance-no-int-to-ptr): memory-mapped system register
  auto* cpacr = reinterpret_cast<volatile std::uint32_t*>(kCpacr);
  *cpacr = *cpacr | (0xFU << 20U);  // CP10, CP11: full access
  __asm volatile("dsb\n isb" ::: "memory");
#endif
  const std::uint32_t* src = &_data_load;
  for (std::uint32_t* dst = &_data_start; dst < &_data_end; ++dst, ++src) {
    *dst = *src;
  }
  for (std::uint32_t* p = &_bss_start; p < &_bss_end; ++p) {
    *p = 0U;
  }
  for (void (**ctor)() = __init_array_start; ctor < __init_array_end; ++ctor) {
    (*ctor)();
  }
  jg::mcu::exit_with(jg_app_main());
}

extern "C" void jg_fault_handler() { jg::mcu::exit_with(99); }

// The vector table: initial stack pointer, reset, then faults (NMI .. usage fault).
extern "C" __attribute__((section(".vectors"), used)) void (*const jg_vectors[16])() = {
    reinterpret_cast<void (*)()>(&_stack_top),
    jg_reset_handler,
    jg_fault_handler, jg_fault_handler, jg_fault_handler, jg_fault_handler, jg_fault_handler,
    nullptr, nullptr, nullptr, nullptr,
    jg_fault_handler, jg_fault_handler, nullptr, jg_fault_handler, jg_fault_handler};
