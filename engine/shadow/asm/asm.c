/* asm.c — Adaptive Shadow Maps (Fernando, Fernandez, Bala, Greenberg 2001; paper 002)
 * under a user-set memory cap: the frame flow, the view-driven analysis and the lookup.
 * Node tiles are rendered by asm_render.c; the tree, its pool and its removal rules are
 * asm_tree.c.
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
 * Bias: the constant and slope-scaled bias of the conventional map (cfg bias_const a
 * fraction of the light's depth range, bias_slope in texels of the node the sample is
 * tested in); the paper notes the ID test does not remove the bias problem. pcf and
 * normal_offset do not apply. */
#include "../method.h"
#include "asm.h"

#include <float.h>

OM__CFG_FITS(om__asm_cfg);
extern const om_method om__method_asm;



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

/* (Saturating, as the layout's arena_bytes: a candidate list past what a 32-bit
 * size_t holds asks for SIZE_MAX, which no arena has.) */
static size_t scratch_bytes(const om__asm_layout *l, uint64_t ncand)
{
    const size_t t2 = (size_t)l->tile * l->tile;
    const size_t n = ncand > SIZE_MAX ? SIZE_MAX : (size_t)ncand;
    return om__size_add(2 * om_arena_need(t2 * sizeof(uint32_t), 8),
                        om_arena_need(om__size_mul(n, sizeof(om__asm_cand)), 8));
}

static uint64_t cand_count(const om__asm_layout *l)
{
    uint64_t n = om__asm_cand_max(l);
    return n ? n : 1;
}

/* Each object's box as the tiles hold it (om__asm_state.drawn); none without objects. */
static size_t drawn_bytes(const om_scene *s)
{
    return s->nobjects ? om_arena_need(om__size_mul(s->nobjects, 2 * sizeof(om_vec3)), 8) : 0;
}

static size_t asm_need(const om_scene *s, const om__asm_layout *l, bool lean)
{
    return om__size_add(om__size_add(om__size_add(om_arena_need(sizeof(om__asm_state), 16), l->arena_bytes),
                                     drawn_bytes(s)),
                        om__size_add(scratch_bytes(l, cand_count(l)), lean ? 0 : scene_bytes(s)));
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
    if ((st = om_arena_alloc(a, sizeof(om__asm_state), 16, &p, d))) return st;
    om__asm_state *m = (om__asm_state *)p;
    m->scene = s;
    m->cfg = *c;
    m->lean = lean;
    m->tbox = NULL;
    m->centre[0] = m->centre[1] = NULL;
    m->cull = NULL;
    m->gready = false;
    m->drawn = NULL;
    if ((st = om__asm_tree_init(&m->tree, a, &l, d))) return st;
    if (s->nobjects) {
        if ((st = om_arena_alloc(a, (size_t)s->nobjects * 2 * sizeof(om_vec3), 8, &p, d))) return st;
        m->drawn = (om_vec3 *)p;
        memset(m->drawn, 0, (size_t)s->nobjects * 2 * sizeof(om_vec3));   /* set at the first build */
    }
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
    if ((st = om_arena_alloc(a, om__size_mul(nc > SIZE_MAX ? SIZE_MAX : (size_t)nc, sizeof(om__asm_cand)), 8, &p,
                             d)))
        return st;
    m->cand = (om__asm_cand *)p;
    m->ncand_max = nc > UINT32_MAX ? UINT32_MAX : (uint32_t)nc;
    for (uint32_t i = 0; i <= OM__ASM_MAX_LEVEL; i++) m->inv_scale[i] = (double)l.tile / om__asm_grid(&l, i);
    m->chunk = NULL;
    m->chunk_tris = 0;
    m->chunk_ready = false;
    if (lean && c->asm_float && s->ntris > 8) {
        /* what the arena has left: the finest runs it holds, if any */
        for (uint32_t ct = 8; ct <= 256 && !m->chunk; ct *= 2) {
            const size_t nb = ((size_t)s->ntris + ct - 1) / ct * 4 * sizeof(float);
            if (om_arena_need(nb, 8) > om_arena_left(a)) continue;
            if ((st = om_arena_alloc(a, nb, 8, &p, d))) return st;
            m->chunk = (float *)p;
            m->chunk_tris = ct;
        }
    }
    m->cache = OM__ASM_NONE;
    *state = m;
    return OM_OK;
}

