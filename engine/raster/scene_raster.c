/* scene_raster.c — a scene through the rasterizer (scene_raster.h): the back-face
 * culling of closed shapes, the per-frame bins of rows and snapped vertices, and the
 * walk over the scene's triangles that the eye pass and the light depth passes share. */
#include "scene_raster.h"

/* Whether the CPU runs several float lanes an instruction (SSE2, NEON): there the
 * bins' vertices go LANES at a time (below), which costs a quarter of one at a time;
 * on a CPU without lanes (a Cortex-M) the batch would only add its loads and stores,
 * and each vertex goes alone. The same bits either way: lanes_project's tests and
 * projection are om__inside_band's and om__project's. */
#if defined(__SSE2__) || defined(__ARM_NEON)
#define VERT_LANES 1
#else
#define VERT_LANES 0
#endif

/* A margin in front of the near plane, in clip z over w: the vertices are inside the
 * box, but their clip coordinates are rounded on their own. */
#define CULL_MARGIN 1e-4f

static bool solid_in_front(const om_solid *so, const om_mat4 *vp, om_vec3 o)
{
    /* the box's corners made relative as vertices are: rounding is monotonic, so the
     * relative vertices stay inside the relative box */
    const om_vec3 lo = om__sub(so->lo, o), hi = om__sub(so->hi, o);
    for (int i = 0; i < 8; i++) {
        om_vec3 p = om__v3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
        om_vec4 q = om__mat_apply(vp, p);
        if (!(q.w > 0.0f && q.z >= CULL_MARGIN * q.w)) return false;
    }
    return true;
}

void om__cull_begin(om__cull *c, const om_scene *s, const om_mat4 *vp, om_vec3 o)
{
    c->s = s;
    c->vp = vp;
    c->o = o;
    c->k = 0;
    c->seen = UINT32_MAX;
    c->on = false;
}

bool om__cull_next(om__cull *c, uint32_t t)
{
    const om_scene *s = c->s;
    if (!s->solids) return false;
    /* solids are in triangle order; a hand-made list out of order only culls less */
    while (c->k < s->nsolids && (uint64_t)s->solids[c->k].first + s->solids[c->k].count <= t) c->k++;
    if (c->k >= s->nsolids) return false;
    const om_solid *o = &s->solids[c->k];
    if (t < o->first || (uint64_t)o->first + o->count > s->ntris) return false;
    if (c->seen != c->k) {
        c->seen = c->k;
        c->on = solid_in_front(o, c->vp, c->o);
    }
    return c->on;
}

size_t om__bins_rows_bytes(const om_scene *s)
{
    return om_arena_need((size_t)s->ntris * sizeof(uint32_t), 8);
}

size_t om__bins_verts_bytes(const om_scene *s)
{
    return om_arena_need((size_t)s->nverts * sizeof(om__vsnap), 8);
}

/* Row r's pixel centres lie at r * 256 + 128: the rows between grid rows lo and hi, a
 * row either side to spare. */
static uint32_t rows_between(int64_t lo, int64_t hi, uint32_t height)
{
    int64_t r0 = (lo - OM_SUBPIX / 2) / OM_SUBPIX - 1, r1 = (hi - OM_SUBPIX / 2) / OM_SUBPIX + 1;
    if (r0 < 0) r0 = 0;
    if (r1 > (int64_t)height - 1) r1 = (int64_t)height - 1;
    return r0 > r1 ? 0x0000FFFFu : (uint32_t)r0 | (uint32_t)r1 << 16;
}

/* rows_between for grid rows of om__project's (within 2^26), in 32 bits: the floor
 * where rows_between truncates gives a row less only below row 0, which both clamp
 * away, and the spare row either side keeps every row a pixel of it can lie in. */
static inline uint32_t rows_between32(int32_t lo, int32_t hi, int32_t height)
{
    int32_t r0 = ((lo - OM_SUBPIX / 2) >> OM_SUBPIX_BITS) - 1, r1 = ((hi - OM_SUBPIX / 2) >> OM_SUBPIX_BITS) + 1;
    r0 = r0 < 0 ? 0 : r0;
    r1 = r1 > height - 1 ? height - 1 : r1;
    return r0 > r1 ? 0x0000FFFFu : (uint32_t)r0 | (uint32_t)r1 << 16;
}

/* The box of the pixel centres that the box of three grid points within 2^26
 * (om__project's) holds, as raster.c's bounds finds them, in 32 bits and without a
 * branch (the bias, a multiple of 256, makes every shifted value non-negative):
 * centres lie at 256 i + 128; the first at or after the box's low side and the last
 * at or before its high side, not yet clamped to an image. */
typedef struct centre_box { int32_t x0, x1, y0, y1; } centre_box;

