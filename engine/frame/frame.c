/* frame.c — one frame, strip by strip: scene -> eye pass (visible samples) ->
 * the method (a shadow term per sample) -> shading -> framebuffer -> host callback.
 *
 * A method that observes (needs every visible sample before it builds) and a
 * directional light (fitted to the visible samples) need a first pass over the image.
 * When the frame is one strip the samples are kept and the eye pass runs once; with
 * smaller strips it runs again for each pass, so memory stays at one strip. */
#include "frame.h"

size_t om_frame_bytes(uint32_t width, uint32_t strip_rows)
{
    size_t n = (size_t)width * strip_rows;
    return om_arena_need(n * sizeof(uint32_t), 8) * 2 + om_arena_need(n * sizeof(om_sample), 8) +
           om_arena_need(n * sizeof(om_term), 8);
}

size_t om_frame_bytes_scene(const om_scene *s, uint32_t width, uint32_t strip_rows)
{
    return om_frame_bytes(width, strip_rows) + om__bins_rows_bytes(s) + om__bins_verts_bytes(s);
}

static uint64_t now(const om_frame_desc *fd)
{
    return fd->clock ? fd->clock(fd->clock_user) : 0;
}

/* Geometric part of the lit rule, set once for every method alike. */
static void mark_exposed(const om_view *v, om_strip *st)
{
    size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        t->flags = st->samples[i].tri != OM_NO_TRI && om__exposed(v, &st->samples[i])
                       ? OM_TERM_EXPOSED : 0;
    }
}

static void grow_light_box(const om_view *v, const om_strip *st, om_vec3 *lo, om_vec3 *hi,
                           bool *any)
{
    size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        const om_sample *smp = &st->samples[i];
        if (smp->tri == OM_NO_TRI) continue;
        om_vec4 q = om__mat_apply(&v->light_view, om__v3(smp->p[0], smp->p[1], smp->p[2]));
        if (!*any || q.x < lo->x) lo->x = q.x;
        if (!*any || q.y < lo->y) lo->y = q.y;
        if (!*any || q.x > hi->x) hi->x = q.x;
        if (!*any || q.y > hi->y) hi->y = q.y;
        *any = true;
    }
}

