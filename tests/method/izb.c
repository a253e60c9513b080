/* method/izb.c — the irregular z-buffer equals the reference sample for sample: on the
 * default scene, on seeded random scenes with semi-transparent casters, on a hot spot
 * (a floor at a grazing light angle), under a directional light, and at every tiling
 * from one pass down to tiles of a few rows, through strips too. Budgets below the
 * minimum fail naming it; budgets between minimum and one pass tile; the default pool
 * takes tiles where the scene has few triangles for the image. The triangles binned on
 * the light's image (lgrid.c) list each triangle where its box lies, made in parts or
 * at once, and a tile that walks only its own gives the same terms and counts. Its
 * tiles as jobs give the same frame on any number of threads (izb_pass). */
#include "../test.h"
#include "../harness.h"
#include "../jobs_util.h"
#include "../../engine/shadow/izb/izb.h"

#include <stdlib.h>

#define W 160
#define H 120
static om_term ref_t[W * H], izb_t[W * H];

static int term_diff(void)
{
    int diff = 0;
    for (int i = 0; i < W * H; i++)
        diff += ref_t[i].r != izb_t[i].r || ref_t[i].g != izb_t[i].g || ref_t[i].b != izb_t[i].b ||
                ref_t[i].flags != izb_t[i].flags;
    return diff;
}

static int blocked(void)
{
    int n = 0;
    for (int i = 0; i < W * H; i++) n += ref_t[i].r != 255 || ref_t[i].g != 255 || ref_t[i].b != 255;
    return n;
}

static void equals_ref(const char *text, const char *what, int min_blocked)
{
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return;
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, NULL, ref_t, NULL));
    CHECK_MSG(blocked() >= min_blocked, "%s: only %d samples blocked", what, blocked());
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("izb"));
    /* one pass, then pools of 40, 7 and 2 rows' worth of samples, and a leaf of 1 */
    static const uint32_t pools[] = {0, W * 40, W * 7, W * 2};
    for (int k = 0; k < 4; k++) {
        CHECK_OK(om_method_cfg_set(&c, "izb.pool", pools[k], NULL));
        CHECK_OK(h_render(&hs.s, "izb", &c, W, H, 0, 0, NULL, izb_t, NULL));
        CHECK_MSG(term_diff() == 0, "%s, pool %u: %d samples differ", what, pools[k], term_diff());
    }
    CHECK_OK(om_method_cfg_set(&c, "izb.pool", 0, NULL));
    CHECK_OK(om_method_cfg_set(&c, "izb.leaf", 1, NULL));
    CHECK_OK(h_render(&hs.s, "izb", &c, W, H, 0, 9, NULL, izb_t, NULL));
    CHECK_MSG(term_diff() == 0, "%s, leaf 1 in strips: %d samples differ", what, term_diff());
    h_scene_free(&hs);
}

static void izb_default_scene(void) { equals_ref(om_scene_default_text(), "default scene", 500); }

static void random_scenes(void)
{
    for (int seed = 1; seed <= 3; seed++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "camera eye 0 5 8 target 0 0.5 0 fov 55\n"
                 "light spot pos %d 9 2 target 0 0 0 fov 75 near 1 far 40\n"
                 "plane size 14 14 divisions 3\n"
                 "triangles count 500 seed %d area 25 in -3 0.3 -3 3 3 3\n"
                 "triangles count 200 seed %d area 20 in -3 0.3 -3 3 3 3 albedo 1 0.6 0.2 opacity 0.5\n"
                 "sphere radius 0.7 segments 24 rings 12 translate 1 1 1 opacity 0.4 albedo 0.3 0.8 1\n",
                 seed * 2 - 3, seed, seed + 10);
        equals_ref(text, "random scene", 500);
    }
}

