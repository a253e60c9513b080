/* svg.c — see svg.h. Layout: 800 x 460, the plot inset for the axes on the left and
 * below and the legend on the right. Point labels are placed greedily, nearest spot
 * first, never over another label: a dense cluster gets leader lines rather than a
 * pile of text, and a label with no free spot left is not drawn but listed under the
 * plot. A series' colour and marker follow the method's place in the registry (so a
 * method looks the same on every chart); points at 0 on a log axis sit in a lane per
 * series, so exact methods at the same time stay apart. */
#include "svg.h"
#include "ombra.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define WIDTH 800
#define HEIGHT 460
#define LEFT 78
#define RIGHT 190
#define TOP 40
#define BOTTOM 58
#define LABEL_FONT 10
#define MAX_BOXES 1024
#define NSTYLE 10
#define LANE 9.0   /* px between the zero row's lanes */

static const char *const colors[NSTYLE] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                           "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};

/* A series' style: the method's index in the registry, else its place on the chart. */
static size_t style_of(const svg_series *s, size_t k)
{
    const om_method *m = om_method_find(s[k].name);
    for (size_t i = 0; m && i < om_method_count(); i++)
        if (om_method_at(i) == m) return i % NSTYLE;
    return k % NSTYLE;
}

/* A marker: five shapes, filled, then the same hollow. */
static void marker(FILE *f, size_t style, double X, double Y, const char *cls)
{
    const char *col = colors[style];
    const double r = 4.6;
    fprintf(f, "<path class=\"%s\" fill=\"%s\" stroke=\"%s\" stroke-width=\"%s\" d=\"", cls,
            style < 5 ? col : "white", col, style < 5 ? "0.6" : "1.8");
    switch (style % 5) {
    case 0: fprintf(f, "M%.1f %.1fa%.1f %.1f 0 1 0 %.1f 0a%.1f %.1f 0 1 0 %.1f 0Z", X - r * 0.85, Y, r * 0.85,
                    r * 0.85, 2 * r * 0.85, r * 0.85, r * 0.85, -2 * r * 0.85); break;
    case 1: fprintf(f, "M%.1f %.1fh%.1fv%.1fh%.1fZ", X - r * 0.75, Y - r * 0.75, 1.5 * r, 1.5 * r, -1.5 * r); break;
    case 2: fprintf(f, "M%.1f %.1fL%.1f %.1fL%.1f %.1fZ", X, Y - r, X + r, Y + r * 0.75, X - r, Y + r * 0.75); break;
    case 3: fprintf(f, "M%.1f %.1fL%.1f %.1fL%.1f %.1fL%.1f %.1fZ", X, Y - r * 1.1, X + r, Y, X, Y + r * 1.1, X - r, Y); break;
    default: fprintf(f, "M%.1f %.1fL%.1f %.1fL%.1f %.1fZ", X, Y + r, X + r, Y - r * 0.75, X - r, Y - r * 0.75); break;
    }
    fprintf(f, "\">");
}

void svg_escape(FILE *f, const char *t)
{
    for (; *t; t++) {
        if (*t == '&') fputs("&amp;", f);
        else if (*t == '<') fputs("&lt;", f);
        else if (*t == '>') fputs("&gt;", f);
        else if (*t == '"') fputs("&quot;", f);
        else fputc(*t, f);
    }
}

/* An integer with thousands separators: 1,234,567. */
static void thousands(char *buf, size_t n, double v)
{
    char digits[32];
    snprintf(digits, sizeof digits, "%.0f", fabs(v));
    size_t len = strlen(digits), o = 0;
    if (v < 0 && o + 1 < n) buf[o++] = '-';
    for (size_t i = 0; i < len && o + 2 < n; i++) {
        buf[o++] = digits[i];
        if ((len - 1 - i) % 3 == 0 && i + 1 < len) buf[o++] = ',';
    }
    buf[o] = 0;
}

