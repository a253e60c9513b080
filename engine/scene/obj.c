/* obj.c — Wavefront OBJ meshes: vertex positions (`v`) and faces (`f`), nothing else.
 * Faces may use the i, i/j, i//k and i/j/k forms and negative (relative) indices, and
 * polygons are fan-triangulated; every other statement (vt, vn, g, o, s, usemtl,
 * mtllib, l, ...) is skipped. The same reader counts (for om_obj_count and the scene's
 * first pass) and writes (the scene's second pass) through an om__sink, so the counts
 * cannot disagree with what is written. */
#include "scene.h"

#include <string.h>

typedef struct obj_ctx {
    const char *name;      /* file name for messages, NULL: "obj" */
    uint32_t scene_line;   /* the scene's `mesh` line, 0 if none */
    om_diag *d;
    const om__line *l;
} obj_ctx;

static om__str obj_begin(const obj_ctx *c, om_status st, uint32_t col, char *tmp, size_t cap)
{
    return om__perr(c->d, st, c->name ? c->name : "obj", c->l->no, col, tmp, cap);
}

/* Every OBJ message ends by naming the scene line that asked for the file. */
static om_status obj_end(const obj_ctx *c, om__str *s, om_status st)
{
    if (c->scene_line) {
        om__str_s(s, " (mesh on scene line ");
        om__str_u(s, c->scene_line);
        om__str_s(s, ")");
    }
    return st;
}

static om_status obj_fail(const obj_ctx *c, om_status st, uint32_t col, const char *a,
                          const char *q, size_t qn, const char *b)
{
    char tmp[4];
    om__str s = obj_begin(c, st, col, tmp, sizeof tmp);
    om__str_s(&s, a);
    if (q) om__str_tok(&s, q, qn);
    if (b) om__str_s(&s, b);
    return obj_end(c, &s, st);
}


/* A signed integer; magnitudes saturate (an index that large is out of range anyway). */
static bool read_int(const char *s, size_t n, size_t *i, int64_t *v)
{
    size_t j = *i;
    bool neg = false;
    if (j < n && (s[j] == '-' || s[j] == '+')) neg = s[j++] == '-';
    if (j >= n || !om__is_digit(s[j])) return false;
    int64_t x = 0;
    for (; j < n && om__is_digit(s[j]); j++)
        if (x < 1000000000000LL) x = x * 10 + (s[j] - '0');
    *v = neg ? -x : x;
    *i = j;
    return true;
}

/* i, i/j, i//k or i/j/k: only i matters here, but j and k must be well formed. */
static bool read_ref(const char *s, size_t n, int64_t *v)
{
    size_t i = 0;
    int64_t skip;
    if (!read_int(s, n, &i, v)) return false;
    if (i == n) return true;
    if (s[i++] != '/') return false;
    if (i < n && s[i] == '/') {
        i++;
        return read_int(s, n, &i, &skip) && i == n;
    }
    if (!read_int(s, n, &i, &skip)) return false;
    if (i == n) return true;
    if (s[i++] != '/') return false;
    return read_int(s, n, &i, &skip) && i == n;
}

static om_status read_vertex(const obj_ctx *c, om__line *l, om__sink *k, uint64_t *nv)
{
    const char *text = l->text;
    double p[3];
    for (int i = 0; i < 3; i++) {
        om__tok t;
        if (om__tok_next(l, &t) != 1)
            return obj_fail(c, OM_E_PARSE, om__line_end_col(l), "expected 3 numbers after 'v'",
                            NULL, 0, NULL);
        if (!om__num(text + t.at, t.len, &p[i]))
            return obj_fail(c, OM_E_PARSE, t.col, "malformed number ", text + t.at, t.len,
                            " in a vertex");
        if (!(p[i] - p[i] == 0.0))
            return obj_fail(c, OM_E_PARSE, t.col, "number ", text + t.at, t.len,
                            " is not finite");
    }
    /* Anything after x y z (w, or the colours some exporters add) is ignored. */
    if (*nv >= OM__MAX_ELEMS)
        return obj_fail(c, OM_E_RANGE, 1, "more than 2147483647 vertices", NULL, 0, NULL);
    k->note = l->no;
    om__sink_vert(k, p[0], p[1], p[2]);
    (*nv)++;
    return OM_OK;
}

