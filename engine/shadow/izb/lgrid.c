/* lgrid.c — the scene's triangles binned once a frame on a coarse grid over the light's
 * image, and a tile's selection of them (lgrid.h says what it is for and why the
 * selection keeps the scene's order). */
#include "lgrid.h"

/* About this many triangles a cell (for a scene spread over the light's image): finer
 * cells select a tile's triangles more closely, but cost every tile a bit a cell and
 * every triangle more entries. */
#define CELL_TRIS 4u
/* Entries the lists hold, a triangle: one in most scenes of small triangles, up to
 * four at the cells' corners; a frame that needs more walks every triangle. */
#define ENTRIES_TRI 3u
/* A box that lists a triangle nowhere but in the wide list: cx0 = 1 > cx1 = 0. */
#define WIDE 1u

static uint32_t side_of(const om_scene *s)
{
    uint32_t side = 8;
    while (side < 256 && (uint64_t)side * side * CELL_TRIS < s->ntris) side *= 2;
    return side;
}

static size_t sel_words(const om_scene *s)
{
    const uint32_t side = side_of(s);
    return (size_t)side * side / 32 + ((size_t)s->ntris + 31) / 32;
}

static uint32_t cap_of(const om_scene *s)
{
    return (uint32_t)((uint64_t)s->ntris * ENTRIES_TRI + 64 > 0xFFFFFFFFu ? 0xFFFFFFFFu
                                                                        : (uint64_t)s->ntris * ENTRIES_TRI + 64);
}

size_t om__lgrid_bytes(const om_scene *s)
{
    const uint32_t side = side_of(s);
    return om_arena_need((size_t)s->ntris * sizeof(uint32_t), 16) +
           om_arena_need(((size_t)side * side + 2) * sizeof(uint32_t), 16) +
           om_arena_need((size_t)cap_of(s) * sizeof(uint32_t), 16);
}

size_t om__lgrid_sel_bytes(const om_scene *s) { return sel_words(s) * sizeof(uint32_t); }

om_status om__lgrid_init(om__lgrid *g, om_arena *a, const om__lspace *ls, om_diag *d)
{
    const om_scene *s = ls->scene;
    om_status st;
    void *p;
    memset(g, 0, sizeof *g);
    g->ls = ls;
    g->ntris = s->ntris;
    g->side = side_of(s);
    g->shift = 21;   /* the light grid's 2^21 units over side cells */
    for (uint32_t k = g->side; k > 1; k >>= 1) g->shift--;
    g->lists = g->side * g->side + 1;
    g->cap = cap_of(s);
    if ((st = om_arena_alloc(a, (size_t)s->ntris * sizeof(uint32_t), 16, &p, d))) return st;
    g->box = (uint32_t *)p;
    if ((st = om_arena_alloc(a, ((size_t)g->lists + 1) * sizeof(uint32_t), 16, &p, d))) return st;
    g->start = (uint32_t *)p;
    if ((st = om_arena_alloc(a, (size_t)g->cap * sizeof(uint32_t), 16, &p, d))) return st;
    g->tris = (uint32_t *)p;
    return OM_OK;
}

/* A light grid coordinate's cell, clamped to the grid (as om__lgrid_mark does). */
static uint32_t cell_of(const om__lgrid *g, int32_t v)
{
    const int32_t top = (int32_t)(OM_LIGHT_GRID << 8) - 1;
    return (uint32_t)((v < 0 ? 0 : v > top ? top : v) >> g->shift);
}

