/* spsm.c — Sub-Pixel Shadow Maps (paper 004, Lecocq et al., i3D 2014): a shadow map
 * whose texels keep a 128-bit record of the nearest triangle, so shadow edges are
 * rebuilt below texel size. The texel format, the derivative code and the tangent
 * table are in spsm_texel.c (spsm_texel.h), the recovered outline in spsm_outline.c
 * (spsm_lookup.h), the build in spsm_build.c (spsm.h: the state); this file
 * owns the method's settings and lookup, spsm_observe.c its observe.
 *
 * Observe (not in the paper; spsm.records, by default when the map is finer than the
 * image): each exposed sample marks its texel. The lookup reads the records of the
 * 3x3 around a sample's texel and no others, so the build writes only those (the
 * marks grown by one texel); a record nobody reads is not made. The frames are the
 * same as with every record made; the build's work follows the view's needs.
 *
 * Build (section 3.2): spsm_build.c, the conservative rasterization and the records.
 *
 * Lookup (section 4): each exposed sample is projected with the light's matrix, as the
 * conventional map does, onto the sub-texel grid. Then
 *  - lit when the stored triangle covers it in 2-D and its plane, reconstructed from
 *    the centre depth and the derivatives (Equation 1), passes through the sample;
 *  - shadowed when the stored triangle or one in the 3x3 neighbourhood covers it and
 *    is nearer (Algorithm 1);
 *  - otherwise uncertain: the silhouette is recovered (section 4.2) from the 3x3
 *    pattern of consistent depth tests (Figure 9), pruned by the pattern table
 *    (Figures 7 and 8), and the outline of the occluders it keeps (Figure 10; our
 *    outline is a hull: spsm_outline.c); with spsm.aa = K > 1, K positions in
 *    the eye pixel are tested against the same outline (section 5). When every texel
 *    around holds an occluder there is no outline to find, and the plain map's test at
 *    the texel centre decides (the paper assumes shadow there). A point the outline
 *    leaves lit is still shadowed when the plain map finds an occluder at all four
 *    texel centres around it, or with spsm.fine at all four points of the twice finer
 *    map around it (plain_shadow: not in the paper).
 * The depth tolerance is what the record cannot resolve: half a 16-bit depth step for
 * rounding, one step of margin, and the derivative code's error bound times the
 * distance from the texel centre. No bias setting is used. */
#include "spsm.h"

OM__CFG_FITS(om__spsm_cfg);
extern const om_method om__method_spsm;

#define LIT_CAP (64.0 * OM__SPSM_STEP)    /* a plane known this loosely proves nothing lit */
#define PAT_CAP (16.0 * OM__SPSM_STEP)    /* the pattern's tests use at most this much slack */

static bool size_ok(const om__spsm_cfg *c) { return c->map_size >= 1 && c->map_size <= OM_MAX_DIM; }

static uint32_t row_words(uint32_t size) { return (size + 31) / 32; }

static size_t spsm_need(const om__spsm_cfg *c)
{
    size_t n = (size_t)c->map_size * c->map_size, bits = (size_t)c->map_size * row_words(c->map_size);
    size_t fbits = (size_t)2 * c->map_size * row_words(2 * c->map_size);
    size_t fine = c->spsm_fine ? om_arena_need(4 * n * sizeof(uint32_t), 16) +
                                     om_arena_need(fbits * sizeof(uint32_t), 16) : 0;
    return om_arena_need(sizeof(om__spsm_state), 16) + om_arena_need(n * sizeof(om__spsm_texel), 16) +
           om_arena_need(n * sizeof(uint32_t), 16) * 2 + om_arena_need(bits * sizeof(uint32_t), 16) * 2 +
           om_arena_need(row_words(c->map_size) * sizeof(uint32_t), 16) + fine;
}

static size_t map_bytes(const om__spsm_state *m)
{
    return (size_t)m->size * m->size * (sizeof(om__spsm_texel) + (m->fine ? 6 : 2) * sizeof(uint32_t)) +
           ((size_t)m->size * m->words * 2 + m->words + (m->fine ? (size_t)2 * m->size * m->fwords : 0)) * sizeof(uint32_t);
}

static om_status spsm_bytes(const om_method_cfg *mc, const om_scene *s, uint32_t w, uint32_t h,
                            size_t *min, size_t *full)
{
    (void)s; (void)w; (void)h;
    om__spsm_cfg c;
    if (om__method_cfg_of(mc, &om__method_spsm, &c, NULL) || !size_ok(&c)) return OM_E_INVALID;
    *min = *full = spsm_need(&c);
    return OM_OK;
}

