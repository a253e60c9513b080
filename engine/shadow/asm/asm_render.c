/* asm_render.c — Adaptive Shadow Maps' tiles (paper 002, section 4.2): each node's
 * tile is a small shadow map of its square of the light's image, rendered with the
 * engine's rasterizer from the triangles whose bounds meet it. Once a frame, prepare
 * projects the scene and bounds each triangle in base texels, and lays a grid of cells
 * over them so that a tile gathers its triangles from its cells; lean mode keeps none
 * of it and tests every triangle, or every chunk of triangles where it has room for
 * their bounds. asm.c decides which tiles exist. */
#include "../method.h"
#include "asm.h"

#include <float.h>

static om__asm_dvec dapply(const om_mat4 *mt, om_vec3 p)
{
    const float *a = mt->m;
    om__asm_dvec r;
    r.x = (double)a[0] * p.x + (double)a[1] * p.y + (double)a[2] * p.z + (double)a[3];
    r.y = (double)a[4] * p.x + (double)a[5] * p.y + (double)a[6] * p.z + (double)a[7];
    r.z = (double)a[8] * p.x + (double)a[9] * p.y + (double)a[10] * p.z + (double)a[11];
    r.w = (double)a[12] * p.x + (double)a[13] * p.y + (double)a[14] * p.z + (double)a[15];
    return r;
}

/* A triangle's bounds on the light's image in base texels (R per side), from its
 * vertices' light clip coordinates. */
static void tri_box(const om__asm_dvec q[3], double R, float b[4])
{
    double lo_u = 0, lo_v = 0, hi_u = 0, hi_v = 0;
    bool all = false;
    for (int i = 0; i < 3; i++) {
        /* Behind or on the light's plane: the triangle's image is unbounded; let the
         * rasterizer's clipping decide for every tile. */
        if (!(q[i].w > 1e-9 * (fabs(q[i].x) + fabs(q[i].y)))) { all = true; break; }
        double u = (q[i].x / q[i].w + 1.0) * 0.5 * R, v = (1.0 - q[i].y / q[i].w) * 0.5 * R;
        if (i == 0 || u < lo_u) lo_u = u;
        if (i == 0 || v < lo_v) lo_v = v;
        if (i == 0 || u > hi_u) hi_u = u;
        if (i == 0 || v > hi_v) hi_v = v;
    }
    if (all || !(lo_u > -1e30 && hi_u < 1e30 && lo_v > -1e30 && hi_v < 1e30)) {
        b[0] = b[1] = -FLT_MAX;
        b[2] = b[3] = FLT_MAX;
    } else {   /* widened by far more than float rounding: never narrower than in double */
        b[0] = (float)(lo_u - (1.0 / 256 + fabs(lo_u) * 1e-6));
        b[1] = (float)(lo_v - (1.0 / 256 + fabs(lo_v) * 1e-6));
        b[2] = (float)(hi_u + (1.0 / 256 + fabs(hi_u) * 1e-6));
        b[3] = (float)(hi_v + (1.0 / 256 + fabs(hi_v) * 1e-6));
    }
}

static inline bool box_meets(const float *b, float u0, float v0, float u1, float v1)
{
    return !((b[2] < u0) | (b[0] > u1) | (b[3] < v0) | (b[1] > v1));
}

/* Whether [lo, hi] holds an integer: exact, without libm (|lo| < 1e15 converts to an
 * integer and back unchanged); wide or huge ranges hold one. */
static inline bool holds_integer(double lo, double hi)
{
    if (!(hi - lo < 1.0) || !(lo > -1e15 && lo < 1e15)) return true;
    double c = (double)(int64_t)lo;   /* towards zero: lo's ceiling, or one below it */
    if (c < lo) c += 1.0;
    return c <= hi;
}

/* Whether bounds b (base texels) hold a texel centre of a grid `sc` times finer on both
 * axes. The rasterizer samples a tile at its texel centres only, and a snapped triangle
 * covers none outside its vertices' box, so one whose bounds hold no centre writes
 * nothing: most of a big scene's triangles in the base and many in a root tile, each a
 * fraction of a texel there. Skipping them leaves every tile as it was. The bounds are
 * already wider than the rasterizer's snap and float x/w can move a vertex (tri_box);
 * another 1/32 texel here keeps the test from deciding on rounding at all. */
static inline bool box_holds_centre(const float *b, double sc)
{
    const double e = 1.0 / 32;
    return holds_integer((double)b[0] * sc - 0.5 - e, (double)b[2] * sc - 0.5 + e) &&
           holds_integer((double)b[1] * sc - 0.5 - e, (double)b[3] * sc - 0.5 + e);
}