static void hot_spot(void)
{
    /* A large floor lit at a grazing angle: thousands of samples fall into a thin band
     * of the light's image; a fence of thin bars shadows it. */
    equals_ref("camera eye 0 3 10 target 0 0 -10 fov 60\n"
               "light spot pos 0 0.6 -60 target 0 0 0 fov 20 near 1 far 200\n"
               "plane size 80 80 divisions 4\n"
               "box size 0.05 1.5 0.05 translate -1 0.75 -30\n"
               "box size 0.05 1.5 0.05 translate 0 0.75 -30\n"
               "box size 0.05 1.5 0.05 translate 1 0.75 -30\n"
               "box size 3 0.05 0.05 translate 0 0.4 -25\n",
               "hot spot", 200);
}

static void directional(void)
{
    equals_ref("camera eye 2 6 9 target 0 0.5 0 fov 50\n"
               "light directional dir -0.4 -1 -0.3\n"
               "plane size 20 20\n"
               "sphere radius 1 segments 32 rings 16 translate 0 1.5 0\n"
               "box size 1 2 1 translate 2 1 -1 rotate 0 30 0\n"
               "triangles count 300 seed 5 area 10 in -3 2 -3 3 4 3\n",
               "directional", 500);
}

static void budgets(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    const om_method *m = om_method_find("izb");
    om_method_cfg c;
    om_method_cfg_default(&c, om_method_find("izb"));
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
    CHECK(mn < full);
    /* below the minimum: a budget error naming it */
    unsigned char *buf = malloc(full + 64);
    om_arena a;
    om_arena_init(&a, buf, mn - 1, "method");
    void *state;
    om_diag d;
    CHECK(om_method_init(m, &state, &a, &c, &hs.s, W, H, &d) == OM_E_BUDGET);
    char num[32];
    snprintf(num, sizeof num, "%zu", mn);
    CHECK_MSG(strstr(d.msg, num) != NULL, "'%s' does not name %s", d.msg, num);
    free(buf);
    /* between minimum and one pass: tiles, and the same terms as the reference */
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, NULL, ref_t, NULL));
    om_view v;
    CHECK_OK(h_view(&v, &hs.s, 0, W, H, NULL));
    size_t sizes[3] = {mn, (mn + full) / 2, full};
    for (int k = 0; k < 3; k++) {
        unsigned char *mem = malloc(sizes[k]), *fmem = malloc(h_frame_least(W, H));
        unsigned char *px = malloc(W * H * 3);
        om_arena ma, fa;
        om_arena_init(&ma, mem, sizes[k], "method");
        om_arena_init(&fa, fmem, h_frame_least(W, H), "frame");
        CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, &d));
        CHECK(ma.peak <= sizes[k]);
        om_framebuffer fb = {OM_RGB888, W, H, W * 3, px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, &hs.s, &v, m, state, &fb, 0);
        /* capture terms through the strip callback of the harness' kind */
        CHECK_OK(om_render_frame(&fd, &fa, NULL, &d));
        om_method_stats ms;
        om_method_get_stats(m, state, &ms);
        uint32_t tiles = ms.counters[5];
        if (k == 0) CHECK_MSG(tiles > 10, "minimum budget: %u tiles", tiles);
        if (k == 2) CHECK_EQ_U(tiles, 1);
        free(mem);
        free(fmem);
        free(px);
    }
    h_scene_free(&hs);
}

/* The default pool follows the scene: with few triangles on a larger image it takes
 * tiles of 32768 samples (less memory than one pass), and still equals the reference;
 * with a pool of the whole image the same frame takes one. */
