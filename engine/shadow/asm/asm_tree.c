/* asm_tree.c — the Adaptive Shadow Map's tree (see asm.h): layout and memory under the
 * user's cap, the node pool, finding the deepest node over a point, the candidates of
 * section 3.1 ordered by benefit / cost, and node removal as section 3.2 describes it. */
#include "asm.h"

#include <string.h>
#include <math.h>

static size_t up8(size_t n) { return (n + 7u) & ~(size_t)7u; }

om_status om__asm_layout_of(om__asm_layout *l, const om__asm_cfg *c, uint32_t ntris,
                            om_diag *d)
{
    memset(l, 0, sizeof *l);
    if (c->asm_tile < 4 || c->asm_tile > 1024 || c->asm_cells < 1 || c->asm_cells > 64 ||
        c->asm_tile % c->asm_cells != 0)
        return om__fail(d, OM_E_INVALID, "asm: asm.tile must be 4..1024 and a multiple of asm.cells (1..64)");
    l->tile = c->asm_tile;
    l->cells = c->asm_cells;
    l->cp = c->asm_tile / c->asm_cells;
    if (c->asm_root < l->tile || c->asm_root > OM_MAX_DIM || c->asm_root % l->tile != 0 ||
        l->tile % (c->asm_root / l->tile) != 0)
        return om__fail(d, OM_E_INVALID, "asm: asm.root must be asm.tile times a divisor of asm.tile, up to 8192");
    if (!(c->asm_cost_a >= 0.0f && c->asm_cost_b >= 0.0f && c->asm_cost_a <= 1e6f && c->asm_cost_b <= 1e6f))
        return om__fail(d, OM_E_INVALID, "asm: asm.a and asm.b must be 0..1e6");
    l->root = c->asm_root;
    l->base_cells = c->asm_root / l->tile;
    l->base_cp = l->tile / l->base_cells;
    /* Deepest level: the effective resolution stays within the reference's own light
     * grid (2^21 snapped steps across the frustum); finer is below what "correct" means
     * and would strain float clip coordinates. asm.cells = 1 stops at the root tiles. */
    l->mul[0] = l->base_cells;
    for (uint32_t i = 1; i <= OM__ASM_MAX_LEVEL; i++) l->mul[i] = l->cells;
    l->scale[0] = 1.0;
    for (uint32_t i = 1; i <= OM__ASM_MAX_LEVEL; i++) l->scale[i] = l->scale[i - 1] * l->mul[i - 1];
    l->max_level = 1;
    if (l->cells > 1) {
        uint64_t r = l->root;
        while (l->max_level < OM__ASM_MAX_LEVEL && r * l->cells <= ((uint64_t)1 << 21)) {
            r *= l->cells;
            l->max_level++;
        }
    }
    l->id16 = ntris < 0xFFFFu;
    const size_t idb = l->id16 ? 2 : 4;
    const size_t rc2 = (size_t)l->base_cells * l->base_cells, r2 = (size_t)l->tile * l->tile;
    const size_t c2 = (size_t)l->cells * l->cells, t2 = (size_t)l->tile * l->tile;
    l->root_bytes = 3 * om_arena_need(rc2 * 4, 8) + om_arena_need(r2 * 4, 8) + om_arena_need(r2 * idb, 8);
    l->item_bytes = up8(sizeof(om__asm_node)) + 3 * up8(c2 * 4) + up8(t2 * 4) + up8(t2 * idb);
    l->node_bytes = l->item_bytes + sizeof(uint32_t);   /* + its free-list link */
    l->min_cap = (uint64_t)l->root_bytes + l->node_bytes;
    uint64_t cap = c->asm_cap;
    if (cap >= l->min_cap) {
        uint64_t n = (cap - l->root_bytes) / l->node_bytes;
        /* what a size_t can carve (32-bit hosts), and never more than 2^24 nodes */
        uint64_t most = ((uint64_t)(SIZE_MAX / 2) - l->root_bytes) / l->node_bytes;
        if (n > most) n = most;
        if (n > (1u << 24)) n = 1u << 24;
        l->count = (uint32_t)n;
        l->arena_bytes = l->root_bytes + om_pool_bytes(l->item_bytes, l->count);
    }
    return OM_OK;
}

