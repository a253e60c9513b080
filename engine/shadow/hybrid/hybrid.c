/* hybrid.c — exact shadows at close to a shadow map's cost. A conservative map of the
 * occlusion predicate's light grid (occlude.h) proves most samples lit or shadowed;
 * only the samples it leaves uncertain go through an irregular z-buffer of their own
 * (below), whose every test is the shared predicate. The result equals `ref` bit for
 * bit.
 *
 * The map has side x side texels over the light's grid (hybrid.map, or by default
 * about a quarter of the image's larger side: map_side), each a square of
 * T x T grid points (the last row and column reach on to the guard band). A triangle
 * touches a texel when its edge functions admit a point of the texel's square (tested
 * against the square's extreme corner per edge: never missed, sometimes extra). Per
 * texel the build keeps
 *   lo      a plane below every touching triangle's depth (clamped as the predicate
 *           clamps) plus its snapping bound, at every point of the square inside the
 *           box of the triangle's vertices;
 *   hi, cid over opaque triangles of one sub-triangle whose edges admit all four
 *           corners of the square (so every point of it: the admitted set is convex):
 *           the least of (their depth at the square's corner where their plane is
 *           greatest, + their bound), and which triangle gave it.
 * Depths are rounded outwards by a depth unit (far above the double evaluation's
 * error), then to float outwards.
 *
 * Why the two certain answers are the predicate's, for a sample p with grid point g in
 * texel e (om__blocks: a triangle t blocks p when t != p's own triangle, g is inside
 * t's first sub-triangle that admits it, and that sub-triangle's depth at g plus its
 * bound is below p.z):
 *   certainly lit when lo at g >= p.z. A blocker t admits g, so it touches e; g is in
 *     the closed triangle of t's vertices (every edge function >= 0: the tie rule only
 *     takes points away), so in their box; and lo at g is at most t's depth at g plus
 *     its bound, which is below p.z: lo < p.z.
 *   certainly shadowed when hi < p.z and cid != own. cid is one sub-triangle admitting
 *     every point of e, g among them (so it is the first that admits g), with depth
 *     at g at most its depth at the corner where its plane is greatest (the clamp
 *     keeps the order), so its depth + bound < p.z: it blocks p; it is opaque, so the
 *     optical depth saturates whatever else blocks, and the term is 0 in every
 *     channel, as the reference's. No predicate is run: the lookup is the answer.
 * A semi-transparent caster never makes a sample certain but lit (then nothing blocks
 * and the term is exactly 255); the sample's own triangle is excluded by its id; a
 * sample on a texel's border belongs to the one texel its grid point falls in, and
 * that texel's square holds the point. Everything else is uncertain.
 *
 * The uncertain samples go through an irregular z-buffer of their own, a tile of them
 * at a time (izb.pool, or as many as the arena holds; hybrid_tile.c): every test there
 * is the predicate, om__blocks, so those answers are the reference's too. */
#include "hybrid.h"

/* Most uncertain samples a tile takes, whatever izb.pool says (tile_most): the tiles
 * are the jobs of the pass on the host's threads (om__pass, below), each with a
 * tile's memory of its own from the frame arena, which om_frame_bytes' with_jobs sizes from
 * the scene alone; and a strip's uncertain samples make several tiles to share out.
 * But every tile walks every triangle (or with candidates, hybrid_tile.c, finds them
 * among every triangle): twice the scene's triangles, at least TILE_LEAST and at
 * most TILE_CAP, keeps that walk small beside a tile's own work, where smaller tiles
 * would set up a large scene's triangles again in each; a tile of many samples is cut
 * into regions instead. */
#define TILE_LEAST 32768u
#define TILE_CAP 262144u

static uint32_t tile_most(const om_scene *s)
{
    const uint64_t t = 2 * (uint64_t)s->ntris;
    return t < TILE_LEAST ? TILE_LEAST : t > TILE_CAP ? TILE_CAP : (uint32_t)t;
}

/* The map's side: as set, or by default the largest power of two at most a quarter
 * of the image's larger side (at least 16): texels of about 4 x 4 pixels where the
 * light's image and the camera's agree, and memory that scales with the image (256 at
 * 1024x768, 32 at 160x120). A finer map leaves fewer samples uncertain but costs
 * more to build and clear than the irregular pass it saves; a coarser one leaves the
 * irregular pass more than its build saves. */
static uint32_t map_side(const hybrid_cfg *c, uint32_t w, uint32_t h)
{
    if (c->hybrid_map) return c->hybrid_map;
    uint32_t quarter = (w > h ? w : h) / 4, side = 16;
    while (side * 2 <= quarter && side < 4096) side *= 2;
    return side;
}

