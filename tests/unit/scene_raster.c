/* unit/scene_raster.c — the walk over a scene's triangles (om__scene_raster,
 * scene_raster.c): without vertex bins it transforms, tests, projects and boxes a batch
 * of triangles at a time and passes over those whose box holds no pixel centre. Its
 * maps and ids must be exactly those of sending every triangle on its own through
 * om__raster_tri_guarded, as the walk did before: here over scenes whose triangles are
 * tiny (most between pixel centres), cross the near and far planes and the guard band,
 * have vertices that are NaN, infinite or huge, and whose count is no multiple of the
 * batch; into whole targets and strips, depth and depth + id, with and without the
 * culling of closed shapes and the coarse depth. With the frame's bins (rows and
 * vertices snapped alone), whose triangles a 32-bit box test passes over first, too;
 * and the bins themselves, made in parts, against each vertex projected alone. And the
 * back-face culling of closed shapes (om__cull) leaving light and eye maps the same. */
#include "../test.h"
#include "../../engine/raster/scene_raster.h"
#include "../../engine/raster/hiz.h"
#include "../harness.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Every triangle on its own, in order, as the walk did before it had batches. */
static void walk_one_by_one(const om_scene *s, const om_mat4 *vp, om_vec3 o, const om_target *tg, om_raster_mode mode,
                            bool cull, uint32_t *hiz)
{
    om_raster r;
    memset(&r, 0, sizeof r);
    r.target = tg;
    r.mode = mode;
    om__cull cl;
    om__cull_begin(&cl, s, vp, o);
    om__target_clear(tg);
    om__hiz_clear(hiz, tg);
    const om__guard g = om__guard_band(tg->width, tg->height);
    for (uint32_t t = 0; t < s->ntris; t++) {
        r.cull_back = cull && om__cull_next(&cl, t);
        om_vec4 c[3];
        om__clip_tri(s, vp, o, t, c);
        om__raster_tri_guarded(&r, hiz, c, t, tg->width, tg->height, g);
    }
}

/* The walk against one by one on scene s through vp onto a W x H image: whole, and by
 * strips of `strip` rows (the coarse depth only where its tiles fit, rows from a
 * multiple of 16). Returns the number of texels either drew. */
static size_t compare_walks(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t W, uint32_t H, uint32_t strip)
{
    size_t n = (size_t)W * H, drawn = 0;
    uint32_t *da = malloc(n * 4), *db = malloc(n * 4), *ia = malloc(n * 4), *ib = malloc(n * 4);
    uint32_t *ha = malloc(om__hiz_words(W, H) * 4), *hb = malloc(om__hiz_words(W, H) * 4);
    om__bins bins = {malloc((size_t)s->ntris * 4), malloc((size_t)s->nverts * sizeof(om__vsnap)), false};
    om__bins exact = {malloc((size_t)s->ntris * 4), bins.verts, true};
    CHECK(da && db && ia && ib && ha && hb && bins.rows && bins.verts && exact.rows);
    if (bins.rows && bins.verts && exact.rows) {
        om__bins_make(s, vp, o, W, H, &bins);
        om__bins_make_rows(s, vp, o, W, H, &exact, 0, s->ntris);
    }
    for (int mode = 0; da && db && ia && ib && ha && hb && bins.rows && bins.verts && exact.rows && mode < 12; mode++) {
        /* mode 4..7 with the bins (rows and snapped vertices), 8..11 with rows of pixel
         * centres (om__bins.centres, where the CPU has lanes) */
        const bool id = mode & 1, cull = mode & 2, binned = mode >= 4;
        const om__bins *with = mode >= 8 ? &exact : &bins;
        for (uint32_t y0 = 0; y0 < H; y0 += strip) {
            const uint32_t rows = H - y0 < strip ? H - y0 : strip;
            om_target ta = {W, H, y0, rows, da + (size_t)y0 * W, id ? ia + (size_t)y0 * W : NULL};
            om_target tb = {W, H, y0, rows, db + (size_t)y0 * W, id ? ib + (size_t)y0 * W : NULL};
            const bool coarse = !id && om__hiz_fits(&ta);
            const om_raster_mode m = id ? OM_RASTER_DEPTH_ID : OM_RASTER_DEPTH;
            om__scene_raster_hiz(s, vp, o, &ta, m, cull, binned ? with : NULL, coarse ? ha : NULL);
            walk_one_by_one(s, vp, o, &tb, m, cull, coarse ? hb : NULL);
        }
        size_t diff = 0;
        for (size_t i = 0; i < n; i++) {
            diff += da[i] != db[i] || (id && ia[i] != ib[i]);
            drawn += da[i] != 0xFFFFFFFFu;
        }
        CHECK_MSG(diff == 0, "%ux%u strips of %u, mode %d: %zu texels differ", W, H, strip, mode, diff);
    }
    free(da);
    free(db);
    free(ia);
    free(ib);
    free(ha);
    free(hb);
    free(bins.rows);
    free(bins.verts);
    free(exact.rows);
    return drawn;
}

