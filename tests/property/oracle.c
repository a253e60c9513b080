/* property/oracle.c — the reference against an independent oracle, and surfaces that
 * never shadow themselves.
 *
 * The oracle shares nothing with the occlusion predicate: for every exposed sample it
 * tests the segment from the sample's point to the light against every triangle but
 * the sample's own, in double precision (Moller-Trumbore, a hit strictly between the
 * ends, no offset). Its only speed-up is obviously safe: each triangle is binned by the
 * box of its vertices as seen from the light (the segment is one point there). Each
 * disagreement with `ref` is classified:
 *   - eye pass: the exact ray through the pixel centre hits another triangle than the
 *     one the eye pass gave the pixel (the centre is within its snapping of an edge);
 *   - edge-on: the oracle's own answer changes when the sample's point moves along its
 *     own triangle's plane by at most TIE_STEPS grid steps across the light's image
 *     (a facet almost edge-on to the light, steep on its grid: occlude.h);
 *   - tie: it changes when the point moves by at most TIE_STEPS grid steps of the
 *     light's 2^21-step grid in any direction (an edge or a depth within what the grid
 *     resolves);
 *   - data: it changes when the oracle's allowance for the rounding of the vertices
 *     (eps_at, four units in the last place) is taken at the sample's distance from
 *     the view's origin rather than from the world's: far from the world's origin a
 *     blocker that close to the sample's surface is within the float data's spacing;
 *   - other: none of these; a test fails on any.
 * and the share that disagrees but for edge-on and data must stay within 0.005% of the
 * covered samples, edge-on within 0.02%.
 * The same scenes moved far from the origin and scaled, lone spheres at many rotations
 * and the eye pass's points on slivers follow at the end. */
#include "../test.h"
#include "../harness.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>

/* The predicate's lateral bound on these scenes is 8 to 23 grid steps (twice half a
 * step plus the float rounding of x/w: occlude.h); the largest under the directional
 * light, fitted to a view much smaller than the scene's box, where the grid is finer
 * than float positions resolve. */
#define TIE_STEPS 24.0

typedef struct dv { double x, y, z; } dv;

