/* izb.c — the irregular z-buffer (Alias-Free Shadow Maps, Aila and Laine 2004).
 *
 * Section 3: every exposed visible sample is transformed to the light's image plane
 * without discretising it (the light grid of occlude.h, 2^21 steps across).
 * Section 5.1: the samples are organised in an axis-aligned 2-D BSP (here split along
 * their Z order rather than at medians), leaves of at most izb.leaf samples; each
 * node keeps the bounds of its samples and their largest light depth. A grid of
 * cells, each one node of the tree, lets small triangles skip the descent.
 * Sections 3-5: every triangle is rasterized through the BSP (izb_raster.c), where
 * the frame's grid of triangles on the light's image (lgrid.h) does not rule it out
 * for the tile. Section 4: semi-transparent casters add their optical depth per
 * sample.
 *
 * Bounded pools: samples and nodes live in pools carved once from the method's arena.
 * When a strip holds more exposed samples than the pool, it is processed in tiles of
 * consecutive samples, each with its own BSP — memory stays fixed whatever the image
 * size. The tie rule, depth test and transmittance are the reference's own, so the
 * result equals the reference exactly, whatever the tiling. */
#include "../method.h"
#include "izb.h"

extern const om_method om__method_izb;

typedef struct izb_state {
    om__state_head head;   /* first (method.h) */
    om__izb z;
    om__izb_cfg cfg;
    uint32_t width, height;
    /* The pass on the host's threads (om__pass, below): the current strip's exposed
     * samples before each row (rowsum[r], height + 1 of them; NULL without
     * OM_WITH_JOBS), and their tiling. */
    uint32_t *rowsum;
    uint32_t exposed, ntiles;
    /* The triangles binned on the light's image (z.grid points here when it has room),
     * and the pass's slots that make it, a frame at a time (om__pass.lend). */
    om__lgrid grid;
    const om__lend *lend;
} izb_state;

/* Least samples a split leaves in a leaf: a node splits only above `leaf` samples. */
static uint32_t min_leaf(uint32_t leaf) { return (leaf + 1) / 2 ? (leaf + 1) / 2 : 1; }

/* The Z order of the BSP's keys has ZBITS bits an axis (om__izb_zcode): 4M cells over a
 * tile, far finer than its leaves (keys of one code are split in the middle), and a
 * sort of two passes. */
#define ZBITS 11

/* The grid in front of the BSP (see om__izb_build): at most a cell per CELL_FILL
 * samples, a power of 4 (2^k x 2^k cells), k at most ZBITS. Finer cells let a small
 * triangle reach its samples without descending the tree; coarser ones cost a large
 * triangle fewer cell checks. */
#define CELL_FILL 4u

static uint32_t cells_bound(uint32_t samples)
{
    uint32_t c = 1, want = samples / CELL_FILL;
    while (c < (1u << 2 * ZBITS) && c * 4 <= want) c *= 4;
    return c;
}

/* The tree's top (down to the grid's cells) has at most 2 nodes a cell; below, a node
 * splits only while it has room. */
static uint32_t node_bound(uint32_t samples, uint32_t leaf)
{
    uint32_t leaves = samples / min_leaf(leaf);
    return 2 * (leaves ? leaves : 1) + 1 + 2 * cells_bound(samples);
}

/* Arena bytes of setup's parts: the material depths and, with `cache`, the per-frame
 * vertex projection; and of a pool of `samples` with its BSP nodes. */
