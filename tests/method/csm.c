/* method/csm.c — cascaded shadow maps: one cascade over the whole light image is sm,
 * more cascades at the same memory are right more often on a long view under a low
 * sun, the practical splits cover near..far without going back, the fitted mode's
 * windows hold every exposed sample, the frames are the same bits on any number of
 * threads and through strips, and bad settings and budgets are refused by name. */
#include "../test.h"
#include "../harness.h"
#include "../jobs_util.h"
#include "../../platform/platform.h"
#include "../../engine/shadow/csm/csm.h"

#include <stdlib.h>

/* A street under a low sun: a ground 400 m across, two rows of blocks along the
 * street, poles near the camera, the camera at eye height looking down it. */
static const char street[] =
    "camera eye 0 1.7 0 target 0 1.5 -40 fov 60 near 0.1 far 1000\n"
    "light directional dir 0.55 -0.35 -0.45\n"
    "plane size 400 400 divisions 8\n"
    "box size 6 12 10 translate -11 6 -10\n"
    "box size 8 20 12 translate 12 10 -14\n"
    "box size 5 8 9 translate -10.5 4 -30\n"
    "box size 7 15 11 translate 11.5 7.5 -38\n"
    "box size 6 25 14 translate -11 12.5 -60\n"
    "box size 9 10 10 translate 12.5 5 -70\n"
    "box size 6 18 12 translate -11 9 -100\n"
    "box size 8 9 14 translate 12 4.5 -120\n"
    "box size 20 30 20 translate -60 15 -150\n"
    "box size 15 12 15 translate 70 6 -90\n"
    "box size 0.1 3 0.1 translate 5 1.5 -4\n"
    "box size 0.1 3 0.1 translate -5 1.5 -9\n"
    "box size 0.1 3 0.1 translate 5 1.5 -15\n"
    "box size 1.5 0.5 0.5 translate -3 0.25 -6\n";

/* Samples `name` with settings `set` gets wrong against ref on scene s at w x h. */
static uint64_t wrong(const om_scene *s, const char *name, const char *set, const uint8_t *ref, uint32_t w,
                      uint32_t h, uint8_t *mask)
{
    om_method_cfg c = h_cfg(name, set);
    if (h_render(s, name, &c, w, h, 0, 0, mask, NULL, NULL) != OM_OK) return UINT64_MAX;
    om_metrics m;
    om_compare_masks(ref, mask, w, h, &m);
    return m.false_lit + m.false_shadowed;
}

/* One frame of csm with `set` on scene s at w x h through strips of `rows` (0: whole);
 * the state stays in *mem (the caller frees it). */
static om__csm *frame(const om_scene *s, const char *set, uint32_t w, uint32_t h, uint32_t rows, void **mem)
{
    const om_method *m = om_method_find("csm");
    om_method_cfg c = h_cfg("csm", set);
    size_t mn, full;
    om_view v;
    *mem = NULL;
    if (om_method_bytes(m, &c, s, w, h, &mn, &full) != OM_OK || h_view(&v, s, 0, w, h, NULL) != OM_OK) return NULL;
    const size_t fbytes = h_frame_bins(s, w, rows ? rows : h);
    void *fm = malloc(fbytes), *px = malloc((size_t)w * h * 3);
    *mem = malloc(full);
    om_arena ma, fa;
    om_arena_init(&ma, *mem, full, "method");
    om_arena_init(&fa, fm, fbytes, "frame");
    void *state = NULL;
    om_diag d;
    om_status st = om_method_init(m, &state, &ma, &c, s, w, h, &d);
    if (st == OM_OK) {
        om_framebuffer fb = {OM_RGB888, w, h, (size_t)w * 3, (uint8_t *)px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, s, &v, m, state, &fb, rows);
        st = om_render_frame(&fd, &fa, NULL, &d);
    }
    CHECK_MSG(st == OM_OK, "csm %s: %s", set, d.msg);
    free(fm);
    free(px);
    return st == OM_OK ? (om__csm *)state : NULL;
}

/* The counter named `name` of a frame's stats. */
static uint32_t counter(const om_method_stats *ms, const char *name)
{
    for (uint32_t i = 0; i < ms->ncounters; i++)
        if (!strcmp(ms->counter_names[i], name)) return ms->counters[i];
    CHECK_MSG(0, "no counter '%s'", name);
    return UINT32_MAX;
}

