/* csm.h — what csm's files share: its configuration, its state, and the split and
 * window arithmetic of csm_split.c. A cascade is a conventional depth map (sm's, with
 * sm's biased test from smlookup.c) over a square window of the light's image, the
 * window that holds one slice of the view's depth; csm.c owns the method's table, its
 * maps and its lookup. */
#ifndef OM_CSM_H
#define OM_CSM_H

#include "../method.h"
#include "../common/smlookup.h"

#define OM__CSM_MAX 4      /* cascades at most */
#define OM__CSM_BINS 64    /* the fitted mode's bins of view depth */

/* csm's configuration: what its settings (csm.c) set. */
typedef struct om__csm_cfg {
    uint32_t cascades, map_size;
    float lambda;
    uint32_t fit;
    float bias_const, bias_slope, normal_offset;
    uint32_t pcf;
} om__csm_cfg;
OM__CFG_FITS(om__csm_cfg);

/* A window of the light's image: the box [cx - hx, cx + hx] x [cy - hy, cy + hy] of
 * its normalized device coordinates (x right, y up, [-1, 1] across). A sample whose
 * projection lies within limx, limy of the centre (the window less a margin of texels
 * for PCF and the normal offset) is held by the cascade. */
typedef struct om__csm_win {
    float cx, cy, hx, hy, limx, limy;
    float ix, iy;         /* 1 / hx, 1 / hy */
    bool live;            /* false: the cascade holds nothing this frame, no map drawn */
} om__csm_win;

/* A box of the light's image (normalized device coordinates), empty while x0 > x1. */
typedef struct om__csm_box {
    float x0, y0, x1, y1;
} om__csm_box;

typedef struct om__csm {
    om__state_head head;   /* first (method.h) */
    const om_scene *scene;
    om__csm_cfg cfg;
    uint32_t size, n;      /* a map's side, the cascades */
    uint32_t *depth[OM__CSM_MAX];
    uint32_t *hiz[OM__CSM_MAX];   /* each map's coarse depth; NULL: no room */
    om__vsnap *verts;      /* the light pass's vertex cache, one map at a time; NULL: no room */
    om_view view;          /* this frame's */
    /* Each cascade's view: the frame's, its light_vp cropped to the cascade's window
     * (the lookup reads light_vp for texels, light_proj for depth and bias). */
    om_view cview[OM__CSM_MAX];
    om__smlook look[OM__CSM_MAX];
    om__csm_win win[OM__CSM_MAX];
    uint32_t nlive, live[OM__CSM_MAX];   /* the live cascades, in order: the maps drawn */
    bool ready;            /* the windows and cascade views are made for this frame */
    float split[OM__CSM_MAX + 1];   /* view depths: cascade c's slice [split[c], split[c + 1]] */
    float znear, zfar;     /* the view depth the splits share out: the scene's along the view */
    /* The fitted mode's observation: bins of view depth between znear and zfar
     * (edges log-spaced), each with the box of the exposed samples in it and their
     * count. */
    float edge[OM__CSM_BINS + 1];
    om__csm_box bin[OM__CSM_BINS];
    uint32_t bin_n[OM__CSM_BINS];
    uint32_t samples, shadowed;
    uint32_t held[OM__CSM_MAX];   /* this frame's exposed samples each cascade held */
    uint32_t unheld;       /* and those no window held (read from the last live map) */
} om__csm;

/* csm_split.c. The frame's depth range along the view (the scene's, within the
 * camera's near and far) and the fitted mode's bin edges over it; the bins cleared. */
void om__csm_range(om__csm *m);
/* A sample's view depth: its distance in front of the camera along the view axis. */
static inline float om__csm_depth(const om_view *v, om_vec3 p)
{
    const float *r = v->cam_view.m;
    return -(r[8] * p.x + r[9] * p.y + r[10] * p.z + r[11]);
}
/* The bin of view depth d: the last whose lower edge d reaches (the first below). */
uint32_t om__csm_bin(const om__csm *m, float d);
/* The observation of a strip's exposed samples into the bins. */
void om__csm_observe(om__csm *m, const om_strip *st);
/* The practical splits (Zhang et al. 2006): lambda of the logarithmic split plus
 * 1 - lambda of the uniform one, of [lo, hi] into n slices; out[0] = lo, out[n] = hi,
 * never decreasing. */
void om__csm_practical(float lo, float hi, float lambda, uint32_t n, float *out);
/* This frame's splits and windows (practical: the slices of the view's frustum;
 * fitted: the observed samples' bins), then each cascade's view and lookup. */
void om__csm_windows(om__csm *m);
/* The light image coordinates of p through the frame's light_vp `vp`; false behind
 * the light (or NaN). The observation and the pick share it, so the same bits. */
static inline bool om__csm_project(const om_mat4 *vp, om_vec3 p, float *x, float *y)
{
    const om_vec4 q = om__mat_apply(vp, p);
    if (!(q.w > 0.0f)) return false;
    const float iw = 1.0f / q.w;
    *x = q.x * iw;
    *y = q.y * iw;
    return *x == *x && *y == *y;
}
/* Which of the n cascades `win` a sample at point p (relative to the view's origin)
 * reads: the first whose window holds its projection (*held true), else the last
 * live one (*held false); n (none) where no cascade is live or p is behind the
 * light. */
static inline uint32_t om__csm_pick(const om_mat4 *vp, const om__csm_win *win, uint32_t n, om_vec3 p, bool *held)
{
    float x, y;
    *held = false;
    if (!om__csm_project(vp, p, &x, &y)) return n;
    uint32_t last = n;
    for (uint32_t k = 0; k < n; k++) {
        if (!win[k].live) continue;
        if (om__fabsf(x - win[k].cx) <= win[k].limx && om__fabsf(y - win[k].cy) <= win[k].limy) {
            *held = true;
            return k;
        }
        last = k;
    }
    return last;
}

#endif
