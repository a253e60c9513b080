/* svg.c — see svg.h. Layout: 720 x 440, plot area inset for the axes and the legend. */
#include "svg.h"

#include <math.h>
#include <string.h>

#define WIDTH 720
#define HEIGHT 440
#define LEFT 78
#define RIGHT 170
#define TOP 40
#define BOTTOM 58

static const char *const colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                     "#8c564b", "#e377c2", "#17becf"};

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

typedef struct axis { double lo, hi; bool log; } axis;

static double tr(const axis *a, double v)
{
    if (a->log) {
        double floor_v = pow(10.0, a->lo);
        return log10(v > floor_v ? v : floor_v);
    }
    return v;
}

static void fit(axis *a, const svg_series *s, size_t ns, bool is_x)
{
    double lo = INFINITY, hi = -INFINITY;
    for (size_t k = 0; k < ns; k++)
        for (size_t i = 0; i < s[k].n; i++) {
            double v = is_x ? s[k].x[i] : s[k].y[i];
            if (a->log && !(v > 0)) continue;
            if (v < lo) lo = v;
            if (v > hi) hi = v;
        }
    if (!(lo <= hi)) { lo = a->log ? 1e-3 : 0; hi = a->log ? 1 : 1; }
    if (a->log) {
        a->lo = floor(log10(lo));
        a->hi = ceil(log10(hi));
        if (a->hi <= a->lo) a->hi = a->lo + 1;
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

static void tick_label(char *buf, size_t n, double v)
{
    if (v != 0 && (fabs(v) >= 1e5 || fabs(v) < 1e-3)) snprintf(buf, n, "%.0e", v);
    else snprintf(buf, n, "%g", v);
}

static void ticks(FILE *f, const axis *a, bool is_x)
{
    const double x0 = LEFT, x1 = WIDTH - RIGHT, y0 = HEIGHT - BOTTOM, y1 = TOP;
    char buf[32];
    int steps = a->log ? (int)(a->hi - a->lo) : 5;
    for (int i = 0; i <= steps; i++) {
        double v = a->log ? pow(10.0, a->lo + i) : a->lo + (a->hi - a->lo) * i / steps;
        tick_label(buf, sizeof buf, v);
        if (is_x) {
            double x = px(a, v, x0, x1);
            fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", x, y0, x, y1);
            fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"11\">%s</text>\n", x, y0 + 16, buf);
        } else {
            double y = px(a, v, y0, y1);
            fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", x0, y, x1, y);
            fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\" font-size=\"11\">%s</text>\n", x0 - 6, y + 4, buf);
        }
    }
}

bool svg_write(FILE *f, const svg_chart *c, const svg_series *s, size_t ns)
{
    axis ax = {0, 1, c->logx}, ay = {0, 1, c->logy};
    fit(&ax, s, ns, true);
    fit(&ay, s, ns, false);
    const double x0 = LEFT, x1 = WIDTH - RIGHT, y0 = HEIGHT - BOTTOM, y1 = TOP;
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
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
    fprintf(f, "%s</text>\n", c->logx ? " (log)" : "");
    fprintf(f, "<text x=\"16\" y=\"%d\" text-anchor=\"middle\" font-size=\"12\" transform=\"rotate(-90 16 %d)\">",
            (TOP + HEIGHT - BOTTOM) / 2, (TOP + HEIGHT - BOTTOM) / 2);
    svg_escape(f, c->ylabel);
    fprintf(f, "%s</text>\n", c->logy ? " (log)" : "");
    for (size_t k = 0; k < ns; k++) {
        const char *col = colors[k % (sizeof colors / sizeof colors[0])];
        if (c->lines && s[k].n > 1) {
            fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" points=\"", col);
            for (size_t i = 0; i < s[k].n; i++)
                fprintf(f, "%.1f,%.1f ", px(&ax, s[k].x[i], x0, x1), px(&ay, s[k].y[i], y0, y1));
            fprintf(f, "\"/>\n");
        }
        if (c->pareto && s[k].n > 1) {
            /* sweep by x ascending, keep points that lower the best y so far */
            size_t order[256], n = s[k].n < 256 ? s[k].n : 256;
            for (size_t i = 0; i < n; i++) order[i] = i;
            for (size_t i = 1; i < n; i++)
                for (size_t j = i; j > 0 && s[k].x[order[j - 1]] > s[k].x[order[j]]; j--) {
                    size_t t = order[j]; order[j] = order[j - 1]; order[j - 1] = t;
                }
            double best = INFINITY;
            fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-dasharray=\"5,3\" points=\"", col);
            for (size_t i = 0; i < n; i++) {
                size_t p = order[i];
                if (s[k].y[p] < best) {
                    best = s[k].y[p];
                    fprintf(f, "%.1f,%.1f ", px(&ax, s[k].x[p], x0, x1), px(&ay, s[k].y[p], y0, y1));
                }
            }
            fprintf(f, "\"/>\n");
        }
        for (size_t i = 0; i < s[k].n; i++) {
            fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"%s\">",
                    px(&ax, s[k].x[i], x0, x1), px(&ay, s[k].y[i], y0, y1), col);
            fprintf(f, "<title>");
            svg_escape(f, s[k].name);
            if (s[k].labels && s[k].labels[i]) { fputc(' ', f); svg_escape(f, s[k].labels[i]); }
            fprintf(f, ": %g, %g</title></circle>\n", s[k].x[i], s[k].y[i]);
        }
        double ly = TOP + 14 + 18.0 * (double)k;
        fprintf(f, "<circle cx=\"%d\" cy=\"%.1f\" r=\"5\" fill=\"%s\"/>\n", WIDTH - RIGHT + 16, ly - 4, col);
        fprintf(f, "<text x=\"%d\" y=\"%.1f\" font-size=\"12\">", WIDTH - RIGHT + 26, ly);
        svg_escape(f, s[k].name);
        fprintf(f, "</text>\n");
    }
    if (c->pareto)
        fprintf(f, "<text x=\"%d\" y=\"%d\" font-size=\"10\" fill=\"#555\">dashed: Pareto front</text>\n",
                WIDTH - RIGHT + 10, HEIGHT - BOTTOM);
    if (c->logy)
        fprintf(f, "<text x=\"%d\" y=\"%d\" font-size=\"10\" fill=\"#555\">on the bottom edge: 0</text>\n",
                WIDTH - RIGHT + 10, HEIGHT - BOTTOM - 14);
    fprintf(f, "</svg>\n");
    return !ferror(f);
}
