/* unit/hiz.c — the coarse depth of depth-only targets (om__hiz_words, hiz.c):
 * maps drawn with it hold exactly the bits drawn without it, over random and
 * adversarial triangles (huge ones through one point, as the slow scene of issue 24
 * makes them; flat ties; depths at 0 and 2^32 - 1; steep slivers at the slopes' limit;
 * small ones between), at pixel centres and on rectilinear grids, whole and by bands;
 * its bounds stay above every stored depth; and a scene's light map of 300 huge
 * triangles is the same through om__scene_raster_hiz. */
#include "../test.h"
#include "../../engine/raster/scene_raster.h"
#include "../../engine/scene/scene.h"
#include "../scene_util.h"
#include "../harness.h"

#include <stdlib.h>
#include <string.h>

enum { HW = 300, HH = 200, NTRI = 160 };

static uint64_t rng_state;
static uint32_t rnd(void)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(rng_state >> 33);
}

static uint32_t plain[HW * HH], coarse[HW * HH], hiz_buf[4096];
static int64_t tx[NTRI][3], ty[NTRI][3];
static uint32_t tz[NTRI][3];

static uint32_t clamp_z(double z)
{
    return z <= 0.0 ? 0u : z >= 4294967295.0 ? 0xFFFFFFFFu : (uint32_t)z;
}

/* One round's triangles, in sub-pixel units of an HW x HH image. */
static void make_tris(int round)
{
    const double S = OM_SUBPIX;
    const double cx = (double)(rnd() % HW) * S, cy = (double)(rnd() % HH) * S, cz = 2147483648.0;
    if (round % 8 == 5) {   /* one tilted plane over the whole image, a unit nearer a step:
                             * every triangle writes every texel, where a bound one too high
                             * would skip them all; then the same plane again (ties) */
        /* flat, or tilted by under a unit a tile (fractional slopes of either sign) */
        const double u = round % 16 == 5 ? 0.0 : 1.0 / 65536.0;
        const double gx = ((double)(rnd() % 9) - 4.0) * u, gy = ((double)(rnd() % 9) - 4.0) * u;
        const int64_t X[3] = {-HW * OM_SUBPIX, 3 * HW * OM_SUBPIX, -HW * OM_SUBPIX};
        const int64_t Y[3] = {-HH * OM_SUBPIX, HH * OM_SUBPIX / 2, 3 * HH * OM_SUBPIX};
        for (int k = 0; k < NTRI; k++)
            for (int i = 0; i < 3; i++) {
                tx[k][i] = X[i];
                ty[k][i] = Y[i];
                tz[k][i] = clamp_z(cz - (k < NTRI - 8 ? k : NTRI - 9) + gx * ((double)X[i] - cx) + gy * ((double)Y[i] - cy));
            }
        return;
    }
    for (int k = 0; k < NTRI; k++) {
        int64_t *x = tx[k], *y = ty[k];
        uint32_t *z = tz[k];
        const int kind = (k + round) % 6;
        if (kind <= 1) {         /* huge, through one point: the slow scene's shape */
            const double gx = ((double)(rnd() % 2001) - 1000.0) * 4.0, gy = ((double)(rnd() % 2001) - 1000.0) * 4.0;
            for (int i = 0; i < 3; i++) {
                x[i] = (int64_t)(cx + ((double)(rnd() % 4001) - 2000.0) * S);
                y[i] = (int64_t)(cy + ((double)(rnd() % 4001) - 2000.0) * S);
                z[i] = clamp_z(cz + gx * ((double)x[i] - cx) + gy * ((double)y[i] - cy));
            }
        } else if (kind == 2) {  /* huge and flat: ties, both ends, and a stair down by
                                  * one unit a step, where a bound one too high shows */
            static const uint32_t flat[4] = {0u, 0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu};
            const uint32_t f = rnd() % 4 ? 0xC0000000u - (uint32_t)k : rnd() % 2 ? flat[rnd() % 4] : (uint32_t)rnd();
            for (int i = 0; i < 3; i++) {
                x[i] = (int64_t)((double)(rnd() % (3 * HW)) * S) - HW * OM_SUBPIX;
                y[i] = (int64_t)((double)(rnd() % (3 * HH)) * S) - HH * OM_SUBPIX;
                z[i] = f;
            }
        } else if (kind == 3) {  /* long diagonal slivers, the whole depth range across 1 to
                                  * 64 units: slopes either side of the coarse path's limit */
            const int64_t w = 1 + (int64_t)(rnd() % 64);
            x[0] = -(int64_t)(rnd() % 2000); y[0] = -(int64_t)(rnd() % 2000);
            x[1] = HW * OM_SUBPIX + (int64_t)(rnd() % 2000); y[1] = HH * OM_SUBPIX + (int64_t)(rnd() % 2000);
            if (rnd() % 2) { y[0] = HH * OM_SUBPIX - y[0]; y[1] = HH * OM_SUBPIX - y[1]; }
            x[2] = x[0] + (rnd() % 2 ? w : -w); y[2] = y[0] + (rnd() % 2 ? w : -w);
            z[0] = rnd() % 2 ? 0u : 0xFFFFFFFFu;
            z[1] = (uint32_t)rnd();
            z[2] = ~z[0];
        } else if (kind == 4) {  /* large, random depths */
            for (int i = 0; i < 3; i++) {
                x[i] = (int64_t)(rnd() % (HW * OM_SUBPIX * 2)) - HW * OM_SUBPIX / 2;
                y[i] = (int64_t)(rnd() % (HH * OM_SUBPIX * 2)) - HH * OM_SUBPIX / 2;
                z[i] = (uint32_t)rnd();
            }
        } else {                 /* small, for the plain path between */
            const int64_t ox = (int64_t)(rnd() % (HW * OM_SUBPIX)), oy = (int64_t)(rnd() % (HH * OM_SUBPIX));
            for (int i = 0; i < 3; i++) {
                x[i] = ox + (int64_t)(rnd() % 6000);
                y[i] = oy + (int64_t)(rnd() % 6000);
                z[i] = (uint32_t)rnd() >> (rnd() % 4);
            }
        }
    }
}

