/* unit/obj.c — OBJ meshes and the scene's mesh line: om_obj_count's counts of
 * vertices and triangles (polygons fanned, negative indices, skipped statements) and
 * its errors with line and column; meshes brought in through a loader, moved by their
 * transforms, with errors inside the OBJ or from the loader named with both files'
 * lines; a file that changes between the two passes is noticed. */
#include "../test.h"
#include "../scene_util.h"

#include <stdlib.h>

typedef struct memfile { const char *name, *data; } memfile;

static om_status mem_load(void *user, const char *name, const char **data, size_t *len)
{
    for (const memfile *f = (const memfile *)user; f->name; f++)
        if (strcmp(f->name, name) == 0) {
            *data = f->data;
            *len = strlen(f->data);
            return OM_OK;
        }
    return OM_E_NOTFOUND;
}

static void obj_count(void)
{
    uint32_t nv, nt;
    om_diag d;
    const char *obj =
        "# a comment\n"
        "mtllib x.mtl\n"
        "o thing\n"
        "v 0 0 0\n"
        "v 1 0 0 1.0\n"              /* w is ignored */
        "v 1 1 0\n"
        "v 0 1 0 0.5 0.5 0.5\n"      /* vertex colours too */
        "v 0.5 2 0\r\n"
        "vt 0 0\nvn 0 0 1\ng grp\ns off\nusemtl m\nl 1 2\n"
        "f 1 2 3\n"                  /* 1 */
        "f 1/1 3/2 4/3\n"            /* 1 */
        "f 1//1 2//1 3//1 4//1\n"    /* quad: 2 */
        "f -5/1/1 -4/2/2 -3/3/3 -1/1/1 -2/2/2\n";   /* pentagon: 3 */
    CHECK_OK(om_obj_count(obj, strlen(obj), &nv, &nt, &d));
    CHECK_EQ_U(nv, 5);
    CHECK_EQ_U(nt, 7);
    CHECK_OK(om_obj_count("", 0, &nv, &nt, NULL));
    CHECK(nv == 0 && nt == 0);
    CHECK_OK(om_obj_count("v 1e20 0 0\n", 11, &nv, &nt, NULL));   /* no scene limit here */

    static const struct { const char *text; uint32_t line, col; const char *msg; } bad[] = {
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 4, 7, "vertex index 4 is out of range (3 vertices so far)"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", 4, 3, "vertex index 0"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", 4, 7, "vertex index -4 is out of range"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", 4, 1, "at least 3 vertices, this one has 2"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/\n", 4, 7, "malformed vertex reference '3/'"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/1/\n", 4, 7, "malformed vertex reference"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", 4, 7, "malformed vertex reference 'x'"},
        {"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", 1, 3, "out of range (0 vertices so far)"},
        {"v 0 0\n", 1, 6, "expected 3 numbers after 'v'"},
        {"\n\nv 0 0 0x1\n", 3, 7, "malformed number '0x1'"},
        {"v 0 nan 0\n", 1, 5, "malformed number 'nan'"},
        {"v 0 1e999 0\n", 1, 5, "is not finite"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\0\n", 4, 7, "malformed vertex reference"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        size_t len = strlen(bad[i].text);
        if (i == sizeof bad / sizeof bad[0] - 1) len = 33;   /* the one with a NUL byte */
        char *t = exact_copy(bad[i].text, len);
        om_status st = om_obj_count(t, len, &nv, &nt, &d);
        free(t);
        CHECK_MSG(st == OM_E_PARSE && d.line == bad[i].line && d.col == bad[i].col,
                  "obj case %zu: %s %u:%u (%s)", i, om_status_str(st), d.line, d.col, d.msg);
        CHECK_MSG(strstr(d.msg, bad[i].msg) != NULL, "obj case %zu: '%s'", i, d.msg);
        CHECK(strncmp(d.msg, "obj: line ", 10) == 0);
    }
    /* bytes after the length are never read; junk in skipped statements is fine */
    CHECK_OK(om_obj_count("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 99", 31, &nv, &nt, &d));
    CHECK_EQ_U(nt, 1);
    static const char junk[] = "vt \x01\x02\0\xff\nusemtl \0\n";
    CHECK_OK(om_obj_count(junk, sizeof junk - 1, &nv, &nt, &d));
}