static dv dsub(dv a, dv b) { dv r = {a.x - b.x, a.y - b.y, a.z - b.z}; return r; }
static dv dcross(dv a, dv b)
{
    dv r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return r;
}
static double ddot(dv a, dv b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dv dscale(dv a, double k) { dv r = {a.x * k, a.y * k, a.z * k}; return r; }
static dv dadd(dv a, dv b) { dv r = {a.x + b.x, a.y + b.y, a.z + b.z}; return r; }
static dv dnorm(dv a) { return dscale(a, 1.0 / sqrt(ddot(a, a))); }
static dv fv(om_vec3 v) { dv r = {v.x, v.y, v.z}; return r; }
static dv vert(const om_scene *s, uint32_t t, int k) { return fv(s->verts[s->idx[(size_t)t * 3 + k]]); }

/* The segment o -> o + d meets triangle t strictly between its ends (edges included).
 * With eps > 0, a triangle whose plane passes within eps of o does not count: o is a
 * float position, and a surface through it to within its rounding is o's own surface
 * (the other half of a planar quad, a coplanar neighbour). */
static bool seg_hits(const om_scene *s, uint32_t t, dv o, dv d, double eps, double *tout)
{
    dv a = vert(s, t, 0), e1 = dsub(vert(s, t, 1), a), e2 = dsub(vert(s, t, 2), a);
    dv pv = dcross(d, e2);
    double det = ddot(e1, pv);
    if (det == 0.0) return false;
    double inv = 1.0 / det;
    dv tv = dsub(o, a);
    double u = ddot(tv, pv) * inv;
    if (u < 0.0 || u > 1.0) return false;
    dv qv = dcross(tv, e1);
    double v = ddot(d, qv) * inv;
    if (v < 0.0 || u + v > 1.0) return false;
    double tt = ddot(e2, qv) * inv;
    if (tout) *tout = tt;
    if (!(tt > 0.0 && tt < 1.0)) return false;
    if (eps > 0.0) {   /* last: the answer is the same, most triangles are missed sooner */
        dv n = dcross(e1, e2);
        double nn = sqrt(ddot(n, n));
        if (!(nn > 0.0) || fabs(ddot(n, tv)) <= eps * nn) return false;
    }
    return true;
}

#define G 384
typedef struct oracle {
    const om_scene *s;
    om_view v;             /* for the light's projection only (its grid step) */
    om_camera cam;         /* the scene's camera and light at time 0, in world space, */
    om_light lt;           /* as the scene gives them: not the view's copies */
    dv origin;             /* where the samples' points are relative to (smp_world) */
    bool spot;
    dv light, toward, ax, ay, az;   /* toward: unit direction to a directional light */
    double reach, step_k;           /* directional segment length; grid step per depth */
    double lo[2], hi[2];
    uint32_t *start, *list;         /* triangles by cell of the light's view; */
    uint32_t *always, nalways;      /* those that cannot be projected */
} oracle;

/* Where a point is in the light's view: a position on its image plane. */
static bool light_xy(const oracle *o, dv p, double xy[2])
{
    if (o->spot) {
        dv q = dsub(p, o->light);
        double d = ddot(q, o->az);
        if (!(d > 1e-9)) return false;
        xy[0] = ddot(q, o->ax) / d;
        xy[1] = ddot(q, o->ay) / d;
    } else {
        xy[0] = ddot(p, o->ax);
        xy[1] = ddot(p, o->ay);
    }
    return true;
}

static bool tri_box(const oracle *o, uint32_t t, double b[4])
{
    for (int k = 0; k < 3; k++) {
        double xy[2];
        if (!light_xy(o, vert(o->s, t, k), xy)) return false;
        if (k == 0 || xy[0] < b[0]) b[0] = xy[0];
        if (k == 0 || xy[1] < b[1]) b[1] = xy[1];
        if (k == 0 || xy[0] > b[2]) b[2] = xy[0];
        if (k == 0 || xy[1] > b[3]) b[3] = xy[1];
    }
    /* the projection of the triangle is the triangle of its projected vertices; a pad
     * far above double rounding keeps points on an edge inside */
    double pad = 1e-9 * (fabs(b[0]) + fabs(b[1]) + fabs(b[2]) + fabs(b[3]) + 1.0);
    b[0] -= pad; b[1] -= pad; b[2] += pad; b[3] += pad;
    return true;
}

static int cell(const oracle *o, double v, int axis)
{
    double f = (v - o->lo[axis]) / (o->hi[axis] - o->lo[axis]) * G;
    return f < 0 ? 0 : f >= G ? G - 1 : (int)f;
}

/* The oracle's camera, light and origin, without the bins (oracle_init adds them). */
static void oracle_view(oracle *o, const om_scene *s, uint32_t w, uint32_t h)
{
    om_diag d;
    memset(o, 0, sizeof *o);
    o->s = s;
    CHECK_OK(h_view(&o->v, s, 0, w, h, &d));
    om_scene_at(s, 0.0f, &o->cam, &o->lt);
    o->cam.width = w;
    o->cam.height = h;
    /* om_sample.p is relative to the view's origin (om_view) */
    o->origin = fv(o->v.origin);
}

static void oracle_init(oracle *o, const om_scene *s, uint32_t w, uint32_t h)
{
    oracle_view(o, s, w, h);
    o->spot = o->lt.kind == OM_LIGHT_SPOT;
    o->light = fv(o->lt.pos);
    o->az = dnorm(o->spot ? dsub(fv(o->lt.target), o->light) : fv(o->lt.dir));
    dv up = fabs(o->az.y) < 0.9 ? (dv){0, 1, 0} : (dv){1, 0, 0};
    o->ax = dnorm(dcross(o->az, up));
    o->ay = dcross(o->ax, o->az);
    o->toward = dscale(o->az, -1.0);
    dv ext = dsub(fv(s->hi), fv(s->lo));
    o->reach = 2.0 * (fabs(ext.x) + fabs(ext.y) + fabs(ext.z)) + 1.0;
    /* one step of the light's grid in world units: per unit of depth from a spot light,
     * or across an orthographic box */
    double p0 = fabs((double)o->v.light_proj.m[0]), p5 = fabs((double)o->v.light_proj.m[5]);
    o->step_k = 2.0 / ((p0 < p5 ? p0 : p5) * 2097152.0);

    double (*box)[4] = malloc(sizeof *box * (s->ntris ? s->ntris : 1));
    bool *ok = malloc(s->ntris ? s->ntris : 1);
    o->lo[0] = o->lo[1] = INFINITY;
    o->hi[0] = o->hi[1] = -INFINITY;
    for (uint32_t t = 0; t < s->ntris; t++) {
        ok[t] = tri_box(o, t, box[t]);
        if (!ok[t]) { o->nalways++; continue; }
        for (int a = 0; a < 2; a++) {
            if (box[t][a] < o->lo[a]) o->lo[a] = box[t][a];
            if (box[t][a + 2] > o->hi[a]) o->hi[a] = box[t][a + 2];
        }
    }
    o->start = calloc(G * G + 1, sizeof *o->start);
    o->always = malloc(sizeof *o->always * (o->nalways + 1));
    o->nalways = 0;
    for (int pass = 0; pass < 2; pass++) {
        uint32_t *fill = pass ? calloc(G * G, sizeof *fill) : NULL;
        for (uint32_t t = 0; t < s->ntris; t++) {
            if (!ok[t]) { if (pass) o->always[o->nalways++] = t; continue; }
            for (int cy = cell(o, box[t][1], 1); cy <= cell(o, box[t][3], 1); cy++)
                for (int cx = cell(o, box[t][0], 0); cx <= cell(o, box[t][2], 0); cx++) {
                    if (!pass) o->start[cy * G + cx + 1]++;
                    else o->list[o->start[cy * G + cx] + fill[cy * G + cx]++] = t;
                }
        }
        if (!pass) {
            for (int c = 0; c < G * G; c++) o->start[c + 1] += o->start[c];
            o->list = malloc(sizeof *o->list * (o->start[G * G] + 1));
        }
        free(fill);
    }
    free(box);
    free(ok);
}

static void oracle_free(oracle *o)
{
    free(o->start);
    free(o->list);
    free(o->always);
}

/* A sample's point in world space, in double: the one place that reads om_sample.p. */
static dv smp_world(const oracle *o, const om_sample *smp)
{
    dv p = {smp->p[0], smp->p[1], smp->p[2]};
    return dadd(o->origin, p);
}

/* The oracle: does anything but triangle `own` lie on the segment from p to the light?
 * With `gap`, every triangle is tried and *gap is the distance from p to the nearest
 * blocker (INFINITY: none). */
static bool oracle_blocked_eps(const oracle *o, dv p, uint32_t own, double eps, double *gap);

/* Four half-units in the last place of the largest coordinate of q: the rounding to
 * float of p and of the vertices of the surface it lies on, where q is p's world
 * position (the vertices' data) or its position relative to the origin (the sample's
 * own point, as the frame holds it). */
static double eps_at(dv q)
{
    double big = fabs(q.x) > fabs(q.y) ? fabs(q.x) : fabs(q.y);
    return (fabs(q.z) > big ? fabs(q.z) : big) * (4.0 / 16777216.0);
}

static bool oracle_blocked_gap(const oracle *o, dv p, uint32_t own, double *gap)
{
    return oracle_blocked_eps(o, p, own, eps_at(p), gap);
}

static bool oracle_blocked_eps(const oracle *o, dv p, uint32_t own, double eps, double *gap)
{
    dv d = o->spot ? dsub(o->light, p) : dscale(o->toward, o->reach);
    double near = INFINITY, t;
    bool hit = false;
    if (gap) *gap = INFINITY;
    for (uint32_t i = 0; i < o->nalways; i++)
        if (o->always[i] != own && seg_hits(o->s, o->always[i], p, d, eps, &t)) {
            if (!gap) return true;
            hit = true;
            if (t < near) near = t;
        }
    double xy[2];
    if (light_xy(o, p, xy) && !(xy[0] < o->lo[0] || xy[0] > o->hi[0] || xy[1] < o->lo[1] || xy[1] > o->hi[1])) {
        int c = cell(o, xy[1], 1) * G + cell(o, xy[0], 0);
        for (uint32_t i = o->start[c]; i < o->start[c + 1]; i++)
            if (o->list[i] != own && seg_hits(o->s, o->list[i], p, d, eps, &t)) {
                if (!gap) return true;
                hit = true;
                if (t < near) near = t;
            }
    }
    if (gap && hit) *gap = near * sqrt(ddot(d, d));
    return hit;
}

static bool oracle_blocked(const oracle *o, dv p, uint32_t own) { return oracle_blocked_gap(o, p, own, NULL); }

/* Does the oracle change its answer when p moves along its own triangle's plane by
 * TIE_STEPS grid steps across the light's image (2), or else by TIE_STEPS grid steps
 * in any direction (1)? 0: neither. (The first: a facet almost edge-on to the light
 * is steep on the image, and a point moved across it by the grid's error moves far in
 * depth; occlude.h counts that as a tie.) */
static int oracle_tie(const oracle *o, dv p, uint32_t own, bool was)
{
    double k = o->step_k * TIE_STEPS;
    if (o->spot) k *= ddot(dsub(p, o->light), o->az);
    const dv a = vert(o->s, own, 0), n = dcross(dsub(vert(o->s, own, 1), a), dsub(vert(o->s, own, 2), a));
    const dv l = o->spot ? dnorm(dsub(o->light, p)) : o->toward;
    const double nl = ddot(n, l);
    for (int i = 0; i < 8 && nl != 0.0; i++) {
        int m = i < 4 ? i : i + 1;   /* the 8 neighbours of a 3x3 square on the image */
        const dv d = dadd(dscale(o->ax, k * (m % 3 - 1)), dscale(o->ay, k * (m / 3 - 1)));
        const dv q = dadd(p, dsub(d, dscale(l, ddot(n, d) / nl)));   /* back onto the plane */
        if (oracle_blocked(o, q, own) != was) return 2;
    }
    for (int i = 0; i < 26; i++) {
        int m = i < 13 ? i : i + 1;   /* the 26 neighbours of a 3x3x3 block */
        dv q = dadd(p, dadd(dscale(o->ax, k * (m % 3 - 1)),
                            dadd(dscale(o->ay, k * (m / 3 % 3 - 1)), dscale(o->az, k * (m / 9 - 1)))));
        if (oracle_blocked(o, q, own) != was) return 1;
    }
    return 0;
}

/* The ray through the centre of pixel (x, y) from the camera's eye: its direction d
 * (unnormalised: a unit step along the view axis f), f, and one pixel's size per unit
 * of depth along f. */
typedef struct pray { dv eye, d, f; double pix; } pray;

static pray pixel_ray(const oracle *o, uint32_t x, uint32_t y)
{
    const om_camera *c = &o->cam;
    pray r;
    r.eye = fv(c->eye);
    r.f = dnorm(dsub(fv(c->target), r.eye));
    dv rt = dnorm(dcross(r.f, fv(c->up))), u = dcross(rt, r.f);
    double ty = tan((double)c->fovy_deg * 3.14159265358979323846 / 360.0);
    double tx = ty * (double)c->width / (double)c->height;
    double sx = ((double)x + 0.5) * 2.0 / c->width - 1.0, sy = 1.0 - ((double)y + 0.5) * 2.0 / c->height;
    r.d = dadd(r.f, dadd(dscale(rt, sx * tx), dscale(u, sy * ty)));
    r.pix = 2.0 * ty / (double)c->height;
    return r;
}

/* The triangle the exact ray through pixel (x, y) meets first (OM_NO_TRI: none). */
static uint32_t eye_hit(const oracle *o, uint32_t x, uint32_t y)
{
    pray r = pixel_ray(o, x, y);
    dv eye = r.eye, d = dscale(r.d, (double)o->cam.zfar * 4.0);
    uint32_t best = OM_NO_TRI;
    double bt = 2.0, tt;
    for (uint32_t t = 0; t < o->s->ntris; t++) {
        if (seg_hits(o->s, t, eye, d, 0.0, &tt) && tt < bt) {
            bt = tt;
            best = t;
        }
    }
    return best;
}

typedef struct tally { uint32_t covered, exposed, differ, eye, tie, edge_on, data, other, other_lit; } tally;

/* Renders `ref` at w x h and holds every exposed sample against the oracle. */
static tally against_oracle(const om_scene *s, const char *what, uint32_t w, uint32_t h)
{
    tally n;
    memset(&n, 0, sizeof n);
    om_term *terms = malloc(sizeof *terms * w * h);
    om_sample *smp = malloc(sizeof *smp * w * h);
    CHECK_OK(h_render(s, "ref", NULL, w, h, 0, 0, NULL, terms, smp));
    oracle o;
    oracle_init(&o, s, w, h);
    for (uint32_t i = 0; i < w * h; i++) {
        if (smp[i].tri == OM_NO_TRI) continue;
        n.covered++;
        if (!(terms[i].flags & OM_TERM_EXPOSED)) continue;
        n.exposed++;
        dv p = smp_world(&o, &smp[i]);
        bool ob = oracle_blocked(&o, p, smp[i].tri);
        bool rb = !om_term_lit(&terms[i]);
        if (ob == rb) continue;
        n.differ++;
        int tie = 0;
        if (eye_hit(&o, i % w, i / w) != smp[i].tri) n.eye++;
        else if ((tie = oracle_tie(&o, p, smp[i].tri, ob)) == 1) n.tie++;
        else if (tie == 2) n.edge_on++;
        else if (oracle_blocked_eps(&o, p, smp[i].tri, eps_at(dsub(p, o.origin)), NULL) == rb) n.data++;
        else {
            n.other++;
            n.other_lit += !rb;
            if (n.other <= 5) {
                double gap;
                oracle_blocked_gap(&o, p, smp[i].tri, &gap);
                fprintf(stderr, "  %s: pixel (%u,%u) tri %u: ref %s, oracle %s (nearest blocker %.3g away)\n",
                        what, i % w, i / w, smp[i].tri, rb ? "shadowed" : "lit", ob ? "shadowed" : "lit", gap);
            }
        }
    }
    printf("  oracle %-16s %ux%u: %u covered, %u exposed; %u disagree (%u eye pass, %u ties, %u edge-on, "
           "%u data, %u other", what, w, h, n.covered, n.exposed, n.differ, n.eye, n.tie, n.edge_on, n.data,
           n.other);
    if (n.other) printf(": %u lit by ref", n.other_lit);
    printf(")\n");
    CHECK_MSG(n.other == 0, "%s: %u disagreements the oracle cannot explain", what, n.other);
    /* at least 99.995% agree but for edge-on facets and the data's spacing (above);
     * at most 0.02% on edge-on facets. A share can only be held where one sample is
     * within it: from 20,000 covered samples (every size but OM_TEST_QUICK's, whose
     * runs are for memory checkers; every other build holds the shares at full size) */
    if (n.covered >= 20000) {
        CHECK_MSG((double)(n.differ - n.edge_on - n.data) <= 5e-5 * n.covered,
                  "%s: %u of %u covered samples disagree", what, n.differ - n.edge_on - n.data, n.covered);
        CHECK_MSG((double)n.edge_on <= 2e-4 * n.covered, "%s: %u of %u covered samples disagree on edge-on "
                  "facets", what, n.edge_on, n.covered);
    }
    oracle_free(&o);
    free(terms);
    free(smp);
    return n;
}

static bool quick(void) { return getenv("OM_TEST_QUICK") != NULL; }

static void oracle_scene(const char *text, const char *what, uint32_t w, uint32_t h)
{
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return;
    if (quick()) { w /= 4; h /= 4; }
    against_oracle(&hs.s, what, w, h);
    h_scene_free(&hs);
}

static void oracle_floor(void)
{
    oracle_scene("camera eye 0 3 12 target 0 0 -4 fov 55\n"
                 "light directional dir -1 -0.035 -0.4\n"
                 "plane size 40 40 divisions 64\n"
                 "box size 1 1.5 1 rotate 0 20 0 translate 2 0.75 -3\n"
                 "box size 0.1 2 0.1 translate -2 1 0\n",
                 "grazing floor", 320, 240);
    oracle_scene("camera eye 0 3 12 target 0 0 -4 fov 55\n"
                 "light spot pos 30 1.2 -10 target 0 0 -2 fov 60 near 1 far 100\n"
                 "plane size 40 40 divisions 64\n"
                 "box size 1 1.5 1 rotate 0 20 0 translate 2 0.75 -3\n",
                 "grazing spot", 320, 240);
}

static void oracle_curved(void)
{
    oracle_scene("camera eye 0 3 7 target 0 1 0 fov 50\n"
                 "light spot pos 6 9 4 target 0 0 0 fov 60 near 1 far 40\n"
                 "plane size 20 20 divisions 16\n"
                 "sphere radius 1 segments 128 rings 64 translate -1.2 1 0\n"
                 "cylinder radius 0.6 height 2 segments 512 translate 1.3 0 0.3\n",
                 "sphere, cylinder", 320, 240);
}

/* A seeded, deformed sphere as an OBJ: a closed mesh with irregular facets, concave and
 * convex, the way a scanned model is. */
typedef struct blob { char *text; size_t len; } blob;

static om_status blob_load(void *user, const char *name, const char **data, size_t *len)
{
    const blob *b = (const blob *)user;
    if (strcmp(name, "blob.obj")) return OM_E_NOTFOUND;
    *data = b->text;
    *len = b->len;
    return OM_OK;
}

static blob make_blob(unsigned seed, int seg, int rings)
{
    blob b;
    size_t cap = (size_t)(seg * rings + 2) * 160;
    b.text = malloc(cap);
    b.len = 0;
    uint32_t r = seed * 2654435761u + 1;
    double amp[6];
    for (int k = 0; k < 6; k++) {
        r = r * 1664525u + 1013904223u;
        amp[k] = 0.25 * ((double)(r >> 8) / 16777216.0 - 0.5);
    }
    for (int i = 0; i <= rings; i++)
        for (int j = 0; j < (i == 0 || i == rings ? 1 : seg); j++) {
            double th = 3.14159265358979323846 * i / rings, ph = 2 * 3.14159265358979323846 * j / seg;
            double rad = 1.0 + amp[0] * sin(3 * th) + amp[1] * cos(2 * ph) + amp[2] * sin(5 * th + ph) +
                         amp[3] * cos(4 * ph - 2 * th) + amp[4] * sin(7 * ph) * sin(th) + amp[5] * cos(th);
            b.len += (size_t)snprintf(b.text + b.len, cap - b.len, "v %.9g %.9g %.9g\n",
                                      rad * sin(th) * cos(ph), rad * cos(th) * 0.8, rad * sin(th) * sin(ph));
        }
    /* vertex 1 the top, then rings 1..rings-1 of seg each, then the bottom */
    int bottom = 2 + (rings - 1) * seg;
    for (int i = 0; i < rings; i++)
        for (int j = 0; j < seg; j++) {
            int j1 = (j + 1) % seg;
            int a = 2 + (i - 1) * seg + j, b1 = 2 + (i - 1) * seg + j1;
            int c = 2 + i * seg + j, d = 2 + i * seg + j1;
            if (i == 0)
                b.len += (size_t)snprintf(b.text + b.len, cap - b.len, "f 1 %d %d\n", d, c);
            else if (i == rings - 1)
                b.len += (size_t)snprintf(b.text + b.len, cap - b.len, "f %d %d %d\n", a, b1, bottom);
            else
                b.len += (size_t)snprintf(b.text + b.len, cap - b.len, "f %d %d %d %d\n", a, b1, d, c);
        }
    return b;
}

static const char blob_scene[] = "camera eye 0 2.5 6 target 0 0.6 0 fov 45\n"
                                 "light spot pos -5 7 3 target 0 0 0 fov 60 near 1 far 40\n"
                                 "plane size 20 20 divisions 8\n"
                                 "mesh blob.obj scale 1.2 translate 0 1.1 0\n";

static void oracle_blob(void)
{
    blob b = make_blob(7, 160, 80);
    om_loader ld = {blob_load, &b};
    h_scene hs;
    if (h_scene_parse_ld(&hs, blob_scene, &ld)) {
        against_oracle(&hs.s, "deformed sphere", quick() ? 80 : 320, quick() ? 60 : 240);
        h_scene_free(&hs);
    }
    free(b.text);
}

static void oracle_default(void)
{
    oracle_scene(om_scene_default_text(), "default scene", 320, 240);
}

static void oracle_clouds(void)
{
    oracle_scene("camera eye 0 6 9 target 0 1 0 fov 55\n"
                 "light spot pos 4 12 3 target 0 0 0 fov 70 near 1 far 60\n"
                 "plane size 14 14 divisions 4\n"
                 "triangles count 1000 seed 3 area 20 in -4 0.3 -4 4 3 4\n",
                 "random 1K", 320, 240);
    oracle_scene("camera eye 0 6 9 target 0 1 0 fov 55\n"
                 "light directional dir -0.3 -1 -0.5\n"
                 "plane size 14 14 divisions 4\n"
                 "triangles count 10000 seed 4 area 20 in -4 0.3 -4 4 3 4\n",
                 "random 10K", 320, 240);
}

/* ---- surfaces never shadow themselves */

/* Exposed samples that `name` shadows in the scene `text`. */
static uint32_t shadowed(const char *text, const char *name, uint32_t w, uint32_t h)
{
    h_scene hs;
    if (!h_scene_parse(&hs, text)) return UINT32_MAX;
    om_term *terms = malloc(sizeof *terms * w * h);
    uint32_t n = 0;
    CHECK_OK(h_render(&hs.s, name, NULL, w, h, 0, 0, NULL, terms, NULL));
    for (uint32_t i = 0; i < w * h; i++) n += (terms[i].flags & OM_TERM_EXPOSED) && !om_term_lit(&terms[i]);
    free(terms);
    h_scene_free(&hs);
    return n;
}

/* Light from elevation `elev` degrees above a plane through `c` with unit normal n and
 * in-plane direction t, as a spot or a directional light line. */
static void light_line(char *out, size_t cap, bool spot, double elev, dv c, dv n, dv t, double dist)
{
    double e = elev * 3.14159265358979323846 / 180.0;
    dv to = dadd(dscale(n, sin(e)), dscale(t, cos(e)));
    if (spot)
        snprintf(out, cap, "light spot pos %.6f %.6f %.6f target %.6f %.6f %.6f fov 80 near 1 far %.1f\n",
                 c.x + to.x * dist, c.y + to.y * dist, c.z + to.z * dist, c.x, c.y, c.z, dist * 3);
    else
        snprintf(out, cap, "light directional dir %.6f %.6f %.6f\n", -to.x, -to.y, -to.z);
}

static const double elevations[] = {90, 30, 5, 1};

static void planes_never_self_shadow(void)
{
    static const int divs[] = {1, 2, 7, 32, 256};
    char text[1024], light[256];
    /* a plane tilted by 23 degrees about z: normal (-sin, cos, 0), in-plane (cos, sin, 0);
     * the light comes in along the in-plane direction turned by 30 degrees about n */
    const double tilt = 23.0 * 3.14159265358979323846 / 180.0;
    for (int r = 0; r < 2; r++) {
        dv n = r ? (dv){-sin(tilt), cos(tilt), 0} : (dv){0, 1, 0};
        dv t1 = r ? (dv){cos(tilt), sin(tilt), 0} : (dv){1, 0, 0}, t2 = {0, 0, 1};
        dv t = dadd(dscale(t1, cos(0.5236)), dscale(t2, sin(0.5236)));
        dv c = {0, 0, 0};
        for (int k = 0; k < (int)(sizeof divs / sizeof divs[0]); k++)
            for (int e = 0; e < 4; e++)
                for (int spot = 0; spot < 2; spot++) {
                    if (quick() && (divs[k] == 256 || e == 1)) continue;
                    light_line(light, sizeof light, spot, elevations[e], c, n, t, 40);
                    snprintf(text, sizeof text,
                             "camera eye %.4f %.4f %.4f target 0 0 0 fov 60\n%s"
                             "plane size 20 14 divisions %d rotate 0 0 %d\n",
                             n.x * 8 - t1.x * 3, n.y * 8 - t1.y * 3, 9.0, light, divs[k], r ? 23 : 0);
                    for (int m = 0; m < 2; m++) {
                        uint32_t k0 = shadowed(text, m ? "izb" : "ref", 160, 120);
                        CHECK_MSG(k0 == 0, "%s: plane divisions %d tilt %d, %s light at %g degrees: %u "
                                  "samples shadowed", m ? "izb" : "ref", divs[k], r ? 23 : 0,
                                  spot ? "spot" : "directional", elevations[e], k0);
                    }
                }
    }
    /* the faces of a lone box, each two coplanar triangles */
    for (int e = 0; e < 4; e++) {
        light_line(light, sizeof light, true, elevations[e], (dv){0, 0, 0}, (dv){0, 1, 0},
                   dnorm((dv){1, 0, 0.4}), 40);
        snprintf(text, sizeof text, "camera eye 6 5 9 target 0 0 0 fov 50\n%s"
                 "box size 6 2 4 rotate 10 35 0\n", light);
        uint32_t k0 = shadowed(text, "ref", 160, 120);
        CHECK_MSG(k0 == 0, "box faces, light at %g degrees: %u samples shadowed", elevations[e], k0);
    }
}

/* A quad-meshed OBJ on a plane at no simple angle: its triangles come from fanning
 * quads, its coordinates are decimal text, and it is lit at a grazing angle. */
static void quad_mesh_never_self_shadows(void)
{
    size_t cap = 40 * 40 * 64 + 64 * 1024;
    char *obj = malloc(cap);
    size_t len = 0;
    for (int j = 0; j <= 40; j++)
        for (int i = 0; i <= 40; i++) {
            double x = i * 0.25 - 5, z = j * 0.25 - 5;
            len += (size_t)snprintf(obj + len, cap - len, "v %.7f %.7f %.7f\n", x, 0.31 * x - 0.17 * z, z);
        }
    for (int j = 0; j < 40; j++)
        for (int i = 0; i < 40; i++) {
            int a = j * 41 + i + 1;
            len += (size_t)snprintf(obj + len, cap - len, "f %d %d %d %d\n", a, a + 41, a + 42, a + 1);
        }
    blob b = {obj, len};
    om_loader ld = {blob_load, &b};
    /* the plane's normal is (-0.31, 1, 0.17) normalised */
    dv n = dnorm((dv){-0.31, 1, 0.17}), t = dnorm(dcross(n, (dv){0, 0, 1}));
    for (int e = 0; e < 4; e++)
        for (int spot = 0; spot < 2; spot++) {
            char text[512], light[256];
            light_line(light, sizeof light, spot, elevations[e], (dv){0, 0, 0}, n, t, 30);
            snprintf(text, sizeof text, "camera eye 1 7 8 target 0 0 0 fov 60\n%smesh blob.obj\n", light);
            h_scene hs;
            if (!h_scene_parse_ld(&hs, text, &ld)) continue;
            om_term terms[160 * 120];
            CHECK_OK(h_render(&hs.s, "ref", NULL, 160, 120, 0, 0, NULL, terms, NULL));
            uint32_t k0 = 0, lit = 0;
            for (uint32_t i = 0; i < 160 * 120; i++) {
                k0 += (terms[i].flags & OM_TERM_EXPOSED) && !om_term_lit(&terms[i]);
                lit += om_term_lit(&terms[i]);
            }
            CHECK_MSG(k0 == 0 && lit > 1000, "quad mesh, %s light at %g degrees: %u shadowed, %u lit",
                      spot ? "spot" : "directional", elevations[e], k0, lit);
            h_scene_free(&hs);
        }
    free(obj);
}

/* Lone spheres and cylinders: nothing on their lit side is shadowed. */
static void convex_lit_side(void)
{
    static const int segs[] = {8, 32, 128, 512, 1024};
    for (int k = 0; k < 5; k++)
        for (int e = 0; e < 4; e++) {
            if (quick() && (segs[k] > 128 || e == 1)) continue;
            char text[512], light[256];
            light_line(light, sizeof light, e & 1, elevations[e], (dv){0, 0, 0}, (dv){0, 1, 0},
                       dnorm((dv){0.3, 0, 1}), 20);
            snprintf(text, sizeof text, "camera eye 1 1.5 3.5 target 0 0 0 fov 50\n%s"
                     "sphere radius 1 segments %d rings %d rotate 20 0 10\n", light, segs[k],
                     segs[k] > 64 ? 32 : segs[k] / 2);
            uint32_t k0 = shadowed(text, "ref", 160, 120);
            CHECK_MSG(k0 == 0, "sphere of %d segments, light at %g degrees: %u samples shadowed",
                      segs[k], elevations[e], k0);
            snprintf(text, sizeof text, "camera eye 1 2 4 target 0 0.6 0 fov 50\n%s"
                     "cylinder radius 0.7 height 1.5 segments %d rotate 0 0 15\n", light, segs[k]);
            k0 = shadowed(text, "ref", 160, 120);
            CHECK_MSG(k0 == 0, "cylinder of %d segments, light at %g degrees: %u samples shadowed",
                      segs[k], elevations[e], k0);
        }
}

/* ---- exact wherever the scene sits
 *
 * The oracle's scenes moved far from the origin and scaled, a sweep of lone spheres,
 * and the eye pass's points on slivers seen at grazing angles: no disagreement the
 * oracle cannot explain at any offset up to 1e5 or scale; a moved scene's mask that of
 * its own float geometry at the origin; no lone sphere's lit side shadowed; every
 * sample's point within 1/256 px of its pixel's ray, on its own triangle. */

typedef struct sbuf { char *p; size_t len, cap; } sbuf;

static void sb_put(sbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (b->len + (size_t)n + 1 > b->cap) {
        b->cap = (b->len + (size_t)n + 1) * 2;
        b->p = realloc(b->p, b->cap);
    }
    va_start(ap, fmt);
    vsnprintf(b->p + b->len, b->cap - b->len, fmt, ap);
    va_end(ap);
    b->len += (size_t)n;
}

static bool numlike(const char *t) { return (*t >= '0' && *t <= '9') || *t == '-' || *t == '+' || *t == '.'; }

/* Scene text moved as a whole: every position p becomes k p + (off, off, off) (the
 * camera's eye and target, a spot light's pos and target, their keys, each object's
 * translate), and every length scales by k: each object's scale (an object is scaled,
 * rotated, then translated, so k S and k T + off move it as one piece about the
 * origin) and the near and far planes, written out where the line left the defaults.
 * Directions, fields of view and image sizes stay; comments go. Returns malloc'd text. */
static char *moved(const char *text, double k, double off)
{
    static const char *const shapes[] = {"plane", "box", "sphere", "cylinder", "mesh", "triangles"};
    sbuf b = {NULL, 0, 0};
    sb_put(&b, "");
    for (const char *line = text; *line;) {
        const char *end = strchr(line, '\n');
        if (!end) end = line + strlen(line);
        const char *hash = memchr(line, '#', (size_t)(end - line));
        char buf[1024], *tok[64];
        size_t n = (size_t)((hash ? hash : end) - line);
        int nt = 0;
        CHECK(n < sizeof buf);
        if (n >= sizeof buf) n = sizeof buf - 1;
        memcpy(buf, line, n);
        buf[n] = 0;
        line = *end ? end + 1 : end;
        for (char *t = strtok(buf, " \t\r"); t && nt < 64; t = strtok(NULL, " \t\r")) tok[nt++] = t;
        if (!nt) continue;
        bool cam = !strcmp(tok[0], "camera"), spot = !strcmp(tok[0], "light") && nt > 1 && !strcmp(tok[1], "spot");
        bool shape = false, scaled = false, placed = false, near = false, far = false;
        for (size_t s = 0; s < sizeof shapes / sizeof shapes[0]; s++) shape |= !strcmp(tok[0], shapes[s]);
        for (int i = 0; i < nt; i++) {
            const char *t = tok[i];
            sb_put(&b, "%s%s", i ? " " : "", t);
            if (!strcmp(t, "eye") || !strcmp(t, "target") || !strcmp(t, "pos") || !strcmp(t, "translate")) {
                placed |= !strcmp(t, "translate");
                for (int c = 0; c < 3 && i + 1 < nt; c++) sb_put(&b, " %.17g", strtod(tok[++i], NULL) * k + off);
            } else if (shape && !strcmp(t, "scale")) {
                scaled = true;
                while (i + 1 < nt && numlike(tok[i + 1])) sb_put(&b, " %.17g", strtod(tok[++i], NULL) * k);
            } else if ((cam || spot) && (!strcmp(t, "near") || !strcmp(t, "far")) && i + 1 < nt) {
                near |= t[0] == 'n';
                far |= t[0] == 'f';
                sb_put(&b, " %.17g", strtod(tok[++i], NULL) * k);
            }
        }
        if ((cam || spot) && k != 1.0) {
            if (!near) sb_put(&b, " near %.17g", (cam ? 0.1 : 0.5) * k);   /* FORMAT.md's defaults */
            if (!far) sb_put(&b, " far %.17g", 1000.0 * k);
        }
        if (shape && !scaled && k != 1.0) sb_put(&b, " scale %.17g", k);
        if (shape && !placed && off != 0.0) sb_put(&b, " translate %.17g %.17g %.17g", off, off, off);
        sb_put(&b, "\n");
    }
    return b.p;
}

static void moved_name(char *out, size_t cap, const char *what, double k, double off)
{
    if (off != 0.0) snprintf(out, cap, "%s at %g", what, off);
    else if (k != 1.0) snprintf(out, cap, "%s x%g", what, k);
    else snprintf(out, cap, "%s", what);
}

/* The oracle on scene `text` moved by k and off (moved()). */
static tally oracle_moved(const char *text, const om_loader *ld, const char *what, double k, double off,
                          uint32_t w, uint32_t h)
{
    char name[96], *t = moved(text, k, off);
    tally n;
    h_scene hs;
    memset(&n, 0, sizeof n);
    moved_name(name, sizeof name, what, k, off);
    if (quick()) { w /= 4; h /= 4; }
    if (h_scene_parse_ld(&hs, t, ld)) {
        n = against_oracle(&hs.s, name, w, h);
        h_scene_free(&hs);
    }
    free(t);
    return n;
}

/* 1e2 and 3e3 besides 1e3, 1e4 and 1e5: where the figures start to move. */
static const double offsets[] = {1e2, 1e3, 3e3, 1e4, 1e5};
#define NOFFSETS (sizeof offsets / sizeof offsets[0])

/* The default scene and the deformed sphere on its floor, moved by (d, d, d). Where
 * the engine's snapping bound grows with the coordinates' size, ref lights samples
 * the oracle finds shadowed by a blocker a few hundredths of a unit away (1e3) to a
 * few units (1e5); those are "other". As in oracle_scaled, the quick mode leaves the
 * deformed sphere out. */
static void oracle_far(void)
{
    blob b = make_blob(7, 160, 80);
    om_loader ld = {blob_load, &b};
    for (size_t i = 0; i < NOFFSETS; i++) {
        oracle_moved(om_scene_default_text(), NULL, "default", 1.0, offsets[i], 320, 240);
        if (!quick()) oracle_moved(blob_scene, &ld, "deformed sphere", 1.0, offsets[i], 320, 240);
    }
    free(b.text);
}

/* The same scenes scaled about the origin: shapes, camera, light, near and far. The
 * engine meets this one already. Scaled by a power of ten, the deformed sphere's float
 * vertices are not the origin's scaled, and one eye-pass disagreement moves into view:
 * at the quick mode's 80x60 that one alone is beyond the 0.005% share, so the quick
 * mode leaves the deformed sphere out. */
static void oracle_scaled(void)
{
    static const double scales[] = {0.001, 1000.0};
    blob b = make_blob(7, 160, 80);
    om_loader ld = {blob_load, &b};
    for (int i = 0; i < 2; i++) {
        oracle_moved(om_scene_default_text(), NULL, "default", scales[i], 0.0, 320, 240);
        if (!quick()) oracle_moved(blob_scene, &ld, "deformed sphere", scales[i], 0.0, 320, 240);
    }
    free(b.text);
}

/* Scene s brought back by -off as text: its camera and light at time 0 and one mesh,
 * blob.obj (its text in *obj), of its float vertices less off. Near off the vertices
 * are multiples of off's float spacing, so less off they are floats still, and exact:
 * the same float geometry at the origin, where the engine is known to be exact. */
static char *back_to_origin(const om_scene *s, double off, blob *obj)
{
    sbuf t = {NULL, 0, 0}, m = {NULL, 0, 0};
    om_camera c;
    om_light l;
    om_scene_at(s, 0.0f, &c, &l);
    sb_put(&t, "camera eye %.17g %.17g %.17g target %.17g %.17g %.17g up %.17g %.17g %.17g fov %.17g near %.17g "
           "far %.17g\n", c.eye.x - off, c.eye.y - off, c.eye.z - off, c.target.x - off, c.target.y - off,
           c.target.z - off, c.up.x, c.up.y, c.up.z, c.fovy_deg, c.znear, c.zfar);
    if (l.kind == OM_LIGHT_SPOT)
        sb_put(&t, "light spot pos %.17g %.17g %.17g target %.17g %.17g %.17g fov %.17g near %.17g far %.17g\n",
               l.pos.x - off, l.pos.y - off, l.pos.z - off, l.target.x - off, l.target.y - off, l.target.z - off,
               l.fov_deg, l.znear, l.zfar);
    else
        sb_put(&t, "light directional dir %.17g %.17g %.17g\n", l.dir.x, l.dir.y, l.dir.z);
    sb_put(&t, "mesh blob.obj\n");
    for (uint32_t v = 0; v < s->nverts; v++) {
        dv p = dsub(fv(s->verts[v]), (dv){off, off, off});
        CHECK(p.x == (float)p.x && p.y == (float)p.y && p.z == (float)p.z);
        sb_put(&m, "v %.17g %.17g %.17g\n", p.x, p.y, p.z);
    }
    for (uint32_t f = 0; f < s->ntris; f++)
        sb_put(&m, "f %u %u %u\n", s->idx[3 * f] + 1, s->idx[3 * f + 1] + 1, s->idx[3 * f + 2] + 1);
    obj->text = m.p;
    obj->len = m.len;
    return t.p;
}

/* Which samples `ref` lights: 1 lit, 0 not (covered), 2 background. Returns the
 * covered count. With `back`, *back receives the scene brought back by -off
 * (back_to_origin). */
static uint32_t ref_mask(const char *text, const om_loader *ld, uint32_t w, uint32_t h, uint8_t *m, double off,
                         char **back, blob *obj)
{
    h_scene hs;
    uint32_t covered = 0;
    memset(m, 2, (size_t)w * h);
    if (!h_scene_parse_ld(&hs, text, ld)) return 0;
    if (back) *back = back_to_origin(&hs.s, off, obj);
    om_term *terms = malloc(sizeof *terms * w * h);
    om_sample *smp = malloc(sizeof *smp * w * h);
    CHECK_OK(h_render(&hs.s, "ref", NULL, w, h, 0, 0, NULL, terms, smp));
    for (uint32_t i = 0; i < w * h; i++) {
        if (smp[i].tri == OM_NO_TRI) continue;
        covered++;
        m[i] = om_term_lit(&terms[i]);
    }
    free(terms);
    free(smp);
    h_scene_free(&hs);
    return covered;
}

static uint32_t mask_differ(const uint8_t *a, const uint8_t *b, uint32_t n)
{
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++) k += (a[i] == 1) != (b[i] == 1);
    return k;
}

