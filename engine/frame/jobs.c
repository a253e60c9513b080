/* jobs.c — the frame's stages on the host's threads: the one file of the frame that
 * knows how (OM_WITH_JOBS, config.h: where it is 0 every function here runs inline or
 * does nothing, and the compiler drops the rest).
 *
 * With the host's parallel-for and more than one thread, each strip is cut into bands
 * of rows, and the eye pass, the exposure marks, shading and (for methods with
 * om__bands) the resolve run on the bands at once, each band a job of the host's
 * parallel-for (several a thread, so the host can even out the work and a stalled
 * thread holds up one small band). A band's pixels are those of the strip (every
 * stage is strip-invariant), so the frame is the same whatever the number of jobs;
 * the stages that fold the whole strip into one answer (the light's fit, observe, a
 * serial resolve) stay on the calling thread. A method's own pass (om__pass) runs its
 * jobs on slots of scratch carved here, and lends them to its stages (om__lend).
 *
 * The bands' eye pass needs bins (each band sets up only the triangles that reach its
 * rows, from vertices projected once), and on a scene of many small triangles making
 * them costs a good share of the pass. A frame of one strip on two jobs splits the eye
 * pass's rasterization by triangles instead: each job walks part of them over the
 * whole image, as one thread would walk all, into one of two depth and id targets
 * (the second in the strip's samples, which the pass writes only later); the bands
 * then merge the two by depth (om__scene_raster_part says why that is one walk's
 * answer) and resolve their samples. Where the host names the thread that runs a job,
 * the parts are many and each goes to its thread's target, so a thread that runs
 * slower takes fewer; else they are the halves. More jobs would each need such a
 * target and a merge; they take the bins. */
#include "pipe.h"

/* Bands per thread: a strip (or a map) is cut into at most this many bands a thread,
 * and the host's parallel-for hands them out, so a thread that the system stalls holds
 * up one small band, not a thread's share. An eye pass that rasterizes and the map's
 * build take BANDS_PER_JOB: each band sets up every triangle that reaches its rows.
 * The stages whose work is per pixel (a method's resolve, shading, the eye pass that
 * resolves ids, the halves' merge) take FINE_BANDS_PER_JOB, which costs no more: their
 * work can crowd a few rows (ref's rays where a dense cloud stands), and a few coarse
 * bands would leave one thread with most of it. */
#define BANDS_PER_JOB 4
#define FINE_BANDS_PER_JOB 16

/* A method whose light depth pass runs by bands of the map also wants bins for it. */
static size_t map_bins_bytes(const om__bands *b, const om_scene *s)
{
    return b && b->build_rows && s ? om__frame_bins_bytes(s) : 0;
}

/* A pass's slot: its counts and scratch (one a job at most). */
static size_t pass_slot_bytes(size_t scratch)
{
    return om_arena_need(sizeof(om__job_slot), 8) + om_arena_need(scratch ? scratch : 1, 16);
}

/* A job's band slots: counts, and the bands' scratch. */
static size_t band_job_bytes(const om__bands *b)
{
    return FINE_BANDS_PER_JOB *
           (om_arena_need(sizeof(om__job_slot), 8) + (b ? om_arena_need(b->scratch ? b->scratch : 1, 16) : 0));
}

size_t om__jobs_bytes(const om_method *m, const void *state, const om_scene *s, uint32_t threads)
{
    if (!OM_WITH_JOBS || threads <= 1) return 0;
    const om__bands *b = m ? m->bands : NULL;
    const om__pass *p = m ? m->pass : NULL;
    return (size_t)threads * (band_job_bytes(b) + (p ? pass_slot_bytes(p->scratch(state, s)) : 0)) +
           map_bins_bytes(b, s);
}

/* A pass slot's scratch, zeroed by the slot's first job (on its thread, not all on the
 * caller's: for izb it is megabytes a thread). */
static void *slot_scratch(om__job_slot *sl)
{
    if (sl->dirty) {
        memset(sl->scratch, 0, sl->dirty);
        sl->dirty = 0;
    }
    return sl->scratch;
}

/* The stages: each runs job b of one call of the host's parallel-for (run_stage). A
 * job writes only its own band's rows, its own slot, or the parts its index names. */