static inline centre_box centres_in(int32_t xa, int32_t xb, int32_t xc, int32_t ya, int32_t yb, int32_t yc)
{
    const int32_t B = 1 << 27, b = B >> OM_SUBPIX_BITS;
    int32_t x0 = xa < xb ? xa : xb, x1 = xa < xb ? xb : xa, y0 = ya < yb ? ya : yb, y1 = ya < yb ? yb : ya;
    x0 = xc < x0 ? xc : x0;
    x1 = xc > x1 ? xc : x1;
    y0 = yc < y0 ? yc : y0;
    y1 = yc > y1 ? yc : y1;
    const centre_box c = {((x0 + 127 + B) >> OM_SUBPIX_BITS) - b, ((x1 - 128 + B) >> OM_SUBPIX_BITS) - b,
                          ((y0 + 127 + B) >> OM_SUBPIX_BITS) - b, ((y1 - 128 + B) >> OM_SUBPIX_BITS) - b};
    return c;
}

#if VERT_LANES
/* om__bins.centres' rows of a triangle of snapped vertices on a width x height image:
 * the rows of the pixel centres its box holds (centres_in, clamped to the image),
 * 0x0000FFFF when it holds none. holds_centre on a target of rows [y0, y1] is then
 * these rows reaching [y0, y1]: its clamps to the target's rows are these clamped
 * further. */
static inline uint32_t centre_rows(const om__vsnap *va, const om__vsnap *vb, const om__vsnap *vc, int32_t width,
                                   int32_t height)
{
    centre_box c = centres_in(va->x, vb->x, vc->x, va->y, vb->y, vc->y);
    c.x0 = c.x0 < 0 ? 0 : c.x0;
    c.x1 = c.x1 > width - 1 ? width - 1 : c.x1;
    c.y0 = c.y0 < 0 ? 0 : c.y0;
    c.y1 = c.y1 > height - 1 ? height - 1 : c.y1;
    return c.x0 <= c.x1 && c.y0 <= c.y1 ? (uint32_t)c.y0 | (uint32_t)c.y1 << 16 : 0x0000FFFFu;
}
#endif

void om__bins_make(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t width, uint32_t height, const om__bins *b)
{
    om__bins_make_verts(s, vp, o, width, height, b, 0, s->nverts);
    om__bins_make_rows(s, vp, o, width, height, b, 0, s->ntris);
}

/* The rows of triangle t that has a vertex to clip (or outside the bins' vertices):
 * from its clip-space vertices. */
static uint32_t rows_clipped(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t width, uint32_t height, uint32_t t)
{
    const uint32_t all = (height - 1) << 16;
    om_vec4 c[3];
    om__clip_tri(s, vp, o, t, c);
    unsigned out_all = 0x3F, out_any = 0;
    for (int k = 0; k < 3; k++) {
        unsigned oc = om__outcode(&c[k], width, height);
        out_all &= oc;
        out_any |= oc;
    }
    if (out_all) return 0x0000FFFFu;   /* wholly beyond one plane */
    if (out_any) return all;           /* clipped: every row */
    /* Inside every plane: the rasterizer snaps these very positions. */
    int64_t lo = INT64_MAX, hi = INT64_MIN;
    for (int k = 0; k < 3; k++) {
        int64_t gx, gy;
        if (!om__project_xy(&c[k], width, height, &gx, &gy)) return all;
        if (gy < lo) lo = gy;
        if (gy > hi) hi = gy;
    }
    return rows_between(lo, hi, height);
}

void om__bins_make_rows(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t width, uint32_t height, const om__bins *b,
                        uint32_t t0, uint32_t t1)
{
    const om__vsnap *vs = b->verts;
    if (!b->rows) return;
    if (t1 > s->ntris) t1 = s->ntris;
#if VERT_LANES
    if (vs && b->centres) {   /* the eye's rows of pixel centres: a loop of their own */
        for (uint32_t t = t0; t < t1; t++) {
            const uint32_t *ix = s->idx + (size_t)t * 3;
            const om__vsnap *va = &vs[ix[0]], *vb = &vs[ix[1]], *vc = &vs[ix[2]];
            const bool alone = (va->x != INT32_MIN) & (vb->x != INT32_MIN) & (vc->x != INT32_MIN);
            b->rows[t] = alone ? centre_rows(va, vb, vc, (int32_t)width, (int32_t)height)
                               : rows_clipped(s, vp, o, width, height, t);
        }
        return;
    }
#endif
    for (uint32_t t = t0; t < t1; t++) {
        const uint32_t *ix = s->idx + (size_t)t * 3;
        if (vs) {
            const om__vsnap *va = &vs[ix[0]], *vb = &vs[ix[1]], *vc = &vs[ix[2]];
            if (va->x != INT32_MIN && vb->x != INT32_MIN && vc->x != INT32_MIN) {
                int32_t lo = va->y < vb->y ? va->y : vb->y, hi = va->y < vb->y ? vb->y : va->y;
                lo = vc->y < lo ? vc->y : lo;
                hi = vc->y > hi ? vc->y : hi;
                b->rows[t] = rows_between32(lo, hi, (int32_t)height);
                continue;
            }
        }
        b->rows[t] = rows_clipped(s, vp, o, width, height, t);
    }
}