om_status om__asm_tree_init(om__asm_tree *t, om_arena *a, const om__asm_layout *l, om_diag *d)
{
    om_status st;
    void *p[5];
    memset(t, 0, sizeof *t);
    t->lay = *l;
    const size_t rc2 = (size_t)l->base_cells * l->base_cells, r2 = (size_t)l->tile * l->tile;
    if ((st = om_arena_alloc(a, rc2 * 4, 8, &p[0], d)) || (st = om_arena_alloc(a, rc2 * 4, 8, &p[1], d)) ||
        (st = om_arena_alloc(a, rc2 * 4, 8, &p[2], d)) || (st = om_arena_alloc(a, r2 * 4, 8, &p[3], d)) ||
        (st = om_arena_alloc(a, r2 * (l->id16 ? 2 : 4), 8, &p[4], d)))
        return st;
    t->root_child = (uint32_t *)p[0];
    t->root_ben = (uint32_t *)p[1];
    t->root_need = (float *)p[2];
    t->root_depth = (uint32_t *)p[3];
    if (l->id16) t->root_id16 = (uint16_t *)p[4];
    else t->root_id32 = (uint32_t *)p[4];
    if ((st = om_pool_init(&t->pool, a, l->item_bytes, l->count, d))) return st;
    const size_t c2 = (size_t)l->cells * l->cells, t2 = (size_t)l->tile * l->tile;
    t->off_child = up8(sizeof(om__asm_node));
    t->off_ben = t->off_child + up8(c2 * 4);
    t->off_need = t->off_ben + up8(c2 * 4);
    t->off_depth = t->off_need + up8(c2 * 4);
    t->off_id = t->off_depth + up8(t2 * 4);
    t->root.parent = OM__ASM_NONE;
    t->root.pcell = OM__ASM_NONE;
    t->root.alive = 1;
    t->frame = 2;
    om__asm_tree_clear(t);
    return OM_OK;
}

om__asm_node *om__asm_node_at(om__asm_tree *t, uint32_t index)
{
    if (index == OM__ASM_ROOT) return &t->root;
    return (om__asm_node *)om_pool_item(&t->pool, index);
}

void om__asm_tile_of(om__asm_tree *t, uint32_t index, om__asm_tile *o)
{
    if (index == OM__ASM_ROOT) {
        o->node = &t->root;
        o->size = t->lay.tile;
        o->cells = t->lay.base_cells;
        o->cp = t->lay.base_cp;
        o->child = t->root_child;
        o->ben = t->root_ben;
        o->need = t->root_need;
        o->depth = t->root_depth;
        o->id16 = t->root_id16;
        o->id32 = t->root_id32;
        return;
    }
    unsigned char *b = (unsigned char *)om_pool_item(&t->pool, index);
    o->node = (om__asm_node *)b;
    o->size = t->lay.tile;
    o->cells = t->lay.cells;
    o->cp = t->lay.cp;
    o->child = (uint32_t *)(b + t->off_child);
    o->ben = (uint32_t *)(b + t->off_ben);
    o->need = (float *)(b + t->off_need);
    o->depth = (uint32_t *)(b + t->off_depth);
    o->id16 = t->lay.id16 ? (uint16_t *)(b + t->off_id) : NULL;
    o->id32 = t->lay.id16 ? NULL : (uint32_t *)(b + t->off_id);
}

double om__asm_grid(const om__asm_layout *l, uint32_t level)
{
    double r = l->tile;
    for (uint32_t i = 0; i < level; i++) r *= l->mul[i];
    return r;
}

