/* raster.c — clipping, snapping and filling of triangles (plain, conservative, on a
 * rectilinear grid); large triangles on a target with a coarse depth go through
 * hiz.c, which draws its rows with this file's fill. The rule is written at the top
 * of raster.h. Everything after the snap is integer, the depth plane included: fixed
 * point from one origin per triangle (so strips agree). */
#include "hiz.h"
#include "../core/core.h"

#include <math.h>
#include <string.h>

/* floor(a / 256), a grid position's pixel, by shifts of non-negative values (a
 * shift of a negative one is the implementation's to define, a 64-bit division a
 * library routine on a 32-bit CPU). */
static int64_t pixel_floor(int64_t a)
{
    return a >= 0 ? a >> OM_SUBPIX_BITS : -((OM_SUBPIX - 1 - a) >> OM_SUBPIX_BITS);
}

/* n / d for n >= 0, d > 0: in 32 bits when both fit (a single instruction where a
 * 64-bit division is a library routine), the same quotient either way. */
static inline int64_t div_nonneg(int64_t n, int64_t d)
{
    return ((uint64_t)n | (uint64_t)d) >> 32 ? n / d : (int64_t)((uint32_t)n / (uint32_t)d);
}

/* The top-left rule for the edge with coefficients a (of x) and b (of y), area2 > 0 in
 * a y-down image: a top edge runs in +x (a = 0, b > 0) and a left edge runs upwards
 * (a > 0); points exactly on any other edge are outside. */
static bool top_left(int64_t a, int64_t b)
{
    return a > 0 || (a == 0 && b > 0);
}

bool om__tri2_setup(om__tri2 *t, const int64_t x[3], const int64_t y[3], bool biased)
{
    int p[3] = {0, 1, 2};
    t->area2 = 0;
    for (int i = 0; i < 3; i++)
        if (x[i] > OM_TRI2_MAX_COORD || x[i] < -OM_TRI2_MAX_COORD ||
            y[i] > OM_TRI2_MAX_COORD || y[i] < -OM_TRI2_MAX_COORD)
            return false;
    int64_t area2 = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if (area2 < 0) { p[1] = 2; p[2] = 1; area2 = -area2; }
    if (area2 == 0 && biased) return false;
    for (int i = 0; i < 3; i++) {
        t->perm[i] = p[i];
        t->x[i] = x[p[i]];
        t->y[i] = y[p[i]];
    }
    for (int i = 0; i < 3; i++) {
        int j = i == 2 ? 0 : i + 1;
        int64_t dx = t->x[j] - t->x[i], dy = t->y[j] - t->y[i];
        /* E(p) = dx * (py - yi) - dy * (px - xi): positive on the interior side. */
        t->a[i] = -dy;
        t->b[i] = dx;
        t->c[i] = dy * t->x[i] - dx * t->y[i];
        if (biased && !top_left(t->a[i], t->b[i])) t->c[i] -= 1;
    }
    t->area2 = area2;
    return true;
}

typedef char om__no_tri_is_all_ones[OM_NO_TRI == 0xFFFFFFFFu ? 1 : -1];   /* target_clear's memset */

void om__target_clear(const om_target *t)
{
    /* every byte 0xFF: depth 2^32 - 1 and OM_NO_TRI, by the C library's memset,
     * which fills a large map several words an instruction */
    size_t n = (size_t)t->rows * t->width;
    memset(t->depth, 0xFF, n * sizeof *t->depth);
    if (t->id) memset(t->id, 0xFF, n * sizeof *t->id);
}

/* ---- clipping */

typedef struct cvert { float x, y, z, w; } cvert;

static float plane_dist(int plane, const cvert *v, float gx, float gy)
{
    switch (plane) {
    case 0: return v->z;               /* near: z >= 0 */
    case 1: return v->w - v->z;        /* far: z <= w */
    case 2: return v->x + gx * v->w;   /* guard band, left */
    case 3: return gx * v->w - v->x;   /* right */
    case 4: return v->y + gy * v->w;   /* bottom */
    default: return gy * v->w - v->y;  /* top */
    }
}

static float guard(uint32_t size) { return 1.0f + 2.0f * (float)OM_GUARD_PX / (float)size; }

/* om__outcode with the guard band's extents gx, gy (guard) worked out by the caller,
 * once a triangle: plane_dist's six expressions, written out. */
static inline unsigned outcode_g(const om_vec4 *v, float gx, float gy)
{
    return (unsigned)!(v->z >= 0.0f) | (unsigned)!(v->w - v->z >= 0.0f) << 1 |
           (unsigned)!(v->x + gx * v->w >= 0.0f) << 2 | (unsigned)!(gx * v->w - v->x >= 0.0f) << 3 |
           (unsigned)!(v->y + gy * v->w >= 0.0f) << 4 | (unsigned)!(gy * v->w - v->y >= 0.0f) << 5;
}

unsigned om__outcode(const om_vec4 *v, uint32_t width, uint32_t height)
{
    return outcode_g(v, guard(width), guard(height));
}

/* The intersection is always computed from the inside vertex towards the outside one,
 * so an edge shared by two triangles is cut at the same point in both: no cracks. */
static cvert cut(const cvert *in, const cvert *out, float din, float dout)
{
    float t = din / (din - dout);
    cvert r;
    r.x = in->x + t * (out->x - in->x);
    r.y = in->y + t * (out->y - in->y);
    r.z = in->z + t * (out->z - in->z);
    r.w = in->w + t * (out->w - in->w);
    return r;
}

