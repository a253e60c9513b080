/* test_shadow.c — the reference and the conventional shadow map: analytic cases, the
 * BVH walk against a brute-force loop over every triangle (semi-transparent casters
 * included), the map's accuracy growing with its resolution, bad budgets, and every
 * method's kept state against a fresh one. */
#include "test.h"
#include "harness.h"
#include "../engine/shadow/common/occlude.h"
#include "../engine/frame/frame.h"
#include "../engine/shadow/common/smlookup.h"
#include "../engine/shadow/ref/ref_light.h"

#include <math.h>
#include <stdlib.h>

#define W 160
#define H 120
static uint8_t mask[W * H], mask2[W * H];
static om_term terms[W * H];
static om_sample samples[W * H];

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
    for (int i = 0; i < W * H; i++) {
        if (samples[i].tri == OM_NO_TRI || samples[i].p[1] > 0.5f) continue;   /* floor only */
        float x = fabsf(samples[i].p[0]), z = fabsf(samples[i].p[2]);
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
    int checked = 0, shadowed = 0, wrong = 0;
    for (int i = 0; i < W * H; i++) {
        /* floor samples inside the light's frustum (outside it nothing is lit) */
        if (samples[i].tri == OM_NO_TRI || samples[i].tri >= 2 || !(terms[i].flags & OM_TERM_EXPOSED))
            continue;
        double p[3] = {samples[i].p[0], samples[i].p[1], samples[i].p[2]};
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
    };
    static unsigned char mem[12 << 20];
    for (int k = 0; k < 4; k++) {
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
        unsigned char *seen = (unsigned char *)calloc(b.nnodes + s->ntris, 1);
        if (!seen) return;
        om__lbvh_plan(&parts, &b);
        if (k == 0) CHECK_MSG(parts.nparts >= 8, "%u parts", parts.nparts);
        if (k == 3) CHECK(parts.nparts == 1 && parts.ntop == 0);
        CHECK(parts.nparts >= 1 && parts.nparts <= OM__LBVH_PARTS && parts.ntop == parts.nparts - 1);
        for (uint32_t i = 0; i < parts.ntop; i++) {
            CHECK(parts.top[i] < b.nnodes && b.nodes[parts.top[i]].count == 0);
            seen[parts.top[i]]++;
        }
        for (uint32_t p = 0; p < parts.nparts; p++) {
            const om__lbvh_part *q = &parts.parts[p];
            CHECK(q->node < b.nnodes && q->lo <= q->hi && q->hi <= b.nnodes && q->thi <= s->ntris);
            seen[q->node]++;
            for (uint32_t i = q->lo; i < q->hi && i < b.nnodes; i++) seen[i]++;
            for (uint32_t t = q->tlo; t < q->thi && t < s->ntris; t++) seen[b.nnodes + t]++;
        }
        uint32_t once = 0;
        for (uint32_t i = 0; i < b.nnodes + s->ntris; i++) once += seen[i] == 1;
        CHECK_EQ_U(once, b.nnodes + s->ntris);
        free(seen);
        /* the whole tree as one part: the fit in one pass from the last node back */
        whole.nparts = 1;
        whole.ntop = 0;
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
        CHECK_MSG(!memcmp(parts.nodes, whole.nodes, nb) && !memcmp(parts.tris, whole.tris, tb),
                  "scene %d: the fit in %u parts differs from the whole tree's", k, parts.nparts);
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

/* om__blocks_f, the predicate in single precision, gives om__blocks' double answer
 * whenever it gives one: random triangles written into the frame's vertex projection
 * (wide ones, small ones and slivers, either winding, depths across the whole range),
 * points inside, on edges and beyond, under a spot and a directional light, each with
 * a depth next to the double's threshold (depth plus bound), a few units from it, or
 * far from it. */
static uint32_t rnd32(uint32_t *s)
{
    *s ^= *s << 13;   /* xorshift: every bit as random as the others */
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return *s;
}

static void float_predicate_is_the_double_one(void)
{
    static const char *scenes[] = {
        "camera eye 0 5 8 target 0 0.5 0 fov 55 size 160 120\n"
        "light spot pos 3 9 2 target 0 0 0 fov 75 near 1 far 40\n"
        "triangles count 2 seed 3 area 1 in -3 0.3 -3 3 3 3\n",
        "camera eye 2 4 6 target 0 0.5 0 fov 60 size 160 120\n"
        "light directional dir -0.3 -1 -0.2\n"
        "plane size 14 14\n"
        "triangles count 2 seed 9 area 1 in -2 2 -2 2 3 2\n",
    };
    uint32_t s = 29;
    unsigned long long wrong = 0, near = 0, near_answered = 0, far = 0, far_answered = 0, blocked = 0;
    for (int k = 0; k < 2; k++) {
        h_scene hs;
        if (!h_scene_parse(&hs, scenes[k])) return;
        om_view v;
        CHECK_OK(h_view(&v, &hs.s, 0, 0, 0, NULL));
        static unsigned char mem[1 << 16];
        om_arena a;
        om_arena_init(&a, mem, sizeof mem, "t");
        om__lspace ls;
        CHECK_OK(om__lspace_init(&ls, &a, &hs.s, NULL));
        om__lspace_begin(&ls, &v);
        const uint32_t *ix = hs.s.idx;   /* triangle 0's vertices are rewritten */
        for (int it = 0; it < 200000; it++) {
            const int shape = it % 5;   /* wide, small, sliver, anywhere, steep */
            const int32_t span = shape == 1 ? (int32_t)(1u << (8 + rnd32(&s) % 8)) : 1 << 21;
            int32_t x[3], y[3];
            x[0] = (int32_t)(rnd32(&s) % (3u << 21)) - (1 << 21);
            y[0] = (int32_t)(rnd32(&s) % (3u << 21)) - (1 << 21);
            for (int i = 1; i < 3; i++) {
                x[i] = x[0] + (int32_t)(rnd32(&s) % (2u * (uint32_t)span)) - span;
                y[i] = y[0] + (int32_t)(rnd32(&s) % (2u * (uint32_t)span)) - span;
            }
            if (shape == 2) {   /* the third vertex a few units off the line of the others */
                const double f = (double)(rnd32(&s) % 1000) / 1000.0;
                x[2] = x[0] + (int32_t)((x[1] - x[0]) * f) + (int32_t)(rnd32(&s) % 7) - 3;
                y[2] = y[0] + (int32_t)((y[1] - y[0]) * f) + (int32_t)(rnd32(&s) % 7) - 3;
            }
            for (int i = 0; i < 3; i++) {   /* the guard band's range */
                x[i] = x[i] < -(1 << 21) ? -(1 << 21) : x[i] > 1 << 22 ? 1 << 22 : x[i];
                y[i] = y[i] < -(1 << 21) ? -(1 << 21) : y[i] > 1 << 22 ? 1 << 22 : y[i];
            }
            if (shape == 3 && it % 16 == 3) x[1] = 1 << 23;   /* beyond 2^22: no answer */
            const uint32_t zb = rnd32(&s), zr = rnd32(&s) >> (rnd32(&s) % 32);
            for (int i = 0; i < 3; i++) {
                uint32_t z = zb + (rnd32(&s) % (zr | 1u));
                if (it % 7 == 0) z = rnd32(&s);
                ls.verts[ix[i]].x = x[i];
                ls.verts[ix[i]].y = y[i];
                ls.verts[ix[i]].z = z;
            }
            if (shape == 4) {   /* the first vertex far, the others near: the depth at p
                                   cancels most of the first vertex's */
                ls.verts[ix[0]].z = 0xFFFFFFFFu - rnd32(&s) % 4096u;
                ls.verts[ix[1]].z = rnd32(&s) % 65536u;
                ls.verts[ix[2]].z = rnd32(&s) % 65536u;
            }
            /* a point: inside by weights, at an edge's midpoint, or anywhere near */
            om__lpoint p;
            p.tri = it % 50 == 0 ? 0u : 1u;
            const uint32_t w0 = rnd32(&s) % (shape == 4 ? 20 : 1000), w1 = rnd32(&s) % (1000 - w0), w2 = 1000 - w0 - w1;
            const int where = (int)(rnd32(&s) % 8);
            if (where == 0) {
                p.x = ((int64_t)x[0] + x[1]) / 2;
                p.y = ((int64_t)y[0] + y[1]) / 2;
            } else if (where == 1) {
                p.x = x[0] + (int64_t)(rnd32(&s) % 2001) - 1000;
                p.y = y[0] + (int64_t)(rnd32(&s) % 2001) - 1000;
            } else {
                p.x = (int64_t)floor(((double)x[0] * w0 + (double)x[1] * w1 + (double)x[2] * w2) / 1000.0);
                p.y = (int64_t)floor(((double)y[0] * w0 + (double)y[1] * w1 + (double)y[2] * w2) / 1000.0);
            }
            om__ltri lt;
            const bool set = om__lspace_tri(&ls, 0, &lt);
            /* the depth: next to the threshold where p is inside, else anywhere */
            double zq = (double)rnd32(&s);
            if (set && lt.n == 1 && om__tri2_covers(&lt.sub[0].e, p.x, p.y))
                zq = om__rtri_depth(&lt.sub[0], p.x, p.y) + lt.bound[0];
            const uint32_t r = rnd32(&s) % 4;
            double zt = floor(zq) + (r == 0 ? (double)((int)(rnd32(&s) % 5) - 2)
                                     : r == 1 ? (double)((int)(rnd32(&s) % 4001) - 2000)
                                              : (double)((int)(rnd32(&s) % 2000001) - 1000000) * 64.0);
            if (!(zt >= 0.0 && zt <= 4294967295.0)) continue;
            const uint32_t z = (uint32_t)zt;
            p.z = z;
            const int want = set && om__blocks(&lt, &p);
            const int got = om__blocks_f(&ls, 0, &p, z);
            blocked += want;
            near += r <= 1;
            far += r >= 2;
            if (got < 0) continue;
            near_answered += r <= 1;
            far_answered += r >= 2;
            if (got != want && wrong++ < 5)
                fprintf(stderr, "  light %d it %d: threshold %.17g z %u: float %d, double %d\n", k, it, zq, z, got, want);
        }
        h_scene_free(&hs);
    }
    CHECK_EQ_U(wrong, 0);
    CHECK_MSG(blocked > 20000, "%llu blocked", blocked);
    CHECK_MSG(near_answered * 5 > near, "%llu of %llu answered next to the threshold", near_answered, near);
    CHECK_MSG(far_answered * 10 > far * 8, "%llu of %llu answered away from it", far_answered, far);
}

/* om__zdepth by 32-bit words (raster.h, the Cortex-M4's way) gives the 64-bit
 * division's quotient: every shift, significands at both ends of their range, next to
 * each other and random, wherever the quotient fits 32 bits (z < w). */
static void zdepth_by_words(void)
{
    uint32_t seed = 0x2545F491u, bad = 0, n = 0;
    for (int s = -24; s <= 32; s++)
        for (int i = 0; i < 4000; i++) {
            uint32_t mz, mw;
            switch (i % 8) {
            case 0: mz = rnd32(&seed) % 0xFFFFFFu + 1; mw = 0xFFFFFFu; break;
            case 1: mw = (rnd32(&seed) & 0x7FFFFFu) | 0x800000u; mz = mw - 1 - rnd32(&seed) % 4; break;
            case 2: mz = (rnd32(&seed) & 0x7FFFFFu) | 0x800000u; mw = 0x800000u; break;
            case 3: mz = rnd32(&seed) % 64 + 1; mw = rnd32(&seed) % 64 + 1; break;   /* subnormal-like */
            default: mz = rnd32(&seed) % 0xFFFFFFu + 1; mw = rnd32(&seed) % 0xFFFFFFu + 1; break;
            }
            const uint64_t z = mz, w = mw;
            /* the quotient must fit 32 bits, as it does for z < w */
            if (s > 0 && (z << s) / w > 0xFFFFFFFFu) continue;
            const uint64_t want = s >= 0 ? (z << s) / w : z / (w << -s);
            bad += om__zdepth_words(mz, mw, s) != want;
            n++;
        }
    CHECK_MSG(bad == 0 && n > 150000, "%u of %u quotients differ", bad, n);
    /* and through om__zdepth, whichever way it divides: depths of floats */
    const float zs[] = {1e-40f, 1e-30f, 0.25f, 0.5f, 0.999f, 1.0f, 3.0f, 1e20f};
    for (int a = 0; a < 8; a++)
        for (int b = 0; b < 8; b++) {
            const float z = zs[a], w = zs[b];
            const double q = (double)z / (double)w * 4294967296.0;   /* exact enough to floor here */
            const uint32_t want = !(z > 0.0f) ? 0 : !(z < w) ? 0xFFFFFFFFu : (uint32_t)floor(q);
            CHECK_MSG(om__zdepth(z, w) == want || (q - floor(q)) * (q - floor(q)) < 1e-12,
                      "zdepth(%g, %g) = %u, not %u", (double)z, (double)w, om__zdepth(z, w), want);
        }
}

static void transmittance_composes(void)
{
    om_material glass = {1.0f, 0.5f, 0.0f, 0.5f};
    om__odepth o = om__material_odepth(&glass), acc = {{0, 0, 0}};
    om_term t;
    om__odepth_add(&acc, &o);
    om__odepth_term(&acc, &t);
    CHECK(t.r == 128 && t.g == 64 && t.b == 0);
    om__odepth_add(&acc, &o);
    om__odepth_term(&acc, &t);
    CHECK_MSG(t.r == 64 && t.g == 16 && t.b == 0, "%d %d %d", t.r, t.g, t.b);
    om_material opaque = {1, 1, 1, 1};
    o = om__material_odepth(&opaque);
    CHECK(om__odepth_opaque(&o));
    CHECK(fabs(om__log2(0.3) - log2(0.3)) < 1e-13 && fabs(om__exp2(-3.7) - exp2(-3.7)) < 1e-15);
}

static const char *default_scene(void) { return om_scene_default_text(); }

static om_status capture_terms(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)fb;
    om_term *t = *(om_term **)user;
    memcpy(t + (size_t)st->y0 * st->width, st->terms, (size_t)st->rows * st->width * sizeof *t);
    return OM_OK;
}

static void sm_improves_with_resolution(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, default_scene())) return;
    static uint8_t ref[320 * 240], sm[320 * 240];
    CHECK_OK(h_render(&hs.s, "ref", NULL, 320, 240, 0, 0, ref, NULL, NULL));
    uint64_t prev = UINT64_MAX;
    for (uint32_t size = 512; size <= 4096; size *= 2) {
        om_method_cfg c = h_cfg("sm", "");
        CHECK_OK(om_method_cfg_set(&c, "map", size, NULL));
        CHECK_OK(h_render(&hs.s, "sm", &c, 320, 240, 0, 0, sm, NULL, NULL));
        om_metrics m;
        om_compare_masks(ref, sm, 320, 240, &m);
        uint64_t bad = m.false_lit + m.false_shadowed;
        CHECK_MSG(bad < prev, "map %u: %llu mismatches, not fewer than %llu", size,
                  (unsigned long long)bad, (unsigned long long)prev);
        CHECK_EQ_U(m.mismatched_bg, 0);
        prev = bad;
    }
    CHECK(prev < 320 * 240 / 50);
    h_scene_free(&hs);
}

