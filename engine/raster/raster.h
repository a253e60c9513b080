/* raster.h — the fixed-point triangle rasterizer shared by the eye pass, every
 * shadow map and the occlusion predicate.
 *
 * The rule, in plain words:
 *  - Clip space is D3D-style: visible when -w <= x, y <= w and 0 <= z <= w. Triangles are
 *    clipped in homogeneous space against the near (z >= 0) and far (z <= w) planes and
 *    against a guard band OM_GUARD_PX pixels beyond each image side, so that every
 *    snapped coordinate stays below 2^23 and edge functions fit in int64 with room.
 *  - Vertices snap to 1/256 pixel (OM_SUBPIX_BITS = 8), rounding half up from x/w and
 *    y/w in single precision; their depth z/w * 2^32 is exact, truncated (om__project).
 *    Pixel (x, y) is sampled at its centre ((x + 0.5) * 256, (y + 0.5) * 256); row 0
 *    is the top.
 *  - Edge functions are exact integers. A point is inside when it is strictly inside
 *    every edge, or exactly on an edge that is a top edge (horizontal, other vertex
 *    below) or a left edge (the interior lies to its right when going up): the top-left
 *    rule, so a point on an edge shared by two triangles belongs to exactly one.
 *    Both windings are accepted (they are put in one order first); zero-area triangles
 *    after snapping cover nothing.
 *  - Depth is z/w, affine in screen space, stored as uint32: 0 at the near plane,
 *    0xFFFFFFFF at the far plane (z/w * 2^32). Vertex depths are integers (om__zdepth
 *    truncates). A fill evaluates the plane in fixed point from one origin per triangle,
 *    the stored vertex 0, so a pixel's depth does not depend on the strip it is rendered
 *    in (om__rtri_zplane): the plane's slopes per sub-pixel unit along x and y, times
 *    2^32, are rounded to the nearest integers zqx, zqy and kept modulo 2^64, and a
 *    pixel's depth is the top 32 bits of  zq0 + zqx * dx + zqy * dy  (mod 2^64), with
 *    zq0 = z0 * 2^32 + 2^31 and dx, dy its offsets from the origin: the exact plane's
 *    value rounded to the nearest integer, but for the two steps' roundings (each
 *    within 2^-33 of a unit per sub-pixel unit). Offsets inside a triangle are below
 *    2^30 (om__tri2's range), so those move the sum by at most 1/4 of a unit: a depth
 *    is within 3/4 of the exact plane (within 1/2 + 2^-33 (|dx| + |dy|)), never
 *    outside the triangle's vertex depths, and the sum never wraps, whatever the
 *    wrapped terms were. Integer multiplies and adds only, no clamp: on a 32-bit CPU
 *    the top half is a register. The depth test is strict (<): among equal depths
 *    the first triangle drawn wins.
 *  - Conservative mode reports every pixel whose closed square the snapped triangle
 *    touches at all (an exact separating-axis test: bounding boxes and three edges).
 *  - A depth pass may sample a rectilinear grid instead of pixel centres (om_raster's
 *    grid_x, grid_y): the same rule at other points, so a pixel holds exactly what the
 *    triangles cover at its grid point.
 */
#ifndef OM_RASTER_H
#define OM_RASTER_H

#include "ombra.h"
#include "../core/core.h"

#include <math.h>
#include <string.h>

/* The depth scale: z/w in [0, 1] is stored as z/w * 2^32 (the rule below), in double
 * and in float. */
#define OM_DEPTH_ONE 4294967296.0
#define OM_DEPTH_ONE_F 4294967296.0f

#define OM_SUBPIX_BITS 8
#define OM_SUBPIX (1 << OM_SUBPIX_BITS)
#define OM_GUARD_PX 8192
/* om__tri2 accepts coordinates of magnitude up to 2^29 so that a*x + b*y + c stays far
 * from int64 overflow (|a|, |b| < 2^30, products < 2^60). */
#define OM_TRI2_MAX_COORD (1ll << 29)

/* A 2-D triangle on an integer grid with its three edge functions
 * E_i(x, y) = a[i] * x + b[i] * y + c[i]; inside when all E_i >= 0 (top-left bias
 * folded into c when built with `biased`). Vertices are stored in the order that makes
 * area2 > 0. */
typedef struct om__tri2 {
    int64_t x[3], y[3];
    int64_t a[3], b[3], c[3];
    int64_t area2;         /* twice the signed area, > 0 after setup (0: degenerate) */
    int perm[3];           /* perm[i]: which input vertex is stored at i */
} om__tri2;

