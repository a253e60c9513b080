/* method/asm.c — Adaptive Shadow Maps (issue 5): the tree's rules driven directly (pool,
 * LRU among nodes not used last frame, replacement only by greater benefit, subtrees go
 * with their node, the descent), the memory cap along camera paths for caps from the
 * smallest usable to generous, progressive refinement of a still view against the
 * reference and the conventional map of the same memory, budgets that name their
 * minimum, and bit-identical frames (strips included). On threads: a kept state's
 * frames, counters and tree the same on 1 to 16 threads (asm_bands), and observe and the
 * tile renders on lent slots leaving the tree one thread leaves (asm_jobs_tree). */
#include "../test.h"
#include "../harness.h"
#include "../jobs_util.h"
#include "../../engine/shadow/method.h"
#include "../../engine/shadow/asm/asm.h"

#include <stdlib.h>
#include <math.h>

/* The tree's layout for a configuration of the method (asm.c reads it the same way). */
static om_status layout_of(om__asm_layout *l, const om_method_cfg *c, uint32_t ntris)
{
    om__asm_cfg t;
    om_status st = om__method_cfg_of(c, om_method_find("asm"), &t, NULL);
    return st ? st : om__asm_layout_of(l, &t, ntris, NULL);
}

static uint64_t cap_of(const om_method_cfg *c)
{
    double v = 0;
    CHECK_OK(om_method_cfg_get(c, "asm.cap", &v));
    return (uint64_t)v;
}

/* One ASM state kept across frames, as a host keeps it. */
typedef struct arun {
    const om_scene *s;
    const om_method *m;
    void *mem, *fmem, *px, *state;
    size_t bytes;
    uint32_t W, H;
} arun;

/* A state in the bytes a single fast pass needs, or with `lean` in the minimum (2: and
 * room for the lean mode's bounds of chunks of 8 triangles, 2 bytes a triangle). */
static bool arun_init(arun *r, const om_scene *s, const om_method_cfg *c, uint32_t W, uint32_t H,
                      int lean)
{
    size_t mn, full;
    om_diag d;
    memset(r, 0, sizeof *r);
    r->s = s;
    r->m = om_method_find("asm");
    r->W = W;
    r->H = H;
    if (!r->m) { CHECK_MSG(0, "asm is not registered"); return false; }
    CHECK_OK(om_method_bytes(r->m, c, s, W, H, &mn, &full));
    CHECK(mn <= full);
    const size_t most = full;
    if (lean) full = mn + (lean == 2 ? 2 * (size_t)s->ntris + 64 : 0);
    CHECK(full <= most);
    r->bytes = full;
    r->mem = malloc(full);
    r->fmem = malloc(h_frame_least(W, H));
    r->px = malloc((size_t)W * H * 3);
    om_arena a;
    om_arena_init(&a, r->mem, full, "method");
    om_status st = om_method_init(r->m, &r->state, &a, c, s, W, H, &d);
    CHECK_MSG(st == OM_OK, "asm init: %s", d.msg);
    CHECK(a.peak <= full);
    return st == OM_OK;
}

static void arun_free(arun *r)
{
    free(r->mem);
    free(r->fmem);
    free(r->px);
}

typedef struct agrab { uint8_t *mask; om_term *terms; } agrab;

static om_status agrab_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    agrab *g = (agrab *)user;
    (void)fb;
    for (uint32_t i = 0; i < st->rows * st->width; i++) {
        size_t o = (size_t)st->y0 * st->width + i;
        if (g->mask) g->mask[o] = om_mask_of(&st->samples[i], &st->terms[i]);
        if (g->terms) g->terms[o] = st->terms[i];
    }
    return OM_OK;
}

/* A frame with the camera at time t and the light at time tl. */
static om_status arun_frame(arun *r, float t, float tl, uint32_t strip, uint8_t *mask, om_term *terms,
                            om_method_stats *ms)
{
    om_camera cam, c2;
    om_light light, l2;
    om_view v;
    om_diag d;
    om_scene_at(r->s, t, &cam, &l2);
    om_scene_at(r->s, tl, &c2, &light);
    cam.width = r->W;
    cam.height = r->H;
    om_status st = om_view_init(&v, &cam, &light, r->s, &d);
    if (st) return st;
    uint32_t rows = strip ? strip : r->H;
    om_arena fa;
    om_arena_init(&fa, r->fmem, h_frame_least(r->W, rows), "frame");
    om_framebuffer fb = {OM_RGB888, r->W, rows, (size_t)r->W * 3, (uint8_t *)r->px};
    om_shade_cfg shade;
    agrab g = {mask, terms};
    om_frame_desc fd;
    h_frame_desc(&fd, &shade, r->s, &v, r->m, r->state, &fb, strip);
    fd.on_strip = agrab_strip; fd.user = &g;
    st = om_render_frame(&fd, &fa, NULL, &d);
    if (st) fprintf(stderr, "  (asm frame: %s)\n", d.msg);
    if (ms) om_method_get_stats(r->m, r->state, ms);
    return st;
}

static uint32_t counter(const om_method_stats *ms, const char *name)
{
    for (uint32_t k = 0; k < ms->ncounters; k++)
        if (!strcmp(ms->counter_names[k], name)) return ms->counters[k];
    CHECK_MSG(0, "no counter '%s'", name);
    return 0;
}

/* ---- the tree alone */

static void small_cfg(om_method_cfg *c, uint32_t nodes)
{
    om_method_cfg_default(c, om_method_find("asm"));
    CHECK_OK(om_method_cfg_set(c, "asm.root", 64, NULL));
    CHECK_OK(om_method_cfg_set(c, "asm.tile", 16, NULL));
    CHECK_OK(om_method_cfg_set(c, "asm.cells", 4, NULL));
    om__asm_layout l;
    layout_of(&l, c, 100);
    CHECK_OK(om_method_cfg_set(c, "asm.cap", l.root_bytes + (uint64_t)nodes * l.node_bytes, NULL));
}

