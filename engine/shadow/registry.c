/* registry.c — every shadow method by name, and settings by name. Adding a method is
 * its own file plus one line of METHODS; its settings and their defaults live in its
 * file (om_method.settings), so every tool, chart and test finds both through here. */
#include "shadow.h"

/* Compile-time selection (ombra.h): a method left out is not named below, so the
 * linker takes none of its files from the library. */
#ifndef OM_WITH_NONE
#define OM_WITH_NONE 1
#endif
#ifndef OM_WITH_REF
#define OM_WITH_REF 1
#endif
#ifndef OM_WITH_SM
#define OM_WITH_SM 1
#endif
#ifndef OM_WITH_ASM
#define OM_WITH_ASM 1
#endif
#ifndef OM_WITH_RTW
#define OM_WITH_RTW 1
#endif
#ifndef OM_WITH_SPSM
#define OM_WITH_SPSM 1
#endif
#ifndef OM_WITH_IZB
#define OM_WITH_IZB 1
#endif
#ifndef OM_WITH_HYBRID
#define OM_WITH_HYBRID 1
#endif

/* One line a method, in the order tools list them: X(name, 1) builds it in always,
 * X(name, OM_WITH_NAME) lets a firmware leave it out (with its default above). */
#define METHODS(X)           \
    X(none, OM_WITH_NONE)    \
    X(ref, OM_WITH_REF)      \
    X(sm, OM_WITH_SM)        \
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

/* The methods whose resolve runs by bands on the host's threads (frame.h, om__bands):
 * those whose resolve only reads the state once it is built (spsm's window of decoded
 * texels is the band's own; hybrid: its map lookup by bands, its irregular pass after
 * them; asm: its leaf cache is the band's own, the use stamps put on the tree after
 * them). izb (per-strip lists in the state) resolves a strip at a time. */
#define BANDED(X)            \
    X(none, OM_WITH_NONE)    \
    X(ref, OM_WITH_REF)      \
    X(sm, OM_WITH_SM)        \
    X(rtw, OM_WITH_RTW)      \
    X(hybrid, OM_WITH_HYBRID) \
    X(spsm, OM_WITH_SPSM)    \
    X(asm, OM_WITH_ASM)

#define DECLARE_BANDS(m, on) extern const om__bands om__bands_##m;
BANDED(DECLARE_BANDS)

#define BANDS_1(m) if (m_ == &om__method_##m) return &om__bands_##m;
#define BANDS_0(m)
#define BANDS(m, on) CAT(BANDS_, on)(m)

const om__bands *om__method_bands(const om_method *m_)
{
    if (!OM_WITH_JOBS) return NULL;   /* (frame.h) none linked */
    BANDED(BANDS)
    (void)m_;
    return NULL;
}

/* The methods with a pass of jobs of their own (frame.h, om__pass): izb's tiles, ref's
 * per-frame vertex projection (its begin; its bands resolve), asm, which lends the
 * threads to its analysis and tile renders (asm_jobs.c), rtw and spsm, which lend them
 * to their observe (rtw_jobs.c, spsm_observe.c), and hybrid's tiles of uncertain
 * samples. */
#define PASSED(X) \
    X(izb, OM_WITH_IZB) X(ref, OM_WITH_REF) X(asm, OM_WITH_ASM) X(rtw, OM_WITH_RTW) X(spsm, OM_WITH_SPSM) \
    X(hybrid, OM_WITH_HYBRID)

#define DECLARE_PASS(m, on) extern const om__pass om__pass_##m;
PASSED(DECLARE_PASS)

#define PASS_1(m) if (m_ == &om__method_##m) return &om__pass_##m;
#define PASS_0(m)
#define PASS(m, on) CAT(PASS_, on)(m)

const om__pass *om__method_pass(const om_method *m_)
{
    if (!OM_WITH_JOBS) return NULL;
    PASSED(PASS)
    (void)m_;
    return NULL;
}

size_t om_method_count(void) { return sizeof methods / sizeof methods[0] - 1; }

const om_method *om_method_at(size_t i)
{
    return i < om_method_count() ? methods[i] : NULL;
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
    memset(c, 0, sizeof *c);
    c->method = m;
    for (uint32_t i = 0; m && i < m->nsettings; i++) put(c, &m->settings[i], m->settings[i].def);
}

om_status om_method_cfg_set(om_method_cfg *c, const char *name, double value, om_diag *d)
{
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
    const om_setting *f = om_method_setting(c->method, name);
    if (!f) return OM_E_NOTFOUND;
    const unsigned char *p = c->store.bytes + f->offset;
    if (f->kind == OM_SETTING_U32) { uint32_t v; memcpy(&v, p, sizeof v); *value = v; }
    else if (f->kind == OM_SETTING_U64) { uint64_t v; memcpy(&v, p, sizeof v); *value = (double)v; }
    else { float v; memcpy(&v, p, sizeof v); *value = v; }
    return OM_OK;
}

void om_method_cfg_from(om_method_cfg *c, const om_method *m, const om_method_cfg *from)
{
    om_method_cfg src;
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
