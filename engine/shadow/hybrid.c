/* hybrid.c — exact shadows at close to a shadow map's cost. A conservative map of the
 * occlusion predicate's light grid (occlude.h) proves most samples lit or shadowed;
 * only the samples it leaves uncertain go through the irregular z-buffer (izb.c),
 * whose answer is the reference's. The result equals `ref` bit for bit.
 *
 * The map has side x side texels over the light's grid (hybrid.map, or by default
 * about half the image's larger side: map_side), each a square of
 * T x T grid points (the last row and column reach on to the guard band). A triangle
 * touches a texel when its edge functions admit a point of the texel's square (tested
 * against the square's extreme corner per edge: never missed, sometimes extra). Per
 * texel the build keeps
 *   lo      a plane below every touching triangle's depth over the square (clamped as
 *           the predicate clamps) plus its snapping bound;
 *   hi, cid over opaque triangles of one sub-triangle whose edges admit all four
 *           corners of the square (so every point of it: the admitted set is convex):
 *           the least of (their depth at the square's corner where their plane is
 *           greatest, + their bound), and which triangle gave it.
 * Depths are rounded outwards by a depth unit (far above the double evaluation's
 * error), then to float outwards.
 *
 * Why the two certain answers are the predicate's, for a sample p with grid point g in
 * texel e (om__blocks: a triangle t blocks p when t != p's own triangle, g is inside
 * t's first sub-triangle that admits it, and that sub-triangle's depth at g plus its
 * bound is below p.z):
 *   certainly lit when lo at g >= p.z. A blocker t admits g, so it touches e, and lo at
 *     g is at most its depth at g plus its bound, which is below p.z: lo < p.z.
 *   certainly shadowed when hi < p.z and cid != own. cid is one sub-triangle admitting
 *     every point of e, g among them (so it is the first that admits g), with depth
 *     at g at most its depth at the corner where its plane is greatest (the clamp
 *     keeps the order), so its depth + bound < p.z: it blocks p; it is opaque, so the
 *     optical depth saturates whatever else blocks, and the term is 0 in every
 *     channel, as the reference's. No predicate is run: the lookup is the answer.
 * A semi-transparent caster never makes a sample certain but lit (then nothing blocks
 * and the term is exactly 255); the sample's own triangle is excluded by its id; a
 * sample on a texel's border belongs to the one texel its grid point falls in, and
 * that texel's square holds the point. Everything else is uncertain. */
#include "shadow.h"
#include "hybrid.h"

#include <float.h>

/* A texel: a plane P(x, y) = z + gx (x - xc) + gy (y - yc) about the texel's centre,
 * below every touching triangle's depth plus bound over the texel (lo); and the
 * opaque triangle covering all of it whose greatest depth plus bound is least (hi,
 * cid). */
typedef struct htexel { float z, gx, gy, hi; uint32_t cid; } htexel;

/* hybrid's configuration: the sample pool's settings and its map's side. */
typedef struct hybrid_cfg {
    om__izb_cfg izb;
    uint32_t hybrid_map;   /* 0: auto (map_side) */
} hybrid_cfg;
OM__CFG_FITS(hybrid_cfg);

extern const om_method om__method_hybrid;

typedef struct hybrid_state {
    om__izb z;             /* first: the irregular z-buffer for the uncertain samples */
    hybrid_cfg cfg;
    htexel *map;
    uint32_t side;         /* texels per side */
    int64_t T;             /* grid units per texel side */
    int tshift;            /* log2(T) when T is a power of two (the default sides), else -1 */
    uint32_t lit, shadowed, uncertain;
} hybrid_state;

#define GRID_SIDE ((int64_t)OM_LIGHT_GRID * OM_SUBPIX)   /* 2^21 grid units */
#define FAR_OUT ((int64_t)1 << 27)   /* beyond every grid point a triangle can admit */

/* The map's side: as set, or by default the largest power of two at most half the
 * image's larger side (at least 16): texels of about 2 x 2 pixels where the light's
 * image and the camera's agree, and memory that scales with the image (512 at
 * 1024x768, 64 at 160x120). */
static uint32_t map_side(const hybrid_cfg *c, uint32_t w, uint32_t h)
{
    if (c->hybrid_map) return c->hybrid_map;
    uint32_t half = (w > h ? w : h) / 2, side = 16;
    while (side * 2 <= half && side < 4096) side *= 2;
    return side;
}

static size_t fixed_bytes(uint32_t side, const om_scene *s, bool cache)
{
    return om_arena_need(sizeof(hybrid_state), 16) + om__izb_parts_bytes(s, cache) +
           om_arena_need((size_t)side * side * sizeof(htexel), 16);
}

