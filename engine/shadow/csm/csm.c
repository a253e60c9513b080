/* csm.c — cascaded shadow maps (Engel 2006; the practical splits of Zhang et al.
 * 2006; the fitted mode after Lauritzen et al. 2011's sample distribution shadow
 * maps): 1 to 4 conventional depth maps, each over the window of the light's image
 * that holds one slice of the view's depth (csm_split.c). A sample reads the first
 * cascade whose window holds it, with sm's biased test (smlookup.c) in that map's
 * texels; no blending between cascades, so shadows stay hard.
 *
 * Frame: begin (the depth range the splits share out) -> observe (fitted mode only:
 * the exposed samples' boxes by view depth) -> build (the windows, then each live
 * cascade's map, as sm draws its one, by bands of its rows on the host's threads) ->
 * resolve (by bands). */
#include "csm.h"

extern const om_method om__method_csm;

static size_t map_bytes(const om__csm_cfg *c)
{
    return om_arena_need(om__size_mul(om__size_mul(c->map_size, c->map_size), sizeof(uint32_t)), 16);
}

static size_t hiz_bytes(const om__csm_cfg *c)
{
    return om_arena_need(om__hiz_words(c->map_size, c->map_size) * sizeof(uint32_t), 16);
}

static size_t csm_need(const om__csm_cfg *c)
{
    return om__size_add(om_arena_need(sizeof(om__csm), 16), om__size_mul(c->cascades, map_bytes(c)));
}

/* A configuration's error, or NULL. */
static const char *check_cfg(const om__csm_cfg *c)
{
    if (c->cascades < 1 || c->cascades > OM__CSM_MAX) return "csm: csm.cascades must be 1..4";
    if (c->map_size < 1 || c->map_size > OM_MAX_DIM) return "csm: csm.map must be 1..8192";
    if (!(c->lambda >= 0.0f && c->lambda <= 1.0f)) return "csm: csm.lambda must be 0..1";
    if (c->fit > 1) return "csm: csm.fit must be 0 or 1";
    if (!(c->bias_const >= 0.0f && c->bias_const <= 1.0f)) return "csm: bias must be 0..1";
    if (!(c->bias_slope >= 0.0f && c->bias_slope <= 1e3f)) return "csm: slope must be 0..1000";
    if (!(c->normal_offset >= 0.0f && c->normal_offset <= 1e3f)) return "csm: offset must be 0..1000";
    if (c->pcf < 1 || c->pcf > 9) return "csm: pcf must be 1..9";
    return NULL;
}

static om_status csm_bytes(const om_method_cfg *mc, const om_scene *s, uint32_t w, uint32_t h, size_t *min,
                           size_t *full)
{
    (void)w; (void)h;
    om__csm_cfg c;
    if (om__method_cfg_of(mc, &om__method_csm, &c, NULL) || check_cfg(&c)) return OM_E_INVALID;
    *min = csm_need(&c);
    /* each map's coarse depth, and one vertex cache the maps take in turn */
    *full = om__size_add(om__size_add(*min, om__size_mul(c.cascades, hiz_bytes(&c))), om__bins_verts_bytes(s));
    return OM_OK;
}

static om_status csm_init(void **state, om_arena *a, const om_method_cfg *mc, const om_scene *s, uint32_t w,
                          uint32_t h, om_diag *d)
{
    (void)w; (void)h;
    om_status st;
    void *p;
    om__csm_cfg c;
    if ((st = om__method_cfg_of(mc, &om__method_csm, &c, d))) return st;
    const char *bad = check_cfg(&c);
    if (bad) return om__fail(d, OM_E_INVALID, bad);
    if ((st = om__need(a, csm_need(&c), "csm", d))) return st;
    if ((st = om_arena_alloc(a, sizeof(om__csm), 16, &p, d))) return st;
    om__csm *m = (om__csm *)p;
    memset(m, 0, sizeof *m);
    m->scene = s;
    m->cfg = c;
    m->size = c.map_size;
    m->n = c.cascades;
    const size_t texels = (size_t)m->size * m->size;
    for (uint32_t k = 0; k < m->n; k++) {
        if ((st = om_arena_alloc(a, texels * sizeof(uint32_t), 16, &p, d))) return st;
        m->depth[k] = (uint32_t *)p;
    }
    for (uint32_t k = 0; k < m->n; k++)
        if (om_arena_left(a) >= hiz_bytes(&c) &&
            om_arena_alloc(a, om__hiz_words(m->size, m->size) * sizeof(uint32_t), 16, &p, NULL) == OM_OK)
            m->hiz[k] = (uint32_t *)p;
    if (s->nverts && om_arena_left(a) >= om__bins_verts_bytes(s) &&
        om_arena_alloc(a, (size_t)s->nverts * sizeof(om__vsnap), 8, &p, NULL) == OM_OK)
        m->verts = (om__vsnap *)p;
    for (uint32_t k = 0; k < OM__CSM_MAX; k++) {
        om__smlook *L = &m->look[k];
        L->depth = m->depth[k];
        L->size = m->size;
        L->window = 1.0f;
        L->bias_const = c.bias_const;
        L->bias_slope = c.bias_slope;
        L->normal_offset = c.normal_offset;
        L->pcf = c.pcf;
        L->warp_x = L->warp_y = NULL;
        L->warp_n = 0;
        L->unwarped_pcf = false;
        L->view = &m->cview[k];
    }
    *state = m;
    return OM_OK;
}