static om_status spsm_init(void **state, om_arena *a, const om_method_cfg *mc, const om_scene *s,
                           uint32_t w, uint32_t h, om_diag *d)
{
    om_status st;
    void *p;
    om__spsm_cfg cv;
    const om__spsm_cfg *c = &cv;
    if ((st = om__method_cfg_of(mc, &om__method_spsm, &cv, d))) return st;
    if (!size_ok(c)) return om__fail(d, OM_E_INVALID, "spsm: map size must be 1..8192");
    if (c->spsm_aa > 64) return om__fail(d, OM_E_INVALID, "spsm: aa must be 0..64");
    if (c->spsm_records > 2) return om__fail(d, OM_E_INVALID, "spsm: records must be 0 (auto), 1 (all) or 2 (read)");
    if (c->spsm_fine > 1) return om__fail(d, OM_E_INVALID, "spsm: fine must be 0 (off) or 1 (on)");
    if ((st = om__need(a, spsm_need(c), "spsm", d))) return st;
    if ((st = om_arena_alloc(a, sizeof(om__spsm_state), 16, &p, d))) return st;
    om__spsm_state *m = (om__spsm_state *)p;
    m->scene = s;
    m->cfg = *c;
    m->size = c->map_size;
    size_t n = (size_t)m->size * m->size;
    if ((st = om_arena_alloc(a, n * sizeof(om__spsm_texel), 16, &p, d))) return st;
    m->tex = (om__spsm_texel *)p;
    if ((st = om_arena_alloc(a, n * sizeof(uint32_t), 16, &p, d))) return st;
    m->depth = (uint32_t *)p;
    if ((st = om_arena_alloc(a, n * sizeof(uint32_t), 16, &p, d))) return st;
    m->cdepth = (uint32_t *)p;
    m->words = row_words(m->size);
    m->fine = c->spsm_fine == 1;
    m->fwords = row_words(2 * m->size);
    m->fdepth = m->fneed = NULL;
    /* Marking costs a projection per sample and saves the build a texel's work where
     * no sample reads: it pays only when the map is finer than the image, where most
     * texels go unread. */
    m->marks = c->spsm_records == 2 ||
               (c->spsm_records == 0 && (uint64_t)m->size * m->size > 2u * (uint64_t)w * h);
    const size_t bits = (size_t)m->size * m->words;
    if ((st = om_arena_alloc(a, bits * sizeof(uint32_t), 16, &p, d))) return st;
    m->seen = (uint32_t *)p;
    if ((st = om_arena_alloc(a, bits * sizeof(uint32_t), 16, &p, d))) return st;
    m->need = (uint32_t *)p;
    if ((st = om_arena_alloc(a, m->words * sizeof(uint32_t), 16, &p, d))) return st;
    m->need_rows = (uint32_t *)p;
    if (m->fine) {
        if ((st = om_arena_alloc(a, 4 * n * sizeof(uint32_t), 16, &p, d))) return st;
        m->fdepth = (uint32_t *)p;
        if ((st = om_arena_alloc(a, (size_t)2 * m->size * m->fwords * sizeof(uint32_t), 16, &p, d))) return st;
        m->fneed = (uint32_t *)p;
    }
    om__spsm_win_reset(&m->win);
#if OM_WITH_JOBS
    om__lent_take(&m->lent, NULL);
#endif
    om__spsm_qtable_build(&m->q);
    om__spsm_tangent_build(m->lut);
    *state = m;
    return OM_OK;
}

static om_status spsm_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    om__spsm_state *m = (om__spsm_state *)state;
    m->view = *v;
    m->samples = m->lit = m->shadowed = m->uncertain = m->recovered = m->needed = 0;
    if (m->marks) memset(m->seen, 0, (size_t)m->size * m->words * sizeof(uint32_t));
    return OM_OK;
}

/* A sample on the map: grid position, depth (zi; zf rounded to float for the float
 * tests, the double tests convert zi when they run), clip-space point q. */
typedef struct sample_pt { int64_t x, y; uint32_t zi; float zf; bool ok; om_vec4 q; } sample_pt;

/* om__project's position and depth. */
static sample_pt project(const om__spsm_state *m, om_vec3 p)
{
    sample_pt s;
    s.q = om__mat_apply(&m->view.light_vp, p);
    s.zi = 0;
    s.ok = om__project(&s.q, m->size, m->size, &s.x, &s.y, &s.zi);
    s.zf = (float)s.zi;
    return s;
}

/* floor(a / 2^bits), without a division and without shifting a negative number
 * (implementation-defined in C). */
static int32_t floor_shift(int32_t a, int bits)
{
    return a >= 0 ? a >> bits : -((((int32_t)1 << bits) - 1 - a) >> bits);
}

static om_status spsm_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)d;
    om__spsm_observe((om__spsm_state *)state, st);
    return OM_OK;
}

/* ---------------------------------------------------------------- lookup (4) */

/* The lookup's counts (om__bands' counts[8]), added to the state's after a strip. */
enum { N_SAMPLES, N_LIT, N_SHADOWED, N_UNCERTAIN, N_RECOVERED };

/* Decodes texel k of the 3x3 (k = (dy + 1) * 3 + dx + 1) into t[k]: its vertices and
 * plane; the edges are set up when a test first needs them (edges). */
static void decode(const om__spsm_state *m, int64_t tx, int64_t ty, om__spsm_dtri t[9], int k)
{
    const int dx = k % 3 - 1, dy = k / 3 - 1;
    om__spsm_dtri *o = &t[k];
    int64_t x = tx + dx, y = ty + dy;
    o->empty = true;
    o->ok = false;
    if (x < 0 || y < 0 || x >= (int64_t)m->size || y >= (int64_t)m->size) return;
    size_t at = (size_t)y * m->size + (size_t)x;
    if (m->depth[at] == 0xFFFFFFFFu) return;
    const om__spsm_texel *r = &m->tex[at];
    o->empty = false;
    o->cx = (int64_t)dx * OM_SUBPIX;
    o->cy = (int64_t)dy * OM_SUBPIX;
    int64_t X[3], Y[3];
    for (int i = 0; i < 3; i++) {
        X[i] = o->cx + om__spsm_o16_decode(r->vx[i]);
        Y[i] = o->cy + om__spsm_o16_decode(r->vy[i]);
    }
    om__spsm_copy3(o->rx, X);
    om__spsm_copy3(o->ry, Y);
    /* the edge setup waits until a test needs it (edges); whether there is a triangle
     * at all is its area, as the setup finds it (offsets stay far inside its range) */
    o->ok = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]) != 0;
    o->have_e = false;
    /* the plane in float (a 16-bit depth times 2^16 is exact in float); in double only
     * when a test needs it (dtri_double) */
    o->qx = r->qx;
    o->qy = r->qy;
    o->have_d = false;
    o->zf = (float)r->z * (float)OM__SPSM_STEP;
    o->gxf = m->q.decf[r->qx];
    o->gyf = m->q.decf[r->qy];
    o->exf = m->q.errf[r->qx];
    o->eyf = m->q.errf[r->qy];
    o->have_cmin = false;
    o->have_vz = false;
}

/* The decoded plane in double, for the double tests (those float is not sure of, or
 * all of them where double is not a library routine): the centre depth, the slopes and
 * their bounds as decoded from the codes. */
static void dtri_double(const om__spsm_state *m, om__spsm_dtri *o)
{
    if (o->have_d) return;
    const double u = OM__SPSM_STEP * OM_SPSM_DSCALE / (double)OM_SUBPIX;   /* code -> raw per unit */
    o->z = (double)o->zf;   /* exact */
    o->gx = m->q.dec[o->qx] * u;
    o->gy = m->q.dec[o->qy] * u;
    o->ex = m->q.err[o->qx] * u;
    o->ey = m->q.err[o->qy] * u;
    o->have_d = true;
}

