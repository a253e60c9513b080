/* report_stability.c — the report's stability section (see report.h): what
 * `make stability` measured along each failure case's 30-frame path, drawn as small
 * multiples (one strip per case, one small chart per method, each on its own scale:
 * flicker is a shape, and one method far off would flatten the others; the numbers
 * over each say how big), then the frame where flicker is worst, re-rendered along the
 * same path so it is the very frame the numbers count. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "report.h"
#include "svg.h"

#include <stdlib.h>
#include <string.h>

/* make stability's image size and cases (tests/stability/stability.c) */
#define SW 160
#define SH 120
#define CASES "tests/stability/"
#define CROP 48
#define CELL_W 184
#define CELL_H 72

/* The per-frame shares of row r ("0.1;0.2;..."); returns how many (at most max). */
static int frame_shares(const rcsv *sc, size_t r, double *out, int max)
{
    const char *p = rcsv_get(sc, r, "frame_mismatch");
    int n = 0;
    while (*p && n < max) {
        char *end;
        out[n++] = strtod(p, &end);
        if (end == p) break;
        p = *end == ';' ? end + 1 : end;
    }
    return n;
}

/* A method the strips show: not the reference (always 0) nor `none` (no shadows). */
static bool shown(const char *method)
{
    return strcmp(method, "ref") && strcmp(method, "none");
}

/* One small chart: a method's mismatch share over the frames, from 0 to its worst
 * frame, the most flickering frame marked. */
static void cell(FILE *f, const char *method, const double *v, int n, int flick)
{
    const double x0 = 6, x1 = CELL_W - 6, y0 = CELL_H - 8, y1 = 20;
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"multiple\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\" font-family=\"sans-serif\">\n", CELL_W, CELL_H, CELL_W, CELL_H);
    fprintf(f, "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"#fafafa\" stroke=\"#bbb\"/>\n",
            x0, y1, x1 - x0, y0 - y1);
    double mean = 0, worst = 0;
    for (int i = 0; i < n; i++) { mean += v[i] / n; if (v[i] > worst) worst = v[i]; }
    const double top = worst;
    char a[32], b[32];
    svg_format(a, sizeof a, mean, SVG_SHARE);
    svg_format(b, sizeof b, worst, SVG_SHARE);
    fprintf(f, "<text x=\"6\" y=\"13\" font-size=\"10\"><tspan font-weight=\"bold\" font-size=\"11\">");
    svg_escape(f, method);
    fprintf(f, "</tspan> mean %s, worst %s</text>\n", a, b);
    fprintf(f, "<polyline class=\"cell\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\" points=\"");
    for (int i = 0; i < n; i++) {
        double x = x0 + (x1 - x0) * (n > 1 ? (double)i / (n - 1) : 0.5);
        double y = y0 - (y0 - y1) * (top > 0 ? v[i] / top : 0);
        fprintf(f, "%.1f,%.1f ", x, y);
    }
    fprintf(f, "\"/>\n");
    if (flick > 0 && flick < n) {
        double x = x0 + (x1 - x0) * (n > 1 ? (double)flick / (n - 1) : 0.5);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#d62728\" "
                   "stroke-dasharray=\"2,2\"><title>frame %d flickers most</title></line>\n",
                x, y1, x, y0, flick);
    }
    fprintf(f, "</svg>\n");
}

/* Frames 0..last of the case's path with one state of m (progressive methods refine,
 * as under make stability); the masks of frames last - 1 and last come out, and the
 * last frame's pixels when rgb is given. */
static om_status path(const om_scene *s, const om_method *m, const om_method_cfg *cfg, int frames,
                      int last, uint8_t *prev, uint8_t *cur, uint8_t *rgb, om_diag *d)
{
    size_t mn, full, fbytes = cli_frame_rows(NULL, SW, SH, false);
    om_status st = om_method_bytes(m, cfg, s, SW, SH, &mn, &full);
    if (st) return st;
    void *mem = malloc(full ? full : 1), *fmem = malloc(fbytes), *px = malloc((size_t)SW * SH * 3);
    if (!mem || !fmem || !px) { free(mem); free(fmem); free(px); return cli_oom(d); }
    om_arena ma, fa;
    om_arena_init(&ma, mem, full, "method");
    om_arena_init(&fa, fmem, fbytes, "frame");
    void *state;
    st = om_method_init(m, &state, &ma, cfg, s, SW, SH, d);
    float tend = 0;
    if (s->ncam_keys) tend = s->cam_keys[s->ncam_keys - 1].t;
    if (s->nlight_keys && s->light_keys[s->nlight_keys - 1].t > tend) tend = s->light_keys[s->nlight_keys - 1].t;
    for (int fr = 0; fr <= last && st == OM_OK; fr++) {
        om_camera cam;
        om_light light;
        om_view v;
        om_scene_at(s, frames > 1 ? tend * (float)fr / (float)(frames - 1) : 0, &cam, &light);
        cam.width = SW;
        cam.height = SH;
        if ((st = om_view_init(&v, &cam, &light, s, d)) != OM_OK) break;
        om_shade_cfg shade;
        om_shade_cfg_default(&shade);
        om_framebuffer fb = {OM_RGB888, SW, SH, (size_t)SW * 3, (uint8_t *)px};
        cli_masks g = {fr == last ? cur : prev, fr == last ? rgb : NULL};
        om_frame_desc fd;
        memset(&fd, 0, sizeof fd);
        fd.scene = s; fd.view = &v; fd.method = m; fd.method_state = state;
        fd.shade = &shade; fd.fb = &fb; fd.on_strip = cli_grab_mask; fd.user = &g; fd.clock = om_clock_ns;
        om_frame_stats fs;
        st = om_render_frame(&fd, &fa, &fs, d);
    }
    free(mem);
    free(fmem);
    free(px);
    return st;
}