/* The bins of scene s through vp onto a W x H image, made in one go and in parts cut
 * anywhere (mid-batch, one vertex, empty): each vertex exactly what om__project gives
 * it alone when om__raster_tri would send it unclipped (finite, inside every plane),
 * x = INT32_MIN when not; the rows the same however cut. Returns how many were alone. */
static size_t check_bins(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t W, uint32_t H)
{
    om__bins a = {malloc((size_t)s->ntris * 4), malloc((size_t)s->nverts * sizeof(om__vsnap)), false};
    om__bins b = {malloc((size_t)s->ntris * 4), malloc((size_t)s->nverts * sizeof(om__vsnap)), false};
    size_t alone = 0;
    CHECK(a.rows && a.verts && b.rows && b.verts);
    if (!(a.rows && a.verts && b.rows && b.verts)) goto out;
    memset(b.verts, 0x5A, (size_t)s->nverts * sizeof(om__vsnap));   /* not zeroed, as the frame's */
    memset(b.rows, 0x5A, (size_t)s->ntris * 4);
    om__bins_make(s, vp, o, W, H, &a);
    const uint32_t cuts[] = {0, 1, 5, 29, 30, 77, s->nverts / 2, s->nverts - 1, s->nverts};
    for (int k = 0; k + 1 < 9; k++)
        if (cuts[k] <= cuts[k + 1]) om__bins_make_verts(s, vp, o, W, H, &b, cuts[k], cuts[k + 1]);
    om__bins_make_rows(s, vp, o, W, H, &b, 0, s->ntris / 3);
    om__bins_make_rows(s, vp, o, W, H, &b, s->ntris / 3, s->ntris + 9);
    size_t wrong = 0;
    const om__guard g = om__guard_band(W, H);
    for (uint32_t v = 0; v < s->nverts; v++) {
        const om_vec4 c = om__mat_apply(vp, om__sub(s->verts[v], o));
        int64_t x, y;
        uint32_t z;
        const bool in = om__finite(c.x) && om__finite(c.y) && om__finite(c.z) && om__finite(c.w) &&
                        om__inside_band(&c, g) && om__project(&c, W, H, &x, &y, &z);
        const om__vsnap *p = &a.verts[v], *q = &b.verts[v];
        alone += in;
        wrong += in ? p->x != x || p->y != y || p->z != z : p->x != INT32_MIN;
        wrong += p->x != q->x || p->y != q->y || p->z != q->z;
    }
    for (uint32_t t = 0; t < s->ntris; t++) wrong += a.rows[t] != b.rows[t];
    CHECK_MSG(wrong == 0, "%ux%u: %zu vertices or rows differ", W, H, wrong);
    CHECK_MSG(alone > s->nverts / 4, "%ux%u: %zu of %u vertices alone", W, H, alone, s->nverts);
out:
    free(a.rows);
    free(a.verts);
    free(b.rows);
    free(b.verts);
    return alone;
}

/* Tiny triangles around a camera inside the cloud (the near plane cuts some, the
 * guard band others), closed shapes in front of it and behind, 4,003 triangles (not a
 * multiple of any batch); then the same with some vertices made NaN, infinite, huge or
 * zero-w, every few of them, so that such lanes fall in every position of a batch. */
