/* report_memory.c — the report's "accuracy at equal memory" (see report.h): for each
 * memory budget (all the arenas together: the scene's, the frame's and the method's),
 * each method's best setting that fits and its mismatch share and time, as a table and
 * a chart. The small budgets are a microcontroller's: the default scene's 1,600-
 * triangle twin at 160x120; the larger ones the default scene at 640x480. The
 * framebuffer is the display's and is not counted; the reference that scores the
 * masks is the measuring instrument and runs outside the budget. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "report.h"
#include "svg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The scenes and budgets of the section, a line each: the small scene's are a
 * microcontroller's, the default scene's a desktop's or a console's. A scene is a name
 * cli_load_named knows ("small": the default scene's 1,600-triangle twin). */
#define NBUDGET 4
static const struct mscene { const char *scene; uint32_t w, h; size_t budgets[NBUDGET]; } mscenes[] = {
    {"small", 160, 120, {64 << 10, 128 << 10, 256 << 10, 512 << 10}},
    {"default", 640, 480, {1 << 20, 4 << 20, 16 << 20, 64 << 20}},
};
#define NSCENE (sizeof mscenes / sizeof mscenes[0])
/* At 640x480 a strip of fewer rows than this costs more (every strip walks the scene)
 * than the memory it saves buys; the small scene at 160x120 goes down to one row. */
#define MIN_ROWS 8
#define MAXC 48
#define MEASURE 4   /* candidates rendered per method and budget, the largest first */

/* A method's candidate settings: the product of two knobs' values (the second may be
 * absent), wider than the sweep's where small budgets need smaller maps. A method the
 * registry has and this table does not is tried at its sweep's settings (cli_sweep),
 * or its defaults; one whose sweep is "" (none) is left out. */
typedef struct knobs { const char *method, *a, *av, *b, *bv; } knobs;
static const knobs cands[] = {
    {"sm", "map", "16 32 64 128 256 512 1024 2048 4096", NULL, NULL},
    {"csm", "csm.map", "8 16 32 64 128 256 512 1024 2048", NULL, NULL},
    {"asm", "asm.root", "64 128 256 512 1024", "asm.cap", "16384 65536 262144 1048576 4194304 16777216"},
    {"rtw", "map", "32 64 128 256 512 1024 2048", NULL, NULL},
    {"spsm", "map", "16 32 64 128 256 512 1024 2048", NULL, NULL},
    {"izb", "izb.pool", "64 128 256 1024 4096 16384 65536 0", NULL, NULL},
    {"hybrid", "hybrid.map", "16 32 64 128 256 512", "izb.pool", "1024 4096 16384 0"},
};

/* The knobs of method m: its line above, else its sweep's (at most two of its
 * NAME=V1,V2 lists, the commas made spaces into buf), else none (its defaults). */
static knobs knobs_of(const om_method *m, char buf[2][2][160])
{
    knobs k = {om_method_name(m), NULL, NULL, NULL, NULL};
    for (size_t i = 0; i < sizeof cands / sizeof cands[0]; i++)
        if (!strcmp(cands[i].method, k.method)) return cands[i];
    const char *s = cli_sweep(m);
    for (int j = 0; s && *s && j < 2;) {
        size_t l = strcspn(s, " "), e = strcspn(s, "=");
        if (e < l) {
            snprintf(buf[j][0], sizeof buf[j][0], "%.*s", (int)e, s);
            snprintf(buf[j][1], sizeof buf[j][1], "%.*s", (int)(l - e - 1), s + e + 1);
            for (char *c = buf[j][1]; *c; c++) if (*c == ',') *c = ' ';
            if (j == 0) { k.a = buf[0][0]; k.av = buf[0][1]; } else { k.b = buf[1][0]; k.bv = buf[1][1]; }
            j++;
        }
        s += l;
        while (*s == ' ') s++;
    }
    return k;
}

typedef struct cand { char setting[96]; size_t method, total; uint32_t rows; size_t fbytes; } cand;

