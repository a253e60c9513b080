/* ombra.h — the public API of ombra, a freestanding, allocation-free C99 engine
 * for hard shadows.
 *
 * Usage: the host hands in memory as arenas (om_arena_init over its own buffers),
 * parses or builds a scene into one, picks a shadow method by name, asks every piece
 * how many bytes it needs, and renders frames strip by strip into a framebuffer.
 * The engine never allocates, never does I/O and keeps no global state: everything a
 * call needs is in the structs it is given, so two engines can run in one process.
 *
 * Conventions: every fallible function returns an om_status; results go through
 * out-parameters; an optional om_diag* receives the details (bytes asked and left
 * for a budget error, line and column for a parse error) and may be NULL. A NULL
 * where a declaration does not allow one is refused, never followed: a function that
 * returns an om_status returns OM_E_INVALID, and the others do nothing and return 0,
 * NULL, "" or a neutral value (om_metrics_match 1, om_flicker_share 0, om_hash its
 * h). The inline accessors (om_term_lit, om_mask_of) read what they are handed.
 *
 * Measuring (masks, their comparison, flicker, frame hashes) is in ombra_measure.h;
 * the compile-time switches are listed in engine/core/config.h.
 *
 * Coordinates: right-handed world space. Cameras look down -z of their view space.
 * Pixel (x, y) has its centre at (x + 0.5, y + 0.5); row 0 is the top row.
 *
 * Determinism: the same inputs give the same bits on every CPU and compiler when
 * float arithmetic is evaluated in float (FLT_EVAL_METHOD == 0: SSE2, not x87, on
 * i386; -fexcess-precision=fast with s390x gcc) and never contracted into FMA
 * (-ffp-contract=off). The engine does not compile where FLT_EVAL_METHOD != 0 unless
 * OM_ALLOW_EXCESS_PRECISION is defined (README, Determinism).
 */
#ifndef OMBRA_H
#define OMBRA_H

/* The release this header belongs to (`ombra --version` prints the string). */
#define OMBRA_VERSION_MAJOR 0
#define OMBRA_VERSION_MINOR 2
#define OMBRA_VERSION_PATCH 0
#define OMBRA_VERSION_STRING "0.2.0"

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------- status */

typedef enum om_status {
    OM_OK = 0,
    OM_E_BUDGET,      /* an arena is too small: om_diag says bytes asked and left */
    OM_E_INVALID,     /* an argument is out of its documented range */
    OM_E_PARSE,       /* malformed text: om_diag says line, column, what was expected */
    OM_E_RANGE,       /* a value is outside what the engine represents (NaN, 1e30, ...) */
    OM_E_NOTFOUND,    /* a name (method, file) is unknown */
    OM_E_IO,          /* the host could not read or write a file (platform/ only) */
    OM_E_COUNT_
} om_status;

/* A static English name for a status, never NULL. */
const char *om_status_str(om_status s);

/* The release of the library linked in, as OMBRA_VERSION_STRING was when it was
 * built: a host may compare it with the header it was compiled against. */
const char *om_version(void);

/* Details of the last failure. Filled by functions that take one; may be NULL. */
typedef struct om_diag {
    om_status status;
    size_t asked, left;    /* OM_E_BUDGET: bytes asked for, bytes that were left */
    uint32_t line, col;    /* OM_E_PARSE: 1-based position in the text */
    char msg[160];         /* one line, NUL-terminated, no trailing newline */
} om_diag;

/* ---------------------------------------------------------------- memory */

/* An arena is a bump allocator over a buffer the host owns. It never writes outside
 * [base, base + cap). `peak` is the high-water mark of `used`. A failing carve leaves
 * the arena unchanged and records the request in fail_asked / fail_left. */
typedef struct om_arena {
    unsigned char *base;
    size_t cap, used, peak;
    size_t fail_asked, fail_left;
    uint32_t carves;       /* successful carves so far */
    uint32_t private_;     /* the engine's own: hosts leave it as om_arena_init sets it */
    const char *name;      /* subsystem name for messages ("scene", "frame", ...) */
} om_arena;

