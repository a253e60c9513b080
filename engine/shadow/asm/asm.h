/* asm.h — the Adaptive Shadow Map's tree (Fernando et al. 2001, paper 002): the node
 * pool carved from the user's memory cap, the cells that may hold children, and the
 * rules that create, find and remove nodes (section 3). The method itself (frame flow,
 * analysis, lookup) is asm.c, its tile rendering asm_render.c; the tree is here so
 * tests can drive it, and the method's state at the end, which those two share.
 *
 * Geometry. The root ("base") is one node whose tile of asm.tile texels covers the
 * light's whole image plane; it is cut into B = asm.root / asm.tile cells per side, and
 * each of its cells may hold a root tile: a node of asm.tile texels, so the root level
 * sees the light's image at asm.root texels per side, as one shadow map would. Root
 * tiles exist where visible samples fall (they are made before any refinement and
 * outside the work budget); where the cap has no room for one, the base answers,
 * coarsely. Every other tile is cut into square cells of cp = asm.tile / asm.cells
 * texels; a cell may hold a child node of asm.tile texels, so each level below the
 * root tiles multiplies the resolution by asm.cells. Level 0 is the base (grid side
 * asm.tile), level 1 the root tiles (asm.root), level L > 1 asm.root * asm.cells^(L-1).
 * A node of level L covers texels [ox, ox + tile) x [oy, oy + tile) of its level's
 * grid; the grid side is "the effective resolution".
 *
 * Memory. The cap counts the base (tile, cell links and per-cell analysis) and every
 * node in use (header, cells, tile, pool link): bytes in use never exceed it. Depth is
 * 32 bits per texel; the polygon ID is 16 bits when the scene has fewer than 65535
 * triangles, else 32 ("model no more than a scene needs"). */
#ifndef OM_ASM_H
#define OM_ASM_H

#include "../method.h"

#define OM__ASM_NONE 0xFFFFFFFFu   /* no node (an empty cell) */
#define OM__ASM_ROOT 0xFFFFFFFEu   /* the root's index: it is not in the pool */
#define OM__ASM_MAX_LEVEL 12u

/* What asm's settings (asm.c) set. */
typedef struct om__asm_cfg {
    uint64_t asm_cap;      /* bytes the node structure may hold, at most */
    float bias_const;      /* the conventional map's bias (smlookup.h): a fraction of
                            * the light's depth range */
    float bias_slope;      /* ... and its slope-scaled bias, in the node's texels */
    uint32_t asm_tile;     /* texels per side of every node's tile */
    uint32_t asm_cells;    /* cells per side of a node; a cell may hold a child node */
    uint32_t asm_root;     /* texels per side of the root's view of the light frustum */
    uint32_t asm_work;     /* per-frame work budget, in cost units */
    uint32_t asm_stride;   /* analyse one visible sample in asm_stride (the paper: 8) */
    float asm_cost_a, asm_cost_b;   /* cost of a node: a * texels required + b */
    uint32_t asm_float;    /* place samples in float first (asm_point.c): same frames */
} om__asm_cfg;

/* The head of every pool item (and of the root). */
typedef struct om__asm_node {
    uint32_t parent;       /* index of the parent node (OM__ASM_ROOT for level 1) */
    uint32_t pcell;        /* the parent's cell this node fills */
    uint32_t level;        /* 0 root, 1 its children, ... */
    uint32_t ox, oy;       /* origin on the level's grid, texels */
    uint32_t stamp;        /* frame it was last used: looked up or analysed */
    uint32_t benefit;      /* this frame's benefit of keeping it (see om__asm_make) */
    uint32_t nchild;       /* cells holding a child */
    uint32_t alive;
    uint32_t gen;          /* bumped on every reuse, so stale references can tell */
} om__asm_node;

/* A node's arrays. */
typedef struct om__asm_tile {
    om__asm_node *node;
    uint32_t size;         /* texels per side */
    uint32_t cells;        /* cells per side */
    uint32_t cp;           /* texels per cell side */
    uint32_t *child;       /* cells^2: child index or OM__ASM_NONE */
    uint32_t *ben;         /* cells^2: this frame's benefit of refining the cell */
    float *need;           /* cells^2: this frame's largest N_required in the cell */
    uint32_t *depth;       /* size^2, row-major, row 0 at the top (light +y) */
    uint16_t *id16;        /* size^2 polygon IDs when the scene is small, else NULL */
    uint32_t *id32;        /* size^2 polygon IDs otherwise, else NULL */
} om__asm_tile;

