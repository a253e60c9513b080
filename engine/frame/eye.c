/* eye.c — the eye pass: rasterize the scene from the camera (depth + triangle id),
 * then give every covered pixel its visible point. The point comes from the
 * perspective-correct weights of the pixel centre's ray on its triangle (eye_finish:
 * from the camera's ray and the triangle's edges, no division by w, so triangles
 * crossing the camera plane are handled), applied as v0 + w1 (v1 - v0) + w2 (v2 - v0):
 * an error in the weights moves the point within the triangle's plane, not off it,
 * whatever the depth buffer's precision. A centre that the rasterizer's snapped edges
 * gave a triangle though it lies just outside it gets the triangle's point nearest it
 * on the image (eye_clamp): every point is on its triangle and within 1/256 px of its
 * centre's ray. All in float: per pixel it is a handful of single-precision
 * operations, which a Cortex-M4F does in hardware (double there is a software routine
 * per operation); off the plane the point is within a few float roundings of its
 * coordinates (occlude.h counts them).
 * The pixels are taken a run of one triangle at a time, and where the frame asks for
 * it (om__eye_pass_mark) each pixel's exposure marks are made in the same loop; where
 * a triangle is, with room to spare, wholly inside the light's frustum and seen from
 * one side, its pixels skip those two tests (expo_setup says why the answers are the
 * same). */
#include "frame.h"

/* Every pixel's point lies on its triangle (eye_clamp), so in the triangle grown by
 * EYE_GROW (below) with room for its rounding; EYE_MARGIN is the room, relative to the
 * size of the values, that expo_setup asks of that grown triangle: 256 float
 * roundings. */
#define EYE_WAYS 16
#define EYE_RUNS 32
#define EYE_LAZY 8
#define EYE_GROW (1.0f / 512.0f)
#define EYE_MARGIN (1.0f / 65536.0f)

/* A triangle of the eye pass: its perspective setup and, with the exposure marks,
 * whether its pixels' marks need only the light-facing test (`sure`), and the normal
 * turned to the camera they then use. */
typedef struct eye_tri {
    om__persp_tri t;
    om_vec3 nf, anchor;   /* anchor: the first vertex as the scene lists it */
    float h;              /* with `sure`: the light's height, om__light_height(nf, anchor) */
    bool sure, tried;
    uint32_t seen;   /* pixels resolved since the setup, until expo_setup is tried */
} eye_tri;

/* What expo_setup's bounds take from the frame: per row r of light_vp, the sum of
 * |m[r][0..2]| and |m[r][3]|; the largest |coordinate| of the camera's eye. */
typedef struct eye_frame {
    float rows[4], cols3[4], eye;
} eye_frame;

static float maxabs3(om_vec3 a)
{
    const float x = om__fabsf(a.x), y = om__fabsf(a.y), z = om__fabsf(a.z);
    const float m = x > y ? x : y;
    return m > z ? m : z;
}

static void eye_frame_of(const om_view *v, eye_frame *f)
{
    const float *m = v->light_vp.m;
    for (int r = 0; r < 4; r++) {
        f->rows[r] = om__fabsf(m[4 * r]) + om__fabsf(m[4 * r + 1]) + om__fabsf(m[4 * r + 2]);
        f->cols3[r] = om__fabsf(m[4 * r + 3]);
    }
    f->eye = maxabs3(v->cam.eye);
}

/* Whether the exposure tests of om__exposed_at, but for the light-facing one, give
 * every pixel of triangle c the same answers: the normal turned the same way, inside
 * the frustum. The pixel's point is p = o + w1 d1 + w2 d2 rounded (o = v0, d1, d2 as
 * the setup has them) with weights in [0, 1], or a point of an edge v_i + t (v_j - v_i)
 * rounded (eye_clamp, clamp_weights), so it lies within 4u R (u = 2^-24, per
 * coordinate) of the triangle grown by EYE_GROW, whose corners e_j are worked out here, R = max|o| + 2 (max|d1| +
 * max|d2|) bounding every coordinate. Each test is of the sign of an affine function of
 * the point (q.w - |q.x| is the lesser of two), so it holds over the grown triangle
 * when it holds at its corners; computed at a pixel, such a function's value is within
 * 8.1u S of the exact one at the grown triangle's point (S: the sum of the magnitudes
 * of its terms, A_r R + |m[r][3]| for the light's row r, 2 (|eye| + R) for the normal's
 * side), and computed here at a corner within 9.1u S likewise. A margin of 256u S
 * (EYE_MARGIN) is then far more than both together: where every corner clears it, every
 * such pixel's tests come out as they do here. A NaN or an infinity anywhere fails a
 * comparison and leaves the triangle to the per-pixel tests. */
