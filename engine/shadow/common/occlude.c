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
    /* The largest coordinate of a vertex relative to the origin: the scene's box made
     * relative as the vertices are (rounding is monotonic, so it holds them all). */
    double big = 0.0;
    const om_vec3 lo = om__sub(s->lo, v->origin), hi = om__sub(s->hi, v->origin);
    const float c[6] = {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z};
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
    /* the sample's facet (facet_slope): z/w = -p10 + p11 / w (spot) or p10 z + p11
     * (directional) over x/w = p0 x / w, y/w = p5 y / w; the grid has 2^20 units per unit
     * of x/w and 2^32 of depth per unit of z/w, hence 2^12 */
    const om_mat4 *lv = &v->light_view, *lp = &v->light_proj;
    ls->spot = v->light.kind == OM_LIGHT_SPOT;
    ls->row0 = om__v3(lv->m[0], lv->m[1], lv->m[2]);
    ls->row1 = om__v3(lv->m[4], lv->m[5], lv->m[6]);
    ls->row2 = om__v3(lv->m[8], lv->m[9], lv->m[10]);
    ls->lpos = v->light.pos;
    const double coef = fabs((double)(ls->spot ? lp->m[11] : lp->m[10])) * 4096.0;
    ls->kx = (float)(coef / fabs((double)lp->m[0]));
    ls->ky = (float)(coef / fabs((double)lp->m[5]));
    ls->iw0f = (float)ls->iw0;
    ls->iw1f = (float)ls->iw1;
    ls->latf = (float)ls->lat;
    ls->depf = (float)ls->dep;
    ls->iw0a = om__fabsf(ls->iw0f);
    ls->iw1a = om__fabsf(ls->iw1f);
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
    ls->o = v->origin;
    bound_begin(ls, v);
}

