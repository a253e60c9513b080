/* rtw.c — the `rtw` method: Rectilinear Texture Warping shadow maps (paper 003). A
 * conventional depth texture plus two 1-D warp tables that give the light's image
 * more texels where the view needs them (section 3).
 *
 * Per frame (section 4's algorithm):
 *   observe  (a) backward analysis: every exposed visible sample raises the importance
 *            of its cell (rtw_warp.c)
 *   build    (a) forward analysis, if asked; (b) collapse, blur, warp tables
 *            (rtw_warp.c); (c) render the warped map. By default (rtw_exact) every
 *            texel samples the unwarped scene at the point its centre warps from, so
 *            edges need no tessellation (not in the paper: a GPU can only draw warped
 *            vertices). With rtw_exact 0, the paper's way: vertices are warped after
 *            the perspective divide (4.3), long edges tessellated first (6.1)
 *   resolve  (d) lookup: the sample's light coordinates are warped (4.4) and tested
 *            with the conventional map's bias rules, in warped texels (smlookup.c;
 *            in float here where that gives the same bits)
 * All state lives in the method's arena; nothing persists between frames but the
 * buffers. */
#include "../method.h"
#include "rtw.h"
#include "../common/occlude.h"   /* OM_LIGHT_GRID */

OM__CFG_FITS(om__rtw_cfg);
extern const om_method om__method_rtw;

/* ---------------------------------------------------------------- sizes */

/* The importance map's side: as asked, or by default 512 (section 6's size), no finer
 * than the map itself (a super-cell narrower than a texel moves nothing); at least 8
 * either way (a side asked below 8 is 8, so every value the setting takes renders). */
uint32_t om__rtw_importance_side(const om__rtw_cfg *c)
{
    if (c->rtw_importance) return c->rtw_importance < 8 ? 8 : c->rtw_importance;
    uint32_t n = c->map_size < 512 ? c->map_size : 512;
    return n < 8 ? 8 : n;
}

/* The exact map's grid indexes: buckets of 2^shift light-grid units, about as many as
 * the map has texels per side. */
static uint32_t grid_shift(uint32_t size)
{
    const uint32_t steps = OM_LIGHT_GRID * OM_SUBPIX;
    uint32_t s = 0;
    while ((steps >> (s + 1)) >= size) s++;
    return s;
}

static uint32_t grid_buckets(uint32_t size)
{
    return ((OM_LIGHT_GRID * OM_SUBPIX) >> grid_shift(size)) + 1;
}

static size_t rtw_need(const om__rtw_cfg *c)
{
    size_t n = om__rtw_importance_side(c), nn = n * n, s = c->map_size;
    size_t b = om_arena_need(sizeof(om__rtw), 16) + om_arena_need(nn * sizeof(float), 16) +
               om_arena_need((nn + 7) / 8, 16) + om_arena_need(n * sizeof(double), 16) * 3 +
               om_arena_need((OM_RTW_MAX_RADIUS + 1) * sizeof(double), 16) +
               om_arena_need((n + 1) * sizeof(int32_t), 16) * 2 +
               om_arena_need(s * s * sizeof(uint32_t), 16);
    if (c->rtw_analysis != OM_RTW_BACKWARD) b += om_arena_need(nn * sizeof(uint32_t), 16) * 2;
    if (c->rtw_exact)
        b += om_arena_need(s * sizeof(int64_t), 16) * 2 +
             om_arena_need(((size_t)grid_buckets(c->map_size) + 1) * sizeof(int32_t), 16) * 2;
    return b;
}

static const char *check_cfg(const om__rtw_cfg *c)
{
    if (c->map_size < 1 || c->map_size > OM_MAX_DIM) return "rtw: map size must be 1..8192";
    if (c->pcf < 1 || c->pcf > 9) return "rtw: pcf must be 1..9";
    if (c->rtw_importance > OM_MAX_DIM)
        return "rtw: importance map side must be 0..8192 (0: 512, or the map's side if smaller)";
    if (c->rtw_analysis > 2) return "rtw: analysis must be 0 (backward), 1 (forward) or 2 (hybrid)";
    if (c->rtw_funcs > 15) return "rtw: importance functions are a mask of 1, 2, 4, 8";
    if (!(c->rtw_sigma >= 0.0f && c->rtw_sigma <= 64.0f)) return "rtw: sigma must be 0..64";
    if (!(c->rtw_tess >= 0.0f && c->rtw_tess <= 1.0f)) return "rtw: tessellation must be 0..1";
    if (c->rtw_exact > 1) return "rtw: exact must be 0 (warped vertices) or 1 (inverse-warped texel centres)";
    if (c->rtw_footprint > 1) return "rtw: footprint must be 0 (PCF taps a warped texel apart) or 1 (an unwarped one)";
    return NULL;
}

static size_t hiz_bytes(const om__rtw_cfg *c)
{
    return om_arena_need(om__hiz_words(c->map_size, c->map_size) * sizeof(uint32_t), 16);
}

