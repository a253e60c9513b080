/* bench_objects.c — things move (issue 53): one 960-triangle object moving through a
 * 100,960-triangle scene at 1024x768, each method's frames with the object still and
 * moved (interleaved, medians), its set-up and build stage (where ref builds the
 * moved object's subtree and the top level over the objects again), and asm's tiles
 * redrawn a frame; the same for ref where the scene's 96,000 other triangles are 100
 * still copies of one mesh (whose subtrees a move leaves as they are); then what
 * 1,000 copies of one mesh cost the scene arena against 1,000 shapes of their own,
 * and where the difference goes. */
#include "bench.h"

#include <string.h>

static char crowd_text[16384];

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
        if (move && !strcmp(name, "ref"))
            for (uint32_t c = 0; c < ms.ncounters; c++)
                if (!strcmp(ms.counter_names[c], "objects rebuilt")) redrawn += ms.counters[c];
    }
    const double a = bench_median_ns(still, RUNS), m = bench_median_ns(moving, RUNS);
    printf("  %-7s still %8.2f ms  moved %8.2f ms  x%.3f   build still %6.2f ms, moved %6.2f ms", name, a, m,
           m / a, bench_median_ns(bstill, RUNS), bench_median_ns(bmoving, RUNS));
    if (!strcmp(name, "asm")) printf("   tiles redrawn %.1f%% a frame", 100.0 * redrawn / (nodes ? nodes : 1));
    if (!strcmp(name, "ref")) printf("   objects rebuilt %.1f a moved frame", (double)redrawn / RUNS);
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
    /* where the difference goes: the mesh once, and per object its record beside the
     * posed triangles every object owns (what the methods read) */
    const size_t one = scene_bytes("sphere segments 32 rings 16\n"),
                 own = scene_bytes("sphere segments 32 rings 16\nsphere segments 32 rings 16 translate 3 0 0\n") - one,
                 named = scene_bytes("sphere segments 32 rings 16 name s0\n"),
                 copy = scene_bytes("sphere segments 32 rings 16 name s0\ncopy s0 translate 3 0 0\n") - named;
    printf("objects: the mesh once %zu bytes; a copy %zu bytes: its posed triangles, as a sphere of its own, "
           "%zu, and its record %zu (sizeof om_object %zu)\n", named - one - sizeof(om_object), copy, own,
           copy - own, sizeof(om_object));
    size_t n = (size_t)snprintf(crowd_text, sizeof crowd_text,
                                "camera eye 0 12 22 target 0 0 0 size 1024 768\n"
                                "light spot pos 12 25 10 target 0 0 0 fov 70 near 1 far 100\n"
                                "plane size 40 40\nsphere radius 1 segments 32 rings 16 translate 0 2 0 name ball\n"
                                "sphere radius 0.4 segments 32 rings 16 translate -14 0.4 -14 name s0\n");
    for (int i = 1; i < 100; i++)
        n += (size_t)snprintf(crowd_text + n, sizeof crowd_text - n, "copy s0 translate %d 0 %d\n", i % 10 * 3,
                              i / 10 * 3);
    printf("objects: ref, the 960-triangle object moving among 100 still copies of one 960-triangle mesh, "
           "1024x768\n");
    if (bench_load(&b, "crowd", crowd_text)) return;
    one_method(&b, "ref");
    bench_free(&b);
}
