/* frame.c — one frame, strip by strip: scene -> eye pass (visible samples) ->
 * the method (a shadow term per sample) -> shading -> framebuffer -> host callback.
 *
 * A method that observes (needs every visible sample before it builds) and a
 * directional light (fitted to the visible samples) need a first pass over the image.
 * When the frame is one strip the samples are kept and the eye pass runs once; with
 * smaller strips it runs again for each pass, so memory stays at one strip, but where
 * the arena has room (om_frame_bytes_ids) the first pass keeps the triangle under
 * every pixel, and the later passes only resolve the samples from them: the scene is
 * rasterized once.
 *
 * With the host's parallel-for and more than one thread, each strip is cut into bands
 * of rows, and the eye pass, the exposure marks, shading and (for methods with
 * om__bands) the resolve run on the bands at once, each band a job of the host's
 * parallel-for (several a thread, so the host can even out the work and a stalled
 * thread holds up one small band). A band's pixels are those of the strip (every
 * stage is strip-invariant), so the frame is the same whatever the number of jobs;
 * the stages that fold the whole strip into one answer (the light's fit, observe, a
 * serial resolve) stay on the calling thread.
 *
 * The bands' eye pass needs bins (each band sets up only the triangles that reach its
 * rows, from vertices projected once), and on a scene of many small triangles making
 * them costs a fifth of the pass (issue 26: random 100K). A frame of one strip on two
 * jobs splits the eye pass's rasterization by triangles instead: each job walks part
 * of them over the whole image, as one thread would walk all, into one of two depth
 * and id targets (the second in the strip's samples, which the pass writes only
 * later); the bands then merge the two by depth (om__scene_raster_part says why that
 * is one walk's answer) and resolve their samples. Where the host names the thread
 * that runs a job, the parts are many and each goes to its thread's target, so a
 * thread that runs slower takes fewer; else they are the halves. More jobs would each
 * need such a target and a merge; they take the bins. */
#include "../shadow/method.h"

/* Bands per thread: a strip (or a map) is cut into at most this many bands a thread,
 * and the host's parallel-for hands them out, so a thread that the system stalls holds
 * up one small band, not a thread's share. An eye pass that rasterizes and the map's
 * build take BANDS_PER_JOB: each band sets up every triangle that reaches its rows.
 * The stages whose work is per pixel (a method's resolve, shading, the eye pass that
 * resolves ids, the halves' merge) take FINE_BANDS_PER_JOB, which costs no more: their
 * work can crowd a few rows (ref's rays where random 100K's cloud stands: one of 8
 * bands held a third of the frame's rays, and the other thread waited 6 to 13 ms). */
#define BANDS_PER_JOB 4
#define FINE_BANDS_PER_JOB 16

/* One band's method counts and resolve scratch (from the frame arena): a band is one
 * job of the host's parallel-for, so it owns its slot whichever thread runs it. */
typedef struct job_slot {
    uint32_t counts[8];
    void *scratch;
    size_t dirty;   /* bytes of scratch its first job zeroes (a pass slot: band_job) */
    uint32_t run;    /* the band that job k of the map build runs (order_bands) */
    uint32_t weight; /* order_bands' estimate of band k's work */
} job_slot;

static size_t bins_bytes(const om_scene *s)
{
    return om__bins_rows_bytes(s) + om__bins_verts_bytes(s);
}

/* A method whose light depth pass runs by bands of the map also wants bins for it. */
static size_t map_bins_bytes(const om__bands *b, const om_scene *s)
{
    return b && b->build_rows && s ? bins_bytes(s) : 0;
}

/* A pass's slot: its counts and scratch (one a job at most). */
static size_t pass_slot_bytes(size_t scratch)
{
    return om_arena_need(sizeof(job_slot), 8) + om_arena_need(scratch ? scratch : 1, 16);
}

/* A job's band slots: counts, and the bands' scratch. */
static size_t band_job_bytes(const om__bands *b)
{
    return FINE_BANDS_PER_JOB *
           (om_arena_need(sizeof(job_slot), 8) + (b ? om_arena_need(b->scratch ? b->scratch : 1, 16) : 0));
}

size_t om_frame_bytes_jobs(const om_method *m, const om_scene *s, uint32_t threads)
{
    if (!OM_WITH_JOBS || threads <= 1) return 0;
    const om__bands *b = m ? m->bands : NULL;
    const om__pass *p = m ? m->pass : NULL;
    return (size_t)threads * (band_job_bytes(b) + (p ? pass_slot_bytes(p->scratch(NULL, s)) : 0)) +
           map_bins_bytes(b, s);
}

size_t om_frame_bytes(uint32_t width, uint32_t strip_rows)
{
    size_t n = (size_t)width * strip_rows;
    return om_arena_need(n * sizeof(uint32_t), 8) * 2 + om_arena_need(n * sizeof(om_sample), 8) +
           om_arena_need(n * sizeof(om_term), 8);
}

