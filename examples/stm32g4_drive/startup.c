/* Minimal Cortex-M4F start-up for the example: vector table (stack, reset, faults), .data
 * copied from flash, .bss zeroed, the FPU enabled before any float code, static
 * constructors, then main. A real board adds its clock tree set-up in board_init(). */
#include <stdint.h>

extern uint32_t __data_load, __data_start, __data_end, __bss_start, __bss_end, __stack_top;
extern void (*__init_array_start[])(void);
extern void (*__init_array_end[])(void);
int main(void);
void reset_handler(void);

static void fault_handler(void) {
  for (;;) {
  }
}

__attribute__((section(".isr_vector"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))(&__stack_top), reset_handler, fault_handler, fault_handler, fault_handler, fault_handler,
    fault_handler, 0, 0, 0, 0, fault_handler, fault_handler, 0, fault_handler, fault_handler};

void reset_handler(void) {
  uint32_t* src = &__data_load;
  for (uint32_t* dst = &__data_start; dst < &__data_end;) *dst++ = *src++;
  for (uint32_t* dst = &__bss_start; dst < &__bss_end;) *dst++ = 0U;
  /* CPACR: full access to CP10 and CP11 (the FPU), then barriers (ARMv7-M ARM, B3.2.20). */
  *(volatile uint32_t*)0xE000ED88U |= (0xFU << 20);
  __asm volatile("dsb\n isb" ::: "memory");
  for (void (**f)(void) = __init_array_start; f < __init_array_end; ++f) (*f)();
  (void)main();
  fault_handler();
}
