/* bvh.c — build (binned SAH, 16 bins along the widest centroid axis, a median split
 * when the bins cannot separate), the two levels of a scene with objects (a subtree
 * per object in its own region, a top level over them; bvh.h) and the segment walk.
 * The builds are iterative with explicit stacks so their depth never depends on the C
 * stack. */
#include "bvh.h"

#include <float.h>
#include <string.h>

#define BINS 16
#define STACK 64

typedef struct box { float lo[3], hi[3]; } box;

static void box_empty(box *b)
{
    for (int i = 0; i < 3; i++) { b->lo[i] = FLT_MAX; b->hi[i] = -FLT_MAX; }
}
/* Selects rather than branches (a compiler makes them min and max instructions): the
 * build's bins take their triangles in no predictable order. */
static inline float lower(float a, float b) { return a < b ? a : b; }
static inline float upper(float a, float b) { return a > b ? a : b; }
static inline void box_grow(box *b, const float *lo, const float *hi)
{
    b->lo[0] = lower(lo[0], b->lo[0]);
    b->lo[1] = lower(lo[1], b->lo[1]);
    b->lo[2] = lower(lo[2], b->lo[2]);
    b->hi[0] = upper(hi[0], b->hi[0]);
    b->hi[1] = upper(hi[1], b->hi[1]);
    b->hi[2] = upper(hi[2], b->hi[2]);
}
static float box_area(const box *b)
{
    float dx = b->hi[0] - b->lo[0], dy = b->hi[1] - b->lo[1], dz = b->hi[2] - b->lo[2];
    return dx < 0 ? 0.0f : dx * dy + dy * dz + dz * dx;
}

/* Every leaf holds at least half a leaf's worth (a split never leaves less), so there
 * are at most n / that many leaves and twice as many nodes. */
static size_t node_bound(size_t n, uint32_t leaf)
{
    size_t least = leaf / 2 ? leaf / 2 : 1, leaves = n / least;
    return 2 * (leaves ? leaves : 1);
}

/* A scene with objects splits its root into the static triangles and the objects'
 * (om__bvh_build): the root, its two children, the static subtree within its bound,
 * every object's region within its own (node_bound of its triangles) and the top level
 * over the objects (a node per object and one fewer above them). */
static bool two_level(const om_scene *s) { return s->nobjects && s->ntris; }

static uint32_t obj_tris(const om_scene *s, uint32_t i)
{
    return s->meshes[s->objects[i].mesh].ntris;
}

size_t om__bvh_nodes_max(const om_scene *s, uint32_t leaf)
{
    if (!two_level(s)) return node_bound(s->ntris ? s->ntris : 1, leaf);
    size_t n = s->ntris, regions = 0;
    for (uint32_t i = 0; i < s->nobjects; i++) {
        n -= obj_tris(s, i);
        if (obj_tris(s, i)) regions += node_bound(obj_tris(s, i), leaf);
    }
    return 3 + node_bound(n ? n : 1, leaf) + 2 * (size_t)s->nobjects + regions;
}

size_t om__bvh_bytes(const om_scene *s, uint32_t leaf)
{
    size_t n = s->ntris ? s->ntris : 1;
    return om_arena_need(om__bvh_nodes_max(s, leaf) * sizeof(om__bvh_node), 16) +
           om_arena_need(n * sizeof(uint32_t), 4) +
           (two_level(s) ? om_arena_need((3 * (size_t)s->nobjects + 2) * sizeof(uint32_t), 4) +
                               om_arena_need(6 * (size_t)s->nobjects * sizeof(float), 4)
                         : 0);
}

size_t om__bvh_scratch_bytes(const om_scene *s)
{
    return om_arena_need((size_t)(s->ntris ? s->ntris : 1) * sizeof(box), 4);
}

/* The triangles' boxes during the build: with the scratch array, tb[i] is the box of
 * tris[i] and moves with it, so every pass reads both arrays in order; without it (an
 * arena below the scratch's size) each box comes from the triangle's vertices (slower,
 * the same numbers). */
typedef struct boxes { const om_scene *s; box *tb; uint32_t *tris; } boxes;

static box vert_box(const om_scene *s, uint32_t t)
{
    box r;
    box_empty(&r);
    for (int k = 0; k < 3; k++) {
        const om_vec3 *v = &s->verts[s->idx[3 * (size_t)t + k]];
        float p[3] = {v->x, v->y, v->z};
        box_grow(&r, p, p);
    }
    return r;
}

