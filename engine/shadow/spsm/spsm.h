/* spsm.h — the state of the SPSM method (paper 004), shared by its two halves:
 * spsm.c (settings, observe, lookup and recovery: sections 4 and 5) and spsm_build.c
 * (the conservative build of the records: section 3.2). */
#ifndef OM_SPSM_H
#define OM_SPSM_H

#include "../method.h"
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
    uint8_t occ_k[9];            /* occ[j] is t[occ_k[j]] */
    int nocc;
    om__spsm_outline_pt cand[9];
    uint8_t cand_k[9];
    int ncand;
    uint16_t bx_pts;
    om__spsm_boundary bd, bx;
    uint16_t bd_keep;
    bool bd_have;
    /* the float plane of each texel at the sample being looked up (om__spsm_pf_at:
     * the lit test's at t[4], Algorithm 1's at the others), which recovery's pattern
     * test reads again: set for every t[k].ok before recover runs */
    om__spsm_pf pf[9];
    /* spsm.c's receiver_plane: the light's matrix applied to two directions in the
     * surface of normal rn (while rd_have) */
    float rn[3];
    float rd[2][4];
    bool rd_have;
} om__spsm_win;

/* Forgets what the window holds (all of it, so that nothing is read unset). */
static inline void om__spsm_win_reset(om__spsm_win *w)
{
    memset(w, 0, sizeof *w);
    w->t4_at = (size_t)-1;
}

typedef struct om__spsm_state {
    om__state_head head;   /* first (method.h) */
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
#if OM_WITH_JOBS
    om__lent lent;               /* the host's threads for this frame's observe (spsm_observe.c) */
#endif
} om__spsm_state;

/* The texel holding grid position g (x or y), clamped to the map (so negative
 * positions need no floor division: they clamp to 0). */
static inline int64_t om__spsm_texel_of(const om__spsm_state *m, int64_t g)
{
    /* in 32 bits: om__project_xy's positions lie below 2^26 */
    const int32_t t = g < 0 ? 0 : (int32_t)((uint32_t)g >> OM_SUBPIX_BITS), last = (int32_t)m->size - 1;
    return t > last ? last : t;
}

/* Observe (spsm_observe.c): each exposed sample of the strip marks its texel in seen;
 * on the host's threads by bands of rows, each into its slot's marks, which
 * om__spsm_observe_fold puts into seen before the build reads it (map_of calls it;
 * nothing to do where no band ran). */
void om__spsm_observe(om__spsm_state *m, const om_strip *st);
void om__spsm_observe_fold(om__spsm_state *m);

/* The part of the segment (ax, ay) + t (dx, dy), t in [0, 1], that lies in the closed
 * square [0, side] x [0, side] (coordinates relative to its corner): its ends t0 <= t1
 * (Liang-Barsky), false when it misses. In float: the callers take the least depth of a
 * triangle inside a texel's square at such an end (spsm_build.c's clipped_min and
 * spsm.c's consistent_min), where an end off by 2^-22 of the edge moves that depth by
 * as little of the edge's depth range, far below a 16-bit depth step. */
static inline bool om__spsm_clip_f(float ax, float ay, float dx, float dy, float side, float *t0, float *t1)
{
    const float a[2] = {ax, ay}, d[2] = {dx, dy};
    float lo = 0.0f, hi = 1.0f;
    for (int k = 0; k < 2; k++) {
        if (d[k] == 0.0f) {
            if (!(a[k] >= 0.0f && a[k] <= side)) return false;
            continue;
        }
        const float inv = 1.0f / d[k];
        float ta = -a[k] * inv, tb = (side - a[k]) * inv;
        if (ta > tb) { const float s = ta; ta = tb; tb = s; }
        if (ta > lo) lo = ta;
        if (tb < hi) hi = tb;
        if (!(lo <= hi)) return false;
    }
    *t0 = lo;
    *t1 = hi;
    return true;
}

/* The build (spsm_build.c): the records the lookup will read, from the marks; by bands
 * of the map's rows (om__bands: map_of on the calling thread, then build_rows for
 * each band), or all at once. */
om_status om__spsm_build(void *state, om_diag *d);
uint32_t om__spsm_map_of(void *state, uint32_t k, const om_mat4 **vp);
void om__spsm_build_rows(const void *state, uint32_t k, const om__bins *bins, uint32_t y0, uint32_t rows,
                         uint32_t counts[8]);

#endif
