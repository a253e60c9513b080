/* unit/scene.c — the scene text format, procedural shapes and paths: values and
 * defaults as parsed, exact byte queries, closed outward-wound shapes, errors with the
 * right status, line and column, om_scene_at and the built-in scenes. OBJ meshes are in
 * unit/obj.c, random mutations in unit/scene_fuzz.c, shared helpers in scene_util.c. */
#include "../test.h"
#include "../../engine/testing.h"
#include "../scene_util.h"

#include <math.h>
#include <stdlib.h>

/* ---------------------------------------------------------------- helpers */

static bool feq(float a, float b, float tol) { return fabsf(a - b) <= tol; }

static om_vec3 tri_centroid(const om_scene *s, uint32_t t)
{
    const uint32_t *i = s->idx + 3 * t;
    om_vec3 c = om__add(om__add(s->verts[i[0]], s->verts[i[1]]), s->verts[i[2]]);
    return om__scale(c, 1.0f / 3.0f);
}

typedef struct edge { uint32_t a, b; } edge;

static int edge_cmp(const void *x, const void *y)
{
    const edge *e = (const edge *)x, *f = (const edge *)y;
    if (e->a != f->a) return e->a < f->a ? -1 : 1;
    if (e->b != f->b) return e->b < f->b ? -1 : 1;
    return 0;
}

static bool has_edge(const edge *es, size_t n, uint32_t a, uint32_t b)
{
    edge k = {a, b};
    return bsearch(&k, es, n, sizeof k, edge_cmp) != NULL;
}

/* Every directed edge appears once; in a closed mesh its reverse appears too (so each
 * undirected edge has exactly two triangles, wound in opposite directions). Returns the
 * number of boundary edges (those without a reverse). */
static size_t check_edges(const om_scene *s, const char *what)
{
    size_t n = (size_t)s->ntris * 3, dup = 0, open = 0;
    edge *es = (edge *)malloc(n * sizeof *es);
    for (uint32_t t = 0; t < s->ntris; t++)
        for (int k = 0; k < 3; k++) {
            es[3 * t + k].a = s->idx[3 * t + k];
            es[3 * t + k].b = s->idx[3 * t + (k + 1) % 3];
        }
    qsort(es, n, sizeof *es, edge_cmp);
    for (size_t i = 0; i < n; i++) {
        if (i && edge_cmp(&es[i], &es[i - 1]) == 0) dup++;
        if (!has_edge(es, n, es[i].b, es[i].a)) open++;
    }
    CHECK_MSG(dup == 0, "%s: %zu directed edges repeat (inconsistent winding)", what, dup);
    free(es);
    return open;
}

/* Closed, consistently wound, non-degenerate, normals pointing away from `centre`. */
static void check_closed_convex(const char *text, om_vec3 centre)
{
    parsed p;
    CHECK_MSG(parse(text, &p) == OM_OK, "%s: %s", text, p.d.msg);
    if (p.st != OM_OK) return;
    CHECK_MSG(p.s.ntris > 0, "%s: no triangles", text);
    CHECK_MSG(check_edges(&p.s, text) == 0, "%s: not closed", text);
    uint32_t inward = 0, degenerate = 0;
    for (uint32_t t = 0; t < p.s.ntris; t++) {
        om_vec3 n = tri_normal(&p.s, t);
        if (!(om__dot(n, n) > 0.0f)) degenerate++;
        if (!(om__dot(n, om__sub(tri_centroid(&p.s, t), centre)) > 0.0f)) inward++;
    }
    CHECK_MSG(inward == 0 && degenerate == 0, "%s: %u inward, %u degenerate of %u", text, inward,
              degenerate, p.s.ntris);
    for (uint32_t i = 0; i < p.s.nverts; i++) {
        om_vec3 v = p.s.verts[i];
        CHECK(v.x >= p.s.lo.x && v.y >= p.s.lo.y && v.z >= p.s.lo.z);
        CHECK(v.x <= p.s.hi.x && v.y <= p.s.hi.y && v.z <= p.s.hi.z);
    }
    done(&p);
}

/* An error with its status, line and column, the same from both passes' entry points. */
static void expect_err_n(const char *orig, size_t len, om_status st, uint32_t line, uint32_t col,
                         const char *msg_part)
{
    char *text = exact_copy(orig, len);
    size_t bytes = 123;
    om_diag d, d2;
    memset(&d, 0x5A, sizeof d);
    om_status got = om_scene_bytes(text, len, NULL, &bytes, &d);
    CHECK_MSG(got == st && d.line == line && d.col == col && d.status == st,
              "[%.60s]: got %s %u:%u, wanted %s %u:%u (%s)", orig, om_status_str(got), d.line,
              d.col, om_status_str(st), line, col, d.msg);
    CHECK_EQ_U(bytes, 0);
    CHECK_MSG(strstr(d.msg, msg_part) != NULL, "[%.60s]: message '%s' lacks '%s'", orig, d.msg,
              msg_part);
    char where[48];
    snprintf(where, sizeof where, "line %u, col %u: ", line, col);
    CHECK_MSG(strncmp(d.msg, where, strlen(where)) == 0, "message '%s' should start '%s'", d.msg,
              where);
    /* om_scene_parse fails the same way, before carving anything */
    static unsigned char buf[1 << 16];
    om_arena a;
    om_scene s;
    om_arena_init(&a, buf, sizeof buf, "scene");
    got = om_scene_parse(text, len, NULL, &a, &s, &d2);
    CHECK(got == st && d2.line == line && d2.col == col && strcmp(d.msg, d2.msg) == 0);
    CHECK_EQ_U(a.used, 0);
    CHECK(s.ntris == 0 && s.verts == NULL);
    free(text);
}

static void expect_err(const char *text, om_status st, uint32_t line, uint32_t col,
                       const char *msg_part)
{
    expect_err_n(text, strlen(text), st, line, col, msg_part);
}

/* ---------------------------------------------------------------- numbers */

static void numbers(void)
{
    static const char *exact[] = {
        "0", "-0", "1", "+5", "0.1", ".5", "5.", "123.456", "3.14159265358979", "1e22",
        "1e-22", "1E3", "00012", "-2.5e-3", "9007199254740993", "0.000001", "1234567890123456789",
        "4294967295", "1e23", "0.30000000000000004", "8192", "179.999",
    };
    for (size_t i = 0; i < sizeof exact / sizeof exact[0]; i++) {
        double v = -1;
        CHECK_MSG(om__num(exact[i], strlen(exact[i]), &v), "%s rejected", exact[i]);
        CHECK_MSG(v == strtod(exact[i], NULL), "%s: %.17g vs %.17g", exact[i], v,
                  strtod(exact[i], NULL));
    }
    static const char *close[] = {
        "1e300", "1.7976931348623157e308", "2.2250738585072014e-308", "123456789012345678901234567890",
        "0.00000000000000000000000001234", "6.02214076e23", "1e-300", "4.9e-320",
    };
    for (size_t i = 0; i < sizeof close / sizeof close[0]; i++) {
        double v = -1, want = strtod(close[i], NULL);
        CHECK_MSG(om__num(close[i], strlen(close[i]), &v), "%s rejected", close[i]);
        CHECK_MSG(fabs(v - want) <= fabs(want) * 1e-14 || (want < 1e-307 && fabs(v - want) < 1e-320),
                  "%s: %.17g vs %.17g", close[i], v, want);
    }
    static const char *bad[] = {"", "-", "+", ".", "1e", "1e+", "1.2.3", "0x10", "nan", "inf",
                                "1 ", "+-1", "1e5x", "e5", "--1", "1..", "1e5.5", "."};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        double v;
        CHECK_MSG(!om__num(bad[i], strlen(bad[i]), &v), "'%s' accepted", bad[i]);
    }
    double v;
    CHECK(om__num("1e400", 5, &v) && isinf(v));
    CHECK(om__num("-1e99999999999999999999", 23, &v) && isinf(v) && v < 0);
    CHECK(om__num("1e-99999999999999999999", 23, &v) && v == 0.0);
    /* a long run of zeros before and after the point */
    static char longnum[20010];
    memset(longnum, '0', sizeof longnum);
    longnum[10000] = '.';
    longnum[20005] = '7';
    CHECK(om__num(longnum, 20006, &v) && v == 0.0);   /* 7e-10005 underflows to 0 */
    longnum[9999] = '3';
    CHECK(om__num(longnum, 20006, &v) && v == 3.0);
    longnum[0] = '1';
    CHECK(om__num(longnum, 10000, &v) && isinf(v));
    /* only the given length is read: "12" of "123" */
    CHECK(om__num("123", 2, &v) && v == 12.0);
}

