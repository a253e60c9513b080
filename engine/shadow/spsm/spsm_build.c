/* spsm_build.c — the build of the Sub-Pixel Shadow Map (paper 004, section 3.2): every
 * triangle is rasterized conservatively from the light (every texel whose square it
 * touches); the depth test uses the minimum conservative depth over the texel (the
 * least depth the triangle reaches inside the square), kept in a 32-bit buffer beside
 * the texels, and the winner's record (section 3.3, spsm_texel.c) is written to the
 * texel; near ties share the texels out in a fixed pattern (texel, below). The plain
 * map's depth at texel centres is made in the same pass, and with spsm.fine the plain
 * map at twice the resolution in a second one. With marks (spsm.c's observe) all of it
 * is done only at the texels the lookup will read. */
#include "spsm.h"

/* need = seen grown by one texel each way (the 3x3 the lookup decodes); returns the
 * number of texels in it. Bits past the map's width in a row's last word may be set:
 * no texel reads them. */
static uint32_t grow_needs(om__spsm_state *m)
{
    const uint32_t W = m->words, S = m->size;
    uint32_t count = 0;
    if (!m->marks) {
        memset(m->need, 0xFF, (size_t)S * W * sizeof(uint32_t));
        return S * S;
    }
    memset(m->need_rows, 0, W * sizeof(uint32_t));
    for (uint32_t y = 0; y < S; y++) {
        uint32_t *out = m->need + (size_t)y * W, any = 0;
        for (uint32_t j = 0; j < W; j++) {
            uint32_t v = 0;   /* the three rows' words, each grown sideways */
            for (uint32_t r = y ? y - 1 : 0; r <= y + 1 && r < S; r++) {
                const uint32_t *row = m->seen + (size_t)r * W;
                uint32_t w = row[j];
                v |= w | w << 1 | w >> 1;
                if (j) v |= row[j - 1] >> 31;
                if (j + 1 < W) v |= row[j + 1] << 31;
            }
            out[j] = v;
            any |= v;
            for (uint32_t b = v; b; b &= b - 1) count++;
        }
        if (any) m->need_rows[y >> 5] |= 1u << (y & 31);
    }
    return count;
}
typedef struct build_ctx {
    const om__spsm_state *m;     /* its buffers written at the band's rows only */
    /* what the texels of one triangle share (tri_setup), for the triangle with these
     * vertices and fixed-point plane: the spans of a triangle come one after another */
    bool have;
    int64_t ex[3], ey[3];
    uint64_t zq[3];
    uint32_t zv[3], zmin;        /* its vertex depths (e's order) and their least */
    float zf[3];                 /* the vertex depths in float (clipped_min) */
    bool down_x, down_y;         /* whether depth falls along x, along y */
    uint8_t qx, qy;              /* the derivative codes */
    om__spsm_fplane fp;          /* the double plane's answers without it (spsm_texel.h) */
    om__rtri dt;                 /* the triangle with its double plane, where fp is */
    bool have_dt;                /* not sure (made on demand) */
    /* the y codes of the row being filled, for the triangle with these y coordinates:
     * the fill runs along rows, so most texels written reuse them */
    int64_t ry[3];
    int32_t row;
    bool have_row;
    uint16_t vy[3];
} build_ctx;

/* The triangle's double plane (om__rtri_plane, which conservative mode does not set),
 * for the answers om__spsm_fplane is not sure of. */
static const om__rtri *double_plane(build_ctx *b, const om__rtri *t)
{
    if (!b->have_dt) {
        uint32_t z[3];   /* om__rtri_plane takes them in the input order */
        for (int i = 0; i < 3; i++) z[t->e.perm[i]] = b->zv[i];
        b->dt = *t;
        om__rtri_plane(&b->dt, z);
        b->have_dt = true;
    }
    return &b->dt;
}

/* What every texel of triangle t needs, worked out once: the vertex depths from the
 * fixed-point plane (at a vertex its value is the vertex's own depth: om__rtri_zat's
 * rule at the top of raster.h), and the derivative codes of the double plane's slopes
 * from the table's boundaries (om__spsm_q_encode_f; the slopes rounded to float
 * first), where om__spsm_fplane is not sure of them from the plane itself. */