void om_arena_init(om_arena *a, void *buf, size_t size, const char *name);
/* Carves `size` bytes aligned to `align` (a power of two, at most 64). The memory is
 * zeroed. On OM_E_BUDGET, *out is set to NULL and `d` (if given) gets the numbers. */
om_status om_arena_alloc(om_arena *a, size_t size, size_t align, void **out, om_diag *d);
/* Carves a whole child arena of `size` bytes (aligned to 16) out of `a`. */
om_status om_arena_sub(om_arena *a, size_t size, const char *name, om_arena *child,
                       om_diag *d);
size_t om_arena_mark(const om_arena *a);
void om_arena_rewind(om_arena *a, size_t mark);
size_t om_arena_left(const om_arena *a);
/* Bytes an arena must have to satisfy a carve of `size` at `align` from any state:
 * the size plus the worst-case alignment padding. Bytes-needed queries add these up. */
size_t om_arena_need(size_t size, size_t align);

/* A pool of `count` fixed-size items carved from an arena, recycled through a free
 * list. Items are `item_size` bytes rounded up to 8. */
typedef struct om_pool {
    unsigned char *items;
    size_t item_size;
    uint32_t count, in_use, peak;
    uint32_t free_head;    /* index of first free item, or count if none */
    uint32_t *next;        /* free-list links, one per item */
} om_pool;

size_t om_pool_bytes(size_t item_size, uint32_t count);
om_status om_pool_init(om_pool *p, om_arena *a, size_t item_size, uint32_t count,
                       om_diag *d);
/* Takes a zeroed item; returns NULL when all `count` are in use. */
void *om_pool_get(om_pool *p);
void om_pool_put(om_pool *p, void *item);
uint32_t om_pool_index(const om_pool *p, const void *item);
void *om_pool_item(const om_pool *p, uint32_t index);

/* ---------------------------------------------------------------- math */

typedef struct om_vec3 { float x, y, z; } om_vec3;
typedef struct om_vec4 { float x, y, z, w; } om_vec4;
/* Row-major 4x4: v' = M v with v a column vector; m[r * 4 + c]. */
typedef struct om_mat4 { float m[16]; } om_mat4;

/* ---------------------------------------------------------------- scene */

#define OM_NO_TRI 0xFFFFFFFFu
#define OM_MAX_DIM 8192u           /* largest image or shadow-map side */

typedef struct om_material {
    float r, g, b;         /* albedo, 0..1 */
    float opacity;         /* 1 = opaque; below 1 the caster tints light by its albedo */
} om_material;

typedef struct om_camera {
    om_vec3 eye, target, up;
    float fovy_deg;        /* vertical field of view in degrees, (0, 180) */
    uint32_t width, height;
    float znear, zfar;     /* 0 < znear < zfar */
} om_camera;

typedef enum om_light_kind { OM_LIGHT_SPOT = 0, OM_LIGHT_DIRECTIONAL = 1 } om_light_kind;

typedef struct om_light {
    om_light_kind kind;
    om_vec3 pos, target;   /* spot: position and aim point */
    om_vec3 dir;           /* directional: direction the light travels (from the light) */
    float fov_deg;         /* spot: full angle of its square frustum, (0, 180) */
    float znear, zfar;     /* spot: depth range */
} om_light;

typedef struct om_camera_key { float t; om_vec3 eye, target; } om_camera_key;
typedef struct om_light_key { float t; om_vec3 pos, target, dir; } om_light_key;

/* A closed shape: triangles [first, first + count) form a closed surface wound
 * counter-clockwise seen from outside, inside the box lo..hi. Seen from a point
 * outside it, the nearest surface along any ray faces that point, so a depth map may
 * skip the triangles facing away. */
