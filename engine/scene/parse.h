/* parse.h — what the scene text reader's two files share: the parameters every
 * command may take (names, value counts, kinds, ranges), the parser's state across a
 * pass, and the messages with line and column. params.c reads parameters and words
 * the errors; parse.c runs the commands and the two passes. */
#ifndef OM_SCENE_PARSE_H
#define OM_SCENE_PARSE_H

#include "scene.h"

enum {
    P_EYE, P_TARGET, P_UP, P_FOV, P_SIZE, P_NEAR, P_FAR, P_POS, P_DIR, P_ALBEDO, P_OPACITY,
    P_SIZE2, P_DIVISIONS, P_SIZE3, P_RADIUS, P_SEGMENTS, P_RINGS, P_HEIGHT, P_COUNT, P_SEED,
    P_AREA, P_IN, P_SCALE, P_ROTATE, P_TRANSLATE, P_MATERIAL, P_NAME, P_SCALE1, P_N_
};
enum { K_NUM, K_INT, K_SCALE, K_WORD };   /* what a parameter's values are */
enum {
    R_COORD, R_LEN, R_FOV, R_UNIT, R_DIM, R_DIV, R_SEG, R_RING, R_COUNT, R_SEED, R_NEAR,
    R_FAR, R_AREA, R_SCALE, R_N_
};

/* One parameter as read from a line. */
typedef struct pv {
    bool has;
    uint8_t n;             /* values read (scale: 1 or 3) */
    uint32_t col;          /* column of the parameter's name */
    uint32_t vcol[6];      /* column of each value */
    double v[6];
    om__tok w;             /* K_WORD: the word */
} pv;

#define MCACHE 64          /* material names remembered; a miss rescans earlier lines */

typedef struct mslot { size_t at, len; uint32_t ord; bool used; } mslot;

/* What the parser knows of an object by name: found again by reading the lines above
 * (obj_scan), remembered in a small cache (no table to allocate). */
typedef struct oinfo {
    size_t at, len;        /* the name in the text */
    bool used;
    uint32_t ord, mesh;    /* the object's and its mesh's index */
    uint64_t nv, nt;       /* its mesh's vertices and triangles */
    bool closed;
    double radius;         /* how far from the origin its vertices reach at rest (base on) */
    uint32_t line;         /* where it is named */
    uint32_t nkeys, last_line;   /* its keys so far, and the latest's line, t and scale */
    float last_t, last_scale;
} oinfo;

#define OCACHE 16
#define NAME_BITS 4096     /* a filter of the names so far: a new name mostly skips the scan */

typedef struct parser {
    const char *text;
    size_t len;
    const om_loader *ld;
    om_diag *d;
    om__line l;
    om__tok cmd;           /* the current line's command */
    bool fill;             /* second pass: write into the scene */
    uint64_t nv, nt;       /* vertices and triangles so far */
    uint32_t nnamed, ninline, ncam, nlight;
    uint32_t nsolids;      /* closed shapes so far (om_solid) */
    uint32_t nnamed_total; /* second pass: named materials in the whole text */
    bool have_cam, have_light;
    uint32_t cam_line, light_line;
    float cam_t, light_t;  /* time of the last key of each kind */
    om_camera_key cam_k;   /* the last key of each kind, for the segment to the next */
    om_light_key light_k;
    uint32_t cam_t_line, light_t_line;
    int lkey_form;         /* 0 none yet, 1 spot (pos/target), 2 directional (dir) */
    uint32_t lkey_line, lkey_col;
    om_camera cam;
    om_light light;
    om_scene *s;           /* second pass */
    om__sink out;          /* second pass: the whole scene's sink */
    mslot cache[MCACHE];
    uint32_t nobjects, nmeshes, nobj_keys;   /* objects, meshes and object keys so far */
    uint64_t nmesh_v, nmesh_t, name_bytes;   /* the meshes' vertices, triangles; names */
    oinfo ocache[OCACHE];
    uint32_t name_bits[NAME_BITS / 32];
} parser;

/* Starts a message "line L, col C: " on the current line. */
om__str om__parse_fail_begin(parser *p, om_status st, uint32_t col, char *tmp, size_t cap);
/* "line L, col C: <a>'<q>'<b>" — most messages have this shape. */
om_status om__parse_fail(parser *p, om_status st, uint32_t col, const char *a, const char *q,
                         size_t qn, const char *b);
om_status om__parse_fail_tok(parser *p, om_status st, const om__tok *t, const char *a,
                             const char *b);
om_status om__parse_bad_byte(parser *p, const om__tok *t);
/* Reads one value of parameter `what`; want (0: "1 or 3") only shapes messages. */
om_status om__parse_value(parser *p, const char *what, uint8_t kind, uint8_t rng,
                          unsigned want, double *v, uint32_t *col);
/* Reads `name value...` pairs to the end of the line, any order, each at most once. */
om_status om__parse_params(parser *p, const char *what, const uint8_t *ids, size_t nids,
                           pv *pl);
/* "'what' needs <need>" at the command. */
om_status om__parse_missing(parser *p, const char *what, const char *need);
om_status om__parse_near_far(parser *p, const pv *pl, float zn, float zf);
/* A second camera or light line. */
om_status om__parse_second_line(parser *p, const char *what, uint32_t first);

static inline om_vec3 pv3(const pv *v, int i) { return om__v3((float)v->v[i], (float)v->v[i + 1], (float)v->v[i + 2]); }
static inline double val(const pv *pl, int id, int i, double def) { return pl[id].has ? pl[id].v[i] : def; }
/* paths.c: whether a - b, lerped from (a0, b0) to (a1, b1), (nearly) vanishes. */
bool om__path_meets(om_vec3 a0, om_vec3 b0, om_vec3 a1, om_vec3 b1);

static inline bool v3_zero(om_vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
/* Whether v gives no direction: its unit vector (om__normalize, as the view makes
 * it) is zero, as for a vector too short for float to square. The view refuses such a
 * camera or light (om_view_init), so the parser does, with the line and column. */
static inline bool v3_no_dir(om_vec3 v)
{
    const om_vec3 n = om__normalize(v);
    return om__dot(n, n) == 0.0f;
}


#endif
