/* spsm_texel.c — the SPSM's storage formats (paper 004, sections 3.3 and 3.4) and its
 * tangent look-up table (section 4.2, Figure 8): vertex offsets in 16 bits, depth
 * derivatives in 8 bits, and the 512 depth-test patterns. Everything here is integer
 * or built from the engine's deterministic functions, so every build agrees. */
#include "spsm_texel.h"

/* ---- o16 vertex offsets (section 3.3; our choice of code, see spsm_texel.h) */

/* Bits in x > 0: one instruction where the compiler offers it (the pack runs per
 * texel written, and far vertices are the wide case), else five steps. */
static unsigned bit_length(uint32_t x)
{
#if defined(__GNUC__) || defined(__clang__)
    return 32u - (unsigned)__builtin_clz(x);
#else
    unsigned len = 1;
    if (x >> 16) { x >>= 16; len += 16; }
    if (x >> 8) { x >>= 8; len += 8; }
    if (x >> 4) { x >>= 4; len += 4; }
    if (x >> 2) { x >>= 2; len += 2; }
    if (x >> 1) len += 1;
    return len;
#endif
}

/* The code of |v| >= 2048 (e > 0), apart so that the exact range below stays small
 * enough to be inlined into the pack, which runs for every texel written. */
static uint16_t o16_wide(uint16_t sign, uint64_t a)
{
    const uint16_t top = (uint16_t)(sign | (15u << 11) | 2047u);
    if (a >> 32) return top;   /* far beyond the largest code (about 2^26) */
    unsigned e = bit_length((uint32_t)a) - 11;
    /* round half up to the step 2^(e-1); a carry moves to the next exponent */
    uint64_t m = e == 1 ? a : (a + (1ull << (e - 2))) >> (e - 1);
    if (m >= 4096u) { m >>= 1; e++; }
    if (e > 15) return top;   /* saturate */
    return (uint16_t)(sign | (e << 11) | (unsigned)(m - 2048u));
}

/* In line in the pack, which runs for every texel written. */
static inline uint16_t o16_encode(int64_t v)
{
    /* offsets of a small triangle's vertices from the texels it covers: mostly exact */
    if (v > -2048 && v < 2048) return (uint16_t)(v < 0 ? 0x8000u | (unsigned)-v : (unsigned)v);
    return v < 0 ? o16_wide(0x8000u, (uint64_t)(-(v + 1)) + 1u) : o16_wide(0, (uint64_t)v);
}

uint16_t om__spsm_o16_encode(int64_t v)
{
    return o16_encode(v);
}

/* ---- derivative code (section 3.4) */

uint8_t om__spsm_q_encode(double d)
{
    if (d != d) return 127;
    if (d < 0) return (uint8_t)(254 - om__spsm_q_encode(-d));   /* odd, exactly */
    double x = 2.0 / OM_PI * om__atan(d);
    double x5 = x * x * x * x * x;     /* odd power: the sign survives (Equation 3) */
    double v = floor(127.0 * (1.0 + x5) + 0.5);
    return (uint8_t)(v < 0.0 ? 0.0 : v > 254.0 ? 254.0 : v);
}

/* Equation 4 at a real-valued code: the signed fifth root, then tan. */
static double decode_at(double q)
{
    double y = q / 127.0 - 1.0;
    if (y == 0.0) return 0.0;
    double r = om__exp2(om__log2(fabs(y)) / 5.0);
    if (r > 1.0) r = 1.0;
    return om__tan(OM_PI / 2.0 * (y < 0.0 ? -r : r));
}