static void tri_setup(build_ctx *b, const om__rtri *t)
{
    const om__tri2 *e = &t->e;
    om__spsm_copy3(b->ex, e->x);
    om__spsm_copy3(b->ey, e->y);
    b->zq[0] = t->zq0;
    b->zq[1] = t->zqx;
    b->zq[2] = t->zqy;
    for (int i = 0; i < 3; i++) {
        b->zv[i] = om__rtri_zat(t, e->x[i], e->y[i]);
        b->zf[i] = (float)b->zv[i];
    }
    b->zmin = b->zv[0] < b->zv[1] ? b->zv[0] : b->zv[1];
    if (b->zv[2] < b->zmin) b->zmin = b->zv[2];
    b->have_dt = false;
    om__spsm_fplane_setup(&b->fp, &b->m->q, t, b->zv);
    if (b->fp.sure) {
        b->qx = b->fp.qx;
        b->qy = b->fp.qy;
        b->down_x = b->fp.down_x;
        b->down_y = b->fp.down_y;
    } else {
        /* derivatives in depth steps per texel, scaled (spsm_texel.h): raw per grid unit
         * times OM_SUBPIX / OM__SPSM_STEP / OM_SPSM_DSCALE = 2^-11, exact in float */
        const om__rtri *d = double_plane(b, t);
        const float gx = (float)d->zx, gy = (float)d->zy, k = (float)(OM_SUBPIX / OM__SPSM_STEP / OM_SPSM_DSCALE);
        b->qx = om__spsm_q_encode_f(&b->m->q, gx * k);
        b->qy = om__spsm_q_encode_f(&b->m->q, gy * k);
        b->down_x = gx > 0.0f;   /* the least depth over a square is at its left side */
        b->down_y = gy > 0.0f;
    }
    b->have = true;
}

static bool same_tri(const build_ctx *b, const om__rtri *t)
{
    return b->have && b->zq[0] == t->zq0 && b->zq[1] == t->zqx && b->zq[2] == t->zqy && om__spsm_same3(b->ex, t->e.x) &&
           om__spsm_same3(b->ey, t->e.y);
}

/* The least depth of the triangle inside the texel square at grid corner (x0, y0),
 * when the square's corner its slopes point to lies outside it: the least over their
 * overlap is then on the triangle's boundary, at an end of one of its edges clipped to
 * the square (om__spsm_clip_f), the end its depth falls towards, interpolated between
 * the edge's vertex depths in float (within a few hundred raw units, under 2^-7 of a
 * 16-bit depth step, of the exact value). The triangle's least vertex depth when no
 * edge meets the square (only the conservative bounds' rounding brings it here). */
static uint32_t clipped_min(const build_ctx *b, const om__tri2 *e, int64_t x0, int64_t y0)
{
    float best = 4294967040.0f;   /* the largest float below 2^32 */
    bool any = false;
    for (int i = 0; i < 3; i++) {
        const int j = i == 2 ? 0 : i + 1;
        float t0, t1;
        if (!om__spsm_clip_f(om__spsm_off_f(e->x[i] - x0), om__spsm_off_f(e->y[i] - y0),
                             om__spsm_off_f(e->x[j] - e->x[i]), om__spsm_off_f(e->y[j] - e->y[i]),
                             (float)OM_SUBPIX, &t0, &t1))
            continue;
        const float zi = b->zf[i], zj = b->zf[j], z = zi + (zj < zi ? t1 : t0) * (zj - zi);
        if (z < best) best = z;
        any = true;
    }
    if (!any) return b->zmin;
    return best > 0.0f ? (uint32_t)best : 0u;
}

/* One texel x of row y touched by t: the depth test and, for the winner, its record. */
/* Texel rows of the whole map whose squares meet a triangle's bounding box, first and
 * last: the rasterizer's conservative bounds (raster.c) before a band clamps them to
 * its own rows, so that a band decides as the whole map would. */
static int64_t texel_floor(int64_t a)
{
    return a >= 0 ? a >> OM_SUBPIX_BITS : -((OM_SUBPIX - 1 - a) >> OM_SUBPIX_BITS);
}

static bool one_row(const om__spsm_state *m, const om__tri2 *e)
{
    int64_t lo = e->y[0], hi = e->y[0];
    for (int i = 1; i < 3; i++) {
        if (e->y[i] < lo) lo = e->y[i];
        if (e->y[i] > hi) hi = e->y[i];
    }
    int64_t y0 = texel_floor(lo - 1), y1 = texel_floor(hi);
    if (y0 < 0) y0 = 0;
    if (y1 > (int64_t)m->size - 1) y1 = (int64_t)m->size - 1;
    return y0 == y1;
}

