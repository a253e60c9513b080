/* shapes.c — procedural geometry for scene files: plane, box, UV sphere, capped
 * cylinder and the random-triangle cloud used by benchmarks; the object transform
 * (scale, rotate, translate); and the sink all geometry goes through.
 *
 * Every closed shape is wound counter-clockwise seen from outside, so the geometric
 * normal cross(v1 - v0, v2 - v0) points out, and shares its vertices so each edge
 * belongs to exactly two triangles (tests/unit/scene.c checks both). Shapes are built
 * in double and rounded to float once, after the transform, so a scene gives the same
 * bits on every machine (trigonometry is core's om__sin/om__cos, not libm's). */
#include "scene.h"

#include <math.h>
#include <string.h>

/* ---- transform */

void om__sincos_deg(double deg, double *s, double *c)
{
    /* Quarter turns are exact, so a box rotated by 90 degrees stays axis-aligned and
     * a 4-segment cylinder has exact corners. */
    double r = deg - 360.0 * floor(deg / 360.0);
    if (r == 0.0) { *s = 0.0; *c = 1.0; return; }
    if (r == 90.0) { *s = 1.0; *c = 0.0; return; }
    if (r == 180.0) { *s = 0.0; *c = -1.0; return; }
    if (r == 270.0) { *s = -1.0; *c = 0.0; return; }
    double rad = r * (OM_PI / 180.0);
    *s = om__sin(rad);
    *c = om__cos(rad);
}

void om__xform_make(om__xform *x, const double scale[3], const double rot_deg[3],
                    const double move[3])
{
    double sa, ca, sb, cb, sg, cg;
    om__sincos_deg(rot_deg[0], &sa, &ca);
    om__sincos_deg(rot_deg[1], &sb, &cb);
    om__sincos_deg(rot_deg[2], &sg, &cg);
    /* R = Rz(g) * Ry(b) * Rx(a): x first, then y, then z. */
    double r[9];
    r[0] = cg * cb; r[1] = cg * sb * sa - sg * ca; r[2] = cg * sb * ca + sg * sa;
    r[3] = sg * cb; r[4] = sg * sb * sa + cg * ca; r[5] = sg * sb * ca - cg * sa;
    r[6] = -sb;     r[7] = cb * sa;                r[8] = cb * ca;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) x->m[i * 4 + j] = r[i * 3 + j] * scale[j];
        x->m[i * 4 + 3] = move[i];
    }
    x->flip = (scale[0] < 0) != ((scale[1] < 0) != (scale[2] < 0));
}

/* ---- sink */

void om__sink_init(om__sink *k, bool write)
{
    memset(k, 0, sizeof *k);
    k->write = write;
    k->check_range = true;
    k->xf.m[0] = k->xf.m[5] = k->xf.m[10] = 1.0;
}

void om__sink_begin(om__sink *k, const om__xform *xf, uint16_t mat)
{
    k->xf = *xf;
    k->base = k->nv;
    k->mat = mat;
}

void om__sink_vert(om__sink *k, double x, double y, double z)
{
    const double *m = k->xf.m;
    double X = m[0] * x + m[1] * y + m[2] * z + m[3];
    double Y = m[4] * x + m[5] * y + m[6] * z + m[7];
    double Z = m[8] * x + m[9] * y + m[10] * z + m[11];
    /* Written so that NaN fails the test too. */
    bool inside = fabs(X) <= OM__COORD_MAX && fabs(Y) <= OM__COORD_MAX &&
                  fabs(Z) <= OM__COORD_MAX;
    if (inside && X * X + Y * Y + Z * Z > k->r2) k->r2 = X * X + Y * Y + Z * Z;
    if (k->check_range && !inside && !k->out_of_range) {
        k->out_of_range = true;
        k->where = k->note;
    }
    if (k->write) {
        if (k->nv < k->vcap) {
            /* Out-of-range values never reach a float conversion (that would be UB). */
            k->verts[k->nv] = inside ? om__v3((float)X, (float)Y, (float)Z) : om__v3(0, 0, 0);
        } else {
            k->overflow = true;
        }
    }
    k->nv++;
}

void om__sink_tri(om__sink *k, uint32_t a, uint32_t b, uint32_t c)
{
    if (k->write) {
        if (k->nt < k->tcap) {
            uint32_t *t = k->idx + 3 * k->nt;
            uint32_t base = (uint32_t)k->base;
            t[0] = base + a;
            t[1] = base + (k->xf.flip ? c : b);
            t[2] = base + (k->xf.flip ? b : c);
            k->tri_mat[k->nt] = k->mat;
        } else {
            k->overflow = true;
        }
    }
    k->nt++;
}

