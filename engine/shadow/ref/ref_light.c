/* ref_light.c — the per-frame light-grid boxes of the reference's BVH, and the walks
 * over them (ref_light.h says why they pass every triangle that can block). */
#include "ref_light.h"

/* As bvh.c's walk: the build splits a node only while its own stack has room, and a
 * walk that takes the children in the build's order (the second first) never holds
 * more than the build did. */
#define STACK 128

size_t om__lbvh_bytes(const om_scene *s, uint32_t leaf)
{
    return om_arena_need(om__bvh_nodes_max(s, leaf) * sizeof(om__lnode), 16) +
           om_arena_need((size_t)(s->ntris ? s->ntris : 1) * sizeof(om__lbox), 16) +
           om_arena_need(OM__LBVH_PARTS * sizeof(om__lbvh_part), 4) +
           om_arena_need(OM__LBVH_PARTS * sizeof(uint32_t), 4);
}

om_status om__lbvh_init(om__lbvh *lb, om_arena *a, const om_scene *s, uint32_t leaf,
                        om_diag *d)
{
    void *p;
    om_status st;
    if ((st = om_arena_alloc(a, om__bvh_nodes_max(s, leaf) * sizeof(om__lnode), 16, &p, d)))
        return st;
    lb->nodes = (om__lnode *)p;
    if ((st = om_arena_alloc(a, (size_t)(s->ntris ? s->ntris : 1) * sizeof(om__lbox), 16, &p, d)))
        return st;
    lb->tris = (om__lbox *)p;
    if ((st = om_arena_alloc(a, OM__LBVH_PARTS * sizeof(om__lbvh_part), 4, &p, d))) return st;
    lb->parts = (om__lbvh_part *)p;
    if ((st = om_arena_alloc(a, OM__LBVH_PARTS * sizeof(uint32_t), 4, &p, d))) return st;
    lb->top = (uint32_t *)p;
    lb->nparts = lb->ntop = 0;
    return OM_OK;
}

/* A part smaller than this many nodes is not split further: a job of fewer costs
 * more to hand out than it saves. */
#define PART_LEAST 512

/* The part of node `at`: its descendants' indices (sz nodes under it, the greatest
 * index `last`) and its triangles' positions (the first leaf down its first children
 * to the last down its second: the build partitions a node's range between them). */
static bool part_of(const om__bvh *b, uint32_t at, uint32_t sz, uint32_t last, om__lbvh_part *p)
{
    p->node = at;
    p->lo = p->hi = 0;
    if (!b->nodes[at].count) {
        p->lo = b->nodes[at].first;
        p->hi = last + 1;
    }
    uint32_t i = at;
    while (!b->nodes[i].count) i = b->nodes[i].first;
    p->tlo = b->nodes[i].first;
    for (i = at; !b->nodes[i].count;) i = b->nodes[i].first + 1;
    p->thi = b->nodes[i].first + b->nodes[i].count;
    return p->hi - p->lo == sz - 1;   /* in the build's order, the descendants are these */
}

/* The objects' parts: the objects with triangles in runs of about equal triangle
 * counts, each a part of no node of its own (OM__LBVH_NONE) over their regions' nodes
 * and triangles (bvh.h: both contiguous in the objects' order); at most `most`, and
 * none smaller than a part is worth. The top level above them is fitted by
 * om__lbvh_fit_top. */
static void plan_objects(om__lbvh *lb, const om__bvh *b, uint32_t nobjects, uint32_t most)
{
    uint32_t want = 1 + b->obj_count / (2 * PART_LEAST);
    if (want > most) want = most;
    uint32_t i = 0;
    for (uint32_t k = 0; k < want && i < nobjects; k++) {
        const uint32_t upto = (uint32_t)((uint64_t)b->obj_count * (k + 1) / want), at = i;
        while (i < nobjects && (k + 1 == want || b->obj_tri[i + 1] - b->obj_first <= upto)) i++;
        if (i == at) i++;   /* one object more than the share: a part of it alone */
        if (b->obj_tri[i] == b->obj_tri[at]) continue;   /* none with triangles */
        om__lbvh_part *p = &lb->parts[lb->nparts++];
        p->node = OM__LBVH_NONE;
        p->lo = b->obj_node[at];
        p->hi = b->obj_node[i];
        p->tlo = b->obj_tri[at];
        p->thi = b->obj_tri[i];
    }
}

