/* harness.c — see harness.h. */
#include "harness.h"
#include "frame_need.h"
#include "test.h"

#include <stdlib.h>
#include <string.h>

bool h_scene_parse(h_scene *hs, const char *text) { return h_scene_parse_ld(hs, text, NULL); }

const char h_cloud_bar[] = "camera eye 0 6 14 target 0 1 0 fov 50 near 0.1 far 100\n"
                           "light spot pos 8 20 6 target 0 0 0 fov 60 near 5 far 60\n"
                           "plane size 14 14 albedo 0.7 0.7 0.7\n"
                           "box size 0.3 0.05 14 rotate 0 45 0 translate 0 3.8 0\n"
                           "triangles count 2000 seed 7 area 20 in -5 0.5 -5 5 3 5\n";

char *h_town_text(void)
{
    const size_t len = om_scene_town_text(NULL, 0);
    char *text = malloc(len + 1);
    CHECK_MSG(text != NULL, "the town's %zu bytes", len + 1);
    if (text) om_scene_town_text(text, len + 1);
    return text;
}

bool h_scene_parse_ld(h_scene *hs, const char *text, const om_loader *ld)
{
    om_diag d;
    size_t bytes;
    memset(hs, 0, sizeof *hs);
    if (om_scene_bytes(text, strlen(text), ld, &bytes, &d) != OM_OK) {
        CHECK_MSG(0, "scene bytes: %s", d.msg);
        return false;
    }
    hs->mem = malloc(bytes ? bytes : 1);
    om_arena a;
    om_arena_init(&a, hs->mem, bytes, "scene");
    if (om_scene_parse(text, strlen(text), ld, &a, &hs->s, &d) != OM_OK) {
        CHECK_MSG(0, "scene parse: %s", d.msg);
        return false;
    }
    return true;
}

void h_scene_free(h_scene *hs)
{
    free(hs->mem);
    hs->mem = NULL;
}

static om_vec3 v3_scaled(om_vec3 v, float k)
{
    om_vec3 r = {v.x * k, v.y * k, v.z * k};
    return r;
}

void h_scene_scale(om_scene *s, float k)
{
    for (uint32_t i = 0; i < s->nverts; i++) s->verts[i] = v3_scaled(s->verts[i], k);
    s->lo = v3_scaled(s->lo, k);
    s->hi = v3_scaled(s->hi, k);
    for (uint32_t i = 0; i < s->nsolids; i++) {
        s->solids[i].lo = v3_scaled(s->solids[i].lo, k);
        s->solids[i].hi = v3_scaled(s->solids[i].hi, k);
    }
    om_camera *c = &s->camera;
    c->eye = v3_scaled(c->eye, k);
    c->target = v3_scaled(c->target, k);
    c->znear *= k;
    c->zfar *= k;
    om_light *l = &s->light;
    l->pos = v3_scaled(l->pos, k);   /* a directional light's dir keeps its direction */
    l->target = v3_scaled(l->target, k);
    l->znear *= k;
    l->zfar *= k;
    for (uint32_t i = 0; i < s->ncam_keys; i++) {
        s->cam_keys[i].eye = v3_scaled(s->cam_keys[i].eye, k);
        s->cam_keys[i].target = v3_scaled(s->cam_keys[i].target, k);
    }
    for (uint32_t i = 0; i < s->nlight_keys; i++) {
        s->light_keys[i].pos = v3_scaled(s->light_keys[i].pos, k);
        s->light_keys[i].target = v3_scaled(s->light_keys[i].target, k);
    }
}

uint64_t h_scaled_mismatches(const char *text, float k, const char *name, const om_method_cfg *cfg,
                             uint32_t w, uint32_t h)
{
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return UINT64_MAX;
    h_scene_scale(&hs.s, k);
    uint8_t *ref = malloc((size_t)w * h), *got = malloc((size_t)w * h);
    uint64_t bad = UINT64_MAX;
    if (ref && got && h_render(&hs.s, "ref", NULL, w, h, 0, 0, ref, NULL, NULL) == OM_OK &&
        h_render(&hs.s, name, cfg, w, h, 0, 0, got, NULL, NULL) == OM_OK) {
        om_metrics m;
        om_compare_masks(ref, got, w, h, &m);
        bad = m.false_lit + m.false_shadowed;
    }
    free(ref);
    free(got);
    h_scene_free(&hs);
    return bad;
}

void h_check_scale_free(const char *name, uint32_t w, uint32_t h)
{
    const char *text = om_scene_default_text();
    const uint64_t at1 = h_scaled_mismatches(text, 1.0f, name, NULL, w, h);
    CHECK_MSG(at1 != UINT64_MAX, "%s: the scene at x1 did not render", name);
    static const float scales[] = {0.001f, 1000.0f};
    for (int i = 0; i < 2; i++) {
        const uint64_t got = h_scaled_mismatches(text, scales[i], name, NULL, w, h);
        CHECK_MSG(got != UINT64_MAX && got * 10 <= at1 * 11 && got * 10 >= at1 * 9,
                  "%s: %llu samples disagree with ref at x%g, %llu at x1", name, (unsigned long long)got,
                  (double)scales[i], (unsigned long long)at1);
    }
}

om_status h_view(om_view *v, const om_scene *s, float t, uint32_t w, uint32_t h, om_diag *d)
{
    om_camera cam;
    om_light light;
    om_scene_at(s, t, &cam, &light);
    if (w) { cam.width = w; cam.height = h; }
    return om_view_init(v, &cam, &light, s, d);
}

