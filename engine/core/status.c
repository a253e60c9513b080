/* status.c — status names, the om_diag message builder, and the frame hash.
 * Messages are built with a tiny bounded formatter because the engine has no stdio. */
#include "core.h"

#include <string.h>

const char *om_version(void) { return OMBRA_VERSION_STRING; }

const char *om_status_str(om_status s)
{
    switch (s) {
    case OM_OK: return "ok";
    case OM_E_BUDGET: return "budget exceeded";
    case OM_E_INVALID: return "invalid argument";
    case OM_E_PARSE: return "parse error";
    case OM_E_RANGE: return "value out of range";
    case OM_E_NOTFOUND: return "not found";
    case OM_E_IO: return "input/output error";
    default: return "unknown status";
    }
}

void om__str_init(om__str *s, char *buf, size_t cap)
{
    s->buf = buf;
    s->cap = cap;
    s->len = 0;
    if (cap) buf[0] = '\0';
}

void om__str_s(om__str *s, const char *text)
{
    while (*text && s->len + 1 < s->cap) s->buf[s->len++] = *text++;
    if (s->cap) s->buf[s->len] = '\0';
}

void om__str_u(om__str *s, uint64_t v)
{
    char tmp[24];
    int n = 0;
    do { tmp[n++] = (char)('0' + v % 10u); v /= 10u; } while (v);
    while (n > 0 && s->len + 1 < s->cap) s->buf[s->len++] = tmp[--n];
    if (s->cap) s->buf[s->len] = '\0';
}

void om__str_i(om__str *s, int64_t v)
{
    if (v < 0) {
        om__str_s(s, "-");
        om__str_u(s, (uint64_t)0 - (uint64_t)v);
    } else {
        om__str_u(s, (uint64_t)v);
    }
}

void om__str_f(om__str *s, double v, int decimals)
{
    if (v != v) { om__str_s(s, "nan"); return; }
    if (v < 0) { om__str_s(s, "-"); v = -v; }
    if (v > 1e18) { om__str_s(s, "inf"); return; }
    double scale = 1.0;
    for (int i = 0; i < decimals; i++) scale *= 10.0;
    uint64_t q = (uint64_t)(v * scale + 0.5);
    uint64_t ip = q / (uint64_t)scale, fp = q % (uint64_t)scale;
    om__str_u(s, ip);
    if (decimals > 0) {
        char tmp[24];
        om__str_s(s, ".");
        for (int i = decimals - 1; i >= 0; i--) { tmp[i] = (char)('0' + fp % 10u); fp /= 10u; }
        tmp[decimals] = '\0';
        om__str_s(s, tmp);
    }
}

om__str om__diag_begin(om_diag *d, om_status st, char *scratch, size_t scratch_cap)
{
    om__str s;
    if (d) {
        d->status = st;
        om__str_init(&s, d->msg, sizeof d->msg);
    } else {
        om__str_init(&s, scratch, scratch_cap);
    }
    return s;
}

om_status om__fail(om_diag *d, om_status st, const char *msg)
{
    if (d) {
        om__str s;
        d->status = st;
        om__str_init(&s, d->msg, sizeof d->msg);
        om__str_s(&s, msg);
    }
    return st;
}

