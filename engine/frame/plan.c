/* plan.c — a frame's memory: what the frame arena holds, decided once per frame by
 * om__frame_plan from what the arena has left, in this order of use:
 *   least     a strip's depth and triangle ids (the eye pass's target), samples and
 *             terms: the frame runs in nothing less;
 *   bins      the camera's bins, with strips (each strip then sets up only the
 *             triangles that reach its rows, from vertices projected once; without
 *             room every strip walks every triangle);
 *   jobs      the jobs' slots (jobs.c), keeping beside them the bins they use when two
 *             jobs fit as well: one strip's bands want the camera's, a map built by
 *             bands the light's;
 *   ids       the image's triangle ids, where a frame through strips passes over the
 *             image more than once (a method that observes, a directional light): the
 *             scene is then rasterized once, and later passes resolve from them.
 * The same sizes answer the host's query, om_frame_bytes. Whatever fits, the pixels are
 * the same. */
#include "pipe.h"

static size_t least_bytes(uint32_t width, uint32_t rows)
{
    const size_t n = (size_t)width * rows;
    return om_arena_need(n * sizeof(uint32_t), 8) * 2 + om_arena_need(n * sizeof(om_sample), 8) +
           om_arena_need(n * sizeof(om_term), 8);
}

size_t om__frame_bins_bytes(const om_scene *s)
{
    return s ? om__bins_rows_bytes(s) + om__bins_verts_bytes(s) : 0;
}

/* The ids as uint16_t (OM_NO_TRI as 0xFFFF) under 65535 triangles, else uint32_t. */
static size_t ids_bytes(const om_scene *s, uint32_t width, uint32_t height)
{
    return (size_t)width * height * (s && s->ntris < 0xFFFFu ? sizeof(uint16_t) : sizeof(uint32_t));
}

static bool observes(const om_method *m, const void *state)
{
    return m && (m->flags & OM_METHOD_OBSERVES) && (!m->observes || !state || m->observes(state));
}

uint32_t om__frame_strip_rows(const om_frame_desc *fd, uint32_t height)
{
    return fd->strip_rows == 0 || fd->strip_rows > height ? height : fd->strip_rows;
}

om_status om_frame_bytes(const om_frame_desc *fd, om_frame_need *out)
{
    if (!fd || !fd->view || !out || !om__side_ok(fd->view->cam.width, fd->view->cam.height)) return OM_E_INVALID;
    const om_view *v = fd->view;
    const uint32_t W = v->cam.width, H = v->cam.height, rows = om__frame_strip_rows(fd, H);
    const om_scene *s = fd->scene;
    const void *state = om__state_of(fd->method_state, fd->method);
    out->least = least_bytes(W, rows);
    out->with_bins = out->least + om__frame_bins_bytes(s);
    out->with_jobs = out->with_bins + om__jobs_bytes(fd->method, state, s, fd->parallel_for ? fd->threads : 1);
    out->with_ids = out->with_jobs + om_arena_need(ids_bytes(s, W, H), 8);
    const bool again = rows < H && (v->light.kind == OM_LIGHT_DIRECTIONAL || observes(fd->method, state));
    out->whole = again ? out->with_ids : out->with_jobs;
    return OM_OK;
}

/* Bins' memory: the rows, and the vertices when they fit too. False: no room. Not
 * zeroed: om__bins_make writes every triangle's rows and every vertex before any is
 * read. */
bool om__frame_carve_bins(om_arena *fa, const om_scene *s, om__bins *b)
{
    void *pb, *pv;
    b->rows = NULL;
    b->verts = NULL;
    b->centres = false;
    if (!s->ntris || om_arena_left(fa) < om__bins_rows_bytes(s) ||
        om__arena_alloc_raw(fa, (size_t)s->ntris * sizeof(uint32_t), 8, &pb, NULL) != OM_OK)
        return false;
    b->rows = (uint32_t *)pb;
    if (om_arena_left(fa) >= om__bins_verts_bytes(s) &&
        om__arena_alloc_raw(fa, (size_t)s->nverts * sizeof(om__vsnap), 8, &pv, NULL) == OM_OK)
        b->verts = (om__vsnap *)pv;
    return true;
}

om_status om__frame_plan(om__frame *c, const om_frame_desc *fd, const om_view *view, om_arena *fa,
                         om_diag *d)
{
    const om_scene *s = fd->scene;
    const om_method *m = fd->method;
    const uint32_t W = view->cam.width, H = view->cam.height, rows = om__frame_strip_rows(fd, H);
    const size_t n = (size_t)W * rows;
    void *pd, *pi, *ps, *pt;
    om_status st;
    memset(c, 0, sizeof *c);
    /* Not zeroed (on one thread, and large): every strip's eye pass clears its rows of
     * depth and id and writes every sample, and its exposure marks (or om__frame_mark)
     * every term, before anything reads them. */
    if ((st = om__arena_alloc_raw(fa, n * sizeof(uint32_t), 8, &pd, d)) ||
        (st = om__arena_alloc_raw(fa, n * sizeof(uint32_t), 8, &pi, d)) ||
        (st = om__arena_alloc_raw(fa, n * sizeof(om_sample), 8, &ps, d)) ||
        (st = om__arena_alloc_raw(fa, n * sizeof(om_term), 8, &pt, d)))
        return st;
    c->fd = fd;
    c->view = view;
    c->rows = rows;
    c->single = rows == H;
    c->fit = view->light.kind == OM_LIGHT_DIRECTIONAL;
    c->observes = observes(m, fd->method_state);
    c->tg.width = c->strip.width = W;
    c->tg.height = c->strip.height = H;
    c->tg.rows = c->strip.rows = rows;
    c->tg.depth = (uint32_t *)pd;
    c->tg.id = (uint32_t *)pi;
    c->strip.samples = (om_sample *)ps;
    c->strip.terms = (om_term *)pt;
    c->strip.origin = view->origin;

    /* With strips the bins come before the jobs' slots; one strip needs them only for
     * its bands (and not where two jobs split its eye pass by triangles). */
    bool bins = !c->single && om__frame_carve_bins(fa, s, &c->eye_bins);
    const size_t keep = (c->single ? om__frame_bins_bytes(s) : 0) + om__jobs_map_bins_bytes(m, s);
    om__jobs_carve(c, fa, om_arena_left(fa) >= keep + om__jobs_bytes(m, NULL, NULL, 2) ? keep : 0);
    if (!om__jobs_halves(c, c->strip.samples, n) && c->single && c->jobs > 1)
        bins = om__frame_carve_bins(fa, s, &c->eye_bins);
    if (bins) {
        c->eye_bins.centres = true;   /* the eye samples pixel centres alone */
        c->bins = &c->eye_bins;
    }
    om__jobs_carve_map(c, fa);
    /* The ids last, so they never take the room of the bins or the jobs. Not zeroed:
     * the first pass writes them all before the next reads any. */
    if (!c->single && (c->fit || c->observes) && om_arena_left(fa) >= om_arena_need(ids_bytes(s, W, H), 8) &&
        om__arena_alloc_raw(fa, ids_bytes(s, W, H), 8, &c->ids, NULL) == OM_OK)
        c->ids16 = s->ntris < 0xFFFFu;
    return OM_OK;
}
