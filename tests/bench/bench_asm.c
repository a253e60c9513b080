/* bench_asm.c — Adaptive Shadow Maps against the conventional map of the same memory
 * (issue 5), on the default scene at 1024x768:
 *  - along the walkthrough (30 frames, t = 0..4), one state kept across frames: median
 *    time per frame (whole frame and the method's own stages), bytes in use and the
 *    mismatch share against the reference, for ASM at 8 and 16 MiB and sm at 2048
 *    (16 MiB). Twice: with the scene's drifting light (every frame a rebuild) and with
 *    the light held at its t = 0 place (the paper's walkthrough: a fixed light);
 *  - close-ups of thin and small shadows, a still view refined for 8 frames: mismatches
 *    against sm 2048 and the effective resolution reached;
 *  - bench_asm_big: one frame on the 100K and 1M random clouds against sm 2048. */
#include "bench.h"

#include <string.h>

typedef struct brun {
    const om_method *m;
    void *mem, *state;
} brun;

static int brun_init(brun *r, const bscene *b, const char *name, const om_method_cfg *c,
                     uint32_t W, uint32_t H)
{
    size_t mn, full;
    om_diag d;
    om_arena a;
    memset(r, 0, sizeof *r);
    r->m = om_method_find(name);
    om_method_cfg mc;
    om_method_cfg_from(&mc, r->m, c);   /* asm's cfg gives sm its bias */
    if (!r->m || om_method_bytes(r->m, &mc, &b->s, W, H, &mn, &full)) return 1;
    r->mem = malloc(full);
    om_arena_init(&a, r->mem, full, "method");
    if (om_method_init(r->m, &r->state, &a, &mc, &b->s, W, H, &d)) {
        fprintf(stderr, "bench: %s: %s\n", name, d.msg);
        return 1;
    }
    return 0;
}

typedef struct bgrab { uint8_t *mask; } bgrab;

static om_status bgrab_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)fb;
    uint8_t *m = ((bgrab *)user)->mask;
    for (uint32_t i = 0; i < st->rows * st->width; i++)
        m[(size_t)st->y0 * st->width + i] = om_mask_of(&st->samples[i], &st->terms[i]);
    return OM_OK;
}

/* One frame of a kept state; fills mask, the frame's stage times and the method's stats. */
static int bframe(brun *r, const bscene *b, const om_camera *cam, const om_light *light,
                  uint8_t *mask, om_frame_stats *fs, om_method_stats *ms)
{
    static void *fmem, *px;
    const uint32_t W = cam->width, H = cam->height;
    if (!fmem) {
        fmem = malloc(bench_frame_bytes(NULL, NULL, 1024, 768, 1));
        px = malloc((size_t)1024 * 768 * 3);
    }
    om_view v;
    om_diag d;
    if (om_view_init(&v, cam, light, &b->s, &d)) return 1;
    om_arena fa;
    om_arena_init(&fa, fmem, bench_frame_bytes(NULL, NULL, W, H, 1), "frame");
    om_framebuffer fb = {OM_RGB888, W, H, (size_t)W * 3, (uint8_t *)px};
    om_shade_cfg shade;
    om_shade_cfg_default(&shade);
    bgrab g = {mask};
    om_frame_desc fd;
    memset(&fd, 0, sizeof fd);
    fd.scene = &b->s; fd.view = &v; fd.method = r->m; fd.method_state = r->state; fd.shade = &shade;
    fd.fb = &fb; fd.on_strip = bgrab_strip; fd.user = &g; fd.clock = om_clock_ns;
    if (om_render_frame(&fd, &fa, fs, &d)) {
        fprintf(stderr, "bench: %s: %s\n", om_method_name(r->m), d.msg);
        return 1;
    }
    om_method_get_stats(r->m, r->state, ms);
    return 0;
}

static uint32_t counter(const om_method_stats *ms, const char *name)
{
    for (uint32_t k = 0; k < ms->ncounters; k++)
        if (!strcmp(ms->counter_names[k], name)) return ms->counters[k];
    return 0;
}

#define NRUN 3   /* asm 8 MiB, asm 16 MiB, sm 2048 */
#define FRAMES 30

