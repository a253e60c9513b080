/* smlookup.h — the biased depth test of a shadow map, shared by the conventional map
 * (sm.c) and the warped one (rtw.c). It owns the bias rules: constant bias as a
 * fraction of the light's depth range, slope-scaled bias and normal offset in texels,
 * k x k PCF: units that scale with the scene, so one setting serves a scene drawn in
 * millimetres or in kilometres.
 *
 * A map is a size x size uint32 depth image in the rasterizer's depth format (z/w *
 * 2^32, sampled at texel centres) over the light's image plane. A warped map (RTW) adds
 * a coordinate mapping, two 1-D tables: it moves normalized light-image coordinates (u
 * right, v down, [0, 1] across the map) to the warped map's, and tells how many warped
 * texels one unwarped texel spans there, so that "a texel" in the bias rules is a
 * warped texel (and PCF's taps are warped texels, unless asked to be unwarped ones). */
#ifndef OM_SMLOOKUP_H
#define OM_SMLOOKUP_H

#include "../../frame/frame.h"

/* A warped map's coordinate mapping (rtw.h): one 1-D table per axis of n + 1
 * fixed-point super-cell edge positions, 1.0 = OM_RTW_ONE, interpolated linearly. */
#define OM_RTW_ONE (1 << 30)

/* Warps one coordinate; *density (if not NULL): warped length per unwarped length
 * there (1 outside [0, 1]). Inline: every lookup and every warped vertex runs it. */
static inline double om__rtw_apply(const int32_t *P, uint32_t n, double u, double *density)
{
    if (!(u > 0.0 && u < 1.0)) {   /* outside the map (and NaN): left alone */
        if (density) *density = 1.0;
        return u;
    }
    double t = u * (double)n;
    uint32_t k = (uint32_t)t;
    if (k > n - 1) k = n - 1;
    double f = t - (double)k, a = (double)P[k], b = (double)P[k + 1];
    if (density) *density = (b - a) * (double)n / (double)OM_RTW_ONE;
    return (a + f * (b - a)) / (double)OM_RTW_ONE;
}

typedef struct om__smlook {
    const om_view *view;
    const uint32_t *depth;     /* size * size, row 0 at the top (v = 0) */
    uint32_t size;
    /* The share of the light's image, across, that the map covers: 1 for a map of the
     * whole image (sm, rtw), less for a window of it (csm's cascades, whose light_vp
     * is cropped to it); a texel's world size shrinks with it. */
    float window;
    float bias_const;          /* fraction of the light's depth range (far - near) */
    float bias_slope, normal_offset;   /* texels */
    uint32_t pcf;              /* k for k x k, 1 = a single tap */
    float bias_world;          /* this frame's constant bias, world units along the
                                * light ray: bias_const (far - near) */
    float span_per_dist;       /* spot: frustum width per unit of distance */
    float dz_num, dz_den, half_near;   /* spot: far * near, far - near, near / 2 */
    /* The bias in depth units for an unwarped map (om__smlook_biased): a spot light's
     * c1 / e^2 + c2 tan / e at distance e along its axis, a directional light's
     * c1 + c2 tan. */
    float bias_c1, bias_c2;
    /* A warped map's tables (n + 1 entries each), NULL for the conventional map: u
     * and v are warped by them, and "a texel" in the bias rules is a warped one. */
    const int32_t *warp_x, *warp_y;
    uint32_t warp_n;
    /* With a warped map: PCF taps one unwarped texel (1 / size of the light's image)
     * apart, each warped on its own, rather than one warped texel apart (RTW section
     * 6.2: the filter then covers the same area of the light's image everywhere). */
    bool unwarped_pcf;
} om__smlook;

/* Fills the frame-dependent part (view, span, bias_world) for this frame's light. */
void om__smlook_begin(om__smlook *L, const om_view *v);
/* The terms of a strip. Each exposed sample's is 255 lit, 0 shadowed, between for
 * partial PCF (never 255 unless every tap is lit); 255 where the sample is not exposed
 * or lies behind the light. Counts the exposed samples and the shadowed ones (term
 * below 255) into *samples, *shadowed. */