static size_t mats_bytes(const om_scene *s)
{
    return om_arena_need((size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4);
}

/* Everything but the pool; the per-frame vertex projection with `cache`. */
static size_t fixed_bytes(uint32_t side, const om_scene *s, bool cache)
{
    return om_arena_need(sizeof(hybrid_state), 16) + (cache ? om__lspace_bytes(s) : 0) + mats_bytes(s) +
           om_arena_need((size_t)side * side * sizeof(htexel), 16);
}

/* A pool of n uncertain samples: a tile's memory (hybrid_tile.c), with room for
 * `cands` candidates. */
static size_t pool_bytes(uint32_t n, uint32_t cands) { return om_arena_need(om__htile_bytes(n, cands), 16); }

/* The pool's least and largest sizes: as set, or from one row up to the frame; never
 * above tile_most. */
static void pool_range(const hybrid_cfg *c, const om_scene *s, uint32_t w, uint32_t h, uint32_t *least,
                       uint32_t *most)
{
    const uint32_t lo = c->izb_pool ? c->izb_pool : w, hi = c->izb_pool ? c->izb_pool : w * h, t = tile_most(s);
    *least = lo < t ? lo : t;
    *most = hi < t ? hi : t;
}

/* Most tiles a strip makes with pools of `least` samples, for the pass's starts. */
static uint32_t most_tiles(uint32_t w, uint32_t h, uint32_t least)
{
    return OM_WITH_JOBS ? (uint32_t)(((uint64_t)w * h + least - 1) / least) : 0;
}

static size_t starts_bytes(uint32_t tiles)
{
    return OM_WITH_JOBS ? om_arena_need(((size_t)tiles + 1) * sizeof(uint32_t), 4) : 0;
}

static om_status need(const hybrid_cfg *c, const om_scene *s, uint32_t w, uint32_t h,
                      size_t *min, size_t *full)
{
    if (c->hybrid_map > OM_LIGHT_GRID) return OM_E_INVALID;
    uint32_t smallest, one_pass, side = map_side(c, w, h);
    pool_range(c, s, w, h, &smallest, &one_pass);
    const size_t starts = starts_bytes(most_tiles(w, h, smallest));
    *min = fixed_bytes(side, s, false) + starts + pool_bytes(smallest, 0);
    *full = fixed_bytes(side, s, true) + starts + pool_bytes(one_pass, OM_WITH_JOBS ? s->ntris : 0);
    return OM_OK;
}

static om_status hybrid_bytes(const om_method_cfg *mc, const om_scene *s, uint32_t w, uint32_t h,
                              size_t *min, size_t *full)
{
    hybrid_cfg c;
    if (om__method_cfg_of(mc, &om__method_hybrid, &c, NULL)) return OM_E_INVALID;
    return need(&c, s, w, h, min, full);
}

static om_status carve(om_arena *a, size_t n, size_t size, void **p, om_diag *d)
{
    return om_arena_alloc(a, n * size, 16, p, d);
}

static om_status hybrid_init(void **state, om_arena *a, const om_method_cfg *mc, const om_scene *s,
                             uint32_t w, uint32_t h, om_diag *d)
{
    om_status st;
    void *p;
    size_t mn, full;
    hybrid_cfg c;
    if ((st = om__method_cfg_of(mc, &om__method_hybrid, &c, d))) return st;
    if (c.hybrid_map > OM_LIGHT_GRID)
        return om__fail(d, OM_E_INVALID, "hybrid: hybrid.map must be 0 (auto) to 8192");
    if ((st = need(&c, s, w, h, &mn, &full))) return st;
    if ((st = om__need(a, mn, "hybrid", d))) return st;
    if ((st = om_arena_alloc(a, sizeof(hybrid_state), 16, &p, d))) return st;
    hybrid_state *m = (hybrid_state *)p;
    memset(m, 0, sizeof *m);
    m->scene = s;
    m->cfg = c;
    m->side = map_side(&c, w, h);
    m->T = (GRID_SIDE + m->side - 1) / m->side;
    m->tshift = -1;
    for (int b = 0; b < 62; b++)
        if (((int64_t)1 << b) == m->T) m->tshift = b;
    if ((st = carve(a, (size_t)m->side * m->side, sizeof(htexel), &p, d))) return st;
    m->map = (htexel *)p;
    /* The vertex projection only when the least pool fits beside it (it speeds up
     * triangle setup, it changes no result); then the pool, as set or as large as
     * the arena allows, from one row up to the frame, at most tile_most. */
    uint32_t want, least;
    pool_range(&c, s, w, h, &least, &want);
    m->most_tiles = most_tiles(w, h, least);
    if (OM_WITH_JOBS) {
        if ((st = om_arena_alloc(a, ((size_t)m->most_tiles + 1) * sizeof(uint32_t), 4, &p, d))) return st;
        m->starts = (uint32_t *)p;
    }
    if (om_arena_left(a) >= om__lspace_bytes(s) + mats_bytes(s) + pool_bytes(least, 0)) {
        if ((st = om__lspace_init(&m->ls, a, s, d))) return st;
    } else {
        om__lspace_init_lean(&m->ls, s);
    }
    if ((st = om_arena_alloc(a, (size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4, &p, d)))
        return st;
    m->mat_od = (om__odepth *)p;
    for (uint32_t i = 0; i < s->nmats; i++) m->mat_od[i] = om__material_odepth(&s->mats[i]);
    /* The candidates (hybrid_tile.c) with the projection, where the whole pool still
     * fits beside them (the pool matters more), and the frame has threads to cut tiles
     * for (OM_WITH_JOBS: not on Cortex-M, whose counts are then those of whole tiles). */
    size_t left = om_arena_left(a);
    m->cands = OM_WITH_JOBS && m->ls.verts && pool_bytes(want, s->ntris) <= left ? s->ntris : 0;
    uint32_t cap = least, hi = want;
    while (cap < hi) {   /* the largest pool that fits */
        uint32_t mid = cap + (hi - cap + 1) / 2;
        if (pool_bytes(mid, m->cands) <= left) cap = mid;
        else hi = mid - 1;
    }
    m->cap = cap;
    if ((st = om_arena_alloc(a, om__htile_bytes(cap, m->cands), 16, &p, d))) return st;
    om__htile_carve(&m->tile, p, cap, m->cands);
    m->h.scene = s;
    m->h.ls = &m->ls;
    m->h.mat_od = m->mat_od;
    *state = m;
    return OM_OK;
}

/* begin but for the projection of the scene's vertices (when they are kept): returns
 * how many there are to project, which the pass's jobs do in ranges (hybrid_pass_setup)
 * and hybrid_begin here otherwise. */
static uint32_t begin_view(hybrid_state *m, const om_view *v)
{
    om__lspace_view(&m->ls, v);
    m->lit = m->shadowed = m->uncertain = m->tiles = m->tile.setups = m->tile.tested = m->tile.regions = 0;
    return m->ls.verts ? m->scene->nverts : 0;
}

static om_status hybrid_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    hybrid_state *m = (hybrid_state *)state;
    om__lspace_project(&m->ls, 0, begin_view(m, v));
    return OM_OK;
}

static om_status hybrid_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)state; (void)st; (void)d;
    return OM_OK;
}