/* Sets up a triangle; returns false (and leaves area2 = 0) when the coordinates are
 * out of range or the triangle has zero area. `biased` applies the top-left rule;
 * unbiased edges accept points on every edge (used for conservative coverage). */
bool om__tri2_setup(om__tri2 *t, const int64_t x[3], const int64_t y[3], bool biased);

static inline int64_t om__tri2_edge(const om__tri2 *t, int i, int64_t px, int64_t py)
{
    return t->a[i] * px + t->b[i] * py + t->c[i];
}

/* The point-in-triangle test at any grid position, with the fill rule's ties. */
static inline bool om__tri2_covers(const om__tri2 *t, int64_t px, int64_t py)
{
    return (om__tri2_edge(t, 0, px, py) | om__tri2_edge(t, 1, px, py) |
            om__tri2_edge(t, 2, px, py)) >= 0;
}

/* Where fragments go: a strip of rows [y0, y0 + rows) of a width x height image.
 * depth (and id, when not NULL) hold rows * width entries, row-major, strip-relative. */
typedef struct om_target {
    uint32_t width, height, y0, rows;
    uint32_t *depth;
    uint32_t *id;
} om_target;

void om__target_clear(const om_target *t);

/* A triangle ready to fill: snapped screen coordinates, edges, depth plane, bounds. */
typedef struct om__rtri {
    om__tri2 e;
    uint64_t zq0, zqx, zqy; /* the fixed-point plane the fills use (the rule above) */
    /* The plane in double, for the occlusion predicate, which tests it at points
     * outside the triangle too (om__rtri_plane; no fill sets it, and conservative mode's
     * spans get the fixed-point plane alone): depth (0..2^32) at stored vertex 0, per
     * sub-pixel unit, and the vertex depth range. */
    double z0, zx, zy;
    double zmin, zmax;
    int32_t minx, maxx, miny, maxy;   /* pixel bounds (inclusive), clamped to the image */
} om__rtri;

/* Sets the fixed-point plane from the depths of the vertices as given to
 * om__tri2_setup (input order; the setup's permutation is applied). */
void om__rtri_zplane(om__rtri *t, const uint32_t z[3]);
/* Sets the double plane likewise. */
void om__rtri_plane(om__rtri *t, const uint32_t z[3]);

/* Depth of the triangle's double plane at a grid position (sub-pixel units), clamped
 * to the triangle's vertex depth range. */
static inline double om__rtri_depth(const om__rtri *t, int64_t px, int64_t py)
{
    double z = t->z0 + t->zx * (double)(px - t->e.x[0]) + t->zy * (double)(py - t->e.y[0]);
    return z < t->zmin ? t->zmin : z > t->zmax ? t->zmax : z;
}

/* The fixed-point plane's depth at a grid position inside the triangle (the rule at
 * the top). */
static inline uint32_t om__rtri_zat(const om__rtri *t, int64_t px, int64_t py)
{
    return (uint32_t)((t->zq0 + t->zqx * (uint64_t)(px - t->e.x[0]) + t->zqy * (uint64_t)(py - t->e.y[0])) >> 32);
}

typedef enum om_raster_mode {
    OM_RASTER_DEPTH,       /* depth test and write (shadow maps) */
    OM_RASTER_DEPTH_ID,    /* depth test, write depth and triangle id (eye pass) */
    OM_RASTER_CONSERVATIVE /* call `span` for every run of touched pixels; no buffers written */
} om_raster_mode;

/* Conservative mode's output: pixels x0..x1 (inclusive) of row y, all touched by t. One
 * call per row and triangle, so that the caller's per-pixel loop is its own. */
typedef void (*om__span_fn)(void *user, int32_t y, int32_t x0, int32_t x1, const om__rtri *t);

