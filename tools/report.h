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

/* The equal-memory section (report_memory.c), in two steps, so the summary at the top
 * of the page can use what it measured: report_memory_measure renders, per scene and
 * budget (all the arenas together), the settings of each method that use the most of
 * it and writes DIR/memory.csv (one row a setting measured, its mismatch share and
 * time, the method's best marked; a row "does not fit" with the least it needs);
 * report_memory draws a chart and a table per scene from it. Returns 0, or the exit
 * status of a failure. The scenes of a CSV's "scene" column (memory.csv's, bench.csv's)
 * and the budgets of memory.csv, in their order: */
int report_memory_measure(const char *dir, int runs);
void report_memory(FILE *f, const rcsv *mem);
size_t report_scenes_of(const rcsv *c, const char **names, size_t max);
size_t report_memory_budgets(const rcsv *c, const char *scene, double *budgets, size_t max);

/* What the page says about Cortex-M4 firmware, per method: its code, its whole
 * footprint on the small scene at 160x120 and its instructions a frame there, and the
 * frames a second they make at CHIP_MHZ and CHIP_CPI (assumed: QEMU counts
 * instructions, not cycles). From CROSS/m4-methods.csv where `make cross-test` wrote
 * it, else from the tables it last wrote into the firmware's README (`doc`). */
#define CHIP_MHZ 168
#define CHIP_CPI 1.25
typedef struct rchip { char method[32]; double text, whole, instructions, fps; } rchip;
typedef struct rcross {
    const char *dir;        /* where make cross-test writes its CSVs (out/cross) */
    const char *doc;        /* the firmware README (platform/cortex-m/README.md) */
    const char *doc_rev;    /* the commit that last changed it, as the caller found it */
} rcross;
/* Fills up to max chips; *from says which: "csv" or "doc" (NULL: neither is there). */
size_t report_chips(const rcross *x, rchip *out, size_t max, const char **from);

/* The small-machines section (report_machines.c), from the CSVs of x->dir as make
 * cross-test writes them, or, without them, the firmware README's tables labelled with
 * its commit, and how to refresh them. */
void report_machines(FILE *f, const rcross *x);

/* The decision summary at the top of the page (report_summary.c): from this run's
 * memory.csv and bench.csv, per scene and budget the fastest setting that meets each
 * accuracy (exact, 0.1%, 1% wrong), and the chips' table; every cell links to the
 * chart or table it comes from. */
void report_summary(FILE *f, const rcsv *bench, const rcsv *mem, const rcross *x);

/* The anchor of a scene's chart: "chart-NAME-KIND" (KIND: time, bytes, first). */
void report_chart_id(char *buf, size_t n, const char *scene, const char *kind);

#endif
