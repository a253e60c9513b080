/* registry.c — every shadow method by name. Adding a method is its own file plus one
 * line here; every tool, chart and test finds it through this table. */
#include "shadow.h"

static const om_method *const methods[] = {
    &om__method_none,
    &om__method_ref,
    &om__method_sm,
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

void om_method_cfg_default(om_method_cfg *c)
{
    memset(c, 0, sizeof *c);
    c->map_size = 2048;
    c->bias_const = 0.01f;   /* world units: 1 cm */
    c->bias_slope = 1.5f;    /* texels: a plane's depth across 1.5 texels at its slope */
    c->normal_offset = 0.0f;
    c->pcf = 1;
}
