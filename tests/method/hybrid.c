/* method/hybrid.c — the hybrid method equals the reference sample for sample: on the
 * default scene, on seeded random scenes with semi-transparent casters and grazing
 * lights, with maps coarser and finer than the image, through strips and under its
 * minimum budget; and every sample its map calls certain (lit or shadowed) is what the
 * reference says, checked one by one. On threads (first in the file): its bands and
 * tiles (hybrid_bands) and its regions (hybrid_regions) give the frame of one thread,
 * and its map and a tile on lent slots the state one thread leaves (hybrid_map_lent,
 * hybrid_tile_lent). */
#include "../test.h"
#include "../harness.h"
#include "../jobs_util.h"
#include "../../engine/shadow/hybrid/hybrid.h"

#include <stdlib.h>

/* The threaded tests first: they name their own image sizes and buffers. */

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
        if (!h_scene_parse(&hs, li ? directional_scene : om_scene_default_text())) continue;
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

/* hybrid's map built by bands of rows on three lent slots (in reverse slot order) is
 * the map built on the calling thread, byte for byte: on the default scene and on one
 * whose triangles cross the light's near plane and leave the guard band (so they need
 * clipping, and their rows come from their sub-triangles), at map sides of a power of
 * two, of none (a division per texel) and below the number of bands. */
static void hybrid_map_lent(void)
{
    enum { W = 96, H = 72 };
    static const char clipped[] = "camera eye 0 6 12 target 0 1 0 fov 60 near 0.1 far 100\n"
                                  "light spot pos 0 4 0 target 0.5 0 0 fov 100 near 1 far 30\n"
                                  "plane size 60 60 albedo 0.7 0.7 0.7\n"
                                  "triangles count 400 seed 3 area 3 in -4 2.5 -4 4 4.5 4\n";
    const char *const scenes[] = {om_scene_default_text(), clipped};
    static const char *const sets[] = {"hybrid.map=256", "hybrid.map=100", "hybrid.map=5"};
    const om_method *m = om_method_find("hybrid");
    const om__pass *ps = m->pass;
    CHECK(ps && ps->lend);
    for (int sc = 0; sc < 2 && ps; sc++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[sc])) return;
        for (int i = 0; i < 3; i++) {
            om_method_cfg c = h_cfg("hybrid", sets[i]);
            size_t mn, full;
            om_diag d;
            CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
            uint64_t hash[2] = {0, 0};
            uint32_t clips = 0;
            for (int lend = 0; lend < 2; lend++) {
                void *mm = calloc(1, full), *state = NULL;
                om_arena ma;
                om_arena_init(&ma, mm, full, "method");
                CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, &d));
                const hybrid_state *hy = (const hybrid_state *)state;
                CHECK_MSG(hy->cands == hs.s.ntris, "hybrid: no room for the bands' reach");
                lent3 h = {{NULL, NULL, NULL}};
                const om__lend l = {lent_run, lent_run, &h, 3};
                om_view v;
                CHECK_OK(h_view(&v, &hs.s, 0.0f, W, H, &d));
                ps->lend(state, lend ? &l : NULL);
                CHECK_OK(m->begin(state, &v, &d));
                for (uint32_t k = 0; k < hs.s.nverts && sc == 1; k++) clips += hy->ls.verts[k].x == INT32_MIN;
                CHECK_OK(m->build(state, &d));
                hash[lend] = om_hash(0, hy->map, (size_t)hy->side * hy->side * sizeof *hy->map);
                ps->lend(state, NULL);
                free(mm);
            }
            CHECK_MSG(hash[1] == hash[0], "hybrid %s, scene %d: the map by bands differs", sets[i], sc);
            CHECK_MSG(sc == 0 || clips > 0, "hybrid: no vertex needs clipping");
        }
        h_scene_free(&hs);
    }
}

/* A large tile of hybrid's irregular pass (cut into regions) on three lent slots, its
 * sort by parts and bands of the grid's rows among the jobs, against the same tile on
 * the calling thread: the same samples in the same order in every cell, the same
 * cells, blocks, terms and counts. Every exposed sample of the cloud-and-bar scene
 * is a key (more than the two regions' samples a parallel sort needs). */
