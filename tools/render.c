/* render.c — `ombra render`, `ombra info` and `ombra compare`. Every arena is sized
 * from the engine's bytes-needed queries for this scene, view and method; --budget caps
 * the total, and the frame is then rendered through strips small enough to fit. */
#include "cli.h"
#include "imgfile.h"

#include <stdlib.h>
#include <string.h>

static const char render_help[] =
    "usage: ombra render [SCENE] [options]\n"
    "\n"
    "Renders one frame of SCENE (the built-in default scene when omitted), or with\n"
    "--frames a sequence of them into numbered files.\n"
    "\n"
    "  --method NAME     shadow method (default sm; 'ombra methods' lists them)\n"
    "  --against NAME    also render NAME (usually ref) on the same visible samples and\n"
    "                    print the method's accuracy against it\n"
    "  --out FILE        shaded frame, in the format its extension names: .ppm (binary\n"
    "                    PPM), .png, or .pgm for a grey frame (--format l8); default\n"
    "                    ombra.ppm (ombra.pgm with --format l8); '-' is standard output\n"
    "                    (PPM, or PGM for l8). Every file replaces the old one only once\n"
    "                    it is whole\n"
    "  --mask FILE       shadow mask, .pgm or .png (grey): 255 lit, 0 shadowed, 128\n"
    "                    background\n"
    "  --diff FILE       with --against, .ppm or .png: false lit red, false shadowed blue\n"
    "  --size WxH        image size, 1..8192 each (default: the scene's camera)\n"
    "  --time T          time along the scene's camera, light and object paths (default 0)\n"
    "  --frames N        N frames, at times T, T + 1/F, ...: each to files numbered\n"
    "                    0000, 0001, ... before the extension (ombra-0000.ppm, ...)\n"
    "  --fps F           frames per unit of time with --frames (default 24)\n"
    "  --format F        framebuffer format: rgb888 (default), rgb565, l8\n"
    "  --strip ROWS      render through strips of ROWS rows (default: whole frame)\n"
    "  --threads N       threads a frame runs on (default: the CPUs online); the\n"
    "                    frame is the same bits with any N; under --budget each\n"
    "                    thread past the first counts 16 KiB of it, and threads take\n"
    "                    at most a sixteenth of it (fewer start where more asked)\n"
    "  --budget BYTES    total memory for scene, frame and method (K, M, G suffixes),\n"
    "                    or 'none' (the default); the strip height shrinks to fit, down\n"
    "                    to one row\n"
    "  --set NAME=VALUE  a method setting, repeatable ('ombra methods' lists them all)\n"
    "  --map N           short for --set map=N (shadow-map side, default 2048)\n"
    "  --bias B          short for --set bias=B (constant bias, a fraction of the\n"
    "                    light's depth range far - near)\n"
    "  --slope S         short for --set slope=S (slope-scaled bias, texels)\n"
    "  --offset O        short for --set offset=O (normal offset, texels)\n"
    "  --pcf K           short for --set pcf=K (K x K percentage-closer filtering)\n"
    "  -q, --quiet       print nothing but errors\n";

/* One method's memory and state for a frame. */
typedef struct run {
    const om_method *m;
    om_method_cfg cfg;
    size_t min, full, given;
    void *mem;
    om_arena arena;
    void *state;
    uint64_t ns_init;      /* the method's init (ref builds its BVH there) */
} run;

static om_status run_init(run *r, const cli_scene *cs, uint32_t W, uint32_t H, om_diag *d)
{
    om_status st;
    r->mem = malloc(r->given ? r->given : 1);
    if (!r->mem) return cli_oom(d);
    om_arena_init(&r->arena, r->mem, r->given, "method");
    uint64_t t0 = om_clock_ns(NULL);
    st = om_method_init(r->m, &r->state, &r->arena, &r->cfg, &cs->scene, W, H, d);
    r->ns_init = om_clock_ns(NULL) - t0;
    return st;
}

/* Where each strip goes: the PPM sink, a whole-frame mask and a whole-frame image
 * (img_ch channels: 1 for a grey frame, else RGB888) when asked; and the
 * frame's samples counted: covered (not background) and, of those, exposed (facing
 * the light, inside its frustum: the ones a method decides; the others are shadowed
 * by the lit rule whatever the method says). */
typedef struct strip_out {
    om_ppm_sink *ppm;
    uint8_t *mask, *img;
    unsigned img_ch;
    uint64_t covered, exposed;
} strip_out;

