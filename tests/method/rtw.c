/* method/rtw.c — Rectilinear Texture Warping: the warp tables' properties (identity for
 * uniform importance, monotonic with fixed ends, a single important cell widening, no
 * division by an all-zero map), shared edges staying closed in the warped map, the
 * exact map holding the occlusion predicate's depths at its texels' points, the paper's
 * accuracy claim on the default scene, tessellation helping the warped-vertex map,
 * budgets and determinism; the backward analysis's and the lookup's float shortcuts
 * agreeing with the double arithmetic they stand for. Its threads' tests are with
 * spsm's in tests/property/threads.c: the two share the lent observe. */
#include "../test.h"
#include "../harness.h"
#include "../../engine/shadow/rtw/rtw.h"
#include "../../engine/shadow/common/occlude.h"

#include <math.h>
#include <stdlib.h>

static int32_t ident(uint32_t n, uint32_t k)
{
    return (int32_t)(((int64_t)k * OM_RTW_ONE + n / 2) / n);
}

static double scratch[8192], kernel[OM_RTW_MAX_RADIUS + 1];

static void uniform_is_identity(void)
{
    static const uint32_t ns[] = {8, 37, 100, 512, 1000};
    static const double vals[] = {1.0, 0.3, 1e-20, 7.5e10};
    static double I[1024];
    static int32_t P[1025];
    for (int a = 0; a < 5; a++)
        for (int b = 0; b < 4; b++)
            for (int blur = 0; blur < 2; blur++) {
                uint32_t n = ns[a];
                for (uint32_t k = 0; k < n; k++) I[k] = vals[b];
                om__rtw_blur(I, n, blur ? 3.0f : 0.0f, scratch, kernel);
                CHECK(om__rtw_table(I, n, P));
                int off = 0;
                for (uint32_t k = 0; k <= n; k++) off += om__rtw_warp_at(P, n, k) != 0 || P[k] != ident(n, k);
                CHECK_MSG(off == 0, "n %u value %g blur %d: %d entries off the identity", n, vals[b], blur, off);
                CHECK(om__rtw_max_density(P, n) < 1.0 + 1e-6);
            }
    /* with a power-of-two n the identity maps every coordinate to itself exactly */
    for (uint32_t k = 0; k <= 512; k++) I[k] = 1.0;
    CHECK(om__rtw_table(I, 512, P));
    int moved = 0;
    for (int i = 0; i <= 4000; i++) {
        double u = i / 4000.0, dens;
        moved += om__rtw_apply(P, 512, u, &dens) != u || dens != 1.0;
    }
    CHECK_EQ_U(moved, 0);
}

static uint32_t rng(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static void warps_monotonic_with_fixed_ends(void)
{
    static double I[700];
    static int32_t P[701];
    uint32_t seed = 12345;
    for (int trial = 0; trial < 40; trial++) {
        uint32_t n = 8 + rng(&seed) % 690;
        for (uint32_t k = 0; k < n; k++) {
            uint32_t r = rng(&seed);
            /* runs of zeros, tiny and huge values */
            I[k] = r % 3 == 0 ? 0.0 : r % 7 == 0 ? 1e-9 * (r % 100) : r % 11 == 0 ? 1e6 : (double)(r % 1000);
        }
        om__rtw_blur(I, n, (float)(trial % 4) * 1.5f, scratch, kernel);
        om__rtw_table(I, n, P);
        CHECK(P[0] == 0 && P[n] == OM_RTW_ONE);
        CHECK(om__rtw_warp_at(P, n, 0) == 0 && om__rtw_warp_at(P, n, n) == 0);
        int down = 0;
        for (uint32_t k = 0; k < n; k++) down += P[k + 1] < P[k];
        CHECK_EQ_U(down, 0);
        double prev = 0.0;
        int back = 0;
        for (int i = 0; i <= 5000; i++) {
            double u = om__rtw_apply(P, n, i / 5000.0, NULL);
            back += u < prev || u < 0.0 || u > 1.0;
            prev = u;
        }
        CHECK_MSG(back == 0, "trial %d: %d steps backwards", trial, back);
    }
}

static void important_cell_gets_more(void)
{
    static double I[64];
    static int32_t P[65];
    for (int blur = 0; blur < 2; blur++) {
        for (int k = 0; k < 64; k++) I[k] = 1.0;
        I[20] = 50.0;
        om__rtw_blur(I, 64, blur ? 3.0f : 0.0f, scratch, kernel);
        om__rtw_table(I, 64, P);
        int32_t w20 = P[21] - P[20], unit = OM_RTW_ONE / 64;
        CHECK_MSG(w20 > 2 * unit, "blur %d: cell 20 has %d, a uniform cell %d", blur, w20, unit);
        int wider = 0;
        for (int k = 0; k < 64; k++) wider += P[k + 1] - P[k] > w20;
        CHECK_EQ_U(wider, 0);
        /* the cells far away give up resolution */
        CHECK(P[61] - P[60] < unit);
        CHECK(om__rtw_max_density(P, 64) > 2.0);
    }
    /* zero-importance cells collapse to zero width */
    for (int k = 0; k < 64; k++) I[k] = k >= 10 && k < 20 ? 1.0 : 0.0;
    om__rtw_table(I, 64, P);
    CHECK(P[10] == 0 && P[20] == OM_RTW_ONE && P[64] == OM_RTW_ONE);
    CHECK(P[15] - P[14] == OM_RTW_ONE / 10 || P[15] - P[14] == OM_RTW_ONE / 10 + 1);
}

static void all_zero_is_safe(void)
{
    static double I[100];
    static int32_t P[101];
    for (int k = 0; k < 100; k++) I[k] = 0.0;
    om__rtw_blur(I, 100, 3.0f, scratch, kernel);
    CHECK(!om__rtw_table(I, 100, P));
    int off = 0;
    for (uint32_t k = 0; k <= 100; k++) off += P[k] != ident(100, k);
    CHECK_EQ_U(off, 0);
    double d;
    double u = om__rtw_apply(P, 100, 0.37, &d);
    CHECK(fabs(u - 0.37) < 1e-8 && fabs(d - 1.0) < 1e-6);
    /* NaN and infinity count as nothing */
    I[3] = NAN;
    I[4] = INFINITY;
    I[5] = -2.0;
    CHECK(!om__rtw_table(I, 100, P));
    I[50] = 1.0;
    CHECK(om__rtw_table(I, 100, P));
    CHECK(P[50] == 0 && P[51] == OM_RTW_ONE);
    /* outside the map (and NaN) nothing moves */
    CHECK(om__rtw_apply(P, 100, -0.25, &d) == -0.25 && d == 1.0);
    CHECK(om__rtw_apply(P, 100, 1.5, &d) == 1.5);
    CHECK(isnan(om__rtw_apply(P, 100, NAN, &d)));
}

static void collapse_by_maximum(void)
{
    static float imp[8 * 8];
    double cols[8], rows[8];
    memset(imp, 0, sizeof imp);
    imp[2 * 8 + 5] = 3.0f;   /* row 2, column 5 */
    imp[6 * 8 + 5] = 1.0f;
    imp[6 * 8 + 1] = 2.0f;
    om__rtw_collapse(imp, 8, cols, rows);
    CHECK(cols[5] == 3.0 && cols[1] == 2.0 && cols[0] == 0.0 && cols[7] == 0.0);
    CHECK(rows[2] == 3.0 && rows[6] == 2.0 && rows[0] == 0.0);
}

/* ---- whole frames, keeping the method's state for a look inside */

typedef void (*inspect_fn)(const om__rtw *m, void *user);

static om_status on_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    om_term *out = (om_term *)user;
    (void)fb;
    if (out) memcpy(out + (size_t)st->y0 * st->width, st->terms, (size_t)st->rows * st->width * sizeof *out);
    return OM_OK;
}