static void default_pool(void)
{
    enum { W2 = 320, H2 = 240 };
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 5 8 target 0 0.5 0 fov 55\n"
                            "light spot pos -1 9 2 target 0 0 0 fov 75 near 1 far 40\n"
                            "plane size 14 14 divisions 3\n"
                            "triangles count 500 seed 1 area 25 in -3 0.3 -3 3 3 3\n"))
        return;
    const om_method *m = om_method_find("izb");
    om_method_cfg c, one;
    om_method_cfg_default(&c, m);
    om_method_cfg_default(&one, m);
    CHECK_OK(om_method_cfg_set(&one, "izb.pool", W2 * H2, NULL));
    size_t mn, full, full_one;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, W2, H2, &mn, &full));
    CHECK_OK(om_method_bytes(m, &one, &hs.s, W2, H2, &mn, &full_one));
    CHECK_MSG(full < full_one / 2, "default pool %zu bytes, one pass %zu", full, full_one);
    om_term *rt = malloc(sizeof *rt * W2 * H2), *zt = malloc(sizeof *zt * W2 * H2);
    CHECK_OK(h_render(&hs.s, "ref", NULL, W2, H2, 0, 0, NULL, rt, NULL));
    uint32_t tiles[2] = {0, 0};
    for (int k = 0; k < 2; k++) {
        const om_method_cfg *ck = k ? &one : &c;
        CHECK_OK(h_render(&hs.s, "izb", ck, W2, H2, 0, 0, NULL, zt, NULL));
        int diff = 0;
        for (int i = 0; i < W2 * H2; i++)
            diff += rt[i].r != zt[i].r || rt[i].g != zt[i].g || rt[i].b != zt[i].b || rt[i].flags != zt[i].flags;
        CHECK_MSG(diff == 0, "pool %s: %d samples differ", k ? "one pass" : "default", diff);
        /* the tiles it took, through a frame of its own */
        size_t bytes = k ? full_one : full;
        unsigned char *mem = malloc(bytes), *fmem = malloc(h_frame_least(W2, H2)), *px = malloc(W2 * H2 * 3);
        om_arena ma, fa;
        om_arena_init(&ma, mem, bytes, "method");
        om_arena_init(&fa, fmem, h_frame_least(W2, H2), "frame");
        om_view v;
        om_diag d;
        void *state;
        CHECK_OK(h_view(&v, &hs.s, 0, W2, H2, NULL));
        CHECK_OK(om_method_init(m, &state, &ma, ck, &hs.s, W2, H2, &d));
        om_framebuffer fb = {OM_RGB888, W2, H2, W2 * 3, px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, &hs.s, &v, m, state, &fb, 0);
        CHECK_OK(om_render_frame(&fd, &fa, NULL, &d));
        om_method_stats ms;
        om_method_get_stats(m, state, &ms);
        tiles[k] = ms.counters[5];
        free(mem);
        free(fmem);
        free(px);
    }
    CHECK_MSG(tiles[0] >= 2 && tiles[1] == 1, "default pool %u tiles, one pass %u", tiles[0], tiles[1]);
    free(rt);
    free(zt);
    h_scene_free(&hs);
}

/* ---- the grid (lgrid.h) */

/* Triangle t's cells on g as lgrid.c's box says, worked out here again: false for one
 * in the wide list. */
static bool tri_cells(const om__lgrid *g, uint32_t t, uint32_t *x0, uint32_t *y0, uint32_t *x1, uint32_t *y1)
{
    const om__lvert *v = g->ls->verts;
    const uint32_t *ix = g->ls->scene->idx + (size_t)t * 3;
    int64_t lo[2] = {INT64_MAX, INT64_MAX}, hi[2] = {INT64_MIN, INT64_MIN};
    for (int k = 0; k < 3; k++) {
        const om__lvert *p = &v[ix[k]];
        if (p->x == INT32_MIN) return false;
        const int64_t c[2] = {p->x, p->y};
        for (int a = 0; a < 2; a++) {
            if (c[a] < lo[a]) lo[a] = c[a];
            if (c[a] > hi[a]) hi[a] = c[a];
        }
    }
    const int64_t top = (1 << 21) - 1, cell = ((int64_t)1 << 21) / g->side;
    uint32_t r[4];
    const int64_t e[4] = {lo[0], lo[1], hi[0], hi[1]};
    for (int k = 0; k < 4; k++) r[k] = (uint32_t)((e[k] < 0 ? 0 : e[k] > top ? top : e[k]) / cell);
    *x0 = r[0]; *y0 = r[1]; *x1 = r[2]; *y1 = r[3];
    return (uint64_t)(r[2] - r[0] + 1) * (r[3] - r[1] + 1) <= LGRID_MOST;
}

