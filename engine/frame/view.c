/* view.c — camera and light matrices for one frame, relative to an origin that
 * follows the light (om_view's origin: ombra.h says why). A spot light projects through a square
 * perspective frustum; a directional light through an orthographic box whose depth
 * covers the whole scene (every caster) and whose x/y are fitted to the scene, or
 * narrowed by om_view_fit_light to what the camera sees. */
#include "frame.h"

static om_status check_vec(om_vec3 v, om_diag *d, const char *what)
{
    if (!om__finite3(v) || v.x > 1e7f || v.x < -1e7f || v.y > 1e7f || v.y < -1e7f ||
        v.z > 1e7f || v.z < -1e7f) {
        char tmp[8];
        om__str s = om__diag_begin(d, OM_E_RANGE, tmp, sizeof tmp);
        om__str_s(&s, what);
        om__str_s(&s, " must be finite and within 1e7");
        return OM_E_RANGE;
    }
    return OM_OK;
}

static om_status check_range(float v, float lo, float hi, om_diag *d, const char *what)
{
    if (!(v > lo && v < hi)) {
        char tmp[8];
        om__str s = om__diag_begin(d, OM_E_INVALID, tmp, sizeof tmp);
        om__str_s(&s, what);
        om__str_s(&s, " must be in (");
        om__str_f(&s, lo, 3);
        om__str_s(&s, ", ");
        om__str_f(&s, hi, 1);
        om__str_s(&s, ")");
        return OM_E_INVALID;
    }
    return OM_OK;
}

/* A world position relative to origin o: the difference in double, rounded once. */
static om_vec3 rel(om_vec3 p, om_vec3 o)
{
    return om__v3((float)((double)p.x - o.x), (float)((double)p.y - o.y), (float)((double)p.z - o.z));
}

/* Light-space bounds of the scene's box: x/y extent and depth range along the view.
 * The box's corners are made relative as vertices are (om__sub): rounding is monotonic,
 * so every relative vertex lies in the relative box. */
static void light_box(const om_view *v, const om_scene *s, om_vec3 *lo, om_vec3 *hi)
{
    const om_vec3 slo = om__sub(s->lo, v->origin), shi = om__sub(s->hi, v->origin);
    for (int i = 0; i < 8; i++) {
        om_vec3 c = om__v3(i & 1 ? shi.x : slo.x, i & 2 ? shi.y : slo.y, i & 4 ? shi.z : slo.z);
        om_vec4 q = om__mat_apply(&v->light_view, c);
        if (i == 0 || q.x < lo->x) lo->x = q.x;
        if (i == 0 || q.y < lo->y) lo->y = q.y;
        if (i == 0 || q.z < lo->z) lo->z = q.z;
        if (i == 0 || q.x > hi->x) hi->x = q.x;
        if (i == 0 || q.y > hi->y) hi->y = q.y;
        if (i == 0 || q.z > hi->z) hi->z = q.z;
    }
}

static void ortho_from(om_view *v, float x0, float x1, float y0, float y1, float zn, float zf)
{
    /* A little margin keeps samples on the box's faces strictly inside: a share of the
     * box and of its coordinates (their rounding), so the same at any scale; the last
     * term only keeps a box of no extent open. */
    float mx = (x1 - x0) * 1e-3f + (om__fabsf(x0) + om__fabsf(x1)) * 1e-6f + 1e-30f;
    float my = (y1 - y0) * 1e-3f + (om__fabsf(y0) + om__fabsf(y1)) * 1e-6f + 1e-30f;
    v->light_proj = om__mat_ortho(x0 - mx, x1 + mx, y0 - my, y1 + my, zn, zf);
    v->light_vp = om__mat_mul(&v->light_proj, &v->light_view);
}