/* %g, but never in e-notation for the ranges charts show */
static void plain(char *buf, size_t n, double v)
{
    if (fabs(v) >= 1000 && fabs(v - floor(v)) < 1e-9) thousands(buf, n, v);
    else if (fabs(v) >= 10 || v == 0) snprintf(buf, n, "%.0f", v);
    else if (fabs(v) >= 1) snprintf(buf, n, "%.3g", v);
    else {
        int dec = (int)ceil(-log10(fabs(v))) + 1;   /* two significant digits */
        snprintf(buf, n, "%.*f", dec > 8 ? 8 : dec, v);
        /* drop trailing zeros: 0.050 -> 0.05 */
        char *e = buf + strlen(buf) - 1;
        while (e > buf && *e == '0' && strchr(buf, '.')) *e-- = 0;
        if (*e == '.') *e = 0;
    }
}

/* s after buf's text where the whole of it fits in n bytes (no format: gcc cannot bound
 * a number's length through one and warns at -O3). */
static void put_after(char *buf, size_t n, const char *s)
{
    const size_t l = strlen(buf), k = strlen(s);
    if (l + k < n) memcpy(buf + l, s, k + 1);
}

void svg_format(char *buf, size_t n, double v, svg_unit u)
{
    if (u == SVG_SHARE) {
        plain(buf, n, 100 * v);
        put_after(buf, n, "%");
    } else if (u == SVG_MS) {
        plain(buf, n, v);
        put_after(buf, n, " ms");
    } else if (u == SVG_BYTES) {
        static const char *const units[] = {" B", " KiB", " MiB", " GiB"};
        int k = 0;
        while (fabs(v) >= 1024 && k < 3) { v /= 1024; k++; }
        plain(buf, n, v);
        put_after(buf, n, units[k]);
    } else {
        plain(buf, n, v);
    }
}

/* lo, hi: the axis' range, in log10 units on a log axis. zero: a log axis carries a row
 * for the values at 0, at zpos, under the decades from dlo up (a gap between). */
typedef struct axis { double lo, hi, dlo, zpos; bool log, zero; svg_unit unit; } axis;

static double tr(const axis *a, double v)
{
    if (a->log) return v > 0 ? log10(v) : a->zpos;
    return v;
}

static void fit(axis *a, const svg_series *s, size_t ns, bool is_x)
{
    double lo = INFINITY, hi = -INFINITY;
    a->zero = false;
    for (size_t k = 0; k < ns; k++)
        for (size_t i = 0; i < s[k].n; i++) {
            double v = is_x ? s[k].x[i] : s[k].y[i];
            if (isnan(v)) continue;   /* a missing point: no y, its x still on the axis */
            if (a->log && !(v > 0)) { a->zero = true; continue; }
            if (v < lo) lo = v;
            if (v > hi) hi = v;
            if (is_x && s[k].xlo && s[k].xlo[i] > 0 && s[k].xlo[i] < lo) lo = s[k].xlo[i];
            if (is_x && s[k].xhi && s[k].xhi[i] > hi) hi = s[k].xhi[i];
        }
    if (!(lo <= hi)) { lo = a->log ? 1e-3 : 0; hi = 1; }
    if (a->log) {
        /* the data's own range, padded a little: whole decades left half a chart empty */
        /* room above and below the outermost points for their labels */
        double l = log10(lo), h = log10(hi), pad = (h - l) * 0.08;
        if (pad < 0.1) pad = 0.1;
        a->lo = a->dlo = l - pad;
        a->hi = h + pad;
        if (a->zero) {
            double gap = (a->hi - a->lo) * 0.10;
            a->zpos = a->lo - gap;
            a->lo = a->zpos - gap * 0.5;
        }
    } else {
        double span = hi - lo;
        if (span <= 0) span = fabs(hi) > 0 ? fabs(hi) : 1;
        double step = pow(10.0, floor(log10(span / 5)));
        a->lo = floor((lo < 0 ? lo : 0) / step) * step;
        a->hi = ceil(hi / step) * step;
        if (a->hi <= a->lo) a->hi = a->lo + step;
    }
}

