/* asm_jobs.c — Adaptive Shadow Maps on the host's threads: the tile renders, the view
 * analysis of observe and the scan behind resolve's use stamps as jobs (method.h's
 * om__lend, through asm's om__pass), with the tree the same bits as on one thread.
 * asm.c decides what is made and analysed; this file cuts the work into jobs, gives
 * each job its scratch and puts what the jobs found on the tree afterwards, on the
 * calling thread.
 *
 * Tiles: a node's tile depends on its place, the light and the frame's bounds only, so
 * the tiles a build (or an observe) makes are rendered after the nodes are made, one
 * job a tile, each into its own node.
 *
 * Analysis: a strip's analysed samples by bands of rows, each band reading the tree
 * and adding into its job's accumulators (benefits, cell benefits and needs, use
 * marks, counts: sums, maxima and set bits, so the same in any order), added to the
 * tree after the bands. The one thing the analysis does in order is making a root tile
 * where a sample first falls in an empty cell of the base: the bands note each empty
 * cell's first sample and go no further with its samples; after them the root tiles
 * are made in the order of their first samples, which, as long as the pool has a free
 * node for each, is what a strip at a time does (a node taken from the free list
 * replaces nothing, so no use mark decides it); they are rendered as jobs, and the
 * samples that waited are analysed by bands in them. Where the pool would run short,
 * a replacement would depend on the use marks of the samples before it: that strip is
 * analysed a strip at a time instead (asm.c), nothing of the bands kept. Unless no
 * node may be replaced at all (every node was used in the last frame: a full pool
 * under a still view, whose root tiles come from free nodes alone, benefit 0): then
 * the cells of the free nodes' first samples get them, as a strip at a time, every
 * other cell gets none, and the samples that fell in those are counted in their
 * cells, as root_tile counts them. */
#include "../method.h"
#include "asm.h"

#if OM_WITH_JOBS

/* Slots registered (om__lend_table), and so jobs at once for the analysis (its
 * accumulators are read back from every slot): more threads render tiles but analyse
 * with OM__LEND_SLOTS. */

extern const om_method om__method_asm;

/* A slot's scratch, in 32-bit words from its start: slot 0's starts with the table
 * of every slot's scratch (the others leave it unused). */
typedef struct slot_layout {
    size_t hdr, stamp, benefit, ben, need, first, missed, sdepth, sid, cull, gbits, words;
} slot_layout;

static void slot_layout_of(const om__asm_layout *l, uint32_t ntris, bool lean, slot_layout *o)
{
    const size_t count = l->count, c2 = (size_t)l->cells * l->cells, t2 = (size_t)l->tile * l->tile;
    const size_t n = ntris ? ntris : 1;
    size_t w = OM__LEND_SLOTS * sizeof(void *) / sizeof(uint32_t);
    o->hdr = w;
    w += 4;
    o->stamp = w;
    w += (count + 1 + 31) / 32;
    o->benefit = w;
    w += count;
    o->ben = w;
    w += count * c2;
    o->need = w;
    w += count * c2;
    o->first = w;
    w += (size_t)l->base_cells * l->base_cells;
    o->missed = w;
    w += (size_t)l->base_cells * l->base_cells;
    o->sdepth = w;
    w += t2;
    o->sid = w;
    w += t2;
    o->cull = w;
    w += lean ? 0 : n;
    o->gbits = w;
    w += lean ? 0 : (n + 31) / 32;
    o->words = w;
}

static void slot_layout_m(const om__asm_state *m, slot_layout *o)
{
    slot_layout_of(&m->tree.lay, m->scene->ntris, m->lean, o);
}

static void acc_of(const slot_layout *sl, void *scratch, om__asm_acc *a)
{
    uint32_t *w = (uint32_t *)scratch;
    a->hdr = w + sl->hdr;
    a->stamp = w + sl->stamp;
    a->benefit = w + sl->benefit;
    a->ben = w + sl->ben;
    a->need = (float *)(void *)(w + sl->need);
    a->first = w + sl->first;
    a->missed = w + sl->missed;
}

/* om__pass.scratch: a slot's bytes; without a state, for the default settings (the
 * fast mode's, the larger). */
static size_t asm_pass_scratch(const void *state, const om_scene *s)
{
    slot_layout sl;
    if (state) {
        slot_layout_m((const om__asm_state *)state, &sl);
        return sl.words * sizeof(uint32_t);
    }
    if (!s) return 0;
    om_method_cfg mc;
    om__asm_cfg c;
    om__asm_layout l;
    om_method_cfg_default(&mc, &om__method_asm);
    if (om__method_cfg_of(&mc, &om__method_asm, &c, NULL) || om__asm_layout_of(&l, &c, s->ntris, NULL)) return 0;
    slot_layout_of(&l, s->ntris, false, &sl);
    return sl.words * sizeof(uint32_t);
}

/* asm has no pass over the resolve's samples (its bands do that): lend only. */
static uint32_t asm_pass_plan(void *state, om_strip *strip)
{
    (void)state;
    (void)strip;
    return 0;
}