/* Is the texel's plane at offset (dx, dy) from its centre at depth z (zi, as an
 * integer) or beyond? The test is in double; with OM_FAST_FLOAT single
 * precision answers first where it can. The float's value is within
 * (|h->z| + |gx dx| + |gy dy| + z) 2^-21 of the exact one (the conversions of dx, dy
 * and z, two products and two sums, each within 2^-24 of its magnitude), and the
 * double's within 2^-50 of that: more than e = that sum times 2^-19 away from z, the
 * float answers as the double would, the same on every CPU. */
static inline bool plane_at_or_beyond(const htexel *h, int64_t dx, int64_t dy, double z, uint32_t zi)
{
#if OM_FAST_FLOAT
    /* dx, dy: a sample is within 2^26 of the grid (om__snap_xy), so int32 converts */
    const float a = h->gx * (float)(int32_t)dx, b = h->gy * (float)(int32_t)dy, fz = (float)zi;
    const float v = h->z + a + b, e = (om__fabsf(h->z) + om__fabsf(a) + om__fabsf(b) + fz) * 0x1p-19f;
    if (v - e >= fz) return true;
    if (v + e < fz) return false;
#else
    (void)zi;
#endif
    return (double)h->z + (double)h->gx * (double)dx + (double)h->gy * (double)dy >= z;
}

/* The map's answer for a sample: 1 certainly lit, 2 certainly shadowed (t set to 0),
 * 0 uncertain, with *tex its texel. */
