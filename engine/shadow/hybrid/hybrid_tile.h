/* hybrid_tile.h — the hybrid exact method's pieces shared between its files and its tests:
 * the map lookup (hybrid.c has the method and the proof) and the irregular pass over
 * a tile of uncertain samples (hybrid_tile.c). */
#ifndef OM_HYBRID_TILE_H
#define OM_HYBRID_TILE_H

#include "../method.h"
#include "../common/occlude.h"

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

/* The key of sample i of the strip, projected to p. */
static inline void om__hkey_put(om__hkey *q, const om__lpoint *p, size_t i)
{
    q->x = (int32_t)p->x;
    q->y = (int32_t)p->y;
    q->z = (uint32_t)p->z;
    q->tri = p->tri;
    q->idx = (uint32_t)i;
}

/* Most regions a tile is cut into, and the parts its candidates are found in (both
 * fixed: hybrid_tile.c says why). */
#define OM__HTILE_REGIONS 32u
#define OM__HTILE_PARTS 16u

/* A triangle that may block a sample of the tile (a candidate): its projected
 * vertices and their box and nearest depth where `near` has bit 0 (else it needs
 * clipping), and the tile's regions it reaches in its other bits (hybrid_tile.c). 64
 * bytes: a cache line. */
typedef struct om__hcand { uint32_t tri, near; om__lvbox box; om__lvert v[3]; } om__hcand;

/* A region of a tile: the cells [c0, c1) (whole rows of blocks), its samples' bounds
 * and farthest depth, and the triangles set up and samples tested for it. */
typedef struct om__hregion { uint32_t c0, c1, n; om__lvbox box; uint32_t setups, tested; } om__hregion;

/* A tile of uncertain samples and its scratch: the samples as they come (raw, n of
 * them, at most cap), then sorted into a grid of cells fitted to their bounds (smp,
 * with each one's optical depth in od), and the triangles set up and samples tested
 * for it. With room for the scene's triangles as candidates (cand), a tile of many
 * samples is cut into regions that run apart. The memory is om__htile_bytes(cap,
 * cands) bytes, om__htile_carve's. */
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
    uint32_t setups, tested, regions;   /* regions: walked, a tile not cut counting one */
    om__hcand *cand;        /* a slot a triangle of the scene, or NULL: no regions */
    uint32_t ncand[OM__HTILE_PARTS];   /* part k's candidates, from its first triangle's slot */
    /* Each part's candidates listed by the regions their rows reach (two entries a
     * slot, from the part's first triangle's; region r's in [at[r], at[r + 1]) of the
     * part's row of OM__HTILE_REGIONS + 2, the list nreg those that reach more than
     * two regions). */
    uint32_t *list, *at;
    uint8_t *breg;          /* each row of blocks' region */
    om__hregion *reg;       /* OM__HTILE_REGIONS of them, with cand */
    uint32_t nreg;
} om__htile;

/* What the irregular pass reads: the scene, its light space this frame and each
 * material's optical depth. */
typedef struct om__hscene {
    const om_scene *scene;
    const om__lspace *ls;
    const om__odepth *mat_od;
} om__hscene;

/* A tile of cap samples, with candidates' room for `cands` triangles (0: none, else
 * the scene's). */
size_t om__htile_bytes(uint32_t cap, uint32_t cands);
/* Lays such a tile over `mem` (om__htile_bytes bytes, 16-aligned). */
void om__htile_carve(om__htile *t, void *mem, uint32_t cap, uint32_t cands);
/* Runs the tile's n samples (t->raw[0..n)) through every triangle of the scene and
 * writes their terms into st; adds to t->setups, t->tested and t->regions. With `l`
 * (NULL: on this thread), a tile cut into regions runs its candidates' parts and its
 * regions as the host's jobs (om__lend.run_any). The same terms and counts whatever
 * the tile's memory held before; with `l` its samples' sort too, where the tile is cut
 * into regions. */
void om__htile_run(const om__hscene *h, om__htile *t, uint32_t n, const om_strip *st, const om__lend *l);

/* With the host's threads (the map's bands, a tile's sort): counts into places, for
 * work cut into parts (rows of cnt) that each send items to bins (its columns), every
 * bin's items laid out in the bins' order and within a bin in the parts' order: each
 * count becomes where that part's first item in that bin goes, start[b] where bin b
 * begins and start[bins] the total, returned (start's values are that total's low 32
 * bits where it is larger). */
#if OM_WITH_JOBS
uint64_t om__hplaces(uint32_t *cnt, uint32_t parts, uint32_t bins, uint32_t *start);
#endif

#endif