void om__lbvh_plan(om__lbvh *lb, const om__bvh *b, uint32_t nobjects)
{
    uint32_t size[OM__LBVH_PARTS];
    om__lnode *sc = lb->nodes;
    lb->nparts = lb->ntop = 0;
    lb->top_first = lb->top_end = 0;
    if (!b->nnodes || (!b->nodes[0].count && !b->nodes[0].first))
        return;   /* an empty scene's lone root: om__lbvh_fit_top's */
    /* The nodes as scratch until the first fit: how many nodes each has under it
     * (itself included) in count, the greatest index among them in first. */
    for (uint32_t i = b->nnodes; i-- > 0;) {
        const om__bvh_node *n = &b->nodes[i];
        sc[i].count = 1;
        sc[i].first = i;
        if (n->count) continue;
        const om__lnode *c0 = &sc[n->first], *c1 = &sc[n->first + 1];
        sc[i].count += c0->count + c1->count;
        sc[i].first = c0->first > c1->first ? c0->first : c1->first;
    }
    /* Two levels (bvh.h): the objects' parts, the static subtree's split as one
     * level's root, and above them node 2, 1 where not a part, and the root. */
    uint32_t start = 0, most = OM__LBVH_PARTS, k0 = 0;
    if (b->obj_node) {
        const uint32_t share = (uint32_t)((uint64_t)OM__LBVH_PARTS * b->obj_count /
                                          (b->obj_count + b->obj_first));
        plan_objects(lb, b, nobjects, share < 1 ? 1 : share > OM__LBVH_PARTS - 4 ? OM__LBVH_PARTS - 4 : share);
        lb->top_first = b->top_first;
        lb->top_end = b->top_end;
        lb->top[lb->ntop++] = 0;
        lb->top[lb->ntop++] = 2;
        if (!b->obj_first) {
            lb->top[lb->ntop++] = 1;   /* a spare (bvh.c's build_top) */
            return;
        }
        start = 1;
        k0 = lb->nparts;
        most = OM__LBVH_PARTS - 2 - lb->nparts;   /* the top's 0 and 2 and a split's each */
    }
    if (!part_of(b, start, sc[start].count, sc[start].first, &lb->parts[k0])) {
        /* not in the build's order: the static nodes as one part */
        if (start) {
            om__lbvh_part *p = &lb->parts[lb->nparts++];
            p->node = 1;
            p->lo = 3;
            p->hi = b->top_first;
            p->tlo = 0;
            p->thi = b->obj_first;
        }
        return;
    }
    size[k0] = sc[start].count;
    lb->nparts = k0 + 1;
    /* The largest part splits into its children while there is room: the node above
     * them joins the top. */
    while (lb->nparts - k0 < most) {
        uint32_t k = k0;
        for (uint32_t i = k0 + 1; i < lb->nparts; i++)
            if (size[i] > size[k]) k = i;
        const uint32_t at = lb->parts[k].node, c = b->nodes[at].first;
        om__lbvh_part p[2];
        if (size[k] < 2 * PART_LEAST || b->nodes[at].count ||
            !part_of(b, c, sc[c].count, sc[c].first, &p[0]) ||
            !part_of(b, c + 1, sc[c + 1].count, sc[c + 1].first, &p[1]))
            break;
        for (uint32_t i = lb->nparts; i > k + 1; i--) {   /* the second child beside the first */
            lb->parts[i] = lb->parts[i - 1];
            size[i] = size[i - 1];
        }
        lb->parts[k] = p[0];
        size[k] = sc[c].count;
        lb->parts[k + 1] = p[1];
        size[k + 1] = sc[c + 1].count;
        lb->nparts++;
        lb->top[lb->ntop++] = at;
    }
}

static void box_none(om__lbox *x)
{
    x->lox = x->loy = INT32_MAX;
    x->hix = x->hiy = INT32_MIN;
    x->zmin = OM_DEPTH_ONE;   /* beyond every depth */
}

