/* rtw_warp.c — the analysis half of Rectilinear Texture Warping (paper 003): the 2-D
 * importance map on the light's image plane (section 4.1, importance functions of
 * section 5) and its reduction to two 1-D warp tables (section 4.2: collapse by
 * maximum, Gaussian blur, warp). The rendering and lookup half is rtw.c.
 *
 * Everything here is plain IEEE arithmetic in a fixed order (sums in double, maxima in
 * float) plus the engine's deterministic exp2, so the tables are the same bits on every
 * compiler and CPU; the tables themselves are integers (OM_RTW_ONE fixed point). */
#include "rtw.h"

/* ---------------------------------------------------------------- 1-D tables */

void om__rtw_collapse(const float *imp, uint32_t n, double *cols, double *rows)
{
    for (uint32_t i = 0; i < n; i++) cols[i] = rows[i] = 0.0;
    for (uint32_t j = 0; j < n; j++) {
        const float *row = imp + (size_t)j * n;
        float rmax = 0.0f;
        for (uint32_t i = 0; i < n; i++) {
            float v = row[i];
            if (v > rmax) rmax = v;
            if ((double)v > cols[i]) cols[i] = v;
        }
        rows[j] = rmax;
    }
}

void om__rtw_blur(double *I, uint32_t n, float sigma, double *scratch, double *kernel)
{
    if (!(sigma > 0.0f) || n < 2) return;
    int r = (int)ceil(3.0 * (double)sigma);
    if (r > OM_RTW_MAX_RADIUS) r = OM_RTW_MAX_RADIUS;
    if (r > (int)n - 1) r = (int)n - 1;
    /* exp(-k^2 / (2 sigma^2)) through the engine's exp2: libm's exp may differ in the
     * last bit between C libraries, and these weights reach the pixels. */
    const double log2e = 1.4426950408889634;
    for (int k = 0; k <= r; k++)
        kernel[k] = om__exp2(-(double)k * (double)k / (2.0 * (double)sigma * (double)sigma) * log2e);
    for (int i = 0; i < (int)n; i++) {
        int lo = i - r < 0 ? -i : -r, hi = i + r > (int)n - 1 ? (int)n - 1 - i : r;
        double sum = 0.0, wsum = 0.0;
        for (int k = lo; k <= hi; k++) {
            double w = kernel[k < 0 ? -k : k];
            sum += w * I[i + k];
            wsum += w;
        }
        scratch[i] = sum / wsum;   /* renormalized at the ends: uniform stays uniform */
    }
    for (uint32_t i = 0; i < n; i++) I[i] = scratch[i];
}

static int32_t identity_at(uint32_t n, uint32_t k)
{
    return (int32_t)(((int64_t)k * OM_RTW_ONE + n / 2) / n);
}

bool om__rtw_table(const double *I, uint32_t n, int32_t *P)
{
    /* DESIGN.md's form of the paper's lost Equation 1: with S(k) = I_0 + ... + I_{k-1},
     * super-cell edge k moves to S(k) / S(n), i.e. warp(k) = S(k)/S(n) - k/n. Each
     * super-cell's warped width is its share of the total importance, so a cell of zero
     * importance collapses to zero width (section 4.2: "implicitly culled"). */
    double total = 0.0;
    for (uint32_t k = 0; k < n; k++) {
        double v = I[k];
        if (v > 0.0 && v < 1e300) total += v;   /* negative, NaN and inf count as 0 */
    }
    if (!(total > 0.0) || !(total < 1e300)) {   /* all zero: nothing to adapt to */
        for (uint32_t k = 0; k <= n; k++) P[k] = identity_at(n, k);
        return false;
    }
    double s = 0.0;
    P[0] = 0;
    for (uint32_t k = 1; k < n; k++) {
        double v = I[k - 1];
        if (v > 0.0 && v < 1e300) s += v;
        double p = floor(s / total * (double)OM_RTW_ONE + 0.5);
        P[k] = p > (double)OM_RTW_ONE ? OM_RTW_ONE : (int32_t)p;
    }
    P[n] = OM_RTW_ONE;
    return true;
}