/* box_holds_centre in float, for the float-first bounds below and their chunks' unions:
 * true wherever box_holds_centre is, its intervals wider than that test's by more than
 * the float rounding of b * sc - 0.5 (a relative 2^-22 at most, sc's own rounding to
 * float included) and the same 1/32 texel; false where no texel centre lies in them.
 * So a box it says holds none holds none. */
static inline bool fholds_integer(float lo, float hi)
{
    const float e = 1.0f / 32 + 1.0f / 1024 + (om__fabsf(lo) + om__fabsf(hi)) * 0x1p-19f;
    lo -= e;
    hi += e;
    if (!(hi - lo < 1.0f) || !(lo > -0x1p22f && lo < 0x1p22f)) return true;
    float c = (float)(int32_t)lo;   /* towards zero: lo's ceiling, or one below it */
    if (c < lo) c += 1.0f;
    return c <= hi;
}

static inline bool fbox_holds_centre(const float *b, float sc)
{
    return fholds_integer(b[0] * sc - 0.5f, b[2] * sc - 0.5f) && fholds_integer(b[1] * sc - 0.5f, b[3] * sc - 0.5f);
}

/* Float-first bounds (asm.float, lean mode, where double is software and tri_box's
 * double projection of every triangle for every tile is most of a tile's cost): a
 * box in base texels that holds the one tri_box makes from the same vertices. Each
 * vertex's light clip x, y, w in float, with a bound on their distance to dapply's
 * values (a dot product of four terms rounds within 4 * 2^-24 of the sum of their
 * magnitudes, dapply's within 4 * 2^-53: 1e-6 of it holds both with room), then x / w
 * and y / w over those intervals, then tri_box's widening and more. false where float
 * cannot bound the box (a vertex near or behind the light's plane, values out of
 * range): the exact path decides. A box that holds tri_box's skips a triangle only
 * where tri_box's would: it misses the region, or holds no texel centre. Made of
 * each vertex's part (vert_box_float: bounds u0, u1, v0, v1 of its u and v, false
 * where float cannot bound them) and the triangle's box of them (box_of_verts). */
static bool vert_box_float(const om_mat4 *mt, om_vec3 p, float R, float o[4])
{
    const float *a = mt->m;
    float e[3], c[3];
    for (int r = 0; r < 3; r++) {
        const int k = r == 2 ? 12 : 4 * r;   /* rows x, y and w */
        const float t0 = a[k] * p.x, t1 = a[k + 1] * p.y, t2 = a[k + 2] * p.z;
        c[r] = t0 + t1 + t2 + a[k + 3];
        e[r] = (om__fabsf(t0) + om__fabsf(t1) + om__fabsf(t2) + om__fabsf(a[k + 3])) * 1e-6f + 1e-30f;
    }
    const float wl = c[2] - e[2], wh = c[2] + e[2];
    /* tri_box's own test of the plane, with the bounds against it */
    if (!(wl > 1e-6f * (om__fabsf(c[0]) + e[0] + om__fabsf(c[1]) + e[1]) + 1e-30f) || !(wh < 1e30f)) return false;
    float q[2][2];
    for (int r = 0; r < 2; r++) {
        const float xl = c[r] - e[r], xh = c[r] + e[r];
        float ql = xl / wl < xl / wh ? xl / wl : xl / wh, qh = xh / wl > xh / wh ? xh / wl : xh / wh;
        q[r][0] = ql - (om__fabsf(ql) * 1e-6f + 1e-30f);
        q[r][1] = qh + (om__fabsf(qh) * 1e-6f + 1e-30f);
    }
    /* u = (x / w + 1) R / 2, v = (1 - y / w) R / 2 */
    o[0] = (q[0][0] + 1.0f) * 0.5f * R;
    o[1] = (q[0][1] + 1.0f) * 0.5f * R;
    o[2] = (1.0f - q[1][1]) * 0.5f * R;
    o[3] = (1.0f - q[1][0]) * 0.5f * R;
    return true;
}

/* The triangle's box from its vertices' parts (each vert_box_float's, all true). */
static bool box_of_verts(const float *const o[3], float b[4])
{
    float lo_u = 0, lo_v = 0, hi_u = 0, hi_v = 0;
    for (int i = 0; i < 3; i++) {
        if (i == 0 || o[i][0] < lo_u) lo_u = o[i][0];
        if (i == 0 || o[i][2] < lo_v) lo_v = o[i][2];
        if (i == 0 || o[i][1] > hi_u) hi_u = o[i][1];
        if (i == 0 || o[i][3] > hi_v) hi_v = o[i][3];
    }
    if (!(lo_u > -1e29f && hi_u < 1e29f && lo_v > -1e29f && hi_v < 1e29f)) return false;
    /* tri_box widens by 1/256 + 1e-6 |u| and rounds to float; this, by far more */
    b[0] = lo_u - (1.0f / 128 + om__fabsf(lo_u) * 1e-5f);
    b[1] = lo_v - (1.0f / 128 + om__fabsf(lo_v) * 1e-5f);
    b[2] = hi_u + (1.0f / 128 + om__fabsf(hi_u) * 1e-5f);
    b[3] = hi_v + (1.0f / 128 + om__fabsf(hi_v) * 1e-5f);
    return true;
}


