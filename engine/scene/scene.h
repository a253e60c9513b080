/* scene.h — what the scene parser (parse.c), the OBJ reader (obj.c) and the shape
 * generators (shapes.c) share: scanning lines and tokens of text that is not
 * NUL-terminated, our own decimal number reader (no strtod in the engine), messages
 * that carry line and column, and the sink every shape writes its vertices and
 * triangles into. The sink has two modes so that one piece of code both counts and
 * validates (first pass, before any memory is carved) and fills (second pass): the
 * two passes cannot disagree about what a line produces. */
#ifndef OM_SCENE_INTERNAL_H
#define OM_SCENE_INTERNAL_H

#include "../core/core.h"

/* ---- lines and tokens */

static inline size_t om__cstr_len(const char *s)   /* strlen, which the engine may not call */
{
    size_t n = 0;
    while (s[n]) n++;
    return n;
}

static inline bool om__is_digit(char c) { return c >= '0' && c <= '9'; }

/* A cursor over the lines of a text. A line's content stops at '#' (comment) or at
 * '\n'; '\r', ' ' and '\t' separate tokens, so CRLF text reads like LF text. */
typedef struct om__line {
    const char *text;
    size_t len;
    size_t start, end;     /* the current line's content: [start, end) */
    size_t next;           /* where the following line starts */
    size_t p;              /* token cursor within [start, end) */
    uint32_t no;           /* 1-based number of the current line (saturates) */
    bool strict;           /* control bytes outside comments are errors (scene text) */
} om__line;

typedef struct om__tok {
    size_t at, len;        /* offset in the text and length */
    uint32_t col;          /* 1-based column of its first byte */
} om__tok;

void om__line_init(om__line *l, const char *text, size_t len, bool strict);
/* Moves to the next line; false when the text is exhausted. */
bool om__line_next(om__line *l);
/* Reads the next token of the current line: 1 = a token, 0 = end of line, -1 = a control
 * byte (strict mode only; t->at and t->col point at it). */
int om__tok_next(om__line *l, om__tok *t);
/* The next token without consuming it (same results as om__tok_next). */
int om__tok_peek(const om__line *l, om__tok *t);
/* The column just past the line's last token: where a missing value was expected. */
uint32_t om__line_end_col(const om__line *l);
uint32_t om__col(const om__line *l, size_t at);
bool om__tok_is(const char *text, const om__tok *t, const char *word);
/* Looks like a number (starts with a digit, a sign or a point): such a token is read
 * as a value, never as a parameter name, so "1.2.3" is reported as a bad number. */
bool om__numlike(const char *s, size_t n);

/* ---- numbers */

/* Reads a whole token as a decimal number: [+-] digits [. digits] [(e|E) [+-] digits]
 * (at least one mantissa digit). Up to 19 significant digits are kept in a uint64
 * and scaled by exact powers of ten, so the result is the same on every machine.
 * Returns false when malformed; an overflow gives +-inf, which callers reject. */
bool om__num(const char *s, size_t n, double *out);

/* ---- messages */

/* Starts a message "[file: ]line L, col C: " in d (setting status, line, col) and
 * returns the builder to go on with. Works with d == NULL (writes to scratch). */
om__str om__perr(om_diag *d, om_status st, const char *file, uint32_t line, uint32_t col,
                 char *scratch, size_t cap);
/* Appends a token in quotes, at most 32 bytes, control and non-ASCII bytes as '?'. */
void om__str_tok(om__str *s, const char *p, size_t n);

/* ---- transforms and the vertex/triangle sink */

/* v' = M v with M the top three rows of a 4x4, in double: scale, then rotate about
 * x, y and z (degrees), then translate. `flip` is set when M mirrors (negative
 * determinant): triangles then swap two corners so they stay wound outward. */
typedef struct om__xform { double m[12]; bool flip; } om__xform;

void om__xform_make(om__xform *x, const double scale[3], const double rot_deg[3],
                    const double move[3]);
void om__sincos_deg(double deg, double *s, double *c);

