/* asm_point.c — where a sample lands on the Adaptive Shadow Map's light image (asm.h):
 * its place, light depth, bias and footprint ratio, exactly in double (what every
 * decision of the method is defined by), and in float with error bounds (the fast
 * path: a Cortex-M4F runs double in software routines, and every looked-up sample
 * needs dozens of such operations).
 *
 * The float path decides only where its bounds leave no doubt, so the frames, the
 * tree and its statistics are the exact path's. Bounds (u = 2^-24, float's unit
 * roundoff): a row of the light matrix applied to a point, three products and three
 * additions, lies within 4u (1 + 4u) of the sum of the terms' magnitudes of the exact
 * value (Higham, recursive summation), in float and (with 2^-53) in double alike; 2^-21
 * of that sum (8u) covers both and the rounding of the sum itself. A quotient x/w then
 * lies within (ex + |x/w| ew) / w of the exact one, w being bounded below; every
 * further operation adds one rounding, counted as 2^-21 of the result's magnitude or
 * more. The bias terms are products and quotients of float inputs, about 16 roundings:
 * 2^-17 (128u) of each bounds them. The comparisons in asm.h add the stored depth's
 * rounding to float and a few units of room. */
#include "asm.h"
#include "../method.h"

static bool pow2(double x)
{
    if (!(x >= 1.0 && x < 4294967296.0)) return false;
    uint32_t k = (uint32_t)x;
    return (double)k == x && (k & (k - 1)) == 0;
}

static uint32_t log2u(uint32_t k)
{
    uint32_t a = 0;
    while (k > 1u) k >>= 1, a++;
    return a;
}

void om__asm_pctx_begin(om__asm_pctx *c, const om__asm_layout *l, const om__asm_cfg *cfg,
                        const om_view *v)
{
    memset(c, 0, sizeof *c);
    c->view = v;
    c->R = l->tile;
    c->bias_const = cfg->bias_const * (v->light.zfar - v->light.znear);   /* world units */
    c->bias_slope = cfg->bias_slope;
    c->span_per_dist = 2.0f * (float)om__tan((double)v->light.fov_deg * OM_PI / 360.0);
    c->pix_per_dist = 2.0f * (float)om__tan((double)v->cam.fovy_deg * OM_PI / 360.0) / (float)v->cam.height;
    c->dir_texel = 2.0f / om__fabsf(v->light_proj.m[0]) / (float)l->tile;
    c->dir_dz = 4294967296.0f * om__fabsf(v->light_proj.m[10]);
    /* Fixed point for the base texels [0, R): as many fraction bits as keep R * 2^fix
     * within 2^30. Levels whose grid is 2^a times the base's take the top bits. */
    uint32_t fix = 0;
    while (((uint64_t)l->tile + 1) << (fix + 1) <= ((uint64_t)1 << 30)) fix++;
    c->fix = fix;
    for (uint32_t L = 0; L <= l->max_level && L <= OM__ASM_MAX_LEVEL; L++) {
        const double s = l->scale[L];
        if (!pow2(s)) break;
        const uint32_t a = log2u((uint32_t)s);
        if (a > fix) break;
        c->shift[L] = fix - a;
        c->inv_scale[L] = (float)(1.0 / s);   /* a power of two: exact */
        c->fast_levels = L + 1;
    }
    if (!cfg->asm_float || c->fast_levels <= l->max_level) c->fix = 0;   /* the exact path alone */
}

bool om__asm_pt_uv(const om__asm_pctx *c, const om_sample *smp, om__asm_pt *o)
{
    const float *a = c->view->light_vp.m;
    const double px = smp->p[0], py = smp->p[1], pz = smp->p[2];
    const double qx = (double)a[0] * px + (double)a[1] * py + (double)a[2] * pz + (double)a[3];
    const double qy = (double)a[4] * px + (double)a[5] * py + (double)a[6] * pz + (double)a[7];
    const double qz = (double)a[8] * px + (double)a[9] * py + (double)a[10] * pz + (double)a[11];
    const double qw = (double)a[12] * px + (double)a[13] * py + (double)a[14] * pz + (double)a[15];
    if (!(qw > 0.0)) return false;
    const double R = c->R, iw = 1.0 / qw;
    o->u = (qx * iw + 1.0) * 0.5 * R;
    o->v = (1.0 - qy * iw) * 0.5 * R;
    o->z = qz * iw * OM_DEPTH_ONE;
    o->tri = smp->tri;
    return o->u > -1e9 && o->u < 1e9 && o->v > -1e9 && o->v < 1e9 && o->z > -1e30 && o->z < 1e30;
}

