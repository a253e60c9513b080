/* platform.h — what touches the operating system: reading files, a monotonic clock,
 * output files that appear whole or not at all, and PPM/PGM sinks that stream a
 * frame row by row. Hosts without an OS (the Cortex-M
 * build) replace this directory's .c files; the engine never calls them. */
#ifndef OM_PLATFORM_H
#define OM_PLATFORM_H

#include "ombra.h"
#include "ombra_measure.h"
#include <stdio.h>

/* The most bytes om_file_read takes from one file: past it the read stops with
 * OM_E_BUDGET rather than growing until the system stops it (a scene or mask named
 * /dev/zero). A budget (om_file_read_max) may ask for less. */
#define OM_FILE_MAX ((size_t)1 << 31)

/* Reads a whole file into a malloc'd buffer (NUL-terminated for convenience; *len
 * excludes the NUL). On failure returns OM_E_IO or OM_E_NOTFOUND with d->msg naming
 * the file and the system's reason, or OM_E_BUDGET for a file of more than max bytes
 * (a regular file is refused by its size before anything is read). */
om_status om_file_read_max(const char *path, size_t max, char **data, size_t *len, om_diag *d);
/* The same for a text (a scene, an OBJ file): a NUL byte, which no text holds, ends
 * the read at its chunk with OM_E_PARSE, so a large binary file is not read whole. */
om_status om_file_read_text(const char *path, size_t max, char **data, size_t *len, om_diag *d);
/* om_file_read_max with OM_FILE_MAX. */
om_status om_file_read(const char *path, char **data, size_t *len, om_diag *d);

/* An om_loader that reads files relative to the scene file's directory. Each file is
 * read once and kept until om_file_loader_free, however many passes or `mesh` lines
 * ask for it (so a FIFO works and a file changing between passes cannot make them
 * disagree); there is no limit on how many files. */
typedef struct om_file_entry {
    char *path;            /* as resolved: base + name, or name when absolute */
    char *data;
    size_t len;
} om_file_entry;

typedef struct om_file_loader {
    char *base;            /* the scene's directory with its '/', or NULL */
    om_file_entry *files;
    size_t nfiles, cap;
    size_t limit, held;    /* bytes the files may hold together (0: OM_FILE_MAX each), held */
    om_diag *diag;         /* where a failed read's message goes; may be NULL */
} om_file_loader;

/* OM_E_IO only when out of memory (scene_path may be NULL: the current directory). */
om_status om_file_loader_init(om_file_loader *fl, const char *scene_path);
om_loader om_file_loader_get(om_file_loader *fl);
/* Frees the files' bytes but keeps their paths (which files a scene read); a later
 * load of one reads it again. */
void om_file_loader_drop_data(om_file_loader *fl);
void om_file_loader_free(om_file_loader *fl);

/* A parallel-for on a pool of threads (jobs.c): om_jobs_for is an om_parallel_for_fn
 * whose `host` is the pool. om_jobs_start starts threads - 1 workers (the caller is
 * the last thread); threads <= 1 starts none and runs every job inline. */
typedef struct om_jobs om_jobs;
/* What each thread of a pool past the caller costs the process beyond the arenas (its
 * stack's touched pages and the system's records of it): counted at twice the 8 KB or
 * so a worker adds to the peak resident size on Linux, so that a memory budget that
 * counts them holds. */
#define OM_JOBS_WORKER_BYTES ((size_t)16 << 10)
om_status om_jobs_start(om_jobs **out, uint32_t threads, om_diag *d);
void om_jobs_for(void *host, om_job_fn fn, void *user, uint32_t n);
/* The threads a pool runs jobs on (1 for NULL), the caller's included. */
uint32_t om_jobs_threads(const om_jobs *j);
/* An om_worker_fn: the calling thread's index in the pool (0 for the caller's, which
 * runs jobs too; 1.. for the workers). */
uint32_t om_jobs_worker(void *host);
void om_jobs_stop(om_jobs *j);
/* The CPUs online (at least 1). */
uint32_t om_cpus_online(void);

/* Nanoseconds from a monotonic clock (an om_clock_fn; user is unused). */
uint64_t om_clock_ns(void *user);

