/* hybrid_tile.c — hybrid's irregular pass over one tile of the samples its map leaves
 * uncertain (hybrid.c has the map, the tiling and the proof of the certain answers).
 *
 * The tile's samples are sorted into a grid of square cells fitted to their bounds on
 * the light's grid (at most CELL_SAMPLES cells a sample, the side a power of two), and
 * each block of BLOCK x BLOCK cells keeps the farthest of their depths. A triangle then
 * reaches only the blocks its bounds touch that hold samples farther than its nearest
 * depth, and in them the cells its edges touch. With its vertices projected once a
 * frame (no clipping), that is checked before any setup: first against the tile's
 * bounds and farthest depth (a tile of a few rows of the image lies in a small part of
 * the light's grid), then against the blocks, and where its bounds reach a few cells,
 * whether any open sample there lies within them, farther; so a triangle near no
 * uncertain sample costs a few comparisons. Every sample it reaches gets the shared
 * predicate, om__blocks; semi-transparent casters add their optical depth (integer
 * sums, the same in any order), and an opaquely shadowed sample is done: it leaves
 * its cell's open samples (each cell keeps them first), so no later triangle visits
 * it. The grid depends on the tile's samples alone, and every triangle visits each
 * sample that is still open in the cells it reaches once, whatever their order in a
 * cell, so the terms and the counts do not depend on where the tile runs or what its
 * memory held. */
#include "hybrid.h"

/* Cells per side of a block (the coarse level a triangle looks at first). */
#define BLOCK 4
/* Most cells of a tile's grid per sample: finer cells let a small triangle reach
 * fewer samples, more of them cost a large one more cell tests (on the Cortex-M4's
 * small scene 1 cost 23.4 M instructions a frame, 2 23.9 M, 4 25.1 M). */
#define CELL_SAMPLES 1u
/* Most cells a triangle's bounds may reach for the samples in them to be checked
 * against it before its setup. */
#define NEAR_CELLS 16u

static uint32_t cells_cap(uint32_t cap) { return (cap ? cap : 1) * CELL_SAMPLES; }
/* Once sorted, the samples' cells (om__htile.cell, one a sample) become each cell's
 * end of open samples (oend, one a cell): as many while a cell is a sample at most. */
typedef char one_cell_a_sample[CELL_SAMPLES == 1 ? 1 : -1];
/* ceil(w / 4) ceil(h / 4) <= w h / 16 + (w + h) / 4 + 1, and w + h <= w h + 1 */
static uint32_t blocks_cap(uint32_t cap) { return cells_cap(cap) / 16 + (cells_cap(cap) + 1) / 4 + 2; }

/* Each array starts on 16 bytes. */
static size_t up16(size_t n) { return (n + 15) & ~(size_t)15; }

size_t om__htile_bytes(uint32_t cap)
{
    return 2 * up16((size_t)cap * sizeof(om__hkey)) + up16((size_t)cap * sizeof(om__odepth)) +
           up16((size_t)cap * sizeof(uint32_t)) + up16((size_t)cells_cap(cap) * sizeof(uint32_t)) +
           up16((size_t)blocks_cap(cap) * sizeof(uint32_t));
}

void om__htile_carve(om__htile *t, void *mem, uint32_t cap)
{
    unsigned char *p = (unsigned char *)mem;
    memset(t, 0, sizeof *t);
    t->cap = cap;
    t->raw = (om__hkey *)p;
    p += up16((size_t)cap * sizeof(om__hkey));
    t->smp = (om__hkey *)p;
    p += up16((size_t)cap * sizeof(om__hkey));
    t->od = (om__odepth *)p;
    p += up16((size_t)cap * sizeof(om__odepth));
    t->cell = t->oend = (uint32_t *)p;
    p += up16((size_t)cap * sizeof(uint32_t));
    t->cend = (uint32_t *)p;
    p += up16((size_t)cells_cap(cap) * sizeof(uint32_t));
    t->bzmax = (uint32_t *)p;
}