void om__scene_raster(const om_scene *s, const om_mat4 *vp, om_vec3 o, const om_target *tg,
                      om_raster_mode mode, bool cull, const om__bins *bins)
{
    om__scene_raster_hiz(s, vp, o, tg, mode, cull, bins, NULL);
}

/* Whether the box of three grid points holds the centre of a pixel of tg (centres_in,
 * clamped to the target): 1 or 0. */
static inline int32_t holds_centre(int32_t xa, int32_t xb, int32_t xc, int32_t ya, int32_t yb, int32_t yc,
                                   const om_target *tg)
{
    centre_box c = centres_in(xa, xb, xc, ya, yb, yc);
    const int32_t xe = (int32_t)tg->width - 1, ya0 = (int32_t)tg->y0, ye = (int32_t)(tg->y0 + tg->rows) - 1;
    c.x0 = c.x0 < 0 ? 0 : c.x0;
    c.x1 = c.x1 > xe ? xe : c.x1;
    c.y0 = c.y0 < ya0 ? ya0 : c.y0;
    c.y1 = c.y1 > ye ? ye : c.y1;
    return (c.x0 <= c.x1) & (c.y0 <= c.y1);
}

/* ---- vertices a batch at a time
 *
 * Most triangles of a detailed scene hold no pixel centre of the target, and cost the
 * walk (and the bins) their vertices' transform, plane tests and projection. Those run
 * in loops over arrays, LANES vertices at a time, with no branch on the data, so that
 * a compiler may run several lanes an instruction (four on SSE2): each lane does
 * om__mat_apply's, om__inside_band's and om__project_xy's operations in their order,
 * the same bits. They give no depth (a 64-bit division): the walk works a triangle's
 * out once it covers a pixel centre, the bins one per vertex for all its triangles. */
#define BATCH 8
#define LANES (3 * BATCH)
/* How many batches ahead om__bins_make_verts asks for its vertices' lines (about 2 KB):
 * far enough that a line is fetched, and the other cores' copies dropped, before its
 * store (see OM_PREFETCH_WRITE). */
#define PREFETCH_AHEAD 8

typedef struct lanes {
    float x[LANES], y[LANES], z[LANES], w[LANES];   /* clip space */
    int32_t gx[LANES], gy[LANES];                   /* om__project_xy's */
    int32_t ok[LANES];   /* inside every plane, w finite and > 0, within 2^26 */
} lanes;

/* The points (px, py, pz) through vp, tested and projected onto a width x height image
 * (sx, sy: om__project_xy's scales); px and py are used up. */
static inline void lanes_project(lanes *restrict b, float *restrict px, float *restrict py, const float *restrict pz,
                                 const om_mat4 *vp, om__guard g, float sx, float sy)
{
    const float *a = vp->m, lim = 67108864.0f;
    for (int i = 0; i < LANES; i++) {
        const float x = a[0] * px[i] + a[1] * py[i] + a[2] * pz[i] + a[3];
        const float y = a[4] * px[i] + a[5] * py[i] + a[6] * pz[i] + a[7];
        const float z = a[8] * px[i] + a[9] * py[i] + a[10] * pz[i] + a[11];
        const float w = a[12] * px[i] + a[13] * py[i] + a[14] * pz[i] + a[15];
        /* on a lane that fails a test these may be infinite or NaN, and are not used */
        const float iw = 1.0f / w;
        const float X = (x * iw + 1.0f) * sx + 0.5f, Y = (1.0f - y * iw) * sy + 0.5f;
        /* an infinite or NaN x, y or z fails a plane test, an infinite w its w - w */
        const int32_t in = (X > -lim) & (X < lim) & (Y > -lim) & (Y < lim);
        const int32_t ok = (z >= 0.0f) & (w - z >= 0.0f) & (x + g.x * w >= 0.0f) & (g.x * w - x >= 0.0f) &
                           (y + g.y * w >= 0.0f) & (g.y * w - y >= 0.0f) & (w > 0.0f) & (w - w == 0.0f) & in;
        b->x[i] = x;
        b->y[i] = y;
        b->z[i] = z;
        b->w[i] = w;
        /* 0 off the grid (NaN included), so that every lane converts (below): one
         * mask, where clamping each side costs a compare and a blend */
        px[i] = in ? X : 0.0f;
        py[i] = in ? Y : 0.0f;
        b->ok[i] = ok;
    }
    /* a loop of its own: in the one above, a compiler would convert only the lanes it
     * knows to be in range, under a branch, and then not vectorize it */
    for (int i = 0; i < LANES; i++) {
        b->gx[i] = om__floorf_i32(px[i]);
        b->gy[i] = om__floorf_i32(py[i]);
    }
}