om_vec3 h_origin(const om_scene *s, float t)
{
    om_view v;
    if (h_view(&v, s, t, 0, 0, NULL) != OM_OK) { const om_vec3 zero = {0, 0, 0}; return zero; }
    return v.origin;
}

void h_frame_desc(om_frame_desc *fd, om_shade_cfg *shade, const om_scene *s, const om_view *v,
                  const om_method *m, void *state, om_framebuffer *fb, uint32_t strip_rows)
{
    om_shade_cfg_default(shade);
    memset(fd, 0, sizeof *fd);
    fd->scene = s; fd->view = v; fd->method = m; fd->method_state = state; fd->shade = shade;
    fd->strip_rows = strip_rows; fd->fb = fb;
}

typedef struct grab { uint8_t *mask; om_term *terms; om_sample *samples; } grab;

static om_status on_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    grab *g = (grab *)user;
    (void)fb;
    for (uint32_t y = 0; y < st->rows; y++)
        for (uint32_t x = 0; x < st->width; x++) {
            size_t i = (size_t)y * st->width + x, o = (size_t)(st->y0 + y) * st->width + x;
            if (g->mask) g->mask[o] = om_mask_of(&st->samples[i], &st->terms[i]);
            if (g->terms) g->terms[o] = st->terms[i];
            if (g->samples) g->samples[o] = st->samples[i];
        }
    return OM_OK;
}

om_method_cfg h_cfg(const char *method, const char *list)
{
    const om_method *m = om_method_find(method);
    om_method_cfg c;
    om_method_cfg_default(&c, m);
    CHECK_MSG(m != NULL, "h_cfg: no method %s", method);
    for (const char *p = list; p && *p;) {
        char name[64];
        double v;
        int used = 0;
        if (sscanf(p, " %63[^= ]=%lf%n", name, &v, &used) != 2) {
            CHECK_MSG(0, "h_cfg: '%s' is not NAME=VALUE ...", p);
            break;
        }
        p += used;
        while (*p == ' ') p++;
        if (!om_method_setting(m, name)) continue;
        om_diag d;
        CHECK_MSG(om_method_cfg_set(&c, name, v, &d) == OM_OK, "h_cfg %s %s: %s", method, name, d.msg);
    }
    return c;
}

om_status h_render(const om_scene *s, const char *name, const om_method_cfg *cfg, uint32_t w,
                   uint32_t h, float t, uint32_t strip_rows, uint8_t *mask, om_term *terms,
                   om_sample *samples)
{
    return h_render_in(s, name, cfg, w, h, t, strip_rows, 0, mask, terms, samples);
}

om_status h_render_in(const om_scene *s, const char *name, const om_method_cfg *cfg, uint32_t w,
                      uint32_t h, float t, uint32_t strip_rows, size_t method_bytes, uint8_t *mask,
                      om_term *terms, om_sample *samples)
{
    om_view v;
    om_diag d;
    om_status st = h_view(&v, s, t, w, h, &d);
    if (st) return st;
    const om_method *m = om_method_find(name);
    if (!m) return OM_E_NOTFOUND;
    om_method_cfg c;
    om_method_cfg_from(&c, m, cfg);
    size_t mn, full;
    const uint32_t W = v.cam.width, H = v.cam.height;
    if ((st = om_method_bytes(m, &c, s, W, H, &mn, &full))) return st;
    if (method_bytes) full = method_bytes;
    uint32_t rows = strip_rows ? strip_rows : H;
    size_t fbytes = h_frame_bins(s, W, rows);
    void *mm = malloc(full), *fm = malloc(fbytes), *px = malloc((size_t)W * rows * 3);
    om_arena ma, fa;
    om_arena_init(&ma, mm, full, "method");
    om_arena_init(&fa, fm, fbytes, "frame");
    void *state;
    st = om_method_init(m, &state, &ma, &c, s, W, H, &d);
    if (st == OM_OK) {
        om_framebuffer fb = {OM_RGB888, W, rows, (size_t)W * 3, (uint8_t *)px};
        om_shade_cfg shade;
        om_frame_desc fd;
        grab g = {mask, terms, samples};
        h_frame_desc(&fd, &shade, s, &v, m, state, &fb, strip_rows);
        fd.on_strip = on_strip; fd.user = &g;
        st = om_render_frame(&fd, &fa, NULL, &d);
    }
    if (st) fprintf(stderr, "  (h_render %s: %s)\n", name, d.msg);
    free(mm);
    free(fm);
    free(px);
    return st;
}

om_frame_need h_frame_need(const om_method *m, const om_scene *s, uint32_t width, uint32_t height, uint32_t rows,
                           uint32_t threads)
{
    return frame_need_of(m, s, width, height, rows, threads);
}

size_t h_frame_least(uint32_t width, uint32_t rows) { return h_frame_need(NULL, NULL, width, rows, rows, 1).least; }

size_t h_frame_bins(const om_scene *s, uint32_t width, uint32_t rows)
{
    return h_frame_need(NULL, s, width, rows, rows, 1).with_bins;
}

size_t h_frame_jobs(const om_method *m, const om_scene *s, uint32_t threads)
{
    const om_frame_need n = h_frame_need(m, s, 1, 1, 0, threads);
    return n.with_jobs - n.with_bins;
}

size_t h_frame_ids(const om_scene *s, uint32_t width, uint32_t height)
{
    const om_frame_need n = h_frame_need(NULL, s, width, height, 1, 1);
    return n.with_ids - n.with_jobs;
}