static box box_at(const boxes *bx, uint32_t i)
{
    return bx->tb ? bx->tb[i] : vert_box(bx->s, bx->tris[i]);
}

static inline void swap_at(const boxes *bx, uint32_t i, uint32_t j)
{
    uint32_t t = bx->tris[i]; bx->tris[i] = bx->tris[j]; bx->tris[j] = t;
    if (bx->tb) { box b = bx->tb[i]; bx->tb[i] = bx->tb[j]; bx->tb[j] = b; }
}

static inline float centre(const box *b, int axis)
{
    return (b->lo[axis] + b->hi[axis]) * 0.5f;
}

/* Grows c by the centroid of t. */
static inline void grow_centre(box *c, const box *t)
{
    const float m[3] = {centre(t, 0), centre(t, 1), centre(t, 2)};
    box_grow(c, m, m);
}

/* A centroid as an integer whose unsigned order is the floats' order (-0 equal to +0,
 * as a float comparison has them; a NaN gets a place of its own). The quickselect
 * compares these keys: a float comparison need not give the same answer twice (with
 * x87 excess precision a centroid recomputed in a register and the pivot stored as a
 * float disagree, and the scans below ran past their sentinel forever), while the
 * bits of a stored float are what they are. */
static uint32_t centre_key(const boxes *bx, uint32_t i, int axis)
{
    box b = box_at(bx, i);
    float c = centre(&b, axis);
    uint32_t u;
    memcpy(&u, &c, sizeof u);
    if (u == 0x80000000u) u = 0;
    return u & 0x80000000u ? ~u : u | 0x80000000u;
}

/* Puts the k-th smallest centroid (along axis) of positions [first, first + n) at
 * first + k: Hoare's quickselect. The scans are also kept inside [lo, hi], so that
 * [lo, hi] shrinks every round and the loop ends whatever the keys say; with
 * consistent keys the bounds never bind, and the order is the one the float
 * comparison gave on SSE. */