/* The sample's texel stepped to a neighbour, (dx, dy) texels away: the decoded texels
 * the old and the new 3x3 share are kept, moved to their new places (in an order that
 * reads each before it is overwritten) and made relative to the new centre. The shift
 * is exact: vertices and centre move by whole texels and each edge constant by the
 * matching integer, so an entry is what decoding it anew gives, with its plane values
 * at the vertices and its consistent minimum (found in the texel's own coordinates). */
/* *to = *from, but for the parts set up only on demand (the edges, the plane at the
 * vertices) when they are not: most entries never need them, and the window moves
 * at almost every texel step. Every field of om__spsm_dtri is here. */
static void move_entry(om__spsm_dtri *to, const om__spsm_dtri *from)
{
    to->empty = from->empty;
    to->ok = from->ok;
    to->have_e = from->have_e;
    if (from->have_e) to->e = from->e;
    om__spsm_copy3(to->rx, from->rx);
    om__spsm_copy3(to->ry, from->ry);
    to->cx = from->cx;
    to->cy = from->cy;
    to->have_d = from->have_d;
    if (from->have_d) {
        to->z = from->z;
        to->gx = from->gx;
        to->gy = from->gy;
        to->ex = from->ex;
        to->ey = from->ey;
    }
    to->qx = from->qx;
    to->qy = from->qy;
    to->zf = from->zf;
    to->gxf = from->gxf;
    to->gyf = from->gyf;
    to->exf = from->exf;
    to->eyf = from->eyf;
    to->cmin = from->cmin;
    to->have_cmin = from->have_cmin;
    to->cminf = from->cminf;
    to->have_vz = from->have_vz;
    if (from->have_vz) {
        for (int i = 0; i < 3; i++) {
            to->vzf[i] = from->vzf[i];
            to->vtolf[i] = from->vtolf[i];
        }
    }
}

static void shift_window(om__spsm_win *w, int dx, int dy)
{
    const int64_t sx = -(int64_t)dx * OM_SUBPIX, sy = -(int64_t)dy * OM_SUBPIX;
    uint32_t have = 0;
    for (int rr = 0; rr < 3; rr++) {
        const int r = dy >= 0 ? rr : 2 - rr, orow = r + dy;
        for (int cc = 0; cc < 3; cc++) {
            const int c = dx >= 0 ? cc : 2 - cc, ocol = c + dx;
            if (orow < 0 || orow > 2 || ocol < 0 || ocol > 2) continue;
            const int from = orow * 3 + ocol, to = r * 3 + c;
            if (!((w->t_have >> from) & 1u)) continue;
            om__spsm_dtri *t = &w->t[to];
            if (to != from) move_entry(t, &w->t[from]);
            t->cx += sx;
            t->cy += sy;
            for (int i = 0; i < 3; i++) {
                t->rx[i] += sx;
                t->ry[i] += sy;
                if (!t->have_e) continue;
                t->e.x[i] += sx;
                t->e.y[i] += sy;
                t->e.c[i] -= t->e.a[i] * sx + t->e.b[i] * sy;
            }
            have |= 1u << to;
        }
    }
    w->t_have = have;
}

/* The entry's edge functions, set up on first use. Neighbours often hold the same
 * triangle: its setup is then copied from another entry of the 3x3 with the very same
 * vertices. (That entry may be left from an earlier 3x3; the setup is a function of
 * the vertices alone, so a match there is as good.) */
static const om__tri2 *edges(om__spsm_dtri t[9], int k)
{
    om__spsm_dtri *o = &t[k];
    if (o->have_e) return &o->e;
    int same = -1;
    for (int j = 0; j < 9 && same < 0; j++)
        if (j != k && t[j].have_e && !t[j].empty && t[j].rx[0] == o->rx[0] && t[j].ry[0] == o->ry[0] &&
            om__spsm_same3(t[j].rx, o->rx) && om__spsm_same3(t[j].ry, o->ry))
            same = j;
    if (same >= 0) o->e = t[same].e;
    else om__tri2_setup(&o->e, o->rx, o->ry, false);
    o->have_e = true;
    return &o->e;
}

/* The slack of the pattern's tests (4.2): they only orient the silhouette, so a plane
 * known loosely (a nearly edge-on triangle) is used at its decoded slope. */
static double pat_tol(const om__spsm_dtri *t, int64_t px, int64_t py)
{
    const double tol = om__spsm_tol_at(t, px, py);   /* finite: fmin's NaN rule is not needed */
    return tol < OM__SPSM_TOL0 + PAT_CAP ? tol : OM__SPSM_TOL0 + PAT_CAP;
}

/* Algorithm 1's depth half: the stored plane is nearer than the sample at (px, py).
 * The float plane there is left in *f (where OM_FAST_FLOAT), for recovery's test. */
static bool nearer(const om__spsm_state *m, om__spsm_dtri *t, int64_t px, int64_t py, uint32_t pz, float pzf,
                   om__spsm_pf *f)
{
    int below = -1;
    if (OM_FAST_FLOAT) {
        om__spsm_pf_at(f, t, px, py, pzf);
        below = om__spsm_pf_below(f, pzf, -1.0f, 0.0f);
    }
    if (below >= 0) return below == 1;
    dtri_double(m, t);
    return om__spsm_plane_at(t, px, py) < (double)pz - om__spsm_tol_at(t, px, py);
}

/* Algorithm 1 at texel k of the 3x3: its stored triangle covers the point in 2-D and is
 * nearer there. The depth first: most neighbours lie in the sample's own surface, and
 * their edges are then not set up. */
static bool hits(const om__spsm_state *m, om__spsm_dtri t[9], int k, int64_t px, int64_t py, uint32_t pz, float pzf,
                 om__spsm_pf *f)
{
    return t[k].ok && nearer(m, &t[k], px, py, pz, pzf, f) && om__spsm_covers(edges(t, k), px, py);
}