/* Under a directional light (fitted to the visible samples) one cascade's window is
 * the whole light image and a margin: the mask of sm at the same side, but for
 * samples at shadow edges, and about as often right. */
static void csm_one_cascade_is_sm(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, directional_scene)) return;
    enum { W = 320, H = 240 };
    static uint8_t ref[W * H], sm[W * H], csm[W * H];
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, ref, NULL, NULL));
    const uint64_t wsm = wrong(&hs.s, "sm", "map=512", ref, W, H, sm);
    const uint64_t wcsm = wrong(&hs.s, "csm", "csm.cascades=1 csm.map=512", ref, W, H, csm);
    /* their texel grids differ by the margin (a texel at the edges), so they differ at
     * shadow edges: every sample where they differ lies within 2 px of an edge of sm's */
    om_metrics vs;
    om_compare_masks(sm, csm, W, H, &vs);
    const uint64_t differ = vs.false_lit + vs.false_shadowed, off = differ - vs.edge_false_lit - vs.edge_false_shadowed;
    /* but for a few on surfaces almost parallel to the light, where a rounding of
     * the biased depth decides */
    CHECK_MSG(off * 20 <= differ, "one cascade differs from sm in %llu samples, %llu of them away from sm's edges",
              (unsigned long long)differ, (unsigned long long)off);
    CHECK_MSG(wcsm <= wsm + wsm / 4 + 20, "one cascade: %llu wrong, sm: %llu", (unsigned long long)wcsm,
              (unsigned long long)wsm);
    h_scene_free(&hs);
}

/* The street at the same memory: sm at 1024 against four cascades of 512; each
 * cascade added is right more often than one cascade, and four at least three times
 * as often as sm. */
static void csm_cascades_beat_sm(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, street)) return;
    enum { W = 480, H = 360 };
    static uint8_t ref[W * H], mask[W * H];
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, ref, NULL, NULL));
    const uint64_t wsm = wrong(&hs.s, "sm", "map=1024", ref, W, H, mask);
    uint64_t w1 = 0;
    for (int n = 1; n <= 4; n++) {
        char set[64];
        snprintf(set, sizeof set, "csm.cascades=%d csm.map=512", n);
        const uint64_t wn = wrong(&hs.s, "csm", set, ref, W, H, mask);
        if (n == 1) w1 = wn;
        else CHECK_MSG(wn < w1, "%d cascades: %llu wrong, one: %llu", n, (unsigned long long)wn, (unsigned long long)w1);
        if (n == 4) CHECK_MSG(3 * wn <= wsm, "4 cascades: %llu wrong, sm 1024: %llu", (unsigned long long)wn,
                              (unsigned long long)wsm);
    }
    h_scene_free(&hs);
}

/* The practical splits: from lo to hi, never going back; lambda 0 the uniform split,
 * 1 the logarithmic one (each slice the same ratio). And a frame's splits cover the
 * depth its range gives them. */
static void csm_splits_cover_near_far(void)
{
    static const float lambdas[] = {0.0f, 0.3f, 0.75f, 1.0f};
    for (uint32_t n = 1; n <= OM__CSM_MAX; n++)
        for (int l = 0; l < 4; l++) {
            float z[OM__CSM_MAX + 1];
            om__csm_practical(0.1f, 1000.0f, lambdas[l], n, z);
            CHECK(z[0] == 0.1f && z[n] == 1000.0f);
            for (uint32_t i = 1; i <= n; i++) CHECK_MSG(z[i] >= z[i - 1], "n %u lambda %g: split %u goes back", n, lambdas[l], i);
            for (uint32_t i = 1; i < n; i++) {
                const double uni = 0.1 + (1000.0 - 0.1) * i / n, lg = 0.1 * pow(1e4, (double)i / n);
                const double want = lambdas[l] * lg + (1 - lambdas[l]) * uni;
                CHECK_MSG(fabs(z[i] - want) <= want * 1e-5, "n %u lambda %g: split %u is %g, not %g", n, lambdas[l], i,
                          z[i], want);
            }
        }
    h_scene hs;
    if (!h_scene_parse(&hs, street)) return;
    for (int fit = 0; fit <= 1; fit++) {
        void *mem;
        om__csm *m = frame(&hs.s, fit ? "csm.fit=1 csm.map=128" : "csm.map=128", 160, 120, 0, &mem);
        if (m) {
            CHECK(m->znear >= 0.1f && m->zfar <= 1000.0f && m->znear < m->zfar);
            /* the scene's depth along the view: the ground reaches 200 m ahead */
            CHECK_MSG(m->zfar < 400.0f, "far %g", m->zfar);
            CHECK(fit ? m->split[0] >= m->znear && m->split[4] <= m->zfar
                      : m->split[0] == m->znear && m->split[4] == m->zfar);
            for (int i = 1; i <= 4; i++) CHECK(m->split[i] >= m->split[i - 1]);
            CHECK(m->split[1] > m->split[0]);   /* the first cascade holds some depth */
        }
        free(mem);
    }
    h_scene_free(&hs);
}