static om_status on_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    strip_out *o = (strip_out *)user;
    for (size_t i = 0; i < (size_t)st->rows * st->width; i++) {
        o->covered += st->samples[i].tri != OM_NO_TRI;
        o->exposed += st->samples[i].tri != OM_NO_TRI && (st->terms[i].flags & OM_TERM_EXPOSED);
    }
    if (o->img)
        for (uint32_t y = 0; y < st->rows; y++) {
            uint8_t *row = o->img + (size_t)(st->y0 + y) * st->width * o->img_ch;
            if (o->img_ch == 1) memcpy(row, fb->pixels + (size_t)y * fb->stride, st->width);
            else om_row_to_rgb(fb, y, row);
        }
    if (o->mask)
        for (uint32_t y = 0; y < st->rows; y++)
            for (uint32_t x = 0; x < st->width; x++) {
                size_t i = (size_t)y * st->width + x;
                o->mask[(size_t)(st->y0 + y) * st->width + x] = om_mask_of(&st->samples[i], &st->terms[i]);
            }
    return o->ppm ? om_ppm_strip(o->ppm, st, fb) : OM_OK;
}

/* The frame arena: the strips, and their row bins when `bins` (then each strip sets
 * up only its own triangles; the same pixels either way). */
static om_status run_frame(run *r, const cli_scene *cs, const om_view *v, uint32_t rows, bool bins,
                           bool jobs, om_format fmt, strip_out *out, om_frame_stats *fs, size_t *frame_bytes,
                           om_diag *d)
{
    uint32_t W = v->cam.width;
    const om_frame_need need = cli_frame_need(r->m, r->state, &cs->scene, v, rows, jobs);
    *frame_bytes = bins ? need.with_bins : need.least;
    /* Threads: each job's scratch, the bins for the bands of a whole frame, and for
     * strips of a frame that passes over the image more than once the first pass's
     * triangle ids, so the scene is rasterized once (under a --budget there is no
     * room kept for them: the frame runs with what fits). */
    if (jobs && (bins || rows == v->cam.height)) *frame_bytes = need.whole;
    void *frame_mem = malloc(*frame_bytes);
    om_framebuffer fb;
    fb.format = fmt;
    fb.width = W;
    fb.rows = rows;
    fb.stride = (size_t)W * om_format_bpp(fmt);
    fb.pixels = malloc(fb.stride * rows);
    om_status st;
    if (!frame_mem || !fb.pixels) {
        st = cli_oom(d);
    } else {
        om_arena fa;
        om_arena_init(&fa, frame_mem, *frame_bytes, "frame");
        om_shade_cfg shade;
        om_shade_cfg_default(&shade);
        om_frame_desc fd;
        memset(&fd, 0, sizeof fd);
        fd.scene = &cs->scene;
        fd.view = v;
        fd.method = r->m;
        fd.method_state = r->state;
        fd.shade = &shade;
        fd.strip_rows = rows;
        fd.fb = &fb;
        fd.on_strip = on_strip;
        fd.user = out;
        fd.clock = om_clock_ns;
        cli_frame_jobs(&fd);
        st = om_render_frame(&fd, &fa, fs, d);
    }
    free(frame_mem);
    free(fb.pixels);
    return st;
}

static int parse_format(const char *s, om_format *f)
{
    if (!strcmp(s, "rgb888")) *f = OM_RGB888;
    else if (!strcmp(s, "rgb565")) *f = OM_RGB565;
    else if (!strcmp(s, "l8")) *f = OM_L8;
    else return 0;
    return 1;
}

static void print_metrics(FILE *f, const char *name, const char *against, const om_metrics *m)
{
    double n = m->samples ? (double)m->samples : 1.0, e = m->edge_samples ? (double)m->edge_samples : 1.0;
    fprintf(f, "accuracy of %s against %s: match %.4f%% of %llu covered samples; false lit %llu (%.4f%%), "
           "false shadowed %llu (%.4f%%)\n",
           name, against, 100.0 * om_metrics_match(m), (unsigned long long)m->samples,
           (unsigned long long)m->false_lit, 100.0 * (double)m->false_lit / n,
           (unsigned long long)m->false_shadowed, 100.0 * (double)m->false_shadowed / n);
    fprintf(f, "near reference edges (%d px): %llu covered samples; false lit %llu (%.3f%%), false shadowed %llu (%.3f%%)\n",
           OM_EDGE_BAND, (unsigned long long)m->edge_samples, (unsigned long long)m->edge_false_lit,
           100.0 * (double)m->edge_false_lit / e, (unsigned long long)m->edge_false_shadowed,
           100.0 * (double)m->edge_false_shadowed / e);
}

/* Two of the files a render reads or writes are one file: a usage error, since one
 * would destroy the other (--out x --mask x lost the image). */
static int same_files(const char *const *paths, const char *const *names, size_t n)
{
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++)
            if (paths[i] && paths[j] && om_out_same(paths[i], paths[j])) {
                fprintf(stderr, "ombra render: %s and %s name the same file '%s': each needs "
                        "its own\n(see 'ombra render --help')\n", names[i], names[j], paths[j]);
                return 2;
            }
    return 0;
}