/* Slot b of the pass: jobs b, b + P, ... of the method's pass (om__pass). */
static void stage_pass(om__frame *c, uint32_t b)
{
    om__job_slot *sl = &c->j.pass_slots[b];
    void *scratch = slot_scratch(sl);
    for (uint32_t k = b; k < c->j.pass_jobs; k += c->j.pass_slots_now)
        c->j.pass->job(c->fd->method_state, &c->strip, k, scratch, sl->counts);
}

/* Slot b of the pass lent to a method's own stage: its jobs b, b + P, ... (om__lend.run). */
static void stage_lend(om__frame *c, uint32_t b)
{
    void *scratch = slot_scratch(&c->j.pass_slots[b]);
    for (uint32_t k = b; k < c->j.pass_jobs; k += c->j.pass_slots_now) c->j.lend_fn(c->j.lend_user, k, scratch);
}

/* Job b of the pass on the slot of the thread that runs it (om_frame_desc.worker). */
static void stage_pass_any(om__frame *c, uint32_t b)
{
    const om_frame_desc *fd = c->fd;
    om__job_slot *sl = &c->j.pass_slots[fd->worker(fd->parallel_user) % c->j.pass_max];   /* in bounds whatever the host says */
    c->j.pass->job(fd->method_state, &c->strip, b, slot_scratch(sl), sl->counts);
}

/* A method's own job b, without scratch (om__lend.run_any). */
static void stage_lend_any(om__frame *c, uint32_t b)
{
    c->j.lend_fn(c->j.lend_user, b, NULL);
}

/* Items [first, end) of BANDS_PER_JOB * jobs parts of n. */
static uint32_t part_at(const om__frame *c, uint32_t n, uint32_t b)
{
    return (uint32_t)((uint64_t)n * b / (BANDS_PER_JOB * c->jobs));
}

/* Part b of the pass's per-frame items (om__pass.setup). */
static void stage_pass_setup(om__frame *c, uint32_t b)
{
    const uint32_t n = c->j.setup_items;
    c->j.pass->setup(c->fd->method_state, part_at(c, n, b), part_at(c, n, b + 1));
}

/* Part b of the bins' vertices, then (once they are all made) of the triangles' rows. */
static void stage_bin_verts(om__frame *c, uint32_t b)
{
    const uint32_t n = c->fd->scene->nverts;
    om__bins_make_verts(c->fd->scene, c->j.mk_vp, c->view->origin, c->j.mk_w, c->j.mk_h, c->j.mk, part_at(c, n, b),
                        part_at(c, n, b + 1));
}

static void stage_bin_rows(om__frame *c, uint32_t b)
{
    const uint32_t n = c->fd->scene->ntris;
    om__bins_make_rows(c->fd->scene, c->j.mk_vp, c->view->origin, c->j.mk_w, c->j.mk_h, c->j.mk, part_at(c, n, b),
                       part_at(c, n, b + 1));
}

/* Part b of the triangles over the whole strip: the halves, half b into target b;
 * else into its thread's target, cleared by the first part the thread runs (only that
 * thread touches it). */
static void stage_eye_half(om__frame *c, uint32_t b)
{
    const om_frame_desc *fd = c->fd;
    const uint32_t n = fd->scene->ntris, k = c->j.eye_parts;
    const uint32_t w = k == 2 ? b : fd->worker(fd->parallel_user) % 2;
    om_target tg = c->tg;
    if (w == 1) {
        tg.depth = c->j.half_depth;
        tg.id = c->j.half_id;
    }
    if (!c->j.part_drawn[w]) {
        om__target_clear(&tg);
        c->j.part_drawn[w] = true;
    }
    om__eye_raster_part(fd->scene, c->view, &tg, (uint32_t)((uint64_t)n * b / k),
                        (uint32_t)((uint64_t)n * (b + 1) / k));
}

/* Band b of the light's map, in the order order_bands chose. */
static void stage_build(om__frame *c, uint32_t b)
{
    b = c->j.slots[b].run;
    const uint32_t y0 = b * c->j.map_band, rows = c->j.map_size - y0;
    c->j.bands->build_rows(c->fd->method_state, c->j.map_k, c->j.map_bins.rows ? &c->j.map_bins : NULL, y0,
                           rows < c->j.map_band ? rows : c->j.map_band, c->j.slots[b].counts);
}

