/* need.c — the check every init makes first: does the arena hold what the bytes query
 * promised? Failing here names the minimum, before anything is carved. */
#include "core.h"

om_status om__need(om_arena *a, size_t need, const char *who, om_diag *d)
{
    size_t left = om_arena_left(a);
    if (left >= need) return OM_OK;
    a->fail_asked = need;
    a->fail_left = left;
    if (d) {
        char tmp[8];
        om__str s = om__diag_begin(d, OM_E_BUDGET, tmp, sizeof tmp);
        d->asked = need;
        d->left = left;
        om__str_s(&s, who);
        om__str_s(&s, " needs at least ");
        om__str_u(&s, need);
        om__str_s(&s, " bytes; the ");
        om__str_s(&s, a->name);
        om__str_s(&s, " arena has ");
        om__str_u(&s, left);
        om__str_s(&s, " left");
    }
    return OM_E_BUDGET;
}
