/* test_lent.c — a method's own stages on slots the frame lends it (om__lend), driven
 * directly: asm's observe and tile renders, rtw's and spsm's observe, hybrid's map and a
 * tile of its irregular pass, each on three fake slots whose jobs run backwards, against
 * the same stage on the calling thread, compared by the state they leave (trees, maps,
 * tiles), which whole frames (test_threads.c) would not all show. */
#include "test.h"
#include "harness.h"
#include "../engine/shadow/asm/asm.h"
#include "../engine/shadow/rtw/rtw.h"
#include "../engine/shadow/spsm/spsm_method.h"
#include "../engine/shadow/hybrid/hybrid_method.h"

#include <stdlib.h>

/* ---- asm: observe's analysis and the tile renders as jobs (asm_jobs.c). The method
 * driven directly, its tree hashed after observe and after build (use marks, benefits,
 * every cell's benefit and need, every tile, the triangle grid), on method memory
 * filled with different garbage, with the jobs lent to it run backwards
 * on 3 slots against none lent: views still, jumping between two places (so that
 * nodes were last used two frames before) or moving on each frame (jump < 0: so that
 * some were not used in the last frame), caps that leave the free list short or not
 * (and the last set with nodes left that observe may replace: it then runs a strip at
 * a time), strips of 8 rows or one. */
typedef struct lent3 {
    void *slot[3];
} lent3;

static void lent_run(const om__lend *l, void (*fn)(void *user, uint32_t k, void *scratch), void *user,
                     uint32_t n)
{
    lent3 *h = (lent3 *)l->frame;
    const uint32_t p = n < l->slots ? n : l->slots;
    for (uint32_t s = p; s-- > 0;)
        for (uint32_t k = s; k < n; k += p) fn(user, k, h->slot[s]);
}

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
        om_strip st = {W, H, 0, H, smp, terms};
        om__eye_pass_mark(s, &v, &tg, &st, NULL);
        memcpy(kept, terms, (size_t)W * H * sizeof *terms);
        ps->lend(state, lend ? &l : NULL);
        CHECK_OK(m->begin(state, &v, &d));
        for (uint32_t y = 0; y < H; y += rows) {
            om_strip sub = {W, H, y, y + rows > H ? H - y : rows, smp + (size_t)y * W, terms + (size_t)y * W};
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

/* rtw's and spsm's observe on three lent slots (in reverse slot order), whole and in
 * strips of 8 rows: the bands did run (their slots hold work to fold after observe),
 * and after build the state's importance map and seen bits (rtw) and the texels the
 * build reads (spsm's need) are those of observe on the calling thread. */
static void observe_lent(void)
{
    enum { W = 96, H = 72 };
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    uint32_t *depth = calloc((size_t)W * H, sizeof *depth), *id = calloc((size_t)W * H, sizeof *id);
    om_sample *smp = calloc((size_t)W * H, sizeof *smp);
    om_term *terms = calloc((size_t)W * H, sizeof *terms);
    static const char *const sets[][2] = {{"rtw", "map=256"}, {"spsm", "map=256 spsm.records=2"}};
    for (int i = 0; i < 2; i++) {
        const om_method *m = om_method_find(sets[i][0]);
        const om__pass *ps = m->pass;
        CHECK(ps && ps->lend && !ps->job);
        if (!ps) continue;
        om_method_cfg c = h_cfg(sets[i][0], sets[i][1]);
        size_t mn, full;
        om_diag d;
        CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
        uint64_t hash[2][2] = {{0}};
        for (int lend = 0; lend < 2; lend++)
            for (uint32_t rows = 8; rows <= H; rows += H - 8) {
                void *mm = calloc(1, full), *state = NULL;
                om_arena ma;
                om_arena_init(&ma, mm, full, "method");
                CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, &d));
                lent3 h;
                const size_t sb = ps->scratch(state, &hs.s);
                CHECK(sb > 0);
                for (int k = 0; k < 3; k++) h.slot[k] = calloc(1, sb ? sb : 1);
                const om__lend l = {lent_run, lent_run, &h, 3};
                om_view v;
                CHECK_OK(h_view(&v, &hs.s, 0.0f, W, H, &d));
                om_target tg = {W, H, 0, H, depth, id};
                om_strip st = {W, H, 0, H, smp, terms};
                om__eye_pass_mark(&hs.s, &v, &tg, &st, NULL);
                ps->lend(state, lend ? &l : NULL);
                CHECK_OK(m->begin(state, &v, &d));
                for (uint32_t y = 0; y < H; y += rows) {
                    om_strip sub = {W, H, y, y + rows > H ? H - y : rows, smp + (size_t)y * W, terms + (size_t)y * W};
                    CHECK_OK(m->observe(state, &sub, &d));
                }
                const om__lent *lt = i ? &((const om__spsm_state *)state)->lent : &((const om__rtw *)state)->lent;
                CHECK_MSG(lt->used == (lend == 1), "%s: bands %s", om_method_name(m), lend ? "did not run" : "ran unlent");
                CHECK_OK(m->build(state, &d));
                if (i == 0) {
                    const om__rtw *r = (const om__rtw *)state;
                    const size_t nn = (size_t)r->n * r->n;
                    hash[lend][rows == H] = om_hash(om_hash(0, r->imp, nn * sizeof *r->imp), r->seen, (nn + 7) / 8);
                } else {
                    const om__spsm_state *sp = (const om__spsm_state *)state;
                    hash[lend][rows == H] = om_hash(0, sp->need, (size_t)sp->size * sp->words * sizeof *sp->need);
                }
                ps->lend(state, NULL);
                for (int k = 0; k < 3; k++) free(h.slot[k]);
                free(mm);
            }
        CHECK_MSG(hash[1][0] == hash[0][0] && hash[1][1] == hash[0][1], "%s: lent observe differs", om_method_name(m));
    }
    free(depth);
    free(id);
    free(smp);
    free(terms);
    h_scene_free(&hs);
}

