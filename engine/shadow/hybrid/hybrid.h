/* hybrid.h — the state of the hybrid exact method, shared by its two halves:
 * hybrid.c (settings, the proof of the map's answers, the lookup and the irregular
 * pass's tiling) and hybrid_map.c (the build of the conservative map, on one thread
 * or by bands of its rows). */
#ifndef OM_HYBRID_H
#define OM_HYBRID_H

#include "../method.h"
#include "hybrid_tile.h"

#include <float.h>

/* A texel: a plane P(x, y) = z + gx (x - xc) + gy (y - yc) about the texel's centre,
 * below every touching triangle's depth plus bound over the texel (lo); and the
 * opaque triangle covering all of it whose greatest depth plus bound is least (hi,
 * cid). */
typedef struct htexel { float z, gx, gy, hi; uint32_t cid; } htexel;

/* Where a double operation is a software routine (OM_FAST_FLOAT, core.h), the
 * lookup's plane test and the small triangles' updates of the map try single
 * precision first and use double only where the float's error bound leaves the
 * answer open; elsewhere double costs what float does and runs alone. The answers
 * are the same either way (the float answers only where the double would answer
 * alike), and so the map and the frames. */

/* hybrid's configuration: the sample pool's size and its map's side. */
typedef struct hybrid_cfg {
    uint32_t izb_pool;     /* 0: the whole frame in one pass */
    uint32_t hybrid_map;   /* 0: auto (map_side) */
} hybrid_cfg;
OM__CFG_FITS(hybrid_cfg);

extern const om_method om__method_hybrid;

/* Most parts of a strip the plan's scan and keys are cut into (hybrid.c). */
#define OM__HYBRID_PARTS 64u

typedef struct hybrid_state {
    om__state_head head;   /* first (method.h) */
    const om_scene *scene;
    om__lspace ls;
    om__odepth *mat_od;    /* each material's optical depth */
    hybrid_cfg cfg;
    htexel *map;
    uint32_t side;         /* texels per side */
    int64_t T;             /* grid units per texel side */
    int tshift;            /* log2(T) when T is a power of two (the default sides), else -1 */
    om__hscene h;          /* what the irregular pass reads */
    om__htile tile;        /* its tile of uncertain samples, cap of them */
    uint32_t cands;        /* the tile's room for candidates: the scene's triangles, or 0 */
    const om__lend *lend;  /* the host's threads for this frame's build and tiles, or NULL */
    uint32_t cap;          /* samples the pool holds: a tile's */
    /* The pass (OM_WITH_JOBS): where each of the current strip's tiles begins in it,
     * ntiles + 1 of them (the last: the strip's end), and room for most_tiles. */
    uint32_t *starts, ntiles, most_tiles;
    /* The plan in parts on the lent threads (hybrid.c): each part's marked samples, then
     * the rank of its first; each part's keys put in the current tile. */
    uint32_t part_marked[OM__HYBRID_PARTS + 1], part_put[OM__HYBRID_PARTS];
    uint32_t lit, shadowed, uncertain, tiles;   /* with the tile's setups and tested */
} hybrid_state;

#define GRID_SIDE ((int64_t)OM_LIGHT_GRID * OM_SUBPIX)   /* 2^21 grid units */
#define FAR_OUT ((int64_t)1 << 27)   /* beyond every grid point a triangle can admit */

/* The texel of a grid coordinate: a shift rather than a division where it can be
 * (this runs once a sample); points off the grid take the border texels. Monotone, so
 * the texels of a range of points are those between its ends'. */
static inline int64_t texel_of(const hybrid_state *m, int64_t v)
{
    if (v < 0) return 0;
    int64_t t = m->tshift >= 0 ? v >> m->tshift : v / m->T;
    return t < (int64_t)m->side ? t : (int64_t)m->side - 1;
}

/* The method's build: the map, from every triangle of the scene (hybrid_map.c). */
om_status om__hybrid_build(void *state, om_diag *d);

#endif
