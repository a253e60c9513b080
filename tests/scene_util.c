/* scene_util.c — see scene_util.h. */
#include "test.h"
#include "scene_util.h"

#include <stdlib.h>

char *exact_copy(const char *text, size_t len)
{
    char *c = (char *)malloc(len ? len : 1);
    if (len) memcpy(c, text, len);
    return c;
}

om_status parse_ld(const char *text, size_t len, const om_loader *ld, parsed *p)
{
    memset(p, 0, sizeof *p);
    char *t = text ? exact_copy(text, len) : NULL;
    p->st = om_scene_bytes(t, len, ld, &p->bytes, &p->d);
    if (p->st == OM_OK) {
        p->mem = malloc(p->bytes ? p->bytes : 1);
        om_arena a;
        om_arena_init(&a, p->mem, p->bytes, "scene");
        p->st = om_scene_parse(t, len, ld, &a, &p->s, &p->d);
        if (p->st == OM_OK) CHECK_EQ_U(a.used, p->bytes);
    }
    free(t);
    return p->st;
}

om_status parse(const char *text, parsed *p) { return parse_ld(text, strlen(text), NULL, p); }
void done(parsed *p) { free(p->mem); p->mem = NULL; }

bool veq(om_vec3 a, float x, float y, float z) { return a.x == x && a.y == y && a.z == z; }

om_vec3 tri_normal(const om_scene *s, uint32_t t)
{
    const uint32_t *i = s->idx + 3 * t;
    om_vec3 a = s->verts[i[0]], b = s->verts[i[1]], c = s->verts[i[2]];
    return om__cross(om__sub(b, a), om__sub(c, a));
}