static om_status rtw_bytes(const om_method_cfg *mc, const om_scene *s, uint32_t w, uint32_t h,
                           size_t *min, size_t *full)
{
    (void)s; (void)w; (void)h;
    om__rtw_cfg c;
    if (om__method_cfg_of(mc, &om__method_rtw, &c, NULL) || check_cfg(&c)) return OM_E_INVALID;
    *min = rtw_need(&c);
    *full = *min + hiz_bytes(&c);   /* the coarse depth bounds the cost of huge triangles */
    return OM_OK;
}

static om_status carve(om_arena *a, size_t bytes, void **out, om_diag *d)
{
    return om_arena_alloc(a, bytes, 16, out, d);
}

static om_status rtw_init(void **state, om_arena *a, const om_method_cfg *mc, const om_scene *s,
                          uint32_t w, uint32_t h, om_diag *d)
{
    (void)w; (void)h;
    om_status st;
    void *p;
    om__rtw_cfg cv;
    const om__rtw_cfg *c = &cv;
    if ((st = om__method_cfg_of(mc, &om__method_rtw, &cv, d))) return st;
    const char *bad = check_cfg(c);
    if (bad) return om__fail(d, OM_E_INVALID, bad);
    if ((st = om__need(a, rtw_need(c), "rtw", d))) return st;
    if ((st = carve(a, sizeof(om__rtw), &p, d))) return st;
    om__rtw *m = (om__rtw *)p;
    m->scene = s;
    m->cfg = *c;
    m->n = om__rtw_importance_side(c);
    m->size = c->map_size;
    size_t n = m->n, nn = n * n;
    if ((st = carve(a, nn * sizeof(float), &p, d))) return st;
    m->imp = (float *)p;
    if ((st = carve(a, (nn + 7) / 8, &p, d))) return st;
    m->seen = (uint8_t *)p;
    if ((st = carve(a, n * sizeof(double), &p, d))) return st;
    m->cols = (double *)p;
    if ((st = carve(a, n * sizeof(double), &p, d))) return st;
    m->rows = (double *)p;
    if ((st = carve(a, n * sizeof(double), &p, d))) return st;
    m->scratch = (double *)p;
    if ((st = carve(a, (OM_RTW_MAX_RADIUS + 1) * sizeof(double), &p, d))) return st;
    m->kernel = (double *)p;
    if ((st = carve(a, (n + 1) * sizeof(int32_t), &p, d))) return st;
    m->px = (int32_t *)p;
    if ((st = carve(a, (n + 1) * sizeof(int32_t), &p, d))) return st;
    m->py = (int32_t *)p;
    if ((st = carve(a, (size_t)m->size * m->size * sizeof(uint32_t), &p, d))) return st;
    m->depth = (uint32_t *)p;
    m->gridx = m->gridy = NULL;
    m->gridxs = m->gridys = NULL;
    m->grid_shift = grid_shift(m->size);
    m->grid_buckets = grid_buckets(m->size);
    if (c->rtw_exact) {
        if ((st = carve(a, (size_t)m->size * sizeof(int64_t), &p, d))) return st;
        m->gridx = (int64_t *)p;
        if ((st = carve(a, (size_t)m->size * sizeof(int64_t), &p, d))) return st;
        m->gridy = (int64_t *)p;
        if ((st = carve(a, ((size_t)m->grid_buckets + 1) * sizeof(int32_t), &p, d))) return st;
        m->gridxs = (int32_t *)p;
        if ((st = carve(a, ((size_t)m->grid_buckets + 1) * sizeof(int32_t), &p, d))) return st;
        m->gridys = (int32_t *)p;
    }
    if (c->rtw_analysis != OM_RTW_BACKWARD) {
        if ((st = carve(a, nn * sizeof(uint32_t), &p, d))) return st;
        m->fdepth = (uint32_t *)p;
        if ((st = carve(a, nn * sizeof(uint32_t), &p, d))) return st;
        m->fid = (uint32_t *)p;
    }
    /* Tessellation limit in [0, 1] units of the map, never below one texel: shorter
     * warped edges cannot bend visibly, and the recursion must end. */
    m->limit = c->rtw_tess > 0.0f ? (double)c->rtw_tess : 0.0;
    if (m->limit > 0.0 && m->limit < 1.0 / (double)m->size) m->limit = 1.0 / (double)m->size;
    m->look.depth = m->depth;
    m->look.size = m->size;
    m->look.window = 1.0f;   /* the whole light image */
    m->look.bias_const = c->bias_const;
    m->look.bias_slope = c->bias_slope;
    m->look.normal_offset = c->normal_offset;
    m->look.pcf = c->pcf;
    m->look.warp_x = m->px;
    m->look.warp_y = m->py;
    m->look.warp_n = m->n;
    m->look.unwarped_pcf = c->rtw_footprint == 1;
    for (uint32_t k = 0; k <= m->n; k++) m->px[k] = m->py[k] = (int32_t)(((int64_t)k * OM_RTW_ONE + m->n / 2) / m->n);
#if OM_WITH_JOBS
    om__lent_take(&m->lent, NULL);
#endif
    m->hiz = NULL;
    if (om_arena_left(a) >= hiz_bytes(c) && carve(a, om__hiz_words(m->size, m->size) * sizeof(uint32_t), &p, NULL) == OM_OK)
        m->hiz = (uint32_t *)p;
    *state = m;
    return OM_OK;
}