/* Every triangle is listed once in each cell of its vertices' box (clamped to the
 * grid), or once in the wide list where a vertex needs clipping or the box covers more
 * than LGRID_MOST cells; every list ascends; steps made in parts, in any order, give
 * the same lists as one pass; and a tile's selection is the triangles of its cells. */
static void grid_lists(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 5 8 target 0 0.5 0 fov 55\n"
                            "light spot pos -1 9 2 target 0 0 0 fov 75 near 1 far 40\n"
                            "plane size 30 30 divisions 6\n"
                            "triangles count 3000 seed 3 area 40 in -4 0.3 -4 4 3 4\n"
                            "sphere radius 0.7 segments 24 rings 12 translate 1 1 1\n"))
        return;
    om_camera cam;
    om_light light;
    om_view v;
    om_scene_at(&hs.s, 0, &cam, &light);
    CHECK_OK(om_view_init(&v, &cam, &light, &hs.s, NULL));
    const size_t bytes = om__lspace_bytes(&hs.s) + 2 * om__lgrid_bytes(&hs.s);
    unsigned char *mem = malloc(bytes);
    om_arena a;
    om_arena_init(&a, mem, bytes, "grid");
    om__lspace ls;
    om__lgrid g, p;
    CHECK_OK(om__lspace_init(&ls, &a, &hs.s, NULL));
    CHECK_OK(om__lgrid_init(&g, &a, &ls, NULL));
    CHECK_OK(om__lgrid_init(&p, &a, &ls, NULL));
    CHECK_MSG(a.peak <= bytes, "grid: %zu bytes of %zu", a.peak, bytes);
    om__lspace_begin(&ls, &v);
    om__lgrid_make(&g);
    CHECK_EQ_U(g.ready, 1);
    /* the steps in parts, last part first */
    const uint32_t n = hs.s.ntris, rows = om__lgrid_rows(&p);
    for (uint32_t k = 3; k-- > 0;) om__lgrid_boxes(&p, n * k / 3, n * (k + 1) / 3);
    for (uint32_t k = 5; k-- > 0;) om__lgrid_count(&p, rows * k / 5, rows * (k + 1) / 5);
    om__lgrid_sum(&p);
    for (uint32_t k = 7; k-- > 0;) om__lgrid_fill(&p, rows * k / 7, rows * (k + 1) / 7);
    CHECK(p.ready == 1 && !memcmp(p.start, g.start, ((size_t)g.lists + 1) * sizeof *g.start) &&
          !memcmp(p.tris, g.tris, (size_t)g.start[g.lists] * sizeof *g.tris));
    /* made by parts of the triangles (the frame's jobs: lgrid.h's counting sort), over
     * memory that held other bytes, each step's parts last first */
    static const uint32_t nparts[] = {1, 2, 3, 7};
    for (int i = 0; i < 4; i++) {
        const uint32_t P = nparts[i];
        uint32_t *cnt[7], at[257];
        uint64_t entries[7];
        memset(p.box, 0xA5, (size_t)n * sizeof *p.box);
        memset(p.start, 0xA5, ((size_t)p.lists + 1) * sizeof *p.start);
        memset(p.tris, 0xA5, (size_t)p.cap * sizeof *p.tris);
        p.ready = 0;
        for (uint32_t k = P; k-- > 0;) {
            cnt[k] = malloc(om__lgrid_part_bytes(&p));
            memset(cnt[k], 0xA5, om__lgrid_part_bytes(&p));
            om__lgrid_boxes_count(&p, k, P, cnt[k]);
        }
        for (uint32_t k = P; k-- > 0;) entries[k] = om__lgrid_sum_rows(&p, cnt, k, P);
        om__lgrid_bases(&p, entries, P, at);
        for (uint32_t k = P; k-- > 0;) om__lgrid_fill_part(&p, at, k, P, cnt[k]);
        CHECK_MSG(p.ready == 1 && !memcmp(p.start, g.start, ((size_t)g.lists + 1) * sizeof *g.start) &&
                      !memcmp(p.tris, g.tris, (size_t)g.start[g.lists] * sizeof *g.tris),
                  "grid: the lists made by %u parts differ", P);
        /* with one entry fewer than the lists need, bases says so */
        if (P == 3) {
            const uint32_t cap = p.cap;
            p.cap = g.start[g.lists] - 1;
            for (uint32_t k = 0; k < P; k++) om__lgrid_boxes_count(&p, k, P, cnt[k]);
            for (uint32_t k = 0; k < P; k++) entries[k] = om__lgrid_sum_rows(&p, cnt, k, P);
            om__lgrid_bases(&p, entries, P, at);
            CHECK_MSG(p.ready == -1, "grid: %u entries in %u", g.start[g.lists], p.cap);
            p.cap = cap;
        }
        for (uint32_t k = 0; k < P; k++) free(cnt[k]);
    }
    /* each triangle where its box lies; each list ascending */
    uint32_t *seen = calloc(n, sizeof *seen);
    uint32_t wide = 0, bad = 0, order = 0;
    for (uint32_t c = 0; c < g.lists; c++)
        for (uint32_t e = g.start[c]; e < g.start[c + 1]; e++) {
            const uint32_t t = g.tris[e];
            uint32_t x0, y0, x1, y1, cx = c % g.side, cy = c / g.side;
            const bool cells = tri_cells(&g, t, &x0, &y0, &x1, &y1);
            order += e > g.start[c] && g.tris[e - 1] >= t;
            seen[t]++;
            if (c == g.lists - 1) wide++, bad += cells;
            else bad += !cells || cx < x0 || cx > x1 || cy < y0 || cy > y1;
        }
    uint32_t missing = 0;
    for (uint32_t t = 0; t < n; t++) {
        uint32_t x0, y0, x1, y1;
        missing += seen[t] != (tri_cells(&g, t, &x0, &y0, &x1, &y1) ? (x1 - x0 + 1) * (y1 - y0 + 1) : 1);
    }
    CHECK_MSG(!bad && !order && !missing, "grid: %u misplaced, %u out of order, %u miscounted", bad, order, missing);
    CHECK_MSG(wide > 2 && wide < n / 4, "grid: %u wide of %u (the floor's triangles need clipping)", wide, n);
    /* a tile of samples at two points: the triangles of their cells and the wide ones */
    uint32_t *sel = calloc(om__lgrid_sel_bytes(&hs.s), 1);
    const int64_t pts[2][2] = {{1 << 20, 1 << 20}, {(1 << 20) + (1 << 18), (1 << 20) - (1 << 17)}};
    om__lgrid_clear(&g, sel);
    for (int k = 0; k < 2; k++) om__lgrid_mark(&g, sel, pts[k][0], pts[k][1]);
    om__lgrid_select(&g, sel);
    const uint32_t *tm = om__lgrid_tris(&g, sel);
    uint32_t wrong = 0, picked = 0;
    for (uint32_t t = 0; t < n; t++) {
        uint32_t x0, y0, x1, y1;
        bool want = !tri_cells(&g, t, &x0, &y0, &x1, &y1);
        for (int k = 0; k < 2; k++) {
            const uint32_t cx = (uint32_t)(pts[k][0] >> g.shift), cy = (uint32_t)(pts[k][1] >> g.shift);
            want |= cx >= x0 && cx <= x1 && cy >= y0 && cy <= y1;
        }
        const bool got = (tm[t >> 5] >> (t & 31)) & 1;
        wrong += want != got;
        picked += got;
    }
    CHECK_MSG(!wrong && picked > wide, "selection: %u wrong, %u picked", wrong, picked);
    free(sel);
    free(seen);
    free(mem);
    h_scene_free(&hs);
}

