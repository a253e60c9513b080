/* pipe.h — what the frame's own files share: the frame in progress (om__frame), laid
 * out by the planner (plan.c), run stage by stage by the pipeline (frame.c), its
 * stages spread over the host's threads by jobs.c, the one file here that knows how. */
#ifndef OM_PIPE_H
#define OM_PIPE_H

#include "../shadow/method.h"

/* One job's method counts and scratch (from the frame arena): a band is one job of the
 * host's parallel-for, so it owns its slot whichever thread runs it. */
typedef struct om__job_slot {
    uint32_t counts[8];
    void *scratch;
    size_t dirty;    /* bytes of scratch its first job zeroes (a pass slot) */
    uint32_t run;    /* the band that job k of the map build runs (jobs.c, order_bands) */
    uint32_t weight; /* order_bands' estimate of band k's work */
} om__job_slot;

struct om__frame;

/* The jobs' part of a frame: jobs.c alone reads and writes it. */
typedef struct om__frame_jobs {
    const om__bands *bands;    /* NULL: the method resolves a strip at a time */
    const om__pass *pass;      /* NULL: no pass of its own (or no room for one) */
    uint32_t band_rows, fine_rows;   /* rows of a band, of a fine band */
    om__job_slot *slots;       /* FINE_BANDS_PER_JOB a job */
    om__job_slot *pass_slots;  /* the pass's, pass_max of them */
    uint32_t pass_max, pass_jobs, pass_slots_now;   /* K jobs of the pass on P slots */
    uint32_t setup_items;      /* the pass's per-frame items (om__pass.begin) */
    void (*lend_fn)(void *user, uint32_t k, void *scratch);   /* a lent stage's (om__lend) */
    void *lend_user;
    om__lend lend;
    /* What the current call of the parallel-for runs: job b of it is stage(c, b). */
    void (*stage)(struct om__frame *c, uint32_t b);
    uint32_t rows_now;         /* a band stage's rows a band */
    bool eye, mark;            /* the eye stage: run the eye pass, mark exposure */
    om__bins map_bins;         /* the light map's (rows NULL: none) */
    uint32_t map_k, map_size, map_band;   /* the map build: which map, its side, rows per band */
    const om__bins *mk;        /* the bins being made, through mk_vp */
    const om_mat4 *mk_vp;
    uint32_t mk_w, mk_h;
    uint32_t *half_depth, *half_id;   /* one strip, two jobs: the second target, or NULL */
    uint32_t eye_parts;        /* the parts of the triangles (2: the halves) */
    bool part_drawn[2];        /* and whether each target is cleared and drawn into */
} om__frame_jobs;

typedef struct om__frame {
    const om_frame_desc *fd;
    const om_view *view;       /* the frame's own copy: a directional light is fitted */
    om_target tg;              /* the strip's depth and triangle ids */
    om_strip strip;
    uint32_t rows;             /* a strip's rows */
    bool single;               /* one strip: the whole image */
    bool fit;                  /* a directional light, fitted to the visible samples */
    bool observes;             /* the method observes every strip before it builds */
    uint32_t jobs;             /* jobs at once: 1 runs every stage inline */
    const om__bins *bins;      /* the camera's, or NULL: every strip walks every triangle */
    om__bins eye_bins;
    void *ids;                 /* the image's triangle ids from its first pass, or NULL */
    bool ids16;                /* as uint16_t (OM_NO_TRI as 0xFFFF): under 65535 triangles */
    bool ids_have;             /* the first pass is over: later passes resolve from ids */
    om__frame_jobs j;
} om__frame;

/* plan.c: lays the frame out in `fa` (every carving decision, made once) and fills c;
 * OM_E_BUDGET when not even a strip fits. c->bins, where set, are carved but not yet
 * made. */
om_status om__frame_plan(om__frame *c, const om_frame_desc *fd, const om_view *view, om_arena *fa,
                         om_diag *d);
/* A strip's rows for fd at an image `height` rows high: strip_rows, or the whole. */
uint32_t om__frame_strip_rows(const om_frame_desc *fd, uint32_t height);
/* The bytes of bins for scene s; bins' memory carved from fa (false: no room). */
size_t om__frame_bins_bytes(const om_scene *s);
bool om__frame_carve_bins(om_arena *fa, const om_scene *s, om__bins *b);

/* frame.c: the eye pass of rows [st->y0, + st->rows) into tg (with kept ids, the first
 * pass stores them and later ones resolve from them), and the exposure marks alone. */
void om__frame_eye_rows(const om__frame *c, const om_target *tg, om_strip *st, bool mark);
void om__frame_mark(const om_scene *s, const om_view *v, om_strip *st);

/* jobs.c. Each runs inline, or does nothing where it says so, when c->jobs is 1 (always
 * so where the engine carries no jobs code: config.h). */
size_t om__jobs_bytes(const om_method *m, const void *state, const om_scene *s, uint32_t threads);
/* The light map's bins where m's depth pass runs by bands of the map (0: none). */
size_t om__jobs_map_bins_bytes(const om_method *m, const om_scene *s);
/* The jobs' slots beyond `keep` bytes of fa: sets c->jobs (1: none fit or none asked). */
void om__jobs_carve(om__frame *c, om_arena *fa, size_t keep);
/* One strip on two jobs: the eye pass split by triangles into two targets, the second
 * in the samples' memory (n pixels), where the scene is dense; false: not taken. */
bool om__jobs_halves(om__frame *c, om_sample *samples, size_t n);
/* The light map's bins for a map built by bands, where they fit. */
void om__jobs_carve_map(om__frame *c, om_arena *fa);
/* The method's lent slots for the frame (on), taken back at its end (off). */
void om__jobs_lend(om__frame *c, bool on);
/* om__bins_make on the jobs, for the frame's view (its origin). */
void om__jobs_make_bins(om__frame *c, const om_mat4 *vp, uint32_t w, uint32_t h, const om__bins *b);
/* The method's begin, or its pass's begin and set-up on the jobs. */
om_status om__jobs_begin(om__frame *c, const om_view *v, om_diag *d);
/* The current strip's eye pass and exposure marks on the jobs. */
void om__jobs_eye(om__frame *c, bool eye, bool mark);
/* The light map by bands, the current strip's resolve by bands and pass: false where
 * the method must build (resolve) on the calling thread instead. */
bool om__jobs_build(om__frame *c);
bool om__jobs_resolve(om__frame *c);
/* The current strip's shading on the jobs. */
void om__jobs_shade(om__frame *c);

#endif
