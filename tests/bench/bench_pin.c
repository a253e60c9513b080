/* bench_pin.c — pins the calling thread to one CPU, for the benchmarks that time one
 * thread on each of two CPUs (bench_threads, bench_calls): a virtual machine's CPUs need
 * not run at one speed. Linux only; elsewhere nothing is pinned. */
#if defined(__linux__)
#define _GNU_SOURCE   /* pthread_setaffinity_np */
#include <pthread.h>
#include <sched.h>
#endif
#include "bench.h"

#if defined(__linux__)
static cpu_set_t all_cpus;   /* the thread's CPUs when bench_pin_two looked */

bool bench_pin_two(void)
{
    return om_cpus_online() >= 2 && pthread_getaffinity_np(pthread_self(), sizeof all_cpus, &all_cpus) == 0 &&
           CPU_ISSET(0, &all_cpus) && CPU_ISSET(1, &all_cpus);
}

bool bench_pin(int cpu)
{
    cpu_set_t m = all_cpus;
    if (cpu >= 0) {
        if (!CPU_ISSET(cpu, &all_cpus)) return false;
        CPU_ZERO(&m);
        CPU_SET(cpu, &m);
    }
    return pthread_setaffinity_np(pthread_self(), sizeof m, &m) == 0;
}
#else
bool bench_pin_two(void)
{
    return false;
}

bool bench_pin(int cpu)
{
    (void)cpu;
    return false;
}
#endif
