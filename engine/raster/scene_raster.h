/* scene_raster.h — a scene through the rasterizer: every triangle of an om_scene
 * through a view-projection matrix into a target, with the exact back-face culling of
 * closed shapes and the per-frame bins that let strips and bands skip work. The eye
 * pass (frame/) and the methods' light depth passes (shadow/) share it; it needs the
 * scene's types and the rasterizer, nothing of a frame. */
#ifndef OM_SCENE_RASTER_H
#define OM_SCENE_RASTER_H

#include "raster.h"

/* A triangle of the scene through vp, in clip space. Every function here takes the
 * view's origin o with its matrix: a world vertex v goes through vp as v - o, the float
 * subtraction first (om_view says why). */
static inline void om__clip_tri(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t t, om_vec4 c[3])
{
    const uint32_t *ix = s->idx + (size_t)t * 3;
    for (int k = 0; k < 3; k++) c[k] = om__mat_apply(vp, om__sub(s->verts[ix[k]], o));
}

/* Back-face culling of a depth pass, exact for closed shapes: walking the triangles in
 * order, om__cull_next(c, t) says whether triangle t may be skipped when it faces
 * away, that is whether it belongs to a solid (om_solid) whose box lies wholly in
 * front of the viewpoint's near plane (z >= 1e-4 w in vp's clip space, w > 0). Then
 * the viewpoint is outside the solid and the near plane cuts nothing of it, so the
 * nearest surface under every texel faces the viewpoint: the map is the same without
 * the back faces. */
typedef struct om__cull {
    const om_scene *s;
    const om_mat4 *vp;
    om_vec3 o;
    uint32_t k;            /* the first solid that may still hold t */
    uint32_t seen;         /* the solid `on` was decided for (UINT32_MAX: none yet) */
    bool on;               /* solid k may cull */
} om__cull;

void om__cull_begin(om__cull *c, const om_scene *s, const om_mat4 *vp, om_vec3 o);
bool om__cull_next(om__cull *c, uint32_t t);

/* Strips without repetition: the frame's bins, made once per frame through the
 * camera (om__bins_make) so that a strip's eye pass neither sets up the triangles that
 * miss its rows nor clips and projects again the vertices that need no clipping.
 *  rows[t]:  the image rows triangle t's pixels can lie in (first | last << 16,
 *            conservative by a row; 0x0000FFFF for one that covers nothing; all rows
 *            for one that needs clipping);
 *  verts[v]: vertex v snapped alone (om__project) when it is inside every clip plane,
 *            x = INT32_MIN when not: a triangle of three such vertices goes straight
 *            to om__raster_snapped, as om__raster_tri would send it.
 * verts may be NULL (the arena had room for the rows only). */
typedef struct om__vsnap { int32_t x, y; uint32_t z; } om__vsnap;
typedef struct om__bins {
    uint32_t *rows;
    om__vsnap *verts;
    /* Rows of pixel centres (a pass that samples pixel centres alone: the eye's): where
     * the CPU has lanes, rows[t] of a triangle of three snapped vertices is then
     * exactly the image rows of pixel centres its box holds, 0x0000FFFF where it holds
     * none (nor a column's), so a strip or band finds the triangles whose box holds one
     * of its centres by the rows alone, as the walk's batches do by their boxes.
     * Ignored elsewhere (a Cortex-M): the rows stay conservative. */
    bool centres;
} om__bins;

size_t om__bins_rows_bytes(const om_scene *s);
size_t om__bins_verts_bytes(const om_scene *s);
/* Fills b->verts and b->rows (each when not NULL) for the matrix vp onto a width x
 * height image: the camera's for the eye pass, the light's for a light pass
 * (vertices only: om__scene_raster walks every triangle without rows). */
void om__bins_make(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t width, uint32_t height, const om__bins *b);
/* om__bins_make in parts, for a host's threads: the vertices [v0, v1) of b->verts,
 * then, once every vertex is done, the triangles [t0, t1) of b->rows. Each entry
 * depends on nothing but its own inputs, so any split gives the same bins. */
void om__bins_make_verts(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t width, uint32_t height, const om__bins *b,
                         uint32_t v0, uint32_t v1);
void om__bins_make_rows(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t width, uint32_t height, const om__bins *b,
                        uint32_t t0, uint32_t t1);

/* Clears `tg` and rasterizes every triangle of the scene through `vp` into it: the
 * eye pass (OM_RASTER_DEPTH_ID) and the light depth passes (OM_RASTER_DEPTH); with
 * `cull`, the back faces of closed shapes are skipped (om__cull). With bins (made for
 * this vp and image), triangles whose rows miss the target's are skipped before any
 * setup; NULL walks every triangle. The same pixels either way. */
void om__scene_raster(const om_scene *s, const om_mat4 *vp, om_vec3 o, const om_target *tg,
                      om_raster_mode mode, bool cull, const om__bins *bins);
/* om__scene_raster without bins of the triangles [t0, t1) alone, into a target the
 * caller has cleared: one part of a pass split by triangles. With ids, the parts drawn
 * into any targets in any order, and the targets merged pixel by pixel (the nearer
 * depth; on a tie the lower triangle), hold what one walk of every triangle gives: a
 * pixel's depth depends on its triangle alone, and the depth test gives a tie to the
 * lower triangle, which is the one a walk in order draws first. */
void om__scene_raster_part(const om_scene *s, const om_mat4 *vp, om_vec3 o, const om_target *tg, om_raster_mode mode,
                           bool cull, uint32_t t0, uint32_t t1);
/* The same with a coarse depth of tg's image (om__hiz_words; NULL: none), cleared
 * with the target: for the depth-only light passes, the same texels. */
void om__scene_raster_hiz(const om_scene *s, const om_mat4 *vp, om_vec3 o, const om_target *tg,
                          om_raster_mode mode, bool cull, const om__bins *bins, uint32_t *hiz);

#endif