static om_status csm_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    om__csm *m = (om__csm *)state;
    m->view = *v;
    om__csm_range(m);
    m->samples = m->shadowed = m->unheld = 0;
    memset(m->held, 0, sizeof m->held);
    return OM_OK;
}

static om_status csm_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)d;
    om__csm *m = (om__csm *)state;
    if (m->cfg.fit) om__csm_observe(m, st);
    return OM_OK;
}

static bool csm_observes(const void *state) { return ((const om__csm *)state)->cfg.fit != 0; }

/* Rows [y0, y0 + rows) of the k-th live cascade's map: a target of its own rows. */
static void csm_build_rows(const void *state, uint32_t k, const om__bins *bins, uint32_t y0, uint32_t rows,
                           uint32_t counts[8])
{
    (void)counts;   /* the maps count nothing */
    const om__csm *m = (const om__csm *)state;
    const uint32_t c = m->live[k];
    om_target tg = {m->size, m->size, y0, rows, m->depth[c] + (size_t)y0 * m->size, NULL};
    om__scene_raster_hiz(m->scene, &m->cview[c].light_vp, m->view.origin, &tg, OM_RASTER_DEPTH, true, bins,
                         m->hiz[c]);
}

/* The k-th live cascade's map (the windows made first): its side and matrix. */
static uint32_t csm_map_of(void *state, uint32_t k, const om_mat4 **vp)
{
    om__csm *m = (om__csm *)state;
    if (!m->ready) om__csm_windows(m);
    if (k >= m->nlive) return 0;
    *vp = &m->cview[m->live[k]].light_vp;
    return m->size;
}

static om_status csm_build(void *state, om_diag *d)
{
    (void)d;
    om__csm *m = (om__csm *)state;
    const om_mat4 *vp;
    uint32_t counts[8] = {0};
    for (uint32_t k = 0; csm_map_of(m, k, &vp); k++) {
        const om__bins b = {NULL, m->verts, false};
        if (m->verts) om__bins_make(m->scene, vp, m->view.origin, m->size, m->size, &b);
        csm_build_rows(m, k, m->verts ? &b : NULL, 0, m->size, counts);
    }
    return OM_OK;
}

/* One tap without a normal offset (the defaults): the sample's projection through
 * the light's matrix, which picks its cascade, gives its texel there too (the
 * window's affine map of it: the same texel as the cascade's matrix gives, up to
 * rounding) and its depth (the windows leave depth alone), so each sample is
 * projected once; the bias and the test are smlookup.h's, with the cascade's texel.
 * What a strip's samples share, copied once a strip (the terms' byte stores may
 * alias anything the state's pointers reach). */
typedef struct plain {
    om_mat4 vp, proj;
    bool spot;
    uint32_t n, size;
    float half, half_near, inv_half_near;
    om__csm_win win[OM__CSM_MAX];
    float c1[OM__CSM_MAX], c2[OM__CSM_MAX];
    const uint32_t *depth[OM__CSM_MAX];
} plain;

/* A sample's biased depth and the texel it reads (false: behind the light, lit);
 * counts it held by its cascade or by none. */
