/* bench_calls.c — where a two-thread frame loses against one thread, call by call of
 * the host's parallel-for: the same frame (1024x768, the method's defaults, two jobs)
 * runs with its jobs on a pool of two threads, and with the very same jobs inline on
 * CPU 0 and on CPU 1 (pinned where the host allows it, Linux), in turns. Per call: the
 * gap on the calling thread before it, the jobs' summed time inline on each CPU, and on
 * two threads the call's wall time, the jobs' summed time, each thread's busy time and
 * how late the worker began its first job. "eff" is the call's ideal on the two CPUs,
 * t0 t1 / (t0 + t1), over its wall time; "growth" the jobs' summed time on two threads
 * over their mean inline: above 1 the same jobs cost more where two threads run them
 * (a band's rows in the other thread's cache, say), where eff alone would not tell that
 * from a thread left waiting. Medians over the rounds; each timed frame follows an
 * untimed one of its kind. A call that one thread skips (the halves' merge: one thread
 * draws every part into one target) reads 0 inline. */
#include "bench.h"

#include <string.h>

#define ROUNDS 9
#define MAX_CALLS 32
#define MAX_JOBS 512

typedef struct call_rec {
    uint32_t n;
    uint64_t in, out;              /* ns from the frame's start */
    uint64_t start[MAX_JOBS], end[MAX_JOBS];
    uint32_t thread[MAX_JOBS];
} call_rec;

/* The recording host: `pool` NULL runs the jobs inline. One frame at a time. */
typedef struct rec_host {
    om_jobs *pool;
    uint64_t t0;
    uint32_t ncalls;
    call_rec calls[MAX_CALLS];
    call_rec *cur;
    om_job_fn fn;
    void *user;
} rec_host;

static void rec_job(void *h, uint32_t i)
{
    rec_host *r = (rec_host *)h;
    const uint64_t a = om_clock_ns(NULL);
    r->fn(r->user, i);
    const uint64_t b = om_clock_ns(NULL);
    if (i < MAX_JOBS) {
        r->cur->start[i] = a - r->t0;
        r->cur->end[i] = b - r->t0;
        r->cur->thread[i] = r->pool ? om_jobs_worker(r->pool) : 0;
    }
}

static void rec_for(void *h, om_job_fn fn, void *user, uint32_t n)
{
    rec_host *r = (rec_host *)h;
    call_rec *c = &r->calls[r->ncalls < MAX_CALLS ? r->ncalls : MAX_CALLS - 1];
    r->ncalls++;
    r->cur = c;
    r->fn = fn;
    r->user = user;
    c->n = n;
    c->in = om_clock_ns(NULL) - r->t0;
    if (r->pool) om_jobs_for(r->pool, rec_job, r, n);
    else
        for (uint32_t i = 0; i < n; i++) rec_job(r, i);
    c->out = om_clock_ns(NULL) - r->t0;
}

static uint32_t rec_worker(void *h)
{
    rec_host *r = (rec_host *)h;
    return r->pool ? om_jobs_worker(r->pool) : 0;
}

/* Per kind (0, 1: inline on CPU 0, 1; 2: two threads), per call, per round. */
typedef struct call_ms {
    double gap[3][MAX_CALLS][ROUNDS], sum[3][MAX_CALLS][ROUNDS], wall[MAX_CALLS][ROUNDS];
    double busy[2][MAX_CALLS][ROUNDS], late[MAX_CALLS][ROUNDS];
} call_ms;