static size_t parts_bytes(const om_scene *s, bool cache)
{
    return (cache ? om__lspace_bytes(s) : 0) +
           om_arena_need((size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4);
}

/* (Saturating, as every byte count here: a pool past what a 32-bit size_t holds asks
 * for SIZE_MAX, which no arena has.) */
static size_t pool_bytes_of(uint32_t samples, uint32_t leaf)
{
    const size_t keys = om_arena_need(om__size_mul(samples, sizeof(om__izb_key)), 16);
    return om__size_add(om__size_add(om_arena_need(om__size_mul(samples, sizeof(om__odepth)), 16),
                                     om__size_add(keys, keys)),
                        om__size_add(om_arena_need(om__size_mul(node_bound(samples, leaf), sizeof(om__izb_node)), 16),
                                     om_arena_need(om__size_mul(cells_bound(samples), sizeof(uint32_t)), 16)));
}

/* The pool by default: tiles of at least TILE_LEAST samples, and at least n^2 /
 * 2^TILE_SQ samples for a scene of n triangles, up to the whole image. Each tile walks
 * the triangles the frame's grid lists near its samples (every triangle without the
 * grid, where one that reaches none of its samples costs it little); small tiles keep their keys, nodes and cells in the cache, leave little to clear, and give
 * the host's threads several jobs of the like cost (a strip's tiles are cut in the
 * screen's order, and where a cloud shadows the top half of the image, two tiles
 * differ several times over). With many triangles, though, most reach every tile and
 * are set up in each (clipping and projecting in double), so the pool grows faster
 * than the triangle count: at 1024x768 a frame is one pass from about 900K triangles
 * (izb.md). */
#define TILE_LEAST 32768u
#define TILE_SQ 20

static uint64_t pool_of_tris(const om_scene *s)
{
    const uint64_t n = s->ntris, want = n * n >> TILE_SQ;
    return want < TILE_LEAST ? TILE_LEAST : want;
}

static uint32_t auto_pool(const om_scene *s, uint32_t w, uint32_t h)
{
    uint64_t want = pool_of_tris(s), all = (uint64_t)w * h;
    if (want > all) want = all;
    return (uint32_t)(want > w ? want : w);
}

/* The triangles binned on the light's image and a tile's selection of them (lgrid.h):
 * kept where the arena holds them beside the vertex projection and the whole pool. */
static size_t grid_bytes(const om_scene *s) { return om__lgrid_bytes(s) + om_arena_need(om__lgrid_sel_bytes(s), 16); }

/* The state, its row sums for the pass, and setup's parts. */
static size_t fixed_bytes(const om_scene *s, uint32_t h, bool cache)
{
    return om_arena_need(sizeof(izb_state), 16) +
           (OM_WITH_JOBS ? om_arena_need(((size_t)h + 1) * sizeof(uint32_t), 4) : 0) + parts_bytes(s, cache);
}

static om_status pool_bytes(const om__izb_cfg *c, const om_scene *s, uint32_t w, uint32_t h,
                            size_t *min, size_t *full)
{
    if (c->izb_leaf < 1) return OM_E_INVALID;
    uint32_t one_pass = auto_pool(s, w, h), smallest = w;   /* the smallest tile: one row */
    if (c->izb_pool) one_pass = smallest = c->izb_pool;
    *min = om__size_add(fixed_bytes(s, h, false), pool_bytes_of(smallest, c->izb_leaf));
    *full = om__size_add(om__size_add(fixed_bytes(s, h, true), pool_bytes_of(one_pass, c->izb_leaf)), grid_bytes(s));
    return OM_OK;
}

static om_status izb_bytes(const om_method_cfg *mc, const om_scene *s, uint32_t w, uint32_t h,
                           size_t *min, size_t *full)
{
    om__izb_cfg c;
    if (om__method_cfg_of(mc, &om__method_izb, &c, NULL)) return OM_E_INVALID;
    return pool_bytes(&c, s, w, h, min, full);
}

/* The largest pool from `least` up to `want` samples that `bytes` hold; 0 when not even
 * `least` does. */
static uint32_t pool_fit(size_t bytes, uint32_t least, uint32_t want, uint32_t leaf)
{
    if (pool_bytes_of(least, leaf) > bytes) return 0;
    uint32_t cap = least, hi = want;
    while (cap < hi) {
        uint32_t mid = cap + (hi - cap + 1) / 2;
        if (pool_bytes_of(mid, leaf) <= bytes) cap = mid;
        else hi = mid - 1;
    }
    return cap;
}

/* Carves z's parts from `a`: the vertex projection when the arena holds it and a pool
 * at least half as large as without it, then the pool: c->izb_pool samples when set, else the
 * largest from `least` up to `want` that fits. The caller has checked the minimum. */
static om_status setup(om__izb *z, om__lgrid *g, om_arena *a, const om__izb_cfg *c, const om_scene *s,
                       uint32_t want, uint32_t least, om_diag *d)
{
    om_status st;
    void *p;
    z->scene = s;
    z->leaf = c->izb_leaf;
    if (c->izb_pool) want = least = c->izb_pool;
    /* The vertex projection when the pool keeps at least half the samples it would
     * have without it: without it, every tile sets up every triangle of the scene
     * (clipping and projecting in double), which costs far more than the tiles that
     * half the pool adds (in a microcontroller's thin strips that setup would be most
     * of the frame). */
    size_t left0 = om_arena_left(a), with_cache = parts_bytes(s, true), lean = parts_bytes(s, false);
    uint32_t p_with = left0 >= with_cache ? pool_fit(left0 - with_cache, least, want, z->leaf) : 0;
    uint32_t p_lean = left0 >= lean ? pool_fit(left0 - lean, least, want, z->leaf) : 0;
    if (p_with && (uint64_t)p_with * 2 >= p_lean) {
        if ((st = om__lspace_init(&z->ls, a, s, d))) return st;
    } else {
        om__lspace_init_lean(&z->ls, s);
    }
    if ((st = om_arena_alloc(a, (size_t)(s->nmats ? s->nmats : 1) * sizeof(om__odepth), 4, &p, d)))
        return st;
    z->mat_od = (om__odepth *)p;
    for (uint32_t i = 0; i < s->nmats; i++) z->mat_od[i] = om__material_odepth(&s->mats[i]);
    /* The grid when the whole pool still fits beside it: the pool matters more. */
    z->grid = NULL;
    z->sel = NULL;
    if (z->ls.verts && om_arena_left(a) >= grid_bytes(s) &&
        pool_fit(om_arena_left(a) - grid_bytes(s), least, want, z->leaf) == want) {
        if ((st = om__lgrid_init(g, a, &z->ls, d))) return st;
        if ((st = om_arena_alloc(a, om__lgrid_sel_bytes(s), 16, &p, d))) return st;
        z->grid = g;
        z->sel = (uint32_t *)p;
    }
    /* The pool: as configured, or as many samples as the arena holds, up to one pass. */
    uint32_t cap = pool_fit(om_arena_left(a), least, want, z->leaf);
    if (!cap) cap = least;   /* (the caller checked the minimum: the carve below fails) */
    z->cap = cap;
    z->node_cap = node_bound(cap, z->leaf);
    if ((st = om_arena_alloc(a, om__size_mul(cap, sizeof(om__odepth)), 16, &p, d))) return st;
    z->od = (om__odepth *)p;
    if ((st = om_arena_alloc(a, om__size_mul(cap, sizeof(om__izb_key)), 16, &p, d))) return st;
    z->keys = (om__izb_key *)p;
    if ((st = om_arena_alloc(a, om__size_mul(cap, sizeof(om__izb_key)), 16, &p, d))) return st;
    z->sorted = (om__izb_key *)p;
    if ((st = om_arena_alloc(a, om__size_mul(z->node_cap, sizeof(om__izb_node)), 16, &p, d))) return st;
    z->nodes = (om__izb_node *)p;
    z->cells_cap = cells_bound(cap);
    if ((st = om_arena_alloc(a, om__size_mul(z->cells_cap, sizeof(uint32_t)), 16, &p, d))) return st;
    z->cells = (uint32_t *)p;
    return OM_OK;
}

static om_status izb_init(void **state, om_arena *a, const om_method_cfg *mc, const om_scene *s,
                          uint32_t w, uint32_t h, om_diag *d)
{
    om_status st;
    void *p;
    size_t mn, full;
    om__izb_cfg cv;
    const om__izb_cfg *c = &cv;
    if ((st = om__method_cfg_of(mc, &om__method_izb, &cv, d))) return st;
    if (c->izb_leaf < 1) return om__fail(d, OM_E_INVALID, "izb: leaf size must be at least 1");
    if ((st = pool_bytes(c, s, w, h, &mn, &full))) return st;
    if ((st = om__need(a, mn, "izb", d))) return st;
    if ((st = om_arena_alloc(a, sizeof(izb_state), 16, &p, d))) return st;
    izb_state *m = (izb_state *)p;
    m->cfg = *c;
    m->width = w;
    m->height = h;
    if (OM_WITH_JOBS) {
        if ((st = om_arena_alloc(a, ((size_t)h + 1) * sizeof(uint32_t), 4, &p, d))) return st;
        m->rowsum = (uint32_t *)p;
    }
    if ((st = setup(&m->z, &m->grid, a, c, s, auto_pool(s, w, h), w, d))) return st;
    *state = m;
    return OM_OK;
}

/* begin but for the projection of the scene's vertices (when they are kept): returns
 * how many there are to project, which the pass's jobs do in ranges (izb_pass_setup). */
om__izb *om__izb_of(void *state) { return &((izb_state *)state)->z; }

static uint32_t begin_view(izb_state *m, const om_view *v)
{
    om__lspace_view(&m->z.ls, v);
    m->grid.ready = 0;
    memset(&m->z.st, 0, sizeof m->z.st);
    return m->z.ls.verts ? m->z.scene->nverts : 0;
}

static om_status izb_begin(void *state, const om_view *v, om_diag *d)
{
    (void)d;
    izb_state *m = (izb_state *)state;
    om__lspace_project(&m->z.ls, 0, begin_view(m, v));
    return OM_OK;
}

static om_status izb_observe(void *state, const om_strip *st, om_diag *d)
{
    (void)state; (void)st; (void)d;
    return OM_OK;
}

static om_status izb_build(void *state, om_diag *d)
{
    (void)state; (void)d;
    return OM_OK;
}

/* ---- stage 1: transform */

uint32_t om__izb_transform(om__izb *z, const om_strip *st, size_t *next, size_t end, uint32_t take)
{
    size_t i = *next;
    uint32_t n = 0, taken = 0;
    z->facet.tri = OM_NO_TRI;
    z->facet.slope = 0.0f;
    for (; i < end && taken < take; i++) {
        if (!(st->terms[i].flags & OM_TERM_EXPOSED)) continue;
        taken++;
        om__lpoint p;
        uint32_t pz;
        /* unpulled: izb_raster.c pulls a key's depth where a triangle first blocks it */
        if (!om__lspace_point_at(&z->ls, &st->samples[i], &p, &pz)) continue;   /* behind the light */
        /* the sample's key for the BSP, and the tile's bounds, while it is at hand */
        om__izb_key *k = &z->keys[n];
        k->x = (int32_t)p.x;   /* the light grid fits in 27 bits */
        k->y = (int32_t)p.y;
        k->z = (uint32_t)p.z;  /* a whole number: the projection's depth */
        k->tri = p.tri;
        k->s = (uint32_t)i;
        if (n == 0 || k->x < z->kx0) z->kx0 = k->x;
        if (n == 0 || k->x > z->kx1) z->kx1 = k->x;
        if (n == 0 || k->y < z->ky0) z->ky0 = k->y;
        if (n == 0 || k->y > z->ky1) z->ky1 = k->y;
        n++;
    }
    *next = i;
    z->n = n;
    z->taken = taken;
    return n;
}

/* ---- stage 2: the 2-D BSP */

/* Gives every key its code, then sorts z->keys into Z order (a stable
 * least-significant-digit radix sort through z->sorted, two passes of 11 bits; keys
 * of equal code keep the screen's order), so
 * that halving the array again and again gives nodes that are compact in the light's
 * image. Integer keys only: the same order in any floating-point mode. Returns the
 * shift that fits the tile's span into the codes' 16 bits an axis. */
static int zsort(om__izb *z)
{
    uint32_t n = z->n;
    int32_t x0 = z->kx0, y0 = z->ky0, x1 = z->kx1, y1 = z->ky1;
    uint32_t span = (uint32_t)(x1 - x0) > (uint32_t)(y1 - y0) ? (uint32_t)(x1 - x0) : (uint32_t)(y1 - y0);
    int shift = 0;
    while ((span >> shift) >> ZBITS) shift++;
    /* two digits of 11 bits; their histograms in one pass over the keys */
    uint32_t count[2][2049];
    memset(count, 0, sizeof count);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = z->keys[i].code = om__izb_zcode(&z->keys[i], x0, y0, shift);
        count[0][(c & 2047u) + 1]++;
        count[1][(c >> 11) + 1]++;
    }
    om__izb_key *src = z->keys, *dst = z->sorted;
    for (int pass = 0; pass < 2; pass++) {
        uint32_t *cnt = count[pass];
        int d = 11 * pass;
        if (cnt[((src[0].code >> d) & 2047u) + 1] == n) continue;   /* one digit */
        for (int b = 0; b < 2048; b++) cnt[b + 1] += cnt[b];
        for (uint32_t i = 0; i < n; i++) dst[cnt[(src[i].code >> d) & 2047u]++] = src[i];
        om__izb_key *t = src;
        src = dst;
        dst = t;
    }
    z->keys = src;   /* the two buffers trade places rather than copy */
    z->sorted = dst;
    return shift;
}