static om_status run_rtw(const om_scene *s, const om_method_cfg *c, uint32_t w, uint32_t h,
                         uint32_t strip, om_term *terms, inspect_fn fn, void *user)
{
    om_view v;
    om_status st = h_view(&v, s, 0, w, h, NULL);
    if (st) return st;
    const om_method *m = om_method_find("rtw");
    size_t mn, full;
    if (!m) return OM_E_NOTFOUND;
    if ((st = om_method_bytes(m, c, s, w, h, &mn, &full))) return st;
    uint32_t rows = strip ? strip : h;
    void *mm = malloc(full), *fm = malloc(h_frame_least(w, rows)), *px = malloc((size_t)w * rows * 3);
    om_arena ma, fa;
    om_arena_init(&ma, mm, full, "method");
    om_arena_init(&fa, fm, h_frame_least(w, rows), "frame");
    void *state;
    om_diag d;
    st = om_method_init(m, &state, &ma, c, s, w, h, &d);
    if (st == OM_OK) {
        om_framebuffer fb = {OM_RGB888, w, rows, (size_t)w * 3, (uint8_t *)px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, s, &v, m, state, &fb, strip);
        fd.on_strip = on_strip; fd.user = terms;
        st = om_render_frame(&fd, &fa, NULL, &d);
        if (st == OM_OK && fn) fn((const om__rtw *)state, user);
        CHECK(ma.peak <= full);   /* with the coarse depth, beyond the minimum */
    }
    if (st) fprintf(stderr, "  (run_rtw: %s)\n", d.msg);
    free(mm);
    free(fm);
    free(px);
    return st;
}

typedef struct crack_probe { uint32_t holes; double dens; uint32_t drawn; } crack_probe;

static void count_holes(const om__rtw *m, void *user)
{
    crack_probe *p = (crack_probe *)user;
    p->holes = 0;
    for (size_t i = 0; i < (size_t)m->size * m->size; i++) p->holes += m->depth[i] == 0xFFFFFFFFu;
    p->dens = m->dens_x > m->dens_y ? m->dens_x : m->dens_y;
    p->drawn = m->tris_drawn;
}

/* A floor larger than the light's frustum covers every texel of the warped map, under a
 * strong warp, with and without tessellation: a texel left empty is a crack between two
 * triangles that share an edge (the edge split in one and not in the other, or cut at
 * two different points). */
static void warped_map_has_no_cracks(void)
{
    static const char *scenes[] = {
        "camera eye 0 1.5 9 target 0 0 0 fov 60 size 160 120 near 0.1 far 100\n"
        "light directional dir 0.3 -1 0.2\n"
        "plane size 400 400 divisions 7\n"
        "box size 1 1 1 translate 0 0.5 0\n",
        "camera eye 1 2 6 target 0 0 -2 fov 70 size 160 120 near 0.1 far 100\n"
        "light spot pos 3 12 4 target 0 0 0 fov 60 near 1 far 60\n"
        "plane size 80 80 divisions 5\n"
        "sphere radius 1 segments 24 rings 12 translate 0 1 0\n",
    };
    /* the warped-vertex map at four tessellations, then the exact map */
    static const float tess[] = {0.0f, 0.05f, 0.025f, 0.01f, 0.0f};
    for (int k = 0; k < 2; k++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[k])) return;
        for (int t = 0; t < 5; t++) {
            om_method_cfg c;
            om_method_cfg_default(&c, om_method_find("rtw"));
            CHECK_OK(om_method_cfg_set(&c, "map", 256, NULL));
            CHECK_OK(om_method_cfg_set(&c, "rtw.importance", 128, NULL));
            CHECK_OK(om_method_cfg_set(&c, "rtw.tess", tess[t], NULL));
            CHECK_OK(om_method_cfg_set(&c, "rtw.exact", t == 4, NULL));
            crack_probe p;
            memset(&p, 0, sizeof p);
            CHECK_OK(run_rtw(&hs.s, &c, 160, 120, 0, NULL, count_holes, &p));
            CHECK_MSG(p.holes == 0, "scene %d tess %g exact %u: %u empty texels", k, tess[t], t == 4, p.holes);
            CHECK_MSG(p.dens > 2.0, "scene %d: the warp is too weak to test (%g)", k, p.dens);
            if (t > 0 && t < 4) CHECK(p.drawn > hs.s.ntris);
        }
        h_scene_free(&hs);
    }
}