int om__clip_project(const om_vec4 clip[3], uint32_t width, uint32_t height,
                     int64_t *gx_out, int64_t *gy_out, uint32_t *gz_out)
{
    cvert buf[2][10];
    int n = 3;
    float gx = guard(width), gy = guard(height);
    unsigned outside_all = 0x3F, outside_any = 0;
    for (int i = 0; i < 3; i++) {
        unsigned mask = outcode_g(&clip[i], gx, gy);
        buf[0][i].x = clip[i].x;
        buf[0][i].y = clip[i].y;
        buf[0][i].z = clip[i].z;
        buf[0][i].w = clip[i].w;
        outside_all &= mask;
        outside_any |= mask;
    }
    if (outside_all) return 0;    /* wholly beyond one plane */
    int cur = 0;
    for (int p = 0; p < 6 && n > 0; p++) {
        if (!(outside_any & (1u << p))) continue;
        cvert *src = buf[cur], *dst = buf[cur ^ 1];
        int m = 0;
        for (int i = 0; i < n; i++) {
            const cvert *a = &src[i], *b = &src[i + 1 == n ? 0 : i + 1];
            float da = plane_dist(p, a, gx, gy), db = plane_dist(p, b, gx, gy);
            bool ina = da >= 0.0f, inb = db >= 0.0f;
            if (ina) dst[m++] = *a;
            if (ina && !inb) dst[m++] = cut(a, b, da, db);
            else if (!ina && inb) dst[m++] = cut(b, a, db, da);
        }
        n = m;
        cur ^= 1;
    }
    if (n < 3) return 0;
    for (int i = 0; i < n; i++) {
        const cvert *c = &buf[cur][i];
        om_vec4 v = {c->x, c->y, c->z, c->w};
        if (!om__project(&v, width, height, &gx_out[i], &gy_out[i], &gz_out[i])) return 0;
    }
    return n;
}

/* ---- filling */

void om__rtri_plane(om__rtri *t, const uint32_t z[3])
{
    const om__tri2 *e = &t->e;
    double z0 = z[e->perm[0]], z1 = z[e->perm[1]], z2 = z[e->perm[2]];
    double x1 = (double)(e->x[1] - e->x[0]), y1 = (double)(e->y[1] - e->y[0]);
    double x2 = (double)(e->x[2] - e->x[0]), y2 = (double)(e->y[2] - e->y[0]);
    t->z0 = z0;
    if (e->area2 > 0) {
        double inv = 1.0 / (double)e->area2;
        t->zx = ((z1 - z0) * y2 - (z2 - z0) * y1) * inv;
        t->zy = ((z2 - z0) * x1 - (z1 - z0) * x2) * inv;
    } else {
        t->zx = t->zy = 0.0;
    }
    t->zmin = fmin(z0, fmin(z1, z2));
    t->zmax = fmax(z0, fmax(z1, z2));
}

/* n * 2^32 / d rounded to the nearest integer (halves away from zero), modulo 2^64;
 * d > 0. The quotient's integer part comes from one 64-bit division, its 32 fraction
 * bits from a second where d < 2^32 (the remainder times 2^32 then fits 64 bits) and
 * otherwise bit by bit, as long division does on paper: the same value either way. */
static uint64_t div_q32(int64_t n, int64_t d)
{
    const uint64_t a = n < 0 ? 0u - (uint64_t)n : (uint64_t)n, D = (uint64_t)d;
    uint64_t q = a / D, r = a % D, f;
    if (D <= 0xFFFFFFFFu) {
        f = ((r << 32) + D / 2) / D;
    } else {
        f = 0;
        for (int i = 0; i < 32; i++) {   /* r < D < 2^61: r << 1 fits */
            r <<= 1;
            f <<= 1;
            if (r >= D) { r -= D; f |= 1; }
        }
        f += 2 * r >= D;
    }
    const uint64_t v = (q << 32) + f;
    return n < 0 ? 0u - v : v;
}

void om__rtri_zplane(om__rtri *t, const uint32_t z[3])
{
    const om__tri2 *e = &t->e;
    const int64_t z0 = z[e->perm[0]], dz1 = (int64_t)z[e->perm[1]] - z0, dz2 = (int64_t)z[e->perm[2]] - z0;
    t->zq0 = ((uint64_t)z0 << 32) + (1u << 31);
    if (e->area2 > 0) {
        /* |dz| < 2^32 and offsets <= 2^30: each product < 2^62, the differences fit */
        const int64_t x1 = e->x[1] - e->x[0], y1 = e->y[1] - e->y[0];
        const int64_t x2 = e->x[2] - e->x[0], y2 = e->y[2] - e->y[0];
        t->zqx = div_q32(dz1 * y2 - dz2 * y1, e->area2);
        t->zqy = div_q32(dz2 * x1 - dz1 * x2, e->area2);
    } else {
        t->zqx = t->zqy = 0;
    }
}

/* The bounding box of three grid points (a triangle's, in any vertex order). */
static void tri_box(const int64_t x[3], const int64_t y[3], int64_t *minX, int64_t *maxX, int64_t *minY, int64_t *maxY)
{
    *minX = *maxX = x[0];
    *minY = *maxY = y[0];
    for (int i = 1; i < 3; i++) {
        if (x[i] < *minX) *minX = x[i];
        if (x[i] > *maxX) *maxX = x[i];
        if (y[i] < *minY) *minY = y[i];
        if (y[i] > *maxY) *maxY = y[i];
    }
}

/* The pixels of the target whose centre (or, conservative, whose closed square) meets
 * the bounding box of the triangle with vertices x, y (within om__tri2's range). */