void om__rtw_unwarp_grid(const int32_t *P, uint32_t n, uint32_t size, double steps, int64_t *g)
{
    uint32_t k = 0;
    for (uint32_t x = 0; x < size; x++) {
        /* the texel centre in OM_RTW_ONE units, and the super-cell it lands in: the
         * last k with P[k] <= c (centres rise, so k only moves on) */
        const double c = ((double)x + 0.5) / (double)size * (double)OM_RTW_ONE;
        while (k + 1 < n && (double)P[k + 1] <= c) k++;
        const double a = (double)P[k], b = (double)P[k + 1];
        double f = b > a ? (c - a) / (b - a) : 0.0;
        f = f < 0.0 ? 0.0 : f > 1.0 ? 1.0 : f;
        g[x] = (int64_t)floor(((double)k + f) / (double)n * steps + 0.5);
    }
}

int32_t om__rtw_warp_at(const int32_t *P, uint32_t n, uint32_t k)
{
    return P[k] - identity_at(n, k);
}

double om__rtw_max_density(const int32_t *P, uint32_t n)
{
    int32_t best = 0;
    for (uint32_t k = 0; k < n; k++)
        if (P[k + 1] - P[k] > best) best = P[k + 1] - P[k];
    return (double)best * (double)n / (double)OM_RTW_ONE;
}

/* ---------------------------------------------------------------- importance */

/* What the importance functions need of the view, taken once per frame: the view
 * matrix's depth row, the camera's near and far planes and the eye. */
typedef struct imp_ctx {
    unsigned funcs;
    float row[4];
    double nn, ff, span;   /* span = ff - nn */
    float nnf, fff, spanf; /* the same in float (importance_above) */
    om_vec3 eye;
} imp_ctx;

static imp_ctx imp_ctx_of(const om_view *v, unsigned funcs)
{
    imp_ctx k;
    k.funcs = funcs;
    for (int i = 0; i < 4; i++) k.row[i] = v->cam_view.m[8 + i];
    k.nn = v->cam.znear;
    k.ff = v->cam.zfar;
    k.span = k.ff - k.nn;
    k.nnf = v->cam.znear;
    k.fff = v->cam.zfar;
    k.spanf = k.fff - k.nnf;
    k.eye = v->cam.eye;
    return k;
}

/* Section 5.4: 1 + beta clamp(-normal . view direction, 0, 1), with the normal turned
 * to the camera (the side the camera sees), so only the angle counts. All float. */
static inline float normal_factor(const imp_ctx *k, om_vec3 p, om_vec3 nrm)
{
    om_vec3 e = om__sub(p, k->eye);
    float l2 = om__dot(e, e), c = om__dot(nrm, e);
    c = l2 > 0.0f ? om__fabsf(c) / om__sqrtf(l2) : 0.0f;
    return 1.0f + OM_RTW_BETA * (c > 1.0f ? 1.0f : c);
}

/* Section 5.2's view depth: minus the view matrix's depth row at p, in float. */
static inline float view_depth(const imp_ctx *k, om_vec3 p)
{
    return -(k->row[0] * p.x + k->row[1] * p.y + k->row[2] * p.z + k->row[3]);
}

/* In line: the backward analysis runs it for every exposed sample it cannot rule out
 * (importance_above). */
static inline float point_importance(const imp_ctx *k, om_vec3 p, om_vec3 nrm)
{
    float imp = 1.0f;
    if (k->funcs & OM_RTW_DIST) {
        /* Section 5.2: 1 - (the desired view's depth), which falls as 1/q with the
         * distance q from the eye. Our depth is z/w in [0, 1], and 1 - z/w is
         * near (far - q) / (q (far - near)) for a point at view depth q. Only the view
         * matrix's depth row is needed. */
        double d = (double)view_depth(k, p);
        double id = d > k->nn ? k->nn * (k->ff - d) / (d * k->span) : 1.0;
        imp *= (float)(id > 0.0 ? id : 0.0);
    }
    if (k->funcs & OM_RTW_NORMAL) imp *= normal_factor(k, p, nrm);
    return imp;
}

