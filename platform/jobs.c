/* jobs.c — a parallel-for for the engine's frames (om_frame_desc.parallel_for) on a
 * pool of POSIX threads started once and kept: a frame calls it a few times per strip,
 * so starting threads per call would cost more than the jobs of a small frame. The
 * caller's thread works too; jobs are handed out one index at a time under a mutex
 * (a frame's jobs are few and long, so the lock is not contended).
 *
 * Each thread owns a contiguous chunk of every call's indices, the same chunk for the
 * same n: it runs its own from the front, and once they are done takes the next job
 * of the chunk with the most left. A frame's jobs are bands of rows in row order in
 * every stage, so a thread meets the rows it wrote in the last stage (and the last
 * frame) in its own caches. Handed out in one queue, a band's samples were written
 * by one thread and shaded by the other about half the time: on the 2-CPU machine the
 * eye pass's bands took 10-20% more CPU time on two threads than on one, and 0-6%
 * this way (issue 26; `build/bench calls`, 1024x768). The next job, not the
 * last: the chunks' remainder then runs in index order, as from one queue, so jobs of
 * uneven cost end as they would there (izb's tiles on the default scene, the heavy ones
 * first on screen: 0.96-0.99 of the two CPUs' ideal from one queue, 0.87-0.90 taking
 * the last, 0.88-1.07 the next).
 *
 * A thread that has nothing to do spins for a while (SPIN_NS) before it sleeps on a
 * condition variable: a worker for the next call, the caller for the workers still
 * in this one. A frame's calls come a few microseconds apart, and a sleeping thread
 * takes tens of microseconds to wake on a virtual machine (on this project's 2-CPU
 * one, a worker woken for a call joined it about 40 us late), which is idle time of a
 * whole CPU at every call. The spin reads the counters with the compilers' atomic
 * loads; every write is still made under the mutex, so the mutex alone orders the
 * jobs' memory, and a compiler without those builtins only sleeps. */
#define _POSIX_C_SOURCE 200809L
#include "platform.h"

#include <pthread.h>
#include <sched.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#if defined(__GNUC__) || defined(__clang__)
#define SPIN_NS 200000L   /* how long an idle thread spins before it sleeps */
#define LOAD(p) __atomic_load_n((p), __ATOMIC_ACQUIRE)
#define STORE(p, v) __atomic_store_n((p), (v), __ATOMIC_RELEASE)
#else
#define SPIN_NS 0L
#define LOAD(p) (*(p))
#define STORE(p, v) (*(p) = (v))
#endif

struct om_jobs {
    pthread_mutex_t mu;
    pthread_cond_t go, done;
    pthread_t *workers;
    uint32_t nworkers;
    /* the current call: fn(user, i) for the i left in the threads' chunks; `busy`
     * workers are inside it. call, busy and quit are written under mu and read by
     * spinners without it. */
    om_job_fn fn;
    void *user;
    uint32_t left, busy;       /* jobs not yet begun; workers inside the call */
    uint32_t *lo, *hi;         /* thread k's chunk of the call's jobs still to run: [lo[k], hi[k]) */
    uint32_t call;             /* counts calls (mod 2^32), so a worker joins each at most once */
    uint32_t sleepers;         /* workers asleep on `go` */
    uint32_t quit;
    bool waiting;              /* the caller is asleep on `done` */
};

/* Spins for at most SPIN_NS while (*p == v) == same and no quit; returns with mu
 * unlocked and relocked around the spin. True: the wait ended while spinning. */
static bool spin(om_jobs *j, const uint32_t *p, uint32_t v, bool same)
{
    if (SPIN_NS <= 0) return false;
    bool ended = false;
    struct timespec t0, t;
    pthread_mutex_unlock(&j->mu);
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (uint32_t i = 1;; i++) {
        if ((LOAD(p) == v) != same || LOAD(&j->quit)) {
            ended = true;
            break;
        }
        if (i % 64 == 0) {   /* a CPU shared with other threads hands them its turn */
            sched_yield();
            clock_gettime(CLOCK_MONOTONIC, &t);
            if ((t.tv_sec - t0.tv_sec) * 1000000000L + (t.tv_nsec - t0.tv_nsec) > SPIN_NS) break;
        }
    }
    pthread_mutex_lock(&j->mu);
    return ended;
}

/* Runs the current call's jobs until none is left, thread k's chunk first; called and
 * returns with mu held. */
static void drain(om_jobs *j, uint32_t k)
{
    while (j->left) {
        uint32_t i;
        if (j->lo[k] < j->hi[k]) {
            i = j->lo[k]++;
        } else {
            uint32_t v = 0;   /* the most left: the owner there is furthest from done */
            for (uint32_t t = 1; t <= j->nworkers; t++)
                if (j->hi[t] - j->lo[t] > j->hi[v] - j->lo[v]) v = t;
            i = j->lo[v]++;
        }
        j->left--;
        om_job_fn fn = j->fn;
        void *user = j->user;
        pthread_mutex_unlock(&j->mu);
        fn(user, i);
        pthread_mutex_lock(&j->mu);
    }
}

