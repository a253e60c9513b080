/* report_machines.c — the report's "small machines" section (see report.h): what
 * `make cross-test` measured on the Cortex-M4 firmware under QEMU, read from the CSVs
 * it writes (never typed in): per method its code, least arena, whole footprint and
 * instructions a frame at 160x120 (m4-methods.csv); per method, scene and size the
 * instructions of a frame and the bytes of each arena, on the Cortex-M7 too (m7.csv);
 * the firmware's size; the engine's code per part.
 * Where the files are not there (no cross toolchain), the section shows the tables
 * `make cross-test` and tests/cross/count-table.sh last wrote into the firmware's
 * README, labelled with the commit that wrote them, and how to refresh them; the
 * summary's chips are read from the same tables then. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "report.h"
#include "svg.h"

#include <stdlib.h>
#include <string.h>

static const rcol m4_cols[] = {
    {"scene", "scene", R_TEXT, NULL},
    {"method", "method", R_TEXT, NULL},
    {"width", "size", R_SIZE, "height"},
    {"strip_rows", "strip rows", R_INT, NULL},
    {"instructions", "instructions a frame", R_INT, NULL},
    {"method_bytes", "method arena, bytes", R_INT, NULL},
    {"frame_bytes", "frame arena, bytes", R_INT, NULL},
    {"scene_bytes", "scene arena, bytes", R_INT, NULL},
    {"min_bytes", "method's least arena, bytes", R_INT, NULL},
    {"stack_bytes", "stack, bytes", R_INT, NULL},
    {"whole_bytes", "whole footprint, bytes", R_INT, NULL},
};

static const rcol method_cols[] = {
    {"method", "method", R_TEXT, NULL},
    {"text", "code (.text, Cortex-M4 -Os), bytes", R_INT, NULL},
    {"min_bytes", "least arena at 160x120, bytes", R_INT, NULL},
    {"whole_bytes", "whole footprint, small scene, bytes", R_INT, NULL},
    {"instructions_small", "instructions a frame, small scene", R_INT, NULL},
    {"instructions_default", "instructions a frame, default scene", R_INT, NULL},
};

static const rcol size_cols[] = {
    {"build", "build", R_TEXT, NULL},
    {"text", "code (.text), bytes", R_INT, NULL},
    {"data", "initialised data (.data), bytes", R_INT, NULL},
    {"bss", "zeroed data (.bss), bytes", R_INT, NULL},
};

static const rcol code_cols[] = {
    {"part", "part of the engine, or firmware", R_TEXT, NULL},
    {"text", "code (.text), bytes", R_INT, NULL},
};

/* The firmware README read as Markdown: its "## " sections, paragraphs, tables and
 * indented code. Only what the README uses is understood; the rest is shown as text. */
static char *doc_text(const char *path)
{
    char *text;
    size_t len;
    om_diag d;
    return path && om_file_read(path, &text, &len, &d) == OM_OK ? text : NULL;
}

/* Cuts a table row "| a | b |" into at most max trimmed cells in buf; returns how many. */
static int row_cells(const char *line, char cells[][160], int max)
{
    int n = 0;
    const char *p = strchr(line, '|');
    while (p && n < max) {
        const char *q = p + 1;
        size_t l = strcspn(q, "|\n");
        if (q[l] != '|') break;
        while (l && (*q == ' ')) { q++; l--; }
        while (l && q[l - 1] == ' ') l--;
        snprintf(cells[n++], 160, "%.*s", (int)l, q);
        p = strchr(q, '|');
    }
    return n;
}

static double doc_num(const char *s)
{
    char buf[64];
    size_t o = 0;
    for (; *s && o + 1 < sizeof buf; s++)
        if (*s != ',') buf[o++] = *s;
    buf[o] = 0;
    return atof(buf);
}

/* In the first table whose header row holds a cell `col`, the cell `col` of the row
 * that names `method` (a cell opening with `method` in backquotes), as a number; -1
 * when there is none. A table of pairs (two methods a row) repeats its header's
 * columns: the wanted cell is as far from the method's as in the header. */
