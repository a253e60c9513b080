/* izb.c — the irregular z-buffer (Alias-Free Shadow Maps, Aila and Laine 2004).
 *
 * Section 3: every exposed visible sample is transformed to the light's image plane
 * without discretising it (the light grid of occlude.h, 2^21 steps across).
 * Section 5.1: the samples are organised in an axis-aligned 2-D BSP with alternating
 * x/y splits at the median (quickselect), leaves of at most izb.leaf samples; each
 * node keeps the bounds of its samples and their largest light depth.
 * Sections 3-5: every triangle is rasterized through the BSP: a node is entered only
 * when the triangle's footprint can touch its bounds (bounding boxes, then the exact
 * integer edge functions at the box's corners), when it still holds a sample not yet
 * opaquely shadowed, and when the triangle is nearer the light somewhere than the
 * node's farthest sample; in a leaf each sample gets the shared occlusion predicate.
 * Section 4: semi-transparent casters add their optical depth per sample.
 *
 * Bounded pools: samples and nodes live in pools carved once from the method's arena.
 * When a strip holds more exposed samples than the pool, it is processed in tiles of
 * consecutive samples, each with its own BSP — memory stays fixed whatever the image
 * size. The tie rule, depth test and transmittance are the reference's own, so the
 * result equals the reference exactly, whatever the tiling. */
#include "shadow.h"
#include "izb.h"

#include <float.h>

typedef struct izb_state {
    om__izb z;
    om_method_cfg cfg;
    uint32_t width, height;
} izb_state;

/* Least samples a split leaves in a leaf: a node splits only above `leaf` samples. */
static uint32_t min_leaf(uint32_t leaf) { return (leaf + 1) / 2 ? (leaf + 1) / 2 : 1; }

static uint32_t node_bound(uint32_t samples, uint32_t leaf)
{
    uint32_t leaves = samples / min_leaf(leaf);
    return 2 * (leaves ? leaves : 1) + 1;
}

/* The per-frame vertex projection is kept only when the arena has room for one pass
 * (it speeds up triangle setup, it changes no result). */
size_t om__izb_parts_bytes(const om_scene *s, bool cache)
{
    return (cache ? om__lspace_bytes(s) : 0) +
           om_arena_need((size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4);
}

size_t om__izb_pool_bytes(uint32_t samples, uint32_t leaf)
{
    return om_arena_need((size_t)samples * sizeof(om__izb_sample), 16) +
           om_arena_need((size_t)samples * sizeof(om__izb_key), 16) +
           om_arena_need((size_t)node_bound(samples, leaf) * sizeof(om__izb_node), 16);
}

static size_t fixed_bytes(const om_scene *s, bool cache)
{
    return om_arena_need(sizeof(izb_state), 16) + om__izb_parts_bytes(s, cache);
}

static om_status izb_bytes(const om_method_cfg *c, const om_scene *s, uint32_t w, uint32_t h,
                           size_t *min, size_t *full)
{
    if (c->izb_leaf < 1) return OM_E_INVALID;
    uint32_t one_pass = w * h, smallest = w;   /* the smallest tile: one row */
    if (c->izb_pool) one_pass = smallest = c->izb_pool;
    *min = fixed_bytes(s, false) + om__izb_pool_bytes(smallest, c->izb_leaf);
    *full = fixed_bytes(s, true) + om__izb_pool_bytes(one_pass, c->izb_leaf);
    return OM_OK;
}

om_status om__izb_setup(om__izb *z, om_arena *a, const om_method_cfg *c, const om_scene *s,
                        uint32_t want, uint32_t least, om_diag *d)
{
    om_status st;
    void *p;
    z->scene = s;
    z->leaf = c->izb_leaf;
    if (c->izb_pool) want = least = c->izb_pool;
    if (om_arena_left(a) >= om__izb_parts_bytes(s, true) + om__izb_pool_bytes(want, z->leaf)) {
        if ((st = om__lspace_init(&z->ls, a, s, d))) return st;
    } else {
        om__lspace_init_lean(&z->ls, s);
    }
    if ((st = om_arena_alloc(a, (size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4, &p, d)))
        return st;
    z->mat_od = (om__odepth *)p;
    for (uint32_t i = 0; i < s->nmats; i++) z->mat_od[i] = om__material_odepth(&s->mats[i]);
    /* The pool: as configured, or as many samples as the arena holds, up to one pass. */
    uint32_t cap = least, hi = want;
    size_t left = om_arena_left(a);
    while (cap < hi) {   /* largest pool that fits */
        uint32_t mid = cap + (hi - cap + 1) / 2;
        if (om__izb_pool_bytes(mid, z->leaf) <= left) cap = mid;
        else hi = mid - 1;
    }
    z->cap = cap;
    z->node_cap = node_bound(cap, z->leaf);
    if ((st = om_arena_alloc(a, (size_t)cap * sizeof(om__izb_sample), 16, &p, d))) return st;
    z->samples = (om__izb_sample *)p;
    if ((st = om_arena_alloc(a, (size_t)cap * sizeof(om__izb_key), 16, &p, d))) return st;
    z->keys = (om__izb_key *)p;
    if ((st = om_arena_alloc(a, (size_t)z->node_cap * sizeof(om__izb_node), 16, &p, d))) return st;
    z->nodes = (om__izb_node *)p;
    return OM_OK;
}

static om_status izb_init(void **state, om_arena *a, const om_method_cfg *c, const om_scene *s,
                          uint32_t w, uint32_t h, om_diag *d)
{
    om_status st;
    void *p;
    size_t mn, full;
    if (c->izb_leaf < 1) return om__fail(d, OM_E_INVALID, "izb: leaf size must be at least 1");
    if ((st = izb_bytes(c, s, w, h, &mn, &full))) return st;
    if ((st = om__need(a, mn, "izb", d))) return st;
    if ((st = om_arena_alloc(a, sizeof(izb_state), 16, &p, d))) return st;
    izb_state *m = (izb_state *)p;
    m->cfg = *c;
    m->width = w;
    m->height = h;
    if ((st = om__izb_setup(&m->z, a, c, s, w * h, w, d))) return st;
    *state = m;
    return OM_OK;
}

static om_status izb_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    izb_state *m = (izb_state *)state;
    om__lspace_begin(&m->z.ls, v);
    memset(&m->z.st, 0, sizeof m->z.st);
    return OM_OK;
}

static om_status izb_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)state; (void)st; (void)d;
    return OM_OK;
}