uint64_t om__asm_bytes_in_use(const om__asm_tree *t)
{
    return (uint64_t)t->lay.root_bytes + (uint64_t)t->pool.in_use * t->lay.node_bytes;
}

uint32_t om__asm_depth(const om__asm_tree *t)
{
    uint32_t deepest = 0;
    for (uint32_t i = 0; i < t->lay.count; i++) {
        const om__asm_node *n = (const om__asm_node *)om_pool_item(&t->pool, i);
        if (n->alive && n->level > deepest) deepest = n->level;
    }
    return deepest;
}

void om__asm_tree_clear(om__asm_tree *t)
{
    for (uint32_t i = 0; i < t->lay.count; i++) {
        om__asm_node *n = (om__asm_node *)om_pool_item(&t->pool, i);
        if (n->alive) {
            n->alive = 0;
            om_pool_put(&t->pool, n);
            t->evicted++;
            t->total_evicted++;
        }
    }
    const size_t rc2 = (size_t)t->lay.base_cells * t->lay.base_cells;
    for (size_t i = 0; i < rc2; i++) t->root_child[i] = OM__ASM_NONE;
    t->root.nchild = 0;
}

void om__asm_frame(om__asm_tree *t)
{
    t->frame++;
    t->created = t->evicted = t->replaced = 0;
    const size_t rc2 = (size_t)t->lay.base_cells * t->lay.base_cells;
    memset(t->root_ben, 0, rc2 * sizeof *t->root_ben);
    memset(t->root_need, 0, rc2 * sizeof *t->root_need);
    const size_t c2 = (size_t)t->lay.cells * t->lay.cells;
    for (uint32_t i = 0; i < t->lay.count; i++) {
        om__asm_tile tl;
        om__asm_tile_of(t, i, &tl);
        if (!tl.node->alive) continue;
        tl.node->benefit = 0;
        memset(tl.ben, 0, c2 * sizeof *tl.ben);
        memset(tl.need, 0, c2 * sizeof *tl.need);
    }
}

/* Frees a subtree, children first. Depth is at most max_level, so recursion is bounded. */
static void free_subtree(om__asm_tree *t, uint32_t index)
{
    om__asm_tile tl;
    om__asm_tile_of(t, index, &tl);
    const uint32_t c2 = tl.cells * tl.cells;
    for (uint32_t c = 0; c < c2 && tl.node->nchild; c++)
        if (tl.child[c] != OM__ASM_NONE) {
            free_subtree(t, tl.child[c]);
            tl.child[c] = OM__ASM_NONE;
            tl.node->nchild--;
        }
    tl.node->alive = 0;
    om_pool_put(&t->pool, tl.node);
    t->evicted++;
    t->total_evicted++;
}

void om__asm_evict(om__asm_tree *t, uint32_t index)
{
    if (index == OM__ASM_ROOT || index >= t->lay.count) return;
    om__asm_node *n = om__asm_node_at(t, index);
    if (!n->alive) return;
    om__asm_tile pt;
    om__asm_tile_of(t, n->parent, &pt);
    pt.child[n->pcell] = OM__ASM_NONE;
    pt.node->nchild--;
    free_subtree(t, index);
}

/* Is `index` the node `from` or one of its ancestors? */
static bool on_path(om__asm_tree *t, uint32_t index, uint32_t from)
{
    while (from != OM__ASM_ROOT) {
        if (from == index) return true;
        from = om__asm_node_at(t, from)->parent;
    }
    return false;
}

/* Section 3.2, first rule: least recently used among nodes not used in the last frame
 * (this frame's analysis counts as use). Ties: the deeper, then the lower index. */
