/* scene_raster.c — a scene through the rasterizer (scene_raster.h): the back-face
 * culling of closed shapes, the per-frame bins of rows and snapped vertices, and the
 * walk over the scene's triangles that the eye pass and the light depth passes share. */
#include "scene_raster.h"

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
static bool snap_alone(const om_vec4 *c, uint32_t width, uint32_t height, om__guard g, om__vsnap *out)
{
    int64_t x, y;
    uint32_t z;
    if (!om__finite(c->x) || !om__finite(c->y) || !om__finite(c->z) || !om__finite(c->w) ||
        !om__inside_band(c, g) || !om__project(c, width, height, &x, &y, &z))
        return false;
    out->x = (int32_t)x;   /* |x|, |y| < 2^26 after om__project */
    out->y = (int32_t)y;
    out->z = z;
    return true;
}

/* Row r's pixel centres lie at r * 256 + 128: the rows between grid rows lo and hi, a
 * row either side to spare. */
static uint32_t rows_between(int64_t lo, int64_t hi, uint32_t height)
{
    int64_t r0 = (lo - OM_SUBPIX / 2) / OM_SUBPIX - 1, r1 = (hi - OM_SUBPIX / 2) / OM_SUBPIX + 1;
    if (r0 < 0) r0 = 0;
    if (r1 > (int64_t)height - 1) r1 = (int64_t)height - 1;
    return r0 > r1 ? 0x0000FFFFu : (uint32_t)r0 | (uint32_t)r1 << 16;
}

void om__bins_make(const om_scene *s, const om_mat4 *vp, uint32_t width, uint32_t height, const om__bins *b)
{
    om__bins_make_verts(s, vp, width, height, b, 0, s->nverts);
    om__bins_make_rows(s, vp, width, height, b, 0, s->ntris);
}

void om__bins_make_verts(const om_scene *s, const om_mat4 *vp, uint32_t width, uint32_t height, const om__bins *b,
                         uint32_t v0, uint32_t v1)
{
    om__vsnap *vs = b->verts;
    const om__guard g = om__guard_band(width, height);
    for (uint32_t v = v0; vs && v < v1 && v < s->nverts; v++) {
        const om_vec4 c = om__mat_apply(vp, s->verts[v]);
        if (!snap_alone(&c, width, height, g, &vs[v])) {
            vs[v].x = INT32_MIN;   /* all of it: the frame's bins are not zeroed first */
            vs[v].y = 0;
            vs[v].z = 0;
        }
    }
}

void om__bins_make_rows(const om_scene *s, const om_mat4 *vp, uint32_t width, uint32_t height, const om__bins *b,
                        uint32_t t0, uint32_t t1)
{
    const uint32_t all = (height - 1) << 16;
    const om__vsnap *vs = b->verts;
    for (uint32_t t = t0; b->rows && t < t1 && t < s->ntris; t++) {
        const uint32_t *ix = s->idx + (size_t)t * 3;
        if (vs && vs[ix[0]].x != INT32_MIN && vs[ix[1]].x != INT32_MIN && vs[ix[2]].x != INT32_MIN) {
            int64_t lo = vs[ix[0]].y, hi = lo;
            for (int k = 1; k < 3; k++) {
                if (vs[ix[k]].y < lo) lo = vs[ix[k]].y;
                if (vs[ix[k]].y > hi) hi = vs[ix[k]].y;
            }
            b->rows[t] = rows_between(lo, hi, height);
            continue;
        }
        om_vec4 c[3];
        om__clip_tri(s, vp, t, c);
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
        b->rows[t] = ok ? rows_between(lo, hi, height) : all;
    }
}

void om__scene_raster(const om_scene *s, const om_mat4 *vp, const om_target *tg,
                      om_raster_mode mode, bool cull, const om__bins *bins)
{
    om__scene_raster_hiz(s, vp, tg, mode, cull, bins, NULL);
}

void om__scene_raster_hiz(const om_scene *s, const om_mat4 *vp, const om_target *tg,
                          om_raster_mode mode, bool cull, const om__bins *bins, uint32_t *hiz)
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
    r.row_mask = NULL;
    r.row_shift = 0;
    om__cull cl;
    om__cull_begin(&cl, s, vp);
    om__target_clear(tg);
    om__hiz_clear(hiz, tg);
    const uint32_t y0 = tg->y0, y1 = tg->y0 + tg->rows - 1;
    const uint32_t *rows = bins ? bins->rows : NULL;
    const om__vsnap *vs = bins ? bins->verts : NULL;
    const om__guard g = om__guard_band(tg->width, tg->height);
    for (uint32_t t = 0; t < s->ntris; t++) {
        if (rows && ((rows[t] & 0xFFFFu) > y1 || rows[t] >> 16 < y0)) continue;
        r.cull_back = cull && om__cull_next(&cl, t);
        const uint32_t *ix = s->idx + (size_t)t * 3;
        if (vs && vs[ix[0]].x != INT32_MIN && vs[ix[1]].x != INT32_MIN && vs[ix[2]].x != INT32_MIN) {
            const int64_t x[3] = {vs[ix[0]].x, vs[ix[1]].x, vs[ix[2]].x};
            const int64_t y[3] = {vs[ix[0]].y, vs[ix[1]].y, vs[ix[2]].y};
            const uint32_t z[3] = {vs[ix[0]].z, vs[ix[1]].z, vs[ix[2]].z};
            om__raster_snapped_hiz(&r, hiz, x, y, z, t);
            continue;
        }
        om_vec4 c[3];
        om__clip_tri(s, vp, t, c);
        om__raster_tri_guarded(&r, hiz, c, t, tg->width, tg->height, g);
    }
}
