/* rtw_jobs.c — Rectilinear Texture Warping's backward analysis on the host's threads
 * (method.h's om__lend, through rtw's om__pass), with the importance map the same bits
 * as on one thread.
 *
 * The analysis keeps, per cell of the importance map, the largest importance of the
 * exposed samples that fall in it and whether any fell (section 4.1): a maximum and a
 * set bit, the same in any order and however the samples are split. So a strip's
 * samples go by bands of rows, each band into its job's own map (a slot's scratch,
 * zeroed by the frame once a frame), and before the warp is made the slots' maps are
 * folded into the state's by cells, as jobs too. On one thread, without the host's
 * threads or where the frame's arena has no room for the slots, rtw_warp.c analyses
 * into the state's map directly. */
#include "../method.h"
#include "rtw.h"

#if OM_WITH_JOBS

/* Jobs a slot for the fold. */
#define PARTS 4

extern const om_method om__method_rtw;

/* A slot's scratch: the table of every slot's scratch (om__lend_table: slot 0's alone
 * is used; the fold reads every slot, so more threads analyse with OM__LEND_SLOTS),
 * then its importance map, n * n floats, and its seen bits. */
#define TABLE_BYTES (OM__LEND_SLOTS * sizeof(void *))

static size_t slot_bytes(uint32_t n)
{
    const size_t nn = (size_t)n * n;
    return TABLE_BYTES + nn * sizeof(float) + (nn + 7) / 8;
}

static float *slot_imp(void *scratch) { return (float *)(void *)((char *)scratch + TABLE_BYTES); }

static uint8_t *slot_seen(void *scratch, uint32_t n)
{
    return (uint8_t *)scratch + TABLE_BYTES + (size_t)n * n * sizeof(float);
}

/* om__pass.scratch: a slot's bytes; without a state, for the default settings. */
static size_t rtw_pass_scratch(const void *state, const om_scene *s)
{
    if (state) return slot_bytes(((const om__rtw *)state)->n);
    if (!s) return 0;
    om_method_cfg mc;
    om__rtw_cfg c;
    om_method_cfg_default(&mc, &om__method_rtw);
    if (om__method_cfg_of(&mc, &om__method_rtw, &c, NULL)) return 0;
    return slot_bytes(om__rtw_importance_side(&c));
}

/* rtw has no pass over the resolve's samples (its bands do that): lend only. */
static uint32_t rtw_pass_plan(void *state, om_strip *strip)
{
    (void)state;
    (void)strip;
    return 0;
}

/* om__pass.lend: the slots for this frame. */
static void rtw_lend(void *state, const om__lend *l)
{
    if (state) om__lent_take(&((om__rtw *)state)->lent, l);
}

const om__pass om__pass_rtw = {rtw_pass_scratch, rtw_pass_plan, NULL, NULL, NULL, NULL, rtw_lend};

typedef struct obs_job {
    const om__rtw *m;
    const om_strip *st;
} obs_job;

static void obs_fn(void *user, uint32_t y0, uint32_t rows, void *scratch)
{
    const obs_job *j = (const obs_job *)user;
    const size_t at = (size_t)y0 * j->st->width;
    om__rtw_observe_into(j->m, j->st->samples + at, j->st->terms + at, (size_t)rows * j->st->width,
                         slot_imp(scratch), slot_seen(scratch, j->m->n));
}

bool om__rtw_observe_jobs(om__rtw *m, const om_strip *st)
{
    if (!m->lent.lend) return false;
    obs_job j = {m, st};
    om__lent_rows(&m->lent, st->rows, obs_fn, &j);
    return true;
}

typedef struct fold_job {
    om__rtw *m;
    size_t part;   /* cells a job, a multiple of 8 (whole bytes of seen bits) */
} fold_job;

static void fold_fn(void *user, uint32_t k, void *scratch)
{
    (void)scratch;
    const fold_job *j = (const fold_job *)user;
    om__rtw *m = j->m;
    const size_t nn = (size_t)m->n * m->n, c0 = k * j->part, c1 = nn - c0 < j->part ? nn : c0 + j->part;
    for (uint32_t s = 0; s < m->lent.nslot; s++) {
        const float *imp = slot_imp(m->lent.slot[s]);
        const uint8_t *seen = slot_seen(m->lent.slot[s], m->n);
        for (size_t c = c0; c < c1; c++)
            if (imp[c] > m->imp[c]) m->imp[c] = imp[c];
        for (size_t b = c0 / 8; b < (c1 + 7) / 8; b++) m->seen[b] |= seen[b];
    }
}

void om__rtw_observe_fold(om__rtw *m)
{
    if (!m->lent.used) return;
    const size_t nn = (size_t)m->n * m->n;
    const uint32_t parts = PARTS * m->lent.nslot;
    fold_job j = {m, ((nn + parts - 1) / parts + 7) / 8 * 8};
    m->lent.lend->run_any(m->lent.lend, fold_fn, &j, (uint32_t)((nn + j.part - 1) / j.part));
    m->lent.used = false;
}

#endif
