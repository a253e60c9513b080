/* fuzz_api.c — libFuzzer target: the public API driven as a careless or hostile host
 * drives it, every argument from the input. A scene (the small one, or one built by
 * hand with indices, materials and vertices from the input, NaN and 1e30 among them),
 * a method and its settings set by name to values in and out of range, image sizes
 * from 0 past OM_MAX_DIM, arena sizes from nothing to one pass, strips, formats,
 * framebuffers too small, threads on an inline parallel-for, a state reused with
 * another method, scene or size, and NULLs. Every call must return a status, never
 * crash or write outside its arena: guard bytes around every arena are checked. */
#include "ombra.h"
#include "../frame_need.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "guard.h"

typedef struct reader { const uint8_t *p; size_t n; } reader;

static uint32_t take(reader *r, uint32_t bytes)
{
    uint32_t v = 0;
    for (uint32_t i = 0; i < bytes; i++) {
        v = v << 8 | (r->n ? *r->p : 0u);
        if (r->n) r->p++, r->n--;
    }
    return v;
}

static float take_float(reader *r)
{
    static const float odd[8] = {0.0f, -0.0f, 1e30f, -1e30f, 1e-30f, 3.0e38f, 0.5f, -2.0f};
    const uint32_t k = take(r, 1);
    if (k < 8) {   /* NaN, infinities and the extremes, now and then */
        if (k == 0) return (float)NAN;
        if (k == 1) return (float)INFINITY;
        return odd[k];
    }
    return ((float)take(r, 2) - 32768.0f) / 4096.0f;
}


/* A scene built by hand: up to 12 vertices and 8 triangles from the input, indices and
 * material indices that may point past their arrays. */
static om_vec3 hv[12];
static uint32_t hidx[24];
static uint16_t hmat[8];
static om_material hmats[2] = {{0.8f, 0.8f, 0.8f, 1.0f}, {0.2f, 0.9f, 0.3f, 0.5f}};

