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
#include "hybrid_tile.h"

/* Cells per side of a block (the coarse level a triangle looks at first). */
#define BLOCK 4
/* Most cells of a tile's grid per sample: finer cells let a small triangle reach
 * fewer samples, more of them cost a large one more cell tests; one a sample is the
 * balance on the scenes the project measures. */
#define CELL_SAMPLES 1u
/* Most cells a triangle's bounds may reach for the samples in them to be checked
 * against it before its setup. */
#define NEAR_CELLS 16u
/* Least samples of a region: with room for candidates, a tile of at least two regions'
 * samples is cut into regions of whole rows of its blocks, each of at least this many
 * (and at least a tile's OM__HTILE_REGIONS-th), that walk the tile's candidates apart:
 * jobs of the host's threads, where a tile's walk over the scene's triangles would be
 * one job (a large scene's one tile can be much of the frame). The
 * candidates are the triangles whose projected box meets the tile's bounds nearer
 * than its farthest sample, found once in OM__HTILE_PARTS parts of the triangles and
 * listed by the regions their rows reach; a region then walks its lists and tests
 * their boxes against its own bounds, so a triangle that reaches two regions is set
 * up in each. The cut depends on the tile's samples alone, and each sample meets the
 * triangles that reach it in the scene's order in either walk: the same terms, and
 * the same counts whatever runs the jobs. On one thread it adds a little work but
 * about no time (the candidates are read in order, a line each), and the region's
 * size matters little. */
#define REGION_SAMPLES 8192u
/* Entries of a region's list ahead of the one it walks whose candidate is fetched. */
#define PREFETCH 8

static uint32_t cells_cap(uint32_t cap) { return (cap ? cap : 1) * CELL_SAMPLES; }
/* Once sorted, the samples' cells (om__htile.cell, one a sample) become each cell's
 * end of open samples (oend, one a cell): as many while a cell is a sample at most. */
typedef char one_cell_a_sample[CELL_SAMPLES == 1 ? 1 : -1];
/* ceil(w / 4) ceil(h / 4) <= w h / 16 + (w + h) / 4 + 1, and w + h <= w h + 1 */
static uint32_t blocks_cap(uint32_t cap) { return cells_cap(cap) / 16 + (cells_cap(cap) + 1) / 4 + 2; }

/* Rows of blocks: at most a row of cells a sample, so a row of blocks each BLOCK. */
static uint32_t block_rows_cap(uint32_t cap) { return cells_cap(cap) / BLOCK + 1; }
/* Each array starts on 16 bytes. */
static size_t up16(size_t n) { return (n + 15) & ~(size_t)15; }

size_t om__htile_bytes(uint32_t cap, uint32_t cands)
{
    return 2 * up16((size_t)cap * sizeof(om__hkey)) + up16((size_t)cap * sizeof(om__odepth)) +
           up16((size_t)cap * sizeof(uint32_t)) + up16((size_t)cells_cap(cap) * sizeof(uint32_t)) +
           up16((size_t)blocks_cap(cap) * sizeof(uint32_t)) +
           (cands ? up16((size_t)cands * sizeof(om__hcand)) + up16((size_t)cands * 2 * sizeof(uint32_t)) +
                        up16(OM__HTILE_PARTS * (OM__HTILE_REGIONS + 2) * sizeof(uint32_t)) +
                        up16(OM__HTILE_REGIONS * sizeof(om__hregion)) + up16(block_rows_cap(cap))
                  : 0);
}

void om__htile_carve(om__htile *t, void *mem, uint32_t cap, uint32_t cands)
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
    p += up16((size_t)blocks_cap(cap) * sizeof(uint32_t));
    if (cands) {
        t->cand = (om__hcand *)p;
        p += up16((size_t)cands * sizeof(om__hcand));
        t->list = (uint32_t *)p;
        p += up16((size_t)cands * 2 * sizeof(uint32_t));
        t->at = (uint32_t *)p;
        p += up16(OM__HTILE_PARTS * (OM__HTILE_REGIONS + 2) * sizeof(uint32_t));
        t->reg = (om__hregion *)p;
        p += up16(OM__HTILE_REGIONS * sizeof(om__hregion));
        t->breg = (uint8_t *)p;
    }
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