/* A vertex's light clip coordinates composed with the tile's window. */
static om_vec4 in_window(om__asm_dvec q, double s_, double kx, double ky)
{
    om_vec4 c;
    c.x = (float)(q.x * s_ + q.w * kx);
    c.y = (float)(q.y * s_ + q.w * ky);
    c.z = (float)q.z;
    c.w = (float)q.w;
    return c;
}

/* One triangle into the tile: its clip coordinates composed with the tile's window. */
static void render_tri(om_raster *r, const om__asm_dvec q[3], double s_, double kx, double ky,
                       uint32_t t)
{
    om_vec4 c[3];
    for (int i = 0; i < 3; i++) c[i] = in_window(q[i], s_, kx, ky);
    om__raster_tri(r, c, t);
}

/* Lean mode: a tile's vertices in its window (in_window), by vertex index modulo
 * VCACHE, so that a mesh's triangles drawn one after another project each vertex they
 * share once (on the stack: its values are what in_window gives, whatever it holds). */
#define VCACHE 128
typedef struct vslot {
    uint32_t v;            /* the vertex, or UINT32_MAX: none */
    om_vec4 c;
} vslot;

/* And its part of the float-first bounds (vert_box_float), the same way. */
typedef struct fslot {
    uint32_t v;            /* the vertex, or UINT32_MAX: none */
    bool ok;               /* vert_box_float's verdict */
    float o[4];
} fslot;

/* The float-first box of the triangle with vertex indices ix (box_of_verts of its
 * vertices' parts), the parts through the cache fc (VCACHE slots). */
static bool tri_box_cached(const om__asm_state *m, fslot *fc, const uint32_t *ix, float R, float b[4])
{
    float ov[3][4];   /* copies: two of the vertices may share a slot */
    for (int i = 0; i < 3; i++) {
        fslot *e = &fc[ix[i] % VCACHE];
        if (e->v != ix[i]) {
            e->v = ix[i];
            e->ok = vert_box_float(&m->view.light_vp, om__sub(m->scene->verts[ix[i]], m->view.origin), R, e->o);
        }
        if (!e->ok) return false;
        memcpy(ov[i], e->o, sizeof ov[i]);
    }
    const float *const o[3] = {ov[0], ov[1], ov[2]};
    return box_of_verts(o, b);
}

/* The triangles whose bounds meet the region and hold a texel centre, in index order,
 * into m->cull: every triangle's bounds tested (most miss a deep node's region). */
static uint32_t gather_all(const om__asm_state *m, const om__asm_rs *rs, float u0, float v0, float u1,
                           float v1, double sc, const uint32_t *centre)
{
    uint32_t n = 0;
    if (centre) {   /* a word of bits at a time: in a big scene most are clear */
        for (uint32_t w = 0; w < (m->scene->ntris + 31) / 32; w++)
            for (uint32_t bits = centre[w]; bits; bits &= bits - 1) {
                const uint32_t k = w * 32 + om__ctz32(bits);
                rs->cull[n] = k;
                n += box_meets(&m->tbox[(size_t)k * 4], u0, v0, u1, v1);
            }
        return n;
    }
    for (uint32_t k = 0; k < m->scene->ntris; k++) {
        const float *b = &m->tbox[(size_t)k * 4];
        rs->cull[n] = k;
        n += box_meets(b, u0, v0, u1, v1) && box_holds_centre(b, sc);
    }
    return n;
}

/* The cell of a base-texel coordinate, clamped to the grid (bounds beyond the map
 * fall in its border cells). */
static uint32_t cell_of(const om__asm_state *m, float u)
{
    float f = u * (float)m->gside / (float)m->tree.lay.tile;
    return !(f > 0.0f) ? 0 : f >= (float)(m->gside - 1) ? m->gside - 1 : (uint32_t)f;
}

/* A triangle's cells, a byte each (gside is at most 256): cx0, cy0, cx1, cy1 from the
 * low byte up. Made with its bounds (on the host's threads where there are some) and
 * kept in m->cull, which no tile uses before the grid is made. */
static uint32_t cells_of(const om__asm_state *m, const float *b)
{
    return cell_of(m, b[0]) | cell_of(m, b[1]) << 8 | cell_of(m, b[2]) << 16 | cell_of(m, b[3]) << 24;
}

