/* report.c — `ombra report`: one self-contained HTML page (no scripts, no files from
 * elsewhere; pictures as PNG data URIs, charts as inline SVG). Per scene: what it is,
 * the sweep's charts each with a line on how to read it, the table behind them, and
 * the frame with the window where the methods disagree most with the reference
 * outlined, then that window's crops: the reference's mask, and each method's mask
 * and its difference image (false lit red, false shadowed blue). The tables and CSV
 * reading are report_table.c's. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "png.h"
#include "report.h"
#include "svg.h"

#include <stdlib.h>
#include <string.h>

static const char report_help[] =
    "usage: ombra report [--scenes LIST] [--size WxH] [--runs N] [--threads N] [--out DIR]\n"
    "                    [--tri-sweep] [--equal-memory] [--cross DIR] [--cross-doc FILE]\n"
    "                    [--cross-doc-rev TEXT]\n"
    "\n"
    "Runs 'ombra bench' with the same options, then writes DIR/index.html: per scene the\n"
    "charts, the table and crops where the methods disagree most (default: the default\n"
    "scene at its own size into out/report). A scene NAME@WxH is measured at that size\n"
    "(say, a big scene smaller than the rest); DIR/stability.csv, when there, adds the\n"
    "stability section. --equal-memory adds each method's best setting within memory\n"
    "budgets of 64 KiB to 16 MiB. The small-machines section reads what 'make cross-test'\n"
    "wrote into the --cross directory (default out/cross); without it, the tables that\n"
    "command last wrote into --cross-doc (default platform/cortex-m/README.md), labelled\n"
    "--cross-doc-rev (the commit that wrote them: make run passes git's). The page opens\n"
    "with a summary: per budget and accuracy the fastest setting measured, and the chips.\n"
    "--threads N: the threads each frame runs on (default: the CPUs online), which the\n"
    "page states.\n";

#define CROP_MAX 64
#define ZOOM 3

/* mask -> grey RGB as the mask file has it: lit 255, shadowed 0, background (no
 * surface) 128; crops are crop x crop (CROP_MAX, or less for a smaller image) */
void report_mask_rgb(const uint8_t *mask, uint32_t W, uint32_t x0, uint32_t y0, uint32_t crop,
                     uint8_t *rgb)
{
    for (uint32_t y = 0; y < crop; y++)
        for (uint32_t x = 0; x < crop; x++) {
            uint8_t v = mask[(size_t)(y0 + y) * W + x0 + x];
            uint8_t *o = rgb + 3 * ((size_t)y * crop + x);
            o[0] = o[1] = o[2] = v;
        }
}

void report_crop_rgb(const uint8_t *full, uint32_t W, uint32_t x0, uint32_t y0, uint32_t crop,
                     uint8_t *rgb)
{
    for (uint32_t y = 0; y < crop; y++)
        memcpy(rgb + (size_t)y * crop * 3, full + ((size_t)(y0 + y) * W + x0) * 3, crop * 3);
}

void report_img(FILE *f, const uint8_t *rgb, uint32_t w, uint32_t h, uint32_t zoom, const char *alt)
{
    fprintf(f, "<img alt=\"%s\" width=\"%u\" height=\"%u\" src=\"", alt, w * zoom, h * zoom);
    png_data_uri(f, rgb, w, h);
    fprintf(f, "\"/>");
}

static void inline_svg(FILE *f, const char *path)
{
    FILE *g = fopen(path, "r");
    if (!g) { fprintf(f, "<p>(chart %s missing)</p>\n", path); return; }
    char line[4096];
    while (fgets(line, sizeof line, g))
        if (strncmp(line, "<?xml", 5) != 0) fputs(line, f);
    fclose(g);
}

/* A yellow frame two pixels wide just outside the window, so the crops can be found
 * on the full frame (clipped at its edges). */
void report_outline(uint8_t *rgb, uint32_t W, uint32_t H, uint32_t x0, uint32_t y0, uint32_t crop)
{
    for (int y = (int)y0 - 2; y < (int)(y0 + crop) + 2; y++)
        for (int x = (int)x0 - 2; x < (int)(x0 + crop) + 2; x++) {
            bool inside = x >= (int)x0 && x < (int)(x0 + crop) && y >= (int)y0 && y < (int)(y0 + crop);
            if (inside || x < 0 || y < 0 || x >= (int)W || y >= (int)H) continue;
            uint8_t *o = rgb + 3 * ((size_t)y * W + (size_t)x);
            o[0] = 255; o[1] = 210; o[2] = 0;
        }
}

