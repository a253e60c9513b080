/* startup.c — the least a Cortex-M needs to run ombra under qemu-system-arm (mps2
 * boards): a vector table at address 0 (QEMU takes the stack pointer and the reset
 * address from it), a reset handler that copies .data, zeroes .bss, turns on the FPU
 * when there is one, runs the program and leaves through semihosting with its status.
 * Faults also leave through semihosting, with a failure status, instead of hanging. */
#include <stdint.h>

extern uint32_t __data_load, __data_start, __data_end, __bss_start, __bss_end, __stack_top;
int om_board_main(void);
void om_semihost_exit(int ok);
void om_semihost_puts(const char *s);

void reset_handler(void);
void fault_handler(void);

__attribute__((section(".vectors"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))(uintptr_t)&__stack_top, /* initial stack pointer */
    reset_handler, fault_handler, fault_handler, fault_handler, fault_handler, fault_handler,
    0, 0, 0, 0, fault_handler, fault_handler, 0, fault_handler, fault_handler,
};

void reset_handler(void)
{
    uint32_t *src = &__data_load, *dst = &__data_start;
    while (dst < &__data_end) *dst++ = *src++;
    for (dst = &__bss_start; dst < &__bss_end;) *dst++ = 0;
#if defined(__ARM_FP)
    /* CP10 and CP11 full access, so float instructions do not fault. */
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm volatile("dsb\n\tisb");
#endif
    om_semihost_exit(om_board_main() == 0);
}

void fault_handler(void)
{
    om_semihost_puts("ombra: fault\n");
    om_semihost_exit(0);
}