static double doc_value(const char *text, const char *method, const char *col)
{
    char want[48], head[16][160], cells[16][160];
    snprintf(want, sizeof want, "`%s`", method);
    size_t wl = strlen(want);
    int ci = -1, period = 0, rows = 0;
    for (const char *l = text; l && *l; l = strchr(l, '\n') ? strchr(l, '\n') + 1 : NULL) {
        if (*l != '|') {
            if (ci >= 0) return -1;   /* the table with the column had no such row */
            rows = 0;
            continue;
        }
        if (rows++ == 0) {
            int n = row_cells(l, head, 16);
            for (int k = 0; k < n && ci < 0; k++)
                if (!strcmp(head[k], col)) ci = k;
            period = n;
            for (int k = 1; k < n; k++)
                if (!strcmp(head[k], head[0])) { period = k; break; }
            continue;
        }
        if (ci < 0) continue;
        int n = row_cells(l, cells, 16);
        for (int k = 0; k < n; k++)
            if (!strncmp(cells[k], want, wl) && (cells[k][wl] == 0 || cells[k][wl] == ' ')) {
                int at = k + ci % period;
                return at < n ? doc_num(cells[at]) : -1;
            }
    }
    return -1;
}

size_t report_chips(const rcross *x, rchip *out, size_t max, const char **from)
{
    size_t n = 0;
    *from = NULL;
    rcsv c;
    char *path = cli_path(x->dir, "m4-methods.csv");
    if (path && rcsv_load(&c, path)) {
        *from = "csv";
        for (size_t r = 0; r < c.rows && n < max; r++) {
            rchip *o = &out[n];
            snprintf(o->method, sizeof o->method, "%s", rcsv_get(&c, r, "method"));
            o->text = rcsv_num(&c, r, "text");
            o->whole = rcsv_num(&c, r, "whole_bytes");
            o->instructions = rcsv_num(&c, r, "instructions_small");
            o->fps = o->instructions > 0 ? CHIP_MHZ * 1e6 / (CHIP_CPI * o->instructions) : 0;
            n++;
        }
        rcsv_free(&c);
        free(path);
        return n;
    }
    free(path);
    char *text = doc_text(x->doc);
    if (!text) return 0;
    /* the methods the registry has, as the README's tables name them */
    for (size_t k = 0; k < om_method_count() && n < max; k++) {
        const char *m = om_method_name(om_method_at(k));
        rchip *o = &out[n];
        snprintf(o->method, sizeof o->method, "%s", m);
        o->text = doc_value(text, m, "bytes");
        o->whole = doc_value(text, m, "whole footprint");
        o->instructions = doc_value(text, m, "small 160x120, M") * 1e6;
        o->fps = doc_value(text, m, "fps");
        if (o->whole > 0 || o->instructions > 0) n++;
    }
    if (n) *from = "doc";
    free(text);
    return n;
}

/* Inline Markdown: `code`, **bold**, [text](link) as its text. */
static void md_inline(FILE *f, const char *s, size_t n)
{
    bool code = false;
    char one[2] = {0, 0};
    for (size_t i = 0; i < n; i++) {
        if (s[i] == '`') { fputs(code ? "</code>" : "<code>", f); code = !code; continue; }
        if (!code && s[i] == '*' && i + 1 < n && s[i + 1] == '*') { i++; continue; }
        if (!code && s[i] == ']' && i + 1 < n && s[i + 1] == '(') {
            while (i < n && s[i] != ')') i++;
            continue;
        }
        if (!code && s[i] == '[') continue;
        one[0] = s[i];
        svg_escape(f, one);
    }
    if (code) fputs("</code>", f);
}

/* The README's "## " sections that hold a table of figures (digits in a body row), as
 * HTML: headings, paragraphs, tables and code. */