static void scene_walk_same_as_one_by_one(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 1 0 target 0 1 -5 fov 70 near 0.05 far 9\n"
                            "light spot pos 3 8 2 target 0 0 -2 fov 80 near 1 far 30\n"
                            "box size 1 1 1 translate 0 0.5 -3\nsphere radius 0.6 translate 1 1 2\n"
                            "triangles count 3000 seed 3 area 0.4 in -4 -1 -10 4 3 2\n"
                            "triangles count 800 seed 5 area 30 in -6 -2 -12 6 4 3\n"
                            "triangles count 179 seed 9 area 0.001 in -1 0 -3 1 2 -1\n"))
        return;
    om_scene *s = &hs.s;
    om_view v;
    om_diag d;
    for (int round = 0; round < 2; round++) {
        if (round == 1) {   /* vertices no projection can take */
            const float bad[] = {NAN, INFINITY, -INFINITY, 1e30f, -1e30f, 3e38f, 0.0f};
            for (uint32_t i = 0; i < s->nverts; i += 37) {
                om_vec3 *p = &s->verts[i];
                const float b = bad[(i / 37) % 7];
                if ((i / 37) % 3 == 0) p->x = b;
                else if ((i / 37) % 3 == 1) p->y = b;
                else p->z = b;
            }
        }
        om_camera cam = s->camera;
        cam.width = 96;
        cam.height = 64;
        if (om_view_init(&v, &cam, &s->light, s, &d) != OM_OK) {
            CHECK_MSG(false, "view: %s", d.msg);
            break;
        }
        CHECK(check_bins(s, &v.cam_vp, v.origin, 96, 64) < s->nverts);   /* some need clipping */
        check_bins(s, &v.light_vp, v.origin, 256, 256);
        const size_t eye = compare_walks(s, &v.cam_vp, v.origin, 96, 64, 64);
        compare_walks(s, &v.cam_vp, v.origin, 96, 64, 7);
        compare_walks(s, &v.cam_vp, v.origin, 37, 23, 5);
        const size_t light = compare_walks(s, &v.light_vp, v.origin, 128, 128, 128);
        compare_walks(s, &v.light_vp, v.origin, 256, 256, 32);
        /* the scenes draw: not a comparison of empty maps */
        CHECK(eye > 96 * 64 / 2);
        CHECK(light > 128 * 128 / 4);
    }
    h_scene_free(&hs);
}

/* The bins' vertex depths at om__zdepth's edges: a matrix that takes vertex (w, 0, z)
 * to clip space (0, 0, z, w), so that each vertex tests one pair: z of 0 and -0,
 * subnormal, one unit and just below, equal to w and an ulp either side, w subnormal
 * or near 2^127, and z/w below 2^-24, through every position of a batch. */
static void bins_depths_at_the_edges(void)
{
    const float zs[] = {0.0f, -0.0f, 1e-45f, 1e-40f, 1.1754942e-38f, 1.17549435e-38f, 2.3283064e-10f,
                        2.3283063e-10f, 5.9604645e-08f, 0.25f, 0.5f, 0.99999994f, 1.0f, 1.0000001f,
                        3e38f, 1e-30f, 7.0f, 0.3333333f};
    const float ws[] = {1.0f, 1e-39f, 1.17549435e-38f, 3.4e38f, 0.5f, 1e10f, 7.0f, 2.0f};
    enum { NZ = sizeof zs / sizeof zs[0], NW = sizeof ws / sizeof ws[0], N = NZ * NW };
    om_vec3 verts[N];
    for (int i = 0; i < N; i++) verts[i] = om__v3(ws[i % NW], 0.0f, zs[i / NW]);
    om_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.nverts = N;
    sc.verts = verts;
    om_mat4 vp;
    memset(&vp, 0, sizeof vp);
    vp.m[10] = 1.0f;   /* z' = z */
    vp.m[12] = 1.0f;   /* w' = x */
    om__vsnap vs[N];
    om__bins b = {NULL, vs, false};
    size_t wrong = 0, inside = 0;
    for (uint32_t v0 = 0; v0 < 24; v0 += 7) {   /* batches starting anywhere */
        memset(vs, 0x5A, sizeof vs);
        om__bins_make_verts(&sc, &vp, om__v3(0, 0, 0), 64, 64, &b, v0, N);
        for (uint32_t v = v0; v < N; v++) {
            const om_vec4 c = om__mat_apply(&vp, verts[v]);
            int64_t x, y;
            uint32_t z;
            const bool in = om__inside_band(&c, om__guard_band(64, 64)) && om__project(&c, 64, 64, &x, &y, &z);
            inside += in;
            wrong += in ? vs[v].x == INT32_MIN || vs[v].z != z : vs[v].x != INT32_MIN;
        }
    }
    CHECK_MSG(wrong == 0, "%zu vertex depths differ from om__zdepth", wrong);
    CHECK(inside > N);   /* most pairs are inside the near and far planes */
}

/* Rows of pixel centres (om__bins.centres) where they are tightest: triangles on a
 * 16 x 16 image whose corners lie on pixel centres, a sub-pixel unit either side of
 * them, and between (x/w, y/w chosen so that om__project_xy lands on those grid points
 * exactly), walked by strips of 1, 2 and 3 rows with and without the bins, against
 * every triangle on its own. A row too few at a box's top or left shows here (moving
 * those ends by a sub-pixel unit fails it); the bottom and right ends hold a centre
 * only at a corner there, which the top-left rule never covers. */
