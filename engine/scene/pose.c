/* pose.c — objects under transforms: the one function that writes an object's
 * vertices and triangles from its mesh (om__object_write: the parser bakes every object
 * through it and every later pose goes through it, so a posed scene is bit for bit the
 * scene parsed at that pose), the host's pose and look-up, poses along `key object`
 * paths, and the scene's bounds over its static part and its objects. Transforms are
 * 3x4 rows in double, as om__xform's: a pose happens once per object per frame, never
 * per pixel. */
#include "scene.h"

#include <math.h>
#include <string.h>

static bool finite_d(double x) { return x - x == 0.0; }   /* false for NaN and +-inf */

void om__xform_mul(const double a[12], const double b[12], double out[12])
{
    double r[12];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            r[4 * i + j] = a[4 * i] * b[j] + a[4 * i + 1] * b[4 + j] + a[4 * i + 2] * b[8 + j] +
                           (j == 3 ? a[4 * i + 3] : 0.0);
    memcpy(out, r, sizeof r);
}

static double det3(const double m[12])
{
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
           m[2] * (m[4] * m[9] - m[5] * m[8]);
}

static om_status pose_fail(om_diag *d, const om_object *o, const char *why)
{
    char tmp[8];
    om__str s = om__diag_begin(d, OM_E_RANGE, tmp, sizeof tmp);
    om__str_s(&s, "object '");
    om__str_s(&s, o->name && o->name[0] ? o->name : "(unnamed)");
    om__str_s(&s, "': ");
    om__str_s(&s, why);
    return OM_E_RANGE;
}

static inline void apply(const double m[12], om_vec3 v, double out[3])
{
    const double x = v.x, y = v.y, z = v.z;
    for (int r = 0; r < 3; r++) out[r] = m[4 * r] * x + m[4 * r + 1] * y + m[4 * r + 2] * z + m[4 * r + 3];
}

/* Whether object oi's mesh, ranges and keys lie inside the scene's arrays: a parsed
 * scene's always do; a scene built by hand is checked before anything is written. */
static bool object_fits(const om_scene *s, uint32_t oi)
{
    const om_object *o = &s->objects[oi];
    if (!s->meshes || !s->mesh_verts || !s->mesh_idx || !s->verts || !s->idx || o->mesh >= s->nmeshes)
        return false;
    const om_mesh *me = &s->meshes[o->mesh];
    if ((uint64_t)me->first_vert + me->nverts > s->nmesh_verts ||
        (uint64_t)me->first_idx + 3ull * me->ntris > 3ull * s->nmesh_tris ||
        (uint64_t)o->first_vert + me->nverts > s->nverts || (uint64_t)o->first_tri + me->ntris > s->ntris)
        return false;
    const uint32_t *li = s->mesh_idx + me->first_idx;
    for (uint64_t i = 0; i < 3ull * me->ntris; i++)
        if (li[i] >= me->nverts) return false;
    /* keys: in the array, each one's next later in it (so a walk ends) */
    if (o->nkeys) {
        if (!s->obj_keys || o->first_key >= s->nobj_keys) return false;
        uint32_t k = o->first_key, n = 1;
        while (s->obj_keys[k].next != OM_NO_TRI) {
            const uint32_t nx = s->obj_keys[k].next;
            if (nx <= k || nx >= s->nobj_keys) return false;
            k = nx;
            n++;
        }
        if (n != o->nkeys) return false;
    }
    return true;
}

om_status om__object_write(om_scene *s, uint32_t oi, const double m[12], om_diag *d)
{
    if (!object_fits(s, oi))
        return om__fail(d, OM_E_INVALID, "object: its mesh, ranges or keys do not fit the scene's arrays");
    om_object *o = &s->objects[oi];
    for (int i = 0; i < 12; i++)
        if (!finite_d(m[i])) return pose_fail(d, o, "its transform is not finite");
    const double det = det3(m);
    if (!(fabs(det) >= 1e-18) || !finite_d(det))
        return pose_fail(d, o, "its transform is singular (determinant below 1e-18)");
    const om_mesh *me = &s->meshes[o->mesh];
    const om_vec3 *lv = s->mesh_verts + me->first_vert;
    /* Every vertex is checked before any is written: a refused pose leaves the scene as
     * it was. */
    for (uint32_t i = 0; i < me->nverts; i++) {
        double w[3];
        apply(m, lv[i], w);
        if (!(fabs(w[0]) <= OM__COORD_MAX && fabs(w[1]) <= OM__COORD_MAX && fabs(w[2]) <= OM__COORD_MAX))
            return pose_fail(d, o, "a vertex reaches beyond 1e7 under its transform");
    }
    om_vec3 *out = s->verts + o->first_vert;
    for (uint32_t i = 0; i < me->nverts; i++) {
        double w[3];
        apply(m, lv[i], w);
        om_vec3 v = om__v3((float)w[0], (float)w[1], (float)w[2]);
        out[i] = v;
        if (i == 0) o->lo = o->hi = v;
        o->lo = om__v3(fminf(o->lo.x, v.x), fminf(o->lo.y, v.y), fminf(o->lo.z, v.z));
        o->hi = om__v3(fmaxf(o->hi.x, v.x), fmaxf(o->hi.y, v.y), fmaxf(o->hi.z, v.z));
    }
    /* A mirroring transform would turn the triangles inside out: swap two corners. */
    const bool flip = det < 0.0;
    const uint32_t *li = s->mesh_idx + me->first_idx;
    uint32_t *ti = s->idx + 3 * (size_t)o->first_tri;
    for (uint32_t t = 0; t < me->ntris; t++) {
        ti[3 * t] = o->first_vert + li[3 * t];
        ti[3 * t + 1] = o->first_vert + li[3 * t + (flip ? 2 : 1)];
        ti[3 * t + 2] = o->first_vert + li[3 * t + (flip ? 1 : 2)];
    }
    if (o->solid != OM_NO_TRI && o->solid < s->nsolids) {
        s->solids[o->solid].lo = o->lo;
        s->solids[o->solid].hi = o->hi;
    }
    memcpy(o->pose, m, sizeof o->pose);
    return OM_OK;
}