static int render_one(int argc, char **argv)
{
    const char *scene_path = NULL, *out = NULL, *mask = NULL, *mname = "sm";
    const char *against = NULL, *diff = NULL, *threads = NULL;
    uint32_t w = 0, h = 0, strip = 0;
    size_t budget = 0;     /* 0: no --budget (or --budget none) */
    float t = 0.0f;
    bool quiet = false;
    om_format fmt = OM_RGB888;
    run main_run, ref_run;
    memset(&main_run, 0, sizeof main_run);
    memset(&ref_run, 0, sizeof ref_run);
    static cli_settings settings;   /* 4 KB: off the stack */
    settings.n = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { fputs(render_help, stdout); return 0; }
        if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) { quiet = true; continue; }
        static const char *const valued[] = {"--method", "--against", "--out", "--mask", "--diff",
            "--size", "--strip", "--budget", "--time", "--format", "--set", "--map", "--pcf",
            "--bias", "--slope", "--offset", "--threads"};
        bool known = false;
        for (size_t k = 0; k < sizeof valued / sizeof valued[0]; k++) known |= !strcmp(a, valued[k]);
        if (a[0] == '-' && !known) return cli_usage_error("render", "unknown option '%s'", a);
        if (known && !v) return cli_usage_error("render", "%s needs a value", a);
        if (!strcmp(a, "--method")) mname = v;
        else if (!strcmp(a, "--against")) against = v;
        else if (!strcmp(a, "--out")) out = v;
        else if (!strcmp(a, "--mask")) mask = v;
        else if (!strcmp(a, "--diff")) diff = v;
        else if (!strcmp(a, "--size")) { if (!cli_parse_size(v, &w, &h)) return cli_usage_error("render", "--size takes WxH with each side 1..8192, not '%s'", v); }
        else if (!strcmp(a, "--strip")) { if (!cli_parse_u32(v, 1, OM_MAX_DIM, &strip)) return cli_usage_error("render", "--strip takes a row count 1..8192, not '%s'", v); }
        else if (!strcmp(a, "--threads")) threads = v;
        else if (!strcmp(a, "--budget")) { if (!cli_parse_budget("render", v, &budget)) return 2; }
        else if (!strcmp(a, "--time")) { if (!cli_parse_float(v, &t)) return cli_usage_error("render", "--time takes a number, not '%s'", v); }
        else if (!strcmp(a, "--format")) { if (!parse_format(v, &fmt)) return cli_usage_error("render", "--format is rgb888, rgb565 or l8, not '%s'", v); }
        else if (a[0] != '-') {
            if (scene_path) return cli_usage_error("render", "one scene only; unexpected '%s'", a);
            scene_path = a;
            continue;
        } else {
            /* --set NAME=VALUE and its short forms */
            char setting[128];
            int n = !strcmp(a, "--set") ? snprintf(setting, sizeof setting, "%s", v)
                                        : snprintf(setting, sizeof setting, "%s=%s", a + 2, v);
            if (n < 0 || (size_t)n >= sizeof setting) return cli_usage_error("render", "setting too long: '%s'", v);
            if (!cli_settings_add(&settings, setting)) return 2;
        }
        i++;
    }
    /* A grey frame is written as a PGM; the default name says so. */
    if (!out) out = fmt == OM_L8 ? "ombra.pgm" : "ombra.ppm";
    size_t workers = 0;   /* what the pool's threads count of --budget */
    if (!cli_threads_start_in("render", threads, budget, &workers)) return 2;
    if (diff && !against) return cli_usage_error("render", "%s needs --against", "--diff");
    main_run.m = om_method_find(mname);
    if (!main_run.m) return cli_unknown_method("render", "--method", mname);
    if (against && !(ref_run.m = om_method_find(against)))
        return cli_unknown_method("render", "--against", against);
    if (!cli_cfg(main_run.m, &settings, &main_run.cfg, quiet ? NULL : "render")) return 2;
    om_method_cfg_default(&ref_run.cfg, ref_run.m);
    {
        const char *paths[4] = {scene_path, out, mask, diff};
        const char *names[4] = {"the scene", "--out", "--mask", "--diff"};
        int rc = same_files(paths, names, 4);
        if (rc) return rc;
    }
    /* Each file in the format its name says (imgfile.h), before any work. */
    img_fmt out_fmt, mask_fmt = IMG_NETPBM, diff_fmt = IMG_NETPBM;
    {
        int rc = img_fmt_of("render", "--out", out, IMG_ACCEPT_PPM | IMG_ACCEPT_PGM | IMG_ACCEPT_PNG,
                            ".ppm, .png or, with --format l8, .pgm", &out_fmt);
        if (!rc && mask) rc = img_fmt_of("render", "--mask", mask, IMG_ACCEPT_PGM | IMG_ACCEPT_PNG, ".pgm or .png", &mask_fmt);
        if (!rc && diff) rc = img_fmt_of("render", "--diff", diff, IMG_ACCEPT_PPM | IMG_ACCEPT_PNG, ".ppm or .png", &diff_fmt);
        if (rc) return rc;
        if (out_fmt == IMG_PGM && fmt != OM_L8)
            return cli_usage_error("render", "--out '%s' is a grey PGM: add --format l8 for a grey "
                                   "frame, or name it .ppm or .png", out);
    }
    /* The frame's own netpbm goes out as strips arrive; any other format (a PNG, a
     * grey frame as a PPM) is kept whole, outside --budget, and written after it. */
    const bool out_whole = out_fmt != IMG_NETPBM && out_fmt != (fmt == OM_L8 ? IMG_PGM : IMG_PPM);
    const bool mask_whole = mask && mask_fmt == IMG_PNG;
    const unsigned img_ch = fmt == OM_L8 ? 1 : 3;
    /* With an image on standard output the report goes to standard error. */
    FILE *info = om_out_same(out, "-") || (mask && om_out_same(mask, "-")) ||
                 (diff && om_out_same(diff, "-")) ? stderr : stdout;

    om_diag d;
    memset(&d, 0, sizeof d);
    cli_scene cs;
    om_status st = cli_scene_load(&cs, scene_path, budget, &d);
    const char *where = scene_path ? scene_path : "default scene";
    if (st != OM_OK) { cli_scene_free(&cs); return cli_error(where, &d, st); }
    /* nor may an output be a mesh the scene read (it would be gone after the run) */
    for (size_t i = 0; i < cs.files.nfiles; i++) {
        const char *paths[4] = {cs.files.files[i].path, out, mask, diff};
        const char *names[4] = {"a mesh of the scene", "--out", "--mask", "--diff"};
        for (size_t k = 1; k < 4; k++)
            if (paths[k] && om_out_same(paths[k], paths[0])) {
                fprintf(stderr, "ombra render: %s and %s name the same file '%s': each needs "
                        "its own\n(see 'ombra render --help')\n", names[0], names[k], paths[0]);
                cli_scene_free(&cs);
                return 2;
            }
    }

    om_camera cam;
    om_light light;
    if ((st = om_scene_pose_at(&cs.scene, t, &d)) != OM_OK) { cli_scene_free(&cs); return cli_error(where, &d, st); }
    om_scene_at(&cs.scene, t, &cam, &light);
    if (w) { cam.width = w; cam.height = h; }
    om_view view;
    int rc = 0;
    uint8_t *mask_main = NULL, *mask_ref = NULL, *rgb = NULL, *img_px = NULL;
    om_ppm_sink sink;
    om_out diff_out, img_out, mask_out;
    memset(&sink, 0, sizeof sink);
    memset(&diff_out, 0, sizeof diff_out);
    memset(&img_out, 0, sizeof img_out);
    memset(&mask_out, 0, sizeof mask_out);
    if ((st = om_view_init(&view, &cam, &light, &cs.scene, &d)) != OM_OK) { rc = cli_error(where, &d, st); goto out; }
    const uint32_t W = cam.width, H = cam.height;
    if ((st = om_method_bytes(main_run.m, &main_run.cfg, &cs.scene, W, H, &main_run.min, &main_run.full)) != OM_OK) {
        rc = cli_error(mname, &d, st);
        goto out;
    }
    /* Split the memory: when the method's one-pass size and the whole frame do not
     * both fit, the method gets its minimum plus half of what is left over and the
     * frame the other half, as strips of as many rows as fit (at least one). Both
     * halves cost the same kind of work: another strip or another method tile. */
    uint32_t rows = strip && strip < H ? strip : H;
    bool bins = rows < H;   /* with strips, when --budget leaves room for them */
    main_run.given = main_run.full;
    if (budget) {
        /* a row of the frame: its arena's share and the framebuffer's pixels */
        size_t px = (size_t)W * om_format_bpp(fmt);
        size_t one = cli_frame_rows(NULL, W, 1, false) + px;
        size_t row_bytes = cli_frame_rows(NULL, W, 2, false) - cli_frame_rows(NULL, W, 1, false) + px;
        size_t rest = budget > cs.bytes + workers ? budget - cs.bytes - workers : 0;
        if (rest < main_run.full + cli_frame_rows(NULL, W, rows, false)) {
            size_t spare = rest > main_run.min + one ? rest - main_run.min - one : 0;
            main_run.given = main_run.min + spare / 2;
            if (main_run.given > main_run.full) main_run.given = main_run.full;
        }
        size_t left = rest > main_run.given ? rest - main_run.given : 0;
        size_t fit = left >= one ? 1 + (left - one) / row_bytes : 0;
        if (fit == 0) {
            size_t need = cs.bytes + workers + main_run.min + one;
            char hint[160];
            cli_method_hint(main_run.m, hint, sizeof hint);
            char threads_part[64] = "";
            if (workers)
                snprintf(threads_part, sizeof threads_part, ", %u threads (%zu)", cli_threads(), workers);
            fprintf(stderr, "ombra: --budget %zu is too small: this scene (%zu bytes)%s, method '%s' "
                    "(at least %zu) and one %u-pixel row (%zu) need %zu bytes; raise --budget, "
                    "make --size smaller%s%s\n", budget, cs.bytes, threads_part, mname, main_run.min, W,
                    one, need, workers ? ", use fewer --threads" : "", hint);
            rc = 1;
            goto out;
        }
        if (fit < rows) rows = (uint32_t)fit;
        bins = rows < H && left >= cli_frame_rows(&cs.scene, W, rows, true) + (size_t)rows * px;
    }
    /* The outputs open (as temporaries) before any work, so an unwritable one fails
     * at once; they replace the old files only once all are complete. */
    if ((st = om_ppm_open(&sink, out_whole ? NULL : out, mask_whole ? NULL : mask, W, H, fmt == OM_L8, &d)) != OM_OK ||
        (out_whole && (st = om_out_open(&img_out, out, &d)) != OM_OK) ||
        (mask_whole && (st = om_out_open(&mask_out, mask, &d)) != OM_OK) ||
        (diff && (st = om_out_open(&diff_out, diff, &d)) != OM_OK)) {
        rc = cli_error(NULL, &d, st);
        goto out;
    }
    if (((against || mask_whole) && !(mask_main = malloc((size_t)W * H))) ||
        (out_whole && !(img_px = malloc((size_t)W * H * img_ch)))) {
        rc = cli_error(NULL, &d, cli_oom(&d));
        goto out;
    }
    if ((st = run_init(&main_run, &cs, W, H, &d)) != OM_OK) { rc = cli_error(mname, &d, st); goto out; }
    if (against) {
        /* The reference is a measuring instrument: it gets what it needs, outside --budget. */
        if ((st = om_method_bytes(ref_run.m, &ref_run.cfg, &cs.scene, W, H, &ref_run.min, &ref_run.full)) != OM_OK ||
            (ref_run.given = ref_run.full, st = run_init(&ref_run, &cs, W, H, &d)) != OM_OK) {
            rc = cli_error(against, &d, st);
            goto out;
        }
        mask_ref = malloc((size_t)W * H);
        if (!mask_ref) { rc = cli_error(NULL, &d, cli_oom(&d)); goto out; }
        strip_out ro;
        memset(&ro, 0, sizeof ro);
        ro.mask = mask_ref;
        om_frame_stats rfs;
        size_t rfb;
        if ((st = run_frame(&ref_run, &cs, &view, rows, bins, !budget, fmt, &ro, &rfs, &rfb, &d)) != OM_OK) {
            rc = cli_error(against, &d, st);
            goto out;
        }
    }
    strip_out so;
    memset(&so, 0, sizeof so);
    so.ppm = &sink;
    so.mask = mask_main;
    so.img = img_px;
    so.img_ch = img_ch;
    om_frame_stats fs;
    size_t frame_bytes;
    uint64_t t0 = om_clock_ns(NULL);
    st = run_frame(&main_run, &cs, &view, rows, bins, !budget, fmt, &so, &fs, &frame_bytes, &d);
    uint64_t t1 = om_clock_ns(NULL);
    if (st != OM_OK) {
        /* A write that failed stopped the frame: name the file, not the method. */
        om_status wst = om_ppm_failed(&sink, &d);
        rc = wst != OM_OK ? cli_error(NULL, &d, wst) : cli_error(mname, &d, st);
        goto out;
    }
    om_metrics mt;
    if (against) {
        om_compare_masks(mask_ref, mask_main, W, H, &mt);
        if (diff) {
            if (!(rgb = malloc((size_t)W * H * 3))) { rc = cli_error(NULL, &d, cli_oom(&d)); goto out; }
            om_diff_image(mask_ref, mask_main, W, H, rgb);
            if ((st = img_put(&diff_out, diff_fmt, rgb, 3, W, H, &d)) != OM_OK) {
                rc = cli_error(NULL, &d, st);
                goto out;
            }
        }
    }
    if ((out_whole && (st = img_put(&img_out, out_fmt, img_px, img_ch, W, H, &d)) != OM_OK) ||
        (mask_whole && (st = img_put(&mask_out, mask_fmt, mask_main, 1, W, H, &d)) != OM_OK)) {
        rc = cli_error(NULL, &d, st);
        goto out;
    }
    {
        om_out *outs[5] = {&sink.img, &sink.mask, &img_out, &mask_out, &diff_out};
        if ((st = om_out_commit(outs, 5, &d)) != OM_OK) { rc = cli_error(NULL, &d, st); goto out; }
    }
    if (!quiet) {
        om_method_stats ms;
        om_method_get_stats(main_run.m, main_run.state, &ms);
        fprintf(info, "%s: %ux%u, %u triangles, method %s, %u strip(s) of %u rows, %u thread(s)\n",
                where, W, H, cs.scene.ntris, mname, fs.strips, rows, fs.jobs);
        fprintf(info, "time: total %.2f ms (init %.2f, eye %.2f x%u, observe %.2f, build %.2f, "
                "resolve %.2f, shade %.2f)\n",
                (double)(main_run.ns_init + (t1 - t0)) / 1e6, (double)main_run.ns_init / 1e6,
                (double)fs.ns_eye / 1e6, fs.eye_passes, (double)fs.ns_observe / 1e6,
                (double)fs.ns_build / 1e6, (double)fs.ns_resolve / 1e6, (double)fs.ns_shade / 1e6);
        fprintf(info, "memory: scene %zu, frame %zu (peak %zu), method %zu (peak %zu) bytes\n", cs.bytes,
                frame_bytes, fs.frame_peak, main_run.given, main_run.arena.peak);
        fprintf(info, "samples: %llu covered (not background), %llu of them exposed (facing the light, "
                "inside its frustum: what a method decides; the rest are shadowed whatever it says)\n",
                (unsigned long long)so.covered, (unsigned long long)so.exposed);
        for (uint32_t k = 0; k < ms.ncounters; k++)
            fprintf(info, "%s%s %u", k ? ", " : "stats: ", ms.counter_names[k], ms.counters[k]);
        if (ms.ncounters) fprintf(info, "\n");
        fprintf(info, "hash: image %016llx mask %016llx\n", (unsigned long long)sink.hash_img,
                (unsigned long long)sink.hash_mask);
        fprintf(info, "wrote %s%s%s%s%s\n", out, mask ? " and " : "", mask ? mask : "",
                diff ? " and " : "", diff ? diff : "");
    }
    if (against) print_metrics(info, mname, against, &mt);