static void hybrid_tile_lent(void)
{
    enum { W = 320, H = 240, N = W * H };
    h_scene hs;
    if (!h_scene_parse(&hs, h_cloud_bar)) return;
    const om_method *m = om_method_find("hybrid");
    om_method_cfg c = h_cfg("hybrid", "");
    size_t mn, full;
    om_diag d;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
    void *mm = calloc(1, full), *state = NULL;
    om_arena ma;
    om_arena_init(&ma, mm, full, "method");
    CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, &d));
    om_view v;
    CHECK_OK(h_view(&v, &hs.s, 0.0f, W, H, &d));
    uint32_t *depth = calloc(N, sizeof *depth), *id = calloc(N, sizeof *id);
    om_sample *smp = calloc(N, sizeof *smp);
    om_term *terms[2] = {calloc(N, sizeof(om_term)), calloc(N, sizeof(om_term))};
    om_target tg = {W, H, 0, H, depth, id};
    om_strip st = {W, H, 0, H, smp, terms[0], v.origin};
    om__eye_pass_mark(&hs.s, &v, &tg, &st, NULL);
    memcpy(terms[1], terms[0], N * sizeof(om_term));
    CHECK_OK(m->begin(state, &v, &d));
    CHECK_OK(m->build(state, &d));
    const hybrid_state *hy = (const hybrid_state *)state;
    const size_t tb = om__htile_bytes(N, hs.s.ntris);
    unsigned char *mem[2] = {malloc(tb + 16), malloc(tb + 16)};   /* carved from 16 bytes on */
    om__htile t[2];
    lent3 h = {{NULL, NULL, NULL}};
    const om__lend l = {lent_run, lent_run, &h, 3};
    uint32_t n = 0;
    for (int k = 0; k < 2; k++) {
        unsigned char *at = mem[k] + (16 - (uintptr_t)mem[k] % 16) % 16;
        memset(at, k ? 0x5A : 0xA5, tb);
        om__htile_carve(&t[k], at, N, hs.s.ntris);
        n = 0;
        for (size_t i = 0; i < N; i++) {
            om__lpoint p;
            if ((terms[k][i].flags & OM_TERM_EXPOSED) && om__lspace_point(&hy->ls, &smp[i], &p))
                om__hkey_put(&t[k].raw[n++], &p, i);
        }
        om_strip sk = {W, H, 0, H, smp, terms[k], v.origin};
        om__htile_run(&hy->h, &t[k], n, &sk, k ? &l : NULL);
    }
    const uint32_t nc = t[0].cw * t[0].ch;
    CHECK_MSG(n >= 2 * 8192 && t[0].nreg > 1, "hybrid tile: %u samples, %u regions", n, t[0].nreg);
    CHECK(t[0].cw == t[1].cw && t[0].ch == t[1].ch && t[0].cs == t[1].cs && t[0].nreg == t[1].nreg);
    CHECK(!memcmp(&t[0].box, &t[1].box, sizeof t[0].box));
    CHECK_MSG(!memcmp(t[0].smp, t[1].smp, n * sizeof *t[0].smp), "hybrid tile: sorted samples differ");
    CHECK(!memcmp(t[0].od, t[1].od, n * sizeof *t[0].od));
    CHECK(!memcmp(t[0].cend, t[1].cend, nc * sizeof *t[0].cend) && !memcmp(t[0].oend, t[1].oend, nc * sizeof *t[0].oend));
    CHECK(!memcmp(t[0].bzmax, t[1].bzmax, t[0].cbw * ((t[0].ch + 3) / 4) * sizeof *t[0].bzmax));
    CHECK(t[0].setups == t[1].setups && t[0].tested == t[1].tested && t[0].regions == t[1].regions);
    CHECK_MSG(!memcmp(terms[0], terms[1], N * sizeof(om_term)), "hybrid tile: terms differ");
    for (int k = 0; k < 2; k++) {
        free(mem[k]);
        free(terms[k]);
    }
    free(depth);
    free(id);
    free(smp);
    free(mm);
    h_scene_free(&hs);
}

/* ---- hybrid against the reference, in one thread */
#define W 160
#define H 120
static om_term ref_t[W * H], hyb_t[W * H];
static om_sample smp[W * H];

static int term_diff(void)
{
    int diff = 0;
    for (int i = 0; i < W * H; i++)
        diff += ref_t[i].r != hyb_t[i].r || ref_t[i].g != hyb_t[i].g || ref_t[i].b != hyb_t[i].b ||
                ref_t[i].flags != hyb_t[i].flags;
    return diff;
}

/* Every certain answer of the map, held against the reference's term for the sample,
 * in the one-pass arena or (least) the minimum one, where no vertex projection is kept
 * and every triangle takes the map's full path. Then the method's own resolve, whose
 * float test decides most lit samples without their exact depth: its counts of each
 * answer must be the map's exact ones, sample for sample (a float "lit" where the exact
 * test is not sure would move a sample from uncertain to lit). Returns how many
 * samples the map decided. */
