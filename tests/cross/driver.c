/* driver.c — the cross-CPU determinism driver. For each case it renders every method
 * through strips into an RGB565 framebuffer and prints one line per method: the case,
 * the method and the FNV-1a hashes of the frame and of the shadow mask. `make
 * cross-test` builds it with every compiler and CPU it can find and checks that the
 * lines agree with the reference build's; small sizes miss last-bit differences that
 * larger ones catch, hence several scenes and sizes:
 *
 *   default@WxH      the default scene, every method at its default settings
 *   default-aa@WxH   the same with PCF 3x3 (sm, rtw with unwarped taps) and 4 SPSM
 *                    sub-samples (the methods without such settings are not repeated)
 *   cloud@WxH        10K random triangles over a floor, AA/PCF on
 *   stab-t0@WxH      a stability case (the fast camera: ASM nodes replaced every frame)
 *   stab-t1@WxH      at time 0 and then 0.5 with the method's state carried over
 *   moving-t0@WxH    the small scene with its ball rolling (moving_text), at time 0 and
 *   moving-t1@WxH    then with the ball at 0.5 (the camera and light held at 0: asm
 *                    redraws the tiles under the ball) with the state carried over;
 *                    every method but asm (which refines over frames) must then draw
 *                    what a fresh state draws on the scene posed there, or the build
 *                    fails: moved is baked
 *
 * at 160x120 and 320x240 with the embedded configuration (maps of 96 texels, 64 for
 * spsm and hybrid, a 96 KiB ASM cap, a 64-cell RTW importance map: what fits a
 * microcontroller), and, where
 * OM_CROSS_BIG is defined (hosted targets), at 640x480 with maps of 1024. After the
 * default@160x120 lines come "bytes" lines with each method's arena peak and minimum
 * (they depend on pointer size, so they are not compared). OM_CROSS_ONLY selects
 * cases, bit 5 * size + case in the order above (run.sh gives slow targets fewer). The stability scene's text
 * comes from tests/stability through OM_CROSS_STAB (a header run.sh generates). It
 * needs nothing but the engine and a way to print a line (om_host_puts, from the host
 * file it is linked with). */
#include "ombra.h"
#include "ombra_measure.h"

#include <string.h>

void om_host_puts(const char *line);

/* Strips of 40 rows at the sizes a board renders (three or six strips: each strip's
 * eye pass projects every triangle, which a board without a double FPU pays dearly
 * for), of 60 at 640x480. Every target renders a size through the same strips, so
 * that only the CPU and compiler differ (frames are meant to be the same through any
 * strips, but with spsm.aa they are not yet: tests/README.md, make cross-test). */
#ifndef OM_CROSS_ROWS
#define OM_CROSS_ROWS 40
#endif
#ifdef OM_CROSS_BIG
#define FRAME_PIXELS (640 * 60)
#else
#define FRAME_PIXELS (320 * OM_CROSS_ROWS)
#endif
#ifndef OM_CROSS_METHOD_MEM
#define OM_CROSS_METHOD_MEM (96u << 20)
#endif
#ifndef OM_CROSS_SCENE_MEM
#define OM_CROSS_SCENE_MEM (2u << 20)
#endif

#ifndef OM_CROSS_ONLY
#define OM_CROSS_ONLY 0x7fffu
#endif
#ifndef OM_CROSS_COUNT
#ifndef OM_CROSS_STAB
#define OM_CROSS_STAB "stab_scene.h"
#endif
static const char stab_text[] =
#include OM_CROSS_STAB
    ;

static const char cloud_text[] =
    "plane size 12 12\n"
    "triangles count 10000 seed 4 area 20 in -4 0.3 -4 4 3 4\n";

#endif

static unsigned char scene_mem[OM_CROSS_SCENE_MEM];
static unsigned char method_mem[OM_CROSS_METHOD_MEM];
/* counting: strips up to 320 pixels wide, and room for the default scene's bins (4
 * bytes a triangle, 12 a vertex), without which every strip would walk the whole
 * scene */
#ifdef OM_CROSS_COUNT
static unsigned char frame_mem[320 * OM_CROSS_ROWS * 48 + (320u << 10)];
static uint8_t pixels[320 * OM_CROSS_ROWS * 2];   /* one strip: part of the footprint */
#else
static unsigned char frame_mem[FRAME_PIXELS * 48];
static uint8_t pixels[FRAME_PIXELS * 2];
#endif

