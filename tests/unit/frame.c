/* unit/frame.c — the eye pass, the lit rule's geometric half, shading and the frame
 * driver: exact visible points, strips identical to a whole frame, pixel formats,
 * budgets, and the method registry. Scenes are built by hand so this suite does not
 * depend on the parser. */
#include "../test.h"
#include "../harness.h"
#include "../../engine/shadow/method.h"

#include <math.h>
#include <stdlib.h>

/* A floor quad (20 x 20 at y = 0) and a unit box standing on it. */
static om_vec3 verts[12];
static uint32_t idx[3 * 14];
static uint16_t tmat[14];
static om_material mats[2] = {{0.8f, 0.8f, 0.8f, 1.0f}, {0.9f, 0.3f, 0.2f, 1.0f}};

static void make_scene(om_scene *s)
{
    memset(s, 0, sizeof *s);
    verts[0] = om__v3(-10, 0, -10); verts[1] = om__v3(10, 0, -10);
    verts[2] = om__v3(10, 0, 10);   verts[3] = om__v3(-10, 0, 10);
    for (int i = 0; i < 8; i++)
        verts[4 + i] = om__v3(i & 1 ? 0.5f : -0.5f, i & 2 ? 1.0f : 0.0f, i & 4 ? 0.5f : -0.5f);
    static const uint32_t box[36] = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                     2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    uint32_t floor_idx[6] = {0, 2, 1, 0, 3, 2};
    memcpy(idx, floor_idx, sizeof floor_idx);
    for (int i = 0; i < 36; i++) idx[6 + i] = box[i] + 4;
    for (int t = 0; t < 14; t++) tmat[t] = t < 2 ? 0 : 1;
    s->nverts = 12; s->ntris = 14; s->nmats = 2;
    s->verts = verts; s->idx = idx; s->tri_mat = tmat; s->mats = mats;
    s->lo = om__v3(-10, 0, -10); s->hi = om__v3(10, 1, 10);
    s->camera.eye = om__v3(0, 3, 6); s->camera.target = om__v3(0, 0.5f, 0);
    s->camera.up = om__v3(0, 1, 0); s->camera.fovy_deg = 50;
    s->camera.width = 80; s->camera.height = 60; s->camera.znear = 0.1f; s->camera.zfar = 100;
    s->light.kind = OM_LIGHT_SPOT;
    s->light.pos = om__v3(3, 8, 2); s->light.target = om__v3(0, 0, 0);
    s->light.fov_deg = 60; s->light.znear = 1; s->light.zfar = 50;
}

static unsigned char frame_mem[1 << 20], method_mem[4096];

typedef struct capture { unsigned char *pix; om_sample *smp; om_term *term; uint32_t bpp; } capture;

static om_status grab(void *user, const om_strip *st, const om_framebuffer *fb)
{
    capture *c = (capture *)user;
    for (uint32_t y = 0; y < st->rows; y++) {
        memcpy(c->pix + (size_t)(st->y0 + y) * st->width * c->bpp, fb->pixels + y * fb->stride,
               (size_t)st->width * c->bpp);
        memcpy(c->smp + (size_t)(st->y0 + y) * st->width, st->samples + (size_t)y * st->width,
               st->width * sizeof(om_sample));
        memcpy(c->term + (size_t)(st->y0 + y) * st->width, st->terms + (size_t)y * st->width,
               st->width * sizeof(om_term));
    }
    return OM_OK;
}

static size_t frame_size = sizeof frame_mem;   /* the frame arena render() gives */
static uint32_t frame_carves;                  /* and how many carves it saw */