/* Renders every swept method at its defaults beside the reference and writes the
 * frame with the window where the methods' masks disagree most with the reference's
 * outlined, then that window's crops. */
static int scene_crops(FILE *f, const char *name, uint32_t w, uint32_t h)
{
    om_diag d;
    memset(&d, 0, sizeof d);
    cli_scene cs;
    om_status st = cli_load_named(name, &cs, &d);
    if (st) { cli_scene_free(&cs); return cli_error(name, &d, st); }
    om_view v;
    if ((st = cli_scene_view(&cs, w, h, &v, &d))) { cli_scene_free(&cs); return cli_error(name, &d, st); }
    const uint32_t W = v.cam.width, H = v.cam.height;
    size_t n = (size_t)W * H;
    uint8_t *ref = malloc(n), *frame = malloc(n * 3), *dm = malloc(n * 3);
    if (!ref || !frame || !dm) {
        free(ref); free(frame); free(dm);
        cli_scene_free(&cs);
        return cli_error(name, &d, cli_oom(&d));
    }
    const om_method *ms[16];
    uint8_t *masks[16];
    size_t nm = 0;
    cli_point p;
    om_method_cfg cfg;
    om_method_cfg_default(&cfg, om_method_find("ref"));
    if (cli_measure(om_method_find("ref"), &cfg, &cs, &v, 1, ref, frame, &p, &d)) {
        free(ref); free(frame); free(dm);
        cli_scene_free(&cs);
        return cli_error(name, &d, OM_E_INVALID);
    }
    for (size_t k = 0; k < om_method_count() && nm < 16; k++) {
        const om_method *m = om_method_at(k);
        const char *sw = cli_sweep(m);
        if ((sw && !sw[0]) || !strcmp(om_method_name(m), "ref")) continue;
        if (!(masks[nm] = malloc(n))) continue;
        om_method_cfg_default(&cfg, m);
        if (cli_measure(m, &cfg, &cs, &v, 1, masks[nm], NULL, &p, &d) == OM_OK) ms[nm++] = m;
        else free(masks[nm]);
    }
    /* the window (stepping by 8) with the most disagreements, summed over methods */
    const uint32_t crop = W < CROP_MAX || H < CROP_MAX ? (W < H ? W : H) : CROP_MAX;
    uint32_t bx = 0, by = 0;
    uint64_t best = 0;
    for (uint32_t y0 = 0; y0 + crop <= H; y0 += 8)
        for (uint32_t x0 = 0; x0 + crop <= W; x0 += 8) {
            uint64_t s = 0;
            for (size_t k = 0; k < nm; k++)
                for (uint32_t y = y0; y < y0 + crop; y += 2)
                    for (uint32_t x = x0; x < x0 + crop; x += 2) {
                        size_t i = (size_t)y * W + x;
                        s += masks[k][i] != ref[i] && ref[i] != OM_MASK_BG;
                    }
            if (s > best) { best = s; bx = x0; by = y0; }
        }
    fprintf(f, "<h3>Where the methods disagree</h3>\n<p>The reference frame at %ux%u; the yellow "
               "frame marks the %ux%u pixels at (%u, %u) where the methods, each at its defaults, "
               "disagree most with the reference. Below, that window %u times larger: the frame, "
               "the reference's shadow mask, and per method its mask and its difference (red: lit "
               "where the reference is shadowed; blue: the other way round). Masks as the mask file "
               "has them: lit white, shadowed black, and mid grey where no surface is (the "
               "background, 128 in the file, which no method decides).</p>\n",
            W, H, crop, crop, bx, by, ZOOM);
    uint8_t rgb[CROP_MAX * CROP_MAX * 3];
    report_crop_rgb(frame, W, bx, by, crop, rgb);   /* before the outline is drawn over the frame */
    memcpy(dm, frame, n * 3);
    report_outline(dm, W, H, bx, by, crop);
    fprintf(f, "<div class=\"frame\">");
    report_img(f, dm, W, H, 1, "reference frame, the crops' window outlined");
    fprintf(f, "</div>\n<div class=\"strip\">\n<div class=\"pair\"><figure>");
    report_img(f, rgb, crop, crop, ZOOM, "frame crop");
    fprintf(f, "<figcaption>frame</figcaption></figure>\n<figure>");
    report_mask_rgb(ref, W, bx, by, crop, rgb);
    report_img(f, rgb, crop, crop, ZOOM, "reference mask");
    fprintf(f, "<figcaption>ref</figcaption></figure></div>\n");
    for (size_t k = 0; k < nm; k++) {
        om_metrics mt;
        om_compare_masks(ref, masks[k], W, H, &mt);
        fprintf(f, "<div class=\"pair\"><figure>");
        report_mask_rgb(masks[k], W, bx, by, crop, rgb);
        report_img(f, rgb, crop, crop, ZOOM, om_method_name(ms[k]));
        fprintf(f, "<figcaption>%s mask</figcaption></figure>\n<figure>", om_method_name(ms[k]));
        om_diff_image(ref, masks[k], W, H, dm);
        report_crop_rgb(dm, W, bx, by, crop, rgb);
        report_img(f, rgb, crop, crop, ZOOM, "difference");
        fprintf(f, "<figcaption>%s: %.3f%% wrong</figcaption></figure></div>\n", om_method_name(ms[k]),
                100.0 * (1.0 - om_metrics_match(&mt)));
        free(masks[k]);
    }
    fprintf(f, "</div>\n");
    free(dm);
    free(ref);
    free(frame);
    cli_scene_free(&cs);
    return 0;
}