/* hybrid's map built by bands of rows on three lent slots (in reverse slot order) is
 * the map built on the calling thread, byte for byte: on the default scene and on one
 * whose triangles cross the light's near plane and leave the guard band (so they need
 * clipping, and their rows come from their sub-triangles), at map sides of a power of
 * two, of none (a division per texel) and below the number of bands. */
static void hybrid_map_lent(void)
{
    enum { W = 96, H = 72 };
    static const char clipped[] = "camera eye 0 6 12 target 0 1 0 fov 60 near 0.1 far 100\n"
                                  "light spot pos 0 4 0 target 0.5 0 0 fov 100 near 1 far 30\n"
                                  "plane size 60 60 albedo 0.7 0.7 0.7\n"
                                  "triangles count 400 seed 3 area 3 in -4 2.5 -4 4 4.5 4\n";
    const char *const scenes[] = {om_scene_default_text(), clipped};
    static const char *const sets[] = {"hybrid.map=256", "hybrid.map=100", "hybrid.map=5"};
    const om_method *m = om_method_find("hybrid");
    const om__pass *ps = m->pass;
    CHECK(ps && ps->lend);
    for (int sc = 0; sc < 2 && ps; sc++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[sc])) return;
        for (int i = 0; i < 3; i++) {
            om_method_cfg c = h_cfg("hybrid", sets[i]);
            size_t mn, full;
            om_diag d;
            CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
            uint64_t hash[2] = {0, 0};
            uint32_t clips = 0;
            for (int lend = 0; lend < 2; lend++) {
                void *mm = calloc(1, full), *state = NULL;
                om_arena ma;
                om_arena_init(&ma, mm, full, "method");
                CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, &d));
                const hybrid_state *hy = (const hybrid_state *)state;
                CHECK_MSG(hy->cands == hs.s.ntris, "hybrid: no room for the bands' reach");
                lent3 h = {{NULL, NULL, NULL}};
                const om__lend l = {lent_run, lent_run, &h, 3};
                om_view v;
                CHECK_OK(h_view(&v, &hs.s, 0.0f, W, H, &d));
                ps->lend(state, lend ? &l : NULL);
                CHECK_OK(m->begin(state, &v, &d));
                for (uint32_t k = 0; k < hs.s.nverts && sc == 1; k++) clips += hy->ls.verts[k].x == INT32_MIN;
                CHECK_OK(m->build(state, &d));
                hash[lend] = om_hash(0, hy->map, (size_t)hy->side * hy->side * sizeof *hy->map);
                ps->lend(state, NULL);
                free(mm);
            }
            CHECK_MSG(hash[1] == hash[0], "hybrid %s, scene %d: the map by bands differs", sets[i], sc);
            CHECK_MSG(sc == 0 || clips > 0, "hybrid: no vertex needs clipping");
        }
        h_scene_free(&hs);
    }
}