size_t om_frame_bytes_scene(const om_scene *s, uint32_t width, uint32_t strip_rows)
{
    return om_frame_bytes(width, strip_rows) + om__bins_rows_bytes(s) + om__bins_verts_bytes(s);
}

static uint64_t now(const om_frame_desc *fd)
{
    return fd->clock ? fd->clock(fd->clock_user) : 0;
}

/* Geometric part of the lit rule, set once for every method alike. */
static void mark_exposed(const om_view *v, om_strip *st)
{
    size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        t->flags = st->samples[i].tri != OM_NO_TRI && om__exposed(v, &st->samples[i])
                       ? OM_TERM_EXPOSED : 0;
    }
}

static void grow_light_box(const om_view *v, const om_strip *st, om_vec3 *lo, om_vec3 *hi,
                           bool *any)
{
    size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        const om_sample *smp = &st->samples[i];
        if (smp->tri == OM_NO_TRI) continue;
        om_vec4 q = om__mat_apply(&v->light_view, om__v3(smp->p[0], smp->p[1], smp->p[2]));
        if (!*any || q.x < lo->x) lo->x = q.x;
        if (!*any || q.y < lo->y) lo->y = q.y;
        if (!*any || q.x > hi->x) hi->x = q.x;
        if (!*any || q.y > hi->y) hi->y = q.y;
        *any = true;
    }
}

/* The bands of the strip: band b is job b of the host's parallel-for, with slot b and
 * rows of its own. */
typedef enum { STAGE_PREPARE, STAGE_RESOLVE, STAGE_SHADE, STAGE_BUILD, STAGE_PASS, STAGE_PASS_SETUP,
               STAGE_LEND, STAGE_LEND_ANY, STAGE_BIN_VERTS, STAGE_BIN_ROWS, STAGE_EYE_HALF, STAGE_EYE_MERGE,
               STAGE_PASS_ANY } stage;

typedef struct frame_ctx {
    const om_frame_desc *fd;
    const om_view *view;
    const om__bins *bins;      /* NULL: every strip walks every triangle */
    const om__bands *bands;    /* NULL: the method resolves a strip at a time */
    const om__pass *pass;      /* NULL: no pass of its own (or no room for one) */
    om_target tg;              /* the strip's */
    om_strip strip;
    uint32_t jobs, band_rows, fine_rows;   /* rows of a band, of a fine band */
    job_slot *slots;           /* FINE_BANDS_PER_JOB * jobs of them */
    job_slot *pass_slots;      /* the pass's, pass_max of them */
    uint32_t pass_max, pass_jobs, pass_slots_now;   /* STAGE_PASS, STAGE_LEND: K jobs on P slots */
    uint32_t setup_items;      /* STAGE_PASS_SETUP: the pass's per-frame items */
    void (*lend_fn)(void *user, uint32_t k, void *scratch);   /* STAGE_LEND (om__lend) */
    void *lend_user;
    stage stage;
    bool eye, mark;            /* STAGE_PREPARE: run the eye pass, mark exposure */
    om__bins map_bins;         /* the light map's (rows NULL: none) */
    uint32_t map_size, map_band;   /* STAGE_BUILD: the map's side, rows per band */
    const om__bins *mk;        /* STAGE_BIN_*: the bins being made, through mk_vp */
    const om_mat4 *mk_vp;
    uint32_t mk_w, mk_h;
    void *ids;                 /* the image's triangle ids from its first pass, or NULL */
    bool ids16;                /* as uint16_t (OM_NO_TRI as 0xFFFF): under 65535 triangles */
    bool ids_have;             /* the first pass is over: later passes resolve from ids */
    uint32_t *half_depth, *half_id;   /* one strip, two jobs: the second target, or NULL */
    uint32_t eye_parts;        /* STAGE_EYE_HALF: the parts of the triangles (2: the halves) */
    bool part_drawn[2];        /* and whether each target is cleared and drawn into */
} frame_ctx;

static size_t ids_bytes(const om_scene *s, uint32_t width, uint32_t height)
{
    return (size_t)width * height * (s && s->ntris < 0xFFFFu ? sizeof(uint16_t) : sizeof(uint32_t));
}

size_t om_frame_bytes_ids(const om_scene *s, uint32_t width, uint32_t height)
{
    return om_arena_need(ids_bytes(s, width, height), 8);
}

/* The eye pass of rows [st->y0, + st->rows) into tg (the same rows): with kept ids,
 * the first pass stores its ids there and the later ones resolve from them, for the
 * same samples and marks (om__eye_resolve). */