static om_status izb_build(void *state, om_diag *d)
{
    (void)state; (void)d;
    return OM_OK;
}

/* ---- stage 1: transform */

uint32_t om__izb_transform(om__izb *z, const om_strip *st, size_t *next, size_t end,
                           om__izb_decide decide, void *user)
{
    size_t i = *next;
    uint32_t n = 0;
    for (; i < end && n < z->cap; i++) {
        if (!(st->terms[i].flags & OM_TERM_EXPOSED)) continue;
        om__izb_sample *s = &z->samples[n];
        if (!om__lspace_point(&z->ls, &st->samples[i], &s->p)) continue;   /* behind the light */
        if (decide && decide(user, &s->p, &st->terms[i])) continue;
        s->idx = (uint32_t)i;
        memset(&s->od, 0, sizeof s->od);
        n++;
    }
    *next = i;
    z->n = n;
    return n;
}

/* ---- stage 2: the 2-D BSP */

static int32_t key(const om__izb_key *k, int axis) { return axis ? k->y : k->x; }

static void swap(om__izb_key *a, om__izb_key *b)
{
    om__izb_key t = *a;
    *a = *b;
    *b = t;
}

/* Puts the k-th smallest key (of `axis`) at position k of s[0..n), smaller before,
 * larger after: Hoare's quickselect with a median-of-three pivot (deterministic). The
 * keys are integers stored once, so every comparison gives the same answer twice in
 * any floating-point mode, and the scans stop at their sentinels. */