static void box_union(om__lbox *x, const om__lbox *a)
{
    if (a->lox < x->lox) x->lox = a->lox;
    if (a->loy < x->loy) x->loy = a->loy;
    if (a->hix > x->hix) x->hix = a->hix;
    if (a->hiy > x->hiy) x->hiy = a->hiy;
    if (a->zmin < x->zmin) x->zmin = a->zmin;
}

static int32_t to_i32(int64_t v)
{
    return v < INT32_MIN ? INT32_MIN : v > INT32_MAX ? INT32_MAX : (int32_t)v;
}

/* A triangle with a vertex that needs clipping has no projected vertices to bound
 * it, so its box is that of what clipping leaves of it (om__lspace_tri, once a
 * frame): a sample it blocks is covered by one of its sub-triangles, so inside their
 * grid bounds, and is farther than that sub-triangle's nearest depth plus its bound, so
 * farther than lt.zmin (om__blocks). Nothing left inside the light's frustum: no box,
 * it blocks nothing. Without this a clipped floor's box, and every box above it, would
 * hold every sample. */
static void clipped_box(om__lbox *x, const om__lspace *ls, uint32_t t)
{
    om__ltri lt;
    box_none(x);
    if (!om__lspace_tri(ls, t, &lt)) return;
    x->lox = to_i32(lt.lox);
    x->loy = to_i32(lt.loy);
    x->hix = to_i32(lt.hix);
    x->hiy = to_i32(lt.hiy);
    x->zmin = lt.zmin;
}

static void tri_box(om__lbox *x, const om__lspace *ls, uint32_t t)
{
    const uint32_t *ix = ls->scene->idx + (size_t)t * 3;
    box_none(x);
    for (int k = 0; k < 3; k++) {
        const om__lvert *v = &ls->verts[ix[k]];
        if (v->x == INT32_MIN) {
            clipped_box(x, ls, t);
            return;
        }
        om__lbox one = {v->x, v->y, v->x, v->y, v->z};
        box_union(x, &one);
    }
}

/* Nodes [lo, hi) from the last back (a node's children come after it: the build
 * appends them, so both are fitted before the node), from their children's boxes or
 * their triangles'. */
static void fit_nodes(om__lbvh *lb, const om__bvh *b, uint32_t lo, uint32_t hi)
{
    for (uint32_t i = hi; i-- > lo;) {
        om__lnode *n = &lb->nodes[i];
        n->first = b->nodes[i].first;
        n->count = b->nodes[i].count;
        box_none(&n->box);
        if (n->count) {
            for (uint32_t k = n->first; k < n->first + n->count; k++) box_union(&n->box, &lb->tris[k]);
        } else {
            box_union(&n->box, &lb->nodes[n->first].box);
            box_union(&n->box, &lb->nodes[n->first + 1].box);
        }
    }
}

void om__lbvh_fit_part(om__lbvh *lb, const om__bvh *b, const om__lspace *ls, uint32_t k)
{
    const om__lbvh_part *p = &lb->parts[k];
    for (uint32_t t = p->tlo; t < p->thi; t++) tri_box(&lb->tris[t], ls, b->tris[t]);
    fit_nodes(lb, b, p->lo, p->hi);
    if (p->node != OM__LBVH_NONE) fit_nodes(lb, b, p->node, p->node + 1);
}

void om__lbvh_fit_top(om__lbvh *lb, const om__bvh *b, const om__lspace *ls)
{
    if (!ls->scene->ntris) {   /* the build's lone root has no children to read */
        box_none(&lb->nodes[0].box);
        lb->nodes[0].first = lb->nodes[0].count = 0;
        return;
    }
    fit_nodes(lb, b, lb->top_first, lb->top_end);   /* two levels: above the objects' parts */
    for (uint32_t i = lb->ntop; i-- > 0;) fit_nodes(lb, b, lb->top[i], lb->top[i] + 1);
}

void om__lbvh_fit(om__lbvh *lb, const om__bvh *b, const om__lspace *ls)
{
    for (uint32_t k = 0; k < lb->nparts; k++) om__lbvh_fit_part(lb, b, ls, k);
    om__lbvh_fit_top(lb, b, ls);
}

/* & rather than &&: one branch on the whole test, whose parts are as hard to predict
 * as they are cheap to compute */