#if VERT_LANES
/* om__zdepth of the lanes' z and w up to its division, a loop over the lanes on the
 * floats' bits (copied out whole: a union a lane would stop a compiler's lanes), with
 * its tests and steps in its order: kind 0 for depth 0 (z <= 0, NaN, or below one
 * unit), 2 for 2^32 - 1 (z >= w), 1 for mz * 2^e / mw (a shift left or right, then
 * one integer division), the same bits. Only lanes of w > 0 are used. */
typedef struct depths {
    uint32_t mz[LANES], mw[LANES];
    int32_t e[LANES], kind[LANES];
} depths;

static inline void lanes_depth(depths *restrict d, const lanes *restrict l)
{
    uint32_t bz[LANES], bw[LANES];
    memcpy(bz, l->z, sizeof bz);
    memcpy(bw, l->w, sizeof bw);
    for (int i = 0; i < LANES; i++) {
        const int32_t ez = (int32_t)(bz[i] >> 23), ew = (int32_t)(bw[i] >> 23);   /* z > 0, w > 0: no sign */
        d->mz[i] = (bz[i] & 0x7FFFFFu) | (ez ? 0x800000u : 0u);
        d->mw[i] = (bw[i] & 0x7FFFFFu) | (ew ? 0x800000u : 0u);
        const int32_t e = (ez + !ez) - (ew + !ew) + 32;   /* a subnormal's exponent is the least normal one's */
        const int32_t pos = l->z[i] > 0.0f, below = l->z[i] < l->w[i];
        d->e[i] = e;
        d->kind[i] = pos & below ? (int32_t)(e >= -24) : 2 * pos;
    }
}
#endif

/* The bins' vertices [v0, v1): each snapped alone as om__raster_tri would snap it when
 * it needs no clipping, its depth with it (a triangle's strips and bands share it),
 * x = INT32_MIN when it needs clipping. Every entry is written: the frame's bins are
 * not zeroed first. */
void om__bins_make_verts(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t width, uint32_t height, const om__bins *b,
                         uint32_t v0, uint32_t v1)
{
    om__vsnap *vs = b->verts;
    const om__guard g = om__guard_band(width, height);
    if (!vs) return;
    if (v1 > s->nverts) v1 = s->nverts;
#if VERT_LANES
    const float sx = (float)width * (OM_SUBPIX / 2), sy = (float)height * (OM_SUBPIX / 2);
    lanes l;
    depths d;
    float px[LANES], py[LANES], pz[LANES];
    for (uint32_t v = v0; v < v1; v += LANES) {
        const uint32_t n = v1 - v < LANES ? v1 - v : LANES;
        const om_vec3 *p = s->verts + v;
        if (n == LANES) {   /* a loop of its own: the compiler's lanes load three lanes' worth */
            for (uint32_t i = 0; i < LANES; i++) {
                px[i] = p[i].x - o.x;
                py[i] = p[i].y - o.y;
                pz[i] = p[i].z - o.z;
            }
        } else {
            for (uint32_t i = 0; i < LANES; i++) {   /* a short last batch repeats its first vertex */
                const uint32_t k = i < n ? i : 0;
                px[i] = p[k].x - o.x;
                py[i] = p[k].y - o.y;
                pz[i] = p[k].z - o.z;
            }
        }
        /* The lines PREFETCH_AHEAD batches on, for writing (OM_PREFETCH_WRITE): on a
         * host's threads they were last read by every thread's bands. */
        if (v1 - v > (PREFETCH_AHEAD + 1) * LANES)
            for (uint32_t at = 0; at < LANES * sizeof *vs; at += 64)   /* a line is 64 bytes or more */
                OM_PREFETCH_WRITE((const char *)&vs[v + PREFETCH_AHEAD * LANES] + at);
        lanes_project(&l, px, py, pz, vp, g, sx, sy);
        lanes_depth(&d, &l);
        for (uint32_t i = 0; i < n; i++) {
            om__vsnap *out = &vs[v + i];
            if (l.ok[i]) {
                const uint32_t mz = d.mz[i], mw = d.mw[i];
                const int32_t e = d.e[i];
                out->x = l.gx[i];
                out->y = l.gy[i];
                out->z = d.kind[i] == 1 ? (uint32_t)(e >= 0 ? ((uint64_t)mz << e) / mw : mz / ((uint64_t)mw << -e))
                                      : d.kind[i] == 2 ? 0xFFFFFFFFu : 0u;
            } else {
                out->x = INT32_MIN;
                out->y = 0;
                out->z = 0;
            }
        }
    }
#else
    for (uint32_t v = v0; v < v1; v++) {
        const om_vec4 c = om__mat_apply(vp, om__sub(s->verts[v], o));
        int64_t x, y;
        uint32_t z;
        om__vsnap *out = &vs[v];
        /* om__raster_tri's first test (finite, inside every plane), then its projection */
        if (om__finite(c.x) && om__finite(c.y) && om__finite(c.z) && om__finite(c.w) && om__inside_band(&c, g) &&
            om__project(&c, width, height, &x, &y, &z)) {
            out->x = (int32_t)x;   /* |x|, |y| < 2^26 after om__project */
            out->y = (int32_t)y;
            out->z = z;
        } else {
            out->x = INT32_MIN;
            out->y = 0;
            out->z = 0;
        }
    }
#endif
}

