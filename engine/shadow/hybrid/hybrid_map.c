/* hybrid_map.c — hybrid's conservative map (hybrid.c says what each texel holds and
 * why the lookup's certain answers are the predicate's): every triangle of the scene,
 * in its order, lowers the planes of the texels it touches and offers itself as their
 * cover. On the host's threads, by bands of the map's rows: a texel's updates come from
 * the same triangles in the same order whichever band holds it (the first to touch it
 * gives its slopes), so the same map. */
#include "hybrid.h"

/* A double depth to float, never above it: when rounding went up, from a point a
 * depth unit and a millionth below, far beyond half a float step. */
static float f_down(double v)
{
    float f = (float)v;
    return (double)f > v ? (float)(v - fabs(v) * 1e-6 - 1.0) : f;
}

/* A double depth to float, never below it (as f_down, the other way). */
static float f_up(double v)
{
    float f = (float)v;
    return (double)f < v ? (float)(v + fabs(v) * 1e-6 + 1.0) : f;
}

/* Does every point of the square pass every edge of e? Each edge is tested at the
 * corner where it is least. */
static bool square_inside(const om__tri2 *e, int64_t x0, int64_t y0, int64_t x1, int64_t y1)
{
    for (int i = 0; i < 3; i++)
        if ((e->a[i] > 0 ? e->a[i] * x0 : e->a[i] * x1) + (e->b[i] > 0 ? e->b[i] * y0 : e->b[i] * y1) +
                e->c[i] < 0)
            return false;
    return true;
}

/* The least of a - b over the square's corners, for a and b linear (a given at the
 * corner (x0, y0) with slopes ax, ay, b likewise): at the corner each slope picks. */
static double least_diff(double a0, double ax, double ay, double b0, double bx, double by, int64_t w,
                         int64_t h)
{
    double dx = ax - bx, dy = ay - by;
    return a0 - b0 + (dx < 0.0 ? dx * (double)w : 0.0) + (dy < 0.0 ? dy * (double)h : 0.0);
}

/* Adds sub-triangle r (with its bound) of triangle t to the texels it touches in the
 * map's rows [row0, row1); `cover`: r is an opaque triangle's only sub-triangle, a
 * candidate for hi. */
static void add_sub(hybrid_state *m, const om__rtri *r, double bound, uint32_t t, bool cover, int64_t row0,
                    int64_t row1)
{
    const om__tri2 *e = &r->e;
    int64_t lox = e->x[0], hix = e->x[0], loy = e->y[0], hiy = e->y[0];
    for (int i = 1; i < 3; i++) {
        if (e->x[i] < lox) lox = e->x[i];
        if (e->x[i] > hix) hix = e->x[i];
        if (e->y[i] < loy) loy = e->y[i];
        if (e->y[i] > hiy) hiy = e->y[i];
    }
    int64_t last = (int64_t)m->side - 1;
    int64_t tx0 = lox / m->T, tx1 = hix / m->T, ty0 = loy / m->T, ty1 = hiy / m->T;
    if (lox < 0) tx0 = 0;
    if (loy < 0) ty0 = 0;
    if (tx1 > last) tx1 = last;
    if (ty1 > last) ty1 = last;
    if (hix < 0 || hiy < 0 || tx0 > last || ty0 > last) return;
    if (ty0 < row0) ty0 = row0;
    if (ty1 >= row1) ty1 = row1 - 1;
    bool xlo = r->zx > 0.0, ylo = r->zy > 0.0;   /* where the plane is least */
    for (int64_t ty = ty0; ty <= ty1; ty++) {
        int64_t y0 = ty * m->T, y1 = y0 + m->T - 1;
        if (ty == 0) y0 = -FAR_OUT;
        if (ty == last) y1 = FAR_OUT;
        for (int64_t tx = tx0; tx <= tx1; tx++) {
            int64_t x0 = tx * m->T, x1 = x0 + m->T - 1;
            if (tx == 0) x0 = -FAR_OUT;
            if (tx == last) x1 = FAR_OUT;
            if (!om__square_touches(e, x0, y0, x1, y1)) continue;
            htexel *h = &m->map[ty * (int64_t)m->side + tx];
            int64_t xc = tx * m->T + m->T / 2, yc = ty * m->T + m->T / 2;
            if (h->gx != h->gx) {   /* empty (NaN): the texel takes this plane's slopes */
                h->gx = (float)r->zx;
                h->gy = (float)r->zy;
                h->z = FLT_MAX;
            }
            /* The clamped depth is at least min(plane, zmax): the least of each, less
             * the texel's plane, bounds how far down z must go, over the points the
             * triangle can admit in the square, which lie in its box too (where the
             * square reaches past the triangle's far corner, the plane there is
             * beyond zmax, and over the whole square min(plane, zmax) would fall by
             * up to a texel's depth slope below what any admitted point has). */
            const int64_t ax0 = x0 > lox ? x0 : lox, ax1 = x1 < hix ? x1 : hix;
            const int64_t ay0 = y0 > loy ? y0 : loy, ay1 = y1 < hiy ? y1 : hiy;
            double gx = h->gx, gy = h->gy;
            double p0 = gx * (double)(ax0 - xc) + gy * (double)(ay0 - yc);
            double d0 = r->z0 + r->zx * (double)(ax0 - e->x[0]) + r->zy * (double)(ay0 - e->y[0]);
            double a = least_diff(d0, r->zx, r->zy, p0, gx, gy, ax1 - ax0, ay1 - ay0);
            double b = least_diff(r->zmax, 0.0, 0.0, p0, gx, gy, ax1 - ax0, ay1 - ay0);
            float z = f_down((a < b ? a : b) + bound - 1.0);
            if (z < h->z) h->z = z;
            if (cover && lox <= x0 && hix >= x1 && loy <= y0 && hiy >= y1 &&
                square_inside(e, x0, y0, x1, y1)) {
                float hi = f_up(om__rtri_depth(r, xlo ? x1 : x0, ylo ? y1 : y0) + bound + 1.0);
                if (hi < h->hi) {
                    h->hi = hi;
                    h->cid = t;
                }
            }
        }
    }
}

