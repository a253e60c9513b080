/* spsm_lookup.h — what the SPSM lookup (spsm.c) and its silhouette outline
 * (spsm_outline.c, section 4.2 and Figure 10) share: a texel record decoded around the
 * sample's texel, its plane (Equation 1), and the outline built from the occluders the
 * depth-test pattern keeps. Units as in spsm_texel.h: grid units of 1/256 texel, raw depth. */
#ifndef OM_SPSM_LOOKUP_H
#define OM_SPSM_LOOKUP_H

#include "spsm_texel.h"

#define OM__SPSM_STEP 65536.0                     /* one 16-bit depth step in raw units */
#define OM__SPSM_TOL0 (1.5 * OM__SPSM_STEP)       /* what a record's depth cannot resolve at
                                                     its centre */
#define OM__SPSM_LINK_DZ (32.0 * OM__SPSM_STEP)   /* planes of one smooth surface agree this well */
#define OM__SPSM_MAXV 36                          /* outline points: 9 triangles x 3, and 9
                                                     texel centres */

/* A texel's record decoded around the sample's texel: grid coordinates relative to
 * the centre of the sample's texel, plane in raw depth per grid unit. */
typedef struct om__spsm_dtri {
    bool empty, ok;              /* ok: a 2-D triangle with area */
    bool have_e;                 /* e is set up (edges(): most samples need only the plane) */
    om__tri2 e;
    int64_t rx[3], ry[3];        /* the vertices as decoded (e holds them reordered) */
    int64_t cx, cy;              /* this texel's centre */
    double z, gx, gy, ex, ey;    /* centre depth, slopes and their error bounds (have_d:
                                    made for the double tests when they run) */
    bool have_d;
    uint8_t qx, qy;              /* the record's derivative codes */
    float zf, gxf, gyf, exf, eyf;   /* the same rounded to float (om__spsm_below_f) */
    double cmin;                 /* consistent_min, once computed (have_cmin) */
    bool have_cmin;
    float cminf;                 /* cmin rounded to float (om__spsm_less_f) */
    float vzf[3], vtolf[3];      /* plane and pattern slack at the vertices rx, ry, in
                                    float (have_vz; spsm.c's behind_receiver) */
    bool have_vz;
} om__spsm_dtri;   /* a new field is moved in spsm.c's move_entry too */

/* The recovered silhouette of an uncertain sample (4.2; spsm_outline.c). Its points are
 * a record's vertices, texel centres of the 3x3 and the lookup's points, all below 2^27
 * (om__spsm_edge): 32 bits hold them. */
typedef struct om__spsm_boundary {
    int nv;
    int32_t x[OM__SPSM_MAXV], y[OM__SPSM_MAXV];
    uint8_t piece[OM__SPSM_MAXV];
    uint8_t first[9];            /* a vertex of each occluder (its piece's) */
    /* the pieces' hulls, counter-clockwise without collinear points, one after another:
     * hull h has the vertices [hoff[h], hoff[h + 1]) of hx, hy; pieces with no area
     * (a point, a segment) have none */
    int nh;
    uint8_t hoff[OM__SPSM_MAXV + 1];
    int32_t hx[OM__SPSM_MAXV], hy[OM__SPSM_MAXV];
} om__spsm_boundary;

/* Equation 1: the stored plane at grid point (px, py), and what it cannot resolve. */
static inline double om__spsm_plane_at(const om__spsm_dtri *t, int64_t px, int64_t py)
{
    return t->z + t->gx * (double)(px - t->cx) + t->gy * (double)(py - t->cy);
}

static inline double om__spsm_tol_at(const om__spsm_dtri *t, int64_t px, int64_t py)
{
    return OM__SPSM_TOL0 + t->ex * fabs((double)(px - t->cx)) + t->ey * fabs((double)(py - t->cy));
}

/* Three coordinates copied and compared in line: the firmware is built freestanding,
 * where memcpy and memcmp are calls, and the lookup and the build do these per sample
 * and per texel. */
static inline void om__spsm_copy3(int64_t to[3], const int64_t from[3])
{
    to[0] = from[0];
    to[1] = from[1];
    to[2] = from[2];
}