/* ---- the walk without vertex bins, a batch of triangles at a time: lane c * BATCH + k
 * is corner c of the batch's triangle k. A triangle whose box holds no pixel centre of
 * the target is then passed over before any setup, and one with a vertex outside a
 * plane (or not finite) goes to om__raster_tri_guarded as its clip-space vertices, as
 * before. */
typedef struct batch {
    lanes v;
    int32_t go[BATCH];       /* 0: passed over, 1: to be clipped, 2: projected, in the target's box */
    int32_t todo[BATCH], ntodo;   /* the k whose go is not 0, in order */
} batch;

/* The scene's triangles t0..t0 + n (n <= BATCH) through vp onto a width x height image. */
static void batch_project(batch *b, const om_scene *s, uint32_t t0, uint32_t n, const om_mat4 *vp, om_vec3 o,
                          om__guard g, float sx, float sy)
{
    float px[LANES], py[LANES], pz[LANES];
    for (uint32_t k = 0; k < BATCH; k++)
        for (int c = 0; c < 3; c++) {
            const om_vec3 v = k < n ? om__sub(s->verts[s->idx[((size_t)t0 + k) * 3 + c]], o) : om__v3(0.0f, 0.0f, 0.0f);
            px[c * BATCH + k] = v.x;
            py[c * BATCH + k] = v.y;
            pz[c * BATCH + k] = v.z;
        }
    lanes_project(&b->v, px, py, pz, vp, g, sx, sy);
}

/* What each of the batch's first n triangles needs (batch.go), and which need
 * anything (batch.todo): a list made without branches, as whether a small triangle's
 * box holds a centre is a coin toss to a branch predictor. */
static void batch_boxes(batch *b, uint32_t n, const om_target *tg, bool cons)
{
    for (int k = 0; k < BATCH; k++) {
        const int32_t *gx = b->v.gx + k, *gy = b->v.gy + k, *ok = b->v.ok + k;
        const int32_t in = holds_centre(gx[0], gx[BATCH], gx[2 * BATCH], gy[0], gy[BATCH], gy[2 * BATCH], tg);
        const int32_t all = ok[0] & ok[BATCH] & ok[2 * BATCH];
        /* conservative coverage reaches pixels beyond the centres: no skipping there */
        b->go[k] = all ? 2 * (in | (int32_t)cons) : 1;
    }
    b->ntodo = 0;
    for (int k = 0; k < (int)n; k++) {
        b->todo[b->ntodo] = k;
        b->ntodo += b->go[k] != 0;
    }
#if VERT_LANES && (defined(__GNUC__) || defined(__clang__))
    /* The line of the first pixel centre of each triangle that holds one, asked for a
     * batch before it is drawn (walk_batches): a small triangle's texel is most often
     * a cache miss on a large map. A read: the line comes with no other copy, and its
     * store then needs no more. Where the CPU has lanes, and so caches worth asking. */
    if (!cons)
        for (int j = 0; j < b->ntodo; j++) {
            const int k = b->todo[j];
            if (b->go[k] != 2) continue;
            const int32_t *gx = b->v.gx + k, *gy = b->v.gy + k;
            const centre_box c = centres_in(gx[0], gx[BATCH], gx[2 * BATCH], gy[0], gy[BATCH], gy[2 * BATCH]);
            const int32_t px = c.x0 < 0 ? 0 : c.x0, py = c.y0 < (int32_t)tg->y0 ? (int32_t)tg->y0 : c.y0;
            __builtin_prefetch(tg->depth + (size_t)(py - (int32_t)tg->y0) * tg->width + px);
        }
#endif
}

