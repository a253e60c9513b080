/* math.c — vectors, 4x4 matrices, projections, and trigonometry and logarithms of our
 * own. sin/cos/tan/atan and log2/exp2 are evaluated with fixed polynomials in IEEE double so their bits
 * do not depend on the C library (libm's may differ in the last bit between systems,
 * and anything that reaches a pixel must be bit-identical everywhere). */
#include "core.h"

#include <math.h>

om_vec3 om__normalize(om_vec3 a)
{
    float l2 = om__dot(a, a);
    if (!(l2 > 0.0f)) return om__v3(0, 0, 0);
    float inv = 1.0f / om__sqrtf(l2);
    return om__scale(a, inv);
}

bool om__finite3(om_vec3 a) { return om__finite(a.x) && om__finite(a.y) && om__finite(a.z); }

om_mat4 om__mat_identity(void)
{
    om_mat4 m = {{0}};
    m.m[0] = m.m[5] = m.m[10] = m.m[15] = 1.0f;
    return m;
}

om_mat4 om__mat_mul(const om_mat4 *a, const om_mat4 *b)
{
    om_mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            float s = 0.0f;
            for (int k = 0; k < 4; k++) s += a->m[i * 4 + k] * b->m[k * 4 + j];
            r.m[i * 4 + j] = s;
        }
    return r;
}

om_vec3 om__mat_apply_dir(const om_mat4 *m, om_vec3 d)
{
    const float *a = m->m;
    return om__v3(a[0] * d.x + a[1] * d.y + a[2] * d.z, a[4] * d.x + a[5] * d.y + a[6] * d.z,
                  a[8] * d.x + a[9] * d.y + a[10] * d.z);
}

bool om__mat_look_at(om_mat4 *out, om_vec3 eye, om_vec3 target, om_vec3 up)
{
    om_vec3 f = om__normalize(om__sub(target, eye));
    om_vec3 s = om__normalize(om__cross(f, up));
    if (om__dot(f, f) == 0.0f || om__dot(s, s) == 0.0f) {
        /* up parallel to the view direction: pick any perpendicular up */
        om_vec3 alt = om__fabsf(f.y) < 0.9f ? om__v3(0, 1, 0) : om__v3(1, 0, 0);
        s = om__normalize(om__cross(f, alt));
        if (om__dot(f, f) == 0.0f || om__dot(s, s) == 0.0f) return false;
    }
    om_vec3 u = om__cross(s, f);
    om_mat4 m = om__mat_identity();
    m.m[0] = s.x; m.m[1] = s.y; m.m[2] = s.z; m.m[3] = -om__dot(s, eye);
    m.m[4] = u.x; m.m[5] = u.y; m.m[6] = u.z; m.m[7] = -om__dot(u, eye);
    m.m[8] = -f.x; m.m[9] = -f.y; m.m[10] = -f.z; m.m[11] = om__dot(f, eye);
    *out = m;
    return true;
}

om_mat4 om__mat_perspective(float fovy_deg, float aspect, float znear, float zfar)
{
    om_mat4 m = {{0}};
    float f = (float)(1.0 / om__tan((double)fovy_deg * (OM_PI / 360.0)));
    m.m[0] = f / aspect;
    m.m[5] = f;
    m.m[10] = zfar / (znear - zfar);
    m.m[11] = znear * zfar / (znear - zfar);
    m.m[14] = -1.0f;
    return m;
}

om_mat4 om__mat_ortho(float l, float r, float b, float t, float znear, float zfar)
{
    om_mat4 m = {{0}};
    m.m[0] = 2.0f / (r - l);
    m.m[3] = -(r + l) / (r - l);
    m.m[5] = 2.0f / (t - b);
    m.m[7] = -(t + b) / (t - b);
    m.m[10] = -1.0f / (zfar - znear);
    m.m[11] = -znear / (zfar - znear);
    m.m[15] = 1.0f;
    return m;
}

