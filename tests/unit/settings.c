/* unit/settings.c — every method owns its settings: each table entry lies inside the
 * method's own configuration (no two overlap), its default is inside its range and is
 * what om_method_cfg_default writes, values outside the range or of another method are
 * refused, and om_method_cfg_from carries only what two methods share. */
#include "../test.h"
#include "../harness.h"
#include "../../engine/shadow/method.h"   /* the tables themselves (cfg_bytes) */

#include <math.h>

static size_t kind_bytes(om_setting_kind k) { return k == OM_SETTING_U64 ? 8 : 4; }

static void tables_are_sound(void)
{
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        CHECK_MSG(m->cfg_bytes <= OM_METHOD_CFG_BYTES, "%s: %zu bytes", om_method_name(m), m->cfg_bytes);
        CHECK_MSG((om_method_nsettings(m) == 0) == (m->cfg_bytes == 0), "%s: %u settings in %zu bytes", om_method_name(m),
                  om_method_nsettings(m), m->cfg_bytes);
        for (uint32_t i = 0; i < om_method_nsettings(m); i++) {
            const om_setting *f = om_method_setting_at(m, i);
            size_t n = kind_bytes(f->kind);
            CHECK_MSG(f->name[0] && f->doc[0] && !strchr(f->doc, '\n'), "%s: setting %u", om_method_name(m), i);
            CHECK_MSG(f->offset % n == 0 && f->offset + n <= m->cfg_bytes, "%s %s at %zu", om_method_name(m),
                      f->name, f->offset);
            CHECK_MSG(f->min <= f->def && f->def <= f->max, "%s %s: default %g outside %g..%g", om_method_name(m),
                      f->name, f->def, f->min, f->max);
            CHECK_MSG(om_method_setting(m, f->name) == f, "%s: %s named twice", om_method_name(m), f->name);
            /* METHOD.NAME is that method's own: it takes it (hybrid takes izb's too) */
            const char *dot = strchr(f->name, '.');
            for (size_t j = 0; dot && j < om_method_count(); j++) {
                const om_method *o = om_method_at(j);
                bool own = strlen(om_method_name(o)) == (size_t)(dot - f->name) && !strncmp(om_method_name(o), f->name, (size_t)(dot - f->name));
                if (own) CHECK_MSG(om_method_setting(o, f->name) != NULL, "%s is not %s's", f->name, om_method_name(o));
            }
            for (uint32_t j = 0; j < i; j++) {
                const om_setting *g = om_method_setting_at(m, j);
                CHECK_MSG(f->offset >= g->offset + kind_bytes(g->kind) || g->offset >= f->offset + n,
                          "%s: %s and %s overlap", om_method_name(m), f->name, g->name);
            }
        }
    }
}

static void defaults_and_ranges(void)
{
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        om_method_cfg c;
        om_method_cfg_default(&c, m);
        CHECK(c.method == m);
        for (uint32_t i = 0; i < om_method_nsettings(m); i++) {
            const om_setting *f = om_method_setting_at(m, i);
            const bool whole = f->kind != OM_SETTING_F32;
            double v = -1, want = whole ? f->def : (double)(float)f->def;
            CHECK(om_method_cfg_get(&c, f->name, &v) == OM_OK && v == want);
            CHECK(om_method_cfg_set(&c, f->name, f->max, NULL) == OM_OK);
            CHECK(om_method_cfg_get(&c, f->name, &v) == OM_OK && v == (whole ? f->max : (double)(float)f->max));
            CHECK(om_method_cfg_set(&c, f->name, f->min, NULL) == OM_OK);
            om_diag d;
            CHECK(om_method_cfg_set(&c, f->name, f->max + 1, &d) == OM_E_RANGE);
            CHECK_MSG(strstr(d.msg, f->name) != NULL, "%s", d.msg);
            CHECK(om_method_cfg_set(&c, f->name, NAN, NULL) == OM_E_RANGE);
            if (whole) CHECK(om_method_cfg_set(&c, f->name, f->min + 0.5, NULL) == OM_E_RANGE);
            CHECK(om_method_cfg_get(&c, f->name, &v) == OM_OK && v == f->min);   /* refused: kept */
        }
        CHECK(om_method_cfg_set(&c, "no.such", 1, NULL) == OM_E_NOTFOUND);
        CHECK(om_method_cfg_get(&c, "no.such", NULL) == OM_E_NOTFOUND);
    }
    /* a few by name, as the methods' files give them */
    om_method_cfg c = h_cfg("spsm", "");
    double v = -1;
    CHECK(om_method_cfg_get(&c, "spsm.aa", &v) == OM_OK && v == 0);
    CHECK(om_method_cfg_get(&c, "map", &v) == OM_OK && v == 2048);
    CHECK(om_method_cfg_get(&c, "pcf", &v) == OM_E_NOTFOUND);
    c = h_cfg("asm", "");
    CHECK(om_method_cfg_get(&c, "asm.cap", &v) == OM_OK && v == 16 << 20);
    CHECK(om_method_setting(om_method_find("sm"), "spsm.aa") == NULL);
    CHECK(om_method_setting(om_method_find("hybrid"), "izb.pool") != NULL);
}

/* Settings two methods share go across; the rest take their defaults. */
static void carried_across(void)
{
    om_method_cfg sm = h_cfg("sm", "map=512 pcf=3 bias=0.5"), c;
    double v = 0;
    om_method_cfg_from(&c, om_method_find("rtw"), &sm);
    CHECK(om_method_cfg_get(&c, "map", &v) == OM_OK && v == 512);
    CHECK(om_method_cfg_get(&c, "pcf", &v) == OM_OK && v == 3);
    CHECK(om_method_cfg_get(&c, "rtw.exact", &v) == OM_OK && v == 1);
    om_method_cfg_from(&c, om_method_find("asm"), &sm);
    CHECK(om_method_cfg_get(&c, "bias", &v) == OM_OK && v == 0.5);
    CHECK(om_method_cfg_get(&c, "map", &v) == OM_E_NOTFOUND);
    om_method_cfg_from(&c, om_method_find("spsm"), NULL);
    CHECK(om_method_cfg_get(&c, "map", &v) == OM_OK && v == 2048);
    om_method_cfg_from(&sm, om_method_find("sm"), &sm);   /* onto itself */
    CHECK(om_method_cfg_get(&sm, "map", &v) == OM_OK && v == 512);
    /* a configuration of no method sets nothing and no method takes it */
    om_method_cfg none;
    om_method_cfg_default(&none, NULL);
    CHECK(om_method_cfg_set(&none, "map", 512, NULL) == OM_E_NOTFOUND);
    size_t mn, full;
    CHECK(om_method_bytes(om_method_find("sm"), &none, NULL, 16, 16, &mn, &full) == OM_E_INVALID);
}

void suite_settings(void)
{
    RUN(tables_are_sound);
    RUN(defaults_and_ranges);
    RUN(carried_across);
}
