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
 * subtree (node 1, built once) and the objects' top level (node 2). Every object with
 * triangles has a subtree of its own in a fixed region of the nodes (obj_node[i] to
 * obj_node[i + 1]: its root at the region's start, its nodes after it, the rest of the
 * region spare leaves that nothing refers to) over its fixed range of the triangle list
 * (the objects' triangles in their order from obj_first on), built again only when it
 * moved; the top level (node 2 and the nodes from top_first to top_end, a median split
 * over the objects' boxes, each leaf a copy of an object's root) is built again after
 * any move. So a frame after moves builds what moved, plus a node or two per object,
 * and the BVH is the one a new state would build on the scene posed there. */
typedef struct om__bvh {
    om__bvh_node *nodes;
    uint32_t *tris;        /* triangle indices, leaves refer to ranges of it */
    uint32_t nnodes, depth;
    uint32_t obj_first, obj_count;   /* two levels (obj_node NULL: one) */
    uint32_t top_first, top_end;
    uint32_t *obj_node;    /* nobjects + 1 region starts */
    uint32_t *obj_tri;     /* nobjects + 1: each object's range in tris */
    uint32_t *perm;        /* nobjects: the top level's build order */
    float *obj_box;        /* nobjects x (lo, hi): each object's box at its build (the
                              middle mode writes grid boxes into the nodes) */
    uint32_t obj_leaf, rebuilt;   /* rebuilt: object subtrees built by the last call */
    uint32_t seen;         /* the scene's change count the objects were built at */
} om__bvh;
/* The most nodes a BVH over s with leaves of `leaf` can have. */
size_t om__bvh_nodes_max(const om_scene *s, uint32_t leaf);
/* Bytes the BVH keeps, and the scratch its build needs on top (released after). */
size_t om__bvh_bytes(const om_scene *s, uint32_t leaf);
size_t om__bvh_scratch_bytes(const om_scene *s);
om_status om__bvh_build(om__bvh *b, om_arena *a, const om_scene *s, uint32_t leaf, om_diag *d);

/* Builds again the subtrees of the objects that moved since the BVH last saw the
 * scene (om_object.moved), and the top level over all of them when any did: the BVH
 * om__bvh_build would build for s posed so (nothing where s has no objects). Sets
 * b->rebuilt to how many object subtrees it built. */
void om__bvh_rebuild_objects(om__bvh *b, const om_scene *s);

/* A segment o + t * dir, t in [0, tmax], with boxes grown by `margin` on every side.
 * `visit` is called for every triangle in a leaf whose box the segment meets; it
 * returns true to stop the walk. */
typedef bool (*om__bvh_visit)(void *user, uint32_t tri);
void om__bvh_walk(const om__bvh *b, om_vec3 o, om_vec3 dir, float tmax, float margin,
                  om__bvh_visit visit, void *user);

#endif
