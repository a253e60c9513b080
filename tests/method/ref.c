/* method/ref.c — the reference: analytic cases, the BVH walk against a brute-force
 * loop over every triangle (semi-transparent casters included), the one-pass fit of
 * the light's BVH in parts, and its smaller modes giving the one-pass terms. Its
 * independent oracle is property/oracle.c's. */
#include "../test.h"
#include "../harness.h"
#include "../../engine/shadow/common/occlude.h"
#include "../../engine/shadow/ref/ref_light.h"

#include <math.h>
#include <stdlib.h>

#define W 160
#define H 120
static uint8_t mask[W * H];
static om_term terms[W * H];
static om_sample samples[W * H];

static const char *default_scene(void) { return om_scene_default_text(); }

/* A floor and a cloud (the static part) under 40 copies of one sphere. */
#define OBJECTS_SCENE                                                                 \
    "camera eye 0 6 14 target 0 1 0 fov 50\n"                                         \
    "light spot pos 8 20 6 target 0 0 0 fov 60 near 5 far 60\n"                       \
    "plane size 40 40 divisions 8\n"                                                  \
    "triangles count 8000 seed 3 area 20 in -5 2.5 -5 5 3 5\n"                        \
    "sphere radius 0.4 segments 24 rings 12 translate -4 1 -4 name s0\n"              \
    "copy s0 translate 1 0 0\ncopy s0 translate 2 0 0\ncopy s0 translate 3 0 0\n"    \
    "copy s0 translate 4 0 0\ncopy s0 translate 5 0 0\ncopy s0 translate 6 0 0\n"    \
    "copy s0 translate 7 0 0\ncopy s0 translate 0 0 1\ncopy s0 translate 1 0 1\n"    \
    "copy s0 translate 2 0 1\ncopy s0 translate 3 0 1\ncopy s0 translate 4 0 1\n"    \
    "copy s0 translate 5 0 1\ncopy s0 translate 6 0 1\ncopy s0 translate 7 0 1\n"    \
    "copy s0 translate 0 0 2\ncopy s0 translate 1 0 2\ncopy s0 translate 2 0 2\n"    \
    "copy s0 translate 3 0 2\ncopy s0 translate 4 0 2\ncopy s0 translate 5 0 2\n"    \
    "copy s0 translate 6 0 2\ncopy s0 translate 7 0 2\ncopy s0 translate 0 0 3\n"    \
    "copy s0 translate 1 0 3\ncopy s0 translate 2 0 3\ncopy s0 translate 3 0 3\n"    \
    "copy s0 translate 4 0 3\ncopy s0 translate 5 0 3\ncopy s0 translate 6 0 3\n"    \
    "copy s0 translate 7 0 3\ncopy s0 translate 0 0 4\ncopy s0 translate 1 0 4\n"    \
    "copy s0 translate 2 0 4\ncopy s0 translate 3 0 4\ncopy s0 translate 4 0 4\n"    \
    "copy s0 translate 5 0 4\ncopy s0 translate 6 0 4\ncopy s0 translate 7 0 4\n"

static om_status capture_terms(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)fb;
    om_term *t = *(om_term **)user;
    memcpy(t + (size_t)st->y0 * st->width, st->terms, (size_t)st->rows * st->width * sizeof *t);
    return OM_OK;
}

static void square_under_sun(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 6 6 target 0 0 0 fov 60 size 160 120 near 0.1 far 100\n"
                            "light directional dir 0 -1 0\n"
                            "plane size 20 20\n"
                            "plane size 2 2 translate 0 1 0\n"))
        return;
    CHECK_OK(h_render(&hs.s, "ref", NULL, 0, 0, 0, 0, mask, NULL, samples));
    int checked = 0, shadowed = 0, wrong = 0;
    const om_vec3 o = h_origin(&hs.s, 0);
    for (int i = 0; i < W * H; i++) {
        if (samples[i].tri == OM_NO_TRI || samples[i].p[1] + o.y > 0.5f) continue;   /* floor only */
        float x = fabsf(samples[i].p[0] + o.x), z = fabsf(samples[i].p[2] + o.z);
        if (fabsf(x - 1) < 1e-4f || fabsf(z - 1) < 1e-4f) continue;
        bool expect_shadow = x < 1 && z < 1;
        checked++;
        shadowed += expect_shadow;
        if ((mask[i] == OM_MASK_SHADOW) != expect_shadow) wrong++;
    }
    CHECK_MSG(wrong == 0, "%d of %d floor samples wrong", wrong, checked);
    CHECK(shadowed > 200 && checked > 5000);
    h_scene_free(&hs);
}