typedef struct om_solid { uint32_t first, count; om_vec3 lo, hi; } om_solid;

/* Objects: a named shape or mesh line (`name NAME`) or a `copy` of one. Its mesh's
 * vertices and triangles are stored once, in the mesh's own space (after the defining
 * line's scale, rotate and translate), however many objects share it; every object
 * owns a fixed range of the scene's vertices and triangles, which posing rewrites
 * from its mesh: world = pose * base * local, with base the copy line's own transform
 * (identity for the line that made the mesh). What the methods read is always the
 * posed scene, so a scene after any sequence of poses is, bit for bit, the scene
 * parsed with its objects at that pose. */
typedef struct om_mesh {
    uint32_t first_vert, nverts;   /* its local vertices: mesh_verts[first_vert..] */
    uint32_t first_idx, ntris;     /* its triangles: mesh_idx[first_idx..], 3 per triangle,
                                      numbered from 0 within the mesh */
    bool closed;                   /* a box, sphere or cylinder: its objects are solids */
} om_mesh;

typedef struct om_object_key {
    float t;
    float move[3], rot_deg[3], scale;   /* translate, rotate (x, then y, then z), scale */
    uint32_t next;         /* the object's next key (later t), or OM_NO_TRI */
} om_object_key;

typedef struct om_object {
    const char *name;      /* NUL-terminated, in the scene's arena; "" for an unnamed copy */
    uint32_t mesh;         /* its mesh in om_scene.meshes */
    uint32_t first_vert, first_tri;   /* its posed vertices and triangles in verts / idx */
    uint32_t solid;        /* its om_solid, or OM_NO_TRI */
    uint32_t first_key, nkeys;        /* its keys in om_scene.obj_keys, sorted by t */
    double base[12];       /* the copy line's transform (rows of a 3x4), applied first */
    double pose[12];       /* what verts hold now: world = pose * local (base included) */
    om_vec3 lo, hi;        /* bounds of its posed vertices */
    om_vec3 old_lo, old_hi;   /* ... before its last move (lo, hi before any) */
    uint32_t moved;        /* om_scene.change at its last move (0: never moved) */
    uint32_t last_key;     /* the parser's: its latest key so far */
} om_object;

/* A scene: indexed triangles with a material per triangle, one camera, one light and
 * optional keyframed paths. All arrays live in the arena the scene was parsed into. */
typedef struct om_scene {
    uint32_t nverts, ntris, nmats, ncam_keys, nlight_keys;
    om_vec3 *verts;
    uint32_t *idx;         /* 3 * ntris vertex indices */
    uint16_t *tri_mat;     /* ntris material indices */
    om_material *mats;
    om_camera camera;
    om_light light;
    om_camera_key *cam_keys;   /* sorted by t */
    om_light_key *light_keys;  /* sorted by t */
    om_vec3 lo, hi;        /* bounds of all vertices */
    uint32_t nsolids;      /* closed shapes (box, sphere, cylinder), by first triangle; */
    om_solid *solids;      /* 0 and NULL in a hand-made scene: nothing is skipped */
    /* Objects (0 and NULL in a scene without any). */
    uint32_t nobjects, nmeshes, nobj_keys;
    uint32_t nmesh_verts, nmesh_tris;   /* the sizes of mesh_verts and mesh_idx / 3 */
    om_object *objects;
    om_mesh *meshes;
    om_vec3 *mesh_verts;   /* every mesh's local vertices, each mesh once */
    uint32_t *mesh_idx;    /* every mesh's triangles, each mesh once */
    om_object_key *obj_keys;
    char *names;           /* the objects' names, each NUL-terminated */
    uint32_t change;       /* counts moves (om_object_pose): a method that keeps state
                              across frames compares it with the count it last saw, and
                              the objects whose `moved` is later say what moved */
    om_vec3 static_lo, static_hi;   /* bounds of the vertices outside every object; */
    bool has_static;                /* false: there are none */
} om_scene;

