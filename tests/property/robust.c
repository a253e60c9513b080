/* property/robust.c — nothing crashes, nothing is lost: every arena carve of every
 * method fails once in turn and the next frame still renders correctly; pathological
 * geometry (NaN, infinities, 1e30, zero-area and needle triangles, coincident vertices)
 * and views (empty scene, camera inside a mesh, everything behind the near plane, images
 * of 0x0, 1x1 and 8192x8192) give a status and a message or a correct frame. */
#include "../test.h"
#include "../../engine/testing.h"
#include "../harness.h"

#include <math.h>
#include <stdlib.h>

#define W 48
#define H 36

static const char *small_scene =
    "camera eye 0 3 6 target 0 0.5 0 size 48 36\n"
    "light spot pos 2 7 1 target 0 0 0 fov 70 near 1 far 40\n"
    "plane size 10 10\n"
    "box size 1 1 1 translate 0 0.5 0\n"
    "sphere radius 0.4 segments 12 rings 6 translate 1.2 0.6 0.5 opacity 0.5 albedo 0.2 0.5 0.9\n"
    "triangles count 30 seed 4 area 1 in -2 1 -2 2 2 2\n";

/* Small maps and structures, for whichever method takes them (h_cfg). */
#define SMALL "map=128 asm.cap=1048576 rtw.importance=64"

typedef struct frame_ctx {
    const om_scene *s;
    om_view v;
    const om_method *m;
    om_method_cfg cfg;
    uint8_t mask[W * H];
} frame_ctx;

static om_status grab(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)fb;
    uint8_t *mask = (uint8_t *)user;
    for (uint32_t i = 0; i < st->rows * st->width; i++)
        mask[st->y0 * st->width + i] = om_mask_of(&st->samples[i], &st->terms[i]);
    return OM_OK;
}

static om_status frame(frame_ctx *f, void *state, om_arena *fa, uint8_t *mask)
{
    static uint8_t px[W * H * 3];
    om_shade_cfg shade;
    om_framebuffer fb = {OM_RGB888, W, 9, W * 3, px};
    om_frame_desc fd;
    h_frame_desc(&fd, &shade, f->s, &f->v, f->m, state, &fb, 9);
    fd.on_strip = grab; fd.user = mask;
    return om_render_frame(&fd, fa, NULL, NULL);
}

/* For every method: count the carves of init + two frames, then make each of them fail
 * once in turn. The failing call returns OM_E_BUDGET; the frame after it (the carve
 * counter has moved past the failure) renders the very mask of an undisturbed run. */