/* Sizes that follow from a configuration and a scene (om__asm_layout). */
typedef struct om__asm_layout {
    uint32_t root, tile, cells, cp;   /* cp: texels per cell side below the base */
    uint32_t base_cells, base_cp;     /* the base: B cells per side of T / B texels */
    uint32_t max_level;               /* deepest level: its grid stays within 2^21 */
    double mul[OM__ASM_MAX_LEVEL + 1];   /* grid side of level L + 1 over level L's */
    double scale[OM__ASM_MAX_LEVEL + 1]; /* grid side of level L over the base's: a point
                                            at base texels u is at u * scale[L] there */
    bool id16;
    size_t root_bytes;                /* the base's arrays, as the cap counts them */
    size_t item_bytes;                /* one pool item (header, cells, tile) */
    size_t node_bytes;                /* what one node in use costs the cap */
    uint64_t min_cap;                 /* the base and one node */
    uint32_t count;                   /* nodes the cap holds (0 when below min_cap) */
    size_t arena_bytes;               /* what om__asm_tree_init carves */
} om__asm_layout;

typedef struct om__asm_tree {
    om__asm_layout lay;
    om__asm_node root;
    uint32_t *root_child, *root_ben, *root_depth, *root_id32;
    uint16_t *root_id16;
    float *root_need;
    om_pool pool;
    size_t off_child, off_ben, off_need, off_depth, off_id;   /* within a pool item */
    uint32_t frame;        /* current frame number, starts at 2 */
    uint32_t serial;       /* nodes made so far: each node's gen */
    uint32_t created, evicted, replaced;   /* this frame */
    uint64_t total_created, total_evicted;
} om__asm_tree;

/* Fills `l` for cfg and a scene of ntris triangles: OM_E_INVALID (with a message in d)
 * when tile, cells and root do not fit together; cap below min_cap is not an error
 * here (count is 0), so hosts can still ask for the bytes and init names the minimum. */
om_status om__asm_layout_of(om__asm_layout *l, const om__asm_cfg *c, uint32_t ntris,
                            om_diag *d);
/* Carves the root and the pool (lay.count nodes) from `a`; the root starts cleared. */
om_status om__asm_tree_init(om__asm_tree *t, om_arena *a, const om__asm_layout *l,
                            om_diag *d);
/* Drops every node (the light moved: every tile is stale) and clears the root's cells. */
void om__asm_tree_clear(om__asm_tree *t);
/* Starts frame analysis: frame++, per-frame counters and benefits to zero. */
void om__asm_frame(om__asm_tree *t);

om__asm_node *om__asm_node_at(om__asm_tree *t, uint32_t index);
void om__asm_tile_of(om__asm_tree *t, uint32_t index, om__asm_tile *out);
/* The grid side of a level, R_L (as double: exact for power-of-two cells). */
double om__asm_grid(const om__asm_layout *l, uint32_t level);

/* The tree of an asm method state (om__method_asm's), for tests to read. */
const om__asm_tree *om__asm_tree_of(const void *state);

/* Bytes of the cap in use now: the root and every node in use. */
uint64_t om__asm_bytes_in_use(const om__asm_tree *t);
/* Deepest level in use (0: the root only). */
uint32_t om__asm_depth(const om__asm_tree *t);

/* Removes node `index` and its descendants and unlinks it from its parent. */
void om__asm_evict(om__asm_tree *t, uint32_t index);

/* Creates a child in cell `cell` of node `parent` for a refinement of benefit `benefit`
 * (section 3.2): a free pool item if there is one; else the least recently used node
 * not used in the last frame (stamp + 1 < frame), with its subtree; else, when every
 * node is in use, the leaf of least benefit, only if `benefit` is greater. Never a
 * node on the path to `parent`. Returns the new index, or OM__ASM_NONE when the cell
 * already has a child, the level would pass max_level, or nothing may be replaced. */
uint32_t om__asm_make(om__asm_tree *t, uint32_t parent, uint32_t cell, uint32_t benefit);
/* Whether om__asm_make could take a node not used in the last frame now (its first
 * way to replace one): false when every node in the tree was. */
