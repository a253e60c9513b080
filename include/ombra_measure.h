/* ombra_measure.h — measuring frames: masks (lit, shadowed, background), a method's
 * mask against the reference's on the same visible samples, difference images,
 * flicker along a path, and the hash the tests and tools compare frames by. Part of
 * the library; include it beside ombra.h. */
#ifndef OMBRA_MEASURE_H
#define OMBRA_MEASURE_H

#include "ombra.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Masks are one byte per pixel: 255 lit, 0 shadowed, 128 background (om_mask_of). */
#define OM_MASK_LIT 255u
#define OM_MASK_SHADOW 0u
#define OM_MASK_BG 128u

static inline uint8_t om_mask_of(const om_sample *s, const om_term *t)
{
    return s->tri == OM_NO_TRI ? (uint8_t)OM_MASK_BG : om_term_lit(t) ? (uint8_t)OM_MASK_LIT
                                                                       : (uint8_t)OM_MASK_SHADOW;
}

/* A method's mask against the reference's on the same visible samples. */
typedef struct om_metrics {
    uint64_t samples;          /* foreground samples compared */
    uint64_t false_lit;        /* lit where the reference is shadowed */
    uint64_t false_shadowed;   /* shadowed where the reference is lit */
    uint64_t edge_samples;     /* samples within OM_EDGE_BAND pixels of a reference edge */
    uint64_t edge_false_lit, edge_false_shadowed;
    uint64_t mismatched_bg;    /* pixels background in one mask only (must be 0) */
} om_metrics;

#define OM_EDGE_BAND 2

/* Compares two whole-frame masks. The edge band: foreground pixels within
 * OM_EDGE_BAND pixels (Chebyshev) of a pixel whose reference state differs. */
void om_compare_masks(const uint8_t *ref, const uint8_t *m, uint32_t width, uint32_t height,
                      om_metrics *out);
/* Share of compared samples that match, 0..1 (1 when nothing was compared). */
double om_metrics_match(const om_metrics *m);
/* Difference image, RGB888: false lit red, false shadowed blue, matches grey (lit
 * light, shadowed dark), background black. */
void om_diff_image(const uint8_t *ref, const uint8_t *m, uint32_t width, uint32_t height,
                   uint8_t *rgb);

/* Flicker along a path: between consecutive frames, samples whose binary state changes
 * in the method's mask while the reference's does not. Feed frames in order. */
typedef struct om_flicker {
    uint64_t samples;          /* foreground samples in both frames */
    uint64_t flicker;          /* changes the reference does not have */
    uint32_t frames;
} om_flicker;

void om_flicker_add(om_flicker *f, const uint8_t *ref_prev, const uint8_t *m_prev,
                    const uint8_t *ref, const uint8_t *m, size_t n);
double om_flicker_share(const om_flicker *f);

/* 64-bit FNV-1a over bytes, chained from `h` (start with OM_HASH_INIT). */
#define OM_HASH_INIT 0xcbf29ce484222325ull
uint64_t om_hash(uint64_t h, const void *data, size_t len);

#ifdef __cplusplus
}
#endif
#endif