/* The exact map, texel by texel, against the triangles on the light's grid (clipped and
 * projected as the occlusion predicate's): the nearest depth of any triangle covering
 * the texel's point (gridx[x], gridy[y]), by the same edge functions, tie rule and
 * fixed-point plane (om__rtri_zat). Back faces of closed
 * shapes count too: culling them must change no texel. */
typedef struct exact_probe { uint64_t texels, wrong, covered; uint32_t distinct_x; } exact_probe;

static void check_exact(const om__rtw *m, void *user)
{
    exact_probe *p = (exact_probe *)user;
    static uint32_t want[128 * 128];
    const uint32_t S = m->size;
    if (S > 128) { CHECK(S <= 128); return; }
    for (uint32_t i = 0; i < S * S; i++) want[i] = 0xFFFFFFFFu;
    for (uint32_t t = 0; t < m->scene->ntris; t++) {
        /* the triangle clipped and projected on the light's grid, as the predicate's */
        om_vec4 c[3];
        for (int k = 0; k < 3; k++) c[k] = om__mat_apply(&m->view.light_vp, om__sub(m->scene->verts[m->scene->idx[t * 3 + k]], m->view.origin));
        int64_t gx[9], gy[9];
        uint32_t gz[9];
        const int n = om__clip_project(c, OM_LIGHT_GRID, OM_LIGHT_GRID, gx, gy, gz);
        for (int k = 1; k + 1 < n; k++) {
            const int64_t x[3] = {gx[0], gx[k], gx[k + 1]}, y[3] = {gy[0], gy[k], gy[k + 1]};
            const uint32_t z[3] = {gz[0], gz[k], gz[k + 1]};
            om__rtri r;
            if (!om__tri2_setup(&r.e, x, y, true)) continue;
            om__rtri_zplane(&r, z);
            for (uint32_t yy = 0; yy < S; yy++)
                for (uint32_t xx = 0; xx < S; xx++)
                    if (om__tri2_covers(&r.e, m->gridx[xx], m->gridy[yy])) {
                        uint32_t d = om__rtri_zat(&r, m->gridx[xx], m->gridy[yy]);
                        if (d < want[yy * S + xx]) want[yy * S + xx] = d;
                    }
        }
    }
    for (uint32_t i = 0; i < S * S; i++) {
        p->texels++;
        p->wrong += m->depth[i] != want[i];
        p->covered += want[i] != 0xFFFFFFFFu;
    }
    p->distinct_x = 1;
    for (uint32_t x = 1; x < S; x++) {
        CHECK(m->gridx[x] >= m->gridx[x - 1] && m->gridy[x] >= m->gridy[x - 1]);
        p->distinct_x += m->gridx[x] != m->gridx[x - 1];
    }
}

static void exact_map_is_the_predicate(void)
{
    static const char *scenes[] = {
        /* a box and a sphere on a floor: closed shapes (culled), shared edges, a strong
         * warp towards the camera */
        "camera eye 1 2 6 target 0 0 -2 fov 70 size 160 120 near 0.1 far 100\n"
        "light spot pos 3 12 4 target 0 0 0 fov 60 near 1 far 60\n"
        "plane size 30 30 divisions 3\n"
        "box size 1 2 1 translate 1 1 -1\n"
        "sphere radius 1 segments 16 rings 8 translate -1 1 0\n",
        /* a directional light and random triangles, some off the map */
        "camera eye 0 4 9 target 0 0 0 fov 50 size 160 120 near 0.1 far 100\n"
        "light directional dir 0.2 -1 -0.3\n"
        "plane size 12 12\n"
        "triangles count 300 seed 3 area 20 in -7 0.2 -7 7 3 7\n",
    };
    for (int k = 0; k < 2; k++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[k])) return;
        om_method_cfg c;
        om_method_cfg_default(&c, om_method_find("rtw"));
        CHECK_OK(om_method_cfg_set(&c, "map", 128, NULL));
        CHECK_OK(om_method_cfg_set(&c, "rtw.importance", 64, NULL));
        exact_probe p;
        memset(&p, 0, sizeof p);
        CHECK_OK(run_rtw(&hs.s, &c, 160, 120, 0, NULL, check_exact, &p));
        CHECK_MSG(p.wrong == 0, "scene %d: %llu of %llu texels differ from the predicate", k,
                  (unsigned long long)p.wrong, (unsigned long long)p.texels);
        CHECK_MSG(p.covered > p.texels / 2, "scene %d: only %llu texels covered", k, (unsigned long long)p.covered);
        CHECK_MSG(p.distinct_x > 100, "scene %d: texel points coincide (%u distinct)", k, p.distinct_x);
        h_scene_free(&hs);
    }
}

static uint64_t mismatches(const uint8_t *ref, const uint8_t *m, uint32_t w, uint32_t h)
{
    om_metrics mt;
    om_compare_masks(ref, m, w, h, &mt);
    CHECK_EQ_U(mt.mismatched_bg, 0);
    return mt.false_lit + mt.false_shadowed;
}

/* Mismatches of one method on the samples of `ref` (w x h, into the scratch mask m). */
static uint64_t miss_of(const h_scene *hs, const char *name, const om_method_cfg *c, uint32_t w,
                        uint32_t h, const uint8_t *ref, uint8_t *m)
{
    CHECK_OK(h_render(&hs->s, name, c, w, h, 0, 0, m, NULL, NULL));
    return mismatches(ref, m, w, h);
}

