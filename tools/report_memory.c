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

#include <stdlib.h>
#include <string.h>

#define NBUDGET 5
static const size_t budgets[NBUDGET] = {64 << 10, 256 << 10, 1 << 20, 4 << 20, 16 << 20};
#define SMALL_BUDGET (256 << 10)   /* this and below: the small scene at 160x120 */
/* At 640x480 a strip of fewer rows than this costs more (every strip walks the scene)
 * than the memory it saves buys; the small scene at 160x120 goes down to one row. */
#define MIN_ROWS 8
#define MAXC 48

/* A method's candidate settings: the product of two knobs' values (the second may be
 * absent). Which of them is best is measured, not assumed, for the two-knob methods. */
typedef struct knobs { const char *method, *a, *av, *b, *bv; int measure; } knobs;
static const knobs cands[] = {
    {"ref", NULL, NULL, NULL, NULL, 1},
    {"sm", "map", "16 32 64 128 256 512 1024 2048 4096", NULL, NULL, 1},
    {"asm", "asm.root", "64 128 256 512 1024", "asm.cap", "16384 65536 262144 1048576 4194304 16777216", 2},
    {"rtw", "map", "32 64 128 256 512 1024 2048", NULL, NULL, 1},
    {"spsm", "map", "16 32 64 128 256 512 1024 2048", NULL, NULL, 1},
    {"izb", "izb.pool", "64 128 256 1024 4096 16384 65536 0", NULL, NULL, 1},
    {"hybrid", "hybrid.map", "16 32 64 128 256 512", "izb.pool", "1024 4096 16384 0", 2},
};

typedef struct cand { char setting[64]; size_t method, total; uint32_t rows; size_t fbytes; } cand;

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

typedef struct result {
    bool fits;
    char setting[64];
    size_t total, need;   /* need: the least a setting of it takes, when none fits */
    double share, ms;
} result;

/* The best setting of a method within the budget: of the candidates that fit, the
 * `measure` that use the most memory are rendered and the most accurate kept (the
 * faster on a tie). */
