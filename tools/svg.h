/* svg.h — charts as SVG files written by ombra itself: scatter series with lines, log
 * or linear axes with labelled ticks, a legend, and a dashed Pareto front per series
 * (the points no other point of the series beats on both axes, both minimised). */
#ifndef OM_SVG_H
#define OM_SVG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

typedef struct svg_series {
    const char *name;
    const double *x, *y;
    size_t n;
    const char *const *labels;   /* per point, may be NULL */
} svg_series;

typedef struct svg_chart {
    const char *title, *xlabel, *ylabel;
    bool logx, logy, pareto, lines;
} svg_chart;

/* Writes a whole SVG document. Points with a non-positive coordinate on a log axis
 * are drawn at the axis' floor. Returns false on a write error. */
bool svg_write(FILE *f, const svg_chart *c, const svg_series *s, size_t ns);

/* Writes text with &, <, > and " escaped. */
void svg_escape(FILE *f, const char *text);

#endif
