/* ref.c — the reference: for every exposed sample, walk a BVH along the segment to the
 * light (for a directional light, the ray towards it) and apply the occlusion
 * predicate of occlude.h to each triangle met. Opaque casters end the walk; semi-
 * transparent ones add their optical depth. This defines "correct" for every metric.
 *
 * The BVH's boxes are grown by the light grid's snapping tolerance so the walk never
 * skips a triangle the predicate would accept: the walk is only a filter, the
 * predicate decides. With the memory for it, the walk runs on the light's grid instead
 * (ref_light.h), over packets of neighbouring samples: the same filter's answer for
 * the triangles that matter, in fewer steps. */
#include "../method.h"
#include "../common/occlude.h"
#include "bvh.h"
#include "ref_light.h"

typedef struct ref_state {
    om__state_head head;   /* first (method.h) */
    const om_scene *scene;
    om__lspace ls;
    om__bvh bvh;
    om__lbvh lb;           /* one-pass memory: the BVH on the light's grid, per frame */
    struct packet *pk;     /* one-pass memory: the tile being resolved */
    om__odepth *mat_od;
    om_view view;
    float margin;
    int mode;              /* LEAST, CACHE or PACKETS */
    const om__lend *lend;  /* the frame's threads for the fit (om__pass.lend), or NULL */
    uint32_t samples, candidates, blocked;
    uint32_t rebuilt;      /* object subtrees built again this frame */
} ref_state;

/* Three sizes, the same bits; only the speed differs:
 * PACKETS (one pass) the per-frame vertex projection, a BVH with leaves of 4 and its
 *         per-frame bounds on the light's grid, walked by packets: the fastest where
 *         a frame has many samples a packet can share;
 * CACHE   the vertex projection and leaves of 4, the BVH's own nodes re-bounded on the
 *         light's grid every frame in place of their 3-D boxes, walked per sample:
 *         about half the bytes, for a 256 KiB machine;
 * LEAST   no projection cache, leaves of 32: a fraction of the nodes, for the smallest
 *         machines, walked along the segment in 3-D. */
enum { LEAST, CACHE, PACKETS };
#define LEAF_FAST 4
#define LEAF_SMALL 32

/* Packets (one pass): a TILE x TILE block of the strip's samples on the light's grid,
 * and per level of blocks inside it (TILE, TILE / 2, ... 1) the list of BVH nodes the
 * block can need. A block whose list cannot be opened down to leaves within LIST
 * entries (samples on different surfaces, far apart on the light's grid) passes it on
 * to its four quarters; a single sample walks under what is left. */
#define TILE 16
#define LEVELS 5     /* block sides 16, 8, 4, 2, 1 */
#define LIST 16

typedef struct packet {
    om__lpoint p[TILE * TILE];  /* row-major in the tile */
    uint8_t on[TILE * TILE];    /* 1: an exposed sample in front of the light */
    uint32_t list[LEVELS][LIST];
} packet;

