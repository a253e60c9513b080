/* method.h — the whole internal contract of a shadow method: its table (struct
 * om_method, opaque to hosts, who call om_method_bytes and om_method_init), the stages
 * a frame runs, its hooks for the host's threads (bands, pass, lent slots), and the
 * helpers its settings table is written with. Every method's folder includes this
 * header and the frame (engine/frame/frame.c) reads methods through it alone.
 *
 * A frame runs, for a method m and its state:
 *   begin -> [observe for every strip, if OBSERVES] -> build -> resolve for every strip
 * and the state persists across frames (progressive methods refine it). With the
 * host's threads, bands and pass (below) take the place of build and resolve where a
 * method has them; they must give the same bits. */
#ifndef OM_METHOD_H
#define OM_METHOD_H

#include "../frame/frame.h"

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
     * map_of(state, k), on the calling thread, does what the rows of map k share and
     * gives its side and light matrix (after observe), 0 where the method has no map
     * k (the frame asks for k = 0, 1, ... until then: one map for most methods, one a
     * cascade for csm); build_rows rasterizes rows [y0, y0 + rows) of map k, with bins
     * made for that matrix and side (om__bins_make) or NULL, and adds to `counts`,
     * which the frame adds up over the bands and hands to merge once after each map.
     * The same maps and counts whatever the bands. */
    uint32_t (*map_of)(void *state, uint32_t k, const om_mat4 **vp);
    void (*build_rows)(const void *state, uint32_t k, const om__bins *bins, uint32_t y0, uint32_t rows,
                       uint32_t counts[8]);
    /* May be NULL. Runs on the calling thread after merge, over the whole strip: what
     * the bands left to the method (asm's use stamps on the leaves its bands read). */
    void (*finish)(void *state, om_strip *strip);
} om__bands;

/* A method's own pass over a strip as K jobs, each with scratch memory of its own from
 * the frame arena: for work that does not split by rows (izb's tiles of exposed
 * samples, each with its own pool and BSP). The contract:
 * - scratch(state, s): bytes one job needs (aligned to 16 by the frame). With state
 *   NULL (om_frame_bytes' with_jobs, before there is a state) a bound for the method's
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

/* OM__JOBS_ONLY(p): p where the engine carries the code for the host's threads
 * (OM_WITH_JOBS, config.h), else NULL, so that a firmware links none of it. */
#if OM_WITH_JOBS
#define OM__JOBS_ONLY(p) (p)
#else
#define OM__JOBS_ONLY(p) NULL
#endif

/* What a state was made for: the first member of every method's state struct, filled
 * by om_method_init once the method's init succeeds, so that a frame refuses a state
 * made for another method, scene or image size (om_render_frame) rather than read it
 * as its own. */
typedef struct om__state_head {
    const om_method *method;
    const om_vec3 *verts;
    const uint32_t *idx;
    uint32_t nverts, ntris, width, height;
} om__state_head;

/* Whether a scene's arrays hold what its counts and indices say (scene/check.c):
 * om_method_init asks before a method reads a scene a host may have built by hand. */
om_status om__scene_check(const om_scene *s, om_diag *d);

/* `state` where method m made it, else NULL (a query given another method's state
 * reads none of it). */
static inline const void *om__state_of(const void *state, const om_method *m)
{
    return state && m && ((const om__state_head *)state)->method == m ? state : NULL;
}

/* Whether `state` was made by method m for scene s at width x height. */
bool om__state_for(const void *state, const om_method *m, const om_scene *s, uint32_t width, uint32_t height);

/* A shadow method: a small table of functions behind one interface (registry.c lists
 * them; a method's own files define its table, `om__method_<name>`). */
