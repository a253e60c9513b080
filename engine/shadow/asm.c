/* asm.c — Adaptive Shadow Maps (Fernando, Fernandez, Bala, Greenberg 2001; paper 002)
 * under a user-set memory cap: the frame flow, the view-driven analysis, rendering of
 * node tiles and the lookup. The tree, its pool and its removal rules are asm_tree.c.
 *
 * A frame:
 *  begin    takes the view. If the light's matrix differs from the one the tiles were
 *           rendered with, every tile is stale: the tree is dropped and the base is
 *           re-rendered (a rebuild; root tiles follow in build). A directional light
 *           is fitted to the visible samples every frame, so with one the tree is
 *           rebuilt whenever the view moves.
 *  observe  (every strip, before build) one visible sample in asm.stride is analysed
 *           (section 4.3: the paper uses one in eight): it descends to its leaf cell,
 *           making its root tile if there is none and memory is free, and below the
 *           root tiles, at every
 *           level it passes, it counts towards the benefit of that level's cell
 *           when it straddles a discontinuity and the level's texel is larger on the
 *           surface than its eye pixel (sections 3.1, 4.1 — both footprints analytic).
 *  build    makes the root tiles still missing (most samples first, by the rules of
 *           section 3.2; root tiles are outside the budget: the root covers what the
 *           eye sees), then orders the empty cells with a
 *           benefit by benefit / cost, cost = a * N_required + b (section 3.1), and
 *           creates their nodes, best first, until asm.work cost units are spent;
 *           memory comes back by the rules of section 3.2 (asm_tree.c).
 *  resolve  finds the deepest node over each sample (caching the last leaf, section
 *           4.3) and tests polygon ID, then depth (section 4.2).
 *
 * "Straddles a discontinuity" is decided where it matters: the sample's own shadow test
 * (ID, then depth) against its texel and the eight around it does not agree, i.e. a
 * depth or ID discontinuity that changes its answer lies within a texel of it.
 * A node's benefit is the same count for the samples inside it at its parent's
 * resolution: what would be lost without it. So a still view compares like with like
 * when a node must be replaced, and the tree settles instead of oscillating.
 *
 * Where memory runs out (a cap too small for the root tiles the view asks for), the
 * base answers: one tile over the whole frustum, coarse but never absent, so every
 * cap from the smallest (the base and one tile) renders.
 *
 * Bias: the constant and slope-scaled bias of the conventional map (cfg bias_const,
 * bias_slope in texels of the node the sample is tested in); the paper notes the ID
 * test does not remove the bias problem. pcf and normal_offset do not apply. */
#include "shadow.h"
#include "asm.h"

#include <float.h>

OM__CFG_FITS(om__asm_cfg);
extern const om_method om__method_asm;

typedef struct asm_dvec { double x, y, z, w; } asm_dvec;

typedef struct asm_state {
    const om_scene *scene;
    om__asm_cfg cfg;
    om__asm_tree tree;
    om_view view;
    om_mat4 built_vp;      /* the light the tiles hold */
    bool built;
    bool prepared;         /* this frame's projections are done */
    bool lean;             /* no per-vertex or per-triangle arrays: see render */
    float *tbox;           /* per triangle: base-texel bounds u0, v0, u1, v1 (not lean) */
    /* Per triangle, a bit: its bounds hold a texel centre of level 0's grid (centre[0])
     * or level 1's (centre[1]): box_holds_centre once per frame for the levels every
     * rebuild renders whole, so their gathers read no bounds of triangles that would
     * write nothing (not lean). */
    uint32_t *centre[2];
    uint32_t *cull;        /* triangles that meet the region being rendered (not lean) */
    /* A grid of cells over the base texels, each listing the triangles whose bounds
     * meet it, made once per frame, so that a tile gathers from its cells instead of
     * testing every triangle's bounds; a bit per triangle puts them back in index
     * order. Not lean; unused in a frame whose lists would overflow `gcap`. */
    uint32_t gside;        /* cells per side */
    uint32_t *gstart;      /* gside^2 + 1 offsets into glist */
    uint32_t *glist, gcap;
    uint32_t *gbits;       /* (ntris + 31) / 32 words */
    bool gready;           /* this frame's lists were made */
    uint32_t *sdepth, *sid;   /* one tile of scratch for the rasterizer */
    om__asm_cand *cand;
    uint32_t ncand_max;
    double inv_scale[OM__ASM_MAX_LEVEL + 1];   /* a level-L texel in base texels */
    om__asm_pctx pc;       /* what a sample's setup reads (asm_point.c) */
    uint32_t cache;        /* the last leaf found by resolve, or OM__ASM_NONE */
    om__asm_tile cache_tile;
    uint32_t samples, shadowed, analysed, straddling, candidates, rebuilds;
} asm_state;


/* The scene-sized arrays of the fast mode: projections once per frame, bounds once
 * per frame, a cull list per tile. */
/* Cells per side of the triangle grid: about four triangles a cell, 16 to 256. */
static uint32_t grid_side(const om_scene *s)
{
    uint32_t g = 16;
    while (g < 256 && (uint64_t)g * g * 4 < s->ntris) g *= 2;
    return g;
}

/* Room for twice as many cell entries as triangles: small triangles meet one to four
 * cells; a frame whose large ones need more renders its tiles by the full scan. */
static uint32_t grid_cap(const om_scene *s) { return 2 * (s->ntris ? s->ntris : 1) + grid_side(s) * grid_side(s); }