void om__spsm_qtable_build(om__spsm_qtable *t)
{
    /* The positive half, mirrored: the code is odd, and the table is exactly so. */
    t->dec[127] = t->err[127] = 0.0;
    for (int q = 128; q < 254; q++) t->dec[q] = decode_at((double)q);
    t->dec[254] = 2.0 * t->dec[253];   /* tan(pi/2): the code saturates */
    /* A derivative d gets code q when the rounding boundaries q -+ 1/2 enclose it; the
     * bound is the larger distance from the decoded value to either boundary. */
    for (int q = 127; q < 254; q++) {
        double lo = q == 127 ? -decode_at(127.5) : decode_at((double)q - 0.5), hi = decode_at((double)q + 0.5);
        t->err[q] = fmax(t->dec[q] - lo, hi - t->dec[q]);
    }
    /* Saturated codes stand for every steeper slope: no bound but their own size. */
    t->err[254] = t->dec[254];
    for (int q = 0; q < 127; q++) {
        t->dec[q] = -t->dec[254 - q];
        t->err[q] = t->err[254 - q];
    }
    t->dec[255] = t->err[255] = 0.0;
    for (int q = 0; q < 256; q++) {
        t->decf[q] = (float)(t->dec[q] * (65536.0 * OM_SPSM_DSCALE / OM_SUBPIX));
        t->errf[q] = (float)(t->err[q] * (65536.0 * OM_SPSM_DSCALE / OM_SUBPIX));
    }
    for (int k = 0; k < 127; k++) t->up[k] = (float)decode_at(127.5 + k);
    t->up[127] = HUGE_VALF;
}

uint8_t om__spsm_q_encode_f(const om__spsm_qtable *t, float d)
{
    if (d != d) return 127;
    const float a = om__fabsf(d);
    /* the number of boundaries at or below a (up[] rises): a bisection of 7 steps */
    unsigned lo = 0;
    for (unsigned half = 64; half; half >>= 1)
        if (t->up[lo + half - 1] <= a) lo += half;
    return (uint8_t)(d < 0.0f ? 127 - lo : 127 + lo);
}

/* ---- tangent table (section 4.2) */

static bool bit(unsigned m, int dx, int dy)
{
    if (dx < -1 || dx > 1 || dy < -1 || dy > 1) return false;
    return (m >> ((dy + 1) * 3 + (dx + 1))) & 1u;
}

void om__spsm_tangent_build(om__spsm_tangent lut[512])
{
    /* Candidate tangents for symmetric patterns (first moment zero): the one along which
     * the occluding texels spread most, compared without division or roots. */
    static const int cand[8][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}, {2, 1}, {1, 2}, {2, -1}, {1, -2}};
    for (unsigned m = 0; m < 512; m++) {
        om__spsm_tangent *e = &lut[m];
        memset(e, 0, sizeof *e);
        /* Figure 7(b, c): a texel with no 4-neighbour in the pattern is isolated; the
         * conservative rasterization guarantees the silhouette does not come from it.
         * The sample's own texel is kept whatever its neighbours. */
        unsigned keep = 0;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                if (!bit(m, dx, dy)) continue;
                bool centre = dx == 0 && dy == 0;
                if (centre || bit(m, dx - 1, dy) || bit(m, dx + 1, dy) || bit(m, dx, dy - 1) ||
                    bit(m, dx, dy + 1))
                    keep |= 1u << ((dy + 1) * 3 + (dx + 1));
            }
        e->keep = (uint16_t)keep;
        if (keep == 0 || keep == 511) continue;
        int gx = 0, gy = 0;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++)
                if (bit(keep, dx, dy)) { gx += dx; gy += dy; }
        if (gx != 0 || gy != 0) {
            /* the occluders' side: the shadow lies towards their first moment */
            e->nn = 1;
            e->n[0][0] = (int8_t)gx;
            e->n[0][1] = (int8_t)gy;
            continue;
        }
        /* Balanced pattern: a thin occluder through the texel. Its tangent is the axis of
         * largest spread; the shadow may lie on either side, so both normals are tried. */
        int best = -1, second = -1;
        int64_t bnum = -1, bden = 1, snum = -1, sden = 1;
        for (int c = 0; c < 8; c++) {
            int64_t num = 0, den = cand[c][0] * cand[c][0] + cand[c][1] * cand[c][1];
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    if (bit(keep, dx, dy)) {
                        int64_t p = dx * cand[c][0] + dy * cand[c][1];
                        num += p * p;
                    }
            if (best < 0 || num * bden > bnum * den) {
                second = best; snum = bnum; sden = bden;
                best = c; bnum = num; bden = den;
            } else if (second < 0 || num * sden > snum * den) {
                second = c; snum = num; sden = den;
            }
        }
        if (bnum * sden == snum * bden) continue;   /* isotropic: no tangent */
        e->nn = 2;
        e->n[0][0] = (int8_t)-cand[best][1];
        e->n[0][1] = (int8_t)cand[best][0];
        e->n[1][0] = (int8_t)cand[best][1];
        e->n[1][1] = (int8_t)-cand[best][0];
    }
}

