/* lgrid.h — the scene's triangles binned once a frame on a coarse grid over the light's
 * image, so that a tile of samples (izb's, and any other irregular pass) walks only the
 * triangles whose projected vertices' box meets a cell holding one of its samples,
 * instead of every triangle of the scene.
 *
 * The grid covers the light grid's frustum (occlude.h: 2^21 units a side) in side x
 * side square cells; points and boxes beyond it are clamped to its border cells, so a
 * box meets every cell holding a point inside it. A triangle whose three vertices the
 * frame projected (om__lspace.verts) goes into each cell its vertices' box covers, at
 * most LGRID_MOST of them; any other (a vertex that needs clipping, or a large box)
 * goes into one more list, the wide one, which every tile walks. Each list holds its
 * triangles in ascending order, and a tile's selection (om__lgrid_select) is a bit a
 * triangle, so a tile walks its triangles in the scene's order: the walk gives the
 * same answer and counts as walking every triangle, provided that a triangle whose
 * vertices' box holds none of the tile's samples costs the tile nothing but its skip.
 *
 * Making the grid is three steps, each over disjoint ranges (the answer is the same for
 * any cut): every triangle's cells (boxes, by ranges of triangles), each row of cells'
 * counts (count, by ranges of rows, each range reading every triangle's cells), the
 * lists' starts (sum), each row's lists (fill, by ranges of rows). Jobs make the same
 * lists by parts of the triangles (om__lgrid_boxes_count, below), where no job reads
 * every triangle. Where the lists would need more entries than the
 * grid holds (triangles much larger than their share of the cells), sum says so and
 * the tiles walk every triangle this frame. No state beyond the struct; memory from
 * the caller's arena. */
#ifndef OM_LGRID_H
#define OM_LGRID_H

#include "../common/occlude.h"

/* Most cells a triangle is listed in; a larger one is wide. */
#define LGRID_MOST 16u

typedef struct om__lgrid {
    const om__lspace *ls;  /* the frame's vertex projection, which must be kept */
    uint32_t ntris;
    uint32_t side;         /* cells a side: a power of 2, at most 256 */
    int shift;             /* light grid units -> cell: clamp, then >> shift */
    uint32_t lists;        /* side * side cells, then the wide list */
    uint32_t cap;          /* entries `tris` holds */
    uint32_t *box;         /* per triangle: its cells, packed (om__lgrid_boxes) */
    uint32_t *start;       /* lists + 1: list c is tris[start[c], start[c + 1]) */
    uint32_t *tris;
    int ready;             /* 1: this frame's lists are made; 0: not made; -1: too many */
} om__lgrid;

/* Arena bytes of the grid for scene s (om__lgrid_init carves them), and of one tile's
 * selection: a bit a cell and a bit a triangle (om__lgrid_select). */
size_t om__lgrid_bytes(const om_scene *s);
size_t om__lgrid_sel_bytes(const om_scene *s);
om_status om__lgrid_init(om__lgrid *g, om_arena *a, const om__lspace *ls, om_diag *d);

/* The rows of lists count and fill take: side rows of cells, then the wide list. */
static inline uint32_t om__lgrid_rows(const om__lgrid *g) { return g->side + 1; }

/* The frame's steps, after the vertex projection: */
void om__lgrid_boxes(const om__lgrid *g, uint32_t first, uint32_t end);        /* triangles */
void om__lgrid_count(const om__lgrid *g, uint32_t row0, uint32_t row1);  /* rows */
void om__lgrid_sum(om__lgrid *g);
void om__lgrid_fill(const om__lgrid *g, uint32_t row0, uint32_t row1);   /* rows */
/* All four on one thread. */
void om__lgrid_make(om__lgrid *g);

/* The same lists made in P parts (a counting sort), so that no job reads every
 * triangle's cells. Part k of P takes the k-th of P even ranges of the triangles and
 * of the rows (om__lgrid_rows); each step's parts may run in any order, or at once:
 * - boxes_count: part k takes its triangles' boxes and counts their entries a list
 *   into cnt (om__lgrid_part_bytes, its own: cnt[k] below);
 * - sum_rows: part k lays the lists of its rows out from 0, the parts' entries in part
 *   order (cnt[j][c] becomes part j's place in list c), and returns their entries;
 * - bases (one thread): each row's base (at: om__lgrid_rows of them) from the parts'
 *   entries, start[lists] and ready, as sum does;
 * - fill_part (when ready is 1): part k puts its triangles at their places, and moves
 *   its rows' starts by their base.
 * The lists are those of om__lgrid_make: ascending, as each part's triangles follow
 * those of the parts before. */
size_t om__lgrid_part_bytes(const om__lgrid *g);
void om__lgrid_boxes_count(const om__lgrid *g, uint32_t k, uint32_t parts, uint32_t *cnt);
uint64_t om__lgrid_sum_rows(const om__lgrid *g, uint32_t *const *cnt, uint32_t k, uint32_t parts);
void om__lgrid_bases(om__lgrid *g, const uint64_t *entries, uint32_t parts, uint32_t *at);
void om__lgrid_fill_part(const om__lgrid *g, const uint32_t *at, uint32_t k, uint32_t parts, uint32_t *cnt);

/* A tile's selection, in `sel` (om__lgrid_sel_bytes, aligned to 4): clear, then mark
 * the cell of each of the tile's samples, then select; the triangles to walk are then
 * the set bits of om__lgrid_tris(g, sel), words of 32 triangles,
 * (g->ntris + 31) / 32 of them. */
void om__lgrid_clear(const om__lgrid *g, uint32_t *sel);
static inline void om__lgrid_mark(const om__lgrid *g, uint32_t *sel, int64_t x, int64_t y)
{
    const int64_t top = ((int64_t)OM_LIGHT_GRID << 8) - 1;
    const uint32_t cx = (uint32_t)((x < 0 ? 0 : x > top ? top : x) >> g->shift);
    const uint32_t cy = (uint32_t)((y < 0 ? 0 : y > top ? top : y) >> g->shift);
    const uint32_t c = cy * g->side + cx;
    sel[c >> 5] |= 1u << (c & 31);
}
void om__lgrid_select(const om__lgrid *g, uint32_t *sel);
static inline const uint32_t *om__lgrid_tris(const om__lgrid *g, const uint32_t *sel)
{
    return sel + (g->side * g->side + 31) / 32;
}

#endif
