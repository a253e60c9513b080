/* rtw.h — Rectilinear Texture Warping shadow maps (paper 003, Rosen 2012): the state of
 * the `rtw` method and the pieces of its pipeline, declared here so that tests and the
 * benchmark can reach them.
 *
 *   rtw_warp.c  the importance map (section 4.1, importance functions of section 5),
 *               the 1-D collapse, the Gaussian blur and the warp tables (section 4.2)
 *   rtw.c       the method: rendering the warped map with tessellation (4.3, 6.1) and
 *               the lookup through the shared biased depth test (4.4, smlookup.c)
 *
 * Coordinates: the warp acts on normalized light-image coordinates, u = (x/w + 1) / 2
 * to the right and v = (1 - y/w) / 2 downwards (row 0 of every map at the top), so
 * [0, 1]^2 is the light's image. Importance cell (i, j) covers
 * [i/n, (i+1)/n) x [j/n, (j+1)/n); super-cell k of a warp table is column (or row) k.
 *
 * A warp table holds n + 1 fixed-point entries P(k) = S(k) / S(n) in units of
 * OM_RTW_ONE: where the edge between super-cells k - 1 and k lands in the warped map.
 * The warp of DESIGN.md is warp(k) = P(k) - k/n (om__rtw_warp_at); u in [0, 1] maps to
 * the linear interpolation of P between the super-cell edges around it, u outside
 * [0, 1] is left alone. P is monotonic with P(0) = 0 and P(n) = OM_RTW_ONE. */
#ifndef OM_RTW_H
#define OM_RTW_H

#include "../method.h"
#include "../common/smlookup.h"

#define OM_RTW_ALPHA 0.001f        /* shadow-edge function away from edges (section 5.3) */
#define OM_RTW_BETA 2.0f           /* surface-normal bonus (section 5.4) */
/* Visible samples' cells keep at least this share of the largest importance, so that a
 * product of small factors (distance far away, alpha away from edges) never collapses
 * a super-cell that holds something the camera sees. */
#define OM_RTW_FLOOR (1.0f / 256.0f)
#define OM_RTW_MAX_RADIUS 192      /* blur radius ceil(3 sigma) for sigma <= 64 */

enum { OM_RTW_DV = 1, OM_RTW_DIST = 2, OM_RTW_EDGE = 4, OM_RTW_NORMAL = 8 };
enum { OM_RTW_BACKWARD = 0, OM_RTW_FORWARD = 1, OM_RTW_HYBRID = 2 };

/* ---- 1-D tables (rtw_warp.c) */

/* Collapses the n x n map (row-major, row 0 at the top) by maximum: cols[i] over
 * column i, rows[j] over row j (section 4.2 (i)). */
void om__rtw_collapse(const float *imp, uint32_t n, double *cols, double *rows);
/* Gaussian blur (section 4.2 (ii)) of I[0..n) in place, sigma in super-cells (0 = none),
 * truncated at ceil(3 sigma) and renormalized at the ends so that a uniform input stays
 * uniform. scratch: n doubles; kernel: OM_RTW_MAX_RADIUS + 1 doubles. */
void om__rtw_blur(double *I, uint32_t n, float sigma, double *scratch, double *kernel);
/* The warp table P[0..n] of importances I[0..n) (section 4.2 (iii), DESIGN.md's
 * equation). An all-zero (or non-finite) I gives the identity; returns false then. */
bool om__rtw_table(const double *I, uint32_t n, int32_t *P);
/* warp(k) = P(k) - k/n, both in OM_RTW_ONE units (k/n rounded to nearest). */
int32_t om__rtw_warp_at(const int32_t *P, uint32_t n, uint32_t k);
/* om__rtw_apply, which warps one coordinate, is in smlookup.h: the lookup runs it. */

/* The inverse warp at the centres of a warped map's `size` texels: g[x] is where the
 * centre of texel x, (x + 0.5) / size warped, comes from, on a grid of `steps` units
 * across [0, 1] (rounded to nearest); non-decreasing. A collapsed super-cell is
 * stepped over: no texel centre comes from it. */
void om__rtw_unwarp_grid(const int32_t *P, uint32_t n, uint32_t size, double steps, int64_t *g);

/* Largest warped length of a super-cell, times n: the densest super-cell's
 * magnification (the maximum effective resolution is map_size times it). */
double om__rtw_max_density(const int32_t *P, uint32_t n);

