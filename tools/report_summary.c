/* report_summary.c — the decision summary at the top of the report (see report.h):
 * which method for my memory, my accuracy and my chip, read off this run's data. For
 * each budget (rows) and accuracy need (columns: exact, at most 0.1% and at most 1% of
 * the samples wrong against ref), the fastest setting measured that meets both, with
 * its time, and the most accurate setting that fits at all: from memory.csv per scene with every arena counted, then from bench.csv per
 * swept scene with the method's arena alone. Then the chips: per method its code,
 * whole footprint, instructions a frame and frames a second on a Cortex-M4. Methods
 * and scenes come from the CSVs, so a new one joins without a line here; every cell
 * links to the chart or table it was read from. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "report.h"
#include "svg.h"

#include <stdlib.h>
#include <string.h>

#define NNEED 4
/* the accuracy needs; -1: none, the most accurate setting that fits (the faster on a tie) */
static const double needs[NNEED] = {0, 0.001, 0.01, -1};
static const char *const need_head[NNEED] = {"exact (0 wrong)", "&#8804; 0.1% wrong", "&#8804; 1% wrong",
                                             "the most accurate that fits"};
/* the method-arena budgets of the swept scenes' tables */
static const double arena_budgets[] = {64 << 10, 256 << 10, 1 << 20, 4 << 20, 16 << 20, 64 << 20};
#define NARENA (sizeof arena_budgets / sizeof arena_budgets[0])

void report_chart_id(char *buf, size_t n, const char *scene, const char *kind)
{
    snprintf(buf, n, "chart-%s-%s", cli_base_name(scene), kind);
}

/* A method that chooses shadows (`none`, which bench and memory leave out of sweeps,
 * draws none). */
static bool chooses(const char *method)
{
    const char *sw = cli_sweep(om_method_find(method));
    return !(sw && !sw[0]);
}

/* One cell: the fastest row of c (rows where keep holds) within the budget (in column
 * `bytes`) whose mismatch share is at most need; a link to `anchor` either way. */
static void cell(FILE *f, const rcsv *c, const char *scene, const char *bytes, double budget, double need,
                 const char *anchor, bool fits_col)
{
    long best = -1;
    for (size_t r = 0; r < c->rows; r++) {
        if (strcmp(rcsv_get(c, r, "scene"), scene) || !chooses(rcsv_get(c, r, "method"))) continue;
        if (fits_col && (rcsv_num(c, r, "fits") != 1 || rcsv_num(c, r, "budget") != budget)) continue;
        if (!fits_col && rcsv_num(c, r, bytes) > budget) continue;
        double sh = rcsv_num(c, r, "mismatch_share"), ms = rcsv_num(c, r, "time_ms");
        if (need >= 0 && sh > need) continue;
        double bsh = best < 0 ? 0 : rcsv_num(c, (size_t)best, "mismatch_share");
        double bms = best < 0 ? 0 : rcsv_num(c, (size_t)best, "time_ms");
        if (best < 0 || (need < 0 && sh < bsh) || ((need >= 0 || sh == bsh) && ms < bms)) best = (long)r;
    }
    fprintf(f, "<td class=\"m\"><a href=\"#%s\">", anchor);
    if (best < 0) {
        fprintf(f, "nothing measured meets it</a></td>");
        return;
    }
    char set[64], mem[32];
    size_t r = (size_t)best;
    cli_short_setting(rcsv_get(c, r, "setting"), set, sizeof set);
    svg_format(mem, sizeof mem, rcsv_num(c, r, bytes), SVG_BYTES);
    fprintf(f, "<b>");
    svg_escape(f, rcsv_get(c, r, "method"));
    fprintf(f, "</b> ");
    svg_escape(f, strcmp(set, "defaults") ? set : "at its defaults");
    fprintf(f, "</a><br/><small>%.2f ms, %.3f%% wrong, %s</small></td>", rcsv_num(c, r, "time_ms"),
            100 * rcsv_num(c, r, "mismatch_share"), mem);
}

static void head_row(FILE *f, const char *first)
{
    fprintf(f, "<tr><th>%s</th>", first);
    for (int k = 0; k < NNEED; k++) fprintf(f, "<th>%s</th>", need_head[k]);
    fprintf(f, "</tr>\n");
}

/* One scene's table of c: a row a budget, a cell an accuracy need (cell), the scene
 * named `label` in its caption with its size. total: the budgets count every arena
 * (memory.csv's total_bytes), else the method's alone (bench.csv's bytes). */
static void budget_table(FILE *f, const rcsv *c, const char *scene, const char *label, const double *budgets,
                         size_t nb, const char *anchor, bool total)
{
    const char *w = "", *h = "";
    for (size_t r = 0; r < c->rows; r++)
        if (!strcmp(rcsv_get(c, r, "scene"), scene)) {
            w = rcsv_get(c, r, "width");
            h = rcsv_get(c, r, "height");
            break;
        }
    fprintf(f, "<div class=\"scroll\"><table class=\"summary\">\n<caption>");
    svg_escape(f, label);
    fprintf(f, "%s at %sx%s</caption>\n", total ? " scene" : "", w, h);
    head_row(f, total ? "memory" : "method arena");
    for (size_t b = 0; b < nb; b++) {
        char t[32];
        svg_format(t, sizeof t, budgets[b], SVG_BYTES);
        fprintf(f, "<tr><th>%s</th>", t);
        for (int k = 0; k < NNEED; k++)
            cell(f, c, scene, total ? "total_bytes" : "bytes", budgets[b], needs[k], anchor, total);
        fprintf(f, "</tr>\n");
    }
    fprintf(f, "</table></div>\n");
}

