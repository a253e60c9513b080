/* unit/raster.c — the fixed-point rasterizer: hand-checked masks, both windings, the
 * top-left rule, watertightness of shared edges (fans, grids, random triangulations,
 * sub-pixel vertices), clipping at the near and far planes, coordinates that would
 * overflow 32-bit setup, conservative coverage, the point-in-triangle test, and the
 * entry for triangles already on the grid, the plain depth pass made alongside a
 * conservative one, depth passes on rectilinear grids, non-finite vertices, and the
 * depth's division by 32-bit words. */
#include "../test.h"
#include "../../engine/raster/raster.h"
#include "../../engine/core/core.h"

#include <math.h>
#include <stdlib.h>

#ifdef __SIZEOF_INT128__

#define TW 32
#define TH 32

static uint32_t depth_buf[256 * 256], id_buf[256 * 256];
static int count_buf[256 * 256];

static om_target target(uint32_t w, uint32_t h)
{
    om_target t;
    t.width = w; t.height = h; t.y0 = 0; t.rows = h;
    t.depth = depth_buf;
    t.id = id_buf;
    return t;
}

/* A vertex at sub-pixel grid position (X, Y) of a w x h image, on the plane z/w = z. */
static om_vec4 at(double X, double Y, uint32_t w, uint32_t h, float z)
{
    om_vec4 v;
    v.x = (float)(X / (w * 128.0) - 1.0);
    v.y = (float)(1.0 - Y / (h * 128.0));
    v.z = z;
    v.w = 1.0f;
    return v;
}

__extension__ typedef __int128 i128;
/* Whether depth d at grid point (px, py) is what raster.h promises for the plane
 * through the vertices (x, y, z), given in any order: the exact plane's value z(p)
 * rounded to the nearest integer but for the two steps' roundings, |d - z(p)| <=
 * 1/2 + 2^-33 (|dx| + |dy|) with dx, dy the point's offsets from vertex 0 (at most 3/4
 * in om__tri2's range). In exact rationals: the plane's numerator over twice the
 * signed area, in 128 bits. */
static bool depth_near_plane(const int64_t x[3], const int64_t y[3], const uint32_t z[3], int64_t px, int64_t py,
                             uint32_t d)
{
    const i128 x1 = x[1] - x[0], y1 = y[1] - y[0], x2 = x[2] - x[0], y2 = y[2] - y[0];
    const i128 z0 = z[0], z1 = (i128)z[1] - z0, z2 = (i128)z[2] - z0;
    const i128 D = x1 * y2 - x2 * y1, A = z1 * y2 - z2 * y1, B = z2 * x1 - z1 * x2;
    const i128 gx = px - x[0], gy = py - y[0];
    const i128 N = z0 * D + A * gx + B * gy, aD = D < 0 ? -D : D;
    i128 err = (i128)d * D - N;   /* (d - z(p)) * D */
    if (err < 0) err = -err;
    if (err > aD) return false;   /* beyond one unit: never allowed (and keeps what follows in range) */
    return (err << 34) <= aD * (((i128)1 << 33) + 2 * ((gx < 0 ? -gx : gx) + (gy < 0 ? -gy : gy)));
}


/* Rasterizes one triangle alone and adds its coverage to count_buf. */
static void add_coverage(const om_vec4 c[3], uint32_t w, uint32_t h)
{
    om_target t = target(w, h);
    om__target_clear(&t);
    om_raster r = {&t, OM_RASTER_DEPTH_ID, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
    om__raster_tri(&r, c, 7);
    for (uint32_t i = 0; i < w * h; i++) count_buf[i] += id_buf[i] == 7;
}

static void mask_of(const om_vec4 c[3], char *out)
{
    memset(count_buf, 0, sizeof count_buf);
    add_coverage(c, 8, 8);
    for (int i = 0; i < 64; i++) out[i] = count_buf[i] ? '#' : '.';
    out[64] = 0;
}

static void hand_checked_masks(void)
{
    char m[65];
    /* Right triangle with corners on pixel corners (0,0), (4,0), (0,4): pixel centres
     * (x + 0.5, y + 0.5) with x + y < 3 are inside; x + y == 3 lie on the hypotenuse,
     * a right edge, so they are excluded. */
    om_vec4 a[3] = {at(0, 0, 8, 8, 0.5f), at(4 * 256, 0, 8, 8, 0.5f), at(0, 4 * 256, 8, 8, 0.5f)};
    mask_of(a, m);
    CHECK_MSG(!strcmp(m, "###.....##......#..............................................."), "%s", m);
    /* Same triangle, other winding: same pixels. */
    om_vec4 b[3] = {a[0], a[2], a[1]};
    char m2[65];
    mask_of(b, m2);
    CHECK(!strcmp(m, m2));
    /* A triangle whose edges pass exactly through pixel centres: the left edge x = 1.5
     * (pixel centres of column 1) owns them, the top edge y = 1.5 owns row 1. */
    om_vec4 c[3] = {at(1.5 * 256, 1.5 * 256, 8, 8, 0.5f), at(5.5 * 256, 1.5 * 256, 8, 8, 0.5f),
                    at(1.5 * 256, 5.5 * 256, 8, 8, 0.5f)};
    mask_of(c, m);
    CHECK_MSG(!strcmp(m, ".........####....###.....##......#.............................."), "%s", m);
    /* A triangle smaller than a pixel that holds no centre covers nothing; one that
     * holds a centre covers exactly that pixel. */
    om_vec4 d[3] = {at(300, 300, 8, 8, 0.5f), at(360, 300, 8, 8, 0.5f), at(300, 360, 8, 8, 0.5f)};
    mask_of(d, m);
    CHECK(!strchr(m, '#'));
    om_vec4 e[3] = {at(370, 370, 8, 8, 0.5f), at(420, 370, 8, 8, 0.5f), at(370, 420, 8, 8, 0.5f)};
    mask_of(e, m);
    CHECK_EQ_U(strchr(m, '#') - m, 9);
    CHECK(strchr(m + 10, '#') == NULL);
    /* Zero-area after snapping: nothing. */
    om_vec4 z[3] = {at(0, 0, 8, 8, 0.5f), at(1024, 1024, 8, 8, 0.5f), at(2048, 2048, 8, 8, 0.5f)};
    mask_of(z, m);
    CHECK(!strchr(m, '#'));
}

/* Every pixel of a square region covered exactly once by a mesh with shared edges. */
static void check_square(double X0, double Y0, double X1, double Y1, const char *what)
{
    int bad = 0;
    for (int y = 0; y < TH; y++)
        for (int x = 0; x < TW; x++) {
            double cx = x * 256.0 + 128, cy = y * 256.0 + 128;
            int n = count_buf[y * TW + x];
            bool strict_in = cx > X0 && cx < X1 && cy > Y0 && cy < Y1;
            bool strict_out = cx < X0 || cx > X1 || cy < Y0 || cy > Y1;
            if (n > 1 || (strict_in && n != 1) || (strict_out && n != 0)) bad++;
        }
    CHECK_MSG(bad == 0, "%s: %d pixels covered wrongly", what, bad);
}

static uint64_t rng_state;
static uint32_t rnd(void)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(rng_state >> 33);
}