/* om__pass.lend: each slot's scratch found once a frame (om__lend_table). */
static void asm_lend(void *state, const om__lend *l)
{
    om__asm_state *m = (om__asm_state *)state;
    if (!m) return;
    m->lend = NULL;
    m->slot = NULL;
    m->nslot = 0;
    if (!l || l->slots < 2) return;
    uint32_t n;
    void *const *tab = om__lend_table(l, &n);
    slot_layout sl;
    slot_layout_m(m, &sl);
    for (uint32_t k = 0; k < n; k++) ((uint32_t *)tab[k])[sl.hdr + 2] = UINT32_MAX;   /* no node touched yet */
    m->slot = tab;
    m->nslot = n;
    m->lend = l;
}

const om__pass om__pass_asm = {asm_pass_scratch, asm_pass_plan, NULL, NULL, NULL, NULL, asm_lend};

/* ---- tiles */

typedef struct render_job {
    om__asm_state *m;
    const uint32_t *list;
    slot_layout sl;
} render_job;

static void render_fn(void *user, uint32_t k, void *scratch)
{
    const render_job *j = (const render_job *)user;
    uint32_t *w = (uint32_t *)scratch;
    const om__asm_rs rs = {w + j->sl.sdepth, w + j->sl.sid, j->m->lean ? NULL : w + j->sl.cull,
                           j->m->lean ? NULL : w + j->sl.gbits};
    om__asm_render_with(j->m, j->list[k], &rs);
}

bool om__asm_render_list(om__asm_state *m, const uint32_t *list, uint32_t n)
{
    if (!m->lend) return false;
    om__asm_chunks(m);   /* before the jobs, which read them */
    render_job j = {m, list, {0}};
    slot_layout_m(m, &j.sl);
    m->lend->run(m->lend, render_fn, &j, n);
    return true;
}

/* ---- analysis */

typedef struct obs_job {
    const om__asm_state *m;
    const om_strip *st;
    uint32_t band;         /* rows a band */
    bool again;
    slot_layout sl;
} obs_job;

static void obs_fn(void *user, uint32_t k, void *scratch)
{
    const obs_job *j = (const obs_job *)user;
    om__asm_acc a;
    acc_of(&j->sl, scratch, &a);
    const uint32_t y0 = k * j->band, rows = j->st->rows - y0 < j->band ? j->st->rows - y0 : j->band;
    om__asm_observe_rows(j->m, j->st, y0, rows, &a, j->again);
}

/* The bands' findings onto the tree (keep) or dropped, and every slot's accumulators
 * cleared for the next bands. */
static void merge(om__asm_state *m, const slot_layout *sl, bool keep)
{
    om__asm_tree *t = &m->tree;
    const uint32_t count = t->lay.count, c2 = t->lay.cells * t->lay.cells;
    const uint32_t B2 = t->lay.base_cells * t->lay.base_cells;
    om__asm_tile base;
    om__asm_tile_of(t, OM__ASM_ROOT, &base);
    for (uint32_t j = 0; j < m->nslot; j++) {
        om__asm_acc a;
        acc_of(sl, m->slot[j], &a);
        if (keep) {
            m->analysed += a.hdr[0];
            m->straddling += a.hdr[1];
        }
        a.hdr[0] = a.hdr[1] = 0;
        for (uint32_t c = 0; c < B2; c++) {
            if (keep) base.ben[c] += a.missed[c];
            a.missed[c] = 0;
        }
        for (uint32_t w = 0; w < (count + 1 + 31) / 32; w++) {
            for (uint32_t bits = keep ? a.stamp[w] : 0; bits; bits &= bits - 1) {
                const uint32_t i = w * 32 + om__ctz32(bits);
                om__asm_node_at(t, i == count ? OM__ASM_ROOT : i)->stamp = t->frame;
            }
            a.stamp[w] = 0;
        }
        for (uint32_t i = a.hdr[2]; i < a.hdr[3]; i++) {
            if (keep && a.benefit[i]) om__asm_node_at(t, i)->benefit += a.benefit[i];
            a.benefit[i] = 0;
            uint32_t *ben = a.ben + (size_t)i * c2;
            float *need = a.need + (size_t)i * c2;
            om__asm_tile tl;
            if (keep) om__asm_tile_of(t, i, &tl);
            for (uint32_t c = 0; c < c2; c++) {
                if (!ben[c]) continue;
                if (keep) {
                    tl.ben[c] += ben[c];
                    if (need[c] > tl.need[c]) tl.need[c] = need[c];
                }
                ben[c] = 0;
                need[c] = 0.0f;
            }
        }
        a.hdr[2] = UINT32_MAX;
        a.hdr[3] = 0;
    }
}

