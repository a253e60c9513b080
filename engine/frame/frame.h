/* frame.h — engine-internal pieces of a frame: the eye pass that turns a strip of the
 * image into visible samples, the geometric part of the lit rule, and shading. */
#ifndef OM_FRAME_H
#define OM_FRAME_H

#include "../core/core.h"
#include "../raster/raster.h"
#include "../raster/scene_raster.h"

#include <string.h>
#include <math.h>

/* OM_WITH_JOBS (0 or 1): whether the engine carries the code that runs a frame on the
 * host's threads (bands, om__bands). 1 by default, but 0 on Cortex-M cores (ACLE's
 * __ARM_ARCH_PROFILE 'M': one core), so that a firmware carries none of it; a frame
 * then runs inline whatever parallel-for it is handed, and om_frame_bytes_jobs is 0.
 * The same frames either way. */
#ifndef OM_WITH_JOBS
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
#define OM_WITH_JOBS 0
#else
#define OM_WITH_JOBS 1
#endif
#endif

/* Renders rows [st->y0, st->y0 + st->rows) of the camera view into `tg` (depth and
 * triangle id, strip-sized) and resolves st->samples: the exact point of the visible
 * triangle under each pixel centre, by perspective-correct barycentrics. `bins` may be
 * NULL (every triangle is walked) or om__bins_make's for this view. */
void om__eye_pass(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st,
                  const om__bins *bins);

/* The exact point of a triangle under an image position, by perspective-correct
 * barycentrics in homogeneous clip space (no division by w, so triangles crossing the
 * viewer's plane need no special case). Set up once per triangle, then evaluated at
 * NDC positions (sx, sy) of the image that `vp` projects onto. */
typedef struct om__persp_tri {
    uint32_t tri;
    float adj[9];          /* adjugate of the 3x3 matrix of (x, y, w) columns */
    om_vec3 v[3], d1, d2;  /* world vertices, v1 - v0 and v2 - v0 */
    om_vec3 n;             /* the unit geometric normal */
} om__persp_tri;

void om__persp_setup(const om_scene *s, const om_mat4 *vp, uint32_t t, om__persp_tri *c);
om_vec3 om__persp_point(const om__persp_tri *c, float sx, float sy);

/* The same for om__eye_pass_mark: the eye pass with the exposure marks of each
 * covered pixel (st->terms, as om__exposed sets them) in the same loop, while the
 * pixel's point and its triangle's normal are at hand. */
void om__eye_pass_mark(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st,
                       const om__bins *bins);

/* The second half of the eye pass alone: the samples of st's rows (with `mark`, their
 * exposure marks too) from the triangle ids already in tg->id (tg->depth unread), as
 * om__eye_pass(_mark) gives them after rasterizing. */
void om__eye_resolve(const om_scene *s, const om_view *v, const om_target *tg, om_strip *st, bool mark);
/* The eye pass's rasterization alone, of the scene's triangles [t0, t1) into tg,
 * cleared before (om__scene_raster_part: the parts merged by depth, then
 * om__eye_resolve). */
void om__eye_raster_part(const om_scene *s, const om_view *v, const om_target *tg, uint32_t t0, uint32_t t1);

/* Direction from a point towards the light (unit). */
om_vec3 om__to_light(const om_view *v, om_vec3 p);

/* The unit direction from p towards a point light at `pos`: the operations of
 * om__normalize, in its order, so the same bits. */
static inline om_vec3 om__to_point(om_vec3 pos, om_vec3 p)
{
    const om_vec3 a = om__sub(pos, p);
    const float l2 = om__dot(a, a);
    if (!(l2 > 0.0f)) return om__v3(0, 0, 0);
    return om__scale(a, 1.0f / om__sqrtf(l2));
}

/* om__to_light in line (the exposure marks run it for every covered pixel). */
static inline om_vec3 om__to_light_in(const om_view *v, om_vec3 p)
{
    if (v->light.kind == OM_LIGHT_DIRECTIONAL) return om__scale(v->light_axis, -1.0f);
    return om__to_point(v->light.pos, p);
}

/* The parts of the lit rule that no occluder decides, the same for every method:
 * the normal turned towards the camera faces the light, and the point p (with the
 * normal n, as wound) lies inside the light's frustum. *nl: the cosine between them
 * where exposed, else 0. */
