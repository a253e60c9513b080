/* file.c — whole-file reads for the host, and an om_loader over them that reads each
 * file once. */
#include "platform.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

om_status om_file_read(const char *path, char **data, size_t *len, om_diag *d)
{
    *data = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        om_status st = errno == ENOENT ? OM_E_NOTFOUND : OM_E_IO;
        if (d) {
            d->status = st;
            snprintf(d->msg, sizeof d->msg, "%s: %s", path, strerror(errno));
        }
        return st;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap + 1);
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (n < cap) break;
        char *bigger = realloc(buf, cap * 2 + 1);
        if (!bigger) { free(buf); buf = NULL; break; }
        buf = bigger;
        cap *= 2;
    }
    int err = ferror(f);
    fclose(f);
    if (!buf || err) {
        free(buf);
        if (d) {
            d->status = OM_E_IO;
            snprintf(d->msg, sizeof d->msg, "%s: %s", path, buf ? "read error" : "out of memory");
        }
        return OM_E_IO;
    }
    buf[n] = '\0';
    *data = buf;
    *len = n;
    return OM_OK;
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
    om_status st = om_file_read(path, &e->data, &e->len, d);
    if (st != OM_OK) { free(path); return st; }
    e->path = path;
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