static inline int classify_at(const hybrid_state *m, const om__lpoint *p, int64_t tx, int64_t ty, om_term *t,
                              int64_t *tex)
{
    const htexel *h = &m->map[ty * (int64_t)m->side + tx];
    *tex = ty * (int64_t)m->side + tx;
    int64_t xc = tx * m->T + m->T / 2, yc = ty * m->T + m->T / 2;
#if OM_FAST_FLOAT
    const uint32_t z = (uint32_t)p->z;   /* a whole depth unit (om__lspace_point) */
    if (h->z == FLT_MAX || plane_at_or_beyond(h, p->x - xc, p->y - yc, p->z, z))
        return 1;   /* the term is already 255 */
    /* hi < z exactly, for a whole z: floor(hi) < z (a float is whole from 2^24) */
    const bool below = h->hi < 0.0f || (h->hi < 4294967296.0f && (uint32_t)h->hi < z);
#else
    if (h->z == FLT_MAX || plane_at_or_beyond(h, p->x - xc, p->y - yc, p->z, 0))
        return 1;   /* the term is already 255 */
    const bool below = (double)h->hi < p->z;
#endif
    if (below && h->cid != p->tri) {
        t->r = t->g = t->b = 0;
        return 2;
    }
    return 0;
}

/* classify_at in the texel of p's grid point. */
static inline int classify(const hybrid_state *m, const om__lpoint *p, om_term *t, int64_t *tex)
{
    return classify_at(m, p, texel_of(m, p->x), texel_of(m, p->y), t, tex);
}

int om__hybrid_decide(void *state, const om__lpoint *p, om_term *t)
{
    int64_t tex;
    return classify((const hybrid_state *)state, p, t, &tex);
}

const om__lspace *om__hybrid_lspace(const void *state) { return &((const hybrid_state *)state)->ls; }

/* Samples go onto the light's grid LANES exposed ones at a time: first the light's
 * matrix times each one's point, its division and snap and its texel, in loops over
 * the lanes with no branch on the data that a compiler can run on vector registers
 * (om__mat_apply's and om__project_xy's float operations in their order, as
 * om__lspace_point's: the same bits), then the float test that proves most of them
 * lit (surely_lit), and only for the rest each one's exact depth (om__zdepth: an
 * integer division) and lookup. Each batch sets up the light's matrix and constants
 * again, so wider batches set them up fewer times; 32 where a double is a software
 * routine (OM_FAST_FLOAT: no vector unit, and a small stack), else 64. */
#if OM_FAST_FLOAT
#define LANES 32
#else
#define LANES 64
#endif

/* Is the sample certainly lit, decided in single precision without its exact depth:
 * the answer classify_at's first test would give (the texel's plane, in double, at or
 * beyond om__zdepth of the sample's clip z and w), where this says so; 0 where it
 * cannot tell. hz, gx, gy: the texel's plane (hz FLT_MAX: empty, every sample in it
 * lit); dx, dy: the sample's grid point less the texel's centre; zf: its clip z
 * times 1/w (the float reciprocal om__project_xy takes) times 2^32. Compares and
 * arithmetic only, no branch and no division: lanes. Why a yes is classify_at's
 * (each float operation rounds within 2^-24 of its result, x87's wider ones too; the
 * double's within 2^-53; below, S = |hz| + |a| + |b|):
 *   the depth: om__zdepth is 0 for z <= 0 (zf <= 0), for z/w below a unit (zf's
 *     product underflowed to 0 or beyond) and for NaN; else it is at most q = z/w 2^32
 *     (truncated, clamped), and zf = q (1 + d1)(1 + d2), |d1|, |d2| <= 2^-24, so
 *     for zf > 0, zh = zf + |zf| 2^-21 (rounded, at least zf (1 + 2^-22)) is at
 *     least q. The test asks v - e >= zh and >= 0: at least om__zdepth either way
 *     (a NaN zh answers no);
 *   the plane: dx, dy convert within 2^-24 (exactly below 2^24), so a = gx dx and
 *     b = gy dy are within 2^-22.9 of |a| and |b|, and the two sums within 2^-24 of
 *     theirs: v is within 2^-21.9 S of the exact plane, the double's (classify_at)
 *     within 2^-50.9 S;
 *   the test: fl(v - e) >= zh, 0 gives v - e >= max(zh, 0) - 2^-24 |zh| (rounding is
 *     monotone, zh and 0 are floats), and e is at least 2^-20.01 (S + |zh|) (three
 *     sums rounded down at most) plus 1/2 for the underflows of tiny products (below
 *     2^-126 each): so the double's plane is above max(zh, 0) + (2^-20.01 - 2^-21.9 -
 *     2^-50.9) S >= om__zdepth.
 * Infinities and NaN (an empty texel's NaN slopes, z/w beyond the float's range) make
 * the tests false; an empty texel is lit by its own test. */
static inline int32_t surely_lit(float hz, float gx, float gy, int32_t dx, int32_t dy, float zf)
{
    const float a = gx * (float)dx, b = gy * (float)dy, v = hz + a + b, zh = zf + om__fabsf(zf) * 0x1p-21f;
    const float e = (om__fabsf(hz) + om__fabsf(a) + om__fabsf(b) + om__fabsf(zh)) * 0x1p-20f + 1.0f, d = v - e;
    return (hz == FLT_MAX) | ((d >= zh) & (d >= 0.0f));
}