/* Whether point_importance(k, p, nrm) may exceed `cur` (>= 0): false only when it
 * certainly does not. The distance term in float is within 5 roundings of the exact
 * quotient (its operands are floats, so far - d and far - near are rounded once each),
 * i.e. a relative 5.01 * 2^-24, and the double one rounded to float within 1.01 *
 * 2^-24: 2^-18 above the float quotient bounds the float of the double. Rounding is
 * monotonic, so the same product with the normal factor bounds the importance. Outside
 * 2^-100..2^100 (no underflow, no overflow) it answers true. The double quotient is
 * soft-float on a Cortex-M4F, and most samples of a cell are not its largest. */
static inline bool importance_above(const imp_ctx *k, om_vec3 p, om_vec3 nrm, float cur)
{
    float ub = 1.0f;
    if (k->funcs & OM_RTW_DIST) {
        const float d = view_depth(k, p);
        if (d > k->nnf) {
            const float num = k->fff - d;
            if (!(num > 0.0f)) return false;   /* the term is 0: the importance is 0 */
            const float a = k->nnf * num, b = d * k->spanf;
            if (!(a > 0x1p-100f && a < 0x1p100f && b > 0x1p-100f && b < 0x1p100f)) return true;
            const float q = a / b;
            if (!(q > 0x1p-100f && q < 0x1p100f)) return true;
            ub = q * (1.0f + 0x1p-18f);
        }
    }
    if (k->funcs & OM_RTW_NORMAL) ub *= normal_factor(k, p, nrm);
    return ub > cur;
}

float om__rtw_point_importance(const om_view *v, unsigned funcs, om_vec3 p, om_vec3 nrm)
{
    const imp_ctx k = imp_ctx_of(v, funcs);
    return point_importance(&k, p, nrm);
}

bool om__rtw_importance_above(const om_view *v, unsigned funcs, om_vec3 p, om_vec3 nrm, float cur)
{
    const imp_ctx k = imp_ctx_of(v, funcs);
    return importance_above(&k, p, nrm, cur);
}

void om__rtw_importance_begin(om__rtw *m)
{
    size_t nn = (size_t)m->n * m->n;
    memset(m->imp, 0, nn * sizeof(float));
    memset(m->seen, 0, (nn + 7) / 8);
}

/* The cell of normalized coordinates in [0, 1] (truncation is floor there; 1 itself
 * belongs to the last cell). */
static size_t cell_of(const om__rtw *m, double u, double v)
{
    uint32_t i = (uint32_t)(u * (double)m->n), j = (uint32_t)(v * (double)m->n);
    if (i > m->n - 1) i = m->n - 1;
    if (j > m->n - 1) j = m->n - 1;
    return (size_t)j * m->n + i;
}

void om__rtw_observe_strip(om__rtw *m, const om_strip *st)
{
#if OM_WITH_JOBS
    if (om__rtw_observe_jobs(m, st)) return;   /* the same map, by bands */
#endif
    om__rtw_observe_into(m, st->samples, st->terms, (size_t)st->rows * st->width, m->imp, m->seen);
}

void om__rtw_observe_into(const om__rtw *m, const om_sample *smp0, const om_term *terms, size_t count,
                          float *imp, uint8_t *seen)
{
    const om_view *v = &m->view;
    /* Backward analysis (section 4.1): samples not exposed to the light are unlit
     * whatever the map says, so they ask for no resolution. Forward analysis only
     * needs to know which cells hold a sample (for the floor). */
    unsigned funcs = m->cfg.rtw_analysis == OM_RTW_FORWARD ? 0u
                                                           : m->cfg.rtw_funcs & (OM_RTW_DIST | OM_RTW_NORMAL);
    const imp_ctx k = imp_ctx_of(v, funcs);
    const float *a = v->light_vp.m;
    const float nf = (float)m->n, hn = 0.5f * nf;
    (void)nf; (void)hn;
    for (size_t i = 0; i < count; i++) {
        if (!(terms[i].flags & OM_TERM_EXPOSED)) continue;
        const om_sample *smp = &smp0[i];
        om_vec3 p = om__v3(smp->p[0], smp->p[1], smp->p[2]);
        /* x, y and w of the light's clip coordinates (z is not needed here) */
        float qx = a[0] * p.x + a[1] * p.y + a[2] * p.z + a[3];
        float qy = a[4] * p.x + a[5] * p.y + a[6] * p.z + a[7];
        float qw = a[12] * p.x + a[13] * p.y + a[14] * p.z + a[15];
        if (!(qw > 0.0f)) continue;
        int32_t ci = -2, cj = -2;   /* unsure: the double arithmetic decides */
        if (OM_FAST_FLOAT) {
            const float iwf = 1.0f / qw;
            ci = om__rtw_cell_axis(qx * iwf, hn, nf);
            cj = om__rtw_cell_axis(-(qy * iwf), hn, nf);
            if (ci == -1 || cj == -1) continue;   /* certainly outside */
        }
        size_t c;
        if (ci >= 0 && cj >= 0) {
            c = (size_t)cj * m->n + (size_t)ci;
        } else {   /* near a cell edge: the double arithmetic decides */
            double iw = 1.0 / (double)qw;
            double u = ((double)qx * iw + 1.0) * 0.5, w = (1.0 - (double)qy * iw) * 0.5;
            if (!(u >= 0.0 && u <= 1.0 && w >= 0.0 && w <= 1.0)) continue;
            c = cell_of(m, u, w);
        }
        const om_vec3 nrm = om__v3(smp->n[0], smp->n[1], smp->n[2]);
        seen[c >> 3] |= (uint8_t)(1u << (c & 7));
        /* "only keeping the highest value point" (section 6.3) */
        if (OM_FAST_FLOAT && !importance_above(&k, p, nrm, imp[c])) continue;
        float val = point_importance(&k, p, nrm);
        if (val > imp[c]) imp[c] = val;
    }
}

