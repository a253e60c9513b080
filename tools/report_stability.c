/* report_stability.c — the report's stability section (see report.h): what
 * `make stability` measured along each failure case's 30-frame path. Per case: what it
 * provokes and the settings it forces (the scene file's opening comment and its
 * "# ombra-set" lines), small multiples (one small chart per method, all of a case on
 * one scale with its axes, so heights compare), an animation of the reference beside
 * the methods that flicker most along the whole path (an APNG from png.c: flicker is
 * seen, not read), and the frame where flicker is worst, re-rendered along the same
 * path so it is the very frame the numbers count. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "png.h"
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
#define CELL_H 86
#define ANIM_METHODS 2   /* the methods beside ref in a case's animation */
#define ANIM_GAP 4       /* px between its panels */

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

/* One small chart: a method's mismatch share over the frames, from 0 to `top` (the
 * case's worst frame of any method, so a case's charts compare), with its axes; the
 * most flickering frame marked. */
static void cell(FILE *f, const char *method, const double *v, int n, int flick, double top)
{
    const double x0 = 40, x1 = CELL_W - 8, y0 = CELL_H - 20, y1 = 24;
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"multiple\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\" font-family=\"sans-serif\">\n", CELL_W, CELL_H, CELL_W, CELL_H);
    fprintf(f, "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"#fafafa\" stroke=\"#bbb\"/>\n",
            x0, y1, x1 - x0, y0 - y1);
    double mean = 0, worst = 0;
    for (int i = 0; i < n; i++) { mean += v[i] / n; if (v[i] > worst) worst = v[i]; }
    char a[32], b[32], t[32];
    svg_format(a, sizeof a, mean, SVG_SHARE);
    svg_format(b, sizeof b, worst, SVG_SHARE);
    svg_format(t, sizeof t, top, SVG_SHARE);
    fprintf(f, "<text x=\"4\" y=\"13\" font-size=\"10\"><tspan font-weight=\"bold\" font-size=\"11\">");
    svg_escape(f, method);
    fprintf(f, "</tspan> mean %s, worst %s</text>\n", a, b);
    /* the axes: wrong share 0 to top on the left, frames along the bottom */
    fprintf(f, "<text class=\"tick\" x=\"%.0f\" y=\"%.0f\" text-anchor=\"end\" font-size=\"9\">%s</text>\n",
            x0 - 3, y1 + 7, t);
    fprintf(f, "<text class=\"tick\" x=\"%.0f\" y=\"%.0f\" text-anchor=\"end\" font-size=\"9\">0</text>\n", x0 - 3, y0);
    fprintf(f, "<text class=\"tick\" x=\"%.0f\" y=\"%.0f\" text-anchor=\"start\" font-size=\"9\">frame 0</text>\n",
            x0, y0 + 11);
    fprintf(f, "<text class=\"tick\" x=\"%.0f\" y=\"%.0f\" text-anchor=\"end\" font-size=\"9\">%d</text>\n", x1, y0 + 11,
            n > 0 ? n - 1 : 0);
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
 * as under make stability); the masks of frames last - 1 and last come out, the last
 * frame's pixels when rgb is given, and every frame's mask, one after the other, when
 * all is. */
static om_status path(om_scene *s, const om_method *m, const om_method_cfg *cfg, int frames,
                      int last, uint8_t *prev, uint8_t *cur, uint8_t *rgb, uint8_t *all, om_diag *d)
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
    /* as make stability: the objects posed at time 0 for the state, then at each
     * frame's time; the path runs to the last key of the camera, light or an object */
    st = om_scene_pose_at(s, 0, d);
    if (st == OM_OK) st = om_method_init(m, &state, &ma, cfg, s, SW, SH, d);
    float tend = 0;
    if (s->ncam_keys) tend = s->cam_keys[s->ncam_keys - 1].t;
    if (s->nlight_keys && s->light_keys[s->nlight_keys - 1].t > tend) tend = s->light_keys[s->nlight_keys - 1].t;
    for (uint32_t k = 0; k < s->nobj_keys; k++)
        if (s->obj_keys[k].t > tend) tend = s->obj_keys[k].t;
    for (int fr = 0; fr <= last && st == OM_OK; fr++) {
        om_camera cam;
        om_light light;
        om_view v;
        const float t = frames > 1 ? tend * (float)fr / (float)(frames - 1) : 0;
        if ((st = om_scene_pose_at(s, t, d)) != OM_OK) break;
        om_scene_at(s, t, &cam, &light);
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
        if (all && st == OM_OK) memcpy(all + (size_t)fr * SW * SH, g.mask, (size_t)SW * SH);
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
    om_status st = path(&cs.scene, ref, &rcfg, frames, flick, rp, rc, rgb, NULL, &d);
    if (st == OM_OK) st = path(&cs.scene, m, &cfg, frames, flick, mp, mc, NULL, NULL, &d);
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
            uint8_t v = mc[i];   /* as the mask file has it: lit 255, shadowed 0, background 128 */
            bool fl = mp[i] != mc[i] && rp[i] == rc[i] && rc[i] != OM_MASK_BG;
            img[3 * i] = fl ? 230 : v;
            img[3 * i + 1] = fl ? 0 : v;
            img[3 * i + 2] = fl ? 200 : v;
        }
        fprintf(f, "<p>Where it flickers most: <b>");
        svg_escape(f, method);
        fprintf(f, "</b> from frame %d to %d, %u samples change in the %ux%u window at (%u, %u) while "
                   "the reference's stay (magenta; lit white, shadowed black, background mid grey).</p>\n"
                   "<div class=\"strip\">\n<div class=\"pair\"><figure>",
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
        fprintf(f, "<figcaption>ref, frame %d</figcaption></figure></div>\n<div class=\"pair\"><figure>", flick);
        report_mask_rgb(mp, SW, bx, by, CROP, c);
        report_img(f, c, CROP, CROP, 4, "mask before");
        fprintf(f, "<figcaption>%s, frame %d</figcaption></figure>\n<figure>", method, flick - 1);
        report_crop_rgb(img, SW, bx, by, CROP, c);
        report_img(f, c, CROP, CROP, 4, "mask after, flicker marked");
        fprintf(f, "<figcaption>%s, frame %d</figcaption></figure></div>\n</div>\n", method, flick);
    }
    free(buf);
    cli_scene_free(&cs);
}