static void expo_setup(const om_view *v, const eye_frame *f, eye_tri *et)
{
    const om__persp_tri *c = &et->t;
    et->sure = false;
    const om_vec3 o = c->v[0], d1 = c->d1, d2 = c->d2;
    const float R = maxabs3(o) + 2.0f * (maxabs3(d1) + maxabs3(d2));
    if (!(R < 1e30f)) return;
    const float g = -EYE_GROW, g1 = 1.0f + 2.0f * EYE_GROW;
    const om_vec3 e[3] = {om__add(om__add(o, om__scale(d1, g)), om__scale(d2, g)),
                          om__add(om__add(o, om__scale(d1, g1)), om__scale(d2, g)),
                          om__add(om__add(o, om__scale(d1, g)), om__scale(d2, g1))};
    float mg[4];
    for (int r = 0; r < 4; r++) mg[r] = EYE_MARGIN * (f->rows[r] * R + f->cols3[r]);
    const float mf = EYE_MARGIN * 2.0f * (f->eye + R);
    int front = 0, back = 0;
    for (int j = 0; j < 3; j++) {
        const om_vec4 q = om__mat_apply(&v->light_vp, e[j]);
        if (!(q.w - om__fabsf(q.x) > mg[3] + mg[0] && q.w - om__fabsf(q.y) > mg[3] + mg[1] &&
              q.z > mg[2] && q.w - q.z > mg[3] + mg[2]))
            return;
        const float side = om__dot(c->n, om__sub(v->cam.eye, e[j]));
        front += side > mf;
        back += side < -mf;
    }
    if (front == 3) et->nf = c->n;
    else if (back == 3) et->nf = om__scale(c->n, -1.0f);   /* as om__exposed_at turns it */
    else return;
    et->h = om__light_height(v, et->nf, et->anchor);
    et->sure = true;
}

/* Triangle t's vertices relative to o. */
static void tri_verts(const om_scene *s, om_vec3 o, uint32_t t, om_vec3 v[3])
{
    const uint32_t *ix = s->idx + (size_t)t * 3;
    for (int k = 0; k < 3; k++) v[k] = om__sub(s->verts[ix[k]], o);
}

/* The eye pass's setup of the triangle whose vertices (relative to the view's
 * origin) are in c->v: the same weights as persp_finish's, from the camera's ray
 * instead of clip space. The ray through NDC (sx, sy) runs from the eye e along
 * d = F + sx/p0 R + sy/p5 U (R, U, F: the camera's right, up and forward, p0, p5 its
 * projection's scales, the inverse of cam_vp); it meets the triangle's plane where
 * (Moller-Trumbore, with e1, e2 its edges from v0 and s = e - v0)
 *   det = d . (e2 x e1),  w1 det = d . (e2 x s),  w2 det = d . (s x e1),
 * three linear functions of (sx, sy) whose coefficients are set up here (om__persp_tri's
 * rows: the denominator's first, made whole rather than summed per pixel, which cancels
 * where a pixel lies beyond a sliver's edge). Clip space would take them as 2x2 minors of the vertices'
 * projected coordinates, which cancel for a small triangle far away (the minors'
 * terms grow with the square of the distance, their value with the square of the
 * size); here every product is of the edges, exact differences of nearby floats, and
 * the eye's offset, so the weights keep their precision at any size and distance. */