/* ---- packing (section 3.3, Figure 4) */

void om__spsm_row_codes(uint16_t vy[3], const om__rtri *t, int32_t y)
{
    const int64_t cy = (int64_t)y * OM_SUBPIX + OM_SUBPIX / 2;
    for (int i = 0; i < 3; i++) vy[i] = o16_encode(t->e.y[i] - cy);
}

void om__spsm_pack_row(om__spsm_texel *out, const om__rtri *t, int32_t x, uint8_t qx, uint8_t qy,
                       const uint16_t vy[3], uint16_t z)
{
    const om__tri2 *e = &t->e;
    const int64_t cx = (int64_t)x * OM_SUBPIX + OM_SUBPIX / 2;
    for (int i = 0; i < 3; i++) {
        out->vx[i] = o16_encode(e->x[i] - cx);
        out->vy[i] = vy[i];
    }
    out->z = z;
    out->qx = qx;
    out->qy = qy;
}

uint16_t om__spsm_centre_z(const om__rtri *t, int32_t x, int32_t y)
{
    const om__tri2 *e = &t->e;
    const int64_t cx = (int64_t)x * OM_SUBPIX + OM_SUBPIX / 2, cy = (int64_t)y * OM_SUBPIX + OM_SUBPIX / 2;
    /* The plane at the centre, not clamped to the triangle's depth range: the lookup
     * extrapolates from here with the derivatives (Equation 1). */
    double z = t->z0 + t->zx * (double)(cx - e->x[0]) + t->zy * (double)(cy - e->y[0]);
    double s = floor(z / 65536.0 + 0.5);
    return (uint16_t)(s >= 0.0 ? (s > 65535.0 ? 65535.0 : s) : 0.0);   /* NaN: 0 */
}

void om__spsm_pack(om__spsm_texel *out, const om__rtri *t, int32_t x, int32_t y, uint8_t qx,
                   uint8_t qy)
{
    uint16_t vy[3];
    om__spsm_row_codes(vy, t, y);
    om__spsm_pack_row(out, t, x, qx, qy, vy, om__spsm_centre_z(t, x, y));
}

/* ---- the build's plane without double (om__spsm_fplane, spsm_texel.h)
 *
 * om__rtri_plane's slope along x is zx = fl(fl(fl(dz1 y2) - fl(dz2 y1)) fl(1 / area2))
 * (offsets from vertex 0, each product below 2^62): it is within 2^-50 S / area2 of
 * the exact nx / area2, nx = dz1 y2 - dz2 y1 (exact here in 64 bits) and S = |dz1 y2| +
 * |dz2 y1| (two roundings of the products, one of the difference, two of the
 * reciprocal and product, each 2^-53, and |nx| <= S). The float nx / area2 is within
 * 2^-21 of itself (three roundings of at most an ulp). So the double slope lies within
 * B = 2^-20 |zx_f| + 2^-49 S / area2 of the float one, twice the sum of the bounds.
 * A slope's code and direction follow the double slope monotonically (its float, then
 * a bisection of the code's boundaries), so where both ends of [zx_f - B, zx_f + B] give
 * the same ones, so does the double. nx = 0 is exact: the products are then equal, as
 * are their roundings, and the double slope is +0.
 *
 * The centre depth: om__rtri_zat at the centre is floor(Z + 1/2 + e) modulo 2^32, Z the
 * exact plane there and |e| <= 2^-33 (|dx| + |dy|) (the fixed-point slopes' rounding,
 * raster.h), dx, dy the centre's offsets from vertex 0; the double plane's value there
 * is within 2^-49 (S_x / area2 |dx| + S_y / area2 |dy|) + 2^-19 of Z (the slopes' bound
 * above and three roundings of sums below 2^33 and those terms). A touched texel's
 * centre is within half a texel, each way, of a point of the triangle, where Z lies
 * between the vertex depths; so when those, widened by the slopes over half a texel,
 * stay 2^18 inside [0, 2^32), no centre's depth wraps, and the double's code
 * floor(z / 2^16 + 1/2) is the integer's (n + 2^15) >> 16 wherever n + 2^15 lies more
 * than the sum of those bounds and 1/2 inside its multiple of 2^16 (`reach`). */