/* ---------------------------------------------------------------- values */

static void camera_light_values(void)
{
    parsed p;
    const char *text =
        "# a comment line\n"
        "camera eye 1 2 3 target 4 5 6 up 0 0 1 fov 40 size 320 200 near 0.5 far 50 # trailing\n"
        "\n"
        "light spot target 0 0 0 pos 0 10 0 fov 70.5 near 1 far 99\n";
    CHECK_OK(parse(text, &p));
    const om_camera *c = &p.s.camera;
    CHECK(veq(c->eye, 1, 2, 3) && veq(c->target, 4, 5, 6) && veq(c->up, 0, 0, 1));
    CHECK(c->fovy_deg == 40.0f && c->width == 320 && c->height == 200);
    CHECK(c->znear == 0.5f && c->zfar == 50.0f);
    const om_light *l = &p.s.light;
    CHECK(l->kind == OM_LIGHT_SPOT && veq(l->pos, 0, 10, 0) && veq(l->target, 0, 0, 0));
    CHECK(l->fov_deg == 70.5f && l->znear == 1.0f && l->zfar == 99.0f);
    CHECK(veq(l->dir, 0, -1, 0));
    CHECK(p.s.ntris == 0 && p.s.nverts == 0 && p.s.nmats == 1);
    CHECK(veq(p.s.lo, 0, 0, 0) && veq(p.s.hi, 0, 0, 0));
    done(&p);

    /* defaults: camera eye 0 5 15, light spot 10 20 10, default material */
    CHECK_OK(parse("", &p));
    c = &p.s.camera;
    CHECK(veq(c->eye, 0, 5, 15) && veq(c->target, 0, 0, 0) && veq(c->up, 0, 1, 0));
    CHECK(c->fovy_deg == 50.0f && c->width == 640 && c->height == 480);
    CHECK(c->znear == 0.1f && c->zfar == 1000.0f);
    l = &p.s.light;
    CHECK(l->kind == OM_LIGHT_SPOT && veq(l->pos, 10, 20, 10) && veq(l->target, 0, 0, 0));
    CHECK(l->fov_deg == 60.0f && l->znear == 0.5f && l->zfar == 1000.0f);
    CHECK(p.s.nmats == 1 && p.s.mats[0].r == 0.8f && p.s.mats[0].opacity == 1.0f);
    CHECK(p.s.ncam_keys == 0 && p.s.nlight_keys == 0 && p.s.cam_keys == NULL);
    done(&p);

    /* camera defaults for what a line leaves out; a directional light */
    CHECK_OK(parse("camera target 0 0 -1 eye 0 0 0\r\nlight directional dir 1 -2 0\r\n", &p));
    CHECK(p.s.camera.fovy_deg == 50.0f && p.s.camera.width == 640 && p.s.camera.zfar == 1000.0f);
    CHECK(p.s.light.kind == OM_LIGHT_DIRECTIONAL && veq(p.s.light.dir, 1, -2, 0));
    done(&p);

    /* anything goes in a comment, NUL bytes included; a UTF-8 byte-order mark is skipped */
    static const char odd[] = "\xEF\xBB\xBF" "material m # \0\x01\xff\n\nbox material m#\0\n";
    CHECK_OK(parse_ld(odd, sizeof odd - 1, NULL, &p));
    CHECK(p.s.ntris == 12 && p.s.nmats == 2 && p.s.tri_mat[0] == 1);
    done(&p);
    expect_err("\xEF\xBB\xBF" "camera fov 10", OM_E_PARSE, 1, 1, "'camera' needs eye");

    /* whitespace only, and NULL text of length 0, are empty scenes */
    CHECK_OK(parse(" \t\r\n\n   \n\t", &p));
    CHECK(p.s.ntris == 0 && p.s.nmats == 1);
    done(&p);
    CHECK_OK(parse_ld(NULL, 0, NULL, &p));
    done(&p);
    size_t bytes;
    CHECK(om_scene_bytes(NULL, 5, NULL, &bytes, NULL) == OM_E_INVALID);
}

static void primitive_counts(void)
{
    static const struct { const char *text; uint32_t nv, nt; } cases[] = {
        {"plane", 4, 2},
        {"plane divisions 5", 36, 50},
        {"box", 8, 12},
        {"sphere", 32 * 15 + 2, 2 * 32 * 15},
        {"sphere segments 3 rings 2", 3 + 2, 6},
        {"sphere segments 96 rings 48", 96 * 47 + 2, 2 * 96 * 47},
        {"cylinder", 66, 128},
        {"cylinder segments 3", 8, 12},
        {"triangles count 7", 21, 7},
        {"triangles count 1e3", 3000, 1000},
        {"box\nsphere segments 4 rings 3\nplane divisions 2", 8 + 10 + 9, 12 + 16 + 8},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        parsed p;
        CHECK_MSG(parse(cases[i].text, &p) == OM_OK, "%s: %s", cases[i].text, p.d.msg);
        CHECK_MSG(p.s.nverts == cases[i].nv && p.s.ntris == cases[i].nt, "%s: %u verts %u tris",
                  cases[i].text, p.s.nverts, p.s.ntris);
        for (uint32_t t = 0; t < 3 * p.s.ntris; t++) CHECK(p.s.idx[t] < p.s.nverts);
        done(&p);
    }
}

