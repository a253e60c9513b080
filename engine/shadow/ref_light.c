/* ref_light.c — the per-frame light-grid boxes of the reference's BVH, and the walks
 * over them (ref_light.h says why they filter exactly as om__lspace_maybe does). */
#include "ref_light.h"

/* As bvh.c's walk: the build splits a node only while its own stack has room, and a
 * walk that takes the children in the build's order (the second first) never holds
 * more than the build did. */
#define STACK 128

size_t om__lbvh_bytes(const om_scene *s, uint32_t leaf)
{
    return om_arena_need(om__bvh_nodes_max(s, leaf) * sizeof(om__lnode), 16) +
           om_arena_need((size_t)(s->ntris ? s->ntris : 1) * sizeof(om__lbox), 16);
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
    return OM_OK;
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

static void tri_box(om__lbox *x, const om__lspace *ls, uint32_t t)
{
    const uint32_t *ix = ls->scene->idx + (size_t)t * 3;
    box_none(x);
    for (int k = 0; k < 3; k++) {
        const om__lvert *v = &ls->verts[ix[k]];
        if (v->x == INT32_MIN) {   /* clipped: om__lspace_maybe passes it whatever p */
            x->lox = x->loy = INT32_MIN;
            x->hix = x->hiy = INT32_MAX;
            x->zmin = -1.0;        /* light depths are at least 0 */
            return;
        }
        om__lbox one = {v->x, v->y, v->x, v->y, v->z};
        box_union(x, &one);
    }
}

void om__lbvh_fit(om__lbvh *lb, const om__bvh *b, const om__lspace *ls)
{
    for (uint32_t i = 0; i < ls->scene->ntris; i++) tri_box(&lb->tris[i], ls, b->tris[i]);
    if (!ls->scene->ntris) {   /* the build's lone root has no children to read */
        box_none(&lb->nodes[0].box);
        lb->nodes[0].first = lb->nodes[0].count = 0;
        return;
    }
    /* A node's children come after it (the build appends them), so one pass from the
     * last node back sees both children of a node before the node. */
    for (uint32_t i = b->nnodes; i-- > 0;) {
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