/* The host reads files named in a scene (`mesh FILE.obj`); the engine never does.
 * Return OM_OK with the bytes (which must stay valid during the parse), or an error. */
typedef om_status (*om_file_fn)(void *user, const char *name, const char **data,
                                size_t *len);

typedef struct om_loader {
    om_file_fn load;       /* may be NULL: `mesh` lines then fail with OM_E_NOTFOUND */
    void *user;
} om_loader;

/* Bytes the arena needs to hold the scene that `text` describes (a first pass that
 * counts, including the OBJ files it names). */
om_status om_scene_bytes(const char *text, size_t len, const om_loader *ld,
                         size_t *bytes, om_diag *d);
/* Parses scene text into `a`. Malformed text gives OM_E_PARSE with line and column. */
om_status om_scene_parse(const char *text, size_t len, const om_loader *ld,
                         om_arena *a, om_scene *out, om_diag *d);
/* The built-in default scene, as text in the scene format. */
const char *om_scene_default_text(void);
/* Its small twin for microcontrollers: the same composition in under 2,000 triangles. */
const char *om_scene_small_text(void);
/* The built-in town: a few hundred houses, towers, walls, lamps and trees over a ground
 * a kilometre across, a camera at eye height looking down its main street, a low
 * directional sun, and keys that walk the camera and move the sun. Too long for a
 * C99 string literal, it is written into buf: at most cap bytes, the NUL included (cut
 * short when cap is too small; buf may be NULL when cap is 0). Returns the text's
 * length without the NUL, so om_scene_town_text(NULL, 0) + 1 bytes hold it. */
size_t om_scene_town_text(char *buf, size_t cap);
/* Camera and light at time t along the scene's paths (the scene's own when it has
 * none). Linear interpolation between keys, clamped at the ends. */
void om_scene_at(const om_scene *s, float t, om_camera *cam, om_light *light);
/* Poses object `object` for the next frame: its vertices become m * base * local (m
 * row-major, bottom row 0 0 0 1), its triangles keep facing out under a mirroring m,
 * and the scene's bounds, its solid's box and the change count follow. No memory is
 * carved. OM_E_INVALID for a bad index or bottom row, or an object whose mesh, ranges
 * or keys do not fit the scene's arrays (a scene built by hand); OM_E_RANGE, with the scene left
 * as it was, for an m that is not finite, singular (the determinant of m * base below
 * 1e-18 in magnitude) or puts a vertex beyond 1e7. Posing an object where it already
 * is changes nothing. Make the frame's view (om_view_init) after posing: a directional
 * light's view follows the scene's bounds, which follow the objects. */
om_status om_object_pose(om_scene *s, uint32_t object, const om_mat4 *m, om_diag *d);
/* The index of the object named `name`: OM_E_NOTFOUND when there is none. */
om_status om_object_find(const om_scene *s, const char *name, uint32_t *object);
/* Poses every object that has keys (`key object`) at time t along them, interpolated
 * as the camera's are and clamped at the ends; objects without keys keep their pose.
 * om_scene_at stays a query of the camera and light (it takes a const scene): a host
 * that renders at time t calls both. A parsed scene's keys never give a pose that is
 * refused; a scene built by hand may (OM_E_INVALID or OM_E_RANGE, the objects before
 * the one refused posed). */
om_status om_scene_pose_at(om_scene *s, float t, om_diag *d);

/* Counts of an OBJ file: vertices and triangles after fan triangulation. */
om_status om_obj_count(const char *text, size_t len, uint32_t *nverts, uint32_t *ntris,
                       om_diag *d);

/* ---------------------------------------------------------------- view */