static void mesh_lines(void)
{
    static const memfile files[] = {
        {"tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
        {"quad.obj", "v 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nf 1/1/1 2/2/2 3/3/3 4/4/4\n"},
        {"bad.obj", "v 0 0 0\nv 1 0 0\n\nf 1 2 3\n"},
        {"far.obj", "v 0 0 0\nv 1 0 0\nv 9e6 1 0\nf 1 2 3\n"},
        {"neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -1/1 -3/2 -4/3 2//1\n"},
        {NULL, NULL},
    };
    om_loader ld = {mem_load, (void *)files};
    parsed p;
    const char *text =
        "box\n"
        "mesh quad.obj scale 2 translate 0 1 0 albedo 1 0 0\n"
        "mesh tri.obj rotate 0 0 90\n"
        "mesh quad.obj scale -1 1 1\n";
    CHECK_OK(parse_ld(text, strlen(text), &ld, &p));
    CHECK_EQ_U(p.s.nverts, 8 + 4 + 3 + 4);
    CHECK_EQ_U(p.s.ntris, 12 + 2 + 1 + 2);
    /* the quad: fan (1 2 3) (1 3 4), moved after the box's 8 vertices, scaled, lifted */
    CHECK(p.s.idx[36] == 8 && p.s.idx[37] == 9 && p.s.idx[38] == 10);
    CHECK(p.s.idx[39] == 8 && p.s.idx[40] == 10 && p.s.idx[41] == 11);
    CHECK(veq(p.s.verts[10], 2, 1, -2));
    CHECK(p.s.tri_mat[12] == 1 && p.s.mats[1].r == 1.0f && p.s.mats[1].g == 0.0f);
    CHECK(tri_normal(&p.s, 12).y > 0);
    /* rotated 90 degrees about z: (1,0,0) -> (0,1,0) */
    CHECK(veq(p.s.verts[13], 0, 1, 0));
    CHECK(p.s.idx[42] == 12 && p.s.idx[43] == 13 && p.s.idx[44] == 14);
    /* mirrored: winding swapped, so the normal still points up */
    CHECK(tri_normal(&p.s, 15).y > 0 && tri_normal(&p.s, 16).y > 0);
    CHECK(veq(p.s.hi, 2, 1, 0.5f) && veq(p.s.lo, -1, -0.5f, -2));
    done(&p);

    /* negative indices count back from the last vertex read so far */
    CHECK_OK(parse_ld("box\nmesh neg.obj\n", 17, &ld, &p));
    CHECK_EQ_U(p.s.ntris, 12 + 1 + 2);
    static const uint32_t want[9] = {8, 9, 10, 11, 9, 8, 11, 8, 9};   /* +8: after the box */
    for (int i = 0; i < 9 && p.s.ntris == 15; i++) CHECK_EQ_U(p.s.idx[36 + i], want[i]);
    done(&p);

    /* errors: inside the OBJ (its own line and column, the file and the scene line named) */
    om_diag d;
    size_t bytes;
    text = "box\nmesh bad.obj\n";
    CHECK(om_scene_bytes(text, strlen(text), &ld, &bytes, &d) == OM_E_PARSE);
    CHECK(d.line == 4 && d.col == 7);
    CHECK_MSG(strcmp(d.msg, "bad.obj: line 4, col 7: vertex index 3 is out of range (2 vertices "
                            "so far) (mesh on scene line 2)") == 0, "%s", d.msg);
    /* a missing file: the loader's status, the file and the scene's line and column */
    text = "box\n\nmesh  nothere.obj scale 2\n";
    CHECK(om_scene_bytes(text, strlen(text), &ld, &bytes, &d) == OM_E_NOTFOUND);
    CHECK(d.line == 3 && d.col == 7 && d.status == OM_E_NOTFOUND);
    CHECK_MSG(strstr(d.msg, "line 3, col 7: cannot load mesh 'nothere.obj'") != NULL, "%s", d.msg);
    /* no loader at all */
    CHECK(om_scene_bytes(text, strlen(text), NULL, &bytes, &d) == OM_E_NOTFOUND);
    CHECK(d.line == 3 && d.col == 7 && strstr(d.msg, "nothere.obj") != NULL);
    om_loader none = {NULL, NULL};
    CHECK(om_scene_bytes(text, strlen(text), &none, &bytes, &d) == OM_E_NOTFOUND);
    /* beyond 1e7 once transformed */
    text = "mesh far.obj translate 2e6 0 0\n";
    CHECK(om_scene_bytes(text, strlen(text), &ld, &bytes, &d) == OM_E_RANGE);
    CHECK(d.line == 1 && d.col == 1 && strstr(d.msg, "far.obj") && strstr(d.msg, "OBJ line 3"));
    CHECK_OK(om_scene_bytes("mesh far.obj", 12, &ld, &bytes, &d));
    /* an unknown parameter after the file name */
    text = "mesh tri.obj colour 1\n";
    CHECK(om_scene_bytes(text, strlen(text), &ld, &bytes, &d) == OM_E_PARSE);
    CHECK(d.line == 1 && d.col == 14);
}

/* A loader whose file grows between the two passes: the parse must notice, not overrun. */
static om_status growing_load(void *user, const char *name, const char **data, size_t *len)
{
    int *calls = (int *)user;
    (void)name;
    static const char small[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    static const char big[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\n";
    *data = (*calls)++ == 0 ? small : big;
    *len = strlen(*data);
    return OM_OK;
}

static void mesh_changing(void)
{
    int calls = 0;
    om_loader ld = {growing_load, &calls};
    size_t bytes;
    CHECK_OK(om_scene_bytes("mesh a.obj", 10, &ld, &bytes, NULL));
    unsigned char *buf = (unsigned char *)malloc(bytes);
    om_arena a;
    om_scene s;
    om_diag d;
    om_arena_init(&a, buf, bytes, "scene");
    calls = 0;
    CHECK(om_scene_parse("mesh a.obj", 10, &ld, &a, &s, &d) == OM_E_INVALID);
    CHECK(strstr(d.msg, "changed") != NULL);
    CHECK_EQ_U(a.used, 0);
    free(buf);
}

void suite_obj(void)
{
    RUN(obj_count);
    RUN(mesh_lines);
    RUN(mesh_changing);
}
