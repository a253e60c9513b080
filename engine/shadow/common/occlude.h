/* occlude.h — the one occlusion predicate, shared by the reference and the irregular
 * z-buffer, and the transmittance of semi-transparent casters.
 *
 * The light's image plane is treated as a virtual OM_LIGHT_GRID x OM_LIGHT_GRID raster
 * of the engine's rasterizer: samples and triangles are projected with the same code,
 * snapped to the same 1/256 sub-pixel grid (2^21 steps across the light's frustum), and
 * clipped to the same planes (the light's near and far depth and a guard band). A
 * triangle blocks a sample when
 *   - it is not the sample's own triangle,
 *   - the sample's grid point is inside it by the rasterizer's edge functions and
 *     top-left tie rule (a point on an edge shared by two occluders is inside exactly
 *     one of them), and
 *   - the triangle's light depth (z/w, the plane through its snapped vertices) at that
 *     point, pushed back by the triangle's snapping bound (below), is strictly nearer
 *     the light than the sample's own light depth.
 * Only the light's frustum depth range bounds which geometry casts, as it does for
 * every shadow map.
 *
 * The snapping bound: a surface never shadows itself. In exact geometry a sample on a
 * surface is never behind that surface as seen from the light: not a coplanar
 * neighbour (the floor's seams), nor the next facet of a convex solid, nor the facet
 * the eye pass's snapping handed the pixel to instead of its true one (the sample then
 * lies on its own facet's plane a sub-pixel past the shared edge, in front of the true
 * facet on the lit side of a convex solid). Snapping and float rounding move both
 * depths the predicate compares, by at most
 *   - laterally, per axis: half a grid step for the snap of the sample's point and
 *     another for the triangle's vertices, a step more each for the single-precision
 *     division and scaling before the snap (raster.h), plus the float rounding of x/w
 *     and y/w in clip space; times the triangle's depth gradient on the grid
 *     (|dz/dx| + |dz/dy|);
 *   - in depth: the float rounding of z and w in the light's clip space (the float
 *     matrix product: 4 roundings, the clipper's cut: 2 more, the sample's point made
 *     in float from its triangle's vertices (eye.c: a difference, a product and a sum
 *     a term): 3, and each vertex made relative to the view's origin, a float
 *     subtraction: 1; 10 units of 2^-24 on the sum of the terms' magnitudes, bounded
 *     with the scene's box relative to the origin), over w; and the depth's truncation
 *     to a whole unit (om__zdepth), below one unit each.
 * Every coordinate is relative to the view's origin, which follows the light (om_view):
 * the rounding terms scale with the scene's extent around its light, not with its
 * distance from the world's origin, so a scene moved far away keeps the bound it has
 * at the origin (the float vertex data itself is what loses precision there).
 * Each rounding term grows with 1/w, so the sample's own is at most the triangle's at
 * its nearest vertex whenever the triangle is nearer at all; the bound is therefore
 * twice the triangle's own (om__lspace_tri sets it per sub-triangle).
 * The sample's own facet: the lateral error moves the sample's grid point off the
 * true point of its surface, and where that surface is steep on the grid (a facet
 * almost edge-on to the light, at a convex solid's terminator) the surface next to it
 * there, its neighbour, is nearer the light by that error times the facet's own slope,
 * far more than the blocker's slope covers. The sample's depth is therefore pulled
 * towards the light by its facet's slope (from its vertices, occlude.c) times the same
 * lateral error (om__lspace_point): a facet edge-on to the light is lit by a tie.
 * The slope is the triangle's own, from its vertices, so the same for every sample on
 * it. A
 * blocker must be nearer than the sample by more than that: depths closer than the
 * grid and the float positions resolve are a tie, and a tie is lit. This is derived
 * from the grid and the number formats, not tuned. Laterally it is about ten grid
 * steps, more where the grid is finer than float positions resolve (a directional
 * light fitted to a small view of a large scene: 20 to 70 steps, a few tens of float
 * roundings of the scene's largest coordinate about the origin); in depth, that times the triangle's
 * slope, plus the depth rounding. */