bool om__asm_lru_spare(om__asm_tree *t);

/* The deepest node covering (u, v), given in base texels (x right, y down, both in
 * [0, tile)); also the texel inside it. Stamps every node on the way when `stamp`. */
uint32_t om__asm_find(om__asm_tree *t, double u, double v, bool stamp, uint32_t *tx,
                      uint32_t *ty);

/* A refinement candidate: an empty cell with a benefit this frame (section 3.1). */
typedef struct om__asm_cand {
    uint32_t node, cell, gen, benefit;
    float cost, prio;      /* prio = benefit / cost */
} om__asm_cand;

/* Gathers every empty cell with a benefit into `out` (at most `max`) and orders them as
 * a max-heap on priority (ties: lower node index, then lower cell, so results depend on
 * nothing but the analysis). `base`: the base's empty cells, the root tiles to make,
 * by the number of samples in them; otherwise every other node's, with cost =
 * a * min(N_required, tile^2) + b. Returns the count. */
uint32_t om__asm_candidates(om__asm_tree *t, bool base, float a, float b, om__asm_cand *out,
                            uint32_t max);
/* Takes the best candidate off the heap of n; returns the new n. */
uint32_t om__asm_cand_pop(om__asm_cand *heap, uint32_t n, om__asm_cand *best);
/* Upper bound of om__asm_candidates' count for a layout. */
uint64_t om__asm_cand_max(const om__asm_layout *l);

/* ---- one sample's place on the light's image (asm_point.c) */

/* What a sample's setup reads of the frame (om__asm_pctx_begin). */
typedef struct om__asm_pctx {
    const om_view *view;
    double R;              /* the base's texels per side (asm.tile) */
    float bias_const;      /* world units along the light ray: cfg's times far - near */
    float bias_slope;
    float span_per_dist;   /* spot: frustum width per unit of distance */
    float pix_per_dist;    /* eye: pixel height per unit of distance */
    float dir_texel, dir_dz;   /* directional: texel and depth scale, in float */
    /* The float path (om__asm_fpt): 0 where it is off (asm.float 0, or a level's scale
     * not a power of two), else the fraction bits of its fixed-point base texels; per
     * level the shift from them to the level's texels, and the level's texel in base
     * texels. */
    uint32_t fix;
    uint32_t shift[OM__ASM_MAX_LEVEL + 1];
    float inv_scale[OM__ASM_MAX_LEVEL + 1];
    uint32_t fast_levels;  /* levels below this have a shift */
} om__asm_pctx;

void om__asm_pctx_begin(om__asm_pctx *c, const om__asm_layout *l, const om__asm_cfg *cfg,
                        const om_view *v);

/* The exact place, in double: what the analysis and the lookup decide by. */
typedef struct om__asm_pt {
    double u, v;           /* base texels, x right, y down */
    double z;              /* light depth z/w * 2^32 */
    double bias_c, bias_s; /* constant bias; slope bias for a base texel (depth units) */
    double ratio0;         /* a base texel's surface footprint / the eye pixel's */
    uint32_t tri;
} om__asm_pt;

/* u, v, z; false where the sample is behind the light or off any grid (no lookup). */
bool om__asm_pt_uv(const om__asm_pctx *c, const om_sample *smp, om__asm_pt *o);
/* Its bias and, with `analyse`, the footprint ratio. */
void om__asm_pt_bias(const om__asm_pctx *c, const om_sample *smp, om__asm_pt *o, bool analyse);

/* The same place in float (a Cortex-M4F's FPU runs it; double is software there),
 * with bounds on how far the exact values can lie: every decision taken from it is
 * the one the exact values would take, and one it cannot take falls to them. u and v
 * are kept as fixed-point bounds (base texels * 2^fix, floored) that hold the exact
 * u and v: on a grid 2^a times finer, the texel is decided where both bounds give it. */
typedef struct om__asm_fpt {
    uint32_t u0, u1, v0, v1;
    float z, ez;           /* z/w * 2^32, and a bound on its distance to the exact z */
    float bc, bs;          /* the bias terms (relative error within 2^-17) */
    float ratio0;          /* analysis: 0 where it is not decided */
    bool bias;             /* bc, bs (and ratio0 when asked) are set */
} om__asm_fpt;

