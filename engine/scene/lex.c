/* lex.c — what the scene and OBJ readers scan text with: lines (comments stripped,
 * CRLF accepted) and tokens of a text that is not NUL-terminated, our own decimal
 * number reader (no strtod in the engine: the same bits on every machine), and error
 * messages that carry line and column. */
#include "scene.h"

#include <math.h>
#include <string.h>

/* ================================================================ lines and tokens */

void om__line_init(om__line *l, const char *text, size_t len, bool strict)
{
    memset(l, 0, sizeof *l);
    l->text = text;
    l->len = text ? len : 0;
    l->strict = strict;
    /* Editors on some systems start UTF-8 files with a byte-order mark: skip it. */
    if (l->len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0) l->next = 3;
}

bool om__line_next(om__line *l)
{
    if (l->next >= l->len) return false;
    size_t i = l->next, end = l->len;
    bool comment = false;
    l->start = i;
    for (; i < l->len && l->text[i] != '\n'; i++)
        if (!comment && l->text[i] == '#') {
            comment = true;
            end = i;
        }
    l->end = comment ? end : i;
    l->next = i < l->len ? i + 1 : i;
    l->p = l->start;
    if (l->no < UINT32_MAX) l->no++;
    return true;
}

static bool is_sep(char c) { return c == ' ' || c == '\t' || c == '\r'; }
static bool is_ctrl(unsigned char c) { return (c < 0x20 && c != '\t' && c != '\r') || c == 0x7F; }

uint32_t om__col(const om__line *l, size_t at)
{
    size_t c = at - l->start + 1;
    return c > UINT32_MAX ? UINT32_MAX : (uint32_t)c;
}

int om__tok_next(om__line *l, om__tok *t)
{
    const char *s = l->text;
    size_t i = l->p;
    while (i < l->end && is_sep(s[i])) i++;
    t->at = i;
    t->len = 0;
    t->col = om__col(l, i);
    if (i >= l->end) {
        l->p = i;
        return 0;
    }
    size_t b = i;
    for (; i < l->end && !is_sep(s[i]); i++)
        if (l->strict && is_ctrl((unsigned char)s[i])) {
            t->at = i;
            t->len = 1;
            t->col = om__col(l, i);
            l->p = i;
            return -1;
        }
    t->len = i - b;
    l->p = i;
    return 1;
}

int om__tok_peek(const om__line *l, om__tok *t)
{
    om__line copy = *l;
    return om__tok_next(&copy, t);
}

uint32_t om__line_end_col(const om__line *l)
{
    size_t e = l->end;
    while (e > l->start && is_sep(l->text[e - 1])) e--;
    return om__col(l, e);
}

/* Our own strlen: the engine links against nothing but mem* and a few libm names. */
bool om__tok_is(const char *text, const om__tok *t, const char *word)
{
    size_t i = 0;
    for (; i < t->len; i++)
        if (word[i] == '\0' || text[t->at + i] != word[i]) return false;
    return word[i] == '\0';
}


bool om__numlike(const char *s, size_t n)
{
    return n > 0 && (om__is_digit(s[0]) || s[0] == '+' || s[0] == '-' || s[0] == '.');
}

/* ================================================================ numbers */

bool om__num(const char *s, size_t n, double *out)
{
    static const double p10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                   1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                   1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    const int64_t sat = 1000000000;   /* exponents saturate here; the result is 0 or inf */
    size_t i = 0;
    bool neg = false, any = false;
    uint64_t m = 0;
    int nd = 0;            /* significant digits kept in m (at most 19: < 2^64) */
    int64_t e10 = 0;
    if (i < n && (s[i] == '+' || s[i] == '-')) neg = s[i++] == '-';
    for (; i < n && om__is_digit(s[i]); i++) {
        any = true;
        if (nd < 19) {
            if (m || s[i] != '0') { m = m * 10 + (uint64_t)(s[i] - '0'); nd++; }
        } else if (e10 < sat) {
            e10++;         /* a digit beyond the 19 we keep still scales the value */
        }
    }
    if (i < n && s[i] == '.') {
        for (i++; i < n && om__is_digit(s[i]); i++) {
            any = true;
            if (nd < 19) {
                if (m || s[i] != '0') { m = m * 10 + (uint64_t)(s[i] - '0'); nd++; }
                if (e10 > -sat) e10--;
            }
        }
    }
    if (!any) return false;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        bool eneg = false;
        int64_t e = 0;
        i++;
        if (i < n && (s[i] == '+' || s[i] == '-')) eneg = s[i++] == '-';
        if (i >= n || !om__is_digit(s[i])) return false;
        for (; i < n && om__is_digit(s[i]); i++)
            if (e < sat) e = e * 10 + (s[i] - '0');
        e10 += eneg ? -e : e;
    }
    if (i != n) return false;
    double v = (double)m;
    if (m != 0) {
        /* 19 digits are below 1e19, so beyond +-400 the result is inf or 0 anyway. */
        if (e10 > 400) e10 = 400;
        if (e10 < -400) e10 = -400;
        for (; e10 > 22; e10 -= 22) v *= 1e22;
        for (; e10 < -22; e10 += 22) v /= 1e22;
        v = e10 >= 0 ? v * p10[e10] : v / p10[-e10];
    }
    *out = neg ? -v : v;
    return true;
}

/* ================================================================ messages */

om__str om__perr(om_diag *d, om_status st, const char *file, uint32_t line, uint32_t col,
                 char *scratch, size_t cap)
{
    om__str s = om__diag_begin(d, st, scratch, cap);
    if (d) {
        d->line = line;
        d->col = col;
    }
    if (file) {
        om__str_s(&s, file);
        om__str_s(&s, ": ");
    }
    om__str_s(&s, "line ");
    om__str_u(&s, line);
    om__str_s(&s, ", col ");
    om__str_u(&s, col);
    om__str_s(&s, ": ");
    return s;
}

void om__str_tok(om__str *s, const char *p, size_t n)
{
    char buf[40];
    size_t k = 0;
    for (size_t i = 0; i < n && i < 32; i++) {
        unsigned char c = (unsigned char)p[i];
        buf[k++] = c < 0x20 || c >= 0x7F || c == '\'' ? '?' : (char)c;
    }
    if (n > 32) { buf[k++] = '.'; buf[k++] = '.'; buf[k++] = '.'; }
    buf[k] = '\0';
    om__str_s(s, "'");
    om__str_s(s, buf);
    om__str_s(s, "'");
}