static double px(const axis *a, double v, double p0, double p1)
{
    return p0 + (tr(a, v) - a->lo) / (a->hi - a->lo) * (p1 - p0);
}

/* The tick values of an axis: on a log axis 1-2-5 in each decade (fewer as the range
 * widens; powers of two for bytes), five steps on a linear one. */
static int tick_values(const axis *a, double *out, int max)
{
    int n = 0;
    if (!a->log) {
        for (int i = 0; i <= 5 && n < max; i++) out[n++] = a->lo + (a->hi - a->lo) * i / 5;
        return n;
    }
    double lo = a->dlo, span = a->hi - a->dlo;
    if (a->unit == SVG_BYTES) {
        double l2 = lo / log10(2.0), h2 = a->hi / log10(2.0);
        int step = 1;
        while ((h2 - l2) / step > 7) step *= 2;
        for (int e = (int)ceil(l2); e <= (int)floor(h2) && n < max; e++)
            if (e % step == 0) out[n++] = pow(2.0, e);
        return n;
    }
    static const double m125[] = {1, 2, 5}, m13[] = {1, 3}, m1[] = {1};
    const double *m = span <= 3.5 ? m125 : span <= 6 ? m13 : m1;
    int nm = span <= 3.5 ? 3 : span <= 6 ? 2 : 1;
    for (int e = (int)floor(lo) - 1; e <= (int)ceil(a->hi) && n < max; e++)
        for (int j = 0; j < nm && n < max; j++) {
            double v = m[j] * pow(10.0, e), t = log10(v);
            if (t >= lo - 1e-9 && t <= a->hi + 1e-9) out[n++] = v;
        }
    return n;
}

static void ticks(FILE *f, const axis *a, bool is_x)
{
    const double x0 = LEFT, x1 = WIDTH - RIGHT, y0 = HEIGHT - BOTTOM, y1 = TOP;
    char buf[48];
    double v[64];
    int n = tick_values(a, v, 63);
    if (a->log && a->zero) v[n++] = 0;
    for (int i = 0; i < n; i++) {
        /* a tick has no room for 50,000,000: 50M */
        if (a->unit == SVG_PLAIN && fabs(v[i]) >= 1e4) {
            double m = fabs(v[i]) >= 1e6 ? 1e6 : 1e3;
            plain(buf, sizeof buf - 1, v[i] / m);
            strcat(buf, m > 1e3 ? "M" : "K");
        } else {
            svg_format(buf, sizeof buf, v[i], a->unit);
        }
        if (is_x) {
            double x = px(a, v[i], x0, x1);
            fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n", x, y0, x, y1);
            fprintf(f, "<text class=\"tick\" x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"11\">%s</text>\n",
                    x, y0 + 16, buf);
        } else {
            double y = px(a, v[i], y0, y1);
            fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n", x0, y, x1, y);
            fprintf(f, "<text class=\"tick\" x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\" font-size=\"11\">%s</text>\n",
                    x0 - 6, y + 4, buf);
        }
    }
    if (a->log && a->zero) {   /* the break between the zero row and the decades */
        if (is_x) {
            double x = (px(a, 0, x0, x1) + px(a, pow(10.0, a->dlo), x0, x1)) / 2;
            fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#999\" stroke-dasharray=\"2,3\"/>\n",
                    x, y0, x, y1);
        } else {
            double y = (px(a, 0, y0, y1) + px(a, pow(10.0, a->dlo), y0, y1)) / 2;
            fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#999\" stroke-dasharray=\"2,3\"/>\n",
                    x0, y, x1, y);
        }
    }
}

/* What a label must keep clear of: other labels and points, and (softly: given up
 * before a label is) the spread whiskers. */
typedef struct box { double x0, y0, x1, y1; bool soft, text; } box;

static bool overlaps(const box *a, const box *b)
{
    return a->x0 < b->x1 && b->x0 < a->x1 && a->y0 < b->y1 && b->y0 < a->y1;
}

