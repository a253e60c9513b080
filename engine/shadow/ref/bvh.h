/* bvh.h — a bounding volume hierarchy over a scene's triangles, built once in an arena
 * (binned surface-area heuristic; a node splits while it holds more than `leaf`
 * triangles, and never into a child of fewer than half that, so the node count is
 * bounded by the leaf size) and walked along shadow segments (or, re-bounded on the
 * light's grid each frame, by ref_light.h). Nodes are 32 bytes; a node with count 0 is
 * inner and its children sit at `first` and `first + 1`. */
#ifndef OM_BVH_H
#define OM_BVH_H

#include "../../core/core.h"


/* A box on the light's grid (ref_light.h): the grid bounds and nearest light depth
 * (rounded down; UINT32_MAX: none) of the triangles under a node. */
typedef struct om__bvh_gbox {
    int32_t lox, loy, hix, hiy;
    uint32_t zmin, unused;
} om__bvh_gbox;

/* The build's 3-D box (w), which the walk along a segment reads; a walk on the light's
 * grid re-bounds the nodes every frame in the same bytes (g), in place of it. */
typedef struct om__bvh_node {
    union {
        struct { float lo[3], hi[3]; } w;
        om__bvh_gbox g;
    } box;
    uint32_t first, count;
} om__bvh_node;

/* A scene with objects gets two levels: the root's children are the static triangles'
 * subtree (node 1, built once) and the objects' (node 2, its nodes from obj_nodes on,
 * over tris[obj_first, obj_first + obj_count)), which om__bvh_rebuild_objects builds
 * again after moves, for a cost that grows with the objects' triangles only. */
typedef struct om__bvh {
    om__bvh_node *nodes;
    uint32_t *tris;        /* triangle indices, leaves refer to ranges of it */
    uint32_t nnodes, depth;
    uint32_t obj_first, obj_count, obj_nodes;   /* two levels (obj_nodes 0: one) */
    uint32_t obj_leaf, obj_cap;
} om__bvh;

/* The most nodes a BVH over s with leaves of `leaf` can have. */
size_t om__bvh_nodes_max(const om_scene *s, uint32_t leaf);
/* Bytes the BVH keeps, and the scratch its build needs on top (released after). */
size_t om__bvh_bytes(const om_scene *s, uint32_t leaf);
size_t om__bvh_scratch_bytes(const om_scene *s);
om_status om__bvh_build(om__bvh *b, om_arena *a, const om_scene *s, uint32_t leaf, om_diag *d);

/* Builds the objects' subtree again where they are now: the BVH om__bvh_build would
 * build for s posed so (nothing where s has no objects). */
void om__bvh_rebuild_objects(om__bvh *b, const om_scene *s);

/* A segment o + t * dir, t in [0, tmax], with boxes grown by `margin` on every side.
 * `visit` is called for every triangle in a leaf whose box the segment meets; it
 * returns true to stop the walk. */
typedef bool (*om__bvh_visit)(void *user, uint32_t tri);
void om__bvh_walk(const om__bvh *b, om_vec3 o, om_vec3 dir, float tmax, float margin,
                  om__bvh_visit visit, void *user);

#endif