/* The next batch of the strip's samples from *i on: every term set to 255 on the way,
 * up to LANES exposed samples projected and looked up, counts[0], [1], [2] counting
 * those certainly lit, certainly shadowed and uncertain. The uncertain ones' keys go
 * to q, in the strip's order; returns how many. */
static uint32_t look_up(const hybrid_state *m, om_strip *st, size_t *i, size_t n, uint32_t counts[3],
                        om__hkey q[LANES])
{
    float px[LANES], py[LANES], pz[LANES], cz[LANES], cw[LANES];
    float zf[LANES], hz[LANES], hgx[LANES], hgy[LANES];   /* surely_lit's */
    int32_t gx[LANES], gy[LANES], tx[LANES], ty[LANES], ok[LANES], lit[LANES];
    om__facet facet = {OM_NO_TRI, 0.0f};   /* om__lspace_pull's */
    uint32_t at[LANES], tri[LANES], k = 0, u = 0;
    for (; *i < n && k < LANES; ++*i) {
        om_term *t = &st->terms[*i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        const om_sample *s = &st->samples[*i];
        px[k] = s->p[0];
        py[k] = s->p[1];
        pz[k] = s->p[2];
        tri[k] = s->tri;
        at[k++] = (uint32_t)*i;
    }
    for (uint32_t j = k; j < LANES; j++) {   /* lanes left over */
        px[j] = py[j] = pz[j] = 0.0f;
        at[j] = tri[j] = 0;
    }
    /* om__project_xy's operations in its order, lane by lane, with no branch on the
     * data: the same bits where ok (a lane that fails, where X and Y may be infinite
     * or NaN, converts 0 instead: one mask, where clamps cost a blend each) */
    const float sx = (float)OM_LIGHT_GRID * (OM_SUBPIX / 2), sy = sx, lim = 67108864.0f;
    for (uint32_t j = 0; j < LANES; j++) {
        const om_vec4 c = om__mat_apply(&m->ls.vp, om__v3(px[j], py[j], pz[j]));
        const float iw = 1.0f / c.w;
        const float X = (c.x * iw + 1.0f) * sx + 0.5f, Y = (1.0f - c.y * iw) * sy + 0.5f;
        const int32_t in = (c.w > 0.0f) & (X > -lim) & (X < lim) & (Y > -lim) & (Y < lim);
        ok[j] = in;
        px[j] = in ? X : 0.0f;
        py[j] = in ? Y : 0.0f;
        cz[j] = c.z;
        cw[j] = c.w;
        zf[j] = c.z * iw * OM_DEPTH_ONE_F;
    }
    /* a loop of its own, as scene_raster.c's lanes: in the one above a compiler would
     * convert only the lanes it knows in range, under a branch */
    for (uint32_t j = 0; j < LANES; j++) {
        gx[j] = om__floorf_i32(px[j]);
        gy[j] = om__floorf_i32(py[j]);
    }
    /* texel_of's texels, in lanes where T is a power of two (the default sides) */
    if (m->tshift >= 0) {
        const int sh = m->tshift;
        const int32_t last = (int32_t)m->side - 1;
        for (uint32_t j = 0; j < LANES; j++) {
            const int32_t x = gx[j] < 0 ? 0 : gx[j] >> sh, y = gy[j] < 0 ? 0 : gy[j] >> sh;
            tx[j] = x < last ? x : last;
            ty[j] = y < last ? y : last;
        }
    } else {
        for (uint32_t j = 0; j < LANES; j++) {
            tx[j] = (int32_t)texel_of(m, gx[j]);
            ty[j] = (int32_t)texel_of(m, gy[j]);
        }
    }
    /* each lane's texel plane (a loop of loads), then the float test in lanes; the
     * grid and its texels' centres fit in 32 bits (2^21 units, a sample within 2^26) */
    const int32_t T = (int32_t)m->T, side = (int32_t)m->side;
    for (uint32_t j = 0; j < LANES; j++) {
        const htexel *h = &m->map[ty[j] * side + tx[j]];
        hz[j] = h->z;
        hgx[j] = h->gx;
        hgy[j] = h->gy;
    }
    for (uint32_t j = 0; j < LANES; j++)
        lit[j] = surely_lit(hz[j], hgx[j], hgy[j], gx[j] - (tx[j] * T + T / 2), gy[j] - (ty[j] * T + T / 2), zf[j]);
    for (uint32_t j = 0; j < k; j++) {
        if (!ok[j]) continue;
        if (lit[j]) {   /* the term is already 255 */
            counts[0]++;
            continue;
        }
        om__lpoint p;
        int64_t tex;
        p.x = gx[j];
        p.y = gy[j];
        const uint32_t z = om__zdepth(cz[j], cw[j]);
        p.z = z;
        p.tri = tri[j];
        /* lit at the unpulled depth is lit at the pulled one (om__lspace_point_at):
         * else the depth as om__lspace_point pulls it, and the map asked again */
        int a = classify_at(m, &p, tx[j], ty[j], &st->terms[at[j]], &tex);
        if (a != 1) {
            st->terms[at[j]].r = st->terms[at[j]].g = st->terms[at[j]].b = 255;
            p.z = om__lspace_pull(&m->ls, &facet, tri[j], z);
            a = classify_at(m, &p, tx[j], ty[j], &st->terms[at[j]], &tex);
        }
        counts[a == 1 ? 0 : a == 2 ? 1 : 2]++;
        if (a == 0) om__hkey_put(&q[u++], &p, at[j]);
    }
    return u;
}

/* The strip's resolve on one thread: each exposed sample is projected, looked up and
 * counted, and the uncertain ones go through the irregular pass a tile (cap samples)
 * at a time, in the strip's order. */
static om_status hybrid_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    hybrid_state *m = (hybrid_state *)state;
    const size_t n = (size_t)st->rows * st->width;
    size_t i = 0;
    uint32_t counts[3] = {0, 0, 0}, k = 0;
    om__hkey q[LANES];
    while (i < n) {
        const uint32_t u = look_up(m, st, &i, n, counts, q);
        for (uint32_t j = 0; j < u; j++) {
            m->tile.raw[k++] = q[j];
            if (k == m->cap) {   /* a tile is full: its samples' terms, before the next */
                om__htile_run(&m->h, &m->tile, k, st, NULL);
                m->tiles++;
                k = 0;
            }
        }
    }
    if (k) {
        om__htile_run(&m->h, &m->tile, k, st, NULL);
        m->tiles++;
    }
    m->lit += counts[0];
    m->shadowed += counts[1];
    m->uncertain += counts[2];
    return OM_OK;
}

