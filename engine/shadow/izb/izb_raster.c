/* izb_raster.c — stage 3 of the irregular z-buffer (izb.c has the method, the
 * transform and the BSP): every triangle rasterized through a tile's BSP, entering
 * only the nodes its footprint can touch that still hold an open sample farther than
 * it, each sample in a leaf tested with the shared occlusion predicate. With the
 * frame's grid (lgrid.h) a tile walks only the triangles near its samples. */
#include "izb.h"

#define DIRECT 16   /* most cells a triangle's bounds may cover to be sent to them directly */

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

/* One triangle on its way through the tree: its setup, its optical depth, and the
 * range of Z-order codes of its bounds (clamped to the tile's): a key inside the
 * bounds has a code in [clo, chi], as the code grows with x and with y. */
typedef struct tjob {
    const om__ltri *lt;
    const om__odepth *od;
    uint32_t clo, chi;
} tjob;

/* Returns how many samples of the subtree became opaque-shadowed. */
static uint32_t visit(om__izb *z, uint32_t ni, const tjob *j)
{
    om__izb_node *nd = &z->nodes[ni];
    const om__ltri *lt = j->lt;
    z->st.visited++;
    if (nd->open == 0) { z->st.culled_shadowed++; return 0; }
    if (lt->zmin >= (double)nd->zmax) { z->st.culled_depth++; return 0; }
    uint32_t first = nd->first, end = first + nd->count;
    if (z->keys[first].code > j->chi || z->keys[end - 1].code < j->clo || !box_touches(lt, nd)) return 0;
    uint32_t closed = 0;
    if (nd->child) {
        closed = visit(z, nd->child, j) + visit(z, nd->child + 1, j);
    } else {
        while (end - first > 1) {   /* the first key whose code can be in the bounds */
            uint32_t mid = first + (end - first) / 2;
            if (z->keys[mid - 1].code < j->clo) first = mid;
            else end = mid;
        }
        for (uint32_t i = first; i < nd->first + nd->count && z->keys[i].code <= j->chi; i++) {
            om__izb_key *k = &z->keys[i];
            if ((k->s & OM_IZB_DONE) || k->x < lt->lox || k->x > lt->hix || k->y < lt->loy ||
                k->y > lt->hiy)
                continue;
            om__lpoint p = {k->x, k->y, (double)k->z, k->tri};
            z->st.tested++;
            if (!om__blocks(lt, &p)) continue;
            if (!(k->s & OM_IZB_PULLED)) {   /* the first blocker of the unpulled depth */
                k->s |= OM_IZB_PULLED;
                k->z = om__lspace_pull(&z->ls, &z->facet, k->tri, k->z);
                p.z = k->z;
                if (!om__blocks(lt, &p)) continue;
            }
            z->st.blocked++;
            om__odepth_add(&z->od[i], j->od);
            if (om__odepth_opaque(&z->od[i])) {
                k->s |= OM_IZB_DONE;
                closed++;
            }
        }
    }
    nd->open -= closed;
    return closed;
}

/* Visits a cell's node and takes the samples it closed off the counts above it. */
static void visit_cell(om__izb *z, uint32_t ni, const tjob *j)
{
    uint32_t closed = visit(z, ni, j);
    if (closed)
        for (uint32_t p = z->nodes[ni].parent; p != OM_IZB_NONE; p = z->nodes[p].parent)
            z->nodes[p].open -= closed;
}

/* The grid cells that the grid bounds [lox, hix] x [loy, hiy] can reach; false when
 * they miss the tile's keys. */
typedef struct crange { uint32_t x0, y0, x1, y1; } crange;

static bool cell_range(const om__izb *z, int64_t lox, int64_t loy, int64_t hix, int64_t hiy, crange *c)
{
    if (hix < z->kx0 || lox > z->kx1 || hiy < z->ky0 || loy > z->ky1) return false;
    if (lox < z->kx0) lox = z->kx0;
    if (loy < z->ky0) loy = z->ky0;
    if (hix > z->kx1) hix = z->kx1;
    if (hiy > z->ky1) hiy = z->ky1;
    c->x0 = (uint32_t)((lox - z->kx0) >> z->gshift);
    c->x1 = (uint32_t)((hix - z->kx0) >> z->gshift);
    c->y0 = (uint32_t)((loy - z->ky0) >> z->gshift);
    c->y1 = (uint32_t)((hiy - z->ky0) >> z->gshift);
    return true;
}