/* The tile's grid: the finest cells of a power-of-two side over the samples' bounds
 * with at most CELL_SAMPLES cells a sample. */
static void fit_cells(om__htile *t, uint32_t n)
{
    const om__lvbox *x = &t->box;
    const uint64_t want = (uint64_t)n * CELL_SAMPLES;
    const uint32_t sx = (uint32_t)((int64_t)x->hix - x->lox), sy = (uint32_t)((int64_t)x->hiy - x->loy);
    int cs = 0;
    while (((uint64_t)(sx >> cs) + 1) * ((uint64_t)(sy >> cs) + 1) > want) cs++;
    t->ox = x->lox;
    t->oy = x->loy;
    t->cs = cs;
    t->cw = (sx >> cs) + 1;
    t->ch = (sy >> cs) + 1;
    t->cbw = (t->cw + BLOCK - 1) / BLOCK;
}

/* Sorts the tile's n samples by cell (a counting sort through cend, stable: strip
 * order within a cell), notes each block's farthest depth and clears their optical
 * depths. */
static void sort_tile(om__htile *t, uint32_t n)
{
    om__lvbox *x = &t->box;
    x->lox = x->loy = INT32_MAX;
    x->hix = x->hiy = INT32_MIN;
    x->z = 0;
    for (uint32_t i = 0; i < n; i++) {
        const om__hkey *q = &t->raw[i];
        if (q->x < x->lox) x->lox = q->x;
        if (q->x > x->hix) x->hix = q->x;
        if (q->y < x->loy) x->loy = q->y;
        if (q->y > x->hiy) x->hiy = q->y;
        if (q->z > x->z) x->z = q->z;
    }
    fit_cells(t, n);
    const size_t nc = (size_t)t->cw * t->ch;
    memset(t->bzmax, 0, (size_t)t->cbw * ((t->ch + BLOCK - 1) / BLOCK) * sizeof *t->bzmax);
    memset(t->cend, 0, nc * sizeof *t->cend);
    memset(t->od, 0, (size_t)n * sizeof *t->od);
    for (uint32_t i = 0; i < n; i++) {
        const om__hkey *q = &t->raw[i];
        const uint32_t cx = (uint32_t)(q->x - t->ox) >> t->cs, cy = (uint32_t)(q->y - t->oy) >> t->cs;
        const uint32_t c = cy * t->cw + cx, b = cy / BLOCK * t->cbw + cx / BLOCK;
        t->cell[i] = c;
        t->cend[c]++;
        if (q->z > t->bzmax[b]) t->bzmax[b] = q->z;
    }
    uint32_t sum = 0;
    for (size_t c = 0; c < nc; c++) {   /* counts -> starts */
        uint32_t k = t->cend[c];
        t->cend[c] = sum;
        sum += k;
    }
    for (uint32_t i = 0; i < n; i++) t->smp[t->cend[t->cell[i]]++] = t->raw[i];   /* starts -> ends */
    memcpy(t->oend, t->cend, nc * sizeof *t->oend);   /* every sample open */
}

/* The cells a grid box reaches (one that meets the tile's bounds): clamped to the
 * bounds first, so the shifts are of 32 bits. */
typedef struct crange { uint32_t x0, y0, x1, y1; } crange;

static inline crange cells_in(const om__htile *t, int64_t lox, int64_t loy, int64_t hix, int64_t hiy)
{
    const om__lvbox *x = &t->box;
    crange r;
    r.x0 = (uint32_t)((lox > x->lox ? lox : x->lox) - t->ox) >> t->cs;
    r.y0 = (uint32_t)((loy > x->loy ? loy : x->loy) - t->oy) >> t->cs;
    r.x1 = (uint32_t)((hix < x->hix ? hix : x->hix) - t->ox) >> t->cs;
    r.y1 = (uint32_t)((hiy < x->hiy ? hiy : x->hiy) - t->oy) >> t->cs;
    return r;
}