static om_status need(const hybrid_cfg *c, const om_scene *s, uint32_t w, uint32_t h,
                      size_t *min, size_t *full)
{
    if (c->izb.izb_leaf < 1 || c->hybrid_map > OM_LIGHT_GRID) return OM_E_INVALID;
    uint32_t one_pass = w * h, smallest = w, side = map_side(c, w, h);
    if (c->izb.izb_pool) one_pass = smallest = c->izb.izb_pool;
    *min = fixed_bytes(side, s, false) + om__izb_pool_bytes(smallest, c->izb.izb_leaf);
    *full = fixed_bytes(side, s, true) + om__izb_pool_bytes(one_pass, c->izb.izb_leaf);
    return OM_OK;
}

static om_status hybrid_bytes(const om_method_cfg *mc, const om_scene *s, uint32_t w, uint32_t h,
                              size_t *min, size_t *full)
{
    hybrid_cfg c;
    if (om__method_cfg_of(mc, &om__method_hybrid, &c, NULL)) return OM_E_INVALID;
    return need(&c, s, w, h, min, full);
}

static om_status hybrid_init(void **state, om_arena *a, const om_method_cfg *mc, const om_scene *s,
                             uint32_t w, uint32_t h, om_diag *d)
{
    om_status st;
    void *p;
    size_t mn, full;
    hybrid_cfg cv;
    const hybrid_cfg *c = &cv;
    if ((st = om__method_cfg_of(mc, &om__method_hybrid, &cv, d))) return st;
    if (c->izb.izb_leaf < 1) return om__fail(d, OM_E_INVALID, "hybrid: izb.leaf must be at least 1");
    if (c->hybrid_map > OM_LIGHT_GRID)
        return om__fail(d, OM_E_INVALID, "hybrid: hybrid.map must be 0 (auto) to 8192");
    if ((st = need(c, s, w, h, &mn, &full))) return st;
    if ((st = om__need(a, mn, "hybrid", d))) return st;
    if ((st = om_arena_alloc(a, sizeof(hybrid_state), 16, &p, d))) return st;
    hybrid_state *m = (hybrid_state *)p;
    m->cfg = *c;
    m->side = map_side(c, w, h);
    m->T = (GRID_SIDE + m->side - 1) / m->side;
    m->tshift = -1;
    for (int b = 0; b < 62; b++)
        if (((int64_t)1 << b) == m->T) m->tshift = b;
    size_t tex = (size_t)m->side * m->side;
    if ((st = om_arena_alloc(a, tex * sizeof(htexel), 16, &p, d))) return st;
    m->map = (htexel *)p;
    if ((st = om__izb_setup(&m->z, a, &c->izb, s, w * h, w, d))) return st;
    *state = m;
    return OM_OK;
}

static om_status hybrid_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    hybrid_state *m = (hybrid_state *)state;
    om__lspace_begin(&m->z.ls, v);
    memset(&m->z.st, 0, sizeof m->z.st);
    m->lit = m->shadowed = m->uncertain = 0;
    return OM_OK;
}

static om_status hybrid_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)state; (void)st; (void)d;
    return OM_OK;
}

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

/* Does any point of the square [x0, x1] x [y0, y1] pass every edge of e? Each edge is
 * tested at the corner where it is largest: a square outside one edge is out. */