static size_t state_bytes(const om_scene *s, int mode)
{
    return om_arena_need(sizeof(ref_state), 16) + (mode != LEAST ? om__lspace_bytes(s) : 0) +
           (mode == PACKETS ? om__lbvh_bytes(s, LEAF_FAST) + om_arena_need(sizeof(packet), 16) : 0) +
           om__bvh_bytes(s, mode != LEAST ? LEAF_FAST : LEAF_SMALL) +
           om_arena_need((size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4);
}

static om_status ref_bytes(const om_method_cfg *c, const om_scene *s, uint32_t w, uint32_t h,
                           size_t *min, size_t *full)
{
    (void)c; (void)w; (void)h;
    *min = state_bytes(s, LEAST);   /* the build then finds boxes from the vertices */
    *full = state_bytes(s, PACKETS) + om__bvh_scratch_bytes(s);
    return OM_OK;
}

static om_status ref_init(void **state, om_arena *a, const om_method_cfg *c, const om_scene *s,
                          uint32_t w, uint32_t h, om_diag *d)
{
    (void)c; (void)w; (void)h;
    om_status st;
    void *p;
    if ((st = om__need(a, state_bytes(s, LEAST), "ref", d))) return st;
    const size_t left = om_arena_left(a), scratch = om__bvh_scratch_bytes(s);
    const int mode = left >= state_bytes(s, PACKETS) + scratch ? PACKETS
                     : left >= state_bytes(s, CACHE) + scratch ? CACHE : LEAST;
    const bool fast = mode != LEAST;
    if ((st = om_arena_alloc(a, sizeof(ref_state), 16, &p, d))) return st;
    ref_state *r = (ref_state *)p;
    r->scene = s;
    r->mode = mode;
    if (fast && (st = om__lspace_init(&r->ls, a, s, d))) return st;
    if (!fast) om__lspace_init_lean(&r->ls, s);
    r->pk = NULL;
    r->lend = NULL;
    if (mode == PACKETS) {
        if ((st = om__lbvh_init(&r->lb, a, s, LEAF_FAST, d))) return st;
        if ((st = om_arena_alloc(a, sizeof(packet), 16, &p, d))) return st;
        r->pk = (packet *)p;
    }
    if ((st = om_arena_alloc(a, (size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4, &p, d)))
        return st;
    r->mat_od = (om__odepth *)p;
    for (uint32_t i = 0; i < s->nmats; i++) r->mat_od[i] = om__material_odepth(&s->mats[i]);
    if ((st = om__bvh_build(&r->bvh, a, s, fast ? LEAF_FAST : LEAF_SMALL, d))) return st;
    if (mode == PACKETS) om__lbvh_plan(&r->lb, &r->bvh, s->nobjects);
    r->rebuilt = 0;
    *state = r;
    return OM_OK;
}

/* begin but for the projection of the scene's vertices (in the modes that keep it):
 * returns how many there are, which the frame's jobs project in ranges where it has
 * threads (ref_pass_setup) and ref_begin projects here otherwise. */
static uint32_t begin_view(ref_state *r, const om_view *v)
{
    r->view = *v;
    om__lspace_view(&r->ls, v);
    /* Moved objects: their subtrees and the top level over the objects are built
     * again where they are (the static subtree and the still objects' stay), so the BVH
     * is the one a new state would build; the one pass's parts stay (bvh.h: each
     * object's nodes keep their region). */
    om__bvh_rebuild_objects(&r->bvh, r->scene);
    r->rebuilt = r->bvh.rebuilt;
    /* Two grid steps at the far end of the light's frustum, in world units: how far
     * snapping can move a triangle's edge or a sample across the light's image. */
    om_vec3 ext = om__sub(r->scene->hi, r->scene->lo);
    float span;
    if (v->light.kind == OM_LIGHT_SPOT)
        span = 2.0f * v->light.zfar * (float)om__tan((double)v->light.fov_deg * OM_PI / 360.0);
    else
        span = 2.0f / fminf(fabsf(v->light_proj.m[0]), fabsf(v->light_proj.m[5]));
    /* and the rounding of a sample's world position (shade_sample: the BVH's boxes are
     * in world units), a few units in the last place of the scene's largest coordinate */
    const float big = fmaxf(fmaxf(fmaxf(fabsf(r->scene->lo.x), fabsf(r->scene->hi.x)),
                                  fmaxf(fabsf(r->scene->lo.y), fabsf(r->scene->hi.y))),
                            fmaxf(fabsf(r->scene->lo.z), fabsf(r->scene->hi.z)));
    r->margin = 4.0f * span / (float)(OM_LIGHT_GRID * OM_SUBPIX) +
                1e-6f * (fabsf(ext.x) + fabsf(ext.y) + fabsf(ext.z) + big);
    r->samples = r->candidates = r->blocked = 0;
    return r->ls.verts ? r->scene->nverts : 0;
}

static om_status ref_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    ref_state *r = (ref_state *)state;
    om__lspace_project(&r->ls, 0, begin_view(r, v));
    return OM_OK;
}

static om_status ref_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)state; (void)st; (void)d;
    return OM_OK;
}