static void eye_rows(const frame_ctx *c, const om_target *tg, om_strip *st, bool mark)
{
    const size_t n = (size_t)st->rows * st->width, at = (size_t)st->y0 * st->width;
    if (c->ids && c->ids_have) {
        if (c->ids16) {
            const uint16_t *k = (const uint16_t *)c->ids + at;
            for (size_t i = 0; i < n; i++) tg->id[i] = k[i] == 0xFFFFu ? OM_NO_TRI : k[i];
        } else {
            memcpy(tg->id, (const uint32_t *)c->ids + at, n * sizeof(uint32_t));
        }
        om__eye_resolve(c->fd->scene, c->view, tg, st, mark);
        return;
    }
    if (mark) om__eye_pass_mark(c->fd->scene, c->view, tg, st, c->bins);
    else om__eye_pass(c->fd->scene, c->view, tg, st, c->bins);
    if (!c->ids) return;
    if (c->ids16) {
        uint16_t *k = (uint16_t *)c->ids + at;
        for (size_t i = 0; i < n; i++) k[i] = tg->id[i] == OM_NO_TRI ? 0xFFFFu : (uint16_t)tg->id[i];
    } else {
        memcpy((uint32_t *)c->ids + at, tg->id, n * sizeof(uint32_t));
    }
}

/* Whether stage sg is an eye pass that rasterizes by bands (each sets up every
 * triangle that reaches its rows): it takes bands of band_rows; every other stage fine
 * bands. */
static bool rasters(const frame_ctx *c, stage sg)
{
    return sg == STAGE_PREPARE && c->eye && !c->half_depth && !(c->ids && c->ids_have);
}

static uint32_t stage_rows(const frame_ctx *c, stage sg)
{
    return rasters(c, sg) ? c->band_rows : c->fine_rows;
}

/* The number of stage sg's bands over the current strip. */
static uint32_t stage_bands(const frame_ctx *c, stage sg)
{
    return (c->strip.rows + stage_rows(c, sg) - 1) / stage_rows(c, sg);
}

/* A pass slot's scratch, zeroed by the slot's first job (on its thread, not all on the
 * caller's: for izb it is megabytes a thread). */
static void *slot_scratch(job_slot *sl)
{
    if (sl->dirty) {
        memset(sl->scratch, 0, sl->dirty);
        sl->dirty = 0;
    }
    return sl->scratch;
}