static inline bool om__exposed_at(const om_view *v, om_vec3 p, om_vec3 n, float *nl)
{
    *nl = 0.0f;
    if (om__dot(n, om__sub(v->cam.eye, p)) < 0.0f) n = om__scale(n, -1.0f);
    const float c = om__dot(n, om__to_light_in(v, p));
    if (!(c > 0.0f)) return false;
    /* inside the frustum: -w <= x <= w is |x| <= w (both false for a NaN) */
    const om_vec4 q = om__mat_apply(&v->light_vp, p);
    if (!(q.w > 0.0f && om__fabsf(q.x) <= q.w && om__fabsf(q.y) <= q.w && q.z >= 0.0f && q.z <= q.w))
        return false;
    *nl = c;   /* the lookups and shading read it rather than work it out again */
    return true;
}

/* om__exposed_at for a sample; sets smp->nl. */
bool om__exposed(const om_view *v, om_sample *smp);

/* A method's resolve by bands (frame.c runs them at once on the host's threads): the
 * built-in methods whose resolve only reads the state after build. resolve writes the
 * band's terms (the same as the method's own resolve) and touches nothing else but
 * its job's `scratch` (`scratch` bytes, from the frame arena, aligned to 16) and
 * `counts`, which the frame adds up over the jobs and hands to merge once per strip:
 * integer sums, so the same whatever the number of jobs and their order. */
typedef struct om__bands {
    void (*resolve)(const void *state, om_strip *band, void *scratch, uint32_t counts[8]);
    void (*merge)(void *state, const uint32_t counts[8]);
    size_t scratch;
    /* May be NULL. The light depth pass by bands of the map's rows, in place of build:
     * map_of, on the calling thread, does what the rows share and gives this frame's
     * map side and light matrix (after observe); build_rows rasterizes rows
     * [y0, y0 + rows) of the map, with bins made for that matrix and side
     * (om__bins_make) or NULL, and adds to `counts`, which the frame adds up over the
     * bands and hands to merge once after the map. The same map and counts whatever
     * the bands. */
    uint32_t (*map_of)(void *state, const om_mat4 **vp);
    void (*build_rows)(const void *state, const om__bins *bins, uint32_t y0, uint32_t rows,
                       uint32_t counts[8]);
    /* May be NULL. Runs on the calling thread after merge, over the whole strip: what
     * the bands left to the method (asm's use stamps on the leaves its bands read). */
    void (*finish)(void *state, om_strip *strip);
} om__bands;

/* Method m's bands; NULL where its resolve must run a strip at a time (registry.c,
 * which alone names methods, so a firmware without one links none of its code). */
const om__bands *om__method_bands(const om_method *m);

/* A method's own pass over a strip as K jobs, each with scratch memory of its own from
 * the frame arena: for work that does not split by rows (izb's tiles of exposed
 * samples, each with its own pool and BSP). The contract:
 * - scratch(state, s): bytes one job needs (aligned to 16 by the frame). With state
 *   NULL (om_frame_bytes_jobs, before there is a state) a bound for the method's
 *   default settings from the scene alone, 0 when s is NULL; with the state, the
 *   exact bytes, at most that bound under the default settings.
 * - Per strip, after the bands' resolve and merge (when the method has bands) and
 *   before their finish: plan, on the calling thread, prepares the strip (it may write
 *   the state and the strip's terms) and returns K; then job(state, strip, k, scratch,
 *   counts) runs for every k in [0, K) on P = min(K, slots) slots, slot p running
 *   k = p, p + P, ... one after another with its own scratch, in parallel with the
 *   other slots (or, where the host gives om_frame_desc.worker and every thread has a
 *   slot, each k as a job of its own on the slot of the thread that runs it); then
 *   merge gets the counts added up over the jobs (integer sums: the
 *   same whatever P and the order). A job reads the state, writes only its own
 *   samples' terms, its scratch and counts; its terms and counts must not depend on
 *   which slot ran it or on what the scratch held before (the frame zeroes it once a
 *   frame, not once a job).
 * - The frame uses the pass only when it runs jobs and its arena has room for at least
 *   two slots' scratch beside the bands' (at most one slot a job); otherwise the
 *   method's bands are not used either and its resolve runs a strip at a time, which
 *   must give the same terms and counts. A pass that only lends its slots (job NULL:
 *   asm, rtw, spsm) takes what the bands' jobs leave instead: as many slots as fit
 *   beside them, up to one a job; below two, none (its lend is not called, and the
 *   method runs its own stages on the calling thread). */