static void push(const om_vec4 *a, const om_vec4 *b, const om_vec4 *c, bool flip)
{
    om_vec4 t[3] = {*a, flip ? *c : *b, flip ? *b : *c};
    add_coverage(t, TW, TH);
}

static void watertight_grids(void)
{
    for (int trial = 0; trial < 40; trial++) {
        rng_state = 1000 + (uint64_t)trial;
        int n = 2 + (int)(rnd() % 6);
        /* The square's corners lie on arbitrary sub-pixel positions; interior vertices
         * are jittered by up to a third of a cell so the grid stays valid. */
        double X0 = 100 + rnd() % 700, Y0 = 100 + rnd() % 700;
        double X1 = TW * 256 - 100 - rnd() % 700, Y1 = TH * 256 - 100 - rnd() % 700;
        double gx[9][9], gy[9][9];
        for (int j = 0; j <= n; j++)
            for (int i = 0; i <= n; i++) {
                double cw = (X1 - X0) / n, ch = (Y1 - Y0) / n;
                gx[j][i] = floor(X0 + cw * i + ((i > 0 && i < n) ? ((int)(rnd() % 200) - 100) / 300.0 * cw : 0));
                gy[j][i] = floor(Y0 + ch * j + ((j > 0 && j < n) ? ((int)(rnd() % 200) - 100) / 300.0 * ch : 0));
            }
        memset(count_buf, 0, sizeof count_buf);
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                om_vec4 p00 = at(gx[j][i], gy[j][i], TW, TH, 0.5f);
                om_vec4 p10 = at(gx[j][i + 1], gy[j][i + 1], TW, TH, 0.5f);
                om_vec4 p01 = at(gx[j + 1][i], gy[j + 1][i], TW, TH, 0.5f);
                om_vec4 p11 = at(gx[j + 1][i + 1], gy[j + 1][i + 1], TW, TH, 0.5f);
                if (rnd() & 1) {
                    push(&p00, &p10, &p11, rnd() & 1);
                    push(&p00, &p11, &p01, rnd() & 1);
                } else {
                    push(&p00, &p10, &p01, rnd() & 1);
                    push(&p10, &p11, &p01, rnd() & 1);
                }
            }
        /* The outer boundary is the unjittered square, so its pixels are checkable. */
        check_square(X0, Y0, X1, Y1, "grid");
    }
}

static void watertight_fans(void)
{
    for (int trial = 0; trial < 30; trial++) {
        rng_state = 77 + (uint64_t)trial;
        int n = 3 + (int)(rnd() % 40);
        double cx = 16 * 256 + (double)(rnd() % 512) - 256, cy = 16 * 256 + (double)(rnd() % 512) - 256;
        double r = 2000 + rnd() % 1500;
        memset(count_buf, 0, sizeof count_buf);
        om_vec4 c = at(cx, cy, TW, TH, 0.5f);
        double px[64], py[64];
        for (int i = 0; i < n; i++) {
            double a = 2 * OM_PI * i / n;
            px[i] = floor(cx + r * om__cos(a));
            py[i] = floor(cy + r * om__sin(a));
        }
        for (int i = 0; i < n; i++) {
            int j = (i + 1) % n;
            om_vec4 a = at(px[i], py[i], TW, TH, 0.5f), b = at(px[j], py[j], TW, TH, 0.5f);
            push(&c, &a, &b, rnd() & 1);
        }
        /* Inside the fan's polygon every pixel is covered exactly once; check against
         * the polygon with the same integer edge rule (no pixel twice anywhere). */
        int bad = 0, covered = 0;
        for (int i = 0; i < TW * TH; i++) {
            if (count_buf[i] > 1) bad++;
            covered += count_buf[i];
        }
        int inside = 0;
        for (int y = 0; y < TH; y++)
            for (int x = 0; x < TW; x++) {
                int64_t X = x * 256 + 128, Y = y * 256 + 128;
                bool in = true;
                for (int i = 0; i < n && in; i++) {
                    int j = (i + 1) % n;
                    /* the polygon is convex and wound with angle: interior on one side */
                    int64_t e = (int64_t)(px[j] - px[i]) * (Y - (int64_t)py[i]) -
                                (int64_t)(py[j] - py[i]) * (X - (int64_t)px[i]);
                    if (e <= 0) in = false;
                }
                if (in) {
                    inside++;
                    if (count_buf[y * TW + x] != 1) bad++;
                }
            }
        CHECK_MSG(bad == 0, "fan %d: %d pixels wrong (%d covered, %d strictly inside)", trial, bad,
                  covered, inside);
    }
}

static void watertight_random_triangulation(void)
{
    /* Random points in a square, triangulated by inserting each into the triangle that
     * holds it (split into three): a random triangulation with shared edges. */
    for (int trial = 0; trial < 20; trial++) {
        rng_state = 5 + (uint64_t)trial;
        double X0 = 300, Y0 = 200, X1 = TW * 256 - 257, Y1 = TH * 256 - 300;
        int tri[200][3], nt = 2, np = 4;
        double px[110], py[110];
        px[0] = X0; py[0] = Y0; px[1] = X1; py[1] = Y0; px[2] = X1; py[2] = Y1; px[3] = X0; py[3] = Y1;
        tri[0][0] = 0; tri[0][1] = 1; tri[0][2] = 2;
        tri[1][0] = 0; tri[1][1] = 2; tri[1][2] = 3;
        for (int k = 0; k < 60; k++) {
            double x = X0 + 1 + rnd() % (unsigned)(X1 - X0 - 2), y = Y0 + 1 + rnd() % (unsigned)(Y1 - Y0 - 2);
            for (int t = 0; t < nt; t++) {
                double ax = px[tri[t][0]], ay = py[tri[t][0]], bx = px[tri[t][1]], by = py[tri[t][1]];
                double cx = px[tri[t][2]], cy = py[tri[t][2]];
                double d1 = (bx - ax) * (y - ay) - (by - ay) * (x - ax);
                double d2 = (cx - bx) * (y - by) - (cy - by) * (x - bx);
                double d3 = (ax - cx) * (y - cy) - (ay - cy) * (x - cx);
                if (d1 > 0 && d2 > 0 && d3 > 0) {
                    px[np] = x; py[np] = y;
                    int a = tri[t][0], b = tri[t][1], c = tri[t][2];
                    tri[t][2] = np;
                    tri[nt][0] = b; tri[nt][1] = c; tri[nt][2] = np; nt++;
                    tri[nt][0] = c; tri[nt][1] = a; tri[nt][2] = np; nt++;
                    np++;
                    break;
                }
            }
        }
        memset(count_buf, 0, sizeof count_buf);
        for (int t = 0; t < nt; t++) {
            om_vec4 a = at(px[tri[t][0]], py[tri[t][0]], TW, TH, 0.5f);
            om_vec4 b = at(px[tri[t][1]], py[tri[t][1]], TW, TH, 0.5f);
            om_vec4 c = at(px[tri[t][2]], py[tri[t][2]], TW, TH, 0.5f);
            push(&a, &b, &c, rnd() & 1);
        }
        check_square(X0, Y0, X1, Y1, "random triangulation");
    }
}

