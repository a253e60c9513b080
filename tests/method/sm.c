/* method/sm.c — the conventional shadow map: its accuracy growing with its
 * resolution, and budgets below the minimum refused naming it (the reference's too). */
#include "../test.h"
#include "../harness.h"

#include <stdlib.h>

#define W 160
#define H 120

static const char *default_scene(void) { return om_scene_default_text(); }

static void sm_improves_with_resolution(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, default_scene())) return;
    static uint8_t ref[320 * 240], sm[320 * 240];
    CHECK_OK(h_render(&hs.s, "ref", NULL, 320, 240, 0, 0, ref, NULL, NULL));
    uint64_t prev = UINT64_MAX;
    for (uint32_t size = 512; size <= 4096; size *= 2) {
        om_method_cfg c = h_cfg("sm", "");
        CHECK_OK(om_method_cfg_set(&c, "map", size, NULL));
        CHECK_OK(h_render(&hs.s, "sm", &c, 320, 240, 0, 0, sm, NULL, NULL));
        om_metrics m;
        om_compare_masks(ref, sm, 320, 240, &m);
        uint64_t bad = m.false_lit + m.false_shadowed;
        CHECK_MSG(bad < prev, "map %u: %llu mismatches, not fewer than %llu", size,
                  (unsigned long long)bad, (unsigned long long)prev);
        CHECK_EQ_U(m.mismatched_bg, 0);
        prev = bad;
    }
    CHECK(prev < 320 * 240 / 50);
    h_scene_free(&hs);
}

static void budgets_name_the_minimum(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, default_scene())) return;
    static const char *names[] = {"ref", "sm"};
    for (int k = 0; k < 2; k++) {
        const om_method *m = om_method_find(names[k]);
        om_method_cfg c = h_cfg(names[k], "map=256");
        size_t mn, full;
        CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
        unsigned char *buf = malloc(mn + 64);
        memset(buf, 0xC3, mn + 64);
        om_arena a;
        om_arena_init(&a, buf + 32, mn / 2, "method");
        void *state;
        om_diag d;
        CHECK(om_method_init(m, &state, &a, &c, &hs.s, W, H, &d) == OM_E_BUDGET);
        char num[32];
        snprintf(num, sizeof num, "%zu", mn);
        CHECK_MSG(strstr(d.msg, num) != NULL, "%s: '%s' does not name %s", names[k], d.msg, num);
        om_arena_init(&a, buf + 32, mn, "method");
        CHECK_OK(om_method_init(m, &state, &a, &c, &hs.s, W, H, &d));
        CHECK(a.peak <= mn);
        int guard = 0;
        for (int i = 0; i < 32; i++) guard += buf[i] != 0xC3 || buf[32 + mn + i] != 0xC3;
        CHECK_EQ_U(guard, 0);
        free(buf);
    }
    h_scene_free(&hs);
}

/* The default scene drawn a thousand times smaller or larger keeps its shadows: the
 * settings' units scale with the scene. */
static void sm_bias_is_scale_free(void) { h_check_scale_free("sm", 320, 240); }

void suite_sm(void)
{
    RUN(sm_bias_is_scale_free);
    RUN(sm_improves_with_resolution);
    RUN(budgets_name_the_minimum);
}