static bool bounds(om__rtri *t, const int64_t x[3], const int64_t y[3], const om_target *tg, bool conservative)
{
    int64_t minX, maxX, minY, maxY;
    tri_box(x, y, &minX, &maxX, &minY, &maxY);
    int64_t x0, x1, y0, y1;
    if (conservative) {       /* pixels whose closed square meets the bounding box */
        x0 = pixel_floor(minX - 1); x1 = pixel_floor(maxX);
        y0 = pixel_floor(minY - 1); y1 = pixel_floor(maxY);
    } else {                  /* pixels whose centre lies in the bounding box */
        const int64_t h = OM_SUBPIX / 2;
        x0 = pixel_floor(minX - h + OM_SUBPIX - 1); x1 = pixel_floor(maxX - h);
        y0 = pixel_floor(minY - h + OM_SUBPIX - 1); y1 = pixel_floor(maxY - h);
    }
    if (x0 < 0) x0 = 0;
    if (y0 < (int64_t)tg->y0) y0 = tg->y0;
    if (x1 > (int64_t)tg->width - 1) x1 = (int64_t)tg->width - 1;
    if (y1 > (int64_t)(tg->y0 + tg->rows) - 1) y1 = (int64_t)(tg->y0 + tg->rows) - 1;
    if (x0 > x1 || y0 > y1) return false;
    t->minx = (int32_t)x0; t->maxx = (int32_t)x1;
    t->miny = (int32_t)y0; t->maxy = (int32_t)y1;
    return true;
}

/* The texels of one row, [minx + *lo, minx + *hi], where every edge function (value
 * E[i] at the row's first texel, growing by step[i] per texel) is >= 0: the same
 * texels the per-texel test accepts, found by solving each edge for its crossing, so
 * the fill visits only the span and not the whole bounding box. False: none. */
static bool row_span(const int64_t E[3], const int64_t step[3], int64_t w, int64_t *lo,
                     int64_t *hi)
{
    int64_t l = 0, h = w;
    for (int i = 0; i < 3; i++) {
        if (step[i] > 0) {
            if (E[i] < 0) {
                int64_t k = div_nonneg(-E[i] + step[i] - 1, step[i]);   /* first texel with E >= 0 */
                if (k > l) l = k;
            }
        } else if (E[i] < 0) {
            return false;                                   /* never rises to 0 */
        } else if (step[i] < 0) {
            int64_t k = div_nonneg(E[i], -step[i]);                  /* last texel with E >= 0 */
            if (k < h) h = k;
        }
    }
    *lo = l;
    *hi = h;
    return l <= h;
}

/* The depth test along row y from texel x0 to x1, writing id too when `id_row` is
 * given (that row of the id buffer). With ids, a tie goes to the lower triangle: what
 * one walk of the triangles in order gives (the first drawn stays), and so what a
 * walk of any of them in any order gives, a pixel's depth being its triangle's alone
 * (om__scene_raster_part). Not at the cleared depth, 2^32 - 1, which no triangle
 * takes from the clear: so no drawn pixel has it. */
static void depth_row(const om__rtri *t, const om_target *tg, int32_t y, int32_t x0, int32_t x1,
                      uint32_t *id_row, uint32_t id)
{
    const int64_t S = OM_SUBPIX, H = OM_SUBPIX / 2;
    uint64_t z = t->zq0 + t->zqx * (uint64_t)((int64_t)x0 * S + H - t->e.x[0]) +
                 t->zqy * (uint64_t)((int64_t)y * S + H - t->e.y[0]);
    const uint64_t step = t->zqx * (uint64_t)S;
    uint32_t *dep = tg->depth + (size_t)(y - (int32_t)tg->y0) * tg->width;
    if (!id_row) {   /* a loop of its own: the depth passes' texels, one test each */
        /* four texels a step, each given the lesser of its depth and the fill's, the
         * value the test below leaves, stored whether or not it changed: no branch, so
         * that a compiler with lanes takes the four together; the rest one at a time */
        int32_t x = x0;
#if defined(__SSE2__) || defined(__ARM_NEON)   /* without lanes, one at a time is less */
        for (; x + 3 <= x1; x += 4, z += 4 * step) {
            for (int i = 0; i < 4; i++) {
                const uint32_t d = (uint32_t)((z + (uint64_t)i * step) >> 32);
                dep[x + i] = d < dep[x + i] ? d : dep[x + i];
            }
        }
#endif
        for (; x <= x1; x++, z += step) {
            const uint32_t d = (uint32_t)(z >> 32);
            if (d < dep[x]) dep[x] = d;
        }
        return;
    }
    for (int32_t x = x0; x <= x1; x++, z += step) {
        const uint32_t d = (uint32_t)(z >> 32);
        if (d < dep[x] || (d == dep[x] && id < id_row[x] && d != 0xFFFFFFFFu)) {
            dep[x] = d;
            id_row[x] = id;
        }
    }
}

static const uint32_t *zdepths(const om_vec4 *zc, uint32_t zb[3]);

/* The plain fill. The depth plane (two divisions) is set up at the first row with a
 * covered pixel, from the depths z or, when z is NULL, those of zc (om__zdepth, three
 * more divisions); neither when both are NULL (the plane is set): most triangles of a
 * detailed scene that reach a pixel's row cover no pixel centre at all. */
static void fill(const om_raster *r, om__rtri *t, const uint32_t *z, const om_vec4 *zc, uint32_t id)
{
    const om_target *tg = r->target;
    const om__tri2 *e = &t->e;
    const int64_t S = OM_SUBPIX, H = OM_SUBPIX / 2;
    const int64_t step[3] = {e->a[0] * S, e->a[1] * S, e->a[2] * S};
    const bool with_id = r->mode == OM_RASTER_DEPTH_ID;
    for (int32_t y = t->miny; y <= t->maxy; y++) {
        int64_t py = (int64_t)y * S + H, px0 = (int64_t)t->minx * S + H, lo, hi;
        const int64_t E[3] = {om__tri2_edge(e, 0, px0, py), om__tri2_edge(e, 1, px0, py),
                              om__tri2_edge(e, 2, px0, py)};
        if (!row_span(E, step, t->maxx - t->minx, &lo, &hi)) continue;
        if (z || zc) {
            uint32_t zb[3];
            om__rtri_zplane(t, z ? z : zdepths(zc, zb));
            z = NULL;
            zc = NULL;
        }
        uint32_t *id_row = with_id ? tg->id + (size_t)(y - (int32_t)tg->y0) * tg->width : NULL;
        depth_row(t, tg, y, t->minx + (int32_t)lo, t->minx + (int32_t)hi, id_row, id);
    }
}