struct om_method {
    const char *name;
    const char *summary;
    unsigned flags;        /* OM_METHOD_OBSERVES, OM_METHOD_EXACT */
    /* Bytes the method's arena needs for this configuration, scene and image size:
     * the least it can work with, and the size it is meant to run at (`full`): one
     * pass for every method but izb, whose full is its default pool (it tiles where
     * the scene has few triangles for its samples, which is faster there). */
    om_status (*bytes)(const om_method_cfg *c, const om_scene *s, uint32_t width,
                       uint32_t height, size_t *min, size_t *full);
    /* Creates the state in `a`; the method keeps `a` for per-frame scratch. */
    om_status (*init)(void **state, om_arena *a, const om_method_cfg *c,
                      const om_scene *s, uint32_t width, uint32_t height, om_diag *d);
    om_status (*begin)(void *state, const om_view *v, om_diag *d);
    om_status (*observe)(void *state, const om_strip *st, om_diag *d);
    om_status (*build)(void *state, om_diag *d);
    /* Writes st->terms for every sample of the strip (background samples get 255). */
    om_status (*resolve)(void *state, om_strip *st, om_diag *d);
    void (*stats)(const void *state, om_method_stats *out);
    /* May be NULL. For an OBSERVES method: whether this state observes at all (its
     * configuration may not need the samples first); when not, the frame skips the
     * observe pass and, with strips, the eye pass it would run again for it. */
    bool (*observes)(const void *state);
    /* Its settings, and the size of the configuration they lie in. */
    const om_setting *settings;
    uint32_t nsettings;
    size_t cfg_bytes;
    /* Its resolve by bands (NULL: a strip at a time) and its pass of its own jobs
     * (NULL: none), both OM__JOBS_ONLY. */
    const om__bands *bands;
    const om__pass *pass;
};

/* Copies c's values into method m's own configuration struct `out` (m->cfg_bytes
 * bytes); OM_E_INVALID, with a message, when c was made for another method. A copy,
 * not a cast: the struct is the method's, the store only bytes. */
om_status om__method_cfg_of(const om_method_cfg *c, const om_method *m, void *out, om_diag *d);

/* A method's configuration struct T must fit the host's store. */
#define OM__CFG_FITS(T) typedef char T##_fits[sizeof(T) <= OM_METHOD_CFG_BYTES ? 1 : -1]

/* One entry of a method's settings: field `field` of its configuration struct T. */
#define OM__SETTING(T, field, name, kind, lo, hi, def, doc) \
    {name, doc, kind, offsetof(T, field), lo, hi, def}

/* The settings of a shadow map's depth test, for methods whose struct T has the field
 * of the same name (sm and rtw take all of them, spsm the map, asm the bias). */
#define OM__SET_MAP(T) \
    OM__SETTING(T, map_size, "map", OM_SETTING_U32, 1, OM_MAX_DIM, 2048, "shadow-map side in texels")
#define OM__SET_BIAS(T) \
    OM__SETTING(T, bias_const, "bias", OM_SETTING_F32, 0, 1, 6e-5, \
                "constant bias along the light ray, a fraction of the light's depth range (far - near)")
#define OM__SET_SLOPE(T) \
    OM__SETTING(T, bias_slope, "slope", OM_SETTING_F32, 0, 1e3, 1.5, \
                "slope-scaled bias in texels: a plane's depth across that many texels")
#define OM__SET_OFFSET(T) \
    OM__SETTING(T, normal_offset, "offset", OM_SETTING_F32, 0, 1e3, 0, "normal offset in texels")
#define OM__SET_PCF(T) \
    OM__SETTING(T, pcf, "pcf", OM_SETTING_U32, 1, 9, 1, "k x k percentage-closer filtering, 1 = off")

/* The pool of an irregular z-buffer, for izb and hybrid, whose struct T holds it at `f`
 * (a field designator). */
#define OM__SET_IZB_POOL(T, f) \
    OM__SETTING(T, f, "izb.pool", OM_SETTING_U32, 0, 1e9, 0, \
                "samples the pool holds, 0 = izb: n^2/2^20 for n triangles, 32768 to the frame; hybrid: the frame, at most 2 a triangle (32768..262144)")

#endif