static uint8_t claim_ref[1024 * 768], claim_m[1024 * 768];

/* The paper's claim (Figure 1): a 512 x 512 RTW map is as accurate as a 2048 x 2048
 * conventional one; for the warped-vertex map, tessellation at 2.5% beats none (Figure
 * 7), and the exact map beats both. */
static void rtw512_matches_sm2048(void)
{
    enum { w = 640, h = 480 };
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    uint8_t *ref = claim_ref, *m = claim_m;
    CHECK_OK(h_render(&hs.s, "ref", NULL, w, h, 0, 0, ref, NULL, NULL));
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("rtw"));
    CHECK_OK(om_method_cfg_set(&c, "map", 2048, NULL));
    uint64_t sm2048 = miss_of(&hs, "sm", &c, w, h, ref, m);
    CHECK_OK(om_method_cfg_set(&c, "map", 512, NULL));
    uint64_t sm512 = miss_of(&hs, "sm", &c, w, h, ref, m);
    uint64_t rtw = miss_of(&hs, "rtw", &c, w, h, ref, m);
    CHECK_OK(om_method_cfg_set(&c, "rtw.exact", 0, NULL));
    uint64_t rtw_tess = miss_of(&hs, "rtw", &c, w, h, ref, m);
    CHECK_OK(om_method_cfg_set(&c, "rtw.tess", 0.0f, NULL));
    uint64_t rtw_flat = miss_of(&hs, "rtw", &c, w, h, ref, m);
    CHECK_MSG(rtw <= sm2048, "rtw 512: %llu mismatches, sm 2048: %llu", (unsigned long long)rtw,
              (unsigned long long)sm2048);
    CHECK_MSG(rtw_tess <= sm2048, "rtw 512 warped vertices, 2.5%%: %llu mismatches, sm 2048: %llu",
              (unsigned long long)rtw_tess, (unsigned long long)sm2048);
    CHECK_MSG(rtw_tess < rtw_flat, "tessellated %llu, not fewer than untessellated %llu",
              (unsigned long long)rtw_tess, (unsigned long long)rtw_flat);
    /* the exact map needs no tessellation: far better than the untessellated warped
     * vertices, about as good as tessellating them */
    CHECK_MSG(rtw * 4 < rtw_flat, "exact %llu, untessellated warped vertices %llu", (unsigned long long)rtw,
              (unsigned long long)rtw_flat);
    CHECK_MSG(rtw * 20 < rtw_tess * 21, "exact %llu, warped vertices at 2.5%% %llu", (unsigned long long)rtw,
              (unsigned long long)rtw_tess);
    CHECK(rtw * 2 < sm512);

    /* The same claim at the benchmark's 1024x768, where the view asks more of the map:
     * the backward analysis alone falls short there (0.50% against 0.38%), the hybrid
     * one with the shadow-edge function (section 5.3) keeps the promise. */
    enum { W = 1024, H = 768 };
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, ref, NULL, NULL));
    om_method_cfg_default(&c, om_method_find("rtw"));
    CHECK_OK(om_method_cfg_set(&c, "map", 2048, NULL));
    sm2048 = miss_of(&hs, "sm", &c, W, H, ref, m);
    CHECK_OK(om_method_cfg_set(&c, "map", 512, NULL));
    CHECK_OK(om_method_cfg_set(&c, "rtw.analysis", OM_RTW_HYBRID, NULL));
    CHECK_OK(om_method_cfg_set(&c, "rtw.funcs", OM_RTW_DV | OM_RTW_DIST | OM_RTW_EDGE | OM_RTW_NORMAL, NULL));
    rtw = miss_of(&hs, "rtw", &c, W, H, ref, m);
    CHECK_MSG(rtw <= sm2048, "at 1024x768, rtw 512 hybrid: %llu mismatches, sm 2048: %llu",
              (unsigned long long)rtw, (unsigned long long)sm2048);
    h_scene_free(&hs);
}

/* Every analysis and every single importance function renders and, on the default
 * scene, beats the conventional map of the same size; with every function off the
 * tables are the identity. */
typedef struct table_probe { int off; double dens_x, dens_y; } table_probe;

static void probe_tables(const om__rtw *m, void *user)
{
    table_probe *p = (table_probe *)user;
    p->off = 0;
    for (uint32_t k = 0; k <= m->n; k++) p->off += m->px[k] != ident(m->n, k) || m->py[k] != ident(m->n, k);
    p->dens_x = m->dens_x;
    p->dens_y = m->dens_y;
}

static void analyses_and_functions(void)
{
    enum { w = 320, h = 240 };
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    static uint8_t ref[w * h], m[w * h];
    CHECK_OK(h_render(&hs.s, "ref", NULL, w, h, 0, 0, ref, NULL, NULL));
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("rtw"));
    CHECK_OK(om_method_cfg_set(&c, "map", 512, NULL));
    CHECK_OK(h_render(&hs.s, "sm", &c, w, h, 0, 0, m, NULL, NULL));
    uint64_t sm = mismatches(ref, m, w, h);
    static const struct { uint32_t analysis, funcs; } runs[] = {
        {0, 1}, {0, 1 | 2}, {0, 1 | 8}, {0, 1 | 2 | 8}, {1, 1 | 2 | 4 | 8}, {1, 1 | 2},
        {2, 1 | 2 | 4}, {2, 1 | 2 | 4 | 8},
    };
    for (size_t k = 0; k < sizeof runs / sizeof runs[0]; k++) {
        CHECK_OK(om_method_cfg_set(&c, "rtw.analysis", runs[k].analysis, NULL));
        CHECK_OK(om_method_cfg_set(&c, "rtw.funcs", runs[k].funcs, NULL));
        CHECK_OK(h_render(&hs.s, "rtw", &c, w, h, 0, 0, m, NULL, NULL));
        uint64_t bad = mismatches(ref, m, w, h);
        CHECK_MSG(bad < sm, "analysis %u funcs %u: %llu mismatches, sm 512 %llu", runs[k].analysis,
                  runs[k].funcs, (unsigned long long)bad, (unsigned long long)sm);
    }
    table_probe p;
    memset(&p, 0, sizeof p);   /* the probe may not be called: then the checks fail, on zeros */
    CHECK_OK(om_method_cfg_set(&c, "rtw.analysis", 0, NULL));
    CHECK_OK(om_method_cfg_set(&c, "rtw.funcs", 0, NULL));
    CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, NULL, probe_tables, &p));
    CHECK_EQ_U(p.off, 0);
    CHECK_OK(om_method_cfg_set(&c, "rtw.funcs", 1, NULL));
    CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, NULL, probe_tables, &p));
    CHECK(p.off > 0 && p.dens_x > 1.5 && p.dens_y > 1.5);
    h_scene_free(&hs);
}