/* A frame of izb in a method arena of `bytes`: the frame's hash, its counters, and how
 * its grid went (2: none, else lgrid's ready). */
typedef struct izb_run { uint64_t hash; uint32_t counters[8]; int grid; } izb_run;

static om_status hash_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    *(uint64_t *)user = om_hash(*(uint64_t *)user, fb->pixels, (size_t)st->rows * fb->stride);
    return OM_OK;
}

static izb_run izb_frame(const om_scene *s, const char *pool, size_t bytes, uint32_t rows)
{
    izb_run r;
    memset(&r, 0, sizeof r);
    r.hash = OM_HASH_INIT;
    const om_method *m = om_method_find("izb");
    om_method_cfg c = h_cfg("izb", pool);
    om_camera cam;
    om_light light;
    om_view v;
    om_diag d;
    void *state;
    om_scene_at(s, 0, &cam, &light);
    cam.width = W;
    cam.height = H;
    CHECK_OK(om_view_init(&v, &cam, &light, s, NULL));
    const size_t fbytes = h_frame_least(W, rows ? rows : H);
    unsigned char *mem = malloc(bytes), *fmem = malloc(fbytes), *px = malloc(W * H * 3);
    om_arena ma, fa;
    om_arena_init(&ma, mem, bytes, "method");
    om_arena_init(&fa, fmem, fbytes, "frame");
    CHECK_OK(om_method_init(m, &state, &ma, &c, s, W, H, &d));
    om_framebuffer fb = {OM_RGB888, W, H, W * 3, px};
    om_shade_cfg shade;
    om_shade_cfg_default(&shade);
    om_frame_desc fd;
    memset(&fd, 0, sizeof fd);
    fd.scene = s; fd.view = &v; fd.method = m; fd.method_state = state; fd.shade = &shade;
    fd.fb = &fb; fd.strip_rows = rows; fd.on_strip = hash_strip; fd.user = &r.hash;
    CHECK_OK(om_render_frame(&fd, &fa, NULL, &d));
    om_method_stats ms;
    om_method_get_stats(m, state, &ms);
    for (uint32_t k = 0; k < ms.ncounters && k < 8; k++) r.counters[k] = (uint32_t)ms.counters[k];
    const om__izb *z = om__izb_of(state);
    r.grid = z->grid ? z->grid->ready : 2;
    free(mem);
    free(fmem);
    free(px);
    return r;
}

