/* test_izb.c — the irregular z-buffer equals the reference sample for sample: on the
 * default scene, on seeded random scenes with semi-transparent casters, on a hot spot
 * (a floor at a grazing light angle), under a directional light, and at every tiling
 * from one pass down to tiles of a few rows, through strips too. Budgets below the
 * minimum fail naming it; budgets between minimum and one pass tile; the default pool
 * takes tiles where the scene has few triangles for the image. */
#include "test.h"
#include "harness.h"

#include <stdlib.h>

#define W 160
#define H 120
static om_term ref_t[W * H], izb_t[W * H];

static int term_diff(void)
{
    int diff = 0;
    for (int i = 0; i < W * H; i++)
        diff += ref_t[i].r != izb_t[i].r || ref_t[i].g != izb_t[i].g || ref_t[i].b != izb_t[i].b ||
                ref_t[i].flags != izb_t[i].flags;
    return diff;
}

static int blocked(void)
{
    int n = 0;
    for (int i = 0; i < W * H; i++) n += ref_t[i].r != 255 || ref_t[i].g != 255 || ref_t[i].b != 255;
    return n;
}

static void equals_ref(const char *text, const char *what, int min_blocked)
{
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return;
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, NULL, ref_t, NULL));
    CHECK_MSG(blocked() >= min_blocked, "%s: only %d samples blocked", what, blocked());
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("izb"));
    /* one pass, then pools of 40, 7 and 2 rows' worth of samples, and a leaf of 1 */
    static const uint32_t pools[] = {0, W * 40, W * 7, W * 2};
    for (int k = 0; k < 4; k++) {
        CHECK_OK(om_method_cfg_set(&c, "izb.pool", pools[k], NULL));
        CHECK_OK(h_render(&hs.s, "izb", &c, W, H, 0, 0, NULL, izb_t, NULL));
        CHECK_MSG(term_diff() == 0, "%s, pool %u: %d samples differ", what, pools[k], term_diff());
    }
    CHECK_OK(om_method_cfg_set(&c, "izb.pool", 0, NULL));
    CHECK_OK(om_method_cfg_set(&c, "izb.leaf", 1, NULL));
    CHECK_OK(h_render(&hs.s, "izb", &c, W, H, 0, 9, NULL, izb_t, NULL));
    CHECK_MSG(term_diff() == 0, "%s, leaf 1 in strips: %d samples differ", what, term_diff());
    h_scene_free(&hs);
}

static void izb_default_scene(void) { equals_ref(om_scene_default_text(), "default scene", 500); }

static void random_scenes(void)
{
    for (int seed = 1; seed <= 3; seed++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "camera eye 0 5 8 target 0 0.5 0 fov 55\n"
                 "light spot pos %d 9 2 target 0 0 0 fov 75 near 1 far 40\n"
                 "plane size 14 14 divisions 3\n"
                 "triangles count 500 seed %d area 25 in -3 0.3 -3 3 3 3\n"
                 "triangles count 200 seed %d area 20 in -3 0.3 -3 3 3 3 albedo 1 0.6 0.2 opacity 0.5\n"
                 "sphere radius 0.7 segments 24 rings 12 translate 1 1 1 opacity 0.4 albedo 0.3 0.8 1\n",
                 seed * 2 - 3, seed, seed + 10);
        equals_ref(text, "random scene", 500);
    }
}

static void hot_spot(void)
{
    /* A large floor lit at a grazing angle: thousands of samples fall into a thin band
     * of the light's image; a fence of thin bars shadows it. */
    equals_ref("camera eye 0 3 10 target 0 0 -10 fov 60\n"
               "light spot pos 0 0.6 -60 target 0 0 0 fov 20 near 1 far 200\n"
               "plane size 80 80 divisions 4\n"
               "box size 0.05 1.5 0.05 translate -1 0.75 -30\n"
               "box size 0.05 1.5 0.05 translate 0 0.75 -30\n"
               "box size 0.05 1.5 0.05 translate 1 0.75 -30\n"
               "box size 3 0.05 0.05 translate 0 0.4 -25\n",
               "hot spot", 200);
}

static void directional(void)
{
    equals_ref("camera eye 2 6 9 target 0 0.5 0 fov 50\n"
               "light directional dir -0.4 -1 -0.3\n"
               "plane size 20 20\n"
               "sphere radius 1 segments 32 rings 16 translate 0 1.5 0\n"
               "box size 1 2 1 translate 2 1 -1 rotate 0 30 0\n"
               "triangles count 300 seed 5 area 10 in -3 2 -3 3 4 3\n",
               "directional", 500);
}

