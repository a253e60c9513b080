/* smlookup.c — the biased shadow-map depth test (see smlookup.h), moved out of sm.c so
 * that the RTW map uses the very same rules; for the conventional map (warp_x == NULL)
 * every operation is the one sm.c always did, so its frames are unchanged.
 *
 * The bias is made in world units along the light ray and converted to depth units at
 * the sample:
 *     bias = bias_const * (far - near) + bias_slope * texel * tan(angle between normal and light)
 * (far - near: the light's depth range, a directional light's the scene's extent
 * along it; texel = the world size of one texel at the sample; tan clamped at 10), so
 * the constant term is a fraction of the range and the slope term is in texels: both
 * scale with the scene. k x k PCF averages the binary tests; a sample is lit only when
 * every tap is. */
#include "smlookup.h"

void om__smlook_begin(om__smlook *L, const om_view *v)
{
    L->view = v;
    L->span_per_dist = 2.0f * (float)om__tan((double)v->light.fov_deg * OM_PI / 360.0);
    L->dz_num = v->light.zfar * v->light.znear;   /* the same roundings as per sample */
    L->dz_den = v->light.zfar - v->light.znear;
    L->half_near = v->light.znear * 0.5f;
    L->bias_world = L->bias_const * L->dz_den;   /* a fraction of the depth range */
    const float fsize = (float)L->size;
    if (v->light.kind == OM_LIGHT_SPOT) {
        const float k = L->dz_num / L->dz_den * OM_DEPTH_ONE_F;
        L->bias_c1 = L->bias_world * k;
        L->bias_c2 = L->bias_slope * (L->span_per_dist * L->window / fsize) * k;
    } else {
        const float k = OM_DEPTH_ONE_F * om__fabsf(v->light_proj.m[10]);
        L->bias_c1 = L->bias_world * k;
        L->bias_c2 = L->bias_slope * (2.0f / om__fabsf(v->light_proj.m[0]) * L->window / fsize) * k;
    }
}

/* World size of one (unwarped) texel at distance `dist` along the light's axis. */
static float texel_world(const om__smlook *L, float dist)
{
    const om_view *v = L->view;
    float span = v->light.kind == OM_LIGHT_SPOT ? dist * L->span_per_dist
                                                : 2.0f / om__fabsf(v->light_proj.m[0]);
    return span * L->window / (float)L->size;
}

/* Warps (u, v) in place; *density: warped texels per unwarped texel there, the
 * smaller axis's (the bias then covers the larger warped texel), kept above a sliver:
 * a sample in a collapsed super-cell (possible only just outside what the analysis
 * saw) must not get an infinite bias. In line, with the tables in the struct rather
 * than behind a callback: every sample of a warped map runs it. */
static inline void warp(const om__smlook *L, double *u, double *v, double *density)
{
    double dx, dy;
    *u = om__rtw_apply(L->warp_x, L->warp_n, *u, &dx);
    *v = om__rtw_apply(L->warp_y, L->warp_n, *v, &dy);
    double dmin = dx < dy ? dx : dy;
    *density = dmin > 1.0 / 64.0 ? dmin : 1.0 / 64.0;
}

/* floor(f) for a texel coordinate, limited to 16 texels beyond either side of the
 * map: every PCF tap (k <= 9) of a texel further out clamps to the same edge texel. */
static inline int32_t texel_floor(float f, uint32_t size)
{
    const float hi = (float)size + 16.0f;
    return f > -16.0f ? (f < hi ? om__floorf_i32(f) : (int32_t)size + 16) : -16;
}

/* The same for a warped coordinate (in texels, double). */
static inline int32_t texel_floor_d(double f, uint32_t size)
{
    const double hi = (double)size + 16.0;
    return f > -16.0 ? (f < hi ? (int32_t)floor(f) : (int32_t)size + 16) : -16;
}

/* Where one sample's test looks: its biased depth, the texel under it clamped to the
 * map (`at`, its index: the one tap without PCF) and, for PCF, before the clamp; for a
 * warped map also where it lies before the warp (normalized coordinates), from which
 * unwarped PCF taps are placed. */
typedef struct tap { uint64_t zlit; uint32_t at; int32_t cx, cy; double u, v; } tap;