static void failure_injection(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, small_scene)) return;
    frame_ctx f;
    f.s = &hs.s;
    CHECK_OK(h_view(&f.v, &hs.s, 0, 0, 0, NULL));
    static unsigned char fmem[W * 9 * 52];   /* 44 bytes a pixel, and room for the bins */
    for (size_t k = 0; k < om_method_count(); k++) {
        f.m = om_method_at(k);
        f.cfg = h_cfg(om_method_name(f.m), SMALL);
        size_t mn, full;
        CHECK_OK(om_method_bytes(f.m, &f.cfg, &hs.s, W, H, &mn, &full));
        unsigned char *mem = malloc(full);
        om_arena ma, fa;
        void *state;
        static uint8_t good[W * H], got[W * H];
        /* undisturbed: two frames (progressive methods may change between them) */
        om_arena_init(&ma, mem, full, "method");
        om_arena_init(&fa, fmem, sizeof fmem, "frame");
        CHECK_OK(om_method_init(f.m, &state, &ma, &f.cfg, &hs.s, W, H, NULL));
        CHECK_OK(frame(&f, state, &fa, good));
        uint32_t method_carves = ma.carves, frame_carves = fa.carves;
        CHECK_OK(frame(&f, state, &fa, good));
        method_carves = ma.carves;
        /* the frame: depth, ids, samples, terms, and the bins its strips use, rows and
         * vertices (carves that may fail: the strips then walk every triangle, or clip
         * every vertex, for the same pixels) */
        CHECK_MSG(method_carves >= 1 && frame_carves == 6, "%s: %u method and %u frame carves",
                  om_method_name(f.m), method_carves, frame_carves);
        int bad = 0;
        for (uint32_t n = 1; n <= method_carves + frame_carves; n++) {
            om_arena_init(&ma, mem, full, "method");
            om_arena_init(&fa, fmem, sizeof fmem, "frame");
            if (n <= method_carves) om__test_fail_carve(&ma, n);
            else om__test_fail_carve(&fa, n - method_carves);
            om_status st = om_method_init(f.m, &state, &ma, &f.cfg, &hs.s, W, H, NULL);
            if (st != OM_OK) {
                if (st != OM_E_BUDGET) bad++;
                /* init failed: a fresh init with the carve counter past the failure */
                om_arena_init(&ma, mem, full, "method");
                CHECK_OK(om_method_init(f.m, &state, &ma, &f.cfg, &hs.s, W, H, NULL));
            }
            st = frame(&f, state, &fa, got);
            if (st != OM_OK && st != OM_E_BUDGET) bad++;
            if (frame(&f, state, &fa, got) != OM_OK || memcmp(got, good, sizeof got) != 0) bad++;
        }
        CHECK_MSG(bad == 0, "%s: %d injected failures went wrong (of %u carves)", om_method_name(f.m), bad,
                  method_carves + frame_carves);
        free(mem);
    }
    /* the scene parser: every carve failing once gives OM_E_BUDGET, never a crash */
    size_t bytes;
    CHECK_OK(om_scene_bytes(small_scene, strlen(small_scene), NULL, &bytes, NULL));
    unsigned char *smem = malloc(bytes);
    for (uint32_t n = 1; n <= 8; n++) {
        om_arena a;
        om_scene s;
        om_arena_init(&a, smem, bytes, "scene");
        om__test_fail_carve(&a, n);
        om_status st = om_scene_parse(small_scene, strlen(small_scene), NULL, &a, &s, NULL);
        CHECK(st == OM_OK || st == OM_E_BUDGET);
    }
    free(smem);
    h_scene_free(&hs);
}

/* A scene built by hand, so values the parser would refuse reach the engine. */
static om_vec3 verts[32];
static uint32_t idx[3 * 16];
static uint16_t tmat[16];
static om_material mats[1] = {{0.8f, 0.8f, 0.8f, 1.0f}};

static void hand_scene(om_scene *s, uint32_t ntris)
{
    memset(s, 0, sizeof *s);
    s->verts = verts; s->idx = idx; s->tri_mat = tmat; s->mats = mats;
    s->nverts = 32; s->ntris = ntris; s->nmats = 1;
    s->lo = (om_vec3){-10, 0, -10};
    s->hi = (om_vec3){10, 3, 10};
    s->camera = (om_camera){{0, 3, 6}, {0, 0.5f, 0}, {0, 1, 0}, 50, W, H, 0.1f, 100};
    s->light.kind = OM_LIGHT_SPOT;
    s->light.pos = (om_vec3){2, 7, 1};
    s->light.target = (om_vec3){0, 0, 0};
    s->light.fov_deg = 70;
    s->light.znear = 1;
    s->light.zfar = 40;
    /* a floor (triangles 0, 1) and then whatever the case puts in triangles 2.. */
    verts[0] = (om_vec3){-5, 0, -5}; verts[1] = (om_vec3){5, 0, -5};
    verts[2] = (om_vec3){5, 0, 5}; verts[3] = (om_vec3){-5, 0, 5};
    uint32_t fl[6] = {0, 2, 1, 0, 3, 2};
    memcpy(idx, fl, sizeof fl);
    for (int t = 2; t < 16; t++) { idx[3 * t] = 4 + 3 * (uint32_t)(t - 2) % 27; idx[3 * t + 1] = idx[3 * t] + 1; idx[3 * t + 2] = idx[3 * t] + 2; }
}

static void every_method_survives(const om_scene *s, const char *what)
{
    static uint8_t mask[W * H];
    for (size_t k = 0; k < om_method_count(); k++) {
        om_method_cfg c = h_cfg(om_method_name(om_method_at(k)), SMALL);
        om_status st = h_render(s, om_method_name(om_method_at(k)), &c, W, H, 0, 7, mask, NULL, NULL);
        CHECK_MSG(st == OM_OK, "%s: %s gave %s", what, om_method_name(om_method_at(k)), om_status_str(st));
    }
}