/* The case's "# ombra-set NAME=VALUE ..." lines, as make stability applies them: each
 * to the methods that take it. */
static void case_settings(const char *text, cli_settings *c)
{
    c->n = 0;
    for (const char *p = strstr(text, "# ombra-set "); p; p = strstr(p + 1, "# ombra-set ")) {
        const char *q = p + 12;
        while (*q && *q != '\n') {
            size_t n = strcspn(q, " \n");
            char item[96];
            snprintf(item, sizeof item, "%.*s", (int)(n < 95 ? n : 95), q);
            if (n) cli_settings_add(c, item);
            q += n;
            while (*q == ' ') q++;
        }
    }
}

/* The worst flicker of a case: method m's frames flick - 1 and flick, with the
 * window where its state changes most while the reference's does not. */
static void flicker_crops(FILE *f, const char *name, const char *method, int frames, int flick)
{
    char path_s[256];
    snprintf(path_s, sizeof path_s, CASES "%s.scene", name);
    om_diag d;
    memset(&d, 0, sizeof d);
    cli_scene cs;
    char *text;
    size_t len;
    const om_method *m = om_method_find(method), *ref = om_method_find("ref");
    if (!m || !ref || om_file_read(path_s, &text, &len, &d) != OM_OK) {
        fprintf(f, "<p>(no crops: %s is not here)</p>\n", path_s);
        return;
    }
    static cli_settings set;   /* 4 KB: off the stack */
    case_settings(text, &set);
    free(text);
    om_method_cfg cfg, rcfg;
    if (!cli_cfg(m, &set, &cfg, NULL) || !cli_cfg(ref, &set, &rcfg, NULL)) {
        fprintf(f, "<p>(no crops: %s has a setting out of range)</p>\n", path_s);
        return;
    }
    size_t n = (size_t)SW * SH;
    uint8_t *buf = malloc(n * 4 + n * 3 * 2);
    if (!buf || cli_scene_load(&cs, path_s, 0, &d) != OM_OK) {
        free(buf);
        fprintf(f, "<p>(no crops: %s does not load)</p>\n", path_s);
        return;
    }
    uint8_t *rp = buf, *rc = rp + n, *mp = rc + n, *mc = mp + n, *rgb = mc + n, *img = rgb + n * 3;
    om_status st = path(&cs.scene, ref, &rcfg, frames, flick, rp, rc, rgb, &d);
    if (st == OM_OK) st = path(&cs.scene, m, &cfg, frames, flick, mp, mc, NULL, &d);
    if (st != OM_OK) {
        fprintf(f, "<p>(no crops: ");
        svg_escape(f, d.msg);
        fprintf(f, ")</p>\n");
    } else {
        uint32_t bx = 0, by = 0, best = 0;
        for (uint32_t y0 = 0; y0 + CROP <= SH; y0 += 4)
            for (uint32_t x0 = 0; x0 + CROP <= SW; x0 += 4) {
                uint32_t c = 0;
                for (uint32_t y = y0; y < y0 + CROP; y++)
                    for (uint32_t x = x0; x < x0 + CROP; x++) {
                        size_t i = (size_t)y * SW + x;
                        c += mp[i] != mc[i] && rp[i] == rc[i] && rc[i] != OM_MASK_BG;
                    }
                if (c > best) { best = c; bx = x0; by = y0; }
            }
        /* the flicker itself: the method's mask at the frame, its flickering samples magenta */
        for (size_t i = 0; i < n; i++) {
            uint8_t v = mc[i] == OM_MASK_LIT ? 235 : mc[i] == OM_MASK_SHADOW ? 60 : 0;
            bool fl = mp[i] != mc[i] && rp[i] == rc[i] && rc[i] != OM_MASK_BG;
            img[3 * i] = fl ? 230 : v;
            img[3 * i + 1] = fl ? 0 : v;
            img[3 * i + 2] = fl ? 200 : v;
        }
        fprintf(f, "<p>Where it flickers most: <b>");
        svg_escape(f, method);
        fprintf(f, "</b> from frame %d to %d, %u samples change in the %ux%u window at (%u, %u) while "
                   "the reference's stay (magenta).</p>\n<div class=\"strip\">\n<figure>",
                flick - 1, flick, best, CROP, CROP, bx, by);
        uint8_t c[CROP * CROP * 3];
        uint8_t *frame = malloc(n * 3);
        if (frame) {
            memcpy(frame, rgb, n * 3);
            report_outline(frame, SW, SH, bx, by, CROP);
            report_img(f, frame, SW, SH, 2, "reference frame, the window outlined");
            fprintf(f, "<figcaption>frame %d</figcaption></figure>\n<figure>", flick);
            free(frame);
        }
        report_mask_rgb(rc, SW, bx, by, CROP, c);
        report_img(f, c, CROP, CROP, 4, "reference mask");
        fprintf(f, "<figcaption>ref, frame %d</figcaption></figure>\n<figure>", flick);
        report_mask_rgb(mp, SW, bx, by, CROP, c);
        report_img(f, c, CROP, CROP, 4, "mask before");
        fprintf(f, "<figcaption>%s, frame %d</figcaption></figure>\n<figure>", method, flick - 1);
        report_crop_rgb(img, SW, bx, by, CROP, c);
        report_img(f, c, CROP, CROP, 4, "mask after, flicker marked");
        fprintf(f, "<figcaption>%s, frame %d</figcaption></figure>\n</div>\n", method, flick);
    }
    free(buf);
    cli_scene_free(&cs);
}