static void texel(build_ctx *b, int32_t x, int32_t y, const om__rtri *t)
{
    const om__spsm_state *m = b->m;
    const om__tri2 *e = &t->e;
    if (!same_tri(b, t)) tri_setup(b, t);
    /* Minimum conservative depth (section 3.2): the least depth the triangle reaches
     * inside the texel's square. That is the plane's least value over the square, at
     * the corner its slopes point to, when the triangle covers that corner; otherwise
     * it is on the triangle clipped to the square. (The paper takes the plane's value
     * at the corner even there, nearer than the triangle reaches: a steep triangle
     * behind an occluder then takes its texels.) A long sliver, a fence bar's face,
     * so competes with its depth in this texel, not with its nearest end's. */
    const int64_t kx = (int64_t)x * OM_SUBPIX, ky = (int64_t)y * OM_SUBPIX;
    /* a triangle touching this texel alone lies inside it: its nearest vertex is the
     * answer (at the map's edge the bounds are clamped, and zmin stays a lower bound) */
    const bool alone = t->minx == t->maxx && t->miny == t->maxy && (!OM_WITH_JOBS || one_row(m, e));
    uint32_t z = b->zmin;
    if (!alone) {
        const int64_t qx = kx + (b->down_x ? 0 : OM_SUBPIX), qy = ky + (b->down_y ? 0 : OM_SUBPIX);
        /* inside the triangle the fixed-point plane is exact to a unit (raster.h) */
        z = om__spsm_covers(e, qx, qy) ? om__rtri_zat(t, qx, qy) : clipped_min(b, e, kx, ky);
        if (z < b->zmin) z = b->zmin;
    }
    uint32_t dz = z & ~OM__SPSM_TIES;
    size_t i = (size_t)y * m->size + (size_t)x;
    /* Near ties (within OM__SPSM_TIE_DZ, what recovery takes for one surface) are most often
     * the halves of one flat quad, the faces of one thin part (a fence bar, a pole)
     * or the small triangles of a fine mesh. The k-th triangle to tie for a texel (k
     * = nt) takes it where (x + (k - 1) y) mod k = k - 1: the second on a checkerboard,
     * the third on one texel of each row and column of a 3x3, and so on, so that the
     * neighbourhood recovery reads holds as many of them as it can (keeping the first
     * everywhere loses the rest of the outline). The depth keeps the nearer. */
    uint32_t o = m->depth[i], od = o & ~OM__SPSM_TIES, nt = o & OM__SPSM_TIES;
    if (o != 0xFFFFFFFFu && (dz >= od ? dz - od : od - dz) <= (uint32_t)OM__SPSM_TIE_DZ) {
        if (nt < OM__SPSM_TIES - 1) nt++;
        m->depth[i] = (dz < od ? dz : od) | nt;
        if (((uint32_t)x + (nt - 1) * (uint32_t)y) % nt != nt - 1) return;
    } else {
        if (dz > od) return;
        m->depth[i] = dz | 1u;
    }
    if (!b->have_row || y != b->row || !om__spsm_same3(b->ry, e->y)) {
        om__spsm_row_codes(b->vy, t, y);
        om__spsm_copy3(b->ry, e->y);
        b->row = y;
        b->have_row = true;
    }
    int32_t zc = om__spsm_centre_zf(&b->fp, t, x, y);
    if (zc < 0) zc = om__spsm_centre_z(double_plane(b, t), x, y);
    om__spsm_pack_row(&m->tex[i], t, x, b->qx, b->qy, b->vy, (uint16_t)zc);
}

/* Sets rows [y0, y0 + rows) of a buffer to the far plane (empty) at the needed texels,
 * a word of them at a time. */
static void clear_needed(const om__spsm_state *m, uint32_t *buf, uint32_t y0, uint32_t rows)
{
    if (!m->marks) {   /* every texel is needed: one pass over the rows */
        const size_t n = (size_t)rows * m->size;
        for (size_t i = 0; i < n; i++) buf[(size_t)y0 * m->size + i] = 0xFFFFFFFFu;
        return;
    }
    for (uint32_t y = y0; y < y0 + rows; y++)
        for (uint32_t j = 0; j < m->words; j++) {
            if (!m->need[(size_t)y * m->words + j]) continue;
            const uint32_t x0 = j * 32, x1 = x0 + 32 < m->size ? x0 + 32 : m->size;
            for (uint32_t x = x0; x < x1; x++) buf[(size_t)y * m->size + x] = 0xFFFFFFFFu;
        }
}

