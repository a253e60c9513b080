/* cli.h — what the `ombra` subcommands share: argument helpers, loading a scene
 * (a file or the built-in default) into an arena sized by its bytes query, and
 * one-line errors that name the file and position. */
#ifndef OM_CLI_H
#define OM_CLI_H

#include "ombra.h"
#include "ombra_measure.h"
#include "../platform/platform.h"

#include <stdio.h>

typedef struct cli_scene {
    const char *path;      /* NULL: the built-in default scene */
    char *text;            /* file contents while it is read (malloc'd), then NULL */
    void *mem;             /* the scene arena's buffer */
    size_t bytes;
    om_arena arena;
    om_scene scene;
    om_file_loader files;
} cli_scene;

/* Prints "ombra: <where>: <message>" to stderr; returns exit status 1 (2 for usage). */
int cli_error(const char *where, const om_diag *d, om_status st);
int cli_usage_error(const char *cmd, const char *fmt, const char *arg);
/* "unknown method" with the nearest name and the list; returns 2. */
int cli_unknown_method(const char *cmd, const char *option, const char *name);
/* The tail of a too-small-budget message: the setting that sizes m's memory. */
void cli_method_hint(const om_method *m, char *buf, size_t n);
/* --budget BYTES or 'none' (0 out); 0 bytes is a usage error (printed). */
bool cli_parse_budget(const char *cmd, const char *s, size_t *out);

/* Loads a scene file (NULL: the default scene). With a budget (0: none) its text,
 * meshes and arena must fit in it: refused before the arena is made. */
om_status cli_scene_load(cli_scene *cs, const char *path, size_t budget, om_diag *d);
void cli_scene_free(cli_scene *cs);

bool cli_parse_size(const char *s, uint32_t *w, uint32_t *h);
bool cli_parse_bytes(const char *s, size_t *out);     /* 123, 64K, 8M, 1G (binary) */
bool cli_parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out);
bool cli_parse_float(const char *s, float *out);
/* Applies "NAME=VALUE" to a method configuration; prints the error and returns false. */
bool cli_set(om_method_cfg *c, const char *setting);

/* The settings given on a command line (--set NAME=VALUE and its short forms), kept
 * until the methods they go to are known: each applies to every method that takes it. */
typedef struct cli_settings {
    char item[32][128];
    int n;
} cli_settings;

/* Records "NAME=VALUE"; prints the error and returns false unless VALUE is a number
 * and some method takes NAME. */
bool cli_settings_add(cli_settings *s, const char *setting);
/* m's defaults with every recorded setting m takes (s may be NULL). The others are
 * skipped, each with a line on stderr when `note` names the command. Prints the error
 * and returns false on a value out of m's range. */
bool cli_cfg(const om_method *m, const cli_settings *s, om_method_cfg *c, const char *note);
/* What `ombra bench` sweeps for m (bench.c): space-separated NAME=V1,V2,... lists
 * whose product is swept; NULL = the defaults only, "" = left out of sweeps. */
const char *cli_sweep(const om_method *m);

/* The frames' threads (--threads N, platform/jobs.c): a pool the command starts once
 * (before that, and for commands without --threads, frames run on one thread).
 * cli_threads_start takes N as given ("0" or anything but 1..1024 is a usage error,
 * printed) or, for NULL, the CPUs online; cli_threads_stop ends the pool. */
bool cli_threads_start(const char *cmd, const char *arg);
/* The same within a memory budget (0: none): each worker past the caller counts
 * OM_JOBS_WORKER_BYTES of it (*workers: their bytes), and the workers take at most a
 * sixteenth of it, so the count is capped to what fits. */
bool cli_threads_start_in(const char *cmd, const char *arg, size_t budget, size_t *workers);
void cli_threads_stop(void);
uint32_t cli_threads(void);
/* Hands the pool to a frame: its parallel-for and thread count. */
void cli_frame_jobs(om_frame_desc *fd);
/* The frame size query (om_frame_bytes) for method m (m and its state may be NULL) on
 * scene s (may be NULL) seen by v, through strips of `rows` rows (0: whole), with the
 * pool's jobs when `jobs`. */