/* The texels a grid box [lox, hix] x [loy, hiy] reaches. */
typedef struct trange { uint32_t x0, y0, x1, y1; } trange;

static trange texels_in(const hybrid_state *m, int64_t lox, int64_t loy, int64_t hix, int64_t hiy)
{
    trange r;
    r.x0 = (uint32_t)texel_of(m, lox);
    r.y0 = (uint32_t)texel_of(m, loy);
    r.x1 = (uint32_t)texel_of(m, hix);
    r.y1 = (uint32_t)texel_of(m, hiy);
    return r;
}

/* A projected triangle's bounds and nearest vertex depth; false when it needs
 * clipping (or the projection is not kept). */
static bool vbox_of(const hybrid_state *m, uint32_t t, om__lvbox *v)
{
    if (!m->ls.verts) return false;
    const uint32_t *ix = m->scene->idx + (size_t)t * 3;
    const om__lvert *a = &m->ls.verts[ix[0]], *b = &m->ls.verts[ix[1]], *c = &m->ls.verts[ix[2]];
    if (a->x == INT32_MIN || b->x == INT32_MIN || c->x == INT32_MIN) return false;
    *v = om__lvert_box(a, b, c);
    return true;
}

/* A small triangle (projected without clipping, its bounds within 2 x 2 texels and too
 * narrow to cover one) lowers the texels its bounds reach (a superset of those its
 * edges reach) to its nearest vertex's depth, without a setup: the predicate's depth
 * is clamped to the vertices' range and its bound is positive, so depth plus bound is
 * above that everywhere. As sharp as the plane where the texel is larger than the
 * triangle (the plane, continued over the texel, falls below it). False: the
 * triangle takes the full path. Only the map's rows [row0, row1) change. */
