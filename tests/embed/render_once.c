/* render_once.c — the README's embedding example, compiled with the project's warning
 * flags and run by `make check`: the small scene at 160x120 through strips of 8 rows
 * of RGB565 with the conventional shadow map, in static memory a microcontroller has
 * (about 168 KiB in all). tests/embed/readme.sh fails when the README's copy (the
 * part between the markers) differs from this file's. main() prints the frame's hash
 * and fails if the render does. */
#include <stdio.h>
/* README: begin */
#include "ombra.h"
#include "ombra_measure.h"
#include <string.h>

static unsigned char scene_mem[48 << 10], frame_mem[72 << 10], method_mem[48 << 10];
static uint8_t strip_pixels[160 * 8 * 2];          /* 8 rows of RGB565 */
static uint64_t frame_hash = OM_HASH_INIT;

static om_status show(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)user;   /* a display would copy fb->pixels (st->rows rows) to row st->y0 */
    frame_hash = om_hash(frame_hash, fb->pixels, (size_t)st->rows * fb->stride);
    return OM_OK;
}

int render_once(void)
{
    om_arena sa, fa, ma;
    om_scene scene;
    om_diag d;
    om_arena_init(&sa, scene_mem, sizeof scene_mem, "scene");
    const char *text = om_scene_small_text();   /* 1,600 triangles: a 34 KB arena */
    if (om_scene_parse(text, strlen(text), NULL, &sa, &scene, &d) != OM_OK) return -1;

    om_camera cam;
    om_light light;
    om_view view;
    om_scene_at(&scene, 0.0f, &cam, &light);
    cam.width = 160;
    cam.height = 120;
    if (om_view_init(&view, &cam, &light, &scene, &d) != OM_OK) return -1;

    const om_method *m = om_method_find("sm");
    om_method_cfg cfg;                              /* sm's settings, set by name */
    void *state;
    om_method_cfg_default(&cfg, m);
    om_method_cfg_set(&cfg, "map", 96, NULL);       /* 96 x 96 x 4 bytes: 37 KB */
    om_arena_init(&ma, method_mem, sizeof method_mem, "method");
    if (!m || om_method_init(m, &state, &ma, &cfg, &scene, 160, 120, &d) != OM_OK) return -1;

    om_shade_cfg shade;
    om_shade_cfg_default(&shade);
    om_framebuffer fb = {OM_RGB565, 160, 8, 160 * 2, strip_pixels};
    om_frame_desc fd;
    memset(&fd, 0, sizeof fd);
    fd.scene = &scene; fd.view = &view; fd.method = m; fd.method_state = state;
    fd.shade = &shade; fd.strip_rows = 8; fd.fb = &fb; fd.on_strip = show;
    om_frame_need need;   /* with room for the bins each strip sets up only its triangles */
    if (om_frame_bytes(&fd, &need) != OM_OK || need.with_bins > sizeof frame_mem) return -1;
    om_arena_init(&fa, frame_mem, sizeof frame_mem, "frame");
    return om_render_frame(&fd, &fa, NULL, &d) == OM_OK ? 0 : -1;
}
/* README: end */

int main(void)
{
    if (render_once() != 0) {
        fprintf(stderr, "embed: render_once failed\n");
        return 1;
    }
    printf("embed: render_once ok, frame hash %016llx\n", (unsigned long long)frame_hash);
    return 0;
}