/* What a case provokes, from its scene file's opening comment, and the settings it
 * forces on every method that takes them (its "# ombra-set" lines). */
static void case_about(FILE *f, const char *name)
{
    char path_s[256], *text;
    size_t len;
    om_diag d;
    snprintf(path_s, sizeof path_s, CASES "%s.scene", name);
    if (om_file_read(path_s, &text, &len, &d) != OM_OK) {
        fprintf(f, "<p>(<code>");
        svg_escape(f, path_s);
        fprintf(f, "</code> is not here: no description.)</p>\n");
        return;
    }
    fprintf(f, "<p class=\"case\">");
    for (char *l = text; l && *l == '#'; l = strchr(l, '\n') ? strchr(l, '\n') + 1 : NULL) {
        size_t n = strcspn(l, "\n");
        if (!strncmp(l, "# ombra-set", 11)) continue;
        char c = l[n];
        l[n] = 0;
        svg_escape(f, l + 1 + (l[1] == ' '));
        fputc(' ', f);
        l[n] = c;
    }
    fprintf(f, "<br/><b>Forced settings</b> (<code>");
    svg_escape(f, path_s);
    fprintf(f, "</code>'s <code># ombra-set</code>, for every method that takes them): ");
    bool any = false;
    for (const char *p = strstr(text, "# ombra-set "); p; p = strstr(p + 1, "# ombra-set ")) {
        size_t n = strcspn(p + 12, "\n");
        char line[256];
        snprintf(line, sizeof line, "%.*s", (int)(n < 255 ? n : 255), p + 12);
        fprintf(f, "%s<code>", any ? " " : "");
        svg_escape(f, line);
        fprintf(f, "</code>");
        any = true;
    }
    fprintf(f, "%s.</p>\n", any ? "" : "none, each method at its defaults");
    free(text);
}

/* The case's whole path as an animation: the reference's mask beside the masks of the
 * methods that flicker most, frame by frame (grey as the mask file has it). */
