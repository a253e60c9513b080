/* sm.c — the conventional shadow map, the baseline every chart is drawn against.
 *
 * Build: the scene's depth from the light with the engine's rasterizer (depth format of
 * raster.h: z/w * 2^32 as uint32, sampled at texel centres). Lookup: a sample, moved
 * along its normal by `normal_offset` texels, is shadowed in a texel when its light
 * depth minus the bias is beyond the stored depth; the bias rules and PCF live in
 * smlookup.c, shared with the RTW map. */
#include "../method.h"
#include "../common/smlookup.h"

/* sm's configuration: what its settings (at the end of this file) set. */
typedef struct sm_cfg {
    uint32_t map_size;
    float bias_const, bias_slope, normal_offset;
    uint32_t pcf;
} sm_cfg;
OM__CFG_FITS(sm_cfg);

extern const om_method om__method_sm;

typedef struct sm_state {
    om__state_head head;   /* first (method.h) */
    const om_scene *scene;
    sm_cfg cfg;
    uint32_t size;
    uint32_t *depth;
    om__vsnap *verts;      /* each vertex on the map's grid, once a frame; NULL: no room */
    uint32_t *hiz;         /* the map's coarse depth (om__hiz_words); NULL: no room */
    om_view view;
    om__smlook look;       /* the biased depth test, shared with rtw (smlookup.c) */
    uint32_t samples, shadowed;
} sm_state;

static size_t sm_need(const sm_cfg *c)
{
    return om_arena_need(sizeof(sm_state), 16) +
           om_arena_need((size_t)c->map_size * c->map_size * sizeof(uint32_t), 16);
}

static size_t sm_hiz_bytes(const sm_cfg *c)
{
    return om_arena_need(om__hiz_words(c->map_size, c->map_size) * sizeof(uint32_t), 16);
}

static om_status sm_bytes(const om_method_cfg *mc, const om_scene *s, uint32_t w, uint32_t h,
                          size_t *min, size_t *full)
{
    (void)s; (void)w; (void)h;
    sm_cfg cv;
    const sm_cfg *c = &cv;
    if (om__method_cfg_of(mc, &om__method_sm, &cv, NULL)) return OM_E_INVALID;
    if (c->map_size < 1 || c->map_size > OM_MAX_DIM) return OM_E_INVALID;
    *min = sm_need(c);
    /* the coarse depth bounds the cost of huge triangles; the light pass projects each
     * vertex once */
    *full = *min + sm_hiz_bytes(c) + om__bins_verts_bytes(s);
    return OM_OK;
}

static om_status sm_init(void **state, om_arena *a, const om_method_cfg *mc, const om_scene *s,
                         uint32_t w, uint32_t h, om_diag *d)
{
    (void)w; (void)h;
    om_status st;
    void *p;
    sm_cfg cv;
    const sm_cfg *c = &cv;
    if ((st = om__method_cfg_of(mc, &om__method_sm, &cv, d))) return st;
    if (c->map_size < 1 || c->map_size > OM_MAX_DIM)
        return om__fail(d, OM_E_INVALID, "sm: map size must be 1..8192");
    if (c->pcf < 1 || c->pcf > 9) return om__fail(d, OM_E_INVALID, "sm: pcf must be 1..9");
    if ((st = om__need(a, sm_need(c), "sm", d))) return st;
    if ((st = om_arena_alloc(a, sizeof(sm_state), 16, &p, d))) return st;
    sm_state *m = (sm_state *)p;
    m->scene = s;
    m->cfg = *c;
    m->size = c->map_size;
    if ((st = om_arena_alloc(a, (size_t)m->size * m->size * sizeof(uint32_t), 16, &p, d))) return st;
    m->depth = (uint32_t *)p;
    m->hiz = NULL;
    if (om_arena_left(a) >= sm_hiz_bytes(c) &&
        om_arena_alloc(a, om__hiz_words(m->size, m->size) * sizeof(uint32_t), 16, &p, NULL) == OM_OK)
        m->hiz = (uint32_t *)p;
    m->verts = NULL;
    if (s->nverts && om_arena_left(a) >= om__bins_verts_bytes(s) &&
        om_arena_alloc(a, (size_t)s->nverts * sizeof(om__vsnap), 8, &p, NULL) == OM_OK)
        m->verts = (om__vsnap *)p;
    m->look.depth = m->depth;
    m->look.size = m->size;
    m->look.window = 1.0f;   /* the whole light image */
    m->look.bias_const = c->bias_const;
    m->look.bias_slope = c->bias_slope;
    m->look.normal_offset = c->normal_offset;
    m->look.pcf = c->pcf;
    m->look.warp_x = m->look.warp_y = NULL;
    m->look.warp_n = 0;
    m->look.unwarped_pcf = false;
    *state = m;
    return OM_OK;
}