/* The fitted mode's windows hold every exposed sample (none read a map it lies
 * outside of), spot or directional, whole or through strips; so do the practical
 * mode's, whose slices hold every visible point. */
static void csm_windows_hold_every_sample(void)
{
    const char *texts[3] = {street, directional_scene, om_scene_default_text()};
    for (int t = 0; t < 3; t++) {
        h_scene hs;
        if (!h_scene_parse(&hs, texts[t])) continue;
        for (int fit = 0; fit <= 1; fit++)
            for (uint32_t rows = 0; rows <= 30; rows += 30) {
                void *mem;
                const char *set = fit ? "csm.fit=1 csm.map=256 pcf=3 offset=1" : "csm.map=256";
                om__csm *m = frame(&hs.s, set, 200, 150, rows, &mem);
                if (m) {
                    om_method_stats ms;
                    om_method_get_stats(om_method_find("csm"), m, &ms);
                    uint32_t held = 0;
                    for (uint32_t k = 0; k < m->n; k++) held += m->held[k];
                    CHECK_MSG(counter(&ms, "samples in no window") == 0, "scene %d fit %d rows %u: %u samples in no window",
                              t, fit, rows, counter(&ms, "samples in no window"));
                    CHECK(held == counter(&ms, "samples") && held > 1000);
                    /* the fitted windows lie within the light's image */
                    for (uint32_t k = 0; fit && k < m->n; k++)
                        if (m->win[k].live)
                            CHECK(m->win[k].cx - m->win[k].limx >= -1.0001f && m->win[k].cx + m->win[k].limx <= 1.0001f);
                }
                free(mem);
            }
        h_scene_free(&hs);
    }
}

/* The same bits on 1, 2 and 16 threads, run backwards, and through strips, for both
 * modes and a spot and a directional light (threads.c's same_bits runs the
 * defaults: the practical mode). */
static void csm_same_bits(void)
{
    om_jobs *pools[2];
    static const uint32_t threads[2] = {2, 16};
    for (int k = 0; k < 2; k++) CHECK_OK(om_jobs_start(&pools[k], threads[k], NULL));
    const om_method *m = om_method_find("csm");
    for (int li = 0; li < 2; li++) {
        h_scene hs;
        if (!h_scene_parse(&hs, li ? directional_scene : om_scene_default_text())) continue;
        static const char *const sets[2] = {"csm.fit=1 csm.map=256 pcf=3", "csm.cascades=3 csm.map=200 offset=1"};
        for (int si = 0; si < 2; si++) {
            uint32_t counters[10] = {0};
            for (uint32_t rows = 0; rows <= 25; rows += 25) {
                const frame_out one = render_set(&hs.s, m, sets[si], 160, 120, rows, NULL, NULL, 1, 0, true);
                CHECK(one.st == OM_OK);
                /* strips: the same counters as the whole frame (the hash is by strips) */
                if (rows) CHECK(!memcmp(counters, one.ms.counters, sizeof counters));
                memcpy(counters, one.ms.counters, sizeof counters);
                for (int k = 0; k < 3; k++) {
                    const uint32_t n = k < 2 ? threads[k] : 3;
                    const size_t jb = h_frame_jobs(m, &hs.s, n);
                    const frame_out o = k < 2 ? render_set(&hs.s, m, sets[si], 160, 120, rows, om_jobs_for, pools[k], n, jb, true)
                                              : render_set(&hs.s, m, sets[si], 160, 120, rows, backwards, NULL, n, jb, true);
                    CHECK_MSG(o.st == OM_OK && o.hash == one.hash, "light %d %s rows %u: %u threads change the frame", li,
                              sets[si], rows, n);
                    CHECK(!memcmp(o.ms.counters, one.ms.counters, sizeof o.ms.counters));
                }
            }
        }
        h_scene_free(&hs);
    }
    for (int k = 0; k < 2; k++) om_jobs_stop(pools[k]);
}

