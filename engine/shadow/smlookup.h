/* smlookup.h — the biased depth test of a shadow map, shared by the conventional map
 * (sm.c) and the warped one (rtw.c). It owns the bias rules: constant bias in world
 * units along the light ray, slope-scaled bias and normal offset in texels, k x k PCF.
 *
 * A map is a size x size uint32 depth image in the rasterizer's depth format (z/w *
 * 2^32, sampled at texel centres) over the light's image plane. A warped map (RTW) adds
 * a coordinate mapping: it moves normalized light-image coordinates (u right, v down,
 * [0, 1] across the map) to the warped map's, and reports how many warped texels one
 * unwarped texel spans there, so that "a texel" in the bias rules is a warped texel. */
#ifndef OM_SMLOOKUP_H
#define OM_SMLOOKUP_H

#include "../frame/frame.h"

/* Maps (u, v) in place; *density: warped texels per unwarped texel at (u, v) (the
 * smaller of the two axes', so the bias stays on the safe side). */
typedef void (*om__smwarp_fn)(const void *user, double *u, double *v, double *density);

typedef struct om__smlook {
    const om_view *view;
    const uint32_t *depth;     /* size * size, row 0 at the top (v = 0) */
    uint32_t size;
    float bias_const, bias_slope, normal_offset;
    uint32_t pcf;              /* k for k x k, 1 = a single tap */
    float span_per_dist;       /* spot: frustum width per unit of distance */
    om__smwarp_fn warp;        /* NULL: the conventional map */
    const void *warp_user;
} om__smlook;

/* Fills the frame-dependent part (view, span) for this frame's light. */
void om__smlook_begin(om__smlook *L, const om_view *v);
/* The terms of a strip. Each exposed sample's is 255 lit, 0 shadowed, between for
 * partial PCF (never 255 unless every tap is lit); 255 where the sample is not exposed
 * or lies behind the light. Counts the exposed samples and the shadowed ones (term
 * below 255) into *samples, *shadowed. */
void om__smlook_strip(const om__smlook *L, om_strip *st, uint32_t *samples, uint32_t *shadowed);

#endif