/* ---- on the host's threads: by bands (om__bands), each band projects and looks up
 * its own samples, reading the map only, and marks the uncertain ones; merge adds up
 * the counts. Then the pass (om__pass) takes the marked samples in the tiles
 * hybrid_resolve makes (cap of them, in the strip's order), a job a tile with a tile's
 * memory of its own: the same terms and counts whatever the number of jobs. */

/* The term a band leaves on a sample its map could not decide (no certain answer is
 * ever anything but 0 or 255 in every channel); the pass overwrites every one. */
static bool marked(const om_term *t) { return t->r == 0 && t->g == 0 && t->b == 1; }

static void hybrid_band(const void *state, om_strip *st, void *scratch, uint32_t counts[8])
{
    (void)scratch;
    const hybrid_state *m = (const hybrid_state *)state;
    const size_t n = (size_t)st->rows * st->width;
    size_t i = 0;
    om__hkey q[LANES];
    while (i < n) {
        const uint32_t u = look_up(m, st, &i, n, counts, q);
        for (uint32_t j = 0; j < u; j++) {
            om_term *t = &st->terms[q[j].idx];
            t->r = t->g = 0;
            t->b = 1;
        }
    }
}

static void hybrid_merge(void *state, const uint32_t counts[8])
{
    hybrid_state *m = (hybrid_state *)state;
    m->lit += counts[0];
    m->shadowed += counts[1];
    m->uncertain += counts[2];
}

const om__bands om__bands_hybrid = {hybrid_band, hybrid_merge, 0, NULL, NULL, NULL};

/* A tile job's scratch: a tile like the state's, with its room for candidates. */
static size_t hybrid_pass_scratch(const void *state, const om_scene *s)
{
    const hybrid_state *m = (const hybrid_state *)state;
    return m ? om__htile_bytes(m->cap, m->cands) : s ? om__htile_bytes(tile_most(s), s->ntris) : 0;
}

/* A sample the bands left to the pass. */
static bool left_open(const om_term *t) { return (t->flags & OM_TERM_EXPOSED) && marked(t); }

/* Tile k's samples: the marked ones from its start, projected, into raw; how many. */
static uint32_t tile_keys(const hybrid_state *m, const om_strip *st, uint32_t k, om__hkey *raw)
{
    uint32_t n = 0;
    for (size_t i = m->starts[k]; i < m->starts[k + 1] && n < m->cap; i++) {
        om__lpoint p;
        if (left_open(&st->terms[i]) && om__lspace_point(&m->ls, &st->samples[i], &p)) om__hkey_put(&raw[n++], &p, i);
    }
    return n;
}

