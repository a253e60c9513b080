/* raster.c — clipping, snapping and filling of triangles, and the coarse depth that
 * lets huge overlapping triangles skip tiles of a depth-only target. The rule is
 * written at the top of raster.h. Everything after the snap is integer, the depth
 * plane included: fixed point from one origin per triangle (so strips agree). */
#include "raster.h"
#include "../core/core.h"

#include <math.h>

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

void om__target_clear(const om_target *t)
{
    size_t n = (size_t)t->rows * t->width;
    for (size_t i = 0; i < n; i++) t->depth[i] = 0xFFFFFFFFu;
    if (t->id)
        for (size_t i = 0; i < n; i++) t->id[i] = OM_NO_TRI;
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

unsigned om__outcode(const om_vec4 *v, uint32_t width, uint32_t height)
{
    cvert c = {v->x, v->y, v->z, v->w};
    float gx = guard(width), gy = guard(height);
    unsigned mask = 0;
    for (int p = 0; p < 6; p++)
        if (!(plane_dist(p, &c, gx, gy) >= 0.0f)) mask |= 1u << p;
    return mask;
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
        unsigned mask = om__outcode(&clip[i], width, height);
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
 * given (that row of the id buffer). */
static void depth_row(const om__rtri *t, const om_target *tg, int32_t y, int32_t x0, int32_t x1,
                      uint32_t *id_row, uint32_t id)
{
    const int64_t S = OM_SUBPIX, H = OM_SUBPIX / 2;
    uint64_t z = t->zq0 + t->zqx * (uint64_t)((int64_t)x0 * S + H - t->e.x[0]) +
                 t->zqy * (uint64_t)((int64_t)y * S + H - t->e.y[0]);
    const uint64_t step = t->zqx * (uint64_t)S;
    uint32_t *dep = tg->depth + (size_t)(y - (int32_t)tg->y0) * tg->width;
    for (int32_t x = x0; x <= x1; x++, z += step) {
        const uint32_t d = (uint32_t)(z >> 32);
        if (d < dep[x]) {
            dep[x] = d;
            if (id_row) id_row[x] = id;
        }
    }
}

/* The plain fill. The depth plane (two divisions) is set up at the first row with a
 * covered pixel: most triangles of a detailed scene cover no pixel centre at all. */
static void fill(const om_raster *r, om__rtri *t, const uint32_t z[3], uint32_t id)
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
        if (z) {
            om__rtri_zplane(t, z);
            z = NULL;
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

/* ---- the coarse depth of a depth-only target (om__hiz_words in raster.h)
 *
 * Why a skip changes no texel. For a pixel the triangle covers at grid point p (dx, dy
 * from its origin), the fill stores the top half of zq0 + zqx dx + zqy dy mod 2^64,
 * and the rule at the top of raster.h says that sum never wraps inside the triangle:
 * with Rx, Ry the slopes as integers (zqx, zqy before the modulo), the depth is
 * floor(V(p) / 2^32) with V(p) = zq0 + Rx dx + Ry dy exact. V is affine, so over a
 * rectangle of grid points it is least at the corner c chosen by the slopes' signs,
 * and every covered pixel there has depth >= floor(V(c) / 2^32) >= B(c) (bound_x plus
 * bound_y: an integer lower bound of it). The test is strict (d < stored), so where B(c) is at
 * least the tile's bound every test in the tile fails: the tile is skipped. Rx, Ry
 * are known exactly only when they are moderate: |Rx|, |Ry| <= 2^62 (plane_split);
 * steeper triangles are slivers and take the plain path. A bound only ever needs to
 * be >= the stored depths, which only go down: the plain fill leaves the bounds as
 * they are, and a large triangle marks the tiles it wrote as stale. A stale tile's
 * bound is made its maximum again only when a later large triangle would otherwise
 * draw there (hiz_fresh1, hiz_fresh2), so a scene whose large triangles seldom
 * overlap (a floor, walls) reads no texel twice. */
#define HIZ_T1 8       /* first level: 8 x 8 texels */
#define HIZ_W2 256     /* second level: 16 rows x 256 columns, 2 x 32 first-level tiles */
#define HIZ_H2 16
#define HIZ_BIG 4096   /* triangles whose box holds this many texels take the tiles */
#define HIZ_REDRAW 4   /* see hiz_hot */

static uint32_t cdiv(uint32_t a, uint32_t b) { return (a + b - 1) / b; }

/* The layout: the first level's bounds (row-major, n1 a row), the second's (n2 a row),
 * a counter per second-level row, then a byte per tile of each level, set when the
 * tile is stale. */
typedef struct hiz_map {
    uint32_t *m1, *m2;
    uint32_t *drawn;       /* per second-level row: texels the tiled fill drew there */
    uint8_t *s1, *s2;
    uint32_t n1, n2, r1;   /* tiles a row at each level; first-level rows */
} hiz_map;

static hiz_map hiz_of(uint32_t *hiz, uint32_t width, uint32_t height)
{
    hiz_map h;
    h.n1 = cdiv(width, HIZ_T1);
    h.n2 = cdiv(width, HIZ_W2);
    h.r1 = cdiv(height, HIZ_T1);
    const size_t t1 = (size_t)h.r1 * h.n1, t2 = (size_t)cdiv(height, HIZ_H2) * h.n2;
    h.m1 = hiz;
    h.m2 = hiz + t1;
    h.drawn = hiz + t1 + t2;
    h.s1 = (uint8_t *)(h.drawn + cdiv(height, HIZ_H2));
    h.s2 = h.s1 + t1;
    return h;
}

size_t om__hiz_words(uint32_t width, uint32_t height)
{
    const size_t t = (size_t)cdiv(height, HIZ_T1) * cdiv(width, HIZ_T1) +
                     (size_t)cdiv(height, HIZ_H2) * cdiv(width, HIZ_W2);
    return t + cdiv(height, HIZ_H2) + (t + 3) / 4;
}

/* Tiles are shared by no two targets: see raster.h. */
static bool hiz_fits(const om_target *tg)
{
    return tg->y0 % HIZ_H2 == 0 && (tg->rows % HIZ_H2 == 0 || tg->y0 + tg->rows == tg->height) && tg->rows &&
           tg->width <= 32 * HIZ_W2;   /* a row of second-level tiles is one 32-bit mask */
}

void om__hiz_clear(uint32_t *hiz, const om_target *tg)
{
    if (!hiz || !hiz_fits(tg)) return;
    const hiz_map h = hiz_of(hiz, tg->width, tg->height);
    const uint32_t last = tg->y0 + tg->rows - 1;
    for (size_t i = (size_t)(tg->y0 / HIZ_T1) * h.n1; i < (size_t)(last / HIZ_T1 + 1) * h.n1; i++) {
        h.m1[i] = 0xFFFFFFFFu;
        h.s1[i] = 1;   /* stale: the plain fill may write before the tiles are used */
    }
    for (size_t i = (size_t)(tg->y0 / HIZ_H2) * h.n2; i < (size_t)(last / HIZ_H2 + 1) * h.n2; i++) {
        h.m2[i] = 0xFFFFFFFFu;
        h.s2[i] = 1;
    }
    for (uint32_t i = tg->y0 / HIZ_H2; i <= last / HIZ_H2; i++) h.drawn[i] = 0;
}

/* The plane as exact integers, each slope R split into R = h 2^32 + l, 0 <= l < 2^32. */
typedef struct hplane {
    int64_t z0, hx, lx, hy, ly, ox, oy;
} hplane;

/* floor(v / 2^32), by shifts of non-negative values (as pixel_floor). */
static inline int64_t floor32(int64_t v)
{
    return v >= 0 ? v >> 32 : -(int64_t)((0u - (uint64_t)v + 0xFFFFFFFFu) >> 32);   /* -ceil(-v / 2^32) */
}

/* The slopes as exact integers, when |R| <= 2^62. div_q32 gives R = +-(q 2^32 + f)
 * with q = floor(|n| / area2) and f <= 2^32; q < 2^30 exactly when
 * floor(|n| / 2^30) < area2, and then |R| <= 2^62, so zqx read as a signed 64-bit
 * value is R itself. */
static bool plane_split(const om__rtri *t, const uint32_t z[3], hplane *p)
{
    const om__tri2 *e = &t->e;
    const int64_t z0 = z[e->perm[0]], dz1 = (int64_t)z[e->perm[1]] - z0, dz2 = (int64_t)z[e->perm[2]] - z0;
    const int64_t x1 = e->x[1] - e->x[0], y1 = e->y[1] - e->y[0];
    const int64_t x2 = e->x[2] - e->x[0], y2 = e->y[2] - e->y[0];
    const int64_t n[2] = {dz1 * y2 - dz2 * y1, dz2 * x1 - dz1 * x2};
    const uint64_t q[2] = {t->zqx, t->zqy};
    int64_t h[2], l[2];
    for (int i = 0; i < 2; i++) {
        const uint64_t a = n[i] < 0 ? 0u - (uint64_t)n[i] : (uint64_t)n[i];
        if (!(e->area2 > 0) || (a >> 30) >= (uint64_t)e->area2) return false;
        const int64_t R = q[i] >> 63 ? -(int64_t)(0u - q[i]) : (int64_t)q[i];
        h[i] = floor32(R);
        l[i] = R - h[i] * 4294967296LL;
    }
    p->z0 = z0;
    p->hx = h[0]; p->lx = l[0];
    p->hy = h[1]; p->ly = l[1];
    p->ox = e->x[0];
    p->oy = e->y[0];
    return true;
}

/* A lower bound of every covered depth among the grid points [xa, xb] x [ya, yb]
 * (sub-pixel units, within the target: offsets below 2^30), as the sum of an x part
 * and a y part, so that a row of tiles shares its y part and a column its x part.
 * With d = c - origin at the least corner c, V(c) / 2^32 = z0 + hx dx + hy dy +
 * (2^31 + lx dx + ly dy) / 2^32, and floor(a + b + c) >= floor(a) + floor(b) +
 * floor(c): every term is exact and below 2^61 in size. */
static inline int64_t bound_x(const hplane *p, int64_t xa, int64_t xb)
{
    const int64_t dx = (p->hx >= 0 ? xa : xb) - p->ox;
    return p->hx * dx + floor32(p->lx * dx);
}

static inline int64_t bound_y(const hplane *p, int64_t ya, int64_t yb)
{
    const int64_t dy = (p->hy >= 0 ? ya : yb) - p->oy;
    return p->z0 + p->hy * dy + floor32(p->ly * dy);
}

/* A tile's grid points: pixel centres, or the grid's. */
static inline int64_t hiz_gx(const om_raster *r, int32_t x)
{
    return r->grid_x ? r->grid_x[x] : (int64_t)x * OM_SUBPIX + OM_SUBPIX / 2;
}

static inline int64_t hiz_gy(const om_raster *r, int32_t y)
{
    return r->grid_y ? r->grid_y[y] : (int64_t)y * OM_SUBPIX + OM_SUBPIX / 2;
}

/* The largest stored depth of first-level tile (X, Y). */
static uint32_t tile_max(const om_target *tg, uint32_t X, uint32_t Y)
{
    const uint32_t x1 = X * HIZ_T1 + HIZ_T1 < tg->width ? X * HIZ_T1 + HIZ_T1 : tg->width;
    const uint32_t y1 = Y * HIZ_T1 + HIZ_T1 < tg->height ? Y * HIZ_T1 + HIZ_T1 : tg->height;
    uint32_t m = 0;
    for (uint32_t y = Y * HIZ_T1; y < y1; y++) {
        const uint32_t *row = tg->depth + (size_t)(y - tg->y0) * tg->width;
        for (uint32_t x = X * HIZ_T1; x < x1; x++) m = row[x] > m ? row[x] : m;
    }
    return m;
}

/* Whether second-level row Y has been drawn over more than HIZ_REDRAW times by large
 * triangles (counted by their boxes until then): only then do large triangles there
 * take the tiles and stale tiles get their maximum again. Below that, as in a scene
 * of floors and walls, the tiles would cost more than they save. */
static bool hiz_hot(const hiz_map *h, const om_target *tg, uint32_t Y)
{
    return h->drawn[Y] > HIZ_REDRAW * HIZ_H2 * tg->width;
}

/* First-level tile (X, Y)'s bound, made its maximum again when stale in a hot row. */
static uint32_t hiz_fresh1(const hiz_map *h, const om_target *tg, uint32_t X, uint32_t Y)
{
    const size_t i = (size_t)Y * h->n1 + X;
    if (h->s1[i] && hiz_hot(h, tg, Y / 2)) {
        h->m1[i] = tile_max(tg, X, Y);
        h->s1[i] = 0;
    }
    return h->m1[i];
}

/* Second-level tile (X, Y)'s bound, made the largest of its first-level tiles' (each
 * fresh) when stale, likewise: first-level rows 2 Y and 2 Y + 1, columns 32 X to
 * 32 X + 31. */
static uint32_t hiz_fresh2(const hiz_map *h, const om_target *tg, uint32_t X, uint32_t Y)
{
    const size_t i = (size_t)Y * h->n2 + X;
    if (h->s2[i] && hiz_hot(h, tg, Y)) {
        const uint32_t c1 = X * 32 + 32 < h->n1 ? X * 32 + 32 : h->n1;
        uint32_t m = 0;
        for (uint32_t y = Y * 2; y < Y * 2 + 2 && y < h->r1; y++)
            for (uint32_t c = X * 32; c < c1; c++) {
                const uint32_t b = hiz_fresh1(h, tg, c, y);
                m = b > m ? b : m;
            }
        h->m2[i] = m;
        h->s2[i] = 0;
    }
    return h->m2[i];
}

/* The fill through the tiles: second-level tiles of the box whose bound the triangle
 * cannot beat are passed over whole; in the others, each row's run is drawn over the
 * first-level tiles it may beat, and the tiles written are marked stale. */
static void fill_hiz(const om_raster *r, om__rtri *t, const hplane *p, uint32_t *hiz)
{
    const om_target *tg = r->target;
    const om__tri2 *e = &t->e;
    const hiz_map h = hiz_of(hiz, tg->width, tg->height);
    const int64_t S = OM_SUBPIX, H = OM_SUBPIX / 2;
    const int64_t step[3] = {e->a[0] * S, e->a[1] * S, e->a[2] * S};
    const int32_t X0 = t->minx / HIZ_T1, X1 = t->maxx / HIZ_T1;   /* first-level columns */
    const int32_t XA = t->minx / HIZ_W2, XB = t->maxx / HIZ_W2;   /* second-level columns */
    int64_t bx2[32];   /* their bounds' x parts */
    for (int32_t X = XA; X <= XB; X++) {
        const int32_t xa = X * HIZ_W2 > t->minx ? X * HIZ_W2 : t->minx;
        const int32_t xb = X * HIZ_W2 + HIZ_W2 - 1 < t->maxx ? X * HIZ_W2 + HIZ_W2 - 1 : t->maxx;
        bx2[X] = bound_x(p, hiz_gx(r, xa), hiz_gx(r, xb));
    }
    int32_t cross[3] = {t->minx, t->minx, t->minx};
    bool fresh = true;   /* the grid's crossings must be searched again */
    for (int32_t Y2 = t->miny / HIZ_H2; Y2 <= t->maxy / HIZ_H2; Y2++) {
        const int32_t ya = Y2 * HIZ_H2 > t->miny ? Y2 * HIZ_H2 : t->miny;
        const int32_t yb = Y2 * HIZ_H2 + HIZ_H2 - 1 < t->maxy ? Y2 * HIZ_H2 + HIZ_H2 - 1 : t->maxy;
        const int64_t by = bound_y(p, hiz_gy(r, ya), hiz_gy(r, yb));
        const uint32_t *m2row = h.m2 + (size_t)Y2 * h.n2;
        uint32_t live2 = 0, dirty2 = 0, drawn = 0;
        for (int32_t X = XA; X <= XB; X++)
            if (by + bx2[X] < (int64_t)m2row[X] && by + bx2[X] < (int64_t)hiz_fresh2(&h, tg, (uint32_t)X, (uint32_t)Y2))
                live2 |= 1u << X;
        if (!live2) {
            fresh = true;
            continue;
        }
        for (int32_t Y = ya / HIZ_T1; Y <= yb / HIZ_T1; Y++) {
            const int32_t ra = Y * HIZ_T1 > ya ? Y * HIZ_T1 : ya;
            const int32_t rb = Y * HIZ_T1 + HIZ_T1 - 1 < yb ? Y * HIZ_T1 + HIZ_T1 - 1 : yb;
            const uint32_t *m1 = h.m1 + (size_t)Y * h.n1;
            const int64_t by1 = bound_y(p, hiz_gy(r, ra), hiz_gy(r, rb));
            /* live[w], dirty[w]: first-level tiles 32 w .. 32 w + 31, second-level tile w */
            uint32_t live[32], dirty[32];
            for (int32_t w = X0 >> 5; w <= X1 >> 5; w++) live[w] = dirty[w] = 0;
            for (int32_t X = X0; X <= X1; X++) {
                if (!((live2 >> (X >> 5)) & 1u)) {
                    X |= 31;
                    continue;
                }
                const int32_t xa = X * HIZ_T1 > t->minx ? X * HIZ_T1 : t->minx;
                const int32_t xb = X * HIZ_T1 + HIZ_T1 - 1 < t->maxx ? X * HIZ_T1 + HIZ_T1 - 1 : t->maxx;
                const int64_t b = by1 + bound_x(p, hiz_gx(r, xa), hiz_gx(r, xb));
                if (b < (int64_t)m1[X] && b < (int64_t)hiz_fresh1(&h, tg, (uint32_t)X, (uint32_t)Y))
                    live[X >> 5] |= 1u << (X & 31);
            }
            for (int32_t y = ra; y <= rb; y++) {
                int32_t lo, hi;
                if (r->grid_x) {
                    grid_span(r, t, y, cross, fresh, &lo, &hi);
                    fresh = false;
                } else {
                    int64_t py = (int64_t)y * S + H, px0 = (int64_t)t->minx * S + H, l, u;
                    const int64_t E[3] = {om__tri2_edge(e, 0, px0, py), om__tri2_edge(e, 1, px0, py),
                                          om__tri2_edge(e, 2, px0, py)};
                    if (!row_span(E, step, t->maxx - t->minx, &l, &u)) continue;
                    lo = t->minx + (int32_t)l;
                    hi = t->minx + (int32_t)u;
                }
                /* the runs of live tiles along lo..hi */
                const int32_t last = hi / HIZ_T1;
                for (int32_t a = om__mask_next(live, lo / HIZ_T1, last); a <= last;) {
                    /* a run of live tiles a..b, drawn in one go */
                    int32_t b = a;
                    for (;;) {
                        const uint32_t w = ~live[b >> 5] >> (b & 31);   /* clear bits from b on */
                        if (w) { b += om__ctz32(w) - 1; break; }
                        b = (b | 31) + 1;
                        if (b > last) break;
                    }
                    b = b > last ? last : b;
                    const int32_t xa = a * HIZ_T1 > lo ? a * HIZ_T1 : lo;
                    const int32_t xb = b * HIZ_T1 + HIZ_T1 - 1 < hi ? b * HIZ_T1 + HIZ_T1 - 1 : hi;
                    if (r->grid_x) grid_row(r, t, y, xa, xb);
                    else depth_row(t, tg, y, xa, xb, NULL, 0);
                    drawn += (uint32_t)(xb - xa + 1);
                    for (int32_t k = a; k <= b; k = (k | 31) + 1) {
                        const int32_t e1 = (k | 31) < b ? (k | 31) : b;   /* bits k..e1 of one word */
                        dirty[k >> 5] |= (0xFFFFFFFFu >> (31 - (e1 - k))) << (k & 31);
                    }
                    a = om__mask_next(live, b + 1, last);
                }
            }
            for (int32_t w = X0 >> 5; w <= X1 >> 5; w++) {
                if (!dirty[w]) continue;
                dirty2 |= 1u << w;
                for (uint32_t bits = dirty[w]; bits; bits &= bits - 1)
                    h.s1[(size_t)Y * h.n1 + (uint32_t)w * 32 + om__ctz32(bits)] = 1;
            }
        }
        for (uint32_t bits = dirty2; bits; bits &= bits - 1) h.s2[(size_t)Y2 * h.n2 + om__ctz32(bits)] = 1;
        h.drawn[Y2] = drawn > 0xFFFFFFFFu - h.drawn[Y2] ? 0xFFFFFFFFu : h.drawn[Y2] + drawn;
    }
}

/* Whether large triangle t takes the tiles: some row of its box is hot. Otherwise it
 * takes the plain fill, and its box is counted. */
static bool hiz_take(uint32_t *hiz, const om_target *tg, const om__rtri *t)
{
    const hiz_map h = hiz_of(hiz, tg->width, tg->height);
    bool hot = false;
    for (int32_t Y = t->miny / HIZ_H2; Y <= t->maxy / HIZ_H2 && !hot; Y++) hot = hiz_hot(&h, tg, (uint32_t)Y);
    if (hot) return true;
    for (int32_t Y = t->miny / HIZ_H2; Y <= t->maxy / HIZ_H2; Y++) {
        const int32_t ya = Y * HIZ_H2 > t->miny ? Y * HIZ_H2 : t->miny;
        const int32_t yb = Y * HIZ_H2 + HIZ_H2 - 1 < t->maxy ? Y * HIZ_H2 + HIZ_H2 - 1 : t->maxy;
        h.drawn[Y] += (uint32_t)((yb - ya + 1) * (t->maxx - t->minx + 1));   /* below 2^32: not hot before */
    }
    return false;
}

static bool snapped(const om_raster *r, uint32_t *hiz, const int64_t x[3], const int64_t y[3],
                    const uint32_t z[3], uint32_t id)
{
    const bool cons = r->mode == OM_RASTER_CONSERVATIVE;
    /* The snapped triangle's own orientation decides, the one its coverage has: for a
     * closed surface, every texel centre a back face covers is then also covered by a
     * front face (the signed covers of a closed surface cancel), and nearer, since a
     * ray from outside enters before it leaves. */
    if (r->cull_back && (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]) > 0)
        return false;
    om__rtri t;
    hplane hp;
    if (r->mode != OM_RASTER_DEPTH || (hiz && !hiz_fits(r->target))) hiz = NULL;
    if (r->grid_x) {
        if (!om__tri2_setup(&t.e, x, y, !cons) || !bounds_grid(&t, r)) return false;
        om__rtri_zplane(&t, z);
        if (hiz && (int64_t)(t.maxx - t.minx + 1) * (t.maxy - t.miny + 1) >= HIZ_BIG && plane_split(&t, z, &hp) &&
            hiz_take(hiz, r->target, &t))
            fill_hiz(r, &t, &hp, hiz);
        else
            fill_grid(r, &t);
        return true;
    }
    /* the bounds first: they need no edges, and most triangles of a detailed scene
     * hold no pixel centre of a small target (the setup's range test comes first, as
     * om__tri2_setup would refuse the same triangles) */
    for (int i = 0; i < 3; i++)
        if (x[i] > OM_TRI2_MAX_COORD || x[i] < -OM_TRI2_MAX_COORD || y[i] > OM_TRI2_MAX_COORD ||
            y[i] < -OM_TRI2_MAX_COORD)
            return false;
    if (!bounds(&t, x, y, r->target, cons) || !om__tri2_setup(&t.e, x, y, !cons)) return false;
    if (cons) {
        om__rtri_zplane(&t, z);
        om__rtri_plane(&t, z);   /* the spans' callers test the plane beyond the triangle */
        fill_conservative(r, &t);
    } else if (hiz && (int64_t)(t.maxx - t.minx + 1) * (t.maxy - t.miny + 1) >= HIZ_BIG) {
        om__rtri_zplane(&t, z);
        if (plane_split(&t, z, &hp) && hiz_take(hiz, r->target, &t)) fill_hiz(r, &t, &hp, hiz);
        else fill(r, &t, NULL, id);
    } else {
        fill(r, &t, z, id);
    }
    return true;
}

bool om__raster_snapped(const om_raster *r, const int64_t x[3], const int64_t y[3], const uint32_t z[3],
                        uint32_t id)
{
    return snapped(r, NULL, x, y, z, id);
}

bool om__raster_snapped_hiz(const om_raster *r, uint32_t *hiz, const int64_t x[3], const int64_t y[3],
                            const uint32_t z[3], uint32_t id)
{
    return snapped(r, hiz, x, y, z, id);
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
    int64_t gx[9], gy[9];
    uint32_t gz[9];
    for (int i = 0; i < 3; i++)
        if (!om__finite(clip[i].x) || !om__finite(clip[i].y) || !om__finite(clip[i].z) ||
            !om__finite(clip[i].w))
            return 0;
    int n = om__clip_project(clip, width, height, gx, gy, gz);
    int filled = 0;
    for (int k = 1; k + 1 < n; k++) {
        int64_t tx[3] = {gx[0], gx[k], gx[k + 1]}, ty[3] = {gy[0], gy[k], gy[k + 1]};
        uint32_t tz[3] = {gz[0], gz[k], gz[k + 1]};
        filled += snapped(r, hiz, tx, ty, tz, id);
    }
    return filled;
}