/* Figure 9: the least depth the triangle reaches inside its texel's square, found where
 * the paper finds it — at the square's corner that the slopes point to, when the
 * triangle covers it; otherwise on the triangle's part of the square, whose least depth
 * is at one of its corners, so we clip the triangle to the square. HUGE_VAL when the
 * (quantized) triangle misses the square. Its edges are set up (edges). */
static double consistent_min(const om__spsm_dtri *t)
{
    const int64_t H = OM_SUBPIX / 2;
    const float h = (float)H;
    /* (the float slopes have the double ones' signs) */
    int64_t kx = t->cx + (t->gxf > 0.0f ? -H : H), ky = t->cy + (t->gyf > 0.0f ? -H : H);
    /* the plane at the corner: its least over the square */
    if (om__spsm_covers(&t->e, kx, ky)) return t->zf - (om__fabsf(t->gxf) + om__fabsf(t->gyf)) * h;
    /* in the texel's own coordinates (from the square's corner), so that the value does
     * not depend on where the 3x3 is centred (shift_window keeps it); in float, the
     * plane from the centre over offsets of at most half a texel */
    float best = HUGE_VALF;
    for (int i = 0; i < 3; i++) {
        const int j = i == 2 ? 0 : i + 1;
        const float ax = om__spsm_off_f(t->e.x[i] - t->cx + H), ay = om__spsm_off_f(t->e.y[i] - t->cy + H);
        const float dx = om__spsm_off_f(t->e.x[j] - t->e.x[i]), dy = om__spsm_off_f(t->e.y[j] - t->e.y[i]);
        float t0, t1;
        if (!om__spsm_clip_f(ax, ay, dx, dy, (float)OM_SUBPIX, &t0, &t1)) continue;
        const float u = t->gxf * dx + t->gyf * dy < 0.0f ? t1 : t0;
        const float z = t->zf + t->gxf * (ax + u * dx - h) + t->gyf * (ay + u * dy - h);
        if (z < best) best = z;
    }
    return best;
}

/* The sample's own surface as a plane in light space: depth (raw) at grid offset
 * (dx, dy) from the sample is z + gx dx + gy dy (z/w is affine on a plane). The slopes
 * come from the derivatives of the projection along two directions in the surface (from
 * the geometric normal), in float: a light-space point q = M p moves by d = M t along a
 * direction t, and its projection by (d q.w - q d.w) / q.w^2 in each of x/w, y/w and
 * z/w. The common factor 1 / q.w^2 cancels in the 2x2 solve, so no division is taken
 * before it. Float, the same bits on every CPU: the slopes' relative error (about 2^-20
 * but where the surface is nearly edge-on to the light) moves a depth carried a few
 * texels by far less than the tolerance the tests below use (OM__SPSM_TOL0); the depth
 * at the sample is its own projection's (the lookup's). Every test that carries it
 * (behind_receiver, centre_test, plain_shadow) is in float too. */
typedef struct receiver { float zf, gxf, gyf; bool ok; } receiver;

/* The light's matrix applied to the two directions, a function of the normal alone:
 * kept in the window (w->rd) for the normal w->rn, since neighbouring uncertain samples
 * mostly lie on one flat surface (nearly all have the normal of the one before). Equal
 * values suffice, though the two halves of a floor quad give its normal 0 and -0:
 * +, - and * give equal values from equal values (a zero's sign moves only a zero's),
 * the one division's quotients (by det) are replaced by 0 where det is zero, and the
 * plane meets the tests only through +, -, * and comparisons. */
static void surface_dirs(const om__spsm_state *m, om__spsm_win *w, const float nv[3])
{
    if (w->rd_have && nv[0] == w->rn[0] && nv[1] == w->rn[1] && nv[2] == w->rn[2]) return;
    const float *M = m->view.light_vp.m;
    const float n0 = nv[0], n1 = nv[1], n2 = nv[2];
    /* t1 = n x (an axis away from n), t2 = n x t1: both in the surface, not parallel */
    float t[2][3];
    if (om__fabsf(n0) < 0.5f) { t[0][0] = 0.0f; t[0][1] = n2; t[0][2] = -n1; }
    else { t[0][0] = -n2; t[0][1] = 0.0f; t[0][2] = n0; }
    t[1][0] = n1 * t[0][2] - n2 * t[0][1];
    t[1][1] = n2 * t[0][0] - n0 * t[0][2];
    t[1][2] = n0 * t[0][1] - n1 * t[0][0];
    for (int k = 0; k < 2; k++)
        for (int i = 0; i < 4; i++) w->rd[k][i] = M[i * 4] * t[k][0] + M[i * 4 + 1] * t[k][1] + M[i * 4 + 2] * t[k][2];
    for (int i = 0; i < 3; i++) w->rn[i] = nv[i];
    w->rd_have = true;
}

static receiver receiver_plane(const om__spsm_state *m, om__spsm_win *w, const om_sample *smp, const sample_pt *p)
{
    receiver r;
    surface_dirs(m, w, smp->n);
    const om_vec4 q = p->q;
    float u[2][3];   /* (x/w, y/w, z/w) moved along t[k], times q.w^2 */
    for (int k = 0; k < 2; k++) {
        const float *d = w->rd[k];
        u[k][0] = d[0] * q.w - q.x * d[3];
        u[k][1] = d[1] * q.w - q.y * d[3];
        u[k][2] = d[2] * q.w - q.z * d[3];
    }
    /* slopes of z/w against x/w and y/w: sx u[k][0] + sy u[k][1] = u[k][2] for both k */
    const float det = u[0][0] * u[1][1] - u[0][1] * u[1][0];
    const float sx = (u[0][2] * u[1][1] - u[1][2] * u[0][1]) / det, sy = (u[0][0] * u[1][2] - u[1][0] * u[0][2]) / det;
    /* to raw depth per grid unit: x/w = -1..1 is 2 half grid units, y runs down */
    const float k = OM_DEPTH_ONE_F / ((float)m->size * (float)(OM_SUBPIX / 2));
    r.zf = p->zf;
    r.gxf = sx * k;
    r.gyf = -sy * k;
    r.ok = det != 0.0f && om__fabsf(r.gxf) < 1e30f && om__fabsf(r.gyf) < 1e30f;   /* NaN fails too */
    if (!r.ok) r.gxf = r.gyf = 0.0f;
    return r;
}