#ifndef OM_OCCLUDE_H
#define OM_OCCLUDE_H

#include "../../frame/frame.h"

#define OM_LIGHT_GRID 8192u

/* A sample on the light's grid: position in sub-pixel units and light depth (0..2^32). */
typedef struct om__lpoint {
    int64_t x, y;
    double z;
    uint32_t tri;          /* the sample's own triangle */
} om__lpoint;

/* A vertex projected once per frame; x == INT32_MIN marks one that needs clipping. */
typedef struct om__lvert { int32_t x, y; uint32_t z; } om__lvert;

/* Grid bounds and a depth: a projected triangle's bounds and nearest vertex depth
 * (om__lvert_box), or a set of samples' bounds and farthest depth (hybrid's tiles). */
typedef struct om__lvbox { int32_t lox, loy, hix, hiy; uint32_t z; } om__lvbox;

/* The box of three projected vertices, none of which needs clipping. */
static inline om__lvbox om__lvert_box(const om__lvert *a, const om__lvert *b, const om__lvert *c)
{
    om__lvbox v = {a->x, a->y, a->x, a->y, a->z};
    if (b->x < v.lox) v.lox = b->x;
    if (b->x > v.hix) v.hix = b->x;
    if (c->x < v.lox) v.lox = c->x;
    if (c->x > v.hix) v.hix = c->x;
    if (b->y < v.loy) v.loy = b->y;
    if (b->y > v.hiy) v.hiy = b->y;
    if (c->y < v.loy) v.loy = c->y;
    if (c->y > v.hiy) v.hiy = c->y;
    if (b->z < v.z) v.z = b->z;
    if (c->z < v.z) v.z = c->z;
    return v;
}

typedef struct om__lspace {
    const om_scene *scene;
    om_mat4 vp;            /* the light's clip space of a point less o */
    om_vec3 o;             /* the view's origin */
    om__lvert *verts;      /* scene->nverts projected once per frame; NULL: lean mode */
    /* The snapping bound's parts for this frame (occlude.c, bound()): 1/w as an affine
     * function of light depth, and the lateral (grid units) and depth rounding per
     * unit of 1/w. */
    double iw0, iw1, lat, dep;
    /* The same in float for om__blocks_f, and |iw0|, |iw1| for its error bound. */
    float iw0f, iw1f, latf, depf, iw0a, iw1a;
    /* The sample's own facet (om__lspace_point): the light's view rows, and its depth
     * slope on the grid per unit of the normal's view x and y over the plane's distance
     * from the light (spot) or over the normal's view z (directional). */
    om_vec3 row0, row1, row2, lpos;
    float kx, ky;
    bool spot;
} om__lspace;

/* Bytes of the per-frame vertex projection (om__lspace_init). */
size_t om__lspace_bytes(const om_scene *s);
om_status om__lspace_init(om__lspace *ls, om_arena *a, const om_scene *s, om_diag *d);
/* Lean mode: no memory, every triangle is projected when it is set up. The results are
 * the same bits (a vertex inside every plane projects exactly as clipping projects it);
 * only the speed differs. */
void om__lspace_init_lean(om__lspace *ls, const om_scene *s);
/* Projects every vertex for this frame's light: om__lspace_view, then
 * om__lspace_project over all of them. */
void om__lspace_begin(om__lspace *ls, const om_view *v);
/* Its two halves: this frame's matrix and snapping bound; then the projection of
 * vertices [first, end), which writes only theirs (so disjoint ranges may run at once,
 * after the view). */
void om__lspace_view(om__lspace *ls, const om_view *v);
void om__lspace_project(const om__lspace *ls, uint32_t first, uint32_t end);
/* Projects a sample; false when it is not in front of the light. Its depth is pulled
 * towards the light by its own facet's slack (occlude.c, facet_slope), as a whole
 * number: what a blocker must be nearer than. */
bool om__lspace_point(const om__lspace *ls, const om_sample *smp, om__lpoint *out);
/* A sample's whole depth z pulled towards the light by its own facet's slack, its
 * facet triangle tri, f a cache of the last triangle's slope (tri OM_NO_TRI: empty;
 * it changes no bit, only the work). */
