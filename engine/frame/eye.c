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

static void clip_tri(const om_scene *s, const om_mat4 *vp, uint32_t t, om_vec4 c[3])
{
    const uint32_t *ix = s->idx + (size_t)t * 3;
    for (int k = 0; k < 3; k++) c[k] = om__mat_apply(vp, s->verts[ix[k]]);
}

void om__persp_setup(const om_scene *s, const om_mat4 *vp, uint32_t t, om__persp_tri *c)
{
    om_vec4 q[3];
    clip_tri(s, vp, t, q);
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
}

/* A margin in front of the near plane, in clip z over w: the vertices are inside the
 * box, but their clip coordinates are rounded on their own. */
#define CULL_MARGIN 1e-4f

static bool solid_in_front(const om_solid *o, const om_mat4 *vp)
{
    for (int i = 0; i < 8; i++) {
        om_vec3 p = om__v3(i & 1 ? o->hi.x : o->lo.x, i & 2 ? o->hi.y : o->lo.y, i & 4 ? o->hi.z : o->lo.z);
        om_vec4 q = om__mat_apply(vp, p);
        if (!(q.w > 0.0f && q.z >= CULL_MARGIN * q.w)) return false;
    }
    return true;
}

void om__cull_begin(om__cull *c, const om_scene *s, const om_mat4 *vp)
{
    c->s = s;
    c->vp = vp;
    c->k = 0;
    c->seen = UINT32_MAX;
    c->on = false;
}

bool om__cull_next(om__cull *c, uint32_t t)
{
    const om_scene *s = c->s;
    if (!s->solids) return false;
    /* solids are in triangle order; a hand-made list out of order only culls less */
    while (c->k < s->nsolids && (uint64_t)s->solids[c->k].first + s->solids[c->k].count <= t) c->k++;
    if (c->k >= s->nsolids) return false;
    const om_solid *o = &s->solids[c->k];
    if (t < o->first || (uint64_t)o->first + o->count > s->ntris) return false;
    if (c->seen != c->k) {
        c->seen = c->k;
        c->on = solid_in_front(o, c->vp);
    }
    return c->on;
}

size_t om__bins_rows_bytes(const om_scene *s)
{
    return om_arena_need((size_t)s->ntris * sizeof(uint32_t), 8);
}

size_t om__bins_verts_bytes(const om_scene *s)
{
    return om_arena_need((size_t)s->nverts * sizeof(om__vsnap), 8);
}

/* Vertex c snapped alone, when it needs no clipping: the test om__raster_tri makes
 * first (finite, inside every plane), then its projection. */
static bool snap_alone(const om_vec4 *c, uint32_t width, uint32_t height, om__vsnap *out)
{
    int64_t x, y;
    uint32_t z;
    if (!om__finite(c->x) || !om__finite(c->y) || !om__finite(c->z) || !om__finite(c->w) ||
        om__outcode(c, width, height) != 0 || !om__project(c, width, height, &x, &y, &z))
        return false;
    out->x = (int32_t)x;   /* |x|, |y| < 2^26 after om__project */
    out->y = (int32_t)y;
    out->z = z;
    return true;
}

/* Row r's pixel centres lie at r * 256 + 128: the rows between grid rows lo and hi, a
 * row either side to spare. */
static uint32_t row_span(int64_t lo, int64_t hi, uint32_t height)
{
    int64_t r0 = (lo - OM_SUBPIX / 2) / OM_SUBPIX - 1, r1 = (hi - OM_SUBPIX / 2) / OM_SUBPIX + 1;
    if (r0 < 0) r0 = 0;
    if (r1 > (int64_t)height - 1) r1 = (int64_t)height - 1;
    return r0 > r1 ? 0x0000FFFFu : (uint32_t)r0 | (uint32_t)r1 << 16;
}