/* The small scene's animated variant: its small ball named (" name ball" at the end of
 * its line) and keyed to roll 2.5 m across the floor, near the small cubes, between
 * t = 0 and 1; everything else as in om_scene_small_text(), which it is made from, so
 * it follows that scene. A device would keep such text in flash: the counting
 * firmware leaves this buffer out of the footprint, as it does the arenas. */
#define BALL_LINE "sphere radius 0.25 "
#define BALL_KEYS "key object ball 0 translate 0 0 0\nkey object ball 1 translate -2.4 0 0.6\n"
static char moving_buf[4096];

static const char *moving_text(void)
{
    const char *small = om_scene_small_text(), *ball = strstr(small, BALL_LINE);
    const char *eol = ball ? strchr(ball, '\n') : NULL;
    if (!eol) return NULL;
    const size_t head = (size_t)(eol - small), tail = strlen(eol), name = 10, keys = sizeof BALL_KEYS - 1;
    if (head + name + tail + keys + 1 > sizeof moving_buf) return NULL;
    memcpy(moving_buf, small, head);
    memcpy(moving_buf + head, " name ball", name);
    memcpy(moving_buf + head + name, eol, tail);
    memcpy(moving_buf + head + name + tail, BALL_KEYS, keys + 1);
    return moving_buf;
}

#ifndef OM_CROSS_COUNT
typedef struct hashes { uint64_t img, mask; } hashes;

static om_status on_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    hashes *h = (hashes *)user;
    for (uint32_t y = 0; y < st->rows; y++) {
        h->img = om_hash(h->img, fb->pixels + (size_t)y * fb->stride, (size_t)st->width * 2);
        for (uint32_t x = 0; x < st->width; x++) {
            size_t i = (size_t)y * st->width + x;
            uint8_t m = om_mask_of(&st->samples[i], &st->terms[i]);
            h->mask = om_hash(h->mask, &m, 1);
        }
    }
    return OM_OK;
}
#endif

/* A line built without stdio. */
typedef struct line { char buf[256]; size_t n; } line;

static void put_s(line *l, const char *s)
{
    while (*s && l->n + 1 < sizeof l->buf) l->buf[l->n++] = *s++;
    l->buf[l->n] = '\0';
}

#ifndef OM_CROSS_COUNT
static void put_hex(line *l, uint64_t v)
{
    char t[17];
    for (int i = 15; i >= 0; i--) {
        t[i] = "0123456789abcdef"[v & 15];
        v >>= 4;
    }
    t[16] = '\0';
    put_s(l, t);
}
#endif

static void put_dec(line *l, uint64_t v)
{
    char tmp[24], t[24];
    int n = 0;
    do { tmp[n++] = (char)('0' + v % 10); v /= 10; } while (v);
    for (int i = 0; i < n; i++) t[i] = tmp[n - 1 - i];
    t[n] = '\0';
    put_s(l, t);
}

/* "<case> <method>: <what>: <diag message>"; returns 1 (a failure). */
static int fail(const char *cs, const char *method, const char *what, const om_diag *d)
{
    line l = {{0}, 0};
    put_s(&l, cs);
    put_s(&l, " ");
    put_s(&l, method);
    put_s(&l, ": ");
    put_s(&l, what);
    put_s(&l, ": ");
    put_s(&l, d->msg);
    om_host_puts(l.buf);
    return 1;
}

typedef struct size_cfg { uint32_t w, h, rows; int embedded; const char *tag; } size_cfg;

/* m's settings for a case: each applies where m takes it (om_method_cfg_set says
 * OM_E_NOTFOUND elsewhere). */
static void method_cfg(om_method_cfg *c, const om_method *m, const size_cfg *sz, int aa)
{
    om_method_cfg_default(c, m);
    if (sz->embedded) {
        /* small enough for small machines, the same everywhere (the hashes must agree):
         * each method's whole footprint on the small scene at 160x120 within 256 KiB
         * (the counting firmware checks it), which takes spsm's 24-byte texels a map of
         * 64, asm a cap of 96 KiB and csm four cascades of 48 (sm's 96 x 96 texels) */
        om_method_cfg_set(c, "map", strcmp(om_method_name(m), "spsm") ? 96 : 64, NULL);
        om_method_cfg_set(c, "hybrid.map", 64, NULL);
        om_method_cfg_set(c, "csm.map", 48, NULL);
        om_method_cfg_set(c, "asm.cap", 96u << 10, NULL);
        om_method_cfg_set(c, "rtw.importance", 64, NULL);
    } else {
        om_method_cfg_set(c, "map", 1024, NULL);
        om_method_cfg_set(c, "csm.map", 512, NULL);   /* sm's 1024 x 1024 texels */
    }
    if (aa) {
        om_method_cfg_set(c, "pcf", 3, NULL);
        om_method_cfg_set(c, "rtw.footprint", 1, NULL);
        om_method_cfg_set(c, "spsm.aa", 4, NULL);
    }
}