typedef struct om_raster {
    const om_target *target;
    om_raster_mode mode;
    om__span_fn span;      /* conservative mode */
    void *user;
    /* Conservative mode, may be NULL: also the plain depth test (OM_RASTER_DEPTH) into
     * this target of the same size, at the texel centres the fill rule covers; the
     * same depths as a separate depth pass over the same triangles, in one pass. */
    const om_target *centres;
    /* With centres, may be NULL: the plain test only at pixels whose bit is set here
     * (bit x & 31 of word x >> 5 of a row; mask_words words per row of the image). */
    const uint32_t *centre_mask;
    uint32_t mask_words;
    /* Skip the triangle when it faces away: clockwise on the target (y down), that is
     * counter-clockwise-from-outside seen from behind. The caller sets it per triangle,
     * for closed shapes only (om__cull_next). */
    bool cull_back;
    /* May be NULL (then pixel centres, the rule above): a rectilinear grid of sample
     * positions, for OM_RASTER_DEPTH only. Pixel (x, y) of the target samples the
     * triangle at grid point (grid_x[x], grid_y[y]) (sub-pixel units of whatever image
     * the triangle was snapped on), with the same edge functions, tie rule and depth
     * plane; both tables non-decreasing, grid_y indexed by image row. A warped map
     * (rtw) samples the unwarped light image at its texels' inverse-warped centres. */
    const int64_t *grid_x, *grid_y;
    /* With a grid, may be NULL: an index of each table (om__grid_index) in buckets of
     * 2^grid_shift grid units, grid_buckets + 1 entries, so that a triangle's bounds
     * are found among the few grid points of their buckets rather than by searching
     * the whole table. The same pixels either way. */
    const int32_t *grid_xs, *grid_ys;
    uint32_t grid_shift, grid_buckets;
    /* Conservative mode, may be NULL: a row y of the target whose bit y >> row_shift is
     * clear here is passed over, on the caller's word that its span and centres change
     * nothing there, so that such a row costs a triangle one bit test, not a span. */
    const uint32_t *row_mask;
    uint32_t row_shift;
} om_raster;

/* Indexes a non-decreasing grid table g[0..n): start[b] = the first i with g[i] >=
 * b << shift (n when none), for b = 0..buckets. */
void om__grid_index(const int64_t *g, int32_t n, uint32_t shift, uint32_t buckets, int32_t *start);

/* The first pixel x..x1 whose bit is set in `row` (one row of such a mask), x1 + 1
 * when none: clear words are passed over whole. */
static inline int32_t om__mask_next(const uint32_t *row, int32_t x, int32_t x1)
{
    while (x <= x1) {
        const uint32_t w = row[x >> 5] >> (x & 31);
        if (w) {
            x += om__ctz32(w);
            return x <= x1 ? x : x1 + 1;
        }
        x = (x | 31) + 1;
    }
    return x1 + 1;
}

/* Rasterizes one triangle given in clip space (clipping it first). Non-finite vertices
 * are rejected: they cover nothing. Returns the number of sub-triangles filled. */
int om__raster_tri(const om_raster *r, const om_vec4 clip[3], uint32_t id);
/* The same, projected and clipped on the grid of a width x height image rather than
 * the target's: for a rectilinear grid (om_raster.grid_x) on that image. */
int om__raster_tri_on(const om_raster *r, const om_vec4 clip[3], uint32_t id, uint32_t width,
                      uint32_t height);

/* Rasterizes one triangle already on the sub-pixel grid (coordinates within the
 * guard band, OM_TRI2_MAX_COORD) with depths z/w * 2^32: what om__raster_tri does
 * after clipping, for a caller that places vertices itself. False: nothing to fill. */
bool om__raster_snapped(const om_raster *r, const int64_t x[3], const int64_t y[3], const uint32_t z[3],
                        uint32_t id);

/* The coarse depth of a depth-only target (om__hiz): an upper bound of the stored
 * depths over tiles of 8 x 8 texels and over tiles of 16 rows x 256 columns, for the
 * whole image, after the first level's (om__hiz_words(width, height) words). Depths
 * only ever go down, so a bound stays true whatever is drawn; large triangles tighten
 * the tiles they write and skip, without touching a texel, the tiles where their
 * depth is nowhere below the bound, so a map under thousands of huge overlapping
 * triangles costs about texels + triangles instead of their product. The same texels
 * with it or without (hiz.c gives the proof). A target uses it when its rows start
 * on a multiple of 16 and end on one or at the image's last row (the bands of a map
 * built by bands do), so that no tile is shared by two targets. */
size_t om__hiz_words(uint32_t width, uint32_t height);
/* Sets the bounds of the target's rows to 2^32 - 1: with om__target_clear. */
void om__hiz_clear(uint32_t *hiz, const om_target *tg);
/* om__raster_snapped and om__raster_tri_on with a coarse depth for r's target (NULL:
 * none); OM_RASTER_DEPTH only, the same texels. */
bool om__raster_snapped_hiz(const om_raster *r, uint32_t *hiz, const int64_t x[3], const int64_t y[3],
                            const uint32_t z[3], uint32_t id);
int om__raster_tri_on_hiz(const om_raster *r, uint32_t *hiz, const om_vec4 clip[3], uint32_t id,
                          uint32_t width, uint32_t height);