/* false: the float path cannot place this sample (the exact one decides it). */
bool om__asm_fpt_uv(const om__asm_pctx *c, const om_sample *smp, om__asm_fpt *o);
void om__asm_fpt_bias(const om__asm_pctx *c, const om_sample *smp, om__asm_fpt *o, bool analyse);

/* Whether the biased depth at `level` is lit against a stored depth: 1 lit, 0
 * shadowed, -1 too close to tell in float. The bias must be set. */
static inline int om__asm_fpt_lit(const om__asm_pctx *c, const om__asm_fpt *f, uint32_t level,
                                  uint32_t depth)
{
    const float is = c->inv_scale[level], bsl = f->bs * is;
    const float zl = f->z - f->bc - bsl, d = (float)depth;
    /* the bias terms' and z's bounds, the subtractions' rounding, the stored depth's
     * rounding to float (2^-24 of it) and some room */
    const float M = f->ez + (om__fabsf(f->z) + om__fabsf(f->bc) + om__fabsf(bsl)) * 0x1p-17f +
                    d * 0x1p-22f + 4.0f;
    if (zl + M <= d) return 1;
    if (zl - M > d) return 0;
    return -1;
}

/* Whether ratio0 * inv_scale[level] > 1: 1, 0, or -1 too close (or not set). */
static inline int om__asm_fpt_finer(const om__asm_pctx *c, const om__asm_fpt *f, uint32_t level)
{
    if (!(f->ratio0 > 0.0f)) return -1;
    const float r = f->ratio0 * c->inv_scale[level];
    if (r > 1.0f + 0x1p-15f) return 1;
    if (r < 1.0f - 0x1p-15f) return 0;
    return -1;
}

/* ---- the method's state: asm.c's, and asm_render.c's, which renders its tiles. */
typedef struct om__asm_dvec { double x, y, z, w; } om__asm_dvec;

typedef struct om__asm_state {
    om__state_head head;   /* first (method.h) */
    const om_scene *scene;
    om__asm_cfg cfg;
    om__asm_tree tree;
    om_view view;
    om_mat4 built_vp;      /* the light the tiles hold */
    om_vec3 built_org;     /* and the origin they are relative to */
    bool built;
    bool prepared;         /* this frame's projections are done */
    bool lean;             /* no per-vertex or per-triangle arrays: see render */
    float *tbox;           /* per triangle: base-texel bounds u0, v0, u1, v1 (not lean) */
    /* Per triangle, a bit: its bounds hold a texel centre of level 0's grid (centre[0])
     * or level 1's (centre[1]): box_holds_centre once per frame for the levels every
     * rebuild renders whole, so their gathers read no bounds of triangles that would
     * write nothing (not lean). */
    uint32_t *centre[2];
    uint32_t *cull;        /* triangles that meet the region being rendered (not lean);
                              from the bounds to the grid, each triangle's cells */
    /* A grid of cells over the base texels, each listing the triangles whose bounds
     * meet it, made once per frame, so that a tile gathers from its cells instead of
     * testing every triangle's bounds; a bit per triangle puts them back in index
     * order. Not lean; unused in a frame whose lists would overflow `gcap`. */
    uint32_t gside;        /* cells per side */
    uint32_t *gstart;      /* gside^2 + 1 offsets into glist */
    uint32_t *glist, gcap;
    uint32_t *gbits;       /* (ntris + 31) / 32 words */
    bool gready;           /* this frame's lists were made */
    /* Lean mode with asm.float, where the arena has room: per run of chunk_tris
     * triangles (in index order), the union of their float bounds (tri_box_cached), or
     * everything where one has none, made once a frame before its first tile
     * (chunk_ready), so that a tile skips a run whose union misses it. NULL without. */
    float *chunk;
    uint32_t chunk_tris;
    bool chunk_ready;
    uint32_t *sdepth, *sid;   /* one tile of scratch for the rasterizer */
    om__asm_cand *cand;
    uint32_t ncand_max;
    double inv_scale[OM__ASM_MAX_LEVEL + 1];   /* a level-L texel in base texels */
    om__asm_pctx pc;       /* what a sample's setup reads (asm_point.c) */
    uint32_t cache;        /* the last leaf found by resolve, or OM__ASM_NONE */
    om__asm_tile cache_tile;
    uint32_t samples, shadowed, analysed, straddling, candidates, rebuilds;
    uint32_t change;       /* the scene's change count the tiles hold */
    om_vec3 *drawn;        /* per object, lo and hi of its box as the tiles hold it: a
                              host may move it several times between two frames, and
                              the scene keeps only the box before its last move */
    uint32_t redrawn;      /* this frame: tiles drawn again where objects moved */
#if OM_WITH_JOBS
    /* The host's threads for this frame (om__lend, asm_jobs.c), NULL without; the
     * slots' scratch, slot[j] for j < nslot (one a job: render and analysis scratch). */
    const om__lend *lend;
    void *const *slot;
    uint32_t nslot;
#endif
} om__asm_state;

