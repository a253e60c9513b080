/* spsm_outline.c — the silhouette that SPSM's recovery (paper 004, section 4.2,
 * Figure 10) rebuilds for an uncertain sample from the occluders its depth-test
 * pattern keeps: their vertices, linked into pieces where they lie on one surface, and
 * each piece's convex hull, against which the sample (and each AA sub-sample) is
 * tested. The pattern, the occluders and the decisions around it are in spsm.c. */
#include "spsm_lookup.h"

/* Twice the signed area of (o, a, b): > 0 when b lies left of o -> a. Exact: points
 * stay below 2^27 (spsm_lookup.h), so differences fit 32 bits and their products,
 * taken 32 by 32 bits (one multiply on a 32-bit CPU), stay below 2^56. */
static int64_t turn(int32_t ox, int32_t oy, int32_t ax, int32_t ay, int32_t bx, int32_t by)
{
    return (int64_t)(ax - ox) * (by - oy) - (int64_t)(ay - oy) * (bx - ox);
}

/* Each piece's convex hull (Andrew's monotone chain on its points sorted by x, then
 * y), built once per boundary so that every test point costs one pass over it. */
static void hulls_build(om__spsm_boundary *b)
{
    b->nh = 0;
    b->hoff[0] = 0;
    int used = 0;
    for (int pc = 0; pc < b->nv; pc++) {
        if (b->piece[pc] != pc) continue;   /* a piece is labelled by its first vertex */
        int32_t px[OM__SPSM_MAXV], py[OM__SPSM_MAXV];
        int n = 0;
        for (int i = 0; i < b->nv; i++) {
            if (b->piece[i] != pc) continue;
            int j = n++;
            for (; j > 0 && (px[j - 1] > b->x[i] || (px[j - 1] == b->x[i] && py[j - 1] > b->y[i])); j--) {
                px[j] = px[j - 1];
                py[j] = py[j - 1];
            }
            px[j] = b->x[i];
            py[j] = b->y[i];
        }
        if (n < 3) continue;
        int32_t *hx = b->hx + used, *hy = b->hy + used;
        int32_t cx[2 * OM__SPSM_MAXV], cy[2 * OM__SPSM_MAXV];   /* the chain; its last point repeats the first */
        int k = 0;
        for (int i = 0; i < n; i++) {         /* lower chain */
            while (k >= 2 && turn(cx[k - 2], cy[k - 2], cx[k - 1], cy[k - 1], px[i], py[i]) <= 0) k--;
            cx[k] = px[i]; cy[k] = py[i]; k++;
        }
        for (int i = n - 2, lo = k + 1; i >= 0; i--) {   /* upper chain */
            while (k >= lo && turn(cx[k - 2], cy[k - 2], cx[k - 1], cy[k - 1], px[i], py[i]) <= 0) k--;
            cx[k] = px[i]; cy[k] = py[i]; k++;
        }
        if (k - 1 < 3) continue;               /* all on one line: no inside */
        for (int i = 0; i < k - 1; i++) { hx[i] = cx[i]; hy[i] = cy[i]; }
        used += k - 1;
        b->nh++;
        b->hoff[b->nh] = (uint8_t)used;
    }
}

/* The recovered silhouette (section 4.2, Figure 10), built once per texel and pattern so
 * that AA sub-samples reuse it (section 5). Its points are the vertices of the
 * occluders the pattern keeps. Two are linked when they belong to one stored triangle,
 * or lie within OM_SPSM_LINK of each other on one smooth surface (the plane of one's
 * triangle, carried to the other, meets the other's within OM__SPSM_LINK_DZ): a gap that narrow
 * is taken for geometry the map could not keep, as a dense mesh keeps one small
 * triangle per texel (Figure 10a), while a cloud of separate small triangles does not
 * line up and stays apart. Links join the points into pieces; a piece's outline is the
 * convex hull of its points. Where the paper links the lit-side vertices along the
 * tangent into phi and shadows everything beyond it, the hull also closes the piece
 * on its far side, so two thin occluders a texel or more apart (a fence) do not shadow
 * the gap between them (see spsm.md: the one-sided phi measured worse). */
/* The pieces as a union-find over the occluders (at most nine): a vertex's piece is
 * its triangles', and every link joins two occluders' sets. */
static int root(uint8_t up[9], int k)
{
    while (up[k] != k) k = up[k] = up[up[k]];
    return k;
}