/* The codes of a triangle's bounds; false when the bounds miss the tile's keys. */
static bool codes_of(const om__izb *z, const om__ltri *lt, tjob *j)
{
    if (lt->hix < z->kx0 || lt->lox > z->kx1 || lt->hiy < z->ky0 || lt->loy > z->ky1) return false;
    om__izb_key lo, hi;
    lo.x = (int32_t)(lt->lox > z->kx0 ? lt->lox : z->kx0);
    lo.y = (int32_t)(lt->loy > z->ky0 ? lt->loy : z->ky0);
    hi.x = (int32_t)(lt->hix < z->kx1 ? lt->hix : z->kx1);
    hi.y = (int32_t)(lt->hiy < z->ky1 ? lt->hiy : z->ky1);
    j->clo = om__izb_zcode(&lo, z->kx0, z->ky0, z->zshift);
    j->chi = om__izb_zcode(&hi, z->kx0, z->ky0, z->zshift);
    return true;
}

static uint32_t cell_at(const om__izb *z, uint32_t cx, uint32_t cy)
{
    return z->cells[om__izb_zcode_xy(cx, cy)];
}

/* Could a triangle whose projected vertices have bounds [lox, hix] x [loy, hiy] and
 * nearest depth zlo block a sample of node ni's subtree? Only an open sample inside
 * those bounds and farther than zlo: the culls visit() and the predicate make, before
 * any setup (which, clipping and projecting in double, costs a Cortex-M4 far more). */
typedef struct vbox { int32_t lox, loy, hix, hiy; uint32_t zlo, clo, chi; } vbox;

static bool reaches(const om__izb *z, uint32_t ni, const vbox *b)
{
    const om__izb_node *nd = &z->nodes[ni];
    if (!nd->open || b->zlo >= nd->zmax || b->lox > nd->x1 || b->hix < nd->x0 || b->loy > nd->y1 ||
        b->hiy < nd->y0)
        return false;
    if (nd->child) return reaches(z, nd->child, b) || reaches(z, nd->child + 1, b);
    uint32_t first = nd->first, end = first + nd->count;
    if (z->keys[first].code > b->chi || z->keys[end - 1].code < b->clo) return false;
    while (end - first > 1) {   /* the first key whose code can be in the bounds (as visit) */
        uint32_t mid = first + (end - first) / 2;
        if (z->keys[mid - 1].code < b->clo) first = mid;
        else end = mid;
    }
    for (const om__izb_key *k = &z->keys[first], *e = &z->keys[nd->first + nd->count]; k < e && k->code <= b->chi; k++)
        if (!(k->s & OM_IZB_DONE) && b->zlo < k->z && k->x >= b->lox && k->x <= b->hix && k->y >= b->loy &&
            k->y <= b->hiy)
            return true;
    return false;
}

/* The box's codes (its corners clamped to the tile's keys, which it meets). */
static void vbox_codes(const om__izb *z, vbox *b)
{
    om__izb_key lo, hi;
    lo.x = b->lox > z->kx0 ? b->lox : z->kx0;
    lo.y = b->loy > z->ky0 ? b->loy : z->ky0;
    hi.x = b->hix < z->kx1 ? b->hix : z->kx1;
    hi.y = b->hiy < z->ky1 ? b->hiy : z->ky1;
    b->clo = om__izb_zcode(&lo, z->kx0, z->ky0, z->zshift);
    b->chi = om__izb_zcode(&hi, z->kx0, z->ky0, z->zshift);
}

/* A triangle whose bounds cover at most DIRECT cells goes straight to their nodes;
 * with its projected vertices at hand (no clipping), the nodes are first checked
 * against the vertices' bounds and nearest depth, so that a triangle over no open,
 * farther sample costs no setup. Any other triangle descends the tree from its root.
 * Both reach every sample inside the triangle's bounds once: the cells part the
 * tile's keys. */
