/* property/methods.c — what every method holds: the reference's samples and exposure,
 * frames under odd lights, a kept state's frames those of a fresh one, and the
 * built-in town rendered by every method. */
#include "../test.h"
#include "../harness.h"

#include <stdlib.h>

#define W 160
#define H 120
static uint8_t mask[W * H], mask2[W * H];

static const char *default_scene(void) { return om_scene_default_text(); }

static void methods_agree_on_samples(void)
{
    /* Every method sees the same samples: background and exposure match the reference. */
    h_scene hs;
    if (!h_scene_parse(&hs, default_scene())) return;
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, mask, NULL, NULL));
    for (size_t i = 0; i < om_method_count(); i++) {
        CHECK_OK(h_render(&hs.s, om_method_name(om_method_at(i)), NULL, W, H, 0, 7, mask2, NULL, NULL));
        om_metrics m;
        om_compare_masks(mask, mask2, W, H, &m);
        CHECK_EQ_U(m.mismatched_bg, 0);
    }
    /* the reference through strips equals the reference whole */
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 5, mask2, NULL, NULL));
    CHECK(!memcmp(mask, mask2, sizeof mask));
    h_scene_free(&hs);
}

static void odd_lights(void)
{
    /* A light inside a box, one behind the camera, one on the floor: frames render. */
    static const char *lights[] = {
        "light spot pos 0 0.5 0 target 0 0 3 fov 90 near 0.1 far 50\n",
        "light spot pos 0 3 20 target 0 0 0 fov 40 near 1 far 60\n",
        "light spot pos 2 0 2 target 0 0 0 fov 60 near 0.1 far 50\n",
        "light directional dir 0 1 0\n",
    };
    for (int k = 0; k < 4; k++) {
        char text[512];
        snprintf(text, sizeof text, "camera eye 0 2 8 target 0 0.5 0 size 80 60\n%s"
                 "plane size 10 10\nbox size 1 1 1 translate 0 0.5 0\n", lights[k]);
        h_scene hs;
        if (!h_scene_parse(&hs, text)) return;
        for (size_t i = 0; i < om_method_count(); i++)
            CHECK_OK(h_render(&hs.s, om_method_name(om_method_at(i)), NULL, 0, 0, 0, 0, mask, NULL, NULL));
        h_scene_free(&hs);
    }
}

/* A method's state kept from frame to frame gives each frame what a fresh state
 * gives: nothing it keeps for speed (spsm's surface directions and texel window, the
 * maps, the light's grid) outlives the view it was made for. Two frames at t = 0 and
 * t1 against one at t1, through strips: the default scene, where camera and light
 * move, and floors alone under a moving light (every sample's normal the same, so
 * spsm's surface directions would be kept into the next frame: the case that fails
 * when their reset at the map's build is lost). asm is left out: its tree is meant to
 * refine over the frames. */
static uint64_t kept_hash;

static om_status kept_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)user;
    (void)fb;
    kept_hash = om_hash(kept_hash, st->terms, (size_t)st->rows * st->width * sizeof *st->terms);
    return OM_OK;
}

static void kept_state_case(const char *text, float t1)
{
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return;
    static unsigned char fm[1 << 20];
    static uint8_t px[W * 16 * 3];
    for (size_t mi = 0; mi < om_method_count(); mi++) {
        const om_method *m = om_method_at(mi);
        if (!strcmp(om_method_name(m), "asm")) continue;
        uint64_t h[2];
        for (int fresh = 0; fresh < 2; fresh++) {
            om_method_cfg c = h_cfg(om_method_name(m), "map=256");
            size_t mn, full;
            CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
            void *mm = malloc(full), *state = NULL;
            om_arena ma, fa;
            om_arena_init(&ma, mm, full, "method");
            CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, NULL));
            for (int f = fresh; f < 2; f++) {
                om_view v;
                CHECK_OK(h_view(&v, &hs.s, f ? t1 : 0.0f, W, H, NULL));
                om_framebuffer fb = {OM_RGB888, W, 16, W * 3, px};
                om_shade_cfg shade;
                om_frame_desc fd;
                h_frame_desc(&fd, &shade, &hs.s, &v, m, state, &fb, 16);
                fd.on_strip = kept_strip;
                om_arena_init(&fa, fm, sizeof fm, "frame");
                kept_hash = OM_HASH_INIT;
                CHECK_OK(om_render_frame(&fd, &fa, NULL, NULL));
            }
            h[fresh] = kept_hash;
            free(mm);
        }
        CHECK_MSG(h[0] == h[1], "%s: a kept state's frame at t %g is not a fresh one's", om_method_name(m), t1);
    }
    h_scene_free(&hs);
}

static void kept_state_as_fresh(void)
{
    kept_state_case(om_scene_default_text(), 4.0f);
    kept_state_case("camera eye 0 6 6 target 0 0 0 fov 60 near 0.1 far 100\n"
                    "light spot pos 5 10 0 target 0 0 0 fov 60 near 1 far 50\n"
                    "plane size 20 20\n"
                    "plane size 2 2 translate 0 1 0\n"
                    "key light 0 pos 5 10 0 target 0 0 0\n"
                    "key light 4 pos -5 10 3 target 0 0 0\n", 1.0f);
}

/* The town: every method renders a small view of its street, at both ends of the walk
 * (the sun moved between them), whole and through strips, on the reference's samples;
 * the exact methods agree with ref, and every other one but `none` is wrong on under
 * a fifth of the samples `none` (no shadows at all) is wrong on. */
static void town_every_method(void)
{
    char *text = h_town_text();
    h_scene hs;
    const bool ok = text && h_scene_parse(&hs, text);
    free(text);
    if (!ok) return;
    for (int k = 0; k < 2; k++) {
        const float t = k ? 20.0f : 0.0f;
        uint64_t none_wrong = 0;
        CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, t, 0, mask, NULL, NULL));
        CHECK_OK(h_render(&hs.s, "none", NULL, W, H, t, 0, mask2, NULL, NULL));
        om_metrics m;
        om_compare_masks(mask, mask2, W, H, &m);
        none_wrong = m.false_lit + m.false_shadowed;
        CHECK_MSG(none_wrong > W * H / 20, "t %g: only %llu samples in shadow", (double)t, (unsigned long long)none_wrong);
        for (size_t i = 0; i < om_method_count(); i++) {
            const om_method *me = om_method_at(i);
            const om_method_cfg c = h_cfg(om_method_name(me), "map=1024");
            CHECK_OK(h_render(&hs.s, om_method_name(me), &c, W, H, t, k ? 16 : 0, mask2, NULL, NULL));
            om_compare_masks(mask, mask2, W, H, &m);
            CHECK_EQ_U(m.mismatched_bg, 0);
            const uint64_t wrong = m.false_lit + m.false_shadowed;
            if (om_method_flags(me) & OM_METHOD_EXACT)
                CHECK_MSG(wrong == 0, "%s at t %g: %llu samples differ from ref", om_method_name(me), (double)t,
                          (unsigned long long)wrong);
            else if (strcmp(om_method_name(me), "none"))
                CHECK_MSG(wrong * 5 < none_wrong, "%s at t %g: %llu samples wrong, none %llu", om_method_name(me),
                          (double)t, (unsigned long long)wrong, (unsigned long long)none_wrong);
        }
    }
    h_scene_free(&hs);
}

void suite_methods(void)
{
    RUN(methods_agree_on_samples);
    RUN(odd_lights);
    RUN(kept_state_as_fresh);
    RUN(town_every_method);
}