om_frame_need cli_frame_need(const om_method *m, const void *state, const om_scene *s, const om_view *v,
                             uint32_t rows, bool jobs);
/* Its least (with_bins, when bins) for a width-pixel image through strips of `rows`
 * rows, without jobs. */
size_t cli_frame_rows(const om_scene *s, uint32_t width, uint32_t rows, bool bins);

int cmd_render(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_compare(int argc, char **argv);
int cmd_bench(int argc, char **argv);

/* One measured sweep point (ombra bench, ombra report). */
typedef struct cli_point {
    const char *scene;     /* the name as given (kept by the caller; never cut short) */
    char method[16], setting[96];
    uint32_t w, h;         /* the image size it was measured at */
    double init;           /* the method's init, ms (once per point; ref builds its BVH) */
    double total, eye, observe, build, resolve, shade;   /* per frame, ms (medians) */
    double wall;           /* the whole frame call, ms (median; the strip callbacks left
                              out): total is its stages' sum, which misses what runs
                              between them on the calling thread */
    double tmin, tmax;     /* the fastest and slowest of the frames (total, ms): the spread */
    size_t bytes;
    om_metrics m;
    char stats[256];       /* the method's counters of the last frame: "name=value; ..." */
    uint32_t threads;      /* the jobs its frames ran at once (om_frame_stats.jobs) */
    int ok;
} cli_point;

/* Loads "default", "town", "random-1K" ... "random-1M", or a scene file. */
om_status cli_load_named(const char *name, cli_scene *cs, om_diag *d);
/* Inits `m` with its one-pass bytes (timed: p->init) and renders `runs` frames of
 * view `v`; median times into p, the last frame's mask (and shaded RGB888 pixels, if
 * rgb) out. */
om_status cli_measure(const om_method *m, const om_method_cfg *cfg, const cli_scene *cs,
                      const om_view *v, int runs, uint8_t *mask, uint8_t *rgb, cli_point *p,
                      om_diag *d);
/* The same through strips of `rows` rows (0: the whole frame at once) in a frame arena
 * of fbytes (om_frame_bytes' with_bins, or more, lets the strips use row bins). */
om_status cli_measure_strips(const om_method *m, const om_method_cfg *cfg, const cli_scene *cs,
                             const om_view *v, int runs, uint32_t rows, size_t fbytes, uint8_t *mask,
                             uint8_t *rgb, cli_point *p, om_diag *d);
int cmd_report(int argc, char **argv);
/* A setting as a chart labels it: "asm.cap=1048576" -> "cap 1M", "map=512 rtw.exact=1"
 * -> "map 512, exact 1". */
void cli_short_setting(const char *setting, char *out, size_t n);

/* "dir/file", malloc'd (NULL when out of memory): paths are never cut short. */
char *cli_path(const char *dir, const char *file);
/* What follows the path's last '/' (the whole path without one). */
const char *cli_base_name(const char *path);

/* A frame's strip callback (om_strip_fn) with a cli_masks as its user: each strip's
 * mask into mask (the whole image's, row-major) and, where rgb is given, its RGB888
 * pixels into rgb. */
typedef struct cli_masks { uint8_t *mask, *rgb; } cli_masks;
om_status cli_grab_mask(void *user, const om_strip *st, const om_framebuffer *fb);
/* Cuts a trailing "@WxH" (the size to measure that scene at) off a --scenes entry
 * into w, h (0 when there is none); false when what follows the @ is not a size. */
bool cli_scene_size(char *entry, uint32_t *w, uint32_t *h);
/* Whether NAME is a built-in scene ("default", "town", "random-1K" ...). */
bool cli_builtin_scene(const char *name);
/* The view a sweep measures: the scene at time 0, at --size w x h when given (w > 0),
 * else at its camera's own size (v->cam.width, height). */
om_status cli_scene_view(const cli_scene *cs, uint32_t w, uint32_t h, om_view *v, om_diag *d);

/* Host memory ran out: OM_E_BUDGET with a message. */
om_status cli_oom(om_diag *d);

#endif
