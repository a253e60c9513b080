/* fuzz_render.c — libFuzzer target: arbitrary scene text rendered at a small size with
 * every method under small budgets. The first input byte picks the image size, the
 * strip height and how much of each method's one-pass size its arena gets; every call
 * must return a status (a budget error is fine), never crash or write outside its
 * arena — guard bytes around every arena are checked after each frame. */
#include "ombra.h"

#include <stdlib.h>
#include <string.h>

#include "guard.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    uint8_t ctl = data[0];
    const char *text = (const char *)data + 1;
    size_t len = size - 1;
    size_t bytes;
    om_diag d;
    if (om_scene_bytes(text, len, NULL, &bytes, &d) != OM_OK || bytes > (8u << 20)) return 0;
    void *smem = malloc(bytes ? bytes : 1);
    om_arena sa;
    om_scene s;
    om_arena_init(&sa, smem, bytes, "scene");
    if (om_scene_parse(text, len, NULL, &sa, &s, &d) != OM_OK || s.ntris > 20000) goto out;
    om_camera cam;
    om_light light;
    om_scene_at(&s, (float)(ctl >> 6), &cam, &light);
    cam.width = 8 + (ctl & 7) * 5;
    cam.height = 6 + ((ctl >> 3) & 3) * 7;
    om_view v;
    if (om_view_init(&v, &cam, &light, &s, &d) != OM_OK) goto out;
    uint32_t rows = 1 + (ctl & 3) * 3;
    om_frame_desc q;   /* the frame arena: its least for strips of `rows` rows */
    om_frame_need need;
    memset(&q, 0, sizeof q);
    q.view = &v;
    q.strip_rows = rows;
    if (om_frame_bytes(&q, &need) != OM_OK) abort();
    size_t fbytes = need.least;
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        om_method_cfg cfg;   /* small maps and structures, where m takes them */
        om_method_cfg_default(&cfg, m);
        /* with thousands of triangles and bit 5 of the control byte, maps of 1024: a
         * light pass that costs triangles x texels (issue 24: huge triangles over the
         * whole map) then takes seconds and shows as a slow unit (run.sh's -timeout) */
        om_method_cfg_set(&cfg, "map", (ctl & 0x20) && s.ntris >= 4096 ? 1024 : 64, NULL);
        om_method_cfg_set(&cfg, "asm.cap", 1u << 20, NULL);
        om_method_cfg_set(&cfg, "rtw.importance", 32, NULL);
        size_t mn, full;
        if (om_method_bytes(m, &cfg, &s, cam.width, cam.height, &mn, &full) != OM_OK || full > (32u << 20)) continue;
        /* an arena between below-minimum and one pass, by the control byte */
        size_t give = (ctl & 0x40) ? full : (ctl & 0x80) ? mn : mn / 2;
        unsigned char *mb = guarded_alloc(give), *fb_mem = guarded_alloc(fbytes);
        uint8_t *px = malloc((size_t)cam.width * rows * 3);
        om_arena ma, fa;
        om_arena_init(&ma, mb + GUARD, give, "method");
        om_arena_init(&fa, fb_mem + GUARD, fbytes, "frame");
        void *state;
        if (om_method_init(m, &state, &ma, &cfg, &s, cam.width, cam.height, &d) == OM_OK) {
            om_shade_cfg shade;
            om_shade_cfg_default(&shade);
            om_framebuffer fb = {OM_RGB888, cam.width, rows, (size_t)cam.width * 3, px};
            om_frame_desc fd;
            memset(&fd, 0, sizeof fd);
            fd.scene = &s; fd.view = &v; fd.method = m; fd.method_state = state; fd.shade = &shade;
            fd.strip_rows = rows; fd.fb = &fb;
            /* the second frame with the objects moved along their keys: what a kept
             * state redoes where things move (ref's objects' BVH, asm's tiles) */
            for (int frame = 0; frame < 2; frame++) {
                (void)om_scene_pose_at(&s, (float)(ctl >> 6) + 0.5f * (float)frame, NULL);
                om_render_frame(&fd, &fa, NULL, &d);
            }
        }
        if (!guarded(mb, give) || !guarded(fb_mem, fbytes)) abort();
        free(mb);
        free(fb_mem);
        free(px);
    }
out:
    free(smem);
    return 0;
}