static void transforms_and_bounds(void)
{
    parsed p;
    /* scale, then rotate, then translate */
    CHECK_OK(parse("box size 2 4 6 scale 0.5 translate 10 20 30", &p));
    CHECK(veq(p.s.lo, 9.5f, 19, 28.5f) && veq(p.s.hi, 10.5f, 21, 31.5f));
    done(&p);
    CHECK_OK(parse("box size 2 4 6 scale 1 2 3", &p));
    CHECK(veq(p.s.lo, -1, -4, -9) && veq(p.s.hi, 1, 4, 9));
    done(&p);
    /* quarter turns are exact: about y, x goes to -z */
    CHECK_OK(parse("box size 2 4 6 rotate 0 90 0", &p));
    CHECK(veq(p.s.lo, -3, -2, -1) && veq(p.s.hi, 3, 2, 1));
    done(&p);
    CHECK_OK(parse("plane size 2 2 rotate 90 0 0", &p));   /* +y normal turns to +z */
    {
        om_vec3 n = om__normalize(tri_normal(&p.s, 0));
        CHECK(feq(n.x, 0, 1e-6f) && feq(n.y, 0, 1e-6f) && feq(n.z, 1, 1e-6f));
        CHECK(veq(p.s.lo, -1, -1, 0) && veq(p.s.hi, 1, 1, 0));   /* z -> -y: now in xy */
    }
    done(&p);
    /* x first, then y: the +y normal goes to +z (x), then to +x (y) */
    CHECK_OK(parse("plane rotate 90 90 0", &p));
    {
        om_vec3 n = om__normalize(tri_normal(&p.s, 1));
        CHECK(feq(n.x, 1, 1e-6f) && feq(n.y, 0, 1e-6f) && feq(n.z, 0, 1e-6f));
    }
    done(&p);
    /* ...and about z last: +y -> (z 90) -> -x */
    CHECK_OK(parse("plane rotate 0 0 90", &p));
    {
        om_vec3 n = om__normalize(tri_normal(&p.s, 0));
        CHECK(feq(n.x, -1, 1e-6f) && feq(n.y, 0, 1e-6f));
    }
    done(&p);
    /* a mirrored plane keeps its normal consistent with the mirror: +y -> -y */
    CHECK_OK(parse("plane scale 1 -1 1 translate 0 2 0", &p));
    CHECK(tri_normal(&p.s, 0).y < 0);   /* the mirror image of an up-facing plane faces down */
    done(&p);
    CHECK_OK(parse("plane scale -1 1 1", &p));
    CHECK(tri_normal(&p.s, 0).y > 0);   /* mirroring x keeps a y-facing plane facing +y */
    done(&p);
    /* sphere and cylinder extents; several objects add up */
    CHECK_OK(parse("sphere radius 2 translate 0 5 0\ncylinder radius 1 height 3 translate 10 0 0", &p));
    CHECK(veq(p.s.lo, -2, 0, -2) && veq(p.s.hi, 11, 7, 2));
    CHECK_EQ_U(p.s.ntris, 2 * 32 * 15 + 128);
    done(&p);
}

static void materials(void)
{
    parsed p;
    const char *text =
        "material red albedo 1 0 0\n"
        "material glass albedo 0.5 0.5 1 opacity 0.25\n"
        "box material red\n"                           /* tris 0..11 -> named 1 */
        "box\n"                                        /* 12..23 -> default 0 */
        "box albedo 0 1 0\n"                           /* 24..35 -> inline, opacity 1 */
        "box material glass albedo 0 0 1\n"            /* 36..47 -> inline over glass */
        "material red albedo 0.9 0.1 0.1\n"            /* redefinition: later lines see it */
        "box material red opacity 0.5\n";              /* 48..59 -> inline over the new red */
    CHECK_OK(parse(text, &p));
    CHECK_EQ_U(p.s.nmats, 1 + 3 + 3);
    CHECK_EQ_U(p.s.ntris, 60);
    const om_material *m = p.s.mats;
    CHECK(m[0].r == 0.8f && m[0].g == 0.8f && m[0].b == 0.8f && m[0].opacity == 1.0f);
    CHECK(m[1].r == 1.0f && m[1].g == 0.0f && m[1].opacity == 1.0f);
    CHECK(m[2].b == 1.0f && m[2].opacity == 0.25f);
    CHECK(m[3].r == 0.9f && m[3].g == 0.1f);
    CHECK(m[4].r == 0.0f && m[4].g == 1.0f && m[4].opacity == 1.0f);
    CHECK(m[5].b == 1.0f && m[5].r == 0.0f && m[5].opacity == 0.25f);
    CHECK(m[6].r == 0.9f && m[6].opacity == 0.5f);
    static const uint16_t want[5] = {1, 0, 4, 5, 6};
    for (uint32_t t = 0; t < 60; t++) CHECK_EQ_U(p.s.tri_mat[t], want[t / 12]);
    done(&p);

    /* more names than the look-up cache holds: every one still resolves */
    char *big = (char *)malloc(200 * 64);
    size_t n = 0;
    for (int i = 0; i < 200; i++) n += (size_t)sprintf(big + n, "material m%d albedo 0 0 %g\n", i, i / 200.0);
    for (int i = 0; i < 200; i += 7) n += (size_t)sprintf(big + n, "box material m%d\n", i);
    CHECK_OK(parse_ld(big, n, NULL, &p));
    for (uint32_t t = 0; t < p.s.ntris; t++) {
        uint16_t mi = p.s.tri_mat[t];
        CHECK(mi == 1 + (t / 12) * 7 && p.s.mats[mi].b == (float)((mi - 1) / 200.0));
    }
    done(&p);
    free(big);

    /* at most 65535 materials */
    const char line[] = "material m\n";
    size_t ll = sizeof line - 1;
    big = (char *)malloc(65535 * ll + 32);
    for (size_t i = 0; i < 65535; i++) memcpy(big + i * ll, line, ll);
    CHECK_OK(parse_ld(big, 65534 * ll, NULL, &p));
    CHECK_EQ_U(p.s.nmats, 65535);
    done(&p);
    expect_err_n(big, 65535 * ll, OM_E_RANGE, 65535, 1, "too many materials");
    memcpy(big + 65534 * ll, "box opacity 1\n", 14);
    expect_err_n(big, 65534 * ll + 14, OM_E_RANGE, 65535, 1, "too many materials");
    free(big);
}

static void keys_parse(void)
{
    parsed p;
    const char *text =
        "key camera 0 eye 0 1 10 target 0 0 0\n"
        "key light -1 pos 5 5 5 target 0 0 0\n"
        "key camera 2.5 target 1 1 1 eye 0 2 10\n"
        "key light 3 pos 6 5 5 target 0 0 1\n";
    CHECK_OK(parse(text, &p));
    CHECK_EQ_U(p.s.ncam_keys, 2);
    CHECK_EQ_U(p.s.nlight_keys, 2);
    CHECK(p.s.cam_keys[0].t == 0.0f && veq(p.s.cam_keys[0].eye, 0, 1, 10));
    CHECK(p.s.cam_keys[1].t == 2.5f && veq(p.s.cam_keys[1].target, 1, 1, 1));
    CHECK(p.s.light_keys[0].t == -1.0f && veq(p.s.light_keys[1].pos, 6, 5, 5));
    CHECK(veq(p.s.light_keys[1].target, 0, 0, 1));
    done(&p);
    CHECK_OK(parse("light directional dir 0 -1 0\nkey light 0 dir 1 -1 0\nkey light 1 dir -1 -1 0\n", &p));
    CHECK_EQ_U(p.s.nlight_keys, 2);
    CHECK(veq(p.s.light_keys[1].dir, -1, -1, 0));
    done(&p);
    /* keys may come before the light line they must match */
    CHECK_OK(parse("key light 0 dir 1 -1 0\nlight directional dir 0 -1 0\n", &p));
    done(&p);
}

/* ---------------------------------------------------------------- bytes */