static void walkthrough(const bscene *b, bool held)
{
    const uint32_t W = 1024, H = 768;
    static const char *label[NRUN] = {"asm  8 MiB", "asm 16 MiB", "sm 2048   "};
    brun ref, run[NRUN];
    om_method_cfg c[NRUN];
    for (int k = 0; k < NRUN; k++) om_method_cfg_default(&c[k], om_method_find(k < 2 ? "asm" : "sm"));
    om_method_cfg_set(&c[0], "asm.cap", 8u << 20, NULL);
    om_method_cfg_set(&c[1], "asm.cap", 16u << 20, NULL);
    om_method_cfg_set(&c[2], "map", 2048, NULL);
    if (brun_init(&ref, b, "ref", &c[2], W, H)) return;
    for (int k = 0; k < NRUN; k++)
        if (brun_init(&run[k], b, k < 2 ? "asm" : "sm", &c[k], W, H)) return;
    uint8_t *mref = malloc((size_t)W * H), *m = malloc((size_t)W * H);
    double frame_ms[NRUN][FRAMES], meth_ms[NRUN][FRAMES], obs[NRUN][FRAMES], bld[NRUN][FRAMES],
        res[NRUN][FRAMES];
    uint64_t bad[NRUN] = {0}, samples = 0, most[NRUN] = {0};
    uint32_t eff[NRUN] = {0};
    om_light light0;
    om_camera cam;
    om_scene_at(&b->s, 0.0f, &cam, &light0);
    for (int f = 0; f < FRAMES; f++) {
        float t = 4.0f * (float)f / (FRAMES - 1);
        om_light light;
        om_scene_at(&b->s, t, &cam, &light);
        if (held) light = light0;
        cam.width = W;
        cam.height = H;
        om_frame_stats fs;
        om_method_stats ms;
        if (bframe(&ref, b, &cam, &light, mref, &fs, &ms)) return;
        for (int k = 0; k < NRUN; k++) {
            if (bframe(&run[k], b, &cam, &light, m, &fs, &ms)) return;
            obs[k][f] = (double)fs.ns_observe / 1e6;
            bld[k][f] = (double)fs.ns_build / 1e6;
            res[k][f] = (double)fs.ns_resolve / 1e6;
            meth_ms[k][f] = obs[k][f] + bld[k][f] + res[k][f];
            frame_ms[k][f] = (double)(fs.ns_eye + fs.ns_observe + fs.ns_build + fs.ns_resolve + fs.ns_shade) / 1e6;
            om_metrics mt;
            om_compare_masks(mref, m, W, H, &mt);
            bad[k] += mt.false_lit + mt.false_shadowed;
            if (k == 0) samples += mt.samples;
            uint64_t inuse = k < 2 ? counter(&ms, "bytes in use") : (uint64_t)2048 * 2048 * 4;
            if (inuse > most[k]) most[k] = inuse;
            if (k < 2 && counter(&ms, "effective resolution") > eff[k]) eff[k] = counter(&ms, "effective resolution");
        }
    }
    printf("walkthrough, %s, %d frames at %ux%u (medians per frame):\n",
           held ? "light held still (the paper's setup)" : "the scene's drifting light (asm rebuilds every frame)",
           FRAMES, W, H);
    double sm_ms = bench_median(meth_ms[2], FRAMES);
    for (int k = 0; k < NRUN; k++) {
        double mm = bench_median(meth_ms[k], FRAMES);
        printf("  %s: frame %7.2f ms, method %7.2f ms (observe %6.2f, build %6.2f, resolve %6.2f) = %.2fx sm;"
               " memory %5.2f MiB; mismatches %.4f%%",
               label[k], bench_median(frame_ms[k], FRAMES), mm, bench_median(obs[k], FRAMES),
               bench_median(bld[k], FRAMES), bench_median(res[k], FRAMES), mm / sm_ms,
               (double)most[k] / 1048576.0, 100.0 * (double)bad[k] / (double)(samples ? samples : 1));
        if (k < 2) printf("; finest %u", eff[k]);
        printf("\n");
    }
    free(mref);
    free(m);
    free(ref.mem);
    for (int k = 0; k < NRUN; k++) free(run[k].mem);
}