/* A moved scene's mask against its own float geometry brought back to the origin
 * (back_to_origin): the same, at every offset, since the frame works relative to an
 * origin that follows the light (om_view). Alongside, not asserted: the moved scene
 * against the origin's, which also holds what the rounding of the vertices to float
 * far out changes (the 0.02% at 1e4 is below what that rounding alone makes:
 * 0.037% on the default scene and 0.082% on the deformed sphere at 640x480). */
static void mask_far(void)
{
    const uint32_t w = quick() ? 160 : 640, h = quick() ? 120 : 480;
    blob b = make_blob(7, 160, 80), back_obj;
    om_loader ld = {blob_load, &b}, back_ld = {blob_load, &back_obj};
    const char *texts[2] = {om_scene_default_text(), blob_scene};
    const char *names[2] = {"default", "deformed sphere"};
    uint8_t *m0 = malloc((size_t)w * h), *m1 = malloc((size_t)w * h), *mb = malloc((size_t)w * h);
    for (int s = 0; s < 2; s++) {
        char *back;
        uint32_t covered = ref_mask(texts[s], s ? &ld : NULL, w, h, m0, 0.0, &back, &back_obj);
        /* the origin scene as one mesh: the same mask, or the comparisons below mean little */
        ref_mask(back, &back_ld, w, h, mb, 0.0, NULL, NULL);
        uint32_t same = mask_differ(m0, mb, w * h);
        CHECK_MSG(same == 0, "%s as one mesh: %u samples lit differently", names[s], same);
        free(back);
        free(back_obj.text);
        for (size_t i = 0; i < NOFFSETS; i++) {
            char *t = moved(texts[s], 1.0, offsets[i]);
            ref_mask(t, s ? &ld : NULL, w, h, m1, offsets[i], &back, &back_obj);
            free(t);
            ref_mask(back, &back_ld, w, h, mb, 0.0, NULL, NULL);
            free(back);
            free(back_obj.text);
            uint32_t differ = mask_differ(m0, m1, w * h), floor = mask_differ(m0, mb, w * h);
            uint32_t own = mask_differ(mb, m1, w * h);
            double share = covered ? (double)differ / covered : 1.0;
            printf("  mask %-15s at %-6g %ux%u: %5u of %u covered samples lit differently from the origin's "
                   "(%.4f%%); its float geometry at the origin: %u (%.4f%%); it against that: %u (%.4f%%)\n",
                   names[s], offsets[i], w, h, differ, covered, 100.0 * share, floor,
                   covered ? 100.0 * floor / covered : 0.0, own, covered ? 100.0 * own / covered : 0.0);
            CHECK_MSG(own == 0, "%s at %g: %u of %u covered samples lit differently from its float geometry "
                      "at the origin", names[s], offsets[i], own, covered);
        }
    }
    free(m0);
    free(m1);
    free(mb);
    free(b.text);
}

