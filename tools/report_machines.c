/* report_machines.c — the report's "small machines" section (see report.h): what
 * `make cross-test` measured on the Cortex-M4 firmware under QEMU, read from the CSVs
 * it writes (never typed in): per method its code, least arena, whole footprint and
 * instructions a frame at 160x120 (m4-methods.csv); per method, scene and size the
 * instructions of a frame and the bytes of each arena, on the Cortex-M7 too (m7.csv);
 * the firmware's size; the engine's code per part.
 * Where the files are not there, the page says which command writes them. */
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

void report_machines(FILE *f, const char *cross)
{
    fprintf(f, "<h2 id=\"machines\">Small machines</h2>\n<p class=\"read\">The same methods built "
               "into Cortex-M4 firmware and run under QEMU by <code>make cross-test</code>: per "
               "method and scene the instructions of one frame and the bytes of each arena (strips "
               "keep the frame's small), and the firmware's size.</p>\n");
    char *m4 = cli_path(cross, "m4.csv"), *m7 = cli_path(cross, "m7.csv"), *size = cli_path(cross, "m4-size.csv");
    char *per = cli_path(cross, "m4-methods.csv");
    section(f, per, "<p>Per method at 160x120: its own files' code (the shared parts are in the "
                    "last table), the least method arena it works in, its whole footprint on the "
                    "small scene with the arena the firmware gives it (at most 256 KiB: scene, frame "
                    "and method arenas, the other static data and the stack; the run fails beyond), "
                    "and its instructions a frame:</p>\n",
            method_cols, sizeof method_cols / sizeof method_cols[0], false,
            "each method's code, least arena, footprint and instructions a frame");
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