/* A tile render's scratch: one tile's depth and ids for the rasterizer, and (not lean)
 * a cull list of ntris and a bit a triangle, all clear between renders. */
typedef struct om__asm_rs {
    uint32_t *sdepth, *sid, *cull, *gbits;
} om__asm_rs;

/* asm_render.c: this frame's projections, bounds and triangle grid (once a frame;
 * a rebuild renders the base tile), and the tile of node `index` rendered (with the
 * state's scratch, or with `rs`). */
void om__asm_prepare(om__asm_state *m);
void om__asm_render_node(om__asm_state *m, uint32_t index);
void om__asm_render_with(om__asm_state *m, uint32_t index, const om__asm_rs *rs);
/* This frame's chunk bounds (om__asm_state.chunk), if not made yet: before the frame's
 * first tile, on the calling thread. */
void om__asm_chunks(om__asm_state *m);

/* What a band's analysis adds to the tree, in a job's scratch, put on the tree after
 * the bands on the calling thread (asm_jobs.c): sums, maxima and marks, the same in any
 * order. Declared without the jobs too: asm.c's one analysis walk takes it, NULL for
 * the tree itself. */
typedef struct om__asm_acc {
    uint32_t *hdr;         /* analysed, straddling; nodes touched: lowest, highest + 1 */
    uint32_t *stamp;       /* a bit a node used (stamped), bit `count` the base's */
    uint32_t *benefit;     /* count: added to each node's benefit */
    uint32_t *ben;         /* count * cells^2: added to each cell's benefit */
    float *need;           /* count * cells^2: each cell's largest N_required */
    uint32_t *first;       /* the base's cells: 1 + the first sample (strip index) that
                              fell in the cell while it held no root tile, else 0 */
    uint32_t *missed;      /* the base's cells: samples that fell in the cell once no
                              root tile could be made for it (counted with `again`) */
} om__asm_acc;

#if OM_WITH_JOBS
/* asm_jobs.c: on the host's threads. The tiles of `list` (n nodes, each rendered by
 * one job); false where there are no threads (nothing done). */
bool om__asm_render_list(om__asm_state *m, const uint32_t *list, uint32_t n);
/* observe's analysis of a strip by bands; false where it cannot run so (no threads,
 * or root tiles to make that would need to replace others): nothing done but the
 * strip's terms as they were. */
bool om__asm_observe_jobs(om__asm_state *m, const om_strip *st);

/* asm.c: observe's analysis of rows [y0, y0 + rows) of the strip into `a`, reading
 * the tree only. A sample whose base cell holds no root tile goes no further: its
 * term's g is set to 254 and the cell's first sample noted. With `again`, only those
 * samples (g put back to 255), once the root tiles are made; one whose cell still has
 * none is counted in `missed`. */
void om__asm_observe_rows(const om__asm_state *m, const om_strip *st, uint32_t y0, uint32_t rows,
                          const om__asm_acc *a, bool again);
/* resolve's finish, by parts of the strip; false where there are no threads. */
bool om__asm_finish_jobs(om__asm_state *m, om_strip *st);
/* asm.c: finish's scan of terms [i0, i1): each marked term put back and its leaf's bit
 * set in `bits` (a bit a node, bit `count` the base's), reading the tree only. */
void om__asm_leaves(const om__asm_state *m, om_strip *st, size_t i0, size_t i1, uint32_t *bits);
/* asm.c: stamps the path of every leaf set in `bits` (as om__asm_leaves sets them) as
 * used this frame, and clears them. */
void om__asm_stamp_leaves(om__asm_tree *t, uint32_t *bits);
#endif

#endif
