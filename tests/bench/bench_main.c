/* bench_main.c — the benchmark driver and the helpers of bench.h. */
#include "bench.h"
#include "../frame_need.h"

#include <string.h>

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

double bench_median_ns(uint64_t *t, int n)
{
    qsort(t, (size_t)n, sizeof *t, cmp_u64);
    return (double)t[n / 2] / 1e6;
}

double bench_median(double *v, int n)
{
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && v[j - 1] > v[j]; j--) { double t = v[j]; v[j] = v[j - 1]; v[j - 1] = t; }
    return v[n / 2];
}

int bench_load(bscene *b, const char *name, const char *text)
{
    om_diag d;
    size_t bytes;
    memset(b, 0, sizeof *b);
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

void bench_free(bscene *b)
{
    free(b->mem);
    b->mem = NULL;
}

int bench_load_random(bscene *b, unsigned count)
{
    static char names[4][32];
    static char text[512];
    int slot = count >= 1000000 ? 3 : count >= 100000 ? 2 : count >= 10000 ? 1 : 0;
    snprintf(names[slot], sizeof names[slot], "random-%uK", count / 1000);
    snprintf(text, sizeof text,
             "camera eye 0 6 14 target 0 1 0 fov 50 size 1024 768 near 0.1 far 100\n"
             "light spot pos 8 20 6 target 0 0 0 fov 60 near 5 far 60\n"
             "plane size 14 14 albedo 0.7 0.7 0.7\n"
             "triangles count %u seed 7 area 20 in -5 0.5 -5 5 3 5\n", count);
    return bench_load(b, names[slot], text);
}

void bench_default_and_clouds(void (*fn)(const bscene *b))
{
    bscene b;
    if (bench_load(&b, "default", om_scene_default_text())) return;
    fn(&b);
    bench_free(&b);
    static const unsigned counts[] = {10000, 100000};
    for (int k = 0; k < 2; k++) {
        if (bench_load_random(&b, counts[k])) return;
        fn(&b);
        bench_free(&b);
    }
}

typedef struct mask_sink { uint8_t *mask; } mask_sink;

static om_status grab_mask(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)fb;
    uint8_t *m = ((mask_sink *)user)->mask;
    if (!m) return OM_OK;
    for (uint32_t i = 0; i < st->rows * st->width; i++)
        m[(size_t)st->y0 * st->width + i] = om_mask_of(&st->samples[i], &st->terms[i]);
    return OM_OK;
}

int bench_view(const bscene *b, uint32_t W, uint32_t H, float t, om_view *v)
{
    om_camera cam;
    om_light light;
    om_diag d;
    om_scene_at(&b->s, t, &cam, &light);
    cam.width = W;
    cam.height = H;
    return om_view_init(v, &cam, &light, &b->s, &d) != OM_OK;
}

size_t bench_frame_bytes(const om_method *m, const om_scene *s, uint32_t W, uint32_t H, uint32_t threads)
{
    return frame_need_of(m, s, W, H, 0, threads).with_jobs;
}

int bench_setup(bsetup *t, const bscene *b, const char *name, uint32_t W, uint32_t H, uint32_t threads)
{
    memset(t, 0, sizeof *t);
    t->m = om_method_find(name);
    om_method_cfg c;
    om_diag d;
    size_t mn, full;
    if (!t->m) return 1;
    om_method_cfg_default(&c, t->m);
    if (bench_view(b, W, H, 0, &t->v) || om_method_bytes(t->m, &c, &b->s, W, H, &mn, &full)) return 1;
    t->fbytes = bench_frame_bytes(t->m, &b->s, W, H, threads);
    t->mem = malloc(full);
    t->fmem = malloc(t->fbytes);
    uint8_t *px = malloc((size_t)W * H * 3);
    t->fb = (om_framebuffer){OM_RGB888, W, H, (size_t)W * 3, px};
    om_shade_cfg_default(&t->shade);
    om_arena ma;
    if (!t->mem || !t->fmem || !px) goto fail;
    memset(t->fmem, 0, t->fbytes);
    om_arena_init(&ma, t->mem, full, "method");
    if (om_method_init(t->m, &t->state, &ma, &c, &b->s, W, H, &d) == OM_OK) return 0;
    fprintf(stderr, "bench: %s %s: %s\n", b->name, name, d.msg);
fail:
    bench_teardown(t);
    return 1;
}