/* Places one label near (x, y): the first of the candidate spots, nearest first, that
 * stays inside the plot and clear of every box so far (then clear of all but the
 * whiskers; then of the other labels only, so a point may be covered but no text);
 * writes it, with a leader line when it sits away from its point. Returns false, and
 * writes nothing, when no spot is clear of the other labels. */
static bool place_label(FILE *f, const char *text, double x, double y, const char *col, box *boxes,
                        size_t *nb)
{
    enum { NDIR = 16, NRING = 24 };
    /* wide enough for the widest sans-serif the page may fall back on */
    const double w = 0.62 * LABEL_FONT * (double)strlen(text) + 2, h = LABEL_FONT + 2;
    for (int pass = 0; pass < 3; pass++)
        for (int ring = 1; ring <= NRING; ring++)
            for (int d = 0; d < NDIR; d++) {
                /* right, left, up, down first; then the diagonals and between */
                static const int order[NDIR] = {0, 8, 12, 4, 14, 2, 10, 6, 15, 1, 13, 3, 9, 7, 11, 5};
                double a = order[d] * 6.283185307179586 / NDIR, dx = cos(a), dy = sin(a);
                double r = 7.0 + 11.0 * (ring - 1), cx = x + dx * r, cy = y + dy * r * 0.8;
                box b;
                /* the box's edge nearest the point sits at the candidate spot */
                b.x0 = dx > 0.3 ? cx : dx < -0.3 ? cx - w : cx - w / 2;
                b.y0 = dy > 0.3 ? cy : dy < -0.3 ? cy - h : cy - h / 2;
                b.x1 = b.x0 + w;
                b.y1 = b.y0 + h;
                b.soft = false;
                b.text = true;
                if (b.x0 < LEFT + 2 || b.x1 > WIDTH - RIGHT - 2 || b.y0 < TOP + 2 || b.y1 > HEIGHT - BOTTOM - 2)
                    continue;
                bool clear = true;
                for (size_t i = 0; i < *nb && clear; i++)
                    clear = (pass >= 1 && boxes[i].soft) || (pass == 2 && !boxes[i].text) || !overlaps(&b, &boxes[i]);
                if (!clear) continue;
                if (ring > 1) {
                    double lx = b.x0 > x ? b.x0 : b.x1 < x ? b.x1 : (b.x0 + b.x1) / 2;
                    double ly = b.y0 > y ? b.y0 : b.y1 < y ? b.y1 : (b.y0 + b.y1) / 2;
                    fprintf(f, "<line class=\"leader\" x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" "
                               "stroke=\"%s\" stroke-width=\"0.6\" opacity=\"0.7\"/>\n", x, y, lx, ly, col);
                }
                /* the baseline a little above the box's bottom: descenders stay inside */
                fprintf(f, "<text class=\"label\" x=\"%.1f\" y=\"%.1f\" font-size=\"%d\" fill=\"%s\">",
                        b.x0 + 1, b.y1 - 3, LABEL_FONT, col);
                svg_escape(f, text);
                fprintf(f, "</text>\n");
                if (*nb < MAX_BOXES) boxes[(*nb)++] = b;
                return true;
            }
    return false;
}

typedef struct pt { double x, y; } pt;

static int cmp_pt(const void *a, const void *b)
{
    const pt *p = a, *q = b;
    return p->x < q->x ? -1 : p->x > q->x ? 1 : p->y < q->y ? -1 : p->y > q->y;
}

/* The front over every series, as a staircase from the top edge to the right one
 * (whatever lies above and right of it is beaten by a point on it), each of its points
 * ringed: a front of one point still shows. */