/* The bounds and farthest depth of keys [i0, i1) of q into *x (none: empty bounds). */
static void box_of(const om__hkey *q, uint32_t i0, uint32_t i1, om__lvbox *x)
{
    x->lox = x->loy = INT32_MAX;
    x->hix = x->hiy = INT32_MIN;
    x->z = 0;
    for (uint32_t i = i0; i < i1; i++) {
        if (q[i].x < x->lox) x->lox = q[i].x;
        if (q[i].x > x->hix) x->hix = q[i].x;
        if (q[i].y < x->loy) x->loy = q[i].y;
        if (q[i].y > x->hiy) x->hiy = q[i].y;
        if (q[i].z > x->z) x->z = q[i].z;
    }
}

/* A sample's cell in the grid, and its block in *b. */
static inline uint32_t cell_of(const om__htile *t, const om__hkey *q, uint32_t *b)
{
    const uint32_t cx = (uint32_t)(q->x - t->ox) >> t->cs, cy = (uint32_t)(q->y - t->oy) >> t->cs;
    *b = cy / BLOCK * t->cbw + cx / BLOCK;
    return cy * t->cw + cx;
}

/* Sorts the tile's n samples by cell (a counting sort through cend, stable: strip
 * order within a cell), notes each block's farthest depth and clears their optical
 * depths. */