/* Segment p -> l against triangle (a, b, c) in double: 1 clearly hit, -1 clearly
 * missed, 0 within eps of an edge or an end (left out of the comparison). */
static int seg_tri(const double p[3], const double l[3], const om_vec3 *a, const om_vec3 *b,
                   const om_vec3 *c, double eps)
{
    double d[3] = {l[0] - p[0], l[1] - p[1], l[2] - p[2]};
    double e1[3] = {b->x - a->x, b->y - a->y, b->z - a->z}, e2[3] = {c->x - a->x, c->y - a->y, c->z - a->z};
    double q[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
    double det = e1[0] * q[0] + e1[1] * q[1] + e1[2] * q[2];
    if (fabs(det) < 1e-12) return -1;
    double s[3] = {p[0] - a->x, p[1] - a->y, p[2] - a->z};
    double u = (s[0] * q[0] + s[1] * q[1] + s[2] * q[2]) / det;
    double r[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
    double v = (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]) / det;
    double t = (e2[0] * r[0] + e2[1] * r[1] + e2[2] * r[2]) / det;
    if (u > eps && v > eps && u + v < 1 - eps && t > eps && t < 1 - eps) return 1;
    if (u < -eps || v < -eps || u + v > 1 + eps || t < -eps || t > 1 + eps) return -1;
    return 0;
}

static void sphere_under_spot(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, "camera eye 0 5 7 target 0 0.5 0 fov 50 size 160 120 near 0.1 far 100\n"
                            "light spot pos 1 8 0.5 target 0 0 0 fov 70 near 1 far 30\n"
                            "plane size 20 20\n"
                            "sphere radius 1 segments 48 rings 24 translate 0 1.5 0\n"))
        return;
    CHECK_OK(h_render(&hs.s, "ref", NULL, 0, 0, 0, 0, mask, terms, samples));
    const double L[3] = {1, 8, 0.5};
    const om_vec3 o = h_origin(&hs.s, 0);
    int checked = 0, shadowed = 0, wrong = 0;
    for (int i = 0; i < W * H; i++) {
        /* floor samples inside the light's frustum (outside it nothing is lit) */
        if (samples[i].tri == OM_NO_TRI || samples[i].tri >= 2 || !(terms[i].flags & OM_TERM_EXPOSED))
            continue;
        double p[3] = {(double)samples[i].p[0] + o.x, (double)samples[i].p[1] + o.y, (double)samples[i].p[2] + o.z};
        int verdict = -1;
        for (uint32_t t = 2; t < hs.s.ntris && verdict != 1; t++) {
            const uint32_t *ix = hs.s.idx + 3 * t;
            int r = seg_tri(p, L, &hs.s.verts[ix[0]], &hs.s.verts[ix[1]], &hs.s.verts[ix[2]], 1e-4);
            if (r == 1) verdict = 1;
            else if (r == 0) verdict = 0;
        }
        if (verdict == 0) continue;
        checked++;
        shadowed += verdict == 1;
        if ((mask[i] == OM_MASK_SHADOW) != (verdict == 1)) wrong++;
    }
    CHECK_MSG(wrong == 0, "%d of %d floor samples wrong", wrong, checked);
    CHECK(shadowed > 200 && checked > 5000);
    h_scene_free(&hs);
}

