/* scene_util.h — helpers the scene suites share (unit/scene.c, unit/obj.c,
 * unit/scene_fuzz.c): scene text copied into a heap block of exactly its length, a
 * bytes query and then a parse into an arena of exactly that many bytes, and small
 * vector checks on the result. */
#ifndef OM_SCENE_UTIL_H
#define OM_SCENE_UTIL_H

#include "../engine/scene/scene.h"

typedef struct parsed {
    om_scene s;
    void *mem;
    size_t bytes;
    om_diag d;
    om_status st;
} parsed;

/* The text in a heap block of exactly its length, no NUL after it: under ASan any read
 * past `len` is caught. The caller frees it. */
char *exact_copy(const char *text, size_t len);

/* Bytes query, then a parse into a heap buffer of exactly that many bytes (so ASan
 * sees any write past it); checks that the arena ends exactly full. */
om_status parse_ld(const char *text, size_t len, const om_loader *ld, parsed *p);
om_status parse(const char *text, parsed *p);   /* NUL-terminated text, no loader */
void done(parsed *p);                           /* frees what parse_ld allocated */

bool veq(om_vec3 a, float x, float y, float z);          /* exactly (x, y, z) */
om_vec3 tri_normal(const om_scene *s, uint32_t t);       /* unnormalized, by winding */

#endif