static void centre_rows_at_the_edges(void)
{
    enum { W = 16, T = 1500 };   /* a 16 x 16 image: om__project_xy's scale is 2048 */
    om_vec3 verts[3 * T];
    uint32_t idx[3 * T];
    uint32_t rng = 12345;
    int32_t g[3 * T][2];
    for (int i = 0; i < 3 * T; i++) {
        for (int k = 0; k < 2; k++) {
            rng = rng * 1664525u + 1013904223u;
            const int32_t off[] = {-1, 0, 0, 0, 1, 127, -128};
            const int32_t at = i % 3 ? g[i - i % 3][k] / 256 + (int32_t)(rng >> 8) % 5 - 2   /* near corner 0 */
                                     : (int32_t)(rng >> 8) % (W + 2) - 1;
            g[i][k] = at * 256 + 128 + off[(rng >> 4) % 7];
        }
        /* a horizontal or vertical edge in many (a centre on a top or left edge counts) */
        if (i % 3 == 1 && (rng >> 20) % 2) g[i][1] = g[i - 1][1];
        if (i % 3 == 2 && (rng >> 21) % 2) g[i][0] = g[i - 2][0];
        /* X = (x + 1) * 2048 + 0.5 and Y = (1 - y) * 2048 + 0.5 are g exactly */
        verts[i] = om__v3(((float)g[i][0] - 0.5f) / 2048.0f - 1.0f, 1.0f - ((float)g[i][1] - 0.5f) / 2048.0f,
                          0.25f + (float)(i % 7) / 16.0f);
        idx[i] = (uint32_t)i;
    }
    om_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.nverts = 3 * T;
    sc.verts = verts;
    sc.ntris = T;
    sc.idx = idx;
    om_mat4 vp;
    memset(&vp, 0, sizeof vp);
    vp.m[0] = vp.m[5] = vp.m[10] = vp.m[15] = 1.0f;   /* clip = (x, y, z, 1) */
    const size_t drawn = compare_walks(&sc, &vp, om__v3(0, 0, 0), W, W, 1);
    compare_walks(&sc, &vp, om__v3(0, 0, 0), W, W, 2);
    compare_walks(&sc, &vp, om__v3(0, 0, 0), W, W, 3);
    CHECK(drawn > W * W / 2);
}

/* Rasterizes the scene through vp without and with culling into (d0, i0) and (d1, i1)
 * (ids NULL: depth only) and counts the texels that differ; *covered counts those the
 * unculled pass reached. */
static uint32_t cull_diff(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t n, uint32_t *d0, uint32_t *i0,
                          uint32_t *d1, uint32_t *i1, uint32_t *covered)
{
    om_raster_mode mode = i0 ? OM_RASTER_DEPTH_ID : OM_RASTER_DEPTH;
    om_target t0 = {n, n, 0, n, d0, i0}, t1 = {n, n, 0, n, d1, i1};
    om__scene_raster(s, vp, o, &t0, mode, false, NULL);
    om__scene_raster(s, vp, o, &t1, mode, true, NULL);
    uint32_t diff = 0;
    *covered = 0;
    for (uint32_t i = 0; i < n * n; i++) {
        diff += d0[i] != d1[i] || (i0 && i0[i] != i1[i]);
        *covered += d0[i] != UINT32_MAX;
    }
    return diff;
}

/* Back-face culling of a light's depth map (om__cull): the scene records its closed
 * shapes, and on them the map is the same bits with and without culling, wherever the
 * light is; a solid that holds the light or that the near plane cuts is not culled
 * (culling it would lose its nearest, back-facing, surface). */