/* ---- lone spheres at many rotations */

static uint32_t lcg(uint32_t *r)
{
    *r = *r * 1664525u + 1013904223u;
    return *r >> 8;
}

/* 8 segment counts x 13 rotations x spot and directional: 208 lone spheres, each lit
 * from a different direction and seen from near it, with 16 rings, half the
 * segments (at most 256) or an eighth, at 160x120. Nothing on a lone convex solid's
 * lit side is shadowed. The first spot-lit sphere of 256 segments is the case known
 * to fail: `sphere radius 1 segments 256 rotate 13 29 41` under `light spot pos 4 8 5
 * target 0 0 0 fov 40`, seen from 2 2 3 (1 sample shadowed at 160x120, 2 at 640x480). */
static void sphere_sweep(void)
{
    static const int segs[] = {8, 16, 32, 64, 128, 256, 512, 1024};
    const int rots = quick() ? 3 : 13;
    const uint32_t w = quick() ? 80 : 160, h = quick() ? 60 : 120;
    uint32_t rng = 50;
    for (int k = 0; k < 8; k++) {
        uint32_t spheres = 0, bad = 0, samples = 0, bad_spot = 0;
        for (int c = 0; c < rots; c++)
            for (int spot = 1; spot >= 0; spot--) {
                int rx = (int)(lcg(&rng) % 360), ry = (int)(lcg(&rng) % 360), rz = (int)(lcg(&rng) % 360);
                int rings = c % 3 == 0 ? 16 : c % 3 == 1 ? (segs[k] / 2 < 256 ? segs[k] / 2 : 256)
                                                          : (segs[k] / 8 > 2 ? segs[k] / 8 : 2);
                /* the light from azimuth az, elevation el; the camera 40 degrees round
                 * from it, at most 60 degrees up or down */
                double az = (double)(lcg(&rng) % 3600) / 10.0, el = (double)(lcg(&rng) % 1400) / 10.0 - 60.0;
                double dist = 3.0 + (double)(lcg(&rng) % 1700) / 100.0, r = 3.14159265358979323846 / 180.0;
                double ce = el > 60 ? 60 : el;
                dv L = {cos(el * r) * cos(az * r), sin(el * r), cos(el * r) * sin(az * r)};
                dv C = {cos(ce * r) * cos((az + 40) * r), sin(ce * r), cos(ce * r) * sin((az + 40) * r)};
                char light[256], text[512];
                if (spot)
                    snprintf(light, sizeof light, "light spot pos %.6f %.6f %.6f target 0 0 0 fov %.3f near %.3f "
                             "far %.3f\n", L.x * dist, L.y * dist, L.z * dist,
                             2.0 * asin(1.0 / dist) / r + 10.0, dist * 0.25, dist * 3.0);
                else
                    snprintf(light, sizeof light, "light directional dir %.6f %.6f %.6f\n", -L.x, -L.y, -L.z);
                snprintf(text, sizeof text, "camera eye %.6f %.6f %.6f target 0 0 0 fov 45\n%s"
                         "sphere radius 1 segments %d rings %d rotate %d %d %d\n", C.x * 4, C.y * 4, C.z * 4,
                         light, segs[k], rings, rx, ry, rz);
                if (c == 0 && spot && segs[k] == 256)   /* the case that was known to fail */
                    snprintf(text, sizeof text, "camera eye 2 2 3 target 0 0 0\n"
                             "light spot pos 4 8 5 target 0 0 0 fov 40\n"
                             "sphere radius 1 segments 256 rotate 13 29 41\n");
                uint32_t n = shadowed(text, "ref", w, h);
                spheres++;
                if (n == 0) continue;
                bad++;
                bad_spot += (uint32_t)spot;
                samples += n;
                fprintf(stderr, "  sphere of %d segments, %s light: %u samples shadowed on its lit side in\n%s",
                        segs[k], spot ? "spot" : "directional", n, text);
            }
        printf("  sphere sweep, %4d segments: %u spheres, %u with lit-side samples shadowed (%u spot, %u "
               "directional; %u samples)\n", segs[k], spheres, bad, bad_spot, bad - bad_spot, samples);
        CHECK_MSG(bad == 0, "%d segments: %u of %u lone spheres shadow %u samples on their lit side (the "
                  "scenes above)", segs[k], bad, spheres, samples);
    }
}