static void tree_layout(void)
{
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("asm"));
    om__asm_layout l;
    CHECK_OK(layout_of(&l, &c, 22984));
    CHECK_EQ_U(l.cp, 8);
    CHECK_EQ_U(l.base_cells, 16);   /* 16 x 16 root tiles of 64 make the 1024 root */
    CHECK_EQ_U(l.base_cp, 4);
    CHECK_EQ_U(l.max_level, 4);     /* level 4: 1024 * 8^3 = 524,288 <= 2^21 < 1024 * 8^4 */
    CHECK(om__asm_grid(&l, 0) == 64 && om__asm_grid(&l, 1) == 1024 && om__asm_grid(&l, 4) == 524288);
    CHECK(l.min_cap < (64u << 10));   /* the base and one tile: small devices can run it */
    CHECK(l.id16);
    CHECK(l.count > 100 && l.root_bytes + (uint64_t)l.count * l.node_bytes <= cap_of(&c));
    CHECK(l.root_bytes + (uint64_t)(l.count + 1) * l.node_bytes > cap_of(&c));
    CHECK_OK(layout_of(&l, &c, 70000));
    CHECK(!l.id16);
    CHECK_OK(om_method_cfg_set(&c, "asm.cells", 5, NULL));   /* 64 is not a multiple of 5 */
    CHECK(layout_of(&l, &c, 10) == OM_E_INVALID);
    CHECK_OK(om_method_cfg_set(&c, "asm.cells", 8, NULL));
    CHECK_OK(om_method_cfg_set(&c, "asm.root", 1000, NULL));   /* not a multiple of the tile */
    CHECK(layout_of(&l, &c, 10) == OM_E_INVALID);
    CHECK_OK(om_method_cfg_set(&c, "asm.root", 64 * 3, NULL));   /* 3 root tiles a side do not divide a 64-texel base */
    CHECK(layout_of(&l, &c, 10) == OM_E_INVALID);
}

static void tree_rules(void)
{
    om_method_cfg c;
    small_cfg(&c, 3);
    om__asm_layout l;
    CHECK_OK(layout_of(&l, &c, 100));
    CHECK_EQ_U(l.count, 3);
    CHECK_EQ_U(l.base_cells, 4);   /* a 16-texel base of 4 x 4 cells; root tiles make 64 */
    CHECK_EQ_U(l.max_level, 8);    /* 64 * 4^7 <= 2^21 */
    unsigned char *mem = malloc(l.arena_bytes);
    om_arena a;
    om_arena_init(&a, mem, l.arena_bytes, "tree");
    om__asm_tree t;
    CHECK_OK(om__asm_tree_init(&t, &a, &l, NULL));
    CHECK(a.peak <= l.arena_bytes);
    om__asm_frame(&t);
    /* three nodes: two root tiles, one under the first */
    uint32_t n0 = om__asm_make(&t, OM__ASM_ROOT, 5, 5);    /* base cell (1, 1) */
    uint32_t n1 = om__asm_make(&t, OM__ASM_ROOT, 10, 9);   /* base cell (2, 2) */
    CHECK(n0 != OM__ASM_NONE && n1 != OM__ASM_NONE);
    CHECK(om__asm_make(&t, OM__ASM_ROOT, 5, 99) == OM__ASM_NONE);   /* cell taken */
    uint32_t n2 = om__asm_make(&t, n0, 5, 4);
    CHECK(n2 != OM__ASM_NONE);
    CHECK_EQ_U(om__asm_node_at(&t, n2)->level, 2);
    CHECK_EQ_U(om__asm_depth(&t), 2);
    CHECK_EQ_U(om__asm_bytes_in_use(&t), cap_of(&c));
    /* n0 covers base texels [4, 8) x [4, 8): texels [16, 32) of the 64-texel root */
    CHECK_EQ_U(om__asm_node_at(&t, n0)->ox, 16);
    CHECK_EQ_U(om__asm_node_at(&t, n0)->oy, 16);
    /* n2 is cell (1, 1) of n0: root texels [20, 24), origin 80 on level 2's grid */
    CHECK_EQ_U(om__asm_node_at(&t, n2)->ox, 80);
    uint32_t tx, ty;
    CHECK_EQ_U(om__asm_find(&t, 5.5, 5.25, false, &tx, &ty), n2);   /* 88 - 80 = 8, 84 - 80 = 4 */
    CHECK_EQ_U(tx, 8);
    CHECK_EQ_U(ty, 4);
    CHECK_EQ_U(om__asm_find(&t, 6.5, 4.25, false, &tx, &ty), n0);   /* cell (2, 0) of n0 is empty */
    CHECK_EQ_U(om__asm_find(&t, 14.5, 2.5, false, &tx, &ty), OM__ASM_ROOT);
    CHECK(tx == 14 && ty == 2);

    /* Full, and every node used this frame: only a greater benefit replaces a leaf,
     * the least beneficial one (n2, benefit 4), never the parent of the new node. */
    CHECK(om__asm_make(&t, OM__ASM_ROOT, 3, 4) == OM__ASM_NONE);
    uint32_t n3 = om__asm_make(&t, n1, 0, 5);
    CHECK(n3 != OM__ASM_NONE);
    CHECK(!om__asm_node_at(&t, n2)->alive || om__asm_node_at(&t, n2)->parent != n0);
    CHECK_EQ_U(t.replaced, 1);
    CHECK_EQ_U(om__asm_node_at(&t, n1)->nchild, 1);
    CHECK_EQ_U(om__asm_node_at(&t, n0)->nchild, 0);
    /* n1 (benefit 9) has a child and n3's parent is n1: the only leaves left are n0 (5)
     * and n3 (5); a benefit of 5 replaces neither */
    CHECK(om__asm_make(&t, OM__ASM_ROOT, 3, 5) == OM__ASM_NONE);

    /* Two frames later with only n1 and n3 used in between: n0 was not used in the last
     * frame, so it goes first (least recently used), whatever the benefits. */
    om__asm_frame(&t);
    om__asm_find(&t, 8.25, 8.25, true, &tx, &ty);   /* root texel 33: n1, its cell 0: n3 */
    om__asm_frame(&t);
    CHECK_EQ_U(om__asm_find(&t, 8.25, 8.25, true, &tx, &ty), n3);
    uint32_t n4 = om__asm_make(&t, OM__ASM_ROOT, 15, 1);
    CHECK(n4 != OM__ASM_NONE);
    CHECK(om__asm_find(&t, 5.5, 5.25, false, &tx, &ty) == OM__ASM_ROOT);   /* n0 is gone */
    CHECK_EQ_U(t.evicted, 1);
    CHECK(om__asm_bytes_in_use(&t) <= cap_of(&c));

    /* A subtree leaves with its root node. */
    om__asm_evict(&t, n1);
    CHECK_EQ_U(t.pool.in_use, 1);
    CHECK_EQ_U(t.root.nchild, 1);
    om__asm_tree_clear(&t);
    CHECK_EQ_U(t.pool.in_use, 0);
    CHECK_EQ_U(t.root.nchild, 0);
    free(mem);
}