/* An output file a reader never sees half-written (out.c). A regular file, or a name
 * not yet taken, is written to a temporary beside it ("DIR/.NAME.XXXXXX") that
 * om_out_commit flushes, fsyncs and renames over it; any failure removes the
 * temporary and leaves the old file's bytes alone. "-" (standard output), names under
 * /dev/ and /proc/, and anything that is not a regular file (a FIFO, a device) are
 * written directly. Errors name the path and give the system's reason. */
typedef struct om_out {
    FILE *f;               /* NULL when not open */
    const char *path;      /* as the caller named it (kept, not copied) */
    char *target, *tmp;    /* the file a rename replaces and its temporary; NULL if direct */
    int err;               /* the first errno a write saw, else 0 */
    bool direct, is_stdout;
} om_out;

om_status om_out_open(om_out *o, const char *path, om_diag *d);
/* Writes n bytes; after the first failure every write fails (om_out_failed says why). */
bool om_out_write(om_out *o, const void *p, size_t n);
/* OM_E_IO naming the path and the reason when a write has failed, else OM_OK. */
om_status om_out_failed(const om_out *o, om_diag *d);
/* Finishes every open file of outs (NULL entries and closed ones are skipped); only
 * when all were written whole are the temporaries renamed over their targets, so a
 * set of outputs (an image and its mask) is replaced together or not at all. */
om_status om_out_commit(om_out *const *outs, size_t n, om_diag *d);
/* Closes without keeping anything: the temporary is removed (a direct file keeps
 * what already reached it). Safe on a closed or zeroed om_out. */
void om_out_discard(om_out *o);
/* Whether a path is written directly rather than through a temporary. */
bool om_out_is_direct(const char *path);
/* Whether two names reach the same file ("-" is standard output; /dev/null is never
 * "the same" as itself: discarding twice loses nothing). */
bool om_out_same(const char *a, const char *b);

/* A sink writing a binary PPM (P6) of the shaded frame, or a PGM (P5) when `grey`, and,
 * optionally, a PGM shadow mask: 255 lit, 0 shadowed, 128 background. Rows are
 * written as strips arrive, so a frame never needs to be whole in memory; the files
 * appear only when om_ppm_close commits them. */
typedef struct om_ppm_sink {
    om_out img, mask;      /* .f NULL when not asked for */
    unsigned char *row;    /* one row of conversion scratch (3 * width bytes) */
    uint32_t width, height;
    bool grey;
    uint64_t hash_img, hash_mask;   /* FNV-1a of the pixel rows written (not headers) */
} om_ppm_sink;

/* Opens the files (either path may be NULL) and writes the headers; on failure
 * nothing stays open and om_ppm_discard is harmless. */
om_status om_ppm_open(om_ppm_sink *k, const char *img_path, const char *mask_path,
                      uint32_t width, uint32_t height, bool grey, om_diag *d);
/* An om_strip_fn: pass the sink as `user`. A failed write stops the frame with
 * OM_E_IO; om_out_failed(&k->img or &k->mask) then names the file and reason. */
om_status om_ppm_strip(void *user, const om_strip *st, const om_framebuffer *fb);
/* Commits both files (om_out_commit) and frees the scratch. */
om_status om_ppm_close(om_ppm_sink *k, om_diag *d);
/* Drops both files and frees the scratch; old files stay as they were. */
void om_ppm_discard(om_ppm_sink *k);
/* The first write error of either file, naming it, or OM_OK. */
om_status om_ppm_failed(const om_ppm_sink *k, om_diag *d);

/* Reads a binary PGM (P5, maxval 255) into a malloc'd buffer. */
om_status om_pgm_read(const char *path, uint32_t *w, uint32_t *h, uint8_t **pixels, om_diag *d);
/* Writes a whole RGB888 image as a binary PPM into an open output. */
bool om_ppm_put(om_out *o, const uint8_t *rgb, uint32_t w, uint32_t h);
/* Writes a whole RGB888 image as a binary PPM file (om_out: old file kept on failure). */
om_status om_ppm_write(const char *path, const uint8_t *rgb, uint32_t w, uint32_t h, om_diag *d);

/* Converts one framebuffer row to RGB888. */
void om_row_to_rgb(const om_framebuffer *fb, uint32_t y, unsigned char *rgb);

#endif
