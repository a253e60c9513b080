/* ref_light.h — the reference's BVH bounded on the light's grid every frame (the one-
 * pass mode, which has the frame's vertex projection). A sample's shadow segment ends
 * at the light (or runs along a directional light's axis), so on the light's image it
 * is a single grid point: a triangle can block the sample only when the grid box of its
 * projected vertices holds that point and one of those vertices is nearer the light
 * (the grid-box test: a blocker covers the point, and its depth there lies between
 * its vertices' and is nearer than the sample's, occlude.h). Every triangle gets that box and nearest depth, and every node
 * the union of its triangles', so the walks skip exactly the triangles and subtrees
 * that would fail the test: the same triangles block, found with 2-D integer compares
 * instead of 3-D slab tests along a segment.
 *
 * Packets: samples near each other on the screen are near each other on the light's
 * grid too. One walk per packet, with the packet's grid rectangle and farthest depth,
 * lists the leaves any of its samples can need; each sample then tests only those. */
#ifndef OM_REF_LIGHT_H
#define OM_REF_LIGHT_H

#include "../common/occlude.h"
#include "bvh.h"

/* A grid box and nearest depth; a triangle with a vertex that needs clipping has an
 * unbounded one, and so does every node above it. */
typedef struct om__lbox {
    int32_t lox, loy, hix, hiy;
    double zmin;
} om__lbox;

/* Per frame: a box per node (with the node's first and count, so that a walk reads one
 * array) and a box per entry of the BVH's triangle list. */
typedef struct om__lnode {
    om__lbox box;
    uint32_t first, count;   /* as the BVH node's: count 0 is inner */
} om__lnode;

/* The fit in parts (om__lbvh_plan), fixed once the BVH is built: subtrees of about
 * equal size, each fitted whole by one job (its nodes are `node` and [lo, hi): the
 * build appends a node's descendants after its children, all before it returns to the
 * rest of the tree), and the nodes above them (`top`, parents before children), fitted
 * after them on the calling thread. Every node is fitted from its children by the same
 * code whoever fits it, so the boxes are the same bits for any number of jobs. A
 * part's triangles are [tlo, thi) of the BVH's list (its leaves' ranges). */
#define OM__LBVH_PARTS 64
#define OM__LBVH_NONE UINT32_MAX   /* a part of objects' regions: no node of its own */
typedef struct om__lbvh_part { uint32_t node, lo, hi, tlo, thi; } om__lbvh_part;

typedef struct om__lbvh {
    om__lnode *nodes;
    om__lbox *tris;          /* parallel to the BVH's tris */
    om__lbvh_part *parts;    /* OM__LBVH_PARTS of them */
    uint32_t *top;           /* as many */
    uint32_t nparts, ntop;
    uint32_t top_first, top_end;   /* two levels: the top's nodes, fitted before `top` */
} om__lbvh;

/* Bytes for a BVH over s with leaves of `leaf`; the arrays from the arena. */
size_t om__lbvh_bytes(const om_scene *s, uint32_t leaf);
om_status om__lbvh_init(om__lbvh *lb, om_arena *a, const om_scene *s, uint32_t leaf,
                        om_diag *d);
/* The parts of the fit for b (once, after b is built: a rebuild of objects keeps
 * their regions and the top level's place). A two-level b's objects are parts of
 * their own, by runs of objects (its nobjects). */
void om__lbvh_plan(om__lbvh *lb, const om__bvh *b, uint32_t nobjects);
/* Bounds every triangle and node of b for this frame from ls's projected vertices (ls
 * must have them, begun for the frame): every part (om__lbvh_fit_part, k in [0,
 * nparts), in any order or at once), then the top (om__lbvh_fit_top). */
void om__lbvh_fit(om__lbvh *lb, const om__bvh *b, const om__lspace *ls);
void om__lbvh_fit_part(om__lbvh *lb, const om__bvh *b, const om__lspace *ls, uint32_t k);
void om__lbvh_fit_top(om__lbvh *lb, const om__bvh *b, const om__lspace *ls);

/* A packet's grid rectangle and farthest depth. */
typedef struct om__lrect { int64_t lox, loy, hix, hiy; double zmax; } om__lrect;

/* The nodes of in[0..n) that meet q (box and depth), opened into those of their
 * children that meet q while the list stays within cap; into out, returns how many.
 * *open is set when the cap left inner nodes in the list. A list for a packet is
 * narrowed again for each part of it. */
uint32_t om__lbvh_narrow(const om__lbvh *lb, const uint32_t *in, uint32_t n, const om__lrect *q,
                         uint32_t *out, uint32_t cap, bool *open);
/* Calls visit for every triangle under the listed nodes whose box holds p and has a
 * vertex nearer than p (a list from om__lbvh_narrow for a rectangle that holds p, or
 * the root alone); stops when visit returns true. */
void om__lbvh_walk_list(const om__lbvh *lb, const om__bvh *b, const uint32_t *list, uint32_t n,
                        const om__lpoint *p, om__bvh_visit visit, void *user);

/* The middle mode (the vertex projection without the memory of the boxes above):
 * every node of b gets this frame's grid box (om__bvh_gbox) in place of its 3-D one,
 * and the walk takes the nodes whose box holds p and is nearer somewhere, calling
 * visit for every triangle of their leaves that passes the grid-box test; stops when
 * visit returns true. The same triangles pass as the one-pass walk's, with no bytes
 * beyond the BVH's own. */
void om__bvh_fit_grid(om__bvh *b, const om__lspace *ls);
void om__bvh_walk_grid(const om__bvh *b, const om__lspace *ls, const om__lpoint *p, uint32_t z,
                       om__bvh_visit visit, void *user);

#endif