static void walk_batches(const om_scene *s, const om_mat4 *vp, om_vec3 o, om_raster *r, uint32_t *hiz, bool cull,
                         const uint32_t *rows, uint32_t ta, uint32_t tb)
{
    const om_target *tg = r->target;
    const uint32_t y0 = tg->y0, y1 = tg->y0 + tg->rows - 1;
    const om__guard g = om__guard_band(tg->width, tg->height);
    const float sx = (float)tg->width * (OM_SUBPIX / 2), sy = (float)tg->height * (OM_SUBPIX / 2);
    om__cull cl;
    om__cull_begin(&cl, s, vp, o);
    /* a batch ahead: batch t1 is projected, and its texels asked for (batch_boxes),
     * before batch t1 - BATCH is drawn; one call of each, which a compiler puts in line */
    batch bb[2];
    for (uint32_t t1 = ta, h = 0;; t1 += BATCH, h ^= 1) {
        if (t1 < tb) {
            const uint32_t n = tb - t1 < BATCH ? tb - t1 : BATCH;
            batch_project(&bb[h], s, t1, n, vp, o, g, sx, sy);
            batch_boxes(&bb[h], n, tg, r->mode == OM_RASTER_CONSERVATIVE);
        }
        if (t1 == ta) continue;
        if (t1 - BATCH >= tb) break;
        const uint32_t t0 = t1 - BATCH;
        const batch *b = &bb[h ^ 1];
        for (int q = 0; q < b->ntodo; q++) {
            const uint32_t k = (uint32_t)b->todo[q], t = t0 + k;
            if (rows && ((rows[t] & 0xFFFFu) > y1 || rows[t] >> 16 < y0)) continue;
            r->cull_back = cull && om__cull_next(&cl, t);
            om_vec4 c[3];
            for (int j = 0; j < 3; j++) {
                const uint32_t i = (uint32_t)j * BATCH + k;
                c[j].x = b->v.x[i];
                c[j].y = b->v.y[i];
                c[j].z = b->v.z[i];
                c[j].w = b->v.w[i];
            }
            if (b->go[k] == 2) {
                const int64_t x[3] = {b->v.gx[k], b->v.gx[BATCH + k], b->v.gx[2 * BATCH + k]};
                const int64_t y[3] = {b->v.gy[k], b->v.gy[BATCH + k], b->v.gy[2 * BATCH + k]};
                om__raster_projected(r, hiz, x, y, NULL, c, t);
            } else {
                om__raster_tri_guarded(r, hiz, c, t, tg->width, tg->height, g);
            }
        }
    }
}

/* One triangle of the walk with vertex bins (om__scene_raster_hiz), its rows reaching
 * the target's; `box`: its box is yet to be tested for a pixel centre of the target;
 * `cbox`: the centres its box holds when the caller has them (block_list), or NULL. */
#if VERT_LANES
#define BIN_INLINE OM_INLINE   /* the block walk's loop takes it without a call */
#else
#define BIN_INLINE static inline   /* the compiler's choice: a Cortex-M counts less */
#endif
BIN_INLINE void bin_tri(const om_scene *s, const om_mat4 *vp, om_vec3 o, om_raster *r, uint32_t *hiz, om__cull *cl,
                        bool cull, const om__vsnap *vs, om__guard g, bool box, uint32_t t, const int32_t *cbox)
{
    const om_target *tg = r->target;
    const uint32_t *ix = s->idx + (size_t)t * 3;
    const om__vsnap *va = &vs[ix[0]], *vb = &vs[ix[1]], *vc = &vs[ix[2]];
    if (va->x != INT32_MIN && vb->x != INT32_MIN && vc->x != INT32_MIN) {
        /* in 32 bits first: most triangles a strip's rows reach hold none of its
         * pixel centres (conservative coverage reaches beyond them) */
        if (box && !holds_centre(va->x, vb->x, vc->x, va->y, vb->y, vc->y, tg)) return;
        r->cull_back = cull && s->solids && om__cull_next(cl, t);   /* its first test, without a call */
        const uint32_t z[3] = {va->z, vb->z, vc->z};
#if VERT_LANES
        const int32_t x[3] = {va->x, vb->x, vc->x}, y[3] = {va->y, vb->y, vc->y};
        om__raster_projected32(r, hiz, x, y, z, t, cbox);
#else
        /* without lanes there are no block lists (cbox), and the 64-bit vertices
         * snapped takes cost a Cortex-M less than the 32-bit entry's own tests */
        (void)cbox;
        const int64_t x[3] = {va->x, vb->x, vc->x}, y[3] = {va->y, vb->y, vc->y};
        om__raster_projected(r, hiz, x, y, z, NULL, t);
#endif
        return;
    }
    r->cull_back = cull && om__cull_next(cl, t);
    om_vec4 c[3];
    om__clip_tri(s, vp, o, t, c);
    om__raster_tri_guarded(r, hiz, c, t, tg->width, tg->height, g);
}