void om__lspace_project(const om__lspace *ls, uint32_t first, uint32_t end)
{
    const om_scene *s = ls->scene;
    for (uint32_t i = first; ls->verts && i < end; i++) {
        om_vec4 c = om__mat_apply(&ls->vp, om__sub(s->verts[i], ls->o));
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

/* A facet's depth slope on the grid, |dD/dX| + |dD/dY|, which the sample's own
 * facet's slack (occlude.h) multiplies by the lateral error (1.5 + lat iw) that bound()
 * takes for a blocker. For triangle t's plane n . (X - L) = c (n = e1 x e2 from its
 * vertices relative to the origin, L the spot light, in view coordinates along the
 * light's rows) the slope is
 *   2^12 |p11| (|n0| / |p0| + |n1| / |p5|) / |c|   (spot: 1/w is affine in x/w, y/w),
 *   2^12 |p10| (|n0| / |p0| + |n1| / |p5|) / |n2|  (directional),
 * n0, n1, n2 the normal's view coordinates (any length: the ratios are the same). In
 * float, with M the product of the edges' component sums (each of n's components is
 * within 3u M of the exact one): c and n2 are taken smaller by 2^-19 of M (times the
 * vertex's component sum for c) and n0, n1 larger by 2^-19 M, so the slope is at least
 * the exact one; a facet edge-on to within that has an infinite slope. A function of
 * the triangle and the frame alone, so any cache of it gives the same bits. */
static float facet_slope(const om__lspace *ls, uint32_t t)
{
    const om_scene *s = ls->scene;
    const uint32_t *ix = s->idx + (size_t)t * 3;
    const om_vec3 a = om__sub(s->verts[ix[0]], ls->o), b = om__sub(s->verts[ix[1]], ls->o);
    const om_vec3 c3 = om__sub(s->verts[ix[2]], ls->o);
    const om_vec3 e1 = om__sub(b, a), e2 = om__sub(c3, a), n = om__cross(e1, e2);
    const float m = (om__fabsf(e1.x) + om__fabsf(e1.y) + om__fabsf(e1.z)) *
                    (om__fabsf(e2.x) + om__fabsf(e2.y) + om__fabsf(e2.z)) * 0x1p-19f;
    const float n0 = om__fabsf(om__dot(n, ls->row0)) + m, n1 = om__fabsf(om__dot(n, ls->row1)) + m;
    float den;
    if (ls->spot) {
        const om_vec3 d = om__sub(a, ls->lpos);
        den = om__fabsf(om__dot(n, d)) - m * (om__fabsf(d.x) + om__fabsf(d.y) + om__fabsf(d.z) + 1.0f);
    } else {
        den = om__fabsf(om__dot(n, ls->row2)) - m;
    }
    const float slope = (ls->kx * n0 + ls->ky * n1) / den;
    return den > 0.0f && slope < 1e30f ? slope : 1e30f;
}

/* The slack itself, a whole number of depth units, at least the exact one: the float
 * chain is made 2^-10 larger and rounded up. */
static uint32_t facet_slack(const om__lspace *ls, float slope, uint32_t z)
{
    float iw = ls->spot ? ls->iw0f + ls->iw1f * (float)z : 1.0f;
    if (!(iw > 0.0f)) iw = 0.0f;
    const float k = slope * (1.5f + ls->latf * iw) * (1.0f + 0x1p-10f) + 1.0f;
    if (!(k < 4294967040.0f)) return 0xFFFFFFFFu;   /* the largest float below 2^32 */
    const uint32_t u = (uint32_t)k;
    return u + ((float)u < k);
}

bool om__lspace_point_at(const om__lspace *ls, const om_sample *smp, om__lpoint *out, uint32_t *z)
{
    om_vec4 c = om__mat_apply(&ls->vp, om__v3(smp->p[0], smp->p[1], smp->p[2]));
    *z = 0;
    out->tri = smp->tri;
    const bool ok = om__project(&c, OM_LIGHT_GRID, OM_LIGHT_GRID, &out->x, &out->y, z);
    out->z = *z;
    return ok;
}

bool om__lspace_point_z(const om__lspace *ls, const om_sample *smp, om__lpoint *out, uint32_t *z)
{
    const bool ok = om__lspace_point_at(ls, smp, out, z);
    om__facet f = {OM_NO_TRI, 0.0f};
    *z = om__lspace_pull(ls, &f, smp->tri, *z);
    out->z = *z;
    return ok;
}

uint32_t om__lspace_pull(const om__lspace *ls, om__facet *f, uint32_t tri, uint32_t z)
{
    if (f->tri != tri) {
        f->tri = tri;
        f->slope = facet_slope(ls, tri);
    }
    const uint32_t k = facet_slack(ls, f->slope, z);
    return k < z ? z - k : 0;
}

bool om__lspace_point(const om__lspace *ls, const om_sample *smp, om__lpoint *out)
{
    uint32_t z;
    return om__lspace_point_z(ls, smp, out, &z);
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

/* An empty setup of triangle t. */
static void ltri_begin(om__ltri *lt, uint32_t t)
{
    lt->n = 0;
    lt->tri = t;
    lt->lox = lt->loy = INT64_MAX;
    lt->hix = lt->hiy = INT64_MIN;
    lt->zmin = OM_DEPTH_ONE;
}

bool om__lspace_tri_at(const om__lspace *ls, uint32_t t, const om__lvert v[3], om__ltri *lt)
{
    int64_t x[3] = {v[0].x, v[1].x, v[2].x}, y[3] = {v[0].y, v[1].y, v[2].y};
    uint32_t z[3] = {v[0].z, v[1].z, v[2].z};
    ltri_begin(lt, t);
    add_sub(ls, lt, x, y, z);
    return lt->n > 0;
}

bool om__lspace_tri(const om__lspace *ls, uint32_t t, om__ltri *lt)
{
    const uint32_t *ix = ls->scene->idx + (size_t)t * 3;
    const om__lvert *a = ls->verts ? &ls->verts[ix[0]] : NULL;
    const om__lvert *b = ls->verts ? &ls->verts[ix[1]] : NULL, *c = ls->verts ? &ls->verts[ix[2]] : NULL;
    if (a && a->x != INT32_MIN && b->x != INT32_MIN && c->x != INT32_MIN) {
        const om__lvert v[3] = {*a, *b, *c};
        return om__lspace_tri_at(ls, t, v, lt);
    }
    ltri_begin(lt, t);
    om_vec4 clip[3];
    for (int k = 0; k < 3; k++) clip[k] = om__mat_apply(&ls->vp, om__sub(ls->scene->verts[ix[k]], ls->o));
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

/* ---- the predicate in single precision (om__blocks_f)
 *
 * For a triangle the frame projected whole, om__lspace_tri makes one sub-triangle with
 * its input vertex a first, and om__blocks asks, when p is inside it, whether
 *   Q = depth + bound < z,   depth = z_a + zx dx + zy dy   (dx, dy: p - a),
 *   bound = 2 ((|zx| + |zy|) (1.5 + lat iw) + dep iw + 1),   iw = max(0, iw0 + iw1 zmin),
 * all in double, zx, zy the plane's gradient on the grid. Here the same expression is
 * evaluated in float from exact integer pieces: coordinates within 2^22 (the guard
 * band's vertices are), so every difference of two is an exact float; the edge
 * functions at p (exact int64 products of int32) say whether p is strictly inside,
 * strictly outside (as ref.c's sign test: then no tie rule can hold it) or on an edge
 * (undecided); twice the area A (their sum, below 2^48) and the depth differences d1,
 * d2 (below 2^32) become floats with one rounding each (f48).
 *
 * The bound, with u = 2^-24 and Sx = (|d1 y2| + |d2 y1|) / A, Sy likewise (|zx| <= Sx,
 * |zy| <= Sy), IW = |iw0| + |iw1| zmin, and
 *   M = z_a + Sx |dx| + Sy |dy| + 2 ((Sx + Sy) (1.5 + lat IW) + dep IW + 1)
 * (the expression with every term made positive): each float operation rounds within
 * u of its result and every input is within u of the double's (the conversions), so
 * zx, zy are within 5.1u Sx, 5.1u Sy of the exact gradient, the depth within 8.3u of
 * its part of M, iw within 4.1u IW (max(0, .) moves nothing further apart), the bound
 * within 17u of its part, and Q within 19u M of the exact Q. The double's Q is within
 * 2^-48 M of the exact one (the same steps at 2^-53, including a sliver's cancelling
 * gradient, which M counts through Sx |dx|); z's float is within u z. The float's M
 * is at most 12u below M, so e = 2^-19 (M + z), 32u, covers all of them: Q + e below z
 * (as floats: rounding is monotonic, so a sum that rounds below a float was below
 * it) means the double's Q is below z, blocked; Q - e above z, not blocked. Between
 * them the double decides. The depth clamp of om__rtri_depth changes nothing: the
 * exact depth at a point inside lies between the vertices', and clamping only moves
 * the double's value towards it. tests/unit/shadow_common.c calls this next to the
 * threshold. */

/* |v| < 2^48 as a float with one rounding: both halves are exact floats. */
static inline float f48(int64_t v)
{
    return (float)(int32_t)(v / 16777216) * 16777216.0f + (float)(int32_t)(v % 16777216);
}

/* Within [-2^22, 2^22]. */
static inline bool in22(int64_t v)
{
    return (uint64_t)(v + ((int64_t)1 << 22)) <= ((uint64_t)1 << 23);
}

int om__blocks_f(const om__lspace *ls, uint32_t t, const om__lpoint *p, uint32_t z)
{
    if (t == p->tri) return 0;
    if (!ls->verts || !in22(p->x) || !in22(p->y)) return -1;
    const uint32_t *ix = ls->scene->idx + (size_t)t * 3;
    const om__lvert *a = &ls->verts[ix[0]], *b = &ls->verts[ix[1]], *c = &ls->verts[ix[2]];
    if (!in22(a->x) || !in22(b->x) || !in22(c->x) || !in22(a->y) || !in22(b->y) || !in22(c->y))
        return -1;   /* one that needs clipping (INT32_MIN) too */
    const int32_t px = (int32_t)p->x, py = (int32_t)p->y;
    const int32_t ax = a->x - px, ay = a->y - py, bx = b->x - px, by = b->y - py;
    const int32_t cx = c->x - px, cy = c->y - py;
    const int64_t eab = (int64_t)ax * by - (int64_t)ay * bx, ebc = (int64_t)bx * cy - (int64_t)by * cx;
    const int64_t eca = (int64_t)cx * ay - (int64_t)cy * ax;
    const int pos = (eab > 0) + (ebc > 0) + (eca > 0), neg = (eab < 0) + (ebc < 0) + (eca < 0);
    if (pos && neg) return 0;          /* strictly outside one edge, inside another */
    if (pos != 3 && neg != 3) return -1;   /* on an edge: the tie rule decides */
    const float area = f48(pos ? eab + ebc + eca : -(eab + ebc + eca));
    const float as = pos ? area : -area;   /* signed, as x1 y2 - x2 y1 */
    const float x1 = (float)(b->x - a->x), y1 = (float)(b->y - a->y);
    const float x2 = (float)(c->x - a->x), y2 = (float)(c->y - a->y);
    const float d1 = f48((int64_t)b->z - a->z), d2 = f48((int64_t)c->z - a->z);
    const uint32_t zm = a->z < b->z ? (a->z < c->z ? a->z : c->z) : (b->z < c->z ? b->z : c->z);
    const float zmin = (float)zm, za = (float)a->z, zf = (float)z;
    const float g1 = d1 * y2, g2 = d2 * y1, h1 = d2 * x1, h2 = d1 * x2;
    const float zx = (g1 - g2) / as, zy = (h1 - h2) / as;
    const float sx = (om__fabsf(g1) + om__fabsf(g2)) / area, sy = (om__fabsf(h1) + om__fabsf(h2)) / area;
    const float dx = (float)-ax, dy = (float)-ay;
    const float depth = za + zx * dx + zy * dy;
    float iw = ls->iw0f + ls->iw1f * zmin;
    if (!(iw > 0.0f)) iw = 0.0f;
    const float q = depth + 2.0f * ((om__fabsf(zx) + om__fabsf(zy)) * (1.5f + ls->latf * iw) + ls->depf * iw + 1.0f);
    const float iwm = ls->iw0a + ls->iw1a * zmin;
    const float m = za + sx * om__fabsf(dx) + sy * om__fabsf(dy) +
                    2.0f * ((sx + sy) * (1.5f + ls->latf * iwm) + ls->depf * iwm + 1.0f) + zf;
    const float e = m * 0x1p-19f;
    if (q + e < zf) return 1;
    if (q - e > zf) return 0;
    return -1;
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