static void eye_finish(const om_view *v, om__persp_tri *c)
{
    /* The vertices turned (winding kept) so that v0 faces the longest edge: its edges
     * then meet at the triangle's largest angle, 60 degrees or more, and their cross
     * product keeps its precision for a needle of a triangle, whose two long edges are
     * almost parallel (the weights' common denominator would carry their cancellation
     * along the needle's length). */
    const float l0 = om__dot(om__sub(c->v[2], c->v[1]), om__sub(c->v[2], c->v[1]));
    const float l1 = om__dot(om__sub(c->v[0], c->v[2]), om__sub(c->v[0], c->v[2]));
    const float l2 = om__dot(om__sub(c->v[1], c->v[0]), om__sub(c->v[1], c->v[0]));
    if (l1 > l0 && l1 >= l2) {
        const om_vec3 t = c->v[0];
        c->v[0] = c->v[1];
        c->v[1] = c->v[2];
        c->v[2] = t;
    } else if (l2 > l0 && l2 > l1) {
        const om_vec3 t = c->v[2];
        c->v[2] = c->v[1];
        c->v[1] = c->v[0];
        c->v[0] = t;
    }
    const float *m = v->cam_view.m;
    const om_vec3 R = om__v3(m[0], m[1], m[2]), U = om__v3(m[4], m[5], m[6]), F = om__v3(-m[8], -m[9], -m[10]);
    const float kx = 1.0f / v->cam_proj.m[0], ky = 1.0f / v->cam_proj.m[5];
    c->d1 = om__sub(c->v[1], c->v[0]);
    c->d2 = om__sub(c->v[2], c->v[0]);
    const om_vec3 s = om__sub(v->cam.eye, c->v[0]);
    const om_vec3 g = om__cross(c->d2, c->d1), h = om__cross(c->d2, s), q = om__cross(s, c->d1);
    const float det[3] = {kx * om__dot(g, R), ky * om__dot(g, U), om__dot(g, F)};
    const float b1[3] = {kx * om__dot(h, R), ky * om__dot(h, U), om__dot(h, F)};
    const float b2[3] = {kx * om__dot(q, R), ky * om__dot(q, U), om__dot(q, F)};
    for (int k = 0; k < 3; k++) {
        c->adj[k] = det[k];
        c->adj[3 + k] = b1[k];
        c->adj[6 + k] = b2[k];
    }
    c->n = om__normalize(om__cross(c->d1, c->d2));
}

void om__eye_setup(const om_scene *s, const om_view *v, uint32_t t, om__persp_tri *c)
{
    c->tri = t;
    tri_verts(s, v->origin, t, c->v);
    eye_finish(v, c);
}

/* The setup of the triangle whose vertices are in c->v (the clip-space vertices are
 * om__clip_tri's, made from those copies). */
static void persp_finish(const om_mat4 *vp, om__persp_tri *c)
{
    om_vec4 q[3];
    for (int k = 0; k < 3; k++) q[k] = om__mat_apply(vp, c->v[k]);
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
    for (int k = 0; k < 3; k++) c->adj[k] += c->adj[3 + k] + c->adj[6 + k];   /* the weights' sum */
    c->d1 = om__sub(c->v[1], c->v[0]);
    c->d2 = om__sub(c->v[2], c->v[0]);
    c->n = om__normalize(om__cross(c->d1, c->d2));
}

void om__persp_setup(const om_scene *s, const om_mat4 *vp, om_vec3 o, uint32_t t, om__persp_tri *c)
{
    c->tri = t;
    tri_verts(s, o, t, c->v);
    persp_finish(vp, c);
}

om_vec3 om__persp_point(const om__persp_tri *c, float sx, float sy)
{
    float sum = c->adj[0] * sx + c->adj[1] * sy + c->adj[2];
    float b1 = c->adj[3] * sx + c->adj[4] * sy + c->adj[5];
    float b2 = c->adj[6] * sx + c->adj[7] * sy + c->adj[8];
    float inv = sum != 0.0f ? 1.0f / sum : 0.0f;
    float w1 = b1 * inv, w2 = b2 * inv;
    return om__v3(c->v[0].x + w1 * c->d1.x + w2 * c->d2.x, c->v[0].y + w1 * c->d1.y + w2 * c->d2.y,
                  c->v[0].z + w1 * c->d1.z + w2 * c->d2.z);
}

/* A point of triangle c from p's weights made to lie on it (NaN ones as 0): for a
 * triangle with a vertex not in front of the camera, which has no nearest point on
 * the image. */
static om_vec3 clamp_weights(const om__persp_tri *c, om_vec3 p)
{
    const om_vec3 r = om__sub(p, c->v[0]);
    /* the weights again, from p: the least-squares solution on the edges' plane */
    const float a = om__dot(c->d1, c->d1), b = om__dot(c->d1, c->d2), d = om__dot(c->d2, c->d2);
    const float e = om__dot(c->d1, r), f = om__dot(c->d2, r), det = a * d - b * b;
    float w1 = det != 0.0f ? (d * e - b * f) / det : 0.0f, w2 = det != 0.0f ? (a * f - b * e) / det : 0.0f;
    w1 = w1 > 0.0f ? w1 : 0.0f;   /* NaN too */
    w2 = w2 > 0.0f ? w2 : 0.0f;
    const float s = w1 + w2;
    if (s > 1.0f) {
        w1 /= s;
        w2 /= s;
    }
    return om__add(c->v[0], om__add(om__scale(c->d1, w1), om__scale(c->d2, w2)));
}