static om_status render(const om_scene *s, const om_light *light, uint32_t strip, om_format f,
                        capture *cap)
{
    om_view v;
    om_diag d;
    if (om_view_init(&v, &s->camera, light, s, &d) != OM_OK) return d.status;
    const om_method *m = om_method_find("none");
    om_method_cfg cfg;
    om_method_cfg_default(&cfg, m);
    om_arena ma, fa;
    om_arena_init(&ma, method_mem, sizeof method_mem, "method");
    om_arena_init(&fa, frame_mem, frame_size, "frame");
    void *state;
    om_status st = om_method_init(m, &state, &ma, &cfg, s, v.cam.width, v.cam.height, &d);
    if (st) return st;
    static unsigned char strip_pix[80 * 60 * 3];
    om_framebuffer fb = {f, v.cam.width, strip ? strip : v.cam.height,
                         (size_t)v.cam.width * om_format_bpp(f), strip_pix};
    om_shade_cfg shade;
    om_frame_desc fd;
    h_frame_desc(&fd, &shade, s, &v, m, state, &fb, strip);
    fd.on_strip = grab; fd.user = cap;
    cap->bpp = om_format_bpp(f);
    st = om_render_frame(&fd, &fa, NULL, &d);
    frame_carves = fa.carves;
    return st;
}

static unsigned char pix_a[80 * 60 * 3], pix_b[80 * 60 * 3];
static om_sample smp_a[80 * 60], smp_b[80 * 60];
static om_term term_a[80 * 60], term_b[80 * 60];

/* Strips give the whole frame's pixels, samples and terms: with the bins (the arena has
 * room), with their rows alone, and without (exactly om_frame_bytes), from a camera high above the floor and
 * one at its edge, low enough that the floor's triangles cross the near plane. */
static void strips_equal_whole(void)
{
    om_scene s;
    make_scene(&s);
    for (int cam = 0; cam < 2; cam++) {
        if (cam) { s.camera.eye = om__v3(0.3f, 0.4f, 9.99f); s.camera.target = om__v3(0, 0.3f, 0); }
        for (int kind = 0; kind < 2; kind++) {
            om_light l = s.light;
            if (kind) { l.kind = OM_LIGHT_DIRECTIONAL; l.dir = om__v3(-0.3f, -1, -0.2f); }
            capture a = {pix_a, smp_a, term_a, 0}, b = {pix_b, smp_b, term_b, 0};
            frame_size = sizeof frame_mem;
            CHECK_OK(render(&s, &l, 0, OM_RGB888, &a));
            static const uint32_t strips[] = {1, 7, 13, 59};
            for (int k = 0; k < 12; k++) {
                /* all the bins, the rows alone (no room for the vertices), none */
                const int bins = 2 - k / 4;
                const uint32_t n = strips[k % 4];
                frame_size = bins == 2 ? h_frame_bins(&s, 80, n)
                           : bins == 1 ? h_frame_least(80, n) + om__bins_rows_bytes(&s) : h_frame_least(80, n);
                memset(pix_b, 0, sizeof pix_b);
                CHECK_OK(render(&s, &l, n, OM_RGB888, &b));
                CHECK_EQ_U(frame_carves, (uint32_t)(4 + bins));
                CHECK_MSG(!memcmp(pix_a, pix_b, sizeof pix_a), "camera %d light %d strip %u bins %d: pixels differ",
                          cam, kind, n, bins);
                CHECK(!memcmp(smp_a, smp_b, sizeof smp_a));
                CHECK(!memcmp(term_a, term_b, sizeof term_a));
            }
        }
    }
    frame_size = sizeof frame_mem;
}

/* Every visible point lies on its triangle's plane and on the ray through its pixel. */
static void exact_visible_points(void)
{
    om_scene s;
    make_scene(&s);
    capture a = {pix_a, smp_a, term_a, 0};
    CHECK_OK(render(&s, &s.light, 0, OM_RGB888, &a));
    om_view v;
    CHECK_OK(om_view_init(&v, &s.camera, &s.light, &s, NULL));
    int floor_px = 0, box_px = 0, bad = 0;
    for (uint32_t y = 0; y < 60; y++)
        for (uint32_t x = 0; x < 80; x++) {
            const om_sample *p = &smp_a[y * 80 + x];
            if (p->tri == OM_NO_TRI) continue;
            om_vec3 P = om__v3(p->p[0], p->p[1], p->p[2]);   /* relative to v.origin */
            const uint32_t *ix = s.idx + p->tri * 3;
            om_vec3 n = om__v3(p->n[0], p->n[1], p->n[2]);
            if (fabsf(om__dot(n, om__sub(P, om__sub(s.verts[ix[0]], v.origin)))) > 1e-4f) bad++;
            if (fabsf(om__dot(n, n) - 1.0f) > 1e-5f) bad++;
            /* project back: lands on the pixel centre */
            om_vec4 q = om__mat_apply(&v.cam_vp, P);
            double sx = (q.x / q.w + 1) * 40, sy = (1 - q.y / q.w) * 30;
            if (fabs(sx - (x + 0.5)) > 1e-3 || fabs(sy - (y + 0.5)) > 1e-3) bad++;
            if (p->tri < 2) floor_px++; else box_px++;
        }
    CHECK_EQ_U(bad, 0);
    CHECK(floor_px > 1000);
    CHECK(box_px > 100);
}

