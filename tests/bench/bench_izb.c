/* bench_izb.c — Table 1 of the Alias-Free Shadow Maps paper for ombra's irregular
 * z-buffer: 1K, 10K, 100K and 1M random small triangles of constant total area at
 * 1024x768, with the paper's rows (BSP nodes, nodes visited, nodes culled, samples
 * tested; transform, BSP construction, rasterization and total time) and the tiles of
 * the default pool and the init that clears it, beside the BVH
 * reference's time on the same frame; then the hot-spot scene. Medians of 3 runs.
 * `slots`: the longer of the two sums of the tiles' times (transform, build, raster)
 * that two threads would run as izb's pass hands tiles out (slot k % 2, each odd pair
 * the other way round), the bound that the tiles put on a frame's speed-up on two threads. */
#include "bench.h"
#include "../../engine/shadow/izb/izb.h"
#include "../../engine/shadow/method.h"

static void table_row(const bscene *b, uint32_t W, uint32_t H)
{
    const om_method *m = om_method_find("izb");
    om_method_cfg cfg;
    om_method_cfg_default(&cfg, m);
    om_view v;
    om_diag d;
    size_t mn, full, n = (size_t)W * H;
    if (bench_view(b, W, H, 0, &v) || om_method_bytes(m, &cfg, &b->s, W, H, &mn, &full)) return;
    void *mem = malloc(full);
    om_target tg = {W, H, 0, H, malloc(n * 4), malloc(n * 4)};
    om_strip st = {W, H, 0, H, malloc(n * sizeof(om_sample)), malloc(n * sizeof(om_term)), v.origin};
    om__eye_pass(&b->s, &v, &tg, &st, NULL);
    for (size_t i = 0; i < n; i++) {
        st.terms[i].flags = st.samples[i].tri != OM_NO_TRI && om__exposed(&b->s, &v, &st.samples[i]) ? OM_TERM_EXPOSED : 0;
    }
    double ti[3], tt[3], tb[3], tr[3], ts[3];
    om__izb_stats stats;
    memset(&stats, 0, sizeof stats);
    for (int r = 0; r < 3; r++) {
        om_arena a;
        om_arena_init(&a, mem, full, "method");
        void *state;
        uint64_t ti0 = om_clock_ns(NULL);
        if (om_method_init(m, &state, &a, &cfg, &b->s, W, H, &d)) return;
        ti[r] = (double)(om_clock_ns(NULL) - ti0) / 1e6;
        if (m->begin(state, &v, &d)) return;
        om__izb *z = om__izb_of(state);
        size_t next = 0;
        uint64_t ns[3] = {0, 0, 0}, slot[2] = {0, 0};
        uint64_t tgrid = om_clock_ns(NULL);
        om__izb_grid(z);   /* the triangles binned once a frame: part of the raster's time */
        ns[2] += om_clock_ns(NULL) - tgrid;
        uint32_t exposed = 0;
        for (size_t i = 0; i < n; i++) exposed += (st.terms[i].flags & OM_TERM_EXPOSED) != 0;
        const uint32_t tiles = om__izb_tiles(z, exposed);
        for (uint32_t k = 0; k < tiles; k++) {   /* tile after tile, as the method's default pool has them */
            uint64_t t0 = om_clock_ns(NULL);
            om__izb_transform(z, &st, &next, n,
                              om__izb_tile_first(z, exposed, k + 1) - om__izb_tile_first(z, exposed, k));
            uint64_t t1 = om_clock_ns(NULL);
            ns[0] += t1 - t0;
            om__izb_build(z);
            uint64_t t2 = om_clock_ns(NULL);
            om__izb_raster(z);
            uint64_t t3 = om_clock_ns(NULL);
            ns[1] += t2 - t1;
            ns[2] += t3 - t2;
            /* slot k % 2 of two, but the other way round in each odd, whole pair of tiles
             * (izb.c, tile_of) */
            const uint32_t pair = k / 2;
            slot[(pair & 1) && 2 * pair + 1 < tiles ? 1 - k % 2 : k % 2] += t3 - t0;
            z->st.tiles++;
        }
        tt[r] = (double)ns[0] / 1e6;
        tb[r] = (double)ns[1] / 1e6;
        tr[r] = (double)ns[2] / 1e6;
        ts[r] = (double)(slot[0] > slot[1] ? slot[0] : slot[1]) / 1e6;
        stats = z->st;
    }
    double i0 = bench_median(ti, 3), a = bench_median(tt, 3), bb = bench_median(tb, 3), c = bench_median(tr, 3);
    /* the reference on the same frame: BVH build + shadow tests */
    double rt[3];
    mrun r;
    for (int k = 0; k < 3; k++) {
        if (bench_run(b, "ref", NULL, W, H, 0, NULL, &r)) return;
        rt[k] = r.init_ms + r.resolve_ms;
    }
    printf("%-12s %6u %8u %9u %8u %9u %6.1f %9.1f %9.1f %9.1f %9.1f %7.1f %10.1f\n", b->name, stats.tiles,
           stats.nodes, stats.visited, stats.culled_shadowed + stats.culled_depth, stats.tested, i0, a, bb,
           c, i0 + a + bb + c, bench_median(ts, 3), bench_median(rt, 3));
    free(mem);
    free(tg.depth);
    free(tg.id);
    free(st.samples);
    free(st.terms);
}

void bench_izb(void)
{
    printf("irregular z-buffer at 1024x768 (Table 1 of the paper; times in ms, medians of 3)\n");
    printf("%-12s %6s %8s %9s %8s %9s %6s %9s %9s %9s %9s %7s %10s\n", "scene", "tiles", "nodes", "visited",
           "culled", "tested", "init", "transform", "bsp", "raster", "total", "slots", "ref total");
    static const unsigned counts[] = {1000, 10000, 100000, 1000000};
    for (int k = 0; k < 4; k++) {
        bscene b;
        if (bench_load_random(&b, counts[k])) return;
        table_row(&b, 1024, 768);
        bench_free(&b);
    }
    bscene b;
    if (bench_load(&b, "hot-spot",
                   "camera eye 0 3 10 target 0 0 -10 fov 60\n"
                   "light spot pos 0 0.6 -60 target 0 0 0 fov 20 near 1 far 200\n"
                   "plane size 80 80 divisions 4\n"
                   "box size 0.05 1.5 0.05 translate -1 0.75 -30\n"
                   "box size 0.05 1.5 0.05 translate 0 0.75 -30\n"
                   "box size 0.05 1.5 0.05 translate 1 0.75 -30\n"
                   "box size 3 0.05 0.05 translate 0 0.4 -25\n"
                   "triangles count 10000 seed 3 area 4 in -6 0.2 -40 6 2 -20\n"))
        return;
    table_row(&b, 1024, 768);
    bench_free(&b);
    if (bench_load(&b, "default", om_scene_default_text())) return;
    table_row(&b, 1024, 768);
    bench_free(&b);
}