/* depth_row over the runs of pixels of x0..x1 whose bit is set in `mask` (a row). */
static void depth_row_masked(const om__rtri *t, const om_target *tg, int32_t y, int32_t x0, int32_t x1,
                             const uint32_t *mask)
{
    for (int32_t x = om__mask_next(mask, x0, x1); x <= x1;) {
        int32_t e = x;   /* the run of set bits from x */
        while (e < x1 && ((mask[(e + 1) >> 5] >> ((e + 1) & 31)) & 1u)) e++;
        depth_row(t, tg, y, x, e, NULL, 0);
        x = om__mask_next(mask, e + 1, x1);
    }
}

static void fill_conservative(const om_raster *r, const om__rtri *t)
{
    const om__tri2 *e = &t->e;
    const int64_t S = OM_SUBPIX, H = OM_SUBPIX / 2;
    const int64_t step[3] = {e->a[0] * S, e->a[1] * S, e->a[2] * S};
    /* Largest value of each edge function over a pixel square, relative to its centre. */
    int64_t reach[3];
    for (int i = 0; i < 3; i++)
        reach[i] = ((e->a[i] < 0 ? -e->a[i] : e->a[i]) + (e->b[i] < 0 ? -e->b[i] : e->b[i])) * H;
    /* The plain pass alongside: the fill rule's edges are these less the top-left bias
     * (om__tri2_setup), and a triangle with no area covers no centre. */
    const om_target *ct = e->area2 > 0 ? r->centres : NULL;
    int64_t bias[3];
    for (int i = 0; i < 3; i++) bias[i] = top_left(e->a[i], e->b[i]) ? 0 : 1;
    for (int32_t y = t->miny; y <= t->maxy; y++) {
        const uint32_t ym = (uint32_t)y >> r->row_shift;   /* rows the caller passes over */
        if (r->row_mask && !(r->row_mask[ym >> 5] >> (ym & 31) & 1u)) continue;
        int64_t py = (int64_t)y * S + H, px0 = (int64_t)t->minx * S + H, lo, hi;
        const int64_t E[3] = {om__tri2_edge(e, 0, px0, py), om__tri2_edge(e, 1, px0, py),
                              om__tri2_edge(e, 2, px0, py)};
        const int64_t R[3] = {E[0] + reach[0], E[1] + reach[1], E[2] + reach[2]};
        if (!row_span(R, step, t->maxx - t->minx, &lo, &hi)) continue;
        r->span(r->user, y, t->minx + (int32_t)lo, t->minx + (int32_t)hi, t);
        const int64_t B[3] = {E[0] - bias[0], E[1] - bias[1], E[2] - bias[2]};
        if (ct && row_span(B, step, t->maxx - t->minx, &lo, &hi)) {
            if (r->centre_mask)
                depth_row_masked(t, ct, y, t->minx + (int32_t)lo, t->minx + (int32_t)hi,
                                 r->centre_mask + (size_t)(y - (int32_t)ct->y0) * r->mask_words);
            else
                depth_row(t, ct, y, t->minx + (int32_t)lo, t->minx + (int32_t)hi, NULL, 0);
        }
    }
}

/* ---- rectilinear grids (om_raster.grid_x, grid_y) */

/* Whether grid index x lies past the crossing of edge (a, k), a != 0: a * g[x] + k >= 0
 * when the edge function rises along the row (a > 0), < 0 when it falls. False, then
 * true, along a row (g is non-decreasing). */
static inline bool grid_past(const int64_t *g, int32_t x, int64_t a, int64_t k)
{
    return (a * g[x] + k >= 0) == (a > 0);
}

/* The first i in [lo, hi] past the crossing; hi + 1 when none. Bisection without
 * branches on the data (the choice is a conditional move): small triangles land
 * anywhere on the map, and a mispredicted step costs more than the step. */
static int32_t grid_cross(const int64_t *g, int32_t lo, int32_t hi, int64_t a, int64_t k)
{
    if (lo > hi) return lo;
    int32_t b = lo, n = hi - lo + 1;
    while (n > 1) {
        const int32_t half = n / 2;
        b = grid_past(g, b + half - 1, a, k) ? b : b + half;
        n -= half;
    }
    return b + !grid_past(g, b, a, k);
}

void om__grid_index(const int64_t *g, int32_t n, uint32_t shift, uint32_t buckets, int32_t *start)
{
    int32_t i = 0;
    for (uint32_t b = 0; b <= buckets; b++) {
        while (i < n && g[i] < ((int64_t)b << shift)) i++;
        start[b] = i;
    }
}

/* The first i in [lo, hi] with g[i] >= T, hi + 1 when none; with an index (start,
 * NULL for none), searched between the first grid points of T's bucket and the next:
 * those before the one are below T, and the other is past it. */
static int32_t grid_first(const int64_t *g, const int32_t *start, uint32_t shift, uint32_t buckets,
                          int32_t lo, int32_t hi, int64_t T)
{
    if (lo > hi) return lo;
    int32_t L = lo, H = hi;
    if (start && T >= 0) {
        const int64_t b = (T >> shift) < (int64_t)buckets ? (T >> shift) : (int64_t)buckets;
        if (start[b] > L) L = start[b];
        if (b < (int64_t)buckets && start[b + 1] < H) H = start[b + 1];
    } else if (start && start[0] < H) {
        H = start[0];   /* the first point at or past 0 is past T */
    }
    const int32_t x = grid_cross(g, L, H, 1, -T);
    return x > hi + 1 ? hi + 1 : x;
}

