/* test_threads.c — many cores, same bits: every method's frame (pixels, terms, mask)
 * and counters with 1, 2, 3, 4, 7 and 16 threads through the platform's pool, and with
 * a parallel-for that runs its jobs backwards, against the inline frame; whole frames
 * and strips, a spot and a directional light, each over a frame arena holding other
 * bytes. And the frame arena: room for N jobs but not N + 1 runs N. */
#include "test.h"
#include "harness.h"
#include "../platform/platform.h"
#include "../engine/shadow/asm/asm.h"

#include <stdio.h>
#include <stdlib.h>

/* Jobs in reverse order on the calling thread: no job may depend on another's order. */
static void backwards(void *host, om_job_fn fn, void *user, uint32_t n)
{
    (void)host;
    for (uint32_t i = n; i-- > 0;) fn(user, i);
}

/* A worker index for `backwards`: each job another slot of 5 (its jobs run one at a
 * time, so any index is one that no running job holds); host counts the calls. */
static uint32_t rotating(void *host)
{
    return (*(uint32_t *)host)++ % 5;
}

/* The hosts the pass tests run on: the pools of 2, 3, 7 and 16 threads as they hand out
 * jobs without and with the worker index, backwards, backwards with rotating slots,
 * and one without room for the pass's slots (lean: the tiles inline). */
typedef struct pass_host {
    int pool;              /* index into the test's pools, -1 for backwards */
    bool worker, lean;
    const char *what;
} pass_host;

static const uint32_t pass_threads[] = {2, 3, 7, 16};
static const pass_host pass_hosts[] = {
    {0, false, false, ""}, {1, false, false, ""}, {2, false, false, ""}, {3, false, false, ""},
    {-1, false, false, " backwards"}, {-1, false, true, " inline tiles"},
    {0, true, false, " by worker"}, {3, true, false, " by worker"}, {-1, true, false, " backwards, rotating slots"},
};
#define PASS_HOSTS (sizeof pass_hosts / sizeof pass_hosts[0])

typedef struct frame_out {
    uint64_t hash;             /* pixels, terms and samples, strip by strip */
    om_method_stats ms;
    uint32_t jobs;
    size_t peak;               /* the frame arena's */
    om_status st;
} frame_out;

