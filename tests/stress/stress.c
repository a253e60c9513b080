/* stress.c — `make stress`: every method on a small set of scenes under every budget
 * from 0 bytes up to its one-pass size — each byte around the documented minimum,
 * then coarser steps — with guard bytes before and after the arena. Each run must
 * either render within the method's accuracy contract or refuse with OM_E_BUDGET
 * naming the minimum; it must never touch a guard byte, and the engine must stay
 * usable: after every refusal, a run with the full budget renders the expected frame.
 *
 * Contracts: exact methods (ref, izb) equal the reference's mask at any budget; a
 * method whose minimum is its one-pass size renders the same mask whenever it runs;
 * methods that degrade by design (a smaller ASM cap) render with a mismatch share
 * against the reference of at most twice theirs at the full budget plus 1%. */
#include "../bench/bench.h"

#include <string.h>

#define GUARD 256
#define W 64
#define H 48

static int failures;

static void fail(const char *scene, const char *m, size_t budget, const char *what)
{
    failures++;
    printf("stress: FAIL %s / %s at %zu bytes: %s\n", scene, m, budget, what);
}

typedef struct ctx {
    const bscene *b;
    om_view v;
    uint8_t ref[W * H], full[W * H];
    double full_share;
} ctx;

static om_status grab(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)fb;
    uint8_t *mask = (uint8_t *)user;
    for (uint32_t i = 0; i < st->rows * st->width; i++)
        mask[st->y0 * st->width + i] = om_mask_of(&st->samples[i], &st->terms[i]);
    return OM_OK;
}

/* init + two frames in an arena of `budget` bytes with guards; returns the status. */
static om_status run(ctx *c, const om_method *m, const om_method_cfg *cfg, size_t budget,
                     uint8_t *mask, bool *guards_ok, om_diag *d)
{
    unsigned char *buf = malloc(budget + 2 * GUARD);
    static unsigned char fmem[W * 8 * 48];
    static uint8_t px[W * 8 * 2];
    memset(buf, 0x5C, budget + 2 * GUARD);
    om_arena ma, fa;
    om_arena_init(&ma, buf + GUARD, budget, "method");
    om_arena_init(&fa, fmem, sizeof fmem, "frame");
    void *state;
    om_status st = om_method_init(m, &state, &ma, cfg, &c->b->s, W, H, d);
    for (int f = 0; f < 2 && st == OM_OK; f++) {
        om_shade_cfg shade;
        om_shade_cfg_default(&shade);
        om_framebuffer fb = {OM_RGB565, W, 8, W * 2, px};
        om_frame_desc fd;
        memset(&fd, 0, sizeof fd);
        fd.scene = &c->b->s; fd.view = &c->v; fd.method = m; fd.method_state = state;
        fd.shade = &shade; fd.strip_rows = 8; fd.fb = &fb; fd.on_strip = grab; fd.user = mask;
        st = om_render_frame(&fd, &fa, NULL, d);
    }
    *guards_ok = true;
    for (size_t i = 0; i < GUARD; i++)
        if (buf[i] != 0x5C || buf[GUARD + budget + i] != 0x5C) *guards_ok = false;
    free(buf);
    return st;
}

static double share(const uint8_t *ref, const uint8_t *m)
{
    om_metrics mt;
    om_compare_masks(ref, m, W, H, &mt);
    return 1.0 - om_metrics_match(&mt);
}