static bool square_touches(const om__tri2 *e, int64_t x0, int64_t y0, int64_t x1, int64_t y1)
{
    for (int i = 0; i < 3; i++)
        if ((e->a[i] > 0 ? e->a[i] * x1 : e->a[i] * x0) + (e->b[i] > 0 ? e->b[i] * y1 : e->b[i] * y0) +
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

/* Adds sub-triangle r (with its bound) of triangle t to the texels it touches; `cover`:
 * r is an opaque triangle's only sub-triangle, a candidate for hi. */
static void add_sub(hybrid_state *m, const om__rtri *r, double bound, uint32_t t, bool cover)
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
    bool xlo = r->zx > 0.0, ylo = r->zy > 0.0;   /* where the plane is least */
    for (int64_t ty = ty0; ty <= ty1; ty++) {
        int64_t y0 = ty * m->T, y1 = y0 + m->T - 1;
        if (ty == 0) y0 = -FAR_OUT;
        if (ty == last) y1 = FAR_OUT;
        for (int64_t tx = tx0; tx <= tx1; tx++) {
            int64_t x0 = tx * m->T, x1 = x0 + m->T - 1;
                if (tx == 0) x0 = -FAR_OUT;
            if (tx == last) x1 = FAR_OUT;
            if (!square_touches(e, x0, y0, x1, y1)) continue;
            htexel *h = &m->map[ty * (int64_t)m->side + tx];
            int64_t xc = tx * m->T + m->T / 2, yc = ty * m->T + m->T / 2;
            if (h->gx != h->gx) {   /* empty (NaN): the texel takes this plane's slopes */
                h->gx = (float)r->zx;
                h->gy = (float)r->zy;
                h->z = FLT_MAX;
            }
            /* The clamped depth is at least min(plane, zmax): the least of each over
             * the square, less the texel's plane, bounds how far down z must go. */
            double gx = h->gx, gy = h->gy;
            double p0 = gx * (double)(x0 - xc) + gy * (double)(y0 - yc);
            double d0 = r->z0 + r->zx * (double)(x0 - e->x[0]) + r->zy * (double)(y0 - e->y[0]);
            double a = least_diff(d0, r->zx, r->zy, p0, gx, gy, x1 - x0, y1 - y0);
            double b = least_diff(r->zmax, 0.0, 0.0, p0, gx, gy, x1 - x0, y1 - y0);
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

static om_status hybrid_build(void *state, om_diag *d)
{
    (void)d;
    hybrid_state *m = (hybrid_state *)state;
    size_t n = (size_t)m->side * m->side;
    for (size_t i = 0; i < n; i++) {
        htexel *h = &m->map[i];
        h->z = h->hi = FLT_MAX;
        h->gx = h->gy = NAN;
        h->cid = OM_NO_TRI;
    }
    const om_scene *s = m->z.scene;
    for (uint32_t t = 0; t < s->ntris; t++) {
        om__ltri lt;
        if (!om__lspace_tri(&m->z.ls, t, &lt)) continue;
        bool cover = lt.n == 1 && om__odepth_opaque(&m->z.mat_od[s->tri_mat[t]]);
        for (int k = 0; k < lt.n; k++) add_sub(m, &lt.sub[k], lt.bound[k], t, cover);
    }
    return OM_OK;
}

/* The texel of a grid point: a shift rather than a division where it can be (this
 * runs once a sample); points off the grid take the border texels. */
static inline int64_t texel_of(const hybrid_state *m, int64_t v)
{
    if (v < 0) return 0;
    return m->tshift >= 0 ? v >> m->tshift : v / m->T;
}

static inline int classify(hybrid_state *m, const om__lpoint *p, om_term *t)
{
    int64_t last = (int64_t)m->side - 1, tx = texel_of(m, p->x), ty = texel_of(m, p->y);
    if (tx > last) tx = last;
    if (ty > last) ty = last;
    const htexel *h = &m->map[ty * (int64_t)m->side + tx];
    int64_t xc = tx * m->T + m->T / 2, yc = ty * m->T + m->T / 2;
    if ((double)h->z + (double)h->gx * (double)(p->x - xc) + (double)h->gy * (double)(p->y - yc) >= p->z ||
        h->z == FLT_MAX) {
        m->lit++;
        return 1;   /* the term is already 255 */
    }
    if ((double)h->hi < p->z && h->cid != p->tri) {
        t->r = t->g = t->b = 0;
        m->shadowed++;
        return 2;
    }
    m->uncertain++;
    return 0;
}

int om__hybrid_decide(void *state, const om__lpoint *p, om_term *t)
{
    return classify((hybrid_state *)state, p, t);
}

static bool decide(void *user, const om__lpoint *p, om_term *t)
{
    return classify((hybrid_state *)user, p, t) != 0;
}

static om_status hybrid_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    om__izb_resolve(&((hybrid_state *)state)->z, st, decide, state);
    return OM_OK;
}

static void hybrid_stats(const void *state, om_method_stats *out)
{
    const hybrid_state *m = (const hybrid_state *)state;
    const om__izb *z = &m->z;
    memset(out, 0, sizeof *out);
    out->bytes_used = fixed_bytes(m->side, z->scene, z->ls.verts != NULL) +
                      om__izb_pool_bytes(z->cap, z->leaf);
    static const char *const names[] = {"certain lit", "certain shadowed", "uncertain", "bsp nodes",
                                        "samples tested", "tiles", "pool samples"};
    uint32_t v[7] = {m->lit, m->shadowed, m->uncertain, z->st.nodes, z->st.tested, z->st.tiles, z->cap};
    for (int i = 0; i < 7; i++) {
        out->counters[i] = v[i];
        out->counter_names[i] = names[i];
    }
    out->ncounters = 7;
}

static const om_setting settings[] = {
    OM__SET_IZB_LEAF(hybrid_cfg, izb.izb_leaf), OM__SET_IZB_POOL(hybrid_cfg, izb.izb_pool),
    OM__SETTING(hybrid_cfg, hybrid_map, "hybrid.map", OM_SETTING_U32, 0, OM_MAX_DIM, 0,
                "side of its conservative map (20 bytes a texel), 0 = half the image's side"),
};

const om_method om__method_hybrid = {
    "hybrid", "exact: a conservative map decides most samples, the irregular z-buffer the rest",
    OM_METHOD_EXACT, hybrid_bytes, hybrid_init, hybrid_begin, hybrid_observe, hybrid_build,
    hybrid_resolve, hybrid_stats, NULL, settings, sizeof settings / sizeof settings[0],
    sizeof(hybrid_cfg),
};