/* Where each tile begins, from the strip's samples on this thread; how many tiles. */
static uint32_t starts_here(hybrid_state *m, const om_strip *st)
{
    const size_t n = (size_t)st->rows * st->width;
    uint32_t k = 0, left = 0;
    for (size_t i = 0; i < n; i++) {
        if (!left_open(&st->terms[i])) continue;
        if (left == 0) {
            m->starts[k++] = (uint32_t)i;
            left = m->cap;
        }
        left--;
    }
    m->starts[k] = (uint32_t)n;
    return k;
}

/* ---- the same on the lent threads, in `parts` parts of the strip's samples (about
 * sixteen a thread, up to 64, taken as threads come free: a strip's uncertain samples
 * bunch up, and with a few parts a thread one part can hold much of the keys' work):
 * each part counts its marked samples, and the counts say where each tile begins and
 * where each part's keys go in a tile. A part writes the
 * keys of its samples that fall in the tile, in their order, where its first one goes;
 * a sample whose projection fails (none: the bands marked it after the same
 * projection) would leave a gap, closed after. So the same keys as tile_keys, in the
 * same order. The tiles run one after another, each writing its samples' terms: a
 * part scans from the tile's start on. */
typedef struct key_job {
    hybrid_state *m;
    const om_strip *st;
    uint32_t parts, tile;
} key_job;

static size_t part_first(const key_job *j, uint32_t p)
{
    return (size_t)((uint64_t)j->st->rows * j->st->width * p / j->parts);
}

static void count_part(void *user, uint32_t p, void *scratch)
{
    (void)scratch;
    const key_job *j = (const key_job *)user;
    uint32_t c = 0;
    for (size_t i = part_first(j, p), end = part_first(j, p + 1); i < end; i++) c += left_open(&j->st->terms[i]);
    j->m->part_marked[p + 1] = c;
}

/* starts_here in parts; part_marked becomes each part's first marked sample's rank. */
static uint32_t starts_by_parts(hybrid_state *m, const om_strip *st, uint32_t parts)
{
    key_job j = {m, st, parts, 0};
    m->part_marked[0] = 0;
    m->lend->run_any(m->lend, count_part, &j, parts);
    for (uint32_t p = 0; p < parts; p++) m->part_marked[p + 1] += m->part_marked[p];
    const uint32_t k = (m->part_marked[parts] + m->cap - 1) / m->cap;
    for (uint32_t t = 0, p = 0; t < k; t++) {   /* tile t begins at the marked sample of rank t cap */
        const uint32_t want = t * m->cap;
        while (m->part_marked[p + 1] <= want) p++;
        size_t i = part_first(&j, p);
        for (uint32_t rank = m->part_marked[p];; i++)
            if (left_open(&st->terms[i]) && rank++ == want) break;
        m->starts[t] = (uint32_t)i;
    }
    m->starts[k] = (uint32_t)((size_t)st->rows * st->width);
    return k;
}

static void keys_part(void *user, uint32_t p, void *scratch)
{
    (void)scratch;
    const key_job *j = (const key_job *)user;
    hybrid_state *m = j->m;
    const uint32_t lo = j->tile * m->cap, hi = lo + m->cap;
    size_t i = part_first(j, p);
    const size_t end = part_first(j, p + 1);
    uint32_t rank = m->part_marked[p], put = 0;
    if (i < m->starts[j->tile]) {   /* the earlier tiles' samples are no longer marked */
        i = m->starts[j->tile];
        rank = lo;
    }
    m->part_put[p] = 0;
    if (rank >= hi) return;   /* a later tile's part */
    om__hkey *raw = m->tile.raw + (rank - lo);
    for (; i < end && rank < hi; i++) {
        om__lpoint pt;
        if (!left_open(&j->st->terms[i]) || rank++ < lo) continue;
        if (om__lspace_point(&m->ls, &j->st->samples[i], &pt)) om__hkey_put(&raw[put++], &pt, i);
    }
    m->part_put[p] = put;
}

/* tile_keys of `tile` into the state's tile, in parts. */
static uint32_t keys_by_parts(hybrid_state *m, const om_strip *st, uint32_t parts, uint32_t tile)
{
    key_job j = {m, st, parts, tile};
    m->lend->run_any(m->lend, keys_part, &j, parts);
    const uint32_t lo = tile * m->cap;
    uint32_t n = 0;
    for (uint32_t p = 0; p < parts; p++) {
        const uint32_t at = m->part_marked[p] > lo ? m->part_marked[p] - lo : 0;
        if (m->part_put[p] && at != n) memmove(m->tile.raw + n, m->tile.raw + at, m->part_put[p] * sizeof *m->tile.raw);
        n += m->part_put[p];
    }
    return n;
}