/* With the grid, each tile walks only the triangles whose box meets its samples' cells
 * (and the wide ones); the same frame and counters as an arena short of it,
 * where every tile walks every triangle: whole frames and strips, one tile and many;
 * and on a scene of triangles too large for its lists, the grid left unused. */
static void grid_same_walk(void)
{
    static const char *const scenes[2] = {
        "camera eye 0 5 8 target 0 0.5 0 fov 55\n"
        "light spot pos 1 9 2 target 0 0 0 fov 75 near 1 far 40\n"
        "plane size 14 14 divisions 3\n"
        "triangles count 4000 seed 4 area 25 in -3 0.3 -3 3 3 3\n"
        "triangles count 500 seed 9 area 20 in -3 0.3 -3 3 3 3 albedo 1 0.6 0.2 opacity 0.5\n",
        /* triangles of a few cells each: more entries than the lists hold */
        "camera eye 0 5 8 target 0 0.5 0 fov 55\n"
        "light spot pos 1 9 2 target 0 0 0 fov 75 near 1 far 40\n"
        "plane size 14 14 divisions 3\n"
        "triangles count 1200 seed 4 area 300 in -3 0.3 -3 3 3 3\n"};
    for (int si = 0; si < 2; si++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[si])) continue;
        const om_method *m = om_method_find("izb");
        for (int pi = 0; pi < 2; pi++) {
            const char *pool = pi ? "izb.pool=1500" : "izb.pool=0";
            om_method_cfg c = h_cfg("izb", pool);
            size_t mn, full;
            CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
            for (uint32_t rows = 0; rows <= 16; rows += 16) {
                izb_run a = izb_frame(&hs.s, pool, full, rows),
                        b = izb_frame(&hs.s, pool, full - om__lgrid_bytes(&hs.s) / 2, rows);
                CHECK_MSG(a.grid == (si ? -1 : 1) && b.grid == 2, "scene %d %s strips %u: grid %d, %d", si, pool,
                          rows, a.grid, b.grid);
                CHECK_MSG(a.hash == b.hash && !memcmp(a.counters, b.counters, sizeof a.counters),
                          "scene %d %s strips %u: the grid changes the frame", si, pool, rows);
                CHECK_MSG(pi == 0 || a.counters[5] > 4, "%s: %u tiles", pool, a.counters[5]);
            }
        }
        h_scene_free(&hs);
    }
}