static void quickselect(om__izb_key *s, uint32_t n, uint32_t k, int axis)
{
    uint32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (key(&s[mid], axis) < key(&s[lo], axis)) swap(&s[mid], &s[lo]);
        if (key(&s[hi], axis) < key(&s[lo], axis)) swap(&s[hi], &s[lo]);
        if (key(&s[hi], axis) < key(&s[mid], axis)) swap(&s[hi], &s[mid]);
        int32_t pivot = key(&s[mid], axis);
        uint32_t i = lo, j = hi;
        while (i <= j) {
            while (key(&s[i], axis) < pivot) i++;
            while (key(&s[j], axis) > pivot) j--;
            if (i <= j) {
                swap(&s[i], &s[j]);
                i++;
                if (j == 0) break;
                j--;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else return;
    }
}

/* Bounds and farthest depth of a node: from its keys for a leaf, from its children
 * otherwise (children are created after their parent, so a reverse sweep meets them
 * first). */
static void bound_node(om__izb *z, om__izb_node *nd)
{
    if (nd->child) {
        const om__izb_node *l = &z->nodes[nd->child], *r = l + 1;
        nd->x0 = l->x0 < r->x0 ? l->x0 : r->x0;
        nd->y0 = l->y0 < r->y0 ? l->y0 : r->y0;
        nd->x1 = l->x1 > r->x1 ? l->x1 : r->x1;
        nd->y1 = l->y1 > r->y1 ? l->y1 : r->y1;
        nd->zmax = l->zmax > r->zmax ? l->zmax : r->zmax;
    } else {
        const om__izb_key *k = &z->keys[nd->first];
        int32_t x0 = k->x, x1 = k->x, y0 = k->y, y1 = k->y;
        float zm = k->z;
        for (uint32_t i = 1; i < nd->count; i++) {
            if (k[i].x < x0) x0 = k[i].x;
            if (k[i].x > x1) x1 = k[i].x;
            if (k[i].y < y0) y0 = k[i].y;
            if (k[i].y > y1) y1 = k[i].y;
            if (k[i].z > zm) zm = k[i].z;
        }
        nd->x0 = x0; nd->x1 = x1; nd->y0 = y0; nd->y1 = y1;
        nd->zmax = zm;
    }
    nd->open = nd->count;
}

void om__izb_build(om__izb *z)
{
    z->nnodes = 0;
    if (z->n == 0) return;
    for (uint32_t i = 0; i < z->n; i++) {
        const om__lpoint *p = &z->samples[i].p;
        float f = (float)p->z;
        z->keys[i].x = (int32_t)p->x;   /* the light grid fits in 27 bits */
        z->keys[i].y = (int32_t)p->y;
        z->keys[i].s = i;
        z->keys[i].z = (double)f < p->z ? f * (1.0f + FLT_EPSILON) : f;   /* never below */
    }
    struct { uint32_t node; int axis; } stack[64];
    int sp = 0;
    om__izb_node *root = &z->nodes[z->nnodes++];
    root->first = 0;
    root->count = z->n;
    root->child = 0;
    stack[sp].node = 0;
    stack[sp++].axis = 0;
    while (sp > 0) {
        uint32_t ni = stack[--sp].node;
        int axis = stack[sp].axis;
        om__izb_node *nd = &z->nodes[ni];
        if (nd->count <= z->leaf || z->nnodes + 2 > z->node_cap || sp + 2 > 64) continue;
        uint32_t half = nd->count / 2;
        quickselect(&z->keys[nd->first], nd->count, half, axis);
        uint32_t c = z->nnodes;
        z->nnodes += 2;
        om__izb_node *l = &z->nodes[c], *r = &z->nodes[c + 1];
        l->first = nd->first;
        l->count = half;
        r->first = nd->first + half;
        r->count = nd->count - half;
        l->child = r->child = 0;
        nd->child = c;
        /* Alternating splits, as the paper does. */
        stack[sp].node = c;
        stack[sp++].axis = !axis;
        stack[sp].node = c + 1;
        stack[sp++].axis = !axis;
    }
    for (uint32_t i = z->nnodes; i-- > 0;) bound_node(z, &z->nodes[i]);
    z->st.nodes += z->nnodes;
}

/* ---- stage 3: rasterize the triangles through the BSP */

/* Could any sub-triangle of lt cover a point of the box? Exact: the box is outside a
 * sub-triangle when it lies wholly outside one of its (biased) edges. */
static bool box_touches(const om__ltri *lt, const om__izb_node *nd)
{
    if (lt->hix < nd->x0 || lt->lox > nd->x1 || lt->hiy < nd->y0 || lt->loy > nd->y1) return false;
    for (int k = 0; k < lt->n; k++) {
        const om__tri2 *e = &lt->sub[k].e;
        bool out = false;
        for (int i = 0; i < 3 && !out; i++) {
            int64_t mx = e->a[i] > 0 ? e->a[i] * nd->x1 : e->a[i] * nd->x0;
            int64_t my = e->b[i] > 0 ? e->b[i] * nd->y1 : e->b[i] * nd->y0;
            out = mx + my + e->c[i] < 0;
        }
        if (!out) return true;
    }
    return false;
}

/* Returns how many samples of the subtree became opaque-shadowed. */
static uint32_t visit(om__izb *z, uint32_t ni, const om__ltri *lt, const om__odepth *od)
{
    om__izb_node *nd = &z->nodes[ni];
    z->st.visited++;
    if (nd->open == 0) { z->st.culled_shadowed++; return 0; }
    if (lt->zmin >= nd->zmax) { z->st.culled_depth++; return 0; }
    if (!box_touches(lt, nd)) return 0;
    uint32_t closed = 0;
    if (nd->child) {
        closed = visit(z, nd->child, lt, od) + visit(z, nd->child + 1, lt, od);
    } else {
        for (uint32_t i = nd->first; i < nd->first + nd->count; i++) {
            om__izb_key *k = &z->keys[i];
            if ((k->s & OM_IZB_DONE) || k->x < lt->lox || k->x > lt->hix || k->y < lt->loy ||
                k->y > lt->hiy)
                continue;
            om__izb_sample *s = &z->samples[k->s];
            z->st.tested++;
            if (!om__blocks(lt, &s->p)) continue;
            z->st.blocked++;
            om__odepth_add(&s->od, od);
            if (om__odepth_opaque(&s->od)) {
                k->s |= OM_IZB_DONE;
                closed++;
            }
        }
    }
    nd->open -= closed;
    return closed;
}

void om__izb_raster(om__izb *z)
{
    if (z->nnodes == 0) return;
    const om_scene *sc = z->scene;
    const om__izb_node *root = &z->nodes[0];
    for (uint32_t t = 0; t < sc->ntris && z->nodes[0].open; t++) {
        /* Cheap rejection by the projected vertices before any setup: the tile's
         * light-space bounds and its farthest sample. */
        const uint32_t *ix = sc->idx + (size_t)t * 3;
        const om__lvert *a = z->ls.verts ? &z->ls.verts[ix[0]] : NULL;
        const om__lvert *b = a ? &z->ls.verts[ix[1]] : NULL, *c = a ? &z->ls.verts[ix[2]] : NULL;
        if (a && a->x != INT32_MIN && b->x != INT32_MIN && c->x != INT32_MIN) {
            if ((a->x < root->x0 && b->x < root->x0 && c->x < root->x0) ||
                (a->x > root->x1 && b->x > root->x1 && c->x > root->x1) ||
                (a->y < root->y0 && b->y < root->y0 && c->y < root->y0) ||
                (a->y > root->y1 && b->y > root->y1 && c->y > root->y1) ||
                (a->z >= root->zmax && b->z >= root->zmax && c->z >= root->zmax))
                continue;
        }
        om__ltri lt;
        if (!om__lspace_tri(&z->ls, t, &lt)) continue;
        visit(z, 0, &lt, &z->mat_od[sc->tri_mat[t]]);
    }
}

void om__izb_write(const om__izb *z, om_strip *st)
{
    for (uint32_t i = 0; i < z->n; i++) om__odepth_term(&z->samples[i].od, &st->terms[z->samples[i].idx]);
}

static om_status izb_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    om__izb *z = &((izb_state *)state)->z;
    size_t n = (size_t)st->rows * st->width, next = 0;
    for (size_t i = 0; i < n; i++) st->terms[i].r = st->terms[i].g = st->terms[i].b = 255;
    while (next < n) {
        if (om__izb_transform(z, st, &next, n, NULL, NULL) == 0) break;
        om__izb_build(z);
        om__izb_raster(z);
        om__izb_write(z, st);
        z->st.tiles++;
    }
    return OM_OK;
}

static void izb_stats(const void *state, om_method_stats *out)
{
    const izb_state *m = (const izb_state *)state;
    const om__izb *z = &m->z;
    memset(out, 0, sizeof *out);
    out->bytes_used = fixed_bytes(z->scene, z->ls.verts != NULL) + om__izb_pool_bytes(z->cap, z->leaf);
    static const char *const names[] = {"bsp nodes", "nodes visited", "nodes culled (shadowed)",
                                        "nodes culled (depth)", "samples tested", "tiles",
                                        "pool samples"};
    uint32_t v[7] = {z->st.nodes, z->st.visited, z->st.culled_shadowed, z->st.culled_depth,
                     z->st.tested, z->st.tiles, z->cap};
    for (int i = 0; i < 7; i++) {
        out->counters[i] = v[i];
        out->counter_names[i] = names[i];
    }
    out->ncounters = 7;
}

const om_method om__method_izb = {
    "izb", "irregular z-buffer (alias-free shadow maps): exact, BSP over the visible samples",
    OM_METHOD_EXACT, izb_bytes, izb_init, izb_begin, izb_observe, izb_build, izb_resolve,
    izb_stats, NULL,
};