/* A stored triangle lying wholly on or behind the sample's own plane (seen from the
 * light) cannot block it: the way to the light leaves on the plane's front side. On a
 * curved receiver its neighbouring triangles are such. */
static bool behind_receiver(om__spsm_dtri *t, const receiver *r, int64_t px, int64_t py)
{
    if (!r->ok) return false;
    if (!t->have_vz) {   /* the texel's own part, the same for every sample */
        const float cap = (float)(OM__SPSM_TOL0 + PAT_CAP);
        for (int i = 0; i < 3; i++) {
            const float tol = om__spsm_tol_at_f(t, t->rx[i], t->ry[i]);
            t->vzf[i] = om__spsm_plane_at_f(t, t->rx[i], t->ry[i]);
            t->vtolf[i] = tol < cap ? tol : cap;   /* pat_tol's */
        }
        t->have_vz = true;
    }
    /* in float (the receiver's plane is: receiver_plane) */
    for (int i = 0; i < 3; i++) {
        const float zr = r->zf + r->gxf * om__spsm_off_f(t->rx[i] - px) + r->gyf * om__spsm_off_f(t->ry[i] - py);
        if (t->vzf[i] < zr - t->vtolf[i]) return false;
    }
    return true;
}

/* The fallback when the pattern holds no silhouette (every texel around is an
 * occluder's): the plain map's answer at the texel centre, with the sample's own plane
 * carried to the centre instead of a slope bias. */
static bool centre_test(const om__spsm_state *m, const receiver *r, int64_t tx, int64_t ty, int64_t px,
                        int64_t py)
{
    uint32_t c = m->cdepth[(size_t)ty * m->size + (size_t)tx];
    if (c == 0xFFFFFFFFu) return false;
    const float z = r->ok ? r->zf - r->gxf * om__spsm_off_f(px) - r->gyf * om__spsm_off_f(py) : r->zf;
    return (float)c < z - (float)OM__SPSM_TOL0;   /* in float, as the plane is */
}

/* The plain map around a point of the pixel at grid offset (qx, qy) from the centre of
 * texel (tx, ty), the sample itself being at (px, py): whether the four points of the
 * map nearest to it all hold something nearer than the sample's plane carried there.
 * The map is `buf`, `side` points a side, one every step = 2^bits grid units (its point
 * i at i step + step / 2): the texel centres (cdepth), or with spsm.fine the points a
 * quarter texel from them (fdepth). The point then lies inside a shadow wider than the
 * map's spacing, whatever outline recovery found: a record keeps one triangle per
 * texel, and across a thin bar or along a finely tessellated rim the 3x3 can miss the
 * triangles that reach the point; the band such a rim leaves lit is as wide as the
 * spacing. */
static bool plain_shadow(const uint32_t *buf, int32_t side, int bits, const receiver *r, int64_t tx,
                         int64_t ty, int64_t px, int64_t py, int64_t qx, int64_t qy)
{
    /* the texel centre, the point and the sample in the map's own grid units; in 32
     * bits: centres lie below 2^22, the lookup's offsets below 2^28 (om__project_xy's
     * positions, below 2^26, less a centre or another position), and a point of the
     * map is read (i, j in range) before its offset is taken */
    const int32_t step = (int32_t)1 << bits, h = step / 2;
    const int32_t ox = (int32_t)tx * OM_SUBPIX + OM_SUBPIX / 2, oy = (int32_t)ty * OM_SUBPIX + OM_SUBPIX / 2;
    const int32_t sx = (int32_t)px, sy = (int32_t)py;
    const int32_t ax = floor_shift(ox + (int32_t)qx - h, bits), ay = floor_shift(oy + (int32_t)qy - h, bits);
    for (int32_t j = ay; j <= ay + 1; j++)
        for (int32_t i = ax; i <= ax + 1; i++) {
            if (i < 0 || j < 0 || i >= side || j >= side) return false;
            const uint32_t c = buf[(size_t)j * (size_t)side + (size_t)i];
            if (c == 0xFFFFFFFFu) return false;
            const float dx = (float)(i * step + h - ox - sx), dy = (float)(j * step + h - oy - sy);
            const float z = r->ok ? r->zf + r->gxf * dx + r->gyf * dy : r->zf;
            if (!((float)c < z - (float)OM__SPSM_TOL0)) return false;   /* in float, as the plane is */
        }
    return true;
}

/* Which of the outline's candidate centres (w->cand) hold something nearer than the
 * sample's own plane carried there: bit c for cand[c]. Sets the receiver plane. */
static uint16_t centres_nearer(const om__spsm_state *m, om__spsm_win *w, receiver *rp, bool *have_rp, const om_sample *smp,
                               const sample_pt *p, int64_t tx, int64_t ty, int64_t px, int64_t py)
{
    uint16_t use = 0;
    for (int c = 0; c < w->ncand; c++) {
        const int k = w->cand_k[c], dx = k % 3 - 1, dy = k / 3 - 1;
        if (!*have_rp) { *rp = receiver_plane(m, w, smp, p); *have_rp = true; }
        if (centre_test(m, rp, tx + dx, ty + dy, px - dx * OM_SUBPIX, py - dy * OM_SUBPIX)) use |= (uint16_t)(1u << c);
    }
    return use;
}

/* World-space steps (for AA) to the next pixel's centre along x and along y, on the
 * sample's own triangle (its plane), by the eye pass's own perspective-correct point:
 * where that pixel shows the same triangle, its sample's point to the bit. From the
 * triangle, not from the neighbouring samples, so the steps are the same in any strip
 * or band (the next row may lie in another). */
