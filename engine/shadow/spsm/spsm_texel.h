/* spsm_texel.h — the parts of Sub-Pixel Shadow Maps (paper 004) that the tests reach into:
 * the 128-bit texel and its packing (section 3.3), the power-of-arctangent code for
 * depth derivatives (section 3.4) and the tangent look-up table indexed by the 3x3
 * depth-test pattern (section 4.2, Figure 8). The method itself is in spsm.c.
 *
 * Units. Positions are on the map's sub-texel grid: 1/256 texel (OM_SUBPIX), the grid
 * the rasterizer snaps to, so a texel centre is an integer point. Depth is the
 * rasterizer's z/w * 2^32 ("raw"); the texel keeps its top 16 bits ("steps" of 2^16).
 * A derivative is coded in steps per texel divided by OM_SPSM_DSCALE. */
#ifndef OM_SPSM_TEXEL_H
#define OM_SPSM_TEXEL_H

#include "../../frame/frame.h"

/* One texel, exactly 16 bytes (checked below). vx/vy: the nearest triangle's three
 * vertices as offsets from the texel centre in the 16-bit "o16" code; z: depth of the
 * triangle's plane at the texel centre, rounded to 16 bits; qx/qy: the plane's depth
 * derivatives in the power-of-arctangent code. Whether a texel holds a triangle at all
 * is kept outside it (spsm.c: its depth buffer still at the far plane). */
typedef struct om__spsm_texel {
    uint16_t vx[3], vy[3];
    uint16_t z;
    uint8_t qx, qy;
} om__spsm_texel;

/* C99 has no _Static_assert: a negative array size fails the build instead. */
typedef char om__spsm_texel_is_16_bytes[sizeof(om__spsm_texel) == 16 ? 1 : -1];

#define OM_SPSM_LINK 256       /* silhouette recovery bridges gaps up to a texel */
#define OM_SPSM_DSCALE 8.0    /* a coded derivative of 1 = 8 depth steps per texel */

/* o16: a vertex offset v (grid units, relative to the texel centre) as a small float:
 * sign bit, 4-bit exponent e, 11-bit mantissa m; |v| = m when e = 0, else
 * (2048 + m) << (e - 1). Offsets below 16 texels are exact (the grid itself); beyond,
 * the relative error is at most 2^-12 (a quarter texel at 1000 texels), and the
 * largest magnitude, 4095 << 14 (about 2^26, the rasterizer's whole projected range),
 * is where larger offsets saturate. A far vertex so keeps the direction of its edges
 * near the texel, which a fixed-point window clamped at its border would not. */
uint16_t om__spsm_o16_encode(int64_t v);
/* In line: the lookup decodes six per texel record it reads. */
static inline int64_t om__spsm_o16_decode(uint16_t c)
{
    unsigned e = (c >> 11) & 15u, m = c & 2047u;
    int64_t a = e == 0 ? (int64_t)m : (int64_t)(2048u + m) << (e - 1);
    return (c & 0x8000u) ? -a : a;
}

/* The derivative code of section 3.4 (Equations 2-4) with n = 5:
 * Q(d) = round(127 * (1 + x^5)), x = (2/pi) atan(d), and its decoding table. */
typedef struct om__spsm_qtable {
    double dec[256];       /* decoded derivative, steps per texel / DSCALE */
    double err[256];       /* half the gap to the neighbouring codes: the error bound */
    float up[128];         /* up[k]: where code 127 + k gives way to the next (the
                              boundary decode_at(127.5 + k), rounded to float); up[127]
                              is infinite */
    float decf[256], errf[256];   /* dec and err in raw depth per grid unit (times
                              65536 * OM_SPSM_DSCALE / OM_SUBPIX, exact in double),
                              rounded to float: what the lookup's float tests read */
} om__spsm_qtable;

uint8_t om__spsm_q_encode(double d);
/* The same code from the table's boundaries, for the build (no arctangent): the code
 * whose boundaries enclose d, 254 - that of -d for d < 0, 127 for NaN. It agrees with
 * om__spsm_q_encode but within 2^-22 of a boundary, and the table's error bound holds
 * for it to that much (tests/method/spsm.c). */
uint8_t om__spsm_q_encode_f(const om__spsm_qtable *t, float d);
/* Builds the table from om__tan/om__log2/om__exp2 (bit-identical everywhere). Code 254
 * (x = 1, a slope of 90 degrees) decodes to twice code 253 and 0 to its negative. */