static void tree_candidates_order(void)
{
    om_method_cfg c;
    small_cfg(&c, 4);
    om__asm_layout l;
    CHECK_OK(layout_of(&l, &c, 100));
    unsigned char *mem = malloc(l.arena_bytes);
    om_arena a;
    om_arena_init(&a, mem, l.arena_bytes, "tree");
    om__asm_tree t;
    CHECK_OK(om__asm_tree_init(&t, &a, &l, NULL));
    om__asm_frame(&t);
    uint32_t n0 = om__asm_make(&t, OM__ASM_ROOT, 5, 2);
    CHECK(n0 != OM__ASM_NONE);
    om__asm_tile tl;
    om__asm_tile_of(&t, n0, &tl);
    tl.ben[3] = 10; tl.need[3] = 16;      /* cost 1 + 16 / 4096 */
    tl.ben[7] = 10; tl.need[7] = 1e6f;    /* capped at 256 texels */
    tl.ben[9] = 2; tl.need[9] = 16;
    tl.ben[11] = 10; tl.need[11] = 16;    /* ties with cell 3: lower cell first */
    CHECK(om__asm_make(&t, n0, 9, 2) != OM__ASM_NONE);
    om__asm_cand h[64];
    uint32_t n = om__asm_candidates(&t, false, 1.0f / 4096, 1.0f, h, 64);
    CHECK_EQ_U(n, 3);   /* cell 9 holds a child now */
    om__asm_cand b;
    n = om__asm_cand_pop(h, n, &b);
    CHECK_EQ_U(b.cell, 3);
    n = om__asm_cand_pop(h, n, &b);
    CHECK_EQ_U(b.cell, 11);
    n = om__asm_cand_pop(h, n, &b);
    CHECK_EQ_U(b.cell, 7);
    CHECK(fabsf(b.cost - (1.0f + 256.0f / 4096.0f)) < 1e-6f);
    CHECK_EQ_U(n, 0);
    /* root tiles to make: by samples, whatever the costs */
    t.root_ben[2] = 5;
    t.root_ben[5] = 50;   /* holds n0 already */
    t.root_ben[12] = 9;
    n = om__asm_candidates(&t, true, 1.0f, 1.0f, h, 64);
    CHECK_EQ_U(n, 2);
    n = om__asm_cand_pop(h, n, &b);
    CHECK_EQ_U(b.cell, 12);
    CHECK_EQ_U(b.node, OM__ASM_ROOT);
    free(mem);
}

/* ---- the method */

static void budgets_name_minimum(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    const om_method *m = om_method_find("asm");
    if (!m) { CHECK_MSG(0, "asm is not registered"); return; }
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("asm"));
    om__asm_layout l;
    CHECK_OK(layout_of(&l, &c, hs.s.ntris));
    /* a cap below one root node (and one child) */
    CHECK_OK(om_method_cfg_set(&c, "asm.cap", l.min_cap - 1, NULL));
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, 160, 120, &mn, &full));
    void *buf = malloc(full), *state;
    om_arena a;
    om_diag d;
    om_arena_init(&a, buf, full, "method");
    CHECK(om_method_init(m, &state, &a, &c, &hs.s, 160, 120, &d) == OM_E_BUDGET);
    char num[32];
    snprintf(num, sizeof num, "%llu", (unsigned long long)l.min_cap);
    CHECK_MSG(strstr(d.msg, num) != NULL, "'%s' does not name %s", d.msg, num);
    CHECK_EQ_U(d.asked, l.min_cap);
    free(buf);
    /* the smallest cap works; an arena below the minimum names the minimum, which the
     * lean mode needs: the cap and a tile of scratch, nothing per vertex or triangle */
    CHECK_OK(om_method_cfg_set(&c, "asm.cap", l.min_cap, NULL));
    CHECK_OK(om_method_bytes(m, &c, &hs.s, 160, 120, &mn, &full));
    CHECK(mn < full);
    CHECK(mn < l.arena_bytes + 64 * 1024);
    unsigned char *g = malloc(mn + 64);
    memset(g, 0xA5, mn + 64);
    om_arena_init(&a, g + 32, mn - 1, "method");
    CHECK(om_method_init(m, &state, &a, &c, &hs.s, 160, 120, &d) == OM_E_BUDGET);
    snprintf(num, sizeof num, "%zu", mn);
    CHECK_MSG(strstr(d.msg, num) != NULL, "'%s' does not name %s", d.msg, num);
    om_arena_init(&a, g + 32, mn, "method");
    CHECK_OK(om_method_init(m, &state, &a, &c, &hs.s, 160, 120, &d));
    CHECK(a.peak <= mn);
    int guard = 0;
    for (int i = 0; i < 32; i++) guard += g[i] != 0xA5 || g[32 + mn + i] != 0xA5;
    CHECK_EQ_U(guard, 0);
    free(g);
    h_scene_free(&hs);
}

/* The default scene's layout and paths with coarser curved shapes (about 2K triangles),
 * so that hundreds of frames stay quick under -O0 and the sanitizers. */
static const char *light_scene =
    "camera eye 0 2.5 12 target 0 0.8 0 fov 55 size 160 120 near 0.1 far 200\n"
    "light spot pos 40 40 -60 target -3 0 3 fov 70 near 20 far 200\n"
    "plane size 60 60 divisions 8\n"
    "box size 4 4 4 translate -7 2 -8\n"
    "box size 1 1 1 rotate 0 25 0 translate 2 0.5 -4\n"
    "box size 0.8 2 0.8 rotate 0 -15 0 translate 6 1 -2\n"
    "sphere radius 1.2 segments 24 rings 12 translate 0 1.2 -2\n"
    "cylinder radius 0.4 height 3 segments 24 translate 3.5 0 -0.5\n"
    "box size 0.2 0.2 0.2 translate -1 0.1 3\n"
    "box size 0.2 0.2 0.2 rotate 0 30 0 translate -1 0.3 3\n"
    "sphere radius 0.25 segments 16 rings 8 translate 1.8 0.25 1.5\n"
    "box size 0.05 1.2 0.05 translate -6.0 0.6 0.5\n"
    "box size 0.05 1.2 0.05 translate -5.4 0.6 0.5\n"
    "box size 0.05 1.2 0.05 translate -4.8 0.6 0.5\n"
    "box size 2.8 0.05 0.05 translate -4.65 1.175 0.5\n"
    "box size 1.6 1.6 0.05 rotate 0 40 0 translate 1.5 0.8 -0.5 opacity 0.5\n"
    "key camera 0 eye 0 2.5 12 target 0 0.8 0\n"
    "key camera 1 eye 7 2.2 9 target 0 0.8 -1\n"
    "key camera 2 eye 11 2.8 1 target 0 0.8 -2\n"
    "key camera 3 eye 8 3.5 -10 target 0 0.8 -3\n"
    "key camera 4 eye 0 4 -14 target 0 0.8 -2\n"
    "key light 0 pos 40 40 -60 target -3 0 3\n"
    "key light 4 pos 46 40 -55 target -3 0 3\n";