/* Everything a frame needs to know about where the camera and the light are.
 *
 * Every position in a view, and every matrix, is relative to `origin`: the spot
 * light's position, or the centre of the scene's box for a directional light. cam.eye,
 * cam.target, light.pos and light.target are their world positions less origin, and a
 * matrix takes a point less origin. A scene's world vertices are made relative by one
 * float subtraction before any matrix, and every sample's point (om_sample.p) is
 * relative too: the float arithmetic then works on coordinates as large as the scene
 * is around its light, not as large as its distance from the world's origin. The
 * origin follows the light, not the camera, so what a method builds in the light's
 * space stays the same while only the camera moves.
 * light_vp maps such points to the light's clip space; its image plane is the
 * light's shadow-map plane: x, y in [-1, 1] after division by w, depth z/w in [0, 1]. */
typedef struct om_view {
    om_vec3 origin;        /* world position every other one is relative to */
    om_camera cam;
    om_light light;
    om_mat4 cam_view, cam_proj, cam_vp;
    om_mat4 light_view, light_proj, light_vp;
    om_vec3 light_axis;    /* unit direction light travels along its frustum's axis */
} om_view;

/* Builds the camera and light matrices. A directional light's bounds are fitted to the
 * scene's bounds; om_view_fit_light narrows them to what the camera sees. */
om_status om_view_init(om_view *v, const om_camera *cam, const om_light *light,
                       const om_scene *s, om_diag *d);
/* Narrows a directional light's x/y bounds to the light-space box [lo, hi] (from the
 * visible samples) while keeping its depth range over the whole scene. No-op for spot. */
void om_view_fit_light(om_view *v, const om_scene *s, om_vec3 lo, om_vec3 hi);

/* ---------------------------------------------------------------- samples */

/* One visible sample per pixel: the exact point of the nearest triangle under the
 * pixel centre (within 1/256 px of the centre's ray and on the triangle, edges
 * included; relative to the view's origin, om_view: its world position is
 * origin + p), its geometric normal (unit, as wound; not turned to the camera) and
 * the triangle. tri == OM_NO_TRI is background. `nl` is the cosine between the normal
 * turned to the camera and the direction to the light, which the frame sets with the
 * exposure marks for an exposed sample (OM_TERM_EXPOSED; 0 for any other), so that
 * the methods and shading do not work it out again. */
typedef struct om_sample {
    float p[3];
    float n[3];
    uint32_t tri;
    float nl;
} om_sample;

/* The shadow term of a sample: RGB transmittance from the sample to the light,
 * 0 = blocked, 255 = unblocked. Every method writes the same kind of term (r, g, b);
 * the frame sets `flags` before a method runs and methods leave it alone. */
typedef struct om_term { uint8_t r, g, b, flags; } om_term;

/* flags: the sample faces the light (its normal turned to the camera) and lies inside
 * the light's frustum — the parts of the lit rule that no occluder decides. Samples
 * without it are unlit whatever a method says. */
#define OM_TERM_EXPOSED 1u

/* The binary state every metric and mask uses: lit means exposed and unblocked in
 * every channel; anything else, a semi-transparent caster included, is shadowed. */
static inline bool om_term_lit(const om_term *t)
{
    return (t->flags & OM_TERM_EXPOSED) && t->r == 255 && t->g == 255 && t->b == 255;
}

/* A horizontal band of rows [y0, y0 + rows) of a width x height image. */
typedef struct om_strip {
    uint32_t width, height, y0, rows;
    om_sample *samples;    /* rows * width, row-major */
    om_term *terms;        /* rows * width */
    om_vec3 origin;        /* the frame's view's: a sample's world point is origin + p */
} om_strip;

/* ---------------------------------------------------------------- framebuffers */

typedef enum om_format { OM_RGB888 = 0, OM_RGB565, OM_L8 } om_format;

typedef struct om_framebuffer {
    om_format format;
    uint32_t width, rows;  /* rows: the buffer's height (a strip or a whole frame) */
    size_t stride;         /* bytes per row */
    uint8_t *pixels;
} om_framebuffer;

uint32_t om_format_bpp(om_format f);   /* bytes per pixel */

/* ---------------------------------------------------------------- methods */