static om_status read_face(const obj_ctx *c, om__line *l, uint32_t fcol, om__sink *k,
                           uint64_t nv, uint64_t *nt)
{
    const char *text = l->text;
    uint32_t first = 0, prev = 0, count = 0;
    om__tok t;
    while (om__tok_next(l, &t) == 1) {
        int64_t v;
        if (!read_ref(text + t.at, t.len, &v))
            return obj_fail(c, OM_E_PARSE, t.col, "malformed vertex reference ", text + t.at,
                            t.len, " (expected i, i/j, i//k or i/j/k)");
        if (v == 0)
            return obj_fail(c, OM_E_PARSE, t.col, "vertex index 0 (OBJ indices start at 1)",
                            NULL, 0, NULL);
        /* Indices refer to the vertices read so far; negative ones count back from the last. */
        int64_t at = v > 0 ? v - 1 : (int64_t)nv + v;
        if (at < 0 || at >= (int64_t)nv) {
            char tmp[4];
            om__str s = obj_begin(c, OM_E_PARSE, t.col, tmp, sizeof tmp);
            om__str_s(&s, "vertex index ");
            om__str_i(&s, v);
            om__str_s(&s, " is out of range (");
            om__str_u(&s, nv);
            om__str_s(&s, " vertices so far)");
            return obj_end(c, &s, OM_E_PARSE);
        }
        uint32_t cur = (uint32_t)at;
        if (count == 0) {
            first = cur;
        } else if (count >= 2) {
            if (*nt >= OM__MAX_ELEMS)
                return obj_fail(c, OM_E_RANGE, t.col, "more than 2147483647 triangles", NULL,
                                0, NULL);
            om__sink_tri(k, first, prev, cur);   /* a fan around the first corner */
            (*nt)++;
        }
        prev = cur;
        if (count < UINT32_MAX) count++;
    }
    if (count < 3) {
        char tmp[4];
        om__str s = obj_begin(c, OM_E_PARSE, fcol, tmp, sizeof tmp);
        om__str_s(&s, "a face needs at least 3 vertices, this one has ");
        om__str_u(&s, count);
        return obj_end(c, &s, OM_E_PARSE);
    }
    return OM_OK;
}

om_status om__obj_run(const char *text, size_t len, const char *name, uint32_t scene_line,
                      om__sink *k, om_diag *d)
{
    if (!text && len) return om__fail(d, OM_E_INVALID, "OBJ text is NULL");
    om__line l;
    /* Not strict: bytes of skipped statements are nobody's business; in v and f lines
     * a stray byte makes its token malformed. */
    om__line_init(&l, text, len, false);
    obj_ctx c;
    c.name = name;
    c.scene_line = scene_line;
    c.d = d;
    c.l = &l;
    uint64_t nv = 0, nt = 0;
    while (om__line_next(&l)) {
        om__tok t;
        if (om__tok_next(&l, &t) != 1) continue;
        om_status st = OM_OK;
        if (om__tok_is(text, &t, "v")) st = read_vertex(&c, &l, k, &nv);
        else if (om__tok_is(text, &t, "f")) st = read_face(&c, &l, t.col, k, nv, &nt);
        if (st != OM_OK) return st;
    }
    return OM_OK;
}

om_status om_obj_count(const char *text, size_t len, uint32_t *nverts, uint32_t *ntris,
                       om_diag *d)
{
    if (nverts) *nverts = 0;
    if (ntris) *ntris = 0;
    if (d) {
        d->status = OM_OK;
        d->line = d->col = 0;
        d->msg[0] = '\0';
    }
    om__sink k;
    om__sink_init(&k, false);
    k.check_range = false;   /* the 1e7 limit applies to scenes, after their transforms */
    om_status st = om__obj_run(text, len, NULL, 0, &k, d);
    if (st != OM_OK) return st;
    if (nverts) *nverts = (uint32_t)k.nv;
    if (ntris) *ntris = (uint32_t)k.nt;
    return OM_OK;
}
