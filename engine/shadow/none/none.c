/* none.c — the method with no occluders: every exposed sample is lit. It is the
 * smallest complete example of the method interface, and the lit rule's (a) and (b)
 * alone (facing the light, inside its frustum) decide its image. */
#include "../method.h"

typedef struct none_state {
    om__state_head head;   /* first (method.h) */
    uint32_t frames;
} none_state;

static om_status none_bytes(const om_method_cfg *c, const om_scene *s, uint32_t w,
                            uint32_t h, size_t *min, size_t *full)
{
    (void)c; (void)s; (void)w; (void)h;
    *min = *full = om_arena_need(sizeof(none_state), 8);
    return OM_OK;
}

static om_status none_init(void **state, om_arena *a, const om_method_cfg *c,
                           const om_scene *s, uint32_t w, uint32_t h, om_diag *d)
{
    (void)c; (void)s; (void)w; (void)h;
    om_status st = om__need(a, om_arena_need(sizeof(none_state), 8), "none", d);
    return st ? st : om_arena_alloc(a, sizeof(none_state), 8, state, d);
}

static om_status none_begin(void *state, const om_view *v, om_diag *d)
{
    (void)v; (void)d;
    ((none_state *)state)->frames++;
    return OM_OK;
}

static om_status none_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)state; (void)st; (void)d;
    return OM_OK;
}

static om_status none_build(void *state, om_diag *d)
{
    (void)state; (void)d;
    return OM_OK;
}

static om_status none_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)state; (void)d;
    size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) st->terms[i].r = st->terms[i].g = st->terms[i].b = 255;
    return OM_OK;
}

/* Bands: the same terms; no counts, no scratch. */
static void none_band(const void *state, om_strip *st, void *scratch, uint32_t counts[8])
{
    (void)scratch; (void)counts;
    (void)state;
    none_resolve(NULL, st, NULL);
}

static void none_merge(void *state, const uint32_t counts[8])
{
    (void)state; (void)counts;
}

const om__bands om__bands_none = {none_band, none_merge, 0, NULL, NULL, NULL};

static void none_stats(const void *state, om_method_stats *out)
{
    memset(out, 0, sizeof *out);
    out->bytes_used = sizeof(none_state);
    out->counters[0] = ((const none_state *)state)->frames;
    out->counter_names[0] = "frames";
    out->ncounters = 1;
}

const om_method om__method_none = {
    "none", "no occluders: every sample facing the light inside its frustum is lit", 0,
    none_bytes, none_init, none_begin, none_observe, none_build, none_resolve, none_stats, NULL,
    NULL, 0, 0,
    OM__JOBS_ONLY(&om__bands_none), NULL,
};
