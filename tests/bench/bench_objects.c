/* bench_objects.c — things move (issue 53): one 960-triangle object moving through a
 * 100,960-triangle scene at 1024x768, each method's frames with the object still and
 * moved (interleaved, medians), its set-up and build stage (where ref builds its
 * objects' subtree again), and asm's tiles redrawn a frame; then what 1,000 copies of
 * one mesh cost the scene arena against 1,000 shapes of their own. */
#include "bench.h"

#include <string.h>

static const char moving_text[] =
    "camera eye 0 12 22 target 0 0 0 size 1024 768\n"
    "light spot pos 12 25 10 target 0 0 0 fov 70 near 1 far 100\n"
    "plane size 40 40 divisions 200\n"
    "triangles count 20000 area 40 in -15 0.2 -15 15 3 15\n"
    "sphere radius 1 segments 32 rings 16 translate 0 2 0 name ball\n";

static void one_method(const bscene *b, const char *name)
{
    bsetup t;
    if (bench_setup(&t, b, name, 1024, 768, 1)) return;
    om_scene *s = (om_scene *)&b->s;
    uint64_t still[RUNS], moving[RUNS], bstill[RUNS], bmoving[RUNS];
    uint32_t redrawn = 0, nodes = 0;
    for (int i = 0; i < 2 * RUNS + 2; i++) {   /* two frames to settle first */
        const bool move = i & 1;
        if (move) {
            const float k = (float)(i / 2 + 1);
            om_mat4 m = {{1, 0, 0, 0.15f * k, 0, 1, 0, 0, 0, 0, 1, 0.1f * k, 0, 0, 0, 1}};
            om_object_pose(s, 0, &m, NULL);
        }
        om_frame_desc fd;
        om_arena fa;
        om_frame_stats fs;
        om_diag d;
        bench_frame_desc(&t, b, &fd, &fa);
        const uint64_t t0 = om_clock_ns(NULL);
        if (om_render_frame(&fd, &fa, &fs, &d) != OM_OK) {
            fprintf(stderr, "bench: objects %s: %s\n", name, d.msg);
            break;
        }
        const uint64_t ns = om_clock_ns(NULL) - t0;
        if (i < 2) continue;
        (move ? moving : still)[(i - 2) / 2] = ns;
        (move ? bmoving : bstill)[(i - 2) / 2] = fs.ns_build;
        om_method_stats ms;
        om_method_get_stats(t.m, t.state, &ms);
        if (move && !strcmp(name, "asm")) {
            redrawn += ms.counters[8];
            nodes += ms.counters[0];
        }
    }
    const double a = bench_median_ns(still, RUNS), m = bench_median_ns(moving, RUNS);
    printf("  %-7s still %8.2f ms  moved %8.2f ms  x%.3f   build still %6.2f ms, moved %6.2f ms", name, a, m,
           m / a, bench_median_ns(bstill, RUNS), bench_median_ns(bmoving, RUNS));
    if (!strcmp(name, "asm")) printf("   tiles redrawn %.1f%% a frame", 100.0 * redrawn / (nodes ? nodes : 1));
    printf("\n");
    bench_teardown(&t);
}

static size_t scene_bytes(const char *text)
{
    size_t bytes = 0;
    om_scene_bytes(text, strlen(text), NULL, &bytes, NULL);
    return bytes;
}

void bench_objects(void)
{
    bscene b;
    printf("objects: a 960-triangle object moved every other frame in 100,960 triangles, 1024x768, "
           "one thread\n");
    for (size_t i = 0; i < om_method_count(); i++) {
        if (bench_load(&b, "moving", moving_text)) return;
        one_method(&b, om_method_name(om_method_at(i)));
        bench_free(&b);
    }
    static char copies[64 * 1024], shapes[80 * 1024];
    size_t nc = (size_t)snprintf(copies, sizeof copies, "sphere segments 32 rings 16 name s0\n");
    size_t ns = (size_t)snprintf(shapes, sizeof shapes, "sphere segments 32 rings 16\n");
    for (int i = 1; i < 1000; i++) {
        nc += (size_t)snprintf(copies + nc, sizeof copies - nc, "copy s0 translate %d 0 %d\n", i % 40 * 3, i / 40 * 3);
        ns += (size_t)snprintf(shapes + ns, sizeof shapes - ns, "sphere segments 32 rings 16 translate %d 0 %d\n",
                               i % 40 * 3, i / 40 * 3);
    }
    printf("objects: 1,000 copies of one 960-triangle mesh: scene arena %zu bytes; as 1,000 spheres of "
           "their own: %zu\n", scene_bytes(copies), scene_bytes(shapes));
}
