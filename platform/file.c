/* file.c — whole-file reads for the host, and an om_loader over them. */
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

void om_file_loader_init(om_file_loader *fl, const char *scene_path)
{
    memset(fl, 0, sizeof *fl);
    const char *slash = scene_path ? strrchr(scene_path, '/') : NULL;
    if (slash && (size_t)(slash - scene_path) + 2 < sizeof fl->base) {
        memcpy(fl->base, scene_path, (size_t)(slash - scene_path) + 1);
        fl->base[slash - scene_path + 1] = '\0';
    }
}

static om_status load(void *user, const char *name, const char **data, size_t *len)
{
    om_file_loader *fl = (om_file_loader *)user;
    char path[2048];
    om_diag local;
    if (fl->nbufs == (int)(sizeof fl->bufs / sizeof fl->bufs[0])) return OM_E_INVALID;
    if (name[0] == '/') snprintf(path, sizeof path, "%s", name);
    else snprintf(path, sizeof path, "%s%s", fl->base, name);
    char *buf;
    om_status st = om_file_read(path, &buf, len, fl->diag ? fl->diag : &local);
    if (st != OM_OK) return st;
    fl->bufs[fl->nbufs++] = buf;
    *data = buf;
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
    for (int i = 0; i < fl->nbufs; i++) free(fl->bufs[i]);
    fl->nbufs = 0;
}