out:
    om_ppm_discard(&sink);
    om_out_discard(&img_out);
    om_out_discard(&mask_out);
    om_out_discard(&diff_out);
    free(img_px);
    free(main_run.mem);
    free(ref_run.mem);
    free(mask_main);
    free(mask_ref);
    free(rgb);
    cli_scene_free(&cs);
    return rc;
}

/* FILE.ext -> FILE-NNNN.ext (the number before the last dot of the last path part). */
static void numbered(char *dst, size_t cap, const char *name, uint32_t f)
{
    const char *slash = strrchr(name, '/'), *dot = strrchr(name, '.');
    if (!dot || (slash && dot < slash) || dot == (slash ? slash + 1 : name)) dot = name + strlen(name);
    snprintf(dst, cap, "%.*s-%04u%s", (int)(dot - name), name, f, dot);
}

/* `--frames N [--fps F]`: N frames at times T + k / F (T from --time, default 0), each
 * a render of its own into numbered files (--out, --mask, --diff), so a user sees the
 * objects, the camera and the light move. Without --frames, one frame as always. */
int cmd_render(int argc, char **argv)
{
    uint32_t frames = 0;
    float fps = 24.0f, t0 = 0.0f;
    int at_frames = -1;
    for (int i = 1; i + 1 < argc; i++) {
        if (!strcmp(argv[i], "--frames")) {
            if (!cli_parse_u32(argv[i + 1], 1, 100000, &frames))
                return cli_usage_error("render", "--frames takes a frame count 1..100000, not '%s'", argv[i + 1]);
            at_frames = i;
        } else if (!strcmp(argv[i], "--fps")) {
            if (!cli_parse_float(argv[i + 1], &fps) || !(fps > 0.0f) || fps > 1e6f)
                return cli_usage_error("render", "--fps takes a frame rate above 0, not '%s'", argv[i + 1]);
        } else if (!strcmp(argv[i], "--time")) {
            if (!cli_parse_float(argv[i + 1], &t0))
                return cli_usage_error("render", "--time takes a number, not '%s'", argv[i + 1]);
        } else if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            break;
        } else {
            continue;
        }
        i++;
    }
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--fps") && at_frames < 0)
            return cli_usage_error("render", "%s needs --frames", "--fps");
    if (at_frames < 0) return render_one(argc, argv);
    const char *out = NULL;
    bool grey = false;
    for (int i = 1; i + 1 < argc; i++) {
        if (!strcmp(argv[i], "--out")) out = argv[i + 1];
        if (!strcmp(argv[i], "--format") && !strcmp(argv[i + 1], "l8")) grey = true;
    }
    for (int i = 1; i + 1 < argc; i++)
        if ((!strcmp(argv[i], "--out") || !strcmp(argv[i], "--mask") || !strcmp(argv[i], "--diff")) &&
            !strcmp(argv[i + 1], "-"))
            return cli_usage_error("render", "--frames writes numbered files: %s cannot be '-'", argv[i]);
    char **av = malloc((size_t)(argc + 4) * sizeof *av);
    static char names[4][1024], tbuf[64];
    if (!av) return 1;
    int rc = 0;
    for (uint32_t f = 0; f < frames && !rc; f++) {
        int n = 0;
        av[n++] = argv[0];
        for (int i = 1; i < argc; i++) {
            const char *a = argv[i];
            if ((!strcmp(a, "--frames") || !strcmp(a, "--fps") || !strcmp(a, "--time")) && i + 1 < argc) {
                i++;
                continue;
            }
            av[n++] = argv[i];
            if (i + 1 < argc && (!strcmp(a, "--out") || !strcmp(a, "--mask") || !strcmp(a, "--diff"))) {
                char *dst = names[!strcmp(a, "--out") ? 0 : !strcmp(a, "--mask") ? 1 : 2];
                numbered(dst, sizeof names[0], argv[++i], f);
                av[n++] = dst;
            }
        }
        if (!out) {
            numbered(names[3], sizeof names[3], grey ? "ombra.pgm" : "ombra.ppm", f);
            av[n++] = (char *)"--out";
            av[n++] = names[3];
        }
        snprintf(tbuf, sizeof tbuf, "%.9g", (double)(t0 + (float)f / fps));
        av[n++] = (char *)"--time";
        av[n++] = tbuf;
        rc = render_one(n, av);
    }
    free(av);
    return rc;
}