static bool holds(const om__lbox *x, const om__lpoint *p)
{
    return (p->x >= x->lox) & (p->x <= x->hix) & (p->y >= x->loy) & (p->y <= x->hiy) &
           (x->zmin < p->z);
}

static bool meets(const om__lbox *x, const om__lrect *q)
{
    return (q->lox <= x->hix) & (q->hix >= x->lox) & (q->loy <= x->hiy) & (q->hiy >= x->loy) &
           (x->zmin < q->zmax);
}

/* The triangles of one leaf whose own box holds p; true when visit stopped the walk. */
static bool leaf(const om__lbvh *lb, const om__bvh *b, const om__lnode *n, const om__lpoint *p,
                 om__bvh_visit visit, void *user)
{
    for (uint32_t i = n->first; i < n->first + n->count; i++)
        if (holds(&lb->tris[i], p) && visit(user, b->tris[i])) return true;
    return false;
}

/* The triangles under node `at` whose box holds p; true when visit stopped the walk. */
static bool walk_from(const om__lbvh *lb, const om__bvh *b, uint32_t at, const om__lpoint *p,
                      om__bvh_visit visit, void *user)
{
    const om__lnode *ln = lb->nodes;
    uint32_t stack[STACK];
    int sp = 0;
    stack[sp++] = at;
    while (sp > 0) {
        const om__lnode *n = &ln[stack[--sp]];
        if (n->count) {
            if (leaf(lb, b, n, p, visit, user)) return true;
            continue;
        }
        /* the children are tested here, so only those that hold p are pushed */
        if (holds(&ln[n->first].box, p)) stack[sp++] = n->first;
        if (holds(&ln[n->first + 1].box, p)) stack[sp++] = n->first + 1;
    }
    return false;
}

uint32_t om__lbvh_narrow(const om__lbvh *lb, const uint32_t *in, uint32_t n, const om__lrect *q,
                         uint32_t *out, uint32_t cap, bool *open)
{
    const om__lnode *ln = lb->nodes;
    uint32_t m = 0;
    for (uint32_t k = 0; k < n && m < cap; k++)
        if (meets(&ln[in[k]].box, q)) out[m++] = in[k];
    *open = false;
    for (uint32_t i = 0; i < m;) {
        const om__lnode *nd = &ln[out[i]];
        if (nd->count) { i++; continue; }
        bool a = meets(&ln[nd->first].box, q), c = meets(&ln[nd->first + 1].box, q);
        if (a && c) {
            if (m == cap) { *open = true; i++; continue; }   /* no room: left whole */
            out[i] = nd->first;
            out[m++] = nd->first + 1;
        } else if (a || c) {
            out[i] = a ? nd->first : nd->first + 1;
        } else {
            out[i] = out[--m];   /* neither child meets q: gone (the order is free) */
        }
    }
    return m;
}

void om__lbvh_walk_list(const om__lbvh *lb, const om__bvh *b, const uint32_t *list, uint32_t n,
                        const om__lpoint *p, om__bvh_visit visit, void *user)
{
    for (uint32_t k = 0; k < n; k++) {
        const om__lnode *nd = &lb->nodes[list[k]];
        if (!holds(&nd->box, p)) continue;
        if (nd->count ? leaf(lb, b, nd, p, visit, user) : walk_from(lb, b, list[k], p, visit, user))
            return;
    }
}

/* ---- the middle mode: the BVH's own nodes on the grid */

static void gbox_grow(om__bvh_gbox *x, const om__bvh_gbox *a)
{
    if (a->lox < x->lox) x->lox = a->lox;
    if (a->loy < x->loy) x->loy = a->loy;
    if (a->hix > x->hix) x->hix = a->hix;
    if (a->hiy > x->hiy) x->hiy = a->hiy;
    if (a->zmin < x->zmin) x->zmin = a->zmin;
}

/* The grid box of a leaf's triangles: their projected vertices', or for one that needs
 * clipping what is left of it (clipped_box). */
