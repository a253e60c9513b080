/* spsm_method.h — the state of the SPSM method (paper 004), shared by its two halves:
 * spsm.c (settings, observe, lookup and recovery: sections 4 and 5) and spsm_build.c
 * (the conservative build of the records: section 3.2). */
#ifndef OM_SPSM_METHOD_H
#define OM_SPSM_METHOD_H

#include "shadow.h"
#include "spsm_lookup.h"

#define OM__SPSM_TIE_DZ (OM__SPSM_LINK_DZ / 2)   /* the build's near tie: one surface to recovery */
#define OM__SPSM_TIES 0xFFu                      /* the depth buffer's low bits: ties counted
                                                    (texel) */

/* What spsm's settings (spsm.c) set. */
typedef struct om__spsm_cfg {
    uint32_t map_size;
    uint32_t spsm_aa;      /* sub-samples at uncertain samples, 0 or 1 = off */
    uint32_t spsm_records; /* which texel records the build makes: 1 every one (the
                              paper's build), 2 only those the view reads (observe
                              marks them), 0 = 2 when the map has more than twice as
                              many texels as the image has pixels, else 1. The same
                              frames either way; only the time differs. */
    uint32_t spsm_fine;    /* 1: the plain-map fallback at 2 x 2 points per texel (16
                              more bytes per texel and a second pass; fewer false-lit
                              samples along fine rims), 0: at texel centres */
} om__spsm_cfg;

/* The lookup's moving parts. Its 3x3 of decoded texels: consecutive samples mostly
 * fall in the same texel, and the 3x3 around it depends on nothing but the map and
 * that texel's index, so it is kept from one sample to the next while `t4_at` names
 * the texel (and what it shares with the next texel's 3x3 is kept too: shift_window):
 * bit k of `t_have` says t[k] is decoded. The recovery's occluders (pointers into t)
 * and outline for the pattern `bd_keep` of the texel t4_at, while bd_have; and the
 * texel centres that may join the outline (cand_k: their texels): those nearer than
 * the sample, which varies, do. bd is the outline without them, bx with those in
 * bx_pts (a superset of bd's hulls: points only join pieces).
 * Nothing in it changes an answer, only the work: a strip resolves with the state's
 * own, a band with one of its job's (om__spsm_win_reset first). */
typedef struct om__spsm_win {
    om__spsm_dtri t[9];
    size_t t4_at;
    uint32_t t_have;
    const om__spsm_dtri *occ[9];
    int nocc;
    om__spsm_outline_pt cand[9];
    uint8_t cand_k[9];
    int ncand;
    uint16_t bx_pts;
    om__spsm_boundary bd, bx;
    uint16_t bd_keep;
    bool bd_have;
} om__spsm_win;

/* Forgets what the window holds (all of it, so that nothing is read unset). */
static inline void om__spsm_win_reset(om__spsm_win *w)
{
    memset(w, 0, sizeof *w);
    w->t4_at = (size_t)-1;
}

typedef struct om__spsm_state {
    const om_scene *scene;
    om__spsm_cfg cfg;
    uint32_t size;
    om__spsm_texel *tex;
    uint32_t *depth;             /* minimum conservative depth: the build's depth test
                                  * (low 8 bits: ties so far; all ones: empty) */
    uint32_t *cdepth;            /* nearest depth at each texel centre (fallback) */
    /* spsm.fine: the plain map at 2 x 2 points per texel (plain_shadow), and need at
     * those points, fwords words per row */
    bool fine;
    uint32_t *fdepth, *fneed;
    uint32_t fwords;
    /* Texels the lookup will read, one bit each, `words` 32-bit words per row: `seen`
     * (the samples' texels, from observe) grown by one texel into `need` (build). */
    uint32_t *seen, *need;
    /* need_rows: bit y set when row y of need has any bit (the build passes over the
     * others: with marks, nothing in them is read) */
    uint32_t *need_rows;
    uint32_t words;
    bool marks;                  /* observe marks texels (spsm.records); else need is full */
    om_view view;
    om__spsm_qtable q;
    om__spsm_tangent lut[512];
    /* per frame */
    uint32_t samples, lit, shadowed, uncertain, recovered, needed;
    om__spsm_win win;            /* the lookup's, a strip at a time */
} om__spsm_state;

/* A depth plane: z at grid point (ox, oy), slopes gx, gy per grid unit. */
typedef struct om__spsm_zplane { double z, gx, gy; int64_t ox, oy; } om__spsm_zplane;

/* The least depth of plane p over the triangle (X, Y) clipped to the square
 * [x0, x0 + side] x [y0, y0 + side], for a square whose corner the slopes point to
 * (the plane's least value over the square) lies outside the triangle: the least
 * value over the two's overlap is then on the triangle's boundary, at an end of one
 * of its edges clipped to the square (Liang-Barsky), whichever the slope along the
 * edge points to. HUGE_VAL when no edge crosses the square. */
static inline double om__spsm_clipped_min(const int64_t X[3], const int64_t Y[3], int64_t x0, int64_t y0, int64_t side,
                                 const om__spsm_zplane *p)
{
    const double lo[2] = {(double)x0, (double)y0}, hi[2] = {(double)(x0 + side), (double)(y0 + side)};
    double best = HUGE_VAL;
    for (int i = 0; i < 3; i++) {
        const int j = i == 2 ? 0 : i + 1;
        const double a[2] = {(double)X[i], (double)Y[i]}, d[2] = {(double)(X[j] - X[i]), (double)(Y[j] - Y[i])};
        double t0 = 0.0, t1 = 1.0;
        bool in = true;
        for (int k = 0; k < 2 && in; k++) {
            if (d[k] == 0.0) { in = a[k] >= lo[k] && a[k] <= hi[k]; continue; }
            double inv = 1.0 / d[k], ta = (lo[k] - a[k]) * inv, tb = (hi[k] - a[k]) * inv;
            if (ta > tb) { double s = ta; ta = tb; tb = s; }
            if (ta > t0) t0 = ta;
            if (tb < t1) t1 = tb;
            in = t0 <= t1;
        }
        if (!in) continue;
        double t = p->gx * d[0] + p->gy * d[1] < 0.0 ? t1 : t0;
        double z = p->z + p->gx * (a[0] + t * d[0] - (double)p->ox) + p->gy * (a[1] + t * d[1] - (double)p->oy);
        if (z < best) best = z;
    }
    return best;
}

/* The build (spsm_build.c): the records the lookup will read, from the marks; by bands
 * of the map's rows (om__bands: map_of on the calling thread, then build_rows for
 * each band), or all at once. */
om_status om__spsm_build(void *state, om_diag *d);
uint32_t om__spsm_map_of(void *state, const om_mat4 **vp);
void om__spsm_build_rows(const void *state, const om__bins *bins, uint32_t y0, uint32_t rows, uint32_t counts[8]);

#endif