static inline bool plain_locate(const plain *P, const om_sample *smp, float *zb, const uint32_t **tap,
                                uint32_t c8[8])
{
    const om_vec4 q = om__mat_apply(&P->vp, om__v3(smp->p[0], smp->p[1], smp->p[2]));
    if (!(q.w > 0.0f)) return false;
    const float iw = 1.0f / q.w, x = q.x * iw, y = q.y * iw;
    if (!(x == x && y == y)) return false;
    const uint32_t n = P->n;
    uint32_t k = n, last = n;
    for (uint32_t j = 0; j < n; j++) {
        const om__csm_win *w = &P->win[j];
        if (!w->live) continue;
        last = j;
        if (om__fabsf(x - w->cx) <= w->limx && om__fabsf(y - w->cy) <= w->limy) {
            k = j;
            break;
        }
    }
    const bool held = k < n;   /* else the last live one, as om__csm_pick */
    if (!held) k = last;
    if (k == n) return false;
    c8[held ? 2 + k : 6]++;
    const om__csm_win *w = &P->win[k];
    const float uf = ((x - w->cx) * w->ix + 1.0f) * P->half;
    const float wf = (1.0f - (y - w->cy) * w->iy) * P->half;
    *tap = P->depth[k] + om__smlook_texel(wf, P->size) * P->size + om__smlook_texel(uf, P->size);
    const float z = om__smlook_depth(&P->proj, P->spot, q, iw);
    const float r = P->spot ? (q.w > P->half_near ? iw : P->inv_half_near) : 0.0f;
    *zb = om__smlook_biased(P->c1[k], P->c2[k], P->spot, z, r, om__smlook_tan(smp->nl));
    return true;
}

static void lookup_plain(const om__csm *m, om_strip *st, uint32_t c8[8])
{
    plain P;
    P.vp = m->view.light_vp;
    P.proj = m->view.light_proj;
    P.spot = m->view.light.kind == OM_LIGHT_SPOT;
    P.n = m->n;
    P.size = m->size;
    P.half = 0.5f * (float)m->size;
    P.half_near = m->look[0].half_near;
    P.inv_half_near = 1.0f / P.half_near;
    for (uint32_t k = 0; k < m->n; k++) {
        P.win[k] = m->win[k];
        P.c1[k] = m->look[k].bias_c1;
        P.c2[k] = m->look[k].bias_c2;
        P.depth[k] = m->depth[k];
    }
    const size_t count = (size_t)st->rows * st->width;
#if OM_SMLOOK_DIRECT
    /* a microcontroller's loads take a cycle or two: each sample tested at once */
    for (size_t i = 0; i < count; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        c8[0]++;
        float zb;
        const uint32_t *tap;
        if (plain_locate(&P, &st->samples[i], &zb, &tap, c8) && !om__smlook_lit(zb, *tap)) {
            t->r = t->g = t->b = 0;
            c8[1]++;
        }
    }
#else
    /* Blocks, as smlookup.c's: a run of samples located first, each map load asked
     * for at once, then tested, so that the loads overlap. */
    enum { BLOCK = 32 };
    float zb[BLOCK];
    const uint32_t *tap[BLOCK];
    uint32_t idx[BLOCK];
    for (size_t i = 0; i < count;) {
        int got = 0;
        for (; i < count && got < BLOCK; i++) {
            om_term *t = &st->terms[i];
            t->r = t->g = t->b = 255;
            if (!(t->flags & OM_TERM_EXPOSED)) continue;
            c8[0]++;
            if (plain_locate(&P, &st->samples[i], &zb[got], &tap[got], c8)) {
#if defined(__GNUC__) || defined(__clang__)
                __builtin_prefetch(tap[got]);
#endif
                idx[got++] = (uint32_t)i;
            }
        }
        for (int j = 0; j < got; j++)
            if (!om__smlook_lit(zb[j], *tap[j])) {
                om_term *t = &st->terms[idx[j]];
                t->r = t->g = t->b = 0;
                c8[1]++;
            }
    }
#endif
}

/* The terms of a strip: each exposed sample tested in the cascade it picks. counts:
 * [0] exposed samples, [1] shadowed, [2 + c] held by cascade c, [6] held by none. */