static void methods_agree_on_samples(void)
{
    /* Every method sees the same samples: background and exposure match the reference. */
    h_scene hs;
    if (!h_scene_parse(&hs, default_scene())) return;
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 0, mask, NULL, NULL));
    for (size_t i = 0; i < om_method_count(); i++) {
        CHECK_OK(h_render(&hs.s, om_method_name(om_method_at(i)), NULL, W, H, 0, 7, mask2, NULL, NULL));
        om_metrics m;
        om_compare_masks(mask, mask2, W, H, &m);
        CHECK_EQ_U(m.mismatched_bg, 0);
    }
    /* the reference through strips equals the reference whole */
    CHECK_OK(h_render(&hs.s, "ref", NULL, W, H, 0, 5, mask2, NULL, NULL));
    CHECK(!memcmp(mask, mask2, sizeof mask));
    h_scene_free(&hs);
}

static void budgets_name_the_minimum(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, default_scene())) return;
    static const char *names[] = {"ref", "sm"};
    for (int k = 0; k < 2; k++) {
        const om_method *m = om_method_find(names[k]);
        om_method_cfg c = h_cfg(names[k], "map=256");
        size_t mn, full;
        CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
        unsigned char *buf = malloc(mn + 64);
        memset(buf, 0xC3, mn + 64);
        om_arena a;
        om_arena_init(&a, buf + 32, mn / 2, "method");
        void *state;
        om_diag d;
        CHECK(om_method_init(m, &state, &a, &c, &hs.s, W, H, &d) == OM_E_BUDGET);
        char num[32];
        snprintf(num, sizeof num, "%zu", mn);
        CHECK_MSG(strstr(d.msg, num) != NULL, "%s: '%s' does not name %s", names[k], d.msg, num);
        om_arena_init(&a, buf + 32, mn, "method");
        CHECK_OK(om_method_init(m, &state, &a, &c, &hs.s, W, H, &d));
        CHECK(a.peak <= mn);
        int guard = 0;
        for (int i = 0; i < 32; i++) guard += buf[i] != 0xC3 || buf[32 + mn + i] != 0xC3;
        CHECK_EQ_U(guard, 0);
        free(buf);
    }
    h_scene_free(&hs);
}