/* Draws the round's triangles into `depth` as bands of `band` rows (0: whole), with
 * the coarse depth or without. */
static void draw(uint32_t *depth, bool with_hiz, uint32_t band, const int64_t *gx, const int64_t *gy)
{
    for (uint32_t y0 = 0; y0 < HH; y0 += band ? band : HH) {
        om_target t = {HW, HH, y0, band && y0 + band < HH ? band : HH - y0, depth + (size_t)y0 * HW, NULL};
        om_raster r = {&t, OM_RASTER_DEPTH, NULL, NULL, NULL, NULL, 0, false, gx, gy, NULL, NULL, 0, 0, NULL, 0};
        om__target_clear(&t);
        om__hiz_clear(with_hiz ? hiz_buf : NULL, &t);
        for (int k = 0; k < NTRI; k++)
            om__raster_snapped_hiz(&r, with_hiz ? hiz_buf : NULL, tx[k], ty[k], tz[k], (uint32_t)k);
    }
}

/* Every first-level bound is at least its tile's largest depth; returns how many are
 * below 2^32 - 1 (tightened by a large triangle). */
static int bounds_hold(const uint32_t *depth, int *bad)
{
    const uint32_t n1 = (HW + 7) / 8;
    int tight = 0;
    for (uint32_t Y = 0; Y < (HH + 7) / 8; Y++)
        for (uint32_t X = 0; X < n1; X++) {
            uint32_t m = 0;
            for (uint32_t y = Y * 8; y < Y * 8 + 8 && y < HH; y++)
                for (uint32_t x = X * 8; x < X * 8 + 8 && x < HW; x++) m = depth[y * HW + x] > m ? depth[y * HW + x] : m;
            *bad += hiz_buf[Y * n1 + X] < m;
            tight += hiz_buf[Y * n1 + X] != 0xFFFFFFFFu;
        }
    return tight;
}

static void hiz_same_texels(void)
{
    CHECK(om__hiz_words(HW, HH) <= sizeof hiz_buf / sizeof hiz_buf[0]);
    static int64_t gx[HW], gy[HH];
    rng_state = 2024;
    int diff = 0, bad = 0, tight = 0, written = 0;
    for (int round = 0; round < 32; round++) {
        make_tris(round);
        const int64_t *px = NULL, *py = NULL;
        if (round % 3 == 2) {   /* a rectilinear grid: uneven steps, some repeated points */
            int64_t g = -(int64_t)(rnd() % 3000);
            for (int i = 0; i < HW; i++) { gx[i] = g; g += rnd() % 4 ? (int64_t)(rnd() % 520) : 0; }
            g = -(int64_t)(rnd() % 3000);
            for (int i = 0; i < HH; i++) { gy[i] = g; g += rnd() % 4 ? (int64_t)(rnd() % 520) : 0; }
            px = gx;
            py = gy;
        }
        /* whole, then bands of 16 and 48 rows, then bands the tiles do not fit (the
         * coarse depth is then left alone) */
        const uint32_t band = round % 4 == 0 ? 0 : round % 4 == 1 ? 16 : round % 4 == 2 ? 48 : 24;
        draw(plain, false, 0, px, py);
        draw(coarse, true, band, px, py);
        for (int i = 0; i < HW * HH; i++) {
            diff += plain[i] != coarse[i];
            written += plain[i] != 0xFFFFFFFFu;
        }
        if (band != 24) tight += bounds_hold(coarse, &bad);
    }
    CHECK_EQ_U(diff, 0);
    CHECK_EQ_U(bad, 0);
    CHECK(tight > 1000);                 /* the coarse path ran and tightened tiles */
    CHECK(written > 32 * HW * HH / 2);
}

/* Through the clipper: huge triangles that cross the near and far planes and the guard
 * band, on a target whose size is no multiple of any tile. */