static void chips(FILE *f, const rcross *x)
{
    rchip ch[32];
    const char *from = NULL;
    size_t n = report_chips(x, ch, 32, &from);
    const char *anchor = from && !strcmp(from, "csv") ? "machines-methods" : "machines-doc";
    fprintf(f, "<h3 id=\"summary-chips\">Which method for my chip</h3>\n");
    if (!n) {
        fprintf(f, "<p><a href=\"#machines\">No Cortex-M figures</a>: neither <code>");
        svg_escape(f, x->dir);
        fprintf(f, "/m4-methods.csv</code> nor the tables of <code>");
        svg_escape(f, x->doc);
        fprintf(f, "</code> are there; <code>make cross-test</code> writes both.</p>\n");
        return;
    }
    fprintf(f, "<p class=\"read\">Cortex-M4F firmware (gcc -O2), the small scene at 160x120 in strips of 8 "
               "rows, under QEMU; frames a second at %d MHz and %.2f cycles an instruction (an "
               "assumption: QEMU counts instructions, not cycles). ",
            CHIP_MHZ, CHIP_CPI);
    if (!strcmp(from, "csv")) {
        fprintf(f, "Measured by <code>make cross-test</code> into <code>");
        svg_escape(f, x->dir);
        fprintf(f, "/m4-methods.csv</code>.</p>\n");
    } else {
        fprintf(f, "No cross toolchain here: read from the tables <code>make cross-test</code> last wrote "
                   "into <code>");
        svg_escape(f, x->doc);
        fprintf(f, "</code>");
        if (x->doc_rev && x->doc_rev[0]) {
            fprintf(f, " (commit ");
            svg_escape(f, x->doc_rev);
            fprintf(f, ")");
        }
        fprintf(f, ".</p>\n");
    }
    fprintf(f, "<div class=\"scroll\"><table class=\"summary\">\n<tr><th>method</th><th>code, bytes</th>"
               "<th>whole footprint, bytes</th><th>instructions a frame</th><th>frames a second at %d MHz</th></tr>\n",
            CHIP_MHZ);
    for (size_t i = 0; i < n; i++) {
        char a[32], b[32], c[32];
        svg_format(a, sizeof a, ch[i].text, SVG_PLAIN);
        svg_format(b, sizeof b, ch[i].whole, SVG_PLAIN);
        if (!strcmp(from, "csv")) svg_format(c, sizeof c, ch[i].instructions, SVG_PLAIN);
        else snprintf(c, sizeof c, "%.1f M", ch[i].instructions / 1e6);   /* as the README rounds it */
        fprintf(f, "<tr><td class=\"t\"><a href=\"#%s\">", anchor);
        svg_escape(f, ch[i].method);
        fprintf(f, "</a></td><td><a href=\"#%s\">%s</a></td><td><a href=\"#%s\">%s</a></td>"
                   "<td><a href=\"#%s\">%s</a></td><td><a href=\"#%s\">%.1f</a></td></tr>\n",
                anchor, ch[i].text > 0 ? a : "?", anchor, ch[i].whole > 0 ? b : "?", anchor,
                ch[i].instructions > 0 ? c : "?", anchor, ch[i].fps);
    }
    fprintf(f, "</table></div>\n");
}

void report_summary(FILE *f, const rcsv *bench, const rcsv *mem, const rcross *x)
{
    fprintf(f, "<section id=\"summary\">\n<h2>Which method: what this run says</h2>\n"
               "<p class=\"read\">The fastest setting measured in this run that meets each accuracy "
               "(the share of visible samples whose shadow differs from the exact reference "
               "<code>ref</code>; &#8220;exact&#8221; is 0 wrong on this frame) within each memory "
               "budget, and the most accurate setting that fits at all. Each cell links to the "
               "chart it was read from.</p>\n");
    const char *scenes[16];
    size_t ns = mem ? report_scenes_of(mem, scenes, 16) : 0;
    if (ns) {
        fprintf(f, "<h3>All the memory you have (scene, frame and method arenas)</h3>\n<div class=\"cards\">\n");
        for (size_t s = 0; s < ns; s++) {
            double budgets[16];
            size_t nb = report_memory_budgets(mem, scenes[s], budgets, 16);
            char anchor[96];
            snprintf(anchor, sizeof anchor, "chart-memory-%s", scenes[s]);
            budget_table(f, mem, scenes[s], scenes[s], budgets, nb, anchor, true);
        }
        fprintf(f, "</div>\n");
    } else {
        fprintf(f, "<p>(No <code>memory.csv</code>: <code>ombra report --equal-memory</code> measures the "
                   "budgets of all the arenas.)</p>\n");
    }
    chips(f, x);
    ns = bench ? report_scenes_of(bench, scenes, 16) : 0;
    if (ns) {
        fprintf(f, "<h3>Per scene of the sweep, the method's own arena</h3>\n<p class=\"read\">The same "
                   "question on each scene of the sweep at its size, the budget counting the method's arena "
                   "alone (its peak; the scene and the frame, the same for every method, come on top).</p>\n"
                   "<div class=\"cards\">\n");
        for (size_t s = 0; s < ns; s++) {
            char anchor[300];
            report_chart_id(anchor, sizeof anchor, scenes[s], "bytes");
            budget_table(f, bench, scenes[s], cli_base_name(scenes[s]), arena_budgets, NARENA, anchor, false);
        }
        fprintf(f, "</div>\n");
    }
    fprintf(f, "</section>\n");
}