/* A quad in 3-D crossing the near plane, seen through a perspective camera: after
 * clipping, the two halves still cover every pixel of the quad exactly once. */
static void clipping_near_far(void)
{
    om_mat4 view, proj;
    om__mat_look_at(&view, om__v3(0, 1, 0), om__v3(0, 0.5f, -10), om__v3(0, 1, 0));
    proj = om__mat_perspective(90.0f, 1.0f, 0.5f, 20.0f);
    om_mat4 vp = om__mat_mul(&proj, &view);
    /* A ground quad from behind the camera to beyond the far plane. */
    om_vec3 q[4] = {om__v3(-3, 0, 5), om__v3(3, 0, 5), om__v3(3, 0, -40), om__v3(-3, 0, -40)};
    om_vec4 c[4];
    for (int i = 0; i < 4; i++) c[i] = om__mat_apply(&vp, q[i]);
    memset(count_buf, 0, sizeof count_buf);
    om_vec4 t1[3] = {c[0], c[1], c[2]}, t2[3] = {c[0], c[2], c[3]};
    add_coverage(t1, TW, TH);
    add_coverage(t2, TW, TH);
    int twice = 0, covered = 0;
    for (int i = 0; i < TW * TH; i++) {
        twice += count_buf[i] > 1;
        covered += count_buf[i] > 0;
    }
    CHECK_EQ_U(twice, 0);
    CHECK(covered > 100);
    /* Every covered pixel lies below the horizon; the bottom row (near the camera's
     * feet, where the near plane cuts) is fully covered in the quad's middle columns. */
    for (int x = 12; x < 20; x++) CHECK(count_buf[(TH - 1) * TW + x] == 1);
    for (int x = 0; x < TW; x++) CHECK(count_buf[0 * TW + x] == 0);
    /* The far plane cuts the quad: pixels just below the horizon, beyond 20 m, stay empty. */
    int horizon_row = -1;
    for (int y = 0; y < TH && horizon_row < 0; y++)
        if (count_buf[y * TW + 16]) horizon_row = y;
    CHECK(horizon_row > TH / 2 - 4);   /* looking 2.9 degrees down: horizon just above centre */
    /* A triangle entirely behind the camera covers nothing. */
    om_vec3 b[3] = {om__v3(-1, 0, 3), om__v3(1, 0, 3), om__v3(0, 2, 3)};
    om_vec4 bc[3];
    for (int i = 0; i < 3; i++) bc[i] = om__mat_apply(&vp, b[i]);
    memset(count_buf, 0, sizeof count_buf);
    add_coverage(bc, TW, TH);
    int any = 0;
    for (int i = 0; i < TW * TH; i++) any += count_buf[i];
    CHECK_EQ_U(any, 0);
    /* NaN vertices are rejected. */
    om_vec4 nan3[3] = {c[0], c[1], c[2]};
    nan3[1].x = nan3[1].x * 0.0f / 0.0f;
    memset(count_buf, 0, sizeof count_buf);
    add_coverage(nan3, TW, TH);
    any = 0;
    for (int i = 0; i < TW * TH; i++) any += count_buf[i];
    CHECK_EQ_U(any, 0);
}

/* A 2 km ground plane seen from 1 m above, and one with vertices at 1e6: every pixel
 * below the horizon is ground, none above; depths grow towards the horizon. */
