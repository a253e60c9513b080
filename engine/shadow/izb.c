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

extern const om_method om__method_izb;

typedef struct izb_state {
    om__izb z;
    om__izb_cfg cfg;
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
           2 * om_arena_need((size_t)samples * sizeof(om__izb_key), 16) +
           om_arena_need((size_t)node_bound(samples, leaf) * sizeof(om__izb_node), 16);
}

static size_t fixed_bytes(const om_scene *s, bool cache)
{
    return om_arena_need(sizeof(izb_state), 16) + om__izb_parts_bytes(s, cache);
}

static om_status pool_bytes(const om__izb_cfg *c, const om_scene *s, uint32_t w, uint32_t h,
                            size_t *min, size_t *full)
{
    if (c->izb_leaf < 1) return OM_E_INVALID;
    uint32_t one_pass = w * h, smallest = w;   /* the smallest tile: one row */
    if (c->izb_pool) one_pass = smallest = c->izb_pool;
    *min = fixed_bytes(s, false) + om__izb_pool_bytes(smallest, c->izb_leaf);
    *full = fixed_bytes(s, true) + om__izb_pool_bytes(one_pass, c->izb_leaf);
    return OM_OK;
}

static om_status izb_bytes(const om_method_cfg *mc, const om_scene *s, uint32_t w, uint32_t h,
                           size_t *min, size_t *full)
{
    om__izb_cfg c;
    if (om__method_cfg_of(mc, &om__method_izb, &c, NULL)) return OM_E_INVALID;
    return pool_bytes(&c, s, w, h, min, full);
}

om_status om__izb_setup(om__izb *z, om_arena *a, const om__izb_cfg *c, const om_scene *s,
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
    if ((st = om_arena_alloc(a, (size_t)cap * sizeof(om__izb_key), 16, &p, d))) return st;
    z->sorted = (om__izb_key *)p;
    if ((st = om_arena_alloc(a, (size_t)z->node_cap * sizeof(om__izb_node), 16, &p, d))) return st;
    z->nodes = (om__izb_node *)p;
    return OM_OK;
}

static om_status izb_init(void **state, om_arena *a, const om_method_cfg *mc, const om_scene *s,
                          uint32_t w, uint32_t h, om_diag *d)
{
    om_status st;
    void *p;
    size_t mn, full;
    om__izb_cfg cv;
    const om__izb_cfg *c = &cv;
    if ((st = om__method_cfg_of(mc, &om__method_izb, &cv, d))) return st;
    if (c->izb_leaf < 1) return om__fail(d, OM_E_INVALID, "izb: leaf size must be at least 1");
    if ((st = pool_bytes(c, s, w, h, &mn, &full))) return st;
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
        /* the sample's key for the BSP, and the tile's bounds, while it is at hand */
        om__izb_key *k = &z->keys[n];
        float f = (float)s->p.z;
        k->x = (int32_t)s->p.x;   /* the light grid fits in 27 bits */
        k->y = (int32_t)s->p.y;
        k->s = n;
        k->z = (double)f < s->p.z ? f * (1.0f + FLT_EPSILON) : f;   /* never below */
        if (n == 0 || k->x < z->kx0) z->kx0 = k->x;
        if (n == 0 || k->x > z->kx1) z->kx1 = k->x;
        if (n == 0 || k->y < z->ky0) z->ky0 = k->y;
        if (n == 0 || k->y > z->ky1) z->ky1 = k->y;
        n++;
    }
    *next = i;
    z->n = n;
    return n;
}

/* ---- stage 2: the 2-D BSP */

/* The Z-order (Morton) code of a key: x and y relative to the tile's corner, shifted
 * to 16 bits each, bits interleaved. */
static uint32_t spread(uint32_t v)
{
    v &= 0xFFFFu;
    v = (v | (v << 8)) & 0x00FF00FFu;
    v = (v | (v << 4)) & 0x0F0F0F0Fu;
    v = (v | (v << 2)) & 0x33333333u;
    return (v | (v << 1)) & 0x55555555u;
}

static uint32_t zcode(const om__izb_key *k, int32_t x0, int32_t y0, int shift)
{
    return spread((uint32_t)(k->x - x0) >> shift) | spread((uint32_t)(k->y - y0) >> shift) << 1;
}

/* Sorts z->keys into Z order (a stable least-significant-digit radix sort through
 * z->sorted, three passes of 11 bits; keys of equal code keep the screen's order), so
 * that halving the array again and again gives nodes that are compact in the light's
 * image. Integer keys only: the same order in any floating-point mode. */
typedef struct zframe { int32_t x0, y0; int shift; } zframe;