static size_t scene_bytes(const om_scene *s)
{
    const size_t n = s->ntris ? s->ntris : 1, g = grid_side(s);
    return om_arena_need(n * 4 * sizeof(float), 8) + om_arena_need(n * sizeof(uint32_t), 8) +
           2 * om_arena_need((n + 31) / 32 * sizeof(uint32_t), 8) +
           om_arena_need((g * g + 1) * sizeof(uint32_t), 8) +
           om_arena_need((size_t)grid_cap(s) * sizeof(uint32_t), 8) +
           om_arena_need((n + 31) / 32 * sizeof(uint32_t), 8);
}

static size_t scratch_bytes(const om__asm_layout *l, uint64_t ncand)
{
    const size_t t2 = (size_t)l->tile * l->tile;
    return 2 * om_arena_need(t2 * sizeof(uint32_t), 8) +
           om_arena_need((size_t)ncand * sizeof(om__asm_cand), 8);
}

static uint64_t cand_count(const om__asm_layout *l)
{
    uint64_t n = om__asm_cand_max(l);
    return n ? n : 1;
}

static size_t asm_need(const om_scene *s, const om__asm_layout *l, bool lean)
{
    return om_arena_need(sizeof(asm_state), 16) + l->arena_bytes + scratch_bytes(l, cand_count(l)) +
           (lean ? 0 : scene_bytes(s));
}

static om_status asm_bytes(const om_method_cfg *mc, const om_scene *s, uint32_t w, uint32_t h,
                           size_t *min, size_t *full)
{
    (void)w; (void)h;
    om__asm_layout l;
    om__asm_cfg c;
    if (om__method_cfg_of(mc, &om__method_asm, &c, NULL)) return OM_E_INVALID;
    om_status st = om__asm_layout_of(&l, &c, s->ntris, NULL);
    if (st) return st;
    /* Below the smallest cap the figure is what the state needs to say so (init fails
     * with OM_E_BUDGET naming the smallest cap). The lean mode renders the same frame. */
    *min = asm_need(s, &l, true);
    *full = asm_need(s, &l, false);
    return OM_OK;
}

static om_status asm_init(void **state, om_arena *a, const om_method_cfg *mc, const om_scene *s,
                          uint32_t w, uint32_t h, om_diag *d)
{
    om_status st;
    om__asm_layout l;
    void *p;
    *state = NULL;   /* a host that ignores a failed init gets OM_E_INVALID, not a crash */
    om__asm_cfg cv;
    const om__asm_cfg *c = &cv;
    if ((st = om__method_cfg_of(mc, &om__method_asm, &cv, d))) return st;
    if ((st = om__asm_layout_of(&l, c, s->ntris, d))) return st;
    if (l.count == 0) {
        char tmp[8];
        om__str b = om__diag_begin(d, OM_E_BUDGET, tmp, sizeof tmp);
        if (d) { d->asked = (size_t)l.min_cap; d->left = (size_t)(c->asm_cap < SIZE_MAX ? c->asm_cap : SIZE_MAX); }
        om__str_s(&b, "asm: asm.cap ");
        om__str_u(&b, c->asm_cap);
        om__str_s(&b, " is below the root node and one tile; the smallest cap is ");
        om__str_u(&b, l.min_cap);
        om__str_s(&b, " bytes");
        return OM_E_BUDGET;
    }
    if (w < 1 || h < 1) return om__fail(d, OM_E_INVALID, "asm: image size must be at least 1x1");
    if ((st = om__need(a, asm_need(s, &l, true), "asm", d))) return st;
    const bool lean = om_arena_left(a) < asm_need(s, &l, false);
    if ((st = om_arena_alloc(a, sizeof(asm_state), 16, &p, d))) return st;
    asm_state *m = (asm_state *)p;
    m->scene = s;
    m->cfg = *c;
    m->lean = lean;
    m->tbox = NULL;
    m->centre[0] = m->centre[1] = NULL;
    m->cull = NULL;
    m->gready = false;
    if ((st = om__asm_tree_init(&m->tree, a, &l, d))) return st;
    const size_t t2 = (size_t)l.tile * l.tile;
    uint64_t nc = cand_count(&l);
    if (!lean) {
        if ((st = om_arena_alloc(a, (size_t)(s->ntris ? s->ntris : 1) * 4 * sizeof(float), 8, &p, d))) return st;
        m->tbox = (float *)p;
        for (int i = 0; i < 2; i++) {
            if ((st = om_arena_alloc(a, ((size_t)(s->ntris ? s->ntris : 1) + 31) / 32 * sizeof(uint32_t), 8, &p, d)))
                return st;
            m->centre[i] = (uint32_t *)p;
        }
        if ((st = om_arena_alloc(a, (size_t)(s->ntris ? s->ntris : 1) * sizeof(uint32_t), 8, &p, d))) return st;
        m->cull = (uint32_t *)p;
        const size_t g = grid_side(s);
        m->gside = (uint32_t)g;
        m->gcap = grid_cap(s);
        if ((st = om_arena_alloc(a, (g * g + 1) * sizeof(uint32_t), 8, &p, d))) return st;
        m->gstart = (uint32_t *)p;
        if ((st = om_arena_alloc(a, (size_t)m->gcap * sizeof(uint32_t), 8, &p, d))) return st;
        m->glist = (uint32_t *)p;
        if ((st = om_arena_alloc(a, ((size_t)(s->ntris ? s->ntris : 1) + 31) / 32 * sizeof(uint32_t), 8, &p, d)))
            return st;
        m->gbits = (uint32_t *)p;
        memset(m->gbits, 0, ((size_t)(s->ntris ? s->ntris : 1) + 31) / 32 * sizeof(uint32_t));
    }
    if ((st = om_arena_alloc(a, t2 * sizeof(uint32_t), 8, &p, d))) return st;
    m->sdepth = (uint32_t *)p;
    if ((st = om_arena_alloc(a, t2 * sizeof(uint32_t), 8, &p, d))) return st;
    m->sid = (uint32_t *)p;
    if ((st = om_arena_alloc(a, (size_t)nc * sizeof(om__asm_cand), 8, &p, d))) return st;
    m->cand = (om__asm_cand *)p;
    m->ncand_max = nc > UINT32_MAX ? UINT32_MAX : (uint32_t)nc;
    for (uint32_t i = 0; i <= OM__ASM_MAX_LEVEL; i++) m->inv_scale[i] = (double)l.tile / om__asm_grid(&l, i);
    m->cache = OM__ASM_NONE;
    *state = m;
    return OM_OK;
}

