/* occlude.c — projection onto the light's grid, triangle setup for the occlusion
 * predicate (see occlude.h for the rule), and optical-depth transmittance. */
#include "occlude.h"

size_t om__lspace_bytes(const om_scene *s)
{
    return om_arena_need((size_t)s->nverts * sizeof(om__lvert), 8);
}

om_status om__lspace_init(om__lspace *ls, om_arena *a, const om_scene *s, om_diag *d)
{
    void *p;
    memset(ls, 0, sizeof *ls);
    ls->scene = s;
    om_status st = om_arena_alloc(a, (size_t)s->nverts * sizeof(om__lvert), 8, &p, d);
    ls->verts = (om__lvert *)p;
    return st;
}

void om__lspace_init_lean(om__lspace *ls, const om_scene *s)
{
    memset(ls, 0, sizeof *ls);
    ls->scene = s;
}

/* Sum of |terms| of clip-space row r over the scene's box: what the float rounding of
 * that coordinate is relative to. A row that is exactly 1 (an orthographic w) has no
 * rounding at all. */
static double row_mag(const om_mat4 *m, int r, double big)
{
    const float *a = m->m + 4 * r;
    if (a[0] == 0.0f && a[1] == 0.0f && a[2] == 0.0f && a[3] == 1.0f) return 0.0;
    return (fabs((double)a[0]) + fabs((double)a[1]) + fabs((double)a[2])) * big + fabs((double)a[3]);
}

static void bound_begin(om__lspace *ls, const om_view *v)
{
    const om_scene *s = ls->scene;
    const double u10 = 10.0 / 16777216.0;   /* 10 roundings of 2^-24 each (occlude.h) */
    double big = 0.0;
    const float c[6] = {s->lo.x, s->lo.y, s->lo.z, s->hi.x, s->hi.y, s->hi.z};
    for (int i = 0; i < 6; i++)
        if (fabs((double)c[i]) > big) big = fabs((double)c[i]);
    double sx = row_mag(&ls->vp, 0, big), sy = row_mag(&ls->vp, 1, big);
    double sz = row_mag(&ls->vp, 2, big), sw = row_mag(&ls->vp, 3, big);
    /* x/w, y/w reach 3 at the guard band's edge; z/w is clamped to [0, 1]. The grid has
     * 2^20 units per unit of x/w, depth 2^32 per unit of z/w. */
    ls->lat = u10 * ((sx > sy ? sx : sy) + 3.0 * sw) * 1048576.0;
    ls->dep = u10 * (sz + sw) * OM_DEPTH_ONE;
    if (v->light.kind == OM_LIGHT_SPOT) {
        /* z/w = -p10 + p11 / w for the perspective projection, so 1/w is affine in depth */
        double p10 = v->light_proj.m[10], p11 = v->light_proj.m[11];
        ls->iw0 = p10 / p11;
        ls->iw1 = 1.0 / (p11 * OM_DEPTH_ONE);
    } else {
        ls->iw0 = 1.0;
        ls->iw1 = 0.0;
    }
}

/* The snapping bound of a triangle whose nearest depth is zmin (occlude.h). */
static double bound(const om__lspace *ls, const om__rtri *r)
{
    double iw = ls->iw0 + ls->iw1 * r->zmin;
    if (!(iw > 0.0)) iw = 0.0;
    return 2.0 * ((fabs(r->zx) + fabs(r->zy)) * (1.5 + ls->lat * iw) + ls->dep * iw + 1.0);
}

void om__lspace_view(om__lspace *ls, const om_view *v)
{
    ls->vp = v->light_vp;
    bound_begin(ls, v);
}

void om__lspace_project(const om__lspace *ls, uint32_t first, uint32_t end)
{
    const om_scene *s = ls->scene;
    for (uint32_t i = first; ls->verts && i < end; i++) {
        om_vec4 c = om__mat_apply(&ls->vp, s->verts[i]);
        om__lvert *o = &ls->verts[i];
        int64_t X, Y;
        uint32_t Z;
        /* A vertex inside every plane projects exactly as clipping would project it. */
        if (om__outcode(&c, OM_LIGHT_GRID, OM_LIGHT_GRID) == 0 &&
            om__project(&c, OM_LIGHT_GRID, OM_LIGHT_GRID, &X, &Y, &Z)) {
            o->x = (int32_t)X;
            o->y = (int32_t)Y;
            o->z = Z;
        } else {
            o->x = INT32_MIN;
            o->y = 0;
            o->z = 0;
        }
    }
}

void om__lspace_begin(om__lspace *ls, const om_view *v)
{
    om__lspace_view(ls, v);
    om__lspace_project(ls, 0, ls->scene->nverts);
}