/* Copies a file that bench wrote into the page, or says it is missing. */
static void inline_file(FILE *f, const char *dir, const char *file, void (*put)(FILE *, const char *))
{
    char *path = cli_path(dir, file);
    if (path) put(f, path);
    free(path);
}

/* What a scene is, in a sentence: the built-in ones described, a file by the comment
 * lines that open it (a stability case says there what it provokes). */
static void scene_about(FILE *f, const char *name)
{
    if (!strcmp(name, "default")) {
        fprintf(f, "<p>The built-in default scene: a few solids on a plane under a spot light.</p>\n");
        return;
    }
    if (!strcmp(name, "town")) {
        fprintf(f, "<p>The built-in town (<code>ombra scene --town</code>): houses, towers, walls, "
                   "lamps and trees along streets over a ground a kilometre across, seen from eye "
                   "height down the main street under a low sun: the case cascaded shadow maps are "
                   "made for, and the comparison of the Rectilinear Texture Warping paper's "
                   "section 6.4.</p>\n");
        return;
    }
    if (!strncmp(name, "random-", 7)) {
        fprintf(f, "<p><code>%s</code>: random triangles of one constant total area in a box above a "
                   "plane (the Alias-Free Shadow Maps paper's Table 1): the more there are, the "
                   "smaller each, and the finer the shadows.</p>\n", name);
        return;
    }
    char *text;
    size_t len;
    om_diag d;
    if (om_file_read(name, &text, &len, &d) != OM_OK) return;
    fprintf(f, "<p><code>");
    svg_escape(f, name);
    fprintf(f, "</code>:");
    for (char *l = text; l && *l == '#'; l = strchr(l, '\n') ? strchr(l, '\n') + 1 : NULL) {
        size_t n = strcspn(l, "\n");
        if (!strncmp(l, "# ombra-set", 11)) continue;
        l[n] = 0;
        fputc(' ', f);
        svg_escape(f, l + 1 + (l[1] == ' '));
        if (l + n < text + len) l[n] = '\n';
    }
    fprintf(f, "</p>\n");
    free(text);
}

static bool same_scene(const rcsv *c, size_t r, const void *scene)
{
    return !strcmp(rcsv_get(c, r, "scene"), (const char *)scene);
}

static const rcol bench_cols[] = {
    {"method", "method", R_TEXT, NULL},
    {"setting", "setting", R_TEXT, NULL},
    {"time_ms", "frame, ms (median)", R_MS, NULL},
    {"time_min_ms", "fastest\xe2\x80\x93slowest, ms", R_RANGE, "time_max_ms"},
    {"init_ms", "init, ms", R_MS, NULL},
    {"build_ms", "map build, ms", R_MS, NULL},
    {"resolve_ms", "lookup, ms", R_MS, NULL},
    {"bytes", "memory, bytes", R_INT, NULL},
    {"samples", "covered samples", R_INT, NULL},
    {"mismatch_share", "wrong, %", R_SHARE, NULL},
    {"edge_mismatch_share", "wrong near edges, %", R_SHARE, NULL},
};