/* Where the sorted keys [first, first + count) split: at the highest bit in which their
 * codes differ (the node's quadtree-like cell is cut in two halves of space), or in
 * the middle when they all share one code. */
static uint32_t zsplit(const om__izb *z, uint32_t first, uint32_t count)
{
    const om__izb_key *k = &z->keys[first];
    uint32_t a = k[0].code, b = k[count - 1].code;
    if (a == b) return count / 2;
    uint32_t bit = 1u << (2 * ZBITS - 1);
    while (!((a ^ b) & bit)) bit >>= 1;
    uint32_t lo = 0, hi = count - 1;   /* the first key with the bit set: in (lo, hi] */
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (k[mid].code & bit) hi = mid;
        else lo = mid;
    }
    return hi;
}

/* Bounds and farthest depth of a node: from its keys for a leaf, from its children
 * otherwise (children are created after their parent, so a reverse sweep meets them
 * first). */
static void bound_node(om__izb *z, om__izb_node *nd)
{
    if (nd->child) {
        const om__izb_node *l = &z->nodes[nd->child], *r = l + 1;
        nd->x0 = l->x0 < r->x0 ? l->x0 : r->x0;
        nd->y0 = l->y0 < r->y0 ? l->y0 : r->y0;
        nd->x1 = l->x1 > r->x1 ? l->x1 : r->x1;
        nd->y1 = l->y1 > r->y1 ? l->y1 : r->y1;
        nd->zmax = l->zmax > r->zmax ? l->zmax : r->zmax;
    } else {
        const om__izb_key *k = &z->keys[nd->first];
        int32_t x0 = k->x, x1 = k->x, y0 = k->y, y1 = k->y;
        uint32_t zm = k->z;
        for (uint32_t i = 1; i < nd->count; i++) {
            if (k[i].x < x0) x0 = k[i].x;
            if (k[i].x > x1) x1 = k[i].x;
            if (k[i].y < y0) y0 = k[i].y;
            if (k[i].y > y1) y1 = k[i].y;
            if (k[i].z > zm) zm = k[i].z;
        }
        nd->x0 = x0; nd->x1 = x1; nd->y0 = y0; nd->y1 = y1;
        nd->zmax = zm;
    }
    nd->open = nd->count;
}

