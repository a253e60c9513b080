/* hiz.h — between raster.c and hiz.c (not for other parts of the engine, which use
 * om__hiz_words, om__hiz_clear and the *_hiz entry points of raster.h): which
 * triangles may take the coarse depth, its fill, and the pieces of raster.c's fill
 * that it draws rows with. */
#ifndef OMBRA_RASTER_HIZ_H
#define OMBRA_RASTER_HIZ_H

#include "raster.h"

/* Triangles whose box holds this many texels may take the tiles; smaller ones cost
 * less drawn plainly than their tiles' tests. */
#define OM__HIZ_BIG 4096

static inline bool om__hiz_big(const om__rtri *t)
{
    return (int64_t)(t->maxx - t->minx + 1) * (t->maxy - t->miny + 1) >= OM__HIZ_BIG;
}

/* Whether target tg may use a coarse depth: its tiles are shared with no other
 * target (see om__hiz_words in raster.h). */
bool om__hiz_fits(const om_target *tg);

/* Fills t (bounds, edges and om__rtri_zplane set; depths z) through the tiles of
 * `hiz` when its plane is moderate and some row of its box is hot; false, having
 * drawn nothing, when it should take the plain fill instead. */
bool om__hiz_fill(const om_raster *r, uint32_t *hiz, om__rtri *t, const uint32_t z[3]);

/* raster.c's fill, for hiz.c: a row's covered run at pixel centres (edge values E
 * at the box's first column, steps a column; false: none), the depth test along a
 * row, and the same two on a rectilinear grid (cross: each edge's crossing, searched
 * again when `fresh`). */
bool om__fill_row_span(const int64_t E[3], const int64_t step[3], int64_t w, int64_t *lo, int64_t *hi);
void om__fill_depth_row(const om__rtri *t, const om_target *tg, int32_t y, int32_t x0, int32_t x1);
void om__fill_grid_span(const om_raster *r, const om__rtri *t, int32_t y, int32_t cross[3], bool fresh,
                        int32_t *lo, int32_t *hi);
void om__fill_grid_row(const om_raster *r, const om__rtri *t, int32_t y, int32_t lo, int32_t hi);

#endif
