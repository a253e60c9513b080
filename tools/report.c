/* report.c — `ombra report`: one self-contained HTML page (no scripts, no files from
 * elsewhere; pictures as PNG data URIs, charts as inline SVG) with the sweep's charts,
 * the table behind them, and per scene a strip of crops where the methods disagree
 * most with the reference: the reference's mask, and each method's mask and its
 * difference image (false lit red, false shadowed blue). */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "png.h"
#include "svg.h"

#include <stdlib.h>
#include <string.h>

static const char report_help[] =
    "usage: ombra report [--scenes LIST] [--size WxH] [--runs N] [--out DIR] [--tri-sweep]\n"
    "\n"
    "Runs 'ombra bench' with the same options, then writes DIR/index.html: the charts,\n"
    "the table, and crops of each scene where the methods disagree most (default: the\n"
    "default scene at its own size into out/report).\n";

#define CROP_MAX 64
#define ZOOM 3

/* mask -> grey RGB: lit light, shadowed dark, background black; crops are crop x crop
 * (CROP_MAX, or less for a smaller image) */
static void mask_rgb(const uint8_t *mask, uint32_t W, uint32_t x0, uint32_t y0, uint32_t crop,
                     uint8_t *rgb)
{
    for (uint32_t y = 0; y < crop; y++)
        for (uint32_t x = 0; x < crop; x++) {
            uint8_t m = mask[(size_t)(y0 + y) * W + x0 + x];
            uint8_t v = m == OM_MASK_LIT ? 235 : m == OM_MASK_SHADOW ? 60 : 0;
            uint8_t *o = rgb + 3 * ((size_t)y * crop + x);
            o[0] = o[1] = o[2] = v;
        }
}

static void crop_rgb(const uint8_t *full, uint32_t W, uint32_t x0, uint32_t y0, uint32_t crop,
                     uint8_t *rgb)
{
    for (uint32_t y = 0; y < crop; y++)
        memcpy(rgb + (size_t)y * crop * 3, full + ((size_t)(y0 + y) * W + x0) * 3, crop * 3);
}

static void img(FILE *f, const uint8_t *rgb, uint32_t w, uint32_t h, uint32_t zoom, const char *alt)
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

static void table(FILE *f, const char *csv)
{
    FILE *g = fopen(csv, "r");
    if (!g) return;
    char line[2048];
    fprintf(f, "<table>\n");
    int skip = -1;   /* the methods' counters (the CSV's stats column) stay in the CSV */
    for (int row = 0; fgets(line, sizeof line, g); row++) {
        line[strcspn(line, "\n")] = 0;
        fprintf(f, "<tr>");
        int col = 0;
        for (char *c = line, *e; c; c = e ? e + 1 : NULL, col++) {
            e = strchr(c, ',');
            if (e) *e = 0;
            if (row == 0 && !strcmp(c, "stats")) skip = col;
            if (col == skip) continue;
            fprintf(f, row ? "<td>" : "<th>");
            svg_escape(f, c);
            fprintf(f, row ? "</td>" : "</th>");
        }
        fprintf(f, "</tr>\n");
    }
    fprintf(f, "</table>\n");
    fclose(g);
}

/* Renders every swept method at its defaults beside the reference and writes the
 * scene's section: the reference frame, then crops at the window where the methods'
 * masks disagree most with the reference's. */