/* Band b of the current strip (rows of c->j.rows_now): its strip, and its offset. */
static om_strip band_of(const om__frame *c, uint32_t b, size_t *off)
{
    const uint32_t band = c->j.rows_now, r0 = b * band;
    om_strip st = c->strip;
    *off = (size_t)r0 * c->strip.width;
    st.y0 += r0;
    st.rows = c->strip.rows - r0 < band ? c->strip.rows - r0 : band;
    st.samples += *off;
    st.terms += *off;
    return st;
}

/* The second target's nearer pixels into the first; a tie to the lower triangle. */
static void stage_eye_merge(om__frame *c, uint32_t b)
{
    size_t off;
    const om_strip st = band_of(c, b, &off);
    const size_t n = (size_t)st.rows * st.width;
    uint32_t *depth = c->tg.depth + off, *id = c->tg.id + off;
    const uint32_t *hd = c->j.half_depth + off, *hi = c->j.half_id + off;
    if (!c->j.part_drawn[1]) return;   /* every part in the first */
    if (!c->j.part_drawn[0]) {         /* every part in the second */
        memcpy(depth, hd, n * sizeof *depth);
        memcpy(id, hi, n * sizeof *id);
        return;
    }
    for (size_t i = 0; i < n; i++)
        if (hd[i] < depth[i] || (hd[i] == depth[i] && hi[i] < id[i])) {
            depth[i] = hd[i];
            id[i] = hi[i];
        }
}

/* The band's eye pass (from the merged halves: their samples alone) and marks. */
static void stage_eye(om__frame *c, uint32_t b)
{
    size_t off;
    om_strip st = band_of(c, b, &off);
    if (c->j.eye) {
        om_target tg = c->tg;
        tg.y0 = st.y0;
        tg.rows = st.rows;
        tg.depth += off;
        tg.id += off;
        if (c->j.half_depth) om__eye_resolve(c->fd->scene, c->view, &tg, &st, c->j.mark);
        else om__frame_eye_rows(c, &tg, &st, c->j.mark);
    } else if (c->j.mark) {
        om__frame_mark(c->fd->scene, c->view, &st);
    }
}

static void stage_resolve(om__frame *c, uint32_t b)
{
    size_t off;
    om_strip st = band_of(c, b, &off);
    c->j.bands->resolve(c->fd->method_state, &st, c->j.slots[b].scratch, c->j.slots[b].counts);
}

static void stage_shade(om__frame *c, uint32_t b)
{
    size_t off;
    const om_strip st = band_of(c, b, &off);
    om_framebuffer fb = *c->fd->fb;
    fb.pixels += (size_t)(st.y0 - c->strip.y0) * fb.stride;
    fb.rows = st.rows;
    om__shade_strip(c->fd->scene, c->view, c->fd->shade, &st, &fb);
}

static void band_job(void *user, uint32_t b)
{
    om__frame *c = (om__frame *)user;
    c->j.stage(c, b);
}

/* Runs `stage` as `n` jobs of the host's parallel-for. */
static void run_stage(om__frame *c, void (*stage)(om__frame *c, uint32_t b), uint32_t n)
{
    c->j.stage = stage;
    c->fd->parallel_for(c->fd->parallel_user, band_job, c, n);
}

/* The same over the current strip's bands of `rows` rows. */
static void run_bands(om__frame *c, void (*stage)(om__frame *c, uint32_t b), uint32_t rows)
{
    c->j.rows_now = rows;
    run_stage(c, stage, (c->strip.rows + rows - 1) / rows);
}

/* A frame of one strip on two jobs splits its eye pass by triangles (see the top)
 * when the scene has more than one vertex for every HALVES_PIXELS pixels: the bins
 * cost a little per vertex, the second target's clearing and merging a little per
 * pixel, and a vertex costs the bins several times what a pixel costs the halves, so
 * a scene dense in vertices for its image takes less CPU time by halves, and a sparse
 * one less with the bins. */
#define HALVES_PIXELS 8
/* Parts of the triangles where the host names the thread: as many as the fine bands
 * of two jobs, so that the slower thread waits for at most a small part at the end,
 * where two fixed halves can leave one thread waiting for the other's whole. */
#define EYE_PARTS (2 * FINE_BANDS_PER_JOB)

/* At most this many triangles' rows are read to weigh the bands (order_bands). */
#define ORDER_SAMPLES 1024