/* A new node over keys [first, first + count) under `parent`. */
static uint32_t new_node(om__izb *z, uint32_t first, uint32_t count, uint32_t parent)
{
    om__izb_node *nd = &z->nodes[z->nnodes];
    nd->first = first;
    nd->count = count;
    nd->child = 0;
    nd->parent = parent;
    return z->nnodes++;
}

static void split_node(om__izb *z, uint32_t ni, uint32_t half)
{
    om__izb_node *nd = &z->nodes[ni];
    uint32_t c = new_node(z, nd->first, half, ni);
    new_node(z, nd->first + half, nd->count - half, ni);
    nd->child = c;
}

/* The tree is built in two phases. The top splits every node whose keys fall in more
 * than one cell of the grid (2^gk x 2^gk cells, the top 2 gk bits of the Z order): a
 * split at the highest differing bit of the codes then parts whole cells, so every
 * non-empty cell ends as one node holding exactly its keys, and the grid records it.
 * Then each cell's node is split as before, down to leaves of at most `leaf` keys (or
 * while nodes remain). The top never runs out: it has fewer than 2 nodes a cell. */
void om__izb_build(om__izb *z)
{
    z->nnodes = 0;
    if (z->n == 0) return;
    int shift = zsort(z);
    int k = 0;
    uint32_t ncells = 1, want = z->n / CELL_FILL;
    while (ncells < z->cells_cap && ncells * 4 <= want) {
        ncells *= 4;
        k++;
    }
    z->gk = k;
    z->gshift = shift + ZBITS - k;
    z->zshift = shift;
    for (uint32_t i = 0; i < ncells; i++) z->cells[i] = OM_IZB_NONE;
    uint32_t stack[64];
    int sp = 0;
    stack[sp++] = new_node(z, 0, z->n, OM_IZB_NONE);
    const int cut = 2 * (ZBITS - k);   /* a code's cell: its top 2k bits */
    while (sp > 0) {
        uint32_t ni = stack[--sp];
        const om__izb_node *nd = &z->nodes[ni];
        uint32_t a = z->keys[nd->first].code, b = z->keys[nd->first + nd->count - 1].code;
        if (a >> cut == b >> cut) {
            z->cells[a >> cut] = ni;
            continue;
        }
        split_node(z, ni, zsplit(z, nd->first, nd->count));
        stack[sp++] = z->nodes[ni].child;
        stack[sp++] = z->nodes[ni].child + 1;
    }
    uint32_t top = z->nnodes;
    for (uint32_t r = 0; r < top; r++) {
        if (z->nodes[r].child) continue;   /* a cell's node: the rest of the tree below it */
        sp = 0;
        stack[sp++] = r;
        while (sp > 0) {
            uint32_t ni = stack[--sp];
            const om__izb_node *nd = &z->nodes[ni];
            if (nd->count <= z->leaf || z->nnodes + 2 > z->node_cap || sp + 2 > 64) continue;
            split_node(z, ni, zsplit(z, nd->first, nd->count));
            stack[sp++] = z->nodes[ni].child;
            stack[sp++] = z->nodes[ni].child + 1;
        }
    }
    for (uint32_t i = z->nnodes; i-- > 0;) bound_node(z, &z->nodes[i]);
    memset(z->od, 0, (size_t)z->n * sizeof *z->od);   /* by the keys' sorted places */
    z->st.nodes += z->nnodes;
}