/* One part of the one-pass fit (ref_light.h), a job of the frame's threads. */
static void fit_job(void *user, uint32_t k, void *scratch)
{
    (void)scratch;
    ref_state *r = (ref_state *)user;
    om__lbvh_fit_part(&r->lb, &r->bvh, &r->ls, k);
}

/* The BVH's boxes on this frame's light grid (a stage of its own, so the frame's clock
 * counts it): one pass into their own arrays, the middle mode into the nodes. With the
 * frame's threads the one pass's parts are their jobs, and the few nodes above them
 * are fitted here after (the fit reads every triangle's projected vertices, which on
 * the calling thread alone would hold the others up in a large scene). */
static om_status ref_build(void *state, om_diag *d)
{
    (void)d;
    ref_state *r = (ref_state *)state;
    if (r->mode == PACKETS && r->lend && r->lend->slots > 1 && r->lb.nparts > 1) {
        r->lend->run(r->lend, fit_job, r, r->lb.nparts);
        om__lbvh_fit_top(&r->lb, &r->bvh, &r->ls);
    } else if (r->mode == PACKETS) {
        om__lbvh_fit(&r->lb, &r->bvh, &r->ls);
    }
    if (r->mode == CACHE) om__bvh_fit_grid(&r->bvh, &r->ls);
    return OM_OK;
}

/* What one resolve changes: its counts and (one pass) its packet. The state is only
 * read while the frame resolves, so jobs on several bands share it (om__bands). */
typedef struct ref_job {
    const ref_state *r;
    packet *pk;
    uint32_t samples, candidates, blocked;
    /* The last partial transmittance turned into a term: the samples a semi-
     * transparent caster shades in a row have the same optical depth, and each
     * channel's term is a power of two in double (om__odepth_term). */
    om__odepth last_od;
    om_term last_term;
    om__facet facet;       /* the last sample's facet (om__lspace_pull) */
} ref_job;

typedef struct walk_ctx {
    const ref_state *r;
    ref_job *j;
    om__lpoint p;
    uint32_t z;            /* p.z, the whole number it is */
    om__odepth od;
    bool pulled;           /* p's depth pulled (om__lspace_pull): where a triangle first
                              blocks it unpulled */
} walk_ctx;

/* Whether triangle t's edges hold p, where that settles it: a triangle whose three
 * vertices the frame projected is one sub-triangle of om__lspace_tri, and om__blocks
 * asks its edges before its depth. Most triangles that reach here pass the grid-box
 * test without covering the point; they are refused without the depth plane and the
 * snapping bound, double arithmetic that a chip without a double FPU runs in software
 * (on the Cortex-M4 they were most of ref's frame). */
/* Within 2^30 of the origin: the grid and its guard band are, far inside it. */
static int near_grid(int64_t v)
{
    return (uint64_t)(v + ((int64_t)1 << 30)) < ((uint64_t)1 << 31);
}

static bool covers(const om__lspace *ls, uint32_t t, const om__lpoint *p)
{
    if (!ls->verts) return true;
    const uint32_t *ix = ls->scene->idx + (size_t)t * 3;
    const om__lvert *a = &ls->verts[ix[0]], *b = &ls->verts[ix[1]], *c = &ls->verts[ix[2]];
    if (a->x == INT32_MIN || b->x == INT32_MIN || c->x == INT32_MIN) return true;
    const int64_t x[3] = {a->x, b->x, c->x}, y[3] = {a->y, b->y, c->y};
    if (near_grid(p->x) && near_grid(p->y) && near_grid(x[0]) && near_grid(x[1]) && near_grid(x[2]) &&
        near_grid(y[0]) && near_grid(y[1]) && near_grid(y[2])) {
        /* Strictly outside one edge and strictly inside another: outside the closed
         * triangle whichever its winding, so no tie rule covers p. This settles most
         * triangles met for a fraction of the setup (the products stay below 2^62). */
        int neg = 0, pos = 0;
        for (int i = 0; i < 3; i++) {
            const int j = i == 2 ? 0 : i + 1;
            const int64_t e = (x[j] - x[i]) * (p->y - y[i]) - (y[j] - y[i]) * (p->x - x[i]);
            neg |= e < 0;
            pos |= e > 0;
        }
        if (neg & pos) return false;
    }
    om__tri2 e;
    return om__tri2_setup(&e, x, y, true) && om__tri2_covers(&e, p->x, p->y);
}