/* The reference's BVH walk must give exactly what testing every triangle gives. */
static void bvh_equals_brute_force(void)
{
    static const char *scenes[] = {
        "camera eye 0 5 8 target 0 0.5 0 fov 55 size 160 120\n"
        "light spot pos 3 9 2 target 0 0 0 fov 75 near 1 far 40\n"
        "plane size 14 14\n"
        "triangles count 400 seed 3 area 25 in -3 0.3 -3 3 3 3\n"
        "triangles count 200 seed 4 area 20 in -3 0.3 -3 3 3 3 albedo 1 0.6 0.2 opacity 0.5\n",
        "camera eye 2 4 6 target 0 0.5 0 fov 60 size 160 120\n"
        "light spot pos -4 7 -1 target 0 0 0 fov 80 near 0.5 far 40\n"
        "plane size 14 14 divisions 6\n"
        "sphere radius 0.8 segments 20 rings 10 translate 0.5 1.2 0 opacity 0.6 albedo 0.2 0.9 0.9\n"
        "box size 1 2 1 translate -1 1 0\n"
        "triangles count 150 seed 9 area 6 in -2 2 -2 2 3 2 opacity 0.3\n",
    };
    for (int k = 0; k < 2; k++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[k])) return;
        CHECK_OK(h_render(&hs.s, "ref", NULL, 0, 0, 0, 0, NULL, terms, samples));
        om_view v;
        CHECK_OK(h_view(&v, &hs.s, 0, 0, 0, NULL));
        static unsigned char mem[1 << 20];
        om_arena a;
        om_arena_init(&a, mem, sizeof mem, "t");
        om__lspace ls;
        CHECK_OK(om__lspace_init(&ls, &a, &hs.s, NULL));
        om__lspace_begin(&ls, &v);
        int diff = 0, partial = 0, blocked = 0;
        for (int i = 0; i < W * H; i++) {
            if (!(terms[i].flags & OM_TERM_EXPOSED)) continue;
            om__lpoint p;
            om__odepth od = {{0, 0, 0}};
            if (om__lspace_point(&ls, &samples[i], &p))
                for (uint32_t t = 0; t < hs.s.ntris; t++) {
                    om__ltri lt;
                    if (om__lspace_tri(&ls, t, &lt) && om__blocks(&lt, &p)) {
                        om__odepth m = om__material_odepth(&hs.s.mats[hs.s.tri_mat[t]]);
                        om__odepth_add(&od, &m);
                    }
                }
            om_term want;
            om__odepth_term(&od, &want);
            if (want.r != terms[i].r || want.g != terms[i].g || want.b != terms[i].b) diff++;
            partial += want.r != 255 && (want.r != 0 || want.g != 0);
            blocked += want.r != 255;
        }
        CHECK_MSG(diff == 0, "scene %d: %d samples differ from brute force", k, diff);
        CHECK_MSG(partial > 50 && blocked > 500, "scene %d: %d partial, %d blocked", k, partial, blocked);
        h_scene_free(&hs);
    }
}

/* Marks the nodes a walk from the root can reach. */
static void reachable(const om__bvh *b, unsigned char *live)
{
    uint32_t stack[256];
    int sp = 0;
    if (!b->nnodes) return;
    stack[sp++] = 0;
    while (sp > 0) {
        const uint32_t i = stack[--sp];
        live[i] = 1;
        if (b->nodes[i].count || sp + 2 > 256) continue;
        stack[sp++] = b->nodes[i].first;
        stack[sp++] = b->nodes[i].first + 1;
    }
}

/* The reference's one-pass fit in parts (ref_light.h, om__lbvh_plan): the parts and the
 * nodes above them hold every node once and the parts every triangle once, and fitted
 * part by part (last first, as threads may take them) and then the top, every node
 * and triangle box is the same bits as the fit of the whole tree in one pass from the
 * last node back. A cloud of 20K triangles (many parts), one with a floor the light's
 * near plane clips, the default scene, and three triangles (the root a leaf). */