/* Over 60 frames of the walkthrough, for caps from the smallest usable to generous:
 * every frame renders and bytes in use never pass the cap — with the scene's own
 * drifting light (a rebuild every frame) and with the light held still, where the
 * tree persists and a tight cap must evict as the camera moves. */
static void cap_holds_along_path(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, light_scene)) return;
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("asm"));
    CHECK_OK(om_method_cfg_set(&c, "asm.root", 512, NULL));   /* the paper's; a quarter of the root to re-render per frame */
    om__asm_layout l;
    CHECK_OK(layout_of(&l, &c, hs.s.ntris));
    const uint64_t caps[4] = {l.min_cap, l.min_cap + 8 * l.node_bytes, l.min_cap + 64 * l.node_bytes,
                              64u << 20};
    static uint8_t mask[160 * 120];
    for (int held = 0; held < 2; held++)
        for (int k = 0; k < 4; k++) {
            if (!held && (k == 1 || k == 2)) continue;   /* the tree is dropped every frame */
            CHECK_OK(om_method_cfg_set(&c, "asm.cap", caps[k], NULL));
            arun r;
            if (!arun_init(&r, &hs.s, &c, 160, 120, false)) continue;
            uint32_t worst = 0, evicted = 0, most = 0, failed = 0;
            for (int f = 0; f < 60; f++) {
                float t = 4.0f * (float)f / 59.0f;
                om_method_stats ms;
                if (arun_frame(&r, t, held ? 0.0f : t, 0, mask, NULL, &ms) != OM_OK) { failed++; continue; }
                uint32_t b = counter(&ms, "bytes in use");
                if (b > worst) worst = b;
                if (counter(&ms, "nodes") > most) most = counter(&ms, "nodes");
                if (held) evicted += counter(&ms, "evicted");
            }
            CHECK_MSG(failed == 0, "cap %llu: %u frames failed", (unsigned long long)caps[k], failed);
            CHECK_MSG(worst <= caps[k], "cap %llu: %u bytes in use", (unsigned long long)caps[k], worst);
            CHECK(most >= 1);
            /* a held light with a tight cap: the pool fills and nodes are evicted */
            if (held && k < 2) CHECK_MSG(evicted > 0, "cap %llu: nothing evicted", (unsigned long long)caps[k]);
            arun_free(&r);
        }
    h_scene_free(&hs);
}

/* A still view refines progressively: mismatches against the reference never grow
 * from frame to frame, fall, and end well below the conventional map of the same
 * memory (16 MiB: a 2048 x 2048 map of 32-bit depth). */
static void still_view_converges(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    enum { SW = 320, SH = 240 };
    static uint8_t ref[SW * SH], sm[SW * SH], m[SW * SH];
    for (int view = 0; view < 2; view++) {
        float t = view ? 2.0f : 0.0f;
        CHECK_OK(h_render(&hs.s, "ref", NULL, SW, SH, t, 0, ref, NULL, NULL));
        om_method_cfg smc = h_cfg("sm", "map=2048"), c = h_cfg("asm", "");
        CHECK_OK(h_render(&hs.s, "sm", &smc, SW, SH, t, 0, sm, NULL, NULL));
        om_metrics mt;
        om_compare_masks(ref, sm, SW, SH, &mt);
        uint64_t sm_bad = mt.false_lit + mt.false_shadowed;
        CHECK_EQ_U(cap_of(&c), (uint64_t)2048 * 2048 * 4);
        CHECK_OK(om_method_cfg_set(&c, "asm.work", 8, NULL));   /* a few nodes a frame, so refinement spans several frames */
        arun r;
        if (!arun_init(&r, &hs.s, &c, SW, SH, false)) continue;
        uint64_t prev = UINT64_MAX, first = 0;
        uint32_t eff = 0;
        for (int f = 0; f < 10; f++) {
            om_method_stats ms;
            CHECK_OK(arun_frame(&r, t, t, 0, m, NULL, &ms));
            om_compare_masks(ref, m, SW, SH, &mt);
            CHECK_EQ_U(mt.mismatched_bg, 0);
            uint64_t bad = mt.false_lit + mt.false_shadowed;
            CHECK_MSG(bad <= prev, "t %.0f frame %d: %llu mismatches, up from %llu", t, f,
                      (unsigned long long)bad, (unsigned long long)prev);
            if (f == 0) first = bad;
            prev = bad;
            eff = counter(&ms, "effective resolution");
        }
        CHECK_MSG(prev < first, "t %.0f: no progress (%llu)", t, (unsigned long long)prev);
        CHECK_MSG(prev * 3 < sm_bad * 2, "t %.0f: asm %llu mismatches, sm 2048 %llu", t,
                  (unsigned long long)prev, (unsigned long long)sm_bad);
        CHECK_MSG(eff >= 8192, "t %.0f: effective resolution %u", t, eff);
        arun_free(&r);
    }
    h_scene_free(&hs);
}

/* Identical runs give identical frames; strips give the frames the whole image gives;
 * the lean mode (the minimum bytes: no per-vertex or per-triangle arrays) gives the
 * frames the fast mode gives. */