static void bytes_exact(void)
{
    const char *texts[] = {
        "",
        "box",
        "sphere segments 5 rings 3\nmaterial a\nbox material a albedo 1 1 1\nkey camera 0 eye 0 0 1 target 0 0 0\n",
        "key light 0 pos 1 1 1 target 0 0 0\nkey light 1 pos 1 2 1 target 0 0 0\nplane divisions 3\n",
        "box name b\ncopy b name c\ncopy c albedo 1 0 0\nkey object c 1 scale 2\nsphere rings 3 name s\n",
    };
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
        const char *text = texts[i];
        size_t bytes;
        CHECK_OK(om_scene_bytes(text, strlen(text), NULL, &bytes, NULL));
        unsigned char *buf = (unsigned char *)malloc(bytes + 64);
        /* wherever the buffer starts, exactly `bytes` works and one byte less does not */
        for (size_t off = 0; off < 8; off++) {
            om_arena a;
            om_scene s;
            om_diag d;
            om_arena_init(&a, buf + off, bytes, "scene");
            CHECK_OK(om_scene_parse(text, strlen(text), NULL, &a, &s, &d));
            CHECK_EQ_U(a.used, bytes);
            CHECK(((uintptr_t)s.verts & 3) == 0 && ((uintptr_t)s.idx & 3) == 0);
            CHECK(((uintptr_t)s.tri_mat & 1) == 0 && ((uintptr_t)s.mats & 3) == 0);
            CHECK(((uintptr_t)s.solids & 3) == 0);
            if (bytes == 0) continue;
            om_arena_init(&a, buf + off, bytes - 1, "scene");
            CHECK(om_scene_parse(text, strlen(text), NULL, &a, &s, &d) == OM_E_BUDGET);
            CHECK(d.status == OM_E_BUDGET && d.asked > d.left);
            CHECK(strstr(d.msg, "scene arena") != NULL);
            CHECK_EQ_U(a.used, 0);   /* a failed parse gives back what it carved */
            CHECK(s.verts == NULL && s.ntris == 0);
        }
        free(buf);
    }
    /* the count is what the arrays take, plus alignment slack */
    size_t bytes;
    CHECK_OK(om_scene_bytes("box", 3, NULL, &bytes, NULL));
    size_t arrays = 8 * sizeof(om_vec3) + 12 * 3 * 4 + 12 * 2 + sizeof(om_material) + sizeof(om_solid);
    CHECK(bytes >= arrays && bytes <= arrays + 5 * 8);
    /* fault injection: a carve failing in the middle leaves the arena as it was */
    static unsigned char buf[1 << 16];
    const char *six = "box\nkey camera 0 eye 0 0 1 target 0 0 0";   /* six arrays, a solid */
    for (uint32_t k = 1; k <= 7; k++) {
        om_arena a;
        om_scene s;
        om_arena_init(&a, buf, sizeof buf, "scene");
        om__test_fail_carve(&a, k);
        om_status st = om_scene_parse(six, strlen(six), NULL, &a, &s, NULL);
        CHECK(st == (k <= 6 ? OM_E_BUDGET : OM_OK));
        if (k <= 6) CHECK_EQ_U(a.used, 0);
    }
}

/* ---------------------------------------------------------------- shapes */

static void shapes_closed(void)
{
    check_closed_convex("box", om__v3(0, 0, 0));
    check_closed_convex("box size 0.05 1.2 0.05 translate 3 0.6 -1", om__v3(3, 0.6f, -1));
    check_closed_convex("box size 1 2 3 rotate 10 20 30 translate 1 2 3", om__v3(1, 2, 3));
    check_closed_convex("box scale -1 1 1", om__v3(0, 0, 0));
    check_closed_convex("box scale 1 -2 -3 rotate 0 45 0", om__v3(0, 0, 0));
    check_closed_convex("sphere", om__v3(0, 0, 0));
    check_closed_convex("sphere segments 3 rings 2", om__v3(0, 0, 0));
    check_closed_convex("sphere segments 4 rings 3 radius 2", om__v3(0, 0, 0));
    check_closed_convex("sphere segments 96 rings 48 translate 0 1.2 -2", om__v3(0, 1.2f, -2));
    check_closed_convex("sphere segments 7 rings 5 scale 1.5 0.6 1 rotate 0 30 0", om__v3(0, 0, 0));
    check_closed_convex("sphere segments 9 rings 4 scale -1 1 1 rotate 30 0 60", om__v3(0, 0, 0));
    check_closed_convex("cylinder", om__v3(0, 0.5f, 0));
    check_closed_convex("cylinder segments 3 radius 2 height 0.5", om__v3(0, 0.25f, 0));
    check_closed_convex("cylinder segments 128 radius 0.4 height 3 translate 3.5 0 -1", om__v3(3.5f, 1.5f, -1));
    check_closed_convex("cylinder segments 5 scale 1 1 -1 rotate 90 0 0", om__v3(0, 0, 0.5f));

    /* the plane: open along its border only, every triangle facing +y */
    for (uint32_t div = 1; div <= 4; div++) {
        char text[64];
        parsed p;
        snprintf(text, sizeof text, "plane size 3 5 divisions %u", div);
        CHECK_OK(parse(text, &p));
        CHECK_EQ_U(check_edges(&p.s, text), 4 * div);
        for (uint32_t t = 0; t < p.s.ntris; t++) {
            om_vec3 n = tri_normal(&p.s, t);
            CHECK(n.y > 0 && n.x == 0 && n.z == 0);
        }
        CHECK(veq(p.s.lo, -1.5f, 0, -2.5f) && veq(p.s.hi, 1.5f, 0, 2.5f));
        done(&p);
    }
}

static void random_triangles(void)
{
    parsed p, q;
    const char *text = "triangles count 1000 seed 3 area 2 in -1 0 -2 1 1 2";
    CHECK_OK(parse(text, &p));
    CHECK_EQ_U(p.s.ntris, 1000);
    CHECK_EQ_U(p.s.nverts, 3000);
    double total = 0, lo = 1e9, hi = 0, nz = 0;
    for (uint32_t t = 0; t < p.s.ntris; t++) {
        om_vec3 n = tri_normal(&p.s, t);
        double a = 0.5 * sqrt((double)om__dot(n, n));
        total += a;
        if (a < lo) lo = a;
        if (a > hi) hi = a;
        nz += fabs(om__normalize(n).z);
        for (int k = 0; k < 3; k++) CHECK(p.s.idx[3 * t + k] == 3 * t + (uint32_t)k);
    }
    CHECK_MSG(fabs(total - 2.0) < 1e-4, "total area %.9f", total);
    CHECK_MSG(lo > 0.002 * 0.999 && hi < 0.002 * 1.001, "areas %g..%g", lo, hi);
    /* random orientation: |n.z| averages 1/2 for normals uniform on the sphere */
    CHECK_MSG(fabs(nz / 1000 - 0.5) < 0.05, "mean |n.z| %.3f", nz / 1000);
    const float eps = 1e-6f;
    CHECK(p.s.lo.x >= -1 - eps && p.s.lo.y >= -eps && p.s.lo.z >= -2 - eps);
    CHECK(p.s.hi.x <= 1 + eps && p.s.hi.y <= 1 + eps && p.s.hi.z <= 2 + eps);
    CHECK(p.s.hi.x - p.s.lo.x > 1.9f && p.s.hi.z - p.s.lo.z > 3.9f);   /* spread over the box */
    /* the same seed gives the same bits, another seed other ones */
    CHECK_OK(parse(text, &q));
    CHECK(memcmp(p.s.verts, q.s.verts, 3000 * sizeof(om_vec3)) == 0);
    done(&q);
    CHECK_OK(parse("triangles count 1000 seed 4 area 2 in -1 0 -2 1 1 2", &q));
    CHECK(memcmp(p.s.verts, q.s.verts, 3000 * sizeof(om_vec3)) != 0);
    done(&q);
    done(&p);
    /* default box, and a box thinner than a triangle: still non-degenerate */
    CHECK_OK(parse("triangles count 100", &p));
    CHECK(p.s.lo.x >= -5 && p.s.hi.x <= 5 && p.s.lo.y >= 0.5f && p.s.hi.y <= 3);
    done(&p);
    CHECK_OK(parse("triangles count 10 area 10 in 0 0 0 0 0 0", &p));
    for (uint32_t t = 0; t < p.s.ntris; t++) CHECK(om__dot(tri_normal(&p.s, t), tri_normal(&p.s, t)) > 0);
    done(&p);
}