#define OM__COORD_MAX 1e7  /* largest |coordinate| after transformation */

/* ---- objects (pose.c) */

/* out = a * b, both 3x4 rows of affine transforms (out may be either). */
void om__xform_mul(const double a[12], const double b[12], double out[12]);
/* Writes object oi's vertices (m * its mesh's local ones), triangles (corners swapped
 * where m mirrors), bounds and solid box, and keeps m as its pose: the one place that
 * turns a mesh into scene geometry, at parse time and for every move. Refuses (scene
 * unchanged) a transform that is not finite, singular or carries a vertex beyond
 * 1e7. Neither the change count nor the scene's bounds: the callers' part. */
om_status om__object_write(om_scene *s, uint32_t oi, const double m[12], om_diag *d);
/* s->lo, s->hi from the static bounds and every object's. */
void om__scene_bounds(om_scene *s);
/* The transform of o's key path at time t, base included. */
void om__object_key_at(const om_scene *s, const om_object *o, float t, double out[12]);

typedef struct om__sink {
    om__xform xf;
    bool write;            /* false: count and check only */
    bool check_range;      /* report vertices beyond OM__COORD_MAX */
    om_vec3 *verts;        /* write mode: the scene's arrays and their capacity */
    uint32_t *idx;
    uint16_t *tri_mat;
    uint64_t vcap, tcap;
    uint64_t nv, nt;       /* vertices and triangles appended so far */
    uint64_t base;         /* index of the current object's first vertex */
    uint16_t mat;          /* material of the triangles being appended */
    bool out_of_range;     /* a vertex went beyond OM__COORD_MAX */
    bool overflow;         /* write mode: more than the capacity was offered */
    uint32_t where;        /* caller's note for the first out-of-range vertex (OBJ line) */
    uint32_t note;         /* the caller keeps its current note here */
    double r2;             /* the largest squared distance of a vertex from the origin */
} om__sink;

void om__sink_init(om__sink *k, bool write);
/* Starts an object: its vertices are numbered from 0 in om__sink_tri. */
void om__sink_begin(om__sink *k, const om__xform *xf, uint16_t mat);
void om__sink_vert(om__sink *k, double x, double y, double z);
void om__sink_tri(om__sink *k, uint32_t a, uint32_t b, uint32_t c);

/* ---- procedural shapes (shapes.c): counts, then generation into a sink */

void om__plane_counts(uint32_t div, uint64_t *nv, uint64_t *nt);
void om__sphere_counts(uint32_t seg, uint32_t rings, uint64_t *nv, uint64_t *nt);
void om__cylinder_counts(uint32_t seg, uint64_t *nv, uint64_t *nt);

void om__gen_plane(om__sink *k, double sx, double sz, uint32_t div);
void om__gen_box(om__sink *k, double sx, double sy, double sz);
void om__gen_sphere(om__sink *k, double r, uint32_t seg, uint32_t rings);
void om__gen_cylinder(om__sink *k, double r, double h, uint32_t seg);
/* splitmix64: tiny, well mixed, and the same sequence everywhere (the random cloud's
 * triangles, the built-in town's houses). */
uint64_t om__mix_next(uint64_t *state);
/* n roughly equilateral triangles of area `area / n` each, randomly oriented, with
 * their vertices inside box = {x0, y0, z0, x1, y1, z1} (where the box is large enough). */
void om__gen_triangles(om__sink *k, uint32_t n, uint32_t seed, double area,
                       const double box[6]);

/* ---- OBJ (obj.c) */

/* Reads an OBJ into the sink (counting or writing). `name` names the file in messages
 * (NULL: "obj"); scene_line, if non-zero, is mentioned as the line of the mesh. */
om_status om__obj_run(const char *text, size_t len, const char *name, uint32_t scene_line,
                      om__sink *k, om_diag *d);

#define OM__MAX_ELEMS 0x7FFFFFFFu   /* vertices and triangles of a scene: < 2^31 each */

#endif