OM_INLINE void cast(om__izb *z, uint32_t t)
{
    const om_scene *sc = z->scene;
    const om__izb_node *root = &z->nodes[0];
    const uint32_t *ix = sc->idx + (size_t)t * 3;
    const om__lvert *a = z->ls.verts ? &z->ls.verts[ix[0]] : NULL;
    const om__lvert *b = a ? &z->ls.verts[ix[1]] : NULL, *c = a ? &z->ls.verts[ix[2]] : NULL;
    const om__odepth *od = &z->mat_od[sc->tri_mat[t]];
    crange cr;
    uint32_t hit[DIRECT];
    int nhit = -1;   /* -1: not sorted out before setup */
    if (a && a->x != INT32_MIN && b->x != INT32_MIN && c->x != INT32_MIN) {
        /* The plane's depth lies within its vertices', and the triangle's bounds are
         * its vertices': the same culls visit() makes, before any setup. */
        const om__lvbox lb = om__lvert_box(a, b, c);
        if (lb.z >= root->zmax || !cell_range(z, lb.lox, lb.loy, lb.hix, lb.hiy, &cr)) return;
        vbox vb = {lb.lox, lb.loy, lb.hix, lb.hiy, lb.z, 0, 0};
        if ((uint64_t)(cr.x1 - cr.x0 + 1) * (cr.y1 - cr.y0 + 1) <= DIRECT) {
            nhit = 0;
            for (uint32_t cy = cr.y0; cy <= cr.y1; cy++)
                for (uint32_t cx = cr.x0; cx <= cr.x1; cx++) {
                    uint32_t ni = cell_at(z, cx, cy);
                    if (ni == OM_IZB_NONE) continue;
                    const om__izb_node *nd = &z->nodes[ni];
                    if (nd->open && lb.z < nd->zmax && lb.lox <= nd->x1 && lb.hix >= nd->x0 &&
                        lb.loy <= nd->y1 && lb.hiy >= nd->y0)
                        hit[nhit++] = ni;
                }
            if (nhit == 0) return;
            /* and then by their samples */
            vbox_codes(z, &vb);
            int i = 0;
            while (i < nhit && !reaches(z, hit[i], &vb)) i++;
            if (i == nhit) return;
        } else {
            vbox_codes(z, &vb);
            if (!reaches(z, 0, &vb)) return;
        }
    }
    om__ltri lt;
    tjob j = {&lt, od, 0, 0};
    if (!om__lspace_tri(&z->ls, t, &lt) || !codes_of(z, &lt, &j)) return;
    if (nhit < 0 && cell_range(z, lt.lox, lt.loy, lt.hix, lt.hiy, &cr) &&
        (uint64_t)(cr.x1 - cr.x0 + 1) * (cr.y1 - cr.y0 + 1) <= DIRECT) {
        nhit = 0;
        for (uint32_t cy = cr.y0; cy <= cr.y1; cy++)
            for (uint32_t cx = cr.x0; cx <= cr.x1; cx++) {
                uint32_t ni = cell_at(z, cx, cy);
                if (ni != OM_IZB_NONE) hit[nhit++] = ni;
            }
    }
    if (nhit < 0) {
        visit(z, 0, &j);
    } else {
        for (int i = 0; i < nhit; i++) visit_cell(z, hit[i], &j);
    }
}

/* Every triangle in the scene's order, or with the frame's grid only those whose
 * vertices' box meets a cell of the tile's samples (and those it lists for every
 * tile), still in the scene's order: any other would leave cast() before its setup, as
 * its box holds no sample, and without a count, so the counts are the same. */
void om__izb_raster(om__izb *z)
{
    if (z->nnodes == 0) return;
    const om__izb_node *root = &z->nodes[0];
    const om__lgrid *g = z->grid;
    const uint32_t *tm = NULL;
    if (g && g->ready == 1) {   /* (not when this frame's lists were too long for it) */
        om__lgrid_clear(g, z->sel);
        for (uint32_t i = 0; i < z->n; i++) om__lgrid_mark(g, z->sel, z->keys[i].x, z->keys[i].y);
        om__lgrid_select(g, z->sel);
        tm = om__lgrid_tris(g, z->sel);
    }
    /* One walk for both: without the selection, every bit of every word. */
    const uint32_t n = z->scene->ntris, words = (n + 31) / 32;
    for (uint32_t w = 0; w < words && root->open; w++) {
        uint32_t bits = tm ? tm[w] : w + 1 < words || !(n & 31) ? ~0u : (1u << (n & 31)) - 1;
        for (; bits && root->open; bits &= bits - 1) cast(z, w * 32 + (uint32_t)om__ctz32(bits));
    }
}