static void pathological_geometry(void)
{
    om_scene s;
    float nan = NAN, inf = INFINITY;
    struct { const char *what; om_vec3 a, b, c; } cases[] = {
        {"NaN vertex", {0, 1, 0}, {nan, 1, 0}, {0, 1, 1}},
        {"infinite vertex", {0, 1, 0}, {inf, 1, 0}, {0, 1, -inf}},
        {"1e30 coordinates", {-1e30f, 1, -1e30f}, {1e30f, 1, -1e30f}, {0, 1, 1e30f}},
        {"zero-area triangle", {0, 1, 0}, {1, 1, 0}, {2, 1, 0}},
        {"needle triangle", {-3, 1, 0}, {3, 1, 0}, {3, 1, 1e-6f}},
        {"coincident vertices", {0.5f, 1, 0.5f}, {0.5f, 1, 0.5f}, {0.5f, 1, 0.5f}},
        {"huge triangle", {-1e7f, 1.5f, -1e7f}, {1e7f, 1.5f, -1e7f}, {0, 1.5f, 1e7f}},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        hand_scene(&s, 3);
        verts[4] = cases[k].a;
        verts[5] = cases[k].b;
        verts[6] = cases[k].c;
        every_method_survives(&s, cases[k].what);
    }
    /* the parser refuses what it cannot represent, with line and column */
    om_diag d;
    size_t bytes;
    CHECK(om_scene_bytes("box translate 1e30 0 0\n", 23, NULL, &bytes, &d) != OM_OK);
    CHECK(d.line == 1 && d.col > 0);
    CHECK(om_scene_bytes("box translate nan 0 0\n", 22, NULL, &bytes, &d) == OM_E_PARSE);
}

static void pathological_views(void)
{
    om_scene s;
    hand_scene(&s, 0);
    every_method_survives(&s, "empty scene");
    /* camera inside a closed box */
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 0.5 0 target 1 0.5 0 size 48 36\n"
                            "light spot pos 2 7 1 target 0 0 0 fov 70 near 1 far 40\n"
                            "plane size 10 10\nbox size 2 2 2 translate 0 1 0\n"))
        return;
    every_method_survives(&hs.s, "camera inside a box");
    h_scene_free(&hs);
    /* everything behind the near plane: all background */
    if (!h_scene_parse(&hs, "camera eye 0 2 -20 target 0 2 -40 size 48 36\n"
                            "light spot pos 2 7 1 target 0 0 0 fov 70 near 1 far 40\n"
                            "plane size 10 10\nbox size 1 1 1\n"))
        return;
    every_method_survives(&hs.s, "scene behind the camera");
    static uint8_t mask[W * H];
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, mask, NULL, NULL));
    int fg = 0;
    for (int i = 0; i < W * H; i++) fg += mask[i] != OM_MASK_BG;
    CHECK_EQ_U(fg, 0);
    h_scene_free(&hs);
    /* image sizes */
    hand_scene(&s, 2);
    om_view v;
    om_diag d;
    om_camera cam = s.camera;
    cam.width = cam.height = 0;
    CHECK(om_view_init(&v, &cam, &s.light, &s, &d) == OM_E_INVALID);
    CHECK(strstr(d.msg, "8192") != NULL);
    cam.width = cam.height = 8193;
    CHECK(om_view_init(&v, &cam, &s.light, &s, &d) == OM_E_INVALID);
    for (size_t k = 0; k < om_method_count(); k++) {
        om_method_cfg c = h_cfg(om_method_name(om_method_at(k)), SMALL);
        CHECK_OK(h_render(&s, om_method_name(om_method_at(k)), &c, 1, 1, 0, 0, mask, NULL, NULL));
    }
}

/* The largest image, through strips, with the cheapest methods (the others follow the
 * same frame code; their memory at this size is the stress runs' subject). */
/* A host's misuse gets a status, never a crash: every method's bytes and init with a
 * side of 0 or past OM_MAX_DIM, and a frame without its method state, without a frame
 * arena, with a format outside om_format, or with a state made for another method,
 * scene or image size. */