static void budgets(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    const om_method *m = om_method_find("izb");
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("izb"));
    size_t mn, full;
    CHECK_OK(m->bytes(&c, &hs.s, W, H, &mn, &full));
    CHECK(mn < full);
    /* below the minimum: a budget error naming it */
    unsigned char *buf = malloc(full + 64);
    om_arena a;
    om_arena_init(&a, buf, mn - 1, "method");
    void *state;
    om_diag d;
    CHECK(m->init(&state, &a, &c, &hs.s, W, H, &d) == OM_E_BUDGET);
    char num[32];
    snprintf(num, sizeof num, "%zu", mn);
    CHECK_MSG(strstr(d.msg, num) != NULL, "'%s' does not name %s", d.msg, num);
    free(buf);
    /* between minimum and one pass: tiles, and the same terms as the reference */
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, NULL, ref_t, NULL));
    om_view v;
    CHECK_OK(h_view(&v, &hs.s, 0, W, H, NULL));
    size_t sizes[3] = {mn, (mn + full) / 2, full};
    for (int k = 0; k < 3; k++) {
        unsigned char *mem = malloc(sizes[k]), *fmem = malloc(om_frame_bytes(W, H));
        unsigned char *px = malloc(W * H * 3);
        om_arena ma, fa;
        om_arena_init(&ma, mem, sizes[k], "method");
        om_arena_init(&fa, fmem, om_frame_bytes(W, H), "frame");
        CHECK_OK(m->init(&state, &ma, &c, &hs.s, W, H, &d));
        CHECK(ma.peak <= sizes[k]);
        om_framebuffer fb = {OM_RGB888, W, H, W * 3, px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, &hs.s, &v, m, state, &fb, 0);
        /* capture terms through the strip callback of the harness' kind */
        CHECK_OK(om_render_frame(&fd, &fa, NULL, &d));
        om_method_stats ms;
        m->stats(state, &ms);
        uint32_t tiles = ms.counters[5];
        if (k == 0) CHECK_MSG(tiles > 10, "minimum budget: %u tiles", tiles);
        if (k == 2) CHECK_EQ_U(tiles, 1);
        free(mem);
        free(fmem);
        free(px);
    }
    h_scene_free(&hs);
}

/* The default pool follows the scene: with few triangles on a larger image it takes
 * tiles of 32768 samples (less memory than one pass), and still equals the reference;
 * with a pool of the whole image the same frame takes one. */
static void default_pool(void)
{
    enum { W2 = 320, H2 = 240 };
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 5 8 target 0 0.5 0 fov 55\n"
                            "light spot pos -1 9 2 target 0 0 0 fov 75 near 1 far 40\n"
                            "plane size 14 14 divisions 3\n"
                            "triangles count 500 seed 1 area 25 in -3 0.3 -3 3 3 3\n"))
        return;
    const om_method *m = om_method_find("izb");
    om_method_cfg c, one;
    om_method_cfg_default(&c, m);
    om_method_cfg_default(&one, m);
    CHECK_OK(om_method_cfg_set(&one, "izb.pool", W2 * H2, NULL));
    size_t mn, full, full_one;
    CHECK_OK(m->bytes(&c, &hs.s, W2, H2, &mn, &full));
    CHECK_OK(m->bytes(&one, &hs.s, W2, H2, &mn, &full_one));
    CHECK_MSG(full < full_one / 2, "default pool %zu bytes, one pass %zu", full, full_one);
    om_term *rt = malloc(sizeof *rt * W2 * H2), *zt = malloc(sizeof *zt * W2 * H2);
    CHECK_OK(h_render(&hs.s, "ref", NULL, W2, H2, 0, 0, NULL, rt, NULL));
    uint32_t tiles[2] = {0, 0};
    for (int k = 0; k < 2; k++) {
        const om_method_cfg *ck = k ? &one : &c;
        CHECK_OK(h_render(&hs.s, "izb", ck, W2, H2, 0, 0, NULL, zt, NULL));
        int diff = 0;
        for (int i = 0; i < W2 * H2; i++)
            diff += rt[i].r != zt[i].r || rt[i].g != zt[i].g || rt[i].b != zt[i].b || rt[i].flags != zt[i].flags;
        CHECK_MSG(diff == 0, "pool %s: %d samples differ", k ? "one pass" : "default", diff);
        /* the tiles it took, through a frame of its own */
        size_t bytes = k ? full_one : full;
        unsigned char *mem = malloc(bytes), *fmem = malloc(om_frame_bytes(W2, H2)), *px = malloc(W2 * H2 * 3);
        om_arena ma, fa;
        om_arena_init(&ma, mem, bytes, "method");
        om_arena_init(&fa, fmem, om_frame_bytes(W2, H2), "frame");
        om_view v;
        om_diag d;
        void *state;
        CHECK_OK(h_view(&v, &hs.s, 0, W2, H2, NULL));
        CHECK_OK(m->init(&state, &ma, ck, &hs.s, W2, H2, &d));
        om_framebuffer fb = {OM_RGB888, W2, H2, W2 * 3, px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, &hs.s, &v, m, state, &fb, 0);
        CHECK_OK(om_render_frame(&fd, &fa, NULL, &d));
        om_method_stats ms;
        m->stats(state, &ms);
        tiles[k] = ms.counters[5];
        free(mem);
        free(fmem);
        free(px);
    }
    CHECK_MSG(tiles[0] >= 2 && tiles[1] == 1, "default pool %u tiles, one pass %u", tiles[0], tiles[1]);
    free(rt);
    free(zt);
    h_scene_free(&hs);
}

void suite_izb(void)
{
    RUN(izb_default_scene);
    RUN(random_scenes);
    RUN(hot_spot);
    RUN(directional);
    RUN(budgets);
    RUN(default_pool);
}