/* All of the test's arithmetic; false when the sample is behind the light. */
static bool locate(const om__smlook *L, const om_sample *smp, tap *out)
{
    const om_view *v = L->view;
    om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]);
    float dist = v->light.kind == OM_LIGHT_SPOT ? om__dot(om__sub(p, v->light.pos), v->light_axis) : 1.0f;
    float texel = texel_world(L, dist);
    double u0 = 0.0, v0 = 0.0;
    om_vec4 q0 = {0.0f, 0.0f, 0.0f, 0.0f};
    if (L->warp_x) {
        /* A warped texel covers 1/density of an unwarped one: where the warp stretches
         * the map, texels are smaller in the world and the bias shrinks with them. */
        q0 = om__mat_apply(&v->light_vp, p);
        if (!(q0.w > 0.0f)) return false;
        double iw0 = 1.0 / (double)q0.w, dens = 1.0;
        u0 = ((double)q0.x * iw0 + 1.0) * 0.5;
        v0 = (1.0 - (double)q0.y * iw0) * 0.5;
        out->u = u0;
        out->v = v0;
        warp(L, &u0, &v0, &dens);
        /* Unwarped PCF taps lie an unwarped texel apart, and the bias must cover the
         * receiver's depth across that span as well as across the warped texel each
         * tap reads: the larger of the two, where the warp compresses the map. */
        if (!(L->unwarped_pcf && L->pcf > 1) || dens < 1.0)
            texel = (float)((double)texel / dens);
    }
    const float tanang = om__smlook_tan(smp->nl);   /* nl: kept by the exposure marks */
    om_vec4 q;
    if (L->warp_x && L->normal_offset == 0.0f) {
        q = q0;   /* the point did not move: its projection and warp are done */
    } else {
        /* Without an offset p + n * 0 is p (up to the sign of a zero coordinate,
         * which no comparison or rounding below sees), so the normal is left alone. */
        if (L->normal_offset != 0.0f) {
            om_vec3 n = om__v3(smp->n[0], smp->n[1], smp->n[2]);
            if (om__dot(n, om__sub(v->cam.eye, p)) < 0.0f) n = om__scale(n, -1.0f);
            p = om__add(p, om__scale(n, L->normal_offset * texel));
        }
        q = om__mat_apply(&v->light_vp, p);
        if (!(q.w > 0.0f)) return false;
    }
    /* The plain map's texel and every map's depth in float: per sample, the work a
     * Cortex-M4F does in hardware. A float's 24 bits place the texel to 2^-11 of one at
     * 8192 texels, and the depth to 2^8 of the 2^32 units, far inside the bias; the
     * comparison with the stored depths stays exact (test). The warp keeps double:
     * its tables' fractions need it. */
    const float iw = 1.0f / q.w;
    if (L->warp_x) {
        if (L->normal_offset != 0.0f) {   /* the point moved: warp it anew */
            double dens, diw = 1.0 / (double)q.w;
            u0 = ((double)q.x * diw + 1.0) * 0.5;
            v0 = (1.0 - (double)q.y * diw) * 0.5;
            out->u = u0;
            out->v = v0;
            warp(L, &u0, &v0, &dens);
        }
        out->cx = texel_floor_d(u0 * L->size, L->size);
        out->cy = texel_floor_d(v0 * L->size, L->size);
        out->at = om__smlook_clamp(out->cy, L->size) * L->size + om__smlook_clamp(out->cx, L->size);
    } else {
        out->u = out->v = 0.0;   /* no warp: taps are the map's texels */
        const float uf = (q.x * iw + 1.0f) * (0.5f * (float)L->size);
        const float wf = (1.0f - q.y * iw) * (0.5f * (float)L->size);
        out->at = om__smlook_texel(wf, L->size) * L->size + om__smlook_texel(uf, L->size);
        if (L->pcf > 1) {
            out->cx = texel_floor(uf, L->size);
            out->cy = texel_floor(wf, L->size);
        } else {
            out->cx = out->cy = 0;   /* one tap: `at` is all the test reads */
        }
    }
    if (!L->warp_x) {   /* the distance as plain_locate takes it: the unmoved point's w */
        const bool spot = v->light.kind == OM_LIGHT_SPOT;
        const float z = om__smlook_depth(&v->light_proj, spot, q, iw);
        float r = 0.0f;
        if (spot) {
            const float w = L->normal_offset == 0.0f
                                ? q.w   /* the point did not move */
                                : om__mat_apply(&v->light_vp, om__v3(smp->p[0], smp->p[1], smp->p[2])).w;
            r = 1.0f / (w > L->half_near ? w : L->half_near);
        }
        out->zlit = om__smlook_threshold(om__smlook_biased(L->bias_c1, L->bias_c2, spot, z, r, tanang));
        return true;
    }
    /* a warped map's depth, and its bias from world units to depth units,
     * d(z/w)/d(distance) at this sample, in the order rtw.c's float lookup repeats bit
     * for bit */
    const float z = q.z * iw * OM_DEPTH_ONE_F;
    float dz;
    if (v->light.kind == OM_LIGHT_SPOT) {
        const float e = dist > L->half_near ? dist : L->half_near;
        dz = L->dz_num / (L->dz_den * e * e) * OM_DEPTH_ONE_F;   /* f n / ((f - n) e e) */
    } else {
        dz = OM_DEPTH_ONE_F * om__fabsf(v->light_proj.m[10]);
    }
    const float bias = L->bias_world + L->bias_slope * texel * tanang;
    out->zlit = om__smlook_threshold(z - bias * dz);
    return true;
}