/* Splits "v1 v2 ..." into at most max items of buf; returns the count. */
static int words(const char *s, char out[][16], int max)
{
    int n = 0;
    while (s && *s && n < max) {
        size_t l = strcspn(s, " ");
        snprintf(out[n++], 16, "%.*s", (int)(l < 15 ? l : 15), s);
        s += l;
        while (*s == ' ') s++;
    }
    return n;
}

static bool configure(const om_method *m, const char *setting, om_method_cfg *cfg)
{
    om_method_cfg_default(cfg, m);
    char item[64];
    for (const char *p = setting; *p;) {
        size_t l = strcspn(p, " ");
        snprintf(item, sizeof item, "%.*s", (int)(l < 63 ? l : 63), p);
        if (l && !cli_set(cfg, item)) return false;
        p += l;
        while (*p == ' ') p++;
    }
    return true;
}

/* Fits a candidate into the budget: its method arena at its one-pass size, the rest
 * for the frame in strips of as many rows as fit (with row bins when they fit too).
 * Returns false when not even MIN_ROWS fit; *need is then the bytes it would take. */
static bool fit(const om_method *m, const char *setting, const cli_scene *cs, uint32_t W, uint32_t H,
                size_t budget, cand *c, size_t *need)
{
    om_method_cfg cfg;
    size_t mn, full;
    *need = SIZE_MAX;
    if (!configure(m, setting, &cfg) || om_method_bytes(m, &cfg, &cs->scene, W, H, &mn, &full) != OM_OK) return false;
    uint32_t lo = W <= 160 ? 1 : H < MIN_ROWS ? H : MIN_ROWS;
    size_t base = cs->bytes + full;
    *need = base + cli_frame_rows(NULL, W, lo, false);
    if (*need > budget) return false;
    snprintf(c->setting, sizeof c->setting, "%s", setting);
    c->method = full;
    c->rows = lo;
    for (uint32_t r = H; r >= lo; r = r > lo && r / 2 < lo ? lo : r / 2) {
        size_t with_bins = cli_frame_rows(&cs->scene, W, r, true), plain = cli_frame_rows(NULL, W, r, false);
        if (base + with_bins <= budget) { c->rows = r; c->fbytes = with_bins; break; }
        if (base + plain <= budget) { c->rows = r; c->fbytes = plain; break; }
        if (r == lo) break;
    }
    if (!c->fbytes) c->fbytes = cli_frame_rows(NULL, W, lo, false);
    c->total = base + c->fbytes;
    return true;
}

static int by_method_bytes(const void *a, const void *b)
{
    const cand *x = a, *y = b;
    return x->method > y->method ? -1 : x->method < y->method;
}

/* Renders the MEASURE candidates of method m that use the most memory within the
 * budget (and fit) and writes a row of memory.csv for each, the most accurate (the
 * faster on a tie) marked best; one row "does not fit" with the least any setting
 * needs when none fits. */