static void hostile_calls(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, "box size 1 1 1\nplane size 4 4\n")) return;
    static unsigned char mem[1 << 16];
    size_t mn, full;
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        om_method_cfg c;
        om_arena a;
        void *state = (void *)&a;
        om_diag d;
        om_method_cfg_default(&c, m);
        om_arena_init(&a, mem, sizeof mem, "method");
        const uint32_t sides[4][2] = {{0, 120}, {160, 0}, {OM_MAX_DIM + 1, 8}, {8, OM_MAX_DIM + 1}};
        for (int i = 0; i < 4; i++) {
            CHECK_MSG(om_method_bytes(m, &c, &hs.s, sides[i][0], sides[i][1], &mn, &full) == OM_E_INVALID,
                      "%s bytes at %ux%u", om_method_name(m), sides[i][0], sides[i][1]);
            CHECK_MSG(om_method_init(m, &state, &a, &c, &hs.s, sides[i][0], sides[i][1], &d) == OM_E_INVALID &&
                          state == NULL && a.used == 0,
                      "%s init at %ux%u", om_method_name(m), sides[i][0], sides[i][1]);
        }
        CHECK(om_method_bytes(m, NULL, &hs.s, 16, 16, &mn, &full) == OM_E_INVALID);
        CHECK(om_method_init(NULL, &state, &a, &c, &hs.s, 16, 16, &d) == OM_E_INVALID);
    }
    CHECK(om_method_bytes(NULL, NULL, NULL, 16, 16, &mn, &full) == OM_E_INVALID);
    /* a scene built by hand whose arrays do not hold what it says: refused by init */
    {
        om_scene bad;
        const om_method *m = om_method_find("ref");
        om_method_cfg c;
        om_arena a;
        void *state;
        om_diag d;
        om_method_cfg_default(&c, m);
        hand_scene(&bad, 3);
        idx[7] = 32;   /* past its 32 vertices */
        om_arena_init(&a, mem, sizeof mem, "method");
        CHECK(om_method_init(m, &state, &a, &c, &bad, 16, 12, &d) == OM_E_INVALID && state == NULL &&
              strstr(d.msg, "triangle 2 names a vertex"));
        hand_scene(&bad, 3);
        tmat[1] = 1;   /* past its one material */
        CHECK(om_method_init(m, &state, &a, &c, &bad, 16, 12, &d) == OM_E_INVALID && strstr(d.msg, "material"));
        tmat[1] = 0;
        hand_scene(&bad, 3);
        bad.idx = NULL;
        CHECK(om_method_init(m, &state, &a, &c, &bad, 16, 12, &d) == OM_E_INVALID && strstr(d.msg, "missing"));
        hand_scene(&bad, 3);
        CHECK_OK(om_method_init(m, &state, &a, &c, &bad, 16, 12, &d));
    }
    om_view v;
    om_frame_desc fd;
    om_shade_cfg shade;
    uint8_t px[16 * 8 * 3];
    om_framebuffer fb = {OM_RGB888, 16, 8, 16 * 3, px};
    static unsigned char fmem[1 << 18];
    om_arena fa;
    om_diag d;
    CHECK_OK(h_view(&v, &hs.s, 0.0f, 16, 8, NULL));
    h_frame_desc(&fd, &shade, &hs.s, &v, om_method_find("sm"), NULL, &fb, 0);
    om_arena_init(&fa, fmem, sizeof fmem, "frame");
    CHECK(om_render_frame(&fd, &fa, NULL, &d) == OM_E_INVALID && strstr(d.msg, "state"));
    const om_method *sm = om_method_find("sm");
    om_method_cfg c;
    om_arena sa;
    void *st;
    om_method_cfg_default(&c, sm);
    CHECK_OK(om_method_cfg_set(&c, "map", 64, NULL));
    om_arena_init(&sa, mem, sizeof mem, "method");
    CHECK_OK(om_method_init(sm, &st, &sa, &c, &hs.s, 16, 8, &d));
    fd.method_state = st;
    CHECK(om_render_frame(&fd, NULL, NULL, &d) == OM_E_INVALID);
    fb.format = (om_format)9;
    CHECK(om_render_frame(&fd, &fa, NULL, &d) == OM_E_INVALID && strstr(d.msg, "format"));
    fb.format = OM_RGB888;
    CHECK_OK(om_render_frame(&fd, &fa, NULL, &d));
    /* a state read only by the method, scene and image size it was made for */
    fd.method = om_method_find("izb");
    CHECK(om_render_frame(&fd, &fa, NULL, &d) == OM_E_INVALID && strstr(d.msg, "another method"));
    fd.method = sm;
    h_scene other;
    if (h_scene_parse(&other, "box size 1 1 1\nplane size 4 4\n")) {
        fd.scene = &other.s;
        CHECK(om_render_frame(&fd, &fa, NULL, &d) == OM_E_INVALID && strstr(d.msg, "another method, scene"));
        fd.scene = &hs.s;
        h_scene_free(&other);
    }
    om_view v2;
    CHECK_OK(h_view(&v2, &hs.s, 0.0f, 8, 8, NULL));
    om_framebuffer fb2 = {OM_RGB888, 8, 8, 8 * 3, px};
    fd.view = &v2;
    fd.fb = &fb2;
    CHECK(om_render_frame(&fd, &fa, NULL, &d) == OM_E_INVALID && strstr(d.msg, "image size"));
    om_frame_need need;
    v2.cam.width = OM_MAX_DIM + 1;   /* a view a host filled by hand, past what the engine takes */
    CHECK(om_frame_bytes(&fd, &need) == OM_E_INVALID);
    CHECK(om_render_frame(&fd, &fa, NULL, &d) == OM_E_INVALID && strstr(d.msg, "1..8192"));
    om_method_stats ms;
    om_method_get_stats(om_method_find("izb"), st, &ms);   /* another method's state: zeros */
    CHECK(ms.ncounters == 0 && ms.bytes_used == 0);
    CHECK(fa.used == 0);
    h_scene_free(&hs);
}

