/* registry.c — every shadow method by name, the functions a host reads a method
 * through, and settings by name. Adding a method is its own folder plus one line of
 * METHODS; its settings and their defaults live in its files (struct om_method,
 * method.h), so every tool, chart and test finds both through here. */
#include "method.h"

/* One line a method, in the order tools list them: X(name, OM_WITH_NAME) builds it in
 * where its switch is 1 (config.h), so that a firmware may leave it out. */
#define METHODS(X)           \
    X(none, OM_WITH_NONE)    \
    X(ref, OM_WITH_REF)      \
    X(sm, OM_WITH_SM)        \
    X(csm, OM_WITH_CSM)      \
    X(asm, OM_WITH_ASM)      \
    X(rtw, OM_WITH_RTW)      \
    X(spsm, OM_WITH_SPSM)    \
    X(izb, OM_WITH_IZB)      \
    X(hybrid, OM_WITH_HYBRID)

#define DECLARE(m, on) extern const om_method om__method_##m;
METHODS(DECLARE)

/* ENTRY(m, 1) names the method, ENTRY(m, 0) nothing: the switch must be 0 or 1. */
#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
#define ENTRY_1(m) &om__method_##m,
#define ENTRY_0(m)
#define ENTRY(m, on) CAT(ENTRY_, on)(m)

static const om_method *const methods[] = {METHODS(ENTRY) NULL};

size_t om_method_count(void) { return sizeof methods / sizeof methods[0] - 1; }

const om_method *om_method_at(size_t i)
{
    return i < om_method_count() ? methods[i] : NULL;
}

const char *om_method_name(const om_method *m) { return m ? m->name : ""; }
const char *om_method_summary(const om_method *m) { return m ? m->summary : ""; }
unsigned om_method_flags(const om_method *m) { return m ? m->flags : 0u; }
uint32_t om_method_nsettings(const om_method *m) { return m ? m->nsettings : 0u; }

const om_setting *om_method_setting_at(const om_method *m, uint32_t i)
{
    return m && i < m->nsettings ? &m->settings[i] : NULL;
}

om_status om_method_bytes(const om_method *m, const om_method_cfg *c, const om_scene *s, uint32_t width,
                          uint32_t height, size_t *min, size_t *full)
{
    if (!m || !c || !s || !min || !full || !om__side_ok(width, height)) return OM_E_INVALID;
    return m->bytes(c, s, width, height, min, full);
}

om_status om_method_init(const om_method *m, void **state, om_arena *a, const om_method_cfg *c,
                         const om_scene *s, uint32_t width, uint32_t height, om_diag *d)
{
    if (state) *state = NULL;
    if (!m || !state || !a || !c || !s)
        return om__fail(d, OM_E_INVALID, "om_method_init needs a method, a state pointer, an arena, a configuration and a scene");
    if (!om__side_ok(width, height)) return om__fail(d, OM_E_INVALID, "image width and height must be 1..8192");
    om_status st = om__scene_check(s, d);
    if (st != OM_OK) return st;
    st = m->init(state, a, c, s, width, height, d);
    if (st != OM_OK) {
        *state = NULL;
        return st;
    }
    om__state_head *h = (om__state_head *)*state;   /* every state's first member */
    h->method = m;
    h->verts = s->verts;
    h->idx = s->idx;
    h->nverts = s->nverts;
    h->ntris = s->ntris;
    h->width = width;
    h->height = height;
    return OM_OK;
}

bool om__state_for(const void *state, const om_method *m, const om_scene *s, uint32_t width, uint32_t height)
{
    const om__state_head *h = (const om__state_head *)state;
    return h->method == m && h->verts == s->verts && h->idx == s->idx && h->nverts == s->nverts &&
           h->ntris == s->ntris && h->width == width && h->height == height;
}

void om_method_get_stats(const om_method *m, const void *state, om_method_stats *out)
{
    if (!out) return;
    if (!om__state_of(state, m)) {
        memset(out, 0, sizeof *out);
        return;
    }
    m->stats(state, out);
}

static bool same_name(const char *a, const char *b)
{
    while (*a && *a == *b) a++, b++;
    return *a == *b;
}

const om_method *om_method_find(const char *name)
{
    for (size_t i = 0; name && i < om_method_count(); i++)
        if (same_name(methods[i]->name, name)) return methods[i];
    return NULL;
}

