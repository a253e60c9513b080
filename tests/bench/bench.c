/* bench.c — `make bench`: prints figures, asserts nothing. Each figure is the median
 * of several runs on one core; the ratios worth quoting are the ones printed in the
 * same run, since these machines are shared and noisy.
 *
 *   eye pass at 1024x768 (rasterize depth + id, resolve visible samples)
 *   depth-only light pass at 1024x1024 and 2048x2048
 * for the default scene and for 100K random small triangles above a floor; then, at
 * 1024x768 for the default scene and 1K/10K/100K random triangles of constant total
 * area: the reference's BVH build and shadow-test time, and the shadow map's build
 * and lookup time and mismatch share against the reference at 1024, 2048 and 4096. */
#include "../../engine/frame/frame.h"
#include "../../platform/platform.h"

#include <stdio.h>
#include <stdlib.h>

#define RUNS 7

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static double median_ms(uint64_t *t, int n)
{
    qsort(t, (size_t)n, sizeof *t, cmp_u64);
    return (double)t[n / 2] / 1e6;
}

typedef struct bscene { const char *name; char *text; void *mem; om_scene s; } bscene;

static int load(bscene *b, const char *name, const char *text)
{
    om_diag d;
    size_t bytes;
    b->name = name;
    if (om_scene_bytes(text, strlen(text), NULL, &bytes, &d) != OM_OK) {
        fprintf(stderr, "bench: %s: %s\n", name, d.msg);
        return 1;
    }
    b->mem = malloc(bytes);
    om_arena a;
    om_arena_init(&a, b->mem, bytes, "scene");
    if (om_scene_parse(text, strlen(text), NULL, &a, &b->s, &d) != OM_OK) {
        fprintf(stderr, "bench: %s: %s\n", name, d.msg);
        return 1;
    }
    return 0;
}

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
    om_strip st = {W, H, 0, H, smp, NULL};
    uint64_t raster[RUNS], total[RUNS];
    size_t covered = 0;
    for (int r = 0; r < RUNS; r++) {
        uint64_t t0 = om_clock_ns(NULL);
        om__scene_raster(&b->s, &v.cam_vp, &tg, OM_RASTER_DEPTH_ID);
        uint64_t t1 = om_clock_ns(NULL);
        om__eye_pass(&b->s, &v, &tg, &st);
        uint64_t t2 = om_clock_ns(NULL);
        raster[r] = t1 - t0;
        total[r] = t2 - t1;
    }
    for (size_t i = 0; i < n; i++) covered += smp[i].tri != OM_NO_TRI;
    printf("%-12s eye pass %ux%u: %8.2f ms (raster alone %.2f ms), %u tris, %.0f%% covered\n",
           b->name, W, H, median_ms(total, RUNS), median_ms(raster, RUNS), b->s.ntris,
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
    uint64_t t[RUNS];
    for (int r = 0; r < RUNS; r++) {
        uint64_t t0 = om_clock_ns(NULL);
        om__scene_raster(&b->s, &v.light_vp, &tg, OM_RASTER_DEPTH);
        t[r] = om_clock_ns(NULL) - t0;
    }
    size_t written = 0;
    for (size_t i = 0; i < n; i++) written += tg.depth[i] != 0xFFFFFFFFu;
    printf("%-12s light depth pass %ux%u: %8.2f ms, %.0f%% of texels written\n", b->name, size,
           size, median_ms(t, RUNS), 100.0 * (double)written / (double)n);
    free(tg.depth);
}

/* One method over one frame: init (timed: the reference builds its BVH there), then
 * the frame with per-stage times; the whole-frame mask goes to `mask`. */
typedef struct mrun { double init_ms, build_ms, resolve_ms; uint32_t exposed; } mrun;

typedef struct mask_sink { uint8_t *mask; } mask_sink;
static om_status grab_mask(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)fb;
    uint8_t *m = ((mask_sink *)user)->mask;
    for (uint32_t i = 0; i < st->rows * st->width; i++)
        m[(size_t)st->y0 * st->width + i] = om_mask_of(&st->samples[i], &st->terms[i]);
    return OM_OK;
}