om_status om_view_init(om_view *v, const om_camera *cam, const om_light *light,
                       const om_scene *s, om_diag *d)
{
    om_status st;
    if (!v || !cam || !light || !s) return om__fail(d, OM_E_INVALID, "om_view_init needs a view, a camera, a light and a scene");
    memset(v, 0, sizeof *v);
    if (!om__side_ok(cam->width, cam->height))
        return om__fail(d, OM_E_INVALID, "image size must be 1..8192 in each direction");
    if ((st = check_vec(cam->eye, d, "camera eye")) || (st = check_vec(cam->target, d, "camera target")) ||
        (st = check_vec(cam->up, d, "camera up")) ||
        (st = check_range(cam->fovy_deg, 0.0f, 180.0f, d, "camera fov")) ||
        (st = check_range(cam->znear, 0.0f, 1e7f, d, "camera near")) ||
        (st = check_range(cam->zfar, cam->znear, 1e8f, d, "camera far")))
        return st;
    const bool spot = light->kind == OM_LIGHT_SPOT;
    if (spot) {
        if ((st = check_vec(light->pos, d, "light pos")) ||
            (st = check_vec(light->target, d, "light target")) ||
            (st = check_range(light->fov_deg, 0.0f, 180.0f, d, "light fov")) ||
            (st = check_range(light->znear, 0.0f, 1e7f, d, "light near")) ||
            (st = check_range(light->zfar, light->znear, 1e8f, d, "light far")))
            return st;
    } else if (light->kind != OM_LIGHT_DIRECTIONAL) {
        return om__fail(d, OM_E_INVALID, "light kind must be spot or directional");
    } else if ((st = check_vec(light->dir, d, "light dir"))) {
        return st;
    }
    /* The origin follows the light: what a method builds in the light's space is then
     * the same bits while only the camera moves. */
    v->origin = spot ? light->pos : om__scale(om__add(s->lo, s->hi), 0.5f);
    v->cam = *cam;
    v->cam.eye = rel(cam->eye, v->origin);
    v->cam.target = rel(cam->target, v->origin);
    v->light = *light;
    if (!om__mat_look_at(&v->cam_view, v->cam.eye, v->cam.target, cam->up))
        return om__fail(d, OM_E_INVALID, "camera eye and target must differ");
    v->cam_proj = om__mat_perspective(cam->fovy_deg, (float)cam->width / (float)cam->height,
                                      cam->znear, cam->zfar);
    v->cam_vp = om__mat_mul(&v->cam_proj, &v->cam_view);

    if (spot) {
        v->light.pos = om__v3(0, 0, 0);
        v->light.target = rel(light->target, v->origin);
        if (!om__mat_look_at(&v->light_view, v->light.pos, v->light.target, om__v3(0, 1, 0)))
            return om__fail(d, OM_E_INVALID, "light pos and target must differ");
        v->light_axis = om__normalize(om__sub(v->light.target, v->light.pos));
        v->light_proj = om__mat_perspective(light->fov_deg, 1.0f, light->znear, light->zfar);
        v->light_vp = om__mat_mul(&v->light_proj, &v->light_view);
        return OM_OK;
    }
    om_vec3 dir = om__normalize(light->dir);
    if (om__dot(dir, dir) == 0.0f) return om__fail(d, OM_E_INVALID, "light dir must not be zero");
    v->light_axis = dir;
    /* Stand the light outside the scene's bounding sphere, looking along dir at its
     * centre (the origin). */
    const om_vec3 c = om__v3(0, 0, 0), h = om__sub(s->hi, v->origin);
    const float r = om__sqrtf(om__dot(h, h)) * 1.001f;   /* at any scale */
    /* a scene of no extent (or none at all) has its light a unit away */
    if (!(r > 1e-30f) || !om__mat_look_at(&v->light_view, om__sub(c, om__scale(dir, 2.0f * r)), c, om__v3(0, 1, 0)))
        om__mat_look_at(&v->light_view, om__sub(c, dir), c, om__v3(0, 1, 0));
    om_vec3 lo, hi;
    light_box(v, s, &lo, &hi);
    v->light.znear = -hi.z;
    v->light.zfar = -lo.z;
    ortho_from(v, lo.x, hi.x, lo.y, hi.y, -hi.z * 0.999f, -lo.z * 1.001f);
    return OM_OK;
}

void om_view_fit_light(om_view *v, const om_scene *s, om_vec3 lo, om_vec3 hi)
{
    if (!v || !s || v->light.kind != OM_LIGHT_DIRECTIONAL || !(lo.x <= hi.x && lo.y <= hi.y)) return;
    om_vec3 slo, shi;
    light_box(v, s, &slo, &shi);
    ortho_from(v, lo.x, hi.x, lo.y, hi.y, -shi.z * 0.999f, -slo.z * 1.001f);
}