/* A triangle a walk met (the walks on the grid have passed over those whose grid box
 * misses p or whose vertices are all farther; ref_light.h). Where double arithmetic
 * is a library routine, single precision answers first (om__blocks_f: the same
 * answer, or none). */
/* Whether triangle tri blocks w's point: 1 yes, 0 no; lt set up where the double
 * predicate was asked (*set), for asking it again. */
static bool blocks(const walk_ctx *w, uint32_t tri, om__ltri *lt, bool *set)
{
    const int f = OM_FAST_FLOAT ? om__blocks_f(&w->r->ls, tri, &w->p, w->z) : -1;
    if (f >= 0) return f == 1;
    *set = tri != w->p.tri && covers(&w->r->ls, tri, &w->p) && om__lspace_tri(&w->r->ls, tri, lt);
    return *set && om__blocks(lt, &w->p);
}

static bool visit(void *user, uint32_t tri)
{
    walk_ctx *w = (walk_ctx *)user;
    om__ltri lt;
    bool set = false;
    w->j->candidates++;
    if (!blocks(w, tri, &lt, &set)) return false;
    if (!w->pulled) {   /* the first blocker of the unpulled depth: pull it, ask again */
        w->pulled = true;
        w->z = om__lspace_pull(&w->r->ls, &w->j->facet, w->p.tri, w->z);
        w->p.z = w->z;
        if (set ? !om__blocks(&lt, &w->p) : !blocks(w, tri, &lt, &set)) return false;
    }
    om__odepth_add(&w->od, &w->r->mat_od[w->r->scene->tri_mat[tri]]);
    return om__odepth_opaque(&w->od);
}

static void finish(const walk_ctx *w, om_term *t)
{
    ref_job *j = w->j;
    if (w->od.c[0] != j->last_od.c[0] || w->od.c[1] != j->last_od.c[1] || w->od.c[2] != j->last_od.c[2]) {
        om__odepth_term(&w->od, &j->last_term);
        j->last_od = w->od;
    }
    t->r = j->last_term.r;
    t->g = j->last_term.g;
    t->b = j->last_term.b;
    if (t->r != 255 || t->g != 255 || t->b != 255) j->blocked++;
}

/* The shadow term of one sample against every triangle (the walk is a filter): the
 * middle mode's way, on the light's grid, or the least memory's, along the segment in
 * 3-D. */
static void shade_sample(ref_job *j, const om_sample *smp, om_term *t)
{
    const ref_state *r = j->r;
    walk_ctx w;
    w.r = r;
    w.j = j;
    memset(&w.od, 0, sizeof w.od);
    w.pulled = false;
    if (!om__lspace_point_at(&r->ls, smp, &w.p, &w.z)) return;
    if (r->mode == CACHE) {
        om__bvh_walk_grid(&r->bvh, &r->ls, &w.p, w.z, visit, &w);
        finish(&w, t);
        return;
    }
    /* the BVH is in world units: the segment too (begin_view's margin covers the
     * rounding of the sum) */
    om_vec3 p = om__add(om__v3(smp->p[0], smp->p[1], smp->p[2]), r->view.origin), dir;
    float tmax;
    if (r->view.light.kind == OM_LIGHT_SPOT) {
        dir = om__sub(om__add(r->view.light.pos, r->view.origin), p);
        tmax = 1.0f;
    } else {
        om_vec3 ext = om__sub(r->scene->hi, r->scene->lo);
        dir = om__scale(r->view.light_axis, -1.0f);
        tmax = 2.0f * (fabsf(ext.x) + fabsf(ext.y) + fabsf(ext.z)) + 1.0f;
    }
    om__bvh_walk(&r->bvh, p, dir, tmax, r->margin, visit, &w);
    finish(&w, t);
}