/* Where each tile of marked samples begins: at every cap-th of them. Each tile is then
 * a job with a tile's memory of its own (its regions one after another), or where a
 * strip makes too few tiles to keep the threads busy (with candidates, fewer than
 * two a slot), they run here one after another on the state's tile, their regions the
 * jobs (0 returned: no job left). The same terms and counts either way. */
static uint32_t hybrid_pass_plan(void *state, om_strip *st)
{
    hybrid_state *m = (hybrid_state *)state;
    const uint32_t want = m->lend ? 16 * m->lend->slots : 0;
    const uint32_t parts = want < OM__HYBRID_PARTS ? want : OM__HYBRID_PARTS;
    const uint32_t k = parts ? starts_by_parts(m, st, parts) : starts_here(m, st);
    if (!m->cands || !m->lend || k >= 2 * m->lend->slots) return m->ntiles = k;
    for (uint32_t t = 0; t < k; t++, m->tiles++)
        om__htile_run(&m->h, &m->tile, keys_by_parts(m, st, parts, t), st, m->lend);
    return 0;
}

static void hybrid_pass_job(const void *state, const om_strip *st, uint32_t k, void *scratch, uint32_t counts[8])
{
    const hybrid_state *m = (const hybrid_state *)state;
    om__htile t;
    om__htile_carve(&t, scratch, m->cap, m->cands);
    om__htile_run(&m->h, &t, tile_keys(m, st, k, t.raw), st, NULL);
    counts[0] += t.setups;
    counts[1] += t.tested;
    counts[2]++;
    counts[3] += t.regions;
}

static void hybrid_pass_merge(void *state, const uint32_t counts[8])
{
    hybrid_state *m = (hybrid_state *)state;
    m->tile.setups += counts[0];
    m->tile.tested += counts[1];
    m->tiles += counts[2];
    m->tile.regions += counts[3];
}

/* begin with the vertex projection left to the jobs, in ranges of vertices (a large
 * scene's projection would otherwise hold every other thread up); the build that
 * reads them runs after. */
static om_status hybrid_pass_begin(void *state, const om_view *v, uint32_t *items, om_diag *d)
{
    (void)d;
    *items = begin_view((hybrid_state *)state, v);
    return OM_OK;
}

static void hybrid_pass_setup(const void *state, uint32_t first, uint32_t end)
{
    om__lspace_project(&((const hybrid_state *)state)->ls, first, end);
}

/* The slots the regions run on, this frame (NULL at its end or with fewer than two). */
static void hybrid_pass_lend(void *state, const om__lend *l)
{
    if (state) ((hybrid_state *)state)->lend = l && l->slots > 1 ? l : NULL;
}

const om__pass om__pass_hybrid = {hybrid_pass_scratch, hybrid_pass_plan, hybrid_pass_job, hybrid_pass_merge,
                                  hybrid_pass_begin, hybrid_pass_setup, hybrid_pass_lend};

static void hybrid_stats(const void *state, om_method_stats *out)
{
    const hybrid_state *m = (const hybrid_state *)state;
    memset(out, 0, sizeof *out);
    out->bytes_used = fixed_bytes(m->side, m->scene, m->ls.verts != NULL) + starts_bytes(m->most_tiles) +
                      pool_bytes(m->cap, m->cands);
    static const char *const names[] = {"certain lit", "certain shadowed", "uncertain", "triangles set up",
                                        "samples tested", "tiles", "pool samples", "regions"};
    uint32_t v[8] = {m->lit, m->shadowed, m->uncertain, m->tile.setups, m->tile.tested, m->tiles, m->cap,
                     m->tile.regions};
    for (int i = 0; i < 8; i++) {
        out->counters[i] = v[i];
        out->counter_names[i] = names[i];
    }
    out->ncounters = 8;
}

static const om_setting settings[] = {
    OM__SET_IZB_POOL(hybrid_cfg, izb_pool),
    OM__SETTING(hybrid_cfg, hybrid_map, "hybrid.map", OM_SETTING_U32, 0, OM_MAX_DIM, 0,
                "side of its conservative map (20 bytes a texel), 0 = a quarter of the image's side"),
};

const om_method om__method_hybrid = {
    "hybrid", "exact: a conservative map decides most samples, an irregular z-buffer the rest",
    OM_METHOD_EXACT, hybrid_bytes, hybrid_init, hybrid_begin, hybrid_observe, om__hybrid_build,
    hybrid_resolve, hybrid_stats, NULL, settings, sizeof settings / sizeof settings[0],
    sizeof(hybrid_cfg),
    OM__JOBS_ONLY(&om__bands_hybrid), OM__JOBS_ONLY(&om__pass_hybrid),
};
