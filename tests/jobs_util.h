/* jobs_util.h — helpers the threaded tests share (property/threads.c and the method
 * suites' own threading tests): parallel-fors that run their jobs backwards, worker
 * indices, the hosts the pass tests run on, one frame rendered on a host and hashed,
 * and three lent slots (om__lend) whose jobs run backwards. */
#ifndef OM_JOBS_UTIL_H
#define OM_JOBS_UTIL_H

#include "ombra.h"
#include "ombra_measure.h"
#include "../platform/platform.h"
#include "../engine/shadow/method.h"

/* Jobs in reverse order on the calling thread: no job may depend on another's order. */
void backwards(void *host, om_job_fn fn, void *user, uint32_t n);
/* A worker index for `backwards`: each job another slot of 5 (its jobs run one at a
 * time, so any index is one that no running job holds); host counts the calls. */
uint32_t rotating(void *host);

/* The hosts the pass tests run on: the pools of 2, 3, 7 and 16 threads as they hand out
 * jobs without and with the worker index, backwards, backwards with rotating slots,
 * and one without room for the pass's slots (lean: the tiles inline). */
typedef struct pass_host {
    int pool;              /* index into the test's pools, -1 for backwards */
    bool worker, lean;
    const char *what;
} pass_host;

extern const uint32_t pass_threads[4];   /* the pools' threads */
extern const pass_host pass_hosts[9];
#define PASS_HOSTS (sizeof pass_hosts / sizeof pass_hosts[0])

typedef struct frame_out {
    uint64_t hash;             /* pixels, terms and samples, strip by strip */
    om_method_stats ms;
    uint32_t jobs;
    size_t peak;               /* the frame arena's */
    om_status st;
} frame_out;

/* A strip callback hashing pixels, terms and samples into *(uint64_t *)user. */
om_status frame_hash_strip(void *user, const om_strip *st, const om_framebuffer *fb);
/* One frame of method m with a fresh state, width x height through strips of `rows`
 * rows (0: whole) with settings `set`; frame arena of om_frame_bytes' with_bins (or
 * without bins, om_frame_bytes) plus job_bytes for the jobs. */
frame_out render_on(const om_scene *s, const om_method *m, const char *set, uint32_t width,
                    uint32_t height, uint32_t rows, om_parallel_for_fn pf, void *host, om_worker_fn worker,
                    uint32_t threads, size_t job_bytes, bool bins);
/* The same without the host's worker index. */
frame_out render_set(const om_scene *s, const om_method *m, const char *set, uint32_t width,
                     uint32_t height, uint32_t rows, om_parallel_for_fn pf, void *host,
                     uint32_t threads, size_t job_bytes, bool bins);
/* The same with the settings "map=512". */
frame_out render(const om_scene *s, const om_method *m, uint32_t width, uint32_t height, uint32_t rows,
                 om_parallel_for_fn pf, void *host, uint32_t threads, size_t job_bytes, bool bins);

/* A scene under a directional light, which the frame fits to the visible samples in a
 * pass of its own (the tests' other is the default scene, a spot light). */
extern const char directional_scene[];

/* The threads pass host h runs its frames on. */
uint32_t host_threads(const pass_host *h);
/* A pass frame (izb, hybrid) at 160x120 on pass host h (the pools started for
 * pass_threads). */
frame_out pass_frame(const om_scene *s, const om_method *m, const char *set, uint32_t rows,
                     const pass_host *h, om_jobs *const *pools, uint32_t *calls);

/* Three slots a method is lent (om__lend's frame); lent_run runs a lent stage's jobs
 * on them, last slot first. */
typedef struct lent3 {
    void *slot[3];
} lent3;

void lent_run(const om__lend *l, void (*fn)(void *user, uint32_t k, void *scratch), void *user,
              uint32_t n);

#endif