/* Rows [r0, r1) of the triangle grid: with `place` false, each cell's count of the
 * triangles that meet it into gstart[cell + 1] (zeroed first), stopping once the rows
 * hold more than gcap entries; with `place`, each triangle appended to the lists of its
 * cells there (gstart[cell]: where the cell's next goes), in index order. Every
 * triangle's cells are read (m->cull), only these rows' counts and lists written, so
 * bands of rows may run at once and give what one band of all rows gives. Returns the
 * entries the rows hold (counting). */
static uint64_t grid_rows(const om__asm_state *m, uint32_t r0, uint32_t r1, bool place)
{
    const uint32_t G = m->gside, *cells = m->cull;
    uint32_t *start = m->gstart;
    uint64_t total = 0;
    if (!place) memset(start + (size_t)r0 * G + 1, 0, (size_t)(r1 - r0) * G * sizeof(uint32_t));
    for (uint32_t k = 0; k < m->scene->ntris; k++) {
        const uint32_t p = cells[k], cy0 = p >> 8 & 255u, cy1 = p >> 24;
        if (cy1 < r0 || cy0 >= r1) continue;
        const uint32_t cx0 = p & 255u, cx1 = p >> 16 & 255u, y0 = cy0 > r0 ? cy0 : r0, y1 = cy1 < r1 ? cy1 : r1 - 1;
        if (place) {
            for (uint32_t cy = y0; cy <= y1; cy++)
                for (uint32_t cx = cx0; cx <= cx1; cx++) m->glist[start[cy * G + cx]++] = k;
            continue;
        }
        total += (uint64_t)(cx1 - cx0 + 1) * (y1 - y0 + 1);
        if (total > m->gcap) return total;
        for (uint32_t cy = y0; cy <= y1; cy++)
            for (uint32_t cx = cx0; cx <= cx1; cx++) start[cy * G + cx + 1]++;
    }
    return total;
}

#if OM_WITH_JOBS
/* grid_rows by bands of rows as jobs (om__lend): the same lists. */
typedef struct grid_job {
    const om__asm_state *m;
    uint32_t bands;
    bool place;
    uint64_t total[256];   /* each band's entries (gside, so bands, is at most 256) */
} grid_job;

static void grid_band(void *user, uint32_t b, void *scratch)
{
    grid_job *j = (grid_job *)user;
    const uint32_t G = j->m->gside;
    (void)scratch;
    j->total[b] = grid_rows(j->m, G * b / j->bands, G * (b + 1) / j->bands, j->place);
}
#endif

/* This frame's cell lists (a counting sort of triangles by cell, from their cells in
 * m->cull); gready stays false when they would not fit. */
static void grid_make(om__asm_state *m)
{
    const uint32_t G = m->gside;
    m->gready = false;
    m->gstart[0] = 0;
#if OM_WITH_JOBS
    if (m->lend) {
        /* two bands a slot: every band reads every triangle's cells, so few */
        grid_job j;
        j.m = m;
        j.bands = 2 * m->lend->slots < G ? 2 * m->lend->slots : G;
        j.place = false;
        m->lend->run(m->lend, grid_band, &j, j.bands);
        uint64_t total = 0;
        for (uint32_t b = 0; b < j.bands; b++) total += j.total[b];
        if (total > m->gcap) return;
        for (uint32_t c = 0; c < G * G; c++) m->gstart[c + 1] += m->gstart[c];
        j.place = true;
        m->lend->run(m->lend, grid_band, &j, j.bands);
    } else
#endif
    {
        if (grid_rows(m, 0, G, false) > m->gcap) return;
        for (uint32_t c = 0; c < G * G; c++) m->gstart[c + 1] += m->gstart[c];
        (void)grid_rows(m, 0, G, true);
    }
    for (uint32_t c = G * G; c > 0; c--) m->gstart[c] = m->gstart[c - 1];   /* back to starts */
    m->gstart[0] = 0;
    m->gready = true;
}

/* gather_all's result from the cells the region meets: their triangles marked in a
 * bit set (a triangle in several cells once; with `centre`, only those it has),
 * collected in index order and tested as gather_all tests them. */
