/* sm.c — the conventional shadow map, the baseline every chart is drawn against.
 *
 * Build: the scene's depth from the light with the engine's rasterizer (depth format of
 * raster.h: z/w * 2^32 as uint32, sampled at texel centres). Lookup: a sample, moved
 * along its normal by `normal_offset` texels, is shadowed in a texel when its light
 * depth minus the bias is beyond the stored depth. The bias is given in world units
 * along the light ray and converted to depth units at the sample:
 *     bias = bias_const + bias_slope * texel * tan(angle between normal and light)
 * (texel = the world size of one texel at the sample; tan clamped at 10), so the
 * slope term is in texels. k x k PCF averages the binary tests; a sample is lit only
 * when every tap is. */
#include "shadow.h"

typedef struct sm_state {
    const om_scene *scene;
    om_method_cfg cfg;
    uint32_t size;
    uint32_t *depth;
    om_view view;
    float span_per_dist;   /* spot: frustum width per unit of distance, 2 tan(fov / 2) */
    uint32_t samples, shadowed;
} sm_state;

static size_t sm_need(const om_method_cfg *c)
{
    return om_arena_need(sizeof(sm_state), 16) +
           om_arena_need((size_t)c->map_size * c->map_size * sizeof(uint32_t), 16);
}

static om_status sm_bytes(const om_method_cfg *c, const om_scene *s, uint32_t w, uint32_t h,
                          size_t *min, size_t *full)
{
    (void)s; (void)w; (void)h;
    if (c->map_size < 1 || c->map_size > OM_MAX_DIM) return OM_E_INVALID;
    *min = *full = sm_need(c);
    return OM_OK;
}

static om_status sm_init(void **state, om_arena *a, const om_method_cfg *c, const om_scene *s,
                         uint32_t w, uint32_t h, om_diag *d)
{
    (void)w; (void)h;
    om_status st;
    void *p;
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
    *state = m;
    return OM_OK;
}

static om_status sm_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    sm_state *m = (sm_state *)state;
    m->view = *v;
    m->span_per_dist = 2.0f * (float)om__tan((double)v->light.fov_deg * OM_PI / 360.0);
    m->samples = m->shadowed = 0;
    return OM_OK;
}

static om_status sm_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)state; (void)st; (void)d;
    return OM_OK;
}

static om_status sm_build(void *state, om_diag *d)
{
    (void)d;
    sm_state *m = (sm_state *)state;
    om_target tg = {m->size, m->size, 0, m->size, m->depth, NULL};
    om__scene_raster(m->scene, &m->view.light_vp, &tg, OM_RASTER_DEPTH);
    return OM_OK;
}

/* World size of one texel at distance `dist` along the light's axis. */
static float texel_world(const sm_state *m, float dist)
{
    const om_view *v = &m->view;
    float span = v->light.kind == OM_LIGHT_SPOT ? dist * m->span_per_dist
                                                : 2.0f / fabsf(v->light_proj.m[0]);
    return span / (float)m->size;
}

static void lookup(sm_state *m, const om_sample *smp, om_term *t)
{
    const om_view *v = &m->view;
    om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]);
    om_vec3 n = om__v3(smp->n[0], smp->n[1], smp->n[2]);
    if (om__dot(n, om__sub(v->cam.eye, p)) < 0.0f) n = om__scale(n, -1.0f);
    om_vec3 l = om__to_light(v, p);
    float dist = v->light.kind == OM_LIGHT_SPOT ? om__dot(om__sub(p, v->light.pos), v->light_axis) : 1.0f;
    float texel = texel_world(m, dist);
    float cosang = om__dot(n, l);
    float tanang = cosang > 0.0995f ? sqrtf(1.0f - cosang * cosang) / cosang : 10.0f;
    float bias = m->cfg.bias_const + m->cfg.bias_slope * texel * tanang;
    p = om__add(p, om__scale(n, m->cfg.normal_offset * texel));
    om_vec4 q = om__mat_apply(&v->light_vp, p);
    if (!(q.w > 0.0f)) return;
    double iw = 1.0 / (double)q.w;
    double u = ((double)q.x * iw + 1.0) * 0.5 * m->size, w = (1.0 - (double)q.y * iw) * 0.5 * m->size;
    double z = (double)q.z * iw * 4294967296.0;
    /* bias from world units to depth units: d(z/w)/d(distance) at this sample */
    double dz;
    if (v->light.kind == OM_LIGHT_SPOT) {
        double f = v->light.zfar, nn = v->light.znear, e = dist > nn * 0.5f ? dist : nn * 0.5;
        dz = f * nn / ((f - nn) * e * e) * 4294967296.0;
    } else {
        dz = 4294967296.0 * fabs((double)v->light_proj.m[10]);
    }
    z -= (double)bias * dz;
    int k = (int)m->cfg.pcf, half = k / 2, lit = 0;
    int64_t cx = (int64_t)floor(u), cy = (int64_t)floor(w);
    for (int dy = -half; dy < k - half; dy++)
        for (int dx = -half; dx < k - half; dx++) {
            int64_t x = cx + dx, y = cy + dy;
            if (x < 0) x = 0;
            if (y < 0) y = 0;
            if (x >= m->size) x = m->size - 1;
            if (y >= m->size) y = m->size - 1;
            lit += z <= (double)m->depth[(size_t)y * m->size + (size_t)x];
        }
    uint8_t val = (uint8_t)((255 * lit + k * k / 2) / (k * k));
    if (lit < k * k && val == 255) val = 254;   /* partly shadowed is never "lit" */
    t->r = t->g = t->b = val;
}

static om_status sm_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    sm_state *m = (sm_state *)state;
    size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        if (!(t->flags & OM_TERM_EXPOSED)) continue;
        m->samples++;
        lookup(m, &st->samples[i], t);
        if (t->r != 255) m->shadowed++;
    }
    return OM_OK;
}

static void sm_stats(const void *state, om_method_stats *out)
{
    const sm_state *m = (const sm_state *)state;
    memset(out, 0, sizeof *out);
    out->bytes_used = sm_need(&m->cfg);
    out->counters[0] = m->samples;
    out->counter_names[0] = "samples";
    out->counters[1] = m->shadowed;
    out->counter_names[1] = "samples shadowed";
    out->counters[2] = m->size;
    out->counter_names[2] = "map size";
    out->ncounters = 3;
}

const om_method om__method_sm = {
    "sm", "conventional shadow map: depth from the light, bias, optional PCF", 0,
    sm_bytes, sm_init, sm_begin, sm_observe, sm_build, sm_resolve, sm_stats,
};