static om__bvh_gbox leaf_gbox(const om__bvh *b, const om__bvh_node *n, const om__lspace *ls)
{
    om__bvh_gbox g = {INT32_MAX, INT32_MAX, INT32_MIN, INT32_MIN, UINT32_MAX, 0};
    for (uint32_t k = n->first; k < n->first + n->count; k++) {
        const uint32_t *ix = ls->scene->idx + (size_t)b->tris[k] * 3;
        const om__lvert *v[3] = {&ls->verts[ix[0]], &ls->verts[ix[1]], &ls->verts[ix[2]]};
        if (v[0]->x == INT32_MIN || v[1]->x == INT32_MIN || v[2]->x == INT32_MIN) {
            om__lbox x;
            clipped_box(&x, ls, b->tris[k]);
            /* rounded down, as a sample's depth is a whole number */
            const double z = floor(x.zmin);
            const om__bvh_gbox one = {x.lox, x.loy, x.hix, x.hiy,
                                      z < 0.0 ? 0u : z < 4294967295.0 ? (uint32_t)z : UINT32_MAX, 0};
            gbox_grow(&g, &one);
            continue;
        }
        for (int c = 0; c < 3; c++) {
            const om__bvh_gbox one = {v[c]->x, v[c]->y, v[c]->x, v[c]->y, v[c]->z, 0};
            gbox_grow(&g, &one);
        }
    }
    return g;
}

void om__bvh_fit_grid(om__bvh *b, const om__lspace *ls)
{
    /* Children come after their node (the build appends them): one pass from the last
     * node back bounds both children of a node before the node. */
    for (uint32_t i = b->nnodes; i-- > 0;) {
        om__bvh_node *n = &b->nodes[i];
        if (n->count || !ls->scene->ntris) {   /* a leaf, or an empty scene's lone root */
            n->box.g = leaf_gbox(b, n, ls);
        } else {
            om__bvh_gbox g = b->nodes[n->first].box.g;
            gbox_grow(&g, &b->nodes[n->first + 1].box.g);
            n->box.g = g;
        }
    }
}

/* All in 32 bits, which a small chip compares in one instruction; && rather than the
 * one-pass walk's &: this walk is the small chips' (short pipelines, no prediction to
 * miss), where most boxes fail the first or second compare. */
static bool gholds(const om__bvh_gbox *x, int32_t px, int32_t py, uint32_t pz)
{
    return px >= x->lox && px <= x->hix && py >= x->loy && py <= x->hiy && x->zmin < pz;
}

/* The grid-box test (ref_light.h) in 32 bits: false when triangle t's projected vertices leave p
 * outside their grid box, or are none nearer than p; true for one that needs clipping
 * (its leaf's box has bounded it). */
static bool tri_maybe(const om__lspace *ls, uint32_t t, int32_t px, int32_t py, uint32_t pz)
{
    const uint32_t *ix = ls->scene->idx + (size_t)t * 3;
    const om__lvert *a = &ls->verts[ix[0]], *b = &ls->verts[ix[1]], *c = &ls->verts[ix[2]];
    if (a->x == INT32_MIN || b->x == INT32_MIN || c->x == INT32_MIN) return true;
    if ((px < a->x && px < b->x && px < c->x) || (px > a->x && px > b->x && px > c->x) ||
        (py < a->y && py < b->y && py < c->y) || (py > a->y && py > b->y && py > c->y))
        return false;
    return a->z < pz || b->z < pz || c->z < pz;
}

void om__bvh_walk_grid(const om__bvh *b, const om__lspace *ls, const om__lpoint *p, uint32_t pz,
                       om__bvh_visit visit, void *user)
{
    const om__bvh_node *nd = b->nodes;
    /* A point beyond 32 bits is held by no box but those that reach that far, as its
     * clamped value is (boxes are clamped the same way). */
    const int32_t px = to_i32(p->x), py = to_i32(p->y);
    uint32_t stack[STACK];
    int sp = 0;
    if (!b->nnodes || !gholds(&nd[0].box.g, px, py, pz)) return;
    stack[sp++] = 0;
    while (sp > 0) {
        const om__bvh_node *n = &nd[stack[--sp]];
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++)
                if (tri_maybe(ls, b->tris[i], px, py, pz) && visit(user, b->tris[i])) return;
            continue;
        }
        /* the children are tested here, so only those that hold p are pushed */
        if (gholds(&nd[n->first].box.g, px, py, pz)) stack[sp++] = n->first;
        if (gholds(&nd[n->first + 1].box.g, px, py, pz)) stack[sp++] = n->first + 1;
    }
}