static void doc_sections(FILE *f, const char *text)
{
    const char *sec = NULL;
    for (const char *l = text;; l = strchr(l, '\n') + 1) {
        bool end = !strchr(l, '\n') || !strncmp(l, "## ", 3);
        if (end && sec) {
            /* does the section hold figures: a table cell of digits, commas, points and slashes? */
            bool figures = false;
            for (const char *p = sec; p < l && !figures; p = strchr(p, '\n') + 1) {
                if (*p == '|') {
                    char cells[16][160];
                    int nc = row_cells(p, cells, 16);
                    for (int k = 0; k < nc && !figures; k++)
                        figures = cells[k][0] >= '0' && cells[k][0] <= '9' && !cells[k][strspn(cells[k], "0123456789,./ ")];
                }
                if (!strchr(p, '\n')) break;
            }
            if (figures) {
                const char *p = sec;
                size_t n = strcspn(p, "\n");
                fprintf(f, "<h3>");
                md_inline(f, p + 3, n - 3);
                fprintf(f, "</h3>\n");
                p += n + 1;
                while (p < l) {
                    n = strcspn(p, "\n");
                    if (n == 0) { p++; continue; }
                    if (*p == '|') {
                        fprintf(f, "<div class=\"scroll\"><table>\n");
                        for (int row = 0; p < l && *p == '|'; row++) {
                            n = strcspn(p, "\n");
                            char cells[16][160];
                            int nc = row_cells(p, cells, 16);
                            if (row != 1) {
                                fprintf(f, "<tr>");
                                for (int k = 0; k < nc; k++) {
                                    bool num = cells[k][0] >= '0' && cells[k][0] <= '9';
                                    fprintf(f, row == 0 ? "<th>" : num ? "<td>" : "<td class=\"t\">");
                                    md_inline(f, cells[k], strlen(cells[k]));
                                    fprintf(f, row == 0 ? "</th>" : "</td>");
                                }
                                fprintf(f, "</tr>\n");
                            }
                            p += n + (p[n] != 0);
                        }
                        fprintf(f, "</table></div>\n");
                        continue;
                    }
                    if (!strncmp(p, "    ", 4)) {
                        fprintf(f, "<pre>");
                        while (p < l && !strncmp(p, "    ", 4)) {
                            n = strcspn(p, "\n");
                            char line[512];
                            snprintf(line, sizeof line, "%.*s\n", (int)(n - 4 < 510 ? n - 4 : 510), p + 4);
                            svg_escape(f, line);
                            p += n + (p[n] != 0);
                        }
                        fprintf(f, "</pre>\n");
                        continue;
                    }
                    /* a paragraph: its lines joined, so code spans may cross them */
                    static char para[8192];
                    size_t o = 0;
                    while (p < l && *p != '|' && *p != '\n' && strncmp(p, "    ", 4)) {
                        n = strcspn(p, "\n");
                        if (o + n + 2 < sizeof para) {
                            memcpy(para + o, p, n);
                            o += n;
                            para[o++] = ' ';
                        }
                        p += n + (p[n] != 0);
                    }
                    fprintf(f, "<p>");
                    md_inline(f, para, o);
                    fprintf(f, "</p>\n");
                }
            }
            sec = NULL;
        }
        if (!strncmp(l, "## ", 3)) sec = l;
        if (!strchr(l, '\n')) break;
    }
}

static void missing(FILE *f, const char *path, const char *what)
{
    fprintf(f, "<p class=\"missing\">No <code>");
    svg_escape(f, path);
    fprintf(f, "</code> yet: <code>make cross-test</code> writes it (%s).</p>\n", what);
}

/* Instructions a frame against all the arenas' bytes, a series per method in the
 * CSV's (the registry's) order, `none` left to the table: the methods then keep the
 * colours they have on the other charts. */
static void chart(FILE *f, const rcsv *c)
{
    enum { MAXM = 16, MAXP = 32 };
    static double xs[MAXM][MAXP], ys[MAXM][MAXP];
    static char text[MAXM][MAXP][48];
    static const char *labels[MAXM][MAXP];
    svg_series s[MAXM];
    const char *names[MAXM];
    size_t ns = 0;
    for (size_t r = 0; r < c->rows; r++) {
        const char *m = rcsv_get(c, r, "method");
        double ins = rcsv_num(c, r, "instructions");
        if (!(ins > 0) || !strcmp(m, "none")) continue;
        size_t k = 0;
        while (k < ns && strcmp(names[k], m)) k++;
        if (k == ns) {
            if (ns == MAXM) continue;
            names[ns] = m;
            s[ns] = (svg_series){m, xs[ns], ys[ns], 0, labels[ns], NULL, NULL};
            ns++;
        }
        if (s[k].n == MAXP) continue;
        xs[k][s[k].n] = rcsv_num(c, r, "whole_bytes");
        ys[k][s[k].n] = ins;
        snprintf(text[k][s[k].n], sizeof text[k][s[k].n], "%s@%sx%s", rcsv_get(c, r, "scene"),
                 rcsv_get(c, r, "width"), rcsv_get(c, r, "height"));
        labels[k][s[k].n] = text[k][s[k].n];
        s[k].n++;
    }
    if (!ns) return;
    svg_chart ch = {"Cortex-M4: instructions a frame against memory", "whole footprint, bytes",
                    "instructions a frame", true, true, false, false, SVG_BYTES, SVG_PLAIN};
    fprintf(f, "<p class=\"read\">Left needs less memory (the whole footprint: the three "
               "arenas, the firmware's other static data and the stack), down less work a frame (instructions "
               "retired under QEMU; at a cycle or two each, 100M instructions are about a second "
               "at 100 MHz). <code>none</code>, the frame without shadows, is in the table: what "
               "every method pays besides its own work.</p>\n");
    svg_write_inline(f, &ch, s, ns);
}

/* One CSV of the cross directory: its paragraph, its chart where asked and its table;
 * where the file is not there (path non-NULL), what writes it; nothing for a NULL path. */
