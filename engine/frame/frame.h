/* frame.h — engine-internal pieces of a frame: the eye pass that turns a strip of the
 * image into visible samples, the geometric part of the lit rule, and shading. */
#ifndef OM_FRAME_H
#define OM_FRAME_H

#include "../core/core.h"
#include "../raster/raster.h"
#include "../raster/scene_raster.h"

#include <string.h>
#include <math.h>

/* Renders rows [st->y0, st->y0 + st->rows) of the camera view into `tg` (depth and
 * triangle id, strip-sized) and resolves st->samples: the exact point of the visible
 * triangle under each pixel centre, by perspective-correct barycentrics. `bins` may be
 * NULL (every triangle is walked) or om__bins_make's for this view. */
void om__eye_pass(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st,
                  const om__bins *bins);

/* The exact point of a triangle under an image position, by perspective-correct
 * barycentrics in homogeneous clip space (no division by w, so triangles crossing the
 * viewer's plane need no special case). Set up once per triangle, then evaluated at
 * NDC positions (sx, sy) of the image that `vp` projects onto. */
typedef struct om__persp_tri {
    uint32_t tri;
    float adj[9];          /* weights w1, w2 and their sum as linear functions of NDC:
                              rows of (sx, sy, 1): the sum, then w1 and w2 times it */
    om_vec3 v[3], d1, d2;  /* vertices less the view's origin, v1 - v0 and v2 - v0 */
    om_vec3 n;             /* the unit geometric normal */
} om__persp_tri;

void om__persp_setup(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t t, om__persp_tri *c);
/* The same for the camera of view v, as the eye pass sets it up (eye.c: from the
 * camera's ray, which keeps small triangles far away precise). */
void om__eye_setup(const om_scene *s, const om_view *v, uint32_t t, om__persp_tri *c);
/* The eye pass's point of such a triangle at NDC (sx, sy): om__persp_point's, or where
 * that lies beyond the triangle (a centre its snapped edges took), the triangle's point
 * nearest the centre on the image. */
om_vec3 om__eye_point(const om_view *v, const om__persp_tri *c, float sx, float sy);
om_vec3 om__persp_point(const om__persp_tri *c, float sx, float sy);

/* The same for om__eye_pass_mark: the eye pass with the exposure marks of each
 * covered pixel (st->terms, as om__exposed sets them) in the same loop, while the
 * pixel's point and its triangle's normal are at hand. */
void om__eye_pass_mark(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st,
                       const om__bins *bins);

/* The second half of the eye pass alone: the samples of st's rows (with `mark`, their
 * exposure marks too) from the triangle ids already in tg->id (tg->depth unread), as
 * om__eye_pass(_mark) gives them after rasterizing. */
void om__eye_resolve(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st, bool mark);
/* The eye pass's rasterization alone, of the scene's triangles [t0, t1) into tg,
 * cleared before (om__scene_raster_part: the parts merged by depth, then
 * om__eye_resolve). */
void om__eye_raster_part(const om_scene *s, const om_view *v, const om_target *tg, uint32_t t0, uint32_t t1);

/* Direction from a point towards the light (unit). */
om_vec3 om__to_light(const om_view *v, om_vec3 p);

/* The unit direction from p towards a point light at `pos`: the operations of
 * om__normalize, in its order, so the same bits. */
static inline om_vec3 om__to_point(om_vec3 pos, om_vec3 p)
{
    const om_vec3 a = om__sub(pos, p);
    const float l2 = om__dot(a, a);
    if (!(l2 > 0.0f)) return om__v3(0, 0, 0);
    return om__scale(a, 1.0f / om__sqrtf(l2));
}

/* The light's height over the plane of a triangle with normal nf (unit, turned to
 * the camera) through `anchor` (its first vertex as the scene lists it, relative to
 * the view's origin): nf . (pos - anchor) for a spot light at pos, and the cosine
 * itself, nf . -axis, for a directional one. The same for every point of the plane,
 * so a triangle's pixels share it. */
static inline float om__light_height(const om_view *v, om_vec3 nf, om_vec3 anchor)
{
    if (v->light.kind == OM_LIGHT_DIRECTIONAL) return om__dot(nf, om__scale(v->light_axis, -1.0f));
    return om__dot(nf, om__sub(v->light.pos, anchor));
}

/* The cosine between the normal and the direction to a spot light from p on the
 * plane whose height is h (om__light_height): h / |pos - p|, 0 at the light. */
static inline float om__spot_cos(om_vec3 pos, om_vec3 p, float h)
{
    const om_vec3 a = om__sub(pos, p);
    const float l2 = om__dot(a, a);
    return l2 > 0.0f ? h / om__sqrtf(l2) : 0.0f;
}

/* The parts of the lit rule that no occluder decides, the same for every method:
 * the normal turned towards the camera faces the light, and the point p (with the
 * normal n, as wound, of a triangle through `anchor`: om__light_height) lies inside
 * the light's frustum. *nl: the cosine between them where exposed, else 0. */
static inline bool om__exposed_at(const om_view *v, om_vec3 p, om_vec3 n, om_vec3 anchor, float *nl)
{
    *nl = 0.0f;
    if (om__dot(n, om__sub(v->cam.eye, p)) < 0.0f) n = om__scale(n, -1.0f);
    const float h = om__light_height(v, n, anchor);
    const float c = v->light.kind == OM_LIGHT_DIRECTIONAL ? h : om__spot_cos(v->light.pos, p, h);
    if (!(c > 0.0f)) return false;
    /* inside the frustum: -w <= x <= w is |x| <= w (both false for a NaN) */
    const om_vec4 q = om__mat_apply(&v->light_vp, p);
    if (!(q.w > 0.0f && om__fabsf(q.x) <= q.w && om__fabsf(q.y) <= q.w && q.z >= 0.0f && q.z <= q.w))
        return false;
    *nl = c;   /* the lookups and shading read it rather than work it out again */
    return true;
}

/* om__exposed_at for a sample of scene s; sets smp->nl. */
bool om__exposed(const om_scene *s, const om_view *v, om_sample *smp);

/* Shades a strip into fb rows 0..st->rows-1. */
void om__shade_strip(const om_scene *s, const om_view *v, const om_shade_cfg *c,
                     const om_strip *st, om_framebuffer *fb);

#endif