static void front(FILE *f, const axis *ax, const axis *ay, const svg_series *s, size_t ns)
{
    static pt all[MAX_BOXES];
    size_t n = 0;
    for (size_t k = 0; k < ns; k++)
        for (size_t i = 0; i < s[k].n && n < MAX_BOXES; i++) all[n++] = (pt){s[k].x[i], s[k].y[i]};
    if (n < 1) return;
    qsort(all, n, sizeof all[0], cmp_pt);
    const double x0 = LEFT, x1 = WIDTH - RIGHT, y0 = HEIGHT - BOTTOM, y1 = TOP;
    double best = INFINITY, prev_y = y1;
    fprintf(f, "<polyline class=\"front\" fill=\"none\" stroke=\"#333\" stroke-width=\"2\" "
               "stroke-opacity=\"0.45\" points=\"");
    for (size_t i = 0; i < n; i++) {
        if (!(all[i].y < best)) continue;
        best = all[i].y;
        double X = px(ax, all[i].x, x0, x1), Y = px(ay, all[i].y, y0, y1);
        fprintf(f, "%.1f,%.1f %.1f,%.1f ", X, prev_y, X, Y);
        prev_y = Y;
    }
    fprintf(f, "%.1f,%.1f\"/>\n", x1, prev_y);
    best = INFINITY;
    for (size_t i = 0; i < n; i++) {
        if (!(all[i].y < best)) continue;
        best = all[i].y;
        fprintf(f, "<circle class=\"front\" cx=\"%.1f\" cy=\"%.1f\" r=\"7\" fill=\"none\" stroke=\"#333\" "
                   "stroke-width=\"1.5\" stroke-opacity=\"0.6\"/>\n",
                px(ax, all[i].x, x0, x1), px(ay, all[i].y, y0, y1));
    }
}

/* The legend: each series' marker and name, the front, the whiskers, the marks of
 * points that are missing, and the labels that found no room (as "series: label").
 * Returns where it ends. */
static double legend(FILE *f, const svg_chart *c, const svg_series *s, size_t ns, bool missing)
{
    double ly = TOP + 14;
    for (size_t k = 0; k < ns; k++, ly += 18) {
        marker(f, style_of(s, k), WIDTH - RIGHT + 16, ly - 4, "key");
        fprintf(f, "</path>\n<text x=\"%d\" y=\"%.1f\" font-size=\"12\">", WIDTH - RIGHT + 26, ly);
        svg_escape(f, s[k].name);
        fprintf(f, "</text>\n");
    }
    ly += 8;
    if (c->pareto) {
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#333\" stroke-width=\"2\" "
                   "stroke-opacity=\"0.45\"/>\n", WIDTH - RIGHT + 6, ly - 4, WIDTH - RIGHT + 24, ly - 4);
        fprintf(f, "<circle cx=\"%d\" cy=\"%.1f\" r=\"7\" fill=\"none\" stroke=\"#333\" stroke-width=\"1.5\" "
                   "stroke-opacity=\"0.6\"/>\n", WIDTH - RIGHT + 15, ly - 4);
        fprintf(f, "<text class=\"front-name\" x=\"%d\" y=\"%.1f\" font-size=\"11\">Pareto front (all methods)</text>\n",
                WIDTH - RIGHT + 26, ly);
        ly += 18;
    }
    bool spread = false;
    for (size_t k = 0; k < ns; k++) spread |= s[k].xlo != NULL;
    if (spread) {
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#555\"/>\n", WIDTH - RIGHT + 8,
                ly - 4, WIDTH - RIGHT + 22, ly - 4);
        fprintf(f, "<text x=\"%d\" y=\"%.1f\" font-size=\"11\">min-max of the runs</text>\n", WIDTH - RIGHT + 26, ly);
        ly += 18;
    }
    if (missing) {
        fprintf(f, "<text x=\"%d\" y=\"%.1f\" font-size=\"13\" fill=\"#555\">&#215;</text>\n", WIDTH - RIGHT + 11, ly);
        fprintf(f, "<text x=\"%d\" y=\"%.1f\" font-size=\"11\">no setting fits (line broken)</text>\n",
                WIDTH - RIGHT + 26, ly);
        ly += 18;
    }
    return ly;
}

/* Where point i of series k is drawn: on a log axis a point at 0 sits on the zero row,
 * in its series' lane. */