/* ---------------------------------------------------------------- errors */

static void parse_errors(void)
{
    expect_err("sphre radius 1\n", OM_E_PARSE, 1, 1,
               "line 1, col 1: unknown command 'sphre' (expected camera, light, material, plane, "
               "box, sphere, cylinder, mesh, triangles, key, copy)");
    expect_err("# c\n\ncamera eye 0 5 10 target 0 0 0 fov\n", OM_E_PARSE, 3, 35,
               "line 3, col 35: expected a number after 'fov'");
    expect_err("box size 1 2x 3\n", OM_E_PARSE, 1, 12, "malformed number '2x'");
    expect_err("box\nsphere radius nan\n", OM_E_PARSE, 2, 15,
               "expected a number after 'radius', found 'nan'");
    expect_err("sphere radius 1e999\n", OM_E_PARSE, 1, 15, "number '1e999' is not finite");
    expect_err("box translate 1e30 0 0\n", OM_E_RANGE, 1, 15, "translate '1e30' is out of range");
    expect_err("camera eye 1e30 0 0 target 0 0 0\n", OM_E_RANGE, 1, 12, "out of range");
    expect_err("camera eye 0 1 2 target 0 0 0 fov 0\n", OM_E_RANGE, 1, 35, "fov '0' is out of range");
    expect_err("camera eye 0 1 2 target 0 0 0 fov 180\n", OM_E_RANGE, 1, 35, "fov");
    expect_err("camera eye 0 1 2 target 0 0 0 size 0 0\n", OM_E_RANGE, 1, 36, "size '0'");
    expect_err("camera eye 0 1 2 target 0 0 0 size 640 8193\n", OM_E_RANGE, 1, 40, "1..8192");
    expect_err("camera eye 0 1 2 target 0 0 0\ncamera eye 0 1 3 target 0 0 0\n", OM_E_PARSE, 2, 1,
               "second 'camera' line");
    expect_err("light spot pos 1 1 1 target 0 0 0\n  light directional dir 0 -1 0\n", OM_E_PARSE, 2,
               3, "second 'light' line");
    expect_err("key camera 1 eye 0 1 2 target 0 0 0\nkey camera 1 eye 0 1 3 target 0 0 0\n",
               OM_E_PARSE, 2, 12, "times must increase");
    expect_err("key light 5 pos 0 1 2 target 0 0 0\nkey light 4.5 pos 0 1 3 target 0 0 0\n",
               OM_E_PARSE, 2, 11, "times must increase");
    expect_err("material red albedo 1 0 0\nbox material blue\n", OM_E_PARSE, 2, 14,
               "unknown material 'blue'");
    expect_err("box material red\nmaterial red\n", OM_E_PARSE, 1, 14, "unknown material 'red'");
    expect_err("camera eye 0 1 2 target 0 0", OM_E_PARSE, 1, 28, "expected 3 numbers after 'target'");
    expect_err("box\nsphere radius 1e", OM_E_PARSE, 2, 15, "malformed number '1e'");
    expect_err("box\nsphere radi", OM_E_PARSE, 2, 8, "unknown parameter 'radi'");
    expect_err_n("box size 1 1\0 1\n", 16, OM_E_PARSE, 1, 13, "unexpected byte 0x00");
    expect_err_n("box\n\0box\n", 9, OM_E_PARSE, 2, 1, "unexpected byte 0x00");
    expect_err("box\x01\n", OM_E_PARSE, 1, 4, "0x01");
    expect_err("sphere radius 1 segmnts 8\n", OM_E_PARSE, 1, 17,
               "unknown parameter 'segmnts' for 'sphere' (expected radius, segments, rings, scale, "
               "rotate, translate, albedo, opacity, material, name)");
    expect_err("sphere radius 1 2\n", OM_E_PARSE, 1, 17, "too many values after 'radius' (it takes 1)");
    expect_err("box 1\n", OM_E_PARSE, 1, 5, "unexpected value '1' for 'box'");
    expect_err("box scale 1 2 translate 0 0 0\n", OM_E_PARSE, 1, 15,
               "expected 1 or 3 numbers after 'scale', found 'translate'");
    expect_err("box scale 1 2 3 4\n", OM_E_PARSE, 1, 17, "too many values after 'scale'");
    expect_err("box scale\n", OM_E_PARSE, 1, 10, "expected 1 or 3 numbers after 'scale'");
    expect_err("box scale 0 1 1\n", OM_E_RANGE, 1, 11, "scale '0' is out of range");
    expect_err("box size 1 1 1 size 2 2 2\n", OM_E_PARSE, 1, 16, "parameter 'size' is given twice");
    expect_err("camera eye 0 1 2 target 0 0 0 near 5 far 2\n", OM_E_RANGE, 1, 42,
               "'far' must be greater than 'near'");
    expect_err("camera eye 0 1 2 target 0 0 0 near 2000\n", OM_E_RANGE, 1, 36, "'far' must be greater");
    expect_err("camera eye 1 1 1 target 1 1 1\n", OM_E_RANGE, 1, 25, "eye and target must differ");
    expect_err("camera eye 0 0 1 target 0 0 0 up 0 0 0\n", OM_E_RANGE, 1, 34, "'up' must not be zero");
    expect_err("camera eye 0 0 1\n", OM_E_PARSE, 1, 1, "'camera' needs eye X Y Z and target X Y Z");
    expect_err("sphere segments 8.5\n", OM_E_PARSE, 1, 17,
               "expected a whole number after 'segments', found '8.5'");
    expect_err("sphere segments 2\n", OM_E_RANGE, 1, 17, "3..4096");
    expect_err("sphere rings 4097\n", OM_E_RANGE, 1, 14, "2..4096");
    expect_err("plane divisions 0\n", OM_E_RANGE, 1, 17, "1..4096");
    expect_err("plane size 10 -1\n", OM_E_RANGE, 1, 15, "size '-1'");
    expect_err("box albedo 1 1.5 0\n", OM_E_RANGE, 1, 14, "0..1");
    expect_err("material m opacity -0.1\n", OM_E_RANGE, 1, 20, "0..1");
    expect_err("material 1m\n", OM_E_PARSE, 1, 10, "bad material name '1m'");
    expect_err("material\n", OM_E_PARSE, 1, 9, "expected a name after 'material'");
    expect_err("box material\n", OM_E_PARSE, 1, 13, "expected a name after 'material'");
    expect_err("key light 0 pos 1 2 3 target 0 0 0\nkey light 1 dir 0 -1 0\n", OM_E_PARSE, 2, 1,
               "light keys mix");
    expect_err("key light 0 pos 1 2 3 dir 0 -1 0\n", OM_E_PARSE, 1, 23, "either pos and target");
    expect_err("light directional dir 0 -1 0\n\nkey light 0 pos 1 2 3 target 0 0 0\n", OM_E_PARSE, 3,
               1, "the light is directional");
    expect_err("key light 0 dir 0 -1 0\n", OM_E_PARSE, 1, 1, "the light is a spot light");
    expect_err("key light 0 dir 0 0 0\nlight directional dir 0 -1 0", OM_E_RANGE, 1, 17, "'dir' must not be zero");
    expect_err("light directional dir 0 0 0\n", OM_E_RANGE, 1, 23, "'dir' must not be zero");
    expect_err("light point pos 1 2 3\n", OM_E_PARSE, 1, 7, "expected 'spot' or 'directional'");
    expect_err("light\n", OM_E_PARSE, 1, 6, "expected 'spot' or 'directional'");
    expect_err("light spot pos 1 2 3 target 1 2 3\n", OM_E_RANGE, 1, 29, "pos and target must differ");
    /* apart, but by a vector float cannot square: the view would refuse them */
    expect_err("camera eye 0 0 0 target 0 0 1e-30\n", OM_E_RANGE, 1, 25, "gives no direction");
    expect_err("light spot pos 0 5 0 target 0 5 1e-30\n", OM_E_RANGE, 1, 29, "gives no direction");
    expect_err("light directional dir 0 -1e-30 0\n", OM_E_RANGE, 1, 23, "too short to give a direction");
    expect_err("key camera 0 eye 0 0 0 target 1e-30 0 0\n", OM_E_RANGE, 1, 31, "gives no direction");
    expect_err("light spot pos 1 2 3\n", OM_E_PARSE, 1, 1, "needs pos X Y Z and target X Y Z");
    expect_err("key\n", OM_E_PARSE, 1, 4, "expected 'camera', 'light' or 'object' after 'key'");
    expect_err("key camera eye 0 0 1 target 0 0 0\n", OM_E_PARSE, 1, 12,
               "expected a number after 'key camera', found 'eye'");
    expect_err("key camera 0 eye 0 0 1\n", OM_E_PARSE, 1, 1, "needs eye X Y Z and target X Y Z");
    expect_err("triangles seed 3\n", OM_E_PARSE, 1, 1, "'triangles' needs count N");
    expect_err("triangles count 0\n", OM_E_RANGE, 1, 17, "1..10000000");
    expect_err("triangles count 10000001\n", OM_E_RANGE, 1, 17, "1..10000000");
    expect_err("triangles count 5 seed -1\n", OM_E_RANGE, 1, 24, "0..4294967295");
    expect_err("triangles count 5 in 0 0 0 1 -1 1\n", OM_E_RANGE, 1, 30, "'in' needs X0 <= X1");
    expect_err("mesh\n", OM_E_PARSE, 1, 5, "expected a file name after 'mesh'");
    expect_err("box\n box size 1e7 1 1 translate 1e7 0 0\n", OM_E_RANGE, 2, 2,
               "box reaches beyond 1e7");
    expect_err("sphere radius 9e6 translate 2e6 0 0\n", OM_E_RANGE, 1, 1, "sphere reaches beyond 1e7");
    expect_err("triangles count 3 in 1e7 0 0 1e7 1 1\n", OM_E_RANGE, 1, 1,
               "triangles reaches beyond 1e7");
    expect_err("camera\tfov 30\teye 0 0 1 target 0 0 0 far 0\n", OM_E_RANGE, 1, 42, "1e-6..1e8");

    /* near the limit the check is exact, vertex by vertex */
    parsed p;
    CHECK_OK(parse("box size 1e7 1 1 translate 5e6 0 0", &p));   /* corners at exactly 1e7 */
    CHECK(p.s.hi.x == 1e7f);
    done(&p);
    CHECK_OK(parse("sphere radius 9.9e6 segments 4 rings 2 rotate 0 45 0", &p));
    CHECK(p.s.hi.x <= 1e7f);   /* its bounding box's corners would be beyond 1e7 */
    done(&p);

    /* a very long line: columns keep counting */
    size_t n = 100000;
    char *text = (char *)malloc(n + 16);
    memset(text, ' ', n);
    memcpy(text + n, "bogus\n", 6);
    expect_err_n(text, n + 6, OM_E_PARSE, 1, (uint32_t)n + 1, "unknown command 'bogus'");
    memcpy(text + n, "box  \n", 6);
    CHECK_OK(parse_ld(text, n + 6, NULL, &p));
    CHECK_EQ_U(p.s.ntris, 12);
    done(&p);
    /* a huge number of digits */
    memcpy(text, "sphere radius 1", 15);
    memset(text + 15, '0', 5000);
    expect_err_n(text, 5015, OM_E_PARSE, 1, 15, "is not finite");
    memcpy(text, "sphere radius 0", 15);
    memset(text + 15, '0', 5000);
    memcpy(text + 5015, ".5", 2);
    CHECK_OK(parse_ld(text, 5017, NULL, &p));
    CHECK(p.s.hi.y == 0.5f);
    done(&p);
    free(text);

    /* more than 2^31 - 1 triangles in total */
    const char line[] = "plane divisions 4096\n";   /* 33554432 triangles each */
    size_t ll = sizeof line - 1;
    text = (char *)malloc(64 * ll);
    for (int i = 0; i < 64; i++) memcpy(text + i * ll, line, ll);
    size_t bytes;
    om_diag d;
    /* 63 of them fit a 64-bit size_t's count of bytes; a 32-bit host's cannot hold
     * them: a budget error, not a wrapped size */
    const om_status st63 = om_scene_bytes(text, 63 * ll, NULL, &bytes, &d);
    if (sizeof(size_t) < 8) CHECK(st63 == OM_E_BUDGET && d.asked == SIZE_MAX);
    else CHECK(st63 == OM_OK && (double)bytes > 63.0 * 33554432 * 14);
    expect_err_n(text, 64 * ll, OM_E_RANGE, 64, 1, "more than 2147483647");
    free(text);

    /* NULL arguments */
    CHECK(om_scene_bytes("box", 3, NULL, NULL, NULL) == OM_E_INVALID);
    om_scene s;
    CHECK(om_scene_parse("box", 3, NULL, NULL, &s, NULL) == OM_E_INVALID);
}