static void hiz_clipped_huge(void)
{
    rng_state = 99;
    int diff = 0;
    for (int round = 0; round < 6; round++) {
        static om_vec4 c[NTRI][3];
        for (int k = 0; k < NTRI; k++)
            for (int i = 0; i < 3; i++) {
                c[k][i].x = (float)((double)(rnd() % 20001) - 10000.0) / 100.0f;
                c[k][i].y = (float)((double)(rnd() % 20001) - 10000.0) / 100.0f;
                c[k][i].w = (float)(rnd() % 1000) / 100.0f + 0.01f;
                c[k][i].z = c[k][i].w * ((float)((double)(rnd() % 3001) - 1000.0) / 1000.0f);
            }
        for (int pass = 0; pass < 2; pass++) {
            om_target t = {HW, HH, 0, HH, pass ? coarse : plain, NULL};
            om_raster r = {&t, OM_RASTER_DEPTH, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
            om__target_clear(&t);
            om__hiz_clear(pass ? hiz_buf : NULL, &t);
            for (int k = 0; k < NTRI; k++) om__raster_tri_on_hiz(&r, pass ? hiz_buf : NULL, c[k], (uint32_t)k, HW, HH);
        }
        for (int i = 0; i < HW * HH; i++) diff += plain[i] != coarse[i];
    }
    CHECK_EQ_U(diff, 0);
}

/* The slow scene itself, smaller: a light map of 300 huge triangles through one
 * point, with the coarse depth and without. */
static void hiz_scene_light_map(void)
{
    enum { M = 512 };
    parsed p;
    CHECK_OK(parse("triangles count 300 area 1e12 in 0 0 0 0 0 0\n", &p));
    if (p.st != OM_OK) return;
    om_view v;
    om_diag d;
    om_camera cam = p.s.camera;
    cam.width = 160;
    cam.height = 120;
    CHECK_OK(om_view_init(&v, &cam, &p.s.light, &p.s, &d));
    uint32_t *a = malloc((size_t)M * M * 4), *b = malloc((size_t)M * M * 4);
    uint32_t *h = malloc(om__hiz_words(M, M) * 4);
    CHECK(a && b && h);
    if (a && b && h) {
        om_target ta = {M, M, 0, M, a, NULL}, tb = {M, M, 0, M, b, NULL};
        om__scene_raster(&p.s, &v.light_vp, v.origin, &ta, OM_RASTER_DEPTH, true, NULL);
        om__scene_raster_hiz(&p.s, &v.light_vp, v.origin, &tb, OM_RASTER_DEPTH, true, NULL, h);
        int diff = 0, written = 0;
        for (size_t i = 0; i < (size_t)M * M; i++) {
            diff += a[i] != b[i];
            written += a[i] != 0xFFFFFFFFu;
        }
        CHECK_EQ_U(diff, 0);
        CHECK(written > M * M / 2);
    }
    free(a);
    free(b);
    free(h);
    done(&p);
}

/* sm and rtw take the coarse depth from their arenas when there is room (the one-pass
 * bytes) and draw without it at their minimum: the same frames either way, over 400
 * triangles that each cover a twentieth of the map (lit and shadowed samples both). */
static void hiz_methods_same_without_room(void)
{
    enum { FW = 96, FH = 72 };
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 4 6 target 0 0 0\n"
                            "light spot pos 2 7 1 target 0 0 0 fov 70 near 1 far 40\n"
                            "plane size 8 8\ntriangles count 400 area 2000 in -2 0 -2 2 2 2\n"))
        return;
    static const char *const names[2] = {"sm", "rtw"};
    for (int k = 0; k < 2; k++) {
        const om_method *m = om_method_find(names[k]);
        om_method_cfg cfg = h_cfg(names[k], "map=512");
        size_t mn = 0, full = 0;
        CHECK_OK(om_method_bytes(m, &cfg, &hs.s, FW, FH, &mn, &full));
        CHECK(full >= mn + om__hiz_words(512, 512) * 4);
        static uint8_t a[FW * FH], b[FW * FH];
        static om_term ta[FW * FH], tb[FW * FH];
        CHECK_OK(h_render_in(&hs.s, names[k], &cfg, FW, FH, 0, 0, full, a, ta, NULL));
        CHECK_OK(h_render_in(&hs.s, names[k], &cfg, FW, FH, 0, 16, mn, b, tb, NULL));
        CHECK(memcmp(a, b, sizeof a) == 0 && memcmp(ta, tb, sizeof ta) == 0);
        int lit = 0, dark = 0;
        for (int i = 0; i < FW * FH; i++) {
            lit += a[i] == 255;
            dark += a[i] == 0;
        }
        CHECK(lit > 100 && dark > 100);
    }
    h_scene_free(&hs);
}

void suite_hiz(void)
{
    RUN(hiz_same_texels);
    RUN(hiz_clipped_huge);
    RUN(hiz_scene_light_map);
    RUN(hiz_methods_same_without_room);
}