/* ---- importance (rtw_warp.c) */

/* The product of the importance functions `funcs` that a visible point can evaluate:
 * distance to eye (5.2) and surface normal (5.4); the desired-view function (5.1) is
 * the caller's (a backward sample is in view by construction; a forward texel is
 * tested against the camera's frustum). n need not face the camera. */
float om__rtw_point_importance(const om_view *v, unsigned funcs, om_vec3 p, om_vec3 n);

/* Whether om__rtw_point_importance(v, funcs, p, n) may exceed cur (>= 0): false only
 * when it certainly does not, from float arithmetic (the importance itself takes a
 * double quotient, soft-float on a Cortex-M4F); the backward analysis skips it then. */
bool om__rtw_importance_above(const om_view *v, unsigned funcs, om_vec3 p, om_vec3 nrm, float cur);

/* The importance cell along one axis of a sample whose light-clip coordinate over w,
 * r = x * (1 / w) in float (for v: -(y * (1 / w))), lies at, with hn = n / 2: the cell
 * the backward analysis's double arithmetic gives, floor(((double)x / w + 1) / 2 * n),
 * -1 when that is outside [0, 1], and -2 when float cannot be sure (a NaN, or within
 * about n 2^-20 of a cell edge: the caller asks the double arithmetic then).
 *
 * Why it is sure otherwise: t = (r + 1) * hn in float is within hn (|x/w| + 1) 2^-22
 * of the exact value (four roundings, 1 / w included) and the double within 2^-50 of
 * it; with a margin of four times that, when no cell edge lies in [t - margin, t +
 * margin] both give the same cell, and when t + margin < 0 or t - margin > n both are
 * outside. In line: the backward analysis runs it twice a sample. */
static inline int32_t om__rtw_cell_axis(float r, float hn, float n)
{
    const float t = (r + 1.0f) * hn, margin = (om__fabsf(r) + 1.0f) * hn * 0x1p-20f;
    const float lo = t - margin, hi = t + margin;
    if (lo > 0.0f && hi < n) {
        const int32_t i = (int32_t)lo;
        return i == (int32_t)hi ? i : -2;
    }
    return hi < 0.0f || lo > n ? -1 : -2;
}

/* Their float paths run where OM_FAST_FLOAT is 1 (core.h). */

/* ---- the lookup in float (rtw.c): the warped depth test of smlookup.c, whose warp
 * is double arithmetic (soft-float on a Cortex-M4F), by float arithmetic that is
 * proven to give the same bits and says so, or says it cannot be sure. */

/* The density the lookup divides the bias texel by, of super-cell k: (P[k+1] - P[k])
 * n, at least 2^24 (smlookup.c's floor of 1/64, in 2^-30 units). */
static inline uint64_t om__rtw_dens(const int32_t *P, uint32_t n, uint32_t k)
{
    const uint64_t D = (uint64_t)(uint32_t)(P[k + 1] - P[k]) * n;
    return D > (1u << 24) ? D : (1u << 24);
}
/* rcp[0] + rcp[1] = 2^30 / D within 2^-47 of it (rcp[0] the float nearest). */
void om__rtw_rcp(uint64_t D, float rcp[2]);
/* (float)((double)t / (D / 2^30)), the lookup's bias texel in warped texels, from
 * rcp = om__rtw_rcp(D); -1 when float cannot be sure (t outside 2^-60..2^60, or the
 * quotient within 2^-38 of halfway between two floats). */
float om__rtw_div_dens(float t, const float rcp[2]);
/* The warped texel (floor of the warped coordinate times size) of a sample whose light
 * coordinate is r = x * (1 / w) (as om__rtw_cell_axis), as smlookup.c's double warp
 * gives it, and its super-cell in *k; -2 when float cannot be sure or the sample is not
 * strictly inside the light's image. */
int32_t om__rtw_texel_axis(const int32_t *P, uint32_t n, uint32_t size, float r, uint32_t *k);

/* ---- the method's configuration and state (rtw.c) */