static void pixel_steps(const om__spsm_state *m, const om_strip *st, size_t i, om_vec3 *sx, om_vec3 *sy)
{
    const om_sample *s = &st->samples[i];
    const uint32_t x = (uint32_t)(i % st->width), y = st->y0 + (uint32_t)(i / st->width);
    om__persp_tri c;
    om__eye_setup(m->scene, &m->view, s->tri, &c);
    const float kx = 2.0f / (float)st->width, ky = 2.0f / (float)st->height;
    const float fx = ((float)x + 0.5f) * kx - 1.0f, fy = 1.0f - ((float)y + 0.5f) * ky;
    const om_vec3 p = om__v3(s->p[0], s->p[1], s->p[2]);
    *sx = om__sub(om__eye_point(&m->view, &c, ((float)x + 1.5f) * kx - 1.0f, fy), p);
    *sy = om__sub(om__eye_point(&m->view, &c, fx, 1.0f - ((float)y + 1.5f) * ky), p);
}

/* The occluders the pattern `keep` keeps in the 3x3 of texel (tx, ty) (distinct
 * triangles), their outline, and the texel centres that may extend it. Out of line:
 * it runs once per texel and pattern. */
static void occluders_of(const om__spsm_state *m, om__spsm_win *w, om__spsm_dtri t[9], uint16_t keep, int64_t tx, int64_t ty)
{
    w->nocc = 0;
    w->ncand = 0;
    for (int k = 0; k < 9; k++) {
        if (!((keep >> k) & 1u) || !t[k].ok) continue;
        edges(t, k);
        int j = 0;   /* neighbours often hold the same triangle */
        while (j < w->nocc && !(om__spsm_same3(w->occ[j]->e.x, t[k].e.x) && om__spsm_same3(w->occ[j]->e.y, t[k].e.y)))
            j++;
        if (j == w->nocc) {
            w->occ_k[w->nocc] = (uint8_t)k;
            w->occ[w->nocc++] = &t[k];
        }
        /* the texel's centre, when the plain map saw this occluder's surface there
         * but its stored triangle does not reach it */
        const int64_t x = tx + k % 3 - 1, y = ty + k / 3 - 1;
        if (x < 0 || y < 0 || x >= (int64_t)m->size || y >= (int64_t)m->size) continue;
        const uint32_t c = m->cdepth[(size_t)y * m->size + (size_t)x];
        if (c == 0xFFFFFFFFu || om__spsm_covers(&t[k].e, t[k].cx, t[k].cy)) continue;
        /* at its own centre the plane is z and the tolerance OM__SPSM_TOL0 */
        if (om__fabsf(t[k].zf - (float)c) > (float)(OM__SPSM_TOL0 + OM__SPSM_LINK_DZ)) continue;
        w->cand[w->ncand].x = t[k].cx;
        w->cand[w->ncand].y = t[k].cy;
        w->cand[w->ncand].owner = j;
        w->cand_k[w->ncand++] = (uint8_t)k;
    }
    /* one triangle's hull is itself (hits decides there), but its points may be
     * extended */
    if (w->nocc < 2 && !w->ncand) w->bd.nv = w->bd.nh = 0;
    else om__spsm_outline_build(&w->bd, w->occ, w->nocc);
    if (w->nocc < 2) w->bd.nh = 0;
    w->bd_keep = keep;
    w->bx_pts = 0;   /* none built yet (0 is never asked for) */
    w->bd_have = true;
}

/* Whether (qx, qy) lies inside the outline extended by the candidate centres in `use`
 * (built once per set). */
static bool inside_extended(om__spsm_win *w, uint16_t use, int64_t qx, int64_t qy)
{
    if (use != w->bx_pts) {
        om__spsm_outline_pt pts[9];
        int npts = 0;
        for (int c = 0; c < w->ncand; c++)
            if (use >> c & 1u) pts[npts++] = w->cand[c];
        om__spsm_outline_extend(&w->bx, &w->bd, pts, npts);
        w->bx_pts = use;
    }
    return om__spsm_outline_inside(&w->bx, qx, qy);
}

OM_NOINLINE static uint8_t recover(const om__spsm_state *m, om__spsm_win *w, uint32_t n[8], const om_strip *st,
                                   size_t i, const sample_pt *p, int64_t tx, int64_t ty, int64_t px, int64_t py);

/* The whole lookup of one sample; returns the term value (255 lit, 0 shadowed, partial
 * with AA). */
static uint8_t lookup(const om__spsm_state *m, om__spsm_win *w, uint32_t n[8], const om_strip *st, size_t i)
{
    const om_sample *smp = &st->samples[i];
    om_vec3 pw = om__v3(smp->p[0], smp->p[1], smp->p[2]);
    sample_pt p = project(m, pw);
    if (!p.ok) { n[N_LIT]++; return 255; }
    const int64_t tx = om__spsm_texel_of(m, p.x), ty = om__spsm_texel_of(m, p.y);
    /* the sample relative to its texel's centre */
    const int64_t ox = tx * OM_SUBPIX + OM_SUBPIX / 2, oy = ty * OM_SUBPIX + OM_SUBPIX / 2;
    const int64_t px = p.x - ox, py = p.y - oy;

    /* 4.1 lit: the sample lies on the stored triangle. Nothing touching the texel was
     * nearer than it over the texel (conservative rasterization and depth; but for a
     * near tie, which is one surface with it). We also accept a stored triangle that
     * does not cover the sample but lies in its plane (the other half of a floor quad):
     * it too was the nearest thing in the texel. That takes many samples out of
     * recovery at no cost in accuracy. */
    om__spsm_dtri *t = w->t;
    size_t at = (size_t)ty * m->size + (size_t)tx;
    if (at != w->t4_at) {
        const int64_t dx = w->t4_at == (size_t)-1 ? 9 : tx - (int64_t)(w->t4_at % m->size),
                      dy = w->t4_at == (size_t)-1 ? 9 : ty - (int64_t)(w->t4_at / m->size);
        if (dx >= -1 && dx <= 1 && dy >= -1 && dy <= 1) shift_window(w, (int)dx, (int)dy);
        else w->t_have = 0;
        if (!(w->t_have & (1u << 4))) { decode(m, tx, ty, t, 4); w->t_have |= 1u << 4; }
        w->t4_at = at;
        w->bd_have = false;
    }
    if (t[4].empty) { n[N_LIT]++; return 255; }
    if (t[4].ok) {
        /* in float where that is sure of the double's answers (om__spsm_below_f), from
         * one float plane at the sample (kept for recovery's test) */
        int below = -1, on = 0, close = 0;
        om__spsm_pf f;
        if (OM_FAST_FLOAT) {
            om__spsm_pf_at(&f, &t[4], px, py, p.zf);
            below = om__spsm_pf_below(&f, p.zf, -1.0f, 0.0f);
            if (below == 0) on = om__spsm_pf_below(&f, p.zf, 1.0f, 0.0f);
            if (on == 1) close = om__spsm_pf_within(&f, (float)(OM__SPSM_TOL0 + LIT_CAP));
        }
        if (below < 0 || on < 0 || close < 0) {
            dtri_double(m, &t[4]);
            const double z = om__spsm_plane_at(&t[4], px, py), tol = om__spsm_tol_at(&t[4], px, py);
            const double pz = p.zi;
            below = z < pz - tol;
            on = z <= pz + tol;
            close = tol <= OM__SPSM_TOL0 + LIT_CAP;
        }
        if (below) {
            if (om__spsm_covers(edges(t, 4), px, py)) { n[N_SHADOWED]++; return 0; }
        } else if (on && close) {
            n[N_LIT]++;
            return 255;
        }
        if (OM_FAST_FLOAT) w->pf[4] = f;
    }
    /* 4.1 shadowed: Algorithm 1 on the 3x3 neighbourhood */
    for (int k = 0; k < 9; k++) {
        if (k == 4) continue;
        if (!((w->t_have >> k) & 1u)) { decode(m, tx, ty, t, k); w->t_have |= 1u << k; }
        if (hits(m, t, k, px, py, p.zi, p.zf, &w->pf[k])) { n[N_SHADOWED]++; return 0; }
    }
    return recover(m, w, n, st, i, &p, tx, ty, px, py);
}