static void measure(FILE *o, const struct mscene *ms, const om_method *m, const knobs *k, const cli_scene *cs,
                    const om_view *v, size_t budget, int runs, const uint8_t *ref, uint8_t *mask)
{
    const uint32_t W = v->cam.width, H = v->cam.height;
    static cand c[MAXC];
    static double share[MAXC], ms_of[MAXC];
    char av[12][16], bv[12][16];
    int na = k->a ? words(k->av, av, 12) : 1, nb = k->b ? words(k->bv, bv, 12) : 1, n = 0;
    size_t least = SIZE_MAX;
    for (int i = 0; i < na; i++)
        for (int j = 0; j < nb && n < MAXC; j++) {
            char setting[96];
            snprintf(setting, sizeof setting, "%.31s%s%.15s%s%.31s%s%.15s", k->a ? k->a : "", k->a ? "=" : "",
                     k->a ? av[i] : "", k->b ? " " : "", k->b ? k->b : "", k->b ? "=" : "", k->b ? bv[j] : "");
            size_t need;
            memset(&c[n], 0, sizeof c[n]);
            if (fit(m, setting, cs, W, H, budget, &c[n], &need)) n++;
            else if (need < least) least = need;
        }
    qsort(c, (size_t)n, sizeof c[0], by_method_bytes);
    int done = 0, bi = -1;
    static bool measured[MAXC];
    for (int i = 0; i < n; i++) {
        om_method_cfg cfg;
        cli_point p;
        om_diag d;
        memset(&p, 0, sizeof p);
        measured[i] = false;
        if (done == MEASURE || !configure(m, c[i].setting, &cfg) ||
            cli_measure_strips(m, &cfg, cs, v, runs, c[i].rows < H ? c[i].rows : 0, c[i].fbytes, mask, NULL, &p,
                               &d) != OM_OK)
            continue;
        om_metrics mt;
        om_compare_masks(ref, mask, W, H, &mt);
        share[i] = 1.0 - om_metrics_match(&mt);
        ms_of[i] = p.total;
        measured[i] = true;
        if (bi < 0 || share[i] < share[bi] || (share[i] == share[bi] && ms_of[i] < ms_of[bi])) bi = i;
        done++;
    }
    for (int i = 0; i < n; i++)
        if (measured[i])
            fprintf(o, "%s,%u,%u,%zu,%s,%s,1,%zu,,%.6f,%.3f,%d\n", ms->scene, W, H, budget, om_method_name(m),
                    c[i].setting[0] ? c[i].setting : "defaults", c[i].total, share[i], ms_of[i], i == bi);
    if (bi < 0 && least != SIZE_MAX)
        fprintf(o, "%s,%u,%u,%zu,%s,,0,,%zu,,,0\n", ms->scene, W, H, budget, om_method_name(m), least);
    else if (bi < 0)
        fprintf(o, "%s,%u,%u,%zu,%s,,0,,,,,0\n", ms->scene, W, H, budget, om_method_name(m));
}

static om_status load_text(const char *text, cli_scene *cs, om_diag *d)
{
    memset(cs, 0, sizeof *cs);
    size_t len = strlen(text);
    om_status st = om_scene_bytes(text, len, NULL, &cs->bytes, d);
    if (st) return st;
    if (!(cs->mem = malloc(cs->bytes ? cs->bytes : 1))) return cli_oom(d);
    om_arena_init(&cs->arena, cs->mem, cs->bytes, "scene");
    return om_scene_parse(text, len, NULL, &cs->arena, &cs->scene, d);
}

int report_memory_measure(const char *dir, int runs)
{
    om_diag d;
    memset(&d, 0, sizeof d);
    char *path = cli_path(dir, "memory.csv");
    om_out out;
    om_status st = path ? om_out_open(&out, path, &d) : cli_oom(&d);
    if (st != OM_OK) { free(path); return cli_error("equal memory", &d, st); }
    fprintf(out.f, "scene,width,height,budget,method,setting,fits,total_bytes,need_bytes,mismatch_share,time_ms,best\n");
    for (size_t s = 0; s < NSCENE && st == OM_OK; s++) {
        const struct mscene *ms = &mscenes[s];
        cli_scene cs;
        st = !strcmp(ms->scene, "small") ? load_text(om_scene_small_text(), &cs, &d) : cli_load_named(ms->scene, &cs, &d);
        om_view v;
        if (st == OM_OK) st = cli_scene_view(&cs, ms->w, ms->h, &v, &d);
        size_t n = (size_t)ms->w * ms->h;
        uint8_t *ref = st == OM_OK ? malloc(n) : NULL, *mask = st == OM_OK ? malloc(n) : NULL;
        if (st == OM_OK && (!ref || !mask)) st = cli_oom(&d);
        cli_point p;
        om_method_cfg cfg;
        om_method_cfg_default(&cfg, om_method_find("ref"));
        if (st == OM_OK) st = cli_measure(om_method_find("ref"), &cfg, &cs, &v, 1, ref, NULL, &p, &d);
        for (int b = 0; b < NBUDGET && st == OM_OK; b++) {
            fprintf(stderr, "report:   equal memory: every method in %zu KiB, %s at %ux%u\n", ms->budgets[b] >> 10,
                    ms->scene, ms->w, ms->h);
            for (size_t k = 0; k < om_method_count(); k++) {
                const om_method *m = om_method_at(k);
                const char *sw = cli_sweep(m);
                if (sw && !sw[0]) continue;   /* none: no shadows, nothing to choose */
                char buf[2][2][160];
                knobs kn = knobs_of(m, buf);
                measure(out.f, ms, m, &kn, &cs, &v, ms->budgets[b], runs, ref, mask);
            }
        }
        free(ref);
        free(mask);
        cli_scene_free(&cs);
    }
    om_out *outs[1] = {&out};
    if (st != OM_OK) om_out_discard(&out);
    else st = om_out_commit(outs, 1, &d);
    free(path);
    return st != OM_OK ? cli_error("equal memory", &d, st) : 0;
}