/* A large tile of hybrid's irregular pass (cut into regions) on three lent slots, its
 * sort by parts and bands of the grid's rows among the jobs, against the same tile on
 * the calling thread: the same samples in the same order in every cell, the same
 * cells, blocks, terms and counts. Every exposed sample of the cloud-and-bar scene
 * is a key (more than the two regions' samples a parallel sort needs). */
static void hybrid_tile_lent(void)
{
    enum { W = 320, H = 240, N = W * H };
    h_scene hs;
    if (!h_scene_parse(&hs, h_cloud_bar)) return;
    const om_method *m = om_method_find("hybrid");
    om_method_cfg c = h_cfg("hybrid", "");
    size_t mn, full;
    om_diag d;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
    void *mm = calloc(1, full), *state = NULL;
    om_arena ma;
    om_arena_init(&ma, mm, full, "method");
    CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, &d));
    om_view v;
    CHECK_OK(h_view(&v, &hs.s, 0.0f, W, H, &d));
    uint32_t *depth = calloc(N, sizeof *depth), *id = calloc(N, sizeof *id);
    om_sample *smp = calloc(N, sizeof *smp);
    om_term *terms[2] = {calloc(N, sizeof(om_term)), calloc(N, sizeof(om_term))};
    om_target tg = {W, H, 0, H, depth, id};
    om_strip st = {W, H, 0, H, smp, terms[0]};
    om__eye_pass_mark(&hs.s, &v, &tg, &st, NULL);
    memcpy(terms[1], terms[0], N * sizeof(om_term));
    CHECK_OK(m->begin(state, &v, &d));
    CHECK_OK(m->build(state, &d));
    const hybrid_state *hy = (const hybrid_state *)state;
    const size_t tb = om__htile_bytes(N, hs.s.ntris);
    unsigned char *mem[2] = {malloc(tb + 16), malloc(tb + 16)};   /* carved from 16 bytes on */
    om__htile t[2];
    lent3 h = {{NULL, NULL, NULL}};
    const om__lend l = {lent_run, lent_run, &h, 3};
    uint32_t n = 0;
    for (int k = 0; k < 2; k++) {
        unsigned char *at = mem[k] + (16 - (uintptr_t)mem[k] % 16) % 16;
        memset(at, k ? 0x5A : 0xA5, tb);
        om__htile_carve(&t[k], at, N, hs.s.ntris);
        n = 0;
        for (size_t i = 0; i < N; i++) {
            om__lpoint p;
            if ((terms[k][i].flags & OM_TERM_EXPOSED) && om__lspace_point(&hy->ls, &smp[i], &p))
                om__hkey_put(&t[k].raw[n++], &p, i);
        }
        om_strip sk = {W, H, 0, H, smp, terms[k]};
        om__htile_run(&hy->h, &t[k], n, &sk, k ? &l : NULL);
    }
    const uint32_t nc = t[0].cw * t[0].ch;
    CHECK_MSG(n >= 2 * 8192 && t[0].nreg > 1, "hybrid tile: %u samples, %u regions", n, t[0].nreg);
    CHECK(t[0].cw == t[1].cw && t[0].ch == t[1].ch && t[0].cs == t[1].cs && t[0].nreg == t[1].nreg);
    CHECK(!memcmp(&t[0].box, &t[1].box, sizeof t[0].box));
    CHECK_MSG(!memcmp(t[0].smp, t[1].smp, n * sizeof *t[0].smp), "hybrid tile: sorted samples differ");
    CHECK(!memcmp(t[0].od, t[1].od, n * sizeof *t[0].od));
    CHECK(!memcmp(t[0].cend, t[1].cend, nc * sizeof *t[0].cend) && !memcmp(t[0].oend, t[1].oend, nc * sizeof *t[0].oend));
    CHECK(!memcmp(t[0].bzmax, t[1].bzmax, t[0].cbw * ((t[0].ch + 3) / 4) * sizeof *t[0].bzmax));
    CHECK(t[0].setups == t[1].setups && t[0].tested == t[1].tested && t[0].regions == t[1].regions);
    CHECK_MSG(!memcmp(terms[0], terms[1], N * sizeof(om_term)), "hybrid tile: terms differ");
    for (int k = 0; k < 2; k++) {
        free(mem[k]);
        free(terms[k]);
    }
    free(depth);
    free(id);
    free(smp);
    free(mm);
    h_scene_free(&hs);
}

void suite_lent(void)
{
    RUN(asm_jobs_tree);
    RUN(observe_lent);
    RUN(hybrid_map_lent);
    RUN(hybrid_tile_lent);
}
