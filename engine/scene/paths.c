/* paths.c — keyframed camera and light paths: om_scene_at interpolates linearly
 * between keys and clamps at the ends; the parser asks om__path_meets whether a
 * segment would leave a view without a direction at some time. */
#include "scene.h"

#include <math.h>

/* ================================================================ paths */

static om_vec3 lerp3(om_vec3 a, om_vec3 b, float u)
{
    /* (1-u) a + u b gives a exactly at u = 0 and b exactly at u = 1. */
    float w = 1.0f - u;
    return om__v3(w * a.x + u * b.x, w * a.y + u * b.y, w * a.z + u * b.z);
}

/* Keys are sorted by strictly increasing t. Returns the key at or before t (clamped to
 * the first and the last) and in *u the weight of the key after it. */
#define FIND_SEGMENT(keys, n, t, u, out)                                                 \
    do {                                                                                 \
        uint32_t lo_ = 0, hi_ = (n) - 1;                                                 \
        *(u) = 0.0f;                                                                     \
        if (!((t) > (keys)[0].t)) { (out) = 0; break; }      /* before, or NaN */        \
        if ((t) >= (keys)[hi_].t) { (out) = hi_; break; }                                \
        while (hi_ - lo_ > 1) {                              /* keys[lo].t < t < keys[hi].t */ \
            uint32_t mid_ = lo_ + (hi_ - lo_) / 2;                                       \
            if ((keys)[mid_].t <= (t)) lo_ = mid_; else hi_ = mid_;                      \
        }                                                                                \
        *(u) = ((t) - (keys)[lo_].t) / ((keys)[hi_].t - (keys)[lo_].t);                  \
        (out) = lo_;                                                                     \
    } while (0)

void om_scene_at(const om_scene *s, float t, om_camera *cam, om_light *light)
{
    if (cam) {
        *cam = s->camera;
        if (s->ncam_keys && s->cam_keys) {
            float u;
            uint32_t i;
            FIND_SEGMENT(s->cam_keys, s->ncam_keys, t, &u, i);
            const om_camera_key *a = &s->cam_keys[i];
            const om_camera_key *b = i + 1 < s->ncam_keys ? a + 1 : a;
            cam->eye = lerp3(a->eye, b->eye, u);
            cam->target = lerp3(a->target, b->target, u);
        }
    }
    if (light) {
        *light = s->light;
        if (s->nlight_keys && s->light_keys) {
            float u;
            uint32_t i;
            FIND_SEGMENT(s->light_keys, s->nlight_keys, t, &u, i);
            const om_light_key *a = &s->light_keys[i];
            const om_light_key *b = i + 1 < s->nlight_keys ? a + 1 : a;
            if (light->kind == OM_LIGHT_SPOT) {
                light->pos = lerp3(a->pos, b->pos, u);
                light->target = lerp3(a->target, b->target, u);
                light->dir = om__normalize(om__sub(light->target, light->pos));
            } else {
                light->dir = lerp3(a->dir, b->dir, u);
            }
        }
    }
}

/* Whether a - b, interpolated linearly from (a0, b0) to (a1, b1), comes to within a
 * millionth of the points' size of zero for some u in [0, 1] (in exact arithmetic the
 * difference of the two lerps is the lerp of the differences; the float lerps each
 * round by an ulp of their size, so nearer than that they may meet exactly). */
bool om__path_meets(om_vec3 a0, om_vec3 b0, om_vec3 a1, om_vec3 b1)
{
    double d0[3] = {(double)a0.x - b0.x, (double)a0.y - b0.y, (double)a0.z - b0.z};
    double d1[3] = {(double)a1.x - b1.x, (double)a1.y - b1.y, (double)a1.z - b1.z};
    double e[3], de = 0.0, ee = 0.0, size = 0.0;
    const float pts[12] = {a0.x, a0.y, a0.z, b0.x, b0.y, b0.z, a1.x, a1.y, a1.z, b1.x, b1.y, b1.z};
    for (int i = 0; i < 12; i++) size = fabs((double)pts[i]) > size ? fabs((double)pts[i]) : size;
    for (int i = 0; i < 3; i++) {
        e[i] = d1[i] - d0[i];
        de += d0[i] * e[i];
        ee += e[i] * e[i];
    }
    double u = ee > 0.0 ? -de / ee : 0.0, m = 0.0;
    u = u < 0.0 ? 0.0 : u > 1.0 ? 1.0 : u;
    for (int i = 0; i < 3; i++) m += (d0[i] + u * e[i]) * (d0[i] + u * e[i]);
    return sqrt(m) <= 1e-6 * size;
}
