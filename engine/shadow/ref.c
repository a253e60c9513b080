/* ref.c — the reference: for every exposed sample, walk a BVH along the segment to the
 * light (for a directional light, the ray towards it) and apply the occlusion
 * predicate of occlude.h to each triangle met. Opaque casters end the walk; semi-
 * transparent ones add their optical depth. This defines "correct" for every metric.
 *
 * The BVH's boxes are grown by the light grid's snapping tolerance so the walk never
 * skips a triangle the predicate would accept: the walk is only a filter, the
 * predicate decides. */
#include "shadow.h"
#include "occlude.h"
#include "bvh.h"

typedef struct ref_state {
    const om_scene *scene;
    om__lspace ls;
    om__bvh bvh;
    om__odepth *mat_od;
    om_view view;
    float margin;
    bool fast;             /* one-pass memory: vertex projection cache, small leaves */
    uint32_t samples, candidates, blocked;
} ref_state;

/* Two sizes: one pass (the per-frame vertex projection and a BVH with leaves of 4, the
 * fastest) and the least (no projection cache, leaves of 32: a fraction of the nodes,
 * for small machines). Both give the same bits; only the speed differs. */
#define LEAF_FAST 4
#define LEAF_SMALL 32

static size_t state_bytes(const om_scene *s, bool fast)
{
    return om_arena_need(sizeof(ref_state), 16) + (fast ? om__lspace_bytes(s) : 0) +
           om__bvh_bytes(s, fast ? LEAF_FAST : LEAF_SMALL) +
           om_arena_need((size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4);
}

static om_status ref_bytes(const om_method_cfg *c, const om_scene *s, uint32_t w, uint32_t h,
                           size_t *min, size_t *full)
{
    (void)c; (void)w; (void)h;
    *min = state_bytes(s, false);   /* the build then finds boxes from the vertices */
    *full = state_bytes(s, true) + om__bvh_scratch_bytes(s);
    return OM_OK;
}

static om_status ref_init(void **state, om_arena *a, const om_method_cfg *c, const om_scene *s,
                          uint32_t w, uint32_t h, om_diag *d)
{
    (void)c; (void)w; (void)h;
    om_status st;
    void *p;
    if ((st = om__need(a, state_bytes(s, false), "ref", d))) return st;
    bool fast = om_arena_left(a) >= state_bytes(s, true) + om__bvh_scratch_bytes(s);
    if ((st = om_arena_alloc(a, sizeof(ref_state), 16, &p, d))) return st;
    ref_state *r = (ref_state *)p;
    r->scene = s;
    r->fast = fast;
    if (fast && (st = om__lspace_init(&r->ls, a, s, d))) return st;
    if (!fast) om__lspace_init_lean(&r->ls, s);
    if ((st = om_arena_alloc(a, (size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4, &p, d)))
        return st;
    r->mat_od = (om__odepth *)p;
    for (uint32_t i = 0; i < s->nmats; i++) r->mat_od[i] = om__material_odepth(&s->mats[i]);
    if ((st = om__bvh_build(&r->bvh, a, s, fast ? LEAF_FAST : LEAF_SMALL, d))) return st;
    *state = r;
    return OM_OK;
}

static om_status ref_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    ref_state *r = (ref_state *)state;
    r->view = *v;
    om__lspace_begin(&r->ls, v);
    /* Two grid steps at the far end of the light's frustum, in world units: how far
     * snapping can move a triangle's edge or a sample across the light's image. */
    om_vec3 ext = om__sub(r->scene->hi, r->scene->lo);
    float span;
    if (v->light.kind == OM_LIGHT_SPOT)
        span = 2.0f * v->light.zfar * (float)om__tan((double)v->light.fov_deg * OM_PI / 360.0);
    else
        span = 2.0f / fminf(fabsf(v->light_proj.m[0]), fabsf(v->light_proj.m[5]));
    r->margin = 4.0f * span / (float)(OM_LIGHT_GRID * OM_SUBPIX) +
                1e-6f * (fabsf(ext.x) + fabsf(ext.y) + fabsf(ext.z));
    r->samples = r->candidates = r->blocked = 0;
    return OM_OK;
}

static om_status ref_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)state; (void)st; (void)d;
    return OM_OK;
}

static om_status ref_build(void *state, om_diag *d)
{
    (void)state; (void)d;
    return OM_OK;
}

typedef struct walk_ctx {
    ref_state *r;
    om__lpoint p;
    om__odepth od;
} walk_ctx;

static bool visit(void *user, uint32_t tri)
{
    walk_ctx *w = (walk_ctx *)user;
    om__ltri lt;
    w->r->candidates++;
    if (tri == w->p.tri || !om__lspace_maybe(&w->r->ls, tri, &w->p) ||
        !om__lspace_tri(&w->r->ls, tri, &lt) || !om__blocks(&lt, &w->p))
        return false;
    om__odepth_add(&w->od, &w->r->mat_od[w->r->scene->tri_mat[tri]]);
    return om__odepth_opaque(&w->od);
}

/* The shadow term of one sample against every triangle (the walk is a filter). */
static void shade_sample(ref_state *r, const om_sample *smp, om_term *t)
{
    walk_ctx w;
    w.r = r;
    memset(&w.od, 0, sizeof w.od);
    if (!om__lspace_point(&r->ls, smp, &w.p)) return;
    om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]), dir;
    float tmax;
    if (r->view.light.kind == OM_LIGHT_SPOT) {
        dir = om__sub(r->view.light.pos, p);
        tmax = 1.0f;
    } else {
        om_vec3 ext = om__sub(r->scene->hi, r->scene->lo);
        dir = om__scale(r->view.light_axis, -1.0f);
        tmax = 2.0f * (fabsf(ext.x) + fabsf(ext.y) + fabsf(ext.z)) + 1.0f;
    }
    om__bvh_walk(&r->bvh, p, dir, tmax, r->margin, visit, &w);
    om__odepth_term(&w.od, t);
    if (t->r != 255 || t->g != 255 || t->b != 255) r->blocked++;
}

static om_status ref_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    ref_state *r = (ref_state *)state;
    size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        r->samples++;
        shade_sample(r, &st->samples[i], t);
    }
    return OM_OK;
}

static void ref_stats(const void *state, om_method_stats *out)
{
    const ref_state *r = (const ref_state *)state;
    memset(out, 0, sizeof *out);
    out->bytes_used = state_bytes(r->scene, r->fast);
    out->counters[0] = r->samples;
    out->counter_names[0] = "samples";
    out->counters[1] = r->candidates;
    out->counter_names[1] = "triangles tested";
    out->counters[2] = r->blocked;
    out->counter_names[2] = "samples blocked";
    out->counters[3] = r->bvh.nnodes;
    out->counter_names[3] = "bvh nodes";
    out->ncounters = 4;
}

const om_method om__method_ref = {
    "ref", "exact reference: shadow segments through a BVH, the shared occlusion predicate",
    OM_METHOD_EXACT, ref_bytes, ref_init, ref_begin, ref_observe, ref_build, ref_resolve,
    ref_stats, NULL,
};