static int scene_section(FILE *f, const char *name, uint32_t w, uint32_t h)
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
    uint8_t *ref = malloc(n), *frame = malloc(n * 3);
    const om_method *ms[16];
    uint8_t *masks[16];
    size_t nm = 0;
    cli_point p;
    om_method_cfg cfg;
    om_method_cfg_default(&cfg);
    if (cli_measure(om_method_find("ref"), &cfg, &cs, &v, 1, ref, frame, &p, &d)) {
        cli_scene_free(&cs);
        return cli_error(name, &d, OM_E_INVALID);
    }
    for (size_t k = 0; k < om_method_count() && nm < 16; k++) {
        const om_method *m = om_method_at(k);
        const char *sw = om_method_sweep(m);
        if ((sw && !sw[0]) || !strcmp(m->name, "ref")) continue;
        masks[nm] = malloc(n);
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
    const char *base = strrchr(name, '/') ? strrchr(name, '/') + 1 : name;
    fprintf(f, "<h2>");
    svg_escape(f, base);
    fprintf(f, " at %ux%u</h2>\n<p>The reference frame; the crops below are its %ux%u pixels at "
               "(%u, %u), where the methods disagree most with the reference.</p>\n", W, H, crop, crop, bx, by);
    img(f, frame, W, H, 1, "reference frame");
    uint8_t rgb[CROP_MAX * CROP_MAX * 3], *dm = malloc(n * 3);
    fprintf(f, "\n<div class=\"strip\">\n<figure>");
    crop_rgb(frame, W, bx, by, crop, rgb);
    img(f, rgb, crop, crop, ZOOM, "frame crop");
    fprintf(f, "<figcaption>frame</figcaption></figure>\n<figure>");
    mask_rgb(ref, W, bx, by, crop, rgb);
    img(f, rgb, crop, crop, ZOOM, "reference mask");
    fprintf(f, "<figcaption>ref</figcaption></figure>\n");
    for (size_t k = 0; k < nm; k++) {
        om_metrics mt;
        om_compare_masks(ref, masks[k], W, H, &mt);
        fprintf(f, "<figure>");
        mask_rgb(masks[k], W, bx, by, crop, rgb);
        img(f, rgb, crop, crop, ZOOM, ms[k]->name);
        fprintf(f, "<figcaption>%s mask</figcaption></figure>\n<figure>", ms[k]->name);
        om_diff_image(ref, masks[k], W, H, dm);
        crop_rgb(dm, W, bx, by, crop, rgb);
        img(f, rgb, crop, crop, ZOOM, "difference");
        fprintf(f, "<figcaption>%s diff, %.3f%% of the frame wrong</figcaption></figure>\n",
                ms[k]->name, 100.0 * (1.0 - om_metrics_match(&mt)));
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

int cmd_report(int argc, char **argv)
{
    const char *scenes = "default", *dir = "out/report", *size = NULL, *runs = "3";
    bool tri = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { fputs(report_help, stdout); return 0; }
        if (!strcmp(a, "--tri-sweep")) { tri = true; continue; }
        if (!v) return cli_usage_error("report", "unknown option or missing value: '%s'", a);
        if (!strcmp(a, "--scenes")) scenes = v;
        else if (!strcmp(a, "--out")) dir = v;
        else if (!strcmp(a, "--size")) size = v;
        else if (!strcmp(a, "--runs")) runs = v;
        else return cli_usage_error("report", "unknown option '%s'", a);
        i++;
    }
    uint32_t W = 0, H = 0;
    if (size && !cli_parse_size(size, &W, &H)) return cli_usage_error("report", "--size takes WxH, not '%s'", size);
    char *bargv[12] = {"report", "--scenes", (char *)scenes, "--runs", (char *)runs, "--out", (char *)dir};
    int bargc = 7;
    if (size) { bargv[bargc++] = "--size"; bargv[bargc++] = (char *)size; }
    if (tri) bargv[bargc++] = "--tri-sweep";
    int rc = cmd_bench(bargc, bargv);   /* its usage errors name 'report' (argv[0]) */
    if (rc) return rc;
    om_diag d;
    memset(&d, 0, sizeof d);
    om_out page;
    char *path = cli_path(dir, "index.html"), *list = malloc(strlen(scenes) + 1);
    om_status st = path && list ? om_out_open(&page, path, &d) : cli_oom(&d);
    if (st != OM_OK) { free(path); free(list); return cli_error(NULL, &d, st); }
    FILE *f = page.f;
    fprintf(f, "<!DOCTYPE html>\n<html xmlns=\"http://www.w3.org/1999/xhtml\" lang=\"en\">\n<head>\n"
               "<meta charset=\"utf-8\"/>\n<title>ombra report</title>\n<style>\n"
               "body { font-family: sans-serif; margin: 2em; color: #222; }\n"
               "table { border-collapse: collapse; font-size: 12px; display: block; overflow-x: auto; }\n"
               "td, th { border: 1px solid #ccc; padding: 2px 6px; text-align: right; }\n"
               "img { image-rendering: pixelated; border: 1px solid #888; }\n"
               ".strip { display: flex; flex-wrap: wrap; gap: 8px; }\n"
               "figure { margin: 0; font-size: 12px; text-align: center; }\n"
               "</style>\n</head>\n<body>\n<h1>ombra: hard shadows, accuracy against speed</h1>\n"
               "<p>Every method renders the same visible samples; accuracy is the share of samples "
               "whose binary shadow state differs from the exact reference (<code>ref</code>). "
               "Times are medians of %s frames on one core at %s; a method's init (where "
               "<code>ref</code> builds its BVH) is its own stage, paid again whenever the scene "
               "changes.</p>\n", runs, size ? size : "each scene's own size");
    memcpy(list, scenes, strlen(scenes) + 1);
    fprintf(f, "<h2>Charts</h2>\n");
    static const char *const charts[3] = {"time", "bytes", "first"};
    for (char *name = strtok(list, ","); name; name = strtok(NULL, ",")) {
        const char *base = strrchr(name, '/') ? strrchr(name, '/') + 1 : name;
        for (int c = 0; c < 3; c++) {
            char file[300];
            snprintf(file, sizeof file, "%s-%s.svg", base, charts[c]);
            inline_file(f, dir, file, inline_svg);
        }
    }
    if (tri) inline_file(f, dir, "triangles.svg", inline_svg);
    fprintf(f, "<h2>The table</h2>\n");
    inline_file(f, dir, "bench.csv", table);
    memcpy(list, scenes, strlen(scenes) + 1);
    char *stab = cli_path(dir, "stability.csv");
    FILE *sf = stab ? fopen(stab, "r") : NULL;
    if (sf) {
        fclose(sf);
        fprintf(f, "<h2>Stability: where each method is known to fail</h2>\n"
                   "<p>Every method along the 30-frame camera and light paths of the cases in "
                   "<code>tests/stability/</code> (<code>make stability</code>): mismatch share "
                   "against the reference (mean and worst frame), the same near shadow edges, "
                   "flicker (state changes the reference does not have), median frame time and "
                   "arena bytes.</p>\n");
        table(f, stab);
    }
    free(stab);
    for (char *name = strtok(list, ","); name && !rc; name = strtok(NULL, ","))
        rc = scene_section(f, name, W, H);
    fprintf(f, "</body>\n</html>\n");
    om_out *outs[1] = {&page};
    if (rc) om_out_discard(&page);
    else if ((st = om_out_commit(outs, 1, &d)) != OM_OK) rc = cli_error(NULL, &d, st);
    if (!rc) printf("wrote %s\n", path);
    free(path);
    free(list);
    return rc;
}