/* ---- izb: its tiles of exposed samples as jobs (om__pass), each with a pool of its
 * own from the frame arena. The same terms, pixels and counters for any number of jobs
 * and their order, whole frames and strips, one tile or many (izb.pool); a frame arena
 * without room for two pools runs the tiles inline, the same again. */
static void izb_pass(void)
{
    om_jobs *pools[4];
    uint32_t calls = 0;
    const om_method *m = om_method_find("izb");
    for (int k = 0; k < 4; k++) CHECK_OK(om_jobs_start(&pools[k], pass_threads[k], NULL));
    for (int li = 0; li < 2; li++) {
        h_scene hs;
        if (!h_scene_parse(&hs, li ? directional_scene : om_scene_default_text())) continue;
        for (int pi = 0; pi < 3; pi++)
            for (uint32_t rows = 0; rows <= 24; rows += 24) {
                static const uint32_t pool_of[] = {0, 397, 2000};
                char set[32];
                snprintf(set, sizeof set, "izb.pool=%u", pool_of[pi]);
                frame_out one = render_set(&hs.s, m, set, 160, 120, rows, NULL, NULL, 1, 0, true);
                CHECK_MSG(one.st == OM_OK && one.jobs == 1, "izb: inline frame");
                size_t last_peak = 0;
                /* a pool of 397 leaves many tiles a strip */
                CHECK_MSG(pi != 1 || one.ms.counters[5] > 3 * (rows ? 120 / rows : 1), "izb pool %u: %u tiles",
                          pool_of[pi], one.ms.counters[5]);
                for (size_t k = 0; k < PASS_HOSTS; k++) {
                    const pass_host *h = &pass_hosts[k];
                    const uint32_t n = host_threads(h);
                    const bool lean = h->lean;   /* room for the bands' slots only: the tiles inline */
                    frame_out o = pass_frame(&hs.s, m, set, rows, h, pools, &calls);
                    CHECK_MSG(o.st == OM_OK && o.jobs == n, "izb: %u jobs ran %u", n, o.jobs);
                    CHECK_MSG(o.hash == one.hash && !memcmp(o.ms.counters, one.ms.counters, sizeof o.ms.counters),
                              "izb light %d pool %u strips %u: %u threads%s change the frame", li, pool_of[pi],
                              rows, n, h->what);
                    /* the pools of two jobs at least (keys of 24 bytes, two buffers); the
                     * lean frame (5 jobs, as the one before it) without them */
                    size_t pool = pool_of[pi] ? pool_of[pi] : 160 * 120;
                    if (!lean) CHECK_MSG(o.peak > one.peak + 2 * 48 * pool, "izb %u jobs: no pools (%zu vs %zu)",
                                         n, o.peak, one.peak);
                    else CHECK_MSG(o.peak + 2 * 48 * pool < last_peak, "izb lean: %zu vs %zu", o.peak, last_peak);
                    last_peak = o.peak;
                }
            }
        h_scene_free(&hs);
    }
    CHECK_MSG(calls > 0, "izb: the pass never asked the host which thread runs a job");
    for (int k = 0; k < 4; k++) om_jobs_stop(pools[k]);
}

void suite_izb(void)
{
    RUN(izb_default_scene);
    RUN(random_scenes);
    RUN(hot_spot);
    RUN(directional);
    RUN(budgets);
    RUN(default_pool);
    RUN(grid_lists);
    RUN(grid_same_walk);
    RUN(izb_pass);
}