static void runs_are_bit_identical(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    enum { BW = 200, BH = 150 };
    static om_term terms[3][BW * BH];
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("asm"));
    CHECK_OK(om_method_cfg_set(&c, "asm.cap", 8u << 20, NULL));
    arun r[3];
    for (int k = 0; k < 3; k++)
        if (!arun_init(&r[k], &hs.s, &c, BW, BH, k == 1)) return;
    int differ = 0;
    for (int f = 0; f < 8; f++) {
        float t = 0.4f * (float)(f / 2);   /* each view twice: a rebuild, then a refinement */
        for (int k = 0; k < 3; k++)
            CHECK_OK(arun_frame(&r[k], t, 0.0f, k == 2 ? 7 : 0, NULL, terms[k], NULL));
        differ += memcmp(terms[0], terms[1], sizeof terms[0]) != 0;
        differ += memcmp(terms[0], terms[2], sizeof terms[0]) != 0;
    }
    CHECK_EQ_U(differ, 0);
    for (int k = 0; k < 3; k++) arun_free(&r[k]);
    h_scene_free(&hs);
}

/* Settings at their edges still give frames: no refinement at all, every sample
 * analysed, one cell per node, a light that moves every frame. */
static void odd_settings_render(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 3 6 target 0 0 0 size 80 60\n"
                            "light spot pos 1 6 1 target 0 0 0 fov 120 near 0.5 far 50\n"
                            "plane size 10 10\nbox size 1 1 1 translate 0 0.5 0\n"
                            "triangles count 50 seed 2 area 3 in -2 0.2 -2 2 2 2\n"
                            "key light 0 pos 1 6 1 target 0 0 0\nkey light 1 pos -3 5 0 target 0 0 0\n"))
        return;
    static const char *sets[][2] = {{"asm.work", "0"}, {"asm.stride", "1"}, {"asm.cells", "1"},
                                    {"asm.a", "0"}, {"asm.b", "0"}, {"asm.root", "16"}};
    static uint8_t mask[80 * 60];
    for (int k = 0; k < 6; k++) {
        om_method_cfg c;
        om_method_cfg_default(&c, om_method_find("asm"));
        CHECK_OK(om_method_cfg_set(&c, "asm.cap", 4u << 20, NULL));
        CHECK_OK(om_method_cfg_set(&c, "asm.tile", 16, NULL));
        CHECK_OK(om_method_cfg_set(&c, "asm.root", 64, NULL));
        CHECK_OK(om_method_cfg_set(&c, sets[k][0], atof(sets[k][1]), NULL));
        arun r;
        if (!arun_init(&r, &hs.s, &c, 80, 60, false)) continue;
        for (int f = 0; f < 4; f++) {
            om_method_stats ms;
            CHECK_OK(arun_frame(&r, 0.0f, 0.3f * (float)f, 0, mask, NULL, &ms));
            CHECK(counter(&ms, "bytes in use") <= cap_of(&c));
        }
        arun_free(&r);
    }
    h_scene_free(&hs);
}

/* A uniform number in [lo, hi) from a 64-bit LCG. */
static double lcg_in(uint64_t *x, double lo, double hi)
{
    *x = *x * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (double)(*x >> 11) / 9007199254740992.0;
}

/* The float path's bounds hold, one sample at a time, against the exact values it
 * stands for: wherever it places a sample, the exact u, v lie within its fixed-point
 * bounds and z within ez; its depth comparisons (against stored depths chosen around
 * the exact biased depth, where they are hardest) and its footprint decisions are the
 * exact ones wherever it takes them; and it takes most of them. A spot and a
 * directional light. */
static void float_bounds_hold(void)
{
    static const char *const scenes[] = {
        "camera eye 0 2.5 12 target 0 0.8 0 size 320 240\n"
        "light spot pos 4 9 5 target 0 0 0 fov 70 near 0.5 far 40\nplane size 10 10\n",
        "camera eye 0 4 7 target 0 0 0 size 320 240\nlight directional dir -0.4 -1 -0.3\n"
        "plane size 10 10\n"};
    uint64_t x = 12345;
    for (int k = 0; k < 2; k++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[k])) return;
        om_view v;
        CHECK_OK(h_view(&v, &hs.s, 0, 0, 0, NULL));
        om__asm_cfg c;
        memset(&c, 0, sizeof c);
        c.asm_cap = 16u << 20;
        c.bias_const = 2.5e-4f;   /* of the light's depth range: 1 cm for the spot */
        c.bias_slope = 1.5f;
        c.asm_tile = 64;
        c.asm_cells = 8;
        c.asm_root = 1024;
        c.asm_float = 1;
        om__asm_layout l;
        CHECK_OK(om__asm_layout_of(&l, &c, 100, NULL));
        om__asm_pctx pc;
        om__asm_pctx_begin(&pc, &l, &c, &v);
        CHECK(pc.fix > 0);
        uint32_t placed = 0, tried = 0, decided = 0, compared = 0, finer = 0, finer_asked = 0;
        for (int i = 0; i < 20000; i++) {
            om_sample smp;
            smp.p[0] = (float)lcg_in(&x, -5, 5) - v.origin.x;   /* relative to the view's origin */
            smp.p[1] = (float)lcg_in(&x, 0, 2.5) - v.origin.y;
            smp.p[2] = (float)lcg_in(&x, -5, 5) - v.origin.z;
            double n0 = lcg_in(&x, -1, 1), n1 = lcg_in(&x, 0.05, 1), n2 = lcg_in(&x, -1, 1);
            double nl = sqrt(n0 * n0 + n1 * n1 + n2 * n2);
            smp.n[0] = (float)(n0 / nl);
            smp.n[1] = (float)(n1 / nl);
            smp.n[2] = (float)(n2 / nl);
            smp.tri = 1;
            smp.nl = 0.0f;
            om__asm_fpt f;
            om__asm_pt p;
            tried++;
            if (!om__asm_fpt_uv(&pc, &smp, &f)) continue;
            placed++;
            CHECK_MSG(om__asm_pt_uv(&pc, &smp, &p), "sample %d: placed in float, not exactly", i);
            const double one = (double)(1u << pc.fix);
            const double fu = floor(p.u * one), fv = floor(p.v * one);
            CHECK_MSG(f.u0 <= fu && fu <= f.u1 && f.v0 <= fv && fv <= f.v1,
                      "sample %d: u %.17g v %.17g outside [%u, %u] x [%u, %u] / 2^%u", i, p.u, p.v, f.u0, f.u1,
                      f.v0, f.v1, pc.fix);
            CHECK_MSG(fabs((double)f.z - p.z) <= (double)f.ez, "sample %d: z %.17g, float %g +- %g", i, p.z,
                      (double)f.z, (double)f.ez);
            om__asm_fpt_bias(&pc, &smp, &f, true);
            om__asm_pt_bias(&pc, &smp, &p, true);
            for (uint32_t L = 0; L <= l.max_level; L++) {
                const double zl = p.z - p.bias_c - p.bias_s * (1.0 / l.scale[L]);
                /* stored depths around the exact biased depth, out to 2^-12 of it */
                const double span = fabs(zl) * lcg_in(&x, 0, 1) * lcg_in(&x, 0, 1) * (1.0 / 4096) + 1.0;
                const double dd = floor(zl + lcg_in(&x, -span, span));
                if (!(dd >= 0.0 && dd <= 4294967295.0)) continue;
                const uint32_t depth = (uint32_t)dd;
                const int r = om__asm_fpt_lit(&pc, &f, L, depth);
                compared++;
                if (r < 0) continue;
                decided++;
                CHECK_MSG(r == (zl <= (double)depth), "sample %d level %u: depth %u, exact %.17g, float says %d", i,
                          L, depth, zl, r);
                const int g = om__asm_fpt_finer(&pc, &f, L);
                finer_asked++;
                if (g < 0) continue;
                finer++;
                CHECK_MSG(g == (p.ratio0 / l.scale[L] > 1.0), "sample %d level %u: ratio %.17g, float says %d", i,
                          L, p.ratio0 / l.scale[L], g);
            }
        }
        CHECK_MSG(placed * 10 > tried * 6, "light %d: %u of %u samples placed in float", k, placed, tried);
        CHECK_MSG(decided * 3 > compared, "light %d: %u of %u depths decided in float", k, decided, compared);
        CHECK_MSG(finer * 10 > finer_asked * 9, "light %d: %u of %u ratios decided", k, finer, finer_asked);
        CHECK_MSG(decided < compared, "light %d: every depth decided: the test is too easy", k);
        h_scene_free(&hs);
    }
}

