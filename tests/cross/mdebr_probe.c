/* mdebr_probe.c — whether the emulator multiplies two floats into a double correctly.
 * clang compiles (double)a * (double)b for s390x to one mdebr; QEMU 7.2 gets its result
 * wrong (gcc's ldebr, ldebr, mdbr is right), so run.sh runs s390x clang at -O1 and
 * above only where this probe, built by that clang, exits 0. The product of two floats
 * is exact in a double, so there is one right answer: the product of the significands
 * in integers, scaled. */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* noinline: the multiply must happen at run time, in the instruction under test */
__attribute__((noinline)) static double mul(float a, float b) { return (double)a * (double)b; }

int main(void)
{
    uint32_t s = 12345, bad = 0;
    for (int i = 0; i < 1000; i++) {
        uint32_t x, y;
        float a, b;
        s = s * 1664525u + 1013904223u;
        x = (s >> 9) | 0x3f800000u;   /* a in [1, 2) */
        s = s * 1664525u + 1013904223u;
        y = (s >> 9) | 0x3f800000u;   /* b in [1, 2) */
        memcpy(&a, &x, 4);
        memcpy(&b, &y, 4);
        uint64_t ma = (x & 0x7fffffu) | 0x800000u, mb = (y & 0x7fffffu) | 0x800000u;
        if (mul(a, b) != (double)(ma * mb) * 0x1p-46) bad++;
    }
    printf("mdebr probe: %u of 1000 products wrong\n", (unsigned)bad);
    return bad != 0;
}
