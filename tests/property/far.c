/* property/far.c — a scene far from the world's origin renders as it does at the
 * origin, up to what its float vertex data loses there.
 *
 * Every position a frame computes with is relative to the view's origin, the spot
 * light's position (om_view). A scene moved by T in float (each vertex, box corner,
 * camera and light position rounded to fl(x + T)) therefore gives the same relative
 * coordinates as the scene at the origin with each of those positions replaced by
 * fl(x + T) - T (exact in float: the two lie within a factor of two of each other),
 * so the same frame, bit for bit, for every method: its samples, terms and mask. That
 * is the whole of what the move may change: the rounding of the data itself. For a
 * directional light the origin is the centre of the scene's box, which rounds
 * differently at each place; there the masks must agree but for a handful of samples
 * on shadow edges. */
#include "../test.h"
#include "../harness.h"

#include <stdlib.h>

#define W 160
#define H 120

/* A copy of s whose positions are fl(x + T), or fl(x + T) - T with `back`. */
typedef struct moved { om_scene s; om_vec3 *verts; om_solid *solids; } moved;

static float mv(float x, float t, bool back)
{
    volatile float y = x + t;   /* one float rounding, not contracted or kept wider */
    return back ? y - t : y;
}

static om_vec3 mv3(om_vec3 p, float t, bool back)
{
    const om_vec3 r = {mv(p.x, t, back), mv(p.y, t, back), mv(p.z, t, back)};
    return r;
}

static void move_scene(moved *m, const om_scene *s, float t, bool back)
{
    m->s = *s;
    m->verts = malloc(sizeof *m->verts * (s->nverts ? s->nverts : 1));
    m->solids = malloc(sizeof *m->solids * (s->nsolids ? s->nsolids : 1));
    for (uint32_t i = 0; i < s->nverts; i++) m->verts[i] = mv3(s->verts[i], t, back);
    for (uint32_t i = 0; i < s->nsolids; i++) {
        m->solids[i] = s->solids[i];
        m->solids[i].lo = mv3(s->solids[i].lo, t, back);
        m->solids[i].hi = mv3(s->solids[i].hi, t, back);
    }
    m->s.verts = m->verts;
    m->s.solids = s->nsolids ? m->solids : NULL;
    m->s.lo = mv3(s->lo, t, back);
    m->s.hi = mv3(s->hi, t, back);
    m->s.camera.eye = mv3(s->camera.eye, t, back);
    m->s.camera.target = mv3(s->camera.target, t, back);
    m->s.light.pos = mv3(s->light.pos, t, back);
    m->s.light.target = mv3(s->light.target, t, back);
    m->s.ncam_keys = m->s.nlight_keys = 0;   /* the scene's own camera and light */
    m->s.cam_keys = NULL;
    m->s.light_keys = NULL;
}

static void moved_free(moved *m)
{
    free(m->verts);
    free(m->solids);
}

typedef struct frame { uint8_t mask[W * H]; om_term terms[W * H]; om_sample smp[W * H]; } frame;

/* Samples whose mask differs between a and b. */
static uint32_t mask_diff(const frame *a, const frame *b)
{
    uint32_t n = 0;
    for (int i = 0; i < W * H; i++) n += a->mask[i] != b->mask[i];
    return n;
}

static bool same_frame(const frame *a, const frame *b)
{
    return !memcmp(a->mask, b->mask, sizeof a->mask) && !memcmp(a->terms, b->terms, sizeof a->terms) &&
           !memcmp(a->smp, b->smp, sizeof a->smp);
}