/* Settings outside their ranges are refused by name; the bytes query counts a map a
 * cascade; a budget below the minimum is refused naming it. */
static void csm_settings_and_budgets(void)
{
    const om_method *m = om_method_find("csm");
    om_method_cfg c;
    om_method_cfg_default(&c, m);
    om_diag d;
    CHECK(om_method_cfg_set(&c, "csm.cascades", 5, &d) == OM_E_RANGE && strstr(d.msg, "csm.cascades"));
    CHECK(om_method_cfg_set(&c, "csm.cascades", 0, &d) == OM_E_RANGE);
    CHECK(om_method_cfg_set(&c, "csm.lambda", 1.5, &d) == OM_E_RANGE && strstr(d.msg, "csm.lambda"));
    CHECK(om_method_cfg_set(&c, "csm.fit", 2, &d) == OM_E_RANGE);
    CHECK(om_method_cfg_set(&c, "csm.map", 0, &d) == OM_E_RANGE);
    CHECK(om_method_cfg_set(&c, "map", 512, &d) == OM_E_NOTFOUND);   /* its own: csm.map */
    h_scene hs;
    if (!h_scene_parse(&hs, street)) return;
    size_t mn2, full2, mn4, full4;
    om_method_cfg c2 = h_cfg("csm", "csm.cascades=2 csm.map=256"), c4 = h_cfg("csm", "csm.cascades=4 csm.map=256");
    CHECK_OK(om_method_bytes(m, &c2, &hs.s, 64, 48, &mn2, &full2));
    CHECK_OK(om_method_bytes(m, &c4, &hs.s, 64, 48, &mn4, &full4));
    CHECK_MSG(mn4 - mn2 >= 2 * 256 * 256 * 4 && mn4 - mn2 <= 2 * (256 * 256 * 4 + 16), "two maps of 256: %zu bytes",
              mn4 - mn2);
    CHECK(full4 > mn4 && full2 > mn2);
    /* a configuration made for another method is refused by name */
    om_method_cfg smc = h_cfg("sm", "");
    size_t a, b;
    CHECK(om_method_bytes(m, &smc, &hs.s, 64, 48, &a, &b) == OM_E_INVALID);
    unsigned char *buf = malloc(mn4);
    om_arena ar;
    void *state;
    om_arena_init(&ar, buf, mn4 - 1, "method");
    CHECK(om_method_init(m, &state, &ar, &c4, &hs.s, 64, 48, &d) == OM_E_BUDGET);
    char num[32];
    snprintf(num, sizeof num, "%zu", mn4);
    CHECK_MSG(strstr(d.msg, num) != NULL, "'%s' does not name %s", d.msg, num);
    /* at the minimum it renders, without the coarse depth and vertex cache: the same mask */
    static uint8_t lean[64 * 48], fat[64 * 48];
    CHECK_OK(h_render_in(&hs.s, "csm", &c4, 64, 48, 0, 0, mn4, lean, NULL, NULL));
    CHECK_OK(h_render_in(&hs.s, "csm", &c4, 64, 48, 0, 0, 0, fat, NULL, NULL));
    CHECK(!memcmp(lean, fat, sizeof lean));
    free(buf);
    h_scene_free(&hs);
}

/* A spot light (the default scene): four cascades of 512 as right as sm at 1024, or
 * more; each cascade a window of the light's image. */
static void csm_spot_light(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    enum { W = 320, H = 240 };
    static uint8_t ref[W * H], mask[W * H];
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, ref, NULL, NULL));
    const uint64_t wsm = wrong(&hs.s, "sm", "map=1024", ref, W, H, mask);
    const uint64_t wcsm = wrong(&hs.s, "csm", "csm.map=512", ref, W, H, mask);
    CHECK_MSG(wcsm < wsm, "spot: csm 4 x 512 %llu wrong, sm 1024 %llu", (unsigned long long)wcsm,
              (unsigned long long)wsm);
    h_scene_free(&hs);
}

void suite_csm(void)
{
    RUN(csm_splits_cover_near_far);
    RUN(csm_settings_and_budgets);
    RUN(csm_one_cascade_is_sm);
    RUN(csm_cascades_beat_sm);
    RUN(csm_spot_light);
    RUN(csm_windows_hold_every_sample);
    RUN(csm_same_bits);
}