/* 4.2 for an uncertain sample: its term. Out of line: few samples come here, and the
 * decisions above stay small enough to sit in the strip's loop. p is the sample's
 * projection, (tx, ty) its texel, whose 3x3 is decoded in w->t. */
OM_NOINLINE static uint8_t recover(const om__spsm_state *m, om__spsm_win *w, uint32_t n[8], const om_strip *st,
                                   size_t i, const sample_pt *p, int64_t tx, int64_t ty, int64_t px, int64_t py)
{
    const om_sample *smp = &st->samples[i];
    om__spsm_dtri *t = w->t;

    /* 4.2 uncertain: the silhouette from partial geometry. Consistent depth tests give
     * the 3x3 pattern: a texel holds an occluder when its triangle reaches nearer than
     * the sample inside its square (Figure 9) and the sample lies behind its plane. Two
     * guards keep the receiver out of it: its own flat neighbours fail the second test,
     * and a triangle wholly behind the sample's own tangent plane (a curved receiver's
     * neighbours, near its terminator) cannot block the way to the light. */
    n[N_UNCERTAIN]++;
    unsigned pat = 0;
    receiver rp = {0.0f, 0.0f, 0.0f, false};
    bool have_rp = false;
    for (int k = 0; k < 9; k++) {
        /* cheapest test first; the receiver's plane only when a texel needs it */
        if (t[k].empty) continue;
        /* the float plane at the sample is w->pf[k] where the tests above found it (a
         * texel with a triangle) */
        if (OM_FAST_FLOAT && !t[k].ok) om__spsm_pf_at(&w->pf[k], &t[k], px, py, p->zf);
        const int below = OM_FAST_FLOAT ? om__spsm_pf_below(&w->pf[k], p->zf, -1.0f, (float)(OM__SPSM_TOL0 + PAT_CAP)) : -1;
        if (below < 0) dtri_double(m, &t[k]);
        if (below == 0 || (below < 0 && !(om__spsm_plane_at(&t[k], px, py) < (double)p->zi - pat_tol(&t[k], px, py))))
            continue;
        if (!have_rp) { rp = receiver_plane(m, w, smp, p); have_rp = true; }
        if (t[k].ok && behind_receiver(&t[k], &rp, px, py)) continue;
        if (!t[k].have_cmin) {
            edges(t, k);
            t[k].cmin = consistent_min(&t[k]);
            t[k].cminf = (float)t[k].cmin;
            t[k].have_cmin = true;
        }
        /* pat_tol at the texel's centre is OM__SPSM_TOL0: its offsets are 0 and its
         * error bounds finite */
        int in = OM_FAST_FLOAT ? om__spsm_less_f(t[k].cminf, p->zf, 0.0f, 0.0f, 0.0f, 0.0f, (float)OM__SPSM_TOL0) : -1;
        if (in < 0) {
            dtri_double(m, &t[k]);
            in = t[k].cmin < (double)p->zi - pat_tol(&t[k], t[k].cx, t[k].cy);
        }
        if (in) pat |= 1u << k;
    }
    const om__spsm_tangent *tg = &m->lut[pat];
    /* The occluders the pattern keeps and their outline depend on nothing but the texel
     * and `keep`: the next uncertain sample in this texel with the same pattern reuses
     * them. */
    if (!w->bd_have || w->bd_keep != tg->keep) occluders_of(m, w, t, tg->keep, tx, ty);
    const int nocc = w->nocc;
    const om__spsm_boundary *bd = &w->bd;

    /* The decision at one point of the pixel. */
    uint32_t K = m->cfg.spsm_aa > 1 ? m->cfg.spsm_aa : 1, nlit = 0;
    uint16_t use = 0;   /* the candidate centres that join the outline, once asked */
    bool have_use = false;
    om_vec3 sx = om__v3(0, 0, 0), sy = sx;
    if (K > 1) pixel_steps(m, st, i, &sx, &sy);
    for (uint32_t s = 0; s < K; s++) {
        sample_pt q = *p;
        int64_t qx = px, qy = py;
        if (K > 1) {
            /* a fixed stratified pattern in the pixel: rows by index, columns by the
             * golden ratio (no two sub-samples share a row or a column) */
            double a = ((double)s + 0.5) / (double)K - 0.5;
            double g = ((double)s + 0.5) * 0.6180339887498949;
            double b = g - floor(g) - 0.5;
            const om_vec3 pw = om__v3(smp->p[0], smp->p[1], smp->p[2]);
            om_vec3 at = om__add(pw, om__add(om__scale(sx, (float)a), om__scale(sy, (float)b)));
            q = project(m, at);
            if (!q.ok) q = *p;
            qx = px + (q.x - p->x);   /* q relative to the texel's centre, as px is */
            qy = py + (q.y - p->y);
        }
        bool shadow = false;
        /* at the sample itself the lookup found no hit in the whole 3x3 */
        if (K > 1)
            for (int k = 0; k < nocc && !shadow; k++) {
                om__spsm_pf f;   /* another point: not the sample's */
                shadow = hits(m, t, w->occ_k[k], qx, qy, q.zi, q.zf, &f);
            }
        if (!shadow && bd->nh) shadow = om__spsm_outline_inside(bd, qx, qy);
        if (!shadow && w->ncand) {
            if (!have_use) { use = centres_nearer(m, w, &rp, &have_rp, smp, p, tx, ty, px, py); have_use = true; }
            if (use) shadow = inside_extended(w, use, qx, qy);
        }
        if (!shadow && tg->keep == 511) shadow = centre_test(m, &rp, tx, ty, px, py);   /* rp set */
        if (!shadow) {
            if (!have_rp) { rp = receiver_plane(m, w, smp, p); have_rp = true; }
            shadow = m->fine ? plain_shadow(m->fdepth, 2 * (int32_t)m->size, OM_SUBPIX_BITS - 1, &rp, tx, ty, px, py, qx, qy)
                             : plain_shadow(m->cdepth, m->size, OM_SUBPIX_BITS, &rp, tx, ty, px, py, qx, qy);
        }
        nlit += !shadow;
    }
    if (nlit == K) return 255;
    n[N_RECOVERED]++;
    uint8_t v = (uint8_t)((255 * nlit + K / 2) / K);
    return v == 255 ? 254 : v;   /* partly shadowed is never "lit" */
}