static uint32_t lru_victim(om__asm_tree *t, uint32_t parent)
{
    uint32_t best = OM__ASM_NONE;
    const om__asm_node *b = NULL;
    for (uint32_t i = 0; i < t->lay.count; i++) {
        const om__asm_node *n = (const om__asm_node *)om_pool_item(&t->pool, i);
        if (!n->alive || n->stamp + 1 >= t->frame) continue;
        if (b && (n->stamp > b->stamp || (n->stamp == b->stamp && n->level <= b->level))) continue;
        if (on_path(t, i, parent)) continue;
        best = i;
        b = n;
    }
    return best;
}

/* Second rule: every node is in use; the leaf whose benefit is least (ties: older,
 * deeper, lower index) is replaced only by a node of greater benefit. Leaves only:
 * a node with children serves them too. */
static uint32_t benefit_victim(om__asm_tree *t, uint32_t parent)
{
    uint32_t best = OM__ASM_NONE;
    const om__asm_node *b = NULL;
    for (uint32_t i = 0; i < t->lay.count; i++) {
        const om__asm_node *n = (const om__asm_node *)om_pool_item(&t->pool, i);
        if (!n->alive || n->nchild) continue;
        if (b && (n->benefit > b->benefit ||
                  (n->benefit == b->benefit &&
                   (n->stamp > b->stamp || (n->stamp == b->stamp && n->level <= b->level)))))
            continue;
        if (on_path(t, i, parent)) continue;
        best = i;
        b = n;
    }
    return best;
}

bool om__asm_lru_spare(om__asm_tree *t) { return lru_victim(t, OM__ASM_ROOT) != OM__ASM_NONE; }

uint32_t om__asm_make(om__asm_tree *t, uint32_t parent, uint32_t cell, uint32_t benefit)
{
    om__asm_tile pt;
    if (parent != OM__ASM_ROOT && (parent >= t->lay.count || !om__asm_node_at(t, parent)->alive))
        return OM__ASM_NONE;
    om__asm_tile_of(t, parent, &pt);
    if (cell >= pt.cells * pt.cells || pt.child[cell] != OM__ASM_NONE ||
        pt.node->level + 1 > t->lay.max_level)
        return OM__ASM_NONE;
    void *item = om_pool_get(&t->pool);
    if (!item) {
        uint32_t v = lru_victim(t, parent);
        if (v != OM__ASM_NONE) {
            om__asm_evict(t, v);
            item = om_pool_get(&t->pool);
        }
    }
    if (!item) {
        uint32_t v = benefit_victim(t, parent);
        if (v != OM__ASM_NONE && om__asm_node_at(t, v)->benefit < benefit) {
            om__asm_evict(t, v);
            t->replaced++;
            item = om_pool_get(&t->pool);
        }
    }
    if (!item) return OM__ASM_NONE;
    uint32_t index = om_pool_index(&t->pool, item);
    om__asm_tile nt;
    om__asm_tile_of(t, index, &nt);
    om__asm_node *n = nt.node;
    n->parent = parent;
    n->pcell = cell;
    n->level = pt.node->level + 1;
    /* The cell's texels [cx * cp, cx * cp + cp) of the parent, on a grid `cells` times
     * finer: cp * cells = tile, so the child's origin is parent origin * cells + cx * tile. */
    n->ox = pt.node->ox * pt.cells + (cell % pt.cells) * t->lay.tile;
    n->oy = pt.node->oy * pt.cells + (cell / pt.cells) * t->lay.tile;
    n->stamp = t->frame;
    n->benefit = benefit;
    n->alive = 1;
    n->gen = ++t->serial;   /* unique while 2^32 nodes are not made: candidates check it */
    const uint32_t c2 = t->lay.cells * t->lay.cells;
    for (uint32_t c = 0; c < c2; c++) nt.child[c] = OM__ASM_NONE;
    pt.child[cell] = index;
    pt.node->nchild++;
    t->created++;
    t->total_created++;
    return index;
}