static void budget_and_determinism(void)
{
    enum { w = 160, h = 120 };
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    const om_method *m = om_method_find("rtw");
    CHECK(m != NULL);
    if (!m) return;
    for (uint32_t analysis = 0; analysis < 3; analysis++) {
        om_method_cfg c;
        om_method_cfg_default(&c, om_method_find("rtw"));
        CHECK_OK(om_method_cfg_set(&c, "map", 256, NULL));
        CHECK_OK(om_method_cfg_set(&c, "rtw.importance", 64, NULL));
        CHECK_OK(om_method_cfg_set(&c, "rtw.analysis", analysis, NULL));
        size_t mn, full;
        CHECK_OK(om_method_bytes(m, &c, &hs.s, w, h, &mn, &full));
        CHECK(mn < full && mn >= 256 * 256 * 4);
        unsigned char *buf = malloc(mn + 64);
        memset(buf, 0xC3, mn + 64);
        om_arena a;
        om_arena_init(&a, buf + 32, mn - 1, "method");
        void *state;
        om_diag d;
        CHECK(om_method_init(m, &state, &a, &c, &hs.s, w, h, &d) == OM_E_BUDGET);
        CHECK_EQ_U(a.used, 0);
        char num[32];
        snprintf(num, sizeof num, "%zu", mn);
        CHECK_MSG(strstr(d.msg, num) != NULL, "'%s' does not name %s", d.msg, num);
        int guard = 0;
        for (int i = 0; i < 32; i++) guard += buf[i] != 0xC3 || buf[32 + mn + i] != 0xC3;
        CHECK_EQ_U(guard, 0);
        free(buf);
    }
    /* identical runs, and the frame through strips, give the same bits */
    static om_term t1[w * h], t2[w * h], t3[w * h];
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("rtw"));
    CHECK_OK(om_method_cfg_set(&c, "map", 512, NULL));
    for (uint32_t k = 0; k < 6; k++) {
        CHECK_OK(om_method_cfg_set(&c, "rtw.analysis", k % 3, NULL));
        CHECK_OK(om_method_cfg_set(&c, "rtw.exact", k / 3, NULL));
        CHECK_OK(om_method_cfg_set(&c, "rtw.funcs", 15, NULL));
        CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, t1, NULL, NULL));
        CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, t2, NULL, NULL));
        CHECK_OK(run_rtw(&hs.s, &c, w, h, 7, t3, NULL, NULL));
        CHECK(!memcmp(t1, t2, sizeof t1));
        CHECK(!memcmp(t1, t3, sizeof t1));
    }
    /* settings out of range are refused cleanly, and keep the value they had */
    double v = 0;
    CHECK(om_method_cfg_set(&c, "rtw.sigma", NAN, NULL) == OM_E_RANGE);
    CHECK(om_method_cfg_get(&c, "rtw.sigma", &v) == OM_OK && v == 3.0);
    CHECK(om_method_cfg_set(&c, "rtw.analysis", 3, NULL) == OM_E_RANGE);
    CHECK(om_method_cfg_set(&c, "rtw.exact", 2, NULL) == OM_E_RANGE);
    CHECK(om_method_cfg_set(&c, "rtw.footprint", 2, NULL) == OM_E_RANGE);
    CHECK(om_method_cfg_set(&c, "rtw.sigma", 0.5, NULL) == OM_OK);
    /* as is a configuration made for another method */
    void *state;
    om_arena a;
    static unsigned char small[64];
    om_arena_init(&a, small, sizeof small, "method");
    om_method_cfg other;
    om_method_cfg_default(&other, om_method_find("sm"));
    CHECK(om_method_init(m, &state, &a, &other, &hs.s, w, h, NULL) == OM_E_INVALID);
    h_scene_free(&hs);
}

/* Section 6.2: PCF taps one warped texel apart follow the map's local resolution (a
 * narrow filter where the warp magnifies), taps one unwarped texel apart keep the
 * filter's area in the light's image, that of a conventional map of the same size.
 * Counted in partly lit samples (0 < term < 255) on the default scene: the unwarped
 * footprint's penumbrae are as wide as sm's (within 20%), the warped one's less than
 * half as wide; with a single tap the footprint changes nothing. */
static om_term pcf_terms[3][320 * 240];

static uint32_t partly_lit(const om_term *t, size_t n)
{
    uint32_t k = 0;
    for (size_t i = 0; i < n; i++) k += (t[i].flags & OM_TERM_EXPOSED) && t[i].r > 0 && t[i].r < 255;
    return k;
}