/* fneed = need at twice the resolution (a texel's bit becomes its four points'), and
 * those points of the fine map cleared. */
static void grow_fine_needs(om__spsm_state *m)
{
    const uint32_t S = m->size, W = m->words, FW = m->fwords;
    for (uint32_t y = 0; y < S; y++) {
        uint32_t *f0 = m->fneed + (size_t)(2 * y) * FW, *f1 = f0 + FW;
        for (uint32_t j = 0; j < FW; j++) {
            /* fine word j holds texels 16j .. 16j + 15, each bit twice */
            const uint32_t w = m->need[(size_t)y * W + j / 2] >> (16 * (j & 1)) & 0xFFFFu;
            uint32_t v = 0;
            for (uint32_t b = w; b; b &= b - 1) v |= 3u << (2 * om__ctz32(b));
            /* (need may hold bits past the map's side; no point lies there) */
            const uint32_t left = 2 * S - 32 * j;
            if (left < 32) v &= (1u << left) - 1u;
            f0[j] = f1[j] = v;
            for (uint32_t bit = v; bit; bit &= bit - 1) {   /* and clears them */
                const size_t x = 32 * (size_t)j + (size_t)om__ctz32(bit);
                m->fdepth[(size_t)(2 * y) * (2 * S) + x] = m->fdepth[(size_t)(2 * y + 1) * (2 * S) + x] = 0xFFFFFFFFu;
            }
        }
    }
}

/* The fine pass has no records to write: its conservative spans are not needed. */
static void no_span(void *user, int32_t y, int32_t x0, int32_t x1, const om__rtri *t)
{
    (void)user; (void)y; (void)x0; (void)x1; (void)t;
}

/* Every triangle of the scene through r, from the light, back faces of closed shapes
 * culled. With bins (made for the light's matrix on the map's grid, om__bins_make), a
 * triangle whose rows miss the target's is passed over and, on the map's own grid
 * (fine = 1), one that needs no clipping goes straight to om__raster_snapped, as
 * om__raster_tri would send it; on the fine map (fine = 2) a map row is two of its
 * rows. The same texels either way. */
static void raster_scene(const om__spsm_state *m, om_raster *r, const om__bins *bins, uint32_t fine)
{
    const om_scene *s = m->scene;
    const uint32_t y0 = r->target->y0, y1 = r->target->y0 + r->target->rows - 1;
    const uint32_t *rows = OM_WITH_JOBS && bins ? bins->rows : NULL;   /* (config.h) */
    const om__vsnap *vs = OM_WITH_JOBS && bins && fine == 1 ? bins->verts : NULL;
    om__cull cl;
    om__cull_begin(&cl, s, &m->view.light_vp, m->view.origin);
    for (uint32_t t = 0; t < s->ntris; t++) {
        if (rows && ((rows[t] & 0xFFFFu) * fine > y1 || (rows[t] >> 16) * fine + fine - 1 < y0)) continue;
        r->cull_back = om__cull_next(&cl, t);
        const uint32_t *ix = s->idx + (size_t)t * 3;
        if (vs && vs[ix[0]].x != INT32_MIN && vs[ix[1]].x != INT32_MIN && vs[ix[2]].x != INT32_MIN) {
            const int64_t x[3] = {vs[ix[0]].x, vs[ix[1]].x, vs[ix[2]].x};
            const int64_t y[3] = {vs[ix[0]].y, vs[ix[1]].y, vs[ix[2]].y};
            const uint32_t z[3] = {vs[ix[0]].z, vs[ix[1]].z, vs[ix[2]].z};
            om__raster_snapped(r, x, y, z, t);
            continue;
        }
        om_vec4 c[3];
        om__clip_tri(s, &m->view.light_vp, m->view.origin, t, c);
        om__raster_tri(r, c, t);
    }
}

/* The texels of a span that the lookup will read (need). */
static void span(void *user, int32_t y, int32_t x0, int32_t x1, const om__rtri *t)
{
    build_ctx *b = (build_ctx *)user;
    const uint32_t *row = b->m->need + (size_t)y * b->m->words;
    for (int32_t x = om__mask_next(row, x0, x1); x <= x1; x = om__mask_next(row, x + 1, x1)) texel(b, x, y, t);
}

/* What the map's rows share, on the calling thread (om__bands.map_of): the texels the
 * lookup will read, and with spsm.fine the fine map's points (those cleared). */