static const char info_help[] =
    "usage: ombra info [SCENE] [--size WxH] [--set NAME=VALUE ...]\n"
    "\n"
    "Prints the scene's triangles, vertices, materials and bounds, and the bytes the\n"
    "scene, a frame and each method need at that image size.\n";


/* How many objects share mesh m. */
static uint32_t mesh_users(const om_scene *s, uint32_t m)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < s->nobjects; i++) n += s->objects[i].mesh == m;
    return n;
}

int cmd_info(int argc, char **argv)
{
    const char *scene_path = NULL;
    uint32_t w = 0, h = 0;
    static cli_settings settings;
    settings.n = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { fputs(info_help, stdout); return 0; }
        if (!strcmp(a, "--size")) {
            if (!v || !cli_parse_size(v, &w, &h)) return cli_usage_error("info", "--size takes WxH with each side 1..8192, not '%s'", v ? v : "");
            i++;
        } else if (!strcmp(a, "--set") || !strcmp(a, "--map")) {
            char setting[128];
            if (!v) return cli_usage_error("info", "%s needs a value", a);
            if (!strcmp(a, "--set")) snprintf(setting, sizeof setting, "%s", v);
            else snprintf(setting, sizeof setting, "map=%s", v);
            if (!cli_settings_add(&settings, setting)) return 2;
            i++;
        } else if (a[0] == '-') return cli_usage_error("info", "unknown option '%s'", a);
        else if (!scene_path) scene_path = a;
        else return cli_usage_error("info", "one scene only; unexpected '%s'", a);
    }
    om_diag d;
    memset(&d, 0, sizeof d);
    cli_scene cs;
    const char *where = scene_path ? scene_path : "default scene";
    om_status st = cli_scene_load(&cs, scene_path, 0, &d);
    if (st != OM_OK) { cli_scene_free(&cs); return cli_error(where, &d, st); }
    const om_scene *s = &cs.scene;
    uint32_t W = w ? w : s->camera.width, H = w ? h : s->camera.height;
    printf("scene: %s\n", where);
    printf("triangles %u, vertices %u, materials %u, camera keys %u, light keys %u\n", s->ntris,
           s->nverts, s->nmats, s->ncam_keys, s->nlight_keys);
    if (s->nobjects) {
        printf("objects %u sharing %u meshes (%u object keys):\n", s->nobjects, s->nmeshes, s->nobj_keys);
        for (uint32_t i = 0; i < s->nobjects; i++) {
            if (i == 24 && s->nobjects > 25) {   /* a crowd: the first ones say enough */
                printf("  ... and %u more\n", s->nobjects - i);
                break;
            }
            const om_object *o = &s->objects[i];
            printf("  %-12s mesh %u (%u triangles, %u objects share it), %u keys\n", o->name[0] ? o->name : "(copy)",
                   o->mesh, s->meshes[o->mesh].ntris, mesh_users(s, o->mesh), o->nkeys);
        }
    }
    printf("bounds: (%g, %g, %g) .. (%g, %g, %g)\n", s->lo.x, s->lo.y, s->lo.z, s->hi.x, s->hi.y,
           s->hi.z);
    printf("light: %s\n", s->light.kind == OM_LIGHT_SPOT ? "spot" : "directional");
    printf("bytes at %ux%u: scene %zu, frame %zu (whole) / %zu (one row)\n", W, H, cs.bytes,
           cli_frame_rows(NULL, W, H, false), cli_frame_rows(NULL, W, 1, false));
    printf("threads: %u CPUs online; under --budget each thread past the first counts %zu bytes "
           "of it, and threads take at most a sixteenth\n", om_cpus_online(), OM_JOBS_WORKER_BYTES);
    for (size_t i = 0; i < om_method_count(); i++) {
        const om_method *m = om_method_at(i);
        size_t mn, full;
        om_method_cfg cfg;
        if (!cli_cfg(m, &settings, &cfg, NULL)) { cli_scene_free(&cs); return 2; }
        st = om_method_bytes(m, &cfg, s, W, H, &mn, &full);
        if (st == OM_OK) printf("  %-6s min %zu, full %zu\n", om_method_name(m), mn, full);
        else printf("  %-6s %s\n", om_method_name(m), om_status_str(st));
    }
    cli_scene_free(&cs);
    return 0;
}