static uint32_t certain_agree(const om_scene *s, const om_method_cfg *c, const char *what, bool least)
{
    const om_method *m = om_method_find("hybrid");
    om_view v;
    om_diag d;
    CHECK_OK(h_view(&v, s, 0, W, H, &d));
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, c, s, W, H, &mn, &full));
    void *mem = malloc(least ? mn : full), *state;
    om_arena a;
    om_arena_init(&a, mem, least ? mn : full, "method");
    uint32_t decided = 0, wrong = 0, answers[3] = {0, 0, 0};
    bool ran = false;
    if (om_method_init(m, &state, &a, c, s, W, H, &d) == OM_OK && m->begin(state, &v, &d) == OM_OK &&
        m->build(state, &d) == OM_OK) {
        ran = true;
        const om__lspace *ls = om__hybrid_lspace(state);
        for (int i = 0; i < W * H; i++) {
            if (!(ref_t[i].flags & OM_TERM_EXPOSED)) continue;
            om__lpoint p;
            if (!om__lspace_point(ls, &smp[i], &p)) continue;
            om_term t = {255, 255, 255, ref_t[i].flags};
            int k = om__hybrid_decide(state, &p, &t);
            answers[k == 1 ? 0 : k == 2 ? 1 : 2]++;
            if (k == 0) continue;
            decided++;
            bool lit = ref_t[i].r == 255 && ref_t[i].g == 255 && ref_t[i].b == 255;
            bool black = ref_t[i].r == 0 && ref_t[i].g == 0 && ref_t[i].b == 0;
            if ((k == 1 && !lit) || (k == 2 && !black) || t.r != ref_t[i].r || t.g != ref_t[i].g ||
                t.b != ref_t[i].b) {
                if (++wrong <= 3)
                    fprintf(stderr, "  %s: pixel (%d,%d) certain %s, reference %u %u %u\n", what, i % W,
                            i / W, k == 1 ? "lit" : "shadowed", ref_t[i].r, ref_t[i].g, ref_t[i].b);
            }
        }
    }
    CHECK_MSG(wrong == 0, "%s: %u certain samples differ from the reference", what, wrong);
    CHECK_MSG(ran, "%s: the method did not start", what);
    if (ran) {
        static om_term terms[W * H];
        for (int i = 0; i < W * H; i++) terms[i] = ref_t[i];
        om_strip st = {W, H, 0, H, smp, terms, v.origin};
        om_method_stats ms;
        CHECK_OK(m->resolve(state, &st, &d));
        om_method_get_stats(m, state, &ms);
        for (int k = 0; k < 3; k++)
            CHECK_MSG(ms.counters[k] == answers[k], "%s: resolve's %s %u, the map's %u", what,
                      ms.counter_names[k], (unsigned)ms.counters[k], answers[k]);
        int diff = 0;
        for (int i = 0; i < W * H; i++)
            diff += terms[i].r != ref_t[i].r || terms[i].g != ref_t[i].g || terms[i].b != ref_t[i].b;
        CHECK_MSG(diff == 0, "%s: %d of resolve's terms differ from the reference", what, diff);
    }
    free(mem);
    return decided;
}

static void equals_ref(const char *text, const char *what, double least_certain)
{
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return;
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, NULL, ref_t, smp));
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("hybrid"));
    /* maps from far coarser than the image to far finer */
    static const uint32_t maps[] = {1, 16, 96, 512, 2048};
    for (int k = 0; k < 5; k++) {
        CHECK_OK(om_method_cfg_set(&c, "hybrid.map", maps[k], NULL));
        CHECK_OK(h_render(&hs.s, "hybrid", &c, W, H, 0, 0, NULL, hyb_t, NULL));
        CHECK_MSG(term_diff() == 0, "%s, map %u: %d samples differ", what, maps[k], term_diff());
        uint32_t decided = certain_agree(&hs.s, &c, what, false);
        certain_agree(&hs.s, &c, what, true);
        uint32_t exposed = 0;
        for (int i = 0; i < W * H; i++) exposed += ref_t[i].flags & OM_TERM_EXPOSED;
        if (maps[k] == 512) {
            printf("  %s map 512: %u of %u certain\n", what, decided, exposed);
            CHECK_MSG(decided >= least_certain * exposed, "%s, map 512: %u of %u exposed samples certain",
                      what, decided, exposed);
        }
    }
    /* strips of 7 rows, and the least memory it renders in (tiles of the uncertain) */
    CHECK_OK(om_method_cfg_set(&c, "hybrid.map", 96, NULL));
    CHECK_OK(h_render(&hs.s, "hybrid", &c, W, H, 0, 7, NULL, hyb_t, NULL));
    CHECK_MSG(term_diff() == 0, "%s, strips: %d samples differ", what, term_diff());
    const om_method *m = om_method_find("hybrid");
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
    CHECK_OK(h_render_in(&hs.s, "hybrid", &c, W, H, 0, 0, mn, NULL, hyb_t, NULL));
    CHECK_MSG(term_diff() == 0, "%s, minimum budget: %d samples differ", what, term_diff());
    h_scene_free(&hs);
}