/* The point of triangle c nearest, on the image, to NDC (sx, sy), for a pixel whose
 * centre the rasterizer's snapped edges gave to c though it lies just outside it (p
 * then on c's plane beyond an edge, where a triangle seen at a grazing angle takes a
 * point far along its plane for a fraction of a pixel): on the edge nearest the centre
 * on the image, at the point of it nearest the centre there, carried back to the
 * edge in 3-D with 1/w, which the projection keeps linear along it. Within the
 * snapping of the centre's ray, on the triangle (clamp_weights where a vertex is not
 * in front of the camera). Out of line: few pixels take it. */
static om_vec3 eye_clamp(const om_view *v, const om__persp_tri *c, float sx, float sy, om_vec3 p)
{
    const float *m = v->cam_view.m;
    const om_vec3 R = om__v3(m[0], m[1], m[2]), U = om__v3(m[4], m[5], m[6]), F = om__v3(-m[8], -m[9], -m[10]);
    float ax[3], ay[3], w[3];
    for (int k = 0; k < 3; k++) {
        const om_vec3 r = om__sub(c->v[k], v->cam.eye);
        w[k] = om__dot(F, r);
        if (!(w[k] > 0.0f)) return clamp_weights(c, p);
        ax[k] = v->cam_proj.m[0] * om__dot(R, r) / w[k];
        ay[k] = v->cam_proj.m[5] * om__dot(U, r) / w[k];
    }
    float best = -1.0f, bt = 0.0f;
    int bi = 0;
    for (int i = 0; i < 3; i++) {
        const int j = i == 2 ? 0 : i + 1;
        const float ex = ax[j] - ax[i], ey = ay[j] - ay[i], e2 = ex * ex + ey * ey;
        float t = e2 > 0.0f ? ((sx - ax[i]) * ex + (sy - ay[i]) * ey) / e2 : 0.0f;
        t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
        const float qx = ax[i] + t * ex - sx, qy = ay[i] + t * ey - sy, d2 = qx * qx + qy * qy;
        if (best < 0.0f || d2 < best) {
            best = d2;
            bt = t;
            bi = i;
        }
    }
    const int bj = bi == 2 ? 0 : bi + 1;
    const float den = (1.0f - bt) * w[bj] + bt * w[bi];
    const float tau = den > 0.0f ? bt * w[bi] / den : bt;
    return om__add(c->v[bi], om__scale(om__sub(c->v[bj], c->v[bi]), tau));
}

om_vec3 om__eye_point(const om_view *v, const om__persp_tri *c, float sx, float sy)
{
    const float sum = c->adj[0] * sx + c->adj[1] * sy + c->adj[2];
    const float b1 = c->adj[3] * sx + c->adj[4] * sy + c->adj[5];
    const float b2 = c->adj[6] * sx + c->adj[7] * sy + c->adj[8];
    const float inv = sum != 0.0f ? 1.0f / sum : 0.0f;
    const float w1 = b1 * inv, w2 = b2 * inv;
    const om_vec3 p = om__v3(c->v[0].x + w1 * c->d1.x + w2 * c->d2.x, c->v[0].y + w1 * c->d1.y + w2 * c->d2.y,
                             c->v[0].z + w1 * c->d1.z + w2 * c->d2.z);
    return w1 >= 0.0f && w2 >= 0.0f && w1 + w2 <= 1.0f ? p : eye_clamp(v, c, sx, sy, p);
}

/* The pixels [x0, x1) of one row that triangle c covers (mark: with terms; sure:
 * et->sure; dir: a directional light; dark: sure and the light not above its plane;
 * constants where resolve_one calls it, so that each of its loops is without their
 * tests): the run's constants sit in locals (registers) rather than being loaded
 * again per pixel, and the products with the row's sy are made once; each is the very
 * product om__eye_point makes, so the points are the same bits. With `terms`, each
 * pixel's exposure marks too: where the triangle is `sure`, only the light-facing
 * test, with the operations om__exposed_at makes for it and the light's height over
 * the plane made once (expo_setup): the cosine is that height (directional) or it over
 * the point's distance to the light, never above 0 where the height is not (dark). */
