/* registry.c — every shadow method by name. Adding a method is its own file plus one
 * line here; every tool, chart and test finds it through this table. */
#include "shadow.h"

static const om_method *const methods[] = {
    &om__method_none,
    &om__method_ref,
    &om__method_sm,
    &om__method_asm,
    &om__method_rtw,
    &om__method_spsm,
    &om__method_izb,
    &om__method_hybrid,
};

/* What `ombra bench` sweeps, by method name (see om_method_sweep). */
static const struct { const char *name, *sweep; } sweeps[] = {
    {"none", ""},
    {"sm", "map=256,512,1024,2048,4096,8192"},
    {"izb", "izb.pool=0,65536,16384"},
    {"asm", "asm.cap=1048576,4194304,8388608,16777216"},
    {"rtw", "map=512,1024,2048 rtw.exact=1,0"},
    {"spsm", "map=512,1024,2048,4096"},
    {"hybrid", "hybrid.map=256,512,1024"},
};

size_t om_method_count(void) { return sizeof methods / sizeof methods[0]; }

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

const char *om_method_sweep(const om_method *m)
{
    for (size_t i = 0; m && i < sizeof sweeps / sizeof sweeps[0]; i++)
        if (same_name(sweeps[i].name, m->name)) return sweeps[i].sweep;
    return NULL;
}

void om_method_cfg_default(om_method_cfg *c)
{
    memset(c, 0, sizeof *c);
    c->map_size = 2048;
    c->bias_const = 0.01f;   /* world units: 1 cm */
    c->bias_slope = 1.5f;    /* texels: a plane's depth across 1.5 texels at its slope */
    c->normal_offset = 0.0f;
    c->pcf = 1;
    c->asm_cap = 16u << 20;
    c->asm_tile = 64;
    c->asm_cells = 8;
    c->asm_root = 1024;
    c->asm_work = 64;
    c->asm_stride = 8;
    c->asm_cost_a = 1.0f / 4096.0f;
    c->asm_cost_b = 1.0f;
    c->izb_leaf = 64;
    c->izb_pool = 0;
    c->rtw_importance = 0;
    c->rtw_analysis = 0;
    c->rtw_funcs = 1 | 2 | 8;
    c->rtw_sigma = 3.0f;
    c->rtw_tess = 0.025f;
    c->rtw_exact = 1;
    c->rtw_footprint = 0;
    c->spsm_aa = 0;
    c->spsm_records = 0;
    c->spsm_fine = 0;
    c->hybrid_map = 0;
}

#define F(name, kind, field, lo, hi, help) {name, help, kind, offsetof(om_method_cfg, field), lo, hi}

static const om_cfg_field fields[] = {
    F("map", 'u', map_size, 1, 8192, "shadow-map side in texels (sm, rtw, spsm)"),
    F("bias", 'f', bias_const, 0, 1e6, "constant bias, world units along the light ray (sm, rtw)"),
    F("slope", 'f', bias_slope, 0, 1e3, "slope-scaled bias in texels (sm, rtw)"),
    F("offset", 'f', normal_offset, 0, 1e3, "normal offset in texels (sm, rtw)"),
    F("pcf", 'u', pcf, 1, 9, "k x k percentage-closer filtering, 1 = off (sm, rtw)"),
    F("asm.cap", 'z', asm_cap, 0, 1e15, "bytes the ASM node structure may hold"),
    F("asm.tile", 'u', asm_tile, 4, 1024, "texels per side of an ASM node's tile"),
    F("asm.cells", 'u', asm_cells, 1, 64, "cells per side of an ASM node"),
    F("asm.root", 'u', asm_root, 16, 8192, "texels per side of the ASM root"),
    F("asm.work", 'u', asm_work, 0, 1e9, "ASM per-frame work budget, cost units"),
    F("asm.stride", 'u', asm_stride, 1, 1024, "ASM analyses one visible sample in N"),
    F("asm.a", 'f', asm_cost_a, 0, 1e6, "ASM node cost per required texel"),
    F("asm.b", 'f', asm_cost_b, 0, 1e6, "ASM node cost, constant part"),
    F("izb.leaf", 'u', izb_leaf, 1, 65536, "most samples in an IZB BSP leaf (izb, hybrid)"),
    F("izb.pool", 'u', izb_pool, 0, 1e9, "IZB sample pool, 0 = whole frame in one pass (izb, hybrid)"),
    F("rtw.importance", 'u', rtw_importance, 0, 8192, "RTW importance map side (at least 8), 0 = 512 or the map's if smaller"),
    F("rtw.analysis", 'u', rtw_analysis, 0, 2, "RTW analysis: 0 backward, 1 forward, 2 hybrid"),
    F("rtw.funcs", 'u', rtw_funcs, 0, 15, "RTW importance: 1 view, 2 distance, 4 edge, 8 normal"),
    F("rtw.sigma", 'f', rtw_sigma, 0, 64, "RTW blur sigma in super-cells"),
    F("rtw.tess", 'f', rtw_tess, 0, 1, "RTW longest warped edge / map width, 0 = off"),
    F("rtw.exact", 'u', rtw_exact, 0, 1, "RTW map: 1 texels sample at inverse-warped centres, 0 warped vertices"),
    F("rtw.footprint", 'u', rtw_footprint, 0, 1, "RTW PCF taps: 0 a warped texel apart, 1 an unwarped one"),
    F("spsm.aa", 'u', spsm_aa, 0, 64, "SPSM sub-samples at uncertain samples, 0 = off"),
    F("spsm.records", 'u', spsm_records, 0, 2, "SPSM records made: 1 all, 2 those the view reads, 0 auto"),
    F("spsm.fine", 'u', spsm_fine, 0, 1, "SPSM fallback: 1 the plain map at 2 x 2 points per texel, 0 at centres"),
    F("hybrid.map", 'u', hybrid_map, 0, 8192, "hybrid's conservative map side (20 bytes a texel), 0 = auto: half the image's side"),
};

#undef F

const om_cfg_field *om_method_cfg_fields(size_t *count)
{
    *count = sizeof fields / sizeof fields[0];
    return fields;
}

om_status om_method_cfg_set(om_method_cfg *c, const char *name, double value, om_diag *d)
{
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) {
        const om_cfg_field *f = &fields[i];
        if (!same_name(f->name, name)) continue;
        if (!(value >= f->min && value <= f->max) || (f->kind != 'f' && value != floor(value))) {
            char tmp[8];
            om__str s = om__diag_begin(d, OM_E_RANGE, tmp, sizeof tmp);
            om__str_s(&s, f->name);
            om__str_s(&s, f->kind == 'f' ? " takes a number from " : " takes a whole number from ");
            om__str_f(&s, f->min, f->kind == 'f' ? 3 : 0);
            om__str_s(&s, " to ");
            om__str_f(&s, f->max, f->kind == 'f' ? 3 : 0);
            return OM_E_RANGE;
        }
        unsigned char *p = (unsigned char *)c + f->offset;
        if (f->kind == 'u') { uint32_t v = (uint32_t)value; memcpy(p, &v, sizeof v); }
        else if (f->kind == 'z') { uint64_t v = (uint64_t)value; memcpy(p, &v, sizeof v); }
        else { float v = (float)value; memcpy(p, &v, sizeof v); }
        return OM_OK;
    }
    return om__fail(d, OM_E_NOTFOUND, "unknown setting (see 'ombra methods')");
}