static zframe zsort(om__izb *z)
{
    uint32_t n = z->n;
    int32_t x0 = z->kx0, y0 = z->ky0, x1 = z->kx1, y1 = z->ky1;
    uint32_t span = (uint32_t)(x1 - x0) > (uint32_t)(y1 - y0) ? (uint32_t)(x1 - x0) : (uint32_t)(y1 - y0);
    int shift = 0;
    while ((span >> shift) > 0xFFFFu) shift++;
    /* three digits of 11 bits; their histograms in one pass over the keys */
    static const int at[3] = {0, 11, 22};
    uint32_t count[3][2049];
    memset(count, 0, sizeof count);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = zcode(&z->keys[i], x0, y0, shift);
        count[0][(c & 2047u) + 1]++;
        count[1][(c >> 11 & 2047u) + 1]++;
        count[2][(c >> 22) + 1]++;
    }
    om__izb_key *src = z->keys, *dst = z->sorted;
    for (int pass = 0; pass < 3; pass++) {
        uint32_t *cnt = count[pass];
        int d = at[pass];
        if (cnt[((zcode(&src[0], x0, y0, shift) >> d) & 2047u) + 1] == n) continue;   /* one digit */
        for (int b = 0; b < 2048; b++) cnt[b + 1] += cnt[b];
        for (uint32_t i = 0; i < n; i++) dst[cnt[(zcode(&src[i], x0, y0, shift) >> d) & 2047u]++] = src[i];
        om__izb_key *t = src;
        src = dst;
        dst = t;
    }
    z->keys = src;   /* the two buffers trade places rather than copy */
    z->sorted = dst;
    zframe f = {x0, y0, shift};
    return f;
}

/* Where the sorted keys [first, first + count) split: at the highest bit in which their
 * codes differ (the node's quadtree-like cell is cut in two halves of space), or in
 * the middle when they all share one code. */
static uint32_t zsplit(const om__izb *z, const zframe *f, uint32_t first, uint32_t count)
{
    const om__izb_key *k = &z->keys[first];
    uint32_t a = zcode(&k[0], f->x0, f->y0, f->shift), b = zcode(&k[count - 1], f->x0, f->y0, f->shift);
    if (a == b) return count / 2;
    uint32_t bit = 0x80000000u;
    while (!((a ^ b) & bit)) bit >>= 1;
    uint32_t lo = 0, hi = count - 1;   /* the first key with the bit set: in (lo, hi] */
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (zcode(&k[mid], f->x0, f->y0, f->shift) & bit) hi = mid;
        else lo = mid;
    }
    return hi;
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
    zframe f = zsort(z);
    uint32_t stack[64];
    int sp = 0;
    om__izb_node *root = &z->nodes[z->nnodes++];
    root->first = 0;
    root->count = z->n;
    root->child = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        om__izb_node *nd = &z->nodes[stack[--sp]];
        if (nd->count <= z->leaf || z->nnodes + 2 > z->node_cap || sp + 2 > 64) continue;
        uint32_t half = zsplit(z, &f, nd->first, nd->count);
        uint32_t c = z->nnodes;
        z->nnodes += 2;
        om__izb_node *l = &z->nodes[c], *r = &z->nodes[c + 1];
        l->first = nd->first;
        l->count = half;
        r->first = nd->first + half;
        r->count = nd->count - half;
        l->child = r->child = 0;
        nd->child = c;
        stack[sp++] = c;
        stack[sp++] = c + 1;
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

void om__izb_resolve(om__izb *z, om_strip *st, om__izb_decide decide, void *user)
{
    size_t n = (size_t)st->rows * st->width, next = 0;
    for (size_t i = 0; i < n; i++) st->terms[i].r = st->terms[i].g = st->terms[i].b = 255;
    while (next < n) {
        if (om__izb_transform(z, st, &next, n, decide, user) == 0) break;
        om__izb_build(z);
        om__izb_raster(z);
        om__izb_write(z, st);
        z->st.tiles++;
    }
}

static om_status izb_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    om__izb_resolve(&((izb_state *)state)->z, st, NULL, NULL);
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

static const om_setting settings[] = {
    OM__SET_IZB_LEAF(om__izb_cfg, izb_leaf), OM__SET_IZB_POOL(om__izb_cfg, izb_pool),
};

const om_method om__method_izb = {
    "izb", "irregular z-buffer (alias-free shadow maps): exact, BSP over the visible samples",
    OM_METHOD_EXACT, izb_bytes, izb_init, izb_begin, izb_observe, izb_build, izb_resolve,
    izb_stats, NULL, settings, sizeof settings / sizeof settings[0], sizeof(om__izb_cfg),
};