/* The texel (before the clamp) that an unwarped tap `d` texels from the sample falls
 * in, along one axis: the tap is placed before the warp, then warped on its own. */
static int64_t unwarped_tap(const int32_t *P, uint32_t n, uint32_t size, double at, int d)
{
    return (int64_t)floor(om__rtw_apply(P, n, at + (double)d / (double)size, NULL) * size);
}

/* The map loads: k x k taps around the texel (or, for unwarped PCF, around the
 * sample's unwarped position), each clamped to the map. */
static inline int32_t clamp_texel(int64_t x, uint32_t size)
{
    return x < 0 ? 0 : x >= (int64_t)size ? (int32_t)size - 1 : (int32_t)x;
}

static uint8_t test(const om__smlook *L, const tap *tp)
{
    const uint64_t z = tp->zlit;
    if (L->pcf == 1) return z <= L->depth[tp->at] ? 255 : 0;   /* one tap, without the loops */
    int k = (int)L->pcf, half = k / 2, lit = 0;
    int64_t tx[9], ty[9];   /* pcf <= 9 */
    for (int d = -half; d < k - half; d++) {
        const bool spread = L->unwarped_pcf && L->warp_x && d != 0;
        tx[d + half] = spread ? unwarped_tap(L->warp_x, L->warp_n, L->size, tp->u, d) : tp->cx + d;
        ty[d + half] = spread ? unwarped_tap(L->warp_y, L->warp_n, L->size, tp->v, d) : tp->cy + d;
    }
    for (int j = 0; j < k; j++)
        for (int i = 0; i < k; i++)
            lit += z <= L->depth[(size_t)clamp_texel(ty[j], L->size) * L->size + (size_t)clamp_texel(tx[i], L->size)];
    uint8_t val = (uint8_t)((255 * lit + k * k / 2) / (k * k));
    if (lit < k * k && val == 255) val = 254;   /* partly shadowed is never "lit" */
    return val;
}

/* Locating a block of samples first and testing them after keeps the test loop short
 * and its loads independent, so that many of them are in flight at once; and each
 * tap's centre texel is asked for as soon as it is located, so that the load is on its
 * way while the rest of the block is located. A warped map spreads the view over the
 * whole map, and its loads miss the cache: the hint overlaps those misses with the
 * locating. The hint changes no term: they are the same as testing sample by
 * sample. */
#define SMLOOK_BLOCK 32

/* The plain map with one tap and no normal offset (sm's usual settings): the
 * operations of locate and test for that case, in their order (so the same bits),
 * with what does not change within a strip (the map's size as a float, a
 * directional light's texel and depth slope) worked out once rather than per sample. */
typedef struct plain {
    om_mat4 vp;
    bool spot;
    uint32_t size;
    float half, half_near, inv_half_near, c1, c2;
    om_mat4 proj;   /* the light's projection: om__smlook_depth reads two of its values */
} plain;

/* A sample's biased depth (om__smlook_lit tests it) and texel index; false when it is
 * behind the light. `spot` is P->spot, a constant where the callers are inlined. A
 * spot light's distance along its axis is the projection's w, so its 1 / w serves
 * the bias too (om__smlook_biased). */
OM_INLINE bool plain_locate(const plain *P, const bool spot, const om_sample *smp,
                          float *zb, uint32_t *at)
{
    const om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]);
    const float tanang = om__smlook_tan(smp->nl);
    const om_vec4 q = om__mat_apply(&P->vp, p);
    if (!(q.w > 0.0f)) return false;
    const float iw = 1.0f / q.w;
    const float uf = (q.x * iw + 1.0f) * P->half;
    const float wf = (1.0f - q.y * iw) * P->half;
    *at = om__smlook_texel(wf, P->size) * P->size + om__smlook_texel(uf, P->size);
    const float z = om__smlook_depth(&P->proj, spot, q, iw);
    const float r = spot ? (q.w > P->half_near ? iw : P->inv_half_near) : 0.0f;
    *zb = om__smlook_biased(P->c1, P->c2, spot, z, r, tanang);
    return true;
}

/* A microcontroller's loads take a cycle or two: there (OM_SMLOOK_DIRECT, 1 on
 * Cortex-M cores; define it 1 elsewhere to try it) each sample is tested as soon as it
 * is located. The same terms either way. Both this loop and plain_locate must sit in
 * line (OM_INLINE): gcc for the M4 otherwise calls them, with `spot` a variable, and
 * every constant of P is loaded again per sample. */