static void band_job(void *user, uint32_t b)
{
    const frame_ctx *c = (const frame_ctx *)user;
    const om_frame_desc *fd = c->fd;
    if (c->stage == STAGE_PASS || c->stage == STAGE_LEND) {   /* slot b: jobs b, b + P, ... (om__pass) */
        job_slot *sl = &c->pass_slots[b];
        void *scratch = slot_scratch(sl);
        for (uint32_t k = b; k < c->pass_jobs; k += c->pass_slots_now)
            if (c->stage == STAGE_PASS) c->pass->job(fd->method_state, &c->strip, k, scratch, sl->counts);
            else c->lend_fn(c->lend_user, k, scratch);   /* a method's own stage (om__lend) */
        return;
    }
    if (c->stage == STAGE_PASS_ANY) {   /* pass job b, on the slot of the thread that runs it */
        job_slot *sl = &c->pass_slots[fd->worker(fd->parallel_user) % c->pass_max];   /* in bounds whatever the host says */
        c->pass->job(fd->method_state, &c->strip, b, slot_scratch(sl), sl->counts);
        return;
    }
    if (c->stage == STAGE_LEND_ANY) {   /* a method's own job b, without scratch (om__lend.run_any) */
        c->lend_fn(c->lend_user, b, NULL);
        return;
    }
    if (c->stage == STAGE_PASS_SETUP) {   /* part b of BANDS_PER_JOB * jobs */
        const uint32_t parts = BANDS_PER_JOB * c->jobs, n = c->setup_items;
        c->pass->setup(fd->method_state, (uint32_t)((uint64_t)n * b / parts),
                       (uint32_t)((uint64_t)n * (b + 1) / parts));
        return;
    }
    if (c->stage == STAGE_BIN_VERTS || c->stage == STAGE_BIN_ROWS) {
        const uint32_t parts = BANDS_PER_JOB * c->jobs;
        const uint32_t n = c->stage == STAGE_BIN_VERTS ? fd->scene->nverts : fd->scene->ntris;
        const uint32_t a = (uint32_t)((uint64_t)n * b / parts), e = (uint32_t)((uint64_t)n * (b + 1) / parts);
        if (c->stage == STAGE_BIN_VERTS) om__bins_make_verts(fd->scene, c->mk_vp, c->mk_w, c->mk_h, c->mk, a, e);
        else om__bins_make_rows(fd->scene, c->mk_vp, c->mk_w, c->mk_h, c->mk, a, e);
        return;
    }
    if (c->stage == STAGE_EYE_HALF) {   /* part b of the triangles, over the whole strip */
        const uint32_t n = fd->scene->ntris, k = c->eye_parts;
        /* the halves: half b into target b; else its thread's target, cleared by
         * the first part the thread runs (only that thread touches it) */
        const uint32_t w = k == 2 ? b : fd->worker(fd->parallel_user) % 2;
        om_target tg = c->tg;
        if (w == 1) {
            tg.depth = c->half_depth;
            tg.id = c->half_id;
        }
        if (!c->part_drawn[w]) {
            om__target_clear(&tg);
            ((frame_ctx *)user)->part_drawn[w] = true;
        }
        om__eye_raster_part(fd->scene, c->view, &tg, (uint32_t)((uint64_t)n * b / k),
                            (uint32_t)((uint64_t)n * (b + 1) / k));
        return;
    }
    if (c->stage == STAGE_BUILD) {
        b = c->slots[b].run;   /* see order_bands */
        uint32_t y0 = b * c->map_band, rows = c->map_size - y0;
        c->bands->build_rows(fd->method_state, c->map_bins.rows ? &c->map_bins : NULL, y0,
                             rows < c->map_band ? rows : c->map_band, c->slots[b].counts);
        return;
    }
    const uint32_t band = stage_rows(c, c->stage), r0 = b * band;
    size_t off = (size_t)r0 * c->strip.width;
    om_strip st = c->strip;
    st.y0 += r0;
    st.rows = c->strip.rows - r0 < band ? c->strip.rows - r0 : band;
    st.samples += off;
    st.terms += off;
    if (c->stage == STAGE_EYE_MERGE) {   /* the second target's nearer pixels; a tie to the lower triangle */
        const size_t n = (size_t)st.rows * st.width;
        uint32_t *depth = c->tg.depth + off, *id = c->tg.id + off;
        const uint32_t *hd = c->half_depth + off, *hi = c->half_id + off;
        if (!c->part_drawn[1]) return;   /* every part in the first */
        if (!c->part_drawn[0]) {         /* every part in the second */
            memcpy(depth, hd, n * sizeof *depth);
            memcpy(id, hi, n * sizeof *id);
            return;
        }
        for (size_t i = 0; i < n; i++)
            if (hd[i] < depth[i] || (hd[i] == depth[i] && hi[i] < id[i])) {
                depth[i] = hd[i];
                id[i] = hi[i];
            }
    } else if (c->stage == STAGE_PREPARE) {
        if (c->eye) {
            om_target tg = c->tg;
            tg.y0 = st.y0;
            tg.rows = st.rows;
            tg.depth += off;
            tg.id += off;
            if (c->half_depth) om__eye_resolve(fd->scene, c->view, &tg, &st, c->mark);   /* merged */
            else eye_rows(c, &tg, &st, c->mark);
        } else if (c->mark) {
            mark_exposed(c->view, &st);
        }
    } else if (c->stage == STAGE_RESOLVE) {
        c->bands->resolve(fd->method_state, &st, c->slots[b].scratch, c->slots[b].counts);
    } else {
        om_framebuffer fb = *fd->fb;
        fb.pixels += (size_t)r0 * fb.stride;
        fb.rows = st.rows;
        om__shade_strip(fd->scene, c->view, fd->shade, &st, &fb);
    }
}

/* A frame of one strip on two jobs splits its eye pass by triangles (see the top)
 * when the scene has more than one vertex for every HALVES_PIXELS pixels: the bins
 * cost about 10 ns a vertex, the second target's clearing and merging about 1.3 ns a
 * pixel (random 100K at 1024x768, 300K vertices: the eye pass's jobs take 8% less
 * CPU time by halves; the default scene, 12K vertices, and random 10K, 30K, take
 * less with the bins). */
#define HALVES_PIXELS 8
/* Parts of the triangles where the host names the thread: as many as the fine bands
 * of two jobs, so that the slower thread waits for at most a small part at the end
 * (random 100K at 1024x768: the halves' jobs took 5.9 and 4.2 ms in one frame). */
#define EYE_PARTS (2 * FINE_BANDS_PER_JOB)

/* At most this many triangles' rows are read to weigh the bands (order_bands). */
#define ORDER_SAMPLES 1024

/* The order the map build's `nb` bands of `band` rows run in (slots[k].run): weighed
 * by the triangles whose bins' rows reach each (every ntris / ORDER_SAMPLES + 1-th
 * triangle, on the calling thread), then dealt heaviest first to the jobs' T shares of
 * the indices, [nb k / T, nb (k + 1) / T) for share k, back and forth (share 0, 1, ..,
 * T - 1, T - 1, .., 0, 0, ..), each share heaviest first; in row order without rows.
 * A heavy band that starts last keeps one thread busy while the others wait (a scene
 * whose triangles crowd a few rows: issue 26's random cloud), and a host that gives each
 * thread its own share of the indices (the platform's pool) would give one thread all
 * the heaviest of bands merely sorted: on random 100K (sm, 1024x768, two threads) the
 * build took 0.80-0.87 of the two CPUs' ideal sorted, 0.94-1.00 dealt. Where T does not
 * divide nb they stay sorted. The strip's stages run in row order: such a host then
 * finds each band's rows in the cache of the thread that wrote them in the last stage
 * (the default scene's eye pass: its bands took 17-20% more CPU time on two threads
 * than on one heaviest first, none more in row order). Which band a job runs changes
 * when it finishes, never a pixel. */