static om_status on_strip(void *user, const om_strip *st, const om_framebuffer *fb)
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
static frame_out render_on(const om_scene *s, const om_method *m, const char *set, uint32_t W,
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
        fd.on_strip = on_strip; fd.user = &o.hash;
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
static frame_out render_set(const om_scene *s, const om_method *m, const char *set, uint32_t W,
                            uint32_t H, uint32_t rows, om_parallel_for_fn pf, void *host,
                            uint32_t threads, size_t job_bytes, bool bins)
{
    return render_on(s, m, set, W, H, rows, pf, host, NULL, threads, job_bytes, bins);
}

/* The same with the settings "map=512". */
static frame_out render(const om_scene *s, const om_method *m, uint32_t W, uint32_t H, uint32_t rows,
                        om_parallel_for_fn pf, void *host, uint32_t threads, size_t job_bytes,
                        bool bins)
{
    return render_set(s, m, "map=512", W, H, rows, pf, host, threads, job_bytes, bins);
}

/* The default scene (a spot light) and one under a directional light, which the frame
 * fits to the visible samples in a pass of its own. */
static const char directional[] =
    "camera eye 2 6 9 target 0 0.5 0 fov 50\n"
    "light directional dir -0.4 -1 -0.3\n"
    "plane size 20 20 divisions 5\n"
    "sphere radius 1 segments 32 rings 16 translate 0 1.5 0 opacity 0.5\n"
    "box size 1 2 1 translate 2 1 -1 rotate 0 30 0\n"
    "triangles count 300 seed 5 area 10 in -3 2 -3 3 4 3\n";

static void same_bits(void)
{
    static const uint32_t threads[] = {1, 2, 3, 4, 7, 16};
    om_jobs *pools[6];
    for (int k = 0; k < 6; k++) CHECK_OK(om_jobs_start(&pools[k], threads[k], NULL));
    for (int li = 0; li < 2; li++) {
        const char *text = li ? directional : om_scene_default_text();
        h_scene hs;
        if (!h_scene_parse(&hs, text)) continue;
        for (size_t mi = 0; mi < om_method_count(); mi++) {
            const om_method *m = om_method_at(mi);
            for (uint32_t rows = 0; rows <= 40; rows += 40) {
                frame_out one = render(&hs.s, m, 120, 90, rows, NULL, NULL, 1, 0, true);
                CHECK_MSG(one.st == OM_OK && one.jobs == 1, "%s: inline frame", om_method_name(m));
                for (int k = 0; k < 7; k++) {
                    uint32_t n = k < 6 ? threads[k] : 5;
                    frame_out o = k < 6 ? render(&hs.s, m, 120, 90, rows, om_jobs_for, pools[k], n, h_frame_jobs(m, &hs.s, n), true)
                                        : render(&hs.s, m, 120, 90, rows, backwards, NULL, n, h_frame_jobs(m, &hs.s, n), true);
                    CHECK_MSG(o.st == OM_OK && o.jobs == n, "%s: %u jobs ran %u", om_method_name(m), n, o.jobs);
                    CHECK_MSG(o.hash == one.hash, "%s light %d strips %u: %u threads%s change the frame",
                              om_method_name(m), li, rows, n, k < 6 ? "" : " backwards");
                    CHECK_MSG(!memcmp(o.ms.counters, one.ms.counters, sizeof o.ms.counters),
                              "%s: %u threads change the counters", om_method_name(m), n);
                }
            }
        }
        h_scene_free(&hs);
    }
    for (int k = 0; k < 6; k++) om_jobs_stop(pools[k]);
}

/* A frame arena with room for 3 jobs runs 3 when 8 are asked for (the bins of a whole
 * frame kept beside them), and one (inline) with room for fewer than 2. */
static void fewer_jobs(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    const om_method *m = om_method_find("ref");
    frame_out one = render(&hs.s, m, 64, 48, 0, NULL, NULL, 1, 0, true);
    frame_out three = render(&hs.s, m, 64, 48, 0, backwards, NULL, 8, h_frame_jobs(m, &hs.s, 3), true);
    frame_out three_nobins = render(&hs.s, m, 64, 48, 0, backwards, NULL, 8, h_frame_jobs(m, &hs.s, 3), false);
    frame_out none = render(&hs.s, m, 64, 48, 0, backwards, NULL, 8, h_frame_jobs(m, &hs.s, 1), false);
    CHECK_EQ_U(three.jobs, 3);
    CHECK_EQ_U(three_nobins.jobs, 3);
    CHECK_EQ_U(none.jobs, 1);
    CHECK(three.hash == one.hash && three_nobins.hash == one.hash && none.hash == one.hash);
    CHECK_EQ_U(h_frame_jobs(m, &hs.s, 1), 0);
    CHECK(h_frame_jobs(m, &hs.s, 4) == 2 * h_frame_jobs(m, &hs.s, 2));
    /* sm's map by bands, with the light's bins and without (one band a job) */
    const om_method *sm = om_method_find("sm");
    frame_out sm1 = render(&hs.s, sm, 64, 48, 0, NULL, NULL, 1, 0, true);
    frame_out sm3 = render(&hs.s, sm, 64, 48, 0, backwards, NULL, 3, h_frame_jobs(sm, &hs.s, 3), false);
    frame_out sm3_lean = render(&hs.s, sm, 64, 48, 0, backwards, NULL, 3, h_frame_jobs(sm, NULL, 3), false);
    CHECK(sm3.jobs == 3 && sm3_lean.jobs == 3);
    CHECK(sm3.hash == sm1.hash && sm3_lean.hash == sm1.hash);
    h_scene_free(&hs);
}

/* A worker index for `backwards` that names the thread *host says. */
static uint32_t named(void *host)
{
    return *(const uint32_t *)host;
}

/* One strip on two jobs and a scene of more than one vertex for every 8 pixels: the
 * eye pass rasterizes by parts of the triangles (frame.c), the halves, or with the
 * host's worker index many parts, each into its thread's target. Two planes that
 * coincide, one in each half: where they tie the first one's colour wins, as in one
 * walk of every triangle, whichever target holds which part and in whatever order
 * they are drawn (every part in one target, drawn last to first, leaves the tie to the
 * depth test); and no bins are carved (the frame arena's peak is the same with room
 * for them and without). Three jobs (with the bins) give the same frame. */
static void eye_halves(void)
{
    static const char two_planes[] =
        "camera eye 0 4 4 target 0 0 0 fov 60\n"
        "light spot pos 0 6 0 target 0 0 0 fov 90\n"
        "plane size 4 4 albedo 1 0 0\n"
        "plane size 4 4 albedo 0 0 1\n";
    h_scene hs;
    if (!h_scene_parse(&hs, two_planes)) return;
    const om_method *m = om_method_find("none");
    const size_t two_b = h_frame_jobs(m, &hs.s, 2), three_b = h_frame_jobs(m, &hs.s, 3);
    frame_out one = render(&hs.s, m, 8, 6, 0, NULL, NULL, 1, 0, true);
    frame_out two = render(&hs.s, m, 8, 6, 0, backwards, NULL, 2, two_b, true);
    frame_out lean = render(&hs.s, m, 8, 6, 0, backwards, NULL, 2, two_b, false);
    frame_out three = render(&hs.s, m, 8, 6, 0, backwards, NULL, 3, three_b, true);
    CHECK(two.jobs == 2 && lean.jobs == 2 && three.jobs == 3);
    CHECK(two.hash == one.hash && lean.hash == one.hash && three.hash == one.hash);
    CHECK_EQ_U(two.peak, lean.peak);
    uint32_t calls = 0, first = 0, second = 1;
    om_jobs *pool = NULL;
    CHECK_OK(om_jobs_start(&pool, 2, NULL));
    const frame_out spread = render_on(&hs.s, m, "map=512", 8, 6, 0, backwards, &calls, rotating, 2, two_b, true);
    const frame_out in0 = render_on(&hs.s, m, "map=512", 8, 6, 0, backwards, &first, named, 2, two_b, true);
    const frame_out in1 = render_on(&hs.s, m, "map=512", 8, 6, 0, backwards, &second, named, 2, two_b, true);
    const frame_out pooled = render_on(&hs.s, m, "map=512", 8, 6, 0, om_jobs_for, pool, om_jobs_worker, 2, two_b, true);
    CHECK(spread.jobs == 2 && in0.jobs == 2 && in1.jobs == 2 && pooled.jobs == 2);
    CHECK(spread.hash == one.hash && in0.hash == one.hash && in1.hash == one.hash && pooled.hash == one.hash);
    om_jobs_stop(pool);
    h_scene_free(&hs);
}

/* ---- asm: its bands look up with caches of their own and write nothing of the tree;
 * the use stamps of their lookups are put on the tree after the bands (om__bands.
 * finish). A state kept over frames, a still light, a moving camera and one sample
 * in 200 analysed (so that most leaves are stamped by lookups alone, and a missing
 * stamp changes the tree): the same frames, counters, nodes and stamps for any number
 * of jobs and their order, frame after frame. */
static void asm_frames(const om_scene *s, uint32_t rows, om_parallel_for_fn pf, void *host, uint32_t threads,
                       uint64_t *hash, uint32_t counters[][8], int nframes, const char *set)
{
    const om_method *m = om_method_find("asm");
    enum { W = 160, H = 120 };
    om_method_cfg c = h_cfg("asm", set);
    size_t mn, full;
    om_diag d;
    CHECK_OK(om_method_bytes(m, &c, s, W, H, &mn, &full));
    const uint32_t r = rows ? rows : H;
    void *mm = malloc(full), *px = malloc((size_t)W * r * 3), *state = NULL;
    om_arena ma, fa;
    om_arena_init(&ma, mm, full, "method");
    CHECK_OK(om_method_init(m, &state, &ma, &c, s, W, H, &d));
    /* om_frame_bytes' with_jobs is for the default settings; a larger tree's jobs need more */
    const bool big_tree = strstr(set, "asm.tile=4") != NULL;
    const size_t big = state && threads > 1 && big_tree ? threads * (m->pass->scratch(state, s) + 64) : 0;
    const size_t fbytes = h_frame_bins(s, W, r) + h_frame_jobs(m, s, threads) + big;
    void *fm = malloc(fbytes);
    for (int f = 0; f < nframes && state; f++) {
        om_camera cam, cam0;
        om_light light, moving;
        om_view v;
        om_scene_at(s, 0.0f, &cam0, &light);   /* the light held still: the tree lives on */
        om_scene_at(s, 0.15f * (float)f, &cam, &moving);
        cam.width = W;
        cam.height = H;
        CHECK_OK(om_view_init(&v, &cam, &light, s, &d));
        om_arena_init(&fa, fm, fbytes, "frame");
        om_framebuffer fb = {OM_RGB888, W, r, (size_t)W * 3, (uint8_t *)px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, s, &v, m, state, &fb, rows);
        fd.on_strip = on_strip; fd.user = &hash[f];
        fd.parallel_for = pf; fd.parallel_user = host; fd.threads = threads;
        hash[f] = OM_HASH_INIT;
        om_frame_stats fs;
        CHECK_OK(om_render_frame(&fd, &fa, &fs, &d));
        CHECK_MSG(fs.jobs == (pf ? threads : 1), "asm: %u jobs ran %u", threads, fs.jobs);
        om_method_stats ms;
        om_method_get_stats(m, state, &ms);
        memcpy(counters[f], ms.counters, sizeof counters[f]);
        /* and the tree: every node's place and use stamp */
        const om__asm_tree *t = om__asm_tree_of(state);
        if (big_tree) CHECK(t->lay.count >= 0xFFFFu);   /* finish finds the leaves again */
        uint64_t th = OM_HASH_INIT;
        th = om_hash(th, &t->root.stamp, sizeof t->root.stamp);
        for (uint32_t i = 0; i < t->lay.count; i++) {
            const om__asm_node *nd = (const om__asm_node *)om_pool_item(&t->pool, i);
            if (nd->alive) th = om_hash(om_hash(th, &i, sizeof i), nd, sizeof *nd);
        }
        hash[f] = om_hash(hash[f], &th, sizeof th);
    }
    free(mm);
    free(fm);
    free(px);
}

static void asm_bands(void)
{
    static const uint32_t threads[] = {2, 3, 4, 7, 16};
    enum { NF = 6 };
    om_jobs *pools[5];
    for (int k = 0; k < 5; k++) CHECK_OK(om_jobs_start(&pools[k], threads[k], NULL));
    /* the third: a tree of more than 0xFFFF nodes, whose leaves the bands cannot name */
    for (int li = 0; li < 3; li++) {
        h_scene hs;
        if (!h_scene_parse(&hs, li == 1 ? directional : om_scene_default_text())) continue;
        const char *set = li < 2 ? "asm.cap=400000 asm.stride=200"
                                 : "asm.cap=16000000 asm.tile=4 asm.cells=2 asm.root=16 asm.stride=300 asm.work=200";
        for (uint32_t rows = 0; rows <= 24; rows += 24) {
            uint64_t h1[NF], hn[NF];
            uint32_t c1[NF][8], cn[NF][8];
            asm_frames(&hs.s, rows, NULL, NULL, 1, h1, c1, NF, set);
            for (int k = 0; k < 6; k++) {
                uint32_t n = k < 5 ? threads[k] : 5;
                asm_frames(&hs.s, rows, k < 5 ? om_jobs_for : backwards, k < 5 ? pools[k] : NULL, n, hn, cn, NF, set);
                for (int f = 0; f < NF; f++)
                    CHECK_MSG(hn[f] == h1[f] && !memcmp(cn[f], c1[f], sizeof c1[f]),
                              "asm case %d strips %u frame %d: %u threads%s change the frame", li, rows, f, n,
                              k < 5 ? "" : " backwards");
            }
        }
        h_scene_free(&hs);
    }
    for (int k = 0; k < 5; k++) om_jobs_stop(pools[k]);
}

/* The threads pass host h runs its frames on. */
static uint32_t host_threads(const pass_host *h)
{
    return h->pool >= 0 ? pass_threads[h->pool] : 5;
}

/* A pass frame (izb, hybrid) on pass host h (the pools started for pass_threads). */
static frame_out pass_frame(const om_scene *s, const om_method *m, const char *set, uint32_t rows,
                            const pass_host *h, om_jobs *const *pools, uint32_t *calls)
{
    const uint32_t n = host_threads(h);
    return render_on(s, m, set, 160, 120, rows, h->pool >= 0 ? om_jobs_for : backwards,
                     h->pool >= 0 ? (void *)pools[h->pool] : (void *)calls,
                     !h->worker ? NULL : h->pool >= 0 ? om_jobs_worker : rotating, n,
                     h_frame_jobs(m, h->lean ? NULL : s, n), true);
}

/* ---- hybrid: its bands look the map up and mark the samples they leave uncertain;
 * its pass (om__pass) then runs the tiles of those as jobs, each with a tile's memory
 * of its own from the frame arena. The same terms, pixels and counters for any number
 * of jobs and their order, whole frames and strips, one tile of uncertain samples a
 * strip or tiles of a few (izb.pool); a frame arena without room for two tiles runs
 * inline (the bands unused), the same again. */
static void hybrid_bands(void)
{
    om_jobs *pools[4];
    uint32_t calls = 0;
    const om_method *m = om_method_find("hybrid");
    for (int k = 0; k < 4; k++) CHECK_OK(om_jobs_start(&pools[k], pass_threads[k], NULL));
    for (int li = 0; li < 2; li++) {
        h_scene hs;
        if (!h_scene_parse(&hs, li ? directional : om_scene_default_text())) continue;
        for (int pi = 0; pi < 2; pi++)
            for (uint32_t rows = 0; rows <= 24; rows += 24) {
                uint32_t pool = pi ? 97 : 0;
                char set[32];
                snprintf(set, sizeof set, "izb.pool=%u", pool);
                frame_out one = render_set(&hs.s, m, set, 160, 120, rows, NULL, NULL, 1, 0, true);
                CHECK_MSG(one.st == OM_OK && one.jobs == 1, "hybrid: inline frame");
                /* a pool of 97 leaves several tiles a strip; the counters say how many */
                CHECK_MSG(one.ms.counters[2] > 0 && (pool == 0 || one.ms.counters[5] > one.ms.counters[2] / 97),
                          "hybrid: %u uncertain in %u tiles", one.ms.counters[2], one.ms.counters[5]);
                size_t last_peak = 0;
                for (size_t k = 0; k < PASS_HOSTS; k++) {
                    const pass_host *h = &pass_hosts[k];
                    const uint32_t n = host_threads(h);
                    const bool lean = h->lean;   /* room for the bands' slots only: inline */
                    frame_out o = pass_frame(&hs.s, m, set, rows, h, pools, &calls);
                    CHECK_MSG(o.st == OM_OK && o.jobs == n, "hybrid: %u jobs ran %u", n, o.jobs);
                    CHECK_MSG(o.hash == one.hash && !memcmp(o.ms.counters, one.ms.counters, sizeof o.ms.counters),
                              "hybrid light %d pool %u strips %u: %u threads%s change the frame", li, pool, rows,
                              n, h->what);
                    /* the tiles of two jobs at least (two keys of 20 bytes a sample); the
                     * lean frame (5 jobs, as the one before it) without them */
                    size_t tile = pool ? pool : 160 * 120;   /* below hybrid's most, 32768 */
                    if (!lean) CHECK_MSG(o.peak > one.peak + 2 * 40 * tile, "hybrid %u jobs: no tiles (%zu vs %zu)",
                                         n, o.peak, one.peak);
                    else CHECK_MSG(o.peak + 2 * 40 * tile < last_peak, "hybrid lean: %zu vs %zu", o.peak, last_peak);
                    last_peak = o.peak;
                }
            }
        h_scene_free(&hs);
    }
    CHECK_MSG(calls > 0, "hybrid: the pass never asked the host which thread runs a job");
    for (int k = 0; k < 4; k++) om_jobs_stop(pools[k]);
}

/* hybrid's regions (hybrid_tile.c) on h_cloud_bar at 480x360: a strip of fewer tiles
 * than two a thread runs them one after another, each tile's candidates and regions
 * the jobs, on the hosts' slots by the worker index where they name it. The same frame
 * and counters as inline, for every host, and more regions than tiles. */
static void hybrid_regions(void)
{
    om_jobs *pools[4];
    uint32_t calls = 0;
    const om_method *m = om_method_find("hybrid");
    for (int k = 0; k < 4; k++) CHECK_OK(om_jobs_start(&pools[k], pass_threads[k], NULL));
    h_scene hs;
    if (h_scene_parse(&hs, h_cloud_bar)) {
        const frame_out one = render_set(&hs.s, m, "", 480, 360, 0, NULL, NULL, 1, 0, true);
        CHECK_MSG(one.st == OM_OK && one.ms.counters[7] > one.ms.counters[5], "hybrid: %u regions in %u tiles",
                  one.ms.counters[7], one.ms.counters[5]);
        for (size_t k = 0; k < PASS_HOSTS; k++) {
            const pass_host *h = &pass_hosts[k];
            const uint32_t n = host_threads(h);
            const frame_out o =
                render_on(&hs.s, m, "", 480, 360, 0, h->pool >= 0 ? om_jobs_for : backwards,
                          h->pool >= 0 ? (void *)pools[h->pool] : (void *)&calls,
                          !h->worker ? NULL : h->pool >= 0 ? om_jobs_worker : rotating, n,
                          h_frame_jobs(m, h->lean ? NULL : &hs.s, n), true);
            CHECK_MSG(o.st == OM_OK && o.hash == one.hash &&
                          !memcmp(o.ms.counters, one.ms.counters, sizeof o.ms.counters),
                      "hybrid regions: %u threads%s change the frame", n, h->what);
        }
        h_scene_free(&hs);
    }
    for (int k = 0; k < 4; k++) om_jobs_stop(pools[k]);
}

/* ---- izb: its tiles of exposed samples as jobs (om__pass), each with a pool of its
 * own from the frame arena. The same terms, pixels and counters for any number of jobs
 * and their order, whole frames and strips, one tile or many (izb.pool); a frame arena
 * without room for two pools runs the tiles inline, the same again. */
static void izb_pass(void)
{
    om_jobs *pools[4];
    uint32_t calls = 0;
    const om_method *m = om_method_find("izb");
    for (int k = 0; k < 4; k++) CHECK_OK(om_jobs_start(&pools[k], pass_threads[k], NULL));
    for (int li = 0; li < 2; li++) {
        h_scene hs;
        if (!h_scene_parse(&hs, li ? directional : om_scene_default_text())) continue;
        for (int pi = 0; pi < 3; pi++)
            for (uint32_t rows = 0; rows <= 24; rows += 24) {
                static const uint32_t pool_of[] = {0, 397, 2000};
                char set[32];
                snprintf(set, sizeof set, "izb.pool=%u", pool_of[pi]);
                frame_out one = render_set(&hs.s, m, set, 160, 120, rows, NULL, NULL, 1, 0, true);
                CHECK_MSG(one.st == OM_OK && one.jobs == 1, "izb: inline frame");
                size_t last_peak = 0;
                /* a pool of 397 leaves many tiles a strip */
                CHECK_MSG(pi != 1 || one.ms.counters[5] > 3 * (rows ? 120 / rows : 1), "izb pool %u: %u tiles",
                          pool_of[pi], one.ms.counters[5]);
                for (size_t k = 0; k < PASS_HOSTS; k++) {
                    const pass_host *h = &pass_hosts[k];
                    const uint32_t n = host_threads(h);
                    const bool lean = h->lean;   /* room for the bands' slots only: the tiles inline */
                    frame_out o = pass_frame(&hs.s, m, set, rows, h, pools, &calls);
                    CHECK_MSG(o.st == OM_OK && o.jobs == n, "izb: %u jobs ran %u", n, o.jobs);
                    CHECK_MSG(o.hash == one.hash && !memcmp(o.ms.counters, one.ms.counters, sizeof o.ms.counters),
                              "izb light %d pool %u strips %u: %u threads%s change the frame", li, pool_of[pi],
                              rows, n, h->what);
                    /* the pools of two jobs at least (keys of 24 bytes, two buffers); the
                     * lean frame (5 jobs, as the one before it) without them */
                    size_t pool = pool_of[pi] ? pool_of[pi] : 160 * 120;
                    if (!lean) CHECK_MSG(o.peak > one.peak + 2 * 48 * pool, "izb %u jobs: no pools (%zu vs %zu)",
                                         n, o.peak, one.peak);
                    else CHECK_MSG(o.peak + 2 * 48 * pool < last_peak, "izb lean: %zu vs %zu", o.peak, last_peak);
                    last_peak = o.peak;
                }
            }
        h_scene_free(&hs);
    }
    CHECK_MSG(calls > 0, "izb: the pass never asked the host which thread runs a job");
    for (int k = 0; k < 4; k++) om_jobs_stop(pools[k]);
}

/* Settings that change how a method works by bands, on 2 and 5 backwards jobs, whole
 * and through strips of 40, against the inline frame (frame and counters):
 *  - rtw's warped map by bands: the exact map (with the light's bins, which pass over
 *    the triangles that miss a band's grid rows, and without: the counters hold the
 *    triangles drawn, counted in the band of a triangle's first grid row), the warped
 *    vertices' map (the first band makes it whole), forward analysis;
 *  - spsm's map by bands (a triangle touching one texel row of the whole map, not of
 *    its band, takes its nearest vertex's depth; the fine map's rows are two of the
 *    map's; with the light's bins and without) and its resolve by bands with AA (its
 *    sub-samples' steps must not come from the next row, which another band holds),
 *    with the fine plain map, its points all made or only those the lookup reads. */
static void settings_by_bands(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    static const char *const sets[][2] = {
        {"rtw", "map=512"}, {"rtw", "map=300 rtw.exact=0"}, {"rtw", "map=256 rtw.analysis=2 rtw.sigma=0"},
        {"spsm", "map=256 spsm.aa=4"}, {"spsm", "map=512 spsm.aa=3 spsm.fine=1 spsm.records=1"},
        {"spsm", "map=1024 spsm.fine=1 spsm.records=2"}, {"spsm", "map=64"},
    };
    for (size_t i = 0; i < sizeof sets / sizeof sets[0]; i++) {
        const om_method *m = om_method_find(sets[i][0]);
        for (uint32_t rows = 0; rows <= 40; rows += 40) {
            frame_out one = render_set(&hs.s, m, sets[i][1], 96, 72, rows, NULL, NULL, 1, 0, true);
            CHECK_MSG(one.st == OM_OK, "%s %s: inline frame", om_method_name(m), sets[i][1]);
            for (uint32_t n = 2; n <= 5; n += 3)
                for (int lean = 0; lean < (rows ? 1 : 2); lean++) {   /* strips' bins come first */
                    frame_out o = render_set(&hs.s, m, sets[i][1], 96, 72, rows, backwards, NULL, n,
                                             h_frame_jobs(m, lean ? NULL : &hs.s, n), !lean);
                    CHECK_MSG(o.st == OM_OK && o.jobs == n, "%s %s strips %u%s: %u jobs ran %u", om_method_name(m), sets[i][1], rows, lean ? " lean" : "", n, o.jobs);
                    CHECK_MSG(o.hash == one.hash, "%s %s strips %u: %u bands%s change the frame", om_method_name(m),
                              sets[i][1], rows, n, lean ? " without bins" : "");
                    CHECK_MSG(!memcmp(o.ms.counters, one.ms.counters, sizeof o.ms.counters),
                              "%s %s strips %u: %u bands change the counters", om_method_name(m), sets[i][1], rows, n);
                }
        }
    }
    h_scene_free(&hs);
}

/* A frame through strips that passes over the image more than once (asm and rtw
 * observe; a directional light is fitted) keeps its first pass's triangle ids where the
 * arena has om_frame_bytes' with_ids beyond the rest, and its later passes resolve from them:
 * the same frames and counters as without the room, inline and with jobs; a frame that
 * passes once (sm under the spot light) carves none. */
static void kept_ids(void)
{
    static const char *const names[] = {"asm", "rtw", "sm"};
    for (int li = 0; li < 2; li++) {
        h_scene hs;
        if (!h_scene_parse(&hs, li ? directional : om_scene_default_text())) continue;
        const size_t ids = h_frame_ids(&hs.s, 120, 90);
        CHECK(ids >= 120 * 90 * 2);
        for (int mi = 0; mi < 3; mi++) {
            const om_method *m = om_method_find(names[mi]);
            const bool twice = li || mi < 2;
            for (uint32_t rows = 8; rows <= 40; rows += 32)
                for (uint32_t n = 1; n <= 3; n += 2) {
                    const size_t jb = h_frame_jobs(m, &hs.s, n);
                    om_parallel_for_fn pf = n > 1 ? backwards : NULL;
                    frame_out a = render(&hs.s, m, 120, 90, rows, pf, NULL, n, jb, true);
                    frame_out b = render(&hs.s, m, 120, 90, rows, pf, NULL, n, jb + ids, true);
                    CHECK_MSG(a.st == OM_OK && b.st == OM_OK && a.hash == b.hash,
                              "%s light %d strips %u threads %u: kept ids change the frame", om_method_name(m), li, rows, n);
                    CHECK_MSG(!memcmp(a.ms.counters, b.ms.counters, sizeof a.ms.counters),
                              "%s: kept ids change the counters", om_method_name(m));
                    CHECK_MSG(twice ? b.peak >= a.peak + 120 * 90 * 2 : b.peak == a.peak,
                              "%s light %d: ids carved %s", om_method_name(m), li, twice ? "not" : "needlessly");
                }
        }
        h_scene_free(&hs);
    }
}

void suite_threads(void)
{
    RUN(same_bits);
    RUN(fewer_jobs);
    RUN(eye_halves);
    RUN(hybrid_bands);
    RUN(hybrid_regions);
    RUN(asm_bands);
    RUN(izb_pass);
    RUN(settings_by_bands);
    RUN(kept_ids);
}