static inline int32_t min3(int32_t a, int32_t b, int32_t c) { return a < b ? (a < c ? a : c) : (b < c ? b : c); }
static inline int32_t max3(int32_t a, int32_t b, int32_t c) { return a > b ? (a > c ? a : c) : (b > c ? b : c); }

/* Triangle tri's projected vertices against the tile, an axis at a time: -1 when its
 * bounds miss the tile's or it is nowhere nearer than their farthest (it blocks none
 * of them), 1 with v its bounds and nearest vertex depth, 0 when it needs clipping (or
 * the projection is not kept). */
static int vbox_near(const om__hscene *h, const om__htile *t, uint32_t tri, om__lvbox *v)
{
    const om__lvert *vs = h->ls->verts;
    if (!vs) return 0;
    const uint32_t *ix = h->scene->idx + (size_t)tri * 3;
    const om__lvert *a = &vs[ix[0]], *b = &vs[ix[1]], *c = &vs[ix[2]];
    if (a->x == INT32_MIN || b->x == INT32_MIN || c->x == INT32_MIN) return 0;
    const om__lvbox *x = &t->box;
    v->lox = min3(a->x, b->x, c->x);
    v->hix = max3(a->x, b->x, c->x);
    if (v->hix < x->lox || v->lox > x->hix) return -1;
    v->loy = min3(a->y, b->y, c->y);
    v->hiy = max3(a->y, b->y, c->y);
    if (v->hiy < x->loy || v->loy > x->hiy) return -1;
    v->z = a->z < b->z ? (a->z < c->z ? a->z : c->z) : (b->z < c->z ? b->z : c->z);
    return v->z >= x->z ? -1 : 1;
}

/* Does a block that r reaches hold a sample farther than depth z? (A triangle whose
 * every depth plus bound is at z or beyond blocks none there.) */
static bool any_farther(const om__htile *t, const crange *r, uint32_t z)
{
    for (uint32_t by = r->y0 / BLOCK; by <= r->y1 / BLOCK; by++)
        for (uint32_t bx = r->x0 / BLOCK; bx <= r->x1 / BLOCK; bx++)
            if (t->bzmax[by * t->cbw + bx] > z) return true;
    return false;
}

/* Is an open sample in the cells of r inside v's bounds and farther than its nearest
 * vertex? */
static bool any_within(const om__htile *t, const crange *r, const om__lvbox *v)
{
    const int32_t lox = v->lox, hix = v->hix, loy = v->loy, hiy = v->hiy;
    const uint32_t z = v->z;
    for (uint32_t cy = r->y0; cy <= r->y1; cy++)
        for (uint32_t cx = r->x0; cx <= r->x1; cx++) {
            const size_t c = (size_t)cy * t->cw + cx;
            const om__hkey *q = t->smp + (c ? t->cend[c - 1] : 0), *end = t->smp + t->oend[c];
            for (; q < end; q++)
                if (q->x >= lox && q->x <= hix && q->y >= loy && q->y <= hiy && q->z > z) return true;
        }
    return false;
}

/* Could a sub-triangle of lt cover a point of cell (cx, cy)? */
static bool cell_touches(const om__htile *t, const om__ltri *lt, uint32_t cx, uint32_t cy)
{
    const int64_t x0 = t->ox + ((int64_t)cx << t->cs), y0 = t->oy + ((int64_t)cy << t->cs);
    const int64_t x1 = x0 + ((int64_t)1 << t->cs) - 1, y1 = y0 + ((int64_t)1 << t->cs) - 1;
    for (int k = 0; k < lt->n; k++)
        if (om__square_touches(&lt->sub[k].e, x0, y0, x1, y1)) return true;
    return false;
}

/* Sample i of a cell whose open samples end at *oend is done: the last open one takes
 * its place (with its optical depth) and it goes after them. */
static void close_sample(om__htile *t, uint32_t i, uint32_t *oend)
{
    const uint32_t j = --*oend;
    const om__hkey q = t->smp[i];
    const om__odepth o = t->od[i];
    t->smp[i] = t->smp[j];
    t->od[i] = t->od[j];
    t->smp[j] = q;
    t->od[j] = o;
}