static void odd_lights(void)
{
    /* A light inside a box, one behind the camera, one on the floor: frames render. */
    static const char *lights[] = {
        "light spot pos 0 0.5 0 target 0 0 3 fov 90 near 0.1 far 50\n",
        "light spot pos 0 3 20 target 0 0 0 fov 40 near 1 far 60\n",
        "light spot pos 2 0 2 target 0 0 0 fov 60 near 0.1 far 50\n",
        "light directional dir 0 1 0\n",
    };
    for (int k = 0; k < 4; k++) {
        char text[512];
        snprintf(text, sizeof text, "camera eye 0 2 8 target 0 0.5 0 size 80 60\n%s"
                 "plane size 10 10\nbox size 1 1 1 translate 0 0.5 0\n", lights[k]);
        h_scene hs;
        if (!h_scene_parse(&hs, text)) return;
        for (size_t i = 0; i < om_method_count(); i++)
            CHECK_OK(h_render(&hs.s, om_method_name(om_method_at(i)), NULL, 0, 0, 0, 0, mask, NULL, NULL));
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

/* Rasterizes the scene through vp without and with culling into (d0, i0) and (d1, i1)
 * (ids NULL: depth only) and counts the texels that differ; *covered counts those the
 * unculled pass reached. */
static uint32_t cull_diff(const om_scene *s, const om_mat4 *vp, uint32_t n, uint32_t *d0, uint32_t *i0,
                          uint32_t *d1, uint32_t *i1, uint32_t *covered)
{
    om_raster_mode mode = i0 ? OM_RASTER_DEPTH_ID : OM_RASTER_DEPTH;
    om_target t0 = {n, n, 0, n, d0, i0}, t1 = {n, n, 0, n, d1, i1};
    om__scene_raster(s, vp, &t0, mode, false, NULL);
    om__scene_raster(s, vp, &t1, mode, true, NULL);
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
        uint32_t covered, diff = cull_diff(s, &v.light_vp, N, full, NULL, culled, NULL, &covered);
        CHECK_MSG(diff == 0, "light %d: %u of %u covered texels differ", k, diff, covered);
        CHECK(covered > N * N / 8);
        /* which solids were culled */
        om__cull cl;
        om__cull_begin(&cl, s, &v.light_vp);
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
        uint32_t covered, diff = cull_diff(s, &v.cam_vp, N, full, ids_full, culled, ids_culled, &covered);
        CHECK_MSG(diff == 0, "eye %d: %u of %u covered texels differ", k, diff, covered);
        CHECK(covered > N * N / 8);
    }
    h_scene_free(&hs);
}

/* A method's state kept from frame to frame gives each frame what a fresh state
 * gives: nothing it keeps for speed (spsm's surface directions and texel window, the
 * maps, the light's grid) outlives the view it was made for. Two frames at t = 0 and
 * t1 against one at t1, through strips: the default scene, where camera and light
 * move, and floors alone under a moving light (every sample's normal the same, so
 * spsm's surface directions would be kept into the next frame: the case that fails
 * when their reset at the map's build is lost). asm is left out: its tree is meant to
 * refine over the frames. */
static uint64_t kept_hash;

static om_status kept_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)user;
    (void)fb;
    kept_hash = om_hash(kept_hash, st->terms, (size_t)st->rows * st->width * sizeof *st->terms);
    return OM_OK;
}