static void select_median(const boxes *bx, uint32_t first, uint32_t n, uint32_t k, int axis)
{
    uint32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        const uint32_t pivot = centre_key(bx, first + lo + (hi - lo) / 2, axis);
        uint32_t i = lo, j = hi;
        while (i <= j) {
            while (i < hi && centre_key(bx, first + i, axis) < pivot) i++;
            while (j > lo && centre_key(bx, first + j, axis) > pivot) j--;
            if (i <= j) {
                swap_at(bx, first + i, first + j);
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

/* The box of positions [first, end) and of their centroids. */
static void bound_range(const boxes *bx, uint32_t first, uint32_t end, box *bb, box *cb)
{
    box_empty(bb);
    box_empty(cb);
    for (uint32_t i = first; i < end; i++) {
        box t = box_at(bx, i);
        box_grow(bb, t.lo, t.hi);
        grow_centre(cb, &t);
    }
}

/* The bin of a centroid: the same arithmetic for counting and for partitioning, so a
 * triangle lands on the side its bin was counted on. */
typedef struct binning { int axis; float lo, scale; } binning;

static inline int bin_of(const binning *g, const box *t)
{
    /* compared before the conversion: a NaN or huge centre (a hand-made scene's) has
     * no int, and goes to an end bin */
    const float f = (centre(t, g->axis) - g->lo) * g->scale;
    return !(f > 0.0f) ? 0 : f >= (float)BINS ? BINS - 1 : (int)f;
}

/* Counts and bounds the triangles of [first, end) per bin. The loops below read the
 * scratch array directly when there is one: they are most of the build. */
static void bin_range(const boxes *bx, const binning *g, uint32_t first, uint32_t end,
                      uint32_t cnt[BINS], box bin[BINS])
{
    for (int k = 0; k < BINS; k++) { cnt[k] = 0; box_empty(&bin[k]); }
    for (uint32_t i = first; i < end; i++) {
        box v;
        const box *t = bx->tb ? &bx->tb[i] : (v = vert_box(bx->s, bx->tris[i]), &v);
        int k = bin_of(g, t);
        cnt[k]++;
        box_grow(&bin[k], t->lo, t->hi);
    }
}

/* Partitions [first, end) in place, bins up to `split` first; returns where the rest
 * begin. Each triangle is looked at once, and its centroid bounds its side's (cside). */
static uint32_t partition_range(const boxes *bx, const binning *g, uint32_t first, uint32_t end,
                                int split, box cside[2])
{
    box_empty(&cside[0]);
    box_empty(&cside[1]);
    uint32_t l = first, h = end;
    while (l < h) {
        box v;
        const box *t = bx->tb ? &bx->tb[l] : (v = vert_box(bx->s, bx->tris[l]), &v);
        if (bin_of(g, t) <= split) {
            grow_centre(&cside[0], t);
            l++;
        } else {
            grow_centre(&cside[1], t);
            swap_at(bx, l, --h);
        }
    }
    return l;
}

/* A node waiting on the stack: its range, depth and, when its parent's bins gave them
 * (`known`), its centroids' box (its own box is then in the node already). */
typedef struct job {
    uint32_t node, first, count, depth;
    box cb;
    bool known;
} job;

/* Builds the subtree of the job `top` (its node allocated, its triangles' range in
 * tris), appending its nodes from b->nnodes on. */
static void build_from(om__bvh *b, const boxes *bxs, job top, uint32_t leaf, size_t cap)
{
    const boxes bx = *bxs;
    const uint32_t least = leaf / 2 ? leaf / 2 : 1;
    job stack[STACK];
    stack[0] = top;
    int sp = 1;
    while (sp > 0) {
        job j = stack[--sp];
        const uint32_t end = j.first + j.count;
        if (j.depth > b->depth) b->depth = j.depth;
        om__bvh_node *nd = &b->nodes[j.node];
        box cb = j.cb;
        if (!j.known) {
            /* the root, or a child of a median split: one pass for its boxes */
            box bb;
            bound_range(&bx, j.first, end, &bb, &cb);
            if (j.count == 0) for (int k = 0; k < 3; k++) bb.lo[k] = bb.hi[k] = 0;
            memcpy(nd->box.w.lo, bb.lo, sizeof bb.lo);
            memcpy(nd->box.w.hi, bb.hi, sizeof bb.hi);
        }
        nd->first = j.first;
        nd->count = j.count;
        if (j.count <= leaf || sp + 2 > STACK || b->nnodes + 2 > cap) continue;
        int axis = 0;
        for (int k = 1; k < 3; k++)
            if (cb.hi[k] - cb.lo[k] > cb.hi[axis] - cb.lo[axis]) axis = k;
        float ext = cb.hi[axis] - cb.lo[axis];
        uint32_t mid = j.first;   /* no useful bin boundary: the median below */
        /* what the bins say of the two sides: their boxes and their centroids' boxes */
        box side[2], cside[2];
        if (ext > 0.0f) {
            /* Binned SAH: count and bound the triangles per bin, sweep both ways. */
            uint32_t cnt[BINS];
            box bin[BINS];
            const binning g = {axis, cb.lo[axis], (float)BINS / ext};
            bin_range(&bx, &g, j.first, end, cnt, bin);
            float right_area[BINS];
            uint32_t right_cnt[BINS];
            box acc;
            box_empty(&acc);
            uint32_t c = 0;
            for (int k = BINS - 1; k > 0; k--) {
                box_grow(&acc, bin[k].lo, bin[k].hi);
                c += cnt[k];
                right_area[k] = box_area(&acc);
                right_cnt[k] = c;
            }
            box_empty(&acc);
            c = 0;
            float best = FLT_MAX;
            int split = -1;
            for (int k = 0; k < BINS - 1; k++) {
                box_grow(&acc, bin[k].lo, bin[k].hi);
                c += cnt[k];
                if (c == 0 || right_cnt[k + 1] == 0) continue;
                float cost = box_area(&acc) * (float)c + right_area[k + 1] * (float)right_cnt[k + 1];
                if (cost < best) { best = cost; split = k; }
            }
            if (split >= 0) {
                mid = partition_range(&bx, &g, j.first, end, split, cside);
                /* the union of a side's bins' boxes is the union of its triangles' */
                box_empty(&side[0]);
                box_empty(&side[1]);
                for (int k = 0; k < BINS; k++) box_grow(&side[k > split], bin[k].lo, bin[k].hi);
            }
        }
        bool known = mid != j.first;
        if (mid < j.first + least || mid > end - least) {
            /* too small a child: split at the centroid median instead, which bounds the
             * node count by the leaf size; the children then find their own boxes */
            mid = j.first + j.count / 2;
            select_median(&bx, j.first, j.count, j.count / 2, axis);
            known = false;
        }
        uint32_t child = b->nnodes;
        b->nnodes += 2;
        nd->first = child;
        nd->count = 0;
        for (int e = 0; e < 2; e++) {
            job *c = &stack[sp++];
            memset(c, 0, sizeof *c);
            c->node = child + (uint32_t)e;
            c->first = e ? mid : j.first;
            c->count = e ? end - mid : mid - j.first;
            c->depth = j.depth + 1;
            c->known = known;
            if (known) {
                c->cb = cside[e];
                memcpy(b->nodes[c->node].box.w.lo, side[e].lo, sizeof side[e].lo);
                memcpy(b->nodes[c->node].box.w.hi, side[e].hi, sizeof side[e].hi);
            }
        }
    }
}

/* The subtree of object i in its region (its root at the region's start), and the
 * region's spare nodes made leaves of one of its triangles: nothing refers to them,
 * and every pass over all nodes finds them well formed. */
static void build_object(om__bvh *b, const boxes *bx, uint32_t i)
{
    const uint32_t lo = b->obj_node[i], hi = b->obj_node[i + 1];
    if (lo == hi) return;   /* no triangles: no region */
    job top;
    memset(&top, 0, sizeof top);
    top.node = lo;
    top.first = b->obj_tri[i];
    top.count = b->obj_tri[i + 1] - b->obj_tri[i];
    top.depth = 3;
    /* its triangles in their order again (a build leaves them partitioned), so that
     * the build is a new one's (at om__bvh_build, the order they are already in) */
    for (uint32_t t = 0; t < top.count; t++) b->tris[top.first + t] = bx->s->objects[i].first_tri + t;
    const uint32_t all = b->nnodes;
    b->nnodes = lo + 1;
    build_from(b, bx, top, b->obj_leaf, hi);
    memcpy(b->obj_box + 6 * (size_t)i, b->nodes[lo].box.w.lo, 3 * sizeof(float));
    memcpy(b->obj_box + 6 * (size_t)i + 3, b->nodes[lo].box.w.hi, 3 * sizeof(float));
    for (uint32_t k = b->nnodes; k < hi; k++) {
        memset(&b->nodes[k], 0, sizeof b->nodes[k]);
        b->nodes[k].first = top.first;
        b->nodes[k].count = 1;
    }
    b->nnodes = all;
}

/* A box's centre along axis as an unsigned key in the floats' order (centre_key). */
static uint32_t obj_key(const om__bvh *b, uint32_t i, int axis)
{
    const float *o = b->obj_box + 6 * (size_t)i;
    float c = (o[axis] + o[3 + axis]) * 0.5f, u0;
    uint32_t u;
    u0 = c;
    memcpy(&u, &u0, sizeof u);
    if (u == 0x80000000u) u = 0;
    return u & 0x80000000u ? ~u : u | 0x80000000u;
}

/* The k-th smallest key of perm[first, first + n) to first + k (select_median's
 * quickselect, on the objects' keys). */
static void select_obj(const om__bvh *b, uint32_t *perm, uint32_t n, uint32_t k, int axis)
{
    uint32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        const uint32_t pivot = obj_key(b, perm[lo + (hi - lo) / 2], axis);
        uint32_t i = lo, j = hi;
        while (i <= j) {
            while (i < hi && obj_key(b, perm[i], axis) < pivot) i++;
            while (j > lo && obj_key(b, perm[j], axis) > pivot) j--;
            if (i <= j) {
                const uint32_t t = perm[i]; perm[i] = perm[j]; perm[j] = t;
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

/* The top level: node 2 over the objects with triangles, split at the median of their
 * boxes' centres along the widest axis of those centres down to one object a node,
 * which becomes a copy of its root; then the root's box. The objects in their order
 * first, so the same boxes give the same tree. Its depth is below 33 (a median split
 * of at most 2^32 objects), so a walk's stack holds it above any object's subtree. */
static void build_top(om__bvh *b, const om_scene *s)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < s->nobjects; i++)
        if (b->obj_node[i] != b->obj_node[i + 1]) b->perm[n++] = i;
    b->top_end = b->top_first;
    if (n == 0) {   /* objects without triangles: node 2 a spare (the root below) */
        memset(&b->nodes[2], 0, sizeof b->nodes[2]);
        b->nodes[2].count = 1;
    }
    typedef struct tjob { uint32_t node, first, count; } tjob;
    tjob stack[STACK];
    int sp = 0;
    if (n) stack[sp++] = (tjob){2, 0, n};
    while (sp > 0) {
        const tjob j = stack[--sp];
        om__bvh_node *nd = &b->nodes[j.node];
        if (j.count == 1) {
            *nd = b->nodes[b->obj_node[b->perm[j.first]]];
            continue;
        }
        box bb, cb;
        box_empty(&bb);
        box_empty(&cb);
        for (uint32_t k = j.first; k < j.first + j.count; k++) {
            const float *o = b->obj_box + 6 * (size_t)b->perm[k];
            box t;
            memcpy(t.lo, o, sizeof t.lo);
            memcpy(t.hi, o + 3, sizeof t.hi);
            box_grow(&bb, t.lo, t.hi);
            grow_centre(&cb, &t);
        }
        memcpy(nd->box.w.lo, bb.lo, sizeof bb.lo);
        memcpy(nd->box.w.hi, bb.hi, sizeof bb.hi);
        int axis = 0;
        for (int k = 1; k < 3; k++)
            if (cb.hi[k] - cb.lo[k] > cb.hi[axis] - cb.lo[axis]) axis = k;
        const uint32_t half = j.count / 2;
        select_obj(b, b->perm + j.first, j.count, half, axis);
        nd->first = b->top_end;
        nd->count = 0;
        b->top_end += 2;
        stack[sp++] = (tjob){nd->first, j.first, half};
        stack[sp++] = (tjob){nd->first + 1, j.first + half, j.count - half};
    }
    for (uint32_t k = b->top_end; k < b->top_first + 2 * s->nobjects; k++) {
        /* spare: as a region's (build_object) */
        memset(&b->nodes[k], 0, sizeof b->nodes[k]);
        b->nodes[k].count = 1;
    }
    /* The root over both sides; where one side has no triangles, a copy of the other
     * (the empty side's node a spare, which nothing then refers to). */
    if (!n || !b->obj_first) {
        b->nodes[0] = b->nodes[n ? 2 : 1];
        return;
    }
    b->nodes[0].first = 1;
    b->nodes[0].count = 0;
    box r;
    box_empty(&r);
    for (int c = 1; c < 3; c++) box_grow(&r, b->nodes[c].box.w.lo, b->nodes[c].box.w.hi);
    memcpy(b->nodes[0].box.w.lo, r.lo, sizeof r.lo);
    memcpy(b->nodes[0].box.w.hi, r.hi, sizeof r.hi);
}

om_status om__bvh_build(om__bvh *b, om_arena *a, const om_scene *s, uint32_t leaf, om_diag *d)
{
    void *pn, *pt, *pb;
    om_status st;
    size_t n = s->ntris ? s->ntris : 1;
    size_t cap = om__bvh_nodes_max(s, leaf);
    memset(b, 0, sizeof *b);
    if ((st = om_arena_alloc(a, cap * sizeof(om__bvh_node), 16, &pn, d)) ||
        (st = om_arena_alloc(a, n * sizeof(uint32_t), 4, &pt, d)))
        return st;
    b->nodes = (om__bvh_node *)pn;
    b->tris = (uint32_t *)pt;
    const bool two = two_level(s);
    if (two) {
        if ((st = om_arena_alloc(a, (3 * (size_t)s->nobjects + 2) * sizeof(uint32_t), 4, &pb, d)))
            return st;
        b->obj_node = (uint32_t *)pb;
        b->obj_tri = b->obj_node + s->nobjects + 1;
        b->perm = b->obj_tri + s->nobjects + 1;
        if ((st = om_arena_alloc(a, 6 * (size_t)s->nobjects * sizeof(float), 4, &pb, d))) return st;
        b->obj_box = (float *)pb;
    }
    size_t mark = om_arena_mark(a);
    boxes bx = {s, NULL, b->tris};
    if (two) {
        /* static triangles first, in order, then each object's in the objects' order */
        uint32_t k = 0, t = 0;
        for (uint32_t i = 0; i <= s->nobjects; i++) {
            const uint32_t end = i < s->nobjects ? s->objects[i].first_tri : s->ntris;
            for (; t < end; t++) b->tris[k++] = t;
            if (i < s->nobjects) t += obj_tris(s, i);
        }
        b->obj_first = k;
        b->obj_count = s->ntris - k;
        for (uint32_t i = 0; i < s->nobjects; i++) {
            b->obj_tri[i] = k;
            for (uint32_t j = 0; j < obj_tris(s, i); j++) b->tris[k++] = s->objects[i].first_tri + j;
        }
        b->obj_tri[s->nobjects] = k;
    } else {
        for (uint32_t t = 0; t < s->ntris; t++) b->tris[t] = t;
    }
    if (om_arena_left(a) >= om__bvh_scratch_bytes(s)) {
        if ((st = om_arena_alloc(a, n * sizeof(box), 4, &pb, d))) return st;
        box *tb = (box *)pb;
        /* tb[i] is the box of tris[i] (boxes) */
        for (uint32_t i = 0; i < s->ntris; i++) tb[i] = vert_box(s, b->tris[i]);
        bx.tb = tb;
    }
    job top;
    memset(&top, 0, sizeof top);
    top.depth = 1;
    if (!two) {
        top.count = s->ntris;
        b->nnodes = 1;
        build_from(b, &bx, top, leaf, cap);
    } else {
        /* the static subtree from node 3 on, within its bound; then the top level's
         * place and the objects' regions (om__bvh_nodes_max) */
        b->nnodes = 3;
        top.node = 1;
        top.count = b->obj_first;
        top.depth = 2;
        const size_t static_cap = 3 + node_bound(b->obj_first ? b->obj_first : 1, leaf);
        if (b->obj_first) build_from(b, &bx, top, leaf, static_cap);
        else {   /* no static triangles: a spare (build_top) */
            memset(&b->nodes[1], 0, sizeof b->nodes[1]);
            b->nodes[1].count = 1;
        }
        for (uint32_t k = b->nnodes; k < static_cap; k++) {
            memset(&b->nodes[k], 0, sizeof b->nodes[k]);   /* spare, as build_object's */
            b->nodes[k].count = 1;
        }
        b->top_first = (uint32_t)static_cap;
        uint32_t at = b->top_first + 2 * s->nobjects;
        for (uint32_t i = 0; i < s->nobjects; i++) {
            b->obj_node[i] = at;
            if (obj_tris(s, i)) at += (uint32_t)node_bound(obj_tris(s, i), leaf);
        }
        b->obj_node[s->nobjects] = at;
        b->nnodes = at;
        b->obj_leaf = leaf;
        for (uint32_t i = 0; i < s->nobjects; i++) build_object(b, &bx, i);
        build_top(b, s);
        b->seen = s->change;
        if (b->depth < 1) b->depth = 1;
    }
    om_arena_rewind(a, mark);
    return OM_OK;
}

void om__bvh_rebuild_objects(om__bvh *b, const om_scene *s)
{
    b->rebuilt = 0;
    if (!b->obj_node || b->seen == s->change) return;
    const boxes bx = {s, NULL, b->tris};   /* boxes from the vertices: the same numbers */
    for (uint32_t i = 0; i < s->nobjects; i++) {
        /* moved after the count last seen, up to now (in unsigned differences, which
         * a wrapped count keeps) */
        const uint32_t m = s->objects[i].moved;
        if (m - b->seen - 1u >= s->change - b->seen) continue;
        build_object(b, &bx, i);
        b->rebuilt++;
    }
    build_top(b, s);
    b->seen = s->change;
}

static bool hits(const om__bvh_node *n, const float o[3], const float inv[3], float tmax, float m)
{
    float t0 = 0.0f, t1 = tmax;
    for (int k = 0; k < 3; k++) {
        float a = (n->box.w.lo[k] - m - o[k]) * inv[k], b = (n->box.w.hi[k] + m - o[k]) * inv[k];
        if (a > b) { float t = a; a = b; b = t; }
        if (a > t0) t0 = a;
        if (b < t1) t1 = b;
        if (t0 > t1) return false;
    }
    return true;
}

void om__bvh_walk(const om__bvh *b, om_vec3 o, om_vec3 dir, float tmax, float margin,
                  om__bvh_visit visit, void *user)
{
    if (!b->nnodes) return;
    float org[3] = {o.x, o.y, o.z}, dv[3] = {dir.x, dir.y, dir.z}, inv[3];
    for (int k = 0; k < 3; k++) {
        /* a zero component gives an infinite slab crossing: a huge finite inverse
         * keeps the arithmetic free of 0 * inf */
        inv[k] = dv[k] != 0.0f ? 1.0f / dv[k] : (dv[k] >= 0.0f ? 1e30f : -1e30f);
    }
    uint32_t stack[2 * STACK];   /* the build keeps the depth below STACK */
    int sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const om__bvh_node *n = &b->nodes[stack[--sp]];
        if (!hits(n, org, inv, tmax, margin)) continue;
        if (n->count == 0) {
            stack[sp++] = n->first;
            stack[sp++] = n->first + 1;
            continue;
        }
        for (uint32_t i = n->first; i < n->first + n->count; i++)
            if (visit(user, b->tris[i])) return;
    }
}