/* The order the map build's `nb` bands of `band` rows run in (slots[k].run): weighed
 * by the triangles whose bins' rows reach each (every ntris / ORDER_SAMPLES + 1-th
 * triangle, on the calling thread), then dealt heaviest first to the jobs' T shares of
 * the indices, [nb k / T, nb (k + 1) / T) for share k, back and forth (share 0, 1, ..,
 * T - 1, T - 1, .., 0, 0, ..), each share heaviest first; in row order without rows.
 * A heavy band that starts last keeps one thread busy while the others wait (a scene
 * whose triangles crowd a few rows, such as a dense random cloud), and a host that
 * gives each thread its own share of the indices (the platform's pool) would give one
 * thread all the heaviest of bands merely sorted; dealt, each share gets its part of
 * them. Where T does not divide nb they stay sorted. The strip's stages run in row
 * order: such a host then finds each band's rows in the cache of the thread that wrote
 * them in the last stage, which a heaviest-first order of the eye pass's bands would
 * lose. Which band a job runs changes when it finishes, never a pixel. */
static void order_bands(om__frame *c, const uint32_t *rows, uint32_t band, uint32_t nb)
{
    om__job_slot *sl = c->j.slots;
    for (uint32_t k = 0; k < nb; k++) {
        sl[k].run = k;
        sl[k].weight = 0;
    }
    if (!rows || nb <= c->jobs) return;
    const uint32_t nt = c->fd->scene->ntris, step = nt / ORDER_SAMPLES + 1, y1 = band * nb;
    for (uint32_t t = 0; t < nt; t += step) {
        uint32_t r0 = rows[t] & 0xFFFFu, r1 = rows[t] >> 16;
        if (r0 > r1 || r0 >= y1) continue;
        r0 /= band;
        r1 = r1 >= y1 ? nb - 1 : r1 / band;
        for (uint32_t k = r0; k <= r1; k++) sl[k].weight++;
    }
    for (uint32_t k = 1; k < nb; k++) {   /* insertion sort of the runs, stable */
        const uint32_t b = sl[k].run;
        uint32_t i = k;
        for (; i > 0 && sl[sl[i - 1].run].weight < sl[b].weight; i--) sl[i].run = sl[i - 1].run;
        sl[i].run = b;
    }
    const uint32_t T = c->jobs, per = nb / T;
    if (nb % T) return;
    for (uint32_t j = 0; j < nb; j++) {   /* dealt, into the weights (done with) */
        const uint32_t r = j / T, q = j % T, share = r % 2 ? T - 1 - q : q;
        sl[share * per + r].weight = sl[j].run;
    }
    for (uint32_t k = 0; k < nb; k++) sl[k].run = sl[k].weight;
}

/* The counts of slots [0, n), added up in slot order, handed to merge. */
static void merge_counts(const om__job_slot *sl, uint32_t n, void (*merge)(void *state, const uint32_t counts[8]),
                         void *state)
{
    uint32_t sum[8] = {0};
    for (uint32_t j = 0; j < n; j++)
        for (int k = 0; k < 8; k++) sum[k] += sl[j].counts[k];
    merge(state, sum);
}

/* Zeroes the counts of slots [0, n). */
static void clear_counts(om__job_slot *sl, uint32_t n)
{
    for (uint32_t j = 0; j < n; j++) memset(sl[j].counts, 0, sizeof sl[j].counts);
}

/* om__bins_make on the host's threads: the vertices, then the triangles' rows, each
 * cut into parts (the same bins however cut: om__bins_make_verts). */
void om__jobs_make_bins(om__frame *c, const om_mat4 *vp, uint32_t w, uint32_t h, const om__bins *b)
{
    if (!OM_WITH_JOBS || c->jobs <= 1) {
        om__bins_make(c->fd->scene, vp, c->view->origin, w, h, b);
        return;
    }
    c->j.mk = b;
    c->j.mk_vp = vp;
    c->j.mk_w = w;
    c->j.mk_h = h;
    run_stage(c, stage_bin_verts, BANDS_PER_JOB * c->jobs);
    run_stage(c, stage_bin_rows, BANDS_PER_JOB * c->jobs);
}

/* The light depth pass by bands of each map (om__bands.build_rows), one map after
 * another: with bins, BANDS_PER_JOB bands a job, each setting up only its own
 * triangles; without, one band a job, since each band then walks every triangle. The
 * bands' counts are added up after each map, as the resolve's after a strip. */
