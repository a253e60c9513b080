/* bench_raster.c — the rasterizer's figures: the eye pass at 1024x768 (depth + id,
 * then visible samples) and the depth-only light pass at 1024x1024 and 2048x2048, for
 * the default scene, for 100K random small triangles above a floor and for 1,000
 * triangles over the whole map; each without and with the coarse depth. Then
 * (bench_raster_sweep) the same passes on random 1K..1M triangles in ms and triangles
 * per second, the figures issue 29's desktop targets are stated in. */
#include "bench.h"

static void bench_eye(const bscene *b, uint32_t W, uint32_t H)
{
    om_camera cam = b->s.camera;
    cam.width = W;
    cam.height = H;
    om_view v;
    om_diag d;
    if (om_view_init(&v, &cam, &b->s.light, &b->s, &d) != OM_OK) {
        fprintf(stderr, "bench: %s\n", d.msg);
        return;
    }
    size_t n = (size_t)W * H;
    om_target tg = {W, H, 0, H, malloc(n * 4), malloc(n * 4)};
    om_sample *smp = malloc(n * sizeof *smp);
    om_strip st = {W, H, 0, H, smp, NULL, v.origin};
    uint64_t raster[RUNS], total[RUNS];
    size_t covered = 0;
    for (int r = 0; r < RUNS; r++) {
        uint64_t t0 = om_clock_ns(NULL);
        om__scene_raster(&b->s, &v.cam_vp, v.origin, &tg, OM_RASTER_DEPTH_ID, false, NULL);
        uint64_t t1 = om_clock_ns(NULL);
        om__eye_pass(&b->s, &v, &tg, &st, NULL);
        uint64_t t2 = om_clock_ns(NULL);
        raster[r] = t1 - t0;
        total[r] = t2 - t1;
    }
    for (size_t i = 0; i < n; i++) covered += smp[i].tri != OM_NO_TRI;
    printf("%-12s eye pass %ux%u: %8.2f ms (raster alone %.2f ms), %u tris, %.0f%% covered\n",
           b->name, W, H, bench_median_ns(total, RUNS), bench_median_ns(raster, RUNS), b->s.ntris,
           100.0 * (double)covered / (double)n);
    free(tg.depth);
    free(tg.id);
    free(smp);
}

static void bench_light(const bscene *b, uint32_t size)
{
    om_view v;
    om_diag d;
    if (om_view_init(&v, &b->s.camera, &b->s.light, &b->s, &d) != OM_OK) {
        fprintf(stderr, "bench: %s\n", d.msg);
        return;
    }
    size_t n = (size_t)size * size;
    om_target tg = {size, size, 0, size, malloc(n * 4), NULL};
    uint32_t *hiz = malloc(om__hiz_words(size, size) * 4);
    /* without and with the coarse depth (what sm and rtw draw with), interleaved */
    uint64_t t[RUNS], th[RUNS];
    for (int r = 0; r < RUNS; r++) {
        uint64_t t0 = om_clock_ns(NULL);
        om__scene_raster(&b->s, &v.light_vp, v.origin, &tg, OM_RASTER_DEPTH, true, NULL);
        uint64_t t1 = om_clock_ns(NULL);
        om__scene_raster_hiz(&b->s, &v.light_vp, v.origin, &tg, OM_RASTER_DEPTH, true, NULL, hiz);
        t[r] = t1 - t0;
        th[r] = om_clock_ns(NULL) - t1;
    }
    size_t written = 0;
    for (size_t i = 0; i < n; i++) written += tg.depth[i] != 0xFFFFFFFFu;
    printf("%-12s light depth pass %ux%u: %8.2f ms, with coarse depth %8.2f ms, %.0f%% of texels written\n",
           b->name, size, size, bench_median_ns(t, RUNS), bench_median_ns(th, RUNS),
           100.0 * (double)written / (double)n);
    free(tg.depth);
    free(hiz);
}

void bench_raster(void)
{
    bscene def, rnd;
    if (bench_load(&def, "default", om_scene_default_text()) || bench_load_random(&rnd, 100000)) return;
    bench_eye(&def, 1024, 768);
    bench_eye(&rnd, 1024, 768);
    bench_light(&def, 1024);
    bench_light(&def, 2048);
    bench_light(&rnd, 1024);
    bench_light(&rnd, 2048);
    bscene huge;   /* issue 24: 1,000 triangles each over the whole map */
    if (!bench_load(&huge, "huge 1K", "triangles count 1000 area 1e12 in 0 0 0 0 0 0\n")) {
        bench_light(&huge, 2048);
        bench_free(&huge);
    }
    bench_free(&def);
    bench_free(&rnd);
}

