/* jobs.c — a parallel-for for the engine's frames (om_frame_desc.parallel_for) on a
 * pool of POSIX threads started once and kept: a frame calls it a few times per strip,
 * so starting threads per call would cost more than the jobs of a small frame. The
 * caller's thread works too; jobs are handed out one index at a time under a mutex
 * (a frame's jobs are few and long, so the lock is not contended). */
#define _POSIX_C_SOURCE 200809L
#include "platform.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

struct om_jobs {
    pthread_mutex_t mu;
    pthread_cond_t go, done;
    pthread_t *workers;
    uint32_t nworkers;
    /* the current call: fn(user, i) for i in [next, n); `busy` workers are inside it */
    om_job_fn fn;
    void *user;
    uint32_t n, next, busy;
    uint64_t call;             /* counts calls, so a worker joins each at most once */
    bool quit;
};

/* Runs the current call's jobs until none is left; called and returns with mu held. */
static void drain(om_jobs *j)
{
    while (j->next < j->n) {
        uint32_t i = j->next++;
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
    uint64_t seen = 0;
    pthread_mutex_lock(&j->mu);
    for (;;) {
        while (!j->quit && (j->call == seen || j->next >= j->n)) {
            seen = j->call;
            pthread_cond_wait(&j->go, &j->mu);
        }
        if (j->quit) break;
        seen = j->call;
        j->busy++;
        drain(j);
        if (--j->busy == 0) pthread_cond_signal(&j->done);
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
    if (!j || (nw && !(j->workers = (pthread_t *)calloc(nw, sizeof(pthread_t))))) {
        free(j);
        if (d) { memset(d, 0, sizeof *d); d->status = OM_E_BUDGET; strcpy(d->msg, "out of memory for the job pool"); }
        return OM_E_BUDGET;
    }
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
    j->n = n;
    j->next = 0;
    j->call++;
    pthread_cond_broadcast(&j->go);
    drain(j);
    while (j->busy) pthread_cond_wait(&j->done, &j->mu);
    pthread_mutex_unlock(&j->mu);
}

uint32_t om_jobs_threads(const om_jobs *j)
{
    return j ? j->nworkers + 1 : 1;
}

void om_jobs_stop(om_jobs *j)
{
    if (!j) return;
    pthread_mutex_lock(&j->mu);
    j->quit = true;
    pthread_cond_broadcast(&j->go);
    pthread_mutex_unlock(&j->mu);
    for (uint32_t i = 0; i < j->nworkers; i++) pthread_join(j->workers[i], NULL);
    pthread_cond_destroy(&j->go);
    pthread_cond_destroy(&j->done);
    pthread_mutex_destroy(&j->mu);
    free(j->workers);
    free(j);
}
