/* guard.h — guard bytes around the buffers a fuzz target hands the engine: a write
 * outside a buffer changes one, and the target aborts. */
#ifndef OM_FUZZ_GUARD_H
#define OM_FUZZ_GUARD_H

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#define GUARD 64

/* n bytes at b + GUARD, with GUARD bytes of 0xA5 before and after (NULL: no memory). */
static inline unsigned char *guarded_alloc(size_t n)
{
    unsigned char *b = malloc(n + 2 * GUARD);
    if (b) memset(b, 0xA5, n + 2 * GUARD);
    return b;
}

static inline bool guarded(const unsigned char *buf, size_t n)
{
    for (size_t i = 0; i < GUARD; i++)
        if (buf[i] != 0xA5 || buf[GUARD + n + i] != 0xA5) return false;
    return true;
}

#endif