#ifdef OM_CROSS_COUNT
/* Instructions per frame on the Cortex-M boards (`make cross-test`, OM_CROSS_COUNT):
 * each method renders the small scene at 160x120 and 320x240, its animated variant
 * (moving_text) at 160x120 and the default scene at 160x120 through strips of
 * OM_CROSS_ROWS rows into RGB565, with the embedded configuration, and prints
 *   count SCENE W H METHOD INSTRUCTIONS EYE OBSERVE BUILD RESOLVE SHADE METHOD_B FRAME_B
 *         SCENE_B MIN_B STATIC_B STACK_B WHOLE_B FIRST POSE
 * (instructions of the frame and of its stages; the arenas' peak bytes, the method's
 * minimum by its bytes query, the firmware's other static data with the strip's
 * pixels, the stack's deepest point and the sum of all these: the whole footprint;
 * the instructions of the method's first frame after its init, and those of posing
 * the objects and making the view before the frame counted, 0 for a still scene).
 * asm is counted on its second frame, when its tiles are cached, as a frame of a
 * running application would be. On the animated variant every method is: a first
 * frame at t = 0, then the ball posed at t = 1/30 (a 30 Hz frame's move) and the
 * frame counted, with what the move made the method redo (ref's objects' subtree,
 * asm's tiles under the ball's old and new boxes); the camera and the light stay
 * where they are at t = 0, so that the ball is all that moves.
 *
 * On the small scene and its animated variant at 160x120 the whole footprint must stay within WHOLE (256 KiB): the frame arena gets what om_frame_bytes calls with_bins, and the method
 * what its bytes query calls full where that fits the rest, else the rest (it
 * then works in smaller pieces); a method whose minimum does not fit prints "too big",
 * one whose footprint ends over prints "over its whole budget", and both fail the run.
 * The other rows (the default scene, a 462 KB scene arena; 320x240, whose strips
 * alone take 112 KB) are beyond that; there a method gets up to 256 KiB.
 *
 * Under qemu-system-arm -icount shift=0 the board's clock ticks one nanosecond per
 * instruction; the MPS2's CMSDK timer 0 (0x40000000) counts down at 25 MHz, so one
 * tick is 40 instructions. OM_CROSS_COUNT_ONLY="none sm" counts the methods it names
 * (the Cortex-M7 count) and OM_CROSS_COUNT_SMALL the small scene and its animated
 * variant alone; for profiling,
 * qemu's `-d exec,nochain,in_asm` log, summed per function, says where they go. The
 * strips go nowhere: a device would send them to its display, and the count is the
 * engine's. */
#define CMSDK_TIMER0 ((volatile uint32_t *)0x40000000u)
#ifndef OM_CROSS_WHOLE
#define OM_CROSS_WHOLE (256u << 10)
#endif
#define WHOLE ((size_t)OM_CROSS_WHOLE)
/* The stack the budget leaves room for; the run fails if it goes deeper. */
#define STACK_ROOM (24u << 10)
/* How much of the stack is painted to find its deepest point. */
#define STACK_PAINT (64u << 10)
#define PAINT 0x5AA5C33Cu

/* The linker script's ends of .data, .bss and the stack (platform/cortex-m/mps2.ld). */
extern uint32_t __data_start, __data_end, __bss_start, __bss_end, __stack_top;

static uint64_t count_now(void *user)
{
    (void)user;
    return (uint64_t)(0xFFFFFFFFu - CMSDK_TIMER0[1]) * 40u;
}

/* .data and .bss but for the three arenas' buffers and the animated scene's text (a
 * device's would be in flash): one strip's pixels at width w (the buffer has room for
 * the widest), the C library's and the driver's own (the engine has none:
 * tests/sh/freestanding.sh). */