/* ---- forward analysis: the world point under a light texel, by the eye pass's
 * perspective-correct barycentrics (om__persp_point) in the light's clip space. */

static bool in_camera(const om_view *v, om_vec3 p)
{
    om_vec4 q = om__mat_apply(&v->cam_vp, p);
    return q.w > 0.0f && q.x >= -q.w && q.x <= q.w && q.y >= -q.w && q.y <= q.w && q.z >= 0.0f &&
           q.z <= q.w;
}

/* The shadow bias's constant term (the lookup's, smlookup.h: a fraction of the light's
 * depth range) in depth units at light depth d (0..2^32): the threshold of a depth
 * discontinuity (section 5.3 compares texel differences with the shadow bias). */
static double bias_depth(const om__rtw *m, double d)
{
    const om_view *v = &m->view;
    double b = (double)m->look.bias_world;
    if (v->light.kind != OM_LIGHT_SPOT) return b * OM_DEPTH_ONE * fabs((double)v->light_proj.m[10]) + 1.0;
    double f = v->light.zfar, nn = v->light.znear, zn = d / OM_DEPTH_ONE;
    double dist = f * nn / (f - zn * (f - nn));
    return b * f * nn / ((f - nn) * dist * dist) * OM_DEPTH_ONE + 1.0;
}

/* Section 5.3: a texel is on a shadow edge when its depth breaks against one of its
 * eight neighbours. We compare second differences (each opposite pair of neighbours
 * against the texel) with the bias rather than plain differences: depth z/w is affine
 * across a plane, so a floor seen at a grazing light angle, whose plain differences
 * exceed any bias, is not mistaken for an edge everywhere. */