/* ---------------------------------------------------------------- frame */

static om_status rtw_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    om__rtw *m = (om__rtw *)state;
    m->view = *v;
    om__smlook_begin(&m->look, &m->view);
    m->samples = m->shadowed = m->tris_drawn = 0;
    om__rtw_importance_begin(m);
    return OM_OK;
}

static om_status rtw_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)d;
    om__rtw_observe_strip((om__rtw *)state, st);
    return OM_OK;
}

static om_status rtw_build(void *state, om_diag *d)
{
    (void)d;
    om__rtw *m = (om__rtw *)state;
    om__rtw_importance_finish(m);
    om__rtw_build_tables(m);
    om__rtw_render_map(m);
    return OM_OK;
}

/* ---------------------------------------------------------------- the warped map */

/* A vertex of the map's triangles: unwarped light clip coordinates (where subdivision
 * happens: midpoints there are the triangle's own points) and its warped position. */
typedef struct tvert {
    om_vec4 c;
    double u, v;           /* warped normalized coordinates */
} tvert;

typedef struct tess_ctx {
    const om__rtw *m;
    om_raster r;
    uint32_t tri;
    double limit2;         /* squared longest warped edge; 0 = no tessellation */
    double bend2;          /* squared RTW_BEND in [0, 1] units of the map */
    uint32_t drawn;
    uint32_t cap;          /* most triangles a frame may draw before splitting stops */
} tess_ctx;

static void warp_vert(const om__rtw *m, tvert *t)
{
    double iw = 1.0 / (double)t->c.w;
    t->u = om__rtw_apply(m->px, m->n, ((double)t->c.x * iw + 1.0) * 0.5, NULL);
    t->v = om__rtw_apply(m->py, m->n, (1.0 - (double)t->c.y * iw) * 0.5, NULL);
}

/* The midpoint in clip space. (a + b) * 0.5 is the same bits whichever end comes
 * first, so two triangles sharing an edge split it at the same vertex. */
static tvert midpoint(const om__rtw *m, const tvert *a, const tvert *b)
{
    tvert r;
    r.c.x = (a->c.x + b->c.x) * 0.5f;
    r.c.y = (a->c.y + b->c.y) * 0.5f;
    r.c.z = (a->c.z + b->c.z) * 0.5f;
    r.c.w = (a->c.w + b->c.w) * 0.5f;
    warp_vert(m, &r);
    return r;
}

/* Whether an edge is split depends on the edge alone (its two ends, symmetrically),
 * never on the triangle: neighbours make the same choice and the map has no cracks.
 * An edge is split when it is longer than the limit and the warp bends it: its warped
 * midpoint (*mid, made here) lies off the straight line between its warped ends by more
 * than RTW_BEND texels. Where the warp is straight along an edge (a region of even
 * density, however magnified) splitting would move no texel, so it is not done. */
#define RTW_BEND 0.25
static bool must_split(const tess_ctx *x, const tvert *a, const tvert *b, tvert *mid)
{
    double du = a->u - b->u, dv = a->v - b->v;
    if (!(du * du + dv * dv > x->limit2)) return false;
    *mid = midpoint(x->m, a, b);
    double eu = mid->u - (a->u + b->u) * 0.5, ev = mid->v - (a->v + b->v) * 0.5;
    return eu * eu + ev * ev > x->bend2;
}

static void emit(tess_ctx *x, const tvert *a, const tvert *b, const tvert *c)
{
    /* Straight onto the map's sub-texel grid: the warped x/w and y/w are u and v, the
     * depth stays z/w (section 4.3; the lead's note on warping after the divide). The
     * triangle is clipped already (clip_tri), so the rasterizer's clipping is skipped. */
    const tvert *t[3] = {a, b, c};
    const double s = (double)x->m->size * OM_SUBPIX;
    int64_t gx[3], gy[3];
    uint32_t gz[3];
    for (int k = 0; k < 3; k++)
        if (!om__snap(t[k]->u * s, t[k]->v * s, (double)t[k]->c.z * (1.0 / (double)t[k]->c.w) * OM_DEPTH_ONE,
                      &gx[k], &gy[k], &gz[k]))
            return;
    om__raster_snapped_hiz(&x->r, x->m->hiz, gx, gy, gz, x->tri);
    x->drawn++;
}

/* Section 6.1: subdivide until no warped edge is longer than the limit. An edge that
 * is too long is halved; the 1, 2 or 3 split edges of a triangle give 2, 3 or 4 parts.
 * The recursion ends because the warp's slope is at most n: halving shrinks every
 * edge's warped length below the limit (>= one texel) within log2(2 n size) levels.
 * Work stays bounded for hostile scenes (thousands of map-sized triangles): past a cap
 * (64 triangles per scene triangle plus 64 map-covering layers at the limit; real
 * scenes use a small part of it) the rest of the frame is drawn without splitting. */