static om_status asm_begin(void *state, const om_view *v, om_diag *d)
{
    asm_state *m = (asm_state *)state;
    if (!m) return om__fail(d, OM_E_INVALID, "asm: no state (did init fail?)");
    m->view = *v;
    om__asm_pctx_begin(&m->pc, &m->tree.lay, &m->cfg, &m->view);
    m->samples = m->shadowed = m->analysed = m->straddling = m->candidates = m->rebuilds = 0;
    m->prepared = false;
    m->cache = OM__ASM_NONE;
    om__asm_frame(&m->tree);
    return OM_OK;
}

/* ---- rendering tiles */

static asm_dvec dapply(const om_mat4 *mt, om_vec3 p)
{
    const float *a = mt->m;
    asm_dvec r;
    r.x = (double)a[0] * p.x + (double)a[1] * p.y + (double)a[2] * p.z + (double)a[3];
    r.y = (double)a[4] * p.x + (double)a[5] * p.y + (double)a[6] * p.z + (double)a[7];
    r.z = (double)a[8] * p.x + (double)a[9] * p.y + (double)a[10] * p.z + (double)a[11];
    r.w = (double)a[12] * p.x + (double)a[13] * p.y + (double)a[14] * p.z + (double)a[15];
    return r;
}

/* A triangle's bounds on the light's image in base texels (R per side), from its
 * vertices' light clip coordinates. */
static void tri_box(const asm_dvec q[3], double R, float b[4])
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

/* One triangle into the tile: its clip coordinates composed with the tile's window. */
static void render_tri(om_raster *r, const asm_dvec q[3], double s_, double kx, double ky,
                       uint32_t t)
{
    om_vec4 c[3];
    for (int i = 0; i < 3; i++) {
        c[i].x = (float)(q[i].x * s_ + q[i].w * kx);
        c[i].y = (float)(q[i].y * s_ + q[i].w * ky);
        c[i].z = (float)q[i].z;
        c[i].w = (float)q[i].w;
    }
    om__raster_tri(r, c, t);
}

/* The triangles whose bounds meet the region and hold a texel centre, in index order,
 * into m->cull: every triangle's bounds tested (most miss a deep node's region). */
static uint32_t gather_all(asm_state *m, float u0, float v0, float u1, float v1, double sc,
                           const uint32_t *centre)
{
    uint32_t n = 0;
    if (centre) {   /* a word of bits at a time: in a big scene most are clear */
        for (uint32_t w = 0; w < (m->scene->ntris + 31) / 32; w++)
            for (uint32_t bits = centre[w]; bits; bits &= bits - 1) {
                const uint32_t k = w * 32 + om__ctz32(bits);
                m->cull[n] = k;
                n += box_meets(&m->tbox[(size_t)k * 4], u0, v0, u1, v1);
            }
        return n;
    }
    for (uint32_t k = 0; k < m->scene->ntris; k++) {
        const float *b = &m->tbox[(size_t)k * 4];
        m->cull[n] = k;
        n += box_meets(b, u0, v0, u1, v1) && box_holds_centre(b, sc);
    }
    return n;
}

/* The cell of a base-texel coordinate, clamped to the grid (bounds beyond the map
 * fall in its border cells). */
static uint32_t cell_of(const asm_state *m, float u)
{
    float f = u * (float)m->gside / (float)m->tree.lay.tile;
    return !(f > 0.0f) ? 0 : f >= (float)(m->gside - 1) ? m->gside - 1 : (uint32_t)f;
}

/* This frame's cell lists (a counting sort of triangles by cell); gready stays false
 * when they would not fit. */
static void grid_make(asm_state *m)
{
    const om_scene *s = m->scene;
    const uint32_t G = m->gside;
    m->gready = false;
    memset(m->gstart, 0, ((size_t)G * G + 1) * sizeof(uint32_t));
    uint64_t total = 0;
    for (uint32_t k = 0; k < s->ntris; k++) {
        const float *b = &m->tbox[(size_t)k * 4];
        uint32_t cx0 = cell_of(m, b[0]), cy0 = cell_of(m, b[1]), cx1 = cell_of(m, b[2]), cy1 = cell_of(m, b[3]);
        total += (uint64_t)(cx1 - cx0 + 1) * (cy1 - cy0 + 1);
        if (total > m->gcap) return;
        for (uint32_t cy = cy0; cy <= cy1; cy++)
            for (uint32_t cx = cx0; cx <= cx1; cx++) m->gstart[cy * G + cx + 1]++;
    }
    for (uint32_t c = 0; c < G * G; c++) m->gstart[c + 1] += m->gstart[c];
    for (uint32_t k = 0; k < s->ntris; k++) {   /* each cell's list in index order */
        const float *b = &m->tbox[(size_t)k * 4];
        uint32_t cx0 = cell_of(m, b[0]), cy0 = cell_of(m, b[1]), cx1 = cell_of(m, b[2]), cy1 = cell_of(m, b[3]);
        for (uint32_t cy = cy0; cy <= cy1; cy++)
            for (uint32_t cx = cx0; cx <= cx1; cx++) m->glist[m->gstart[cy * G + cx]++] = k;
    }
    for (uint32_t c = G * G; c > 0; c--) m->gstart[c] = m->gstart[c - 1];   /* back to starts */
    m->gstart[0] = 0;
    m->gready = true;
}

