/* frame_need.h — the frame size query (om_frame_bytes) as the suite, the benchmarks
 * and the fuzz targets ask it without a view of their own: for a width x height image
 * through strips of `rows` rows (0: whole), scene s and method m (each may be NULL),
 * a spot light, and `threads` jobs on an inline parallel-for. */
#ifndef OM_TESTS_FRAME_NEED_H
#define OM_TESTS_FRAME_NEED_H

#include "ombra.h"

#include <string.h>

/* A parallel-for that runs every job in order on the calling thread. */
static inline void inline_for(void *host, om_job_fn fn, void *job_user, uint32_t n)
{
    (void)host;
    for (uint32_t i = 0; i < n; i++) fn(job_user, i);
}

static inline om_frame_need frame_need_of(const om_method *m, const om_scene *s, uint32_t width, uint32_t height,
                                          uint32_t rows, uint32_t threads)
{
    om_view v;
    om_frame_desc fd;
    om_frame_need need;
    memset(&v, 0, sizeof v);
    memset(&fd, 0, sizeof fd);
    memset(&need, 0, sizeof need);
    v.cam.width = width;
    v.cam.height = height;
    v.light.kind = OM_LIGHT_SPOT;
    fd.view = &v;
    fd.scene = s;
    fd.method = m;
    fd.strip_rows = rows;
    fd.threads = threads;
    fd.parallel_for = threads > 1 ? inline_for : NULL;
    om_frame_bytes(&fd, &need);
    return need;
}

#endif