/* One pass: the samples of the block of side `size` at (bx, by) in the tile at (x0, y0),
 * with the nodes its enclosing block listed (ref_light.h). It recurses at most LEVELS
 * deep. */
static void shade_block(ref_job *j, om_strip *st, uint32_t x0, uint32_t y0, uint32_t bx,
                        uint32_t by, uint32_t size, const uint32_t *in, uint32_t nin, int level)
{
    const ref_state *r = j->r;
    packet *pk = j->pk;
    om__lrect q = {INT64_MAX, INT64_MAX, INT64_MIN, INT64_MIN, 0.0};
    bool any = false;
    for (uint32_t y = by; y < by + size; y++)
        for (uint32_t x = bx; x < bx + size; x++) {
            const om__lpoint *p = &pk->p[y * TILE + x];
            if (!pk->on[y * TILE + x]) continue;
            any = true;
            if (p->x < q.lox) q.lox = p->x;
            if (p->x > q.hix) q.hix = p->x;
            if (p->y < q.loy) q.loy = p->y;
            if (p->y > q.hiy) q.hiy = p->y;
            if (p->z > q.zmax) q.zmax = p->z;
        }
    if (!any) return;
    bool open;
    uint32_t *list = pk->list[level];
    uint32_t n = om__lbvh_narrow(&r->lb, in, nin, &q, list, LIST, &open);
    if (open && size > 1) {
        uint32_t h = size / 2;
        shade_block(j, st, x0, y0, bx, by, h, list, n, level + 1);
        shade_block(j, st, x0, y0, bx + h, by, h, list, n, level + 1);
        shade_block(j, st, x0, y0, bx, by + h, h, list, n, level + 1);
        shade_block(j, st, x0, y0, bx + h, by + h, h, list, n, level + 1);
        return;
    }
    for (uint32_t y = by; y < by + size; y++)
        for (uint32_t x = bx; x < bx + size; x++) {
            if (!pk->on[y * TILE + x]) continue;
            walk_ctx w;
            w.r = r;
            w.j = j;
            w.p = pk->p[y * TILE + x];
            w.z = (uint32_t)w.p.z;   /* a whole number below 2^32 (om__lspace_point_at) */
            w.pulled = false;
            memset(&w.od, 0, sizeof w.od);
            om__lbvh_walk_list(&r->lb, &r->bvh, list, n, &w.p, visit, &w);
            finish(&w, &st->terms[(size_t)(y0 + y) * st->width + x0 + x]);
        }
}

/* Projects the tile's exposed samples, then shades it as one block. */
static void shade_tile(ref_job *j, om_strip *st, uint32_t x0, uint32_t y0)
{
    const ref_state *r = j->r;
    packet *pk = j->pk;
    for (uint32_t y = 0; y < TILE; y++)
        for (uint32_t x = 0; x < TILE; x++) {
            pk->on[y * TILE + x] = 0;
            if (y0 + y >= st->rows || x0 + x >= st->width) continue;
            size_t i = (size_t)(y0 + y) * st->width + x0 + x;
            om_term *t = &st->terms[i];
            t->r = t->g = t->b = 255;
            if (!(t->flags & OM_TERM_EXPOSED)) continue;
            j->samples++;
            uint32_t z;
            pk->on[y * TILE + x] = om__lspace_point_at(&r->ls, &st->samples[i], &pk->p[y * TILE + x], &z);
        }
    const uint32_t root = 0;
    shade_block(j, st, x0, y0, 0, 0, TILE, &root, r->bvh.nnodes ? 1 : 0, 0);
}

static void job_init(ref_job *j, const ref_state *r, packet *pk)
{
    memset(j, 0, sizeof *j);
    j->r = r;
    j->pk = pk;
    j->last_term.r = j->last_term.g = j->last_term.b = 255;   /* the term of depth 0 */
    j->facet.tri = OM_NO_TRI;
    j->facet.slope = 0.0f;
}