static void build_map(om__frame *c)
{
    const om_mat4 *vp;
    for (c->j.map_k = 0; (c->j.map_size = c->j.bands->map_of(c->fd->method_state, c->j.map_k, &vp)) != 0;
         c->j.map_k++) {
        if (c->j.map_bins.rows) om__jobs_make_bins(c, vp, c->j.map_size, c->j.map_size, &c->j.map_bins);
        uint32_t n = c->j.map_bins.rows ? BANDS_PER_JOB * c->jobs : c->jobs;
        c->j.map_band = ((c->j.map_size + n - 1) / n + 15) / 16 * 16;
        const uint32_t nb = (c->j.map_size + c->j.map_band - 1) / c->j.map_band;
        clear_counts(c->j.slots, nb);
        order_bands(c, c->j.map_bins.rows, c->j.map_band, nb);
        run_stage(c, stage_build, nb);
        merge_counts(c->j.slots, nb, c->j.bands->merge, c->fd->method_state);
    }
}

/* The method's pass over the current strip (om__pass): plan, the jobs on their slots,
 * then their counts added up in slot order. Where the host says which thread runs a
 * job (om_frame_desc.worker) and every thread has a slot, each job is one of the
 * host's, on its thread's slot: the host hands them out as threads come free, so a
 * thread that the system slows or a heavy tile holds up no fixed share (a virtual
 * machine's CPUs can run at different speeds for a while). Otherwise slot p runs jobs
 * p, p + P, ... */
static void run_pass(om__frame *c)
{
    void *state = c->fd->method_state;
    uint32_t k = c->j.pass->plan(state, &c->strip);
    if (k == 0) return;
    const bool any = c->fd->worker && c->j.pass_max >= c->fd->threads;
    const uint32_t p = k < c->j.pass_max ? k : c->j.pass_max, used = any ? c->j.pass_max : p;
    c->j.pass_jobs = k;
    c->j.pass_slots_now = p;
    clear_counts(c->j.pass_slots, used);
    if (any) run_stage(c, stage_pass_any, k);
    else run_stage(c, stage_pass, p);
    merge_counts(c->j.pass_slots, used, c->j.pass->merge, state);
}

/* The method's begin: with a pass that has its own (om__pass.begin), that one, then
 * the per-frame items it leaves in parts on the host's threads. */
om_status om__jobs_begin(om__frame *c, const om_view *v, om_diag *d)
{
    void *state = c->fd->method_state;
    if (!OM_WITH_JOBS || !c->j.pass || !c->j.pass->begin) return c->fd->method->begin(state, v, d);
    om_status st = c->j.pass->begin(state, v, &c->j.setup_items, d);
    if (st == OM_OK && c->j.setup_items) run_stage(c, stage_pass_setup, BANDS_PER_JOB * c->jobs);
    return st;
}

/* om__lend.run: a method's own jobs on the pass's slots, from its begin, observe, build
 * or bands' finish on the calling thread (no stage of the frame's is running then). */
static void lend_run(const om__lend *l, void (*fn)(void *user, uint32_t k, void *scratch), void *user, uint32_t n)
{
    om__frame *c = (om__frame *)l->frame;
    if (n == 0) return;
    c->j.lend_fn = fn;
    c->j.lend_user = user;
    c->j.pass_jobs = n;
    c->j.pass_slots_now = n < c->j.pass_max ? n : c->j.pass_max;
    run_stage(c, stage_lend, c->j.pass_slots_now);
}

static void table_fn(void *user, uint32_t k, void *scratch) { ((void **)user)[k] = scratch; }

void *const *om__lend_table(const om__lend *l, uint32_t *n)
{
    void *reg[OM__LEND_SLOTS];
    *n = l->slots < OM__LEND_SLOTS ? l->slots : OM__LEND_SLOTS;
    l->run(l, table_fn, reg, *n);
    void **tab = (void **)reg[0];
    for (uint32_t k = 0; k < *n; k++) tab[k] = reg[k];
    return (void *const *)tab;
}

void om__lent_take(om__lent *t, const om__lend *l)
{
    t->lend = NULL;
    t->slot = NULL;
    t->nslot = 0;
    t->used = false;
    if (!l || l->slots < 2) return;
    t->slot = om__lend_table(l, &t->nslot);
    t->lend = l;
}