void report_stability(FILE *f, const rcsv *sc)
{
    fprintf(f, "<h2 id=\"stability\">Stability: where each method is known to fail</h2>\n"
               "<p class=\"read\">Each case of <code>tests/stability/</code> (<code>make stability</code>, "
               "at %ux%u) provokes a known failure along a 30-frame camera and light path. Per case, "
               "one small chart per method: the share of samples wrong against the reference over "
               "the frames, each from 0 to its own worst frame (the numbers above it say how "
               "much that is). A flat line is a stable method; a jagged one flickers. The dashed "
               "red line marks the "
               "frame whose changes flicker most (state changes the reference does not have). The "
               "exact methods stay at 0; <code>ref</code> and <code>none</code> are left out.</p>\n",
            SW, SH);
    if (rcsv_col(sc, "frame_mismatch") < 0)
        fprintf(f, "<p>(This stability.csv has no per-frame column: run <code>make stability</code> "
                   "again for the strips.)</p>\n");
    const char *done[64];
    size_t ndone = 0;
    for (size_t r = 0; r < sc->rows && ndone < 64; r++) {
        const char *name = rcsv_get(sc, r, "case");
        bool seen = false;
        for (size_t k = 0; k < ndone; k++) seen |= !strcmp(done[k], name);
        if (seen || rcsv_col(sc, "frame_mismatch") < 0) continue;
        done[ndone++] = name;
        double v[240], worst_flicker = -1;
        const char *flicker_method = NULL;
        int flicker_frame = 0, frames = (int)rcsv_num(sc, r, "frames");
        for (size_t q = r; q < sc->rows; q++) {
            if (strcmp(rcsv_get(sc, q, "case"), name) || !shown(rcsv_get(sc, q, "method"))) continue;
            if (rcsv_num(sc, q, "flicker") > worst_flicker) {
                worst_flicker = rcsv_num(sc, q, "flicker");
                flicker_method = rcsv_get(sc, q, "method");
                flicker_frame = (int)rcsv_num(sc, q, "flicker_frame");
            }
        }
        fprintf(f, "<h3>");
        svg_escape(f, name);
        fprintf(f, "</h3>\n<div class=\"strip\">\n");
        for (size_t q = r; q < sc->rows; q++) {
            if (strcmp(rcsv_get(sc, q, "case"), name) || !shown(rcsv_get(sc, q, "method"))) continue;
            int nv = frame_shares(sc, q, v, 240);
            cell(f, rcsv_get(sc, q, "method"), v, nv, (int)rcsv_num(sc, q, "flicker_frame"));
        }
        fprintf(f, "</div>\n");
        if (flicker_method && worst_flicker > 0 && flicker_frame > 0)
            flicker_crops(f, name, flicker_method, frames, flicker_frame);
    }
}
