/* render_sized.c — the README's second embedding example, for a host with memory to
 * spare (a console, a desktop): every arena exactly as big as the engine's bytes
 * queries (om_method_bytes, om_frame_bytes) say, taken from malloc; the default scene at 640x480 in one RGB888 frame
 * with `sm`. `make check` builds it with the project's warning flags, runs it, and
 * checks that its frame is the one `ombra render` draws with the same settings;
 * tests/embed/readme.sh fails when the README's copy (between the markers) differs.
 * main() prints the frame's hash. */
#include <stdio.h>
/* README: begin */
#include "ombra.h"
#include "ombra_measure.h"
#include <stdlib.h>
#include <string.h>

static uint64_t hash = OM_HASH_INIT;

int render_sized(void)
{
    enum { W = 640, H = 480 };
    const char *text = om_scene_default_text();
    const om_method *m = om_method_find("sm");
    size_t scene_bytes, min, full;
    om_arena sa, ma, fa;
    om_scene scene;
    om_camera cam;
    om_light light;
    om_view view;
    om_method_cfg cfg;
    om_shade_cfg shade;
    om_frame_desc fd;
    om_frame_need need;
    om_diag d;
    int ok = -1;
    if (!m || om_scene_bytes(text, strlen(text), NULL, &scene_bytes, &d) != OM_OK) return -1;
    void *scene_mem = malloc(scene_bytes), *method_mem = NULL, *frame_mem = NULL;
    om_framebuffer fb = {OM_RGB888, W, H, W * 3, malloc((size_t)W * H * 3)};
    om_arena_init(&sa, scene_mem, scene_mem ? scene_bytes : 0, "scene");
    om_method_cfg_default(&cfg, m);                 /* map 2048: 16 MiB */
    om_shade_cfg_default(&shade);
    memset(&fd, 0, sizeof fd);
    fd.scene = &scene; fd.view = &view; fd.method = m; fd.shade = &shade; fd.fb = &fb;
    if (fb.pixels && om_scene_parse(text, strlen(text), NULL, &sa, &scene, &d) == OM_OK) {
        om_scene_at(&scene, 0.0f, &cam, &light);
        cam.width = W;
        cam.height = H;
        if (om_view_init(&view, &cam, &light, &scene, &d) == OM_OK && om_frame_bytes(&fd, &need) == OM_OK &&
            om_method_bytes(m, &cfg, &scene, W, H, &min, &full) == OM_OK &&
            (method_mem = malloc(full)) != NULL && (frame_mem = malloc(need.whole)) != NULL) {
            om_arena_init(&ma, method_mem, full, "method");
            om_arena_init(&fa, frame_mem, need.whole, "frame");
            ok = om_method_init(m, &fd.method_state, &ma, &cfg, &scene, W, H, &d) == OM_OK &&
                 om_render_frame(&fd, &fa, NULL, &d) == OM_OK ? 0 : -1;
        }
    }
    if (ok == 0) hash = om_hash(hash, fb.pixels, (size_t)W * H * 3);   /* one strip: the whole frame */
    free(fb.pixels);
    free(frame_mem);
    free(method_mem);
    free(scene_mem);
    return ok;
}
/* README: end */

int main(void)
{
    if (render_sized() != 0) {
        fprintf(stderr, "embed: render_sized failed\n");
        return 1;
    }
    printf("embed: render_sized ok, frame hash %016llx\n", (unsigned long long)hash);
    return 0;
}