static void kept_state_case(const char *text, float t1)
{
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return;
    static unsigned char fm[1 << 20];
    static uint8_t px[W * 16 * 3];
    for (size_t mi = 0; mi < om_method_count(); mi++) {
        const om_method *m = om_method_at(mi);
        if (!strcmp(om_method_name(m), "asm")) continue;
        uint64_t h[2];
        for (int fresh = 0; fresh < 2; fresh++) {
            om_method_cfg c = h_cfg(om_method_name(m), "map=256");
            size_t mn, full;
            CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
            void *mm = malloc(full), *state = NULL;
            om_arena ma, fa;
            om_arena_init(&ma, mm, full, "method");
            CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, NULL));
            for (int f = fresh; f < 2; f++) {
                om_view v;
                CHECK_OK(h_view(&v, &hs.s, f ? t1 : 0.0f, W, H, NULL));
                om_framebuffer fb = {OM_RGB888, W, 16, W * 3, px};
                om_shade_cfg shade;
                om_frame_desc fd;
                h_frame_desc(&fd, &shade, &hs.s, &v, m, state, &fb, 16);
                fd.on_strip = kept_strip;
                om_arena_init(&fa, fm, sizeof fm, "frame");
                kept_hash = OM_HASH_INIT;
                CHECK_OK(om_render_frame(&fd, &fa, NULL, NULL));
            }
            h[fresh] = kept_hash;
            free(mm);
        }
        CHECK_MSG(h[0] == h[1], "%s: a kept state's frame at t %g is not a fresh one's", om_method_name(m), t1);
    }
    h_scene_free(&hs);
}

