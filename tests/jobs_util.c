/* jobs_util.c — see jobs_util.h. */
#include "test.h"
#include "harness.h"
#include "jobs_util.h"

#include <stdlib.h>

/* Jobs in reverse order on the calling thread: no job may depend on another's order. */
void backwards(void *host, om_job_fn fn, void *user, uint32_t n)
{
    (void)host;
    for (uint32_t i = n; i-- > 0;) fn(user, i);
}

/* A worker index for `backwards`: each job another slot of 5 (its jobs run one at a
 * time, so any index is one that no running job holds); host counts the calls. */
uint32_t rotating(void *host)
{
    return (*(uint32_t *)host)++ % 5;
}

/* The hosts the pass tests run on (jobs_util.h). */
const uint32_t pass_threads[4] = {2, 3, 7, 16};
const pass_host pass_hosts[9] = {
    {0, false, false, ""}, {1, false, false, ""}, {2, false, false, ""}, {3, false, false, ""},
    {-1, false, false, " backwards"}, {-1, false, true, " inline tiles"},
    {0, true, false, " by worker"}, {3, true, false, " by worker"}, {-1, true, false, " backwards, rotating slots"},
};

om_status frame_hash_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    uint64_t *h = (uint64_t *)user;
    size_t n = (size_t)st->rows * st->width;
    *h = om_hash(*h, fb->pixels, fb->stride * st->rows);
    *h = om_hash(*h, st->terms, n * sizeof *st->terms);
    *h = om_hash(*h, st->samples, n * sizeof *st->samples);
    return OM_OK;
}

/* One frame of method m with a fresh state; frame arena of om_frame_bytes' with_bins (or
 * without bins, om_frame_bytes) plus job_bytes for the jobs. */
frame_out render_on(const om_scene *s, const om_method *m, const char *set, uint32_t W,
                    uint32_t H, uint32_t rows, om_parallel_for_fn pf, void *host, om_worker_fn worker,
                    uint32_t threads, size_t job_bytes, bool bins)
{
    frame_out o;
    memset(&o, 0, sizeof o);
    om_view v;
    om_diag d;
    if ((o.st = h_view(&v, s, 0, W, H, &d))) return o;
    om_method_cfg c = h_cfg(om_method_name(m), set);
    size_t mn, full;
    if ((o.st = om_method_bytes(m, &c, s, W, H, &mn, &full))) return o;
    uint32_t r = rows ? rows : H;
    size_t fbytes = (bins ? h_frame_bins(s, W, r) : h_frame_least(W, r)) + job_bytes;
    void *mm = malloc(full), *fm = malloc(fbytes), *px = malloc((size_t)W * r * 3);
    /* The frame arena filled with bytes that differ with the thread count and strips
     * (0x00, 0xFF, NaNs...): the frame carves its per-pixel buffers and bins without
     * zeroing them, so a byte read before it is written would change the frame. */
    if (fm) memset(fm, (int)((threads * 0x35u + rows) & 0xFFu), fbytes);
    om_arena ma, fa;
    om_arena_init(&ma, mm, full, "method");
    om_arena_init(&fa, fm, fbytes, "frame");
    void *state;
    if ((o.st = om_method_init(m, &state, &ma, &c, s, W, H, &d)) == OM_OK) {
        om_framebuffer fb = {OM_RGB888, W, r, (size_t)W * 3, (uint8_t *)px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, s, &v, m, state, &fb, rows);
        fd.on_strip = frame_hash_strip; fd.user = &o.hash;
        fd.parallel_for = pf; fd.parallel_user = host; fd.threads = threads; fd.worker = worker;
        o.hash = OM_HASH_INIT;
        om_frame_stats fs;
        o.st = om_render_frame(&fd, &fa, &fs, &d);
        o.jobs = fs.jobs;
        o.peak = fs.frame_peak;
        om_method_get_stats(m, state, &o.ms);
    }
    free(mm);
    free(fm);
    free(px);
    return o;
}

/* The same without the host's worker index. */
frame_out render_set(const om_scene *s, const om_method *m, const char *set, uint32_t W,
                     uint32_t H, uint32_t rows, om_parallel_for_fn pf, void *host,
                     uint32_t threads, size_t job_bytes, bool bins)
{
    return render_on(s, m, set, W, H, rows, pf, host, NULL, threads, job_bytes, bins);
}

/* The same with the settings "map=512". */
frame_out render(const om_scene *s, const om_method *m, uint32_t W, uint32_t H, uint32_t rows,
                 om_parallel_for_fn pf, void *host, uint32_t threads, size_t job_bytes,
                 bool bins)
{
    return render_set(s, m, "map=512", W, H, rows, pf, host, threads, job_bytes, bins);
}

/* The default scene (a spot light) and one under a directional light, which the frame
 * fits to the visible samples in a pass of its own. */
const char directional_scene[] =
    "camera eye 2 6 9 target 0 0.5 0 fov 50\n"
    "light directional dir -0.4 -1 -0.3\n"
    "plane size 20 20 divisions 5\n"
    "sphere radius 1 segments 32 rings 16 translate 0 1.5 0 opacity 0.5\n"
    "box size 1 2 1 translate 2 1 -1 rotate 0 30 0\n"
    "triangles count 300 seed 5 area 10 in -3 2 -3 3 4 3\n";

/* The threads pass host h runs its frames on. */
uint32_t host_threads(const pass_host *h)
{
    return h->pool >= 0 ? pass_threads[h->pool] : 5;
}

/* A pass frame (izb, hybrid) on pass host h (the pools started for pass_threads). */
frame_out pass_frame(const om_scene *s, const om_method *m, const char *set, uint32_t rows,
                     const pass_host *h, om_jobs *const *pools, uint32_t *calls)
{
    const uint32_t n = host_threads(h);
    return render_on(s, m, set, 160, 120, rows, h->pool >= 0 ? om_jobs_for : backwards,
                     h->pool >= 0 ? (void *)pools[h->pool] : (void *)calls,
                     !h->worker ? NULL : h->pool >= 0 ? om_jobs_worker : rotating, n,
                     h_frame_jobs(m, h->lean ? NULL : s, n), true);
}

void lent_run(const om__lend *l, void (*fn)(void *user, uint32_t k, void *scratch), void *user,
              uint32_t n)
{
    lent3 *h = (lent3 *)l->frame;
    const uint32_t p = n < l->slots ? n : l->slots;
    for (uint32_t s = p; s-- > 0;)
        for (uint32_t k = s; k < n; k += p) fn(user, k, h->slot[s]);
}