static void hand_scene(reader *r, om_scene *s)
{
    memset(s, 0, sizeof *s);
    s->nverts = take(r, 1) % 13;
    s->ntris = take(r, 1) % 9;
    s->nmats = 1 + take(r, 1) % 2;
    for (uint32_t v = 0; v < s->nverts; v++) hv[v] = (om_vec3){take_float(r), take_float(r), take_float(r)};
    for (uint32_t i = 0; i < 3 * s->ntris; i++) hidx[i] = take(r, 1) % 14;   /* 12, 13: past the end */
    for (uint32_t t = 0; t < s->ntris; t++) hmat[t] = (uint16_t)(take(r, 1) % 3);
    s->verts = hv;
    s->idx = hidx;
    s->tri_mat = hmat;
    s->mats = hmats;
    s->lo = (om_vec3){-4, -4, -4};
    s->hi = (om_vec3){4, 4, 4};
    s->camera = (om_camera){{0, 3, 6}, {0, 0, 0}, {0, 1, 0}, 50, 32, 24, 0.1f, 100};
    s->light.kind = take(r, 1) & 1 ? OM_LIGHT_DIRECTIONAL : OM_LIGHT_SPOT;
    s->light.pos = (om_vec3){2, 7, 1};
    s->light.target = (om_vec3){0, 0, 0};
    s->light.dir = (om_vec3){-0.3f, -1, -0.2f};
    s->light.fov_deg = 70;
    s->light.znear = 1;
    s->light.zfar = 40;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    static void *small_mem;
    static om_scene small;
    om_diag d;
    if (!small_mem) {   /* the small scene, parsed once */
        const char *t = om_scene_small_text();
        size_t bytes;
        om_arena a;
        if (om_scene_bytes(t, strlen(t), NULL, &bytes, &d) != OM_OK || !(small_mem = malloc(bytes))) abort();
        om_arena_init(&a, small_mem, bytes, "scene");
        if (om_scene_parse(t, strlen(t), NULL, &a, &small, &d) != OM_OK) abort();
    }
    om_scene hand;
    const om_scene *s = &small;
    if (take(&r, 1) & 1) {
        hand_scene(&r, &hand);
        s = &hand;
    }
    /* the method (an index past the list: NULL) and its settings by name */
    const uint32_t mk = take(&r, 1) % (uint32_t)(om_method_count() + 1);
    const om_method *m = om_method_at(mk);
    om_method_cfg cfg;
    om_method_cfg_default(&cfg, m);
    om_method_cfg_set(&cfg, "map", 64, NULL);
    for (uint32_t n = take(&r, 1) % 4; n > 0; n--) {
        const om_setting *f = om_method_setting_at(m, take(&r, 1) % (om_method_nsettings(m) + 1));
        const double v = take(&r, 1) & 1 ? (double)take_float(&r) : (double)take(&r, 3);
        if (f) om_method_cfg_set(&cfg, f->name, v, &d);
    }
    /* sizes: mostly small, now and then 0 or past OM_MAX_DIM */
    const uint32_t sz = take(&r, 1);
    uint32_t w = 1 + sz % 40, h = 1 + (sz >> 3) % 30;
    if (sz == 255) w = 0;
    if (sz == 254) h = OM_MAX_DIM + 1;
    size_t mn = 0, full = 0;
    om_status st = om_method_bytes(m, &cfg, s, w, h, &mn, &full);
    if (st == OM_OK && full > (16u << 20)) return 0;   /* a one-pass size the fuzzer need not allocate */
    const uint32_t share = take(&r, 1);   /* the method arena: from nothing to one pass */
    size_t give = st != OM_OK ? 4096 : share < 32 ? (size_t)share * 64 : share < 128 ? mn : share < 200 ? full
                                                                                                  : mn + (full - mn) / 2;
    unsigned char *mb = guarded_alloc(give);
    if (!mb) return 0;
    om_arena ma;
    om_arena_init(&ma, mb + GUARD, give, "method");
    void *state = NULL;
    st = om_method_init(m, take(&r, 1) == 0 ? NULL : &state, &ma, &cfg, s, w, h, &d);
    /* the view: the scene's own camera at w x h, or another size (state reuse) */
    om_camera cam;
    om_light light;
    om_view v;
    om_scene_at(s, 0.0f, &cam, &light);
    const uint32_t again = take(&r, 1);
    cam.width = again & 1 ? 1 + again % 48 : w;
    cam.height = again & 2 ? 1 + again % 36 : h;
    if (om_view_init(&v, &cam, &light, s, &d) == OM_OK) {
        const uint32_t rows = take(&r, 1) % (cam.height + 2);
        const uint32_t threads = take(&r, 1) % 6;
        om_frame_desc fd;
        om_frame_need need;
        om_shade_cfg shade;
        memset(&fd, 0, sizeof fd);
        om_shade_cfg_default(&shade);
        const uint32_t pick = take(&r, 1);
        fd.scene = pick == 1 ? NULL : pick == 2 && s != &small ? &small : s;
        fd.view = &v;
        fd.method = pick == 3 ? om_method_at((mk + 1) % om_method_count()) : m;
        fd.method_state = state;
        fd.shade = pick == 4 ? NULL : &shade;
        fd.strip_rows = rows;
        fd.threads = threads;
        fd.parallel_for = threads > 1 ? inline_for : NULL;
        if (om_frame_bytes(&fd, &need) == OM_OK && need.whole < (64u << 20)) {
            const uint32_t fpick = take(&r, 1);
            size_t fbytes = fpick < 64 ? need.least / 2 : fpick < 128 ? need.least : fpick < 192 ? need.with_bins
                                                                                               : need.whole;
            const uint32_t frows = rows && rows < cam.height ? rows : cam.height;
            const uint32_t fbw = fpick == 7 ? cam.width - 1 : cam.width, fbr = fpick == 8 ? frows - 1 : frows;
            const om_format fmt = (om_format)(take(&r, 1) % 4);   /* 3: outside om_format */
            const size_t px_bytes = (size_t)fbw * fbr * 3 + 1;
            unsigned char *fm = guarded_alloc(fbytes), *px = guarded_alloc(px_bytes);
            if (fm && px) {
                om_arena fa;
                om_arena_init(&fa, fm + GUARD, fbytes, "frame");
                om_framebuffer fb = {fmt, fbw, fbr, (size_t)fbw * (fmt == OM_RGB888 ? 3 : fmt == OM_L8 ? 1 : 2),
                                     px + GUARD};
                fd.fb = pick == 5 ? NULL : &fb;
                for (int frame = 0; frame < 2; frame++) om_render_frame(&fd, pick == 6 ? NULL : &fa, NULL, &d);
                om_method_stats ms;
                om_method_get_stats(fd.method, state, &ms);
                if (!guarded(fm, fbytes) || !guarded(px, px_bytes)) abort();
            }
            free(fm);
            free(px);
        }
    }
    if (!guarded(mb, give)) abort();
    free(mb);
    return 0;
}