/* gather_all's result from the cells the region meets: their triangles marked in a
 * bit set (a triangle in several cells once; with `centre`, only those it has),
 * collected in index order and tested as gather_all tests them. */
static uint32_t gather_cells(asm_state *m, float u0, float v0, float u1, float v1, double sc,
                             const uint32_t *centre)
{
    const uint32_t G = m->gside;
    uint32_t lo = UINT32_MAX, hi = 0, n = 0;
    for (uint32_t cy = cell_of(m, v0); cy <= cell_of(m, v1); cy++)
        for (uint32_t cx = cell_of(m, u0); cx <= cell_of(m, u1); cx++)
            for (uint32_t i = m->gstart[cy * G + cx]; i < m->gstart[cy * G + cx + 1]; i++) {
                uint32_t k = m->glist[i];
                m->gbits[k >> 5] |= (centre ? centre[k >> 5] : ~0u) & 1u << (k & 31);
                if (k < lo) lo = k;
                if (k > hi) hi = k;
            }
    for (uint32_t w = lo == UINT32_MAX ? 1 : lo >> 5; w <= (hi >> 5) && lo != UINT32_MAX; w++) {
        uint32_t bits = m->gbits[w];
        m->gbits[w] = 0;
        while (bits) {
            uint32_t k = w * 32 + om__ctz32(bits);
            bits &= bits - 1;
            const float *b = &m->tbox[(size_t)k * 4];
            m->cull[n] = k;
            n += box_meets(b, u0, v0, u1, v1) && (centre || box_holds_centre(b, sc));
        }
    }
    return n;
}

/* Renders texels [ox, ox + tile) x [oy, oy + tile) of level `level`'s grid into a
 * tile's depth and ids, from the triangles whose light bounds meet the region. The light's clip space is composed with the window that maps the
 * region's tile to [-1, 1] (x' = s x + k w), so the engine's rasterizer, clipping and
 * fill rule apply unchanged at any depth of the tree. */
static void render(asm_state *m, uint32_t level, uint32_t ox, uint32_t oy, uint32_t *depth,
                   uint16_t *id16, uint32_t *id32)
{
    const om__asm_layout *l = &m->tree.lay;
    const om_scene *s = m->scene;
    const uint32_t T = l->tile;
    const double s_ = om__asm_grid(l, level) / (double)T;
    const double kx = s_ - 2.0 * (double)ox / (double)T - 1.0;
    const double ky = 1.0 - s_ + 2.0 * (double)oy / (double)T;
    /* the region in base texels, one texel of margin against rounding */
    const double ic = m->inv_scale[level];
    const float u0 = (float)(((double)ox - 1.0) * ic), u1 = (float)(((double)ox + T + 1.0) * ic);
    const float v0 = (float)(((double)oy - 1.0) * ic), v1 = (float)(((double)oy + T + 1.0) * ic);
    om_target tg = {T, T, 0, T, m->sdepth, m->sid};
    om__target_clear(&tg);
    om_raster r = {&tg, OM_RASTER_DEPTH_ID, NULL, NULL, NULL, NULL, 0, false, NULL, NULL, NULL, NULL, 0, 0, NULL, 0};
    /* back faces of closed shapes skipped, as in every light map (om__cull); the
     * window scales x and y by s_ > 0, so windings stay */
    om__cull cl;
    om__cull_begin(&cl, s, &m->view.light_vp);
    if (m->lean) {
        /* The same triangles in the same order as the fast path below, so the same tile:
         * projections and bounds are made per tile instead of kept per frame. */
        for (uint32_t t = 0; t < s->ntris; t++) {
            const uint32_t *ix = s->idx + (size_t)t * 3;
            asm_dvec q[3];
            float b[4];
            for (int i = 0; i < 3; i++) q[i] = dapply(&m->view.light_vp, s->verts[ix[i]]);
            tri_box(q, T, b);
            if (!box_meets(b, u0, v0, u1, v1) || !box_holds_centre(b, l->scale[level])) continue;
            r.cull_back = om__cull_next(&cl, t);
            render_tri(&r, q, s_, kx, ky, t);
        }
    } else {
        const double sc = l->scale[level];
        const uint32_t *centre = level < 2 ? m->centre[level] : NULL;
        /* the base covers every cell: its centre bits alone are the shorter walk */
        uint32_t n = m->gready && level > 0 ? gather_cells(m, u0, v0, u1, v1, sc, centre)
                                            : gather_all(m, u0, v0, u1, v1, sc, centre);
        for (uint32_t k = 0; k < n; k++) {
            const uint32_t t = m->cull[k];
            const uint32_t *ix = s->idx + (size_t)t * 3;
#if defined(__GNUC__) || defined(__clang__)
            /* a big scene's triangles in a tile lie far apart in memory: ask for the
             * next ones' vertices early (a hint: no effect on what is computed) */
            if (k + 4 < n) {
                const uint32_t *nx = s->idx + (size_t)m->cull[k + 4] * 3;
                for (int i = 0; i < 3; i++) __builtin_prefetch(&s->verts[nx[i]]);
            }
            if (k + 8 < n) __builtin_prefetch(s->idx + (size_t)m->cull[k + 8] * 3);
#endif
            asm_dvec q[3];
            for (int i = 0; i < 3; i++) q[i] = dapply(&m->view.light_vp, s->verts[ix[i]]);
            r.cull_back = om__cull_next(&cl, t);
            render_tri(&r, q, s_, kx, ky, t);
        }
    }
    const size_t t2 = (size_t)T * T;
    memcpy(depth, m->sdepth, t2 * sizeof *depth);
    if (id16)
        for (size_t i = 0; i < t2; i++) id16[i] = m->sid[i] == OM_NO_TRI ? (uint16_t)0xFFFFu : (uint16_t)m->sid[i];
    else
        memcpy(id32, m->sid, t2 * sizeof *id32);
}