/* The sample's normal turned to the camera, and the cosine with the light. */
static float facing(const om_view *v, const om_sample *smp, om_vec3 *n, om_vec3 *e)
{
    const om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]);
    *n = om__v3(smp->n[0], smp->n[1], smp->n[2]);
    *e = om__sub(v->cam.eye, p);
    if (om__dot(*n, *e) < 0.0f) *n = om__scale(*n, -1.0f);
    return om__dot(*n, om__to_light(v, p));
}

void om__asm_pt_bias(const om__asm_pctx *c, const om_sample *smp, om__asm_pt *o, bool analyse)
{
    const om_view *v = c->view;
    const double R = c->R;
    om_vec3 n, e;
    float cosl = facing(v, smp, &n, &e);
    /* A base texel's world size across the light ray, and depth units per world unit
     * along it, as the conventional map computes them. */
    double texel, dz;
    if (v->light.kind == OM_LIGHT_SPOT) {
        const om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]);
        float dist = om__dot(om__sub(p, v->light.pos), v->light_axis);
        double f = v->light.zfar, nn = v->light.znear, ee = dist > nn * 0.5f ? dist : nn * 0.5;
        texel = (double)dist * c->span_per_dist / R;
        dz = f * nn / ((f - nn) * ee * ee) * OM_DEPTH_ONE;
    } else {
        texel = 2.0 / fabs((double)v->light_proj.m[0]) / R;
        dz = OM_DEPTH_ONE * fabs((double)v->light_proj.m[10]);
    }
    double tanl = cosl > 0.0995f ? sqrt(1.0 - (double)cosl * cosl) / cosl : 10.0;
    o->bias_c = (double)c->bias_const * dz;
    o->bias_s = (double)c->bias_slope * texel * tanl * dz;
    o->ratio0 = 0.0;
    if (!analyse) return;
    /* Footprints on the surface (sections 3.1 and 4.1, computed rather than read from a
     * mip-map): an eye pixel spans dist * 2 tan(fovy / 2) / height across the view ray,
     * a texel its size across the light ray; on the surface each covers that squared
     * over the cosine between the normal and its ray (clamped at 0.1). The ratio kept
     * is linear: the square root of the paper's ratio of projected areas. */
    float de = om__sqrtf(om__dot(e, e));
    float cose = de > 0.0f ? om__fabsf(om__dot(n, e)) / de : 1.0f;
    if (cose < 0.1f) cose = 0.1f;
    if (cosl < 0.1f) cosl = 0.1f;
    double pix = (double)de * c->pix_per_dist;
    o->ratio0 = pix > 0.0 ? texel / pix * sqrt((double)cose / (double)cosl) : 0.0;
}

/* ---- the float path (bounds: the file's head) */