/* Settings belong to their method: each method lists its own (om_method_setting_at) over
 * a configuration struct private to its file, so adding a setting changes that file
 * alone. A host holds one method's values in an om_method_cfg and sets them by name. */
typedef enum om_setting_kind {
    OM_SETTING_U32 = 0,    /* a whole number, stored as uint32_t */
    OM_SETTING_U64,        /* a whole number, stored as uint64_t (byte counts) */
    OM_SETTING_F32         /* a number, stored as float */
} om_setting_kind;

typedef struct om_setting {
    const char *name;      /* "METHOD.NAME" for a method's own; a plain name ("map")
                              for one that several methods take */
    const char *doc;       /* one line */
    om_setting_kind kind;
    size_t offset;         /* where the value lies in the method's configuration */
    double min, max;       /* what om_method_cfg_set accepts */
    double def;            /* the default */
} om_setting;

/* Room for the largest method's configuration (a method that outgrows it does not
 * compile). */
#define OM_METHOD_CFG_BYTES 128

/* The methods built in (om_method_at). Each can be left out when the engine is
 * compiled: -DOM_WITH_SPSM=0 (likewise OM_WITH_NONE, _REF, _SM, _ASM, _RTW, _IZB,
 * _HYBRID; engine/core/config.h lists every switch) drops it from the list, so a
 * program linked against the library carries none of its code. */
typedef struct om_method om_method;

/* One method's settings, by value: plain memory the host keeps where it likes (the
 * stack, a static) and copies freely. Made by om_method_cfg_default for a method,
 * changed by om_method_cfg_set, read by that method's bytes and init (a method with
 * settings refuses a configuration made for another one: OM_E_INVALID). */
typedef struct om_method_cfg {
    const om_method *method;   /* whose settings these are; NULL: none */
    union {                /* private: the method's configuration struct */
        unsigned char bytes[OM_METHOD_CFG_BYTES];
        uint64_t align_u64;
        double align_f64;
    } store;
} om_method_cfg;

/* The defaults of method m (m may be NULL: an empty configuration no method takes). */
void om_method_cfg_default(om_method_cfg *c, const om_method *m);
/* Sets a setting of c's method by name: OM_E_NOTFOUND when the method has no such
 * setting, OM_E_RANGE outside [min, max] or not whole for a whole-number setting. */
om_status om_method_cfg_set(om_method_cfg *c, const char *name, double value, om_diag *d);
/* Reads a setting's value: OM_E_NOTFOUND when c's method has no such setting (value
 * may be NULL: whether it has it). */
om_status om_method_cfg_get(const om_method_cfg *c, const char *name, double *value);
/* m's defaults with the value of every setting of `from` (may be NULL) that m takes
 * too: to compare methods at the same "map", say. `from` may be c's own storage. */
void om_method_cfg_from(om_method_cfg *c, const om_method *m, const om_method_cfg *from);

typedef struct om_method_stats {
    size_t bytes_used;     /* arena bytes held by the method this frame (peak) */
    uint32_t counters[10]; /* method-specific counts; names in counter_names */
    const char *counter_names[10];
    uint32_t ncounters;
} om_method_stats;

enum {
    OM_METHOD_OBSERVES = 1u,  /* wants every visible sample (observe) before build */
    OM_METHOD_EXACT = 2u      /* gives the reference's answer (charts of time against
                                 triangle count compare these) */
};

/* A shadow method, opaque: found by name (om_method_find) or index (om_method_at),
 * read through the functions below. A frame runs its stages (om_render_frame); a host
 * asks it for its arena's size and creates its state. */
size_t om_method_count(void);
const om_method *om_method_at(size_t i);
const om_method *om_method_find(const char *name);
/* Its name ("sm") and a one-line summary; "" for NULL. */
const char *om_method_name(const om_method *m);
const char *om_method_summary(const om_method *m);
/* OM_METHOD_OBSERVES and OM_METHOD_EXACT; 0 for NULL. */
unsigned om_method_flags(const om_method *m);
/* Its settings: om_method_nsettings(m) of them, setting i at om_method_setting_at (NULL
 * past the end or for NULL). */