uint32_t om__asm_find(om__asm_tree *t, double u, double v, bool stamp, uint32_t *tx, uint32_t *ty)
{
    uint32_t index = OM__ASM_ROOT;
    for (;;) {
        om__asm_tile tl;
        om__asm_tile_of(t, index, &tl);
        const double s = t->lay.scale[tl.node->level];   /* the same product on every path */
        double lx = floor(u * s - (double)tl.node->ox), ly = floor(v * s - (double)tl.node->oy);
        uint32_t x = !(lx > 0.0) ? 0u : lx >= (double)tl.size ? tl.size - 1 : (uint32_t)lx;
        uint32_t y = !(ly > 0.0) ? 0u : ly >= (double)tl.size ? tl.size - 1 : (uint32_t)ly;
        if (stamp) tl.node->stamp = t->frame;
        uint32_t c = (y / tl.cp) * tl.cells + x / tl.cp;
        if (tl.child[c] == OM__ASM_NONE) {
            *tx = x;
            *ty = y;
            return index;
        }
        index = tl.child[c];
    }
}

/* ---- candidates: a max-heap on priority */

static bool better(const om__asm_cand *x, const om__asm_cand *y)
{
    if (x->prio != y->prio) return x->prio > y->prio;
    if (x->node != y->node) return x->node < y->node;
    return x->cell < y->cell;
}

static void sift_down(om__asm_cand *h, uint32_t n, uint32_t i)
{
    for (;;) {
        uint32_t l = 2 * i + 1, r = l + 1, m = i;
        if (l < n && better(&h[l], &h[m])) m = l;
        if (r < n && better(&h[r], &h[m])) m = r;
        if (m == i) return;
        om__asm_cand tmp = h[i];
        h[i] = h[m];
        h[m] = tmp;
        i = m;
    }
}

uint64_t om__asm_cand_max(const om__asm_layout *l)
{
    return (uint64_t)l->base_cells * l->base_cells + (uint64_t)l->count * l->cells * l->cells;
}

static uint32_t gather(om__asm_tree *t, uint32_t index, float a, float b, om__asm_cand *out,
                       uint32_t n, uint32_t max)
{
    om__asm_tile tl;
    om__asm_tile_of(t, index, &tl);
    const uint32_t c2 = tl.cells * tl.cells;
    const float full = (float)t->lay.tile * (float)t->lay.tile;
    if (tl.node->level + 1 > t->lay.max_level) return n;
    for (uint32_t c = 0; c < c2 && n < max; c++) {
        if (!tl.ben[c] || tl.child[c] != OM__ASM_NONE) continue;
        om__asm_cand *k = &out[n++];
        k->node = index;
        k->cell = c;
        k->gen = tl.node->gen;
        k->benefit = tl.ben[c];
        if (index == OM__ASM_ROOT) {   /* a root tile: made for coverage, by sample count */
            k->cost = 0.0f;
            k->prio = (float)tl.ben[c];
            continue;
        }
        /* Section 3.1: cost = a * N_required + b. A node never renders more than its
         * tile, so N_required is capped there. */
        float need = tl.need[c] < full ? tl.need[c] : full;
        k->cost = a * need + b;
        k->prio = (float)tl.ben[c] / (k->cost > 1e-20f ? k->cost : 1e-20f);
    }
    return n;
}

uint32_t om__asm_candidates(om__asm_tree *t, bool base, float a, float b, om__asm_cand *out,
                            uint32_t max)
{
    uint32_t n = 0;
    if (base) n = gather(t, OM__ASM_ROOT, a, b, out, 0, max);
    else
        for (uint32_t i = 0; i < t->lay.count; i++)
            if (((const om__asm_node *)om_pool_item(&t->pool, i))->alive) n = gather(t, i, a, b, out, n, max);
    for (uint32_t i = n / 2; i-- > 0;) sift_down(out, n, i);
    return n;
}

uint32_t om__asm_cand_pop(om__asm_cand *h, uint32_t n, om__asm_cand *best)
{
    *best = h[0];
    h[0] = h[n - 1];
    sift_down(h, n - 1, 0);
    return n - 1;
}
