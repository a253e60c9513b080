/* property/objects.c — things move: a method's state kept across frames in which
 * objects move (along their keys and by the host's om_object_pose) gives, bit for bit,
 * the frame of a fresh state on the scene posed once where the objects end, for every
 * method but asm, at 1, 2 and 16 threads, whole and through strips, after 1, 2 and 20
 * frames of moves, at the method's full, least and a middle arena (ref's three modes
 * over its BVH's objects' subtree built again). asm refines over frames, so its kept state is held against one that
 * redraws every tile each frame: what it redraws where objects moved must be what a
 * new tile would hold. The scene model: shared meshes stored once, poses refused
 * (singular, not finite, out of range) leaving the scene as it was. */
#include "../test.h"
#include "../harness.h"
#include "../jobs_util.h"
#include "../../platform/platform.h"
#include "../../engine/shadow/asm/asm.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 96
#define H 72

static const char moving_scene[] =
    "camera eye 0 6 9 target 0 0.5 0 size 96 72\n"
    "light spot pos 4 10 3 target 0 0 0 fov 70 near 1 far 40\n"
    "plane size 12 12 divisions 2\n"
    "box size 1 1 1 translate -2 0.5 -1\n"
    "box size 1 2 1 translate 0 1 0 name crate\n"
    "copy crate translate 2 0 1 name crate2\n"
    "copy crate rotate 0 30 0 translate -1 0 2\n"
    "sphere radius 0.6 segments 12 rings 8 translate 0 2.5 0 name ball\n"
    "key object ball 0 translate 0 0 0\n"
    "key object ball 1 translate 2 0 -1 rotate 0 90 0 scale 0.5\n"
    "key object crate2 0 translate 0 0 0\n"
    "key object crate2 1 translate -1 0.5 -2 rotate 20 0 0\n";

/* Frame f's pose: the keys at t = f / 20, and the first crate turned and moved by the
 * host (mirrored on odd frames, so its triangles' winding turns too; every third frame
 * 3 units away, so the tiles of its old pose are not those of its new one; on even
 * frames posed first somewhere no frame sees, so that what a kept state must undo is
 * the pose two moves back, not the last one's). */
static void pose_frame(om_scene *s, uint32_t f)
{
    CHECK_OK(om_scene_pose_at(s, 0.05f * (float)f, NULL));
    uint32_t crate;
    CHECK_OK(om_object_find(s, "crate", &crate));
    if (f % 2 == 0) {
        const om_mat4 away = {{1, 0, 0, 4.5f, 0, 1, 0, 0, 0, 0, 1, -2.5f, 0, 0, 0, 1}};
        CHECK_OK(om_object_pose(s, crate, &away, NULL));
    }
    const float a = 0.13f * (float)f, c = cosf(a), sn = sinf(a), mx = (f & 1) ? -1.0f : 1.0f;
    const float jump = f % 3 ? 0.0f : -3.0f;   /* every third frame far from the last */
    om_mat4 m = {{mx * c, 0, sn, 0.2f * (float)f + jump, 0, 1, 0, 0, -mx * sn, 0, c, -0.1f * (float)f, 0, 0, 0, 1}};
    CHECK_OK(om_object_pose(s, crate, &m, NULL));
}

static om_vec3 mk3(float x, float y, float z) { om_vec3 v = {x, y, z}; return v; }

/* asm's reference: every object moved, and the box asm's tiles hold it in (its
 * state's `drawn`) made the whole world, so every tile is drawn again, whole, in this
 * frame. */
static void everything_moved(om_scene *s, void *asm_state)
{
    om__asm_state *m = (om__asm_state *)asm_state;
    for (uint32_t i = 0; i < s->nobjects; i++) {
        s->objects[i].moved = ++s->change;
        m->drawn[2 * i] = mk3(-1e7f, -1e7f, -1e7f);
        m->drawn[2 * i + 1] = mk3(1e7f, 1e7f, 1e7f);
    }
}

typedef struct runner {
    const om_method *m;
    om_method_cfg cfg;
    void *mm, *state;
    om_arena ma;
} runner;

/* size 0: the method's full arena, 1: halfway to its least (ref's middle mode), 2:
 * its least (ref's 3-D walk). */
static void runner_init(runner *r, const om_method *m, const om_scene *s, int size)
{
    r->m = m;
    /* asm's least arena is its lean mode, there with its triangles bounded in float
     * first, as on a chip whose double is software */
    r->cfg = h_cfg(om_method_name(m), size == 2 ? "map=256 asm.float=1" : "map=256");
    size_t mn, full;
    CHECK_OK(om_method_bytes(m, &r->cfg, s, W, H, &mn, &full));
    size_t n = size == 0 ? full : size == 1 ? mn + (full - mn) / 2 : mn;
    r->mm = malloc(n);
    om_arena_init(&r->ma, r->mm, n, "method");
    CHECK_OK(om_method_init(m, &r->state, &r->ma, &r->cfg, s, W, H, NULL));
}