static om_status sm_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    sm_state *m = (sm_state *)state;
    m->view = *v;
    om__smlook_begin(&m->look, &m->view);
    m->samples = m->shadowed = 0;
    return OM_OK;
}

static om_status sm_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)state; (void)st; (void)d;
    return OM_OK;
}

static void sm_build_rows(const void *state, uint32_t k, const om__bins *bins, uint32_t y0, uint32_t rows,
                          uint32_t counts[8]);

static om_status sm_build(void *state, om_diag *d)
{
    (void)d;
    sm_state *m = (sm_state *)state;
    const om__bins b = {NULL, m->verts, false};
    if (m->verts) om__bins_make(m->scene, &m->view.light_vp, m->view.origin, m->size, m->size, &b);
    uint32_t counts[8] = {0};
    sm_build_rows(state, 0, m->verts ? &b : NULL, 0, m->size, counts);
    return OM_OK;
}

static om_status sm_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    sm_state *m = (sm_state *)state;
    om__smlook_strip(&m->look, st, &m->samples, &m->shadowed);
    return OM_OK;
}

/* Bands: the lookup reads the map and the state; its counts go to the job's. */
static void sm_band(const void *state, om_strip *st, void *scratch, uint32_t counts[8])
{
    (void)scratch;
    om__smlook_strip(&((const sm_state *)state)->look, st, &counts[0], &counts[1]);
}

static void sm_merge(void *state, const uint32_t counts[8])
{
    sm_state *m = (sm_state *)state;
    m->samples += counts[0];
    m->shadowed += counts[1];
}

/* The depth pass by rows of the map: each band a target of its own rows. */
static uint32_t sm_map_of(void *state, uint32_t k, const om_mat4 **vp)
{
    const sm_state *m = (const sm_state *)state;
    if (k > 0) return 0;   /* one map */
    *vp = &m->view.light_vp;
    return m->size;
}

static void sm_build_rows(const void *state, uint32_t k, const om__bins *bins, uint32_t y0, uint32_t rows,
                          uint32_t counts[8])
{
    (void)k;        /* one map */
    (void)counts;   /* the map counts nothing */
    const sm_state *m = (const sm_state *)state;
    om_target tg = {m->size, m->size, y0, rows, m->depth + (size_t)y0 * m->size, NULL};
    om__scene_raster_hiz(m->scene, &m->view.light_vp, m->view.origin, &tg, OM_RASTER_DEPTH, true, bins, m->hiz);
}

const om__bands om__bands_sm = {sm_band, sm_merge, 0, sm_map_of, sm_build_rows, NULL};

static void sm_stats(const void *state, om_method_stats *out)
{
    const sm_state *m = (const sm_state *)state;
    memset(out, 0, sizeof *out);
    out->bytes_used = sm_need(&m->cfg) + (m->hiz ? sm_hiz_bytes(&m->cfg) : 0) +
                      (m->verts ? om__bins_verts_bytes(m->scene) : 0);
    out->counters[0] = m->samples;
    out->counter_names[0] = "samples";
    out->counters[1] = m->shadowed;
    out->counter_names[1] = "samples shadowed";
    out->counters[2] = m->size;
    out->counter_names[2] = "map size";
    out->ncounters = 3;
}

static const om_setting settings[] = {
    OM__SET_MAP(sm_cfg), OM__SET_BIAS(sm_cfg), OM__SET_SLOPE(sm_cfg), OM__SET_OFFSET(sm_cfg),
    OM__SET_PCF(sm_cfg),
};

const om_method om__method_sm = {
    "sm", "conventional shadow map: depth from the light, bias, optional PCF", 0,
    sm_bytes, sm_init, sm_begin, sm_observe, sm_build, sm_resolve, sm_stats, NULL,
    settings, sizeof settings / sizeof settings[0], sizeof(sm_cfg),
    OM__JOBS_ONLY(&om__bands_sm), NULL,
};