static void resolve_job(ref_job *j, om_strip *st)
{
    if (j->pk) {
        for (uint32_t y = 0; y < st->rows; y += TILE)
            for (uint32_t x = 0; x < st->width; x += TILE) shade_tile(j, st, x, y);
        return;
    }
    size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        j->samples++;
        shade_sample(j, &st->samples[i], t);
    }
}

static void ref_merge(void *state, const uint32_t counts[8])
{
    ref_state *r = (ref_state *)state;
    r->samples += counts[0];
    r->candidates += counts[1];
    r->blocked += counts[2];
}

static om_status ref_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    ref_state *r = (ref_state *)state;
    ref_job j;
    job_init(&j, r, r->pk);
    resolve_job(&j, st);
    const uint32_t counts[8] = {j.samples, j.candidates, j.blocked, 0, 0, 0, 0, 0};
    ref_merge(r, counts);
    return OM_OK;
}

/* Bands: each job walks with its own packet (the frame's scratch) and counts. */
static void ref_band(const void *state, om_strip *st, void *scratch, uint32_t counts[8])
{
    const ref_state *r = (const ref_state *)state;
    ref_job j;
    job_init(&j, r, r->pk ? (packet *)scratch : NULL);
    resolve_job(&j, st);
    counts[0] += j.samples;
    counts[1] += j.candidates;
    counts[2] += j.blocked;
}

const om__bands om__bands_ref = {ref_band, ref_merge, sizeof(packet), NULL, NULL, NULL};

/* A pass of no jobs of its own (the bands resolve), for its begin and its threads: the
 * projection of the scene's vertices (on the calling thread, a sizeable share of a
 * large scene's frame) runs as the frame's jobs in ranges, before the build, and the
 * build's fit by the parts lend's slots take (ref_build). The same vertices and
 * boxes however cut. */
static size_t ref_pass_scratch(const void *state, const om_scene *s)
{
    (void)state; (void)s;
    return 0;
}

static uint32_t ref_pass_plan(void *state, om_strip *st)
{
    (void)state; (void)st;
    return 0;
}

static void ref_pass_job(const void *state, const om_strip *st, uint32_t k, void *scratch, uint32_t counts[8])
{
    (void)state; (void)st; (void)k; (void)scratch; (void)counts;
}

static void ref_pass_merge(void *state, const uint32_t counts[8])
{
    (void)state; (void)counts;
}

static om_status ref_pass_begin(void *state, const om_view *v, uint32_t *items, om_diag *d)
{
    (void)d;
    *items = begin_view((ref_state *)state, v);
    return OM_OK;
}

static void ref_pass_setup(const void *state, uint32_t first, uint32_t end)
{
    om__lspace_project(&((const ref_state *)state)->ls, first, end);
}

static void ref_pass_lend(void *state, const om__lend *l)
{
    ((ref_state *)state)->lend = l;
}

const om__pass om__pass_ref = {ref_pass_scratch, ref_pass_plan, ref_pass_job, ref_pass_merge,
                               ref_pass_begin, ref_pass_setup, ref_pass_lend};

static void ref_stats(const void *state, om_method_stats *out)
{
    const ref_state *r = (const ref_state *)state;
    memset(out, 0, sizeof *out);
    out->bytes_used = state_bytes(r->scene, r->mode);
    out->counters[0] = r->samples;
    out->counter_names[0] = "samples";
    out->counters[1] = r->candidates;
    out->counter_names[1] = "triangles tested";
    out->counters[2] = r->blocked;
    out->counter_names[2] = "samples blocked";
    out->counters[3] = r->bvh.nnodes;
    out->counter_names[3] = "bvh nodes";
    out->counters[4] = r->rebuilt;
    out->counter_names[4] = "objects rebuilt";
    out->ncounters = 5;
}

const om_method om__method_ref = {
    "ref", "exact reference: shadow segments through a BVH, the shared occlusion predicate",
    OM_METHOD_EXACT, ref_bytes, ref_init, ref_begin, ref_observe, ref_build, ref_resolve,
    ref_stats, NULL, NULL, 0, 0,
    OM__JOBS_ONLY(&om__bands_ref), OM__JOBS_ONLY(&om__pass_ref),
};