/* The methods of memory.csv rows of one scene, in the order they first appear. */
static size_t methods_of(const rcsv *c, const char *scene, const char **names, size_t max)
{
    size_t n = 0;
    for (size_t r = 0; r < c->rows; r++) {
        if (strcmp(rcsv_get(c, r, "scene"), scene)) continue;
        const char *m = rcsv_get(c, r, "method");
        size_t k = 0;
        while (k < n && strcmp(names[k], m)) k++;
        if (k == n && n < max) names[n++] = m;
    }
    return n;
}

/* The scenes of a CSV's "scene" column (memory.csv's, bench.csv's), in order. */
size_t report_scenes_of(const rcsv *c, const char **names, size_t max)
{
    size_t n = 0;
    for (size_t r = 0; r < c->rows; r++) {
        const char *s = rcsv_get(c, r, "scene");
        size_t k = 0;
        while (k < n && strcmp(names[k], s)) k++;
        if (k == n && n < max) names[n++] = s;
    }
    return n;
}

size_t report_memory_budgets(const rcsv *c, const char *scene, double *budgets, size_t max)
{
    size_t n = 0;
    for (size_t r = 0; r < c->rows; r++) {
        if (strcmp(rcsv_get(c, r, "scene"), scene)) continue;
        double b = rcsv_num(c, r, "budget");
        size_t k = 0;
        while (k < n && budgets[k] != b) k++;
        if (k == n && n < max) budgets[n++] = b;
    }
    return n;
}

/* The row of memory.csv that is method m's best at a budget (or says it does not fit). */
static long best_row(const rcsv *c, const char *scene, double budget, const char *m)
{
    long none = -1;
    for (size_t r = 0; r < c->rows; r++) {
        if (strcmp(rcsv_get(c, r, "scene"), scene) || rcsv_num(c, r, "budget") != budget ||
            strcmp(rcsv_get(c, r, "method"), m))
            continue;
        if (rcsv_num(c, r, "best") == 1) return (long)r;
        if (rcsv_num(c, r, "fits") == 0) none = (long)r;
    }
    return none;
}