static void pcf_footprints(void)
{
    enum { w = 320, h = 240 };
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("rtw"));
    CHECK_OK(om_method_cfg_set(&c, "map", 1024, NULL));
    CHECK_OK(om_method_cfg_set(&c, "pcf", 1, NULL));
    CHECK_OK(om_method_cfg_set(&c, "rtw.footprint", 1, NULL));
    CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, pcf_terms[0], NULL, NULL));
    CHECK_OK(om_method_cfg_set(&c, "rtw.footprint", 0, NULL));
    CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, pcf_terms[1], NULL, NULL));
    CHECK(memcmp(pcf_terms[0], pcf_terms[1], sizeof pcf_terms[0]) == 0);
    CHECK_OK(om_method_cfg_set(&c, "pcf", 3, NULL));
    CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, pcf_terms[0], NULL, NULL));
    CHECK_OK(om_method_cfg_set(&c, "rtw.footprint", 1, NULL));
    CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, pcf_terms[1], NULL, NULL));
    CHECK_OK(h_render(&hs.s, "sm", &c, w, h, 0, 0, NULL, pcf_terms[2], NULL));
    uint32_t warped = partly_lit(pcf_terms[0], w * h), unwarped = partly_lit(pcf_terms[1], w * h),
             sm = partly_lit(pcf_terms[2], w * h);
    /* measured: 830, 2,351 and 2,473 */
    CHECK_MSG(unwarped > 2 * warped, "unwarped taps: %u partly lit samples, warped: %u", unwarped, warped);
    CHECK_MSG(10 * unwarped > 8 * sm && 10 * unwarped < 12 * sm, "unwarped taps: %u partly lit samples, sm: %u",
              unwarped, sm);
    h_scene_free(&hs);
}

/* The importance map's default side is 512, or the map's when that is smaller: the
 * same bytes and frames as asking for that side, and a small map's budget is not
 * spent on a 1 MB importance map. */
static void importance_follows_small_maps(void)
{
    enum { w = 160, h = 120 };
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    const om_method *m = om_method_find("rtw");
    CHECK(m != NULL);
    if (!m) return;
    static const uint32_t maps[] = {4, 128, 512, 1024};
    static const uint32_t sides[] = {8, 128, 512, 512};
    for (int i = 0; i < 4; i++) {
        om_method_cfg c;
        om_method_cfg_default(&c, om_method_find("rtw"));
        double side = -1;
        CHECK(om_method_cfg_get(&c, "rtw.importance", &side) == OM_OK && side == 0);
        CHECK_OK(om_method_cfg_set(&c, "map", maps[i], NULL));
        size_t mn0, full0, mn1, full1;
        CHECK_OK(om_method_bytes(m, &c, &hs.s, w, h, &mn0, &full0));
        if (maps[i] <= 128) CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, pcf_terms[0], NULL, NULL));
        CHECK_OK(om_method_cfg_set(&c, "rtw.importance", sides[i], NULL));
        CHECK_OK(om_method_bytes(m, &c, &hs.s, w, h, &mn1, &full1));
        CHECK_MSG(mn0 == mn1, "map %u: %zu bytes by default, %zu with importance %u", maps[i], mn0, mn1, sides[i]);
        if (maps[i] <= 128) {
            CHECK_OK(run_rtw(&hs.s, &c, w, h, 0, pcf_terms[1], NULL, NULL));
            CHECK(memcmp(pcf_terms[0], pcf_terms[1], (size_t)w * h * sizeof pcf_terms[0][0]) == 0);
        }
    }
    h_scene_free(&hs);
}

/* The backward analysis's cell in float (om__rtw_cell_axis) is the one its double
 * arithmetic gives whenever it answers: at random, next to cell edges (a few float
 * steps either side) and at the map's ends, for several importance sides. */
static void float_cell_is_the_double_one(void)
{
    static const uint32_t ns[] = {8, 64, 100, 512, 8192};
    uint32_t s = 7;
    unsigned long long wrong = 0, edge_answered = 0, random = 0, random_unsure = 0;
    for (int a = 0; a < 5; a++) {
        const uint32_t n = ns[a];
        const float nf = (float)n, hn = 0.5f * nf;
        for (int it = 0; it < 40000; it++) {
            const float w = 0.01f + (float)(rng(&s) % 100000) / 1000.0f;
            float x;
            const bool at_random = it % 4 == 0;
            if (at_random) {
                x = ((float)(rng(&s) % 2000001) / 1000000.0f - 1.0f) * 1.25f * w;
            } else {   /* cell edge e (from one before the map to one after), then steps */
                const int e = (int)(rng(&s) % (n + 3)) - 1;
                x = (float)((2.0 * e / n - 1.0) * w);
                for (int j = (int)(rng(&s) % 81) - 40; j; j += j < 0 ? 1 : -1)
                    x = nextafterf(x, j < 0 ? -INFINITY : INFINITY);
            }
            const int32_t got = om__rtw_cell_axis(x * (1.0f / w), hn, nf);
            const double u = ((double)x * (1.0 / (double)w) + 1.0) * 0.5;
            int32_t want = -1;
            if (u >= 0.0 && u <= 1.0) {
                const uint32_t i = (uint32_t)(u * (double)n);
                want = (int32_t)(i > n - 1 ? n - 1 : i);
            }
            if (got != -2) {
                wrong += got != want;
                edge_answered += !at_random;
            }
            random += at_random;
            random_unsure += at_random && got == -2;
            if (got != -2 && got != want && wrong < 5)
                fprintf(stderr, "  n %u x %a w %a: float cell %d, double %d\n", n, (double)x, (double)w, got, want);
        }
    }
    CHECK_EQ_U(wrong, 0);
    CHECK(edge_answered > 0);   /* not every near-edge sample falls back */
    CHECK_MSG(random_unsure * 200 < random, "%llu of %llu random samples fell back", random_unsure, random);
}

/* The bound the backward analysis skips samples by (om__rtw_importance_above) never
 * skips one whose importance exceeds the cell's: just below each sample's own
 * importance it must answer yes, and it should answer no a little above. */
