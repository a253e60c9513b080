/* hiz.c — the coarse depth of a depth-only target (om__hiz_words in raster.h): its
 * layout, its bounds and how they are kept above the stored depths, and the fill of
 * large triangles through it, which passes over the tiles a triangle cannot beat
 * without touching a texel. raster.c decides which triangles come here (hiz.h); the
 * rows themselves are drawn by raster.c's fill. */
#include "hiz.h"

/* Why a skip changes no texel. For a pixel the triangle covers at grid point p (dx, dy
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
bool om__hiz_fits(const om_target *tg)
{
    return tg->y0 % HIZ_H2 == 0 && (tg->rows % HIZ_H2 == 0 || tg->y0 + tg->rows == tg->height) && tg->rows &&
           tg->width <= 32 * HIZ_W2;   /* a row of second-level tiles is one 32-bit mask */
}

void om__hiz_clear(uint32_t *hiz, const om_target *tg)
{
    if (!hiz || !om__hiz_fits(tg)) return;
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
                    om__fill_grid_span(r, t, y, cross, fresh, &lo, &hi);
                    fresh = false;
                } else {
                    int64_t py = (int64_t)y * S + H, px0 = (int64_t)t->minx * S + H, l, u;
                    const int64_t E[3] = {om__tri2_edge(e, 0, px0, py), om__tri2_edge(e, 1, px0, py),
                                          om__tri2_edge(e, 2, px0, py)};
                    if (!om__fill_row_span(E, step, t->maxx - t->minx, &l, &u)) continue;
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
                    if (r->grid_x) om__fill_grid_row(r, t, y, xa, xb);
                    else om__fill_depth_row(t, tg, y, xa, xb);
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

bool om__hiz_fill(const om_raster *r, uint32_t *hiz, om__rtri *t, const uint32_t z[3])
{
    hplane hp;
    if (!plane_split(t, z, &hp) || !hiz_take(hiz, r->target, t)) return false;
    fill_hiz(r, t, &hp, hiz);
    return true;
}