typedef struct om__facet { uint32_t tri; float slope; } om__facet;
uint32_t om__lspace_pull(const om__lspace *ls, om__facet *f, uint32_t tri, uint32_t z);
/* The projection alone, its depth not yet pulled, for a caller that pulls it where a
 * triangle first blocks the unpulled depth (a triangle that blocks the pulled depth
 * blocks the unpulled one: the same answers, the pull's work only where a blocker is
 * near). */
bool om__lspace_point_at(const om__lspace *ls, const om_sample *smp, om__lpoint *out, uint32_t *z);
/* The same, with the depth also as the whole number it is (*z == out->z). */
bool om__lspace_point_z(const om__lspace *ls, const om_sample *smp, om__lpoint *out, uint32_t *z);

/* A triangle on the light's grid: up to 7 sub-triangles after clipping, each with its
 * snapping bound. */
typedef struct om__ltri {
    om__rtri sub[7];
    double bound[7];
    int n;
    uint32_t tri;
    int64_t lox, loy, hix, hiy;   /* grid bounds of all sub-triangles */
    double zmin;                  /* nearest light depth of the triangle, plus its bound:
                                     it blocks no sample at this depth or farther */
} om__ltri;

/* Sets up triangle t; returns false when nothing of it is inside the light's frustum. */
bool om__lspace_tri(const om__lspace *ls, uint32_t t, om__ltri *out);
/* The same for a triangle the frame projected whole, from copies of its projected
 * vertices v (none of which needs clipping): the same setup, without loading them. */
bool om__lspace_tri_at(const om__lspace *ls, uint32_t t, const om__lvert v[3], om__ltri *out);

/* The predicate. */
static inline bool om__blocks(const om__ltri *lt, const om__lpoint *p)
{
    if (lt->tri == p->tri) return false;
    for (int k = 0; k < lt->n; k++) {
        const om__rtri *r = &lt->sub[k];
        if (om__tri2_covers(&r->e, p->x, p->y)) return om__rtri_depth(r, p->x, p->y) + lt->bound[k] < p->z;
    }
    return false;
}

/* The predicate for triangle t, where the frame projected its three vertices, in
 * single precision (occlude.c says why its answer is the double one): 1 t blocks p,
 * 0 it does not, -1 when it cannot say (no vertex projection, a vertex that needs
 * clipping, coordinates beyond 2^22, p on an edge, or the depths too close for the
 * float's error bound): then om__lspace_tri and om__blocks decide. z is p's depth as
 * the whole number it is. For chips whose double arithmetic is a library routine
 * (OM_FAST_FLOAT, core.h). */
int om__blocks_f(const om__lspace *ls, uint32_t t, const om__lpoint *p, uint32_t z);

/* ---- transmittance: casters multiply it, in any order with the same result. Each
 * channel is kept as an optical depth, -log2(t) in 1/4096 units, summed with
 * saturation (integer sums do not depend on order, float products would). */
#define OM_OPAQUE_DEPTH 0xFFFFFFFFu

typedef struct om__odepth { uint32_t c[3]; } om__odepth;

/* The optical depth of one caster: transmittance (1 - opacity) * albedo per channel,
 * quantized to 8 bits first; opacity 1 (or a zero channel) is opaque. */
om__odepth om__material_odepth(const om_material *m);
static inline void om__odepth_add(om__odepth *acc, const om__odepth *o)
{
    for (int i = 0; i < 3; i++) {
        uint32_t s = acc->c[i] + o->c[i];
        acc->c[i] = s < acc->c[i] ? OM_OPAQUE_DEPTH : s;
    }
}
static inline bool om__odepth_opaque(const om__odepth *o)
{
    return o->c[0] == OM_OPAQUE_DEPTH && o->c[1] == OM_OPAQUE_DEPTH && o->c[2] == OM_OPAQUE_DEPTH;
}
/* Back to an 8-bit term, rounded: 255 * 2^(-depth / 4096). */
void om__odepth_term(const om__odepth *o, om_term *t);

#endif