/* The pixels whose grid point lies in the triangle's bounding box. */
static bool bounds_grid(om__rtri *t, const om_raster *r)
{
    const om_target *tg = r->target;
    const om__tri2 *e = &t->e;
    int64_t minX, maxX, minY, maxY;
    tri_box(e->x, e->y, &minX, &maxX, &minY, &maxY);
    const int32_t xe = (int32_t)tg->width - 1, ye = (int32_t)(tg->y0 + tg->rows) - 1;
    const uint32_t s = r->grid_shift, nb = r->grid_buckets;
    /* the first grid point at or past each side */
    t->minx = grid_first(r->grid_x, r->grid_xs, s, nb, 0, xe, minX);
    t->maxx = grid_first(r->grid_x, r->grid_xs, s, nb, t->minx, xe, maxX + 1) - 1;
    t->miny = grid_first(r->grid_y, r->grid_ys, s, nb, (int32_t)tg->y0, ye, minY);
    t->maxy = grid_first(r->grid_y, r->grid_ys, s, nb, t->miny, ye, maxY + 1) - 1;
    return t->minx <= t->maxx && t->miny <= t->maxy;
}

/* The run of row y's pixels whose grid point the triangle covers, lo..hi (lo > hi:
 * none). Along a row every edge function is monotonic in x (the grid is), so the
 * covered pixels are one run, bounded by each edge's crossing: cross[i] is edge i's
 * first index past its crossing, found by bisection when `fresh` and otherwise walked
 * from the row before's, since a straight edge moves little from row to row (both
 * give the same index). */
static inline void grid_span(const om_raster *r, const om__rtri *t, int32_t y, int32_t cross[3], bool fresh,
                             int32_t *lo_out, int32_t *hi_out)
{
    const om__tri2 *e = &t->e;
    const int64_t *gx = r->grid_x;
    const int32_t x0 = t->minx, x1 = t->maxx;
    const int64_t py = r->grid_y[y];
    int32_t lo = x0, hi = x1;
    for (int i = 0; i < 3; i++) {
        const int64_t a = e->a[i], k = e->b[i] * py + e->c[i];
        if (a == 0) {
            if (k < 0) hi = lo - 1;
            continue;
        }
        int32_t x = cross[i];
        if (fresh) {
            x = grid_cross(gx, x0, x1, a, k);
        } else {
            while (x > x0 && grid_past(gx, x - 1, a, k)) x--;
            while (x <= x1 && !grid_past(gx, x, a, k)) x++;
        }
        cross[i] = x;
        if (a > 0) { if (x > lo) lo = x; }
        else if (x - 1 < hi) hi = x - 1;
    }
    *lo_out = lo;
    *hi_out = hi;
}

/* The depth test at the grid points of row y, pixels lo..hi. */
static inline void grid_row(const om_raster *r, const om__rtri *t, int32_t y, int32_t lo, int32_t hi)
{
    const om_target *tg = r->target;
    const int64_t *gx = r->grid_x;
    const uint64_t zrow = t->zq0 + t->zqy * (uint64_t)(r->grid_y[y] - t->e.y[0]);
    uint32_t *dep = tg->depth + (size_t)(y - (int32_t)tg->y0) * tg->width;
#if defined(__GNUC__) || defined(__clang__)
    if (y < t->maxy) __builtin_prefetch(dep + tg->width + lo, 1);
#endif
    for (int32_t x = lo; x <= hi; x++) {
        const uint32_t d = (uint32_t)((zrow + t->zqx * (uint64_t)(gx[x] - t->e.x[0])) >> 32);
        if (d < dep[x]) dep[x] = d;
    }
}

/* fill at grid points, row by row. */
static void fill_grid(const om_raster *r, const om__rtri *t)
{
    int32_t cross[3] = {t->minx, t->minx, t->minx};
    for (int32_t y = t->miny; y <= t->maxy; y++) {
        int32_t lo, hi;
        grid_span(r, t, y, cross, y == t->miny, &lo, &hi);
        if (lo <= hi) grid_row(r, t, y, lo, hi);
    }
}


/* ---- the pieces of the fill that hiz.c draws its rows with (hiz.h) */

bool om__fill_row_span(const int64_t E[3], const int64_t step[3], int64_t w, int64_t *lo, int64_t *hi)
{
    return row_span(E, step, w, lo, hi);
}

void om__fill_depth_row(const om__rtri *t, const om_target *tg, int32_t y, int32_t x0, int32_t x1)
{
    depth_row(t, tg, y, x0, x1, NULL, 0);
}

void om__fill_grid_span(const om_raster *r, const om__rtri *t, int32_t y, int32_t cross[3], bool fresh,
                        int32_t *lo, int32_t *hi)
{
    grid_span(r, t, y, cross, fresh, lo, hi);
}

void om__fill_grid_row(const om_raster *r, const om__rtri *t, int32_t y, int32_t lo, int32_t hi)
{
    grid_row(r, t, y, lo, hi);
}

static const uint32_t *zdepths(const om_vec4 *zc, uint32_t zb[3])
{
    for (int i = 0; i < 3; i++) zb[i] = om__zdepth(zc[i].z, zc[i].w);
    return zb;
}

/* The range om__tri2_setup accepts, tested before snapped's bounds as the setup would
 * refuse the same triangles; om__project's vertices are always in it (below 2^26). */
static bool in_range(const int64_t x[3], const int64_t y[3])
{
    for (int i = 0; i < 3; i++)
        if (x[i] > OM_TRI2_MAX_COORD || x[i] < -OM_TRI2_MAX_COORD || y[i] > OM_TRI2_MAX_COORD ||
            y[i] < -OM_TRI2_MAX_COORD)
            return false;
    return true;
}