static void lbvh_fit_in_parts(void)
{
    static const char *scenes[] = {
        "camera eye 0 6 14 target 0 1 0 fov 50\n"
        "light spot pos 8 20 6 target 0 0 0 fov 60 near 5 far 60\n"
        "triangles count 20000 seed 7 area 20 in -5 0.5 -5 5 3 5\n",
        "camera eye 0 6 14 target 0 1 0 fov 50\n"
        "light spot pos 0 3 0 target 0 0 0 fov 120 near 1 far 60\n"
        "plane size 40 40 divisions 8\n"
        "triangles count 3000 seed 2 area 20 in -5 -1 -5 5 5 5\n",
        NULL,
        "camera eye 0 2 5 target 0 0 0\n"
        "light spot pos 1 5 1 target 0 0 0\n"
        "triangles count 3 seed 1 area 2 in -1 0 -1 1 1 1\n",
        OBJECTS_SCENE,
        "camera eye 0 6 14 target 0 1 0 fov 50\n"
        "light spot pos 8 20 6 target 0 0 0 fov 60 near 5 far 60\n"
        "sphere radius 1 segments 24 rings 12 name a\n"
        "copy a translate 3 0 0\n"
        "copy a translate -3 0 0\n",
    };
    static unsigned char mem[12 << 20];
    for (int k = 0; k < 6; k++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[k] ? scenes[k] : om_scene_default_text())) return;
        const om_scene *s = &hs.s;
        om_view v;
        CHECK_OK(h_view(&v, s, 0, 0, 0, NULL));
        om_arena a;
        om_arena_init(&a, mem, sizeof mem, "t");
        om__lspace ls;
        om__bvh b;
        om__lbvh parts, whole;
        CHECK_OK(om__lspace_init(&ls, &a, s, NULL));
        CHECK_OK(om__lbvh_init(&parts, &a, s, 4, NULL));
        CHECK_OK(om__lbvh_init(&whole, &a, s, 4, NULL));
        CHECK_OK(om__bvh_build(&b, &a, s, 4, NULL));
        unsigned char *seen = (unsigned char *)calloc(b.nnodes + s->ntris, 1),
                      *live = (unsigned char *)calloc(b.nnodes, 1);
        if (!seen || !live) return;
        reachable(&b, live);
        om__lbvh_plan(&parts, &b, s->nobjects);
        if (k == 0 || k == 4) CHECK_MSG(parts.nparts >= 8, "%u parts", parts.nparts);
        if (k == 3) CHECK(parts.nparts == 1 && parts.ntop == 0);
        CHECK(parts.nparts >= 1 && parts.nparts <= OM__LBVH_PARTS && parts.ntop <= OM__LBVH_PARTS);
        if (!s->nobjects) CHECK(parts.ntop == parts.nparts - 1);
        for (uint32_t i = parts.top_first; i < parts.top_end; i++) seen[i]++;
        for (uint32_t i = 0; i < parts.ntop; i++) {
            CHECK(parts.top[i] < b.nnodes && (s->nobjects || b.nodes[parts.top[i]].count == 0));
            seen[parts.top[i]]++;
        }
        for (uint32_t p = 0; p < parts.nparts; p++) {
            const om__lbvh_part *q = &parts.parts[p];
            CHECK((q->node < b.nnodes || q->node == OM__LBVH_NONE) && q->lo <= q->hi &&
                  q->hi <= b.nnodes && q->thi <= s->ntris);
            if (q->node != OM__LBVH_NONE) seen[q->node]++;
            for (uint32_t i = q->lo; i < q->hi && i < b.nnodes; i++) seen[i]++;
            for (uint32_t t = q->tlo; t < q->thi && t < s->ntris; t++) seen[b.nnodes + t]++;
        }
        /* every node a walk can reach and every triangle fitted once; a spare node of
         * a two-level tree's (bvh.h) at most once */
        uint32_t once = 0, spare = 0;
        for (uint32_t i = 0; i < b.nnodes + s->ntris; i++) {
            const bool in = i >= b.nnodes || live[i];
            once += in && seen[i] == 1;
            spare += !in;
            CHECK(seen[i] <= 1);
        }
        CHECK_EQ_U(once, b.nnodes + s->ntris - spare);
        if (k == 4) CHECK(spare > 0);
        free(seen);
        /* the whole tree as one part: the fit in one pass from the last node back */
        whole.nparts = 1;
        whole.ntop = 0;
        whole.top_first = whole.top_end = 0;
        whole.parts[0].node = 0;
        whole.parts[0].lo = b.nnodes > 1 ? 1 : 0;
        whole.parts[0].hi = b.nnodes > 1 ? b.nnodes : 0;
        whole.parts[0].tlo = 0;
        whole.parts[0].thi = s->ntris;
        om__lspace_begin(&ls, &v);
        const size_t nb = b.nnodes * sizeof(om__lnode), tb = s->ntris * sizeof(om__lbox);
        memset(parts.nodes, 0xA5, nb);   /* what a fit leaves unwritten shows */
        memset(parts.tris, 0xA5, tb);
        memset(whole.nodes, 0x5A, nb);
        memset(whole.tris, 0x5A, tb);
        for (uint32_t p = parts.nparts; p-- > 0;) om__lbvh_fit_part(&parts, &b, &ls, p);
        om__lbvh_fit_top(&parts, &b, &ls);
        om__lbvh_fit(&whole, &b, &ls);
        uint32_t differ = 0;
        for (uint32_t i = 0; i < b.nnodes; i++)
            differ += live[i] && memcmp(&parts.nodes[i], &whole.nodes[i], sizeof whole.nodes[i]);
        free(live);
        CHECK_MSG(!differ && !memcmp(parts.tris, whole.tris, tb),
                  "scene %d: the fit in %u parts differs from the whole tree's (%u nodes)", k,
                  parts.nparts, differ);
        /* and that one bounds what it should: the root's box holds every vertex */
        uint32_t out = 0;
        for (uint32_t i = 0; i < s->nverts; i++) {
            const om__lvert *vx = &ls.verts[i];
            const om__lbox *r = &whole.nodes[0].box;
            if (vx->x != INT32_MIN)
                out += vx->x < r->lox || vx->x > r->hix || vx->y < r->loy || vx->y > r->hiy || vx->z < r->zmin;
        }
        CHECK_EQ_U(out, 0);
        h_scene_free(&hs);
    }
}

