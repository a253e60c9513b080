/* file.c — whole-file reads for the host, never more than a stated number of bytes,
 * and an om_loader over them that reads each file once. */
#define _POSIX_C_SOURCE 200809L   /* fileno, fstat */
#include "platform.h"

#include <errno.h>
#include <stdint.h>
#include <sys/stat.h>
#include <stdlib.h>
#include <string.h>

static om_status read_fail(om_diag *d, om_status st, const char *path, const char *why)
{
    if (d) {
        d->status = st;
        snprintf(d->msg, sizeof d->msg, "%s: %s", path, why);
    }
    return st;
}

om_status om_file_read_max(const char *path, size_t max, char **data, size_t *len, om_diag *d)
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
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
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
    for (size_t i = 0; i < fl->nfiles; i++)
        if (!strcmp(fl->files[i].path, path)) {
            free(path);
            *data = fl->files[i].data;
            *len = fl->files[i].len;
            return OM_OK;
        }
    if (fl->nfiles == fl->cap) {
        size_t cap = fl->cap ? 2 * fl->cap : 8;
        om_file_entry *more = realloc(fl->files, cap * sizeof *more);
        if (!more) { free(path); return OM_E_IO; }
        fl->files = more;
        fl->cap = cap;
    }
    om_file_entry *e = &fl->files[fl->nfiles];
    size_t max = !fl->limit ? OM_FILE_MAX : fl->limit > fl->held ? fl->limit - fl->held : 0;
    om_status st = om_file_read_max(path, max, &e->data, &e->len, d);
    if (st != OM_OK) { free(path); return st; }
    e->path = path;
    fl->held += e->len;
    fl->nfiles++;
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