static void lookup(const om__csm *m, om_strip *st, uint32_t counts[8])
{
    if (m->cfg.pcf == 1 && m->cfg.normal_offset == 0.0f) {
        uint32_t c8[8] = {0};
        lookup_plain(m, st, c8);
        for (int j = 0; j < 8; j++) counts[j] += c8[j];
        return;
    }
    /* Copies on the stack, once a strip: the terms' byte stores may alias anything the
     * state's pointers reach, so each field would be loaded again per sample. */
    const uint32_t n = m->n;
    const om_mat4 vp = m->view.light_vp;
    om__csm_win win[OM__CSM_MAX];
    om_view cv[OM__CSM_MAX];
    om__smlook L[OM__CSM_MAX];
    for (uint32_t k = 0; k < n; k++) {
        win[k] = m->win[k];
        cv[k] = m->cview[k];
        L[k] = m->look[k];
        L[k].view = &cv[k];
    }
    uint32_t c8[8] = {0};
    const size_t count = (size_t)st->rows * st->width;
    for (size_t i = 0; i < count; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        c8[0]++;
        const om_sample *smp = &st->samples[i];
        bool held;
        const uint32_t k = om__csm_pick(&vp, win, n, om__v3(smp->p[0], smp->p[1], smp->p[2]), &held);
        if (k >= n) continue;   /* behind the light: lit, as sm's lookup leaves it */
        c8[held ? 2 + k : 6]++;
        const uint8_t val = om__smlook_sample(&L[k], smp);
        t->r = t->g = t->b = val;
        c8[1] += val != 255;
    }
    for (int j = 0; j < 8; j++) counts[j] += c8[j];
}

static void csm_merge(void *state, const uint32_t counts[8])
{
    om__csm *m = (om__csm *)state;
    m->samples += counts[0];
    m->shadowed += counts[1];
    for (uint32_t k = 0; k < OM__CSM_MAX; k++) m->held[k] += counts[2 + k];
    m->unheld += counts[6];
}

static om_status csm_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    uint32_t counts[8] = {0};
    lookup((const om__csm *)state, st, counts);
    csm_merge(state, counts);
    return OM_OK;
}

static void csm_band(const void *state, om_strip *st, void *scratch, uint32_t counts[8])
{
    (void)scratch;
    lookup((const om__csm *)state, st, counts);
}

const om__bands om__bands_csm = {csm_band, csm_merge, 0, csm_map_of, csm_build_rows, NULL};

static void csm_stats(const void *state, om_method_stats *out)
{
    const om__csm *m = (const om__csm *)state;
    static const char *const held[OM__CSM_MAX] = {"samples in cascade 1", "samples in cascade 2",
                                                  "samples in cascade 3", "samples in cascade 4"};
    memset(out, 0, sizeof *out);
    size_t bytes = csm_need(&m->cfg);
    for (uint32_t k = 0; k < m->n; k++) bytes += m->hiz[k] ? hiz_bytes(&m->cfg) : 0;
    out->bytes_used = bytes + (m->verts ? om__bins_verts_bytes(m->scene) : 0);
    uint32_t i = 0;
    out->counters[i] = m->samples;
    out->counter_names[i++] = "samples";
    out->counters[i] = m->shadowed;
    out->counter_names[i++] = "samples shadowed";
    out->counters[i] = m->nlive;
    out->counter_names[i++] = "cascades drawn";
    out->counters[i] = m->size;
    out->counter_names[i++] = "map size";
    for (uint32_t k = 0; k < m->n; k++) {
        out->counters[i] = m->held[k];
        out->counter_names[i++] = held[k];
    }
    out->counters[i] = m->unheld;
    out->counter_names[i++] = "samples in no window";
    out->ncounters = i;
}

static const om_setting settings[] = {
    OM__SETTING(om__csm_cfg, cascades, "csm.cascades", OM_SETTING_U32, 1, OM__CSM_MAX, 4,
                "cascades: slices of the view's depth, each with a map of its own"),
    OM__SETTING(om__csm_cfg, map_size, "csm.map", OM_SETTING_U32, 1, OM_MAX_DIM, 1024,
                "side of each cascade's map in texels"),
    OM__SETTING(om__csm_cfg, lambda, "csm.lambda", OM_SETTING_F32, 0, 1, 0.9,
                "practical split: 1 logarithmic, 0 uniform, between a blend (csm.fit 1: logarithmic)"),
    OM__SETTING(om__csm_cfg, fit, "csm.fit", OM_SETTING_U32, 0, 1, 0,
                "1: splits and windows fitted to the visible samples' depths and extent"),
    OM__SET_BIAS(om__csm_cfg), OM__SET_SLOPE(om__csm_cfg), OM__SET_OFFSET(om__csm_cfg), OM__SET_PCF(om__csm_cfg),
};

const om_method om__method_csm = {
    "csm", "cascaded shadow maps: one map a slice of the view's depth, practical or fitted splits",
    OM_METHOD_OBSERVES,
    csm_bytes, csm_init, csm_begin, csm_observe, csm_build, csm_resolve, csm_stats, csm_observes,
    settings, sizeof settings / sizeof settings[0], sizeof(om__csm_cfg),
    OM__JOBS_ONLY(&om__bands_csm), NULL,
};