bool om__asm_observe_jobs(om__asm_state *m, const om_strip *st)
{
    if (!m->lend || st->rows == 0) return false;
    om__asm_tree *t = &m->tree;
    obs_job j;
    j.m = m;
    j.st = st;
    j.again = false;
    slot_layout_m(m, &j.sl);
    /* bands: about four a slot, never more jobs than registered slots run at once */
    uint32_t nb = m->nslot < m->lend->slots ? m->nslot : 4 * m->nslot;
    if (nb > st->rows) nb = st->rows;
    j.band = (st->rows + nb - 1) / nb;
    nb = (st->rows + j.band - 1) / j.band;
    m->lend->run(m->lend, obs_fn, &j, nb);
    /* The empty base cells samples fell in, by their first sample (an insertion sort
     * into the candidates' memory, which keeps as many as there are free nodes). */
    const uint32_t B2 = t->lay.base_cells * t->lay.base_cells, free = t->pool.count - t->pool.in_use;
    uint32_t *order = (uint32_t *)(void *)m->cand, *firsts = order + free, nn = 0;
    bool fits = true, left = false;   /* left: a cell that gets no root tile */
    int spare = -1;                   /* om__asm_lru_spare, asked once */
    for (uint32_t c = 0; c < B2 && fits; c++) {
        uint32_t f = 0;
        for (uint32_t s = 0; s < m->nslot; s++) {
            om__asm_acc a;
            acc_of(&j.sl, m->slot[s], &a);
            if (a.first[c] && (!f || a.first[c] < f)) f = a.first[c];
            a.first[c] = 0;
        }
        if (!f) continue;
        if (nn == free) {   /* more cells than free nodes */
            if (spare < 0) spare = om__asm_lru_spare(t);
            if (spare) {
                fits = false;
                break;
            }
            /* Nothing may be replaced: the cells of the free nodes' first samples get
             * them, and every other cell none, whatever order; their samples count. */
            left = true;
            if (nn == 0 || f > firsts[nn - 1]) continue;
            nn--;   /* the cell of the latest first gives its place up */
        }
        uint32_t k = nn++;
        for (; k > 0 && firsts[k - 1] > f; k--) {
            firsts[k] = firsts[k - 1];
            order[k] = order[k - 1];
        }
        firsts[k] = f;
        order[k] = c;
    }
    if (!fits) {   /* replacements ahead: a strip at a time decides them */
        for (uint32_t s = 0; s < m->nslot; s++) {
            om__asm_acc a;
            acc_of(&j.sl, m->slot[s], &a);
            memset(a.first, 0, B2 * sizeof *a.first);
        }
        merge(m, &j.sl, false);
        const size_t n = (size_t)st->rows * st->width;
        for (size_t i = 0; i < n; i++)
            if (st->terms[i].g == 254) st->terms[i].g = 255;
        return false;
    }
    merge(m, &j.sl, true);
    if (nn == 0 && !left) return true;
    uint32_t nm = 0;
    for (uint32_t k = 0; k < nn; k++) {   /* each from the free list: it cannot fail */
        const uint32_t made = om__asm_make(t, OM__ASM_ROOT, order[k], 0);
        if (made != OM__ASM_NONE) order[nm++] = made;
    }
    if (nm) (void)om__asm_render_list(m, order, nm);
    j.again = true;
    m->lend->run(m->lend, obs_fn, &j, nb);
    merge(m, &j.sl, true);
    return true;
}

/* ---- resolve's use stamps: the terms the bands marked, scanned by parts, each part
 * setting the bits of the leaves it finds in its slot's use bits; after the parts, the
 * calling thread stamps the paths of every leaf set in any slot (the same stamps, in
 * any order, as a strip at a time leaves). */

typedef struct fin_job {
    const om__asm_state *m;
    om_strip *st;
    uint32_t parts;
    slot_layout sl;
} fin_job;

static void fin_fn(void *user, uint32_t k, void *scratch)
{
    const fin_job *j = (const fin_job *)user;
    const uint64_t n = (uint64_t)j->st->rows * j->st->width;
    om__asm_leaves(j->m, j->st, (size_t)(n * k / j->parts), (size_t)(n * (k + 1) / j->parts),
                   (uint32_t *)scratch + j->sl.stamp);
}

bool om__asm_finish_jobs(om__asm_state *m, om_strip *st)
{
    if (!m->lend) return false;
    /* about four parts a slot, never more jobs than registered slots run at once */
    fin_job j = {m, st, m->nslot < m->lend->slots ? m->nslot : 4 * m->nslot, {0}};
    slot_layout_m(m, &j.sl);
    m->lend->run(m->lend, fin_fn, &j, j.parts);
    const uint32_t words = (m->tree.lay.count + 1 + 31) / 32;
    uint32_t *all = (uint32_t *)m->slot[0] + j.sl.stamp;
    for (uint32_t s = 1; s < m->nslot; s++) {   /* into slot 0's, cleared for the next use */
        uint32_t *bits = (uint32_t *)m->slot[s] + j.sl.stamp;
        for (uint32_t w = 0; w < words; w++) {
            all[w] |= bits[w];
            bits[w] = 0;
        }
    }
    om__asm_stamp_leaves(&m->tree, all);
    return true;
}

#else
typedef int om__asm_jobs_none;   /* (ISO C: a translation unit is not empty) */
#endif