static om_status asm_begin(void *state, const om_view *v, om_diag *d)
{
    om__asm_state *m = (om__asm_state *)state;
    if (!m) return om__fail(d, OM_E_INVALID, "asm: no state (did init fail?)");
    m->view = *v;
    om__asm_pctx_begin(&m->pc, &m->tree.lay, &m->cfg, &m->view);
    m->samples = m->shadowed = m->analysed = m->straddling = m->candidates = m->rebuilds = 0;
    m->redrawn = 0;
    m->prepared = false;
    m->chunk_ready = false;
    m->cache = OM__ASM_NONE;
    om__asm_frame(&m->tree);
    return OM_OK;
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
static bool smp_begin(const om__asm_state *m, const om_sample *s, bool analyse, asm_smp *o)
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

static const om__asm_pt *smp_exact(const om__asm_state *m, asm_smp *o, bool bias)
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

static inline double level_z(const om__asm_state *m, const om__asm_pt *p, uint32_t level)
{
    return p->z - p->bias_c - p->bias_s * m->inv_scale[level];
}

/* The sample's texel on `level`'s grid, where the float path decides it. */
static inline bool fast_grid(const om__asm_state *m, const asm_smp *o, uint32_t level, uint32_t *gx,
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
static inline void smp_texel(const om__asm_state *m, asm_smp *o, const om__asm_tile *tl, uint32_t *x, uint32_t *y)
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
static bool smp_depth_lit(const om__asm_state *m, asm_smp *o, uint32_t level, uint32_t depth)
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
static inline bool smp_lit(const om__asm_state *m, asm_smp *o, const om__asm_tile *tl, uint32_t x, uint32_t y)
{
    const size_t i = (size_t)y * tl->size + x;
    if (tl->id16 ? tl->id16[i] == (uint16_t)o->s->tri : tl->id32[i] == o->s->tri) return true;
    return smp_depth_lit(m, o, tl->node->level, tl->depth[i]);
}

/* Whether `level`'s texel is larger on the surface than the eye's pixel. */
static bool smp_finer(const om__asm_state *m, asm_smp *o, uint32_t level)
{
    if (o->fast) {
        if (!o->f.bias) om__asm_fpt_bias(&m->pc, o->s, &o->f, o->analyse);
        const int r = om__asm_fpt_finer(&m->pc, &o->f, level);
        if (r >= 0) return r == 1;
    }
    return smp_exact(m, o, true)->ratio0 * m->inv_scale[level] > 1.0;
}

/* The sample's own test disagrees across the 3x3 texels around it. */
static bool straddles(const om__asm_state *m, asm_smp *o, const om__asm_tile *tl, uint32_t x, uint32_t y)
{
    bool c = smp_lit(m, o, tl, x, y);
    uint32_t x0 = x ? x - 1 : 0, y0 = y ? y - 1 : 0;
    uint32_t x1 = x + 1 < tl->size ? x + 1 : x, y1 = y + 1 < tl->size ? y + 1 : y;
    for (uint32_t j = y0; j <= y1; j++)
        for (uint32_t i = x0; i <= x1; i++)
            if (smp_lit(m, o, tl, i, j) != c) return true;
    return false;
}

/* Where an analysed sample's findings go: with `a` NULL onto the tree itself (a strip
 * at a time), else into a band's accumulators (asm_jobs.c puts them on the tree after
 * the bands). A node touched is noted so the merge reads only the range. */
static inline void acc_node(const om__asm_acc *a, uint32_t index)
{
    if (index < a->hdr[2]) a->hdr[2] = index;
    if (index >= a->hdr[3]) a->hdr[3] = index + 1;
}

/* One more sample inside node `index` that needs it (its benefit, om__asm_make). */
static inline void add_benefit(om__asm_tree *t, const om__asm_acc *a, uint32_t index)
{
    if (!a) {
        om__asm_node_at(t, index)->benefit++;
        return;
    }
    a->benefit[index]++;
    acc_node(a, index);
}

/* A root tile made where a sample first falls in an empty cell of the base, from
 * free or unused memory only (benefit 0 replaces nothing): the counts that rule
 * replacement are not complete until every strip is seen, and build retries the rest.
 * Where none is made the cell counts the sample. */
static uint32_t root_tile(om__asm_state *m, const om__asm_tile *base, uint32_t c)
{
    const uint32_t k = om__asm_make(&m->tree, OM__ASM_ROOT, c, 0);
    if (k == OM__ASM_NONE) base->ben[c]++;
    else om__asm_render_node(m, k);
    return k;
}

/* observe's analysis of rows [y0, y0 + rows) of the strip: one walk for one thread and
 * for the bands, so both decide alike. With `a` NULL it writes the tree, and a sample
 * whose base cell holds no root tile makes it (root_tile). With `a` it reads the tree
 * only and writes nothing of `m`: such a sample goes no further, its term's g set to
 * 254 and the cell's first sample noted; with `again` only those samples (g back to
 * 255), once the root tiles are made. OM_INLINE: each caller gets its own copy with `a`
 * known, so one thread's walk costs what it did before the bands shared it. */
OM_INLINE void observe_rows(om__asm_state *m, const om_strip *st, uint32_t y0, uint32_t rows,
                            const om__asm_acc *a, bool again)
{
    om__asm_tree *t = &m->tree;
    const om__asm_layout *l = &t->lay;
    const uint32_t stride = m->cfg.asm_stride ? m->cfg.asm_stride : 1;
    const uint32_t c2 = l->cells * l->cells;
    const double ncell = (double)l->cp * l->cp;
    for (uint32_t y = y0; y < y0 + rows; y++) {
        const uint32_t gy = st->y0 + y;
        /* one sample in `stride`, on diagonals so no column or row is favoured */
        for (uint32_t x = (uint32_t)((stride - (3u * gy) % stride) % stride); x < st->width; x += stride) {
            const size_t i = (size_t)y * st->width + x;
            om_term *tm = &st->terms[i];
            if (!(tm->flags & OM_TERM_EXPOSED)) continue;
            if (again) {
                if (tm->g != 254) continue;
                tm->g = 255;
            }
            asm_smp o;
            if (!smp_begin(m, &st->samples[i], true, &o)) continue;
            if (!a) m->analysed++;
            else if (!again) a->hdr[0]++;
            uint32_t index = OM__ASM_ROOT, level = 0;
            for (;;) {
                om__asm_tile tl;
                uint32_t tx, ty;
                bool want = false;
                om__asm_tile_of(t, index, &tl);
                smp_texel(m, &o, &tl, &tx, &ty);
                if (a) {
                    const uint32_t bit = index == OM__ASM_ROOT ? l->count : index;
                    a->stamp[bit >> 5] |= 1u << (bit & 31);
                } else {
                    tl.node->stamp = t->frame;
                }
                const uint32_t c = (ty / tl.cp) * tl.cells + tx / tl.cp;
                uint32_t child = tl.child[c];
                if (level == 0) {   /* the base: into the root tile */
                    if (child == OM__ASM_NONE && a) {   /* made after the bands */
                        if (!again && (!a->first[c] || a->first[c] > i + 1)) a->first[c] = (uint32_t)i + 1;
                        if (again) a->missed[c]++;   /* none could be made: root_tile's count */
                        tm->g = again ? 255 : 254;
                        break;
                    }
                    if (child == OM__ASM_NONE && (child = root_tile(m, &tl, c)) == OM__ASM_NONE) break;
                    add_benefit(t, a, child);
                } else {
                    want = smp_finer(m, &o, level) && straddles(m, &o, &tl, tx, ty);
                    if (child != OM__ASM_NONE && want) add_benefit(t, a, child);
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
                    uint32_t *ben = a ? a->ben + (size_t)index * c2 : tl.ben;
                    float *need = a ? a->need + (size_t)index * c2 : tl.need;
                    ben[c]++;
                    if (nreq > need[c]) need[c] = nreq;
                    if (a) {
                        acc_node(a, index);
                        a->hdr[1]++;
                    } else {
                        m->straddling++;
                    }
                }
                break;
            }
        }
    }
}

static om_status asm_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)d;
    om__asm_state *m = (om__asm_state *)state;
    om__asm_prepare(m);
#if OM_WITH_JOBS
    if (m->lend && om__asm_observe_jobs(m, st)) return OM_OK;   /* the same, by bands */
#endif
    observe_rows(m, st, 0, st->rows, NULL, false);
    return OM_OK;
}