/* ---- counts */

void om__plane_counts(uint32_t div, uint64_t *nv, uint64_t *nt)
{
    *nv = ((uint64_t)div + 1) * ((uint64_t)div + 1);
    *nt = 2 * (uint64_t)div * div;
}

void om__sphere_counts(uint32_t seg, uint32_t rings, uint64_t *nv, uint64_t *nt)
{
    *nv = (uint64_t)seg * (rings - 1) + 2;
    *nt = 2 * (uint64_t)seg * (rings - 1);
}

void om__cylinder_counts(uint32_t seg, uint64_t *nv, uint64_t *nt)
{
    *nv = 2 * (uint64_t)seg + 2;
    *nt = 4 * (uint64_t)seg;
}

/* ---- shapes */

/* Normal +y: seen from above, (i,j) -> (i,j+1) -> (i+1,j) turns counter-clockwise. */
void om__gen_plane(om__sink *k, double sx, double sz, uint32_t div)
{
    uint32_t row = div + 1;
    for (uint32_t i = 0; i <= div; i++) {
        double x = i == div ? 0.5 * sx : -0.5 * sx + sx * (double)i / (double)div;
        for (uint32_t j = 0; j <= div; j++) {
            double z = j == div ? 0.5 * sz : -0.5 * sz + sz * (double)j / (double)div;
            om__sink_vert(k, x, 0.0, z);
        }
        if (k->out_of_range && !k->write) return;
    }
    for (uint32_t i = 0; i < div; i++)
        for (uint32_t j = 0; j < div; j++) {
            uint32_t a = i * row + j, b = a + 1, c = a + row, d = c + 1;
            om__sink_tri(k, a, b, c);
            om__sink_tri(k, c, b, d);
        }
}

/* Corner i has x = bit 0, y = bit 1, z = bit 2; each face is a quad listed
 * counter-clockwise seen from outside and split along its first diagonal. */
void om__gen_box(om__sink *k, double sx, double sy, double sz)
{
    static const uint8_t quads[6][4] = {
        {1, 3, 7, 5}, {0, 4, 6, 2},   /* +x, -x */
        {2, 6, 7, 3}, {0, 1, 5, 4},   /* +y, -y */
        {4, 5, 7, 6}, {0, 2, 3, 1},   /* +z, -z */
    };
    for (int i = 0; i < 8; i++)
        om__sink_vert(k, (i & 1) ? 0.5 * sx : -0.5 * sx, (i & 2) ? 0.5 * sy : -0.5 * sy,
                      (i & 4) ? 0.5 * sz : -0.5 * sz);
    for (int f = 0; f < 6; f++) {
        om__sink_tri(k, quads[f][0], quads[f][1], quads[f][2]);
        om__sink_tri(k, quads[f][0], quads[f][2], quads[f][3]);
    }
}

/* Poles are single vertices (0 on top, last at the bottom); rings 1..rings-1 hold
 * `seg` vertices each at polar angle 180 r / rings. Azimuth runs so that
 * (pole, s, s+1) is counter-clockwise seen from above. */
void om__gen_sphere(om__sink *k, double r, uint32_t seg, uint32_t rings)
{
    om__sink_vert(k, 0.0, r, 0.0);
    for (uint32_t i = 1; i < rings; i++) {
        double st, ct;
        om__sincos_deg(180.0 * (double)i / (double)rings, &st, &ct);
        for (uint32_t s = 0; s < seg; s++) {
            double sp, cp;
            om__sincos_deg(360.0 * (double)s / (double)seg, &sp, &cp);
            om__sink_vert(k, r * st * cp, r * ct, -r * st * sp);
        }
        if (k->out_of_range && !k->write) return;
    }
    uint32_t south = 1 + (rings - 1) * seg;
    om__sink_vert(k, 0.0, -r, 0.0);
    for (uint32_t s = 0; s < seg; s++) {
        uint32_t s1 = s + 1 == seg ? 0 : s + 1;
        om__sink_tri(k, 0, 1 + s, 1 + s1);
        for (uint32_t i = 1; i + 1 < rings; i++) {
            uint32_t a = 1 + (i - 1) * seg + s, b = a + seg;
            uint32_t d = 1 + (i - 1) * seg + s1, c = d + seg;
            om__sink_tri(k, a, b, c);
            om__sink_tri(k, a, c, d);
        }
        om__sink_tri(k, south, 1 + (rings - 2) * seg + s1, 1 + (rings - 2) * seg + s);
    }
}