static size_t static_bytes(uint32_t w)
{
    const size_t all = (size_t)((uintptr_t)&__data_end - (uintptr_t)&__data_start) +
                       (size_t)((uintptr_t)&__bss_end - (uintptr_t)&__bss_start);
    return all - sizeof scene_mem - sizeof method_mem - sizeof frame_mem - sizeof pixels - sizeof moving_buf +
           (size_t)w * OM_CROSS_ROWS * 2;
}

/* Whether the method is counted: every one, or those OM_CROSS_COUNT_ONLY names. */
static int counted(const char *name)
{
#ifdef OM_CROSS_COUNT_ONLY
    const char *l = OM_CROSS_COUNT_ONLY;
    const size_t n = strlen(name);
    for (;;) {
        while (*l == ' ') l++;
        if (!*l) return 0;
        size_t k = 0;
        while (l[k] && l[k] != ' ') k++;
        if (k == n && !strncmp(l, name, n)) return 1;
        l += k;
    }
#else
    (void)name;
    return 1;
#endif
}

/* The stack's lowest STACK_PAINT bytes, up to just below the caller, filled with PAINT;
 * stack_depth then finds the lowest word that changed. Both run between frames,
 * outside what is counted. */
static __attribute__((noinline)) void stack_paint(void)
{
    volatile uint32_t here = 0;
    volatile uint32_t *p = (volatile uint32_t *)((uintptr_t)&__stack_top - STACK_PAINT);
    const uintptr_t below = (uintptr_t)&here - 64;
    while ((uintptr_t)p < below) *p++ = PAINT;
}

static __attribute__((noinline)) size_t stack_depth(void)
{
    volatile uint32_t *p = (volatile uint32_t *)((uintptr_t)&__stack_top - STACK_PAINT);
    while (p < &__stack_top && *p == PAINT) p++;
    return (size_t)((uintptr_t)&__stack_top - (uintptr_t)p);
}

static void say(const char *what, const char *tag, const char *method)
{
    line l = {{0}, 0};
    put_s(&l, what);
    put_s(&l, ": ");
    put_s(&l, tag);
    put_s(&l, " ");
    put_s(&l, method);
    om_host_puts(l.buf);
}

/* The objects posed at t and the view made after them (a directional light's follows
 * the scene's bounds), the camera and light held at time 0, so that only the objects
 * move; non-zero where either fails. */
static int pose_view(om_scene *s, float t, const size_cfg *sz, om_view *v, om_diag *d)
{
    om_camera cam;
    om_light light;
    if (om_scene_pose_at(s, t, d) != OM_OK) return 1;
    om_scene_at(s, 0.0f, &cam, &light);
    cam.width = sz->w;
    cam.height = sz->h;
    return om_view_init(v, &cam, &light, s, d) != OM_OK;
}

/* moving: every method renders a first frame at t = 0 and is counted on the next, at
 * t = 1/30, the objects posed before it (the pose counted apart). */