#if OM_WITH_JOBS
/* The bands' walk (asm_jobs.c runs them): with accumulators it writes nothing of the
 * state, so the bands may share it. */
void om__asm_observe_rows(const om__asm_state *m, const om_strip *st, uint32_t y0, uint32_t rows,
                          const om__asm_acc *a, bool again)
{
    observe_rows((om__asm_state *)m, st, y0, rows, a, again);
}
#endif

static om_status asm_build(void *state, om_diag *d)
{
    (void)d;
    om__asm_state *m = (om__asm_state *)state;
    om__asm_tree *t = &m->tree;
    om__asm_prepare(m);
    /* With the host's threads the new tiles are rendered after the tree is made, each
     * by a job: which nodes are made reads no tile. */
#if OM_WITH_JOBS
    const uint32_t serial0 = t->serial;
    const bool later = m->lend != NULL;
#else
    const bool later = false;
#endif
    /* Root tiles first, wherever samples fell, most samples first: the root level is
     * what a conventional map at asm.root would give, and every refinement hangs off it. */
    uint32_t n = om__asm_candidates(t, true, 0.0f, 0.0f, m->cand, m->ncand_max);
    while (n > 0) {
        om__asm_cand c;
        n = om__asm_cand_pop(m->cand, n, &c);
        uint32_t k = om__asm_make(t, OM__ASM_ROOT, c.cell, c.benefit);
        if (k == OM__ASM_NONE) break;   /* no room: the rest have fewer samples still */
        if (!later) om__asm_render_node(m, k);
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
        if (!later) om__asm_render_node(m, k);
        spent += (double)c.cost;
    }
#if OM_WITH_JOBS
    if (later) {   /* the nodes made here and still in the tree (gen: made after serial0) */
        uint32_t *list = (uint32_t *)(void *)m->cand, nl = 0;   /* the heap is done with */
        for (uint32_t i = 0; i < t->lay.count; i++) {
            const om__asm_node *nd = om__asm_node_at(t, i);
            if (nd->alive && nd->gen > serial0) list[nl++] = i;
        }
        (void)om__asm_render_list(m, list, nl);
    }
#endif
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
static void smp_find(const om__asm_state *m, asm_smp *o, asm_cache *c, om__asm_tile *tl, uint32_t *tx,
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
static int resolve_one(const om__asm_state *m, const om_sample *s, asm_cache *c, bool *moved)
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
    om__asm_state *m = (om__asm_state *)state;
    size_t n = (size_t)st->rows * st->width;
    om__asm_prepare(m);
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


/* By bands on the host's threads (method.h, om__bands): each band looks up its own
 * samples with a cache of its own and writes nothing of the state. The use stamps are
 * the one thing a lookup leaves in the tree: a band marks each sample whose lookup
 * descended with the leaf it found (1 + its index, 0xFFFF the base, in its term's green
 * and blue, each xor its red), and finish puts the terms back and stamps the paths of
 * the leaves they name (the scan by parts on the host's threads, asm_jobs.c). A tree
 * of 0xFFFF nodes or more has no room there: its samples are marked by blue one off
 * red, and finish finds their leaves again. The stamped nodes are the paths to every
 * leaf found, whatever the bands: the stamps, the terms and the counts (added up by
 * merge) are a strip at a time's. */
static void asm_band(const void *state, om_strip *st, void *scratch, uint32_t counts[8])
{
    const om__asm_state *m = (const om__asm_state *)state;
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
        if (moved && m->tree.lay.count < 0xFFFFu) {
            const uint32_t v = c->index == OM__ASM_ROOT ? 0xFFFFu : c->index + 1;
            t->g = (uint8_t)(t->r ^ (v >> 8));
            t->b = (uint8_t)(t->r ^ (v & 255u));
        } else if (moved) {
            t->b ^= 1u;
        }
    }
}

static void asm_merge(void *state, const uint32_t counts[8])
{
    om__asm_state *m = (om__asm_state *)state;
    m->samples += counts[0];
    m->shadowed += counts[1];
}

/* finish's scan of terms [i0, i1) of the strip: each marked term put back, and the leaf
 * its lookup found stamped with its path (`bits` NULL) or its bit set in `bits` (a bit a
 * node, bit `count` the base's: the tree is only read then, and asm_jobs.c stamps the
 * paths of the bits the parts set). */
static void leaves(om__asm_state *m, om_strip *st, size_t i0, size_t i1, uint32_t *bits)
{
    const uint32_t count = m->tree.lay.count;
    const bool direct = count < 0xFFFFu;
    for (size_t i = i0; i < i1; i++) {
        om_term *t = &st->terms[i];
        if (t->b == t->r && t->g == t->r) continue;
        uint32_t leaf;
        if (direct) {
            const uint32_t v = (uint32_t)(t->g ^ t->r) << 8 | (uint32_t)(t->b ^ t->r);
            t->g = t->b = t->r;
            leaf = v == 0xFFFFu ? OM__ASM_ROOT : v - 1;
        } else {
            t->b = t->r;
            asm_smp o;
            asm_cache c = {OM__ASM_NONE, m->cache_tile};
            om__asm_tile tl;
            uint32_t tx, ty;
            bool moved = false;
            if (!smp_begin(m, &st->samples[i], false, &o)) continue;   /* (it was looked up) */
            smp_find(m, &o, &c, &tl, &tx, &ty, &moved);
            leaf = c.index;
        }
        if (!bits) {
            stamp_path(&m->tree, leaf);
            continue;
        }
        const uint32_t bit = leaf == OM__ASM_ROOT ? count : leaf;
        bits[bit >> 5] |= 1u << (bit & 31);
    }
}

static void asm_finish(void *state, om_strip *st)
{
    om__asm_state *m = (om__asm_state *)state;
#if OM_WITH_JOBS
    if (m->lend && om__asm_finish_jobs(m, st)) return;   /* the same, by parts */
#endif
    leaves(m, st, 0, (size_t)st->rows * st->width, NULL);
}

#if OM_WITH_JOBS
/* A part of finish's scan on the host's threads (asm_jobs.c): with `bits` it writes
 * nothing of the state. */
void om__asm_leaves(const om__asm_state *m, om_strip *st, size_t i0, size_t i1, uint32_t *bits)
{
    leaves((om__asm_state *)m, st, i0, i1, bits);
}

void om__asm_stamp_leaves(om__asm_tree *t, uint32_t *bits)
{
    const uint32_t count = t->lay.count;
    for (uint32_t w = 0; w < (count + 1 + 31) / 32; w++) {
        for (uint32_t b = bits[w]; b; b &= b - 1) {
            const uint32_t i = w * 32 + om__ctz32(b);
            stamp_path(t, i == count ? OM__ASM_ROOT : i);
        }
        bits[w] = 0;
    }
}
#endif

const om__bands om__bands_asm = {asm_band, asm_merge, sizeof(asm_cache), NULL, NULL, asm_finish};

const om__asm_tree *om__asm_tree_of(const void *state) { return &((const om__asm_state *)state)->tree; }

static void asm_stats(const void *state, om_method_stats *out)
{
    const om__asm_state *m = (const om__asm_state *)state;
    const om__asm_tree *t = &m->tree;
    memset(out, 0, sizeof *out);
    out->bytes_used = asm_need(m->scene, &t->lay, m->lean);
    if (m->chunk)
        out->bytes_used += om_arena_need(((size_t)m->scene->ntris + m->chunk_tris - 1) / m->chunk_tris * 4 * sizeof(float), 8);
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
    out->counters[8] = m->redrawn;
    out->counter_names[8] = "tiles redrawn: objects moved";
    out->ncounters = 9;
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

extern const om__pass om__pass_asm;
const om_method om__method_asm = {
    "asm", "adaptive shadow map: a tree of tiles refined where the eye needs it, within asm.cap",
    OM_METHOD_OBSERVES,
    asm_bytes, asm_init, asm_begin, asm_observe, asm_build, asm_resolve, asm_stats, NULL,
    settings, sizeof settings / sizeof settings[0], sizeof(om__asm_cfg),
    OM__JOBS_ONLY(&om__bands_asm), OM__JOBS_ONLY(&om__pass_asm),
};
