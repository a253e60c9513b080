/* driver.c — the cross-CPU determinism driver: renders the default scene at 160x120
 * with every method, through strips of 8 rows into an RGB565 framebuffer, and prints
 * one line per method: its name and the FNV-1a hashes of the frame and of the shadow
 * mask, then a "bytes" line with its arena's peak (which depends on pointer size).
 * `make cross-test` builds it with every compiler and CPU it can find and checks
 * that all the hash lines agree. It needs nothing but the engine
 * and a way to print a line (om_host_puts, from the host file it is linked with). */
#include "ombra.h"

#include <string.h>

void om_host_puts(const char *line);

#define W 160
#define H 120
#define ROWS 8

#ifndef OM_CROSS_METHOD_MEM
#define OM_CROSS_METHOD_MEM (24u << 20)
#endif
#ifndef OM_CROSS_SCENE_MEM
#define OM_CROSS_SCENE_MEM (1u << 20)
#endif

static unsigned char scene_mem[OM_CROSS_SCENE_MEM];
static unsigned char method_mem[OM_CROSS_METHOD_MEM];
static unsigned char frame_mem[W * ROWS * 48];
static uint8_t pixels[W * ROWS * 2];

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

static void put_hex(char *out, uint64_t v)
{
    for (int i = 15; i >= 0; i--) {
        out[i] = "0123456789abcdef"[v & 15];
        v >>= 4;
    }
    out[16] = '\0';
}

static void put_dec(char *out, uint64_t v)
{
    char tmp[24];
    int n = 0;
    do { tmp[n++] = (char)('0' + v % 10); v /= 10; } while (v);
    for (int i = 0; i < n; i++) out[i] = tmp[n - 1 - i];
    out[n] = '\0';
}

static int fail(const char *what, const om_diag *d)
{
    char line[256];
    size_t n = strlen(what);
    memcpy(line, what, n);
    line[n++] = ':';
    line[n++] = ' ';
    size_t m = strlen(d->msg);
    if (m > sizeof line - n - 1) m = sizeof line - n - 1;
    memcpy(line + n, d->msg, m);
    line[n + m] = '\0';
    om_host_puts(line);
    return 1;
}

int om_cross_main(void)
{
    om_arena sa;
    om_scene s;
    om_diag d;
    const char *text = om_scene_default_text();
    om_arena_init(&sa, scene_mem, sizeof scene_mem, "scene");
    if (om_scene_parse(text, strlen(text), NULL, &sa, &s, &d) != OM_OK) return fail("scene", &d);
    om_camera cam;
    om_light light;
    om_view v;
    om_scene_at(&s, 0.0f, &cam, &light);
    cam.width = W;
    cam.height = H;
    if (om_view_init(&v, &cam, &light, &s, &d) != OM_OK) return fail("view", &d);
    int bad = 0;
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        /* One configuration everywhere (the hashes must agree), small enough for small
         * machines: the bytes lines say which methods fit 256 KiB. */
        om_method_cfg cfg;
        om_method_cfg_default(&cfg);
        cfg.map_size = 96;
        cfg.asm_cap = 192u << 10;
        cfg.rtw_importance = 64;
        size_t mn, full;
        om_arena ma, fa;
        void *state;
        if (m->bytes(&cfg, &s, W, H, &mn, &full) != OM_OK || mn > sizeof method_mem) {
            char line[96] = "too big: ";
            memcpy(line + 9, m->name, strlen(m->name) + 1);
            om_host_puts(line);
            bad = 1;
            continue;
        }
        /* one pass when it fits, else what there is: the result must not change */
        om_arena_init(&ma, method_mem, full < sizeof method_mem ? full : sizeof method_mem, "method");
        om_arena_init(&fa, frame_mem, sizeof frame_mem, "frame");
        if (m->init(&state, &ma, &cfg, &s, W, H, &d) != OM_OK) { bad |= fail(m->name, &d); continue; }
        om_shade_cfg shade;
        om_shade_cfg_default(&shade);
        om_framebuffer fb = {OM_RGB565, W, ROWS, W * 2, pixels};
        hashes h = {OM_HASH_INIT, OM_HASH_INIT};
        om_frame_desc fd;
        memset(&fd, 0, sizeof fd);
        fd.scene = &s; fd.view = &v; fd.method = m; fd.method_state = state; fd.shade = &shade;
        fd.strip_rows = ROWS; fd.fb = &fb; fd.on_strip = on_strip; fd.user = &h;
        if (om_render_frame(&fd, &fa, NULL, &d) != OM_OK) { bad |= fail(m->name, &d); continue; }
        char line[128], num[24];
        size_t n = strlen(m->name);
        memcpy(line, m->name, n);
        line[n++] = ' ';
        put_hex(line + n, h.img);
        n += 16;
        line[n++] = ' ';
        put_hex(line + n, h.mask);
        line[n + 16] = '\0';
        om_host_puts(line);
        memcpy(line, "bytes ", 6);
        memcpy(line + 6, m->name, strlen(m->name));
        n = 6 + strlen(m->name);
        line[n++] = ' ';
        put_dec(num, ma.peak);
        memcpy(line + n, num, strlen(num));
        n += strlen(num);
        memcpy(line + n, " min ", 5);
        n += 5;
        put_dec(num, mn);
        memcpy(line + n, num, strlen(num) + 1);
        om_host_puts(line);
    }
    return bad;
}