/* ---- tiny triangles
 *
 * Most triangles of a detailed scene that reach a pixel centre at all hold one or a
 * few: their box spans at most TINY centres each way. For those the general path's
 * work is mostly branches on the data (the box, the setup's orientation and tie
 * rule, each row's span) that a random triangle mispredicts. Here every coordinate is
 * taken relative to vertex 0 (the box is below (TINY + 1) * 256 < 2^13 units a side,
 * so products fit 32 bits), each centre of the box is tested with the edge functions
 * om__tri2_setup would build (the same values: dx (py - yi) - dy (px - xi), less one
 * off the top and left edges), and a covered centre gets the depth fill gives it:
 * om__rtri_zplane's plane from the same origin, vertex 0, which no orientation moves
 * (perm[0] is always 0), or at the first covered centre, most often the only one,
 * the same depth from one division (tiny_depth). The same texels and bits; the
 * vertex depths are still worked out only once a centre is covered. */
/* Past 8 centres a side the spans cost less than testing every centre (a Cortex-M's
 * light pass, the eye pass of larger triangles). The bounds below hold up to 16. */
#define TINY 8
typedef char om__tiny_within_bounds[TINY <= 16 ? 1 : -1];

/* The depth fill gives the point at offsets P, Q from vertex 0 inside a triangle of
 * vertex depths z0, z0 + dz1, z0 + dz2 at offsets (X[i], Y[i]) from vertex 0 (stored
 * order, area2 > 0 below 2^26, offsets below 2^13), with one division rather than
 * om__rtri_zplane's four, when it can tell; false when it cannot.
 *
 * Why: fill's sum A = zq0 + zqx P + zqy Q is the exact plane's
 * V = 2^32 (z0 + 1/2 + M / area2), M = Nx P + Ny Q with Nx, Ny om__rtri_zplane's
 * numerators, but for the slopes' roundings, each within 1/2: |A - V| <= (|P| + |Q|)
 * / 2 < 2^13. And A's top half is floor(A / 2^32), as the sum never wraps inside the
 * triangle (the rule in raster.h). With k = floor((2M + area2) / (2 area2)) and rem
 * the remainder, V = 2^32 (z0 + k) + 2^32 rem / (2 area2): when rem and 2 area2 - rem
 * both pass m = area2 (|P| + |Q|) / 2^32, V lies farther than (|P| + |Q|) / 2 from
 * either end of its unit, so A's floor is z0 + k; otherwise (some 2m + 1 in 2 area2)
 * fill's own sum decides. Magnitudes: |Nx|, |Ny| < 2^46, |M| < 2^60, area2 (|P| +
 * |Q|) < 2^39. */
static inline bool tiny_depth(uint32_t z0, int64_t dz1, int64_t dz2, const int32_t X[3], const int32_t Y[3],
                              int32_t area2, int64_t P, int64_t Q, uint32_t *d)
{
    const int64_t Nx = dz1 * Y[2] - dz2 * Y[1], Ny = dz2 * X[1] - dz1 * X[2];
    const int64_t num = 2 * (Nx * P + Ny * Q) + area2, den = 2 * (int64_t)area2;
    /* the floor of num / den, by a division of non-negative values */
    const int64_t k = num >= 0 ? num / den : -((-num - 1) / den) - 1, rem = num - k * den;
    const int64_t m = (int64_t)(((uint64_t)area2 * (uint64_t)((P < 0 ? -P : P) + (Q < 0 ? -Q : Q))) >> 32);
    if (rem <= m || den - rem <= m) return false;
    *d = (uint32_t)((int64_t)z0 + k);
    return true;
}

/* The edge from (xi, yi) to (xj, yj) of a triangle in om__tri2_setup's order, at
 * offsets (P, Q): its value there, less one off an edge that is neither top nor left
 * (top_left(-dy, dx), without branches), and its steps a pixel along and down. */
static inline void tiny_edge(int32_t xi, int32_t yi, int32_t xj, int32_t yj, int32_t P, int32_t Q, int32_t *e,
                             int32_t *sx, int32_t *sy)
{
    const int32_t dx = xj - xi, dy = yj - yi;
    *e = dx * (Q - yi) - dy * (P - xi) - (int32_t)!((dy < 0) | ((dy == 0) & (dx > 0)));
    *sx = -dy * OM_SUBPIX;
    *sy = dx * OM_SUBPIX;
}

/* 1 or 0, what snapped returns for such a triangle (whether its box holds a centre of
 * the target and it has area), or -1 when its box is not tiny. x, y are within
 * om__tri2's range (2^29), so the biased shifts below see non-negative values; `box`,
 * when given, their centres as the caller found them (om__raster_projected32). In line:
 * snapped and om__raster_projected32 each take it without a call. */
