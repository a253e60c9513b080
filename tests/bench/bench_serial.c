/* bench_serial.c — what the serial share of a frame lets more threads do (issue 26:
 * this project's host has two CPUs, so 8 and 16 threads are estimated, not run).
 *
 * A frame is rendered as it would be on N threads, but its jobs run one after another
 * on the calling thread (a parallel-for that loops, and a worker index that says which
 * of the N threads a job would have been on, jobs split among them in order). Each
 * parallel-for call is timed, and so is each job in it, so the frame divides into:
 *   serial: the time outside the calls, which no thread count shortens;
 *   work:   the whole frame so run, against the one-thread frame (N threads' bands
 *           and bins cost some work of their own);
 * and two estimates of the N-thread frame, each as a speed-up over one thread:
 *   Amdahl: serial + (the calls' time) / N, the work spread perfectly;
 *   jobs:   serial + the sum over calls of the larger of (the call's jobs) / N and its
 *           longest job: a call cannot end before its longest job, so a stage of few
 *           or uneven jobs caps the threads it can use.
 * Both leave out what running at once costs (shared caches and memory, the slower of
 * two CPUs, waking threads): `build/bench threads` measures two threads for real, and
 * the gap between its speed-up and the estimate for N = 2 is that cost. Every frame is
 * checked to be the bits of the one-thread frame. Figures: medians over ROUNDS. */
#include "bench.h"

#include <string.h>

#define ROUNDS 5
#define SETTLE 64   /* at most this many frames before timing, until two are the same */

static const uint32_t counts[] = {2, 8, 16};
#define NCOUNTS (sizeof counts / sizeof counts[0])

/* The looping parallel-for's tally of one frame. */
typedef struct tally {
    uint32_t threads, worker;   /* the threads the frame is told of; the current job's */
    uint64_t calls_ns;          /* inside the calls */
    double bound_ns;            /* the sum over calls of max(jobs / threads, longest job) */
} tally;

static void loop_for(void *host, om_job_fn fn, void *job_user, uint32_t n)
{
    tally *t = host;
    uint64_t sum = 0, longest = 0;
    const uint64_t c0 = om_clock_ns(NULL);
    for (uint32_t i = 0; i < n; i++) {
        t->worker = (uint32_t)((uint64_t)i * t->threads / n);   /* in order, as evenly as they go */
        const uint64_t j0 = om_clock_ns(NULL);
        fn(job_user, i);
        const uint64_t j = om_clock_ns(NULL) - j0;
        sum += j;
        if (j > longest) longest = j;
    }
    t->calls_ns += om_clock_ns(NULL) - c0;
    const double even = (double)sum / t->threads;
    t->bound_ns += even > (double)longest ? even : (double)longest;
}

static uint32_t loop_worker(void *host)
{
    return ((const tally *)host)->worker;
}

/* One frame on `threads` (1: inline) into fb: its time, and the tally. */
static int frame(const bscene *b, bsetup *bs, uint32_t threads, double *ms, tally *t)
{
    om_arena fa;
    om_frame_desc fd;
    bench_frame_desc(bs, b, &fd, &fa);
    memset(t, 0, sizeof *t);
    t->threads = threads;
    if (threads > 1) {
        fd.parallel_for = loop_for;
        fd.parallel_user = t;
        fd.worker = loop_worker;
        fd.threads = threads;
    }
    om_frame_stats fs;
    om_diag d;
    const uint64_t t0 = om_clock_ns(NULL);
    if (om_render_frame(&fd, &fa, &fs, &d) != OM_OK) {
        fprintf(stderr, "bench: %s %s: %s\n", b->name, om_method_name(bs->m), d.msg);
        return 1;
    }
    *ms = (double)(om_clock_ns(NULL) - t0) / 1e6;
    return 0;
}

