/* semihost.c — output and exit through ARM semihosting (bkpt 0xAB with r0 = the
 * operation, r1 = its argument), and the cross driver's host on a board: it prints
 * each line and exits 0 when the driver succeeds. QEMU needs
 * -semihosting-config enable=on for this; the text arrives on its stderr. */
#include <stdint.h>

int om_cross_main(void);

static void call(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm("r0") = op;
    register const void *r1 __asm("r1") = arg;
    __asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
}

void om_semihost_puts(const char *s) { call(0x04, s); }   /* SYS_WRITE0 */

void om_semihost_exit(int ok)
{
    /* SYS_EXIT takes the reason itself on 32-bit ARM: ApplicationExit (0x20026) makes
     * QEMU exit 0, anything else 1. */
    call(0x18, (const void *)(uintptr_t)(ok ? 0x20026u : 0x20023u));
    for (;;) {}
}

void om_host_puts(const char *line)
{
    om_semihost_puts(line);
    om_semihost_puts("\n");
}

int om_board_main(void) { return om_cross_main(); }