OM_INLINE int tiny(const om_raster *r, const int32_t x[3], const int32_t y[3], const uint32_t *z, const om_vec4 *zc,
                   uint32_t id, const int32_t *box)
{
    const om_target *tg = r->target;
    const int32_t xa = x[0], xb = x[1], xc = x[2];
    const int32_t ya = y[0], yb = y[1], yc = y[2];
    int32_t x0, x1, y0, y1;
    if (box) {   /* the caller's: the same centres */
        x0 = box[0];
        x1 = box[1];
        y0 = box[2];
        y1 = box[3];
    } else {
        int32_t lx = xa < xb ? xa : xb, hx = xa < xb ? xb : xa, ly = ya < yb ? ya : yb, hy = ya < yb ? yb : ya;
        lx = xc < lx ? xc : lx;
        hx = xc > hx ? xc : hx;
        ly = yc < ly ? yc : ly;
        hy = yc > hy ? yc : hy;
        /* bounds' centres, floor((lo + 127) / 256) to floor((hi - 128) / 256), by
         * shifts of values made non-negative by a bias of 2^30 (a multiple of 256) */
        const int32_t B = 1 << 30, b = B >> OM_SUBPIX_BITS;
        x0 = ((lx + 127 + B) >> OM_SUBPIX_BITS) - b;
        x1 = ((hx - 128 + B) >> OM_SUBPIX_BITS) - b;
        y0 = ((ly + 127 + B) >> OM_SUBPIX_BITS) - b;
        y1 = ((hy - 128 + B) >> OM_SUBPIX_BITS) - b;
    }
    if (x1 - x0 >= TINY || y1 - y0 >= TINY) return -1;
    x0 = x0 < 0 ? 0 : x0;
    x1 = x1 > (int32_t)tg->width - 1 ? (int32_t)tg->width - 1 : x1;
    y0 = y0 < (int32_t)tg->y0 ? (int32_t)tg->y0 : y0;
    y1 = y1 > (int32_t)(tg->y0 + tg->rows) - 1 ? (int32_t)(tg->y0 + tg->rows) - 1 : y1;
    if (x0 > x1 || y0 > y1) return 0;
    /* the box is below (TINY + 1) * 256 a side: so is every offset below */
    const int32_t X1 = xb - xa, Y1 = yb - ya, X2 = xc - xa, Y2 = yc - ya, a2 = X1 * Y2 - X2 * Y1;
    if (a2 == 0) return 0;
    /* om__tri2_setup's order, vertices 1 and 2 swapped where the area is negative, by
     * selects: the orientation of a random triangle is a coin toss to a branch */
    const int perm1 = a2 < 0 ? 2 : 1;
    const int32_t area2 = a2 < 0 ? -a2 : a2;
    const int32_t X[3] = {0, a2 < 0 ? X2 : X1, a2 < 0 ? X1 : X2}, Y[3] = {0, a2 < 0 ? Y2 : Y1, a2 < 0 ? Y1 : Y2};
    /* the edges at the first centre, and their steps a centre along and down */
    const int32_t S = OM_SUBPIX, P0 = x0 * S + S / 2 - xa, Q0 = y0 * S + S / 2 - ya;
    int32_t E[3], sx[3], sy[3];
    tiny_edge(X[0], Y[0], X[1], Y[1], P0, Q0, &E[0], &sx[0], &sy[0]);
    tiny_edge(X[1], Y[1], X[2], Y[2], P0, Q0, &E[1], &sx[1], &sy[1]);
    tiny_edge(X[2], Y[2], X[0], Y[0], P0, Q0, &E[2], &sx[2], &sy[2]);
    om__rtri t;
    bool plane = false;
    uint32_t zb[3];
    const uint32_t *zs = NULL;   /* the vertex depths, once a centre is covered */
    for (int32_t py = y0; py <= y1; py++) {
        int32_t e0 = E[0], e1 = E[1], e2 = E[2];
        uint32_t *dep = tg->depth + (size_t)(py - (int32_t)tg->y0) * tg->width;
        for (int32_t px = x0; px <= x1; px++, e0 += sx[0], e1 += sx[1], e2 += sx[2]) {
            if ((e0 | e1 | e2) < 0) continue;
            const int64_t P = (int64_t)px * S + S / 2 - xa, Q = (int64_t)py * S + S / 2 - ya;
            uint32_t d = 0;
            bool known = false;
            if (!zs) {   /* the first covered centre: the depths, and one division */
                zs = z ? z : zdepths(zc, zb);
                known = tiny_depth(zs[0], (int64_t)zs[perm1] - zs[0], (int64_t)zs[3 - perm1] - zs[0], X, Y, area2,
                                   P, Q, &d);
            }
            if (!known) {
                if (!plane) {
                    t.e.x[0] = xa;
                    t.e.y[0] = ya;
                    t.e.x[1] = x[perm1];
                    t.e.y[1] = y[perm1];
                    t.e.x[2] = x[3 - perm1];
                    t.e.y[2] = y[3 - perm1];
                    t.e.perm[0] = 0;
                    t.e.perm[1] = perm1;
                    t.e.perm[2] = 3 - perm1;
                    t.e.area2 = area2;
                    om__rtri_zplane(&t, zs);
                    plane = true;
                }
                d = (uint32_t)((t.zq0 + t.zqx * (uint64_t)P + t.zqy * (uint64_t)Q) >> 32);
            }
            if (r->mode == OM_RASTER_DEPTH_ID) {
                uint32_t *ids = tg->id + (size_t)(py - (int32_t)tg->y0) * tg->width;
                if (d < dep[px] || (d == dep[px] && id < ids[px] && d != 0xFFFFFFFFu)) {
                    dep[px] = d;
                    ids[px] = id;
                }
            } else if (d < dep[px]) {
                dep[px] = d;
            }
        }
        E[0] += sy[0];
        E[1] += sy[1];
        E[2] += sy[2];
    }
    return 1;
}

/* A triangle on the grid (x, y) into r's target. Its depths are z, or when z is NULL
 * those of clip-space vertices zc (om__zdepth, as om__project gives them), worked out
 * only once the triangle is known to reach a pixel: most of a detailed scene's
 * triangles hold no pixel centre, and each depth is a 64-bit division. `ranged`: the
 * caller's vertices are om__project's (within 2^26), so in_range need not look. */
