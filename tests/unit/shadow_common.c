/* unit/shadow_common.c — what the methods share (engine/shadow/common/): the
 * occlusion predicate in single precision against the double one, transmittance
 * composed along a ray, and the plain map's one-tap lookup against the threshold. */
#include "../test.h"
#include "../harness.h"
#include "../../engine/shadow/common/occlude.h"
#include "../../engine/shadow/common/smlookup.h"

#include <math.h>

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

void suite_shadow_common(void)
{
    RUN(float_predicate_is_the_double_one);
    RUN(transmittance_composes);
    RUN(smlook_lit_is_the_threshold);
}
