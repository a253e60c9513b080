/* test_hybrid.c — the hybrid method equals the reference sample for sample: on the
 * default scene, on seeded random scenes with semi-transparent casters and grazing
 * lights, with maps coarser and finer than the image, through strips and under its
 * minimum budget; and every sample its map calls certain (lit or shadowed) is what the
 * reference says, checked one by one. */
#include "test.h"
#include "harness.h"
#include "../engine/shadow/hybrid/hybrid.h"

#include <stdlib.h>

#define W 160
#define H 120
static om_term ref_t[W * H], hyb_t[W * H];
static om_sample smp[W * H];

static int term_diff(void)
{
    int diff = 0;
    for (int i = 0; i < W * H; i++)
        diff += ref_t[i].r != hyb_t[i].r || ref_t[i].g != hyb_t[i].g || ref_t[i].b != hyb_t[i].b ||
                ref_t[i].flags != hyb_t[i].flags;
    return diff;
}

/* Every certain answer of the map, held against the reference's term for the sample,
 * in the one-pass arena or (least) the minimum one, where no vertex projection is kept
 * and every triangle takes the map's full path. Then the method's own resolve, whose
 * float test decides most lit samples without their exact depth: its counts of each
 * answer must be the map's exact ones, sample for sample (a float "lit" where the exact
 * test is not sure would move a sample from uncertain to lit). Returns how many
 * samples the map decided. */
static uint32_t certain_agree(const om_scene *s, const om_method_cfg *c, const char *what, bool least)
{
    const om_method *m = om_method_find("hybrid");
    om_view v;
    om_diag d;
    CHECK_OK(h_view(&v, s, 0, W, H, &d));
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, c, s, W, H, &mn, &full));
    void *mem = malloc(least ? mn : full), *state;
    om_arena a;
    om_arena_init(&a, mem, least ? mn : full, "method");
    uint32_t decided = 0, wrong = 0, answers[3] = {0, 0, 0};
    bool ran = false;
    if (om_method_init(m, &state, &a, c, s, W, H, &d) == OM_OK && m->begin(state, &v, &d) == OM_OK &&
        m->build(state, &d) == OM_OK) {
        ran = true;
        const om__lspace *ls = om__hybrid_lspace(state);
        for (int i = 0; i < W * H; i++) {
            if (!(ref_t[i].flags & OM_TERM_EXPOSED)) continue;
            om__lpoint p;
            if (!om__lspace_point(ls, &smp[i], &p)) continue;
            om_term t = {255, 255, 255, ref_t[i].flags};
            int k = om__hybrid_decide(state, &p, &t);
            answers[k == 1 ? 0 : k == 2 ? 1 : 2]++;
            if (k == 0) continue;
            decided++;
            bool lit = ref_t[i].r == 255 && ref_t[i].g == 255 && ref_t[i].b == 255;
            bool black = ref_t[i].r == 0 && ref_t[i].g == 0 && ref_t[i].b == 0;
            if ((k == 1 && !lit) || (k == 2 && !black) || t.r != ref_t[i].r || t.g != ref_t[i].g ||
                t.b != ref_t[i].b) {
                if (++wrong <= 3)
                    fprintf(stderr, "  %s: pixel (%d,%d) certain %s, reference %u %u %u\n", what, i % W,
                            i / W, k == 1 ? "lit" : "shadowed", ref_t[i].r, ref_t[i].g, ref_t[i].b);
            }
        }
    }
    CHECK_MSG(wrong == 0, "%s: %u certain samples differ from the reference", what, wrong);
    CHECK_MSG(ran, "%s: the method did not start", what);
    if (ran) {
        static om_term terms[W * H];
        for (int i = 0; i < W * H; i++) terms[i] = ref_t[i];
        om_strip st = {W, H, 0, H, smp, terms};
        om_method_stats ms;
        CHECK_OK(m->resolve(state, &st, &d));
        om_method_get_stats(m, state, &ms);
        for (int k = 0; k < 3; k++)
            CHECK_MSG(ms.counters[k] == answers[k], "%s: resolve's %s %u, the map's %u", what,
                      ms.counter_names[k], (unsigned)ms.counters[k], answers[k]);
        int diff = 0;
        for (int i = 0; i < W * H; i++)
            diff += terms[i].r != ref_t[i].r || terms[i].g != ref_t[i].g || terms[i].b != ref_t[i].b;
        CHECK_MSG(diff == 0, "%s: %d of resolve's terms differ from the reference", what, diff);
    }
    free(mem);
    return decided;
}

