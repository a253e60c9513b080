/* frame.c — one frame, strip by strip: scene -> eye pass (visible samples) -> the
 * method (a shadow term per sample) -> shading -> framebuffer -> host callback.
 *
 * A method that observes (needs every visible sample before it builds) and a
 * directional light (fitted to the visible samples) need a first pass over the image.
 * When the frame is one strip the samples are kept and the eye pass runs once; with
 * smaller strips it runs again for each pass, so memory stays at one strip, but where
 * the arena has room (plan.c) the first pass keeps the triangle under every pixel,
 * and the later passes only resolve the samples from them: the scene is rasterized
 * once. Where the frame has jobs, each stage runs on them (jobs.c); the stages are
 * the same either way, and so are the pixels. */
#include "pipe.h"

static uint64_t now(const om_frame_desc *fd)
{
    return fd->clock ? fd->clock(fd->clock_user) : 0;
}

/* Geometric part of the lit rule, set once for every method alike. */
void om__frame_mark(const om_scene *s, const om_view *v, om_strip *st)
{
    size_t n = (size_t)st->rows * st->width;
    for (size_t i = 0; i < n; i++) {
        om_term *t = &st->terms[i];
        t->r = t->g = t->b = 255;
        t->flags = st->samples[i].tri != OM_NO_TRI && om__exposed(s, v, &st->samples[i])
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

void om__frame_eye_rows(const om__frame *c, const om_target *tg, om_strip *st, bool mark)
{
    const size_t n = (size_t)st->rows * st->width, at = (size_t)st->y0 * st->width;
    if (c->ids && c->ids_have) {
        if (c->ids16) {
            const uint16_t *k = (const uint16_t *)c->ids + at;
            for (size_t i = 0; i < n; i++) tg->id[i] = k[i] == 0xFFFFu ? OM_NO_TRI : k[i];
        } else {
            memcpy(tg->id, (const uint32_t *)c->ids + at, n * sizeof(uint32_t));
        }
        om__eye_resolve(c->fd->scene, c->view, tg, st, mark);
        return;
    }
    if (mark) om__eye_pass_mark(c->fd->scene, c->view, tg, st, c->bins);
    else om__eye_pass(c->fd->scene, c->view, tg, st, c->bins);
    if (!c->ids) return;
    if (c->ids16) {
        uint16_t *k = (uint16_t *)c->ids + at;
        for (size_t i = 0; i < n; i++) k[i] = tg->id[i] == OM_NO_TRI ? 0xFFFFu : (uint16_t)tg->id[i];
    } else {
        memcpy((uint32_t *)c->ids + at, tg->id, n * sizeof(uint32_t));
    }
}

/* The strip (and its target) moved to rows [y, y + c->rows). */
static void strip_at(om__frame *c, uint32_t y)
{
    const uint32_t H = c->strip.height;
    c->strip.y0 = c->tg.y0 = y;
    c->strip.rows = c->tg.rows = y + c->rows > H ? H - y : c->rows;
}

/* The eye pass (unless the samples are kept) and the exposure marks (unless kept) of
 * the current strip. */
static void eye(om__frame *c, bool samples, bool marks, om_frame_stats *fs)
{
    const uint64_t t0 = now(c->fd);
    if (c->jobs > 1) om__jobs_eye(c, !samples, !marks);
    else if (!samples) om__frame_eye_rows(c, &c->tg, &c->strip, !marks);
    else if (!marks) om__frame_mark(c->fd->scene, c->view, &c->strip);
    if (!samples) {
        fs->ns_eye += now(c->fd) - t0;
        fs->eye_passes++;
    }
}

/* A directional light fitted to the box of the visible samples in its view. */
static void fit_light(om__frame *c, om_view *view, om_frame_stats *fs)
{
    om_vec3 lo = om__v3(0, 0, 0), hi = om__v3(0, 0, 0);
    bool any = false;
    for (uint32_t y = 0; y < view->cam.height; y += c->rows) {
        strip_at(c, y);
        eye(c, false, true, fs);
        grow_light_box(view, &c->strip, &lo, &hi, &any);
    }
    if (any) om_view_fit_light(view, c->fd->scene, lo, hi);
}

static om_status check(const om_frame_desc *fd, const om_arena *fa, om_diag *d)
{
    if (!fd || !fa || !fd->scene || !fd->view || !fd->method || !fd->method_state || !fd->fb || !fd->shade)
        return om__fail(d, OM_E_INVALID, "frame needs a frame arena, a scene, view, method and its state, "
                                         "shading and framebuffer");
    const uint32_t W = fd->view->cam.width, H = fd->view->cam.height;
    const uint32_t rows = om__frame_strip_rows(fd, H);
    if (!om__side_ok(W, H)) return om__fail(d, OM_E_INVALID, "image width and height must be 1..8192");
    if (!om__state_for(fd->method_state, fd->method, fd->scene, W, H))
        return om__fail(d, OM_E_INVALID, "the method state was made for another method, scene or image size "
                                         "(om_method_init it for this frame's)");
    if ((unsigned)fd->fb->format > (unsigned)OM_L8)
        return om__fail(d, OM_E_INVALID, "framebuffer format must be OM_RGB888, OM_RGB565 or OM_L8");
    if (fd->fb->width != W || fd->fb->rows < rows || !fd->fb->pixels ||
        fd->fb->stride < (size_t)W * om_format_bpp(fd->fb->format))
        return om__fail(d, OM_E_INVALID, "framebuffer must be as wide as the image and hold a strip");
    return OM_OK;
}

/* plan -> (fit the light) -> begin -> observe -> build -> per strip {eye, resolve,
 * shade, sink}. Each stage's time goes to its om_frame_stats field; the method's
 * per-frame set-up (begin) counts as build time, so the times add up to the frame. */
om_status om_render_frame(const om_frame_desc *fd, om_arena *fa, om_frame_stats *stats, om_diag *d)
{
    om_frame_stats local;
    om_frame_stats *fs = stats ? stats : &local;
    memset(fs, 0, sizeof *fs);
    om_status st = check(fd, fa, d);
    if (st != OM_OK) return st;
    const om_method *m = fd->method;
    void *state = fd->method_state;
    const size_t mark = om_arena_mark(fa);
    om_view view = *fd->view;
    om__frame c;
    if ((st = om__frame_plan(&c, fd, &view, fa, d)) != OM_OK) goto done;
    fs->jobs = c.jobs;
    uint64_t t0 = now(fd);
    if (c.bins) {
        om__jobs_make_bins(&c, &view.cam_vp, view.cam.width, view.cam.height, c.bins);
        fs->ns_eye += now(fd) - t0;
    }
    om__jobs_lend(&c, true);
    bool samples = false, marks = false;   /* the whole frame's are in the strip already */
    if (c.fit) {
        fit_light(&c, &view, fs);
        samples = c.single;
        c.ids_have = c.ids != NULL;
    }
    t0 = now(fd);
    st = om__jobs_begin(&c, &view, d);
    fs->ns_build += now(fd) - t0;
    for (uint32_t y = 0; st == OM_OK && c.observes && y < view.cam.height; y += c.rows) {
        strip_at(&c, y);
        eye(&c, samples, false, fs);
        t0 = now(fd);
        st = m->observe(state, &c.strip, d);
        fs->ns_observe += now(fd) - t0;
    }
    if (c.observes) {
        samples = marks = c.single;   /* observe leaves the strip as marked */
        c.ids_have = c.ids != NULL;
    }
    t0 = now(fd);
    if (st == OM_OK && !om__jobs_build(&c)) st = m->build(state, d);
    fs->ns_build += now(fd) - t0;
    for (uint32_t y = 0; st == OM_OK && y < view.cam.height; y += c.rows) {
        strip_at(&c, y);
        eye(&c, samples, marks, fs);
        t0 = now(fd);
        if (!om__jobs_resolve(&c)) st = m->resolve(state, &c.strip, d);
        fs->ns_resolve += now(fd) - t0;
        if (st != OM_OK) break;
        t0 = now(fd);
        if (c.jobs > 1) om__jobs_shade(&c);
        else om__shade_strip(fd->scene, &view, fd->shade, &c.strip, fd->fb);
        fs->ns_shade += now(fd) - t0;
        fs->strips++;
        if (fd->on_strip) st = fd->on_strip(fd->user, &c.strip, fd->fb);
    }
    om__jobs_lend(&c, false);
done:
    fs->frame_peak = fa->peak;
    om_arena_rewind(fa, mark);
    return st;
}