void report_memory(FILE *f, const rcsv *mem)
{
    fprintf(f, "<h2 id=\"memory\">Accuracy at equal memory</h2>\n<p class=\"read\">Which method for "
               "the memory you have: for each budget, all the arenas together (the scene's, the "
               "frame's and the method's; the framebuffer is the display's and not counted), each "
               "method's best setting that fits, rendered through strips of as many rows as the "
               "rest allows. One chart per scene: the small budgets are a microcontroller's, on the "
               "default scene's 1,600-triangle twin (<code>ombra scene --small</code>) at 160x120; "
               "the large ones the default scene at 640x480. Down is more accurate; where no setting "
               "of a method fits, its line breaks and a cross along the top edge marks the budget "
               "(the table says what it would need). Every setting measured is in "
               "<code>memory.csv</code>.</p>\n");
    const char *scenes[8];
    size_t nsc = report_scenes_of(mem, scenes, 8);
    for (size_t s = 0; s < nsc; s++) {
        enum { MAXM = 16 };
        static double xs[MAXM][NBUDGET * 2], ys[MAXM][NBUDGET * 2];
        static char text[MAXM][NBUDGET * 2][64];
        static const char *labels[MAXM][NBUDGET * 2];
        const char *names[MAXM];
        double budgets[NBUDGET * 2];
        size_t nm = methods_of(mem, scenes[s], names, MAXM), nbud = report_memory_budgets(mem, scenes[s], budgets, NBUDGET * 2);
        long w = -1;
        for (size_t r = 0; r < mem->rows && w < 0; r++)
            if (!strcmp(rcsv_get(mem, r, "scene"), scenes[s])) w = (long)r;
        svg_series ser[MAXM];
        for (size_t k = 0; k < nm; k++) {
            for (size_t b = 0; b < nbud; b++) {
                long r = best_row(mem, scenes[s], budgets[b], names[k]);
                xs[k][b] = budgets[b];
                bool fits = r >= 0 && rcsv_num(mem, (size_t)r, "fits") == 1;
                ys[k][b] = fits ? rcsv_num(mem, (size_t)r, "mismatch_share") : NAN;
                text[k][b][0] = 0;
                if (fits) cli_short_setting(rcsv_get(mem, (size_t)r, "setting"), text[k][b], sizeof text[k][b]);
                labels[k][b] = text[k][b];
            }
            ser[k] = (svg_series){names[k], xs[k], ys[k], nbud, labels[k], NULL, NULL};
        }
        char title[160];
        snprintf(title, sizeof title, "%s at %sx%s: accuracy at equal memory", scenes[s],
                 rcsv_get(mem, (size_t)w, "width"), rcsv_get(mem, (size_t)w, "height"));
        fprintf(f, "<h3 id=\"memory-%s\">%s scene at %sx%s</h3>\n<div class=\"chart-box\" id=\"chart-memory-%s\">", scenes[s],
                scenes[s], rcsv_get(mem, (size_t)w, "width"), rcsv_get(mem, (size_t)w, "height"), scenes[s]);
        svg_chart c = {title, "memory budget: scene + frame + method arenas", "samples wrong against ref", true, true,
                       false, true, SVG_BYTES, SVG_SHARE};
        svg_write_inline(f, &c, ser, nm);
        fprintf(f, "</div>\n<div class=\"scroll\"><table>\n<tr><th>method</th>");
        for (size_t b = 0; b < nbud; b++) {
            char t[32];
            svg_format(t, sizeof t, budgets[b], SVG_BYTES);
            fprintf(f, "<th>%s</th>", t);
        }
        fprintf(f, "</tr>\n");
        for (size_t k = 0; k < nm; k++) {
            fprintf(f, "<tr><td class=\"t\">");
            svg_escape(f, names[k]);
            fprintf(f, "</td>");
            for (size_t b = 0; b < nbud; b++) {
                long r = best_row(mem, scenes[s], budgets[b], names[k]);
                char t[32];
                if (r >= 0 && rcsv_num(mem, (size_t)r, "fits") == 1) {
                    svg_format(t, sizeof t, rcsv_num(mem, (size_t)r, "total_bytes"), SVG_BYTES);
                    fprintf(f, "<td class=\"m\"><b>%.3f%%</b> wrong, %.1f ms<br/><small>",
                            100 * rcsv_num(mem, (size_t)r, "mismatch_share"), rcsv_num(mem, (size_t)r, "time_ms"));
                    svg_escape(f, rcsv_get(mem, (size_t)r, "setting"));
                    fprintf(f, ", %s in all</small></td>", t);
                } else if (r >= 0 && rcsv_get(mem, (size_t)r, "need_bytes")[0] &&
                           rcsv_num(mem, (size_t)r, "need_bytes") < 1e18) {
                    svg_format(t, sizeof t, rcsv_num(mem, (size_t)r, "need_bytes"), SVG_BYTES);
                    fprintf(f, "<td class=\"m\">does not fit: needs at least %s</td>", t);
                } else {
                    fprintf(f, "<td class=\"m\">does not fit</td>");
                }
            }
            fprintf(f, "</tr>\n");
        }
        fprintf(f, "</table></div>\n");
    }
}