static void equals_ref(const char *text, const char *what, double least_certain)
{
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return;
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, NULL, ref_t, smp));
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("hybrid"));
    /* maps from far coarser than the image to far finer */
    static const uint32_t maps[] = {1, 16, 96, 512, 2048};
    for (int k = 0; k < 5; k++) {
        CHECK_OK(om_method_cfg_set(&c, "hybrid.map", maps[k], NULL));
        CHECK_OK(h_render(&hs.s, "hybrid", &c, W, H, 0, 0, NULL, hyb_t, NULL));
        CHECK_MSG(term_diff() == 0, "%s, map %u: %d samples differ", what, maps[k], term_diff());
        uint32_t decided = certain_agree(&hs.s, &c, what, false);
        certain_agree(&hs.s, &c, what, true);
        uint32_t exposed = 0;
        for (int i = 0; i < W * H; i++) exposed += ref_t[i].flags & OM_TERM_EXPOSED;
        if (maps[k] == 512) {
            printf("  %s map 512: %u of %u certain\n", what, decided, exposed);
            CHECK_MSG(decided >= least_certain * exposed, "%s, map 512: %u of %u exposed samples certain",
                      what, decided, exposed);
        }
    }
    /* strips of 7 rows, and the least memory it renders in (tiles of the uncertain) */
    CHECK_OK(om_method_cfg_set(&c, "hybrid.map", 96, NULL));
    CHECK_OK(h_render(&hs.s, "hybrid", &c, W, H, 0, 7, NULL, hyb_t, NULL));
    CHECK_MSG(term_diff() == 0, "%s, strips: %d samples differ", what, term_diff());
    const om_method *m = om_method_find("hybrid");
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
    CHECK_OK(h_render_in(&hs.s, "hybrid", &c, W, H, 0, 0, mn, NULL, hyb_t, NULL));
    CHECK_MSG(term_diff() == 0, "%s, minimum budget: %d samples differ", what, term_diff());
    h_scene_free(&hs);
}

static void hybrid_default_scene(void) { equals_ref(om_scene_default_text(), "default scene", 0.8); }

/* A tile of many uncertain samples, with room for the candidates, is cut into regions
 * that walk apart (hybrid_tile.c): on h_cloud_bar at 480x360, the reference's terms,
 * as without room for the candidates (every tile whole: the method's least memory). */
static void hybrid_regions_equal_ref(void)
{
    enum { RW = 480, RH = 360 };
    static om_term ref[RW * RH], hyb[RW * RH];
    h_scene hs;
    if (!h_scene_parse(&hs, h_cloud_bar)) return;
    const om_method *m = om_method_find("hybrid");
    om_method_cfg c;
    om_method_cfg_default(&c, m);
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, RW, RH, &mn, &full));
    CHECK_OK(h_render(&hs.s, "ref", NULL, RW, RH, 0, 0, NULL, ref, NULL));
    for (int least = 0; least < 2; least++) {
        CHECK_OK(h_render_in(&hs.s, "hybrid", &c, RW, RH, 0, 0, least ? mn : full, NULL, hyb, NULL));
        int diff = 0;
        for (int i = 0; i < RW * RH; i++)
            diff += ref[i].r != hyb[i].r || ref[i].g != hyb[i].g || ref[i].b != hyb[i].b ||
                    ref[i].flags != hyb[i].flags;
        CHECK_MSG(diff == 0, "cloud%s: %d samples differ from the reference", least ? ", least memory" : "", diff);
    }
    h_scene_free(&hs);
}

static void hybrid_random_scenes(void)
{
    for (int seed = 1; seed <= 3; seed++) {
        char text[1024];
        /* seed 3's spot light grazes the floor at a few degrees */
        snprintf(text, sizeof text,
                 "camera eye 0 5 8 target 0 0.5 0 fov 55\n"
                 "light spot pos %d %s 2 target 0 0 0 fov 75 near 1 far 40\n"
                 "plane size 14 14 divisions %d\n"
                 "triangles count 500 seed %d area 25 in -3 0.3 -3 3 3 3\n"
                 "triangles count 200 seed %d area 20 in -3 0.3 -3 3 3 3 albedo 1 0.6 0.2 opacity 0.5\n"
                 "sphere radius 0.7 segments 24 rings 12 translate 1 1 1 opacity 0.4 albedo 0.3 0.8 1\n"
                 "box size 1 1 1 translate -1 0.5 1\n",
                 seed * 2 - 3 + (seed == 3 ? 20 : 0), seed == 3 ? "1.5" : "9", seed * 3, seed, seed + 10);
        equals_ref(text, "random scene", 0.25);
    }
    equals_ref("camera eye 2 6 9 target 0 0.5 0 fov 50\n"
               "light directional dir -0.4 -1 -0.3\n"
               "plane size 20 20 divisions 5\n"
               "sphere radius 1 segments 32 rings 16 translate 0 1.5 0\n"
               "box size 1 2 1 translate 2 1 -1 rotate 0 30 0\n"
               "triangles count 300 seed 5 area 10 in -3 2 -3 3 4 3\n",
               "directional", 0.8);
    /* casters resting on the floor at shallow angles: near their low edges they are
     * barely nearer the light than what they shadow, so the map's planes are tested
     * where their margins are thinnest */
    equals_ref("camera eye 0 4 7 target 0 0 0 fov 50\n"
               "light spot pos 3 8 -4 target 0 0 0 fov 60 near 1 far 30\n"
               "plane size 10 10 divisions 4\n"
               "plane size 3 3 divisions 2 rotate 0 0 12 translate 0 0.31 0\n"
               "plane size 2 2 rotate 6 30 0 translate -2.5 0.1 -1\n"
               "box size 2 0.1 1 rotate 0 0 4 translate 1.5 0.12 2\n"
               "box size 1 1 1 rotate 0 20 0 translate 3 0.5 -1\n",
               "contact", 0.5);
}

void suite_hybrid(void)
{
    RUN(hybrid_default_scene);
    RUN(hybrid_random_scenes);
    RUN(hybrid_regions_equal_ref);
}
