/* report.h — what the files of `ombra report` share: a CSV read whole by its header's
 * column names (so a column added to bench.csv moves nothing), and tables written
 * from it with human headers and numbers in a unit. The page itself is report.c's. */
#ifndef OM_REPORT_H
#define OM_REPORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

typedef struct rcsv {
    char *text;          /* the file, its commas and newlines cut to NULs */
    char **cell;         /* rows x cols; a short row's missing cells are "" */
    size_t rows, cols;   /* rows: data rows, the header not counted */
    char **head;
} rcsv;

/* Reads a CSV; false (nothing to free) when it is missing or empty. */
bool rcsv_load(rcsv *c, const char *path);
void rcsv_free(rcsv *c);
/* The column named `name`, or -1. */
int rcsv_col(const rcsv *c, const char *name);
/* Row r's cell in the column named `name`; "" when there is no such column. */
const char *rcsv_get(const rcsv *c, size_t r, const char *name);
double rcsv_num(const rcsv *c, size_t r, const char *name);

/* How a table cell reads: as it is, an integer with separators, ms, a share in
 * percent, WxH from width and height, min-max of two ms columns. */
typedef enum rkind { R_TEXT, R_INT, R_MS, R_SHARE, R_SIZE, R_RANGE } rkind;
typedef struct rcol {
    const char *csv;     /* the column (R_SIZE: width; R_RANGE: the min's) */
    const char *head;    /* the header a reader sees, unit included */
    rkind kind;
    const char *csv2;    /* R_SIZE: height; R_RANGE: the max's */
} rcol;

/* A table of the rows for which keep(c, r, user) holds (NULL: every row), in a box
 * of its own that scrolls sideways when the window is narrow. */
void report_table(FILE *f, const rcsv *c, const rcol *cols, size_t ncols,
                  bool (*keep)(const rcsv *c, size_t r, const void *user), const void *user);

/* Pictures (report.c). A mask as grey RGB (lit light, shadowed dark, background
 * black) and an RGB image, each cut to the crop x crop window at (x0, y0) of a W-wide
 * image; an image as a PNG data URI, shown zoom times larger; a yellow frame just
 * outside a window, so its crops can be found on the full frame. */
void report_mask_rgb(const uint8_t *mask, uint32_t W, uint32_t x0, uint32_t y0, uint32_t crop, uint8_t *rgb);
void report_crop_rgb(const uint8_t *full, uint32_t W, uint32_t x0, uint32_t y0, uint32_t crop, uint8_t *rgb);
void report_img(FILE *f, const uint8_t *rgb, uint32_t w, uint32_t h, uint32_t zoom, const char *alt);
void report_outline(uint8_t *rgb, uint32_t W, uint32_t H, uint32_t x0, uint32_t y0, uint32_t crop);

/* The stability section (report_stability.c): per case of DIR's stability.csv, a strip
 * of small charts of each method's mismatch share over the frames and the crops of
 * the frame where the method that flickers most flickers most (re-rendered from
 * tests/stability/CASE.scene when it is there). */
void report_stability(FILE *f, const rcsv *sc);

/* The equal-memory section (report_memory.c): per budget of 64 KiB to 16 MiB, each
 * method's best setting that fits, its mismatch share and time (medians of `runs`
 * frames), as a chart and a table. Returns 0, or the exit status of a failure. */
int report_memory(FILE *f, int runs);

/* The small-machines section (report_machines.c), from CROSS/m4.csv and
 * CROSS/m4-size.csv as make cross-test writes them; a line naming that command for
 * each file that is not there. */
void report_machines(FILE *f, const char *cross);

#endif