void bench_teardown(bsetup *t)
{
    free(t->mem);
    free(t->fmem);
    free(t->fb.pixels);
    t->mem = t->fmem = NULL;
    t->fb.pixels = NULL;
}

void bench_frame_desc(bsetup *t, const bscene *b, om_frame_desc *fd, om_arena *fa)
{
    om_arena_init(fa, t->fmem, t->fbytes, "frame");
    memset(fd, 0, sizeof *fd);
    fd->scene = &b->s; fd->view = &t->v; fd->method = t->m; fd->method_state = t->state;
    fd->shade = &t->shade; fd->fb = &t->fb; fd->clock = om_clock_ns;
}

int bench_run(const bscene *b, const char *name, const om_method_cfg *cfg, uint32_t W,
              uint32_t H, float t, uint8_t *mask, mrun *out)
{
    return bench_run_hooked(b, name, cfg, W, H, t, mask, out, NULL);
}

int bench_run_hooked(const bscene *b, const char *name, const om_method_cfg *cfg, uint32_t W,
                     uint32_t H, float t, uint8_t *mask, mrun *out,
                     void (*hook)(void *state, mrun *out))
{
    const om_method *m = om_method_find(name);
    om_method_cfg c;
    om_method_cfg_from(&c, m, cfg);   /* the settings m shares with cfg's method */
    om_view v;
    om_diag d;
    size_t mn, full;
    memset(out, 0, sizeof *out);
    if (!m || bench_view(b, W, H, t, &v) || om_method_bytes(m, &c, &b->s, W, H, &mn, &full)) {
        fprintf(stderr, "bench: cannot set up %s\n", name);
        return 1;
    }
    void *mem = malloc(full), *fmem = malloc(bench_frame_bytes(NULL, NULL, W, H, 1)), *px = malloc((size_t)W * H * 3);
    /* A host that renders frame after frame has its arenas resident: touch every page
     * now, so that the first-touch faults of a fresh malloc (hundreds of ms for a large
     * map) are not charged to the method that happens to write them first. */
    if (mem) memset(mem, 0, full);
    if (fmem) memset(fmem, 0, bench_frame_bytes(NULL, NULL, W, H, 1));
    om_arena ma, fa;
    om_arena_init(&ma, mem, full, "method");
    om_arena_init(&fa, fmem, bench_frame_bytes(NULL, NULL, W, H, 1), "frame");
    void *state;
    uint64_t t0 = om_clock_ns(NULL);
    om_status st = om_method_init(m, &state, &ma, &c, &b->s, W, H, &d);
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
        out->eye_ms = (double)fs.ns_eye / 1e6;
        out->observe_ms = (double)fs.ns_observe / 1e6;
        out->build_ms = (double)fs.ns_build / 1e6;
        out->resolve_ms = (double)fs.ns_resolve / 1e6;
        out->shade_ms = (double)fs.ns_shade / 1e6;
        om_method_get_stats(m, state, &out->stats);
        if (st == OM_OK && hook) hook(state, out);
    }
    if (st) fprintf(stderr, "bench: %s: %s\n", name, d.msg);
    free(mem);
    free(fmem);
    free(px);
    return st != OM_OK;
}

#ifndef OM_BENCH_NO_MAIN
int main(int argc, char **argv)
{
    const char *filter = argc > 1 ? argv[1] : NULL;
    printf("ombra bench: medians of several runs, one core (threads: two)\n");
#define X(name) if (!filter || strstr(#name, filter)) { name(); fflush(stdout); }
    OM_BENCHES
#undef X
    return 0;
}
#endif
