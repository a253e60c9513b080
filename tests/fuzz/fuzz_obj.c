/* fuzz_obj.c — libFuzzer target: arbitrary bytes as a Wavefront OBJ file, counted and
 * then loaded through a scene's `mesh` line. */
#include "ombra.h"

#include <stdlib.h>
#include <string.h>

typedef struct input { const char *data; size_t len; } input;

static om_status load(void *user, const char *name, const char **data, size_t *len)
{
    (void)name;
    const input *in = (const input *)user;
    *data = in->data;
    *len = in->len;
    return OM_OK;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint32_t nv, nt;
    om_diag d;
    om_obj_count((const char *)data, size, &nv, &nt, &d);
    input in = {(const char *)data, size};
    om_loader ld = {load, &in};
    static const char text[] = "mesh fuzz.obj scale 2\n";
    size_t bytes;
    if (om_scene_bytes(text, sizeof text - 1, &ld, &bytes, &d) != OM_OK || bytes > (64u << 20))
        return 0;
    void *mem = malloc(bytes ? bytes : 1);
    om_arena arena;
    om_scene s;
    om_arena_init(&arena, mem, bytes, "scene");
    if (om_scene_parse(text, sizeof text - 1, &ld, &arena, &s, &d) != OM_OK) abort();
    free(mem);
    return 0;
}