static void count_scene(const char *tag, const char *text, uint32_t w, uint32_t h, int whole, int moving, int *bad)
{
    const size_cfg sz = {w, h, OM_CROSS_ROWS, 1, ""};
    om_arena sa;
    om_scene s;
    om_diag d;
    om_view v;
    if (!text) { om_host_puts("count: no animated scene (the small scene's ball line is gone)"); *bad = 1; return; }
    om_arena_init(&sa, scene_mem, sizeof scene_mem, "scene");
    if (om_scene_parse(text, strlen(text), NULL, &sa, &s, &d) != OM_OK) { *bad |= fail(tag, "-", "scene", &d); return; }
    if (pose_view(&s, 0.0f, &sz, &v, &d)) { *bad |= fail(tag, "-", "view", &d); return; }
    om_frame_desc q;   /* the frame size query: the strips with their bins, and the ids */
    om_frame_need need;
    memset(&q, 0, sizeof q);
    q.scene = &s; q.view = &v; q.strip_rows = sz.rows;
    if (om_frame_bytes(&q, &need) != OM_OK) { *bad |= fail(tag, "-", "frame bytes", &d); return; }
    const size_t frame_need = need.with_bins, ids = need.with_ids - need.with_jobs, stat = static_bytes(w);
    /* what a method may take: all that is left of WHOLE, or (default scene) 256 KiB */
    size_t room = sizeof method_mem;
    if (whole) {
        const size_t rest = sa.peak + frame_need + stat + STACK_ROOM;
        room = rest < WHOLE ? WHOLE - rest : 0;
        if (room > sizeof method_mem) room = sizeof method_mem;
    }
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        if (!counted(om_method_name(m))) continue;
        om_method_cfg cfg;
        method_cfg(&cfg, m, &sz, 0);
        size_t mn, full;
        om_arena ma, fa;
        void *state;
        if (om_method_bytes(m, &cfg, &s, sz.w, sz.h, &mn, &full) != OM_OK || mn > room) {
            say("too big", tag, om_method_name(m));
            *bad = 1;
            continue;
        }
        /* each method starts from the scene at t = 0 (the one before left it moved) */
        if (moving && pose_view(&s, 0.0f, &sz, &v, &d)) { *bad |= fail(tag, om_method_name(m), "pose", &d); continue; }
        stack_paint();
        om_arena_init(&ma, method_mem, full < room ? full : room, "method");
        if (om_method_init(m, &state, &ma, &cfg, &s, sz.w, sz.h, &d) != OM_OK) { *bad |= fail(tag, om_method_name(m), "init", &d); continue; }
        om_shade_cfg shade;
        om_shade_cfg_default(&shade);
        om_framebuffer fb = {OM_RGB565, sz.w, sz.rows, sz.w * 2, pixels};
        om_frame_desc fd;
        memset(&fd, 0, sizeof fd);
        fd.scene = &s; fd.view = &v; fd.method = m; fd.method_state = state; fd.shade = &shade;
        fd.strip_rows = sz.rows; fd.fb = &fb; fd.on_strip = NULL; fd.clock = count_now;
        om_frame_stats fs;
        uint64_t n = 0, first = 0, pose = 0;
        size_t frame_peak = 0;
        /* A method that observes passes over the image twice: on the small scene its
         * frame also gets room to keep the first pass's triangle ids where that leaves
         * the method its full arena (the default scene's frame arena has room) */
        size_t fbytes = frame_need;
        if (whole && (om_method_flags(m) & OM_METHOD_OBSERVES) && full + ids <= room) fbytes += ids;
        for (int f = 0; f < (moving || !strcmp(om_method_name(m), "asm") ? 2 : 1); f++) {
            if (f == 1 && moving) {
                const uint64_t p0 = count_now(NULL);
                if (pose_view(&s, 1.0f / 30.0f, &sz, &v, &d)) { *bad |= fail(tag, om_method_name(m), "pose", &d); n = 0; break; }
                pose = count_now(NULL) - p0;
            }
            om_arena_init(&fa, frame_mem, whole ? fbytes : sizeof frame_mem, "frame");
            const uint64_t t0 = count_now(NULL);
            if (om_render_frame(&fd, &fa, &fs, &d) != OM_OK) { *bad |= fail(tag, om_method_name(m), "render", &d); n = 0; break; }
            n = count_now(NULL) - t0;
            if (f == 0) first = n;
            if (fa.peak > frame_peak) frame_peak = fa.peak;
        }
        if (!n) continue;
        const size_t stack = stack_depth();
        const size_t all = sa.peak + frame_peak + ma.peak + stat + stack;
        line l = {{0}, 0};
        const uint64_t fig[] = {n, fs.ns_eye, fs.ns_observe, fs.ns_build, fs.ns_resolve, fs.ns_shade,
                                ma.peak, frame_peak, sa.peak, mn, stat, stack, all, first, pose};
        put_s(&l, "count ");
        put_s(&l, tag);
        put_s(&l, " ");
        put_dec(&l, w);
        put_s(&l, " ");
        put_dec(&l, h);
        put_s(&l, " ");
        put_s(&l, om_method_name(m));
        for (size_t i = 0; i < sizeof fig / sizeof fig[0]; i++) {
            put_s(&l, " ");
            put_dec(&l, fig[i]);
        }
        om_host_puts(l.buf);
        if (whole && (all > WHOLE || stack > STACK_ROOM)) {
            say(all > WHOLE ? "over its whole budget" : "stack deeper than its room", tag, om_method_name(m));
            *bad = 1;
        }
    }
}