static bool is_edge(const om__rtw *m, uint32_t i, uint32_t j)
{
    static const int dirs[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    const uint32_t n = m->n;
    double d = (double)m->fdepth[(size_t)j * n + i], thr = bias_depth(m, d);
    for (int k = 0; k < 4; k++) {
        int ax = (int)i - dirs[k][0], ay = (int)j - dirs[k][1];
        int bx = (int)i + dirs[k][0], by = (int)j + dirs[k][1];
        double da = ax >= 0 && ay >= 0 && ax < (int)n && ay < (int)n ? (double)m->fdepth[(size_t)ay * n + (size_t)ax] : d;
        double db = bx >= 0 && by >= 0 && bx < (int)n && by < (int)n ? (double)m->fdepth[(size_t)by * n + (size_t)bx] : d;
        if (fabs(da + db - 2.0 * d) > thr) return true;
    }
    return false;
}

static void forward(om__rtw *m)
{
    const uint32_t n = m->n;
    const unsigned funcs = m->cfg.rtw_funcs;
    const bool hybrid = m->cfg.rtw_analysis == OM_RTW_HYBRID;
    /* hybrid needs only the depths (for edges); forward also the triangle under a texel */
    om_target tg = {n, n, 0, n, m->fdepth, hybrid ? NULL : m->fid};
    om__scene_raster(m->scene, &m->view.light_vp, m->view.origin, &tg, hybrid ? OM_RASTER_DEPTH : OM_RASTER_DEPTH_ID, false, NULL);
    om__persp_tri cache;
    memset(&cache, 0, sizeof cache);
    cache.tri = OM_NO_TRI;
    for (uint32_t j = 0; j < n; j++)
        for (uint32_t i = 0; i < n; i++) {
            size_t c = (size_t)j * n + i;
            if (hybrid) {
                /* desired view, distance, normal from the samples; edges here, and only
                 * where a sample asked for something (0 times alpha is 0) */
                if ((funcs & OM_RTW_EDGE) && m->imp[c] > 0.0f && !is_edge(m, i, j)) m->imp[c] *= OM_RTW_ALPHA;
                continue;
            }
            float edge = (funcs & OM_RTW_EDGE) && !is_edge(m, i, j) ? OM_RTW_ALPHA : 1.0f;
            uint32_t t = m->fid[c];
            if (t == OM_NO_TRI) { m->imp[c] = 0.0f; continue; }
            if (cache.tri != t) om__persp_setup(m->scene, &m->view.light_vp, m->view.origin, t, &cache);
            float sx = ((float)i + 0.5f) * (2.0f / (float)n) - 1.0f;
            float sy = 1.0f - ((float)j + 0.5f) * (2.0f / (float)n);
            om_vec3 p = om__persp_point(&cache, sx, sy);
            float imp = edge;
            if ((funcs & OM_RTW_DV) && !in_camera(&m->view, p)) imp = 0.0f;
            if (imp > 0.0f) imp *= om__rtw_point_importance(&m->view, funcs, p, cache.n);
            m->imp[c] = imp;
        }
}

void om__rtw_importance_finish(om__rtw *m)
{
    const size_t nn = (size_t)m->n * m->n;
#if OM_WITH_JOBS
    om__rtw_observe_fold(m);   /* the bands' maps, where they analysed */
#endif
    if (m->cfg.rtw_analysis != OM_RTW_BACKWARD) forward(m);
    float top = 0.0f;
    for (size_t c = 0; c < nn; c++)
        if (m->imp[c] > top) top = m->imp[c];
    /* The floor under visible samples. Without the desired-view function, backward
     * analysis does not cull the cells no sample reached: it knows nothing about them,
     * so they count as much as the most important cell (all functions off is then a
     * uniform map, the identity warp: the conventional map). */
    const float floor_v = top * OM_RTW_FLOOR;
    const bool keep_all = !(m->cfg.rtw_funcs & OM_RTW_DV) && m->cfg.rtw_analysis != OM_RTW_FORWARD;
    for (size_t c = 0; c < nn; c++) {
        bool seen = (m->seen[c >> 3] >> (c & 7)) & 1u;
        if (!seen && keep_all) m->imp[c] = top;
        else if (seen && !(m->imp[c] >= floor_v)) m->imp[c] = floor_v;
    }
}

void om__rtw_build_tables(om__rtw *m)
{
    om__rtw_collapse(m->imp, m->n, m->cols, m->rows);
    om__rtw_blur(m->cols, m->n, m->cfg.rtw_sigma, m->scratch, m->kernel);
    om__rtw_blur(m->rows, m->n, m->cfg.rtw_sigma, m->scratch, m->kernel);
    om__rtw_table(m->cols, m->n, m->px);
    om__rtw_table(m->rows, m->n, m->py);
    m->dens_x = om__rtw_max_density(m->px, m->n);
    m->dens_y = om__rtw_max_density(m->py, m->n);
    /* the lookup's reciprocal densities, where the collapsed importances were (2n
     * floats in n doubles; the next frame's tables make those again) */
    m->rcp_x = (float *)(void *)m->cols;
    m->rcp_y = (float *)(void *)m->rows;
    for (uint32_t k = 0; k < m->n; k++) {
        om__rtw_rcp(om__rtw_dens(m->px, m->n, k), m->rcp_x + 2 * k);
        om__rtw_rcp(om__rtw_dens(m->py, m->n, k), m->rcp_y + 2 * k);
    }
}