static void stress_method(ctx *c, const om_method *m)
{
    om_method_cfg cfg;   /* small maps and structures, where m takes them */
    om_method_cfg_default(&cfg, m);
    om_method_cfg_set(&cfg, "map", 256, NULL);
    om_method_cfg_set(&cfg, "csm.map", 128, NULL);   /* four: the texels of one 256 map */
    om_method_cfg_set(&cfg, "asm.cap", 2u << 20, NULL);
    om_method_cfg_set(&cfg, "rtw.importance", 64, NULL);
    size_t mn, full;
    if (om_method_bytes(m, &cfg, &c->b->s, W, H, &mn, &full) != OM_OK) { fail(c->b->name, om_method_name(m), 0, "bytes query failed"); return; }
    om_diag d;
    bool guards;
    if (run(c, m, &cfg, full, c->full, &guards, &d) != OM_OK || !guards) {
        fail(c->b->name, om_method_name(m), full, "the full budget does not render");
        return;
    }
    bool exact = !strcmp(om_method_name(m), "ref") || !strcmp(om_method_name(m), "izb");
    if (exact && memcmp(c->full, c->ref, sizeof c->ref)) fail(c->b->name, om_method_name(m), full, "differs from the reference");
    c->full_share = share(c->ref, c->full);
    char minimum[32];
    snprintf(minimum, sizeof minimum, "%zu", mn);
    /* budgets: 0, a few below, every byte within 64 of the minimum, then geometric */
    size_t budgets[512];
    int nb = 0;
    budgets[nb++] = 0;
    budgets[nb++] = mn / 2;
    for (size_t b = mn > 64 ? mn - 64 : 0; b <= mn + 64 && nb < 200; b++) budgets[nb++] = b;
    for (size_t b = mn + 65; b < full && nb < 500; b += (b - mn) / 4 + 1) budgets[nb++] = b;
    budgets[nb++] = full;
    int runs = 0, refused = 0;
    uint8_t *mask = malloc(W * H);
    for (int k = 0; k < nb; k++) {
        size_t b = budgets[k];
        if (b > full) continue;
        memset(&d, 0, sizeof d);
        om_status st = run(c, m, &cfg, b, mask, &guards, &d);
        runs++;
        if (!guards) fail(c->b->name, om_method_name(m), b, "wrote outside its arena");
        if (st == OM_E_BUDGET) {
            refused++;
            if (b >= mn) fail(c->b->name, om_method_name(m), b, "refused a budget at or above its minimum");
            if (!strstr(d.msg, minimum)) fail(c->b->name, om_method_name(m), b, "the refusal does not name the minimum");
            /* the engine stays usable */
            uint8_t *again = malloc(W * H);
            if (run(c, m, &cfg, full, again, &guards, &d) != OM_OK || memcmp(again, c->full, W * H))
                fail(c->b->name, om_method_name(m), b, "not usable after a refusal");
            free(again);
        } else if (st != OM_OK) {
            fail(c->b->name, om_method_name(m), b, om_status_str(st));
        } else if (b < mn) {
            fail(c->b->name, om_method_name(m), b, "ran below its documented minimum (the minimum is too high)");
        } else if (exact ? memcmp(mask, c->ref, W * H) != 0
                         : mn == full ? memcmp(mask, c->full, W * H) != 0
                                      : share(c->ref, mask) > 2 * c->full_share + 0.01) {
            fail(c->b->name, om_method_name(m), b, "outside its accuracy contract");
        }
    }
    free(mask);
    printf("stress: %-12s %-5s minimum %9zu, full %9zu: %d budgets, %d refused\n", c->b->name,
           om_method_name(m), mn, full, runs, refused);
}

int main(void)
{
    static const char *const texts[][2] = {
        {"small", "camera eye 0 3 6 target 0 0.5 0\n"
                  "light spot pos 2 7 1 target 0 0 0 fov 70 near 1 far 40\n"
                  "plane size 10 10\nbox size 1 1 1 translate 0 0.5 0\n"
                  "sphere radius 0.4 segments 12 rings 6 translate 1.2 0.6 0.5 opacity 0.5\n"
                  "triangles count 30 seed 4 area 1 in -2 1 -2 2 2 2\n"},
        {"sun", "camera eye 2 5 7 target 0 0.5 0\nlight directional dir -0.3 -1 -0.4\n"
                "plane size 12 12 divisions 3\ncylinder radius 0.3 height 2 segments 12\n"
                "box size 2 0.1 2 translate 1 1.5 1\n"},
        {"default", NULL},
        /* issue 24: huge triangles over the whole light map, each budget with and
         * without room for the maps' coarse depth */
        {"huge", "camera eye 0 2 5 target 0 0 0\n"
                 "light spot pos 2 7 1 target 0 0 0 fov 70 near 1 far 40\n"
                 "plane size 8 8\ntriangles count 300 area 1e12 in 0 0 0 0 0 0\n"},
    };
    for (size_t k = 0; k < sizeof texts / sizeof texts[0]; k++) {
        bscene b;
        if (bench_load(&b, texts[k][0], texts[k][1] ? texts[k][1] : om_scene_default_text())) return 1;
        ctx *c = calloc(1, sizeof *c);
        c->b = &b;
        om_camera cam;
        om_light light;
        om_scene_at(&b.s, 0, &cam, &light);
        cam.width = W;
        cam.height = H;
        if (om_view_init(&c->v, &cam, &light, &b.s, NULL) != OM_OK) return 1;
        bool guards;
        om_diag d;
        om_method_cfg cfg;
        size_t mn, full;
        const om_method *ref = om_method_find("ref");
        om_method_cfg_default(&cfg, ref);
        om_method_bytes(ref, &cfg, &b.s, W, H, &mn, &full);
        if (run(c, ref, &cfg, full, c->ref, &guards, &d) != OM_OK) return 1;
        for (size_t i = 0; i < om_method_count(); i++) stress_method(c, om_method_at(i));
        free(c);
        bench_free(&b);
    }
    printf("stress: %s (%d failures)\n", failures ? "FAIL" : "ok", failures);
    return failures != 0;
}
