/* csm_split.c — where csm's cascades lie: the view depth the splits share out, the
 * practical split scheme (Zhang et al. 2006), the fitted mode's observation of the
 * visible samples (Lauritzen et al. 2011) and each cascade's window of the light's
 * image; csm.h's om__csm_pick says which cascade a sample reads.
 *
 * Every window is a box of the light's normalized device coordinates (its texels may
 * be longer on one axis; the bias takes the longer); its margin of texels keeps the
 * PCF taps and the normal offset of every sample it holds on the map. The practical
 * mode's window holds the projection of its slice of the view frustum (the slice's
 * eight corners: the projection is linear for a directional light, and a spot
 * light's window is the whole image where a corner lies behind the light); the
 * fitted mode's, the projections of the samples its bins of view depth hold, split
 * logarithmically. Both are clipped to the light's image: no exposed sample lies
 * outside it, and a directional light's image is fitted to the visible samples
 * already (frame.c). The fitted mode's splits fall on bin edges, so the box of a
 * cascade's bins holds every exposed sample whose depth falls in its slice, and the
 * pick (the same arithmetic) finds it in that window or an earlier one. */
#include "csm.h"

void om__csm_range(om__csm *m)
{
    const om_view *v = &m->view;
    const om_scene *s = m->scene;
    const float cn = v->cam.znear, cf = v->cam.zfar;
    float lo = cn, hi = cf;
    if (s->ntris) {   /* the scene's box: its corners' view depths bound every sample's */
        const om_vec3 slo = om__sub(s->lo, v->origin), shi = om__sub(s->hi, v->origin);
        float dmin = 0.0f, dmax = 0.0f;
        for (int i = 0; i < 8; i++) {
            const float d = om__csm_depth(v, om__v3(i & 1 ? shi.x : slo.x, i & 2 ? shi.y : slo.y,
                                                    i & 4 ? shi.z : slo.z));
            if (i == 0 || d < dmin) dmin = d;
            if (i == 0 || d > dmax) dmax = d;
        }
        /* a little beyond, as the light's box: the corners' depths are rounded */
        dmin -= (dmax - dmin) * 1e-3f;
        dmax += (dmax - dmin) * 1e-3f;
        if (dmin > lo) lo = dmin;
        if (dmax < hi) hi = dmax;
    }
    if (!(hi > lo && lo > 0.0f)) {   /* the scene not in front of the camera: its own range */
        lo = cn;
        hi = cf;
    }
    m->znear = lo;
    m->zfar = hi;
    const double l2 = om__log2((double)hi / (double)lo);
    m->edge[0] = lo;
    for (uint32_t k = 1; k < OM__CSM_BINS; k++) {
        float e = (float)((double)lo * om__exp2(l2 * (double)k / OM__CSM_BINS));
        m->edge[k] = e > m->edge[k - 1] ? e : m->edge[k - 1];
    }
    m->edge[OM__CSM_BINS] = hi;
    for (uint32_t k = 0; k < OM__CSM_BINS; k++) {
        m->bin[k].x0 = m->bin[k].y0 = FLT_MAX;
        m->bin[k].x1 = m->bin[k].y1 = -FLT_MAX;
        m->bin_n[k] = 0;
    }
    m->ready = false;
}

uint32_t om__csm_bin(const om__csm *m, float d)
{
    uint32_t lo = 0, hi = OM__CSM_BINS - 1;
    while (lo < hi) {
        const uint32_t mid = (lo + hi + 1) / 2;
        if (d >= m->edge[mid]) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

void om__csm_observe(om__csm *m, const om_strip *st)
{
    const size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        if (!(st->terms[i].flags & OM_TERM_EXPOSED)) continue;
        const om_sample *smp = &st->samples[i];
        const om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]);
        float x, y;
        if (!om__csm_project(&m->view.light_vp, p, &x, &y)) continue;
        const uint32_t k = om__csm_bin(m, om__csm_depth(&m->view, p));
        om__csm_box *b = &m->bin[k];
        if (x < b->x0) b->x0 = x;
        if (x > b->x1) b->x1 = x;
        if (y < b->y0) b->y0 = y;
        if (y > b->y1) b->y1 = y;
        m->bin_n[k]++;
    }
}

void om__csm_practical(float lo, float hi, float lambda, uint32_t n, float *out)
{
    const double l2 = om__log2((double)hi / (double)lo);
    out[0] = lo;
    for (uint32_t i = 1; i < n; i++) {
        const double t = (double)i / (double)n;
        const double lg = (double)lo * om__exp2(l2 * t), un = (double)lo + ((double)hi - (double)lo) * t;
        const float z = (float)((double)lambda * lg + (1.0 - (double)lambda) * un);
        out[i] = z > out[i - 1] ? (z < hi ? z : hi) : out[i - 1];
    }
    out[n] = hi;
}

static void grow(om__csm_box *b, float x, float y)
{
    if (x < b->x0) b->x0 = x;
    if (x > b->x1) b->x1 = x;
    if (y < b->y0) b->y0 = y;
    if (y > b->y1) b->y1 = y;
}

/* The box of the slice [d0, d1] of the view frustum on the light's image; the whole
 * image where a corner is behind the light. */