void om__izb_write(const om__izb *z, const om_strip *st)
{
    for (uint32_t i = 0; i < z->n; i++) om__odepth_term(&z->od[i], &st->terms[z->keys[i].s & OM_IZB_INDEX]);
}

uint32_t om__izb_tiles(const om__izb *z, uint32_t exposed)
{
    return exposed ? (uint32_t)(((uint64_t)exposed + z->cap - 1) / z->cap) : 0;
}

uint32_t om__izb_tile_first(const om__izb *z, uint32_t exposed, uint32_t k)
{
    const uint64_t o = (uint64_t)k * z->cap;
    return o < exposed ? (uint32_t)o : exposed;
}

void om__izb_grid(om__izb *z)
{
    if (z->grid && z->grid->ready == 0) om__lgrid_make(z->grid);
}

void om__izb_resolve(om__izb *z, om_strip *st)
{
    om__izb_grid(z);
    size_t n = (size_t)st->rows * st->width, next = 0;
    for (size_t i = 0; i < n; i++) st->terms[i].r = st->terms[i].g = st->terms[i].b = 255;
    for (;;) {   /* pool after pool of exposed samples: om__izb_tiles' tiles */
        om__izb_transform(z, st, &next, n, z->cap);
        if (z->taken == 0) break;
        om__izb_build(z);
        om__izb_raster(z);
        om__izb_write(z, st);
        z->st.tiles++;
    }
}

