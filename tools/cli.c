/* cli.c — helpers shared by the subcommands. */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int cli_error(const char *where, const om_diag *d, om_status st)
{
    const char *msg = d && d->msg[0] ? d->msg : om_status_str(st);
    fprintf(stderr, "ombra: %s%s%s (%s)\n", where ? where : "", where ? ": " : "", msg,
            om_status_str(st));
    return 1;
}

int cli_usage_error(const char *cmd, const char *fmt, const char *arg)
{
    fprintf(stderr, "ombra %s: ", cmd);
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n(see 'ombra %s --help')\n", cmd);
    return 2;
}

om_status cli_scene_load(cli_scene *cs, const char *path, om_diag *d)
{
    memset(cs, 0, sizeof *cs);
    cs->path = path;
    const char *text = om_scene_default_text();
    size_t len = strlen(text);
    om_status st;
    if (path) {
        if ((st = om_file_read(path, &cs->text, &len, d)) != OM_OK) return st;
        text = cs->text;
    }
    om_file_loader_init(&cs->files, path);
    cs->files.diag = d;
    om_loader ld = om_file_loader_get(&cs->files);
    /* Model no more than the scene needs: the arena is exactly its bytes query. */
    if ((st = om_scene_bytes(text, len, &ld, &cs->bytes, d)) != OM_OK) return st;
    om_file_loader_free(&cs->files);
    cs->mem = malloc(cs->bytes ? cs->bytes : 1);
    if (!cs->mem) return OM_E_BUDGET;
    om_arena_init(&cs->arena, cs->mem, cs->bytes, "scene");
    st = om_scene_parse(text, len, &ld, &cs->arena, &cs->scene, d);
    om_file_loader_free(&cs->files);
    return st;
}

void cli_scene_free(cli_scene *cs)
{
    free(cs->text);
    free(cs->mem);
    cs->text = NULL;
    cs->mem = NULL;
}

bool cli_parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || end == s || *end || s[0] == '-' || v < lo || v > hi) return false;
    *out = (uint32_t)v;
    return true;
}

bool cli_parse_size(const char *s, uint32_t *w, uint32_t *h)
{
    char buf[64];
    const char *x = strchr(s, 'x');
    if (!x || (size_t)(x - s) >= sizeof buf) return false;
    memcpy(buf, s, (size_t)(x - s));
    buf[x - s] = '\0';
    return cli_parse_u32(buf, 1, OM_MAX_DIM, w) && cli_parse_u32(x + 1, 1, OM_MAX_DIM, h);
}

bool cli_parse_bytes(const char *s, size_t *out)
{
    char *end;
    errno = 0;
    if (s[0] == '-') return false;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || end == s) return false;
    unsigned long long mul = 1;
    if (*end == 'K' || *end == 'k') mul = 1ull << 10, end++;
    else if (*end == 'M' || *end == 'm') mul = 1ull << 20, end++;
    else if (*end == 'G' || *end == 'g') mul = 1ull << 30, end++;
    if (*end == 'i') end++;
    if (*end == 'B') end++;
    if (*end || v > (unsigned long long)SIZE_MAX / mul) return false;
    *out = (size_t)(v * mul);
    return true;
}

bool cli_parse_float(const char *s, float *out)
{
    char *end;
    errno = 0;
    float v = strtof(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return false;
    *out = v;
    return true;
}

om_status cli_oom(om_diag *d)
{
    if (d) {
        d->status = OM_E_BUDGET;
        snprintf(d->msg, sizeof d->msg, "the host could not allocate memory for the arenas");
    }
    return OM_E_BUDGET;
}

bool cli_set(om_method_cfg *c, const char *setting)
{
    char name[64];
    const char *eq = strchr(setting, '=');
    if (!eq || (size_t)(eq - setting) >= sizeof name) {
        fprintf(stderr, "ombra: --set takes NAME=VALUE, not '%s' (see 'ombra methods')\n", setting);
        return false;
    }
    memcpy(name, setting, (size_t)(eq - setting));
    name[eq - setting] = '\0';
    char *end;
    errno = 0;
    double v = strtod(eq + 1, &end);
    if (errno || end == eq + 1 || *end) {
        fprintf(stderr, "ombra: %s takes a number, not '%s'\n", name, eq + 1);
        return false;
    }
    om_diag d;
    om_status st = om_method_cfg_set(c, name, v, &d);
    if (st != OM_OK) {
        fprintf(stderr, "ombra: setting '%s': %s (see 'ombra methods')\n", name, d.msg);
        return false;
    }
    return true;
}