static void tess(tess_ctx *x, const tvert *a, const tvert *b, const tvert *c, int depth)
{
    bool sab = false, sbc = false, sca = false;
    tvert mab, mbc, mca;
    if (x->limit2 > 0.0 && depth < 40 && x->drawn < x->cap) {
        sab = must_split(x, a, b, &mab);
        sbc = must_split(x, b, c, &mbc);
        sca = must_split(x, c, a, &mca);
    }
    int n = (int)sab + (int)sbc + (int)sca;
    if (n == 0) { emit(x, a, b, c); return; }
    /* rotate so that the split edges come first: ab when one, ab and bc when two */
    if (n == 1) {
        if (sbc) { const tvert *t = a; a = b; b = c; c = t; mab = mbc; }
        else if (sca) { const tvert *t = c; c = b; b = a; a = t; mab = mca; }
        tess(x, a, &mab, c, depth + 1);
        tess(x, &mab, b, c, depth + 1);
    } else if (n == 2) {
        if (!sab) { const tvert *t = a; a = b; b = c; c = t; mab = mbc; mbc = mca; }   /* bc, ca -> ab, bc */
        else if (!sbc) { const tvert *t = c; c = b; b = a; a = t; mbc = mab; mab = mca; }   /* ca, ab -> ab, bc */
        tess(x, &mab, b, &mbc, depth + 1);
        tess(x, a, &mab, &mbc, depth + 1);
        tess(x, a, &mbc, c, depth + 1);
    } else {
        tess(x, a, &mab, &mca, depth + 1);
        tess(x, &mab, b, &mbc, depth + 1);
        tess(x, &mca, &mbc, c, depth + 1);
        tess(x, &mab, &mbc, &mca, depth + 1);
    }
}

/* Signed distance of a clip vertex to plane p: near z >= 0, far z <= w, then the four
 * sides |x|, |y| <= g w of a band just beyond the map (what lies further out is never
 * looked up, and the warp is the identity there anyway). */
static float plane_dist(int p, const om_vec4 *v, float g)
{
    switch (p) {
    case 0: return v->z;
    case 1: return v->w - v->z;
    case 2: return v->x + g * v->w;
    case 3: return g * v->w - v->x;
    case 4: return v->y + g * v->w;
    default: return g * v->w - v->y;
    }
}

/* Cut from the inside vertex towards the outside one, as the rasterizer does, so that
 * an edge shared by two triangles is cut at the same point in both. */
static om_vec4 cut(const om_vec4 *in, const om_vec4 *out, float din, float dout)
{
    float t = din / (din - dout);
    om_vec4 r;
    r.x = in->x + t * (out->x - in->x);
    r.y = in->y + t * (out->y - in->y);
    r.z = in->z + t * (out->z - in->z);
    r.w = in->w + t * (out->w - in->w);
    return r;
}

/* Clips a triangle before warping: the warp needs w > 0 (the near plane gives it), and
 * tessellating geometry far outside the map would only waste time. */
static int clip_tri(const om_vec4 in[3], float g, om_vec4 *out)
{
    om_vec4 buf[2][10];
    int n = 3, cur = 0;
    for (int i = 0; i < 3; i++) buf[0][i] = in[i];
    for (int p = 0; p < 6 && n > 0; p++) {
        om_vec4 *src = buf[cur], *dst = buf[cur ^ 1];
        int k = 0;
        bool any_out = false;
        for (int i = 0; i < n; i++) any_out |= !(plane_dist(p, &src[i], g) >= 0.0f);
        if (!any_out) continue;
        for (int i = 0; i < n; i++) {
            const om_vec4 *a = &src[i], *b = &src[i + 1 == n ? 0 : i + 1];
            float da = plane_dist(p, a, g), db = plane_dist(p, b, g);
            bool ina = da >= 0.0f, inb = db >= 0.0f;
            if (ina) dst[k++] = *a;
            if (ina && !inb) dst[k++] = cut(a, b, da, db);
            else if (!ina && inb) dst[k++] = cut(b, a, db, da);
        }
        n = k;
        cur ^= 1;
    }
    for (int i = 0; i < n; i++) out[i] = buf[cur][i];
    return n < 3 ? 0 : n;
}

/* The exact warped map (rtw_exact): texel (x, y) holds the nearest depth of the
 * unwarped light image at the point its centre warps from, (gridx[x], gridy[y]) on the
 * occlusion predicate's grid. The warp is separable and monotonic, so those points form
 * a rectilinear grid and the rasterizer samples it directly (om_raster.grid_x): edges
 * stay straight where they are straight, in the unwarped image, and no triangle needs
 * splitting. The map is what a conventional map as fine as the warp would hold at
 * those points, and the lookup reads the texel whose centre is nearest in warped
 * coordinates, as before.
 *
 * By rows of the map (the frame's bands, om__bands.build_rows): each band clears and
 * fills its own rows. With bins (made through the light's matrix for a map_size image,
 * conservative by a row), a triangle whose unwarped rows miss the band's grid rows is
 * passed over; the map is the same. A sub-triangle counts as drawn in the band that
 * holds its first grid row, so the count is the same whatever the bands. */
