/* bvh.c — build (binned SAH, 16 bins along the widest centroid axis, a median split
 * when the bins cannot separate) and the segment walk. The build is iterative with an
 * explicit stack so its depth never depends on the C stack. */
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
static void box_grow(box *b, const float *lo, const float *hi)
{
    for (int i = 0; i < 3; i++) {
        if (lo[i] < b->lo[i]) b->lo[i] = lo[i];
        if (hi[i] > b->hi[i]) b->hi[i] = hi[i];
    }
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

size_t om__bvh_nodes_max(const om_scene *s, uint32_t leaf)
{
    return node_bound(s->ntris ? s->ntris : 1, leaf);
}

size_t om__bvh_bytes(const om_scene *s, uint32_t leaf)
{
    size_t n = s->ntris ? s->ntris : 1;
    return om_arena_need(node_bound(n, leaf) * sizeof(om__bvh_node), 16) +
           om_arena_need(n * sizeof(uint32_t), 4);
}

size_t om__bvh_scratch_bytes(const om_scene *s)
{
    return om_arena_need((size_t)(s->ntris ? s->ntris : 1) * sizeof(box), 4);
}

typedef struct job { uint32_t node, first, count; } job;

/* A triangle's box: from the scratch array when the arena had room for it, else from
 * its vertices (slower, the same numbers). */
typedef struct boxes { const om_scene *s; const box *tb; } boxes;

static box tri_box(const boxes *bx, uint32_t t)
{
    if (bx->tb) return bx->tb[t];
    box r;
    box_empty(&r);
    for (int k = 0; k < 3; k++) {
        const om_vec3 *v = &bx->s->verts[bx->s->idx[3 * (size_t)t + k]];
        float p[3] = {v->x, v->y, v->z};
        box_grow(&r, p, p);
    }
    return r;
}

static float centre(const boxes *bx, uint32_t t, int axis)
{
    box b = tri_box(bx, t);
    return (b.lo[axis] + b.hi[axis]) * 0.5f;
}

/* A centroid as an integer whose unsigned order is the floats' order (-0 equal to +0,
 * as a float comparison has them; a NaN gets a place of its own). The quickselect
 * compares these keys: a float comparison need not give the same answer twice (with
 * x87 excess precision a centroid recomputed in a register and the pivot stored as a
 * float disagree, and the scans below ran past their sentinel forever), while the
 * bits of a stored float are what they are. */
static uint32_t centre_key(const boxes *bx, uint32_t t, int axis)
{
    float c = centre(bx, t, axis);
    uint32_t u;
    memcpy(&u, &c, sizeof u);
    if (u == 0x80000000u) u = 0;
    return u & 0x80000000u ? ~u : u | 0x80000000u;
}

/* Puts the k-th smallest centroid (along axis) of tris[0..n) at k: Hoare's quickselect.
 * The scans are also kept inside [lo, hi], so that [lo, hi] shrinks every round and
 * the loop ends whatever the keys say; with consistent keys the bounds never bind,
 * and the order is the one the float comparison gave on SSE. */
static void select_median(uint32_t *tris, const boxes *bx, uint32_t n, uint32_t k, int axis)
{
    uint32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        const uint32_t pivot = centre_key(bx, tris[lo + (hi - lo) / 2], axis);
        uint32_t i = lo, j = hi;
        while (i <= j) {
            while (i < hi && centre_key(bx, tris[i], axis) < pivot) i++;
            while (j > lo && centre_key(bx, tris[j], axis) > pivot) j--;
            if (i <= j) {
                uint32_t t = tris[i]; tris[i] = tris[j]; tris[j] = t;
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

om_status om__bvh_build(om__bvh *b, om_arena *a, const om_scene *s, uint32_t leaf, om_diag *d)
{
    void *pn, *pt, *pb;
    om_status st;
    size_t n = s->ntris ? s->ntris : 1;
    const uint32_t least = leaf / 2 ? leaf / 2 : 1;
    size_t cap = node_bound(n, leaf);
    memset(b, 0, sizeof *b);
    if ((st = om_arena_alloc(a, cap * sizeof(om__bvh_node), 16, &pn, d)) ||
        (st = om_arena_alloc(a, n * sizeof(uint32_t), 4, &pt, d)))
        return st;
    b->nodes = (om__bvh_node *)pn;
    b->tris = (uint32_t *)pt;
    size_t mark = om_arena_mark(a);
    boxes bx = {s, NULL};
    if (om_arena_left(a) >= om__bvh_scratch_bytes(s)) {
        if ((st = om_arena_alloc(a, n * sizeof(box), 4, &pb, d))) return st;
        box *tb = (box *)pb;
        for (uint32_t t = 0; t < s->ntris; t++) tb[t] = tri_box(&bx, t);
        bx.tb = tb;
    }
    for (uint32_t t = 0; t < s->ntris; t++) b->tris[t] = t;
    b->nnodes = 1;
    job stack[STACK];
    int sp = 0;
    stack[sp].node = 0; stack[sp].first = 0; stack[sp].count = s->ntris; sp++;
    uint32_t depth_of[STACK];
    depth_of[0] = 1;
    while (sp > 0) {
        job j = stack[--sp];
        uint32_t depth = depth_of[sp];
        if (depth > b->depth) b->depth = depth;
        om__bvh_node *nd = &b->nodes[j.node];
        box bb, cb;
        box_empty(&bb);
        box_empty(&cb);
        for (uint32_t i = j.first; i < j.first + j.count; i++) {
            box t = tri_box(&bx, b->tris[i]);
            float c[3];
            for (int k = 0; k < 3; k++) c[k] = (t.lo[k] + t.hi[k]) * 0.5f;
            box_grow(&bb, t.lo, t.hi);
            box_grow(&cb, c, c);
        }
        if (j.count == 0) { box_empty(&bb); for (int k = 0; k < 3; k++) bb.lo[k] = bb.hi[k] = 0; }
        memcpy(nd->lo, bb.lo, sizeof bb.lo);
        memcpy(nd->hi, bb.hi, sizeof bb.hi);
        nd->first = j.first;
        nd->count = j.count;
        if (j.count <= leaf || sp + 2 > STACK || b->nnodes + 2 > cap) continue;
        int axis = 0;
        for (int k = 1; k < 3; k++)
            if (cb.hi[k] - cb.lo[k] > cb.hi[axis] - cb.lo[axis]) axis = k;
        float ext = cb.hi[axis] - cb.lo[axis];
        uint32_t mid;
        if (ext > 0.0f) {
            /* Binned SAH: count and bound the triangles per bin, sweep both ways. */
            uint32_t cnt[BINS] = {0};
            box bin[BINS];
            for (int k = 0; k < BINS; k++) box_empty(&bin[k]);
            float scale = (float)BINS / ext;
            for (uint32_t i = j.first; i < j.first + j.count; i++) {
                box t = tri_box(&bx, b->tris[i]);
                float c = (t.lo[axis] + t.hi[axis]) * 0.5f;
                int k = (int)((c - cb.lo[axis]) * scale);
                k = k < 0 ? 0 : k >= BINS ? BINS - 1 : k;
                cnt[k]++;
                box_grow(&bin[k], t.lo, t.hi);
            }
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
                /* partition in place: bins <= split go left */
                uint32_t lo = j.first, hi = j.first + j.count;
                while (lo < hi) {
                    float cc = centre(&bx, b->tris[lo], axis);
                    int k = (int)((cc - cb.lo[axis]) * scale);
                    k = k < 0 ? 0 : k >= BINS ? BINS - 1 : k;
                    if (k <= split) lo++;
                    else { uint32_t tmp = b->tris[lo]; b->tris[lo] = b->tris[--hi]; b->tris[hi] = tmp; }
                }
                mid = lo;
            } else {
                mid = j.first;   /* no useful bin boundary: the median below */
            }
        } else {
            mid = j.first;       /* all centroids coincide: the median below splits by count */
        }
        if (mid < j.first + least || mid > j.first + j.count - least) {
            /* too small a child: split at the centroid median instead, which bounds the
             * node count by the leaf size */
            mid = j.first + j.count / 2;
            select_median(b->tris + j.first, &bx, j.count, j.count / 2, axis);
        }
        uint32_t child = b->nnodes;
        b->nnodes += 2;
        nd->first = child;
        nd->count = 0;
        stack[sp].node = child; stack[sp].first = j.first; stack[sp].count = mid - j.first;
        depth_of[sp++] = depth + 1;
        stack[sp].node = child + 1; stack[sp].first = mid; stack[sp].count = j.first + j.count - mid;
        depth_of[sp++] = depth + 1;
    }
    om_arena_rewind(a, mark);
    return OM_OK;
}

static bool hits(const om__bvh_node *n, const float o[3], const float inv[3], float tmax, float m)
{
    float t0 = 0.0f, t1 = tmax;
    for (int k = 0; k < 3; k++) {
        float a = (n->lo[k] - m - o[k]) * inv[k], b = (n->hi[k] + m - o[k]) * inv[k];
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
