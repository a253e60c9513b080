/* file.c — whole-file reads of text for the host, never more than a stated number of
 * bytes, and an om_loader over them that reads each file once. */
#define _POSIX_C_SOURCE 200809L   /* fileno, fstat */
#include "platform.h"

#include <errno.h>
#include <stdint.h>
#include <sys/stat.h>
#include <stdlib.h>
#include <string.h>

#define CHUNK ((size_t)1 << 20)

static om_status read_fail(om_diag *d, om_status st, const char *path, const char *why)
{
    if (d) {
        d->status = st;
        snprintf(d->msg, sizeof d->msg, "%s: %s", path, why);
    }
    return st;
}

/* With `text`, a NUL byte ends the read with OM_E_PARSE. */
static om_status read_file(const char *path, size_t max, bool text, char **data, size_t *len, om_diag *d)
{
    *data = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return read_fail(d, errno == ENOENT ? OM_E_NOTFOUND : OM_E_IO, path, strerror(errno));
    char why[96];
    snprintf(why, sizeof why, "larger than the %zu bytes that may be read", max);
    /* A regular file says its size: refused before a byte is read, and read into a
     * buffer of exactly that size. A stream (a FIFO, /dev/zero) grows one up to max. */
    struct stat sb;
    size_t cap = 1 << 16, n = 0;
    if (fstat(fileno(f), &sb) == 0 && S_ISREG(sb.st_mode)) {
        if ((uintmax_t)sb.st_size > max) { fclose(f); return read_fail(d, OM_E_BUDGET, path, why); }
        cap = (size_t)sb.st_size + 1;   /* one more: a file that grew is seen */
    }
    if (cap > max + 1) cap = max + 1;
    char *buf = malloc(cap + 1);
    const char *nul = NULL;
    while (buf) {
        /* by chunks, each (for text) looked over for a NUL byte, which no text (a
         * scene, an OBJ file) holds: a large binary file is refused at its first
         * chunk, not read whole first */
        size_t want = cap - n < CHUNK ? cap - n : CHUNK, got = fread(buf + n, 1, want, f);
        nul = text ? memchr(buf + n, '\0', got) : NULL;
        n += got;
        if (nul) break;
        if (got == want && n < cap) continue;
        if (n < cap || n > max) break;
        size_t next = cap > max / 2 ? max + 1 : cap * 2;
        char *bigger = realloc(buf, next + 1);
        if (!bigger) { free(buf); buf = NULL; break; }
        buf = bigger;
        cap = next;
    }
    int err = ferror(f) ? errno : 0;
    fclose(f);
    if (!buf) return read_fail(d, OM_E_IO, path, "out of memory");
    if (nul) {
        snprintf(why, sizeof why, "not a text file: byte %zu is NUL", (size_t)(nul - buf));
        free(buf);
        return read_fail(d, OM_E_PARSE, path, why);
    }
    if (err || n > max) {
        free(buf);
        return n > max ? read_fail(d, OM_E_BUDGET, path, why)
                       : read_fail(d, OM_E_IO, path, strerror(err ? err : EIO));
    }
    buf[n] = '\0';
    *data = buf;
    *len = n;
    return OM_OK;
}

om_status om_file_read_max(const char *path, size_t max, char **data, size_t *len, om_diag *d)
{
    return read_file(path, max, false, data, len, d);
}

om_status om_file_read_text(const char *path, size_t max, char **data, size_t *len, om_diag *d)
{
    return read_file(path, max, true, data, len, d);
}

om_status om_file_read(const char *path, char **data, size_t *len, om_diag *d)
{
    return om_file_read_max(path, OM_FILE_MAX, data, len, d);
}

om_status om_file_loader_init(om_file_loader *fl, const char *scene_path)
{
    memset(fl, 0, sizeof *fl);
    const char *slash = scene_path ? strrchr(scene_path, '/') : NULL;
    if (slash) {
        size_t n = (size_t)(slash - scene_path) + 1;
        if (!(fl->base = malloc(n + 1))) return OM_E_IO;
        memcpy(fl->base, scene_path, n);
        fl->base[n] = '\0';
    }
    return OM_OK;
}

static om_status load(void *user, const char *name, const char **data, size_t *len)
{
    om_file_loader *fl = (om_file_loader *)user;
    om_diag local;
    om_diag *d = fl->diag ? fl->diag : &local;
    size_t nb = name[0] != '/' && fl->base ? strlen(fl->base) : 0, nn = strlen(name);
    char *path = malloc(nb + nn + 1);
    if (!path) return OM_E_IO;
    if (nb) memcpy(path, fl->base, nb);
    memcpy(path + nb, name, nn + 1);
    om_file_entry *e = NULL;
    for (size_t i = 0; i < fl->nfiles && !e; i++)
        if (!strcmp(fl->files[i].path, path)) e = &fl->files[i];
    if (e && e->data) {   /* read before, and still held */
        free(path);
        *data = e->data;
        *len = e->len;
        return OM_OK;
    }
    if (!e && fl->nfiles == fl->cap) {
        size_t cap = fl->cap ? 2 * fl->cap : 8;
        om_file_entry *more = realloc(fl->files, cap * sizeof *more);
        if (!more) { free(path); return OM_E_IO; }
        fl->files = more;
        fl->cap = cap;
    }
    const bool fresh = !e;
    if (fresh) e = &fl->files[fl->nfiles];
    size_t max = !fl->limit ? OM_FILE_MAX : fl->limit > fl->held ? fl->limit - fl->held : 0;
    om_status st = om_file_read_text(path, max, &e->data, &e->len, d);
    if (st != OM_OK) {
        free(path);
        return st;
    }
    if (fresh) {
        e->path = path;
        fl->nfiles++;
    } else {
        free(path);   /* read again after om_file_loader_drop_data */
    }
    fl->held += e->len;
    *data = e->data;
    *len = e->len;
    return OM_OK;
}

om_loader om_file_loader_get(om_file_loader *fl)
{
    om_loader l;
    l.load = load;
    l.user = fl;
    return l;
}

void om_file_loader_drop_data(om_file_loader *fl)
{
    for (size_t i = 0; i < fl->nfiles; i++) {
        free(fl->files[i].data);
        fl->files[i].data = NULL;
        fl->files[i].len = 0;
    }
    fl->held = 0;
}

void om_file_loader_free(om_file_loader *fl)
{
    for (size_t i = 0; i < fl->nfiles; i++) {
        free(fl->files[i].path);
        free(fl->files[i].data);
    }
    free(fl->files);
    free(fl->base);
    memset(fl, 0, sizeof *fl);
}