int om_cross_main(void)
{
    int bad = 0;
    CMSDK_TIMER0[2] = 0xFFFFFFFFu;   /* reload */
    CMSDK_TIMER0[1] = 0xFFFFFFFFu;   /* value */
    CMSDK_TIMER0[0] = 1;             /* enable */
    count_scene("small", om_scene_small_text(), 160, 120, 1, 0, &bad);
    count_scene("small", om_scene_small_text(), 320, 240, 0, 0, &bad);
    count_scene("moving", moving_text(), 160, 120, 1, 1, &bad);
#ifndef OM_CROSS_COUNT_SMALL
    count_scene("default", om_scene_default_text(), 160, 120, 0, 0, &bad);
#endif
    return bad;
}
#else
/* Whether a method has AA or PCF settings (the default-aa case repeats only those). */
static int has_aa(const om_method *m)
{
    return om_method_setting(m, "pcf") || om_method_setting(m, "spsm.aa");
}

typedef struct xcase {
    const char *name;
    const char *text;     /* NULL: the default scene (or, with moving, moving_text) */
    int aa, aa_only;      /* AA/PCF settings on; only the methods that have them */
    float t0, t1;         /* t1 >= 0: a second frame at t1 with the same method state */
    int moving;           /* the camera and light held at t0; and a fresh state's frame
                             at t1 must give the same bits */
} xcase;

/* Renders one frame of the case into h: the objects posed at t, the camera and light
 * at tv. */
static om_status render(om_scene *s, const om_method *m, void *state, const size_cfg *sz,
                        float t, float tv, om_arena *fa, hashes *h, om_diag *d)
{
    om_camera cam;
    om_light light;
    om_view v;
    om_status st;
    if ((st = om_scene_pose_at(s, t, d)) != OM_OK) return st;
    om_scene_at(s, tv, &cam, &light);
    cam.width = sz->w;
    cam.height = sz->h;
    if ((st = om_view_init(&v, &cam, &light, s, d)) != OM_OK) return st;
    om_shade_cfg shade;
    om_shade_cfg_default(&shade);
    om_framebuffer fb = {OM_RGB565, sz->w, sz->rows, sz->w * 2, pixels};
    om_frame_desc fd;
    memset(&fd, 0, sizeof fd);
    fd.scene = s; fd.view = &v; fd.method = m; fd.method_state = state; fd.shade = &shade;
    fd.strip_rows = sz->rows; fd.fb = &fb; fd.on_strip = on_strip; fd.user = h;
    h->img = h->mask = OM_HASH_INIT;
    om_arena_init(fa, frame_mem, sizeof frame_mem, "frame");
    return om_render_frame(&fd, fa, NULL, d);
}

static void print_hashes(const char *cs, const char *method, const hashes *h)
{
    line l = {{0}, 0};
    put_s(&l, cs);
    put_s(&l, " ");
    put_s(&l, method);
    put_s(&l, " ");
    put_hex(&l, h->img);
    put_s(&l, " ");
    put_hex(&l, h->mask);
    om_host_puts(l.buf);
}