uint32_t om_method_nsettings(const om_method *m);
const om_setting *om_method_setting_at(const om_method *m, uint32_t i);
/* A setting of method m by name; NULL when m has none of that name. */
const om_setting *om_method_setting(const om_method *m, const char *name);
/* Bytes m's arena needs for configuration c (made for m), scene s and a width x height
 * image: the least it can work with (*min), and the size it is meant to run at
 * (*full): one pass for every method but izb, whose full is its default pool (it tiles
 * where the scene has few triangles for its samples, which is faster there).
 * OM_E_INVALID for a NULL argument, a side outside 1..OM_MAX_DIM, or a configuration
 * made for another method. */
om_status om_method_bytes(const om_method *m, const om_method_cfg *c, const om_scene *s, uint32_t width,
                          uint32_t height, size_t *min, size_t *full);
/* Creates m's state in arena a (at least *min bytes of om_method_bytes); the method
 * keeps `a` for its per-frame scratch, so the arena is the method's until the host is
 * done with the state. *state is NULL on failure; OM_E_INVALID as om_method_bytes,
 * OM_E_BUDGET where the arena is too small. A scene built by hand is checked first:
 * OM_E_INVALID for an array missing for its counts or an index past its vertices or
 * materials (a parsed scene always passes; keep a scene so when editing it). */
om_status om_method_init(const om_method *m, void **state, om_arena *a, const om_method_cfg *c,
                         const om_scene *s, uint32_t width, uint32_t height, om_diag *d);
/* The state's counters and bytes after a frame (zeros for NULL, or a state m did not
 * make). */
void om_method_get_stats(const om_method *m, const void *state, om_method_stats *out);

/* ---------------------------------------------------------------- rendering */

typedef struct om_shade_cfg {
    float ambient;         /* 0..1, the share of light that reaches shadowed surfaces */
    uint8_t bg_r, bg_g, bg_b;
} om_shade_cfg;

void om_shade_cfg_default(om_shade_cfg *c);

/* Called after each strip is shaded, with the strip's samples, terms and pixels
 * (fb->pixels holds the strip's rows). Return non-OK to stop the frame. */
typedef om_status (*om_strip_fn)(void *user, const om_strip *st,
                                 const om_framebuffer *fb);

typedef struct om_frame_stats {
    /* 0 without a clock. ns_build: the method's per-frame set-up (begin) and its map
     * build; the eye pass of every strip counts in ns_eye. */
    uint64_t ns_eye, ns_observe, ns_build, ns_resolve, ns_shade;
    uint32_t strips, eye_passes;
    size_t frame_peak;
    uint32_t jobs;         /* jobs run at once: 1 inline, up to om_frame_desc.threads */
} om_frame_stats;

/* A monotonic clock the host may provide for per-stage timings; NULL for none. */
typedef uint64_t (*om_clock_fn)(void *user);

/* Parallel work. The engine starts no threads; the host may hand in a parallel-for:
 * run(host, fn, job_user, n) calls fn(job_user, i) once for every i in [0, n), in any
 * order, on any of its threads (the calling one included), and returns when all n calls
 * have returned. The engine calls it only from inside om_render_frame, never nested.
 * The jobs write disjoint memory the engine carved from its arenas and take no locks:
 * the host needs no allocation and no locks beyond its own (to hand out and join the
 * jobs). Frames, masks and method counters are bit-identical whatever the thread count
 * and whatever order the jobs run in. NULL runs every job inline, in order. Most of a
 * frame's calls are bands of rows in row order; a host that gives each of its threads
 * the same contiguous share of the indices on every call, then lets a thread that
 * finishes early take the others' next jobs, keeps a band's rows in one thread's
 * caches from stage to stage (the platform's om_jobs_for does so). */
