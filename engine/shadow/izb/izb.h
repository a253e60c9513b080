/* izb.h — the irregular z-buffer of Alias-Free Shadow Maps (Aila and Laine 2004),
 * split into its three stages so the benchmark can time each as the paper's Table 1
 * does: transform the visible samples to the light's image plane (section 3), build
 * the 2-D BSP over them (section 5.1), rasterize every triangle through it (sections
 * 3-5). The samples are never discretised to texels: they keep the light grid's
 * 1/2^21 precision, and every test is the shared occlusion predicate of occlude.h, so
 * the result equals the reference sample for sample. */
#ifndef OM_IZB_H
#define OM_IZB_H

#include "lgrid.h"

/* What the BSP orders and the leaves test: a sample's grid position and light depth
 * (exact: the projection gives integers), its own triangle, where the sample is in its
 * strip, with OM_IZB_DONE set once it is opaquely shadowed, and its Z-order code in
 * the tile (made once by the build, which sorts and splits by it). The key is the
 * whole sample, so the leaves read nothing else; its optical depth sits at the same
 * index of z->od once the build has sorted the keys. */
typedef struct om__izb_key { int32_t x, y; uint32_t z, tri, s, code; } om__izb_key;
#define OM_IZB_DONE 0x80000000u     /* in s: opaquely shadowed */
#define OM_IZB_PULLED 0x40000000u   /* in s: z pulled (om__lspace_pull) */
#define OM_IZB_INDEX 0x3FFFFFFFu    /* in s: the sample's place in the strip */

/* A BSP node: the bounds of its samples on the light grid, their largest light depth,
 * and how many of them are not yet fully (opaquely) shadowed. Leaves have count > 0
 * and no children; inner nodes have children at `child` and `child + 1`; `parent` is
 * OM_IZB_NONE at the root. */
typedef struct om__izb_node {
    int32_t x0, y0, x1, y1;   /* keys' coordinates: the light grid fits in 27 bits */
    uint32_t zmax;
    uint32_t first, count, child, open, parent;
} om__izb_node;
#define OM_IZB_NONE 0xFFFFFFFFu

typedef struct om__izb_stats {
    uint32_t nodes, visited, culled_shadowed, culled_depth, tested, blocked, tiles;
} om__izb_stats;

typedef struct om__izb {
    const om_scene *scene;
    om__facet facet;       /* the last key's facet (om__lspace_pull) */
    om__lspace ls;
    om__odepth *mat_od;
    om__izb_key *keys;
    om__odepth *od;        /* the optical depth of z->keys[i], once they are sorted */
    om__izb_key *sorted;   /* the radix sort's second buffer */
    om__izb_node *nodes;
    /* The grid in front of the BSP: 2^gk x 2^gk cells over the tile's keys (the cells
     * of the Z order's top 2 gk bits), each the node that holds exactly its samples
     * (OM_IZB_NONE when empty), indexed by the cell's Z-order code. */
    uint32_t *cells;
    uint32_t cells_cap;    /* cells the grid holds: a power of 4 */
    int gk, gshift;        /* grid level; grid units -> cell: >> gshift */
    int zshift;            /* grid units -> a code's ZBITS-bit coordinates: >> zshift */
    uint32_t cap;          /* samples the pool holds */
    uint32_t node_cap;
    uint32_t leaf;
    uint32_t n, nnodes;    /* samples and nodes of the current tile */
    uint32_t taken;        /* exposed samples its transform took (n of them kept) */
    int32_t kx0, ky0, kx1, ky1;   /* the bounds of the tile's keys */
    /* The scene's triangles binned on the light's image once a frame (lgrid.h), and
     * the tile's selection of them (om__lgrid_sel_bytes, beside the pool); NULL
     * without room: every tile then walks every triangle, for the same counts. */
    om__lgrid *grid;
    uint32_t *sel;
    om__izb_stats st;
} om__izb;