typedef struct lent_job {
    void (*fn)(void *user, uint32_t y0, uint32_t rows, void *scratch);
    void *user;
    uint32_t band, rows;
} lent_job;

static void lent_fn(void *user, uint32_t k, void *scratch)
{
    const lent_job *j = (const lent_job *)user;
    const uint32_t y0 = k * j->band;
    j->fn(j->user, y0, j->rows - y0 < j->band ? j->rows - y0 : j->band, scratch);
}

void om__lent_rows(om__lent *t, uint32_t rows, void (*fn)(void *user, uint32_t y0, uint32_t rows, void *scratch),
                   void *user)
{
    if (rows == 0) return;
    /* job k runs on slot k mod P: with more slots than registered, one job each */
    uint32_t nb = t->nslot < t->lend->slots ? t->nslot : 4 * t->nslot;
    if (nb > rows) nb = rows;
    lent_job j = {fn, user, (rows + nb - 1) / nb, rows};
    t->lend->run(t->lend, lent_fn, &j, (rows + j.band - 1) / j.band);
    t->used = true;
}

/* om__lend.run_any: jobs without scratch, each one of the host's. */
static void lend_run_any(const om__lend *l, void (*fn)(void *user, uint32_t k, void *scratch), void *user,
                         uint32_t n)
{
    om__frame *c = (om__frame *)l->frame;
    if (n == 0) return;
    c->j.lend_fn = fn;
    c->j.lend_user = user;
    run_stage(c, stage_lend_any, n);
}

/* Carves the jobs' slots: as many as the host asks for and the arena holds beyond
 * `keep` bytes (at least two, or none and the frame runs inline). A method with a pass
 * (om__pass) gets a pass slot a job, with the state's scratch; where fewer than two
 * fit, it resolves a strip at a time (its bands unused) and the jobs are only the eye
 * pass's and shading's. A pass that only lends (method.h) takes what the bands' jobs
 * leave: as many slots as fit beside them, up to one a job, or none. */
void om__jobs_carve(om__frame *c, om_arena *fa, size_t keep)
{
    const om_frame_desc *fd = c->fd;
    c->jobs = 1;
    if (!OM_WITH_JOBS || !fd->parallel_for || fd->threads <= 1) return;
    const om__bands *b = fd->method->bands;
    const om__pass *ps = fd->method->pass;
    size_t per = band_job_bytes(b), pscratch = 0, pslot = 0;
    size_t left = om_arena_left(fa), room = left > keep ? left - keep : 0, fit = room / per;
    if (ps) {
        pscratch = ps->scratch(fd->method_state, fd->scene);
        pslot = pass_slot_bytes(pscratch);
        size_t with = room / (per + pslot);
        if (ps->job && with >= 2) fit = with;
        else if (ps->job) ps = NULL, b = NULL;   /* its jobs pair with the bands */
    }
    uint32_t jobs = fit < fd->threads ? (uint32_t)fit : fd->threads, lent = jobs;
    if (ps && !ps->job) {   /* the bands' jobs first, then as many slots as fit beside them */
        const size_t after = (room > jobs * per ? room - jobs * per : 0) / pslot;
        lent = after < jobs ? (uint32_t)after : jobs;
        if (lent < 2) ps = NULL;
    }
    void *p;
    const uint32_t nslots = FINE_BANDS_PER_JOB * jobs;
    if (jobs < 2 || om_arena_alloc(fa, nslots * sizeof(om__job_slot), 8, &p, NULL)) return;
    c->j.slots = (om__job_slot *)p;
    for (uint32_t j = 0; b && j < nslots; j++)
        if (om_arena_alloc(fa, b->scratch ? b->scratch : 1, 16, &c->j.slots[j].scratch, NULL))
            return;   /* cannot happen: `per` counted it */
    if (ps) {
        if (om_arena_alloc(fa, lent * sizeof(om__job_slot), 8, &p, NULL)) return;
        c->j.pass_slots = (om__job_slot *)p;
        /* The scratch is zeroed by each slot's first job (band_job), in parallel: for
         * izb it is megabytes a thread. */
        for (uint32_t j = 0; j < lent; j++) {
            if (om__arena_alloc_raw(fa, pscratch ? pscratch : 1, 16, &c->j.pass_slots[j].scratch, NULL))
                return;   /* cannot happen: counted above */
            c->j.pass_slots[j].dirty = pscratch ? pscratch : 1;
        }
        c->j.pass = ps;
        c->j.pass_max = lent;
    }
    c->j.bands = b;
    c->jobs = jobs;
    /* Bands of whole 16-row blocks (methods tile strips by 16 from their top row, so a
     * band resolves the same blocks the strip would), at most one a slot. */
    uint32_t rows = c->tg.rows, want = (rows + BANDS_PER_JOB * jobs - 1) / (BANDS_PER_JOB * jobs);
    c->j.band_rows = (want + 15) / 16 * 16;
    want = (rows + nslots - 1) / nslots;
    c->j.fine_rows = (want + 15) / 16 * 16;
}


