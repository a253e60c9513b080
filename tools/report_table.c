/* report_table.c — the report's CSV reading and its tables (see report.h): bench.csv
 * and stability.csv are read by column name and shown with the columns a reader
 * needs, human headers with units and thousands separators; the CSV keeps the rest. */
#define _POSIX_C_SOURCE 200809L
#include "report.h"
#include "svg.h"
#include "../platform/platform.h"

#include <stdlib.h>
#include <string.h>

bool rcsv_load(rcsv *c, const char *path)
{
    memset(c, 0, sizeof *c);
    char *data;
    size_t len;
    om_diag d;
    if (om_file_read(path, &data, &len, &d) != OM_OK) return false;
    /* count the lines and the header's columns, then cut in place */
    size_t lines = 0, cols = 1;
    for (size_t i = 0; i < len; i++) lines += data[i] == '\n';
    if (len && data[len - 1] != '\n') lines++;
    for (size_t i = 0; i < len && data[i] != '\n'; i++) cols += data[i] == ',';
    if (lines < 1) { free(data); return false; }
    c->text = data;
    c->cols = cols;
    c->rows = lines - 1;
    c->cell = calloc(lines * cols, sizeof *c->cell);
    if (!c->cell) { free(data); return false; }
    char *p = data;
    for (size_t r = 0; r < lines; r++) {
        for (size_t k = 0; k < cols; k++) c->cell[r * cols + k] = "";
        char *end = strchr(p, '\n');
        if (end) *end = 0;
        if (end && end > p && end[-1] == '\r') end[-1] = 0;
        for (size_t k = 0; k < cols; k++) {
            c->cell[r * cols + k] = p;
            char *comma = strchr(p, ',');
            if (!comma) { p += strlen(p); break; }
            /* the last column takes the rest of the line (a stray comma stays in it) */
            if (k + 1 < cols) { *comma = 0; p = comma + 1; }
        }
        if (!end) break;
        p = end + 1;
    }
    c->head = c->cell;
    c->cell += cols;
    return true;
}

void rcsv_free(rcsv *c)
{
    if (c->head) free(c->head);
    free(c->text);
    memset(c, 0, sizeof *c);
}

int rcsv_col(const rcsv *c, const char *name)
{
    for (size_t k = 0; k < c->cols; k++)
        if (!strcmp(c->head[k], name)) return (int)k;
    return -1;
}

const char *rcsv_get(const rcsv *c, size_t r, const char *name)
{
    int k = rcsv_col(c, name);
    return k < 0 || r >= c->rows ? "" : c->cell[r * c->cols + (size_t)k];
}

double rcsv_num(const rcsv *c, size_t r, const char *name)
{
    return atof(rcsv_get(c, r, name));
}

static void cell(FILE *f, const rcsv *c, size_t r, const rcol *col)
{
    char buf[96];
    const char *v = rcsv_get(c, r, col->csv);
    switch (col->kind) {
    case R_INT: svg_format(buf, sizeof buf, atof(v), SVG_PLAIN); break;
    case R_MS: snprintf(buf, sizeof buf, "%.2f", atof(v)); break;
    case R_SHARE: snprintf(buf, sizeof buf, "%.3f", 100 * atof(v)); break;
    case R_SIZE: snprintf(buf, sizeof buf, "%s&#215;%s", v, rcsv_get(c, r, col->csv2)); break;
    case R_RANGE:
        snprintf(buf, sizeof buf, "%.1f&#8211;%.1f", atof(v), atof(rcsv_get(c, r, col->csv2)));
        break;
    default: buf[0] = 0; break;
    }
    fprintf(f, col->kind == R_TEXT ? "<td class=\"t\">" : "<td>");
    if (col->kind == R_TEXT) svg_escape(f, v);
    else fputs(buf, f);
    fprintf(f, "</td>");
}

void report_table(FILE *f, const rcsv *c, const rcol *cols, size_t ncols,
                  bool (*keep)(const rcsv *c, size_t r, const void *user), const void *user)
{
    fprintf(f, "<div class=\"scroll\"><table>\n<tr>");
    for (size_t k = 0; k < ncols; k++) {
        fprintf(f, "<th>");
        svg_escape(f, cols[k].head);
        fprintf(f, "</th>");
    }
    fprintf(f, "</tr>\n");
    for (size_t r = 0; r < c->rows; r++) {
        if (keep && !keep(c, r, user)) continue;
        fprintf(f, "<tr>");
        for (size_t k = 0; k < ncols; k++) cell(f, c, r, &cols[k]);
        fprintf(f, "</tr>\n");
    }
    fprintf(f, "</table></div>\n");
}