static uint64_t runner_frame(runner *r, const om_scene *s, uint32_t rows, om_jobs *pool, uint32_t threads)
{
    static uint8_t px[W * H * 3];
    om_view v;
    CHECK_OK(h_view(&v, s, 0.0f, W, H, NULL));
    om_framebuffer fb = {OM_RGB888, W, H, W * 3, px};
    om_shade_cfg shade;
    om_frame_desc fd;
    h_frame_desc(&fd, &shade, s, &v, r->m, r->state, &fb, rows);
    uint64_t h = OM_HASH_INIT;
    fd.on_strip = frame_hash_strip;
    fd.user = &h;
    if (threads > 1) {
        fd.parallel_for = om_jobs_for;
        fd.parallel_user = pool;
        fd.threads = threads;
    }
    om_frame_need need;
    CHECK_OK(om_frame_bytes(&fd, &need));
    void *fm = malloc(need.whole);
    om_arena fa;
    om_arena_init(&fa, fm, need.whole, "frame");
    om_diag d;
    om_status st = om_render_frame(&fd, &fa, NULL, &d);
    CHECK_MSG(st == OM_OK, "%s: %s", om_method_name(r->m), d.msg);
    free(fm);
    return h;
}

static void moved_is_baked(void)
{
    static const uint32_t threads[3] = {1, 2, 16}, frames[3] = {1, 2, 20};
    om_jobs *pools[3];
    for (int k = 0; k < 3; k++) CHECK_OK(om_jobs_start(&pools[k], threads[k], NULL));
    for (size_t mi = 0; mi < om_method_count(); mi++) {
        const om_method *m = om_method_at(mi);
        const bool is_asm = !strcmp(om_method_name(m), "asm");
        for (int least = 0; least < 3; least++)
            for (int k = 0; k < 3; k++)
                for (uint32_t rows = 0; rows <= 24; rows += 24)
                    for (int fi = 0; fi < 3; fi++) {
                        h_scene a, b;
                        if (!h_scene_parse(&a, moving_scene) || !h_scene_parse(&b, moving_scene)) return;
                        runner ra, rb;
                        runner_init(&ra, m, &a.s, least);
                        if (is_asm) runner_init(&rb, m, &b.s, least);
                        uint64_t ha = 0, hb = 0;
                        for (uint32_t f = 1; f <= frames[fi]; f++) {
                            pose_frame(&a.s, f);
                            ha = runner_frame(&ra, &a.s, rows, pools[k], threads[k]);
                            if (is_asm) {   /* the same frames, every tile redrawn */
                                pose_frame(&b.s, f);
                                everything_moved(&b.s, rb.state);
                                hb = runner_frame(&rb, &b.s, rows, pools[k], threads[k]);
                                CHECK_MSG(ha == hb, "asm: frame %u of %u, %u threads, strips %u, least %d: "
                                          "its redrawn tiles are not new ones", f, frames[fi], threads[k], rows, least);
                            }
                        }
                        if (!is_asm) {   /* a fresh state on the scene posed once, at the end */
                            pose_frame(&b.s, frames[fi]);
                            runner_init(&rb, m, &b.s, least);   /* made for the scene posed */
                            hb = runner_frame(&rb, &b.s, rows, pools[k], threads[k]);
                            CHECK_MSG(ha == hb, "%s: after %u frames of moves, %u threads, strips %u, least %d: "
                                      "not the frame of the scene posed once", om_method_name(m), frames[fi],
                                      threads[k], rows, least);
                        }
                        free(ra.mm);
                        free(rb.mm);
                        h_scene_free(&a);
                        h_scene_free(&b);
                    }
    }
    for (int k = 0; k < 3; k++) om_jobs_stop(pools[k]);
}

/* A mesh is stored once however many objects share it; a refused pose changes
 * nothing; posing where an object is changes nothing. */