static void importance_bound_holds(const om__rtw *m, void *user)
{
    unsigned long long *no_above = (unsigned long long *)user;
    const om_view *v = &m->view;
    uint32_t s = 11;
    unsigned long long wrong = 0;
    for (unsigned funcs = 0; funcs < 16; funcs++)
        for (int it = 0; it < 4000; it++) {
            /* points around the scene, many near the camera's near plane and far away */
            const float sc = it % 3 == 0 ? 0.05f : it % 3 == 1 ? 5.0f : 200.0f;
            om_vec3 p = om__v3(v->cam.eye.x + ((float)(rng(&s) % 20001) / 10000.0f - 1.0f) * sc,
                               v->cam.eye.y + ((float)(rng(&s) % 20001) / 10000.0f - 1.0f) * sc,
                               v->cam.eye.z + ((float)(rng(&s) % 20001) / 10000.0f - 1.0f) * sc);
            om_vec3 n = om__v3((float)(rng(&s) % 2001) / 1000.0f - 1.0f, (float)(rng(&s) % 2001) / 1000.0f - 1.0f,
                               (float)(rng(&s) % 2001) / 1000.0f - 1.0f);
            const float imp = om__rtw_point_importance(v, funcs, p, n);
            if (imp > 0.0f) wrong += !om__rtw_importance_above(v, funcs, p, n, nextafterf(imp, 0.0f));
            *no_above += !om__rtw_importance_above(v, funcs, p, n, imp * 1.001f);
        }
    CHECK_EQ_U(wrong, 0);
}

static void importance_bound(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("rtw"));
    CHECK_OK(om_method_cfg_set(&c, "map", 64, NULL));
    unsigned long long no_above = 0;
    CHECK_OK(run_rtw(&hs.s, &c, 64, 48, 0, NULL, importance_bound_holds, &no_above));
    CHECK(no_above > 16 * 4000 / 2);
    h_scene_free(&hs);
}

/* The lookup's bias texel in float (om__rtw_div_dens) is smlookup.c's double
 * quotient whenever it answers: at random and for quotients next to halfway between
 * two floats, over the densities a table can hold. */
static void float_division_is_the_double_one(void)
{
    uint32_t s = 5;
    unsigned long long wrong = 0, random = 0, random_unsure = 0;
    for (int it = 0; it < 400000; it++) {
        uint64_t D = (1ull << 24) + (((uint64_t)rng(&s) << 20 | rng(&s)) >> (rng(&s) % 44));
        float t;
        const bool at_random = it % 2 == 0;
        if (at_random) {
            t = (float)(rng(&s) % 1000000 + 1) * 1e-5f * (float)(1u << (rng(&s) % 8));
        } else {   /* D near 2^43 picked so that the quotient is within about 2^-44 of
                      halfway between two floats (within 2^-53, where the double's own
                      rounding decides, now and then) */
            const float q = (float)(rng(&s) % 1000000 + 1) * 1e-4f;
            const double mid = ((double)q + (double)nextafterf(q, INFINITY)) * 0.5;
            t = (float)(mid * (double)((1ull << 42) + ((uint64_t)rng(&s) << 18)) / OM_RTW_ONE);
            D = (uint64_t)floor((double)t * OM_RTW_ONE / mid + 0.5);
        }
        const double dens = (double)D / (double)OM_RTW_ONE;
        float rcp[2];
        om__rtw_rcp(D, rcp);
        const float got = om__rtw_div_dens(t, rcp), want = (float)((double)t / dens);
        if (got >= 0.0f) {
            wrong += got != want;
            if (got != want && wrong < 5)
                fprintf(stderr, "  t %a D %llu: float %a, double %a\n", (double)t, (unsigned long long)D,
                        (double)got, (double)want);
        }
        random += at_random;
        random_unsure += at_random && got < 0.0f;
    }
    CHECK_EQ_U(wrong, 0);
    CHECK_MSG(random_unsure * 1000 < random, "%llu of %llu random quotients fell back", random_unsure, random);
}

/* The lookup's warped texel in float (om__rtw_texel_axis) is smlookup.c's double warp
 * whenever it answers: at random and a few float steps from texel edges, over tables
 * of random importance. */
static void float_warp_is_the_double_one(void)
{
    static const uint32_t ns[] = {8, 64, 512};
    static const uint32_t sizes[] = {96, 1000, 4096};
    static double I[512];
    static int32_t P[513];
    uint32_t s = 9;
    unsigned long long wrong = 0, random = 0, random_unsure = 0, edge_answered = 0;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            const uint32_t n = ns[a], size = sizes[b];
            for (uint32_t k = 0; k < n; k++) I[k] = rng(&s) % 4 == 0 ? 0.0 : (double)(rng(&s) % 1000) + 1.0;
            om__rtw_table(I, n, P);
            for (int it = 0; it < 20000; it++) {
                const float w = 0.01f + (float)(rng(&s) % 100000) / 1000.0f;
                float x;
                const bool at_random = it % 4 == 0;
                if (at_random) {
                    x = ((float)(rng(&s) % 2000001) / 1000000.0f - 1.0f) * w;
                } else {   /* the unwarped point of texel edge j, then a few float steps */
                    const double c = (double)(rng(&s) % (size + 1)) / size * OM_RTW_ONE;
                    uint32_t k = 0;
                    while (k + 1 < n && P[k + 1] <= c) k++;
                    const double f = P[k + 1] > P[k] ? (c - P[k]) / (P[k + 1] - P[k]) : 0.0;
                    const int j = (int)(rng(&s) % (2u << (rng(&s) % 16))) - (1 << (rng(&s) % 16));
                    x = (float)((2.0 * ((double)k + f) / n - 1.0) * w * (1.0 + j * 0x1p-24));
                }
                uint32_t kk = 0;
                const int32_t got = om__rtw_texel_axis(P, n, size, x * (1.0f / w), &kk);
                const double u = ((double)x * (1.0 / (double)w) + 1.0) * 0.5;
                if (got >= 0) {
                    double dens;
                    const double X = om__rtw_apply(P, n, u, &dens) * size;
                    const uint32_t want_k = (uint32_t)(u * n) > n - 1 ? n - 1 : (uint32_t)(u * n);
                    const bool bad = !(u > 0.0 && u < 1.0) || got != (int32_t)floor(X) || kk != want_k ||
                                     dens != (double)(P[kk + 1] - P[kk]) * n / OM_RTW_ONE;
                    wrong += bad;
                    edge_answered += !at_random;
                    if (bad && wrong < 5)
                        fprintf(stderr, "  n %u size %u x %a w %a: float texel %d, double %.17g\n", n, size,
                                (double)x, (double)w, got, X);
                }
                random += at_random;
                random_unsure += at_random && got < 0;
            }
        }
    CHECK_EQ_U(wrong, 0);
    CHECK(edge_answered > 1000);
    /* the margin grows with a super-cell's magnification: these random tables reach
     * 100x and more, real ones fall back far less (the lookup test) */
    CHECK_MSG(random_unsure * 20 < random, "%llu of %llu random samples fell back", random_unsure, random);
}