/* One pass, RUNS times: its median in ms. */
static double time_pass(const bscene *b, const om_mat4 *vp, om_vec3 o, om_target *tg, om_raster_mode mode, bool cull)
{
    uint64_t t[RUNS];
    for (int r = 0; r < RUNS; r++) {
        uint64_t t0 = om_clock_ns(NULL);
        om__scene_raster(&b->s, vp, o, tg, mode, cull, NULL);
        t[r] = om_clock_ns(NULL) - t0;
    }
    return bench_median_ns(t, RUNS);
}

/* The light depth pass (plain, as every map draws a scene of small triangles) at
 * 1024^2 and 2048^2, walking the scene and through vertex bins made beforehand (as
 * sm's pass is drawn where its arena has room), and the eye pass at 1024x768 (its
 * raster, then raster and visible samples), on random N = 1K..1M: ms and million
 * triangles a second, single thread. */
void bench_raster_sweep(void)
{
    static const unsigned counts[] = {1000, 10000, 100000, 1000000};
    const size_t big = (size_t)2048 * 2048;
    uint32_t *depth = malloc(big * 4), *id = malloc((size_t)1024 * 768 * 4);
    om_sample *smp = malloc((size_t)1024 * 768 * sizeof *smp);
    for (int k = 0; k < 4; k++) {
        bscene b;
        if (bench_load_random(&b, counts[k])) break;
        om_view v;
        om_diag d;
        if (om_view_init(&v, &b.s.camera, &b.s.light, &b.s, &d) != OM_OK) {
            fprintf(stderr, "bench: %s\n", d.msg);
            bench_free(&b);
            break;
        }
        const double n = (double)b.s.ntris;
        om__bins bins = {NULL, malloc(om__bins_verts_bytes(&b.s)), false};
        for (uint32_t size = 1024; size <= 2048; size *= 2) {
            om_target tg = {size, size, 0, size, depth, NULL};
            const double ms = time_pass(&b, &v.light_vp, v.origin, &tg, OM_RASTER_DEPTH, true);
            /* sm's light pass where its arena has room: vertex bins through the light,
             * then the pass through them */
            uint64_t tv[RUNS], tp[RUNS];
            for (int r = 0; r < RUNS; r++) {
                uint64_t t0 = om_clock_ns(NULL);
                om__bins_make(&b.s, &v.light_vp, v.origin, size, size, &bins);
                uint64_t t1 = om_clock_ns(NULL);
                om__scene_raster_hiz(&b.s, &v.light_vp, v.origin, &tg, OM_RASTER_DEPTH, true, &bins, NULL);
                tv[r] = t1 - t0;
                tp[r] = om_clock_ns(NULL) - t1;
            }
            const double vms = bench_median_ns(tv, RUNS), pms = bench_median_ns(tp, RUNS);
            printf("sweep %-12s light depth pass %ux%u: %8.2f ms, %7.2f M tris/s; through vertex bins %8.2f ms "
                   "(%7.2f M tris/s), the bins %8.2f ms\n",
                   b.name, size, size, ms, n / ms / 1e3, pms, n / pms / 1e3, vms);
        }
        free(bins.verts);
        om_target eye = {1024, 768, 0, 768, depth, id};
        om_strip st = {1024, 768, 0, 768, smp, NULL, v.origin};
        uint64_t t[RUNS];
        for (int r = 0; r < RUNS; r++) {
            uint64_t t0 = om_clock_ns(NULL);
            om__scene_raster(&b.s, &v.cam_vp, v.origin, &eye, OM_RASTER_DEPTH_ID, false, NULL);
            om__eye_pass(&b.s, &v, &eye, &st, NULL);
            t[r] = om_clock_ns(NULL) - t0;
        }
        const double ms = time_pass(&b, &v.cam_vp, v.origin, &eye, OM_RASTER_DEPTH_ID, false), all = bench_median_ns(t, RUNS);
        printf("sweep %-12s eye raster 1024x768:       %8.2f ms, %7.2f M tris/s; with samples %8.2f ms, %7.2f M tris/s\n",
               b.name, ms, n / ms / 1e3, all, n / all / 1e3);
        bench_free(&b);
    }
    free(depth);
    free(id);
    free(smp);
}