static void hybrid_default_scene(void) { equals_ref(om_scene_default_text(), "default scene", 0.8); }

/* A tile of many uncertain samples, with room for the candidates, is cut into regions
 * that walk apart (hybrid_tile.c): on h_cloud_bar at 480x360, the reference's terms,
 * as without room for the candidates (every tile whole: the method's least memory). */
static void hybrid_regions_equal_ref(void)
{
    enum { RW = 480, RH = 360 };
    static om_term ref[RW * RH], hyb[RW * RH];
    h_scene hs;
    if (!h_scene_parse(&hs, h_cloud_bar)) return;
    const om_method *m = om_method_find("hybrid");
    om_method_cfg c;
    om_method_cfg_default(&c, m);
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, RW, RH, &mn, &full));
    CHECK_OK(h_render(&hs.s, "ref", NULL, RW, RH, 0, 0, NULL, ref, NULL));
    for (int least = 0; least < 2; least++) {
        CHECK_OK(h_render_in(&hs.s, "hybrid", &c, RW, RH, 0, 0, least ? mn : full, NULL, hyb, NULL));
        int diff = 0;
        for (int i = 0; i < RW * RH; i++)
            diff += ref[i].r != hyb[i].r || ref[i].g != hyb[i].g || ref[i].b != hyb[i].b ||
                    ref[i].flags != hyb[i].flags;
        CHECK_MSG(diff == 0, "cloud%s: %d samples differ from the reference", least ? ", least memory" : "", diff);
    }
    h_scene_free(&hs);
}

static void hybrid_random_scenes(void)
{
    for (int seed = 1; seed <= 3; seed++) {
        char text[1024];
        /* seed 3's spot light grazes the floor at a few degrees */
        snprintf(text, sizeof text,
                 "camera eye 0 5 8 target 0 0.5 0 fov 55\n"
                 "light spot pos %d %s 2 target 0 0 0 fov 75 near 1 far 40\n"
                 "plane size 14 14 divisions %d\n"
                 "triangles count 500 seed %d area 25 in -3 0.3 -3 3 3 3\n"
                 "triangles count 200 seed %d area 20 in -3 0.3 -3 3 3 3 albedo 1 0.6 0.2 opacity 0.5\n"
                 "sphere radius 0.7 segments 24 rings 12 translate 1 1 1 opacity 0.4 albedo 0.3 0.8 1\n"
                 "box size 1 1 1 translate -1 0.5 1\n",
                 seed * 2 - 3 + (seed == 3 ? 20 : 0), seed == 3 ? "1.5" : "9", seed * 3, seed, seed + 10);
        equals_ref(text, "random scene", 0.25);
    }
    equals_ref("camera eye 2 6 9 target 0 0.5 0 fov 50\n"
               "light directional dir -0.4 -1 -0.3\n"
               "plane size 20 20 divisions 5\n"
               "sphere radius 1 segments 32 rings 16 translate 0 1.5 0\n"
               "box size 1 2 1 translate 2 1 -1 rotate 0 30 0\n"
               "triangles count 300 seed 5 area 10 in -3 2 -3 3 4 3\n",
               "directional", 0.8);
    /* casters resting on the floor at shallow angles: near their low edges they are
     * barely nearer the light than what they shadow, so the map's planes are tested
     * where their margins are thinnest */
    equals_ref("camera eye 0 4 7 target 0 0 0 fov 50\n"
               "light spot pos 3 8 -4 target 0 0 0 fov 60 near 1 far 30\n"
               "plane size 10 10 divisions 4\n"
               "plane size 3 3 divisions 2 rotate 0 0 12 translate 0 0.31 0\n"
               "plane size 2 2 rotate 6 30 0 translate -2.5 0.1 -1\n"
               "box size 2 0.1 1 rotate 0 0 4 translate 1.5 0.12 2\n"
               "box size 1 1 1 rotate 0 20 0 translate 3 0.5 -1\n",
               "contact", 0.5);
}

void suite_hybrid(void)
{
    RUN(hybrid_default_scene);
    RUN(hybrid_random_scenes);
    RUN(hybrid_regions_equal_ref);
    RUN(hybrid_bands);
    RUN(hybrid_regions);
    RUN(hybrid_map_lent);
    RUN(hybrid_tile_lent);
}