static void one_method(const bscene *b, const char *name, om_jobs *pool, bool pinned, rec_host *r, call_ms *cm)
{
    const uint32_t W = 1024, H = 768;
    bsetup bs;
    om_diag d;
    if (bench_setup(&bs, b, name, W, H, 2)) return;
    uint32_t ncalls = 0;
    const int kinds = pinned ? 3 : 2;   /* unpinned: inline (as kind 0) and two threads */
    for (int p = -1; p < ROUNDS; p++)
        for (int q = 0; q < kinds; q++) {
            int k = (q + (p < 0 ? 0 : p)) % kinds;
            if (!pinned && k == 1) k = 2;
            if (pinned && !bench_pin(k == 2 ? -1 : k)) {
                printf("%-12s %-7s (a thread would not be pinned)\n", b->name, name);
                goto out;
            }
            r->pool = k == 2 ? pool : NULL;
            for (int rep = 0; rep < 2; rep++) {   /* the first settles */
                om_arena fa;
                om_frame_desc fd;
                bench_frame_desc(&bs, b, &fd, &fa);
                fd.parallel_for = rec_for; fd.parallel_user = r; fd.worker = rec_worker; fd.threads = 2;
                r->ncalls = 0;
                r->t0 = om_clock_ns(NULL);
                if (om_render_frame(&fd, &fa, NULL, &d) != OM_OK) {
                    printf("%-12s %-7s %s\n", b->name, name, d.msg);
                    goto out;
                }
            }
            if (p < 0) continue;
            ncalls = r->ncalls < MAX_CALLS ? r->ncalls : MAX_CALLS;
            uint64_t prev = 0;
            for (uint32_t i = 0; i < ncalls; i++) {
                const call_rec *c = &r->calls[i];
                double s = 0, by[2] = {0, 0};
                uint64_t first = UINT64_MAX;
                for (uint32_t j = 0; j < c->n && j < MAX_JOBS; j++) {
                    const double t = (double)(c->end[j] - c->start[j]) / 1e6;
                    s += t;
                    by[c->thread[j] ? 1 : 0] += t;
                    if (c->thread[j] && c->start[j] < first) first = c->start[j];
                }
                cm->gap[k][i][p] = (double)(c->in - prev) / 1e6;
                cm->sum[k][i][p] = s;
                prev = c->out;
                if (k != 2) continue;
                cm->wall[i][p] = (double)(c->out - c->in) / 1e6;
                cm->busy[0][i][p] = by[0];
                cm->busy[1][i][p] = by[1];
                cm->late[i][p] = first == UINT64_MAX ? -1.0 : (double)(first - c->in) / 1e6;
            }
        }
    printf("%s %s\n", b->name, name);
    for (uint32_t i = 0; i < ncalls; i++) {
        const double s0 = bench_median(cm->sum[0][i], ROUNDS);
        const double s1 = pinned ? bench_median(cm->sum[1][i], ROUNDS) : s0;
        const double w = bench_median(cm->wall[i], ROUNDS), s2 = bench_median(cm->sum[2][i], ROUNDS);
        const double ideal = s0 + s1 > 0 ? s0 * s1 / (s0 + s1) : 0, mean = (s0 + s1) / 2;
        printf("  %3u %4u %7.3f %7.3f %7.3f | %7.3f %7.3f %7.3f %7.3f %7.3f %6.3f |", i, r->calls[i].n,
               bench_median(cm->gap[0][i], ROUNDS), s0, s1, bench_median(cm->gap[2][i], ROUNDS), w, s2,
               bench_median(cm->busy[0][i], ROUNDS), bench_median(cm->busy[1][i], ROUNDS),
               bench_median(cm->late[i], ROUNDS));
        if (mean > 0.005) printf(" %4.2f %5.2f\n", w > 0 ? ideal / w : 0, s2 / mean);
        else printf("    -     -\n");
    }
out:
    if (pinned) bench_pin(-1);
    bench_teardown(&bs);
}

void bench_calls(void)
{
    om_jobs *pool = NULL;
    om_diag d;
    const bool pinned = bench_pin_two();
    if (om_jobs_start(&pool, 2, &d) != OM_OK) {   /* before any pinning: its worker takes every CPU */
        printf("calls: no pool of two (%s)\n", d.msg);
        return;
    }
    rec_host *r = (rec_host *)calloc(1, sizeof *r);
    call_ms *cm = (call_ms *)calloc(1, sizeof *cm);
    if (!r || !cm) goto out;
    printf("\ncalls: a two-job frame's parallel-for calls, 1024x768, %d rounds (medians, ms): inline%s, and\n"
           "on two threads; eff = ideal on the two CPUs / wall, growth = two threads' job time / inline's\n",
           ROUNDS, pinned ? " on cpu0 and cpu1" : " (not pinned: cpu1 = cpu0)");
    printf("  %3s %4s %7s %7s %7s | %7s %7s %7s %7s %7s %6s | %4s %5s\n", "call", "jobs", "gap", "cpu0", "cpu1",
           "gap", "wall", "jobs", "thr0", "thr1", "late", "eff", "growth");
    bscene b;
    for (int sc = 0; sc < 2; sc++) {
        if (sc ? bench_load_random(&b, 100000) : bench_load(&b, "default", om_scene_default_text())) break;
        static const char *const names[] = {"none", "sm", "izb"};
        for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
            one_method(&b, names[k], pool, pinned, r, cm);
            fflush(stdout);
        }
        bench_free(&b);
    }
out:
    free(r);
    free(cm);
    om_jobs_stop(pool);
}