const om_setting *om_method_setting(const om_method *m, const char *name)
{
    for (uint32_t i = 0; m && name && i < m->nsettings; i++)
        if (same_name(m->settings[i].name, name)) return &m->settings[i];
    return NULL;
}

static void put(om_method_cfg *c, const om_setting *f, double value)
{
    unsigned char *p = c->store.bytes + f->offset;
    if (f->kind == OM_SETTING_U32) { uint32_t v = (uint32_t)value; memcpy(p, &v, sizeof v); }
    else if (f->kind == OM_SETTING_U64) { uint64_t v = (uint64_t)value; memcpy(p, &v, sizeof v); }
    else { float v = (float)value; memcpy(p, &v, sizeof v); }
}

void om_method_cfg_default(om_method_cfg *c, const om_method *m)
{
    if (!c) return;
    memset(c, 0, sizeof *c);
    c->method = m;
    for (uint32_t i = 0; m && i < m->nsettings; i++) put(c, &m->settings[i], m->settings[i].def);
}

om_status om_method_cfg_set(om_method_cfg *c, const char *name, double value, om_diag *d)
{
    if (!c) return om__fail(d, OM_E_INVALID, "om_method_cfg_set needs a configuration");
    const om_setting *f = om_method_setting(c->method, name);
    char tmp[8];
    if (!f) {
        om__str s = om__diag_begin(d, OM_E_NOTFOUND, tmp, sizeof tmp);
        om__str_s(&s, c->method ? c->method->name : "the configuration of no method");
        om__str_s(&s, " has no setting '");
        om__str_s(&s, name ? name : "");
        om__str_s(&s, "'");
        return OM_E_NOTFOUND;
    }
    const bool whole = f->kind != OM_SETTING_F32;
    if (!(value >= f->min && value <= f->max) || (whole && value != floor(value))) {
        om__str s = om__diag_begin(d, OM_E_RANGE, tmp, sizeof tmp);
        om__str_s(&s, f->name);
        om__str_s(&s, whole ? " takes a whole number from " : " takes a number from ");
        om__str_f(&s, f->min, whole ? 0 : 3);
        om__str_s(&s, " to ");
        om__str_f(&s, f->max, whole ? 0 : 3);
        return OM_E_RANGE;
    }
    put(c, f, value);
    return OM_OK;
}

om_status om_method_cfg_get(const om_method_cfg *c, const char *name, double *value)
{
    if (!c) return OM_E_INVALID;
    const om_setting *f = om_method_setting(c->method, name);
    if (!f) return OM_E_NOTFOUND;
    if (!value) return OM_OK;   /* only whether it has the setting */
    const unsigned char *p = c->store.bytes + f->offset;
    if (f->kind == OM_SETTING_U32) { uint32_t v; memcpy(&v, p, sizeof v); *value = v; }
    else if (f->kind == OM_SETTING_U64) { uint64_t v; memcpy(&v, p, sizeof v); *value = (double)v; }
    else { float v; memcpy(&v, p, sizeof v); *value = v; }
    return OM_OK;
}

void om_method_cfg_from(om_method_cfg *c, const om_method *m, const om_method_cfg *from)
{
    om_method_cfg src;
    if (!c) return;
    if (from) src = *from;
    else om_method_cfg_default(&src, NULL);
    om_method_cfg_default(c, m);
    for (uint32_t i = 0; src.method && i < src.method->nsettings; i++) {
        const om_setting *f = om_method_setting(m, src.method->settings[i].name);
        double v;
        if (f && f->kind == src.method->settings[i].kind &&
            om_method_cfg_get(&src, f->name, &v) == OM_OK)
            put(c, f, v);
    }
}

om_status om__method_cfg_of(const om_method_cfg *c, const om_method *m, void *out, om_diag *d)
{
    if (!c || c->method != m) {
        char tmp[8];
        om__str s = om__diag_begin(d, OM_E_INVALID, tmp, sizeof tmp);
        om__str_s(&s, m->name);
        om__str_s(&s, ": the configuration was made for ");
        om__str_s(&s, c && c->method ? c->method->name : "no method");
        om__str_s(&s, " (om_method_cfg_default)");
        return OM_E_INVALID;
    }
    memcpy(out, c->store.bytes, m->cfg_bytes);
    return OM_OK;
}