#if OM_SMLOOK_DIRECT
OM_INLINE void plain_tests(const plain *P, const bool spot, const uint32_t *depth, om_strip *st,
                          size_t n, uint32_t *samples, uint32_t *shadowed)
{
    uint32_t nsamples = 0, nshadowed = 0;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;   /* constants the loop keeps in registers */
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        nsamples++;
        float zb;
        uint32_t at;
        if (plain_locate(P, spot, &st->samples[i], &zb, &at) && !om__smlook_lit(zb, depth[at])) {
            t->r = t->g = t->b = 0;
            nshadowed++;
        }
    }
    *samples += nsamples;
    *shadowed += nshadowed;
}
#endif

static void strip_plain(const om__smlook *L, om_strip *st, uint32_t *samples, uint32_t *shadowed)
{
    const om_view *v = L->view;
    plain P;
    P.vp = v->light_vp;
    P.spot = v->light.kind == OM_LIGHT_SPOT;
    P.size = L->size;
    P.half = 0.5f * (float)L->size;
    P.half_near = L->half_near;
    P.inv_half_near = 1.0f / L->half_near;   /* as locate's 1 / max(w, half_near) */
    P.c1 = L->bias_c1;
    P.c2 = L->bias_c2;
    P.proj = v->light_proj;
    const uint32_t *depth = L->depth;
    const size_t n = (size_t)st->rows * st->width;
    uint32_t nsamples = 0, nshadowed = 0;
#if OM_SMLOOK_DIRECT
    if (P.spot) plain_tests(&P, true, depth, st, n, &nsamples, &nshadowed);
    else plain_tests(&P, false, depth, st, n, &nsamples, &nshadowed);
#else
    /* Blocks, as om__smlook_strip's (below), with the taps kept as their biased depth
     * and index alone. */
    float zb[SMLOOK_BLOCK];
    uint32_t at[SMLOOK_BLOCK], idx[SMLOOK_BLOCK];
    for (size_t i = 0; i < n;) {
        int got = 0;
        for (; i < n && got < SMLOOK_BLOCK; i++) {
            om_term *t = &st->terms[i];
            t->r = t->g = t->b = 255;
            if (!(t->flags & OM_TERM_EXPOSED)) continue;
            nsamples++;
            if (plain_locate(&P, P.spot, &st->samples[i], &zb[got], &at[got])) {
#if defined(__GNUC__) || defined(__clang__)
                __builtin_prefetch(&depth[at[got]]);
#endif
                idx[got++] = (uint32_t)i;
            }
        }
        for (int j = 0; j < got; j++) {
            const uint8_t val = om__smlook_lit(zb[j], depth[at[j]]) ? 255 : 0;
            om_term *t = &st->terms[idx[j]];
            t->r = t->g = t->b = val;
            nshadowed += val != 255;
        }
    }
#endif
    *samples += nsamples;
    *shadowed += nshadowed;
}

void om__smlook_strip(const om__smlook *Lin, om_strip *st, uint32_t *samples, uint32_t *shadowed)
{
    /* Copies on the stack, once a strip: the terms' byte stores may alias any memory
     * the caller's pointers reach, so every field would be loaded again per sample. */
    const om_view view = *Lin->view;
    om__smlook look = *Lin;
    look.view = &view;
    const om__smlook *L = &look;
    if (!L->warp_x && L->pcf == 1 && L->normal_offset == 0.0f) {
        strip_plain(L, st, samples, shadowed);
        return;
    }
    const size_t n = (size_t)st->rows * st->width;
    tap taps[SMLOOK_BLOCK];
    uint32_t at[SMLOOK_BLOCK];   /* strip index of each located sample */
    uint32_t nsamples = 0, nshadowed = 0;   /* counted here: *samples may alias the terms */
    for (size_t i = 0; i < n;) {
        int got = 0;
        for (; i < n && got < SMLOOK_BLOCK; i++) {
            om_term *t = &st->terms[i];
            t->r = t->g = t->b = 255;
            if (!(t->flags & OM_TERM_EXPOSED)) continue;
            nsamples++;
            if (locate(L, &st->samples[i], &taps[got])) {
#if defined(__GNUC__) || defined(__clang__)
                __builtin_prefetch(&L->depth[taps[got].at]);
#endif
                at[got++] = (uint32_t)i;
            }
        }
        for (int j = 0; j < got; j++) {
            uint8_t val = test(L, &taps[j]);
            om_term *t = &st->terms[at[j]];
            t->r = t->g = t->b = val;
            nshadowed += val != 255;
        }
    }
    *samples += nsamples;
    *shadowed += nshadowed;
}

uint8_t om__smlook_sample(const om__smlook *L, const om_sample *smp)
{
    tap t;
    return locate(L, smp, &t) ? test(L, &t) : 255;
}