#if VERT_LANES
/* Where the CPU has lanes, the bins' rows are scanned SCAN triangles at a time: which
 * of them reach the target's rows [y0, y1], in a loop over lanes with no branch (a
 * compiler tests four an instruction), so that a band passes over the many triangles
 * outside it at a fraction of a test each (every band of a frame scans every
 * triangle's rows). Without lanes (a Cortex-M) the hits would only be stored and read
 * again, and each triangle is tested as it comes. The same triangles either way. */
#define SCAN 32

static inline uint32_t rows_reach(const uint32_t *restrict rows, uint32_t y0, uint32_t y1, uint32_t *restrict hit)
{
    uint32_t any = 0;
    for (int k = 0; k < SCAN; k++) {
        const uint32_t w = rows[k];
        hit[k] = ((w & 0xFFFFu) <= y1) & ((w >> 16) >= y0);
        any |= hit[k];
    }
    return any;
}

/* The same for the last n < SCAN triangles. */
static uint32_t rows_reach_few(const uint32_t *rows, uint32_t n, uint32_t y0, uint32_t y1, uint32_t *hit)
{
    uint32_t any = 0;
    for (uint32_t k = 0; k < n; k++) {
        hit[k] = (rows[k] & 0xFFFFu) <= y1 && rows[k] >> 16 >= y0;
        any |= hit[k];
    }
    return any;
}
#endif

#if VERT_LANES
/* A block of SCAN triangles of the walk with vertex bins and no rows: the ones to draw,
 * in order (list, n), with the pixel centres their box holds (centres_in's, for
 * om__raster_projected32), and the first texel of each whose box holds a centre of the
 * target (at, m). */
typedef struct block { int32_t list[SCAN], n, at[SCAN], m, cb[4][SCAN]; } block;

/* The block of the n <= SCAN triangles from t0: those of three snapped vertices whose
 * box holds a pixel centre of tg (bin_tri's test), and those to clip, listed without
 * a branch, as whether a small triangle's box holds a centre is a coin toss to a
 * branch predictor. The boxes in a loop over lanes of their own (a compiler tests
 * four an instruction), after the vertices are gathered; a vertex to clip counts as
 * at 0 there, a short block's missing triangles as triangle t0's. */
static inline void block_list(const om_scene *s, const om__vsnap *vs, const om_target *tg, uint32_t t0, uint32_t n,
                              block *b)
{
    int32_t x[3][SCAN], y[3][SCAN], px[SCAN], py[SCAN], go[SCAN], holds[SCAN];
    for (uint32_t k = 0; k < SCAN; k++) {
        const uint32_t *ix = s->idx + (size_t)(t0 + (k < n ? k : 0)) * 3;
        const om__vsnap *va = &vs[ix[0]], *vb = &vs[ix[1]], *vc = &vs[ix[2]];
        x[0][k] = va->x;
        y[0][k] = va->y;
        x[1][k] = vb->x;
        y[1][k] = vb->y;
        x[2][k] = vc->x;
        y[2][k] = vc->y;
    }
    const int32_t xe = (int32_t)tg->width - 1, ya0 = (int32_t)tg->y0, ye = (int32_t)(tg->y0 + tg->rows) - 1;
    for (int k = 0; k < SCAN; k++) {
        const int32_t sn = (x[0][k] != INT32_MIN) & (x[1][k] != INT32_MIN) & (x[2][k] != INT32_MIN);
        const int32_t xa = sn ? x[0][k] : 0, xb = sn ? x[1][k] : 0, xc = sn ? x[2][k] : 0;
        const int32_t ya = sn ? y[0][k] : 0, yb = sn ? y[1][k] : 0, yc = sn ? y[2][k] : 0;
        const centre_box c = centres_in(xa, xb, xc, ya, yb, yc);
        const int32_t px0 = c.x0 < 0 ? 0 : c.x0, px1 = c.x1 > xe ? xe : c.x1;
        const int32_t py0 = c.y0 < ya0 ? ya0 : c.y0, py1 = c.y1 > ye ? ye : c.y1;
        const int32_t h = sn & (px0 <= px1) & (py0 <= py1);
        b->cb[0][k] = c.x0;
        b->cb[1][k] = c.x1;
        b->cb[2][k] = c.y0;
        b->cb[3][k] = c.y1;
        holds[k] = h;
        go[k] = (sn ^ 1) | h;
        px[k] = px0;
        py[k] = py0 - ya0;
    }
    int32_t k1 = 0, m = 0;
    for (int32_t k = 0; k < (int32_t)n; k++) {
        b->list[k1] = k;
        k1 += go[k];
        b->at[m] = py[k] * (int32_t)tg->width + px[k];   /* within the target where it holds a centre */
        m += holds[k];
    }
    b->n = k1;
    b->m = m;
}
#endif