static void render_node(asm_state *m, uint32_t index)
{
    om__asm_tile tl;
    om__asm_tile_of(&m->tree, index, &tl);
    render(m, tl.node->level, tl.node->ox, tl.node->oy, tl.depth, tl.id16, tl.id32);
}

/* This frame's projections (once, from the first observe or build), and the rebuild
 * when the light has moved. */
static void prepare(asm_state *m)
{
    if (m->prepared) return;
    m->prepared = true;
    const om_scene *s = m->scene;
    if (!m->lean) {
        /* Projections per triangle, kept only as bounds: a tile projects again the few
         * it renders (the same bits), which costs less than keeping every vertex's. */
        const size_t words = ((size_t)s->ntris + 31) / 32;
        memset(m->centre[0], 0, words * sizeof(uint32_t));
        memset(m->centre[1], 0, words * sizeof(uint32_t));
        for (uint32_t k = 0; k < s->ntris; k++) {
            const uint32_t *ix = s->idx + (size_t)k * 3;
            asm_dvec q[3];
            for (int i = 0; i < 3; i++) q[i] = dapply(&m->view.light_vp, s->verts[ix[i]]);
            float *b = &m->tbox[(size_t)k * 4];
            tri_box(q, m->tree.lay.tile, b);
            for (int i = 0; i < 2; i++)
                m->centre[i][k >> 5] |= (uint32_t)box_holds_centre(b, m->tree.lay.scale[i]) << (k & 31);
        }
        grid_make(m);
    }
    if (!m->built || memcmp(&m->built_vp, &m->view.light_vp, sizeof m->built_vp) != 0) {
        om__asm_tree_clear(&m->tree);
        render_node(m, OM__ASM_ROOT);
        m->built_vp = m->view.light_vp;
        m->built = true;
        m->rebuilds++;
    }
}

/* ---- one sample: the float path where its bounds decide (asm_point.c), the exact
 * one where they do not. Both give the same answer to every question asked below, so
 * a sample may switch from one to the other at any point of its descent. */

typedef struct asm_smp {
    const om_sample *s;
    bool analyse;          /* the analysis: the bias with the footprint ratio */
    bool fast;             /* f places the sample */
    bool exact, exact_bias;   /* p holds the exact place; and its bias */
    uint32_t zl_level;     /* zl is the exact biased depth at this level */
    double zl;
    om__asm_fpt f;
    om__asm_pt p;
} asm_smp;

/* Starts a sample; false where the exact path does not look it up. */
static bool smp_begin(const asm_state *m, const om_sample *s, bool analyse, asm_smp *o)
{
    o->s = s;
    o->analyse = analyse;
    o->exact = o->exact_bias = false;
    o->zl_level = UINT32_MAX;
    o->fast = m->pc.fix && om__asm_fpt_uv(&m->pc, s, &o->f);
    if (o->fast) return true;
    o->exact = true;
    return om__asm_pt_uv(&m->pc, s, &o->p);
}

static const om__asm_pt *smp_exact(const asm_state *m, asm_smp *o, bool bias)
{
    if (!o->exact) {
        o->exact = true;
        (void)om__asm_pt_uv(&m->pc, o->s, &o->p);   /* true: the float path placed it */
    }
    if (bias && !o->exact_bias) {
        o->exact_bias = true;
        om__asm_pt_bias(&m->pc, o->s, &o->p, o->analyse);
    }
    return &o->p;
}

static inline double level_z(const asm_state *m, const om__asm_pt *p, uint32_t level)
{
    return p->z - p->bias_c - p->bias_s * m->inv_scale[level];
}

/* The sample's texel on `level`'s grid, where the float path decides it. */
static inline bool fast_grid(const asm_state *m, const asm_smp *o, uint32_t level, uint32_t *gx,
                             uint32_t *gy)
{
    if (!o->fast) return false;
    const uint32_t sh = m->pc.shift[level];
    *gx = o->f.u0 >> sh;
    *gy = o->f.v0 >> sh;
    return *gx == o->f.u1 >> sh && *gy == o->f.v1 >> sh;
}

static inline uint32_t clamp_in(uint32_t g, uint32_t o, uint32_t size)
{
    return g < o ? 0u : g - o >= size ? size - 1 : g - o;
}