static uint32_t render_exact(const om__rtw *m, om_raster *r, const om__bins *bins)
{
    const om_scene *s = m->scene;
    const om_target *tg = r->target;
    r->grid_x = m->gridx;
    r->grid_y = m->gridy;
    r->grid_xs = m->gridxs;
    r->grid_ys = m->gridys;
    r->grid_shift = m->grid_shift;
    r->grid_buckets = m->grid_buckets;
    /* the band's grid rows, and the last grid row above it (a sub-triangle whose top
     * lies past that starts in this band) */
    const int64_t g0 = m->gridy[tg->y0], g1 = m->gridy[tg->y0 + tg->rows - 1];
    const int64_t above = tg->y0 ? m->gridy[tg->y0 - 1] : INT64_MIN;
    /* a bin row of the map_size image is unit_num / unit_den grid units high */
    const int64_t unit_num = (int64_t)OM_LIGHT_GRID * OM_SUBPIX, unit_den = m->size;
    const uint32_t *rows = bins ? bins->rows : NULL;
    om__cull cl;
    om__cull_begin(&cl, s, &m->view.light_vp, m->view.origin);
    uint32_t drawn = 0;
    for (uint32_t t = 0; t < s->ntris; t++) {
        if (OM_WITH_JOBS && rows) {
            const uint32_t r0 = rows[t] & 0xFFFFu, r1 = rows[t] >> 16;
            if (r0 > r1) continue;   /* covers nothing */
            /* rows at the image's edges were clamped there: open-ended */
            if (r0 > 0 && (int64_t)r0 * unit_num / unit_den > g1) continue;
            if (r1 + 1 < m->size && ((int64_t)r1 + 1) * unit_num / unit_den + 1 < g0) continue;
        }
        om_vec4 c[3];
        om__clip_tri(s, &m->view.light_vp, m->view.origin, t, c);
        r->cull_back = om__cull_next(&cl, t);
        bool ok = true;
        for (int k = 0; k < 3; k++)
            ok = ok && om__finite(c[k].x) && om__finite(c[k].y) && om__finite(c[k].z) && om__finite(c[k].w);
        if (!ok) continue;
        if (!OM_WITH_JOBS) {   /* one band, the whole map: every fill counts (config.h) */
            drawn += (uint32_t)om__raster_tri_on_hiz(r, m->hiz, c, t, OM_LIGHT_GRID, OM_LIGHT_GRID);
            continue;
        }
        int64_t gx[9], gy[9];
        uint32_t gz[9];
        const int n = om__clip_project(c, OM_LIGHT_GRID, OM_LIGHT_GRID, gx, gy, gz);
        for (int k = 1; k + 1 < n; k++) {
            const int64_t tx[3] = {gx[0], gx[k], gx[k + 1]}, ty[3] = {gy[0], gy[k], gy[k + 1]};
            const uint32_t tz[3] = {gz[0], gz[k], gz[k + 1]};
            int64_t top = ty[0] < ty[1] ? ty[0] : ty[1];
            if (ty[2] < top) top = ty[2];
            if (om__raster_snapped_hiz(r, m->hiz, tx, ty, tz, t) && top > above) drawn++;
        }
    }
    return drawn;
}

/* The warped map with warped vertices (rtw_exact 0), into r's target. */
static uint32_t render_tess(const om__rtw *m, om_raster *r)
{
    const om_scene *s = m->scene;
    tess_ctx x;
    x.m = m;
    x.r = *r;
    x.limit2 = m->limit * m->limit;
    x.bend2 = (RTW_BEND / (double)m->size) * (RTW_BEND / (double)m->size);
    x.drawn = 0;
    {
        /* enough to cover the whole map 64 times over at the limit, and 64 per triangle */
        double cap = 65536.0 + 64.0 * (double)s->ntris;
        if (m->limit > 0.0) cap += 64.0 / (m->limit * m->limit);
        x.cap = cap < 4294967295.0 ? (uint32_t)cap : UINT32_MAX;
    }
    om__cull cl;
    om__cull_begin(&cl, s, &m->view.light_vp, m->view.origin);
    const float g = 1.0f + 4.0f / (float)m->size;
    for (uint32_t t = 0; t < s->ntris; t++) {
        const uint32_t *ix = s->idx + (size_t)t * 3;
        /* Each warped piece is culled by its own orientation on the map: warped and
         * split alike along shared edges, a closed shape stays closed. */
        x.r.cull_back = om__cull_next(&cl, t);
        om_vec4 c[3], poly[9];
        bool ok = true;
        for (int k = 0; k < 3; k++) {
            c[k] = om__mat_apply(&m->view.light_vp, om__sub(s->verts[ix[k]], m->view.origin));
            ok = ok && om__finite(c[k].x) && om__finite(c[k].y) && om__finite(c[k].z) && om__finite(c[k].w);
        }
        if (!ok) continue;
        int n = clip_tri(c, g, poly);
        tvert v[9];
        for (int k = 0; k < n; k++) {
            if (!(poly[k].w > 0.0f)) { n = 0; break; }
            v[k].c = poly[k];
            warp_vert(m, &v[k]);
        }
        x.tri = t;
        for (int k = 1; k + 1 < n; k++) tess(&x, &v[0], &v[k], &v[k + 1], 0);
    }
    return x.drawn;
}