static void light_cull_keeps_the_map(void)
{
    enum { N = 512 };
    static uint32_t full[N * N], culled[N * N];
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 6 9 target 0 0 0 fov 60 size 160 120 near 0.1 far 100\n"
                            "light spot pos 6 8 5 target 0 0 0 fov 70 near 0.5 far 40\n"
                            "plane size 20 20 divisions 4\n"
                            "box size 2 1 3 rotate 10 20 30 translate -3 0.8 0\n"
                            "sphere radius 1 segments 24 rings 12 scale 1 0.5 2 rotate 0 40 0 translate 0 1 -3\n"
                            "triangles count 60 seed 1 area 4 in -5 0 -5 5 3 5\n"
                            "box size 1 1 1 scale -1 2 1 rotate 0 30 0 translate 3 0.5 2\n"
                            "cylinder radius 0.5 height 2 segments 20 rotate 90 0 0 translate 2 1 -2\n"
                            "box size 4 4 4 translate 8 2 8\n"))
        return;
    const om_scene *s = &hs.s;
    /* the three boxes, the sphere and the cylinder, in scene order; not the plane or
     * the triangle cloud */
    static const uint32_t counts[5] = {12, 2 * 24 * 11, 12, 4 * 20, 12};
    CHECK_EQ_U(s->nsolids, 5);
    uint32_t first[5] = {32, 32 + 12, 32 + 12 + 2 * 24 * 11 + 60, 0, 0};
    first[3] = first[2] + 12;
    first[4] = first[3] + 80;
    for (uint32_t k = 0; k < s->nsolids && k < 5; k++) {
        const om_solid *o = &s->solids[k];
        CHECK_EQ_U(o->first, first[k]);
        CHECK_EQ_U(o->count, counts[k]);
        for (uint32_t t = o->first; t < o->first + o->count; t++)
            for (int c = 0; c < 3; c++) {
                om_vec3 v = s->verts[s->idx[3 * t + c]];
                CHECK(v.x >= o->lo.x && v.y >= o->lo.y && v.z >= o->lo.z);
                CHECK(v.x <= o->hi.x && v.y <= o->hi.y && v.z <= o->hi.z);
            }
    }
    CHECK_EQ_U(first[4] + 12, s->ntris);
    /* lights: above, grazing, inside the last box, with a near plane through the
     * first box, and a directional light */
    static const float lights[5][8] = {
        {6, 8, 5, 0, 0, 0, 0.5f, 40}, {-9, 2, -7, 0, 0.5f, 0, 0.5f, 40},
        {8, 2, 8, 0, 0, 0, 0.2f, 40}, {-3, 3.5f, 0, -3, 0, 0, 2.6f, 20}, {0, 0, 0, 0, 0, 0, 0, 0}};
    for (int k = 0; k < 5; k++) {
        om_camera cam;
        om_light light;
        om_scene_at(s, 0, &cam, &light);
        const float *l = lights[k];
        if (k == 4) {
            light.kind = OM_LIGHT_DIRECTIONAL;
            light.dir = om__v3(0.3f, -1.0f, 0.2f);
        } else {
            light.pos = om__v3(l[0], l[1], l[2]);
            light.target = om__v3(l[3], l[4], l[5]);
            light.znear = l[6];
            light.zfar = l[7];
        }
        om_view v;
        CHECK_OK(om_view_init(&v, &cam, &light, s, NULL));
        uint32_t covered, diff = cull_diff(s, &v.light_vp, v.origin, N, full, NULL, culled, NULL, &covered);
        CHECK_MSG(diff == 0, "light %d: %u of %u covered texels differ", k, diff, covered);
        CHECK(covered > N * N / 8);
        /* which solids were culled */
        om__cull cl;
        om__cull_begin(&cl, s, &v.light_vp, v.origin);
        unsigned on = 0;
        for (uint32_t t = 0; t < s->ntris; t++)
            if (om__cull_next(&cl, t))
                for (unsigned j = 0; j < 5; j++)
                    if (t == first[j]) on |= 1u << j;
        /* light 0 has the last box behind it and light 2 inside it; light 3's near
         * plane (y = 0.9) cuts every solid, though the light is inside none */
        unsigned want = k == 0 || k == 2 ? 0x0Fu : k == 3 ? 0u : 0x1Fu;
        CHECK_MSG(on == want, "light %d: solids culled %#x, expected %#x", k, on, want);
    }
    /* the eye pass culls too: the same depths and visible triangles from the scene's
     * camera, from one inside the last box and from one whose near plane cuts it */
    static const float eyes[3][7] = {{0, 6, 9, 0, 0, 0, 0.1f}, {8, 2, 8, 0, 0, 0, 0.1f},
                                     {8, 2, 11, 8, 2, 0, 1.5f}};
    static uint32_t ids_full[N * N], ids_culled[N * N];
    for (int k = 0; k < 3; k++) {
        om_camera cam;
        om_light light;
        om_scene_at(s, 0, &cam, &light);
        const float *e = eyes[k];
        cam.eye = om__v3(e[0], e[1], e[2]);
        cam.target = om__v3(e[3], e[4], e[5]);
        cam.znear = e[6];
        om_view v;
        CHECK_OK(om_view_init(&v, &cam, &light, s, NULL));
        uint32_t covered, diff = cull_diff(s, &v.cam_vp, v.origin, N, full, ids_full, culled, ids_culled, &covered);
        CHECK_MSG(diff == 0, "eye %d: %u of %u covered texels differ", k, diff, covered);
        CHECK(covered > N * N / 8);
    }
    h_scene_free(&hs);
}

void suite_scene_raster(void)
{
    RUN(scene_walk_same_as_one_by_one);
    RUN(bins_depths_at_the_edges);
    RUN(centre_rows_at_the_edges);
    RUN(light_cull_keeps_the_map);
}