/* The sample's texel in a tile, clamped: as om__asm_find does it. */
static inline void smp_texel(const asm_state *m, asm_smp *o, const om__asm_tile *tl, uint32_t *x, uint32_t *y)
{
    const uint32_t level = tl->node->level;
    uint32_t gx, gy;
    if (fast_grid(m, o, level, &gx, &gy)) {
        *x = clamp_in(gx, tl->node->ox, tl->size);
        *y = clamp_in(gy, tl->node->oy, tl->size);
        return;
    }
    const om__asm_pt *p = smp_exact(m, o, false);
    const double s = m->tree.lay.scale[level];
    double lx = floor(p->u * s - (double)tl->node->ox), ly = floor(p->v * s - (double)tl->node->oy);
    *x = !(lx > 0.0) ? 0u : lx >= (double)tl->size ? tl->size - 1 : (uint32_t)lx;
    *y = !(ly > 0.0) ? 0u : ly >= (double)tl->size ? tl->size - 1 : (uint32_t)ly;
}

/* The biased depth at `level` against a stored one (the exact one once a level). */
static bool smp_depth_lit(const asm_state *m, asm_smp *o, uint32_t level, uint32_t depth)
{
    if (o->fast) {
        if (!o->f.bias) om__asm_fpt_bias(&m->pc, o->s, &o->f, o->analyse);
        const int r = om__asm_fpt_lit(&m->pc, &o->f, level, depth);
        if (r >= 0) return r == 1;
    }
    if (o->zl_level != level) {
        o->zl = level_z(m, smp_exact(m, o, true), level);
        o->zl_level = level;
    }
    return o->zl <= (double)depth;
}

/* Section 4.2: the polygon ID first; when it differs, the biased depth. */
static inline bool smp_lit(const asm_state *m, asm_smp *o, const om__asm_tile *tl, uint32_t x, uint32_t y)
{
    const size_t i = (size_t)y * tl->size + x;
    if (tl->id16 ? tl->id16[i] == (uint16_t)o->s->tri : tl->id32[i] == o->s->tri) return true;
    return smp_depth_lit(m, o, tl->node->level, tl->depth[i]);
}

/* Whether `level`'s texel is larger on the surface than the eye's pixel. */
static bool smp_finer(const asm_state *m, asm_smp *o, uint32_t level)
{
    if (o->fast) {
        if (!o->f.bias) om__asm_fpt_bias(&m->pc, o->s, &o->f, o->analyse);
        const int r = om__asm_fpt_finer(&m->pc, &o->f, level);
        if (r >= 0) return r == 1;
    }
    return smp_exact(m, o, true)->ratio0 * m->inv_scale[level] > 1.0;
}

/* The sample's own test disagrees across the 3x3 texels around it. */
static bool straddles(const asm_state *m, asm_smp *o, const om__asm_tile *tl, uint32_t x, uint32_t y)
{
    bool c = smp_lit(m, o, tl, x, y);
    uint32_t x0 = x ? x - 1 : 0, y0 = y ? y - 1 : 0;
    uint32_t x1 = x + 1 < tl->size ? x + 1 : x, y1 = y + 1 < tl->size ? y + 1 : y;
    for (uint32_t j = y0; j <= y1; j++)
        for (uint32_t i = x0; i <= x1; i++)
            if (smp_lit(m, o, tl, i, j) != c) return true;
    return false;
}

static om_status asm_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)d;
    asm_state *m = (asm_state *)state;
    om__asm_tree *t = &m->tree;
    const om__asm_layout *l = &t->lay;
    const uint32_t stride = m->cfg.asm_stride ? m->cfg.asm_stride : 1;
    const double ncell = (double)l->cp * l->cp;
    prepare(m);
    for (uint32_t y = 0; y < st->rows; y++) {
        const uint32_t gy = st->y0 + y;
        /* one sample in `stride`, on diagonals so no column or row is favoured */
        for (uint32_t x = (uint32_t)((stride - (3u * gy) % stride) % stride); x < st->width; x += stride) {
            size_t i = (size_t)y * st->width + x;
            if (!(st->terms[i].flags & OM_TERM_EXPOSED)) continue;
            asm_smp o;
            if (!smp_begin(m, &st->samples[i], true, &o)) continue;
            m->analysed++;
            uint32_t index = OM__ASM_ROOT, level = 0;
            for (;;) {
                om__asm_tile tl;
                uint32_t tx, ty;
                bool want = false;
                om__asm_tile_of(t, index, &tl);
                smp_texel(m, &o, &tl, &tx, &ty);
                tl.node->stamp = t->frame;
                uint32_t c = (ty / tl.cp) * tl.cells + tx / tl.cp;
                uint32_t child = tl.child[c];
                if (level == 0) {   /* the base: into the root tile, made on first touch */
                    if (child == OM__ASM_NONE) {
                        /* Only from free or unused memory here (benefit 0 replaces
                         * nothing): the counts that rule replacement are not complete
                         * until every strip is seen. Build retries the rest. */
                        child = om__asm_make(t, OM__ASM_ROOT, c, 0);
                        if (child == OM__ASM_NONE) {
                            tl.ben[c]++;
                            break;
                        }
                        render_node(m, child);
                    }
                    om__asm_node_at(t, child)->benefit++;
                } else {
                    want = smp_finer(m, &o, level) && straddles(m, &o, &tl, tx, ty);
                    if (child != OM__ASM_NONE && want) om__asm_node_at(t, child)->benefit++;
                }
                if (child != OM__ASM_NONE) {
                    index = child;
                    level++;
                    continue;
                }
                if (want && level < l->max_level) {
                    /* Section 3.1: N_required = N_current * (texel area / pixel area). */
                    const double r = smp_exact(m, &o, true)->ratio0 * m->inv_scale[level];
                    const float nreq = (float)(ncell * r * r);
                    tl.ben[c]++;
                    if (nreq > tl.need[c]) tl.need[c] = nreq;
                    m->straddling++;
                }
                break;
            }
        }
    }
    return OM_OK;
}