static om__csm_box slice_box(const om__csm *m, float d0, float d1)
{
    const om_view *v = &m->view;
    const float *r = v->cam_view.m;
    const om_vec3 right = om__v3(r[0], r[1], r[2]), up = om__v3(r[4], r[5], r[6]);
    const om_vec3 fwd = om__v3(-r[8], -r[9], -r[10]);
    const float tx = 1.0f / v->cam_proj.m[0], ty = 1.0f / v->cam_proj.m[5];
    om__csm_box b = {FLT_MAX, FLT_MAX, -FLT_MAX, -FLT_MAX};
    for (int i = 0; i < 8; i++) {
        const float d = i & 4 ? d1 : d0, sx = i & 1 ? d * tx : -d * tx, sy = i & 2 ? d * ty : -d * ty;
        const om_vec3 p = om__add(om__add(om__add(v->cam.eye, om__scale(fwd, d)), om__scale(right, sx)),
                                  om__scale(up, sy));
        float x, y;
        if (!om__csm_project(&v->light_vp, p, &x, &y)) {
            const om__csm_box all = {-1.0f, -1.0f, 1.0f, 1.0f};
            return all;
        }
        grow(&b, x, y);
    }
    return b;
}

/* The window of box b, with `frac` of its side a margin; dead where b is empty. */
static om__csm_win window_of(om__csm_box b, float frac)
{
    om__csm_win w = {0.0f, 0.0f, 1.0f, 1.0f, 0.0f, 0.0f, 1.0f, 1.0f, false};
    if (b.x0 < -1.0f) b.x0 = -1.0f;
    if (b.y0 < -1.0f) b.y0 = -1.0f;
    if (b.x1 > 1.0f) b.x1 = 1.0f;
    if (b.y1 > 1.0f) b.y1 = 1.0f;
    if (!(b.x0 <= b.x1 && b.y0 <= b.y1)) return w;
    w.cx = 0.5f * (b.x0 + b.x1);
    w.cy = 0.5f * (b.y0 + b.y1);
    /* The margin, and a little more for the roundings of the centre and the box
     * (coordinates within [-1, 1], whose spacing is 2^-23 at most). */
    w.hx = 0.5f * (b.x1 - b.x0) / (1.0f - frac) * (1.0f + 1e-5f) + 1e-6f;
    w.hy = 0.5f * (b.y1 - b.y0) / (1.0f - frac) * (1.0f + 1e-5f) + 1e-6f;
    w.limx = w.hx * (1.0f - frac);
    w.limy = w.hy * (1.0f - frac);
    w.ix = 1.0f / w.hx;
    w.iy = 1.0f / w.hy;
    w.live = true;
    return w;
}

void om__csm_windows(om__csm *m)
{
    const uint32_t n = m->n;
    const om__csm_cfg *c = &m->cfg;
    /* the margin: half the PCF kernel, the normal offset and a texel, in texels */
    float mt = (float)(c->pcf / 2) + c->normal_offset + 1.0f, frac = 2.0f * mt / (float)m->size;
    if (!(frac < 0.5f)) frac = 0.5f;   /* a large offset may leave its taps off the map, as sm's */
    om__csm_box box[OM__CSM_MAX];
    if (!c->fit) {
        om__csm_practical(m->znear, m->zfar, c->lambda, n, m->split);
        for (uint32_t k = 0; k < n; k++) box[k] = slice_box(m, m->split[k], m->split[k + 1]);
    } else {
        uint32_t a = OM__CSM_BINS, z = 0;
        for (uint32_t k = 0; k < OM__CSM_BINS; k++)
            if (m->bin_n[k]) {
                if (a == OM__CSM_BINS) a = k;
                z = k;
            }
        uint32_t at[OM__CSM_MAX + 1];
        if (a == OM__CSM_BINS) {   /* nothing exposed: nothing to hold */
            for (uint32_t k = 0; k <= n; k++) {
                at[k] = 0;
                m->split[k] = m->znear;
            }
        } else {
            /* logarithmic over the samples' range, as Lauritzen et al.: the blend with
             * the uniform split makes up for a near plane far in front of the
             * geometry, which the samples' range has not */
            float ideal[OM__CSM_MAX + 1];
            om__csm_practical(m->edge[a], m->edge[z + 1], 1.0f, n, ideal);
            at[0] = a;
            for (uint32_t k = 1; k < n; k++) {   /* the nearest edge at or above the ideal split */
                uint32_t e = at[k - 1];
                while (e < z + 1 && m->edge[e] < ideal[k]) e++;
                at[k] = e;
            }
            at[n] = z + 1;
            for (uint32_t k = 0; k <= n; k++) m->split[k] = m->edge[at[k]];
        }
        for (uint32_t k = 0; k < n; k++) {
            om__csm_box b = {FLT_MAX, FLT_MAX, -FLT_MAX, -FLT_MAX};
            for (uint32_t e = at[k]; e < at[k + 1]; e++)
                if (m->bin_n[e]) {
                    grow(&b, m->bin[e].x0, m->bin[e].y0);
                    grow(&b, m->bin[e].x1, m->bin[e].y1);
                }
            box[k] = b;
        }
    }
    for (uint32_t k = 0; k < n; k++) {
        m->win[k] = window_of(box[k], frac);
        /* the cascade's light_vp: the frame's, its x and y cropped to the window */
        const om__csm_win *w = &m->win[k];
        const float ix = w->ix, iy = w->iy;
        om_mat4 crop = om__mat_identity();
        crop.m[0] = ix;
        crop.m[3] = -w->cx * ix;
        crop.m[5] = iy;
        crop.m[7] = -w->cy * iy;
        m->cview[k] = m->view;
        m->cview[k].light_vp = om__mat_mul(&crop, &m->view.light_vp);
        om__smlook *L = &m->look[k];
        /* the bias rules take one texel size: the larger axis's */
        L->window = w->hx > w->hy ? w->hx : w->hy;
        L->view = &m->cview[k];
        om__smlook_begin(L, &m->cview[k]);
    }
    m->nlive = 0;
    for (uint32_t k = 0; k < n; k++)
        if (m->win[k].live) m->live[m->nlive++] = k;
    m->ready = true;
}