/* Rows [y0, y0 + rows) of the map (om__bands.build_rows); counts[2] += triangles
 * drawn, counted so that the bands add up to the whole map's count. */
static void rtw_build_rows(const void *state, uint32_t k, const om__bins *bins, uint32_t y0, uint32_t rows,
                           uint32_t counts[8])
{
    (void)k;   /* one map */
    const om__rtw *m = (const om__rtw *)state;
    /* Warped vertices (rtw.exact 0): the cap on splitting counts the pieces of the
     * whole map in triangle order, so a band would split every triangle to fill its
     * rows; the first band makes the whole map, the others nothing. */
    if (!m->cfg.rtw_exact) {
        if (y0 > 0) return;
        rows = m->size;
    }
    om_target tg = {m->size, m->size, y0, rows, m->depth + (size_t)y0 * m->size, NULL};
    om__target_clear(&tg);
    om__hiz_clear(m->hiz, &tg);   /* bands start on multiples of 16 rows: no tile shared */
    om_raster r;
    memset(&r, 0, sizeof r);
    r.target = &tg;
    r.mode = OM_RASTER_DEPTH;
    counts[2] += m->cfg.rtw_exact ? render_exact(m, &r, bins) : render_tess(m, &r);
}

/* The exact map's inverse-warped grid and its indexes, which every row reads. */
static void map_grids(om__rtw *m)
{
    if (!m->cfg.rtw_exact) return;
    const double steps = (double)OM_LIGHT_GRID * OM_SUBPIX;
    om__rtw_unwarp_grid(m->px, m->n, m->size, steps, m->gridx);
    om__rtw_unwarp_grid(m->py, m->n, m->size, steps, m->gridy);
    om__grid_index(m->gridx, (int32_t)m->size, m->grid_shift, m->grid_buckets, m->gridxs);
    om__grid_index(m->gridy, (int32_t)m->size, m->grid_shift, m->grid_buckets, m->gridys);
}

/* What the map's rows share, on the calling thread: the analysis's tables and the
 * grids. */
static uint32_t rtw_map_of(void *state, uint32_t k, const om_mat4 **vp)
{
    om__rtw *m = (om__rtw *)state;
    if (k > 0) return 0;   /* one map */
    om__rtw_importance_finish(m);
    om__rtw_build_tables(m);
    map_grids(m);
    m->tris_drawn = 0;
    *vp = &m->view.light_vp;
    return m->size;
}

void om__rtw_render_map(om__rtw *m)
{
    map_grids(m);
    uint32_t counts[8] = {0};
    rtw_build_rows(m, 0, NULL, 0, m->size, counts);
    m->tris_drawn = counts[2];
}

/* ---------------------------------------------------------------- lookup in float */

/* smlookup.c's warped test takes the sample's light coordinates, their warp and the
 * bias texel's division by the warp's density in double, which a Cortex-M4F runs in
 * software routines. Here the same test runs in float: what
 * the double arithmetic decides (the warped texel on each axis, the bias texel) comes
 * from float where a proven bound leaves no doubt, and the rest is smlookup.c's float
 * arithmetic, the same operations in the same order. A sample float is unsure of (next
 * to a texel or super-cell edge, a quotient next to halfway between floats, outside
 * the light's image) goes to smlookup.c alone, and so do the settings this path leaves
 * out (a normal offset, PCF). Tests compare the terms, and each piece next to its
 * edges, with smlookup.c's. */

void om__rtw_rcp(uint64_t D, float rcp[2])
{
    const double r = (double)(1u << 30) / (double)D;   /* D < 2^44: exact in double */
    rcp[0] = (float)r;
    rcp[1] = (float)(r - (double)rcp[0]);               /* the difference is exact */
}

/* a * b - p exactly for p = a * b in float (Dekker's product by Veltkamp's 12-bit
 * halves: no fused multiply-add needed; exact while nothing over- or underflows). */
static inline float prod_err(float a, float b, float p)
{
    const float ca = 4097.0f * a, ah = ca - (ca - a), al = a - ah;
    const float cb = 4097.0f * b, bh = cb - (cb - b), bl = b - bh;
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl;
}

/* A float's bits and back, through a union (C99; memcpy is a call in a freestanding
 * firmware). */
typedef union fbits { float f; uint32_t u; } fbits;
static inline float float_at(uint32_t bits)
{
    fbits x;
    x.u = bits;
    return x.f;
}

/* Q = t 2^30 / D is within 2^-45.9 Q of r + err: t (rcp[0] + rcp[1]) is within 2^-47.9
 * of it, the product's error is exact and the two roundings after it add 2^-47 and
 * 2^-48. The float nearest Q, and nearest its double (2^-53 Q from it), is then r
 * while err keeps 2^-38 r clear of halfway to r's neighbour on its side. */