/* om__raster_tri_on_hiz with the guard band's extents in clip units (|x| <= x w,
 * |y| <= y w: om__guard_band of the same width and height) worked out once, for a
 * caller that draws many triangles onto one image. */
typedef struct om__guard { float x, y; } om__guard;
om__guard om__guard_band(uint32_t width, uint32_t height);
/* om__outcode(v, width, height) == 0 with g = om__guard_band(width, height): the same
 * six plane tests, as an int (for &, no branches). */
static inline int om__inside_band(const om_vec4 *v, om__guard g)
{
    return (v->z >= 0.0f) & (v->w - v->z >= 0.0f) & (v->x + g.x * v->w >= 0.0f) & (g.x * v->w - v->x >= 0.0f) &
           (v->y + g.y * v->w >= 0.0f) & (g.y * v->w - v->y >= 0.0f);
}
int om__raster_tri_guarded(const om_raster *r, uint32_t *hiz, const om_vec4 clip[3], uint32_t id,
                           uint32_t width, uint32_t height, om__guard g);
/* What om__raster_tri_guarded does with a triangle inside every plane, for a caller
 * that has tested and projected its vertices itself (each inside the band, w finite
 * and positive): x, y are om__project_xy's, and the depths z, or when z is NULL
 * om__zdepth of clip's z and w, worked out when the triangle reaches a pixel. The
 * same as om__raster_snapped_hiz, without its range test (om__project's vertices are
 * within 2^26). False: nothing filled. */
bool om__raster_projected(const om_raster *r, uint32_t *hiz, const int64_t x[3], const int64_t y[3],
                          const uint32_t *z, const om_vec4 *clip, uint32_t id);

/* om__raster_projected of vertices given in 32 bits with their depths (the bins'
 * om__vsnap), which sends a tiny triangle to its fill with no 64-bit setup on the way:
 * the same texels and bits. `box`, when given: the columns and rows of the pixel
 * centres the vertices' box holds, first and last, not clamped to the target (the
 * caller has them already), as {x0, x1, y0, y1}. */
bool om__raster_projected32(const om_raster *r, uint32_t *hiz, const int32_t x[3], const int32_t y[3],
                            const uint32_t z[3], uint32_t id, const int32_t *box);

/* Which of the six clip planes (near, far, four guard-band sides) a vertex is outside
 * of, as a bit mask; 0 means it needs no clipping. */
unsigned om__outcode(const om_vec4 *v, uint32_t width, uint32_t height);
/* Snaps a point given in sub-pixel grid units (x, y) with depth z/w * 2^32 (z) to the
 * grid: rounded to the nearest grid point, the depth clamped to [0, 2^32 - 1]; false
 * beyond 2^26 grid units (or NaN). om__project ends here, and so may a caller that
 * places vertices itself (rtw's warped map). In line, as om__project: the lookups
 * run them for every sample. */
static inline bool om__snap_xy(double x, double y, int64_t *gx, int64_t *gy)
{
    const double lim = (double)(1ll << 26);
    double X = floor(x + 0.5), Y = floor(y + 0.5);
    if (!(X > -lim && X < lim && Y > -lim && Y < lim)) return false;
    *gx = (int64_t)X;
    *gy = (int64_t)Y;
    return true;
}

static inline bool om__snap(double x, double y, double z, int64_t *gx, int64_t *gy, uint32_t *gz)
{
    if (!om__snap_xy(x, y, gx, gy)) return false;
    *gz = z > 0.0 ? (z < 4294967295.0 ? (uint32_t)z : 0xFFFFFFFFu) : 0u;   /* truncated, NaN to 0 */
    return true;
}

/* Projects one clip-space vertex to the sub-pixel grid of a width x height image, with
 * depth z/w * 2^32 (clamped to [0, 2^32 - 1]); false when w <= 0 or it lands beyond
 * 2^26 grid units. Clipping uses exactly this, so a vertex projects the same alone.
 * om__project_xy is its grid position alone (the same, without the depth).
 *
 * No double: x/w and y/w are single precision, what a Cortex-M4F does in hardware
 * (a double there is a software routine per operation), and the grid position rounds
 * from there. On every grid the engine uses (at most 8192 pixels and a guard band of
 * 8192 either side, 256 units a pixel) |X| < 2^23, where a float's step is at most
 * half a unit: the division and the scaled sum move a position by at most one unit
 * before the snap. The depth is exact: om__zdepth. */