/* A plain pass of `mode` into tg: pixel centres, no spans, masks or grid. */
static void raster_plain(om_raster *r, const om_target *tg, om_raster_mode mode)
{
    r->target = tg;
    r->mode = mode;
    r->span = NULL;
    r->user = NULL;
    r->centres = NULL;
    r->centre_mask = NULL;
    r->grid_x = r->grid_y = NULL;
    r->grid_xs = r->grid_ys = NULL;
    r->grid_shift = r->grid_buckets = 0;
    r->mask_words = 0;
    r->cull_back = false;
    r->row_mask = NULL;
    r->row_shift = 0;
}

void om__scene_raster_part(const om_scene *s, const om_mat4 *vp, om_vec3 o, const om_target *tg, om_raster_mode mode,
                           bool cull, uint32_t t0, uint32_t t1)
{
    om_raster r;
    raster_plain(&r, tg, mode);
    walk_batches(s, vp, o, &r, NULL, cull, NULL, t0 < s->ntris ? t0 : s->ntris, t1 < s->ntris ? t1 : s->ntris);
}

void om__scene_raster_hiz(const om_scene *s, const om_mat4 *vp, om_vec3 o, const om_target *tg,
                          om_raster_mode mode, bool cull, const om__bins *bins, uint32_t *hiz)
{
    om_raster r;
    raster_plain(&r, tg, mode);
    om__target_clear(tg);
    om__hiz_clear(hiz, tg);
    const uint32_t y0 = tg->y0, y1 = tg->y0 + tg->rows - 1;
    const uint32_t *rows = bins ? bins->rows : NULL;
    const om__vsnap *vs = bins ? bins->verts : NULL;
    if (!vs) {
        walk_batches(s, vp, o, &r, hiz, cull, rows, 0, s->ntris);
        return;
    }
    om__cull cl;
    om__cull_begin(&cl, s, vp, o);
    const om__guard g = om__guard_band(tg->width, tg->height);
#if VERT_LANES
    /* conservative coverage reaches pixels beyond the centres; centre rows have
     * tested the boxes already (om__bins.centres) */
    const bool box = mode != OM_RASTER_CONSERVATIVE && !(rows && bins->centres);
    if (box && !rows) {
        /* Block t1 is listed before block t1 - SCAN is drawn. Where few of a block's
         * triangles hold a centre (a scene of many triangles below a texel each), the
         * walk's bins stream through the caches between two draws and a texel is most
         * often a miss: the block's first texels are then asked for, a block before
         * they are drawn. Where most of them draw, the draws' own misses overlap, and
         * a burst of requests would only wait for the ones before it. */
        block bl[2];
        for (uint32_t t1 = 0, h = 0;; t1 += SCAN, h ^= 1) {
            if (t1 < s->ntris) {
                block *nb = &bl[h];
                block_list(s, vs, tg, t1, s->ntris - t1 < SCAN ? s->ntris - t1 : SCAN, nb);
#if defined(__GNUC__) || defined(__clang__)
                if (nb->m <= SCAN / 2)
                    for (int32_t j = 0; j < nb->m; j++) __builtin_prefetch(tg->depth + nb->at[j]);
#endif
            }
            if (t1 == 0) continue;
            if (t1 - SCAN >= s->ntris) break;
            const block *b = &bl[h ^ 1];
            for (int32_t j = 0; j < b->n; j++) {
                const int32_t k = b->list[j], cb[4] = {b->cb[0][k], b->cb[1][k], b->cb[2][k], b->cb[3][k]};
                bin_tri(s, vp, o, &r, hiz, &cl, cull, vs, g, false, t1 - SCAN + (uint32_t)k, cb);
            }
        }
        return;
    }
    uint32_t hit[SCAN];
    for (uint32_t t0 = 0; t0 < s->ntris; t0 += SCAN) {
        const uint32_t n = s->ntris - t0 < SCAN ? s->ntris - t0 : SCAN;
        if (rows && (n == SCAN ? !rows_reach(rows + t0, y0, y1, hit) : !rows_reach_few(rows + t0, n, y0, y1, hit)))
            continue;
        for (uint32_t k = 0; k < n; k++)
            if (!rows || hit[k]) bin_tri(s, vp, o, &r, hiz, &cl, cull, vs, g, box, t0 + k, NULL);
    }
#else
    for (uint32_t t = 0; t < s->ntris; t++) {
        if (rows && ((rows[t] & 0xFFFFu) > y1 || rows[t] >> 16 < y0)) continue;
        bin_tri(s, vp, o, &r, hiz, &cl, cull, vs, g, mode != OM_RASTER_CONSERVATIVE, t, NULL);
    }
#endif
}