static void sort_tile(om__htile *t, uint32_t n)
{
    box_of(t->raw, 0, n, &t->box);
    fit_cells(t, n);
    const size_t nc = (size_t)t->cw * t->ch;
    memset(t->bzmax, 0, (size_t)t->cbw * ((t->ch + BLOCK - 1) / BLOCK) * sizeof *t->bzmax);
    memset(t->cend, 0, nc * sizeof *t->cend);
    memset(t->od, 0, (size_t)n * sizeof *t->od);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t b;
        const om__hkey *q = &t->raw[i];
        const uint32_t c = cell_of(t, q, &b);
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

#if OM_WITH_JOBS
/* ---- sort_tile on the host's threads, for a large tile run in the plan (hybrid.c):
 * the same order. Parts of the raw samples find their bounds; then count their
 * samples into bands of the grid's rows of blocks and copy them, in their order, to
 * their band's place in smp; each band then sorts its samples by cell into raw and
 * back (its cells and blocks are its own: a stable counting sort, as sort_tile's, over
 * a range of cells). The counts and places live in the tile's `at`, unused until its
 * candidates. */
#define SORT_PARTS 16u
typedef char sort_table_fits[SORT_PARTS * (SORT_PARTS + 1) + 1 <= OM__HTILE_PARTS * (OM__HTILE_REGIONS + 2) ? 1 : -1];

typedef struct sort_job {
    om__htile *t;
    uint32_t n, parts, bands, brows;   /* brows: the grid's rows of blocks */
    uint32_t *cnt, *start;             /* parts x bands (then places), bands + 1 */
    om__lvbox box[SORT_PARTS];
} sort_job;

static uint32_t sort_first(const sort_job *j, uint32_t p) { return (uint32_t)((uint64_t)j->n * p / j->parts); }

static uint32_t band_of(const sort_job *j, const om__hkey *q)
{
    const uint32_t br = ((uint32_t)(q->y - j->t->oy) >> j->t->cs) / BLOCK;
    return (uint32_t)((((uint64_t)br + 1) * j->bands - 1) / j->brows);
}

static void box_part(void *user, uint32_t p, void *scratch)
{
    (void)scratch;
    sort_job *j = (sort_job *)user;
    box_of(j->t->raw, sort_first(j, p), sort_first(j, p + 1), &j->box[p]);
}

/* Both count and move on a copy of the part's row of the table: the rows of two parts
 * share cache lines. */
static void count_part(void *user, uint32_t p, void *scratch)
{
    (void)scratch;
    const sort_job *j = (const sort_job *)user;
    uint32_t cnt[SORT_PARTS] = {0};
    for (uint32_t i = sort_first(j, p), end = sort_first(j, p + 1); i < end; i++) cnt[band_of(j, &j->t->raw[i])]++;
    memcpy(j->cnt + (size_t)p * j->bands, cnt, j->bands * sizeof *cnt);
}

static void move_part(void *user, uint32_t p, void *scratch)
{
    (void)scratch;
    const sort_job *j = (const sort_job *)user;
    uint32_t at[SORT_PARTS];
    memcpy(at, j->cnt + (size_t)p * j->bands, j->bands * sizeof *at);
    for (uint32_t i = sort_first(j, p), end = sort_first(j, p + 1); i < end; i++)
        j->t->smp[at[band_of(j, &j->t->raw[i])]++] = j->t->raw[i];
}

static void sort_band(void *user, uint32_t b, void *scratch)
{
    (void)scratch;
    const sort_job *j = (const sort_job *)user;
    om__htile *t = j->t;
    const uint32_t br0 = (uint32_t)((uint64_t)j->brows * b / j->bands), br1 = (uint32_t)((uint64_t)j->brows * (b + 1) / j->bands);
    const uint32_t c0 = br0 * BLOCK * t->cw, c1 = (br1 * BLOCK < t->ch ? br1 * BLOCK : t->ch) * t->cw;
    const uint32_t s0 = j->start[b], s1 = j->start[b + 1];
    memset(t->bzmax + (size_t)br0 * t->cbw, 0, (size_t)(br1 - br0) * t->cbw * sizeof *t->bzmax);
    memset(t->cend + c0, 0, (size_t)(c1 - c0) * sizeof *t->cend);
    memset(t->od + s0, 0, (size_t)(s1 - s0) * sizeof *t->od);
    for (uint32_t i = s0; i < s1; i++) {
        uint32_t k;
        const om__hkey *q = &t->smp[i];
        t->cend[cell_of(t, q, &k)]++;
        if (q->z > t->bzmax[k]) t->bzmax[k] = q->z;
    }
    uint32_t sum = s0;
    for (uint32_t c = c0; c < c1; c++) {   /* counts -> starts */
        const uint32_t k = t->cend[c];
        t->cend[c] = sum;
        sum += k;
    }
    for (uint32_t i = s0; i < s1; i++) {   /* starts -> ends */
        uint32_t k;
        t->raw[t->cend[cell_of(t, &t->smp[i], &k)]++] = t->smp[i];
    }
    memcpy(t->smp + s0, t->raw + s0, (size_t)(s1 - s0) * sizeof *t->smp);
    memcpy(t->oend + c0, t->cend + c0, (size_t)(c1 - c0) * sizeof *t->oend);   /* every sample open */
}

static void sort_parts(om__htile *t, uint32_t n, const om__lend *l)
{
    sort_job j;
    j.t = t;
    j.n = n;
    j.parts = SORT_PARTS;   /* as many as the table holds: bands of uneven cost */
    l->run_any(l, box_part, &j, j.parts);
    om__lvbox *x = &t->box;
    *x = j.box[0];
    for (uint32_t p = 1; p < j.parts; p++) {
        const om__lvbox *y = &j.box[p];
        if (y->lox < x->lox) x->lox = y->lox;
        if (y->hix > x->hix) x->hix = y->hix;
        if (y->loy < x->loy) x->loy = y->loy;
        if (y->hiy > x->hiy) x->hiy = y->hiy;
        if (y->z > x->z) x->z = y->z;
    }
    fit_cells(t, n);
    j.brows = (t->ch + BLOCK - 1) / BLOCK;
    j.bands = j.parts < j.brows ? j.parts : j.brows;
    j.cnt = t->at;
    j.start = t->at + (size_t)j.parts * j.bands;
    l->run_any(l, count_part, &j, j.parts);
    (void)om__hplaces(j.cnt, j.parts, j.bands, j.start);
    l->run_any(l, move_part, &j, j.parts);
    l->run_any(l, sort_band, &j, j.bands);
}

uint64_t om__hplaces(uint32_t *cnt, uint32_t parts, uint32_t bins, uint32_t *start)
{
    uint64_t sum = 0;
    for (uint32_t b = 0; b < bins; b++) {
        start[b] = (uint32_t)sum;
        for (uint32_t p = 0; p < parts; p++) {
            const uint32_t c = cnt[(size_t)p * bins + b];
            cnt[(size_t)p * bins + b] = (uint32_t)sum;
            sum += c;
        }
    }
    start[bins] = (uint32_t)sum;
    return sum;
}
#endif

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

/* Triangle tri against the tile's samples, with vbox_near's answer near (not -1) and
 * box v, and where given its projected vertices pv (set up from those copies: a
 * candidate's vertices were loaded long before); returns how many it shadowed
 * opaquely. */
static uint32_t cast_near(const om__hscene *h, om__htile *t, uint32_t tri, int near, const om__lvbox *vb,
                          const om__lvert *pv)
{
    if (near > 0) {
        /* its bounds are its vertices', its plane's depth lies within theirs */
        const om__lvbox v = *vb;
        crange r = cells_in(t, v.lox, v.loy, v.hix, v.hiy);
        if (!any_farther(t, &r, v.z)) return 0;
        if ((r.x1 - r.x0 + 1) * (r.y1 - r.y0 + 1) <= NEAR_CELLS && !any_within(t, &r, &v)) return 0;
    }
    om__ltri lt;
    if (!(pv ? om__lspace_tri_at(h->ls, tri, pv, &lt) : om__lspace_tri(h->ls, tri, &lt))) return 0;
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

/* Triangle tri against the tile's samples (cast_near), from the start. */
static uint32_t cast(const om__hscene *h, om__htile *t, uint32_t tri)
{
    om__lvbox v;
    const int near = vbox_near(h, t, tri, &v);
    return near < 0 ? 0 : cast_near(h, t, tri, near, &v, NULL);
}

/* The samples [i0, i1) of the sorted tile: their terms into st. */
static void write_terms(const om__htile *t, uint32_t i0, uint32_t i1, const om_strip *st)
{
    /* The samples under one semi-transparent caster share its optical depth, and each
     * term of one is three exp2 in double (software on a Cortex-M4): the last one is
     * kept, and a sample with the same depth takes its term. */
    om__odepth last = {{0, 0, 0}};
    om_term lt = {255, 255, 255, 0};
    for (uint32_t i = i0; i < i1; i++) {
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

/* Part k of the parts' even ranges of n. */
static uint32_t part_of(uint32_t n, uint32_t k) { return (uint32_t)((uint64_t)n * k / OM__HTILE_PARTS); }

/* The first sample of cell c on (the cells' ends, cend, stay as sorted). */
static uint32_t cell_first(const om__htile *t, uint32_t c) { return c ? t->cend[c - 1] : 0; }

/* The regions (REGION_SAMPLES): whole rows of blocks, each closed once it holds its
 * share; a cut that would make one region leaves the tile whole (nreg 1). A region's
 * bounds are its rows' (within the tile's), the tile's across, and its blocks'
 * farthest depth: they hold its samples, and no cell of another region. */
static void cut_regions(om__htile *t)
{
    t->nreg = 1;
    if (!OM_WITH_JOBS || !t->cand || t->n < 2 * REGION_SAMPLES) return;
    const uint32_t share = (t->n + OM__HTILE_REGIONS - 1) / OM__HTILE_REGIONS;
    const uint32_t want = share > REGION_SAMPLES ? share : REGION_SAMPLES;
    const uint32_t rows = (t->ch + BLOCK - 1) / BLOCK;
    uint32_t nreg = 0, c0 = 0;
    for (uint32_t br = 0; br < rows; br++) {
        const uint32_t c1 = (br + 1) * BLOCK < t->ch ? (br + 1) * BLOCK * t->cw : t->ch * t->cw;
        const uint32_t held = t->cend[c1 - 1] - cell_first(t, c0);
        t->breg[br] = (uint8_t)nreg;
        if ((held >= want && nreg + 1 < OM__HTILE_REGIONS) || br + 1 == rows) {
            om__hregion *g = &t->reg[nreg++];
            g->c0 = c0;
            g->c1 = c1;
            g->n = held;
            c0 = c1;
        }
    }
    if (nreg < 2) return;
    for (uint32_t r = 0; r < nreg; r++) {
        om__hregion *g = &t->reg[r];
        const uint32_t y0 = g->c0 / t->cw, y1 = g->c1 / t->cw;   /* its cell rows [y0, y1) */
        const int64_t lo = t->oy + ((int64_t)y0 << t->cs), hi = t->oy + ((int64_t)y1 << t->cs) - 1;
        om__lvbox *x = &g->box;
        *x = t->box;
        if (lo > x->loy) x->loy = (int32_t)lo;
        if (hi < x->hiy) x->hiy = (int32_t)hi;
        x->z = 0;
        for (uint32_t b = y0 / BLOCK * t->cbw; b < (y1 + BLOCK - 1) / BLOCK * t->cbw; b++)
            if (t->bzmax[b] > x->z) x->z = t->bzmax[b];
    }
    t->nreg = nreg;
}

/* A tile's steps: begin (sorts the samples, returns the number of regions); with more
 * than one, the candidates' parts (any order, or at once); the regions (any order, or
 * at once: each writes its own samples' terms); end (adds the regions' counts up in
 * their order). */
static uint32_t tile_begin(om__htile *t, uint32_t n, const om__lend *l)
{
    t->n = n;
#if OM_WITH_JOBS
    if (l && t->cand && n >= 2 * REGION_SAMPLES) sort_parts(t, n, l);
    else sort_tile(t, n);
#else
    (void)l;
    sort_tile(t, n);
#endif
    cut_regions(t);
    return t->nreg;
}

/* The region of the grid's row y (clamped to the tile's cells). */
static inline uint32_t region_at(const om__htile *t, int32_t y)
{
    const int64_t d = (int64_t)y - t->oy;
    const uint64_t cy = d < 0 ? 0 : (uint64_t)d >> t->cs;
    return t->breg[(cy < t->ch ? (uint32_t)cy : t->ch - 1) / BLOCK];
}

/* A candidate's `near` (bit 0) and its regions r0 to r1 (bits 8 on, 16 on): those its
 * rows reach (it reaches the tile's, or vbox_near would have left it out), or every
 * one where it needs clipping. A region walks the candidates that reach it: each
 * part lists them by region, and those that reach more than two in a wide list that
 * every region walks too. */
#define NEAR_OF(n) ((int)((n) & 1u))
#define R0_OF(n) ((n) >> 8 & 255u)
#define R1_OF(n) ((n) >> 16 & 255u)

/* Whether a candidate from region r0 to r1 goes in the wide list (more than two). */
static bool wide(uint32_t r0, uint32_t r1) { return r1 > r0 + 1; }

/* Part `part`'s candidates listed by region (om__htile.list), cnt[r] entries for region
 * r (nreg: the wide list): laid out in their order, so each list keeps the scene's.
 * At most two entries a candidate, so the part's two a slot hold them. */
static void list_part(om__htile *t, uint32_t part, uint32_t first, uint32_t *cnt)
{
    const om__hcand *c = t->cand + first;
    uint32_t *at = t->at + part * (OM__HTILE_REGIONS + 2), *list = t->list + 2 * (size_t)first;
    at[0] = 0;
    for (uint32_t r = 0; r <= t->nreg; r++) {
        at[r + 1] = at[r] + cnt[r];
        cnt[r] = at[r];
    }
    for (uint32_t i = 0; i < t->ncand[part]; i++) {
        const uint32_t r0 = R0_OF(c[i].near), r1 = R1_OF(c[i].near);
        if (wide(r0, r1)) list[cnt[t->nreg]++] = i;
        else
            for (uint32_t r = r0; r <= r1; r++) list[cnt[r]++] = i;
    }
}

static void tile_cands(const om__hscene *h, om__htile *t, uint32_t part)
{
    const uint32_t nt = h->scene->ntris, first = part_of(nt, part), end = part_of(nt, part + 1);
    om__hcand *c = t->cand + first;
    uint32_t k = 0, cnt[OM__HTILE_REGIONS + 1] = {0};
    const om__lvert *vs = h->ls->verts;
    for (uint32_t tri = first; tri < end; tri++) {
        om__lvbox v = {0, 0, 0, 0, 0};
        const int near = vbox_near(h, t, tri, &v);
        if (near < 0) continue;
        const uint32_t *ix = h->scene->idx + (size_t)tri * 3;
        for (int j = 0; j < 3; j++) {
            const om__lvert none = {0, 0, 0};
            c[k].v[j] = near ? vs[ix[j]] : none;
        }
        const uint32_t r0 = near ? region_at(t, v.loy) : 0, r1 = near ? region_at(t, v.hiy) : t->nreg - 1;
        if (wide(r0, r1)) cnt[t->nreg]++;
        else
            for (uint32_t r = r0; r <= r1; r++) cnt[r]++;
        c[k].tri = tri;
        c[k].near = (uint32_t)near | r0 << 8 | r1 << 16;
        c[k].box = v;
        k++;
    }
    t->ncand[part] = k;
    list_part(t, part, first, cnt);
}

/* Candidate c against the region's copy of the tile (walk_region): vbox_near's tests
 * on the region's bounds, then cast_near. */
static uint32_t cast_cand(const om__hscene *h, om__htile *rt, const om__hcand *c)
{
    if (!NEAR_OF(c->near)) return cast_near(h, rt, c->tri, 0, NULL, NULL);
    const om__lvbox *v = &c->box, *x = &rt->box;
    if (v->hiy < x->loy || v->loy > x->hiy || v->hix < x->lox || v->lox > x->hix || v->z >= x->z) return 0;
    return cast_near(h, rt, c->tri, 1, v, c->v);
}

/* Region r's walk of the candidates (each part's list of the region and its wide list,
 * merged: the scene's order), on a copy of the tile bounded by its samples: cast_near
 * then reaches only its cells (cells_in clamps to the bounds, and whole rows of blocks
 * are its own), and counts into the copy. */
static void walk_region(const om__hscene *h, const om__htile *t, uint32_t r)
{
    om__hregion *g = &t->reg[r];
    om__htile rt = *t;
    rt.box = g->box;
    rt.setups = rt.tested = 0;
    uint32_t open = g->n;
    for (uint32_t k = 0; k < OM__HTILE_PARTS && open; k++) {
        const uint32_t first = part_of(h->scene->ntris, k), *at = t->at + k * (OM__HTILE_REGIONS + 2);
        const uint32_t *list = t->list + 2 * (size_t)first;
        const uint32_t *a = list + at[r], *ae = list + at[r + 1];                  /* the region's */
        const uint32_t *w = list + at[t->nreg], *we = list + at[t->nreg + 1];   /* the wide */
        const om__hcand *c = t->cand + first;
        while ((a < ae || w < we) && open) {
#if defined(__GNUC__) || defined(__clang__)
            /* a region's candidates lie apart in the part: their loads overlap */
            if (a + PREFETCH < ae) __builtin_prefetch(&c[a[PREFETCH]]);
#endif
            const uint32_t i = w == we || (a < ae && *a < *w) ? *a++ : *w++;
            open -= cast_cand(h, &rt, &c[i]);
        }
    }
    g->setups = rt.setups;
    g->tested = rt.tested;
}

static void tile_region(const om__hscene *h, om__htile *t, uint32_t r, const om_strip *st)
{
    if (!OM_WITH_JOBS || t->nreg <= 1) {   /* the whole tile, every triangle */
        uint32_t open = t->n;
        for (uint32_t tri = 0; tri < h->scene->ntris && open; tri++) open -= cast(h, t, tri);
        write_terms(t, 0, t->n, st);
        return;
    }
    const om__hregion *g = &t->reg[r];
    walk_region(h, t, r);
    write_terms(t, cell_first(t, g->c0), t->cend[g->c1 - 1], st);
}

static void tile_end(om__htile *t)
{
    t->regions += t->nreg;
    for (uint32_t r = 0; OM_WITH_JOBS && t->nreg > 1 && r < t->nreg; r++) {
        t->setups += t->reg[r].setups;
        t->tested += t->reg[r].tested;
    }
}

/* The candidates' parts (regions false) or the regions of a tile, as jobs. */
typedef struct region_job {
    const om__hscene *h;
    om__htile *t;
    const om_strip *st;
    bool regions;
} region_job;

static void region_part(void *user, uint32_t k, void *scratch)
{
    (void)scratch;
    const region_job *j = (const region_job *)user;
    if (j->regions) tile_region(j->h, j->t, k, j->st);
    else tile_cands(j->h, j->t, k);
}

/* n parts of job j: as the host's jobs, or here. */
static void run_parts(const om__lend *l, region_job *j, uint32_t n)
{
    if (OM_WITH_JOBS && l) l->run_any(l, region_part, j, n);
    else
        for (uint32_t k = 0; k < n; k++) region_part(j, k, NULL);
}

void om__htile_run(const om__hscene *h, om__htile *t, uint32_t n, const om_strip *st, const om__lend *l)
{
    const uint32_t nreg = tile_begin(t, n, l);
    region_job j = {h, t, st, false};
    if (nreg > 1) run_parts(l, &j, OM__HTILE_PARTS);
    j.regions = true;
    run_parts(nreg > 1 ? l : NULL, &j, nreg);
    tile_end(t);
}