/* The pass's slots lent to the method's own stages (asm: its analysis and tile renders
 * in observe and build, its bands' finish): run(l, fn, user, n), called on the calling
 * thread while no stage of the frame's runs, calls
 * fn(user, k, scratch) for every k in [0, n) on min(n, slots) of the pass's slots at
 * once (slot p: k = p, p + P, ..., with its scratch) and returns when all have
 * returned. What fn writes must not depend on the slot that ran it. run_any does the
 * same for jobs that need no scratch (fn gets NULL), each k a job of the host's
 * parallel-for, so the threads take them as they come free: for jobs of uneven cost,
 * and no slot's scratch is zeroed for them. */
typedef struct om__lend {
    void (*run)(const struct om__lend *l, void (*fn)(void *user, uint32_t k, void *scratch), void *user,
                uint32_t n);
    void (*run_any)(const struct om__lend *l, void (*fn)(void *user, uint32_t k, void *scratch), void *user,
                    uint32_t n);
    void *frame;
    uint32_t slots;
} om__lend;

/* The slots a method's own analysis reads back after its jobs (asm, rtw) find each
 * other through this: om__lend_table runs min(l->slots, OM__LEND_SLOTS) jobs, job k on
 * slot k, and keeps every one's scratch in a table at the start of slot 0's (whose
 * first OM__LEND_SLOTS pointers are the table's, the other slots' left unused);
 * returns the table, its length in *n. Once a frame, from the pass's lend. */
#define OM__LEND_SLOTS 64
void *const *om__lend_table(const om__lend *l, uint32_t *n);

/* A method's hold on the lent slots for its observe (rtw, spsm): the lend, every
 * slot's scratch, and whether they hold this frame's work, not yet folded into the
 * state. om__lent_take takes l's slots (none where l is NULL or has fewer than two);
 * om__lent_rows runs fn(user, y0, rows, scratch) over a strip of `rows` rows by bands,
 * about four a slot and never more jobs than registered slots, and marks them used. */
typedef struct om__lent {
    const om__lend *lend;
    void *const *slot;
    uint32_t nslot;
    bool used;
} om__lent;
void om__lent_take(om__lent *t, const om__lend *l);
void om__lent_rows(om__lent *t, uint32_t rows, void (*fn)(void *user, uint32_t y0, uint32_t rows, void *scratch),
                   void *user);

typedef struct om__pass {
    size_t (*scratch)(const void *state, const om_scene *s);
    uint32_t (*plan)(void *state, om_strip *strip);
    void (*job)(const void *state, const om_strip *strip, uint32_t k, void *scratch, uint32_t counts[8]);
    void (*merge)(void *state, const uint32_t counts[8]);
    /* May be NULL (both). In place of the method's begin when the frame uses the pass:
     * begin does what the method's begin does but for `*items` items of its per-frame
     * work, which setup then does as jobs, setup(state, first, end) for disjoint ranges
     * that together cover [0, *items), before the first strip's plan (izb's projection
     * of the scene's vertices). */
    om_status (*begin)(void *state, const om_view *v, uint32_t *items, om_diag *d);
    void (*setup)(const void *state, uint32_t first, uint32_t end);
    /* May be NULL. Where the frame uses the pass, it hands lend the slots before begin,
     * and NULL when the frame ends (the method must not keep the pointer beyond). A
     * pass for lend alone has plan return 0, and job and merge NULL. */
    void (*lend)(void *state, const om__lend *l);
} om__pass;

/* Method m's pass; NULL for none (registry.c). */
const om__pass *om__method_pass(const om_method *m);

/* Shades a strip into fb rows 0..st->rows-1. */
void om__shade_strip(const om_scene *s, const om_view *v, const om_shade_cfg *c,
                     const om_strip *st, om_framebuffer *fb);

#endif