void om__smlook_strip(const om__smlook *L, om_strip *st, uint32_t *samples, uint32_t *shadowed);
/* The term of one exposed sample, as om__smlook_strip gives it: for a method that
 * picks one of several maps per sample (csm). */
uint8_t om__smlook_sample(const om__smlook *L, const om_sample *smp);

/* The tangent of the angle between a sample's normal and the light, from their
 * cosine (the sample's nl), at most 10. */
static inline float om__smlook_tan(float cosang)
{
    return cosang > 0.0995f ? om__sqrtf(1.0f - cosang * cosang) / cosang : 10.0f;
}

/* The biased depth of a sample of an unwarped map: its light depth z (z/w * 2^32)
 * less the bias in depth units, for a spot light at r = 1 / e (e: its distance along
 * the light's axis, at least half the near plane's), tanang the tangent of its angle
 * to the light. The world bias bias_const (far - near) + bias_slope texel tan, with a
 * texel's world size e span / size, times d(z/w)/de = f n / ((f - n) e^2) makes
 * c1 / e^2 + c2 tan / e: one reciprocal, which the projection's 1 / w gives where
 * e is w. */
static inline float om__smlook_biased(float c1, float c2, bool spot, float z, float r, float tanang)
{
    return spot ? z - r * (c1 * r + c2 * tanang) : z - (c1 + c2 * tanang);
}

/* The light depth z/w * 2^32 of a point whose projection through the view's light_vp
 * is q (iw = 1 / q.w) on an unwarped map; proj: the view's light_proj. A spot light's perspective makes z = m10
 * zv + m11 and w = -zv of the point's view depth zv (om__mat_perspective), so z/w is
 * m11 / w - m10: from the 1 / w at hand, without the matrix's z row. */
static inline float om__smlook_depth(const om_mat4 *proj, bool spot, om_vec4 q, float iw)
{
    return spot ? (proj->m[11] * iw - proj->m[10]) * OM_DEPTH_ONE_F : q.z * iw * OM_DEPTH_ONE_F;
}

/* A texel coordinate clamped to a map of `size` texels. */
static inline uint32_t om__smlook_clamp(int32_t x, uint32_t size)
{
    return x < 0 ? 0u : (uint32_t)x >= size ? size - 1 : (uint32_t)x;
}

/* The texel of a coordinate f (in texels) on a map of `size`, clamped: below 0 (or
 * NaN) the first texel, from `size` on the last, between them the truncation, which
 * is the floor there. */
static inline uint32_t om__smlook_texel(float f, uint32_t size)
{
    return f >= 0.0f ? (f < (float)size ? (uint32_t)f : size - 1) : 0u;
}

/* The least stored depth a biased sample depth z is not behind: z <= D for a stored
 * integer D exactly when ceil(z) <= D (a NaN never is: 2^32 + 1). Integer compares per
 * tap rather than conversions to double, which a Cortex-M4F runs in software. The
 * ceiling through a 32-bit conversion is exact: (float)t is z itself once z >= 2^23.
 * sm's and rtw's lookups both test with it. */
static inline uint64_t om__smlook_threshold(float z)
{
    if (z != z) return (1ull << 32) + 1;
    if (!(z > 0.0f)) return 0;
    if (!(z < OM_DEPTH_ONE_F)) return 1ull << 32;
    const uint32_t t = (uint32_t)z;
    return (uint64_t)t + ((float)t < z);
}

/* om__smlook_threshold(z) <= d, without the 64-bit sum and compare: within the map's
 * range, t = trunc(z) below d or, equal to it, with z no further than t (the threshold
 * is t there); z <= 0 is lit, NaN and z >= 2^32 never. The plain map's one tap tests
 * with it (smlookup.c); the same answer as the threshold's compare for every z and d. */
static inline bool om__smlook_lit(float z, uint32_t d)
{
    if (z > 0.0f && z < OM_DEPTH_ONE_F) {
        const uint32_t t = (uint32_t)z;
        if (t != d) return t < d;
        return !((float)t < z);
    }
    return !(z > 0.0f) && z == z;
}

#endif
