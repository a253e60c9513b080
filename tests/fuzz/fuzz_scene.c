/* fuzz_scene.c — libFuzzer target: arbitrary bytes as scene text. The bytes query and
 * the parse must agree, never read past the input (ASan), never crash, and a parse
 * that succeeds must fit exactly the bytes its query asked for. Meshes load from a
 * fixed in-memory OBJ. */
#include "ombra.h"

#include <stdlib.h>
#include <string.h>

static const char obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n";

static om_status load(void *user, const char *name, const char **data, size_t *len)
{
    (void)user;
    if (strcmp(name, "m.obj") != 0) return OM_E_NOTFOUND;
    *data = obj;
    *len = sizeof obj - 1;
    return OM_OK;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    om_loader ld = {load, NULL};
    size_t bytes;
    om_diag d;
    om_status a = om_scene_bytes((const char *)data, size, &ld, &bytes, &d);
    if (a != OM_OK || bytes > (64u << 20)) return 0;
    void *mem = malloc(bytes ? bytes : 1);
    om_arena arena;
    om_scene s;
    om_arena_init(&arena, mem, bytes, "scene");
    om_status b = om_scene_parse((const char *)data, size, &ld, &arena, &s, &d);
    if (b != OM_OK || arena.used > bytes) abort();   /* the query promised enough */
    free(mem);
    return 0;
}