void om__lgrid_boxes(const om__lgrid *g, uint32_t first, uint32_t end)
{
    const om_scene *s = g->ls->scene;
    const om__lvert *v = g->ls->verts;
    for (uint32_t t = first; t < end; t++) {
        const uint32_t *ix = s->idx + (size_t)t * 3;
        const om__lvert *a = &v[ix[0]], *b = &v[ix[1]], *c = &v[ix[2]];
        if (a->x == INT32_MIN || b->x == INT32_MIN || c->x == INT32_MIN) {   /* needs clipping */
            g->box[t] = WIDE;
            continue;
        }
        const om__lvbox vb = om__lvert_box(a, b, c);
        const uint32_t x0 = cell_of(g, vb.lox), x1 = cell_of(g, vb.hix), y0 = cell_of(g, vb.loy), y1 = cell_of(g, vb.hiy);
        g->box[t] = (x1 - x0 + 1) * (y1 - y0 + 1) > LGRID_MOST ? WIDE : x0 | y0 << 8 | x1 << 16 | y1 << 24;
    }
}

void om__lgrid_count(const om__lgrid *g, uint32_t row0, uint32_t row1)
{
    const uint32_t side = g->side, wide = side * side;
    const bool has_wide = row1 > side;
    if (row1 > side) row1 = side;
    for (uint32_t c = row0 * side; c < row1 * side; c++) g->start[c] = 0;
    uint32_t nwide = 0;
    for (uint32_t t = 0; t < g->ntris; t++) {
        const uint32_t b = g->box[t];
        if (b == WIDE) {
            nwide++;
            continue;
        }
        uint32_t y0 = b >> 8 & 255, y1 = b >> 24;
        if (y0 < row0) y0 = row0;
        if (y1 >= row1) y1 = row1 - 1;
        for (uint32_t y = y0; y <= y1; y++)
            for (uint32_t x = b & 255; x <= (b >> 16 & 255); x++) g->start[y * side + x]++;
    }
    if (has_wide) g->start[wide] = nwide;
}

void om__lgrid_sum(om__lgrid *g)
{
    uint64_t total = 0;
    for (uint32_t c = 0; c < g->lists; c++) {
        total += g->start[c];
        g->start[c] = total > g->cap ? g->cap : (uint32_t)total;   /* where list c ends */
    }
    g->start[g->lists] = g->start[g->lists - 1];
    g->ready = total <= g->cap ? 1 : -1;
}

/* Triangles last to first, each list filled from its end: ascending lists, and each
 * start[c] ends where list c begins. */
void om__lgrid_fill(const om__lgrid *g, uint32_t row0, uint32_t row1)
{
    if (g->ready != 1) return;
    const uint32_t side = g->side, wide = side * side;
    const bool has_wide = row1 > side;
    if (row1 > side) row1 = side;
    for (uint32_t t = g->ntris; t-- > 0;) {
        const uint32_t b = g->box[t];
        if (b == WIDE) {
            if (has_wide) g->tris[--g->start[wide]] = t;
            continue;
        }
        uint32_t y0 = b >> 8 & 255, y1 = b >> 24;
        if (y0 < row0) y0 = row0;
        if (y1 >= row1) y1 = row1 - 1;
        for (uint32_t y = y0; y <= y1; y++)
            for (uint32_t x = b & 255; x <= (b >> 16 & 255); x++) g->tris[--g->start[y * side + x]] = t;
    }
}

size_t om__lgrid_part_bytes(const om__lgrid *g) { return (size_t)g->lists * sizeof(uint32_t); }

/* Part k of P: triangles [n k / P, n (k + 1) / P) of the n, and rows [m k / P,
 * m (k + 1) / P) of the m of om__lgrid_rows. */
static uint32_t cut(uint32_t n, uint32_t k, uint32_t parts) { return (uint32_t)((uint64_t)n * k / parts); }

/* A row's lists: cells [y side, (y + 1) side), or for row `side` the wide list. */
static uint32_t row_end(const om__lgrid *g, uint32_t y) { return y == g->side ? g->lists : (y + 1) * g->side; }

void om__lgrid_boxes_count(const om__lgrid *g, uint32_t k, uint32_t parts, uint32_t *cnt)
{
    const uint32_t first = cut(g->ntris, k, parts), end = cut(g->ntris, k + 1, parts), side = g->side;
    om__lgrid_boxes(g, first, end);
    memset(cnt, 0, om__lgrid_part_bytes(g));
    for (uint32_t t = first; t < end; t++) {
        const uint32_t b = g->box[t];
        if (b == WIDE) {
            cnt[side * side]++;
            continue;
        }
        for (uint32_t y = b >> 8 & 255; y <= b >> 24; y++)
            for (uint32_t x = b & 255; x <= (b >> 16 & 255); x++) cnt[y * side + x]++;
    }
}