static void best(const knobs *k, const cli_scene *cs, const om_view *v, size_t budget, int runs,
                 const uint8_t *ref, uint8_t *mask, result *res)
{
    const om_method *m = om_method_find(k->method);
    const uint32_t W = v->cam.width, H = v->cam.height;
    static cand c[MAXC];
    char av[12][16], bv[12][16];
    int na = k->a ? words(k->av, av, 12) : 1, nb = k->b ? words(k->bv, bv, 12) : 1, n = 0;
    memset(res, 0, sizeof *res);
    res->need = SIZE_MAX;
    for (int i = 0; i < na && m; i++)
        for (int j = 0; j < nb && n < MAXC; j++) {
            char setting[64];
            snprintf(setting, sizeof setting, "%s%s%s%s%s%s%s", k->a ? k->a : "", k->a ? "=" : "",
                     k->a ? av[i] : "", k->b ? " " : "", k->b ? k->b : "", k->b ? "=" : "", k->b ? bv[j] : "");
            size_t need;
            memset(&c[n], 0, sizeof c[n]);
            if (fit(m, setting, cs, W, H, budget, &c[n], &need)) n++;
            else if (need < res->need) res->need = need;
        }
    qsort(c, (size_t)n, sizeof c[0], by_method_bytes);
    for (int i = 0; i < n && i < k->measure; i++) {
        om_method_cfg cfg;
        cli_point p;
        om_diag d;
        memset(&p, 0, sizeof p);
        if (!configure(m, c[i].setting, &cfg) ||
            cli_measure_strips(m, &cfg, cs, v, runs, c[i].rows < H ? c[i].rows : 0, c[i].fbytes, mask, NULL, &p,
                               &d) != OM_OK)
            continue;
        om_metrics mt;
        om_compare_masks(ref, mask, W, H, &mt);
        double share = 1.0 - om_metrics_match(&mt);
        if (!res->fits || share < res->share || (share == res->share && p.total < res->ms)) {
            res->fits = true;
            res->share = share;
            res->ms = p.total;
            res->total = c[i].total;
            if (c[i].setting[0]) memcpy(res->setting, c[i].setting, sizeof res->setting);
            else strcpy(res->setting, "defaults");
        }
    }
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

#define NMETH (sizeof cands / sizeof cands[0])

int report_memory(FILE *f, int runs)
{
    static result res[NBUDGET][NMETH];
    cli_scene scenes[2];
    om_diag d;
    memset(&d, 0, sizeof d);
    memset(scenes, 0, sizeof scenes);
    om_status st = load_text(om_scene_small_text(), &scenes[0], &d);
    if (st == OM_OK) st = cli_load_named("default", &scenes[1], &d);
    for (int b = 0; b < NBUDGET && st == OM_OK; b++) {
        bool small = budgets[b] <= SMALL_BUDGET;
        cli_scene *cs = &scenes[small ? 0 : 1];
        om_view v;
        if ((st = cli_scene_view(cs, small ? 160 : 640, small ? 120 : 480, &v, &d)) != OM_OK) break;
        size_t n = (size_t)v.cam.width * v.cam.height;
        uint8_t *ref = malloc(n), *mask = malloc(n);
        cli_point p;
        om_method_cfg cfg;
        om_method_cfg_default(&cfg, om_method_find("ref"));
        if (!ref || !mask) st = cli_oom(&d);
        else st = cli_measure(om_method_find("ref"), &cfg, cs, &v, 1, ref, NULL, &p, &d);
        fprintf(stderr, "report:   equal memory: every method in %zu KiB\n", budgets[b] >> 10);
        for (size_t k = 0; k < NMETH && st == OM_OK; k++) {
            best(&cands[k], cs, &v, budgets[b], runs, ref, mask, &res[b][k]);
        }
        free(ref);
        free(mask);
    }
    cli_scene_free(&scenes[0]);
    cli_scene_free(&scenes[1]);
    if (st != OM_OK) return cli_error("equal memory", &d, st);

    fprintf(f, "<h2 id=\"memory\">Accuracy at equal memory</h2>\n<p class=\"read\">Which method for "
               "the memory you have: for each budget, all the arenas together (the scene's, the "
               "frame's and the method's; the framebuffer is the display's and not counted), each "
               "method's best setting that fits, rendered through strips of as many rows as the "
               "rest allows. 64 and 256 KiB are a microcontroller's: the default scene's "
               "1,600-triangle twin (<code>ombra scene --small</code>) at 160x120; 1 MiB and more "
               "the default scene at 640x480. Down is more accurate; a method missing at a budget "
               "does not fit in it (the table says what it needs).</p>\n");
    static double xs[NMETH][NBUDGET], ys[NMETH][NBUDGET];
    static char text[NMETH][NBUDGET][64];
    static const char *labels[NMETH][NBUDGET];
    svg_series s[NMETH];
    size_t ns = 0;
    for (size_t k = 0; k < NMETH; k++) {
        size_t np = 0;
        for (int b = 0; b < NBUDGET; b++) {
            if (!res[b][k].fits) continue;
            xs[ns][np] = (double)budgets[b];
            ys[ns][np] = res[b][k].share;
            cli_short_setting(res[b][k].setting, text[ns][np], sizeof text[ns][np]);
            labels[ns][np] = text[ns][np];
            np++;
        }
        if (!np) continue;
        s[ns] = (svg_series){cands[k].method, xs[ns], ys[ns], np, labels[ns], NULL, NULL};
        ns++;
    }
    svg_chart c = {"accuracy at equal memory", "memory budget: scene + frame + method arenas",
                   "samples wrong against ref", true, true, false, true, SVG_BYTES, SVG_SHARE};
    svg_write_inline(f, &c, s, ns);
    fprintf(f, "<div class=\"scroll\"><table>\n<tr><th>method</th>");
    for (int b = 0; b < NBUDGET; b++) {
        char t[32];
        svg_format(t, sizeof t, (double)budgets[b], SVG_BYTES);
        fprintf(f, "<th>%s<br/>%s</th>", t, budgets[b] <= SMALL_BUDGET ? "small scene, 160x120" : "default, 640x480");
    }
    fprintf(f, "</tr>\n");
    for (size_t k = 0; k < NMETH; k++) {
        fprintf(f, "<tr><td class=\"t\">%s</td>", cands[k].method);
        for (int b = 0; b < NBUDGET; b++) {
            const result *r = &res[b][k];
            char t[32];
            if (r->fits) {
                svg_format(t, sizeof t, (double)r->total, SVG_BYTES);
                fprintf(f, "<td class=\"m\"><b>%.3f%%</b> wrong, %.1f ms<br/><small>", 100 * r->share, r->ms);
                svg_escape(f, r->setting);
                fprintf(f, ", %s in all</small></td>", t);
            } else if (r->need != SIZE_MAX) {
                svg_format(t, sizeof t, (double)r->need, SVG_BYTES);
                fprintf(f, "<td class=\"m\">does not fit: needs at least %s</td>", t);
            } else {
                fprintf(f, "<td class=\"m\">does not fit</td>");
            }
        }
        fprintf(f, "</tr>\n");
    }
    fprintf(f, "</table></div>\n");
    return 0;
}