static uint32_t gather_cells(const om__asm_state *m, const om__asm_rs *rs, float u0, float v0, float u1,
                             float v1, double sc, const uint32_t *centre)
{
    const uint32_t G = m->gside;
    uint32_t lo = UINT32_MAX, hi = 0, n = 0;
    for (uint32_t cy = cell_of(m, v0); cy <= cell_of(m, v1); cy++)
        for (uint32_t cx = cell_of(m, u0); cx <= cell_of(m, u1); cx++)
            for (uint32_t i = m->gstart[cy * G + cx]; i < m->gstart[cy * G + cx + 1]; i++) {
                uint32_t k = m->glist[i];
                rs->gbits[k >> 5] |= (centre ? centre[k >> 5] : ~0u) & 1u << (k & 31);
                if (k < lo) lo = k;
                if (k > hi) hi = k;
            }
    for (uint32_t w = lo == UINT32_MAX ? 1 : lo >> 5; w <= (hi >> 5) && lo != UINT32_MAX; w++) {
        uint32_t bits = rs->gbits[w];
        rs->gbits[w] = 0;
        while (bits) {
            uint32_t k = w * 32 + om__ctz32(bits);
            bits &= bits - 1;
            const float *b = &m->tbox[(size_t)k * 4];
            rs->cull[n] = k;
            n += box_meets(b, u0, v0, u1, v1) && (centre || box_holds_centre(b, sc));
        }
    }
    return n;
}

/* Renders texels [ox, ox + tile) x [oy, oy + tile) of level `level`'s grid into a
 * tile's depth and ids, from the triangles whose light bounds meet the region. The light's clip space is composed with the window that maps the
 * region's tile to [-1, 1] (x' = s x + k w), so the engine's rasterizer, clipping and
 * fill rule apply unchanged at any depth of the tree. Only the tile's texels
 * [wx0, wx1) x [wy0, wy1) are written, from the triangles that meet them: a texel
 * depends on nothing but the triangles whose bounds hold its centre, so a part drawn
 * again is what the whole tile drawn again holds there. */