void om__spsm_qtable_build(om__spsm_qtable *t);

/* Tangent estimate (section 4.2, Figures 7 and 8). Index: the 3x3 depth-test pattern,
 * bit (dy + 1) * 3 + (dx + 1) set when texel (dx, dy) around the sample's texel holds
 * an occluder. `keep` is the pattern after dropping texels that are not 4-connected to
 * another (Figure 7b, c); `n` gives up to two integer normals of the silhouette,
 * pointing from the lit side into the shadow (x right, y down on the map). nn = 0: no
 * orientation (empty, full or isotropic pattern). nn = 2: a thin occluder along the
 * tangent: both sides are tried and must agree (Figure 8, bottom right). spsm.c's
 * recovery uses `keep`; the normals are the paper's tangent estimate, which feeds its
 * one-sided boundary phi (measured worse here, see spsm.md), kept for that comparison. */
typedef struct om__spsm_tangent {
    uint16_t keep;
    uint8_t nn;
    int8_t n[2][2];
} om__spsm_tangent;

void om__spsm_tangent_build(om__spsm_tangent lut[512]);

/* Packs the snapped triangle `t` (as the rasterizer hands it to a fragment, with its
 * double plane, om__rtri_plane) into the texel at (x, y); qx, qy are its derivative
 * codes (the same for every texel of it). The centre depth is om__spsm_centre_z's. */
void om__spsm_pack(om__spsm_texel *out, const om__rtri *t, int32_t x, int32_t y, uint8_t qx,
                   uint8_t qy);
/* The record's depth: the double plane at the centre of texel (x, y), not clamped to
 * the triangle's depth range (the lookup extrapolates from there), rounded to 16 bits
 * and clamped to them. */
uint16_t om__spsm_centre_z(const om__rtri *t, int32_t x, int32_t y);

/* The same in two parts, for the build: the vertices' y codes depend only on the
 * triangle and the texel row, so a run of texels along a row encodes them once
 * (om__spsm_row_codes) and packs each texel x of the row with them and its centre
 * depth z (om__spsm_pack_row). */
void om__spsm_row_codes(uint16_t vy[3], const om__rtri *t, int32_t y);
void om__spsm_pack_row(om__spsm_texel *out, const om__rtri *t, int32_t x, uint8_t qx, uint8_t qy,
                       const uint16_t vy[3], uint16_t z);

/* What the build takes from a triangle's double plane (om__rtri_plane: the slopes'
 * codes, the direction depth falls in, the centre depths om__spsm_centre_z), found
 * without double where that is sure: the slopes' exact numerators in float with an
 * error bound, and the centre depth from the fixed-point plane (om__rtri_zat), which
 * is within a unit of the exact plane where the double one is within far less.
 * Where the bounds leave a doubt the build asks the double plane itself. */
typedef struct om__spsm_fplane {
    float zx, zy;            /* the slopes, raw depth per grid unit */
    bool sure;               /* qx, qy, down_x, down_y are the double plane's */
    uint8_t qx, qy;          /* om__spsm_q_encode_f of the slopes (float) / 2^11 */
    bool down_x, down_y;     /* whether the slopes (float) are > 0 */
    uint32_t reach;          /* centre depths: the doubt around a code boundary (raw
                                units); 0: none decided here */
} om__spsm_fplane;

/* Sets f for triangle t (the fixed-point plane set, om__rtri_zplane) whose vertex
 * depths, in the order of t->e, are z. */
void om__spsm_fplane_setup(om__spsm_fplane *f, const om__spsm_qtable *q, const om__rtri *t, const uint32_t z[3]);
/* om__spsm_centre_z(t, x, y) for a texel (x, y) whose square the triangle touches, or
 * -1 where f cannot be sure of it. */
static inline int32_t om__spsm_centre_zf(const om__spsm_fplane *f, const om__rtri *t, int32_t x, int32_t y)
{
    if (!f->reach) return -1;
    const uint32_t k = om__rtri_zat(t, (int64_t)x * OM_SUBPIX + OM_SUBPIX / 2, (int64_t)y * OM_SUBPIX + OM_SUBPIX / 2) +
                       32768u, r = k & 0xFFFFu;
    return r >= f->reach && r + f->reach < 65536u ? (int32_t)(k >> 16) : -1;
}

#endif