static void object_model(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, moving_scene)) return;
    om_scene *s = &hs.s;
    CHECK(s->nobjects == 4 && s->nmeshes == 2 && s->nobj_keys == 4);
    CHECK(s->objects[1].mesh == s->objects[0].mesh && s->objects[2].mesh == s->objects[0].mesh);
    CHECK(s->meshes[0].nverts == 8 && s->meshes[0].ntris == 12 && s->meshes[0].closed);
    uint32_t i;
    CHECK(om_object_find(s, "nothing", &i) == OM_E_NOTFOUND);
    CHECK_OK(om_object_find(s, "ball", &i));
    CHECK(i == 3);
    const size_t vbytes = (size_t)s->nverts * sizeof(om_vec3);
    om_vec3 *before = malloc(vbytes);
    memcpy(before, s->verts, vbytes);
    const uint32_t change = s->change;
    om_mat4 sing = {{1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    om_mat4 nan_m = {{1, 0, 0, NAN, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    om_mat4 far_m = {{1, 0, 0, 2e7f, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    om_mat4 row = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1}};
    om_diag d;
    CHECK(om_object_pose(s, 0, &sing, &d) == OM_E_RANGE);
    CHECK(strstr(d.msg, "singular") != NULL);
    CHECK(om_object_pose(s, 0, &nan_m, &d) == OM_E_RANGE);
    CHECK(om_object_pose(s, 0, &far_m, &d) == OM_E_RANGE);
    CHECK(om_object_pose(s, 0, &row, &d) == OM_E_INVALID);
    CHECK(om_object_pose(s, 99, &row, &d) == OM_E_INVALID);
    CHECK(!memcmp(before, s->verts, vbytes) && s->change == change);
    om_mat4 id = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    CHECK_OK(om_object_pose(s, 0, &id, NULL));
    CHECK(!memcmp(before, s->verts, vbytes) && s->change == change);
    CHECK_OK(om_scene_pose_at(s, 0.0f, NULL));
    CHECK(!memcmp(before, s->verts, vbytes) && s->change == change);
    CHECK_OK(om_scene_pose_at(s, 1.0f, NULL));
    CHECK(s->change == change + 2 && s->objects[3].moved == s->change);
    /* halfway along the ball's keys: moved by half, scaled by 0.75 about the origin
     * (its centre at y 2.5 before), turned about y (its centre stays) */
    CHECK_OK(om_scene_pose_at(s, 0.5f, NULL));
    const om_object *ball = &s->objects[3];
    const float cx = 0.5f * (ball->lo.x + ball->hi.x), cy = 0.5f * (ball->lo.y + ball->hi.y);
    const float cz = 0.5f * (ball->lo.z + ball->hi.z);
    CHECK_MSG(fabsf(cx - 1.0f) < 1e-3f && fabsf(cy - 1.875f) < 1e-3f && fabsf(cz + 0.5f) < 1e-3f,
              "ball at t 0.5: centre %g %g %g", cx, cy, cz);
    /* the scene's bounds follow its objects */
    CHECK(s->lo.x <= ball->lo.x && s->hi.y >= ball->hi.y);
    /* a scene whose objects do not fit its arrays (built or edited by hand) is refused */
    om_mat4 shift = {{1, 0, 0, 0.5f, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    const uint32_t fv = s->objects[0].first_vert, mesh = s->objects[0].mesh, next = s->obj_keys[0].next;
    s->objects[0].first_vert = s->nverts - 1;
    CHECK(om_object_pose(s, 0, &shift, NULL) == OM_E_INVALID);
    s->objects[0].first_vert = fv;
    s->objects[0].mesh = s->nmeshes;
    CHECK(om_object_pose(s, 0, &shift, NULL) == OM_E_INVALID);
    s->objects[0].mesh = mesh;
    s->obj_keys[s->objects[3].first_key].next = s->objects[3].first_key;   /* a loop */
    CHECK(om_scene_pose_at(s, 0.25f, NULL) == OM_E_INVALID);
    s->obj_keys[s->objects[3].first_key].next = next;
    CHECK_OK(om_object_pose(s, 0, &shift, NULL));
    CHECK_OK(om_scene_pose_at(s, 0.25f, NULL));
    free(before);
    h_scene_free(&hs);
}

/* 1,000 objects of one mesh: the mesh once, and the scene arena grows by the objects'
 * own records and posed geometry only. */
static void shared_meshes(void)
{
    static char text[64 * 1024];
    size_t n = (size_t)snprintf(text, sizeof text, "sphere segments 16 rings 8 name s0\n");
    for (int i = 1; i < 1000; i++) n += (size_t)snprintf(text + n, sizeof text - n, "copy s0 translate %d 0 %d\n", i % 40, i / 40);
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return;
    CHECK(hs.s.nobjects == 1000 && hs.s.nmeshes == 1);
    CHECK(hs.s.nverts == 1000 * hs.s.meshes[0].nverts);
    h_scene_free(&hs);
}

void suite_objects(void)
{
    RUN(object_model);
    RUN(shared_meshes);
    RUN(moved_is_baked);
}
