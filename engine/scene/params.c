/* params.c — the scene text's parameters: each one's name, value count, kind and range,
 * reading them off a line in any order, and the messages (line, column, what was
 * expected, what was found) when a line does not read. */
#include "parse.h"

#include <math.h>
#include <string.h>

typedef struct pdef { const char *name; uint8_t n, kind, rng; } pdef;
static const pdef pdefs[P_N_] = {
    [P_EYE] = {"eye", 3, K_NUM, R_COORD},        [P_TARGET] = {"target", 3, K_NUM, R_COORD},
    [P_UP] = {"up", 3, K_NUM, R_COORD},          [P_FOV] = {"fov", 1, K_NUM, R_FOV},
    [P_SIZE] = {"size", 2, K_INT, R_DIM},        [P_NEAR] = {"near", 1, K_NUM, R_NEAR},
    [P_FAR] = {"far", 1, K_NUM, R_FAR},          [P_POS] = {"pos", 3, K_NUM, R_COORD},
    [P_DIR] = {"dir", 3, K_NUM, R_COORD},        [P_ALBEDO] = {"albedo", 3, K_NUM, R_UNIT},
    [P_OPACITY] = {"opacity", 1, K_NUM, R_UNIT}, [P_SIZE2] = {"size", 2, K_NUM, R_LEN},
    [P_DIVISIONS] = {"divisions", 1, K_INT, R_DIV},
    [P_SIZE3] = {"size", 3, K_NUM, R_LEN},       [P_RADIUS] = {"radius", 1, K_NUM, R_LEN},
    [P_SEGMENTS] = {"segments", 1, K_INT, R_SEG}, [P_RINGS] = {"rings", 1, K_INT, R_RING},
    [P_HEIGHT] = {"height", 1, K_NUM, R_LEN},    [P_COUNT] = {"count", 1, K_INT, R_COUNT},
    [P_SEED] = {"seed", 1, K_INT, R_SEED},       [P_AREA] = {"area", 1, K_NUM, R_AREA},
    [P_IN] = {"in", 6, K_NUM, R_COORD},          [P_SCALE] = {"scale", 3, K_SCALE, R_SCALE},
    [P_ROTATE] = {"rotate", 3, K_NUM, R_COORD},  [P_TRANSLATE] = {"translate", 3, K_NUM, R_COORD},
    [P_MATERIAL] = {"material", 1, K_WORD, 0},   [P_NAME] = {"name", 1, K_WORD, 0},
    [P_SCALE1] = {"scale", 1, K_NUM, R_SCALE},
};

/* Every number has a range; `mag` ranges bound the magnitude (scale may be negative:
 * a mirror); `open` 1 excludes both ends, 2 only the upper one (what the view
 * accepts: near below 1e7, far below 1e8). */
typedef struct rdef { double lo, hi; unsigned char open; bool mag; const char *text; } rdef;
static const rdef rdefs[R_N_] = {
    [R_COORD] = {-1e7, 1e7, 0, false, "-1e7..1e7"},
    [R_LEN] = {1e-6, 1e7, 0, false, "1e-6..1e7"},
    [R_FOV] = {0.0, 180.0, 1, false, "above 0 and below 180"},
    [R_UNIT] = {0.0, 1.0, 0, false, "0..1"},
    [R_DIM] = {1.0, 8192.0, 0, false, "1..8192"},
    [R_DIV] = {1.0, 4096.0, 0, false, "1..4096"},
    [R_SEG] = {3.0, 4096.0, 0, false, "3..4096"},
    [R_RING] = {2.0, 4096.0, 0, false, "2..4096"},
    [R_COUNT] = {1.0, 1e7, 0, false, "1..10000000"},
    [R_SEED] = {0.0, 4294967295.0, 0, false, "0..4294967295"},
    [R_NEAR] = {1e-6, 1e7, 2, false, "1e-6..1e7, 1e7 excluded"},
    [R_FAR] = {1e-6, 1e8, 2, false, "1e-6..1e8, 1e8 excluded"},
    [R_AREA] = {1e-6, 1e12, 0, false, "1e-6..1e12"},
    [R_SCALE] = {1e-6, 1e6, 0, true, "1e-6..1e6 in magnitude"},
};

static bool in_range(const rdef *rd, double x, double lo, double hi)
{
    return rd->open == 1 ? x > lo && x < hi : rd->open == 2 ? x >= lo && x < hi : x >= lo && x <= hi;
}

om__str om__parse_fail_begin(parser *p, om_status st, uint32_t col, char *tmp, size_t cap)
{
    return om__perr(p->d, st, NULL, p->l.no, col, tmp, cap);
}