/* Bottom ring 0..seg-1 at y = 0, top ring seg..2seg-1 at y = h, then the two cap
 * centres; caps are fans so no triangle is a sliver however many segments. */
void om__gen_cylinder(om__sink *k, double r, double h, uint32_t seg)
{
    for (uint32_t ring = 0; ring < 2; ring++)
        for (uint32_t s = 0; s < seg; s++) {
            double sp, cp;
            om__sincos_deg(360.0 * (double)s / (double)seg, &sp, &cp);
            om__sink_vert(k, r * cp, ring ? h : 0.0, -r * sp);
        }
    uint32_t bc = 2 * seg, tc = bc + 1;
    om__sink_vert(k, 0.0, 0.0, 0.0);
    om__sink_vert(k, 0.0, h, 0.0);
    for (uint32_t s = 0; s < seg; s++) {
        uint32_t s1 = s + 1 == seg ? 0 : s + 1;
        uint32_t b0 = s, b1 = s1, t0 = seg + s, t1 = seg + s1;
        om__sink_tri(k, t0, b0, b1);
        om__sink_tri(k, t0, b1, t1);
        om__sink_tri(k, tc, t0, t1);
        om__sink_tri(k, bc, b1, b0);
    }
}

uint64_t om__mix_next(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1): the top 53 bits times 2^-53, both exact. */
static double uniform(uint64_t *state)
{
    return (double)(om__mix_next(state) >> 11) * (1.0 / 9007199254740992.0);
}

void om__gen_triangles(om__sink *k, uint32_t n, uint32_t seed, double area,
                       const double box[6])
{
    uint64_t state = 0x6F6D627261ull ^ ((uint64_t)seed << 17) ^ seed;
    /* Equilateral with area a: side L = sqrt(4a / sqrt 3), circumradius L / sqrt 3. */
    double a = area / (double)n;
    double R = sqrt(4.0 * a / (3.0 * 1.7320508075688772));
    for (uint32_t i = 0; i < n; i++) {
        double c[3], nrm[3], t[3], b[3];
        for (int ax = 0; ax < 3; ax++) {
            double lo = box[ax], hi = box[ax + 3], u = uniform(&state);
            /* The centre stays R inside every face, so all three corners lie in the box. */
            c[ax] = hi - lo >= 2.0 * R ? lo + R + u * (hi - lo - 2.0 * R) : 0.5 * (lo + hi);
        }
        /* A uniform random normal (z uniform in [-1, 1], azimuth uniform). */
        double z = 2.0 * uniform(&state) - 1.0, sp, cp;
        double rho = sqrt(fmax(0.0, 1.0 - z * z));
        om__sincos_deg(360.0 * uniform(&state), &sp, &cp);
        nrm[0] = rho * cp; nrm[1] = rho * sp; nrm[2] = z;
        /* An in-plane basis: cross with the axis the normal is least aligned with. */
        int ax = fabs(nrm[0]) <= fabs(nrm[1]) ? (fabs(nrm[0]) <= fabs(nrm[2]) ? 0 : 2)
                                              : (fabs(nrm[1]) <= fabs(nrm[2]) ? 1 : 2);
        double e[3] = {0.0, 0.0, 0.0};
        e[ax] = 1.0;
        t[0] = nrm[1] * e[2] - nrm[2] * e[1];
        t[1] = nrm[2] * e[0] - nrm[0] * e[2];
        t[2] = nrm[0] * e[1] - nrm[1] * e[0];
        double tl = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        t[0] /= tl; t[1] /= tl; t[2] /= tl;
        b[0] = nrm[1] * t[2] - nrm[2] * t[1];
        b[1] = nrm[2] * t[0] - nrm[0] * t[2];
        b[2] = nrm[0] * t[1] - nrm[1] * t[0];
        /* Corners at psi, psi + 120 and psi + 240 degrees around the centre; the later
         * two by rotating the first (cos 120 = -1/2, sin 120 = sqrt(3)/2). */
        double s, co;
        om__sincos_deg(360.0 * uniform(&state), &s, &co);
        for (int v = 0; v < 3; v++) {
            om__sink_vert(k, c[0] + R * (co * t[0] + s * b[0]), c[1] + R * (co * t[1] + s * b[1]),
                          c[2] + R * (co * t[2] + s * b[2]));
            double co2 = -0.5 * co - 0.8660254037844386 * s;
            s = 0.8660254037844386 * co - 0.5 * s;
            co = co2;
        }
        om__sink_tri(k, 3 * i, 3 * i + 1, 3 * i + 2);
        if (k->out_of_range && !k->write) return;
    }
}
