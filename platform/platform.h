/* platform.h — what touches the operating system: reading files, a monotonic clock,
 * and PPM/PGM sinks that stream a frame row by row. Hosts without an OS (the Cortex-M
 * build) replace this directory's .c files; the engine never calls them. */
#ifndef OM_PLATFORM_H
#define OM_PLATFORM_H

#include "ombra.h"
#include <stdio.h>

/* Reads a whole file into a malloc'd buffer (NUL-terminated for convenience; *len
 * excludes the NUL). On failure returns OM_E_IO or OM_E_NOTFOUND with d->msg naming
 * the file and the system's reason. */
om_status om_file_read(const char *path, char **data, size_t *len, om_diag *d);

/* An om_loader that reads files relative to a base directory and keeps them until
 * om_file_loader_free. */
typedef struct om_file_loader {
    char base[1024];
    char *bufs[64];
    int nbufs;
    om_diag *diag;
} om_file_loader;

void om_file_loader_init(om_file_loader *fl, const char *scene_path);
om_loader om_file_loader_get(om_file_loader *fl);
void om_file_loader_free(om_file_loader *fl);

/* Nanoseconds from a monotonic clock (an om_clock_fn; user is unused). */
uint64_t om_clock_ns(void *user);

/* A sink writing a binary PPM (P6) of the shaded frame and, optionally, a PGM (P5)
 * shadow mask: 255 lit, 0 shadowed, 128 background. Rows are written as strips
 * arrive, so a frame never needs to be whole in memory. */
typedef struct om_ppm_sink {
    FILE *img, *mask;
    const char *img_path, *mask_path;
    unsigned char *row;    /* one row of conversion scratch (3 * width bytes) */
    uint32_t width, height;
    uint64_t hash_img, hash_mask;   /* FNV-1a of the pixel rows written (not headers) */
} om_ppm_sink;

/* Opens the files (mask_path may be NULL) and writes the headers. */
om_status om_ppm_open(om_ppm_sink *k, const char *img_path, const char *mask_path,
                      uint32_t width, uint32_t height, om_diag *d);
/* An om_strip_fn: pass the sink as `user`. */
om_status om_ppm_strip(void *user, const om_strip *st, const om_framebuffer *fb);
/* Flushes and closes; reports a write error with the file's name. */
om_status om_ppm_close(om_ppm_sink *k, om_diag *d);

/* Reads a binary PGM (P5, maxval 255) into a malloc'd buffer. */
om_status om_pgm_read(const char *path, uint32_t *w, uint32_t *h, uint8_t **pixels, om_diag *d);
/* Writes a whole RGB888 image as a binary PPM. */
om_status om_ppm_write(const char *path, const uint8_t *rgb, uint32_t w, uint32_t h, om_diag *d);

/* Converts one framebuffer row to RGB888. */
void om_row_to_rgb(const om_framebuffer *fb, uint32_t y, unsigned char *rgb);

#endif
