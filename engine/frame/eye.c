/* eye.c — the eye pass: rasterize the scene from the camera (depth + triangle id),
 * then give every covered pixel its visible point. The point comes from
 * perspective-correct barycentrics of the pixel centre in homogeneous clip space
 * (no division by w, so triangles crossing the camera plane are handled), applied as
 * v0 + w1 (v1 - v0) + w2 (v2 - v0): an error in the weights moves the point within the
 * triangle's plane, not off it, whatever the depth buffer's precision. All in float:
 * per pixel it is a handful of single-precision operations, which a Cortex-M4F does in
 * hardware (double there is a software routine per operation); off the plane the
 * point is within a few float roundings of its coordinates (occlude.h counts them).
 * The pixels are taken a run of one triangle at a time, and where the frame asks for
 * it (om__eye_pass_mark) each pixel's exposure marks are made in the same loop. */
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

/* The pixels [x0, x1) of one row that triangle c covers: the run's constants sit in
 * locals (registers) rather than being loaded again per pixel, and the products with
 * the row's sy are made once; each is the very product om__persp_point makes, so the
 * points are the same bits. With `terms`, each pixel's exposure marks too. */
static void resolve_run(const om_view *v, const om__persp_tri *c, uint32_t x0, uint32_t x1,
                        float sy, float sxk, om_sample *smp, om_term *terms)
{
    const float a0 = c->adj[0], a3 = c->adj[3], a6 = c->adj[6];
    const float r0 = c->adj[1] * sy, r1 = c->adj[4] * sy, r2 = c->adj[7] * sy;
    const float a2 = c->adj[2], a5 = c->adj[5], a8 = c->adj[8];
    const om_vec3 o = c->v[0], d1 = c->d1, d2 = c->d2, n = c->n;
    const uint32_t tri = c->tri;
    for (uint32_t x = x0; x < x1; x++) {
        const float sx = ((float)x + 0.5f) * sxk - 1.0f;
        const float b0 = a0 * sx + r0 + a2;
        const float b1 = a3 * sx + r1 + a5;
        const float b2 = a6 * sx + r2 + a8;
        const float sum = b0 + b1 + b2;
        const float inv = sum != 0.0f ? 1.0f / sum : 0.0f;
        const float w1 = b1 * inv, w2 = b2 * inv;
        const om_vec3 p = om__v3(o.x + w1 * d1.x + w2 * d2.x, o.y + w1 * d1.y + w2 * d2.y,
                                 o.z + w1 * d1.z + w2 * d2.z);
        om_sample *out = &smp[x];
        out->p[0] = p.x;
        out->p[1] = p.y;
        out->p[2] = p.z;
        out->n[0] = n.x;
        out->n[1] = n.y;
        out->n[2] = n.z;
        out->tri = tri;
        if (terms) {
            om_term *t = &terms[x];
            t->r = t->g = t->b = 255;
            t->flags = om__exposed_at(v, p, n, &out->nl) ? OM_TERM_EXPOSED : 0;
        } else {
            out->nl = 0.0f;   /* set with the exposure marks */
        }
    }
}

static void eye_pass(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st,
                     const om__bins *bins, bool mark)
{
    /* Culling is exact here too: the visible point of a pixel is the nearest, and the
     * nearest surface of a closed shape the camera is outside of faces the camera. */
    om__scene_raster(s, &v->cam_vp, tg, OM_RASTER_DEPTH_ID, true, bins);
    om__persp_tri cache;
    memset(&cache, 0, sizeof cache);
    cache.tri = OM_NO_TRI;
    const uint32_t w = st->width;
    const float sxk = 2.0f / (float)w;
    for (uint32_t y = 0; y < st->rows; y++) {
        float sy = 1.0f - ((float)(st->y0 + y) + 0.5f) * (2.0f / (float)st->height);
        const uint32_t *id = tg->id + (size_t)y * w;
        om_sample *smp = st->samples + (size_t)y * w;
        om_term *terms = mark ? st->terms + (size_t)y * w : NULL;
        for (uint32_t x = 0; x < w;) {
            const uint32_t t = id[x];
            uint32_t x1 = x + 1;
            while (x1 < w && id[x1] == t) x1++;   /* the run of pixels t covers */
            if (t == OM_NO_TRI) {
                for (; x < x1; x++) {   /* field by field: a freestanding build calls memset */
                    smp[x].p[0] = smp[x].p[1] = smp[x].p[2] = 0.0f;
                    smp[x].n[0] = smp[x].n[1] = smp[x].n[2] = 0.0f;
                    smp[x].tri = OM_NO_TRI;
                    smp[x].nl = 0.0f;
                    if (terms) {
                        terms[x].r = terms[x].g = terms[x].b = 255;
                        terms[x].flags = 0;
                    }
                }
                continue;
            }
            if (cache.tri != t) om__persp_setup(s, &v->cam_vp, t, &cache);
            resolve_run(v, &cache, x, x1, sy, sxk, smp, terms);
            x = x1;
        }
    }
}

void om__eye_pass(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st,
                  const om__bins *bins)
{
    eye_pass(s, v, tg, st, bins, false);
}

void om__eye_pass_mark(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st,
                       const om__bins *bins)
{
    eye_pass(s, v, tg, st, bins, true);
}