typedef void (*om_job_fn)(void *job_user, uint32_t i);
typedef void (*om_parallel_for_fn)(void *host, om_job_fn fn, void *job_user, uint32_t n);
/* Optional beside the parallel-for: worker(host), called from inside a job, returns the
 * index in [0, threads) of the host's thread that runs it, the same index for the same
 * thread throughout a frame, so that two jobs running at once never share one. With
 * it, the jobs that need scratch of their own (izb's and hybrid's tiles of samples)
 * are handed out one at a time to whichever thread is free, on that thread's scratch;
 * without it, each thread's scratch takes a fixed share of them. The same frames
 * either way. */
typedef uint32_t (*om_worker_fn)(void *host);

typedef struct om_frame_desc {
    const om_scene *scene;
    const om_view *view;
    const om_method *method;
    void *method_state;
    const om_shade_cfg *shade;
    uint32_t strip_rows;   /* rows per strip; 0 = the whole frame at once */
    om_framebuffer *fb;    /* fb->rows >= strip rows; receives each strip in turn */
    om_strip_fn on_strip;  /* may be NULL */
    void *user;
    om_clock_fn clock;     /* may be NULL */
    void *clock_user;
    om_parallel_for_fn parallel_for;  /* may be NULL: one thread, inline */
    void *parallel_user;   /* the parallel-for's `host` */
    uint32_t threads;      /* jobs at once (0 or 1: inline); each needs its share of the
                              frame arena (om_frame_bytes), and a frame arena with room
                              for fewer runs that many */
    om_worker_fn worker;   /* may be NULL (above) */
} om_frame_desc;

/* What the frame arena needs for the frame fd describes, by what each step buys; each
 * field is a total, at least the one before it. The frame runs in any arena of at
 * least `least` bytes and uses what more it is given, step by step, for the same
 * pixels, faster. From fd it reads: the view (its image's size and light), strip_rows,
 * threads, the method (may be NULL: no method's jobs), its state (may be NULL: a bound
 * for the method's default settings) and the scene (may be NULL: no bins, and jobs
 * without the light map's bins). */
typedef struct om_frame_need {
    size_t least;      /* a strip's samples, terms and the eye pass's depth and triangle ids */
    size_t with_bins;  /* + the scene's bins (4 bytes a triangle, 12 a vertex): each strip
                          (or band) sets up only the triangles that reach its rows, from
                          vertices projected once */
    size_t with_jobs;  /* + what `threads` jobs need at once: each job's scratch for the
                          method's resolve and pass, and the light map's bins for a method
                          whose depth pass runs by bands of the map (none for threads <= 1,
                          nor where the engine carries no jobs code: OM_WITH_JOBS) */
    size_t with_ids;   /* + the image's triangle ids (2 bytes a pixel under 65535 triangles,
                          else 4): a frame through strips that passes over the image more
                          than once rasterizes the scene once, and its later passes resolve
                          from them */
    size_t whole;      /* all the frame can use: with_ids where it passes over the image
                          through strips more than once (a method that observes, a
                          directional light), else with_jobs */
} om_frame_need;
/* OM_E_INVALID without fd, its view or out, or for a view's side outside
 * 1..OM_MAX_DIM. */
om_status om_frame_bytes(const om_frame_desc *fd, om_frame_need *out);
/* Renders one frame. The frame arena is rewound on return; the method's arena keeps
 * what the method keeps. OM_E_INVALID, before anything is drawn, for a missing piece
 * of fd or a frame arena, a framebuffer that is not as wide as the image or holds no
 * strip, a format outside om_format, or a method state that om_method_init did not
 * make for this method, this scene (its vertex and index arrays and counts) and this
 * view's image size. */
om_status om_render_frame(const om_frame_desc *fd, om_arena *frame_arena,
                          om_frame_stats *stats, om_diag *d);

#ifdef __cplusplus
}
#endif
#endif