bool om__jobs_halves(om__frame *c, om_sample *samples, size_t n)
{
    const om_frame_desc *fd = c->fd;
    if (!OM_WITH_JOBS || !c->single || c->jobs != 2 || (uint64_t)fd->scene->nverts * HALVES_PIXELS <= n)
        return false;
    /* the second half's depth and ids in the samples (8 bytes of a sample's 32),
     * which the eye pass writes once the halves are merged: in the last quarter,
     * the samples of the last rows, which the thread that draws the second half
     * resolves where each thread has its own chunk of the bands (om_jobs_for) */
    c->j.half_depth = (uint32_t *)(void *)samples + n * (sizeof(om_sample) / sizeof(uint32_t) - 2);
    c->j.half_id = c->j.half_depth + n;
    c->j.eye_parts = fd->worker && fd->threads == 2 ? EYE_PARTS : 2;
    return true;
}

void om__jobs_carve_map(om__frame *c, om_arena *fa)
{
    if (OM_WITH_JOBS && c->jobs > 1 && c->j.bands && c->j.bands->build_rows)
        om__frame_carve_bins(fa, c->fd->scene, &c->j.map_bins);
}

void om__jobs_lend(om__frame *c, bool on)
{
    if (!OM_WITH_JOBS || !c->j.pass || !c->j.pass->lend) return;
    c->j.lend.run = lend_run;
    c->j.lend.run_any = lend_run_any;
    c->j.lend.frame = c;
    c->j.lend.slots = c->j.pass_max;
    c->j.pass->lend(c->fd->method_state, on ? &c->j.lend : NULL);
}

void om__jobs_eye(om__frame *c, bool eye, bool mark)
{
    if (!OM_WITH_JOBS) return;
    c->j.eye = eye;
    c->j.mark = mark;
    if (eye && c->j.half_depth) {
        c->j.part_drawn[0] = c->j.part_drawn[1] = false;
        run_stage(c, stage_eye_half, c->j.eye_parts);
        run_bands(c, stage_eye_merge, c->j.fine_rows);
    }
    /* an eye pass that rasterizes takes bands of band_rows (each sets up every
     * triangle that reaches its rows); one that resolves merged halves or kept ids,
     * and the marks alone, fine bands */
    run_bands(c, stage_eye, eye && !c->j.half_depth && !(c->ids && c->ids_have) ? c->j.band_rows : c->j.fine_rows);
}

bool om__jobs_build(om__frame *c)
{
    if (!OM_WITH_JOBS || c->jobs <= 1 || !c->j.bands || !c->j.bands->build_rows) return false;
    build_map(c);
    return true;
}

bool om__jobs_resolve(om__frame *c)
{
    if (!OM_WITH_JOBS || (!c->j.bands && !c->j.pass)) return false;
    void *state = c->fd->method_state;
    if (c->j.bands) {
        const uint32_t n = FINE_BANDS_PER_JOB * c->jobs;
        clear_counts(c->j.slots, n);
        run_bands(c, stage_resolve, c->j.fine_rows);
        merge_counts(c->j.slots, n, c->j.bands->merge, state);
    }
    if (c->j.pass) run_pass(c);
    if (c->j.bands && c->j.bands->finish) c->j.bands->finish(state, &c->strip);
    return true;
}

void om__jobs_shade(om__frame *c)
{
    if (OM_WITH_JOBS) run_bands(c, stage_shade, c->j.fine_rows);
}

size_t om__jobs_map_bins_bytes(const om_method *m, const om_scene *s)
{
    return OM_WITH_JOBS && m ? map_bins_bytes(m->bands, s) : 0;
}