static const char spot_scene[] =
    "camera eye 0 2.5 12 target 0 0.8 0 fov 55\n"
    "light spot pos 14 16 -10 target -1 0 1 fov 75 near 2 far 80\n"
    "plane size 30 30 divisions 8\n"
    "box size 4 4 4 translate -7 2 -8\n"
    "box size 1 1 1 rotate 0 25 0 translate 2 0.5 -4\n"
    "sphere radius 1.2 segments 64 rings 32 translate 0 1.2 -2\n"
    "cylinder radius 0.4 height 3 segments 48 translate 3.5 0 -0.5\n"
    "box size 0.2 0.2 0.2 translate -1 0.1 3\n"
    "box size 0.05 1.2 0.05 translate -2 0.6 0.5\n"
    "triangles count 300 seed 5 area 4 in -5 0.5 -5 5 3 0\n"
    "box size 0.3 0.7 0.3 rotate 0 17 0 translate 15.37 0.35 -14.91\n";   /* an odd box */

/* Scene s moved by t (a) and its data rounded so at the origin (b), by method `name`. */
static void render_pair(const om_scene *s, float t, const char *name, frame *a, frame *b)
{
    moved far, near;
    move_scene(&far, s, t, false);
    move_scene(&near, s, t, true);
    CHECK_OK(h_render(&far.s, name, NULL, W, H, 0, 0, a->mask, a->terms, a->smp));
    CHECK_OK(h_render(&near.s, name, NULL, W, H, 0, 0, b->mask, b->terms, b->smp));
    moved_free(&far);
    moved_free(&near);
}

/* Every method gives the moved scene's frame that of the scene with its data rounded
 * as the move rounds it. */
static void spot_far_away(void)
{
    static const float moves[] = {1e3f, -3.7e4f, 1e5f};
    h_scene hs;
    if (!h_scene_parse(&hs, spot_scene)) return;
    frame *a = malloc(sizeof *a), *b = malloc(sizeof *b), *o = malloc(sizeof *o);
    for (size_t k = 0; k < sizeof moves / sizeof moves[0]; k++)
        for (size_t i = 0; i < om_method_count(); i++) {
            const char *name = om_method_name(om_method_at(i));
            render_pair(&hs.s, moves[k], name, a, b);
            CHECK_MSG(same_frame(a, b), "%s moved by %g: not the frame of its rounded data at the origin "
                      "(%u mask samples differ)", name, (double)moves[k], mask_diff(a, b));
            if (strcmp(name, "ref")) continue;
            /* and what the rounding itself costs, against the scene as it was */
            CHECK_OK(h_render(&hs.s, name, NULL, W, H, 0, 0, o->mask, o->terms, o->smp));
            printf("  far: ref moved by %-8g %u of %u samples differ from the unmoved scene's\n",
                   (double)moves[k], mask_diff(a, o), W * H);
        }
    free(a);
    free(b);
    free(o);
    h_scene_free(&hs);
}

/* Under a directional light the masks agree but for a few edge samples. */
static void directional_far_away(void)
{
    static const float moves[] = {1e3f, 1e4f};
    char text[1024];
    snprintf(text, sizeof text, "%s", spot_scene);
    /* the same scene under a low sun */
    char *l = strstr(text, "light spot");
    const char sun[] = "light directional dir -0.5 -0.6 0.4";
    memcpy(l, sun, sizeof sun - 1);
    memset(l + sizeof sun - 1, ' ', (size_t)(strchr(l, '\n') - l) - (sizeof sun - 1));
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return;
    frame *a = malloc(sizeof *a), *b = malloc(sizeof *b);
    for (size_t k = 0; k < sizeof moves / sizeof moves[0]; k++)
        for (size_t i = 0; i < om_method_count(); i++) {
            const char *name = om_method_name(om_method_at(i));
            render_pair(&hs.s, moves[k], name, a, b);
            const uint32_t n = mask_diff(a, b);
            if (n) printf("  far: %s moved by %g under a sun: %u samples differ\n", name, (double)moves[k], n);
            CHECK_MSG(n <= W * H / 2000, "%s moved by %g under a sun: %u mask samples differ", name,
                      (double)moves[k], n);
        }
    free(a);
    free(b);
    h_scene_free(&hs);
}

void suite_far(void)
{
    RUN(spot_far_away);
    RUN(directional_far_away);
}