static bool add_small(hybrid_state *m, uint32_t t, int64_t row0, int64_t row1)
{
    om__lvbox v;
    if (!vbox_of(m, t, &v)) return false;
    if ((int64_t)v.hix - v.lox >= m->T - 1 && (int64_t)v.hiy - v.loy >= m->T - 1) return false;
    trange r = texels_in(m, v.lox, v.loy, v.hix, v.hiy);
    if ((r.x1 - r.x0 + 1) * (r.y1 - r.y0 + 1) > 4) return false;
    int64_t last = (int64_t)m->side - 1;
    for (int64_t ty = r.y0 > row0 ? r.y0 : row0; ty <= r.y1 && ty < row1; ty++)
        for (int64_t tx = r.x0; tx <= r.x1; tx++) {
            htexel *h = &m->map[ty * (int64_t)m->side + tx];
            int64_t x0 = tx * m->T, y0 = ty * m->T, x1 = x0 + m->T - 1, y1 = y0 + m->T - 1;
            int64_t xc = x0 + m->T / 2, yc = y0 + m->T / 2;
            if (tx == 0) x0 = -FAR_OUT;
            if (ty == 0) y0 = -FAR_OUT;
            if (tx == last) x1 = FAR_OUT;
            if (ty == last) y1 = FAR_OUT;
            if (h->gx != h->gx) {   /* empty: a flat plane */
                h->gx = h->gy = 0.0f;
                h->z = FLT_MAX;
            }
#if OM_FAST_FLOAT
            /* Most small triangles lie behind what the texel holds already: single
             * precision says so first where it can (as in plane_at_or_beyond: the
             * float is within s 2^-20 of the exact value, s the sum of its terms'
             * magnitudes, and f_down goes below a value by at most 2 + 4e-6 of it),
             * and then the double would leave z as it is. */
            const float gxf = h->gx, gyf = h->gy;
            const float a = gxf * (float)(int32_t)(x0 - xc), b = gyf * (float)(int32_t)(y0 - yc);
            const float c = gxf > 0.0f ? gxf * (float)(int32_t)(x1 - x0) : 0.0f;
            const float e = gyf > 0.0f ? gyf * (float)(int32_t)(y1 - y0) : 0.0f;
            const float zf = (float)v.z, lo = zf - a - b - c - e - 1.0f;
            const float err = (zf + om__fabsf(a) + om__fabsf(b) + c + e + 1.0f) * 0x1p-20f;
            if ((lo - err) - (om__fabsf(lo) + err) * 4e-6f - 2.0f >= h->z) continue;
#endif
            double gx = h->gx, gy = h->gy;
            double p0 = gx * (double)(x0 - xc) + gy * (double)(y0 - yc);
            float z = f_down(least_diff((double)v.z, 0.0, 0.0, p0, gx, gy, x1 - x0, y1 - y0) - 1.0);
            if (z < h->z) h->z = z;
        }
    return true;
}

/* The map's rows [row0, row1): cleared, then the updates to them of the n triangles
 * tris lists (NULL: every triangle of the scene), in the scene's order. */
static void build_rows(hybrid_state *m, uint32_t row0, uint32_t row1, const uint32_t *tris, uint32_t n)
{
    for (size_t i = (size_t)row0 * m->side; i < (size_t)row1 * m->side; i++) {
        htexel *h = &m->map[i];
        h->z = h->hi = FLT_MAX;
        h->gx = h->gy = NAN;
        h->cid = OM_NO_TRI;
    }
    const om_scene *s = m->scene;
    for (uint32_t i = 0; i < n; i++) {
        const uint32_t t = tris ? tris[i] : i;
#if OM_WITH_JOBS && (defined(__GNUC__) || defined(__clang__))
        /* A band's list skips through the scene, and its triangles' projected vertices
         * were written by every thread's parts of the set-up: ask for the next ones'
         * early (a hint: no effect on what is computed); without it a band waits on
         * the other cores' lines and two threads gain nothing over one. */
        if (tris && m->ls.verts && i + 8 < n) {
            const uint32_t *nx = s->idx + (size_t)tris[i + 8] * 3;
            for (int k = 0; k < 3; k++) __builtin_prefetch(&m->ls.verts[nx[k]]);
            if (i + 16 < n) __builtin_prefetch(s->idx + (size_t)tris[i + 16] * 3);
        }
#endif
        om__ltri lt;
        if (add_small(m, t, row0, row1) || !om__lspace_tri(&m->ls, t, &lt)) continue;
        bool cover = lt.n == 1 && om__odepth_opaque(&m->mat_od[s->tri_mat[t]]);
        for (int k = 0; k < lt.n; k++) add_sub(m, &lt.sub[k], lt.bound[k], t, cover, row0, row1);
    }
}

#if OM_WITH_JOBS
/* ---- by bands. The scene's triangles in n parts and the map's rows in n bands (band
 * b: rows [side b / n, side (b + 1) / n)). Each part finds the rows its triangles
 * reach and counts them into the bands; the counts give every part its place in each
 * band's list, where it writes its triangles in their order; each band then builds
 * its rows from its list: the triangles that reach them, in the scene's order, each
 * set up once a band it reaches. All in the state's tile, idle until the first strip's
 * tiles: the reach in its list (two words a triangle), the counts and lists in its
 * candidates' room (sixteen). */
#define MOST_BANDS 64u

/* The rows a triangle's updates can reach, first | last << 16 (the side is at most
 * 8192): those of its box, or where it needs clipping of its sub-triangles'; NONE
 * where it has none in the light's frustum. */
