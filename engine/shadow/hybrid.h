/* hybrid.h — the hybrid exact method's pieces shared between its files and its tests:
 * the map lookup (hybrid.c has the method and the proof) and the irregular pass over
 * a tile of uncertain samples (hybrid_tile.c). */
#ifndef OM_HYBRID_H
#define OM_HYBRID_H

#include "occlude.h"

/* Classifies a sample of the current frame (after the method's build) by the map
 * alone: 1 certainly lit, 2 certainly shadowed (t set to 0), 0 uncertain. */
int om__hybrid_decide(void *state, const om__lpoint *p, om_term *t);
/* The state's light space, to project the samples to classify. */
const om__lspace *om__hybrid_lspace(const void *state);

/* Does any point of the square [x0, x1] x [y0, y1] pass every edge of e? Each edge is
 * tested at the corner where it is largest: a square outside one edge is out. */
static inline bool om__square_touches(const om__tri2 *e, int64_t x0, int64_t y0, int64_t x1, int64_t y1)
{
    for (int i = 0; i < 3; i++)
        if ((e->a[i] > 0 ? e->a[i] * x1 : e->a[i] * x0) + (e->b[i] > 0 ? e->b[i] * y1 : e->b[i] * y0) +
                e->c[i] < 0)
            return false;
    return true;
}

/* An uncertain sample on the light's grid (the grid fits in 27 bits, its depth is a
 * whole unit: om__lspace_point); idx is its place in the strip. */
typedef struct om__hkey { int32_t x, y; uint32_t z, tri, idx; } om__hkey;

/* A tile of uncertain samples and its scratch: the samples as they come (raw, n of
 * them, at most cap), then sorted into a grid of cells fitted to their bounds (smp,
 * with each one's optical depth in od), and the triangles set up and samples tested
 * for it. The memory is om__htile_bytes(cap) bytes, om__htile_carve's. */
typedef struct om__htile {
    om__hkey *raw, *smp;
    om__odepth *od;
    /* cell: each raw sample's cell while sorting; oend, the same memory after: each
     * cell's end of open samples (its samples from cend[c - 1] on, the open ones
     * first); cend: each cell's end; bzmax: each block's farthest depth */
    uint32_t *cell, *oend, *cend, *bzmax;
    uint32_t cap, n;
    om__lvbox box;          /* the samples' bounds and farthest depth */
    /* The grid (hybrid_tile.c, fit_cells): cell (cx, cy) is the square of grid points
     * from (ox + cx 2^cs, oy + cy 2^cs), side 2^cs; cw x ch of them, in blocks of 4 x 4
     * cells, cbw a row. */
    int32_t ox, oy;
    int cs;
    uint32_t cw, ch, cbw;
    uint32_t setups, tested;
} om__htile;

/* What the irregular pass reads: the scene, its light space this frame and each
 * material's optical depth. */
typedef struct om__hscene {
    const om_scene *scene;
    const om__lspace *ls;
    const om__odepth *mat_od;
} om__hscene;

size_t om__htile_bytes(uint32_t cap);
/* Lays a tile of cap samples over `mem` (om__htile_bytes(cap) bytes, 16-aligned). */
void om__htile_carve(om__htile *t, void *mem, uint32_t cap);
/* Runs the tile's n samples (t->raw[0..n)) through every triangle of the scene and
 * writes their terms into st; adds to t->setups and t->tested. The same terms and
 * counts whatever the tile's memory held before. */
void om__htile_run(const om__hscene *h, om__htile *t, uint32_t n, const om_strip *st);

#endif