/* The izb method's state begins with an om__izb, so a state pointer converts to one. */

/* izb's configuration (hybrid takes izb.pool too, into a struct of its own). */
typedef struct om__izb_cfg {
    uint32_t izb_leaf;     /* most samples in a BSP leaf */
    uint32_t izb_pool;     /* samples the pool holds; 0: izb picks by the scene (izb.c,
                              auto_pool), hybrid the frame, at most 2 a triangle */
} om__izb_cfg;

/* Its entry in the settings of a method whose struct T holds it at `f` (a field
 * designator: izb_leaf, or part.izb_leaf); izb.pool's is method.h's. */
#define OM__SET_IZB_LEAF(T, f) \
    OM__SETTING(T, f, "izb.leaf", OM_SETTING_U32, 1, 65536, 64, "most samples in a BSP leaf (the paper: 64)")

/* The Z-order (Morton) code of a key: x and y relative to the tile's corner, shifted
 * to izb.c's ZBITS bits each, bits interleaved (the build sorts and splits by it, the
 * raster bounds a triangle's keys by it). Both are spread at once, one in each half
 * of a 64-bit word. */
static inline uint32_t om__izb_zcode_xy(uint32_t x, uint32_t y)
{
    uint64_t v = (uint64_t)x | (uint64_t)y << 32;
    v = (v | (v << 8)) & 0x00FF00FF00FF00FFull;
    v = (v | (v << 4)) & 0x0F0F0F0F0F0F0F0Full;
    v = (v | (v << 2)) & 0x3333333333333333ull;
    v = (v | (v << 1)) & 0x5555555555555555ull;
    return (uint32_t)v | (uint32_t)(v >> 32) << 1;
}

static inline uint32_t om__izb_zcode(const om__izb_key *k, int32_t x0, int32_t y0, int shift)
{
    return om__izb_zcode_xy((uint32_t)(k->x - x0) >> shift, (uint32_t)(k->y - y0) >> shift);
}

/* A strip's tiles: its E exposed samples in om__izb_tiles(z, E) = ceil(E / pool)
 * tiles, tile k holding the exposed samples numbered [om__izb_tile_first(z, E, k),
 * om__izb_tile_first(z, E, k + 1)) in the strip's order: full pools, the rest last.
 * The tiling depends on the strip and the pool only, so a tile gives the same counts
 * whether the tiles run one after another (om__izb_resolve) or as jobs (izb.c's pass). */
/* The irregular z-buffer inside izb's state (for tests and benchmarks). */
om__izb *om__izb_of(void *state);
uint32_t om__izb_tiles(const om__izb *z, uint32_t exposed);
uint32_t om__izb_tile_first(const om__izb *z, uint32_t exposed, uint32_t k);

/* The stages, one tile at a time (the benchmark times each):
 * transform fills the pool (the samples' keys) from the first `take` (at most the
 * pool) exposed samples of strip samples [*next, end), advances *next past the last
 * and returns the number kept (those in front of the light; z->taken: how many it
 * took). */
uint32_t om__izb_transform(om__izb *z, const om_strip *st, size_t *next, size_t end, uint32_t take);
void om__izb_build(om__izb *z);
/* Bins the scene's triangles on the light's image for this frame (once, after begin;
 * nothing without the grid): om__izb_raster then walks only a tile's own. */
void om__izb_grid(om__izb *z);
/* Rasterizes every triangle of the scene through the BSP (with the grid, those that
 * can reach the tile's samples, for the same terms and counts). */
void om__izb_raster(om__izb *z);
/* Writes the tile's terms into the strip. */
void om__izb_write(const om__izb *z, const om_strip *st);
/* A strip's terms: 255 everywhere, then (after om__izb_grid) tile after tile of the
 * exposed samples through transform, build, raster, write (on one thread; izb.c's pass runs the same tiles as
 * jobs). */
void om__izb_resolve(om__izb *z, om_strip *st);

#endif