/* The float path (asm.float 1: each sample placed in float, with bounds, the exact
 * double path deciding where they do not; in the lean mode also each triangle's bounds
 * for a tile, and with room left its chunks' bounds) gives the exact path's frames,
 * counters and tree: on close-ups refined to 65,536 texels a side (where float alone
 * could not place samples), with strips, a moving camera, a directional light and a
 * small cap; the lean mode's too. It fails with a chunk's bounds half a texel too
 * narrow, or the float test of texel centres a quarter texel too narrow. */
static void float_path_is_exact(void)
{
    /* the default scene without its camera path, seen from close (bench_asm's views) */
    static char text[16384];
    const char *d = om_scene_default_text();
    size_t n = 0;
    while (*d) {
        const char *e = strchr(d, '\n');
        size_t len = e ? (size_t)(e - d) + 1 : strlen(d);
        if (strncmp(d, "key camera", 10) != 0 && strncmp(d, "camera", 6) != 0 && n + len < sizeof text - 256) {
            memcpy(text + n, d, len);
            n += len;
        }
        d += len;
    }
    static const char *const cams[] = {"camera eye -0.2 0.9 4.8 target -0.6 0.1 3.0\n",
                                       "camera eye 0.8 1.4 2.6 target -1.2 0.0 0.4\n",
                                       "camera eye 0 2.5 12 target 0 0.8 0\n"};
    enum { BW = 160, BH = 120 };
    static om_term terms[4][BW * BH];
    for (int k = 0; k < 4; k++) {
        h_scene hs;
        if (k < 3) {
            memcpy(text + n, cams[k], strlen(cams[k]) + 1);
            if (!h_scene_parse(&hs, text)) return;
        } else if (!h_scene_parse(&hs, "camera eye 0 4 7 target 0 0 0 size 80 60\n"
                                         "light directional dir -0.4 -1 -0.3\nplane size 10 10\n"
                                         "box size 1 1 1 translate 0 0.5 0\n"
                                         "triangles count 300 seed 5 area 6 in -3 0.2 -3 3 2 3\n"
                                         "key camera 0 eye 0 4 7 target 0 0 0\n"
                                         "key camera 1 eye 3 3 5 target 0 0 0\n")) {
            return;
        }
        arun r[4];   /* exact; float; float in the lean mode, in the minimum and with chunks */
        bool ok = true;
        for (int j = 0; j < 4; j++) {
            om_method_cfg c;
            om_method_cfg_default(&c, om_method_find("asm"));
            CHECK_OK(om_method_cfg_set(&c, "asm.cap", k == 2 ? 200000 : 8u << 20, NULL));
            CHECK_OK(om_method_cfg_set(&c, "asm.work", 4096, NULL));
            CHECK_OK(om_method_cfg_set(&c, "asm.float", j > 0, NULL));
            ok = arun_init(&r[j], &hs.s, &c, BW, BH, j < 2 ? 0 : j - 1) && ok;
        }
        uint32_t finest = 0;
        for (int f = 0; ok && f < 6; f++) {
            om_method_stats ms[4];
            for (int j = 0; j < 4; j++)
                CHECK_OK(arun_frame(&r[j], k == 3 ? 0.2f * (float)f : 0.0f, 0.0f, f % 2 ? 7 : 0, NULL,
                                    terms[j], &ms[j]));
            static const char *const mode[4] = {"exact", "float", "lean", "lean with chunks"};
            for (int j = 1; j < 4; j++) {
                CHECK_MSG(memcmp(terms[0], terms[j], sizeof terms[0]) == 0, "view %d frame %d: terms differ (%s)", k, f,
                          mode[j]);
                for (uint32_t i = 0; i < ms[0].ncounters; i++)
                    CHECK_MSG(ms[0].counters[i] == ms[j].counters[i], "view %d frame %d: %s %u, %s %u", k, f,
                              ms[0].counter_names[i], ms[0].counters[i], mode[j], ms[j].counters[i]);
            }
            /* the chunks' bounds are there: 16 bytes a chunk of 8 (r[2] has the minimum) */
            CHECK_MSG(ms[3].bytes_used >= r[2].bytes + hs.s.ntris * 2, "view %d: %zu bytes used, minimum %zu", k,
                      ms[3].bytes_used, r[2].bytes);
            finest = counter(&ms[1], "effective resolution");
        }
        if (k < 2) CHECK_MSG(finest >= 65536, "view %d refined to %u only", k, finest);
        for (int j = 0; j < 4; j++) arun_free(&r[j]);
        h_scene_free(&hs);
    }
}

