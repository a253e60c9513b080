/* eye.c — the eye pass: rasterize the scene from the camera (depth + triangle id),
 * then give every covered pixel its visible point. The point comes from
 * perspective-correct barycentrics of the pixel centre in homogeneous clip space
 * (no division by w, so triangles crossing the camera plane are handled), applied as
 * v0 + w1 (v1 - v0) + w2 (v2 - v0): an error in the weights moves the point within the
 * triangle's plane, not off it, whatever the depth buffer's precision. All in float:
 * per pixel it is a handful of single-precision operations, which a Cortex-M4F does in
 * hardware (double there is a software routine per operation); off the plane the
 * point is within a few float roundings of its coordinates (occlude.h counts them). */
#include "frame.h"

void om__persp_setup(const om_scene *s, const om_mat4 *vp, uint32_t t, om__persp_tri *c)
{
    om_vec4 q[3];
    om__clip_tri(s, vp, t, q);
    /* M has columns (x_i, y_i, w_i); we need M^-1 up to scale: the adjugate. */
    float m[9] = {q[0].x, q[1].x, q[2].x, q[0].y, q[1].y, q[2].y, q[0].w, q[1].w, q[2].w};
    c->adj[0] = m[4] * m[8] - m[5] * m[7];
    c->adj[1] = m[2] * m[7] - m[1] * m[8];
    c->adj[2] = m[1] * m[5] - m[2] * m[4];
    c->adj[3] = m[5] * m[6] - m[3] * m[8];
    c->adj[4] = m[0] * m[8] - m[2] * m[6];
    c->adj[5] = m[2] * m[3] - m[0] * m[5];
    c->adj[6] = m[3] * m[7] - m[4] * m[6];
    c->adj[7] = m[1] * m[6] - m[0] * m[7];
    c->adj[8] = m[0] * m[4] - m[1] * m[3];
    const uint32_t *ix = s->idx + (size_t)t * 3;
    for (int k = 0; k < 3; k++) c->v[k] = s->verts[ix[k]];
    c->d1 = om__sub(c->v[1], c->v[0]);
    c->d2 = om__sub(c->v[2], c->v[0]);
    c->n = om__normalize(om__cross(c->d1, c->d2));
    c->tri = t;
}

om_vec3 om__persp_point(const om__persp_tri *c, float sx, float sy)
{
    float b0 = c->adj[0] * sx + c->adj[1] * sy + c->adj[2];
    float b1 = c->adj[3] * sx + c->adj[4] * sy + c->adj[5];
    float b2 = c->adj[6] * sx + c->adj[7] * sy + c->adj[8];
    float sum = b0 + b1 + b2;
    float inv = sum != 0.0f ? 1.0f / sum : 0.0f;
    float w1 = b1 * inv, w2 = b2 * inv;
    return om__v3(c->v[0].x + w1 * c->d1.x + w2 * c->d2.x, c->v[0].y + w1 * c->d1.y + w2 * c->d2.y,
                  c->v[0].z + w1 * c->d1.z + w2 * c->d2.z);
}

static void resolve_pixel(const om__persp_tri *c, float sx, float sy, om_sample *out)
{
    om_vec3 p = om__persp_point(c, sx, sy);
    out->p[0] = p.x;
    out->p[1] = p.y;
    out->p[2] = p.z;
    out->n[0] = c->n.x;
    out->n[1] = c->n.y;
    out->n[2] = c->n.z;
    out->tri = c->tri;
    out->nl = 0.0f;   /* set with the exposure marks */
}

void om__eye_pass(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st,
                  const om__bins *bins)
{
    /* Culling is exact here too: the visible point of a pixel is the nearest, and the
     * nearest surface of a closed shape the camera is outside of faces the camera. */
    om__scene_raster(s, &v->cam_vp, tg, OM_RASTER_DEPTH_ID, true, bins);
    om__persp_tri cache;
    memset(&cache, 0, sizeof cache);
    cache.tri = OM_NO_TRI;
    for (uint32_t y = 0; y < st->rows; y++) {
        float sy = 1.0f - ((float)(st->y0 + y) + 0.5f) * (2.0f / (float)st->height);
        for (uint32_t x = 0; x < st->width; x++) {
            size_t i = (size_t)y * st->width + x;
            uint32_t t = tg->id[i];
            om_sample *smp = &st->samples[i];
            if (t == OM_NO_TRI) {   /* field by field: a freestanding build calls memset */
                smp->p[0] = smp->p[1] = smp->p[2] = 0.0f;
                smp->n[0] = smp->n[1] = smp->n[2] = 0.0f;
                smp->tri = OM_NO_TRI;
                smp->nl = 0.0f;
                continue;
            }
            if (cache.tri != t) om__persp_setup(s, &v->cam_vp, t, &cache);
            float sx = ((float)x + 0.5f) * (2.0f / (float)st->width) - 1.0f;
            resolve_pixel(&cache, sx, sy, smp);
        }
    }
}