static inline bool om__spsm_same3(const int64_t a[3], const int64_t b[3])
{
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

/* A grid offset as a float: offsets inside the rasterizer's range (om__tri2's, below
 * 2^30) fit 32 bits, whose conversion a single-precision FPU does in one instruction. */
static inline float om__spsm_off_f(int64_t v)
{
    return (float)(int32_t)v;
}

/* The same two in float, for the tests whose slack is wide (outline links, the
 * receiver's plane at a record's vertices, the plain map): every CPU rounds them
 * alike, and their error (2^-22 of the terms) is far inside those slacks. */
static inline float om__spsm_plane_at_f(const om__spsm_dtri *t, int64_t px, int64_t py)
{
    return t->zf + t->gxf * om__spsm_off_f(px - t->cx) + t->gyf * om__spsm_off_f(py - t->cy);
}

static inline float om__spsm_tol_at_f(const om__spsm_dtri *t, int64_t px, int64_t py)
{
    return (float)OM__SPSM_TOL0 + t->exf * om__fabsf(om__spsm_off_f(px - t->cx)) +
           t->eyf * om__fabsf(om__spsm_off_f(py - t->cy));
}

/* om__tri2_covers for the lookup's triangles and points, with 32-bit factors: the
 * same exact edge values, since a record's vertices lie within 2^27 of the texel
 * centre (the o16 range), so the edges' a and b (vertex differences) are below 2^28,
 * and every point tested (a sample or sub-sample on the map's grid, below 2^26, less
 * its texel's centre, below 2^22; a texel centre or corner of the 3x3) is below 2^27.
 * The build's triangles (om__project's vertices, below 2^26) and texel corners (below
 * 2^21) are inside the same bounds.
 * On a 32-bit CPU a 64-by-64-bit product is three multiplies, a 32-by-32 one one. */
static inline int64_t om__spsm_edge(const om__tri2 *e, int i, int64_t px, int64_t py)
{
    return (int64_t)(int32_t)e->a[i] * (int32_t)px + (int64_t)(int32_t)e->b[i] * (int32_t)py + e->c[i];
}

static inline bool om__spsm_covers(const om__tri2 *e, int64_t px, int64_t py)
{
    return (om__spsm_edge(e, 0, px, py) | om__spsm_edge(e, 1, px, py) | om__spsm_edge(e, 2, px, py)) >= 0;
}

/* Their float paths run where OM_FAST_FLOAT is 1 (core.h). */

/* The depth tests of the lookup in float, for a CPU whose double is a library call (a
 * Cortex-M4F): whether om__spsm_plane_at(t, px, py) lies below pz + sign * tol, tol
 * being om__spsm_tol_at(t, px, py), capped at `cap` when cap > 0 (tol < cap ? tol :
 * cap), as the double arithmetic decides it with < or <= (1 below, 0 not), or -1 when
 * float cannot be sure. pz is the double depth rounded to float.
 *
 * Why it is sure otherwise: every value is a sum of at most six terms, each within
 * 2^-24 of its double (conversions) and each float operation adds at most 2^-24 of
 * the sum of their magnitudes S, at most 14 roundings in all, under 2^-20 S; the double
 * arithmetic's own error is under 2^-49 S. A difference beyond 2^-19 S has the same
 * sign in both, and so does the cap's choice; equality lies inside that band, so < and
 * <= agree outside it. Offsets beyond 2^20 grid units (exact in float below 2^24) and
 * non-finite values answer -1. px, py and the centre lie within 2^30 (taken in 32 bits). */
/* The part of those tests that does not depend on the sign or the cap: the plane's
 * value a, the tolerance tol and the bound e at one point against one depth pz, found
 * once per sample and texel (the lit test asks three questions of the sample's own
 * texel, and recovery asks again of each texel that Algorithm 1 tested); ok false
 * where every answer is -1 (offsets beyond 2^20). */
typedef struct om__spsm_pf { float a, tol, e; bool ok; } om__spsm_pf;

static inline void om__spsm_pf_at(om__spsm_pf *f, const om__spsm_dtri *t, int64_t px, int64_t py, float pz)
{
    /* in 32 bits: the lookup's points and centres lie below 2^27 (om__spsm_edge) */
    const int32_t ix = (int32_t)px - (int32_t)t->cx, iy = (int32_t)py - (int32_t)t->cy;
    f->ok = !(ix < -(1 << 20) || ix > (1 << 20) || iy < -(1 << 20) || iy > (1 << 20));
    if (!f->ok) {
        f->a = f->tol = f->e = 0.0f;
        return;
    }
    const float dx = (float)ix, dy = (float)iy;
    const float gdx = t->gxf * dx, gdy = t->gyf * dy;
    f->a = t->zf + gdx + gdy;
    f->tol = (float)OM__SPSM_TOL0 + t->exf * om__fabsf(dx) + t->eyf * om__fabsf(dy);
    f->e = (om__fabsf(t->zf) + om__fabsf(gdx) + om__fabsf(gdy) + om__fabsf(pz) + f->tol) * 0x1p-19f;
}

/* om__spsm_below_f's answer from the shared part f (found against the same pz). */
static inline int om__spsm_pf_below(const om__spsm_pf *f, float pz, float sign, float cap)
{
    if (!f->ok) return -1;
    float tol = f->tol;
    const float e = f->e;
    if (cap > 0.0f) {
        if (tol > cap + e) tol = cap;
        else if (!(tol < cap - e)) return -1;
    }
    const float d = f->a - (pz + sign * tol);
    return d < -e ? 1 : d > e ? 0 : -1;
}

/* om__spsm_tol_within_f's answer from the shared part f. */
static inline int om__spsm_pf_within(const om__spsm_pf *f, float cap)
{
    if (!f->ok) return -1;
    const float e = f->tol * 0x1p-19f;
    return f->tol < cap - e ? 1 : f->tol > cap + e ? 0 : -1;
}

static inline int om__spsm_below_f(const om__spsm_dtri *t, int64_t px, int64_t py, float pz, float sign,
                                   float cap)
{
    om__spsm_pf f;
    om__spsm_pf_at(&f, t, px, py, pz);
    return om__spsm_pf_below(&f, pz, sign, cap);
}

/* Whether om__spsm_tol_at(t, px, py) <= cap as the double arithmetic finds it (1, 0),
 * or -1 when float cannot be sure (the same bounds). */
static inline int om__spsm_tol_within_f(const om__spsm_dtri *t, int64_t px, int64_t py, float cap)
{
    om__spsm_pf f;
    om__spsm_pf_at(&f, t, px, py, 0.0f);
    return om__spsm_pf_within(&f, cap);
}

/* Whether a < b + c dx + d dy - e, each a double and the sum taken in that order, as
 * the double arithmetic finds it (1, 0), from their floats (dx, dy exact); -1 when
 * float cannot be sure. The bounds of om__spsm_below_f: the float sum is within 2^-20
 * of the magnitudes' sum S, the double within 2^-49 S; beyond 2^-19 S both agree. */
static inline int om__spsm_less_f(float a, float b, float c, float dx, float d, float dy, float e)
{
    const float cdx = c * dx, ddy = d * dy, r = b + cdx + ddy - e;
    const float m = (om__fabsf(a) + om__fabsf(b) + om__fabsf(cdx) + om__fabsf(ddy) + om__fabsf(e)) * 0x1p-19f;
    const float diff = a - r;
    return diff < -m ? 1 : diff > m ? 0 : -1;
}

/* Builds the outline of the occluders occ[0..nocc) (distinct triangles, their edges
 * set up): their vertices, linked into pieces, and each piece's convex hull. */
void om__spsm_outline_build(om__spsm_boundary *b, const om__spsm_dtri *const occ[9], int nocc);
/* A point known to lie under the surface of occluder `owner` (an index into the
 * occluders the outline was built from): a texel centre that the plain map saw there. */
typedef struct om__spsm_outline_pt { int64_t x, y; int owner; } om__spsm_outline_pt;

/* The outline `base` with the points pts[0..npts) joined to their owners' pieces. */
void om__spsm_outline_extend(om__spsm_boundary *out, const om__spsm_boundary *base,
                             const om__spsm_outline_pt *pts, int npts);
/* Whether (px, py) lies strictly inside one of the outline's hulls. */
bool om__spsm_outline_inside(const om__spsm_boundary *b, int64_t px, int64_t py);

#endif