/* ---- asm: its bands look up with caches of their own and write nothing of the tree;
 * the use stamps of their lookups are put on the tree after the bands (om__bands.
 * finish). A state kept over frames, a still light, a moving camera and one sample
 * in 200 analysed (so that most leaves are stamped by lookups alone, and a missing
 * stamp changes the tree): the same frames, counters, nodes and stamps for any number
 * of jobs and their order, frame after frame. */
static void asm_frames(const om_scene *s, uint32_t rows, om_parallel_for_fn pf, void *host, uint32_t threads,
                       uint64_t *hash, uint32_t counters[][8], int nframes, const char *set)
{
    const om_method *m = om_method_find("asm");
    enum { W = 160, H = 120 };
    om_method_cfg c = h_cfg("asm", set);
    size_t mn, full;
    om_diag d;
    CHECK_OK(om_method_bytes(m, &c, s, W, H, &mn, &full));
    const uint32_t r = rows ? rows : H;
    void *mm = malloc(full), *px = malloc((size_t)W * r * 3), *state = NULL;
    om_arena ma, fa;
    om_arena_init(&ma, mm, full, "method");
    CHECK_OK(om_method_init(m, &state, &ma, &c, s, W, H, &d));
    /* om_frame_bytes' with_jobs is for the default settings; a larger tree's jobs need more */
    const bool big_tree = strstr(set, "asm.tile=4") != NULL;
    const size_t big = state && threads > 1 && big_tree ? threads * (m->pass->scratch(state, s) + 64) : 0;
    const size_t fbytes = h_frame_bins(s, W, r) + h_frame_jobs(m, s, threads) + big;
    void *fm = malloc(fbytes);
    for (int f = 0; f < nframes && state; f++) {
        om_camera cam, cam0;
        om_light light, moving;
        om_view v;
        om_scene_at(s, 0.0f, &cam0, &light);   /* the light held still: the tree lives on */
        om_scene_at(s, 0.15f * (float)f, &cam, &moving);
        cam.width = W;
        cam.height = H;
        CHECK_OK(om_view_init(&v, &cam, &light, s, &d));
        om_arena_init(&fa, fm, fbytes, "frame");
        om_framebuffer fb = {OM_RGB888, W, r, (size_t)W * 3, (uint8_t *)px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, s, &v, m, state, &fb, rows);
        fd.on_strip = frame_hash_strip; fd.user = &hash[f];
        fd.parallel_for = pf; fd.parallel_user = host; fd.threads = threads;
        hash[f] = OM_HASH_INIT;
        om_frame_stats fs;
        CHECK_OK(om_render_frame(&fd, &fa, &fs, &d));
        CHECK_MSG(fs.jobs == (pf ? threads : 1), "asm: %u jobs ran %u", threads, fs.jobs);
        om_method_stats ms;
        om_method_get_stats(m, state, &ms);
        memcpy(counters[f], ms.counters, sizeof counters[f]);
        /* and the tree: every node's place and use stamp */
        const om__asm_tree *t = om__asm_tree_of(state);
        if (big_tree) CHECK(t->lay.count >= 0xFFFFu);   /* finish finds the leaves again */
        uint64_t th = OM_HASH_INIT;
        th = om_hash(th, &t->root.stamp, sizeof t->root.stamp);
        for (uint32_t i = 0; i < t->lay.count; i++) {
            const om__asm_node *nd = (const om__asm_node *)om_pool_item(&t->pool, i);
            if (nd->alive) th = om_hash(om_hash(th, &i, sizeof i), nd, sizeof *nd);
        }
        hash[f] = om_hash(hash[f], &th, sizeof th);
    }
    free(mm);
    free(fm);
    free(px);
}

static void asm_bands(void)
{
    static const uint32_t threads[] = {2, 3, 4, 7, 16};
    enum { NF = 6 };
    om_jobs *pools[5];
    for (int k = 0; k < 5; k++) CHECK_OK(om_jobs_start(&pools[k], threads[k], NULL));
    /* the third: a tree of more than 0xFFFF nodes, whose leaves the bands cannot name */
    for (int li = 0; li < 3; li++) {
        h_scene hs;
        if (!h_scene_parse(&hs, li == 1 ? directional_scene : om_scene_default_text())) continue;
        const char *set = li < 2 ? "asm.cap=400000 asm.stride=200"
                                 : "asm.cap=16000000 asm.tile=4 asm.cells=2 asm.root=16 asm.stride=300 asm.work=200";
        for (uint32_t rows = 0; rows <= 24; rows += 24) {
            uint64_t h1[NF], hn[NF];
            uint32_t c1[NF][8], cn[NF][8];
            asm_frames(&hs.s, rows, NULL, NULL, 1, h1, c1, NF, set);
            for (int k = 0; k < 6; k++) {
                uint32_t n = k < 5 ? threads[k] : 5;
                asm_frames(&hs.s, rows, k < 5 ? om_jobs_for : backwards, k < 5 ? pools[k] : NULL, n, hn, cn, NF, set);
                for (int f = 0; f < NF; f++)
                    CHECK_MSG(hn[f] == h1[f] && !memcmp(cn[f], c1[f], sizeof c1[f]),
                              "asm case %d strips %u frame %d: %u threads%s change the frame", li, rows, f, n,
                              k < 5 ? "" : " backwards");
            }
        }
        h_scene_free(&hs);
    }
    for (int k = 0; k < 5; k++) om_jobs_stop(pools[k]);
}

/* ---- asm: observe's analysis and the tile renders as jobs (asm_jobs.c). The method
 * driven directly, its tree hashed after observe and after build (use marks, benefits,
 * every cell's benefit and need, every tile, the triangle grid), on method memory
 * filled with different garbage, with the jobs lent to it run backwards
 * on 3 slots against none lent: views still, jumping between two places (so that
 * nodes were last used two frames before) or moving on each frame (jump < 0: so that
 * some were not used in the last frame), caps that leave the free list short or not
 * (and the last set with nodes left that observe may replace: it then runs a strip at
 * a time), strips of 8 rows or one. */