/* The float lookup gives smlookup.c's terms and counts, on samples on the floor
 * (where the bias decides) and anywhere in the scene, after a frame's map. */
typedef struct lookup_probe { unsigned long long differ, shadowed, lit; float extent; } lookup_probe;

static void lookup_is_smlookups(const om__rtw *m, void *user)
{
    lookup_probe *pr = (lookup_probe *)user;
    enum { N = 4096 };
    static om_sample smp[N];
    static om_term a[N], b[N];
    uint32_t s = 3;
    for (int round = 0; round < 8; round++) {
        for (int i = 0; i < N; i++) {
            const bool floor_pt = i % 2 == 0;
            const float x = ((float)(rng(&s) % 20001) / 10000.0f - 1.0f) * pr->extent;
            const float z = ((float)(rng(&s) % 20001) / 10000.0f - 1.0f) * pr->extent;
            const float y = floor_pt ? 0.0f : (float)(rng(&s) % 10001) / 10000.0f * 4.0f;
            /* relative to the view's origin */
            smp[i].p[0] = x - m->view.origin.x; smp[i].p[1] = y - m->view.origin.y; smp[i].p[2] = z - m->view.origin.z;
            smp[i].n[0] = 0.0f; smp[i].n[1] = 1.0f; smp[i].n[2] = 0.0f;
            smp[i].tri = 0;
            smp[i].nl = (float)(rng(&s) % 10001) / 10000.0f;
            a[i].flags = b[i].flags = rng(&s) % 8 ? OM_TERM_EXPOSED : 0;
        }
        om_strip sa = {N, 1, 0, 1, smp, a, m->view.origin}, sb = {N, 1, 0, 1, smp, b, m->view.origin};
        uint32_t na = 0, sha = 0, nb = 0, shb = 0;
        om__rtw_lookup_strip(m, &sa, &na, &sha);
        om__smlook_strip(&m->look, &sb, &nb, &shb);
        pr->differ += na != nb || sha != shb || memcmp(a, b, sizeof a) != 0;
        pr->shadowed += shb;
        pr->lit += nb - shb;
    }
}

static void float_lookup_is_smlookups(void)
{
    static const char *dir_scene =
        "camera eye 0 3 6 target 0 0 0 size 160 120\nlight directional dir -0.3 -1 -0.2\n"
        "plane size 16 16\ntriangles count 3000 seed 9 area 12 in -2 0.5 -2 2 2 2\n";
    for (int sc = 0; sc < 2; sc++) {
        h_scene hs;
        if (!h_scene_parse(&hs, sc ? dir_scene : om_scene_default_text())) return;
        static const uint32_t maps[] = {96, 1024};
        for (int k = 0; k < 2; k++) {
            om_method_cfg c;
            om_method_cfg_default(&c, om_method_find("rtw"));
            CHECK_OK(om_method_cfg_set(&c, "map", maps[k], NULL));
            CHECK_OK(om_method_cfg_set(&c, "rtw.importance", k ? 0 : 64, NULL));
            lookup_probe pr = {0, 0, 0, sc ? 2.5f : 8.0f};
            CHECK_OK(run_rtw(&hs.s, &c, 160, 120, 0, NULL, lookup_is_smlookups, &pr));
            CHECK_MSG(pr.differ == 0, "scene %d map %u: %llu strips differ", sc, maps[k], pr.differ);
            CHECK_MSG(pr.shadowed > 1000 && pr.lit > 1000, "scene %d map %u: %llu shadowed, %llu lit", sc,
                      maps[k], pr.shadowed, pr.lit);
        }
        h_scene_free(&hs);
    }
}

/* The default scene drawn a thousand times smaller or larger keeps its shadows: the
 * settings' units scale with the scene. */
static void rtw_bias_is_scale_free(void) { h_check_scale_free("rtw", 320, 240); }

void suite_rtw(void)
{
    RUN(rtw_bias_is_scale_free);
    RUN(uniform_is_identity);
    RUN(warps_monotonic_with_fixed_ends);
    RUN(important_cell_gets_more);
    RUN(all_zero_is_safe);
    RUN(collapse_by_maximum);
    RUN(warped_map_has_no_cracks);
    RUN(exact_map_is_the_predicate);
    RUN(rtw512_matches_sm2048);
    RUN(analyses_and_functions);
    RUN(budget_and_determinism);
    RUN(pcf_footprints);
    RUN(importance_follows_small_maps);
    RUN(float_cell_is_the_double_one);
    RUN(importance_bound);
    RUN(float_division_is_the_double_one);
    RUN(float_warp_is_the_double_one);
    RUN(float_lookup_is_smlookups);
}