static inline float div_dens(float t, const float rcp[2])
{
    if (!(t > 0x1p-60f && t < 0x1p60f)) return -1.0f;
    const float p = t * rcp[0];
    const float s = prod_err(t, rcp[0], p) + t * rcp[1];
    const float r = p + s, err = s - (r - p);   /* r + err = p + s exactly: |s| < |p| */
    fbits rb;
    rb.f = r;
    const uint32_t b = rb.u;
    const float up = float_at(b + 1) - r, dn = r - float_at(b - 1), tol = r * 0x1p-38f;
    return (err >= 0.0f ? 2.0f * err < up - tol : -2.0f * err < dn - tol) ? r : -1.0f;
}

float om__rtw_div_dens(float t, const float rcp[2])
{
    return div_dens(t, rcp);
}

/* The double warp: t = u n, cell c, X = (P[c] + (t - c)(P[c+1] - P[c])) size / 2^30.
 * In float, t is within mt / 3.9 of the exact value (om__rtw_cell_axis) and t - c is
 * exact (c <= t < c + 1); P's entries to float, the product and the sum are each
 * within 64 of theirs (values below 2^30 + 2^7), and X rounds within X 2^-24 <=
 * 64 S: X is within S (224 + (P[c+1] - P[c]) mt / 3.9) of the exact value, the double
 * within 2^-50 size. The margin is four times that. */
static inline int32_t texel_axis(const int32_t *P, uint32_t n, uint32_t size, float r, uint32_t *k)
{
    const float nf = (float)n, hn = 0.5f * nf;
    const int32_t c = om__rtw_cell_axis(r, hn, nf);
    if (c < 0) return -2;
    const float t = (r + 1.0f) * hn, mt = (om__fabsf(r) + 1.0f) * hn * 0x1p-20f;
    const float B = (float)(P[c + 1] - P[c]), S = (float)size * 0x1p-30f;
    const float X = ((float)P[c] + (t - (float)c) * B) * S, M = (mt * B + 1024.0f) * S;
    const float lo = X - M, hi = X + M;
    *k = (uint32_t)c;
    if (!(lo >= 0.0f)) return -2;
    const int32_t i = (int32_t)lo;
    return i == (int32_t)hi ? i : -2;
}

int32_t om__rtw_texel_axis(const int32_t *P, uint32_t n, uint32_t size, float r, uint32_t *k)
{
    return texel_axis(P, n, size, r, k);
}

/* smlookup.c's locate for a warped map without normal offset, in float: 1 located
 * (the threshold and the texel), 0 behind the light, -1 unsure. */
static int locate_f(const om__rtw *m, const om_view *v, const om_sample *smp, uint64_t *zlit, uint32_t *at)
{
    const om__smlook *L = &m->look;
    const om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]);
    const bool spot = v->light.kind == OM_LIGHT_SPOT;
    const float dist = spot ? om__dot(om__sub(p, v->light.pos), v->light_axis) : 1.0f;
    const float span = spot ? dist * L->span_per_dist : 2.0f / om__fabsf(v->light_proj.m[0]);
    const om_vec4 q = om__mat_apply(&v->light_vp, p);
    if (!(q.w > 0.0f)) return 0;
    const float iw = 1.0f / q.w;
    uint32_t kx = 0, ky = 0;
    const int32_t cx = texel_axis(m->px, m->n, m->size, q.x * iw, &kx);
    const int32_t cy = texel_axis(m->py, m->n, m->size, -(q.y * iw), &ky);
    if (cx < 0 || cy < 0) return -1;
    /* the smaller density of the two axes, so the larger reciprocal */
    const bool by_x = om__rtw_dens(m->px, m->n, kx) <= om__rtw_dens(m->py, m->n, ky);
    const float texel = div_dens(span / (float)L->size, by_x ? m->rcp_x + 2 * kx : m->rcp_y + 2 * ky);
    if (texel < 0.0f) return -1;
    const float tanang = om__smlook_tan(smp->nl);
    const float bias = L->bias_world + L->bias_slope * texel * tanang;
    const float z = q.z * iw * OM_DEPTH_ONE_F;
    float dz;
    if (spot) {
        const float e = dist > L->half_near ? dist : L->half_near;
        dz = L->dz_num / (L->dz_den * e * e) * OM_DEPTH_ONE_F;
    } else {
        dz = OM_DEPTH_ONE_F * om__fabsf(v->light_proj.m[10]);
    }
    *zlit = om__smlook_threshold(z - bias * dz);
    *at = om__smlook_clamp(cy, m->size) * m->size + om__smlook_clamp(cx, m->size);
    return 1;
}

void om__rtw_lookup_strip(const om__rtw *m, om_strip *st, uint32_t *samples, uint32_t *shadowed)
{
    const om__smlook *L = &m->look;
    if (L->normal_offset != 0.0f || L->pcf != 1) {
        om__smlook_strip(L, st, samples, shadowed);
        return;
    }
    /* a copy, as smlookup.c takes: the terms' byte stores may alias the view */
    const om_view view = *L->view;
    const size_t n = (size_t)st->rows * st->width;
    uint32_t nsamples = 0, nshadowed = 0;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        uint64_t z = 0;
        uint32_t at = 0;
        const int got = locate_f(m, &view, &st->samples[i], &z, &at);
        if (got < 0) {   /* smlookup.c decides, on a strip of this one sample */
            om_strip one = *st;
            one.rows = one.width = 1;
            one.samples = &st->samples[i];
            one.terms = t;
            om__smlook_strip(L, &one, &nsamples, &nshadowed);
            continue;
        }
        nsamples++;
        if (!got) continue;
        const uint8_t val = z <= L->depth[at] ? 255 : 0;
        t->r = t->g = t->b = val;
        nshadowed += val != 255;
    }
    *samples += nsamples;
    *shadowed += nshadowed;
}