static void exposure_rule(void)
{
    om_scene s;
    make_scene(&s);
    /* A narrow spot light: samples outside its square frustum are not exposed. */
    om_light l = s.light;
    l.pos = om__v3(0, 10, 0);
    l.fov_deg = 10;
    capture a = {pix_a, smp_a, term_a, 0};
    CHECK_OK(render(&s, &l, 0, OM_RGB888, &a));
    int in = 0, out = 0, bad = 0;
    for (int i = 0; i < 80 * 60; i++) {
        if (smp_a[i].tri == OM_NO_TRI) { if (term_a[i].flags) bad++; continue; }
        /* the view's origin is the spot light's position */
        float x = smp_a[i].p[0] + l.pos.x, z = smp_a[i].p[2] + l.pos.z, y = smp_a[i].p[1] + l.pos.y;
        float half = (10 - y) * (float)om__tan(5 * OM_PI / 180);
        bool inside = fabsf(x) < half * 0.98f && fabsf(z) < half * 0.98f;
        bool outside = fabsf(x) > half * 1.02f || fabsf(z) > half * 1.02f;
        bool exposed = term_a[i].flags & OM_TERM_EXPOSED;
        /* the box's downward-facing sides and faces turned away are never exposed */
        if (smp_a[i].tri < 2) {
            if (inside) { in++; if (!exposed) bad++; }
            if (outside) { out++; if (exposed) bad++; }
        }
    }
    CHECK_EQ_U(bad, 0);
    CHECK(in > 10 && out > 1000);
}

static void pixel_formats(void)
{
    om_scene s;
    make_scene(&s);
    capture a = {pix_a, smp_a, term_a, 0}, b = {pix_b, smp_b, term_b, 0};
    CHECK_OK(render(&s, &s.light, 0, OM_RGB888, &a));
    CHECK_OK(render(&s, &s.light, 9, OM_RGB565, &b));
    int bad = 0;
    for (int i = 0; i < 80 * 60; i++) {
        unsigned w = pix_b[2 * i] | (pix_b[2 * i + 1] << 8);
        if ((w >> 11) != (unsigned)(pix_a[3 * i] >> 3) || ((w >> 5) & 63) != (unsigned)(pix_a[3 * i + 1] >> 2) ||
            (w & 31) != (unsigned)(pix_a[3 * i + 2] >> 3))
            bad++;
    }
    CHECK_EQ_U(bad, 0);
    CHECK_OK(render(&s, &s.light, 0, OM_L8, &b));
    bad = 0;
    for (int i = 0; i < 80 * 60; i++) {
        unsigned l = (77u * pix_a[3 * i] + 150u * pix_a[3 * i + 1] + 29u * pix_a[3 * i + 2] + 128u) >> 8;
        if (pix_b[i] != l) bad++;
    }
    CHECK_EQ_U(bad, 0);
    /* lit floor is brighter than ambient-only floor */
    CHECK(pix_a[3 * (59 * 80 + 40)] > 0);
}