/* "line L, col C: <a>'<q>'<b>" — most messages have this shape. */
om_status om__parse_fail(parser *p, om_status st, uint32_t col, const char *a, const char *q,
                      size_t qn, const char *b)
{
    char tmp[4];
    om__str s = om__parse_fail_begin(p, st, col, tmp, sizeof tmp);
    om__str_s(&s, a);
    if (q) om__str_tok(&s, q, qn);
    if (b) om__str_s(&s, b);
    return st;
}

om_status om__parse_fail_tok(parser *p, om_status st, const om__tok *t, const char *a,
                          const char *b)
{
    return om__parse_fail(p, st, t->col, a, p->text + t->at, t->len, b);
}

om_status om__parse_bad_byte(parser *p, const om__tok *t)
{
    static const char hex[] = "0123456789abcdef";
    unsigned char c = (unsigned char)p->text[t->at];
    char code[5] = {'0', 'x', hex[c >> 4], hex[c & 15], '\0'};
    char tmp[4];
    om__str s = om__parse_fail_begin(p, OM_E_PARSE, t->col, tmp, sizeof tmp);
    om__str_s(&s, "unexpected byte ");
    om__str_s(&s, code);
    om__str_s(&s, " (scene files are text)");
    return OM_E_PARSE;
}

static void list_names(om__str *s, const uint8_t *ids, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (i) om__str_s(s, ", ");
        om__str_s(s, pdefs[ids[i]].name);
    }
}

static void expected_numbers(om__str *s, unsigned want, bool integer)
{
    om__str_s(s, "expected ");
    if (want == 0) om__str_s(s, "1 or 3 numbers");
    else if (want == 1) om__str_s(s, integer ? "a whole number" : "a number");
    else {
        om__str_u(s, want);
        om__str_s(s, integer ? " whole numbers" : " numbers");
    }
}

/* Reads one value of parameter `what`; want (0: "1 or 3") only shapes messages. */
om_status om__parse_value(parser *p, const char *what, uint8_t kind, uint8_t rng,
                            unsigned want, double *v, uint32_t *col)
{
    om__tok t;
    int r = om__tok_next(&p->l, &t);
    if (r < 0) return om__parse_bad_byte(p, &t);
    if (r == 0 || !om__numlike(p->text + t.at, t.len)) {
        char tmp[4];
        om__str s = om__parse_fail_begin(p, OM_E_PARSE, r == 0 ? om__line_end_col(&p->l) : t.col, tmp,
                               sizeof tmp);
        expected_numbers(&s, want, kind == K_INT);
        om__str_s(&s, " after '");
        om__str_s(&s, what);
        om__str_s(&s, "'");
        if (r != 0) {
            om__str_s(&s, ", found ");
            om__str_tok(&s, p->text + t.at, t.len);
        }
        return OM_E_PARSE;
    }
    *col = t.col;
    if (!om__num(p->text + t.at, t.len, v))
        return om__parse_fail_tok(p, OM_E_PARSE, &t, "malformed number ", NULL);
    if (!(*v - *v == 0.0))
        return om__parse_fail_tok(p, OM_E_PARSE, &t, "number ", " is not finite");
    if (kind == K_INT && *v != floor(*v)) {
        char tmp[4];
        om__str s = om__parse_fail_begin(p, OM_E_PARSE, t.col, tmp, sizeof tmp);
        om__str_s(&s, "expected a whole number after '");
        om__str_s(&s, what);
        om__str_s(&s, "', found ");
        om__str_tok(&s, p->text + t.at, t.len);
        return OM_E_PARSE;
    }
    const rdef *rd = &rdefs[rng];
    /* A number is checked as written and as the scene stores it, a float (against
     * the bounds as floats): fov 179.999999 is 180 there, far 99999999 is 1e8. */
    bool ok = in_range(rd, rd->mag ? fabs(*v) : *v, rd->lo, rd->hi);
    if (kind != K_INT) {
        double f = (double)(float)*v;
        ok = ok && in_range(rd, rd->mag ? fabs(f) : f, (double)(float)rd->lo, (double)(float)rd->hi);
    }
    if (!ok) {
        char tmp[4];
        om__str s = om__parse_fail_begin(p, OM_E_RANGE, t.col, tmp, sizeof tmp);
        om__str_s(&s, what);
        om__str_s(&s, " ");
        om__str_tok(&s, p->text + t.at, t.len);
        om__str_s(&s, " is out of range (");
        om__str_s(&s, rd->text);
        om__str_s(&s, ")");
        return OM_E_RANGE;
    }
    return OM_OK;
}

static bool peek_number(parser *p, om__tok *t)
{
    return om__tok_peek(&p->l, t) == 1 && om__numlike(p->text + t->at, t->len);
}