static const rcol stability_cols[] = {
    {"case", "case", R_TEXT, NULL},
    {"method", "method", R_TEXT, NULL},
    {"frames", "frames", R_INT, NULL},
    {"mean_mismatch", "wrong, mean %", R_SHARE, NULL},
    {"worst_mismatch", "wrong, worst frame %", R_SHARE, NULL},
    {"mean_edge_mismatch", "wrong near edges, %", R_SHARE, NULL},
    {"flicker", "flicker, %", R_SHARE, NULL},
    {"median_ms", "frame, ms (median)", R_MS, NULL},
    {"bytes", "memory, bytes", R_INT, NULL},
};

/* One scene's part of the page: what it is, its three charts each with how to read it,
 * its rows of the table, and its crops. */
static int scene_part(FILE *f, const char *dir, const char *name, uint32_t w, uint32_t h,
                      const rcsv *bench, const char *runs)
{
    const char *base = cli_base_name(name);
    uint32_t W = w, H = h;
    for (size_t r = 0; r < bench->rows; r++)
        if (same_scene(bench, r, name)) {
            W = (uint32_t)rcsv_num(bench, r, "width");
            H = (uint32_t)rcsv_num(bench, r, "height");
            break;
        }
    fprintf(f, "<h2 id=\"scene-");
    svg_escape(f, base);
    fprintf(f, "\">");
    svg_escape(f, base);
    fprintf(f, " at %ux%u</h2>\n", W, H);
    scene_about(f, name);
    static const char *const charts[3] = {"time", "bytes", "first"};
    static const char *const read[3] = {
        "Down is more accurate, left is faster. Each point is one setting of a method, each method "
        "a colour and a marker; points at 0 wrong sit on a row of their own under the axis' decades, "
        "each method in a lane, so the exact methods stay apart. The grey "
        "staircase is the Pareto front over all methods: every point above or right of it is beaten "
        "on both counts by a point on it. A bar spans the fastest to the slowest of the %s frames: "
        "points whose bars overlap are not reliably different in speed.",
        "Down is more accurate, left needs less memory (the method's own arena at its peak, the "
        "frame's samples not counted). Read across at the memory you can spare: the lowest point "
        "left of it is the best accuracy that memory buys. %s",
        "The first frame after the scene changes: the method's init (the reference builds its BVH "
        "here; a map's memory is cleared) plus one frame. Methods that pay a lot up front move "
        "right. The bars are the spread of the %s frames."};
    for (int c = 0; c < 3; c++) {
        char file[300];
        snprintf(file, sizeof file, "%s-%s.svg", base, charts[c]);
        char id[300];
        report_chart_id(id, sizeof id, name, charts[c]);
        fprintf(f, "<p class=\"read\">");
        fprintf(f, read[c], c == 1 ? "" : runs);
        fprintf(f, "</p>\n<div class=\"chart-box\" id=\"");
        svg_escape(f, id);
        fprintf(f, "\">");
        inline_file(f, dir, file, inline_svg);
        fprintf(f, "</div>\n");
    }
    fprintf(f, "<h3>The numbers</h3>\n<p>Per point (%s frames each): the median frame and their spread, "
               "the method's init, the map's build and the lookup per sample (a frame's other "
               "stages, the eye pass and shading, are the same for every method and in "
               "<code>bench.csv</code>), the arena's peak bytes, and the share of the visible "
               "samples whose shadow differs from the reference, overall and near shadow edges.</p>\n",
            runs);
    report_table(f, bench, bench_cols, sizeof bench_cols / sizeof bench_cols[0], same_scene, name);
    return scene_crops(f, name, w, h);
}

static void step(int i, int n, const char *what, const char *name)
{
    fprintf(stderr, "report: [%d/%d] %s%s\n", i, n, what, name ? name : "");
}