/* Every method's bytes query at the largest image and each setting at its largest
 * never wraps (make test-32 runs it where size_t has 32 bits): izb's pool of 1e9
 * samples asks for at least 16 bytes a sample, or SIZE_MAX; min <= full; and an arena
 * short of min is refused. */
static void largest_settings(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, "box size 1 1 1\nplane size 4 4\n")) return;
    static unsigned char mem[1 << 16];
    uint32_t queried = 0, refused = 0;
    bool izb_pool = false;
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        for (uint32_t i = 0; i < om_method_nsettings(m); i++) {
            const om_setting *f = om_method_setting_at(m, i);
            om_method_cfg c;
            size_t mn, full;
            om_arena a;
            void *state;
            om_method_cfg_default(&c, m);
            CHECK_OK(om_method_cfg_set(&c, f->name, f->max, NULL));
            if (om_method_bytes(m, &c, &hs.s, OM_MAX_DIM, OM_MAX_DIM, &mn, &full) != OM_OK) continue;
            queried++;
            CHECK_MSG(mn <= full, "%s %s=%g: min %zu > full %zu", om_method_name(m), f->name, f->max, mn, full);
            if (!strcmp(f->name, "izb.pool") && !strcmp(om_method_name(m), "izb")) {
                izb_pool = true;
                CHECK_MSG(mn == SIZE_MAX || (double)mn >= 16e9, "izb pool 1e9 asks %zu bytes", mn);
            }
            om_arena_init(&a, mem, sizeof mem, "method");
            if (mn > sizeof mem && ++refused)
                CHECK_MSG(om_method_init(m, &state, &a, &c, &hs.s, OM_MAX_DIM, OM_MAX_DIM, NULL) == OM_E_BUDGET,
                          "%s %s=%g: init in 64 KiB of %zu", om_method_name(m), f->name, f->max, mn);
        }
    }
    /* the loop asked something: every method's settings, most too large for 64 KiB */
    CHECK_MSG(queried >= 20 && refused >= 10 && izb_pool, "%u queries, %u refused, izb.pool %s", queried, refused,
              izb_pool ? "seen" : "not seen");
    h_scene_free(&hs);
}

/* Every public function handed NULL where its declaration does not allow one: a
 * status or a neutral value, never a dereference (ombra.h's conventions). */
