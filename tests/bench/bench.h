/* bench.h — what the benchmark programs share: scenes, medians, and one method run
 * over one frame with per-stage times. `make bench` runs every benchmark listed in
 * OM_BENCHES; `build/bench NAME` runs the ones whose name contains NAME. Benchmarks
 * print figures and assert nothing. */
#ifndef OM_BENCH_H
#define OM_BENCH_H

#include "../../engine/frame/frame.h"
#include "../../platform/platform.h"

#include <stdio.h>
#include <stdlib.h>

#define RUNS 7

typedef struct bscene { const char *name; char *text; void *mem; om_scene s; } bscene;

/* Parses scene text into a heap arena; prints the error and returns non-zero on failure. */
int bench_load(bscene *b, const char *name, const char *text);
void bench_free(bscene *b);
/* The random-triangle scenes of the Alias-Free Shadow Maps paper's Table 1: `count`
 * small triangles of constant total area above a floor, at 1024x768. */
int bench_load_random(bscene *b, unsigned count);
/* fn on the default scene, then on the 10K and 100K random clouds. */
void bench_default_and_clouds(void (*fn)(const bscene *b));

/* The view of scene b at time t, its camera at W x H; non-zero when it has none. */
int bench_view(const bscene *b, uint32_t W, uint32_t H, float t, om_view *v);

double bench_median_ns(uint64_t *t, int n);   /* in ms */
double bench_median(double *v, int n);

/* One method over one frame at W x H: init (timed; the reference builds its BVH there),
 * then the frame with per-stage times; the whole-frame mask goes to `mask` (may be
 * NULL). cfg NULL = defaults; one made for another
 * method gives the settings they share (om_method_cfg_from). */
typedef struct mrun {
    double init_ms, eye_ms, observe_ms, build_ms, resolve_ms, shade_ms;
    double stage_ms[4];    /* a hook's own measures (bench_run_hooked) */
    om_method_stats stats;
} mrun;
int bench_run(const bscene *b, const char *method, const om_method_cfg *cfg, uint32_t W,
              uint32_t H, float t, uint8_t *mask, mrun *out);
/* bench_run with `hook` called on the method's state after the frame (e.g. to time
 * the method's own stages into out->stage_ms); hook may be NULL. */
int bench_run_hooked(const bscene *b, const char *method, const om_method_cfg *cfg, uint32_t W,
                     uint32_t H, float t, uint8_t *mask, mrun *out,
                     void (*hook)(void *state, mrun *out));

/* A method at its defaults on scene b at W x H, ready for frame after frame: its state
 * in a heap arena, a frame arena with room for `threads` jobs (zeroed, so resident as a
 * host's arenas are), an RGB888 framebuffer and default shading. */
typedef struct bsetup {
    const om_method *m;
    void *state, *mem, *fmem;
    size_t fbytes;
    om_view v;
    om_framebuffer fb;
    om_shade_cfg shade;
} bsetup;
/* Non-zero where it cannot (after bench_teardown of what it made). */
int bench_setup(bsetup *t, const bscene *b, const char *name, uint32_t W, uint32_t H, uint32_t threads);
void bench_teardown(bsetup *t);
/* The frame arena for a whole W x H frame of method m (may be NULL) on scene s (may
 * be NULL: no bins) with `threads` jobs: om_frame_bytes' with_jobs. */
size_t bench_frame_bytes(const om_method *m, const om_scene *s, uint32_t W, uint32_t H, uint32_t threads);
/* A frame of t on one thread: *fd filled but for the parallel-for, and *fa over t's
 * frame arena. */
void bench_frame_desc(bsetup *t, const bscene *b, om_frame_desc *fd, om_arena *fa);

/* Whether the calling thread can be pinned to CPU 0 and to CPU 1 (Linux, two CPUs
 * online); it records the thread's CPUs for bench_pin(-1), so call it before pinning. */
bool bench_pin_two(void);
/* Pins the calling thread to `cpu`, or gives it back the CPUs bench_pin_two found
 * with cpu < 0; false where it cannot. */
bool bench_pin(int cpu);

#define OM_BENCHES \
    X(bench_raster) \
    X(bench_raster_sweep) \
    X(bench_shadow) \
    X(bench_izb) \
    X(bench_rtw) \
    X(bench_asm) \
    X(bench_asm_big) \
    X(bench_spsm) \
    X(bench_hybrid) \
    X(bench_threads) \
    X(bench_calls) \
    X(bench_serial) \
    X(bench_objects) \
    /* end of list */
#define X(name) void name(void);
OM_BENCHES
#undef X

#endif