/* The terms of the strip's (or band's) rows, with window w; counts in n (N_...). */
static void resolve_rows(const om__spsm_state *m, om__spsm_win *w, om_strip *st, uint32_t n[8])
{
    size_t k = (size_t)st->rows * st->width;
    for (size_t i = 0; i < k; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        n[N_SAMPLES]++;
        t->r = t->g = t->b = lookup(m, w, n, st, i);
    }
}

static void add_counts(om__spsm_state *m, const uint32_t n[8])
{
    m->samples += n[N_SAMPLES];
    m->lit += n[N_LIT];
    m->shadowed += n[N_SHADOWED];
    m->uncertain += n[N_UNCERTAIN];
    m->recovered += n[N_RECOVERED];
}

static om_status spsm_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    om__spsm_state *m = (om__spsm_state *)state;
    uint32_t n[8] = {0};
    resolve_rows(m, &m->win, st, n);
    add_counts(m, n);
    return OM_OK;
}

/* Bands (om__bands): each with a window of its job's, from nothing; the map and the
 * state are only read. The counts are added after the strip. */
static void spsm_band(const void *state, om_strip *st, void *scratch, uint32_t counts[8])
{
    om__spsm_win *w = (om__spsm_win *)scratch;
    om__spsm_win_reset(w);
    resolve_rows((const om__spsm_state *)state, w, st, counts);
}

static void spsm_merge(void *state, const uint32_t counts[8])
{
    add_counts((om__spsm_state *)state, counts);
}

const om__bands om__bands_spsm = {spsm_band, spsm_merge, sizeof(om__spsm_win), om__spsm_map_of,
                                   om__spsm_build_rows, NULL};

static bool spsm_observes(const void *state)
{
    return ((const om__spsm_state *)state)->marks;
}

static void spsm_stats(const void *state, om_method_stats *out)
{
    const om__spsm_state *m = (const om__spsm_state *)state;
    memset(out, 0, sizeof *out);
    out->bytes_used = spsm_need(&m->cfg);
    out->counters[0] = m->samples;
    out->counter_names[0] = "samples";
    out->counters[1] = m->lit;
    out->counter_names[1] = "samples lit";
    out->counters[2] = m->shadowed;
    out->counter_names[2] = "samples shadowed";
    out->counters[3] = m->uncertain;
    out->counter_names[3] = "samples uncertain";
    out->counters[4] = m->recovered;
    out->counter_names[4] = "uncertain, shadowed by recovery";
    out->counters[5] = m->size;
    out->counter_names[5] = "map size";
    out->counters[6] = (uint32_t)(map_bytes(m) > 0xFFFFFFFFu ? 0xFFFFFFFFu : map_bytes(m));
    out->counter_names[6] = "map bytes";
    out->counters[7] = m->needed;
    out->counter_names[7] = "texels needed (records made only there)";
    out->ncounters = 8;
}

#define SET(field, name, lo, hi, doc) OM__SETTING(om__spsm_cfg, field, name, OM_SETTING_U32, lo, hi, 0, doc)

static const om_setting settings[] = {
    OM__SET_MAP(om__spsm_cfg),
    SET(spsm_aa, "spsm.aa", 0, 64, "sub-samples at uncertain samples, 0 = off"),
    SET(spsm_records, "spsm.records", 0, 2, "records made: 1 all, 2 those the view reads, 0 auto"),
    SET(spsm_fine, "spsm.fine", 0, 1, "fallback: 1 the plain map at 2 x 2 points per texel, 0 at centres"),
};

#undef SET

extern const om__pass om__pass_spsm;
const om_method om__method_spsm = {
    "spsm", "sub-pixel shadow map: 128-bit texels with the nearest triangle, silhouette recovery",
    OM_METHOD_OBSERVES, spsm_bytes, spsm_init, spsm_begin, spsm_observe, om__spsm_build, spsm_resolve, spsm_stats,
    spsm_observes, settings, sizeof settings / sizeof settings[0], sizeof(om__spsm_cfg),
    OM__JOBS_ONLY(&om__bands_spsm), OM__JOBS_ONLY(&om__pass_spsm),
};