void om__bins_make(const om_scene *s, const om_mat4 *vp, uint32_t width, uint32_t height, const om__bins *b)
{
    const uint32_t all = (height - 1) << 16;
    om__vsnap *vs = b->verts;
    for (uint32_t v = 0; vs && v < s->nverts; v++) {
        const om_vec4 c = om__mat_apply(vp, s->verts[v]);
        if (!snap_alone(&c, width, height, &vs[v])) vs[v].x = INT32_MIN;
    }
    for (uint32_t t = 0; b->rows && t < s->ntris; t++) {
        const uint32_t *ix = s->idx + (size_t)t * 3;
        if (vs && vs[ix[0]].x != INT32_MIN && vs[ix[1]].x != INT32_MIN && vs[ix[2]].x != INT32_MIN) {
            int64_t lo = vs[ix[0]].y, hi = lo;
            for (int k = 1; k < 3; k++) {
                if (vs[ix[k]].y < lo) lo = vs[ix[k]].y;
                if (vs[ix[k]].y > hi) hi = vs[ix[k]].y;
            }
            b->rows[t] = row_span(lo, hi, height);
            continue;
        }
        om_vec4 c[3];
        clip_tri(s, vp, t, c);
        unsigned out_all = 0x3F, out_any = 0;
        for (int k = 0; k < 3; k++) {
            unsigned o = om__outcode(&c[k], width, height);
            out_all &= o;
            out_any |= o;
        }
        if (out_all) { b->rows[t] = 0x0000FFFFu; continue; }   /* wholly beyond one plane */
        if (out_any) { b->rows[t] = all; continue; }            /* clipped: every row */
        /* Inside every plane: the rasterizer snaps these very positions. */
        int64_t lo = INT64_MAX, hi = INT64_MIN;
        bool ok = true;
        for (int k = 0; k < 3; k++) {
            int64_t gx, gy;
            if (!om__project_xy(&c[k], width, height, &gx, &gy)) { ok = false; break; }
            if (gy < lo) lo = gy;
            if (gy > hi) hi = gy;
        }
        b->rows[t] = ok ? row_span(lo, hi, height) : all;
    }
}

void om__scene_raster(const om_scene *s, const om_mat4 *vp, const om_target *tg,
                      om_raster_mode mode, bool cull, const om__bins *bins)
{
    om_raster r;
    r.target = tg;
    r.mode = mode;
    r.span = NULL;
    r.user = NULL;
    r.centres = NULL;
    r.centre_mask = NULL;
    r.grid_x = r.grid_y = NULL;
    r.grid_xs = r.grid_ys = NULL;
    r.grid_shift = r.grid_buckets = 0;
    r.mask_words = 0;
    r.cull_back = false;
    om__cull cl;
    om__cull_begin(&cl, s, vp);
    om__target_clear(tg);
    const uint32_t y0 = tg->y0, y1 = tg->y0 + tg->rows - 1;
    const uint32_t *rows = bins ? bins->rows : NULL;
    const om__vsnap *vs = bins ? bins->verts : NULL;
    for (uint32_t t = 0; t < s->ntris; t++) {
        if (rows && ((rows[t] & 0xFFFFu) > y1 || rows[t] >> 16 < y0)) continue;
        r.cull_back = cull && om__cull_next(&cl, t);
        const uint32_t *ix = s->idx + (size_t)t * 3;
        if (vs && vs[ix[0]].x != INT32_MIN && vs[ix[1]].x != INT32_MIN && vs[ix[2]].x != INT32_MIN) {
            const int64_t x[3] = {vs[ix[0]].x, vs[ix[1]].x, vs[ix[2]].x};
            const int64_t y[3] = {vs[ix[0]].y, vs[ix[1]].y, vs[ix[2]].y};
            const uint32_t z[3] = {vs[ix[0]].z, vs[ix[1]].z, vs[ix[2]].z};
            om__raster_snapped(&r, x, y, z, t);
            continue;
        }
        om_vec4 c[3];
        clip_tri(s, vp, t, c);
        om__raster_tri(&r, c, t);
    }
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
                continue;
            }
            if (cache.tri != t) om__persp_setup(s, &v->cam_vp, t, &cache);
            float sx = ((float)x + 0.5f) * (2.0f / (float)st->width) - 1.0f;
            resolve_pixel(&cache, sx, sy, smp);
        }
    }
}
