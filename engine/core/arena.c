/* arena.c — the only memory the engine has: bump arenas over host buffers, and
 * fixed-capacity pools carved from them. A failed carve changes nothing and reports
 * bytes asked and left; nothing is ever written outside the host's buffer. */
#include "core.h"

#include <string.h>

void om_arena_init(om_arena *a, void *buf, size_t size, const char *name)
{
    if (!a) return;
    memset(a, 0, sizeof *a);
    a->base = (unsigned char *)buf;
    a->cap = buf ? size : 0;
    a->name = name ? name : "arena";
}

size_t om_arena_need(size_t size, size_t align)
{
    return om__size_add(size, align > 1 ? align - 1 : 0);
}

static om_status budget_fail(om_arena *a, size_t asked, om_diag *d)
{
    size_t left = a->cap - a->used;
    a->fail_asked = asked;
    a->fail_left = left;
    if (d) {
        char tmp[8];
        om__str s = om__diag_begin(d, OM_E_BUDGET, tmp, sizeof tmp);
        d->asked = asked;
        d->left = left;
        om__str_s(&s, a->name);
        om__str_s(&s, " arena: asked for ");
        om__str_u(&s, asked);
        om__str_s(&s, " bytes, ");
        om__str_u(&s, left);
        om__str_s(&s, " left of ");
        om__str_u(&s, a->cap);
    }
    return OM_E_BUDGET;
}

/* Carves size bytes; zeroes them when `zero`. */
static om_status carve(om_arena *a, size_t size, size_t align, void **out, om_diag *d, bool zero)
{
    if (!out) return om__fail(d, OM_E_INVALID, "an arena carve needs somewhere to put its pointer");
    *out = NULL;
    if (!a) return om__fail(d, OM_E_INVALID, "an arena carve needs an arena");
    if (align == 0 || (align & (align - 1)) != 0 || align > 64)
        return om__fail(d, OM_E_INVALID, "arena alignment must be a power of two up to 64");
    /* Align the address, not the offset: the host's buffer may start anywhere. */
    uintptr_t at = (uintptr_t)a->base + a->used;
    size_t pad = (size_t)((align - (at & (align - 1))) & (align - 1));
    size_t left = a->cap - a->used;
    if (a->private_ != 0 && a->carves + 1 == a->private_) {
        a->carves++;   /* count the injected failure so the next carve succeeds */
        return budget_fail(a, size, d);
    }
    if (pad > left || size > left - pad) return budget_fail(a, size, d);
    unsigned char *p = a->base ? a->base + a->used + pad : NULL;   /* NULL: cap is 0 */
    a->used += pad + size;
    if (a->used > a->peak) a->peak = a->used;
    a->carves++;
    if (zero && size) memset(p, 0, size);
    *out = p;
    return OM_OK;
}

om_status om_arena_alloc(om_arena *a, size_t size, size_t align, void **out, om_diag *d)
{
    return carve(a, size, align, out, d, true);
}

om_status om__arena_alloc_raw(om_arena *a, size_t size, size_t align, void **out, om_diag *d)
{
    return carve(a, size, align, out, d, false);
}

om_status om_arena_sub(om_arena *a, size_t size, const char *name, om_arena *child,
                       om_diag *d)
{
    void *p;
    if (!child) return om__fail(d, OM_E_INVALID, "om_arena_sub needs a child arena to fill");
    om_status st = om_arena_alloc(a, size, 16, &p, d);
    om_arena_init(child, st == OM_OK ? p : NULL, st == OM_OK ? size : 0, name);
    return st;
}

size_t om_arena_mark(const om_arena *a) { return a ? a->used : 0; }

void om_arena_rewind(om_arena *a, size_t mark)
{
    if (a && mark <= a->used) a->used = mark;
}

size_t om_arena_left(const om_arena *a) { return a ? a->cap - a->used : 0; }

/* ---- pools */

static size_t pool_item(size_t item_size) { return om__size_add(item_size, 7u) & ~(size_t)7u; }

size_t om_pool_bytes(size_t item_size, uint32_t count)
{
    return om__size_add(om_arena_need(om__size_mul(pool_item(item_size), count), 8),
                        om_arena_need(om__size_mul(sizeof(uint32_t), count), 4));
}

om_status om_pool_init(om_pool *p, om_arena *a, size_t item_size, uint32_t count,
                       om_diag *d)
{
    void *items, *next;
    om_status st;
    if (!p || !a) return om__fail(d, OM_E_INVALID, "om_pool_init needs a pool and an arena");
    memset(p, 0, sizeof *p);
    if (item_size == 0 || count == 0)
        return om__fail(d, OM_E_INVALID, "pool needs a non-zero item size and count");
    if ((st = om_arena_alloc(a, om__size_mul(pool_item(item_size), count), 8, &items, d)) != OM_OK) return st;
    if ((st = om_arena_alloc(a, om__size_mul(sizeof(uint32_t), count), 4, &next, d)) != OM_OK) return st;
    p->items = (unsigned char *)items;
    p->item_size = pool_item(item_size);
    p->count = count;
    p->next = (uint32_t *)next;
    for (uint32_t i = 0; i < count; i++) p->next[i] = i + 1;
    p->free_head = 0;
    return OM_OK;
}

void *om_pool_get(om_pool *p)
{
    if (!p || p->free_head >= p->count) return NULL;
    uint32_t i = p->free_head;
    p->free_head = p->next[i];
    p->next[i] = p->count;
    p->in_use++;
    if (p->in_use > p->peak) p->peak = p->in_use;
    void *item = p->items + (size_t)i * p->item_size;
    memset(item, 0, p->item_size);
    return item;
}

uint32_t om_pool_index(const om_pool *p, const void *item)
{
    return (uint32_t)(((const unsigned char *)item - p->items) / p->item_size);
}

void *om_pool_item(const om_pool *p, uint32_t index)
{
    return p && index < p->count ? p->items + (size_t)index * p->item_size : NULL;
}

void om_pool_put(om_pool *p, void *item)
{
    if (!p || !item || !p->count) return;
    uint32_t i = om_pool_index(p, item);
    if (i >= p->count) return;
    p->next[i] = p->free_head;
    p->free_head = i;
    p->in_use--;
}