static void render(const om__asm_state *m, const om__asm_rs *rs, uint32_t level, uint32_t ox, uint32_t oy,
                   const uint32_t win[4], uint32_t *depth, uint16_t *id16, uint32_t *id32)
{
    const om__asm_layout *l = &m->tree.lay;
    const om_scene *s = m->scene;
    const uint32_t T = l->tile;
    const double s_ = om__asm_grid(l, level) / (double)T;
    const double kx = s_ - 2.0 * (double)ox / (double)T - 1.0;
    const double ky = 1.0 - s_ + 2.0 * (double)oy / (double)T;
    /* the region in base texels, one texel of margin against rounding */
    const double ic = m->inv_scale[level];
    const float u0 = (float)(((double)ox + win[0] - 1.0) * ic), u1 = (float)(((double)ox + win[2] + 1.0) * ic);
    const float v0 = (float)(((double)oy + win[1] - 1.0) * ic), v1 = (float)(((double)oy + win[3] + 1.0) * ic);
    om_target tg = {T, T, 0, T, rs->sdepth, rs->sid};
    om__target_clear(&tg);
    om_raster r = {&tg, OM_RASTER_DEPTH_ID, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
    /* back faces of closed shapes skipped, as in every light map (om__cull); the
     * window scales x and y by s_ > 0, so windings stay */
    om__cull cl;
    om__cull_begin(&cl, s, &m->view.light_vp, m->view.origin);
    if (m->lean) {
        /* The same triangles in the same order as the fast path below, so the same tile:
         * projections and bounds are made per tile instead of kept per frame. */
        const bool first = m->cfg.asm_float != 0;
        vslot vc[VCACHE];
        fslot fc[VCACHE];
        for (int i = 0; i < VCACHE; i++) vc[i].v = fc[i].v = UINT32_MAX;
        const uint32_t ct = m->chunk_ready ? m->chunk_tris : s->ntris;
        const float fsc = (float)l->scale[level];
        for (uint32_t t = 0; t < s->ntris; t++) {
            /* a chunk whose union of float boxes misses the region or holds no texel
             * centre: so do its triangles' boxes (the union holds each, and a box
             * fails both tests wherever a box that holds it does) */
            if (ct < s->ntris && t % ct == 0) {
                const float *cb = &m->chunk[(size_t)(t / ct) * 4];
                if (!box_meets(cb, u0, v0, u1, v1) || !fbox_holds_centre(cb, fsc)) {
                    t += ct - 1;
                    continue;
                }
            }
            const uint32_t *ix = s->idx + (size_t)t * 3;
            om__asm_dvec q[3];
            float b[4];
            const bool bounded = first && tri_box_cached(m, fc, ix, (float)T, b);
            if (bounded && (!box_meets(b, u0, v0, u1, v1) || !fbox_holds_centre(b, fsc)))
                continue;   /* the box that holds tri_box's misses: so would tri_box's */
            /* Where the float box meets, the triangle is drawn without tri_box's verdict:
             * one that tri_box's box would skip writes no texel centre of the window (the
             * box holds its snapped image), so drawing it leaves the tile as it was. */
            if (!bounded) {
                for (int i = 0; i < 3; i++) q[i] = dapply(&m->view.light_vp, om__sub(s->verts[ix[i]], m->view.origin));
                tri_box(q, T, b);
                if (!box_meets(b, u0, v0, u1, v1) || !box_holds_centre(b, l->scale[level])) continue;
            }
            om_vec4 c[3];
            for (int i = 0; i < 3; i++) {
                vslot *e = &vc[ix[i] % VCACHE];
                if (e->v != ix[i]) {
                    e->v = ix[i];
                    e->c = in_window(bounded ? dapply(&m->view.light_vp, om__sub(s->verts[ix[i]], m->view.origin)) : q[i],
                                     s_, kx, ky);
                }
                c[i] = e->c;
            }
            r.cull_back = om__cull_next(&cl, t);
            om__raster_tri(&r, c, t);
        }
    } else {
        const double sc = l->scale[level];
        const uint32_t *centre = level < 2 ? m->centre[level] : NULL;
        /* the base covers every cell: its centre bits alone are the shorter walk */
        uint32_t n = m->gready && level > 0 ? gather_cells(m, rs, u0, v0, u1, v1, sc, centre)
                                            : gather_all(m, rs, u0, v0, u1, v1, sc, centre);
        for (uint32_t k = 0; k < n; k++) {
            const uint32_t t = rs->cull[k];
            const uint32_t *ix = s->idx + (size_t)t * 3;
#if defined(__GNUC__) || defined(__clang__)
            /* a big scene's triangles in a tile lie far apart in memory: ask for the
             * next ones' vertices early (a hint: no effect on what is computed) */
            if (k + 4 < n) {
                const uint32_t *nx = s->idx + (size_t)rs->cull[k + 4] * 3;
                for (int i = 0; i < 3; i++) __builtin_prefetch(&s->verts[nx[i]]);
            }
            if (k + 8 < n) __builtin_prefetch(s->idx + (size_t)rs->cull[k + 8] * 3);
#endif
            om__asm_dvec q[3];
            for (int i = 0; i < 3; i++) q[i] = dapply(&m->view.light_vp, om__sub(s->verts[ix[i]], m->view.origin));
            r.cull_back = om__cull_next(&cl, t);
            render_tri(&r, q, s_, kx, ky, t);
        }
    }
    for (uint32_t y = win[1]; y < win[3]; y++) {
        const size_t i0 = (size_t)y * T + win[0], n = win[2] - win[0];
        memcpy(depth + i0, rs->sdepth + i0, n * sizeof *depth);
        if (id16)
            for (size_t i = i0; i < i0 + n; i++)
                id16[i] = rs->sid[i] == OM_NO_TRI ? (uint16_t)0xFFFFu : (uint16_t)rs->sid[i];
        else
            memcpy(id32 + i0, rs->sid + i0, n * sizeof *id32);
    }
}

/* A node's tile depends on nothing but its place and the frame's light and bounds, so
 * tiles render in any order, each written by its own job (om__asm_render_list). */
void om__asm_render_with(om__asm_state *m, uint32_t index, const om__asm_rs *rs)
{
    om__asm_tile tl;
    om__asm_tile_of(&m->tree, index, &tl);
    const uint32_t all[4] = {0, 0, tl.size, tl.size};
    render(m, rs, tl.node->level, tl.node->ox, tl.node->oy, all, tl.depth, tl.id16, tl.id32);
}

/* The texels of node `index`'s tile that the base-texel rectangles touch (a texel
 * wider on each side), drawn again. */
static void render_part(om__asm_state *m, uint32_t index, const float (*rects)[4], uint32_t n)
{
    const om__asm_rs rs = {m->sdepth, m->sid, m->cull, m->gbits};
    om__asm_tile tl;
    om__asm_chunks(m);
    om__asm_tile_of(&m->tree, index, &tl);
    const double sc = m->tree.lay.scale[tl.node->level], T = (double)tl.size;
    const double o[2] = {(double)tl.node->ox, (double)tl.node->oy};
    double w[4] = {T, T, 0, 0};
    for (uint32_t k = 0; k < n; k++)
        for (int e = 0; e < 2; e++) {
            double lo = floor((double)rects[k][e] * sc - o[e]) - 1.0, hi = ceil((double)rects[k][e + 2] * sc - o[e]) + 1.0;
            lo = !(lo > 0.0) ? 0.0 : lo > T ? T : lo;
            hi = !(hi > 0.0) ? 0.0 : hi > T ? T : hi;
            if (hi <= lo) continue;
            if (lo < w[e]) w[e] = lo;
            if (hi > w[e + 2]) w[e + 2] = hi;
        }
    if (!(w[0] < w[2] && w[1] < w[3])) return;
    const uint32_t win[4] = {(uint32_t)w[0], (uint32_t)w[1], (uint32_t)w[2], (uint32_t)w[3]};
    render(m, &rs, tl.node->level, tl.node->ox, tl.node->oy, win, tl.depth, tl.id16, tl.id32);
}

void om__asm_chunks(om__asm_state *m)
{
    if (!m->chunk || m->chunk_ready) return;
    const om_scene *s = m->scene;
    const uint32_t ct = m->chunk_tris;
    const float R = (float)m->tree.lay.tile;
    fslot fc[VCACHE];
    for (int i = 0; i < VCACHE; i++) fc[i].v = UINT32_MAX;
    for (uint32_t c = 0; c * ct < s->ntris; c++) {
        float *u = &m->chunk[(size_t)c * 4];
        const uint32_t t1 = (c + 1) * ct < s->ntris ? (c + 1) * ct : s->ntris;
        for (uint32_t t = c * ct; t < t1; t++) {
            float b[4];
            if (!tri_box_cached(m, fc, s->idx + (size_t)t * 3, R, b)) {   /* unbounded: every tile */
                u[0] = u[1] = -FLT_MAX;
                u[2] = u[3] = FLT_MAX;
                break;
            }
            for (int e = 0; e < 4; e++)
                if (t == c * ct || (e < 2 ? b[e] < u[e] : b[e] > u[e])) u[e] = b[e];
        }
    }
    m->chunk_ready = true;
}

void om__asm_render_node(om__asm_state *m, uint32_t index)
{
    om__asm_chunks(m);
    const om__asm_rs rs = {m->sdepth, m->sid, m->cull, m->gbits};
    om__asm_render_with(m, index, &rs);
}

/* Triangles [k0, k1)'s bounds, their centre bits (into words cleared or their own) and
 * their grid cells (cells_of). */
static void bounds(om__asm_state *m, uint32_t k0, uint32_t k1)
{
    const om_scene *s = m->scene;
    for (uint32_t k = k0; k < k1; k++) {
        const uint32_t *ix = s->idx + (size_t)k * 3;
        om__asm_dvec q[3];
        for (int i = 0; i < 3; i++) q[i] = dapply(&m->view.light_vp, om__sub(s->verts[ix[i]], m->view.origin));
        float *b = &m->tbox[(size_t)k * 4];
        tri_box(q, m->tree.lay.tile, b);
        m->cull[k] = cells_of(m, b);
        for (int i = 0; i < 2; i++)
            m->centre[i][k >> 5] |= (uint32_t)box_holds_centre(b, m->tree.lay.scale[i]) << (k & 31);
    }
}

#if OM_WITH_JOBS
/* Part p of the bounds as a job (om__lend): whole words of centre bits, so no word is
 * shared with another part. */
static void bounds_part(void *user, uint32_t p, void *scratch)
{
    om__asm_state *m = (om__asm_state *)user;
    (void)scratch;
    const uint32_t words = (m->scene->ntris + 31) / 32;
    const uint32_t n = words < 4 * m->lend->slots ? words : 4 * m->lend->slots;
    const uint32_t w0 = (uint32_t)((uint64_t)words * p / n), w1 = (uint32_t)((uint64_t)words * (p + 1) / n);
    const uint32_t k1 = w1 * 32 < m->scene->ntris ? w1 * 32 : m->scene->ntris;
    memset(m->centre[0] + w0, 0, (w1 - w0) * sizeof(uint32_t));
    memset(m->centre[1] + w0, 0, (w1 - w0) * sizeof(uint32_t));
    bounds(m, w0 * 32, k1);
}
#endif

/* The base-texel rectangle (u0, v0, u1, v1) that holds the light's image of the box
 * lo..hi, widened as tri_box widens; everything where a corner is behind the light. */
static void box_rect(const om__asm_state *m, om_vec3 lo, om_vec3 hi, float r[4])
{
    om__asm_dvec q[8];
    for (int c = 0; c < 8; c++) {
        om_vec3 p = om__v3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        q[c] = dapply(&m->view.light_vp, om__sub(p, m->view.origin));
    }
    const double R = (double)m->tree.lay.tile;
    float b[4];
    for (int c = 0; c < 8; c += 2) {   /* corners c and c + 1, with corner 0 in each */
        const om__asm_dvec t[3] = {q[0], q[c], q[c + 1]};
        tri_box(t, R, b);
        if (c == 0 || b[0] < r[0]) r[0] = b[0];
        if (c == 0 || b[1] < r[1]) r[1] = b[1];
        if (c == 0 || b[2] > r[2]) r[2] = b[2];
        if (c == 0 || b[3] > r[3]) r[3] = b[3];
    }
}

static bool rect_meets(const float *a, const float *b)
{
    return !(a[2] < b[0] || b[2] < a[0] || a[3] < b[1] || b[3] < a[1]);
}

/* Each object's box as the tiles now hold it (after a build or a redraw). */
static void note_drawn(om__asm_state *m, bool all)
{
    const om_scene *s = m->scene;
    if (!m->drawn) return;
    for (uint32_t i = 0; i < s->nobjects; i++) {
        const om_object *o = &s->objects[i];
        if (!all && o->moved <= m->change && m->change <= s->change) continue;
        m->drawn[2 * i] = o->lo;
        m->drawn[2 * i + 1] = o->hi;
    }
}

/* Objects moved since the tiles were drawn (om_scene.change): every tile whose part of
 * the light's image meets a moved object's box, where the tiles hold it (m->drawn:
 * however many times it moved since) or where it is now, is drawn again, the base
 * among them; the rest of the tree and its tiles stay. A tile is
 * a function of its place and the scene, so a redrawn tile is what a new one would be.
 * The boxes' images are kept apart up to MOVED_RECTS of them (two objects far apart
 * redraw their own tiles, not those between them), beyond that as one rectangle. */
#define MOVED_RECTS 16

static void redraw_moved(om__asm_state *m)
{
    const om_scene *s = m->scene;
    om__asm_tree *t = &m->tree;
    float rects[MOVED_RECTS][4], all[4] = {0, 0, 0, 0};
    uint32_t n = 0, seen = 0;
    for (uint32_t i = 0; i < s->nobjects; i++) {
        const om_object *o = &s->objects[i];
        if (o->moved <= m->change && m->change <= s->change) continue;
        for (int k = 0; k < 2; k++) {
            float r[4];
            if (k) box_rect(m, o->lo, o->hi, r);
            else box_rect(m, m->drawn[2 * i], m->drawn[2 * i + 1], r);
            if (n < MOVED_RECTS) memcpy(rects[n++], r, sizeof r);
            for (int e = 0; e < 4; e++)
                if (!seen || (e < 2 ? r[e] < all[e] : r[e] > all[e])) all[e] = r[e];
            seen++;
        }
    }
    note_drawn(m, false);
    m->change = s->change;
    if (!seen) return;
    if (seen > MOVED_RECTS) {   /* too many to keep apart: their union */
        memcpy(rects[0], all, sizeof all);
        n = 1;
    }
    render_part(m, OM__ASM_ROOT, (const float (*)[4])rects, n);
    m->redrawn++;
    for (uint32_t i = 0; i < t->lay.count; i++) {
        const om__asm_node *nd = om__asm_node_at(t, i);
        if (!nd->alive) continue;
        /* its texels on its level's grid, in base texels, a texel wider on each side */
        const double sc = t->lay.scale[nd->level];
        const float r[4] = {(float)((nd->ox - 1.0) / sc), (float)((nd->oy - 1.0) / sc),
                            (float)((nd->ox + t->lay.tile + 1.0) / sc),
                            (float)((nd->oy + t->lay.tile + 1.0) / sc)};
        float hit[MOVED_RECTS][4];
        uint32_t nh = 0;
        for (uint32_t k = 0; k < n; k++)
            if (rect_meets(r, rects[k])) memcpy(hit[nh++], rects[k], sizeof hit[0]);
        if (!nh) continue;
        render_part(m, i, (const float (*)[4])hit, nh);
        m->redrawn++;
    }
}

/* This frame's projections (once, from the first observe or build), and the rebuild
 * when the light has moved. */
void om__asm_prepare(om__asm_state *m)
{
    if (m->prepared) return;
    m->prepared = true;
    const om_scene *s = m->scene;
    if (!m->lean) {
        /* Projections per triangle, kept only as bounds: a tile projects again the few
         * it renders (the same bits), which costs less than keeping every vertex's. */
        const uint32_t words = (s->ntris + 31) / 32;
#if OM_WITH_JOBS
        if (m->lend) {   /* by parts of whole words, each its own triangles' */
            const uint32_t n = words < 4 * m->lend->slots ? words : 4 * m->lend->slots;
            m->lend->run(m->lend, bounds_part, m, n);
        } else
#endif
        {
            memset(m->centre[0], 0, words * sizeof(uint32_t));
            memset(m->centre[1], 0, words * sizeof(uint32_t));
            bounds(m, 0, s->ntris);
        }
        grid_make(m);
    }
    if (!m->built || memcmp(&m->built_vp, &m->view.light_vp, sizeof m->built_vp) != 0 ||
        memcmp(&m->built_org, &m->view.origin, sizeof m->built_org) != 0) {
        om__asm_tree_clear(&m->tree);
        om__asm_render_node(m, OM__ASM_ROOT);
        m->built_vp = m->view.light_vp;
        m->built_org = m->view.origin;
        m->built = true;
        m->rebuilds++;
        note_drawn(m, true);
        m->change = m->scene->change;
    } else if (m->change != m->scene->change) {
        redraw_moved(m);
    }
}
