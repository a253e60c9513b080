/* clock.c — a monotonic nanosecond clock for per-stage timings. */
#define _POSIX_C_SOURCE 199309L
#include "platform.h"

#include <time.h>

uint64_t om_clock_ns(void *user)
{
    (void)user;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}