int cmd_report(int argc, char **argv)
{
    const char *scenes = "default", *dir = "out/report", *size = NULL, *runs = "3", *cross = "out/cross";
    const char *threads = NULL, *doc = "platform/cortex-m/README.md", *doc_rev = NULL;
    bool tri = false, memory = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { fputs(report_help, stdout); return 0; }
        if (!strcmp(a, "--tri-sweep")) { tri = true; continue; }
        if (!strcmp(a, "--equal-memory")) { memory = true; continue; }
        if (!v) return cli_usage_error("report", "unknown option or missing value: '%s'", a);
        if (!strcmp(a, "--scenes")) scenes = v;
        else if (!strcmp(a, "--out")) dir = v;
        else if (!strcmp(a, "--size")) size = v;
        else if (!strcmp(a, "--runs")) runs = v;
        else if (!strcmp(a, "--cross")) cross = v;
        else if (!strcmp(a, "--cross-doc")) doc = v;
        else if (!strcmp(a, "--cross-doc-rev")) doc_rev = v;
        else if (!strcmp(a, "--threads")) threads = v;
        else return cli_usage_error("report", "unknown option '%s'", a);
        i++;
    }
    uint32_t W = 0, H = 0;
    if (size && !cli_parse_size(size, &W, &H)) return cli_usage_error("report", "--size takes WxH, not '%s'", size);
    size_t nscenes = 1;
    for (const char *p = scenes; *p; p++) nscenes += *p == ',';
    const int nsteps = 3 + (int)nscenes + memory;
    step(1, nsteps, "the sweep: ombra bench", NULL);
    char *bargv[16] = {"report", "--scenes", (char *)scenes, "--runs", (char *)runs, "--out", (char *)dir,
                       "--no-scaling"};
    int bargc = 8;
    if (threads) { bargv[bargc++] = "--threads"; bargv[bargc++] = (char *)threads; }
    if (size) { bargv[bargc++] = "--size"; bargv[bargc++] = (char *)size; }
    if (tri) bargv[bargc++] = "--tri-sweep";
    int rc = cmd_bench(bargc, bargv);   /* its usage errors name 'report' (argv[0]) */
    if (rc) return rc;
    if (memory) {
        step(2, nsteps, "accuracy at equal memory", NULL);
        /* two frames a point: its time is a median of two, the section's cost half the sweep's */
        if ((rc = report_memory_measure(dir, atoi(runs) < 2 ? atoi(runs) : 2))) return rc;
    }
    const rcross x = {cross, doc, doc_rev};
    om_diag d;
    memset(&d, 0, sizeof d);
    om_out page;
    rcsv bench;
    char *path = cli_path(dir, "index.html"), *list = malloc(strlen(scenes) + 1);
    char *csv = cli_path(dir, "bench.csv");
    om_status st = path && list && csv ? om_out_open(&page, path, &d) : cli_oom(&d);
    if (st != OM_OK) { free(path); free(list); free(csv); return cli_error(NULL, &d, st); }
    if (!rcsv_load(&bench, csv)) memset(&bench, 0, sizeof bench);
    rcsv mem;
    char *mpath = memory ? cli_path(dir, "memory.csv") : NULL;
    bool have_mem = mpath && rcsv_load(&mem, mpath);
    free(mpath);
    FILE *f = page.f;
    fprintf(f, "<!DOCTYPE html>\n<html xmlns=\"http://www.w3.org/1999/xhtml\" lang=\"en\">\n<head>\n"
               "<meta charset=\"utf-8\"/>\n<title>ombra report</title>\n<style>\n"
               "body { font-family: sans-serif; margin: 2em; color: #222; max-width: 1180px; }\n"
               ".scroll { overflow-x: auto; max-width: 100%%; }\n"
               "table { border-collapse: collapse; font-size: 12px; }\n"
               "td, th { border: 1px solid #ccc; padding: 2px 6px; text-align: right; }\n"
               "th { background: #f3f3f3; vertical-align: bottom; }\n"
               "td.t { text-align: left; white-space: nowrap; }\n"
               "td.m { text-align: left; }\n"
               "svg { max-width: 100%%; height: auto; }\n"
               "p.read { max-width: 800px; margin-bottom: 0.3em; }\n"
               "img { image-rendering: pixelated; border: 1px solid #888; max-width: 100%%; height: auto; }\n"
               ".strip { display: flex; flex-wrap: wrap; gap: 8px; margin-top: 8px; }\n"
               "figure { margin: 0; font-size: 12px; text-align: center; }\n"
               ".pair { display: flex; gap: 4px; }\n"
               ".cards { display: flex; flex-wrap: wrap; gap: 12px; align-items: flex-start; }\n"
               "table.summary td { text-align: left; vertical-align: top; }\n"
               "table.summary small { color: #555; }\n"
               "caption { font-weight: bold; text-align: left; padding: 2px 0; }\n"
               "#summary { border: 1px solid #bbb; padding: 0 12px 12px; background: #fcfcf7; }\n"
               "#summary h2 { margin-top: 0.5em; }\n"
               ".anim img { border-color: #444; }\n"
               "</style>\n</head>\n<body>\n<h1>ombra: hard shadows, accuracy against speed</h1>\n");
    report_summary(f, bench.rows ? &bench : NULL, have_mem ? &mem : NULL, &x);
    fprintf(f, "<p>Every method renders the same visible samples; accuracy is the share of samples "
               "whose binary shadow state differs from the exact reference (<code>ref</code>). "
               "Times are medians of %s frames, each on %u thread%s (<code>--threads</code>; "
               "the <code>threads</code> column of <code>bench.csv</code> says how many jobs "
               "ran); a method's init (where <code>ref</code> builds its BVH) is its own stage, "
               "on one thread, paid again whenever the scene changes. All the numbers are in "
               "<code>bench.csv</code> beside this page.</p>\n",
            runs, cli_threads(), cli_threads() == 1 ? "" : "s");
    memcpy(list, scenes, strlen(scenes) + 1);
    fprintf(f, "<p>Scenes:");
    for (char *name = strtok(list, ","); name; name = strtok(NULL, ",")) {
        uint32_t sw, sh;
        cli_scene_size(name, &sw, &sh);
        fprintf(f, " <a href=\"#scene-");
        svg_escape(f, cli_base_name(name));
        fprintf(f, "\">");
        svg_escape(f, cli_base_name(name));
        fprintf(f, "</a>");
    }
    fprintf(f, ".</p>\n");
    memcpy(list, scenes, strlen(scenes) + 1);
    int k = 2 + memory;
    for (char *name = strtok(list, ","); name && !rc; name = strtok(NULL, ","), k++) {
        uint32_t sw, sh;
        cli_scene_size(name, &sw, &sh);   /* bench has checked it */
        step(k, nsteps, "charts, table and crops of ", name);
        rc = scene_part(f, dir, name, sw ? sw : W, sw ? sh : H, &bench, runs);
    }
    if (tri && !rc) {
        fprintf(f, "<h2>The exact methods against scene size</h2>\n<p class=\"read\">The first frame "
                   "(init and one frame) of each exact method on 1K to 1M random triangles: how its "
                   "cost grows with the scene. <code>ref</code> rebuilds its BVH whenever the "
                   "triangles change; the irregular z-buffer's cost follows the visible samples and "
                   "the triangles that reach them.</p>\n");
        inline_file(f, dir, "triangles.svg", inline_svg);
    }
    if (have_mem && !rc) report_memory(f, &mem);
    if (!rc) report_machines(f, &x);
    char *stab = cli_path(dir, "stability.csv");
    rcsv sc;
    if (!rc) step(nsteps - 1, nsteps, "stability strips and crops, from ", stab);
    if (!rc && stab && rcsv_load(&sc, stab)) {
        report_stability(f, &sc);
        fprintf(f, "<h3>The stability numbers</h3>\n<p>Per case and method: the share of samples "
                   "wrong against the reference (mean and worst frame), the same near shadow edges, "
                   "flicker (state changes the reference does not have), median frame time and "
                   "arena bytes.</p>\n");
        report_table(f, &sc, stability_cols, sizeof stability_cols / sizeof stability_cols[0], NULL, NULL);
        rcsv_free(&sc);
    }
    free(stab);
    step(nsteps, nsteps, "the page", NULL);
    fprintf(f, "</body>\n</html>\n");
    om_out *outs[1] = {&page};
    if (rc) om_out_discard(&page);
    else if ((st = om_out_commit(outs, 1, &d)) != OM_OK) rc = cli_error(NULL, &d, st);
    if (!rc) printf("wrote %s\n", path);
    rcsv_free(&bench);
    if (have_mem) rcsv_free(&mem);
    free(csv);
    free(path);
    free(list);
    return rc;
}