void om__scene_bounds(om_scene *s)
{
    bool any = s->has_static;
    if (any) {
        s->lo = s->static_lo;
        s->hi = s->static_hi;
    }
    for (uint32_t i = 0; i < s->nobjects; i++) {
        const om_object *o = &s->objects[i];
        if (o->mesh >= s->nmeshes || !s->meshes[o->mesh].nverts) continue;
        if (!any) {
            s->lo = o->lo;
            s->hi = o->hi;
            any = true;
        }
        s->lo = om__v3(fminf(s->lo.x, o->lo.x), fminf(s->lo.y, o->lo.y), fminf(s->lo.z, o->lo.z));
        s->hi = om__v3(fmaxf(s->hi.x, o->hi.x), fmaxf(s->hi.y, o->hi.y), fmaxf(s->hi.z, o->hi.z));
    }
}

/* m is the whole transform from the mesh's space (base included). */
static om_status pose_m(om_scene *s, uint32_t oi, const double m[12], om_diag *d)
{
    om_object *o = &s->objects[oi];
    bool same = true;   /* where it already is (a zero's sign aside) */
    for (int i = 0; i < 12; i++) same = same && o->pose[i] == m[i];
    if (same) return OM_OK;
    const om_vec3 lo = o->lo, hi = o->hi;
    om_status st = om__object_write(s, oi, m, d);
    if (st != OM_OK) return st;
    o->old_lo = lo;
    o->old_hi = hi;
    o->moved = ++s->change;
    om__scene_bounds(s);
    return OM_OK;
}

om_status om_object_pose(om_scene *s, uint32_t object, const om_mat4 *m, om_diag *d)
{
    if (!s || !m) return om__fail(d, OM_E_INVALID, "om_object_pose needs a scene and a matrix");
    if (object >= s->nobjects || !s->objects)
        return om__fail(d, OM_E_INVALID, "om_object_pose: no such object");
    const float *f = m->m;
    if (!(f[12] == 0.0f && f[13] == 0.0f && f[14] == 0.0f && f[15] == 1.0f))
        return om__fail(d, OM_E_INVALID, "om_object_pose: the matrix's bottom row must be 0 0 0 1");
    double h[12], t[12];
    for (int i = 0; i < 12; i++) h[i] = f[i];
    om__xform_mul(h, s->objects[object].base, t);
    return pose_m(s, object, t, d);
}

om_status om_object_find(const om_scene *s, const char *name, uint32_t *object)
{
    if (!s || !name || !object) return OM_E_INVALID;
    if (!s->objects) return OM_E_NOTFOUND;
    for (uint32_t i = 0; i < s->nobjects; i++) {
        const char *a = s->objects[i].name;
        size_t k = 0;   /* strcmp, which the engine may not call */
        while (a && a[k] && a[k] == name[k]) k++;
        if (a && a[0] && a[k] == '\0' && name[k] == '\0') {
            *object = i;
            return OM_OK;
        }
    }
    return OM_E_NOTFOUND;
}

static float lerp1(float a, float b, float u) { return (1.0f - u) * a + u * b; }

/* The transform of an object's key path at t (keys sorted by t, chained by `next`),
 * base included: linear between keys, clamped at the ends, as the camera's. */
void om__object_key_at(const om_scene *s, const om_object *o, float t, double out[12])
{
    const om_object_key *a = &s->obj_keys[o->first_key], *b = a;
    float u = 0.0f;
    if (t > a->t) {
        while (a->next != OM_NO_TRI && s->obj_keys[a->next].t <= t) a = &s->obj_keys[a->next];
        b = a->next != OM_NO_TRI ? &s->obj_keys[a->next] : a;
        if (b != a) u = (t - a->t) / (b->t - a->t);
    }
    double sc[3], rot[3], mv[3];
    for (int i = 0; i < 3; i++) {
        sc[i] = (double)lerp1(a->scale, b->scale, u);
        rot[i] = (double)lerp1(a->rot_deg[i], b->rot_deg[i], u);
        mv[i] = (double)lerp1(a->move[i], b->move[i], u);
    }
    om__xform k;
    om__xform_make(&k, sc, rot, mv);
    om__xform_mul(k.m, o->base, out);
}

om_status om_scene_pose_at(om_scene *s, float t, om_diag *d)
{
    if (!s) return om__fail(d, OM_E_INVALID, "om_scene_pose_at needs a scene");
    if (s->nobjects && !s->objects) return om__fail(d, OM_E_INVALID, "om_scene_pose_at: no objects array");
    for (uint32_t i = 0; i < s->nobjects; i++) {
        if (!s->objects[i].nkeys) continue;
        if (!object_fits(s, i))
            return om__fail(d, OM_E_INVALID, "object: its mesh, ranges or keys do not fit the scene's arrays");
        double m[12];
        om__object_key_at(s, &s->objects[i], t, m);
        om_status st = pose_m(s, i, m, d);
        if (st != OM_OK) return st;
    }
    return OM_OK;
}