static void frame_budget(void)
{
    om_scene s;
    make_scene(&s);
    om_view v;
    CHECK_OK(om_view_init(&v, &s.camera, &s.light, &s, NULL));
    const om_method *m = om_method_find("none");
    void *state;
    om_arena ma, fa;
    om_arena_init(&ma, method_mem, sizeof method_mem, "method");
    om_method_cfg cfg;
    om_method_cfg_default(&cfg, m);
    CHECK_OK(om_method_init(m, &state, &ma, &cfg, &s, 80, 60, NULL));
    static unsigned char pix[80 * 3 * 4];
    om_framebuffer fb = {OM_RGB888, 80, 4, 240, pix};
    om_shade_cfg shade;
    om_frame_desc fd;
    h_frame_desc(&fd, &shade, &s, &v, m, state, &fb, 4);
    size_t need = h_frame_least(80, 4);
    /* The query covers any alignment of the host's buffer; the four arrays' padding is
     * at most 4 * 7 bytes, so 29 bytes fewer can never be enough. Guard bytes around
     * the arena must survive a failing and a succeeding frame. */
    unsigned char *buf = malloc(need + 96);
    om_diag d;
    for (int off = 32; off < 40; off++) {
        memset(buf, 0x5A, need + 96);
        om_arena_init(&fa, buf + off, need - 29, "frame");
        CHECK(om_render_frame(&fd, &fa, NULL, &d) == OM_E_BUDGET);
        CHECK(strstr(d.msg, "frame arena") != NULL);
        om_arena_init(&fa, buf + off, need, "frame");
        CHECK_OK(om_render_frame(&fd, &fa, NULL, &d));
        CHECK_EQ_U(fa.used, 0);
        CHECK(fa.peak <= need);
        int guard = 0;
        for (int i = 0; i < 32; i++) guard += buf[off - 32 + i] != 0x5A || buf[off + need + i] != 0x5A;
        CHECK_EQ_U(guard, 0);
    }
    free(buf);
    /* a framebuffer narrower than the image is refused */
    fb.width = 79;
    om_arena_init(&fa, frame_mem, sizeof frame_mem, "frame");
    CHECK(om_render_frame(&fd, &fa, NULL, NULL) == OM_E_INVALID);
}

static void bad_views(void)
{
    om_scene s;
    make_scene(&s);
    om_view v;
    om_diag d;
    om_camera c = s.camera;
    c.fovy_deg = 0;
    CHECK(om_view_init(&v, &c, &s.light, &s, &d) == OM_E_INVALID);
    CHECK(strstr(d.msg, "fov") != NULL);
    c = s.camera;
    c.width = 0;
    CHECK(om_view_init(&v, &c, &s.light, &s, &d) == OM_E_INVALID);
    c = s.camera;
    c.eye.x = NAN;
    CHECK(om_view_init(&v, &c, &s.light, &s, &d) == OM_E_RANGE);
    c = s.camera;
    c.target = c.eye;
    CHECK(om_view_init(&v, &c, &s.light, &s, &d) == OM_E_INVALID);
    om_light l = s.light;
    l.kind = OM_LIGHT_DIRECTIONAL;
    l.dir = om__v3(0, 0, 0);
    CHECK(om_view_init(&v, &s.camera, &l, &s, &d) == OM_E_INVALID);
    /* looking straight down with up = y still works */
    c = s.camera;
    c.eye = om__v3(0, 10, 0);
    c.target = om__v3(0, 0, 0);
    CHECK_OK(om_view_init(&v, &c, &s.light, &s, &d));
}

static void registry(void)
{
    CHECK(om_method_count() >= 1);
    CHECK(om_method_find("none") == om_method_at(0));
    CHECK(om_method_find("nope") == NULL);
    CHECK(om_method_find(NULL) == NULL);
    for (size_t i = 0; i < om_method_count(); i++) {
        const om_method *m = om_method_at(i);
        CHECK(om_method_name(m) && om_method_summary(m) && m->bytes && m->init && m->begin && m->observe &&
              m->build && m->resolve && m->stats);
    }
}

void suite_frame(void)
{
    RUN(strips_equal_whole);
    RUN(exact_visible_points);
    RUN(exposure_rule);
    RUN(pixel_formats);
    RUN(frame_budget);
    RUN(bad_views);
    RUN(registry);
}