static void order_bands(frame_ctx *c, const uint32_t *rows, uint32_t band, uint32_t nb)
{
    job_slot *sl = c->slots;
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

/* Runs one stage over `nbands` bands on the host's threads. */
static void run_stage(frame_ctx *c, stage sg, uint32_t nbands)
{
    c->stage = sg;
    c->fd->parallel_for(c->fd->parallel_user, band_job, c, nbands);
}

/* The same over the current strip's bands. */
static void run_bands(frame_ctx *c, stage sg)
{
    run_stage(c, sg, stage_bands(c, sg));
}

/* om__bins_make on the host's threads: the vertices, then the triangles' rows, each
 * cut into parts (the same bins however cut: om__bins_make_verts). */
static void make_bins(frame_ctx *c, const om_mat4 *vp, uint32_t w, uint32_t h, const om__bins *b)
{
    if (!OM_WITH_JOBS || c->jobs <= 1) {
        om__bins_make(c->fd->scene, vp, w, h, b);
        return;
    }
    c->mk = b;
    c->mk_vp = vp;
    c->mk_w = w;
    c->mk_h = h;
    run_stage(c, STAGE_BIN_VERTS, BANDS_PER_JOB * c->jobs);
    run_stage(c, STAGE_BIN_ROWS, BANDS_PER_JOB * c->jobs);
}

/* The light depth pass by bands of the map (om__bands.build_rows): with bins,
 * BANDS_PER_JOB bands a job, each setting up only its own triangles; without, one band
 * a job, since each band then walks every triangle. The bands' counts are added up
 * after the map, as the resolve's after a strip. */
static void build_map(frame_ctx *c)
{
    const om_mat4 *vp;
    c->map_size = c->bands->map_of(c->fd->method_state, &vp);
    if (c->map_bins.rows) make_bins(c, vp, c->map_size, c->map_size, &c->map_bins);
    uint32_t n = c->map_bins.rows ? BANDS_PER_JOB * c->jobs : c->jobs;
    c->map_band = ((c->map_size + n - 1) / n + 15) / 16 * 16;
    const uint32_t nb = (c->map_size + c->map_band - 1) / c->map_band;
    for (uint32_t j = 0; j < nb; j++) memset(c->slots[j].counts, 0, sizeof c->slots[j].counts);
    order_bands(c, c->map_bins.rows, c->map_band, nb);
    run_stage(c, STAGE_BUILD, nb);
    uint32_t sum[8] = {0};
    for (uint32_t j = 0; j < nb; j++)
        for (int k = 0; k < 8; k++) sum[k] += c->slots[j].counts[k];
    c->bands->merge(c->fd->method_state, sum);
}

/* The method's pass over the current strip (om__pass): plan, the jobs on their slots,
 * then their counts added up in slot order. Where the host says which thread runs a
 * job (om_frame_desc.worker) and every thread has a slot, each job is one of the
 * host's, on its thread's slot: the host hands them out as threads come free, so a
 * thread that the system slows or a heavy tile holds up no fixed share (on this
 * project's 2-CPU machine the same thread runs up to a third slower than the other
 * for a while). Otherwise slot p runs jobs p, p + P, ... */
static void run_pass(frame_ctx *c)
{
    void *state = c->fd->method_state;
    uint32_t k = c->pass->plan(state, &c->strip);
    if (k == 0) return;
    const bool any = c->fd->worker && c->pass_max >= c->fd->threads;
    const uint32_t p = k < c->pass_max ? k : c->pass_max, used = any ? c->pass_max : p;
    c->pass_jobs = k;
    c->pass_slots_now = p;
    for (uint32_t j = 0; j < used; j++) memset(c->pass_slots[j].counts, 0, sizeof c->pass_slots[j].counts);
    if (any) run_stage(c, STAGE_PASS_ANY, k);
    else run_stage(c, STAGE_PASS, p);
    uint32_t sum[8] = {0};
    for (uint32_t j = 0; j < used; j++)
        for (int i = 0; i < 8; i++) sum[i] += c->pass_slots[j].counts[i];
    c->pass->merge(state, sum);
}

/* The method's begin: with a pass that has its own (om__pass.begin), that one, then
 * the per-frame items it leaves in parts on the host's threads. */
static om_status begin(frame_ctx *c, const om_view *v, om_diag *d)
{
    void *state = c->fd->method_state;
    if (!OM_WITH_JOBS || !c->pass || !c->pass->begin) return c->fd->method->begin(state, v, d);
    om_status st = c->pass->begin(state, v, &c->setup_items, d);
    if (st == OM_OK && c->setup_items) run_stage(c, STAGE_PASS_SETUP, BANDS_PER_JOB * c->jobs);
    return st;
}

/* om__lend.run: a method's own jobs on the pass's slots, from its begin, observe, build
 * or bands' finish on the calling thread (no stage of the frame's is running then). */
static void lend_run(const om__lend *l, void (*fn)(void *user, uint32_t k, void *scratch), void *user, uint32_t n)
{
    frame_ctx *c = (frame_ctx *)l->frame;
    if (n == 0) return;
    c->lend_fn = fn;
    c->lend_user = user;
    c->pass_jobs = n;
    c->pass_slots_now = n < c->pass_max ? n : c->pass_max;
    run_stage(c, STAGE_LEND, c->pass_slots_now);
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
    frame_ctx *c = (frame_ctx *)l->frame;
    if (n == 0) return;
    c->lend_fn = fn;
    c->lend_user = user;
    run_stage(c, STAGE_LEND_ANY, n);
}

/* Bins' memory: the rows, and the vertices when they fit too. False: no room. Not
 * zeroed: make_bins writes every triangle's rows and every vertex before any is read. */
static bool carve_bins(om_arena *fa, const om_scene *s, om__bins *b)
{
    void *pb, *pv;
    b->rows = NULL;
    b->verts = NULL;
    b->centres = false;
    if (!s->ntris || om_arena_left(fa) < om__bins_rows_bytes(s) ||
        om__arena_alloc_raw(fa, (size_t)s->ntris * sizeof(uint32_t), 8, &pb, NULL) != OM_OK)
        return false;
    b->rows = (uint32_t *)pb;
    if (om_arena_left(fa) >= om__bins_verts_bytes(s) &&
        om__arena_alloc_raw(fa, (size_t)s->nverts * sizeof(om__vsnap), 8, &pv, NULL) == OM_OK)
        b->verts = (om__vsnap *)pv;
    return true;
}

/* The eye pass and the exposure marks of the current strip (rows at strip.y0). */
static void prepare(frame_ctx *c, bool eye, bool mark, om_frame_stats *fs)
{
    uint64_t t0 = now(c->fd);
    if (OM_WITH_JOBS && c->jobs > 1) {
        c->eye = eye;
        c->mark = mark;
        if (eye && c->half_depth) {
            c->part_drawn[0] = c->part_drawn[1] = false;
            run_stage(c, STAGE_EYE_HALF, c->eye_parts);
            run_bands(c, STAGE_EYE_MERGE);
        }
        run_bands(c, STAGE_PREPARE);
    } else {
        if (eye) eye_rows(c, &c->tg, &c->strip, mark);
        else if (mark) mark_exposed(c->view, &c->strip);
    }
    if (eye) {
        fs->ns_eye += now(c->fd) - t0;
        fs->eye_passes++;
    }
}

/* Moves the strip (and its target) to rows [y, y + rows). */
static void strip_at(frame_ctx *c, uint32_t y, uint32_t rows)
{
    uint32_t H = c->strip.height;
    c->strip.y0 = c->tg.y0 = y;
    c->strip.rows = c->tg.rows = y + rows > H ? H - y : rows;
}

/* Carves the jobs' slots: as many as the host asks for and the arena holds beyond
 * `keep` bytes (at least two, or none and the frame runs inline). A method with a pass
 * (om__pass) gets a pass slot a job, with the state's scratch; where fewer than two
 * fit, it resolves a strip at a time (its bands unused) and the jobs are only the eye
 * pass's and shading's. A pass that only lends (frame.h) takes what the bands' jobs
 * leave: as many slots as fit beside them, up to one a job, or none. */
static void carve_jobs(frame_ctx *c, om_arena *fa, size_t keep)
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
    if (jobs < 2 || om_arena_alloc(fa, nslots * sizeof(job_slot), 8, &p, NULL)) return;
    c->slots = (job_slot *)p;
    for (uint32_t j = 0; b && j < nslots; j++)
        if (om_arena_alloc(fa, b->scratch ? b->scratch : 1, 16, &c->slots[j].scratch, NULL))
            return;   /* cannot happen: `per` counted it */
    if (ps) {
        if (om_arena_alloc(fa, lent * sizeof(job_slot), 8, &p, NULL)) return;
        c->pass_slots = (job_slot *)p;
        /* The scratch is zeroed by each slot's first job (band_job), in parallel: for
         * izb it is megabytes a thread. */
        for (uint32_t j = 0; j < lent; j++) {
            if (om__arena_alloc_raw(fa, pscratch ? pscratch : 1, 16, &c->pass_slots[j].scratch, NULL))
                return;   /* cannot happen: counted above */
            c->pass_slots[j].dirty = pscratch ? pscratch : 1;
        }
        c->pass = ps;
        c->pass_max = lent;
    }
    c->bands = b;
    c->jobs = jobs;
    /* Bands of whole 16-row blocks (methods tile strips by 16 from their top row, so a
     * band resolves the same blocks the strip would), at most one a slot. */
    uint32_t rows = c->tg.rows, want = (rows + BANDS_PER_JOB * jobs - 1) / (BANDS_PER_JOB * jobs);
    c->band_rows = (want + 15) / 16 * 16;
    want = (rows + nslots - 1) / nslots;
    c->fine_rows = (want + 15) / 16 * 16;
}