/* The reference at its least memory (no vertex cache, leaves of 32, boxes found from
 * the vertices during the build), and just below its one-pass size (the vertex cache
 * and the 3-D walk, without the packets), gives exactly the one-pass terms. */
static void ref_small_equals_fast(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, default_scene())) return;
    static om_term fast[W * H], small[W * H];
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, NULL, fast, NULL));
    const om_method *m = om_method_find("ref");
    om_method_cfg c;
    om_method_cfg_default(&c, m);
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
    CHECK(mn < full / 4);
    om_view v;
    CHECK_OK(h_view(&v, &hs.s, 0, W, H, NULL));
    for (int k = 0; k < 2; k++) {
        const size_t size = k ? full - 1 : mn;
        unsigned char *mem = malloc(size), *fmem = malloc(h_frame_least(W, H)), *px = malloc(W * H * 3);
        om_arena ma, fa;
        om_arena_init(&ma, mem, size, "method");
        om_arena_init(&fa, fmem, h_frame_least(W, H), "frame");
        void *state;
        CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, NULL));
        om_framebuffer fb = {OM_RGB888, W, H, W * 3, px};
        om_shade_cfg shade;
        om_frame_desc fd;
        h_frame_desc(&fd, &shade, &hs.s, &v, m, state, &fb, 0);
        /* terms out through a strip callback */
        struct cap { om_term *t; } cp = {small};
        fd.user = &cp;
        fd.on_strip = capture_terms;
        memset(small, 0, sizeof small);
        CHECK_OK(om_render_frame(&fd, &fa, NULL, NULL));
        CHECK(!memcmp(fast, small, sizeof fast));
        om_method_stats ms;
        om_method_get_stats(m, state, &ms);
        CHECK(ma.peak <= size);
        if (k) CHECK(ms.bytes_used > mn && ms.bytes_used < full / 2);   /* the middle mode */
        else CHECK(ma.peak <= mn);
        free(mem);
        free(fmem);
        free(px);
    }
    h_scene_free(&hs);
}

/* The counter "objects rebuilt" of a state's last frame. */
static uint32_t rebuilt(const om_method *m, const void *state)
{
    om_method_stats ms;
    om_method_get_stats(m, state, &ms);
    for (uint32_t i = 0; i < ms.ncounters; i++)
        if (!strcmp(ms.counter_names[i], "objects rebuilt")) return ms.counters[i];
    CHECK_MSG(0, "ref reports no \"objects rebuilt\"");
    return UINT32_MAX;
}

/* A kept state builds again the subtrees of the objects that moved and no other (the
 * still copies' stay as they are), in each of its three sizes, and its frames are a
 * new state's on the scene posed there. */