static int run_method(const bscene *b, const char *name, uint32_t map, uint32_t W, uint32_t H,
                      uint8_t *mask, mrun *out)
{
    const om_method *m = om_method_find(name);
    om_method_cfg cfg;
    om_method_cfg_default(&cfg);
    if (map) cfg.map_size = map;
    om_camera cam = b->s.camera;
    cam.width = W;
    cam.height = H;
    om_view v;
    om_diag d;
    size_t mn, full;
    if (om_view_init(&v, &cam, &b->s.light, &b->s, &d) || m->bytes(&cfg, &b->s, W, H, &mn, &full)) return 1;
    void *mem = malloc(full), *fmem = malloc(om_frame_bytes(W, H)), *px = malloc((size_t)W * H * 3);
    om_arena ma, fa;
    om_arena_init(&ma, mem, full, "method");
    om_arena_init(&fa, fmem, om_frame_bytes(W, H), "frame");
    void *state;
    uint64_t t0 = om_clock_ns(NULL);
    om_status st = m->init(&state, &ma, &cfg, &b->s, W, H, &d);
    out->init_ms = (double)(om_clock_ns(NULL) - t0) / 1e6;
    if (st == OM_OK) {
        om_framebuffer fb = {OM_RGB888, W, H, (size_t)W * 3, (uint8_t *)px};
        om_shade_cfg shade;
        om_shade_cfg_default(&shade);
        mask_sink ms = {mask};
        om_frame_desc fd;
        memset(&fd, 0, sizeof fd);
        fd.scene = &b->s; fd.view = &v; fd.method = m; fd.method_state = state; fd.shade = &shade;
        fd.fb = &fb; fd.on_strip = grab_mask; fd.user = &ms; fd.clock = om_clock_ns;
        om_frame_stats fs;
        st = om_render_frame(&fd, &fa, &fs, &d);
        out->build_ms = (double)fs.ns_build / 1e6;
        out->resolve_ms = (double)fs.ns_resolve / 1e6;
        om_method_stats mst;
        m->stats(state, &mst);
        out->exposed = mst.counters[0];
    }
    if (st) fprintf(stderr, "bench: %s: %s\n", name, d.msg);
    free(mem);
    free(fmem);
    free(px);
    return st != OM_OK;
}

static double median_d(double *v, int n)
{
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && v[j - 1] > v[j]; j--) { double t = v[j]; v[j] = v[j - 1]; v[j - 1] = t; }
    return v[n / 2];
}

static void bench_shadows(const bscene *b)
{
    const uint32_t W = 1024, H = 768;
    uint8_t *ref = malloc((size_t)W * H), *sm = malloc((size_t)W * H);
    double bi[3], sh[3];
    mrun r;
    for (int k = 0; k < 3; k++) {
        if (run_method(b, "ref", 0, W, H, ref, &r)) return;
        bi[k] = r.init_ms;
        sh[k] = r.resolve_ms;
    }
    double s = median_d(sh, 3);
    printf("%-12s ref  %ux%u: BVH build %7.2f ms, shadow tests %8.2f ms, %.2f M samples/s (%u samples)\n",
           b->name, W, H, median_d(bi, 3), s, (double)r.exposed / (s * 1e3), r.exposed);
    for (uint32_t size = 1024; size <= 4096; size *= 2) {
        double bu[3], lo[3];
        for (int k = 0; k < 3; k++) {
            if (run_method(b, "sm", size, W, H, sm, &r)) return;
            bu[k] = r.build_ms;
            lo[k] = r.resolve_ms;
        }
        om_metrics mt;
        om_compare_masks(ref, sm, W, H, &mt);
        printf("%-12s sm %4u: build %7.2f ms, lookup %6.2f ms, mismatches %.4f%% (false lit %llu, false shadowed %llu)\n",
               b->name, size, median_d(bu, 3), median_d(lo, 3), 100.0 * (1.0 - om_metrics_match(&mt)),
               (unsigned long long)mt.false_lit, (unsigned long long)mt.false_shadowed);
    }
    free(ref);
    free(sm);
}

static const char random_scene[] =
    "# 100K random small triangles above a floor (benchmark scene)\n"
    "camera eye 0 6 14 target 0 1 0 fov 50 size 1024 768 near 0.1 far 100\n"
    "light spot pos 8 20 6 target 0 0 0 fov 60 near 5 far 60\n"
    "plane size 14 14 albedo 0.7 0.7 0.7\n"
    "triangles count 100000 seed 7 area 20 in -5 0.5 -5 5 3 5\n";

int main(void)
{
    bscene def, rnd;
    if (load(&def, "default", om_scene_default_text()) || load(&rnd, "random-100K", random_scene))
        return 1;
    printf("ombra bench: medians of %d runs, one core\n", RUNS);
    bench_eye(&def, 1024, 768);
    bench_eye(&rnd, 1024, 768);
    bench_light(&def, 1024);
    bench_light(&def, 2048);
    bench_light(&rnd, 1024);
    bench_light(&rnd, 2048);
    bench_shadows(&def);
    free(def.mem);
    free(rnd.mem);
    /* Table 1 of the Alias-Free Shadow Maps paper: constant total area. */
    static const unsigned counts[] = {1000, 10000, 100000};
    for (int k = 0; k < 3; k++) {
        char text[512], name[32];
        snprintf(text, sizeof text,
                 "camera eye 0 6 14 target 0 1 0 fov 50 size 1024 768 near 0.1 far 100\n"
                 "light spot pos 8 20 6 target 0 0 0 fov 60 near 5 far 60\n"
                 "plane size 14 14 albedo 0.7 0.7 0.7\n"
                 "triangles count %u seed 7 area 20 in -5 0.5 -5 5 3 5\n", counts[k]);
        snprintf(name, sizeof name, "random-%uK", counts[k] / 1000);
        bscene b;
        if (load(&b, name, text)) return 1;
        bench_shadows(&b);
        free(b.mem);
    }
    return 0;
}
