/* testing.h — the hooks the project's own tests reach the engine through, and no
 * host: nothing here is part of the API. */
#ifndef OM_TESTING_H
#define OM_TESTING_H

#include "ombra.h"

/* Fault injection: carve number n of arena a (counted as a->carves counts them, from
 * om_arena_init: 1 the first) fails as if the arena were full; 0 turns it off. The
 * failure paths of every carve can then be walked one by one. */
static inline void om__test_fail_carve(om_arena *a, uint32_t n)
{
    a->private_ = n;
}

#endif