/* ---- trigonometry */

/* Reduce x to r in [-pi/4, pi/4] with x = k*pi/2 + r (two-part pi/2 keeps ~1e-16
 * accuracy for the arguments a renderer sees). */
static double reduce(double x, int *quadrant)
{
    const double pio2_hi = 1.57079632673412561417e+00;
    const double pio2_lo = 6.07710050650619224932e-11;
    double k = floor(x * 0.63661977236758134308 + 0.5);
    *quadrant = (int)((long long)k & 3);
    return (x - k * pio2_hi) - k * pio2_lo;
}

static double sin_poly(double r)
{
    double r2 = r * r;
    return r + r * r2 * (-1.0 / 6 + r2 * (1.0 / 120 + r2 * (-1.0 / 5040 + r2 * (1.0 / 362880 +
           r2 * (-1.0 / 39916800 + r2 * (1.0 / 6227020800.0 + r2 * (-1.0 / 1307674368000.0)))))));
}

static double cos_poly(double r)
{
    double r2 = r * r;
    return 1.0 + r2 * (-0.5 + r2 * (1.0 / 24 + r2 * (-1.0 / 720 + r2 * (1.0 / 40320 +
           r2 * (-1.0 / 3628800 + r2 * (1.0 / 479001600 + r2 * (-1.0 / 87178291200.0 +
           r2 * (1.0 / 20922789888000.0 + r2 * (-1.0 / 6402373705728000.0)))))))));
}

double om__sin(double x)
{
    int q;
    double r = reduce(x, &q);
    switch (q) {
    case 0: return sin_poly(r);
    case 1: return cos_poly(r);
    case 2: return -sin_poly(r);
    default: return -cos_poly(r);
    }
}

double om__cos(double x)
{
    int q;
    double r = reduce(x, &q);
    switch (q) {
    case 0: return cos_poly(r);
    case 1: return -sin_poly(r);
    case 2: return -cos_poly(r);
    default: return sin_poly(r);
    }
}

double om__tan(double x) { return om__sin(x) / om__cos(x); }

/* atan by reduction to |t| <= tan(pi/8) and its Taylor series (23 terms reach 1e-17). */
double om__atan(double x)
{
    if (x != x) return x;
    int neg = x < 0;
    if (neg) x = -x;
    double base = 0.0;
    if (x > 1.0) {
        base = OM_PI / 2;
        x = -1.0 / x;          /* atan(x) = pi/2 + atan(-1/x) for x > 0 */
    }
    double off = 0.0;
    if (x > 0.41421356237309503) { off = OM_PI / 4; x = (x - 1.0) / (x + 1.0); }
    else if (x < -0.41421356237309503) { off = -OM_PI / 4; x = (x + 1.0) / (1.0 - x); }
    double x2 = x * x, sum = 0.0;
    for (int k = 22; k >= 0; k--) sum = (k & 1 ? -1.0 : 1.0) / (2 * k + 1) + x2 * sum;
    double r = base + off + x * sum;
    return neg ? -r : r;
}

double om__log2(double x)
{
    /* x = m * 2^e with m in [0.5, 1); ln m = 2 atanh(u), u = (m - 1) / (m + 1). */
    int e;
    double m = frexp(x, &e);
    double u = (m - 1.0) / (m + 1.0), u2 = u * u, sum = 0.0;
    for (int k = 20; k >= 0; k--) sum = 1.0 / (2 * k + 1) + u2 * sum;
    return (double)e + 2.0 * u * sum * 1.44269504088896340736;
}

double om__exp2(double x)
{
    double n = floor(x), f = (x - n) * 0.69314718055994530942;   /* e^f, f in [0, ln 2) */
    double sum = 1.0, term = 1.0;
    for (int k = 1; k < 20; k++) {
        term = term * f / k;
        sum += term;
    }
    return ldexp(sum, (int)n);
}
