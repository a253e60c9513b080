/* property/oracle.h — the independent oracle of oracle.c, shared with oracle_far.c:
 * double-precision vectors, the oracle (the scene's triangles binned on the light's
 * view), the tally of its disagreements with `ref`, and the deformed-sphere OBJ. */
#ifndef OMBRA_TEST_ORACLE_H
#define OMBRA_TEST_ORACLE_H

#include "../test.h"
#include "../harness.h"

#include <math.h>

typedef struct dv { double x, y, z; } dv;

static inline dv dsub(dv a, dv b) { dv r = {a.x - b.x, a.y - b.y, a.z - b.z}; return r; }
static inline dv dcross(dv a, dv b)
{
    dv r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return r;
}
static inline double ddot(dv a, dv b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline dv dscale(dv a, double k) { dv r = {a.x * k, a.y * k, a.z * k}; return r; }
static inline dv dadd(dv a, dv b) { dv r = {a.x + b.x, a.y + b.y, a.z + b.z}; return r; }
static inline dv dnorm(dv a) { return dscale(a, 1.0 / sqrt(ddot(a, a))); }
static inline dv fv(om_vec3 v) { dv r = {v.x, v.y, v.z}; return r; }
static inline dv vert(const om_scene *s, uint32_t t, int k) { return fv(s->verts[s->idx[(size_t)t * 3 + k]]); }

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

typedef struct pray { dv eye, d, f; double pix; } pray;

typedef struct tally { uint32_t covered, exposed, differ, eye, tie, edge_on, data, other, other_lit; } tally;

/* A seeded, deformed sphere as an OBJ: a closed mesh with irregular facets, concave and
 * convex, the way a scanned model is. */
typedef struct blob { char *text; size_t len; } blob;


void oracle_view(oracle *o, const om_scene *s, uint32_t w, uint32_t h);
dv smp_world(const oracle *o, const om_sample *smp);
/* The exact ray through pixel (x, y)'s centre. */
pray pixel_ray(const oracle *o, uint32_t x, uint32_t y);
/* Renders `ref` at w x h and holds every exposed sample against the oracle. */
tally against_oracle(const om_scene *s, const char *what, uint32_t w, uint32_t h);
/* OM_TEST_QUICK: smaller images, for memory checkers' runs. */
bool oracle_quick(void);
om_status blob_load(void *user, const char *name, const char **data, size_t *len);
blob make_blob(unsigned seed, int seg, int rings);
extern const char blob_scene[];

#endif