bool om__asm_fpt_uv(const om__asm_pctx *c, const om_sample *smp, om__asm_fpt *o)
{
    const float *a = c->view->light_vp.m;
    const float p0 = smp->p[0], p1 = smp->p[1], p2 = smp->p[2];
    float q[4], e[4];
    for (int i = 0; i < 4; i++) {
        const float *r = a + 4 * i;
        const float t0 = r[0] * p0, t1 = r[1] * p1, t2 = r[2] * p2;
        q[i] = ((t0 + t1) + t2) + r[3];
        /* 2^-100: what products lost to underflow, with room */
        e[i] = (om__fabsf(t0) + om__fabsf(t1) + om__fabsf(t2) + om__fabsf(r[3])) * 0x1p-21f + 0x1p-100f;
    }
    const float wl = q[3] - e[3] * 1.001f;   /* the exact w is at least this */
    if (!(wl > 0.0f)) return false;
    o->bias = false;
    o->ratio0 = 0.0f;
    const float iw = 1.0f / q[3], hR = 0.5f * (float)c->R, R = (float)c->R;
    const float X = q[0] * iw, Y = q[1] * iw, Z = q[2] * iw;
    /* each quotient's distance to the exact one (twice: the double's too), and its
     * roundings */
    const float ax = (om__fabsf(q[0]) + e[0]) / wl, ay = (om__fabsf(q[1]) + e[1]) / wl,
                az = (om__fabsf(q[2]) + e[2]) / wl;
    const float ex = 2.0f * (e[0] + ax * e[3]) / wl + ax * 0x1p-21f;
    const float ey = 2.0f * (e[1] + ay * e[3]) / wl + ay * 0x1p-21f;
    const float ez = 2.0f * (e[2] + az * e[3]) / wl + az * 0x1p-21f;
    const float u = (X + 1.0f) * hR, v = (1.0f - Y) * hR;
    const float eu = hR * (ex + (om__fabsf(X) + 1.0f) * 0x1p-21f) + om__fabsf(u) * 0x1p-21f + 0x1p-100f;
    const float ev = hR * (ey + (om__fabsf(Y) + 1.0f) * 0x1p-21f) + om__fabsf(v) * 0x1p-21f + 0x1p-100f;
    const float u0 = u - eu, u1 = u + eu, v0 = v - ev, v1 = v + ev;
    /* inside the base (a point beyond it is clamped by the exact path) */
    if (!(u0 >= 0.0f && v0 >= 0.0f && u1 < R && v1 < R)) return false;
    o->z = Z * 4294967296.0f;
    o->ez = ez * 4294967296.0f;
    if (!(om__fabsf(o->z) + o->ez < 1e29f)) return false;
    /* exact scalings by 2^fix (below 2^30), then floors: truncation of non-negatives */
    const float one = (float)(1u << c->fix);
    o->u0 = (uint32_t)(u0 * one);
    o->u1 = (uint32_t)(u1 * one);
    o->v0 = (uint32_t)(v0 * one);
    o->v1 = (uint32_t)(v1 * one);
    return true;
}

void om__asm_fpt_bias(const om__asm_pctx *c, const om_sample *smp, om__asm_fpt *o, bool analyse)
{
    const om_view *v = c->view;
    om_vec3 n, e;
    float cosl = facing(v, smp, &n, &e);   /* the exact path's float operations */
    float texel, dz;
    if (v->light.kind == OM_LIGHT_SPOT) {
        const om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]);
        const float dist = om__dot(om__sub(p, v->light.pos), v->light_axis);
        const float f = v->light.zfar, nn = v->light.znear, ee = dist > nn * 0.5f ? dist : nn * 0.5f;
        texel = dist * c->span_per_dist / (float)c->R;
        dz = f * nn / ((f - nn) * ee * ee) * 4294967296.0f;
    } else {
        texel = c->dir_texel;
        dz = c->dir_dz;
    }
    /* 1 - c^2 as (1 - c)(1 + c): no cancellation, so a relative bound */
    const float tanl = cosl > 0.0995f ? om__sqrtf((1.0f - cosl) * (1.0f + cosl)) / cosl : 10.0f;
    o->bc = c->bias_const * dz;
    o->bs = c->bias_slope * texel * tanl * dz;
    o->bias = true;
    o->ratio0 = 0.0f;
    if (!analyse) return;
    const float de = om__sqrtf(om__dot(e, e));
    float cose = de > 0.0f ? om__fabsf(om__dot(n, e)) / de : 1.0f;
    if (cose < 0.1f) cose = 0.1f;
    if (cosl < 0.1f) cosl = 0.1f;
    const float pix = de * c->pix_per_dist;
    /* left undecided (0) where float would underflow or the ratio is not positive */
    if (pix > 0x1p-100f && texel > 0x1p-100f) o->ratio0 = texel / pix * om__sqrtf(cose / cosl);
}