static const char compare_help[] =
    "usage: ombra compare REF.pgm MASK.pgm [--diff D.ppm|D.png]\n"
    "\n"
    "Compares two shadow masks of the same frame (255 lit, 0 shadowed, 128 background),\n"
    "the first taken as the reference: match share, false lit and false shadowed, the\n"
    "same near the reference's shadow edges, and optionally a difference image (false\n"
    "lit red, false shadowed blue). Masks whose background differs are of different\n"
    "frames (another scene, camera, time or size): an error, exit status 1.\n";

int cmd_compare(int argc, char **argv)
{
    const char *a_path = NULL, *b_path = NULL, *diff = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { fputs(compare_help, stdout); return 0; }
        if (!strcmp(a, "--diff")) {
            if (i + 1 >= argc) return cli_usage_error("compare", "%s needs a file name", a);
            diff = argv[++i];
        } else if (a[0] == '-') return cli_usage_error("compare", "unknown option '%s'", a);
        else if (!a_path) a_path = a;
        else if (!b_path) b_path = a;
        else return cli_usage_error("compare", "two masks only; unexpected '%s'", a);
    }
    if (!b_path) return cli_usage_error("compare", "needs two masks%s", "");
    if (diff && (om_out_same(diff, a_path) || om_out_same(diff, b_path)))
        return cli_usage_error("compare", "--diff '%s' would replace one of the masks it compares", diff);
    img_fmt diff_fmt = IMG_NETPBM;
    if (diff) {
        int e = img_fmt_of("compare", "--diff", diff, IMG_ACCEPT_PPM | IMG_ACCEPT_PNG, ".ppm or .png", &diff_fmt);
        if (e) return e;
    }
    om_diag d;
    memset(&d, 0, sizeof d);
    uint32_t wa, ha, wb, hb;
    uint8_t *ma = NULL, *mb = NULL;
    om_status st;
    int rc = 0;
    if ((st = om_pgm_read(a_path, &wa, &ha, &ma, &d)) != OM_OK ||
        (st = om_pgm_read(b_path, &wb, &hb, &mb, &d)) != OM_OK) {
        rc = cli_error(NULL, &d, st);
    } else if (wa != wb || ha != hb) {
        fprintf(stderr, "ombra: %s is %ux%u but %s is %ux%u: masks of one frame have one size\n",
                a_path, wa, ha, b_path, wb, hb);
        rc = 1;
    } else {
        om_metrics m;
        om_compare_masks(ma, mb, wa, ha, &m);
        /* Two methods' masks of one frame share its background (the eye pass decides
         * it, not the method): where they do not, they are masks of different frames
         * and the figures would mean nothing. */
        if (m.mismatched_bg) {
            fprintf(stderr, "ombra: %s and %s are not masks of one frame: %llu pixels are background "
                    "(128) in one only, so the scene, camera, --time or --size differ; render both "
                    "with the same SCENE, --size and --time, changing only --method\n",
                    a_path, b_path, (unsigned long long)m.mismatched_bg);
            free(ma);
            free(mb);
            return 1;
        }
        print_metrics(stdout, b_path, a_path, &m);
        if (diff) {
            uint8_t *rgb = malloc((size_t)wa * ha * 3);
            if (rgb) {
                om_diff_image(ma, mb, wa, ha, rgb);
                if ((st = img_write(diff, diff_fmt, rgb, 3, wa, ha, &d)) != OM_OK) rc = cli_error(NULL, &d, st);
            }
            free(rgb);
        }
    }
    free(ma);
    free(mb);
    return rc;
}