static void null_arguments(void)
{
    om_diag d;
    size_t z = 7;
    void *p = &z;
    uint8_t m8[4] = {0};
    double v;
    om_arena_init(NULL, NULL, 0, NULL);
    CHECK(om_arena_alloc(NULL, 8, 8, &p, &d) == OM_E_INVALID && p == NULL);
    CHECK(om_arena_sub(NULL, 8, "x", NULL, &d) == OM_E_INVALID);
    CHECK(om_arena_mark(NULL) == 0 && om_arena_left(NULL) == 0);
    om_arena_rewind(NULL, 0);
    CHECK(om_pool_init(NULL, NULL, 8, 8, &d) == OM_E_INVALID);
    CHECK(om_pool_get(NULL) == NULL && om_pool_item(NULL, 0) == NULL);
    om_pool_put(NULL, m8);
    CHECK(om_scene_bytes(NULL, 5, NULL, &z, &d) == OM_E_INVALID);
    CHECK(om_scene_parse(NULL, 5, NULL, NULL, NULL, &d) == OM_E_INVALID);
    CHECK(om_view_init(NULL, NULL, NULL, NULL, &d) == OM_E_INVALID);
    om_view_fit_light(NULL, NULL, (om_vec3){0, 0, 0}, (om_vec3){1, 1, 1});
    om_method_cfg_default(NULL, NULL);
    CHECK(om_method_cfg_set(NULL, "map", 1, &d) == OM_E_INVALID);
    CHECK(om_method_cfg_get(NULL, "map", &v) == OM_E_INVALID);
    om_method_cfg_from(NULL, NULL, NULL);
    om_shade_cfg_default(NULL);
    CHECK(om_frame_bytes(NULL, NULL) == OM_E_INVALID);
    CHECK(om_render_frame(NULL, NULL, NULL, &d) == OM_E_INVALID);
    CHECK(om_method_name(NULL)[0] == 0 && om_method_summary(NULL)[0] == 0 && om_method_flags(NULL) == 0);
    CHECK(om_method_nsettings(NULL) == 0 && om_method_setting_at(NULL, 0) == NULL);
    CHECK(om_method_setting(NULL, NULL) == NULL && om_method_find(NULL) == NULL);
    om_compare_masks(NULL, NULL, 4, 4, NULL);
    om_compare_masks(m8, m8, 0, 0, NULL);
    om_metrics mt;
    om_compare_masks(NULL, m8, 2, 2, &mt);
    CHECK(mt.samples == 0 && om_metrics_match(NULL) == 1.0);
    om_diff_image(NULL, NULL, 4, 4, NULL);
    om_flicker_add(NULL, NULL, NULL, NULL, NULL, 4);
    CHECK(om_flicker_share(NULL) == 0.0);
    CHECK(om_hash(42, NULL, 4) == 42);
    CHECK(om_status_str((om_status)-1)[0] != 0 && om_status_str(OM_E_COUNT_)[0] != 0);
}

static void largest_image(void)
{
    if (getenv("OM_TEST_QUICK")) return;   /* valgrind runs skip the 67M-pixel frame */
    om_scene s;
    hand_scene(&s, 2);
    static const char *names[] = {"none", "sm"};
    for (int k = 0; k < 2; k++) {
        const om_method *m = om_method_find(names[k]);
        om_method_cfg c = h_cfg(names[k], SMALL);
        om_camera cam = s.camera;
        cam.width = cam.height = 8192;
        om_view v;
        CHECK_OK(om_view_init(&v, &cam, &s.light, &s, NULL));
        size_t mn, full, fbytes = h_frame_least(8192, 64);
        CHECK_OK(om_method_bytes(m, &c, &s, 8192, 8192, &mn, &full));
        void *mem = malloc(full), *fmem = malloc(fbytes), *px = malloc(8192 * 64 * 2);
        om_arena ma, fa;
        om_arena_init(&ma, mem, full, "method");
        om_arena_init(&fa, fmem, fbytes, "frame");
        void *state;
        CHECK_OK(om_method_init(m, &state, &ma, &c, &s, 8192, 8192, NULL));
        om_shade_cfg shade;
        om_framebuffer fb = {OM_RGB565, 8192, 64, 8192 * 2, px};
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, &s, &v, m, state, &fb, 64);
        om_frame_stats fs;
        CHECK_OK(om_render_frame(&fd, &fa, &fs, NULL));
        CHECK_EQ_U(fs.strips, 128);
        free(mem);
        free(fmem);
        free(px);
    }
}

void suite_robust(void)
{
    RUN(failure_injection);
    RUN(pathological_geometry);
    RUN(pathological_views);
    RUN(largest_image);
    RUN(hostile_calls);
    RUN(null_arguments);
    RUN(largest_settings);
}