static void section(FILE *f, const char *path, const char *intro, const rcol *cols, size_t ncols, bool with_chart,
                    const char *what)
{
    rcsv c;
    if (!path) return;
    if (!rcsv_load(&c, path)) {
        missing(f, path, what);
        return;
    }
    if (intro) fputs(intro, f);
    if (with_chart) chart(f, &c);
    report_table(f, &c, cols, ncols, NULL, NULL);
    rcsv_free(&c);
}

void report_machines(FILE *f, const rcross *x)
{
    const char *cross = x->dir;
    fprintf(f, "<h2 id=\"machines\">Small machines</h2>\n<p class=\"read\">The same methods built "
               "into Cortex-M4 firmware and run under QEMU by <code>make cross-test</code>: per "
               "method and scene the instructions of one frame and the bytes of each arena (strips "
               "keep the frame's small), and the firmware's size.</p>\n");
    char *m4 = cli_path(cross, "m4.csv"), *m7 = cli_path(cross, "m7.csv"), *size = cli_path(cross, "m4-size.csv");
    char *per = cli_path(cross, "m4-methods.csv");
    rcsv probe;
    bool have = per && rcsv_load(&probe, per);
    if (have) rcsv_free(&probe);
    char *text = have ? NULL : doc_text(x->doc);
    if (!have && text) {
        fprintf(f, "<div id=\"machines-doc\"><p class=\"note\">This machine has no <code>");
        svg_escape(f, cross);
        fprintf(f, "/m4-methods.csv</code> (no <code>arm-none-eabi-gcc</code> and <code>qemu-system-arm</code> "
                   "for <code>make run</code> to count with), so these are the tables <code>make cross-test</code> "
                   "last wrote into <code>");
        svg_escape(f, x->doc);
        fprintf(f, "</code>, as of commit <b>");
        svg_escape(f, x->doc_rev && x->doc_rev[0] ? x->doc_rev : "(unknown: not a git checkout)");
        fprintf(f, "</b>. To refresh them: <code>CROSS_ONLY=m4-count make cross-test</code> (the counts, into "
                   "<code>");
        svg_escape(f, cross);
        fprintf(f, "/</code>), <code>sh tests/cross/count-table.sh</code> (the tables of instructions, for the "
                   "README), or <code>make run</code> on a machine with the toolchain, which counts them "
                   "for this page.</p>\n");
        doc_sections(f, text);
        fprintf(f, "</div>\n");
        free(text);
        free(m4); free(m7); free(per); free(size);
        return;
    }
    free(text);
    fprintf(f, "<div id=\"machines-methods\">");
    section(f, per,"<p>Per method at 160x120: its own files' code (the shared parts are in the "
                    "last table), the least method arena it works in, its whole footprint on the "
                    "small scene with the arena the firmware gives it (at most 256 KiB: scene, frame "
                    "and method arenas, the other static data and the stack; the run fails beyond), "
                    "and its instructions a frame:</p>\n",
            method_cols, sizeof method_cols / sizeof method_cols[0], false,
            "each method's code, least arena, footprint and instructions a frame");
    fprintf(f, "</div>\n");
    section(f, m4, NULL, m4_cols, sizeof m4_cols / sizeof m4_cols[0], true,
            "instructions a frame and arena bytes per method on the Cortex-M4 build");
    section(f, m7, "<p>The same firmware for a Cortex-M7 (QEMU's mps2-an500, a double FPU: "
                   "what a Teensy 4 or an STM32H7 runs), <code>none</code>, <code>sm</code> and "
                   "<code>hybrid</code> on the small scene:</p>\n",
            m4_cols, sizeof m4_cols / sizeof m4_cols[0], false, "instructions a frame on the Cortex-M7 build");
    section(f, size, "<p>The firmware's size (every method and both scenes linked in; the "
                     "<code>.bss</code> holds the arenas):</p>\n",
            size_cols, sizeof size_cols / sizeof size_cols[0], false, "the code size of each Cortex-M4 build");
    char *code = cli_path(cross, "code-size.csv");
    section(f, code, "<p>Code per method and part of the engine (each part's files compiled "
                     "alone for Cortex-M4 at <code>-Os</code>), and the README's embedding example "
                     "as Cortex-M4 firmware with every method and with <code>sm</code> alone "
                     "(<code>OM_WITH_*=0</code> for the others), as <code>make cross-test</code> "
                     "prints them:</p>\n",
            code_cols, sizeof code_cols / sizeof code_cols[0], false,
            "the code size of each method and part of the engine");
    free(m4);
    free(m7);
    free(per);
    free(size);
    free(code);
}