static om_status rtw_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    om__rtw *m = (om__rtw *)state;
    if (OM_FAST_FLOAT) om__rtw_lookup_strip(m, st, &m->samples, &m->shadowed);
    else om__smlook_strip(&m->look, st, &m->samples, &m->shadowed);
    return OM_OK;
}

/* Bands: as sm's; the warp tables are read only. */
static void rtw_band(const void *state, om_strip *st, void *scratch, uint32_t counts[8])
{
    (void)scratch;
    const om__rtw *m = (const om__rtw *)state;
    if (OM_FAST_FLOAT) om__rtw_lookup_strip(m, st, &counts[0], &counts[1]);
    else om__smlook_strip(&m->look, st, &counts[0], &counts[1]);
}

/* The resolve's counts after each strip, the map's (counts[2]) after the build. */
static void rtw_merge(void *state, const uint32_t counts[8])
{
    om__rtw *m = (om__rtw *)state;
    m->samples += counts[0];
    m->shadowed += counts[1];
    m->tris_drawn += counts[2];
}

const om__bands om__bands_rtw = {rtw_band, rtw_merge, 0, rtw_map_of, rtw_build_rows, NULL};

static uint32_t sat_u32(double v)
{
    return !(v > 0.0) ? 0u : v >= 4294967295.0 ? 0xFFFFFFFFu : (uint32_t)(v + 0.5);
}

static void rtw_stats(const void *state, om_method_stats *out)
{
    const om__rtw *m = (const om__rtw *)state;
    memset(out, 0, sizeof *out);
    out->bytes_used = rtw_need(&m->cfg) + (m->hiz ? hiz_bytes(&m->cfg) : 0);
    out->counters[0] = m->shadowed;
    out->counters[1] = m->tris_drawn;
    /* maximum effective resolution: the conventional map as dense as the densest
     * super-cell (section 6), per axis */
    out->counters[2] = sat_u32(m->dens_x * (double)m->size);
    out->counters[3] = sat_u32(m->dens_y * (double)m->size);
    out->counter_names[0] = "samples shadowed";
    out->counter_names[1] = "triangles drawn";
    out->counter_names[2] = "mer x";
    out->counter_names[3] = "mer y";
    out->ncounters = 4;
}

#define SET(field, name, kind, lo, hi, def, doc) OM__SETTING(om__rtw_cfg, field, name, kind, lo, hi, def, doc)

static const om_setting settings[] = {
    OM__SET_MAP(om__rtw_cfg), OM__SET_BIAS(om__rtw_cfg), OM__SET_SLOPE(om__rtw_cfg),
    OM__SET_OFFSET(om__rtw_cfg), OM__SET_PCF(om__rtw_cfg),
    SET(rtw_importance, "rtw.importance", OM_SETTING_U32, 0, OM_MAX_DIM, 0,
        "importance map side (at least 8), 0 = 512 or the map's if smaller"),
    SET(rtw_analysis, "rtw.analysis", OM_SETTING_U32, 0, 2, 0, "analysis: 0 backward, 1 forward, 2 hybrid"),
    SET(rtw_funcs, "rtw.funcs", OM_SETTING_U32, 0, 15, OM_RTW_DV | OM_RTW_DIST | OM_RTW_NORMAL,
        "importance: 1 view, 2 distance, 4 edge, 8 normal"),
    SET(rtw_sigma, "rtw.sigma", OM_SETTING_F32, 0, 64, 3, "blur sigma in super-cells"),
    SET(rtw_tess, "rtw.tess", OM_SETTING_F32, 0, 1, 0.025, "longest warped edge / map width, 0 = off"),
    SET(rtw_exact, "rtw.exact", OM_SETTING_U32, 0, 1, 1,
        "map: 1 texels sample at inverse-warped centres, 0 warped vertices"),
    SET(rtw_footprint, "rtw.footprint", OM_SETTING_U32, 0, 1, 0,
        "PCF taps: 0 a warped texel apart, 1 an unwarped one"),
};

#undef SET

extern const om__pass om__pass_rtw;
const om_method om__method_rtw = {
    "rtw", "rectilinear texture warping: importance-warped shadow map with 1-D warp tables",
    OM_METHOD_OBSERVES,
    rtw_bytes, rtw_init, rtw_begin, rtw_observe, rtw_build, rtw_resolve, rtw_stats, NULL,
    settings, sizeof settings / sizeof settings[0], sizeof(om__rtw_cfg),
    OM__JOBS_ONLY(&om__bands_rtw), OM__JOBS_ONLY(&om__pass_rtw),
};