bool om__lspace_point(const om__lspace *ls, const om_sample *smp, om__lpoint *out)
{
    om_vec4 c = om__mat_apply(&ls->vp, om__v3(smp->p[0], smp->p[1], smp->p[2]));
    uint32_t z = 0;
    out->tri = smp->tri;
    const bool ok = om__project(&c, OM_LIGHT_GRID, OM_LIGHT_GRID, &out->x, &out->y, &z);
    out->z = z;
    return ok;
}

static void add_sub(const om__lspace *ls, om__ltri *lt, const int64_t x[3], const int64_t y[3],
                    const uint32_t z[3])
{
    om__rtri *r = &lt->sub[lt->n];
    if (!om__tri2_setup(&r->e, x, y, true)) return;
    om__rtri_plane(r, z);
    double b = lt->bound[lt->n] = bound(ls, r);
    for (int i = 0; i < 3; i++) {
        if (x[i] < lt->lox) lt->lox = x[i];
        if (x[i] > lt->hix) lt->hix = x[i];
        if (y[i] < lt->loy) lt->loy = y[i];
        if (y[i] > lt->hiy) lt->hiy = y[i];
    }
    if (r->zmin + b < lt->zmin) lt->zmin = r->zmin + b;
    lt->n++;
}

bool om__lspace_tri(const om__lspace *ls, uint32_t t, om__ltri *lt)
{
    const uint32_t *ix = ls->scene->idx + (size_t)t * 3;
    lt->n = 0;
    lt->tri = t;
    lt->lox = lt->loy = INT64_MAX;
    lt->hix = lt->hiy = INT64_MIN;
    lt->zmin = OM_DEPTH_ONE;
    const om__lvert *a = ls->verts ? &ls->verts[ix[0]] : NULL;
    const om__lvert *b = ls->verts ? &ls->verts[ix[1]] : NULL, *c = ls->verts ? &ls->verts[ix[2]] : NULL;
    if (a && a->x != INT32_MIN && b->x != INT32_MIN && c->x != INT32_MIN) {
        int64_t x[3] = {a->x, b->x, c->x}, y[3] = {a->y, b->y, c->y};
        uint32_t z[3] = {a->z, b->z, c->z};
        add_sub(ls, lt, x, y, z);
        return lt->n > 0;
    }
    om_vec4 clip[3];
    for (int k = 0; k < 3; k++) clip[k] = om__mat_apply(&ls->vp, ls->scene->verts[ix[k]]);
    for (int k = 0; k < 3; k++)
        if (!om__finite(clip[k].x) || !om__finite(clip[k].y) || !om__finite(clip[k].z) ||
            !om__finite(clip[k].w))
            return false;
    int64_t gx[9], gy[9];
    uint32_t gz[9];
    int n = om__clip_project(clip, OM_LIGHT_GRID, OM_LIGHT_GRID, gx, gy, gz);
    for (int k = 1; k + 1 < n; k++) {
        int64_t x[3] = {gx[0], gx[k], gx[k + 1]}, y[3] = {gy[0], gy[k], gy[k + 1]};
        uint32_t z[3] = {gz[0], gz[k], gz[k + 1]};
        add_sub(ls, lt, x, y, z);
    }
    return lt->n > 0;
}

/* ---- transmittance */

om__odepth om__material_odepth(const om_material *m)
{
    om__odepth o;
    const float ch[3] = {m->r, m->g, m->b};
    for (int i = 0; i < 3; i++) {
        float t = (1.0f - m->opacity) * ch[i];
        int q = (int)(t * 255.0f + 0.5f);
        if (q <= 0) o.c[i] = OM_OPAQUE_DEPTH;
        else if (q >= 255) o.c[i] = 0;
        else o.c[i] = (uint32_t)(-om__log2(q / 255.0) * 4096.0 + 0.5);
    }
    return o;
}

void om__odepth_term(const om__odepth *o, om_term *t)
{
    uint8_t v[3];
    if ((o->c[0] | o->c[1] | o->c[2]) == 0) {   /* unblocked: the common case */
        t->r = t->g = t->b = 255;
        return;
    }
    for (int i = 0; i < 3; i++) {
        if (o->c[i] == OM_OPAQUE_DEPTH || o->c[i] >= 4096u * 12u) v[i] = 0;   /* below 1/4096: 0 */
        else v[i] = (uint8_t)(255.0 * om__exp2(-(double)o->c[i] / 4096.0) + 0.5);
    }
    t->r = v[0];
    t->g = v[1];
    t->b = v[2];
}