/* ---------------------------------------------------------------- paths */

/* Objects: names, copies and keys, and what each bad line says. */
static void object_lines(void)
{
    expect_err("box name a\nbox name a\n", OM_E_PARSE, 2, 10, "object name 'a' is already used (on line 1)");
    expect_err("box name a\ncopy a name a\n", OM_E_PARSE, 2, 13, "object name 'a' is already used");
    expect_err("box name 1a\n", OM_E_PARSE, 1, 10, "bad object name '1a'");
    expect_err("box name\n", OM_E_PARSE, 1, 9, "expected a name after 'name'");
    expect_err("copy b\n", OM_E_PARSE, 1, 6, "unknown object 'b'");
    expect_err("copy\n", OM_E_PARSE, 1, 5, "expected an object's name after 'copy'");
    expect_err("box name a\nkey object b 0\n", OM_E_PARSE, 2, 12, "unknown object 'b'");
    expect_err("key object a 0\nbox name a\n", OM_E_PARSE, 1, 12, "unknown object 'a'");
    expect_err("box name a\nkey object a 1\nkey object a 1\n", OM_E_PARSE, 3, 14,
               "times must increase (the key before, on line 2");
    expect_err("box name a\nkey object a 0 scale 1\nkey object a 1 scale -1\n", OM_E_RANGE, 3, 22,
               "the scale passes through zero");
    expect_err("box name a\nkey object a 0 scale 0\n", OM_E_RANGE, 2, 22, "scale '0' is out of range");
    expect_err("box name a\nkey object a 0 translate 9999999.5 0 0\n", OM_E_RANGE, 2, 1, "reaches beyond 1e7");
    expect_err("box name a\ncopy a translate 1e7 0 0\n", OM_E_RANGE, 2, 1, "copy reaches beyond 1e7");
    expect_err("box name a\nkey object a 0 scale 1 2 3\n", OM_E_PARSE, 2, 24, "too many values after 'scale'");
    expect_err("box name a\nkey object a\n", OM_E_PARSE, 2, 13, "");
    expect_err("box name a\nkey object a nan\n", OM_E_PARSE, 2, 14, "");

    /* A chain of copies found again by reading the lines above (40 names between push
     * them out of the parser's cache): the mesh is the first line's, and the reach
     * grows along the chain (the sphere's 1, then 1 + 1, then 2 x 2 + 0 = 4: a key
     * moving it by 9999994 fits, by 9999996 does not). */
    static char text[4096];
    size_t n = (size_t)snprintf(text, sizeof text, "sphere segments 5 rings 3 name m\ncopy m name c0 translate 1 0 0\n"
                                                   "copy c0 name c1 scale 2\n");
    for (int i = 0; i < 40; i++) n += (size_t)snprintf(text + n, sizeof text - n, "box name b%d\n", i);
    n += (size_t)snprintf(text + n, sizeof text - n, "copy c1 name d\nkey object c1 0 translate 9999994 0 0\n");
    size_t bytes;
    CHECK_OK(om_scene_bytes(text, n, NULL, &bytes, NULL));
    unsigned char *buf = malloc(bytes);
    om_arena a;
    om_scene s;
    om_arena_init(&a, buf, bytes, "scene");
    CHECK_OK(om_scene_parse(text, n, NULL, &a, &s, NULL));
    CHECK(s.nobjects == 44 && s.nmeshes == 41 && s.objects[43].mesh == 0 && !strcmp(s.objects[43].name, "d"));
    CHECK(s.objects[2].nkeys == 1 && s.nmesh_verts == s.meshes[0].nverts + 40 * 8);
    free(buf);
    n -= strlen("9999994 0 0\n");
    n += (size_t)snprintf(text + n, sizeof text - n, "9999996.5 0 0\n");
    om_diag d;
    CHECK(om_scene_bytes(text, n, NULL, &bytes, &d) == OM_E_RANGE && d.line == 45);

}