static int run_case(const xcase *c, const size_cfg *sz)
{
    om_arena sa;
    om_scene s;
    om_diag d;
    const char *text = c->moving ? moving_text() : c->text ? c->text : om_scene_default_text();
    if (!text) {
        om_host_puts("moving: no animated scene (the small scene's ball line is gone)");
        return 1;
    }
    char name[2][64];
    for (int k = 0; k < 2; k++) {
        line l = {{0}, 0};
        put_s(&l, c->name);
        if (c->t1 >= 0.0f) put_s(&l, k ? "-t1" : "-t0");
        put_s(&l, sz->tag);
        memcpy(name[k], l.buf, l.n + 1);
    }
    om_arena_init(&sa, scene_mem, sizeof scene_mem, "scene");
    if (om_scene_parse(text, strlen(text), NULL, &sa, &s, &d) != OM_OK) return fail(name[0], "-", "scene", &d);
    int bad = 0;
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        if (c->aa_only && !has_aa(m)) continue;
        om_method_cfg cfg;
        method_cfg(&cfg, m, sz, c->aa);
        size_t mn, full;
        om_arena ma, fa;
        void *state;
        if (om_method_bytes(m, &cfg, &s, sz->w, sz->h, &mn, &full) != OM_OK || mn > sizeof method_mem) {
            line l = {{0}, 0};
            put_s(&l, "too big: ");
            put_s(&l, name[0]);
            put_s(&l, " ");
            put_s(&l, om_method_name(m));
            om_host_puts(l.buf);
            bad = 1;
            continue;
        }
        /* one pass when it fits, else what there is: the result must not change; every
         * state starts on the scene at t0 */
        om_arena_init(&ma, method_mem, full < sizeof method_mem ? full : sizeof method_mem, "method");
        if (om_scene_pose_at(&s, c->t0, &d) != OM_OK) { bad |= fail(name[0], om_method_name(m), "pose", &d); continue; }
        if (om_method_init(m, &state, &ma, &cfg, &s, sz->w, sz->h, &d) != OM_OK) { bad |= fail(name[0], om_method_name(m), "init", &d); continue; }
        hashes h;
        if (render(&s, m, state, sz, c->t0, c->t0, &fa, &h, &d) != OM_OK) { bad |= fail(name[0], om_method_name(m), "render", &d); continue; }
        print_hashes(name[0], om_method_name(m), &h);
        if (c->t1 >= 0.0f) {
            const float tv1 = c->moving ? c->t0 : c->t1;
            if (render(&s, m, state, sz, c->t1, tv1, &fa, &h, &d) != OM_OK) { bad |= fail(name[1], om_method_name(m), "render", &d); continue; }
            print_hashes(name[1], om_method_name(m), &h);
            /* moved is baked: a fresh state on the scene as it now stands draws the
             * same (asm refines over frames: a fresh state's first frame differs) */
            if (c->moving && strcmp(om_method_name(m), "asm")) {
                hashes fresh;
                om_arena_init(&ma, method_mem, full < sizeof method_mem ? full : sizeof method_mem, "method");
                if (om_method_init(m, &state, &ma, &cfg, &s, sz->w, sz->h, &d) != OM_OK) {
                    bad |= fail(name[1], om_method_name(m), "fresh init", &d);
                } else if (render(&s, m, state, sz, c->t1, tv1, &fa, &fresh, &d) != OM_OK) {
                    bad |= fail(name[1], om_method_name(m), "fresh render", &d);
                } else if (fresh.img != h.img || fresh.mask != h.mask) {
                    line l = {{0}, 0};
                    put_s(&l, name[1]);
                    put_s(&l, " ");
                    put_s(&l, om_method_name(m));
                    put_s(&l, ": moved is not baked: a fresh state on the posed scene draws other bits");
                    om_host_puts(l.buf);
                    bad = 1;
                }
            }
        }
        if (!c->text && !c->aa && sz->w == 160) {   /* the embedded proof's figures */
            line l = {{0}, 0};
            put_s(&l, "bytes ");
            put_s(&l, om_method_name(m));
            put_s(&l, " ");
            put_dec(&l, ma.peak);
            put_s(&l, " min ");
            put_dec(&l, mn);
            om_host_puts(l.buf);
        }
    }
    return bad;
}

int om_cross_main(void)
{
    static const size_cfg sizes[] = {
        {160, 120, OM_CROSS_ROWS, 1, "@160x120"},
        {320, 240, OM_CROSS_ROWS, 1, "@320x240"},
#ifdef OM_CROSS_BIG
        {640, 480, 60, 0, "@640x480"},
#endif
    };
    static const xcase cases[] = {
        {"default", NULL, 0, 0, 0.0f, -1.0f, 0},
        {"default-aa", NULL, 1, 1, 0.0f, -1.0f, 0},
        {"cloud", cloud_text, 1, 0, 0.0f, -1.0f, 0},
        {"stab", stab_text, 1, 0, 0.0f, 0.5f, 0},
        {"moving", NULL, 1, 0, 0.0f, 0.5f, 1},
    };
#ifdef OM_CROSS_TRAPS
    /* On a board: set bits of the configuration and control register, to fault on
     * division by zero (0x10) and unaligned accesses (0x08). A Cortex-M0 has neither
     * a divide instruction nor unaligned accesses; its firmware runs on an M3 board
     * with both traps on, so that it faults where a real M0 would. */
    *(volatile uint32_t *)0xE000ED14u |= (uint32_t)(OM_CROSS_TRAPS);
#endif
    int bad = 0;
    for (size_t z = 0; z < sizeof sizes / sizeof sizes[0]; z++)
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
            if ((OM_CROSS_ONLY >> (5 * z + c)) & 1u) bad |= run_case(&cases[c], &sizes[z]);
    return bad;
}
#endif