om_status om_render_frame(const om_frame_desc *fd, om_arena *fa, om_frame_stats *stats,
                          om_diag *d)
{
    om_frame_stats local;
    om_frame_stats *fs = stats ? stats : &local;
    memset(fs, 0, sizeof *fs);
    if (!fd || !fd->scene || !fd->view || !fd->method || !fd->fb || !fd->shade)
        return om__fail(d, OM_E_INVALID, "frame needs a scene, view, method, shading and framebuffer");
    const om_scene *s = fd->scene;
    const om_method *m = fd->method;
    uint32_t W = fd->view->cam.width, H = fd->view->cam.height;
    uint32_t rows = fd->strip_rows == 0 || fd->strip_rows > H ? H : fd->strip_rows;
    if (fd->fb->width != W || fd->fb->rows < rows || !fd->fb->pixels ||
        fd->fb->stride < (size_t)W * om_format_bpp(fd->fb->format))
        return om__fail(d, OM_E_INVALID, "framebuffer must be as wide as the image and hold a strip");

    size_t mark = om_arena_mark(fa);
    om_status st;
    void *pd, *pi, *ps, *pt;
    size_t n = (size_t)W * rows;
    if ((st = om_arena_alloc(fa, n * sizeof(uint32_t), 8, &pd, d)) ||
        (st = om_arena_alloc(fa, n * sizeof(uint32_t), 8, &pi, d)) ||
        (st = om_arena_alloc(fa, n * sizeof(om_sample), 8, &ps, d)) ||
        (st = om_arena_alloc(fa, n * sizeof(om_term), 8, &pt, d))) {
        om_arena_rewind(fa, mark);
        return st;
    }
    om_target tg;
    tg.width = W; tg.height = H; tg.y0 = 0; tg.rows = rows;
    tg.depth = (uint32_t *)pd;
    tg.id = (uint32_t *)pi;
    om_strip strip;
    strip.width = W; strip.height = H; strip.y0 = 0; strip.rows = rows;
    strip.samples = (om_sample *)ps;
    strip.terms = (om_term *)pt;

    om_view view = *fd->view;
    const bool single = rows == H;
    /* Bins when the frame has strips and the arena has room (om__bins): each strip
     * then sets up only its own triangles, from vertices projected once (the same
     * pixels; without room, every strip walks every triangle). The camera's matrix
     * does not change within the frame. */
    om__bins bins = {NULL, NULL};
    if (!single && s->ntris && om_arena_left(fa) >= om__bins_rows_bytes(s)) {
        void *pb, *pv;
        if (om_arena_alloc(fa, (size_t)s->ntris * sizeof(uint32_t), 8, &pb, NULL) == OM_OK) {
            bins.rows = (uint32_t *)pb;
            if (om_arena_left(fa) >= om__bins_verts_bytes(s) &&
                om_arena_alloc(fa, (size_t)s->nverts * sizeof(om__vsnap), 8, &pv, NULL) == OM_OK)
                bins.verts = (om__vsnap *)pv;
            uint64_t tb = now(fd);
            om__bins_make(s, &view.cam_vp, W, H, &bins);
            fs->ns_eye += now(fd) - tb;
        }
    }
    const bool observes = (m->flags & OM_METHOD_OBSERVES) && (!m->observes || m->observes(fd->method_state));
    const bool fit = view.light.kind == OM_LIGHT_DIRECTIONAL;
    bool have_samples = false;   /* strip.samples hold the whole frame already */
    bool have_terms = false;     /* and strip.terms their exposure (mark_exposed) */
    uint64_t t0;

#define EYE(y)                                                                   \
    do {                                                                         \
        strip.y0 = tg.y0 = (y);                                                  \
        strip.rows = tg.rows = (y) + rows > H ? H - (y) : rows;                  \
        t0 = now(fd);                                                            \
        om__eye_pass(s, &view, &tg, &strip, bins.rows ? &bins : NULL);           \
        fs->ns_eye += now(fd) - t0;                                              \
        fs->eye_passes++;                                                        \
    } while (0)

    if (fit) {
        om_vec3 lo = om__v3(0, 0, 0), hi = om__v3(0, 0, 0);
        bool any = false;
        for (uint32_t y = 0; y < H; y += rows) {
            EYE(y);
            grow_light_box(&view, &strip, &lo, &hi, &any);
        }
        if (any) om_view_fit_light(&view, s, lo, hi);
        have_samples = single;
    }
    if ((st = m->begin(fd->method_state, &view, d)) != OM_OK) goto done;
    if (observes) {
        for (uint32_t y = 0; y < H; y += rows) {
            if (!have_samples) EYE(y);
            mark_exposed(&view, &strip);
            t0 = now(fd);
            st = m->observe(fd->method_state, &strip, d);
            fs->ns_observe += now(fd) - t0;
            if (st != OM_OK) goto done;
        }
        have_samples = single;
        have_terms = single;   /* observe leaves the strip as marked */
    }
    t0 = now(fd);
    st = m->build(fd->method_state, d);
    fs->ns_build += now(fd) - t0;
    if (st != OM_OK) goto done;
    for (uint32_t y = 0; y < H; y += rows) {
        if (!have_samples) EYE(y);
        if (!have_terms) mark_exposed(&view, &strip);
        t0 = now(fd);
        st = m->resolve(fd->method_state, &strip, d);
        fs->ns_resolve += now(fd) - t0;
        if (st != OM_OK) goto done;
        t0 = now(fd);
        om__shade_strip(s, &view, fd->shade, &strip, fd->fb);
        fs->ns_shade += now(fd) - t0;
        fs->strips++;
        if (fd->on_strip && (st = fd->on_strip(fd->user, &strip, fd->fb)) != OM_OK) goto done;
    }
#undef EYE
done:
    fs->frame_peak = fa->peak;
    om_arena_rewind(fa, mark);
    return st;
}