/* ---- the pass on the host's threads (method.h, om__pass): one job a tile, each with a
 * pool of the state's size in its scratch; the same tiles as om__izb_resolve, so the
 * same terms and counts whatever the number of jobs. */

static size_t up16(size_t b) { return (b + 15) / 16 * 16; }

static size_t izb_pass_scratch(const void *state, const om_scene *s)
{
    if (state) {
        const om__izb *z = &((const izb_state *)state)->z;
        return pool_bytes_of(z->cap, z->leaf) + (z->grid ? up16(om__lgrid_sel_bytes(z->scene)) : 0);
    }
    if (!s) return 0;
    uint64_t most = pool_of_tris(s);   /* auto_pool without the image's bound */
    return pool_bytes_of(most > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)most, 64) + up16(om__lgrid_sel_bytes(s));
}

/* The grid's steps as jobs of the pass's slots (om__lend), by parts of the triangles
 * (lgrid.h's counting sort, each part counting in its slot's scratch, which the tiles
 * overwrite later), so that no job reads every triangle: at most GRID_PARTS parts. */
#define GRID_PARTS 64u

typedef struct grid_job {
    om__lgrid *g;
    uint32_t parts, step;
    uint32_t *cnt[GRID_PARTS];      /* part k's counts, in the scratch of the slot that ran it */
    uint64_t entries[GRID_PARTS];   /* range k's, from sum_rows */
    uint32_t at[257];               /* each row's base: om__lgrid_rows, at most 257 */
} grid_job;

static void grid_part(void *user, uint32_t k, void *scratch)
{
    grid_job *j = (grid_job *)user;
    if (j->step == 0) {
        j->cnt[k] = (uint32_t *)scratch;
        om__lgrid_boxes_count(j->g, k, j->parts, j->cnt[k]);
    } else if (j->step == 1) {
        j->entries[k] = om__lgrid_sum_rows(j->g, j->cnt, k, j->parts);
    } else {
        om__lgrid_fill_part(j->g, j->at, k, j->parts, j->cnt[k]);
    }
}

/* The frame's grid, once, before its first strip's tiles: by jobs where the frame
 * lends its slots and their scratch holds a part's counts, else on this thread (the
 * same lists). */
static void make_grid(izb_state *m)
{
    if (!m->z.grid || m->grid.ready) return;
    if (!m->lend || izb_pass_scratch(m, NULL) < om__lgrid_part_bytes(&m->grid)) {
        om__izb_grid(&m->z);
        return;
    }
    grid_job j;
    j.g = &m->grid;
    j.parts = m->lend->slots < GRID_PARTS ? m->lend->slots : GRID_PARTS;
    for (j.step = 0; j.step < 3; j.step++) {
        if (j.step == 2) {
            om__lgrid_bases(&m->grid, j.entries, j.parts, j.at);
            if (m->grid.ready != 1) return;
        }
        m->lend->run(m->lend, grid_part, &j, j.parts);
    }
}