static void scene_at(void)
{
    parsed p;
    const char *text =
        "camera eye 0 0 10 target 0 0 0 fov 33\n"
        "light spot pos 0 10 0 target 0 0 0 fov 45\n"
        "key camera 0 eye 0 0 10 target 0 0 0\n"
        "key camera 1 eye 10 0 10 target 0 2 0\n"
        "key camera 3 eye 10 0 0 target 0 4 0\n"
        "key light 2 pos 0 10 0 target 0 0 0\n"
        "key light 4 pos 4 10 0 target 4 0 0\n";
    CHECK_OK(parse(text, &p));
    om_camera c;
    om_light l;
    om_scene_at(&p.s, -5.0f, &c, &l);
    CHECK(veq(c.eye, 0, 0, 10) && c.fovy_deg == 33.0f && veq(l.pos, 0, 10, 0) && l.fov_deg == 45.0f);
    om_scene_at(&p.s, 0.5f, &c, &l);
    CHECK(veq(c.eye, 5, 0, 10) && veq(c.target, 0, 1, 0));
    om_scene_at(&p.s, 1.0f, &c, NULL);
    CHECK(veq(c.eye, 10, 0, 10) && veq(c.target, 0, 2, 0));
    om_scene_at(&p.s, 2.0f, &c, &l);
    CHECK(veq(c.eye, 10, 0, 5) && veq(c.target, 0, 3, 0));
    CHECK(veq(l.pos, 0, 10, 0));
    om_scene_at(&p.s, 3.0f, &c, &l);
    CHECK(veq(c.eye, 10, 0, 0) && veq(l.pos, 2, 10, 0) && veq(l.target, 2, 0, 0));
    CHECK(feq(l.dir.y, -1, 1e-6f));
    om_scene_at(&p.s, 100.0f, &c, &l);
    CHECK(veq(c.eye, 10, 0, 0) && veq(c.target, 0, 4, 0) && veq(l.pos, 4, 10, 0));
    CHECK(c.width == 640 && c.fovy_deg == 33.0f && l.kind == OM_LIGHT_SPOT);
    om_scene_at(&p.s, NAN, &c, &l);   /* NaN clamps to the start */
    CHECK(veq(c.eye, 0, 0, 10) && veq(l.pos, 0, 10, 0));
    done(&p);

    /* no keys: the scene's own; directional keys move dir */
    CHECK_OK(parse("camera eye 1 2 3 target 0 0 0\nlight directional dir 0 -1 0\n"
                   "key light 0 dir 0 -1 0\nkey light 2 dir 2 -1 0\n", &p));
    om_scene_at(&p.s, 7.0f, &c, &l);
    CHECK(veq(c.eye, 1, 2, 3) && l.kind == OM_LIGHT_DIRECTIONAL && veq(l.dir, 2, -1, 0));
    om_scene_at(&p.s, 1.0f, NULL, &l);
    CHECK(veq(l.dir, 1, -1, 0));
    done(&p);

    /* a single key holds everywhere */
    CHECK_OK(parse("key camera 5 eye 1 1 1 target 0 0 0\n", &p));
    om_scene_at(&p.s, 0.0f, &c, NULL);
    CHECK(veq(c.eye, 1, 1, 1));
    om_scene_at(&p.s, 9.0f, &c, NULL);
    CHECK(veq(c.eye, 1, 1, 1));
    done(&p);
}

/* ---------------------------------------------------------------- the default scene */

static void default_scene(void)
{
    const char *text = om_scene_default_text();
    parsed p;
    CHECK_MSG(parse(text, &p) == OM_OK, "%s", p.d.msg);
    if (p.st != OM_OK) return;
    CHECK_MSG(p.s.ntris >= 20000 && p.s.ntris <= 30000, "%u triangles", p.s.ntris);
    CHECK(p.s.camera.width == 640 && p.s.camera.height == 480 && p.s.camera.fovy_deg == 55.0f);
    CHECK(veq(p.s.camera.eye, 0, 2.5f, 12) && p.s.camera.zfar == 200.0f);
    CHECK(p.s.light.kind == OM_LIGHT_SPOT && p.s.light.znear == 20.0f);
    CHECK(p.s.ncam_keys == 5 && p.s.nlight_keys == 2);
    CHECK(p.s.lo.y == 0.0f && feq(p.s.lo.x, -30, 0) && feq(p.s.hi.z, 30, 0));
    /* materials: distinct albedos and one semi-transparent */
    uint32_t translucent = 0;
    for (uint32_t i = 0; i < p.s.nmats; i++) translucent += p.s.mats[i].opacity < 1.0f;
    CHECK_EQ_U(translucent, 1);
    /* nothing below the floor, nothing through the camera's path */
    for (uint32_t i = 0; i < p.s.nverts; i++) CHECK(p.s.verts[i].y >= 0.0f);
    for (uint32_t k = 0; k < p.s.ncam_keys; k++) {
        om_vec3 e = p.s.cam_keys[k].eye;
        CHECK(e.y > 1.5f && e.y < 5);
    }
    /* the light's frustum holds the whole floor all along its path: every vertex
     * projects inside it, at the start, in the middle and at the end */
    for (int k = 0; k < 3; k++) {
        om_light l;
        om_mat4 view, proj, vp;
        om_scene_at(&p.s, 2.0f * (float)k, NULL, &l);
        CHECK(om__mat_look_at(&view, l.pos, l.target, om__v3(0, 1, 0)));
        proj = om__mat_perspective(l.fov_deg, 1.0f, l.znear, l.zfar);
        vp = om__mat_mul(&proj, &view);
        uint32_t outside = 0;
        for (uint32_t i = 0; i < p.s.nverts; i++) {
            om_vec4 c = om__mat_apply(&vp, p.s.verts[i]);
            if (!(c.w > 0 && fabsf(c.x) < c.w && fabsf(c.y) < c.w && c.z > 0 && c.z < c.w)) outside++;
        }
        CHECK_MSG(outside == 0, "%u vertices outside the light's frustum at t = %d", outside, 2 * k);
    }
    size_t bytes;
    CHECK_OK(om_scene_bytes(text, strlen(text), NULL, &bytes, NULL));
    CHECK_EQ_U(bytes, p.bytes);
    done(&p);
}