/* Triangle tri against the tile's samples; returns how many it shadowed opaquely. */
static uint32_t cast(const om__hscene *h, om__htile *t, uint32_t tri)
{
    om__lvbox v;
    const int near = vbox_near(h, t, tri, &v);
    if (near < 0) return 0;
    if (near > 0) {
        /* its bounds are its vertices', its plane's depth lies within theirs */
        crange r = cells_in(t, v.lox, v.loy, v.hix, v.hiy);
        if (!any_farther(t, &r, v.z)) return 0;
        if ((r.x1 - r.x0 + 1) * (r.y1 - r.y0 + 1) <= NEAR_CELLS && !any_within(t, &r, &v)) return 0;
    }
    om__ltri lt;
    if (!om__lspace_tri(h->ls, tri, &lt)) return 0;
    t->setups++;
    const om__lvbox *x = &t->box;
    if (lt.hix < x->lox || lt.lox > x->hix || lt.hiy < x->loy || lt.loy > x->hiy) return 0;
    const om__odepth *od = &h->mat_od[h->scene->tri_mat[tri]];
    const crange r = cells_in(t, lt.lox, lt.loy, lt.hix, lt.hiy);
    uint32_t closed = 0;
    for (uint32_t by = r.y0 / BLOCK; by <= r.y1 / BLOCK; by++)
        for (uint32_t bx = r.x0 / BLOCK; bx <= r.x1 / BLOCK; bx++) {
            if ((double)t->bzmax[by * t->cbw + bx] <= lt.zmin) continue;
            const uint32_t ya = by * BLOCK > r.y0 ? by * BLOCK : r.y0, yb = by * BLOCK + BLOCK - 1 < r.y1 ? by * BLOCK + BLOCK - 1 : r.y1;
            const uint32_t xa = bx * BLOCK > r.x0 ? bx * BLOCK : r.x0, xb = bx * BLOCK + BLOCK - 1 < r.x1 ? bx * BLOCK + BLOCK - 1 : r.x1;
            for (uint32_t cy = ya; cy <= yb; cy++)
                for (uint32_t cx = xa; cx <= xb; cx++) {
                    const size_t c = (size_t)cy * t->cw + cx;
                    uint32_t i = c ? t->cend[c - 1] : 0;
                    if (i == t->oend[c] || !cell_touches(t, &lt, cx, cy)) continue;
                    while (i < t->oend[c]) {
                        const om__hkey *q = &t->smp[i];
                        if (q->x < lt.lox || q->x > lt.hix || q->y < lt.loy || q->y > lt.hiy) {
                            i++;
                            continue;
                        }
                        om__lpoint p = {q->x, q->y, (double)q->z, q->tri};
                        t->tested++;
                        if (om__blocks(&lt, &p)) {
                            om__odepth_add(&t->od[i], od);
                            if (om__odepth_opaque(&t->od[i])) {
                                close_sample(t, i, &t->oend[c]);   /* i holds the next one now */
                                closed++;
                                continue;
                            }
                        }
                        i++;
                    }
                }
        }
    return closed;
}

void om__htile_run(const om__hscene *h, om__htile *t, uint32_t n, const om_strip *st)
{
    sort_tile(t, n);
    uint32_t open = n;
    for (uint32_t tri = 0; tri < h->scene->ntris && open; tri++) open -= cast(h, t, tri);
    /* The samples under one semi-transparent caster share its optical depth, and each
     * term of one is three exp2 in double (software on a Cortex-M4): the last one is
     * kept, and a sample with the same depth takes its term. */
    om__odepth last = {{0, 0, 0}};
    om_term lt = {255, 255, 255, 0};
    for (uint32_t i = 0; i < n; i++) {
        om_term *term = &st->terms[t->smp[i].idx];
        if (memcmp(&t->od[i], &last, sizeof last)) {
            om__odepth_term(&t->od[i], &lt);
            last = t->od[i];
        }
        term->r = lt.r;
        term->g = lt.g;
        term->b = lt.b;
    }
}