OM_INLINE void resolve_run(const om_view *v, const eye_tri *et, uint32_t x0, uint32_t x1,
                          float sy, float sxk, om_sample *smp, om_term *terms, const bool mark,
                          const bool sure, const bool dir, const bool dark)
{
    const om__persp_tri *c = &et->t;
    const float a0 = c->adj[0], a3 = c->adj[3], a6 = c->adj[6];
    const float r0 = c->adj[1] * sy, r1 = c->adj[4] * sy, r2 = c->adj[7] * sy;
    const float a2 = c->adj[2], a5 = c->adj[5], a8 = c->adj[8];
    const om_vec3 o = c->v[0], d1 = c->d1, d2 = c->d2, n = c->n;
    const uint32_t tri = c->tri;
    /* the light's and the turned normal's values in locals too: the samples' stores
     * may alias them, and the compiler would load them again per pixel */
    const om_vec3 lpos = v->light.pos, anchor = et->anchor;
    const float h = et->h;
    /* (float)x + 0.5f, stepped by one: exact below 2^22, and images are narrower */
    float xc = (float)x0 + 0.5f;
    for (uint32_t x = x0; x < x1; x++, xc += 1.0f) {
        const float sx = xc * sxk - 1.0f;
        const float sum = a0 * sx + r0 + a2;
        const float b1 = a3 * sx + r1 + a5;
        const float b2 = a6 * sx + r2 + a8;
        const float inv = sum != 0.0f ? 1.0f / sum : 0.0f;
        const float w1 = b1 * inv, w2 = b2 * inv;
        om_vec3 p = om__v3(o.x + w1 * d1.x + w2 * d2.x, o.y + w1 * d1.y + w2 * d2.y,
                           o.z + w1 * d1.z + w2 * d2.z);
        if (!(w1 >= 0.0f && w2 >= 0.0f && w1 + w2 <= 1.0f)) p = eye_clamp(v, c, sx, sy, p);
        om_sample *out = &smp[x];
        out->p[0] = p.x;
        out->p[1] = p.y;
        out->p[2] = p.z;
        out->n[0] = n.x;
        out->n[1] = n.y;
        out->n[2] = n.z;
        out->tri = tri;
        if (mark) {
            bool exposed;
            if (sure) {   /* every point is on its triangle (eye_clamp) */
                const float cs = dark ? 0.0f : dir ? h : om__spot_cos(lpos, p, h);
                exposed = cs > 0.0f;
                out->nl = exposed ? cs : 0.0f;
            } else {
                exposed = om__exposed_at(v, p, n, anchor, &out->nl);
            }
            const om_term t = {255, 255, 255, exposed ? OM_TERM_EXPOSED : 0};
            terms[x] = t;   /* whole: one store where the compiler can */
        } else {
            out->nl = 0.0f;   /* set with the exposure marks */
        }
    }
}

/* resolve_run with its flags made constants. */
static void resolve_one(const om_view *v, const eye_tri *et, uint32_t x0, uint32_t x1,
                        float sy, float sxk, om_sample *smp, om_term *terms)
{
    if (!terms) resolve_run(v, et, x0, x1, sy, sxk, smp, terms, false, false, false, false);
    else if (!et->sure) resolve_run(v, et, x0, x1, sy, sxk, smp, terms, true, false, false, false);
    else if (!(et->h > 0.0f)) resolve_run(v, et, x0, x1, sy, sxk, smp, terms, true, true, false, true);
    else if (v->light.kind == OM_LIGHT_DIRECTIONAL) resolve_run(v, et, x0, x1, sy, sxk, smp, terms, true, true, true, false);
    else resolve_run(v, et, x0, x1, sy, sxk, smp, terms, true, true, false, false);
}

/* The next batch of a row's runs, from *xe on: at most EYE_RUNS runs, their ends in
 * run_end, and the vertices of the triangles that the cache will lack when the runs
 * come (tag: the cache's triangle per way, kept a batch ahead) in `fetched`, in the
 * order they will be set up. Their loads are made together, so that they overlap: on
 * a scene of many small triangles (a dense random cloud) nearly every run is a
 * triangle not yet set up, whose indices and vertices lie anywhere in the scene, and a
 * setup that waited on its own loads spent most of its time there. Returns the number
 * of runs; *xe moves past them. */