/* What rtw's settings (rtw.c) set: the depth test's, and the warp's. */
typedef struct om__rtw_cfg {
    uint32_t map_size;
    float bias_const, bias_slope, normal_offset;
    uint32_t pcf;
    uint32_t rtw_importance;   /* importance map side; 0 = 512, or the map's side when
                                  that is smaller (at least 8) */
    uint32_t rtw_analysis;     /* OM_RTW_BACKWARD, _FORWARD or _HYBRID */
    uint32_t rtw_funcs;        /* importance functions: a mask of OM_RTW_DV ... */
    float rtw_sigma;           /* Gaussian blur, in super-cells */
    float rtw_tess;            /* longest warped edge as a fraction of the map, 0 = off */
    uint32_t rtw_exact;        /* 1: texels sample the scene at inverse-warped centres;
                                  0: warped vertices, straight edges, rtw_tess */
    uint32_t rtw_footprint;    /* PCF taps 0: a warped texel apart (anti-aliasing);
                                  1: an unwarped one (soft shadows; section 6.2) */
} om__rtw_cfg;

typedef struct om__rtw {
    om__state_head head;   /* first (method.h) */
    const om_scene *scene;
    om__rtw_cfg cfg;
    uint32_t n;                /* importance map side = super-cells per axis */
    uint32_t size;             /* warped shadow map side */
    float *imp;                /* n * n: importance; -1 where no visible sample fell */
    uint8_t *seen;             /* n * n bits: a visible sample fell in the cell */
    uint32_t *fdepth, *fid;    /* forward / hybrid: the n x n light depth image */
    double *cols, *rows, *scratch, *kernel;
    /* After the tables (om__rtw_build_tables), in cols' and rows' memory: per super-cell
     * k, 2^30 / D(k) as a float pair (om__rtw_rcp), D(k) its density (om__rtw_dens) */
    float *rcp_x, *rcp_y;
    int32_t *px, *py;          /* warp tables, n + 1 each */
    uint32_t *depth;           /* size * size warped shadow map */
    uint32_t *hiz;             /* its coarse depth (om__hiz_words); NULL: no room */
    int64_t *gridx, *gridy;    /* rtw_exact: each texel's sample point on the light grid */
    int32_t *gridxs, *gridys;  /* and their indexes (om__grid_index), grid_buckets + 1 */
    uint32_t grid_shift, grid_buckets;
    om_view view;
    om__smlook look;
    double limit;              /* tessellation: longest warped edge in [0, 1] units; 0 = off */
    /* per frame */
    uint32_t samples, shadowed, tris_drawn;
    double dens_x, dens_y;     /* densest super-cell per axis (MER = size * density) */
#if OM_WITH_JOBS
    om__lent lent;             /* the host's threads for this frame's analysis (rtw_jobs.c) */
#endif
} om__rtw;

/* The importance map's side for settings c (rtw.c). */
uint32_t om__rtw_importance_side(const om__rtw_cfg *c);

/* Importance map stages (rtw_warp.c). begin clears, observe_strip records the backward
 * analysis of one strip of visible samples (section 4.1: each exposed sample, projected
 * into the light's image, keeps the largest importance of its cell), finish runs the
 * forward analysis when asked (a light depth image of n x n texels, one per cell) and
 * combines the two, then puts the floor under visible samples' cells. */
void om__rtw_importance_begin(om__rtw *m);
void om__rtw_observe_strip(om__rtw *m, const om_strip *st);
/* The backward analysis of `count` samples and their terms into the map imp and its
 * seen bits (the state's, or a job's own: rtw_jobs.c). */
void om__rtw_observe_into(const om__rtw *m, const om_sample *smp, const om_term *terms, size_t count,
                          float *imp, uint8_t *seen);
#if OM_WITH_JOBS
/* rtw_jobs.c: observe_strip by bands of rows on the host's threads, each into its
 * slot's map; false where there are none (nothing done). fold puts the slots' maps
 * into the state's (finish calls it first); nothing to do where no band ran. */
bool om__rtw_observe_jobs(om__rtw *m, const om_strip *st);
void om__rtw_observe_fold(om__rtw *m);
#endif
void om__rtw_importance_finish(om__rtw *m);
/* The 1-D tables of this frame's importance map: collapse, blur, warp (section 4.2).
 * Build runs finish, tables and the map in turn; each may run again on its own (the
 * bench times the stages so). */
void om__rtw_build_tables(om__rtw *m);

/* The terms of a strip, the same as om__smlook_strip(&m->look, ...) gives. */
void om__rtw_lookup_strip(const om__rtw *m, om_strip *st, uint32_t *samples, uint32_t *shadowed);

/* Renders the warped shadow map of this frame's tables (rtw.c; called by build). */
void om__rtw_render_map(om__rtw *m);

#endif
