/* check.c — what a scene must hold for the engine to read it without reading past
 * an array: arrays for its counts, vertex and material indices in range. A parsed
 * scene always holds it; a scene a host builds by hand may not, and om_method_init
 * checks it once, before a method reads it (a host that edits a scene later keeps it
 * so). Values need no check: a NaN, infinite or huge vertex renders, as the triangles
 * it spoils are skipped (tests/property/robust.c). */
#include "scene.h"

static om_status bad(om_diag *d, om_status st, const char *what, uint64_t i, const char *rule)
{
    char tmp[8];
    om__str s = om__diag_begin(d, st, tmp, sizeof tmp);
    om__str_s(&s, "scene: ");
    om__str_s(&s, what);
    om__str_u(&s, i);
    om__str_s(&s, rule);
    return st;
}

om_status om__scene_check(const om_scene *s, om_diag *d)
{
    if ((s->nverts && !s->verts) || (s->ntris && (!s->idx || !s->tri_mat || !s->mats || !s->nmats)) ||
        (s->nsolids && !s->solids))
        return om__fail(d, OM_E_INVALID, "scene: an array its counts ask for is missing (verts, idx, tri_mat, "
                                         "mats or solids)");
    for (uint32_t t = 0; t < s->ntris; t++) {
        const uint32_t *k = &s->idx[3 * (size_t)t];
        if (k[0] >= s->nverts || k[1] >= s->nverts || k[2] >= s->nverts)
            return bad(d, OM_E_INVALID, "triangle ", t, " names a vertex past the scene's vertices");
        if (s->tri_mat[t] >= s->nmats)
            return bad(d, OM_E_INVALID, "triangle ", t, " names a material past the scene's materials");
    }
    return OM_OK;
}
