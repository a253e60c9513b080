/* spsm_observe.c — the Sub-Pixel Shadow Map's observe (not in the paper; spsm.c says
 * why): each exposed sample marks the texel its lookup will centre on, and the build
 * makes records only around the marks. On the host's threads (method.h's om__lend,
 * through spsm's om__pass) a strip's samples go by bands of rows, each into its slot's
 * own marks (a slot's scratch, zeroed by the frame once a frame); set bits are the
 * same in any order and however split, and before the build reads them the slots'
 * marks are ORed into the state's by ranges of words, as jobs too. */
#include "spsm.h"

/* The texel a sample's lookup will centre on, false when the sample does not project.
 * The lookup projects with om__project, whose position is this om__project_xy's: the
 * two agree on every sample. */
static bool sample_texel(const om__spsm_state *m, const om_sample *smp, int64_t *tx, int64_t *ty)
{
    int64_t x, y;
    om_vec4 q = om__mat_apply(&m->view.light_vp, om__v3(smp->p[0], smp->p[1], smp->p[2]));
    if (!om__project_xy(&q, m->size, m->size, &x, &y)) return false;
    *tx = om__spsm_texel_of(m, x);
    *ty = om__spsm_texel_of(m, y);
    return true;
}

/* The marks of `count` samples and their terms, into seen (the state's or a slot's). */
static void observe_into(const om__spsm_state *m, const om_sample *smp, const om_term *terms, size_t count,
                         uint32_t *seen)
{
    for (size_t i = 0; i < count; i++) {
        if (!(terms[i].flags & OM_TERM_EXPOSED)) continue;
        int64_t tx, ty;
        if (!sample_texel(m, &smp[i], &tx, &ty)) continue;
        seen[(size_t)ty * m->words + (size_t)(tx >> 5)] |= 1u << (tx & 31);
    }
}

#if OM_WITH_JOBS

/* Jobs a slot for the fold. */
#define PARTS 4

extern const om_method om__method_spsm;

/* A slot's scratch: the table of every slot's scratch (om__lend_table: slot 0's alone
 * is used; the fold reads every slot, so more threads observe with OM__LEND_SLOTS),
 * then its marks, size * words 32-bit words. */
#define TABLE_BYTES (OM__LEND_SLOTS * sizeof(void *))

static size_t slot_bytes(uint32_t size) { return TABLE_BYTES + (size_t)size * ((size + 31) / 32) * sizeof(uint32_t); }

static uint32_t *slot_seen(void *scratch) { return (uint32_t *)(void *)((char *)scratch + TABLE_BYTES); }

/* om__pass.scratch: a slot's bytes (none where observe marks nothing); without a
 * state, for the default settings. */
static size_t spsm_pass_scratch(const void *state, const om_scene *s)
{
    if (state) {
        const om__spsm_state *m = (const om__spsm_state *)state;
        return m->marks ? slot_bytes(m->size) : 0;
    }
    if (!s) return 0;
    om_method_cfg mc;
    om__spsm_cfg c;
    om_method_cfg_default(&mc, &om__method_spsm);
    if (om__method_cfg_of(&mc, &om__method_spsm, &c, NULL)) return 0;
    return slot_bytes(c.map_size);
}

/* spsm has no pass over the resolve's samples (its bands do that): lend only. */
static uint32_t spsm_pass_plan(void *state, om_strip *strip)
{
    (void)state;
    (void)strip;
    return 0;
}

/* om__pass.lend: the slots for this frame, where observe marks. */
static void spsm_lend(void *state, const om__lend *l)
{
    om__spsm_state *m = (om__spsm_state *)state;
    if (m) om__lent_take(&m->lent, m->marks ? l : NULL);
}

const om__pass om__pass_spsm = {spsm_pass_scratch, spsm_pass_plan, NULL, NULL, NULL, NULL, spsm_lend};

typedef struct obs_job {
    const om__spsm_state *m;
    const om_strip *st;
} obs_job;

static void obs_fn(void *user, uint32_t y0, uint32_t rows, void *scratch)
{
    const obs_job *j = (const obs_job *)user;
    const size_t at = (size_t)y0 * j->st->width;
    observe_into(j->m, j->st->samples + at, j->st->terms + at, (size_t)rows * j->st->width, slot_seen(scratch));
}

typedef struct fold_job {
    om__spsm_state *m;
    size_t part;   /* words a job */
} fold_job;

static void fold_fn(void *user, uint32_t k, void *scratch)
{
    (void)scratch;
    const fold_job *j = (const fold_job *)user;
    om__spsm_state *m = j->m;
    const size_t nw = (size_t)m->size * m->words, w0 = k * j->part, w1 = nw - w0 < j->part ? nw : w0 + j->part;
    for (uint32_t s = 0; s < m->lent.nslot; s++) {
        const uint32_t *seen = slot_seen(m->lent.slot[s]);
        for (size_t w = w0; w < w1; w++) m->seen[w] |= seen[w];
    }
}

void om__spsm_observe_fold(om__spsm_state *m)
{
    if (!m->lent.used) return;
    const size_t nw = (size_t)m->size * m->words;
    const uint32_t parts = PARTS * m->lent.nslot;
    fold_job j = {m, (nw + parts - 1) / parts};
    m->lent.lend->run_any(m->lent.lend, fold_fn, &j, (uint32_t)((nw + j.part - 1) / j.part));
    m->lent.used = false;
}

#else

void om__spsm_observe_fold(om__spsm_state *m) { (void)m; }

#endif

void om__spsm_observe(om__spsm_state *m, const om_strip *st)
{
#if OM_WITH_JOBS
    if (m->lent.lend) {   /* the same marks, by bands */
        obs_job j = {m, st};
        om__lent_rows(&m->lent, st->rows, obs_fn, &j);
        return;
    }
#endif
    observe_into(m, st->samples, st->terms, (size_t)st->rows * st->width, m->seen);
}