static void moves_rebuild_what_moved(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, OBJECTS_SCENE)) return;
    om_scene *s = &hs.s;
    const om_method *m = om_method_find("ref");
    om_method_cfg c;
    om_method_cfg_default(&c, m);
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, &c, s, W, H, &mn, &full));
    static om_term kept[W * H], fresh[W * H];
    om__bvh kbvh;
    memset(&kbvh, 0, sizeof kbvh);
    for (int k = 0; k < 3; k++) {
        CHECK_OK(om_scene_pose_at(s, 0.0f, NULL));
        const size_t size = k == 0 ? full : k == 1 ? mn + (full - mn) / 2 : mn;
        unsigned char *mem = malloc(size), *fmem = malloc(h_frame_least(W, H)), *px = malloc(W * H * 3);
        om_arena ma, fa;
        om_arena_init(&ma, mem, size, "method");
        void *state;
        CHECK_OK(om_method_init(m, &state, &ma, &c, s, W, H, NULL));
        /* frames: still, one copy moved, still, two moved (one of them twice) */
        static const uint32_t moves[4][3] = {{0, 0, 0}, {1, 7, 0}, {0, 0, 0}, {3, 12, 30}};
        for (int f = 0; f < 4; f++) {
            for (uint32_t i = 1; i <= moves[f][0]; i++) {
                const float dx = 0.25f * (float)(f + i) + 0.1f * (float)k;   /* new for each size */
                const om_mat4 mv = {{1, 0, 0, dx, 0, 1, 0, 0.5f, 0, 0, 1, -dx, 0, 0, 0, 1}};
                CHECK_OK(om_object_pose(s, moves[f][i == 3 ? 1 : i], &mv, NULL));
            }
            om_view v;
            CHECK_OK(h_view(&v, s, 0, W, H, NULL));
            om_arena_init(&fa, fmem, h_frame_least(W, H), "frame");
            om_framebuffer fb = {OM_RGB888, W, H, W * 3, px};
            om_shade_cfg shade;
            om_frame_desc fd;
            h_frame_desc(&fd, &shade, s, &v, m, state, &fb, 0);
            struct cap { om_term *t; } cp = {kept};
            fd.user = &cp;
            fd.on_strip = capture_terms;
            CHECK_OK(om_render_frame(&fd, &fa, NULL, NULL));
            const uint32_t want = f == 1 ? 1 : f == 3 ? 2 : 0;
            CHECK_MSG(rebuilt(m, state) == want, "size %d frame %d: %u objects rebuilt, %u moved", k, f,
                      rebuilt(m, state), want);
            CHECK_OK(h_render(s, "ref", NULL, W, H, 0, 0, NULL, fresh, NULL));
            CHECK_MSG(!memcmp(kept, fresh, sizeof kept), "size %d frame %d: not a new state's terms", k, f);
            if (k == 2) {   /* the BVH itself, kept (the 3-D walk's) and new: the same bytes */
                static unsigned char bm[2][8 << 20];
                om_arena ba[2];
                om__bvh bv[2];
                for (int e = 0; e < 2; e++) {
                    om_arena_init(&ba[e], bm[e], sizeof bm[e], "bvh");
                    if (e == 0 && f == 0) CHECK_OK(om__bvh_build(&kbvh, &ba[0], s, 32, NULL));
                    if (e == 1) CHECK_OK(om__bvh_build(&bv[1], &ba[1], s, 32, NULL));
                }
                if (f) om__bvh_rebuild_objects(&kbvh, s);
                bv[0] = kbvh;
                CHECK_EQ_U(bv[0].rebuilt, f ? want : 0);
                CHECK(bv[0].nnodes == bv[1].nnodes &&
                      !memcmp(bv[0].nodes, bv[1].nodes, bv[1].nnodes * sizeof *bv[1].nodes) &&
                      !memcmp(bv[0].tris, bv[1].tris, s->ntris * sizeof *bv[1].tris));
            }
        }
        free(mem);
        free(fmem);
        free(px);
    }
    h_scene_free(&hs);
}

/* A scene whose every triangle is an object's (the static side of the root empty: it
 * once read as an inner node whose children were the root, and the walk never ended)
 * gives the terms of the same scene with its floor static, a BVH of another shape. */
static void objects_alone(void)
{
    static const char *const scenes[2] = {
        "camera eye 0 3 6 target 0 0 0\nlight spot pos 2 8 2 target 0 0 0\n"
        "box size 4 0.2 4 name floor\nsphere radius 0.5 translate 0 1 0 name s\ncopy s translate 1 0 0\n",
        "camera eye 0 3 6 target 0 0 0\nlight spot pos 2 8 2 target 0 0 0\n"
        "box size 4 0.2 4\nsphere radius 0.5 translate 0 1 0 name s\ncopy s translate 1 0 0\n",
    };
    static om_term t[2][W * H];
    for (int k = 0; k < 2; k++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[k])) return;
        CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, mask, t[k], NULL));
        h_scene_free(&hs);
    }
    uint32_t shadowed = 0;
    for (int i = 0; i < W * H; i++) shadowed += t[0][i].r == 0;
    CHECK_MSG(shadowed > 100, "%u samples shadowed", shadowed);
    CHECK(!memcmp(t[0], t[1], sizeof t[0]));
}

void suite_ref(void)
{
    RUN(square_under_sun);
    RUN(sphere_under_spot);
    RUN(bvh_equals_brute_force);
    RUN(lbvh_fit_in_parts);
    RUN(ref_small_equals_fast);
    RUN(moves_rebuild_what_moved);
    RUN(objects_alone);
}