static void kept_state_as_fresh(void)
{
    kept_state_case(om_scene_default_text(), 4.0f);
    kept_state_case("camera eye 0 6 6 target 0 0 0 fov 60 near 0.1 far 100\n"
                    "light spot pos 5 10 0 target 0 0 0 fov 60 near 1 far 50\n"
                    "plane size 20 20\n"
                    "plane size 2 2 translate 0 1 0\n"
                    "key light 0 pos 5 10 0 target 0 0 0\n"
                    "key light 4 pos -5 10 3 target 0 0 0\n", 1.0f);
}

/* The plain map's one-tap test (om__smlook_lit) against the threshold's compare that
 * the other lookups make, on depths around every boundary: each side of an integer,
 * integers, 0 and -0, subnormals, 2^23, 2^24 and 2^32 (where floats are integers),
 * infinities and NaNs, each against stored depths just below, at and above it. */
static void smlook_lit_is_the_threshold(void)
{
    static const float fixed[] = {0.0f, -0.0f, 1e-45f, -1e-45f, 0.5f, 1.0f, -1.0f, 1.5f, 3.0f,
                                  8388607.5f, 8388608.0f, 8388609.0f, 16777215.0f, 16777216.0f,
                                  16777218.0f, 4294967040.0f, 4294967296.0f, 8589934592.0f,
                                  -4294967296.0f, INFINITY, -INFINITY, NAN, -NAN};
    static const uint32_t ends[] = {0u, 1u, 2u, 8388608u, 16777216u, 4294967040u, 4294967294u,
                                    4294967295u};
    uint32_t s = 12345, n = 0, lit = 0;
    for (int i = 0; i < 20000; i++) {
        float z;
        if (i < (int)(sizeof fixed / sizeof fixed[0])) z = fixed[i];
        else {
            s = s * 1664525u + 1013904223u;
            const float base = (float)(s >> 8) * (i % 3 == 0 ? 1.0f : i % 3 == 1 ? 256.0f : 1.0f / 256.0f);
            const float step[] = {0.0f, 0.25f, -0.25f, 1.0f};
            z = base + step[i % 4];
            if (i % 7 == 0) z = nextafterf(z, i % 2 ? INFINITY : -INFINITY);
        }
        const uint64_t th = om__smlook_threshold(z);
        uint32_t ds[11];
        const uint32_t t = z > 0.0f && z < 4294967296.0f ? (uint32_t)z : 0u;
        ds[0] = t; ds[1] = t - 1u; ds[2] = t + 1u;
        for (int k = 0; k < 8; k++) ds[3 + k] = ends[k];
        for (int k = 0; k < 11; k++) {
            const bool want = th <= ds[k], got = om__smlook_lit(z, ds[k]);
            CHECK_MSG(got == want, "z %.9g, stored %u: lit %d, the threshold says %d", (double)z,
                      ds[k], got, want);
            n++;
            lit += got;
        }
    }
    CHECK(lit > n / 8 && lit < n - n / 8);   /* both answers well represented */
}

void suite_shadow(void)
{
    RUN(square_under_sun);
    RUN(sphere_under_spot);
    RUN(bvh_equals_brute_force);
    RUN(lbvh_fit_in_parts);
    RUN(float_predicate_is_the_double_one);
    RUN(zdepth_by_words);
    RUN(transmittance_composes);
    RUN(sm_improves_with_resolution);
    RUN(methods_agree_on_samples);
    RUN(budgets_name_the_minimum);
    RUN(odd_lights);
    RUN(ref_small_equals_fast);
    RUN(light_cull_keeps_the_map);
    RUN(smlook_lit_is_the_threshold);
    RUN(kept_state_as_fresh);
}