static void case_animation(FILE *f, const char *name, int frames, const char *const *methods, int nm)
{
    char path_s[256], *text;
    size_t len;
    om_diag d;
    memset(&d, 0, sizeof d);
    snprintf(path_s, sizeof path_s, CASES "%s.scene", name);
    if (frames < 2 || frames > 240 || om_file_read(path_s, &text, &len, &d) != OM_OK) return;
    static cli_settings set;
    case_settings(text, &set);
    free(text);
    const size_t n = (size_t)SW * SH;
    const uint32_t W = (uint32_t)(SW * (nm + 1) + ANIM_GAP * nm);
    uint8_t *all = malloc(n * (size_t)frames * (size_t)(nm + 1)), *img = malloc((size_t)W * SH * (size_t)frames);
    uint8_t *prev = malloc(n), *cur = malloc(n);
    cli_scene cs;
    memset(&cs, 0, sizeof cs);
    om_status st = all && img && prev && cur ? cli_scene_load(&cs, path_s, 0, &d) : cli_oom(&d);
    for (int k = 0; k <= nm && st == OM_OK; k++) {
        const om_method *m = om_method_find(k ? methods[k - 1] : "ref");
        om_method_cfg cfg;
        if (!m || !cli_cfg(m, &set, &cfg, NULL)) {
            snprintf(d.msg, sizeof d.msg, "%.96s: a # ombra-set value is out of range for %.16s", path_s,
                     k ? methods[k - 1] : "ref");
            st = OM_E_INVALID;
            break;
        }
        st = path(&cs.scene, m, &cfg, frames, frames - 1, prev, cur, NULL, all + n * (size_t)frames * (size_t)k, &d);
    }
    if (st == OM_OK) {
        memset(img, 255, (size_t)W * SH * (size_t)frames);
        for (int fr = 0; fr < frames; fr++)
            for (int k = 0; k <= nm; k++)
                for (uint32_t y = 0; y < SH; y++)
                    memcpy(img + ((size_t)fr * SH + y) * W + (size_t)k * (SW + ANIM_GAP),
                           all + n * ((size_t)frames * (size_t)k + (size_t)fr) + (size_t)y * SW, SW);
        size_t bytes = 0;
        uint8_t *png = png_encode_anim(img, 1, W, SH, (uint32_t)frames, 120, &bytes);
        if (png) {
            fprintf(f, "<figure class=\"anim\"><img alt=\"%s: ref and the methods that flicker most, along the "
                       "path\" width=\"%u\" height=\"%u\" src=\"", name, W * 2, SH * 2);
            png_data_uri_bytes(f, png, bytes);
            fprintf(f, "\"/><figcaption>The whole path, %d frames looping (%zu KB): left to right <b>ref</b>", frames,
                    (bytes + 512) / 1024);
            for (int k = 0; k < nm; k++) {
                fprintf(f, ", <b>");
                svg_escape(f, methods[k]);
                fprintf(f, "</b>");
            }
            fprintf(f, " (the most flicker); lit white, shadowed black, background mid grey.</figcaption></figure>\n");
        }
        free(png);
    } else {
        fprintf(f, "<p>(no animation: ");
        svg_escape(f, d.msg);
        fprintf(f, ")</p>\n");
    }
    if (cs.mem) cli_scene_free(&cs);
    free(all);
    free(img);
    free(prev);
    free(cur);
}

void report_stability(FILE *f, const rcsv *sc)
{
    fprintf(f, "<h2 id=\"stability\">Stability: where each method is known to fail</h2>\n"
               "<p class=\"read\">Each case of <code>tests/stability/</code> (<code>make stability</code>, "
               "at %ux%u) provokes a known failure along a 30-frame camera and light path, under the "
               "settings its scene file forces (shown per case: the figures hold for those, not "
               "for a method's defaults). Per case, one small chart per method: the share of "
               "samples wrong against the reference over the frames, all of a case's charts on one "
               "scale, from 0 to the worst frame of any method in it. A flat line is a stable "
               "method; a jagged one flickers. The dashed red line marks the frame whose changes "
               "flicker most (state changes the reference does not have). The charts leave out "
               "<code>ref</code> (0 by definition) and <code>none</code> (no shadows); the table at "
               "the end has every method. Then the whole path as an animation, the reference "
               "beside the methods that flicker most.</p>\n",
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
        fprintf(f, "<h3 id=\"case-");
        svg_escape(f, name);
        fprintf(f, "\">");
        svg_escape(f, name);
        fprintf(f, "</h3>\n");
        case_about(f, name);
        double top = 0;
        const char *anim[ANIM_METHODS];
        double aflick[ANIM_METHODS];
        int na = 0;
        for (size_t q = r; q < sc->rows; q++) {
            if (strcmp(rcsv_get(sc, q, "case"), name) || !shown(rcsv_get(sc, q, "method"))) continue;
            if (rcsv_num(sc, q, "worst_mismatch") > top) top = rcsv_num(sc, q, "worst_mismatch");
            /* the ANIM_METHODS that flicker most, most first */
            double fl = rcsv_num(sc, q, "flicker");
            int at = na < ANIM_METHODS ? na++ : ANIM_METHODS;
            if (at == ANIM_METHODS && fl > aflick[ANIM_METHODS - 1]) at = ANIM_METHODS - 1;
            if (at == ANIM_METHODS) continue;
            while (at > 0 && fl > aflick[at - 1]) { anim[at] = anim[at - 1]; aflick[at] = aflick[at - 1]; at--; }
            anim[at] = rcsv_get(sc, q, "method");
            aflick[at] = fl;
        }
        fprintf(f, "<div class=\"strip\">\n");
        for (size_t q = r; q < sc->rows; q++) {
            if (strcmp(rcsv_get(sc, q, "case"), name) || !shown(rcsv_get(sc, q, "method"))) continue;
            int nv = frame_shares(sc, q, v, 240);
            cell(f, rcsv_get(sc, q, "method"), v, nv, (int)rcsv_num(sc, q, "flicker_frame"), top);
        }
        fprintf(f, "</div>\n");
        if (na) case_animation(f, name, frames, anim, na);
        if (flicker_method && worst_flicker > 0 && flicker_frame > 0)
            flicker_crops(f, name, flicker_method, frames, flicker_frame);
    }
}