/* Reads `name value...` pairs to the end of the line, any order, each at most once. */
om_status om__parse_params(parser *p, const char *what, const uint8_t *ids, size_t nids,
                             pv *pl)
{
    memset(pl, 0, sizeof(pv) * P_N_);
    om__tok t;
    int r;
    while ((r = om__tok_next(&p->l, &t)) != 0) {
        if (r < 0) return om__parse_bad_byte(p, &t);
        int id = -1;
        for (size_t i = 0; i < nids && id < 0; i++)
            if (om__tok_is(p->text, &t, pdefs[ids[i]].name)) id = ids[i];
        if (id < 0) {
            char tmp[4];
            bool num = om__numlike(p->text + t.at, t.len);
            om__str s = om__parse_fail_begin(p, OM_E_PARSE, t.col, tmp, sizeof tmp);
            om__str_s(&s, num ? "unexpected value " : "unknown parameter ");
            om__str_tok(&s, p->text + t.at, t.len);
            om__str_s(&s, " for '");
            om__str_s(&s, what);
            om__str_s(&s, "' (expected ");
            list_names(&s, ids, nids);
            om__str_s(&s, ")");
            return OM_E_PARSE;
        }
        const pdef *pd = &pdefs[id];
        pv *v = &pl[id];
        if (v->has) return om__parse_fail_tok(p, OM_E_PARSE, &t, "parameter ", " is given twice");
        v->has = true;
        v->col = t.col;
        om_status st;
        if (pd->kind == K_WORD) {
            r = om__tok_next(&p->l, &v->w);
            if (r < 0) return om__parse_bad_byte(p, &v->w);
            if (r == 0)
                return om__parse_fail(p, OM_E_PARSE, om__line_end_col(&p->l), "expected a name after ",
                            pd->name, om__cstr_len(pd->name), NULL);
            continue;
        }
        if (pd->kind == K_SCALE) {
            om__tok nx;
            while (v->n < 4 && peek_number(p, &nx)) {
                if (v->n == 3)
                    return om__parse_fail(p, OM_E_PARSE, nx.col, "too many values after ", pd->name,
                                om__cstr_len(pd->name), " (it takes 1 or 3)");
                if ((st = om__parse_value(p, pd->name, K_NUM, pd->rng, 0, &v->v[v->n],
                                     &v->vcol[v->n])) != OM_OK)
                    return st;
                v->n++;
            }
            if (v->n != 1 && v->n != 3) {
                /* reads the offending token (or the end of the line) for the message */
                double dummy;
                uint32_t dcol;
                return om__parse_value(p, pd->name, K_NUM, pd->rng, 0, &dummy, &dcol);
            }
            if (v->n == 1) v->v[1] = v->v[2] = v->v[0];
            continue;
        }
        for (unsigned i = 0; i < pd->n; i++)
            if ((st = om__parse_value(p, pd->name, pd->kind, pd->rng, pd->n, &v->v[i],
                                 &v->vcol[i])) != OM_OK)
                return st;
        v->n = pd->n;
        om__tok nx;
        if (peek_number(p, &nx)) {
            char tmp[4];
            om__str s = om__parse_fail_begin(p, OM_E_PARSE, nx.col, tmp, sizeof tmp);
            om__str_s(&s, "too many values after '");
            om__str_s(&s, pd->name);
            om__str_s(&s, "' (it takes ");
            om__str_u(&s, pd->n);
            om__str_s(&s, ")");
            return OM_E_PARSE;
        }
    }
    return OM_OK;
}

om_status om__parse_missing(parser *p, const char *what, const char *need)
{
    char tmp[4];
    om__str s = om__parse_fail_begin(p, OM_E_PARSE, p->cmd.col, tmp, sizeof tmp);
    om__str_s(&s, "'");
    om__str_s(&s, what);
    om__str_s(&s, "' needs ");
    om__str_s(&s, need);
    return OM_E_PARSE;
}

om_status om__parse_near_far(parser *p, const pv *pl, float zn, float zf)
{
    if (zf > zn) return OM_OK;
    uint32_t col = pl[P_FAR].has ? pl[P_FAR].vcol[0] : pl[P_NEAR].vcol[0];
    return om__parse_fail(p, OM_E_RANGE, col, "'far' must be greater than 'near'", NULL, 0, NULL);
}

om_status om__parse_second_line(parser *p, const char *what, uint32_t first)
{
    char tmp[4];
    om__str s = om__parse_fail_begin(p, OM_E_PARSE, p->cmd.col, tmp, sizeof tmp);
    om__str_s(&s, "a second '");
    om__str_s(&s, what);
    om__str_s(&s, "' line (a scene has one; the first is on line ");
    om__str_u(&s, first);
    om__str_s(&s, ")");
    return OM_E_PARSE;
}