static inline bool om__project_xy(const om_vec4 *v, uint32_t width, uint32_t height, int64_t *gx, int64_t *gy)
{
    const float sx = (float)width * (OM_SUBPIX / 2), sy = (float)height * (OM_SUBPIX / 2), lim = 67108864.0f;
    if (!(v->w > 0.0f)) return false;
    const float iw = 1.0f / v->w;
    const float X = (v->x * iw + 1.0f) * sx + 0.5f, Y = (1.0f - v->y * iw) * sy + 0.5f;
    /* the same test on X as on floor(X): no float lies strictly between -2^26 and
     * -2^26 + 4 */
    if (!(X > -lim && X < lim && Y > -lim && Y < lim)) return false;
    *gx = om__floorf_i32(X);
    *gy = om__floorf_i32(Y);
    return true;
}

/* Where the CPU divides 32-bit words but a 64-bit division is a library call (32-bit
 * ARM with a divide instruction: the Cortex-M3, M4, M7), om__zdepth divides by words
 * (om__zdepth_words); elsewhere (64-bit CPUs, the Cortex-M0, which divides no word
 * either) by one 64-bit division. The same quotient either way. */
#if defined(__ARM_FEATURE_IDIV) && UINTPTR_MAX <= 0xFFFFFFFFu
#define OM_ZDEPTH_WORDS 1
#else
#define OM_ZDEPTH_WORDS 0
#endif

/* mz * 2^s / mw, truncated, for mz, mw in [1, 2^24) and s in [-24, 32] where the
 * quotient is below 2^32, with 32-bit divisions alone: for s > 0, as in long division,
 * the quotient's first 1 to 8 bits, then eight at a time (each remainder is below mw,
 * so shifted by 8 it still fits a word); for s <= 0, mz / mw shifted down (truncating
 * twice truncates once: floor(floor(a / b) / c) = floor(a / (b c)) for whole a, b,
 * c > 0). */
static inline uint32_t om__zdepth_words(uint32_t mz, uint32_t mw, int s)
{
    if (s <= 0) return (mz / mw) >> -s;
    const int steps = (s - 1) >> 3;   /* after the first: 0 to 3 of 8 bits */
    const uint32_t n = mz << (s - 8 * steps);
    uint32_t q = n / mw, r = n - q * mw;
    for (int i = 0; i < steps; i++) {
        const uint32_t m = r << 8, d = m / mw;   /* d < 2^8, as r < mw */
        q = (q << 8) + d;
        r = m - d * mw;
    }
    return q;
}

/* z/w * 2^32, truncated: exact, from the floats' significands divided as integers (a
 * 64-by-32-bit integer division, or words, far cheaper than an emulated double one);
 * 0 for z <= 0 (or NaN), 2^32 - 1 for z >= w. */
static inline uint32_t om__zdepth(float z, float w)
{
    if (!(z > 0.0f)) return 0;
    if (!(z < w)) return 0xFFFFFFFFu;
    /* the bits through a union (C99 reads the stored float's representation): a
     * freestanding firmware would call memcpy for each */
    union { float f; uint32_t u; } fz, fw;
    fz.f = z;
    fw.f = w;
    const uint32_t bz = fz.u, bw = fw.u;
    int ez = (int)(bz >> 23), ew = (int)(bw >> 23);   /* positive: no sign bit */
    const uint64_t mz = (bz & 0x7FFFFFu) | (ez ? 0x800000u : 0u), mw = (bw & 0x7FFFFFu) | (ew ? 0x800000u : 0u);
    ez += !ez;   /* a subnormal's exponent is the least normal one's */
    ew += !ew;
    const int s = ez - ew + 32;   /* z/w * 2^32 = mz / mw * 2^s, s <= 32 as z < w */
    if (s < -24) return 0;        /* mz / mw < 2^24: below one unit */
    if (OM_ZDEPTH_WORDS) return om__zdepth_words((uint32_t)mz, (uint32_t)mw, s);
    return (uint32_t)(s >= 0 ? (mz << s) / mw : mz / (mw << -s));
}

static inline bool om__project(const om_vec4 *v, uint32_t width, uint32_t height, int64_t *gx, int64_t *gy,
                               uint32_t *gz)
{
    if (!om__project_xy(v, width, height, gx, gy)) return false;
    *gz = om__zdepth(v->z, v->w);
    return true;
}

/* Clips a triangle against the near, far and guard-band planes of a width x height
 * viewport and projects it: up to 9 vertices of a convex polygon in sub-pixel grid
 * coordinates with depth z/w * 2^32. Returns the vertex count (0: nothing left). */
int om__clip_project(const om_vec4 clip[3], uint32_t width, uint32_t height,
                     int64_t *gx, int64_t *gy, uint32_t *gz);

#endif