om_status om_render_frame(const om_frame_desc *fd, om_arena *fa, om_frame_stats *stats,
                          om_diag *d)
{
    om_frame_stats local;
    om_frame_stats *fs = stats ? stats : &local;
    memset(fs, 0, sizeof *fs);
    if (!fd || !fd->scene || !fd->view || !fd->method || !fd->fb || !fd->shade)
        return om__fail(d, OM_E_INVALID, "frame needs a scene, view, method, shading and framebuffer");
    const om_scene *s = fd->scene;
    const om_method *m = fd->method;
    uint32_t W = fd->view->cam.width, H = fd->view->cam.height;
    uint32_t rows = fd->strip_rows == 0 || fd->strip_rows > H ? H : fd->strip_rows;
    if (fd->fb->width != W || fd->fb->rows < rows || !fd->fb->pixels ||
        fd->fb->stride < (size_t)W * om_format_bpp(fd->fb->format))
        return om__fail(d, OM_E_INVALID, "framebuffer must be as wide as the image and hold a strip");

    size_t mark = om_arena_mark(fa);
    om_status st;
    void *pd, *pi, *ps, *pt;
    size_t n = (size_t)W * rows;
    /* Not zeroed (44 bytes a pixel, on one thread): every strip's eye pass clears its
     * rows of depth and id and writes every sample, and its exposure marks (or
     * mark_exposed) every term, before anything reads them. */
    if ((st = om__arena_alloc_raw(fa, n * sizeof(uint32_t), 8, &pd, d)) ||
        (st = om__arena_alloc_raw(fa, n * sizeof(uint32_t), 8, &pi, d)) ||
        (st = om__arena_alloc_raw(fa, n * sizeof(om_sample), 8, &ps, d)) ||
        (st = om__arena_alloc_raw(fa, n * sizeof(om_term), 8, &pt, d))) {
        om_arena_rewind(fa, mark);
        return st;
    }
    om_view view = *fd->view;
    frame_ctx c;
    memset(&c, 0, sizeof c);
    c.fd = fd;
    c.view = &view;
    c.tg.width = W; c.tg.height = H; c.tg.y0 = 0; c.tg.rows = rows;
    c.tg.depth = (uint32_t *)pd;
    c.tg.id = (uint32_t *)pi;
    c.strip.width = W; c.strip.height = H; c.strip.y0 = 0; c.strip.rows = rows;
    c.strip.samples = (om_sample *)ps;
    c.strip.terms = (om_term *)pt;

    const bool single = rows == H;
    /* Bins when the frame has strips (or bands) and the arena has room (om__bins): each
     * strip then sets up only its own triangles, from vertices projected once (the same
     * pixels; without room, every strip walks every triangle). The camera's matrix
     * does not change within the frame. With strips the bins come before the jobs'
     * slots, as they did before there were jobs; one strip needs them only for bands. */
    om__bins bins = {NULL, NULL, false};
    bool eye_bins = !single && carve_bins(fa, s, &bins);
    /* The jobs, keeping beside them the bins they use when two jobs fit as well: one
     * strip's bands want the camera's, a map built by bands the light's. */
    {
        const om__bands *b = m->bands;
        size_t keep = (single ? bins_bytes(s) : 0) + map_bins_bytes(b, s);
        carve_jobs(&c, fa, om_arena_left(fa) >= keep + om_frame_bytes_jobs(m, NULL, 2) ? keep : 0);
    }
    if (single && OM_WITH_JOBS && c.jobs == 2 && (uint64_t)s->nverts * HALVES_PIXELS > n) {
        /* the second half's depth and ids in the samples (8 bytes of a sample's 32),
         * which the eye pass writes once the halves are merged: in the last quarter,
         * the samples of the last rows, which the thread that draws the second half
         * resolves where each thread has its own chunk of the bands (om_jobs_for) */
        c.half_depth = (uint32_t *)ps + n * (sizeof(om_sample) / sizeof(uint32_t) - 2);
        c.half_id = c.half_depth + n;
        c.eye_parts = fd->worker && fd->threads == 2 ? EYE_PARTS : 2;
    } else if (single && OM_WITH_JOBS && c.jobs > 1) {
        eye_bins = carve_bins(fa, s, &bins);
    }
    if (eye_bins) {
        uint64_t tb = now(fd);
        bins.centres = true;   /* the eye samples pixel centres alone */
        make_bins(&c, &view.cam_vp, W, H, &bins);
        fs->ns_eye += now(fd) - tb;
        c.bins = &bins;
    }
    if (OM_WITH_JOBS && c.jobs > 1 && c.bands && c.bands->build_rows) carve_bins(fa, s, &c.map_bins);
    fs->jobs = c.jobs;
    om__lend lend = {lend_run, lend_run_any, &c, c.pass_max};
    if (OM_WITH_JOBS && c.pass && c.pass->lend) c.pass->lend(fd->method_state, &lend);
    const bool observes = (m->flags & OM_METHOD_OBSERVES) && (!m->observes || m->observes(fd->method_state));
    const bool fit = view.light.kind == OM_LIGHT_DIRECTIONAL;
    bool have_samples = false;   /* strip.samples hold the whole frame already */
    bool have_terms = false;     /* and strip.terms their exposure (mark_exposed) */
    uint64_t t0;
    /* More than one pass over an image in strips: its ids kept where they fit, last,
     * so they never take the room of the bins or the jobs (om_frame_bytes_ids). Not
     * zeroed: the first pass writes them all before the next reads any. */
    if (!single && (fit || observes) && om_arena_left(fa) >= om_frame_bytes_ids(s, W, H) &&
        om__arena_alloc_raw(fa, ids_bytes(s, W, H), 8, &c.ids, NULL) == OM_OK)
        c.ids16 = s->ntris < 0xFFFFu;

    if (fit) {
        om_vec3 lo = om__v3(0, 0, 0), hi = om__v3(0, 0, 0);
        bool any = false;
        for (uint32_t y = 0; y < H; y += rows) {
            strip_at(&c, y, rows);
            prepare(&c, true, false, fs);
            grow_light_box(&view, &c.strip, &lo, &hi, &any);
        }
        if (any) om_view_fit_light(&view, s, lo, hi);
        have_samples = single;
        c.ids_have = c.ids != NULL;
    }
    /* The method's per-frame set-up (izb's and ref's vertex projection) counts as
     * build time, so the stage times add up to the frame (om_frame_stats). */
    t0 = now(fd);
    st = begin(&c, &view, d);
    fs->ns_build += now(fd) - t0;
    if (st != OM_OK) goto done;
    if (observes) {
        for (uint32_t y = 0; y < H; y += rows) {
            strip_at(&c, y, rows);
            prepare(&c, !have_samples, true, fs);
            t0 = now(fd);
            st = m->observe(fd->method_state, &c.strip, d);
            fs->ns_observe += now(fd) - t0;
            if (st != OM_OK) goto done;
        }
        have_samples = single;
        have_terms = single;   /* observe leaves the strip as marked */
        c.ids_have = c.ids != NULL;
    }
    t0 = now(fd);
    if (OM_WITH_JOBS && c.jobs > 1 && c.bands && c.bands->build_rows) build_map(&c);
    else st = m->build(fd->method_state, d);
    fs->ns_build += now(fd) - t0;
    if (st != OM_OK) goto done;
    for (uint32_t y = 0; y < H; y += rows) {
        strip_at(&c, y, rows);
        prepare(&c, !have_samples, !have_terms, fs);
        t0 = now(fd);
        if (OM_WITH_JOBS && (c.bands || c.pass)) {
            if (c.bands) {
                for (uint32_t j = 0; j < FINE_BANDS_PER_JOB * c.jobs; j++)
                    memset(c.slots[j].counts, 0, sizeof c.slots[j].counts);
                run_bands(&c, STAGE_RESOLVE);
                uint32_t sum[8] = {0};
                for (uint32_t j = 0; j < FINE_BANDS_PER_JOB * c.jobs; j++)
                    for (int k = 0; k < 8; k++) sum[k] += c.slots[j].counts[k];
                c.bands->merge(fd->method_state, sum);
            }
            if (c.pass) run_pass(&c);
            if (c.bands && c.bands->finish) c.bands->finish(fd->method_state, &c.strip);
        } else {
            st = m->resolve(fd->method_state, &c.strip, d);
        }
        fs->ns_resolve += now(fd) - t0;
        if (st != OM_OK) goto done;
        t0 = now(fd);
        if (OM_WITH_JOBS && c.jobs > 1) run_bands(&c, STAGE_SHADE);
        else om__shade_strip(s, &view, fd->shade, &c.strip, fd->fb);
        fs->ns_shade += now(fd) - t0;
        fs->strips++;
        if (fd->on_strip && (st = fd->on_strip(fd->user, &c.strip, fd->fb)) != OM_OK) goto done;
    }
done:
    if (OM_WITH_JOBS && c.pass && c.pass->lend) c.pass->lend(fd->method_state, NULL);
    fs->frame_peak = fa->peak;
    om_arena_rewind(fa, mark);
    return st;
}