static om_status asm_build(void *state, om_diag *d)
{
    (void)d;
    asm_state *m = (asm_state *)state;
    om__asm_tree *t = &m->tree;
    prepare(m);
    /* Root tiles first, wherever samples fell, most samples first: the root level is
     * what a conventional map at asm.root would give, and every refinement hangs off it. */
    uint32_t n = om__asm_candidates(t, true, 0.0f, 0.0f, m->cand, m->ncand_max);
    while (n > 0) {
        om__asm_cand c;
        n = om__asm_cand_pop(m->cand, n, &c);
        uint32_t k = om__asm_make(t, OM__ASM_ROOT, c.cell, c.benefit);
        if (k == OM__ASM_NONE) break;   /* no room: the rest have fewer samples still */
        render_node(m, k);
    }
    n = om__asm_candidates(t, false, m->cfg.asm_cost_a, m->cfg.asm_cost_b, m->cand, m->ncand_max);
    m->candidates = n;
    double spent = 0.0;
    uint32_t refused = 0;   /* a refused benefit: lesser ones cannot replace anything */
    while (n > 0 && spent < (double)m->cfg.asm_work) {
        om__asm_cand c;
        n = om__asm_cand_pop(m->cand, n, &c);
        if (c.benefit <= refused) continue;
        const om__asm_node *pn = om__asm_node_at(t, c.node);   /* may have gone to make room */
        if (!pn->alive || pn->gen != c.gen) continue;
        uint32_t k = om__asm_make(t, c.node, c.cell, c.benefit);
        if (k == OM__ASM_NONE) {
            refused = c.benefit;
            continue;
        }
        render_node(m, k);
        spent += (double)c.cost;
    }
    m->cache = OM__ASM_NONE;
    return OM_OK;
}

/* The last leaf a lookup found (section 4.3's cache): the state's for a strip at a
 * time, a band's own (its scratch) on the host's threads. */
typedef struct asm_cache {
    uint32_t index;        /* OM__ASM_NONE: empty */
    om__asm_tile tile;
} asm_cache;

/* The deepest node over the sample and its texel there, reading the tree only: the
 * cached leaf when it still holds the sample, else a descent from the root, which
 * refills the cache and says so (*moved). */
static void smp_find(const asm_state *m, asm_smp *o, asm_cache *c, om__asm_tile *tl, uint32_t *tx,
                     uint32_t *ty, bool *moved)
{
    /* om__asm_tile_of hands out the tree's arrays; nothing here writes them */
    om__asm_tree *t = (om__asm_tree *)&m->tree;
    if (c->index != OM__ASM_NONE) {
        const om__asm_tile *ct = &c->tile;
        const om__asm_node *n = ct->node;
        uint32_t gx, gy, x = 0, y = 0;
        bool in;
        if (fast_grid(m, o, n->level, &gx, &gy)) {
            in = gx >= n->ox && gy >= n->oy && gx - n->ox < ct->size && gy - n->oy < ct->size;
            if (in) x = gx - n->ox, y = gy - n->oy;
        } else {
            const om__asm_pt *p = smp_exact(m, o, false);
            const double s = t->lay.scale[n->level];   /* the descent's own arithmetic */
            double lx = floor(p->u * s - (double)n->ox), ly = floor(p->v * s - (double)n->oy);
            in = lx >= 0.0 && ly >= 0.0 && lx < (double)ct->size && ly < (double)ct->size;
            if (in) x = (uint32_t)lx, y = (uint32_t)ly;
        }
        if (in && ct->child[(y / ct->cp) * ct->cells + x / ct->cp] == OM__ASM_NONE) {
            *tl = *ct;
            *tx = x;
            *ty = y;
            return;
        }
    }
    uint32_t index = OM__ASM_ROOT;
    for (;;) {
        om__asm_tile_of(t, index, tl);
        smp_texel(m, o, tl, tx, ty);
        const uint32_t child = tl->child[(*ty / tl->cp) * tl->cells + *tx / tl->cp];
        if (child == OM__ASM_NONE) break;
        index = child;
    }
    c->index = index;
    c->tile = *tl;
    *moved = true;
}

/* A lookup uses its leaf and every node above it (section 3.2's "recently used"). A
 * leaf the cache hands out again was stamped with its path when it was found. */
static void stamp_path(om__asm_tree *t, uint32_t index)
{
    for (;;) {
        om__asm_node *n = om__asm_node_at(t, index);
        n->stamp = t->frame;
        if (index == OM__ASM_ROOT) return;
        index = n->parent;
    }
}

/* One exposed sample: 1 lit, 0 shadowed (behind the light or off every grid: lit). */
static int resolve_one(const asm_state *m, const om_sample *s, asm_cache *c, bool *moved)
{
    asm_smp o;
    if (!smp_begin(m, s, false, &o)) return 1;
    uint32_t tx, ty;
    om__asm_tile tl;
    smp_find(m, &o, c, &tl, &tx, &ty, moved);
    return smp_lit(m, &o, &tl, tx, ty);
}