static void slope_code(const om__spsm_qtable *q, int64_t n, float a, float b, bool *sure, uint8_t *code, bool *down)
{
    if (n == 0) {   /* the double slope is +0 */
        *code = 127;
        *down = false;
        return;
    }
    const float w = b + om__fabsf(a) * 0x1p-22f, lo = a - w, hi = a + w;
    const float k = (float)OM_SUBPIX / 65536.0f / (float)OM_SPSM_DSCALE;   /* build's scale, 2^-11 */
    *code = om__spsm_q_encode_f(q, lo * k);
    *down = lo > 0.0f;
    /* the same code at hi: no boundary up[] between |lo k| and |hi k| (a code's
     * distance from 127 counts the boundaries at or below its magnitude) */
    if (lo > 0.0f) *sure &= hi * k < q->up[*code - 127];              /* up[127] is infinite */
    else if (hi <= 0.0f) *sure &= *code == 127 || -(hi * k) >= q->up[126 - *code];
    else *sure = false;
}

void om__spsm_fplane_setup(om__spsm_fplane *f, const om__spsm_qtable *q, const om__rtri *t, const uint32_t z[3])
{
    const om__tri2 *e = &t->e;
    uint32_t zlo = z[0], zhi = z[0];
    for (int i = 1; i < 3; i++) {
        if (z[i] < zlo) zlo = z[i];
        if (z[i] > zhi) zhi = z[i];
    }
    int64_t nx = 0, ny = 0;
    float rx = 0.0f, ry = 0.0f;   /* S / area2 along x and y */
    f->zx = f->zy = 0.0f;
    if (e->area2 > 0) {   /* else the double plane is flat: slopes 0 */
        const int64_t dz1 = (int64_t)z[1] - z[0], dz2 = (int64_t)z[2] - z[0];
        const int64_t x1 = e->x[1] - e->x[0], y1 = e->y[1] - e->y[0], x2 = e->x[2] - e->x[0], y2 = e->y[2] - e->y[0];
        nx = dz1 * y2 - dz2 * y1;
        ny = dz2 * x1 - dz1 * x2;
        const float A = (float)e->area2;
        f->zx = (float)nx / A;
        f->zy = (float)ny / A;
        /* |dz| < 2^32 and offsets below 2^30: in 32 bits */
        const float a1 = (float)(uint32_t)(dz1 < 0 ? -dz1 : dz1), a2 = (float)(uint32_t)(dz2 < 0 ? -dz2 : dz2);
        const float fx1 = om__fabsf((float)(int32_t)x1), fy1 = om__fabsf((float)(int32_t)y1);
        const float fx2 = om__fabsf((float)(int32_t)x2), fy2 = om__fabsf((float)(int32_t)y2);
        rx = (a1 * fy2 + a2 * fy1) / A;
        ry = (a2 * fx1 + a1 * fx2) / A;
    }
    const float bx = om__fabsf(f->zx) * 0x1p-20f + rx * 0x1p-49f, by = om__fabsf(f->zy) * 0x1p-20f + ry * 0x1p-49f;
    f->sure = true;
    slope_code(q, nx, f->zx, bx, &f->sure, &f->qx, &f->down_x);
    slope_code(q, ny, f->zy, by, &f->sure, &f->qy, &f->down_y);
    /* the centre depths */
    f->reach = 0;
    int64_t lx = e->x[0], hx = e->x[0], ly = e->y[0], hy = e->y[0];
    for (int i = 1; i < 3; i++) {
        if (e->x[i] < lx) lx = e->x[i];
        if (e->x[i] > hx) hx = e->x[i];
        if (e->y[i] < ly) ly = e->y[i];
        if (e->y[i] > hy) hy = e->y[i];
    }
    if (hx - lx > (1 << 28) || hy - ly > (1 << 28)) return;
    const float half = (float)(OM_SUBPIX / 2);
    const float dx = (float)(int32_t)(hx - lx) + half, dy = (float)(int32_t)(hy - ly) + half;
    const float wide = (om__fabsf(f->zx) + bx + om__fabsf(f->zy) + by) * half * 1.001f + 2.0f;
    if (!((float)zlo - wide >= 0x1p18f && (float)zhi + wide <= 0x1p32f - 0x1p18f)) return;
    const float err = (rx * dx + ry * dy) * 0x1p-48f + (dx + dy) * 0x1p-32f + 0x1p-16f;
    if (err < 4096.0f) f->reach = (uint32_t)(err + 0.5f) + 1u;
}