static double pos_y(const axis *ay, const svg_series *s, size_t k, size_t i, const double *lane)
{
    const double y0 = HEIGHT - BOTTOM, y1 = TOP;
    double Y = px(ay, s[k].y[i], y0, y1);
    return ay->log && !(s[k].y[i] > 0) ? Y + lane[k] : Y;
}

bool svg_write(FILE *f, const svg_chart *c, const svg_series *s, size_t ns)
{
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    return svg_write_inline(f, c, s, ns);
}

bool svg_write_inline(FILE *f, const svg_chart *c, const svg_series *s, size_t ns)
{
    axis ax = {0, 1, 0, 0, c->logx, false, c->xunit}, ay = {0, 1, 0, 0, c->logy, false, c->yunit};
    fit(&ax, s, ns, true);
    fit(&ay, s, ns, false);
    const double x0 = LEFT, x1 = WIDTH - RIGHT, y1 = TOP;
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"chart\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\" font-family=\"sans-serif\">\n", WIDTH, HEIGHT, WIDTH, HEIGHT);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"white\"/>\n", WIDTH, HEIGHT);
    fprintf(f, "<text x=\"%d\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">", (LEFT + WIDTH - RIGHT) / 2);
    svg_escape(f, c->title);
    fprintf(f, "</text>\n");
    ticks(f, &ax, true);
    ticks(f, &ay, false);
    fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"#444\"/>\n",
            LEFT, TOP, WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM);
    fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\" font-size=\"12\">", (LEFT + WIDTH - RIGHT) / 2, HEIGHT - 18);
    svg_escape(f, c->xlabel);
    fprintf(f, "%s</text>\n", c->logx ? " (log scale)" : "");
    fprintf(f, "<text x=\"16\" y=\"%d\" text-anchor=\"middle\" font-size=\"12\" transform=\"rotate(-90 16 %d)\">",
            (TOP + HEIGHT - BOTTOM) / 2, (TOP + HEIGHT - BOTTOM) / 2);
    svg_escape(f, c->ylabel);
    fprintf(f, "%s</text>\n", c->logy ? " (log scale)" : "");
    if (c->pareto) front(f, &ax, &ay, s, ns);
    /* the zero row's lanes: one per series with a point at 0, centred on the row */
    static double lane[64];
    size_t nl = 0, nz = 0;
    for (size_t k = 0; k < ns && k < 64; k++)
        for (size_t i = 0; i < s[k].n; i++)
            if (ay.log && !(s[k].y[i] > 0) && !isnan(s[k].y[i])) { nz++; break; }
    const double step = nz > 1 && LANE * (double)(nz - 1) > 30 ? 30 / (double)(nz - 1) : LANE;
    for (size_t k = 0; k < ns && k < 64; k++) {
        bool z = false;
        for (size_t i = 0; i < s[k].n; i++) z |= ay.log && !(s[k].y[i] > 0) && !isnan(s[k].y[i]);
        lane[k] = z ? ((double)nl++ - (double)(nz - 1) / 2) * step : 0;
    }
    if (ns > 64) ns = 64;
    /* the points first (so labels keep clear of all of them), lines and whiskers under;
     * a line is broken at a missing point, marked by a cross along the top */
    static box boxes[MAX_BOXES];
    size_t nb = 0, nmiss = 0;
    for (size_t k = 0; k < ns; k++) {
        const char *col = colors[style_of(s, k)];
        if (c->lines && s[k].n > 1) {
            bool open = false;
            for (size_t i = 0; i < s[k].n; i++) {
                if (isnan(s[k].y[i])) {
                    if (open) fprintf(f, "\"/>\n");
                    open = false;
                    continue;
                }
                if (!open) fprintf(f, "<polyline class=\"line\" fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" points=\"", col);
                open = true;
                fprintf(f, "%.1f,%.1f ", px(&ax, s[k].x[i], x0, x1), pos_y(&ay, s, k, i, lane));
            }
            if (open) fprintf(f, "\"/>\n");
        }
        bool missing = false;
        for (size_t i = 0; i < s[k].n; i++) {
            double X = px(&ax, s[k].x[i], x0, x1);
            if (isnan(s[k].y[i])) {
                double Y = y1 + 9 + 14.0 * (double)nmiss;
                char bx[48];
                svg_format(bx, sizeof bx, s[k].x[i], c->xunit);
                fprintf(f, "<text class=\"missing\" x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"12\" "
                           "fill=\"%s\">&#215;<title>", X, Y + 4, col);
                svg_escape(f, s[k].name);
                fprintf(f, ": no setting fits at %s</title></text>\n", bx);
                if (nb < MAX_BOXES) boxes[nb++] = (box){X - 4.5, Y - 4.5, X + 4.5, Y + 4.5, false, false};
                missing = true;
                continue;
            }
            double Y = pos_y(&ay, s, k, i, lane);
            if (s[k].xlo && s[k].xhi) {
                double a = px(&ax, s[k].xlo[i], x0, x1), b = px(&ax, s[k].xhi[i], x0, x1);
                fprintf(f, "<path class=\"spread\" stroke=\"%s\" stroke-width=\"1.2\" fill=\"none\" "
                           "d=\"M%.1f %.1fH%.1fM%.1f %.1fV%.1fM%.1f %.1fV%.1f\"/>\n",
                        col, a, Y, b, a, Y - 3, Y + 3, b, Y - 3, Y + 3);
                if (nb < MAX_BOXES) boxes[nb++] = (box){a - 1, Y - 3.5, b + 1, Y + 3.5, true, false};
            }
            if (nb < MAX_BOXES) boxes[nb++] = (box){X - 4.5, Y - 4.5, X + 4.5, Y + 4.5, false, false};
        }
        nmiss += missing;
    }
    for (size_t k = 0; k < ns; k++) {
        for (size_t i = 0; i < s[k].n; i++) {
            if (isnan(s[k].y[i])) continue;
            marker(f, style_of(s, k), px(&ax, s[k].x[i], x0, x1), pos_y(&ay, s, k, i, lane), "point");
            char bx[48], by[48];
            svg_format(bx, sizeof bx, s[k].x[i], c->xunit);
            svg_format(by, sizeof by, s[k].y[i], c->yunit);
            fprintf(f, "<title>");
            svg_escape(f, s[k].name);
            if (s[k].labels && s[k].labels[i]) { fputc(' ', f); svg_escape(f, s[k].labels[i]); }
            fprintf(f, ": %s, %s</title></path>\n", bx, by);
        }
    }
    /* labels after every point is known, series by series; those with no room left
     * are listed under the legend */
    static char unplaced[MAX_BOXES][64];
    size_t nu = 0;
    for (size_t k = 0; k < ns; k++) {
        const char *col = colors[style_of(s, k)];
        for (size_t i = 0; s[k].labels && i < s[k].n; i++)
            if (s[k].labels[i] && s[k].labels[i][0] && !isnan(s[k].y[i]) &&
                !place_label(f, s[k].labels[i], px(&ax, s[k].x[i], x0, x1), pos_y(&ay, s, k, i, lane), col,
                             boxes, &nb) && nu < MAX_BOXES)
                snprintf(unplaced[nu++], sizeof unplaced[0], "%s %s", s[k].name, s[k].labels[i]);
    }
    double ly = legend(f, c, s, ns, nmiss > 0);
    if (nu) {
        fprintf(f, "<text class=\"label-note\" x=\"%d\" y=\"%.1f\" font-size=\"10\">no room to label:</text>\n",
                WIDTH - RIGHT + 8, ly);
        for (size_t i = 0; i < nu && ly + 13 < HEIGHT - 4; i++) {
            ly += 13;
            fprintf(f, "<text class=\"label-note\" x=\"%d\" y=\"%.1f\" font-size=\"10\">", WIDTH - RIGHT + 8, ly);
            svg_escape(f, unplaced[i]);
            fprintf(f, "</text>\n");
        }
    }
    fprintf(f, "</svg>\n");
    return !ferror(f);
}