/* ---- the eye pass's points */

/* The point of triangle abc nearest p (Ericson, Real-Time Collision Detection 5.1.5). */
static dv nearest_on_tri(dv p, dv a, dv b, dv c)
{
    dv ab = dsub(b, a), ac = dsub(c, a), ap = dsub(p, a);
    double d1 = ddot(ab, ap), d2 = ddot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    dv bp = dsub(p, b);
    double d3 = ddot(ab, bp), d4 = ddot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return dadd(a, dscale(ab, d1 / (d1 - d3)));
    dv cp = dsub(p, c);
    double d5 = ddot(ab, cp), d6 = ddot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return dadd(a, dscale(ac, d2 / (d2 - d6)));
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
        return dadd(b, dscale(dsub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    double den = 1.0 / (va + vb + vc);
    return dadd(a, dadd(dscale(ab, vb * den), dscale(ac, vc * den)));
}

static double maxabs(dv a)
{
    double m = fabs(a.x) > fabs(a.y) ? fabs(a.x) : fabs(a.y);
    return fabs(a.z) > m ? fabs(a.z) : m;
}

typedef struct ptally { uint32_t covered, off_ray, outside; double ray_px, out_px, out; } ptally;

/* Every covered sample's point: within 1/256 px of the ray through its pixel's centre
 * (the distance from the ray over one pixel's size at the point's depth), and on its
 * own triangle, edges included, to within the rounding of a point made in float from
 * its triangle's vertices: 16 units of 2^-24 on the largest coordinate of the point and
 * the vertices, as the frame holds them (relative to its origin). The distance outside
 * the triangle is also given in pixels at the point's depth; where the surface is seen
 * at a grazing angle, a point a small part of a pixel beside its triangle on screen is
 * many pixels from it along the surface. */
static ptally sample_points(const char *text, const om_loader *ld, const char *what, uint32_t w, uint32_t h)
{
    ptally n;
    h_scene hs;
    memset(&n, 0, sizeof n);
    if (quick()) { w /= 4; h /= 4; }
    if (!h_scene_parse_ld(&hs, text, ld)) return n;
    const om_scene *s = &hs.s;
    om_sample *smp = malloc(sizeof *smp * w * h);
    CHECK_OK(h_render(s, "none", NULL, w, h, 0, 0, NULL, NULL, smp));
    oracle o;
    oracle_view(&o, s, w, h);
    for (uint32_t i = 0; i < w * h; i++) {
        uint32_t t = smp[i].tri;
        if (t == OM_NO_TRI) continue;
        n.covered++;
        pray r = pixel_ray(&o, i % w, i / w);
        dv p = smp_world(&o, &smp[i]), q = dsub(p, r.eye), dn = dnorm(r.d);
        double pix = ddot(q, r.f) * r.pix;   /* one pixel at the point's depth */
        dv off = dsub(q, dscale(dn, ddot(q, dn)));
        double ray = pix > 0.0 ? sqrt(ddot(off, off)) / pix : INFINITY;
        dv a = vert(s, t, 0), b = vert(s, t, 1), c = vert(s, t, 2), e = dsub(p, nearest_on_tri(p, a, b, c));
        double out = sqrt(ddot(e, e)), big = maxabs(dsub(p, o.origin));
        dv va = dsub(a, o.origin), vb = dsub(b, o.origin), vc = dsub(c, o.origin);
        if (maxabs(va) > big) big = maxabs(va);
        if (maxabs(vb) > big) big = maxabs(vb);
        if (maxabs(vc) > big) big = maxabs(vc);
        double slack = big * (16.0 / 16777216.0), out_px = pix > 0.0 ? out / pix : INFINITY;
        bool far_ray = !(ray <= 1.0 / 256.0), off_tri = !(out <= slack);
        if (!(ray <= n.ray_px)) n.ray_px = ray;
        if (!(out_px <= n.out_px)) n.out_px = out_px;
        if (!(out <= n.out)) n.out = out;
        n.off_ray += far_ray;
        n.outside += off_tri;
        if ((far_ray || off_tri) && n.off_ray + n.outside <= 3)
            fprintf(stderr, "  %s: pixel (%u,%u) tri %u: %.5f px off its ray, %.3g px outside its triangle "
                    "(rounding %.3g px)\n", what, i % w, i / w, t, ray, out_px, slack / pix);
    }
    printf("  points %-22s %ux%u: %u covered; off the ray by up to %.5f px, %u beyond 1/256; outside their "
           "triangle by up to %.3g px (%.3g units), %u beyond rounding\n", what, w, h, n.covered, n.ray_px,
           n.off_ray, n.out_px, n.out, n.outside);
    CHECK_MSG(n.off_ray == 0, "%s: %u of %u points more than 1/256 px off their pixel's ray (up to %.5f px)",
              what, n.off_ray, n.covered, n.ray_px);
    CHECK_MSG(n.outside == 0, "%s: %u of %u points outside their own triangle (up to %.3g px, %.3g units)",
              what, n.outside, n.covered, n.out_px, n.out);
    free(smp);
    h_scene_free(&hs);
    return n;
}

/* Tiny and thin triangles at grazing angles: a random cloud of 100K over a floor seen
 * from just above it, spheres of 1024 segments (tiny facets; slivers at the poles with
 * 16 rings), a wide floor to the horizon; and the default scene far out. */
static void sliver_points(void)
{
    static const char cloud[] = "camera eye 0 0.4 12 target 0 0.3 0 fov 55\n"
                                "light spot pos 4 12 3 target 0 0 0 fov 70 near 1 far 60\n"
                                "plane size 14 14 divisions 4\n"
                                "triangles count 100000 seed 5 area 20 in -4 0.3 -4 4 3 4\n";
    sample_points(cloud, NULL, "random 100K", 320, 240);
    sample_points("camera eye 0.3 0.2 2.6 target 0 0 0 fov 50\nsphere radius 1 segments 1024 rings 512\n", NULL,
                  "sphere 1024x512", 320, 240);
    sample_points("camera eye 0.3 2.2 1.6 target 0 0 0 fov 50\n"
                  "sphere radius 1 segments 1024 rings 16 rotate 13 29 41\n", NULL, "sphere 1024x16", 320, 240);
    sample_points("camera eye 0 0.3 0 target 0 0 -100 fov 60\nplane size 2000 2000 divisions 64\n", NULL,
                  "floor to the horizon", 320, 240);
    sample_points(om_scene_default_text(), NULL, "default", 320, 240);
    for (size_t i = 3; i < NOFFSETS; i++) {
        char name[64], *t = moved(om_scene_default_text(), 1.0, offsets[i]);
        moved_name(name, sizeof name, "default", 1.0, offsets[i]);
        sample_points(t, NULL, name, 320, 240);
        free(t);
        t = moved(cloud, 1.0, offsets[i]);
        moved_name(name, sizeof name, "random 100K", 1.0, offsets[i]);
        sample_points(t, NULL, name, 320, 240);
        free(t);
    }
}

void suite_oracle(void)
{
    RUN(planes_never_self_shadow);
    RUN(quad_mesh_never_self_shadows);
    RUN(convex_lit_side);
    RUN(oracle_floor);
    RUN(oracle_curved);
    RUN(oracle_blob);
    RUN(oracle_default);
    RUN(oracle_clouds);
    RUN(oracle_far);
    RUN(oracle_scaled);
    RUN(mask_far);
    RUN(sphere_sweep);
    RUN(sliver_points);
}