/* Still close-ups at t = 0's light: asm refined for 8 frames against sm 2048. */
static void closeups(const bscene *b)
{
    const uint32_t W = 1024, H = 768;
    static const struct { const char *name; om_vec3 eye, target; } views[] = {
        {"small cubes", {-0.2f, 0.9f, 4.8f}, {-0.6f, 0.1f, 3.0f}},
        {"fence shadow", {-3.6f, 1.3f, 3.6f}, {-5.4f, 0.0f, 1.6f}},
        {"sphere edge", {0.8f, 1.4f, 2.6f}, {-1.2f, 0.0f, 0.4f}},
    };
    uint8_t *mref = malloc((size_t)W * H), *m = malloc((size_t)W * H);
    printf("close-ups, %ux%u, asm after 8 frames of a still view:\n", W, H);
    for (size_t v = 0; v < sizeof views / sizeof views[0]; v++) {
        om_camera cam;
        om_light light;
        om_scene_at(&b->s, 0.0f, &cam, &light);
        cam.eye = views[v].eye;
        cam.target = views[v].target;
        cam.width = W;
        cam.height = H;
        om_method_cfg c;
        om_method_cfg_default(&c, om_method_find("asm"));
        brun ref, a8, a16, sm;
        om_method_cfg_set(&c, "asm.cap", 8u << 20, NULL);
        if (brun_init(&ref, b, "ref", &c, W, H) || brun_init(&a8, b, "asm", &c, W, H)) return;
        om_method_cfg_set(&c, "asm.cap", 16u << 20, NULL);
        if (brun_init(&a16, b, "asm", &c, W, H) || brun_init(&sm, b, "sm", &c, W, H)) return;
        om_frame_stats fs;
        om_method_stats ms;
        om_metrics mt;
        if (bframe(&ref, b, &cam, &light, mref, &fs, &ms) || bframe(&sm, b, &cam, &light, m, &fs, &ms)) return;
        om_compare_masks(mref, m, W, H, &mt);
        uint64_t smbad = mt.false_lit + mt.false_shadowed;
        printf("  %-12s sm 2048 %6llu mismatches (%.4f%%)", views[v].name, (unsigned long long)smbad,
               100.0 * (1.0 - om_metrics_match(&mt)));
        brun *as[2] = {&a8, &a16};
        for (int k = 0; k < 2; k++) {
            for (int f = 0; f < 8; f++)
                if (bframe(as[k], b, &cam, &light, m, &fs, &ms)) return;
            om_compare_masks(mref, m, W, H, &mt);
            uint64_t abad = mt.false_lit + mt.false_shadowed;
            printf("; asm %2d MiB %5llu (%.1fx fewer, finest %u, %u nodes)", k ? 16 : 8,
                   (unsigned long long)abad, abad ? (double)smbad / (double)abad : 0.0,
                   counter(&ms, "effective resolution"), counter(&ms, "nodes"));
        }
        printf("\n");
        free(ref.mem);
        free(a8.mem);
        free(a16.mem);
        free(sm.mem);
    }
    free(mref);
    free(m);
}

/* Big scenes: one frame of asm (16 MiB, from an empty tree: observe, build and
 * resolve) against sm 2048's build and lookup, at 1024x768, medians of 3 rounds. */
void bench_asm_big(void)
{
    static const unsigned counts[] = {100000, 1000000};
    printf("random clouds, 1024x768, one frame from an empty tree (medians of 3):\n");
    for (int k = 0; k < 2; k++) {
        bscene b;
        if (bench_load_random(&b, counts[k])) return;
        double a[3], o[3], sm[3], af[3], sf[3];
        for (int r = 0; r < 3; r++) {
            om_method_cfg c, cs;
            om_method_cfg_default(&c, om_method_find("asm"));
            om_method_cfg_set(&c, "asm.cap", 16u << 20, NULL);
            om_method_cfg_default(&cs, om_method_find("sm"));
            om_method_cfg_set(&cs, "map", 2048, NULL);
            mrun ra, rs;
            if (bench_run(&b, "asm", &c, 1024, 768, 0, NULL, &ra) || bench_run(&b, "sm", &cs, 1024, 768, 0, NULL, &rs))
                return;
            a[r] = ra.observe_ms + ra.build_ms + ra.resolve_ms;
            o[r] = ra.observe_ms;
            sm[r] = rs.build_ms + rs.resolve_ms;
            af[r] = ra.eye_ms + a[r] + ra.shade_ms;
            sf[r] = rs.eye_ms + sm[r] + rs.shade_ms;
        }
        double am = bench_median(a, 3), smm = bench_median(sm, 3);
        double afm = bench_median(af, 3), sfm = bench_median(sf, 3);
        printf("  %-12s asm 16 MiB %8.2f ms (observe %8.2f) = %.2fx sm 2048's %7.2f; frames %8.2f and %7.2f ms: "
               "%.2fx\n", b.name, am, bench_median(o, 3), am / smm, smm, afm, sfm, afm / sfm);
        bench_free(&b);
    }
}

void bench_asm(void)
{
    bscene b;
    if (bench_load(&b, "default", om_scene_default_text())) return;
    walkthrough(&b, false);
    fflush(stdout);
    walkthrough(&b, true);
    fflush(stdout);
    closeups(&b);
    bench_free(&b);
}