static void *worker(void *arg)
{
    om_jobs *j = (om_jobs *)arg;
    uint32_t seen = 0;
    pthread_mutex_lock(&j->mu);
    for (;;) {
        while (!j->quit && (j->call == seen || j->left == 0)) {
            seen = j->call;
            if (spin(j, &j->call, seen, true)) continue;
            if (j->quit || j->call != seen) continue;
            j->sleepers++;
            pthread_cond_wait(&j->go, &j->mu);
            j->sleepers--;
        }
        if (j->quit) break;
        seen = j->call;
        STORE(&j->busy, j->busy + 1);
        drain(j, om_jobs_worker(j));
        STORE(&j->busy, j->busy - 1);
        if (j->busy == 0 && j->waiting) pthread_cond_signal(&j->done);
    }
    pthread_mutex_unlock(&j->mu);
    return NULL;
}

uint32_t om_cpus_online(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1u : n > 1024 ? 1024u : (uint32_t)n;
}

om_status om_jobs_start(om_jobs **out, uint32_t threads, om_diag *d)
{
    *out = NULL;
    om_jobs *j = (om_jobs *)calloc(1, sizeof *j);
    uint32_t nw = threads > 1 ? threads - 1 : 0;
    if (!j || (nw && !(j->workers = (pthread_t *)calloc(nw, sizeof(pthread_t)))) ||
        !(j->lo = (uint32_t *)calloc(2 * (size_t)(nw + 1), sizeof(uint32_t)))) {
        if (j) free(j->workers);
        free(j);
        if (d) { memset(d, 0, sizeof *d); d->status = OM_E_BUDGET; strcpy(d->msg, "out of memory for the job pool"); }
        return OM_E_BUDGET;
    }
    j->hi = j->lo + nw + 1;
    pthread_mutex_init(&j->mu, NULL);
    pthread_cond_init(&j->go, NULL);
    pthread_cond_init(&j->done, NULL);
    for (; j->nworkers < nw; j->nworkers++)
        if (pthread_create(&j->workers[j->nworkers], NULL, worker, j) != 0) break;
    *out = j;   /* fewer workers than asked if the system refused some: still correct */
    return OM_OK;
}

void om_jobs_for(void *host, om_job_fn fn, void *user, uint32_t n)
{
    om_jobs *j = (om_jobs *)host;
    if (!j || j->nworkers == 0) {
        for (uint32_t i = 0; i < n; i++) fn(user, i);
        return;
    }
    pthread_mutex_lock(&j->mu);
    j->fn = fn;
    j->user = user;
    j->left = n;
    const uint32_t T = j->nworkers + 1;
    for (uint32_t k = 0; k < T; k++) {
        j->lo[k] = (uint32_t)((uint64_t)n * k / T);
        j->hi[k] = (uint32_t)((uint64_t)n * (k + 1) / T);
    }
    STORE(&j->call, j->call + 1);
    if (j->sleepers) pthread_cond_broadcast(&j->go);
    drain(j, 0);
    while (j->busy) {
        if (spin(j, &j->busy, 0, false)) continue;
        if (!j->busy) break;
        j->waiting = true;
        pthread_cond_wait(&j->done, &j->mu);
        j->waiting = false;
    }
    pthread_mutex_unlock(&j->mu);
}

uint32_t om_jobs_threads(const om_jobs *j)
{
    return j ? j->nworkers + 1 : 1;
}

/* By the thread's place in `workers` (a frame's pool has a few): the array is written
 * before om_jobs_start returns, and a worker runs jobs only after a call has come
 * through the mutex. */
uint32_t om_jobs_worker(void *host)
{
    const om_jobs *j = (const om_jobs *)host;
    const pthread_t self = pthread_self();
    for (uint32_t k = 0; j && k < j->nworkers; k++)
        if (pthread_equal(j->workers[k], self)) return k + 1;
    return 0;
}

void om_jobs_stop(om_jobs *j)
{
    if (!j) return;
    pthread_mutex_lock(&j->mu);
    STORE(&j->quit, 1u);
    pthread_cond_broadcast(&j->go);
    pthread_mutex_unlock(&j->mu);
    for (uint32_t i = 0; i < j->nworkers; i++) pthread_join(j->workers[i], NULL);
    pthread_cond_destroy(&j->go);
    pthread_cond_destroy(&j->done);
    pthread_mutex_destroy(&j->mu);
    free(j->workers);
    free(j->lo);
    free(j);
}