/* The exposed samples of each of the strip's rows [r0, r1), into out[r + 1]. */
static void count_rows(uint32_t *out, const om_strip *st, uint32_t r0, uint32_t r1)
{
    for (uint32_t r = r0; r < r1; r++) {
        const om_term *t = st->terms + (size_t)r * st->width;
        uint32_t e = 0;
        for (uint32_t x = 0; x < st->width; x++) e += (t[x].flags & OM_TERM_EXPOSED) != 0;
        out[r + 1] = e;
    }
}

/* The rows counted as jobs of the pass's slots, each its share of the rows: on one
 * thread the count is a whole pass over the strip's terms, which would hold every
 * other thread up. */
typedef struct rows_job { uint32_t *out; const om_strip *st; uint32_t parts; } rows_job;

static void rows_part(void *user, uint32_t k, void *scratch)
{
    (void)scratch;
    const rows_job *j = (const rows_job *)user;
    const uint32_t n = j->st->rows;
    count_rows(j->out, j->st, (uint32_t)((uint64_t)n * k / j->parts), (uint32_t)((uint64_t)n * (k + 1) / j->parts));
}

/* Counts every row's exposed samples (rowsum: by jobs where the frame lends its
 * slots, then added up in the rows' order) and tiles the strip. */
static uint32_t izb_pass_plan(void *state, om_strip *st)
{
    izb_state *m = (izb_state *)state;
    make_grid(m);
    m->rowsum[0] = 0;
    if (m->lend) {
        rows_job j = {m->rowsum, st, m->lend->slots};
        m->lend->run(m->lend, rows_part, &j, j.parts);
    } else {
        count_rows(m->rowsum, st, 0, st->rows);
    }
    for (uint32_t r = 0; r < st->rows; r++) m->rowsum[r + 1] += m->rowsum[r];
    m->exposed = m->rowsum[st->rows];
    m->ntiles = om__izb_tiles(&m->z, m->exposed);
    if (m->ntiles == 0) {
        size_t n = (size_t)st->rows * st->width;
        for (size_t i = 0; i < n; i++) st->terms[i].r = st->terms[i].g = st->terms[i].b = 255;
    }
    return m->ntiles;
}

/* Where tile k begins in the strip: at its first exposed sample (the strip's start for
 * the first tile, its end past the last). */
static size_t tile_start(const izb_state *m, const om_strip *st, uint32_t k)
{
    if (k == 0) return 0;
    if (k >= m->ntiles) return (size_t)st->rows * st->width;
    const uint32_t o = om__izb_tile_first(&m->z, m->exposed, k);
    uint32_t lo = 0, hi = st->rows - 1;   /* the row holding exposed sample o */
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo + 1) / 2;
        if (m->rowsum[mid] <= o) lo = mid;
        else hi = mid - 1;
    }
    const om_term *t = st->terms + (size_t)lo * st->width;
    uint32_t c = m->rowsum[lo], x = 0;
    for (;; x++)
        if ((t[x].flags & OM_TERM_EXPOSED) && c++ == o) break;
    return (size_t)lo * st->width + x;
}

/* The tile job k runs. The frame hands slot p the jobs p, p + P, ... (om__pass), and a
 * strip's tiles mostly cost less the lower they lie on the screen (the top's samples
 * lie far, under more of the scene), so each round of P jobs takes its P tiles in the
 * other direction from the round before: slot 0 gets tiles 0, 2P - 1, 2P, ..., the
 * last slot P - 1, P, 3P - 1, ... Which slot runs a tile changes no term or count. */
static uint32_t tile_of(const izb_state *m, uint32_t k)
{
    const uint32_t slots = m->lend ? m->lend->slots : 1, p = m->ntiles < slots ? m->ntiles : slots;
    const uint32_t r = k / p, first = r * p, n = m->ntiles - first < p ? m->ntiles - first : p;
    return r & 1 ? first + n - 1 - (k - first) : k;
}