static uint64_t asm_tree_hash(const void *state)
{
    om__asm_tree *t = (om__asm_tree *)om__asm_tree_of(state);
    const om__asm_state *m = (const om__asm_state *)state;
    uint64_t h = OM_HASH_INIT;
    if (m->gready) {   /* the frame's triangle grid: its starts and lists */
        const size_t g2 = (size_t)m->gside * m->gside;
        h = om_hash(om_hash(h, m->gstart, (g2 + 1) * sizeof *m->gstart), m->glist, m->gstart[g2] * sizeof *m->glist);
    }
    for (uint32_t i = 0; i <= t->lay.count; i++) {
        const uint32_t idx = i == t->lay.count ? OM__ASM_ROOT : i;
        om__asm_tile tl;
        om__asm_tile_of(t, idx, &tl);
        if (!tl.node->alive && idx != OM__ASM_ROOT) continue;
        const size_t c2 = (size_t)tl.cells * tl.cells, t2 = (size_t)tl.size * tl.size;
        h = om_hash(om_hash(h, &idx, sizeof idx), tl.node, sizeof *tl.node);
        h = om_hash(om_hash(h, tl.ben, c2 * sizeof *tl.ben), tl.need, c2 * sizeof *tl.need);
        h = om_hash(om_hash(h, tl.child, c2 * sizeof *tl.child), tl.depth, t2 * sizeof *tl.depth);
        h = tl.id16 ? om_hash(h, tl.id16, t2 * sizeof *tl.id16) : om_hash(h, tl.id32, t2 * sizeof *tl.id32);
    }
    return h;
}

static void asm_jobs_case(const om_scene *s, const char *set, uint32_t rows, float jump, bool lend,
                          uint64_t out[][2], uint32_t *used, int nframes)
{
    enum { W = 96, H = 72 };
    const om_method *m = om_method_find("asm");
    const om__pass *ps = m->pass;
    om_method_cfg c = h_cfg("asm", set);
    size_t mn, full;
    om_diag d;
    CHECK_OK(om_method_bytes(m, &c, s, W, H, &mn, &full));
    void *mm = malloc(full), *state = NULL;
    memset(mm, lend ? 0x5A : 0xA5, full);   /* what init leaves unwritten differs between the two */
    uint32_t *depth = calloc((size_t)W * H, sizeof *depth), *id = calloc((size_t)W * H, sizeof *id);
    om_sample *smp = calloc((size_t)W * H, sizeof *smp);
    om_term *terms = calloc((size_t)W * H, sizeof *terms), *kept = calloc((size_t)W * H, sizeof *terms);
    om_arena ma;
    om_arena_init(&ma, mm, full, "method");
    CHECK_OK(om_method_init(m, &state, &ma, &c, s, W, H, &d));
    CHECK(ps && ps->lend);
    lent3 h;
    const size_t sb = ps->scratch(state, s);
    for (int k = 0; k < 3; k++) h.slot[k] = calloc(1, sb ? sb : 1);
    const om__lend l = {lent_run, lent_run, &h, 3};
    for (int f = 0; f < nframes && state && ps && ps->lend; f++) {
        om_camera cam, cam0;
        om_light light, moving;
        om_view v;
        om_scene_at(s, 0.0f, &cam0, &light);
        om_scene_at(s, jump < 0.0f ? -jump * (float)f : jump * (float)(f & 1) + 0.05f * (float)f, &cam, &moving);
        cam.width = W;
        cam.height = H;
        CHECK_OK(om_view_init(&v, &cam, &light, s, &d));
        om_target tg = {W, H, 0, H, depth, id};
        om_strip st = {W, H, 0, H, smp, terms, v.origin};
        om__eye_pass_mark(s, &v, &tg, &st, NULL);
        memcpy(kept, terms, (size_t)W * H * sizeof *terms);
        ps->lend(state, lend ? &l : NULL);
        CHECK_OK(m->begin(state, &v, &d));
        for (uint32_t y = 0; y < H; y += rows) {
            om_strip sub = {W, H, y, y + rows > H ? H - y : rows, smp + (size_t)y * W, terms + (size_t)y * W, v.origin};
            CHECK_OK(m->observe(state, &sub, &d));
        }
        CHECK(!memcmp(kept, terms, (size_t)W * H * sizeof *terms));   /* observe leaves them */
        out[f][0] = asm_tree_hash(state);
        CHECK_OK(m->build(state, &d));
        out[f][1] = asm_tree_hash(state);
        ps->lend(state, NULL);
        CHECK_OK(m->resolve(state, &st, &d));
        *used += ((const om__asm_state *)state)->tree.created;
    }
    for (int k = 0; k < 3; k++) free(h.slot[k]);
    free(mm);
    free(depth);
    free(id);
    free(smp);
    free(terms);
    free(kept);
}

static void asm_jobs_tree(void)
{
    static const char *const sets[] = {"asm.cap=300000 asm.stride=1 asm.root=256 asm.work=100000",
                                       "asm.cap=2000000 asm.stride=1 asm.root=256 asm.work=100000",
                                       "asm.cap=200000 asm.stride=3", "asm.stride=2 asm.work=1000",
                                       "asm.cap=600000 asm.stride=1 asm.root=256 asm.work=10000"};
    enum { NF = 6 };
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    for (int k = 0; k < 5; k++)
        for (uint32_t rows = 8; rows <= 72; rows += 64)
            for (int j = 0; j < 3; j++) {
                const float jump = j == 0 ? 0.0f : j == 1 ? 2.5f : -1.0f;
                uint64_t a[NF][2], b[NF][2];
                uint32_t ua = 0, ub = 0;
                asm_jobs_case(&hs.s, sets[k], rows, jump, false, a, &ua, NF);
                asm_jobs_case(&hs.s, sets[k], rows, jump, true, b, &ub, NF);
                CHECK(ua > 0 && ua == ub);
                for (int f = 0; f < NF; f++)
                    CHECK_MSG(a[f][0] == b[f][0] && a[f][1] == b[f][1],
                              "asm %s, strips of %u, jump %d, frame %d: the tree after %s differs", sets[k], rows, j,
                              f, a[f][0] != b[f][0] ? "observe" : "build");
            }
    h_scene_free(&hs);
}

/* The default scene drawn a thousand times smaller or larger keeps its shadows: the
 * settings' units scale with the scene. */
static void asm_bias_is_scale_free(void) { h_check_scale_free("asm", 320, 240); }

void suite_asm(void)
{
    RUN(asm_bias_is_scale_free);
    RUN(tree_layout);
    RUN(tree_rules);
    RUN(tree_candidates_order);
    RUN(budgets_name_minimum);
    RUN(cap_holds_along_path);
    RUN(still_view_converges);
    RUN(runs_are_bit_identical);
    RUN(float_bounds_hold);
    RUN(float_path_is_exact);
    RUN(odd_settings_render);
    RUN(asm_bands);
    RUN(asm_jobs_tree);
}