/* Joins the sets of occluders a and c; returns 1 when they were apart. */
static int unite(uint8_t up[9], int a, int c)
{
    a = root(up, a);
    c = root(up, c);
    if (a == c) return 0;
    up[a > c ? a : c] = (uint8_t)(a < c ? a : c);
    return 1;
}

void om__spsm_outline_build(om__spsm_boundary *b, const om__spsm_dtri *const occ[9], int nocc)
{
    uint8_t owner[OM__SPSM_MAXV];         /* the first occluder with this vertex */
    uint8_t up[9];
    int sets = nocc;
    b->nv = 0;
    for (int k = 0; k < nocc; k++) {
        up[k] = (uint8_t)k;
        for (int i = 0; i < 3; i++) {
            const int32_t x = (int32_t)occ[k]->e.x[i], y = (int32_t)occ[k]->e.y[i];
            int j = 0;
            while (j < b->nv && (b->x[j] != x || b->y[j] != y)) j++;
            if (j == b->nv) { b->x[j] = x; b->y[j] = y; owner[j] = (uint8_t)k; b->nv++; }
            else sets -= unite(up, owner[j], k);   /* a shared vertex: one piece */
            if (i == 0) b->first[k] = (uint8_t)j;
        }
    }
    for (int i = 0; i < b->nv && sets > 1; i++)   /* (one piece: nothing to link) */
        for (int j = i + 1; j < b->nv; j++) {
            const int32_t dx = b->x[j] - b->x[i], dy = b->y[j] - b->y[i];
            if (dx > OM_SPSM_LINK || dx < -OM_SPSM_LINK || dy > OM_SPSM_LINK || dy < -OM_SPSM_LINK) continue;
            if (root(up, owner[i]) == root(up, owner[j])) continue;   /* joined already */
            /* one surface: i's triangle's plane, carried to j, meets j's triangle there
             * (a smooth mesh bends little over a texel; a cloud of separate triangles
             * does not line up) */
            const om__spsm_dtri *a = occ[owner[i]], *c = occ[owner[j]];
            const float za = om__spsm_plane_at_f(a, b->x[j], b->y[j]), zc = om__spsm_plane_at_f(c, b->x[j], b->y[j]);
            if (om__fabsf(za - zc) > om__spsm_tol_at_f(a, b->x[j], b->y[j]) + (float)OM__SPSM_LINK_DZ) continue;
            sets -= unite(up, owner[i], owner[j]);
        }
    /* A piece is labelled by its first vertex. */
    int8_t label[9];
    for (int k = 0; k < nocc; k++) label[k] = -1;
    for (int i = 0; i < b->nv; i++) {
        int r = root(up, owner[i]);
        if (label[r] < 0) label[r] = (int8_t)i;
        b->piece[i] = (uint8_t)label[r];
    }
    hulls_build(b);
}

/* Texel centres under an occluder's surface beyond its stored triangle: on a finely
 * tessellated rim the record keeps the nearest, innermost triangle of each texel, and
 * the surface reaches on towards the silhouette; its piece reaches as far as the
 * plain map saw it (spsm.c chooses the points). */
void om__spsm_outline_extend(om__spsm_boundary *out, const om__spsm_boundary *base,
                             const om__spsm_outline_pt *pts, int npts)
{
    out->nv = base->nv;
    for (int i = 0; i < base->nv; i++) {
        out->x[i] = base->x[i];
        out->y[i] = base->y[i];
        out->piece[i] = base->piece[i];
    }
    for (int p = 0; p < npts && out->nv < OM__SPSM_MAXV; p++) {
        out->x[out->nv] = (int32_t)pts[p].x;
        out->y[out->nv] = (int32_t)pts[p].y;
        out->piece[out->nv] = base->piece[base->first[pts[p].owner]];
        out->nv++;
    }
    hulls_build(out);
}

/* Strictly inside the hull of one piece: strictly left of each of its edges. */
bool om__spsm_outline_inside(const om__spsm_boundary *b, int64_t qx, int64_t qy)
{
    const int32_t px = (int32_t)qx, py = (int32_t)qy;   /* below 2^27 */
    for (int h = 0; h < b->nh; h++) {
        int a = b->hoff[h], e = b->hoff[h + 1];
        bool in = true;
        for (int i = a; i < e && in; i++) {
            int j = i + 1 == e ? a : i + 1;
            in = turn(b->hx[i], b->hy[i], b->hx[j], b->hy[j], px, py) > 0;
        }
        if (in) return true;
    }
    return false;
}