static om_status asm_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    asm_state *m = (asm_state *)state;
    size_t n = (size_t)st->rows * st->width;
    prepare(m);
    asm_cache c = {m->cache, m->cache_tile};
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        m->samples++;
        bool moved = false;
        if (!resolve_one(m, &st->samples[i], &c, &moved)) {
            t->r = t->g = t->b = 0;
            m->shadowed++;
        }
        if (moved) stamp_path(&m->tree, c.index);
    }
    m->cache = c.index;
    m->cache_tile = c.tile;
    return OM_OK;
}


/* By bands on the host's threads (frame.h, om__bands): each band looks up its own
 * samples with a cache of its own and writes nothing of the state. The use stamps are
 * the one thing a lookup leaves in the tree: a band marks each sample whose lookup
 * descended (its term's blue one off its red), and finish, on the calling thread,
 * finds those samples' leaves again and stamps their paths. The stamped nodes are the
 * paths to every leaf found, whatever the bands: the stamps, the terms and the counts
 * (added up by merge) are a strip at a time's. */
static void asm_band(const void *state, om_strip *st, void *scratch, uint32_t counts[8])
{
    const asm_state *m = (const asm_state *)state;
    asm_cache *c = (asm_cache *)scratch;
    c->index = OM__ASM_NONE;
    const size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        counts[0]++;
        bool moved = false;
        if (!resolve_one(m, &st->samples[i], c, &moved)) {
            t->r = t->g = t->b = 0;
            counts[1]++;
        }
        if (moved) t->b ^= 1u;
    }
}

static void asm_merge(void *state, const uint32_t counts[8])
{
    asm_state *m = (asm_state *)state;
    m->samples += counts[0];
    m->shadowed += counts[1];
}

static void asm_finish(void *state, om_strip *st)
{
    asm_state *m = (asm_state *)state;
    const size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        if (t->b == t->r) continue;
        t->b = t->r;
        asm_smp o;
        asm_cache c = {OM__ASM_NONE, m->cache_tile};
        om__asm_tile tl;
        uint32_t tx, ty;
        bool moved = false;
        if (!smp_begin(m, &st->samples[i], false, &o)) continue;   /* (it was looked up) */
        smp_find(m, &o, &c, &tl, &tx, &ty, &moved);
        stamp_path(&m->tree, c.index);
    }
}

const om__bands om__bands_asm = {asm_band, asm_merge, sizeof(asm_cache), NULL, NULL, asm_finish};

const om__asm_tree *om__asm_tree_of(const void *state) { return &((const asm_state *)state)->tree; }

static void asm_stats(const void *state, om_method_stats *out)
{
    const asm_state *m = (const asm_state *)state;
    const om__asm_tree *t = &m->tree;
    memset(out, 0, sizeof *out);
    out->bytes_used = asm_need(m->scene, &t->lay, m->lean);
    uint64_t inuse = om__asm_bytes_in_use(t);
    double eff = om__asm_grid(&t->lay, om__asm_depth(t));
    const uint32_t v[8] = {t->pool.in_use, t->created, t->evicted,
                           inuse > UINT32_MAX ? UINT32_MAX : (uint32_t)inuse,
                           eff > 4294967295.0 ? UINT32_MAX : (uint32_t)eff, m->candidates,
                           m->samples, m->shadowed};
    for (int i = 0; i < 8; i++) out->counters[i] = v[i];
    out->counter_names[0] = "nodes";
    out->counter_names[1] = "created";
    out->counter_names[2] = "evicted";
    out->counter_names[3] = "bytes in use";
    out->counter_names[4] = "effective resolution";
    out->counter_names[5] = "refinable cells";
    out->counter_names[6] = "samples";
    out->counter_names[7] = "samples shadowed";
    out->ncounters = 8;
}

#define SET(field, name, kind, lo, hi, def, doc) OM__SETTING(om__asm_cfg, field, name, kind, lo, hi, def, doc)

static const om_setting settings[] = {
    OM__SET_BIAS(om__asm_cfg), OM__SET_SLOPE(om__asm_cfg),
    SET(asm_cap, "asm.cap", OM_SETTING_U64, 0, 1e15, 16 << 20, "bytes the node structure may hold"),
    SET(asm_tile, "asm.tile", OM_SETTING_U32, 4, 1024, 64, "texels per side of a node's tile"),
    SET(asm_cells, "asm.cells", OM_SETTING_U32, 1, 64, 8, "cells per side of a node"),
    SET(asm_root, "asm.root", OM_SETTING_U32, 16, OM_MAX_DIM, 1024, "texels per side of the root"),
    SET(asm_work, "asm.work", OM_SETTING_U32, 0, 1e9, 64, "per-frame work budget, cost units"),
    SET(asm_stride, "asm.stride", OM_SETTING_U32, 1, 1024, 8, "analyse one visible sample in N"),
    SET(asm_cost_a, "asm.a", OM_SETTING_F32, 0, 1e6, 1.0 / 4096.0, "node cost per required texel"),
    SET(asm_cost_b, "asm.b", OM_SETTING_F32, 0, 1e6, 1, "node cost, constant part"),
    SET(asm_float, "asm.float", OM_SETTING_U32, 0, 1, OM_FAST_FLOAT,
        "1: place samples in float first (same frames; 1 where double is software)"),
};

#undef SET

const om_method om__method_asm = {
    "asm", "adaptive shadow map: a tree of tiles refined where the eye needs it, within asm.cap",
    OM_METHOD_OBSERVES,
    asm_bytes, asm_init, asm_begin, asm_observe, asm_build, asm_resolve, asm_stats, NULL,
    settings, sizeof settings / sizeof settings[0], sizeof(om__asm_cfg),
};