static void one_method(const bscene *b, const char *name)
{
    const uint32_t W = 1024, H = 768;
    bsetup bs;
    if (bench_setup(&bs, b, name, W, H, 16)) return;
    const uint8_t *px = bs.fb.pixels;
    /* one: the one-thread frame; per count: serial and work against it, the estimates */
    double one[ROUNDS], serial[NCOUNTS][ROUNDS], work[NCOUNTS][ROUNDS], amdahl[NCOUNTS][ROUNDS],
        jobs[NCOUNTS][ROUNDS];
    /* asm refines its tree from frame to frame: the frames are timed once they settle */
    uint64_t first = 0, last = 1;
    int settle = 0;
    for (double ms; settle < SETTLE && first != last; settle++) {
        tally t;
        last = first;
        if (frame(b, &bs, 1, &ms, &t)) goto out;
        first = om_hash(0, px, (size_t)W * H * 3);
    }
    bool same = first == last;
    for (int p = -1; p < ROUNDS; p++)   /* round -1 warms up */
        for (size_t q = 0; q <= NCOUNTS; q++) {
            const size_t k = (q + (p < 0 ? 0 : (size_t)p)) % (NCOUNTS + 1);   /* 0: one thread */
            const uint32_t n = k ? counts[k - 1] : 1;
            double ms;
            tally t;
            if (frame(b, &bs, n, &ms, &t)) goto out;
            const uint64_t h = om_hash(0, px, (size_t)W * H * 3);
            same = same && h == first;
            if (p < 0) continue;
            if (!k) {
                one[p] = ms;
                continue;
            }
            const double s = ms - (double)t.calls_ns / 1e6;
            serial[k - 1][p] = s;
            work[k - 1][p] = ms;
            amdahl[k - 1][p] = s + (double)t.calls_ns / 1e6 / n;
            jobs[k - 1][p] = s + t.bound_ns / 1e6;
        }
    /* each round against its own one-thread frame, then the medians */
    printf("%-12s %-7s %7.2f", b->name, name, bench_median(one, ROUNDS));
    for (size_t k = 0; k < NCOUNTS; k++) {
        double r[4][ROUNDS];
        for (int p = 0; p < ROUNDS; p++) {
            r[0][p] = 100.0 * serial[k][p] / one[p];
            r[1][p] = work[k][p] / one[p];
            r[2][p] = one[p] / amdahl[k][p];
            r[3][p] = one[p] / jobs[k][p];
        }
        printf(" | %4.1f%% %4.2f %5.2fx %5.2fx", bench_median(r[0], ROUNDS), bench_median(r[1], ROUNDS),
               bench_median(r[2], ROUNDS), bench_median(r[3], ROUNDS));
    }
    if (settle > 2) printf("  (settled at frame %d)", settle);
    printf("%s\n", same ? "" : first == last ? "  FRAMES DIFFER" : "  (frames did not settle)");
out:
    bench_teardown(&bs);
}

void bench_serial(void)
{
    printf("\nserial: 1024x768; a frame on N threads run one job at a time (%d rounds, medians):\n"
           "serial = the time outside the parallel-for, as a share of the one-thread frame; work =\n"
           "the frame so run / one thread's; Amdahl = one thread / (serial + the rest / N); jobs =\n"
           "the same with each call at least its longest job. Speed-ups leave out what threads\n"
           "running at once cost (`threads` measures two)\n",
           ROUNDS);
    printf("%-12s %-7s %7s", "scene", "method", "1 thr");
    for (size_t k = 0; k < NCOUNTS; k++) printf(" | N=%-2u serial work Amdahl  jobs", (unsigned)counts[k]);
    printf("\n");
    bscene b;
    for (int sc = 0; sc < 2; sc++) {
        if (sc ? bench_load_random(&b, 100000) : bench_load(&b, "default", om_scene_default_text())) break;
        static const char *const names[] = {"none", "sm", "asm", "izb", "rtw", "spsm", "ref", "hybrid"};
        for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
            one_method(&b, names[k]);
            fflush(stdout);
        }
        bench_free(&b);
    }
}