static uint32_t fetch_batch(const om_scene *s, om_vec3 o, const uint32_t *id, uint32_t w, uint32_t *xe,
                            uint32_t *tag, uint32_t *run_end, om_vec3 (*fetched)[3])
{
    uint32_t miss[EYE_RUNS], nr = 0, nm = 0, x = *xe;
    while (x < w && nr < EYE_RUNS) {
        const uint32_t t = id[x];
        uint32_t x1 = x + 1;
        while (x1 < w && id[x1] == t) x1++;   /* the run of pixels t covers */
        if (t != OM_NO_TRI && tag[t % EYE_WAYS] != t) {
            tag[t % EYE_WAYS] = t;
            miss[nm++] = t;
        }
        run_end[nr++] = x1;
        x = x1;
    }
    for (uint32_t k = 0; k < nm; k++) tri_verts(s, o, miss[k], fetched[k]);
    *xe = x;
    return nr;
}

/* The samples (and with `mark` the terms) of st's rows from the triangle ids in tg. */
static void resolve_ids(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st, bool mark)
{
    /* The triangles set up, by their number modulo EYE_WAYS: the rows of a strip
     * cross the same few triangles in turn, and each setup costs about as much as
     * thirty pixels. */
    eye_tri cache[EYE_WAYS];
    uint32_t tag[EYE_WAYS];
    for (int k = 0; k < EYE_WAYS; k++) {
        tag[k] = OM_NO_TRI;
        cache[k].t.tri = OM_NO_TRI;
        cache[k].sure = cache[k].tried = false;
        cache[k].seen = 0;
    }
    eye_frame fr;
    eye_frame_of(v, &fr);
    const uint32_t w = st->width;
    const float sxk = 2.0f / (float)w;
    for (uint32_t y = 0; y < st->rows; y++) {
        float sy = 1.0f - ((float)(st->y0 + y) + 0.5f) * (2.0f / (float)st->height);
        const uint32_t *id = tg->id + (size_t)y * w;
        om_sample *smp = st->samples + (size_t)y * w;
        om_term *terms = mark ? st->terms + (size_t)y * w : NULL;
        for (uint32_t x = 0, xe = 0; x < w;) {
            uint32_t run_end[EYE_RUNS];
            om_vec3 fetched[EYE_RUNS][3];
            const uint32_t nr = fetch_batch(s, v->origin, id, w, &xe, tag, run_end, fetched);
            for (uint32_t r = 0, k = 0; r < nr; r++) {
                const uint32_t t = id[x], x1 = run_end[r];
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
                eye_tri *et = &cache[t % EYE_WAYS];
                if (et->t.tri != t) {   /* fetch_batch's next triangle */
                    et->t.tri = t;
                    for (int j = 0; j < 3; j++) et->t.v[j] = fetched[k][j];
                    et->anchor = fetched[k][0];   /* before eye_finish turns the vertices */
                    k++;
                    eye_finish(v, &et->t);
                    et->sure = et->tried = false;
                    et->seen = 0;
                }
                /* expo_setup costs about what it saves on a few pixels: tried once the
                 * triangle has EYE_LAZY pixels in the strip (its answer changes no bit,
                 * only the work; EYE_LAZY is where the M4's count is least) */
                if (mark && !et->tried && (et->seen += x1 - x) >= EYE_LAZY) {
                    expo_setup(v, &fr, et);
                    et->tried = true;
                }
                resolve_one(v, et, x, x1, sy, sxk, smp, terms);
                x = x1;
            }
        }
    }
}

/* Culling is exact in the eye pass: the visible point of a pixel is the nearest, and
 * the nearest surface of a closed shape the camera is outside of faces the camera. */
static void eye_pass(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st,
                     const om__bins *bins, bool mark)
{
    om__scene_raster(s, &v->cam_vp, v->origin, tg, OM_RASTER_DEPTH_ID, true, bins);
    resolve_ids(s, v, tg, st, mark);
}

void om__eye_raster_part(const om_scene *s, const om_view *v, const om_target *tg, uint32_t t0, uint32_t t1)
{
    om__scene_raster_part(s, &v->cam_vp, v->origin, tg, OM_RASTER_DEPTH_ID, true, t0, t1);
}

void om__eye_resolve(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st, bool mark)
{
    resolve_ids(s, v, tg, st, mark);
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