static bool snapped(const om_raster *r, uint32_t *hiz, const int64_t x[3], const int64_t y[3],
                    const uint32_t *z, const om_vec4 *zc, uint32_t id, bool ranged)
{
    uint32_t zb[3];
    const bool cons = r->mode == OM_RASTER_CONSERVATIVE;
    /* The snapped triangle's own orientation decides, the one its coverage has: for a
     * closed surface, every texel centre a back face covers is then also covered by a
     * front face (the signed covers of a closed surface cancel), and nearer, since a
     * ray from outside enters before it leaves. */
    if (r->cull_back && (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]) > 0)
        return false;
    om__rtri t;
    if (r->mode != OM_RASTER_DEPTH || (hiz && !om__hiz_fits(r->target))) hiz = NULL;
    if (!cons && !r->grid_x && (ranged || in_range(x, y))) {
        const int32_t x32[3] = {(int32_t)x[0], (int32_t)x[1], (int32_t)x[2]};
        const int32_t y32[3] = {(int32_t)y[0], (int32_t)y[1], (int32_t)y[2]};
        const int got = tiny(r, x32, y32, z, zc, id, NULL);
        if (got >= 0) return got;
    }
    if (r->grid_x) {
        if (!om__tri2_setup(&t.e, x, y, !cons) || !bounds_grid(&t, r)) return false;
        if (!z) z = zdepths(zc, zb);
        om__rtri_zplane(&t, z);
        if (!(hiz && om__hiz_big(&t) && om__hiz_fill(r, hiz, &t, z))) fill_grid(r, &t);
        return true;
    }
    /* the bounds first: they need no edges, and most triangles of a detailed scene
     * hold no pixel centre of a small target; the setup's range test before them, as
     * om__tri2_setup would refuse the same triangles (after the cull, which most
     * back faces leave by; om__project's vertices, `ranged`, are always in range) */
    if ((!ranged && !in_range(x, y)) || !bounds(&t, x, y, r->target, cons) || !om__tri2_setup(&t.e, x, y, !cons))
        return false;
    if (!cons && !(hiz && om__hiz_big(&t))) {
        fill(r, &t, z, zc, id);   /* the depths too once a row holds a covered centre */
        return true;
    }
    if (!z) z = zdepths(zc, zb);
    if (cons) {
        om__rtri_zplane(&t, z);   /* the fixed-point plane alone (spsm_build.c asks for the
                                     double one, om__rtri_plane, where it needs it) */
        fill_conservative(r, &t);
    } else {
        om__rtri_zplane(&t, z);
        if (!om__hiz_fill(r, hiz, &t, z)) fill(r, &t, NULL, NULL, id);
    }
    return true;
}

bool om__raster_projected(const om_raster *r, uint32_t *hiz, const int64_t x[3], const int64_t y[3],
                          const uint32_t *z, const om_vec4 *clip, uint32_t id)
{
    return snapped(r, hiz, x, y, z, clip, id, true);
}

bool om__raster_projected32(const om_raster *r, uint32_t *hiz, const int32_t x[3], const int32_t y[3],
                            const uint32_t z[3], uint32_t id, const int32_t *box)
{
    /* snapped's first tests, then its tiny fill straight from the 32-bit vertices */
    const int64_t X[3] = {x[0], x[1], x[2]}, Y[3] = {y[0], y[1], y[2]};
    if (r->cull_back && (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]) > 0) return false;
    if (r->mode != OM_RASTER_CONSERVATIVE && !r->grid_x) {
        const int got = tiny(r, x, y, z, NULL, id, box);
        if (got >= 0) return got;
    }
    return snapped(r, hiz, X, Y, z, NULL, id, true);
}

bool om__raster_snapped(const om_raster *r, const int64_t x[3], const int64_t y[3], const uint32_t z[3],
                        uint32_t id)
{
    return snapped(r, NULL, x, y, z, NULL, id, false);
}

bool om__raster_snapped_hiz(const om_raster *r, uint32_t *hiz, const int64_t x[3], const int64_t y[3],
                            const uint32_t z[3], uint32_t id)
{
    return snapped(r, hiz, x, y, z, NULL, id, false);
}

int om__raster_tri(const om_raster *r, const om_vec4 clip[3], uint32_t id)
{
    return om__raster_tri_on_hiz(r, NULL, clip, id, r->target->width, r->target->height);
}

int om__raster_tri_on(const om_raster *r, const om_vec4 clip[3], uint32_t id, uint32_t width,
                      uint32_t height)
{
    return om__raster_tri_on_hiz(r, NULL, clip, id, width, height);
}

int om__raster_tri_on_hiz(const om_raster *r, uint32_t *hiz, const om_vec4 clip[3], uint32_t id,
                          uint32_t width, uint32_t height)
{
    return om__raster_tri_guarded(r, hiz, clip, id, width, height, om__guard_band(width, height));
}

om__guard om__guard_band(uint32_t width, uint32_t height)
{
    om__guard g = {guard(width), guard(height)};
    return g;
}

int om__raster_tri_guarded(const om_raster *r, uint32_t *hiz, const om_vec4 clip[3], uint32_t id,
                           uint32_t width, uint32_t height, om__guard g)
{
    int64_t gx[9], gy[9];
    uint32_t gz[9];
    /* A triangle inside every plane, as most are, is what om__clip_project would hand
     * back unclipped: its vertices projected, the depths left until needed. Every
     * inside test fails on a NaN and on an infinite x, y or z, so of the non-finite
     * vertices only w = +inf gets this far, and it is refused as below. */
    if (om__inside_band(&clip[0], g) & om__inside_band(&clip[1], g) & om__inside_band(&clip[2], g)) {
        if (!((clip[0].w - clip[0].w) + (clip[1].w - clip[1].w) + (clip[2].w - clip[2].w) == 0.0f)) return 0;
        for (int i = 0; i < 3; i++)
            if (!om__project_xy(&clip[i], width, height, &gx[i], &gy[i])) return 0;
        return snapped(r, hiz, gx, gy, NULL, clip, id, true);
    }
    /* finite: v - v is 0, and NaN for an infinity or a NaN, which the sum keeps */
    for (int i = 0; i < 3; i++)
        if (!((clip[i].x - clip[i].x) + (clip[i].y - clip[i].y) + (clip[i].z - clip[i].z) +
              (clip[i].w - clip[i].w) == 0.0f))
            return 0;
    int n = om__clip_project(clip, width, height, gx, gy, gz);
    int filled = 0;
    for (int k = 1; k + 1 < n; k++) {
        int64_t tx[3] = {gx[0], gx[k], gx[k + 1]}, ty[3] = {gy[0], gy[k], gy[k + 1]};
        uint32_t tz[3] = {gz[0], gz[k], gz[k + 1]};
        filled += snapped(r, hiz, tx, ty, tz, NULL, id, true);
    }
    return filled;
}