static void huge_ground(float half)
{
    const uint32_t W = 64, H = 48;
    om_mat4 view, proj;
    om__mat_look_at(&view, om__v3(0, 1, 0), om__v3(0, 1, -100), om__v3(0, 1, 0));
    proj = om__mat_perspective(60.0f, (float)W / H, 0.1f, 1e7f);
    om_mat4 vp = om__mat_mul(&proj, &view);
    om_vec3 q[4] = {om__v3(-half, 0, half), om__v3(half, 0, half), om__v3(half, 0, -half),
                    om__v3(-half, 0, -half)};
    om_vec4 c[4];
    for (int i = 0; i < 4; i++) c[i] = om__mat_apply(&vp, q[i]);
    om_target t = target(W, H);
    om__target_clear(&t);
    om_raster r = {&t, OM_RASTER_DEPTH_ID, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
    om_vec4 t1[3] = {c[0], c[1], c[2]}, t2[3] = {c[0], c[2], c[3]};
    om__raster_tri(&r, t1, 1);
    om__raster_tri(&r, t2, 2);
    int wrong = 0;
    for (uint32_t y = 0; y < H; y++)
        for (uint32_t x = 0; x < W; x++) {
            bool below = y >= H / 2;   /* horizon at the centre line (at most 1 m / half) */
            bool ground = id_buf[y * W + x] != OM_NO_TRI;
            if (below != ground) wrong++;
        }
    CHECK_MSG(wrong == 0, "half-size %g: %d pixels wrong", half, wrong);
    for (uint32_t y = H / 2 + 1; y < H; y++)
        CHECK(depth_buf[y * W + 5] < depth_buf[(y - 1) * W + 5]);
}

static void overflow_cases(void)
{
    huge_ground(1000.0f);
    huge_ground(1e6f);
    /* Screen-space coordinates far beyond int32 sub-pixel range before clipping. */
    om_vec4 c[3] = {{-1e9f, -1e9f, 0.5f, 1}, {1e9f, -1e9f, 0.5f, 1}, {0, 1e9f, 0.5f, 1}};
    memset(count_buf, 0, sizeof count_buf);
    add_coverage(c, TW, TH);
    for (int i = 0; i < TW * TH; i++) CHECK(count_buf[i] == 1);
}

static void covers_matches_fill(void)
{
    rng_state = 99;
    int bad = 0;
    for (int k = 0; k < 200; k++) {
        int64_t x[3], y[3];
        for (int i = 0; i < 3; i++) {
            x[i] = rnd() % (TW * 256);
            y[i] = rnd() % (TH * 256);
        }
        om_vec4 c[3];
        for (int i = 0; i < 3; i++) c[i] = at((double)x[i], (double)y[i], TW, TH, 0.5f);
        memset(count_buf, 0, sizeof count_buf);
        add_coverage(c, TW, TH);
        om__tri2 t;
        bool ok = om__tri2_setup(&t, x, y, true);
        for (int py = 0; py < TH; py++)
            for (int px = 0; px < TW; px++) {
                bool in = ok && om__tri2_covers(&t, px * 256 + 128, py * 256 + 128);
                if (in != (count_buf[py * TW + px] == 1)) bad++;
            }
    }
    CHECK_EQ_U(bad, 0);
    /* A point on an edge shared by two triangles belongs to exactly one of them. */
    int64_t ax[3] = {0, 1000, 0}, ay[3] = {0, 0, 1000}, bx[3] = {1000, 1000, 0}, by[3] = {0, 1000, 1000};
    om__tri2 ta, tb;
    CHECK(om__tri2_setup(&ta, ax, ay, true) && om__tri2_setup(&tb, bx, by, true));
    for (int64_t s = 0; s <= 1000; s += 50) {
        int n = om__tri2_covers(&ta, s, 1000 - s) + om__tri2_covers(&tb, s, 1000 - s);
        if (s > 0 && s < 1000) CHECK_MSG(n == 1, "point %lld on the shared edge owned %d times", (long long)s, n);
    }
    /* Coordinates beyond the documented range are refused, not overflowed. */
    int64_t big[3] = {0, OM_TRI2_MAX_COORD + 1, 0};
    CHECK(!om__tri2_setup(&ta, big, ay, true));
}

/* om__zdepth is z/w * 2^32 truncated: whole binary fractions exactly, every quotient
 * within a unit of the double one, 0 and 2^32 - 1 at and beyond the ends, subnormals
 * and huge ratios alike. */
static void zdepth_exact(void)
{
    CHECK(om__zdepth(0.25f, 1.0f) == 1073741824.0);
    CHECK(om__zdepth(3.0f, 4.0f) == 3221225472.0);
    CHECK(om__zdepth(0.0f, 1.0f) == 0.0 && om__zdepth(-1.0f, 1.0f) == 0.0);
    CHECK(om__zdepth(1.0f, 1.0f) == 4294967295.0 && om__zdepth(2.0f, 1.0f) == 4294967295.0);
    CHECK(om__zdepth(1e-30f, 1.0f) == 0.0 && om__zdepth(0x1p-149f, 0x1p-146f) == 536870912.0);
    CHECK(om__zdepth(0x1p-149f, 1.0f) == 0.0 && om__zdepth(0x3p-149f, 0x1p-120f) == 24.0);
    rng_state = 77;
    int bad = 0;
    for (int k = 0; k < 100000; k++) {
        float w = (float)(rnd() % 100000 + 1) / (float)(rnd() % 1000 + 1);
        float z = w * (float)(rnd() % 1000000) / 1000000.0f;
        double q = om__zdepth(z, w), e = (double)z / (double)w * 4294967296.0;
        bad += !(q == floor(q) && q <= e + 1e-6 && q + 1.0 > e - 1e-6);
    }
    CHECK_EQ_U(bad, 0);
}

/* om__raster_snapped is what om__raster_tri does once a triangle is on the grid: the
 * same depths and ids for triangles given either way (partly off the image too). */
static void snapped_matches_clipped(void)
{
    static uint32_t d0[TW * TH], i0[TW * TH];
    rng_state = 123;
    int bad = 0;
    for (int k = 0; k < 300; k++) {
        int64_t x[3], y[3];
        uint32_t z[3];
        om_vec4 c[3];
        for (int i = 0; i < 3; i++) {
            x[i] = (int64_t)(rnd() % (2 * TW * 256)) - TW * 128;
            y[i] = (int64_t)(rnd() % (2 * TH * 256)) - TH * 128;
            /* depths of 1/1024 steps: z/w * 2^32 is a whole number, as om__zdepth gives */
            c[i] = at((double)x[i], (double)y[i], TW, TH, (float)(rnd() % 1000) / 1024.0f);
            z[i] = (uint32_t)((double)c[i].z * 4294967296.0);
        }
        om_target t = target(TW, TH);
        om_raster r = {&t, OM_RASTER_DEPTH_ID, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
        om__target_clear(&t);
        om__raster_tri(&r, c, 5);
        memcpy(d0, depth_buf, sizeof d0);
        memcpy(i0, id_buf, sizeof i0);
        om__target_clear(&t);
        om__raster_snapped(&r, x, y, z, 5);
        bad += memcmp(d0, depth_buf, sizeof d0) != 0 || memcmp(i0, id_buf, sizeof i0) != 0;
    }
    CHECK_EQ_U(bad, 0);
}

/* A depth pass on a rectilinear grid (om_raster.grid_x, grid_y) gives every pixel the
 * nearest depth of the triangles covering its grid point, by the point-in-triangle test
 * and the plane: random non-decreasing grids with repeated points, points on vertices
 * and edges, triangles partly off the grid, both windings, 40 triangles layered; every
 * other round with the grids indexed (om__grid_index) in buckets of 16 to 2048 units,
 * some indexes covering only the lower half of the grid. */
static void grid_matches_point_tests(void)
{
    enum { GW = 48, GH = 40, NT = 40 };
    static int64_t gx[GW], gy[GH];
    static int32_t xs[2048], ys[2048];
    static om__rtri tris[NT];
    static int64_t vx[NT][3], vy[NT][3];
    static uint32_t vz[NT][3];
    rng_state = 77;
    int bad = 0, covered = 0, inexact = 0;
    for (int round = 0; round < 20; round++) {
        /* steps of 0..600 grid units: some points repeat, some lie far apart */
        int64_t g = (int64_t)(rnd() % 500);
        for (int i = 0; i < GW; i++) { gx[i] = g; g += (int64_t)(rnd() % 4 ? rnd() % 600 : 0); }
        g = (int64_t)(rnd() % 500);
        for (int i = 0; i < GH; i++) { gy[i] = g; g += (int64_t)(rnd() % 4 ? rnd() % 600 : 0); }
        om_target t = target(GW, GH);
        t.id = NULL;
        om_raster r = {&t, OM_RASTER_DEPTH, NULL, NULL, NULL, NULL, 0, false, gx, gy, NULL, NULL, 0, 0, NULL, 0};
        if (round % 2) {
            r.grid_shift = 4 + (uint32_t)(round / 2) % 8;
            r.grid_buckets = (uint32_t)((gx[GW - 1] > gy[GH - 1] ? gx[GW - 1] : gy[GH - 1]) >> r.grid_shift) + 1;
            if (round % 4 == 3) r.grid_buckets /= 2;
            om__grid_index(gx, GW, r.grid_shift, r.grid_buckets, xs);
            om__grid_index(gy, GH, r.grid_shift, r.grid_buckets, ys);
            r.grid_xs = xs;
            r.grid_ys = ys;
        }
        om__target_clear(&t);
        int nt = 0;
        for (int k = 0; k < NT; k++) {
            int64_t *x = vx[nt], *y = vy[nt];
            uint32_t *z = vz[nt];
            for (int i = 0; i < 3; i++) {
                /* a third of the vertices exactly on grid points */
                x[i] = rnd() % 3 ? (int64_t)(rnd() % 30000) - 2000 : gx[rnd() % GW];
                y[i] = rnd() % 3 ? (int64_t)(rnd() % 26000) - 2000 : gy[rnd() % GH];
                z[i] = (uint32_t)(rnd() % 1000000) * 4000u + (uint32_t)(rnd() % 4000);
            }
            if (om__raster_snapped(&r, x, y, z, 0)) {
                CHECK(om__tri2_setup(&tris[nt].e, x, y, true));
                om__rtri_zplane(&tris[nt], z);
                nt++;
            }
        }
        for (int j = 0; j < GH; j++)
            for (int i = 0; i < GW; i++) {
                uint32_t d = 0xFFFFFFFFu;
                for (int k = 0; k < nt; k++)
                    if (om__tri2_covers(&tris[k].e, gx[i], gy[j])) {
                        uint32_t z = om__rtri_zat(&tris[k], gx[i], gy[j]);
                        inexact += !depth_near_plane(vx[k], vy[k], vz[k], gx[i], gy[j], z);
                        if (z < d) d = z;
                    }
                covered += d != 0xFFFFFFFFu;
                bad += depth_buf[j * GW + i] != d;
            }
    }
    CHECK_EQ_U(bad, 0);
    CHECK_EQ_U(inexact, 0);
    CHECK(covered > 20 * GW * GH / 4);
}

/* Draws triangle k (vertices x, y, z, kept at tris[nt]'s row of the callers' arrays)
 * and, where it filled anything, keeps its setup for the point tests: nt + 1, else nt. */
static int draw_kept(const om_raster *r, om__rtri *tris, uint32_t *ids, int nt, const int64_t x[3],
                     const int64_t y[3], const uint32_t z[3], uint32_t k)
{
    if (!om__raster_snapped(r, x, y, z, k)) return nt;
    CHECK(om__tri2_setup(&tris[nt].e, x, y, true));
    om__rtri_zplane(&tris[nt], z);
    ids[nt] = k;
    return nt + 1;
}

/* What the point tests give at (px, py) over the kept triangles: the nearest depth
 * (0xFFFFFFFF: none) and in *id its triangle, the first kept at that depth; with vx,
 * each covering triangle's depth also held against its exact plane (*inexact). */
static uint32_t nearest_at(const om__rtri *tris, const uint32_t *ids, int nt, int64_t px, int64_t py, uint32_t *id,
                           int64_t (*vx)[3], int64_t (*vy)[3], uint32_t (*vz)[3], int *inexact)
{
    uint32_t d = 0xFFFFFFFFu;
    *id = OM_NO_TRI;
    for (int k = 0; k < nt; k++)
        if (om__tri2_covers(&tris[k].e, px, py)) {
            const uint32_t z = om__rtri_zat(&tris[k], px, py);
            if (vx) *inexact += !depth_near_plane(vx[k], vy[k], vz[k], px, py, z);
            if (z < d) { d = z; *id = ids[k]; }
        }
    return d;
}

/* The plain fill (depth and id, as the eye pass) gives every pixel the nearest depth
 * of the triangles covering its centre, by the point-in-triangle test and the plane
 * (as near the exact plane as raster.h promises), and the id of the first triangle drawn at
 * that depth: random layered triangles whose depths span [0, 2^32), and flat ones at
 * the ends of the range and around 2^31, where a wrap or a sign would show. Drawn last
 * to first, the same pixels: a tie goes to the lower id in any order. */
static void fill_matches_point_tests(void)
{
    enum { W = 61, H = 37, NT = 30 };
    static om__rtri tris[NT];
    static uint32_t ids[NT];
    static int64_t vx[NT][3], vy[NT][3];
    static uint32_t vz[NT][3];
    static const uint32_t flat[] = {2147483647u, 2147483648u, 4294967294u, 4294967295u, 0u, 1u};
    rng_state = 31;
    int bad = 0, covered = 0, inexact = 0, reordered = 0;
    static uint32_t kept_depth[W * H], kept_id[W * H];
    for (int round = 0; round < 30; round++) {
        om_target t = target(W, H);
        om_raster r = {&t, OM_RASTER_DEPTH_ID, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
        om__target_clear(&t);
        int nt = 0;
        for (int k = 0; k < NT; k++) {
            int64_t *x = vx[nt], *y = vy[nt];
            uint32_t *z = vz[nt];
            const int kind = k % 3;   /* flat, random, or from one end of the range to the other */
            const uint32_t zf = flat[(size_t)(rnd() % (sizeof flat / sizeof flat[0]))];
            for (int i = 0; i < 3; i++) {
                x[i] = (int64_t)(rnd() % (W * 256 + 2000)) - 1000;
                y[i] = (int64_t)(rnd() % (H * 256 + 2000)) - 1000;
                z[i] = kind == 0 ? zf : kind == 1 ? (uint32_t)(rnd() % 4294967) * 1000u + (uint32_t)(rnd() % 1000)
                                                  : (rnd() % 2 ? 0xFFFFFFFFu : 0u);
            }
            nt = draw_kept(&r, tris, ids, nt, x, y, z, (uint32_t)k);
        }
        for (int j = 0; j < H; j++)
            for (int i = 0; i < W; i++) {
                uint32_t id;
                const uint32_t d = nearest_at(tris, ids, nt, i * 256 + 128, j * 256 + 128, &id, vx, vy, vz,
                                              &inexact);
                covered += id != OM_NO_TRI;
                bad += depth_buf[j * W + i] != d || id_buf[j * W + i] != id;
            }
        memcpy(kept_depth, depth_buf, sizeof kept_depth);
        memcpy(kept_id, id_buf, sizeof kept_id);
        om__target_clear(&t);
        for (int k = nt; k-- > 0;) om__raster_snapped(&r, vx[k], vy[k], vz[k], ids[k]);
        reordered += memcmp(kept_depth, depth_buf, sizeof kept_depth) != 0 || memcmp(kept_id, id_buf, sizeof kept_id) != 0;
    }
    CHECK_EQ_U(bad, 0);
    CHECK_EQ_U(inexact, 0);
    CHECK_EQ_U(reordered, 0);
    CHECK(covered > 30 * W * H / 2);
}

/* Tiny triangles, whose box holds a few pixel centres (raster.c's own path for them),
 * and a few just past that size, all over a small image and across its sides, with
 * depths flat, random or from one end of the range to the other: every texel holds
 * what the point test and the fixed-point plane give, with ids and without. */
static void tiny_matches_point_tests(void)
{
    enum { W = 23, H = 19, NT = 400 };
    static om__rtri tris[NT];
    static uint32_t ids[NT];
    static int64_t vx[NT][3], vy[NT][3];
    static uint32_t vz[NT][3];
    static const uint32_t flat[] = {2147483647u, 2147483648u, 4294967294u, 4294967295u, 0u, 1u};
    rng_state = 57;
    int bad = 0, covered = 0;
    for (int round = 0; round < 40; round++) {
        const bool with_id = round % 2;
        om_target t = target(W, H);
        if (!with_id) t.id = NULL;
        om_raster r = {&t, with_id ? OM_RASTER_DEPTH_ID : OM_RASTER_DEPTH, NULL, NULL, NULL, NULL, 0, false,
                       NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
        om__target_clear(&t);
        int nt = 0;
        for (int k = 0; k < NT; k++) {
            int64_t *x = vx[nt], *y = vy[nt];
            uint32_t *z = vz[nt];
            const int kind = k % 4;
            const uint32_t zf = flat[(size_t)(rnd() % (sizeof flat / sizeof flat[0]))];
            /* a box up to 1.5, 3, 6, 12 or 24 pixels a side, anywhere on the image or off
             * it; every other one with vertices on a grid of half pixels, so that
             * edges pass through centres (the tie rule) and, with depths a few units
             * apart (kind 3), the plane lands on halves of a unit at some */
            const int64_t reach = (int64_t)256 << (rnd() % 5), cx = (int64_t)(rnd() % ((W + 4) * 256)) - 512,
                          cy = (int64_t)(rnd() % ((H + 4) * 256)) - 512;
            const int64_t q = rnd() % 2 ? 128 : 1;
            for (int i = 0; i < 3; i++) {
                x[i] = (cx + (int64_t)(rnd() % (uint64_t)(reach * 3 / 2 + 1))) / q * q;
                y[i] = (cy + (int64_t)(rnd() % (uint64_t)(reach * 3 / 2 + 1))) / q * q;
                z[i] = kind == 0 ? zf : kind == 1 ? (uint32_t)(rnd() % 4294967) * 1000u + (uint32_t)(rnd() % 1000)
                                      : kind == 2 ? (rnd() % 2 ? 0xFFFFFFFFu : 0u)
                                                  : zf / 2 + rnd() % 4;
            }
            nt = draw_kept(&r, tris, ids, nt, x, y, z, (uint32_t)k);
        }
        for (int j = 0; j < H; j++)
            for (int i = 0; i < W; i++) {
                uint32_t id;
                const uint32_t d = nearest_at(tris, ids, nt, i * 256 + 128, j * 256 + 128, &id, NULL, NULL, NULL,
                                              NULL);
                covered += id != OM_NO_TRI;
                bad += depth_buf[j * W + i] != d || (with_id && id_buf[j * W + i] != id);
            }
    }
    CHECK_EQ_U(bad, 0);
    CHECK(covered > 40 * W * H / 2);
    /* Planes whose exact value at a centre is a half unit, where the slopes' roundings
     * decide which way the depth goes: vertices on half pixels, depths a unit or two
     * apart, one triangle at a time against the point test. */
    int ties = 0;
    for (int k = 0; k < 20000; k++) {
        om_target t = target(8, 8);
        t.id = NULL;
        om_raster r = {&t, OM_RASTER_DEPTH, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
        om__target_clear(&t);
        int64_t x[3], y[3];
        uint32_t z[3];
        const uint32_t z0 = rnd() * 2u;
        for (int i = 0; i < 3; i++) {
            x[i] = (int64_t)(rnd() % 9) * 128 + 512;
            y[i] = (int64_t)(rnd() % 9) * 128 + 512;
            z[i] = z0 + rnd() % 3;
        }
        om__rtri tr;
        if (!om__raster_snapped(&r, x, y, z, 0)) continue;
        CHECK(om__tri2_setup(&tr.e, x, y, true));
        om__rtri_zplane(&tr, z);
        for (int j = 0; j < 8; j++)
            for (int i = 0; i < 8; i++) {
                const int64_t px = i * 256 + 128, py = j * 256 + 128;
                const bool in = om__tri2_covers(&tr.e, px, py);
                const uint32_t want = in ? om__rtri_zat(&tr, px, py) : 0xFFFFFFFFu;
                bad += depth_buf[j * 8 + i] != want;
                ties += in && ((tr.zq0 + tr.zqx * (uint64_t)(px - tr.e.x[0]) + tr.zqy * (uint64_t)(py - tr.e.y[0])) &
                               0xFFFFFFFFu) > 0xFFFFFF00u;
            }
    }
    CHECK_EQ_U(bad, 0);
    CHECK(ties > 100);
}

/* The fixed-point plane at the ends of its range: triangles with coordinates up to
 * om__tri2's limit (areas far beyond 2^32, where the steps' fractions come bit by
 * bit), slivers whose steps wrap modulo 2^64, depths from 0 to 2^32 - 1; at random
 * points inside each, the depth is as near the exact plane as raster.h promises and
 * lies between the vertex depths. */
static void plane_nearest_at_extremes(void)
{
    rng_state = 2024;
    int tested = 0, inexact = 0, outside = 0;
    for (int k = 0; k < 4000; k++) {
        const int64_t M = k % 2 ? OM_TRI2_MAX_COORD : (int64_t)1 << (8 + k % 22);
        int64_t x[3], y[3];
        uint32_t z[3];
        for (int i = 0; i < 3; i++) {
            x[i] = (int64_t)(((uint64_t)rnd() << 31 ^ rnd()) % (uint64_t)(2 * M + 1)) - M;
            y[i] = (int64_t)(((uint64_t)rnd() << 31 ^ rnd()) % (uint64_t)(2 * M + 1)) - M;
            z[i] = k % 4 < 2 ? (rnd() % 2 ? 0xFFFFFFFFu : 0u) : (uint32_t)((uint64_t)rnd() << 16 ^ rnd());
        }
        if (k % 8 == 7) {   /* a sliver: the third vertex next to the line of the others */
            x[2] = x[0] + (x[1] - x[0]) / 2 + (int64_t)(rnd() % 3) - 1;
            y[2] = y[0] + (y[1] - y[0]) / 2 + (int64_t)(rnd() % 3) - 1;
        }
        om__rtri t;
        if (!om__tri2_setup(&t.e, x, y, true)) continue;
        om__rtri_zplane(&t, z);
        const uint32_t lo = z[0] < z[1] ? (z[0] < z[2] ? z[0] : z[2]) : (z[1] < z[2] ? z[1] : z[2]);
        const uint32_t hi = z[0] > z[1] ? (z[0] > z[2] ? z[0] : z[2]) : (z[1] > z[2] ? z[1] : z[2]);
        for (int n = 0; n < 16; n++) {
            /* a random point of the triangle: the vertices and barycentric mixes */
            const uint32_t a = rnd() % 1024, b = rnd() % (1025 - a);
            const int64_t px = x[0] + ((x[1] - x[0]) * (int64_t)a + (x[2] - x[0]) * (int64_t)b) / 1024;
            const int64_t py = y[0] + ((y[1] - y[0]) * (int64_t)a + (y[2] - y[0]) * (int64_t)b) / 1024;
            if (!om__tri2_covers(&t.e, px, py)) continue;
            const uint32_t d = om__rtri_zat(&t, px, py);
            tested++;
            inexact += !depth_near_plane(x, y, z, px, py, d);
            outside += d < lo || d > hi;
        }
    }
    CHECK_EQ_U(inexact, 0);
    CHECK_EQ_U(outside, 0);
    CHECK(tested > 10000);
}

typedef struct cons_ctx { int *count; uint32_t w; } cons_ctx;
static void cons_span(void *user, int32_t y, int32_t x0, int32_t x1, const om__rtri *t)
{
    cons_ctx *c = (cons_ctx *)user;
    (void)t;
    for (int32_t x = x0; x <= x1; x++) c->count[y * (int32_t)c->w + x]++;
}

static void conservative_superset(void)
{
    rng_state = 4242;
    static int cons[TW * TH];
    int missing = 0, dup = 0;
    for (int k = 0; k < 200; k++) {
        om_vec4 c[3];
        double X[3], Y[3];
        for (int i = 0; i < 3; i++) {
            X[i] = rnd() % (TW * 256);
            Y[i] = rnd() % (TH * 256);
            if (k % 4 == 0) { X[i] = 4000 + rnd() % 300; Y[i] = 4000 + rnd() % 300; }   /* tiny */
            c[i] = at(X[i], Y[i], TW, TH, 0.5f);
        }
        memset(count_buf, 0, sizeof count_buf);
        add_coverage(c, TW, TH);
        memset(cons, 0, sizeof cons);
        om_target t = target(TW, TH);
        cons_ctx ctx = {cons, TW};
        om_raster r = {&t, OM_RASTER_CONSERVATIVE, cons_span, &ctx, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
        om__raster_tri(&r, c, 1);
        for (int i = 0; i < TW * TH; i++) {
            if (count_buf[i] && !cons[i]) missing++;
            if (cons[i] > 1) dup++;
        }
        /* Every pixel holding a vertex is touched. */
        for (int i = 0; i < 3; i++) {
            int px = (int)(X[i] / 256), py = (int)(Y[i] / 256);
            if (!cons[py * TW + px]) missing++;
        }
    }
    CHECK_EQ_U(missing, 0);
    CHECK_EQ_U(dup, 0);
}

/* A row mask (om_raster.row_mask) passes over exactly the rows whose bit, at
 * y >> row_shift, is clear: there no span and no centre is written; every other row
 * gets the spans and centre depths of the unmasked pass. */
static void conservative_row_mask(void)
{
    static int cons[TW * TH], masked[TW * TH];
    static uint32_t cdep[TW * TH], mdep[TW * TH];
    rng_state = 515;
    for (uint32_t shift = 0; shift <= 1; shift++) {
        uint32_t rows[(TH + 31) / 32];
        for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) rows[i] = (uint32_t)rnd() * 2654435761u;
        memset(cons, 0, sizeof cons);
        memset(masked, 0, sizeof masked);
        om_target t = target(TW, TH), ct = {TW, TH, 0, TH, cdep, NULL}, mt = {TW, TH, 0, TH, mdep, NULL};
        om__target_clear(&ct);
        om__target_clear(&mt);
        cons_ctx a = {cons, TW}, b = {masked, TW};
        om_raster r = {&t, OM_RASTER_CONSERVATIVE, cons_span, &a, &ct, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
        om_raster rm = r;
        rm.user = &b;
        rm.centres = &mt;
        rm.row_mask = rows;
        rm.row_shift = shift;
        for (int k = 0; k < 200; k++) {
            om_vec4 c[3];
            for (int i = 0; i < 3; i++)
                c[i] = at((double)(rnd() % (TW * 256)), (double)(rnd() % (TH * 256)), TW, TH, (float)(rnd() % 1000) / 1000.0f);
            om__raster_tri(&r, c, (uint32_t)k);
            om__raster_tri(&rm, c, (uint32_t)k);
        }
        int wrong = 0, kept = 0, passed = 0;
        for (int y = 0; y < TH; y++) {
            const uint32_t ym = (uint32_t)y >> shift;
            const bool on = rows[ym >> 5] >> (ym & 31) & 1u;
            for (int x = 0; x < TW; x++) {
                const int i = y * TW + x;
                if (on) wrong += masked[i] != cons[i] || mdep[i] != cdep[i], kept += cons[i] > 0;
                else wrong += masked[i] != 0 || mdep[i] != 0xFFFFFFFFu, passed += cons[i] > 0;
            }
        }
        CHECK_EQ_U(wrong, 0);
        CHECK(kept > 0 && passed > 0);   /* both kinds of row were drawn on */
    }
}

static void no_span(void *user, int32_t y, int32_t x0, int32_t x1, const om__rtri *t)
{
    (void)user; (void)y; (void)x0; (void)x1; (void)t;
}

/* A conservative pass with `centres` leaves there the very depths a plain depth pass
 * over the same triangles writes (random overlapping triangles, partly off the image,
 * half with their vertices on texel centres, some degenerate). */
static void conservative_centres_match_depth_pass(void)
{
    static uint32_t plain[TW * TH], alongside[TW * TH];
    rng_state = 77;
    om_vec4 c[60][3];
    for (int k = 0; k < 60; k++) {
        int64_t x[3], y[3];
        for (int i = 0; i < 3; i++) {
            x[i] = (int64_t)(rnd() % (2 * TW * 256)) - TW * 128;
            y[i] = (int64_t)(rnd() % (2 * TH * 256)) - TH * 128;
            if (k & 1) {   /* on texel centres: edges through centres test the fill rule */
                x[i] = x[i] / 256 * 256 + 128;
                y[i] = y[i] / 256 * 256 + 128;
            }
        }
        if (k % 10 == 9) { x[2] = x[0] + (x[1] - x[0]) * 2; y[2] = y[0] + (y[1] - y[0]) * 2; }   /* no area */
        for (int i = 0; i < 3; i++) c[k][i] = at((double)x[i], (double)y[i], TW, TH, (float)(rnd() % 1000) / 1000.0f);
    }
    om_target t = target(TW, TH);
    om_raster r = {&t, OM_RASTER_DEPTH, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
    om__target_clear(&t);
    for (int k = 0; k < 60; k++) om__raster_tri(&r, c[k], (uint32_t)k);
    memcpy(plain, depth_buf, sizeof plain);
    om_target ct = {TW, TH, 0, TH, alongside, NULL}, scratch = target(TW, TH);
    om__target_clear(&ct);
    om_raster rc = {&scratch, OM_RASTER_CONSERVATIVE, no_span, NULL, &ct, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
    for (int k = 0; k < 60; k++) om__raster_tri(&rc, c[k], (uint32_t)k);
    int differ = 0, written = 0;
    for (int i = 0; i < TW * TH; i++) {
        differ += plain[i] != alongside[i];
        written += plain[i] != 0xFFFFFFFFu;
    }
    CHECK_EQ_U(differ, 0);
    CHECK(written > TW * TH / 2);
    /* With a mask, the same depths at the pixels it holds and nothing elsewhere: runs
     * of set and clear bits of every length, whole clear words among them. */
    enum { MW = (TW + 31) / 32 };
    static uint32_t mask[MW * TH];
    for (int i = 0; i < MW * TH; i++) mask[i] = i % 5 == 0 ? 0 : rnd() & rnd();
    om__target_clear(&ct);
    rc.centre_mask = mask;
    rc.mask_words = MW;
    for (int k = 0; k < 60; k++) om__raster_tri(&rc, c[k], (uint32_t)k);
    int wrong = 0, held = 0;
    for (int y = 0; y < TH; y++)
        for (int x = 0; x < TW; x++) {
            const bool in = (mask[y * MW + x / 32] >> (x % 32)) & 1u;
            const size_t i = (size_t)y * TW + (size_t)x;
            wrong += alongside[i] != (in ? plain[i] : 0xFFFFFFFFu);
            held += in && plain[i] != 0xFFFFFFFFu;
        }
    CHECK_EQ_U(wrong, 0);
    CHECK(held > TW * TH / 8);
}

static void strips_match_whole(void)
{
    /* The same triangles rendered whole and through strips of 5 rows agree exactly,
     * depth included. */
    static uint32_t whole_d[TW * TH], whole_i[TW * TH];
    rng_state = 31337;
    om_vec4 tris[40][3];
    for (int k = 0; k < 40; k++)
        for (int i = 0; i < 3; i++)
            tris[k][i] = at(rnd() % (TW * 256 + 2000) - 1000.0, rnd() % (TH * 256 + 2000) - 1000.0,
                            TW, TH, (float)(rnd() % 1000) / 1000.0f);
    om_target t = target(TW, TH);
    om__target_clear(&t);
    om_raster r = {&t, OM_RASTER_DEPTH_ID, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
    for (int k = 0; k < 40; k++) om__raster_tri(&r, tris[k], (uint32_t)k);
    memcpy(whole_d, depth_buf, sizeof whole_d);
    memcpy(whole_i, id_buf, sizeof whole_i);
    int diff = 0;
    for (uint32_t y0 = 0; y0 < TH; y0 += 5) {
        t.y0 = y0;
        t.rows = y0 + 5 > TH ? TH - y0 : 5;
        om__target_clear(&t);
        for (int k = 0; k < 40; k++) om__raster_tri(&r, tris[k], (uint32_t)k);
        for (uint32_t i = 0; i < t.rows * TW; i++)
            if (depth_buf[i] != whole_d[y0 * TW + i] || id_buf[i] != whole_i[y0 * TW + i]) diff++;
    }
    CHECK_EQ_U(diff, 0);
}

/* A triangle with a vertex coordinate that is infinite or NaN draws nothing, whichever
 * coordinate it is: w = +inf passes every clip plane's test and would project to the
 * image's centre, so it is the case a fast path could let through. */
static void non_finite_vertices_draw_nothing(void)
{
    om_target t = target(TW, TH);
    om_raster r = {&t, OM_RASTER_DEPTH_ID, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
    const om_vec4 tri[3] = {at(100, 100, TW, TH, 0.5f), at(7000, 300, TW, TH, 0.5f), at(900, 7900, TW, TH, 0.5f)};
    om__target_clear(&t);
    CHECK_EQ_U((uint32_t)om__raster_tri(&r, tri, 1), 1);   /* as given, it draws */
    const float bad[3] = {INFINITY, -INFINITY, NAN};
    uint32_t drawn = 0, touched = 0;
    for (int k = 0; k < 3; k++)
        for (int c = 0; c < 4; c++)
            for (int b = 0; b < 3; b++) {
                om_vec4 v[3] = {tri[0], tri[1], tri[2]};
                float *f = c == 0 ? &v[k].x : c == 1 ? &v[k].y : c == 2 ? &v[k].z : &v[k].w;
                *f = bad[b];
                om__target_clear(&t);
                drawn += (uint32_t)om__raster_tri(&r, v, 2);
                for (uint32_t i = 0; i < TW * TH; i++) touched += depth_buf[i] != 0xFFFFFFFFu;
            }
    CHECK_EQ_U(drawn, 0);
    CHECK_EQ_U(touched, 0);
}

static uint32_t rnd32(uint32_t *s)
{
    *s ^= *s << 13;   /* xorshift: every bit as random as the others */
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return *s;
}

/* om__zdepth by 32-bit words (raster.h, the Cortex-M4's way) gives the 64-bit
 * division's quotient: every shift, significands at both ends of their range, next to
 * each other and random, wherever the quotient fits 32 bits (z < w). */
static void zdepth_by_words(void)
{
    uint32_t seed = 0x2545F491u, bad = 0, n = 0;
    for (int s = -24; s <= 32; s++)
        for (int i = 0; i < 4000; i++) {
            uint32_t mz, mw;
            switch (i % 8) {
            case 0: mz = rnd32(&seed) % 0xFFFFFFu + 1; mw = 0xFFFFFFu; break;
            case 1: mw = (rnd32(&seed) & 0x7FFFFFu) | 0x800000u; mz = mw - 1 - rnd32(&seed) % 4; break;
            case 2: mz = (rnd32(&seed) & 0x7FFFFFu) | 0x800000u; mw = 0x800000u; break;
            case 3: mz = rnd32(&seed) % 64 + 1; mw = rnd32(&seed) % 64 + 1; break;   /* subnormal-like */
            default: mz = rnd32(&seed) % 0xFFFFFFu + 1; mw = rnd32(&seed) % 0xFFFFFFu + 1; break;
            }
            const uint64_t z = mz, w = mw;
            /* the quotient must fit 32 bits, as it does for z < w */
            if (s > 0 && (z << s) / w > 0xFFFFFFFFu) continue;
            const uint64_t want = s >= 0 ? (z << s) / w : z / (w << -s);
            bad += om__zdepth_words(mz, mw, s) != want;
            n++;
        }
    CHECK_MSG(bad == 0 && n > 150000, "%u of %u quotients differ", bad, n);
    /* and through om__zdepth, whichever way it divides: depths of floats */
    const float zs[] = {1e-40f, 1e-30f, 0.25f, 0.5f, 0.999f, 1.0f, 3.0f, 1e20f};
    for (int a = 0; a < 8; a++)
        for (int b = 0; b < 8; b++) {
            const float z = zs[a], w = zs[b];
            const double q = (double)z / (double)w * 4294967296.0;   /* exact enough to floor here */
            const uint32_t want = !(z > 0.0f) ? 0 : !(z < w) ? 0xFFFFFFFFu : (uint32_t)floor(q);
            CHECK_MSG(om__zdepth(z, w) == want || (q - floor(q)) * (q - floor(q)) < 1e-12,
                      "zdepth(%g, %g) = %u, not %u", (double)z, (double)w, om__zdepth(z, w), want);
        }
}

void suite_raster(void)
{
    RUN(hand_checked_masks);
    RUN(watertight_grids);
    RUN(watertight_fans);
    RUN(watertight_random_triangulation);
    RUN(clipping_near_far);
    RUN(overflow_cases);
    RUN(covers_matches_fill);
    RUN(zdepth_exact);
    RUN(snapped_matches_clipped);
    RUN(grid_matches_point_tests);
    RUN(fill_matches_point_tests);
    RUN(tiny_matches_point_tests);
    RUN(plane_nearest_at_extremes);
    RUN(conservative_superset);
    RUN(conservative_row_mask);
    RUN(conservative_centres_match_depth_pass);
    RUN(strips_match_whole);
    RUN(non_finite_vertices_draw_nothing);
    RUN(zdepth_by_words);
}
#else
/* A 32-bit build (make test-32) has no 128-bit integers, which this suite's depth
 * checks need; the 64-bit builds run it. */
void suite_raster(void)
{
    printf("  raster: skipped here (no 128-bit integers; the 64-bit builds run it)\n");
}
#endif