uint32_t om__spsm_map_of(void *state, uint32_t k, const om_mat4 **vp)
{
    om__spsm_state *m = (om__spsm_state *)state;
    if (k > 0) return 0;   /* one map */
    om__spsm_observe_fold(m);    /* the bands' marks, where they observed */
    m->win.t4_at = (size_t)-1;   /* no texel index: the map is about to change */
    m->win.bd_have = false;
    m->win.rd_have = false;      /* and the light's matrix may have moved */
    m->needed = grow_needs(m);
    if (m->fine && m->cfg.spsm_aa <= 1 && m->marks) grow_fine_needs(m);
    *vp = &m->view.light_vp;
    return m->size;
}

/* Rows [y0, y0 + rows) of the map (om__bands.build_rows): every buffer of a texel (or a
 * fine point) in them is written by this band alone. */
void om__spsm_build_rows(const void *state, uint32_t k, const om__bins *bins, uint32_t y0, uint32_t rows,
                         uint32_t counts[8])
{
    (void)k;        /* one map */
    (void)counts;   /* the needs were counted before the bands */
    const om__spsm_state *m = (const om__spsm_state *)state;
    const size_t S = m->size;
    /* The plain map at texel centres, for the fallback of 4.2, is the rasterizer's own
     * depth pass, made alongside the conservative one. Without AA the lookup reads it
     * inside the 3x3 too, so both buffers are cleared and written at the needed texels
     * only; sub-samples reach beyond, so with AA the plain map is made whole. */
    const bool whole_plain = m->cfg.spsm_aa > 1;
    om_target tc = {m->size, m->size, y0, rows, m->cdepth + (size_t)y0 * S, NULL};
    if (whole_plain) om__target_clear(&tc);
    else clear_needed(m, m->cdepth, y0, rows);
    clear_needed(m, m->depth, y0, rows);
    /* texels are not cleared: one whose depth is still the far plane's is empty */
    om_target tg = {m->size, m->size, y0, rows, m->depth + (size_t)y0 * S, NULL};
    build_ctx b;
    memset(&b, 0, sizeof b);
    b.m = m;
    om_raster r;
    memset(&r, 0, sizeof r);
    r.target = &tg;
    r.mode = OM_RASTER_CONSERVATIVE;
    r.span = span;
    r.user = &b;
    r.centres = &tc;
    r.centre_mask = whole_plain ? NULL : m->need + (size_t)y0 * m->words;
    r.mask_words = m->words;
    /* rows with no needed texel: span() and the masked centres would do nothing there */
    r.row_mask = whole_plain || !m->marks ? NULL : m->need_rows;
    r.row_shift = 0;
    /* A light ray that meets a closed shape's back face has met a front face before
     * it, so a back face is never the occluder a record should describe: culled, the
     * record of a rim texel is more often the grazing front face the ray really hits,
     * which leaves fewer mismatches at every map size. The plain depth is the same. */
    raster_scene(m, &r, bins, 1);
    if (!m->fine) return;
    /* The plain map at twice the resolution, at the points the lookup reads (all of
     * them with AA), for plain_shadow: a second pass, since its grid is not the
     * records'. Its rows 2 y0 .. belong to this band. */
    const uint32_t F = 2 * m->size;
    om_target tf = {F, F, 2 * y0, 2 * rows, m->fdepth + (size_t)2 * y0 * F, NULL};
    r.target = &tf;
    r.user = NULL;
    if (whole_plain || !m->marks) {
        /* every point: the plain depth pass itself */
        om__target_clear(&tf);
        r.mode = OM_RASTER_DEPTH;
        r.span = NULL;
        r.centres = NULL;
        r.centre_mask = NULL;
        r.row_mask = NULL;
    } else {
        /* the points needed (cleared by map_of): the depth pass that runs alongside a
         * conservative one (the same depths), with nothing for the conservative one to
         * do */
        r.span = no_span;
        r.centres = &tf;
        r.centre_mask = m->fneed + (size_t)2 * y0 * m->fwords;
        r.mask_words = m->fwords;
        r.row_mask = m->need_rows;   /* fine rows 2y and 2y + 1 are need's row y */
        r.row_shift = 1;
    }
    raster_scene(m, &r, bins, 2);
}

om_status om__spsm_build(void *state, om_diag *d)
{
    (void)d;
    om__spsm_state *m = (om__spsm_state *)state;
    const om_mat4 *vp;
    uint32_t counts[8] = {0};
    om__spsm_build_rows(m, 0, NULL, 0, om__spsm_map_of(m, 0, &vp), counts);
    return OM_OK;
}