static void izb_pass_job(const void *state, const om_strip *st, uint32_t k, void *scratch, uint32_t counts[8])
{
    const izb_state *m = (const izb_state *)state;
    k = tile_of(m, k);
    om__izb z = m->z;   /* the scene, projection and pool's sizes; the pool is the scratch */
    unsigned char *p = (unsigned char *)scratch;
    z.od = (om__odepth *)p;
    p += up16((size_t)z.cap * sizeof(om__odepth));
    z.keys = (om__izb_key *)p;
    p += up16((size_t)z.cap * sizeof(om__izb_key));
    z.sorted = (om__izb_key *)p;
    p += up16((size_t)z.cap * sizeof(om__izb_key));
    z.nodes = (om__izb_node *)p;
    p += up16((size_t)z.node_cap * sizeof(om__izb_node));
    z.cells = (uint32_t *)p;
    if (z.grid) z.sel = (uint32_t *)(p + up16((size_t)z.cells_cap * sizeof(uint32_t)));
    memset(&z.st, 0, sizeof z.st);
    size_t next = tile_start(m, st, k), end = tile_start(m, st, k + 1);
    for (size_t i = next; i < end; i++) st->terms[i].r = st->terms[i].g = st->terms[i].b = 255;
    om__izb_transform(&z, st, &next, end,
                      om__izb_tile_first(&m->z, m->exposed, k + 1) - om__izb_tile_first(&m->z, m->exposed, k));
    om__izb_build(&z);
    om__izb_raster(&z);
    om__izb_write(&z, st);
    const uint32_t v[7] = {z.st.nodes, z.st.visited, z.st.culled_shadowed, z.st.culled_depth,
                           z.st.tested, z.st.blocked, 1};
    for (int i = 0; i < 7; i++) counts[i] += v[i];
}

static void izb_pass_merge(void *state, const uint32_t counts[8])
{
    om__izb_stats *s = &((izb_state *)state)->z.st;
    s->nodes += counts[0];
    s->visited += counts[1];
    s->culled_shadowed += counts[2];
    s->culled_depth += counts[3];
    s->tested += counts[4];
    s->blocked += counts[5];
    s->tiles += counts[6];
}

/* begin with the vertex projection left to the jobs, in ranges of vertices: on the
 * calling thread a large scene's projection would hold every other thread up. */
static om_status izb_pass_begin(void *state, const om_view *v, uint32_t *items, om_diag *d)
{
    (void)d;
    *items = begin_view((izb_state *)state, v);
    return OM_OK;
}

static void izb_pass_setup(const void *state, uint32_t first, uint32_t end)
{
    om__lspace_project(&((const izb_state *)state)->z.ls, first, end);
}

/* The slots to make the grid with, this frame (NULL at its end or with fewer than two). */
static void izb_pass_lend(void *state, const om__lend *l)
{
    if (state) ((izb_state *)state)->lend = l && l->slots > 1 ? l : NULL;
}

const om__pass om__pass_izb = {izb_pass_scratch, izb_pass_plan, izb_pass_job, izb_pass_merge,
                               izb_pass_begin, izb_pass_setup, izb_pass_lend};

static om_status izb_resolve(void *state, om_strip *st, om_diag *d)
{
    (void)d;
    om__izb_resolve(&((izb_state *)state)->z, st);
    return OM_OK;
}

static void izb_stats(const void *state, om_method_stats *out)
{
    const izb_state *m = (const izb_state *)state;
    const om__izb *z = &m->z;
    memset(out, 0, sizeof *out);
    out->bytes_used = fixed_bytes(z->scene, m->height, z->ls.verts != NULL) + pool_bytes_of(z->cap, z->leaf) +
                      (z->grid ? grid_bytes(z->scene) : 0);
    static const char *const names[] = {"bsp nodes", "nodes visited", "nodes culled (shadowed)",
                                        "nodes culled (depth)", "samples tested", "tiles",
                                        "pool samples"};
    uint32_t v[7] = {z->st.nodes, z->st.visited, z->st.culled_shadowed, z->st.culled_depth,
                     z->st.tested, z->st.tiles, z->cap};
    for (int i = 0; i < 7; i++) {
        out->counters[i] = v[i];
        out->counter_names[i] = names[i];
    }
    out->ncounters = 7;
}

static const om_setting settings[] = {
    OM__SET_IZB_LEAF(om__izb_cfg, izb_leaf), OM__SET_IZB_POOL(om__izb_cfg, izb_pool),
};

const om_method om__method_izb = {
    "izb", "irregular z-buffer (alias-free shadow maps): exact, BSP over the visible samples",
    OM_METHOD_EXACT, izb_bytes, izb_init, izb_begin, izb_observe, izb_build, izb_resolve,
    izb_stats, NULL, settings, sizeof settings / sizeof settings[0], sizeof(om__izb_cfg),
    NULL, OM__JOBS_ONLY(&om__pass_izb),
};