#define NONE 0xFFFFFFFFu
static uint32_t reach_of(const hybrid_state *m, uint32_t t)
{
    om__lvbox v;
    int64_t lo, hi;
    if (vbox_of(m, t, &v)) {
        lo = v.loy;
        hi = v.hiy;
    } else {
        om__ltri lt;
        if (!om__lspace_tri(&m->ls, t, &lt)) return NONE;
        lo = lt.loy;
        hi = lt.hiy;
    }
    return (uint32_t)texel_of(m, lo) | (uint32_t)texel_of(m, hi) << 16;
}

typedef struct build_job {
    hybrid_state *m;
    uint32_t n;
    uint32_t *reach;   /* each triangle's */
    uint32_t *at;      /* n x n: part p's count, then its next place, in band b's list (p n + b) */
    uint32_t *start;   /* n + 1: where each band's list starts in list */
    uint32_t *list;
} build_job;

/* The band that holds row y: the b with side b / n <= y < side (b + 1) / n. */
static uint32_t band_of(const build_job *j, uint32_t y)
{
    return (uint32_t)((((uint64_t)y + 1) * j->n - 1) / j->m->side);
}

static uint32_t part_of(const build_job *j, uint32_t k) { return (uint32_t)((uint64_t)j->m->scene->ntris * k / j->n); }

/* Part k's reach and counts (on a copy of its row of the table, whose rows share
 * cache lines, as list_part's places). */
static void reach_part(void *user, uint32_t k, void *scratch)
{
    (void)scratch;
    const build_job *j = (const build_job *)user;
    uint32_t at[MOST_BANDS] = {0};
    for (uint32_t t = part_of(j, k), end = part_of(j, k + 1); t < end; t++) {
        const uint32_t r = j->reach[t] = reach_of(j->m, t);
        if (r != NONE)
            for (uint32_t b = band_of(j, r & 0xFFFFu); b <= band_of(j, r >> 16); b++) at[b]++;
    }
    memcpy(j->at + (size_t)k * j->n, at, j->n * sizeof *at);
}

/* Part k's triangles into the bands' lists, at its places. */
static void list_part(void *user, uint32_t k, void *scratch)
{
    (void)scratch;
    const build_job *j = (const build_job *)user;
    uint32_t at[MOST_BANDS];
    memcpy(at, j->at + (size_t)k * j->n, j->n * sizeof *at);
    for (uint32_t t = part_of(j, k), end = part_of(j, k + 1); t < end; t++) {
        const uint32_t r = j->reach[t];
        if (r != NONE)
            for (uint32_t b = band_of(j, r & 0xFFFFu); b <= band_of(j, r >> 16); b++) j->list[at[b]++] = t;
    }
}

static void band_rows(void *user, uint32_t b, void *scratch)
{
    (void)scratch;
    const build_job *j = (const build_job *)user;
    const uint32_t side = j->m->side;
    build_rows(j->m, (uint32_t)((uint64_t)side * b / j->n), (uint32_t)((uint64_t)side * (b + 1) / j->n),
               j->list + j->start[b], j->start[b + 1] - j->start[b]);
}

/* The map by bands, about sixteen a thread (up to MOST_BANDS) taken as threads come
 * free: the rows' cost follows the scene (with a few bands a thread, one band can
 * hold most of the build). False where the tile has no room for
 * the lists (small scenes, whose build is short). */
static bool build_bands(hybrid_state *m)
{
    const uint32_t want = 16 * m->lend->slots;
    build_job j;
    j.m = m;
    j.n = want < MOST_BANDS ? want : MOST_BANDS;
    if (j.n > m->side) j.n = m->side;
    const size_t words = (size_t)m->cands * (sizeof(om__hcand) / sizeof(uint32_t)), table = (size_t)j.n * (j.n + 1) + 1;
    if (words <= table) return false;
    j.reach = m->tile.list;
    j.at = (uint32_t *)(void *)m->tile.cand;
    j.start = j.at + (size_t)j.n * j.n;
    j.list = j.start + j.n + 1;
    m->lend->run_any(m->lend, reach_part, &j, j.n);
    if (om__hplaces(j.at, j.n, j.n, j.start) > words - table) return false;   /* the lists do not fit */
    m->lend->run_any(m->lend, list_part, &j, j.n);
    m->lend->run_any(m->lend, band_rows, &j, j.n);
    return true;
}
#endif

/* By bands where the frame lends the host's threads and the state's tile has room for
 * candidates; else every row here. */
om_status om__hybrid_build(void *state, om_diag *d)
{
    (void)d;
    hybrid_state *m = (hybrid_state *)state;
#if OM_WITH_JOBS
    if (m->lend && m->cands && build_bands(m)) return OM_OK;
#endif
    build_rows(m, 0, m->side, NULL, m->scene->ntris);
    return OM_OK;
}
