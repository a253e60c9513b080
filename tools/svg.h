/* svg.h — charts as SVG written by ombra itself: scatter series with optional lines,
 * log or linear axes whose ticks read in the data's unit (ms, KiB, %), each point
 * labelled with its setting where there is room (a leader line when it has to move
 * away), a horizontal whisker for a point's spread, and one Pareto front over all
 * series (the points no other point beats on both axes, both minimised). */
#ifndef OM_SVG_H
#define OM_SVG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

/* How an axis' ticks read. SVG_SHARE: values are fractions, shown as percent. */
typedef enum svg_unit { SVG_PLAIN, SVG_MS, SVG_BYTES, SVG_SHARE } svg_unit;

typedef struct svg_series {
    const char *name;
    const double *x, *y;
    size_t n;
    const char *const *labels;   /* per point, may be NULL: drawn beside the point */
    const double *xlo, *xhi;     /* per point spread along x (a whisker), may be NULL */
} svg_series;

typedef struct svg_chart {
    const char *title, *xlabel, *ylabel;
    bool logx, logy, pareto, lines;
    svg_unit xunit, yunit;
} svg_chart;

/* Writes a whole SVG document (an XML declaration first). On a log axis, points at 0
 * (or below) sit on a row of their own labelled 0 under the axis' lowest decade.
 * Returns false on a write error. */
bool svg_write(FILE *f, const svg_chart *c, const svg_series *s, size_t ns);
/* The same without the XML declaration: an <svg> element inside a page. */
bool svg_write_inline(FILE *f, const svg_chart *c, const svg_series *s, size_t ns);

/* A tick's or a cell's text: "12 ms", "64 KiB", "0.05%", "1,000". */
void svg_format(char *buf, size_t n, double v, svg_unit u);

/* Writes text with &, <, > and " escaped. */
void svg_escape(FILE *f, const char *text);

#endif