uint64_t om__lgrid_sum_rows(const om__lgrid *g, uint32_t *const *cnt, uint32_t k, uint32_t parts)
{
    const uint32_t rows = om__lgrid_rows(g), row0 = cut(rows, k, parts), row1 = cut(rows, k + 1, parts);
    const uint32_t c1 = row1 > row0 ? row_end(g, row1 - 1) : row0 * g->side;
    uint64_t run = 0;
    for (uint32_t c = row0 * g->side; c < c1; c++) {
        g->start[c] = (uint32_t)run;
        for (uint32_t j = 0; j < parts; j++) {
            const uint32_t n = cnt[j][c];
            cnt[j][c] = (uint32_t)run;
            run += n;
        }
    }
    return run;
}

void om__lgrid_bases(om__lgrid *g, const uint64_t *entries, uint32_t parts, uint32_t *at)
{
    const uint32_t rows = om__lgrid_rows(g);
    uint64_t total = 0;
    for (uint32_t k = 0; k < parts; k++) {
        for (uint32_t y = cut(rows, k, parts); y < cut(rows, k + 1, parts); y++) at[y] = (uint32_t)total;
        total += entries[k];
    }
    g->start[g->lists] = total > g->cap ? g->cap : (uint32_t)total;
    g->ready = total <= g->cap ? 1 : -1;
}

void om__lgrid_fill_part(const om__lgrid *g, const uint32_t *at, uint32_t k, uint32_t parts, uint32_t *cnt)
{
    const uint32_t side = g->side, rows = om__lgrid_rows(g);
    for (uint32_t t = cut(g->ntris, k, parts); t < cut(g->ntris, k + 1, parts); t++) {
        const uint32_t b = g->box[t];
        if (b == WIDE) {
            g->tris[at[side] + cnt[side * side]++] = t;
            continue;
        }
        for (uint32_t y = b >> 8 & 255; y <= b >> 24; y++)
            for (uint32_t x = b & 255; x <= (b >> 16 & 255); x++) g->tris[at[y] + cnt[y * side + x]++] = t;
    }
    for (uint32_t y = cut(rows, k, parts); y < cut(rows, k + 1, parts); y++)
        for (uint32_t c = y * side; c < row_end(g, y); c++) g->start[c] += at[y];
}

void om__lgrid_make(om__lgrid *g)
{
    om__lgrid_boxes(g, 0, g->ntris);
    om__lgrid_count(g, 0, om__lgrid_rows(g));
    om__lgrid_sum(g);
    om__lgrid_fill(g, 0, om__lgrid_rows(g));
}

void om__lgrid_clear(const om__lgrid *g, uint32_t *sel)
{
    memset(sel, 0, (size_t)g->side * g->side / 32 * sizeof(uint32_t));
}

void om__lgrid_select(const om__lgrid *g, uint32_t *sel)
{
    const uint32_t cw = g->side * g->side / 32;
    uint32_t *tm = sel + cw;
    memset(tm, 0, ((size_t)g->ntris + 31) / 32 * sizeof(uint32_t));
    for (uint32_t w = 0; w < cw; w++)
        for (uint32_t bits = sel[w]; bits; bits &= bits - 1) {
            const uint32_t c = w * 32 + (uint32_t)om__ctz32(bits);
            for (uint32_t e = g->start[c]; e < g->start[c + 1]; e++) tm[g->tris[e] >> 5] |= 1u << (g->tris[e] & 31);
        }
    for (uint32_t e = g->start[g->lists - 1]; e < g->start[g->lists]; e++)
        tm[g->tris[e] >> 5] |= 1u << (g->tris[e] & 31);
}