/* The small twin: the same objects, materials, camera and light, in under 2,000
 * triangles and a scene arena a microcontroller holds. */
static void small_scene(void)
{
    parsed big, small;
    CHECK_MSG(parse(om_scene_default_text(), &big) == OM_OK, "%s", big.d.msg);
    CHECK_MSG(parse(om_scene_small_text(), &small) == OM_OK, "%s", small.d.msg);
    if (big.st == OM_OK && small.st == OM_OK) {
        CHECK_MSG(small.s.ntris <= 2000 && small.s.ntris * 10 < big.s.ntris, "%u triangles", small.s.ntris);
        CHECK_MSG(small.bytes <= 64 * 1024, "scene arena %zu bytes", small.bytes);
        CHECK_EQ_U(small.s.nsolids, big.s.nsolids);
        CHECK_EQ_U(small.s.nmats, big.s.nmats);
        CHECK(!memcmp(&small.s.camera, &big.s.camera, sizeof big.s.camera));
        CHECK(!memcmp(&small.s.light, &big.s.light, sizeof big.s.light));
        CHECK(small.s.ncam_keys == big.s.ncam_keys && small.s.nlight_keys == big.s.nlight_keys);
        CHECK(!memcmp(&small.s.lo, &big.s.lo, sizeof big.s.lo) && !memcmp(&small.s.hi, &big.s.hi, sizeof big.s.hi));
    }
    done(&big);
    done(&small);
}

/* The town: the same text through any buffer (sized by the query; cut short, a prefix
 * with nothing written past the buffer), the figures its first line states, a low
 * sun, and a plan the camera can walk: nothing in the carriageway or at the eye. */
static bool in_box(om_vec3 p, om_vec3 lo, om_vec3 hi, float margin)
{
    return p.x > lo.x - margin && p.x < hi.x + margin && p.y > lo.y - margin && p.y < hi.y + margin &&
           p.z > lo.z - margin && p.z < hi.z + margin;
}

static void town_scene(void)
{
    const size_t len = om_scene_town_text(NULL, 0);
    char *text = malloc(len + 1), *cut = malloc(len + 1);
    if (!text || !cut) { free(text); free(cut); CHECK(0); return; }
    CHECK(om_scene_town_text(text, len + 1) == len && strlen(text) == len);
    CHECK_MSG(len > 4095, "%zu bytes: one C99 literal would hold it", len);
    CHECK(om_scene_town_text(NULL, 7) == len);
    const size_t caps[] = {1, 2, 77, 4096, len};
    for (size_t i = 0; i < sizeof caps / sizeof caps[0]; i++) {
        memset(cut, 0x5A, len + 1);
        CHECK(om_scene_town_text(cut, caps[i]) == len);
        CHECK_MSG(cut[caps[i] - 1] == '\0' && !memcmp(cut, text, caps[i] - 1) && cut[caps[i]] == 0x5A,
                  "cut short at %zu bytes", caps[i]);
    }
    free(cut);

    parsed p;
    CHECK_MSG(parse(text, &p) == OM_OK, "%s", p.d.msg);
    unsigned objects = 0, thousands = 0, units = 0;
    CHECK(sscanf(text, "# ombra town: %u boxes and cylinders, %u,%u triangles", &objects, &thousands, &units) == 3);
    free(text);
    if (p.st != OM_OK) return;
    CHECK_EQ_U(p.s.ntris, 10100);
    CHECK_EQ_U(p.s.ntris, thousands * 1000 + units);
    CHECK_EQ_U(p.s.nsolids, objects);   /* every box and cylinder; the ground is open */
    CHECK(p.s.camera.width == 1024 && p.s.camera.height == 768);
    CHECK(veq(p.s.lo, -500, 0, -500) && p.s.hi.x == 500.0f && p.s.hi.z == 500.0f && p.s.hi.y < 100.0f);
    for (uint32_t i = 0; i < p.s.nverts; i++) CHECK(p.s.verts[i].y >= 0.0f);
    /* a low sun all along its path: 15 to 30 degrees above the horizon */
    CHECK(p.s.light.kind == OM_LIGHT_DIRECTIONAL && p.s.ncam_keys == 2 && p.s.nlight_keys == 2);
    for (uint32_t k = 0; k < p.s.nlight_keys; k++) {
        const om_vec3 d = p.s.light_keys[k].dir;
        const float up = -d.y / sqrtf(om__dot(d, d));
        CHECK_MSG(up > 0.2588f && up < 0.5f, "sun key %u: sin of its elevation %g", k, (double)up);
    }
    /* varied sizes: towers, thin lamps, low walls */
    uint32_t towers = 0, thin = 0, low = 0;
    for (uint32_t i = 0; i < p.s.nsolids; i++) {
        const om_vec3 lo = p.s.solids[i].lo, hi = p.s.solids[i].hi;
        towers += hi.y - lo.y > 40.0f;
        thin += hi.x - lo.x < 0.5f && hi.z - lo.z < 0.5f;
        low += hi.y - lo.y < 3.0f;
        /* the carriageway is clear from end to end */
        CHECK_MSG(lo.x >= 4.0f || hi.x <= -4.0f, "solid %u reaches the carriageway", i);
    }
    CHECK_MSG(towers >= 3 && thin >= 50 && low >= 10, "%u towers, %u lamps, %u low walls", towers, thin, low);
    /* the walk: the eye at 1.7 m, inside no solid, its near plane clear of them */
    for (int k = 0; k <= 10; k++) {
        om_camera c;
        om_scene_at(&p.s, 2.0f * (float)k, &c, NULL);
        CHECK(feq(c.eye.y, 1.7f, 1e-6f));
        for (uint32_t i = 0; i < p.s.nsolids; i++)
            CHECK_MSG(!in_box(c.eye, p.s.solids[i].lo, p.s.solids[i].hi, 2 * c.znear), "t %d: the eye in solid %u", 2 * k, i);
    }
    size_t bytes;
    text = malloc(len + 1);
    if (text) {
        om_scene_town_text(text, len + 1);
        CHECK_OK(om_scene_bytes(text, len, NULL, &bytes, NULL));
        CHECK_EQ_U(bytes, p.bytes);
    }
    free(text);
    done(&p);
}

void suite_scene(void)
{
    RUN(numbers);
    RUN(camera_light_values);
    RUN(primitive_counts);
    RUN(transforms_and_bounds);
    RUN(materials);
    RUN(keys_parse);
    RUN(bytes_exact);
    RUN(shapes_closed);
    RUN(random_triangles);
    RUN(parse_errors);
    RUN(object_lines);
    RUN(scene_at);
    RUN(default_scene);
    RUN(small_scene);
    RUN(town_scene);
}
