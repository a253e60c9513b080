/* cli.c — what the subcommands share (cli.h): one-line errors and usage messages,
 * parsing of sizes, byte counts and numbers, loading a scene into an arena sized by
 * its bytes query, --set settings, the thread pool frames run on, paths, and the strip
 * callback that collects a frame's mask. */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int cli_error(const char *where, const om_diag *d, om_status st)
{
    const char *msg = d && d->msg[0] ? d->msg : om_status_str(st);
    /* A message that already starts with the file's name is not given it twice. */
    size_t n = where ? strlen(where) : 0;
    if (where && !strncmp(msg, where, n) && msg[n] == ':') where = NULL;
    /* File errors end with the system's reason; the status name would only repeat it
     * (or contradict it: "No such file ... (input/output error)"). */
    bool suffix = msg != om_status_str(st) && st != OM_E_IO && st != OM_E_NOTFOUND;
    fprintf(stderr, "ombra: %s%s%s%s%s%s\n", where ? where : "", where ? ": " : "", msg,
            suffix ? " (" : "", suffix ? om_status_str(st) : "", suffix ? ")" : "");
    return 1;
}

int cli_usage_error(const char *cmd, const char *fmt, const char *arg)
{
    fprintf(stderr, "ombra %s: ", cmd);
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n(see 'ombra %s --help')\n", cmd);
    return 2;
}

/* Edit distance, for "did you mean" (names are short). */
static size_t distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b), row[32];
    if (la >= 32 || lb >= 32) return 99;
    for (size_t j = 0; j <= lb; j++) row[j] = j;
    for (size_t i = 1; i <= la; i++) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t up = row[j], best = diag + (a[i - 1] != b[j - 1]);
            if (up + 1 < best) best = up + 1;
            if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
            diag = up;
            row[j] = best;
        }
    }
    return row[lb];
}

int cli_unknown_method(const char *cmd, const char *option, const char *name)
{
    const char *best = NULL;
    size_t bd = 3;   /* suggest only a name at most two edits away */
    for (size_t i = 0; i < om_method_count(); i++) {
        size_t dd = distance(name, om_method_name(om_method_at(i)));
        if (dd < bd) { bd = dd; best = om_method_name(om_method_at(i)); }
    }
    fprintf(stderr, "ombra %s: %s: unknown method '%s'", cmd, option, name);
    if (best) fprintf(stderr, "; did you mean '%s'?", best);
    fprintf(stderr, "\nmethods:");
    for (size_t i = 0; i < om_method_count(); i++) fprintf(stderr, " %s", om_method_name(om_method_at(i)));
    fprintf(stderr, " (see 'ombra methods')\n");
    return 2;
}

void cli_method_hint(const om_method *m, char *buf, size_t n)
{
    /* The first of its settings that sizes its memory: the map, bytes, a pool. */
    for (uint32_t i = 0; i < om_method_nsettings(m); i++) {
        const om_setting *f = om_method_setting_at(m, i);
        if (!strcmp(f->name, "map") || strstr(f->doc, "bytes") || strstr(f->doc, "pool")) {
            snprintf(buf, n, ", or ask the method for less (--set %s=N: %s)", f->name, f->doc);
            return;
        }
    }
    snprintf(buf, n, "%s", "");
}

bool cli_parse_budget(const char *cmd, const char *s, size_t *out)
{
    if (!strcmp(s, "none")) { *out = 0; return true; }
    if (!cli_parse_bytes(s, out)) {
        cli_usage_error(cmd, "--budget takes bytes like 65536, 64K or 8M (or 'none'), not '%s'", s);
        return false;
    }
    if (*out == 0) {
        cli_usage_error(cmd, "--budget %s leaves no memory at all; give bytes like 64K, or "
                        "'none' for no limit", s);
        return false;
    }
    return true;
}

om_status cli_scene_load(cli_scene *cs, const char *path, size_t budget, om_diag *d)
{
    memset(cs, 0, sizeof *cs);
    cs->path = path;
    const char *text = om_scene_default_text();
    size_t len = strlen(text);
    om_status st;
    /* With a budget, the scene's text and meshes count against it while they are
     * held, and the arena is refused by its bytes query before anything is made. */
    if (path && (st = om_file_read_text(path, budget ? budget : OM_FILE_MAX, &cs->text, &len, d)) != OM_OK)
        return st;
    if (path) text = cs->text;
    if (om_file_loader_init(&cs->files, path) != OM_OK) return cli_oom(d);
    cs->files.diag = d;
    cs->files.limit = budget ? (budget > len ? budget - len : 1) : 0;
    om_loader ld = om_file_loader_get(&cs->files);
    /* Model no more than the scene needs: the arena is exactly its bytes query. The
     * loader keeps every mesh it read for the second pass: each file is read once. */
    st = om_scene_bytes(text, len, &ld, &cs->bytes, d);
    size_t files = (path ? len : 0) + cs->files.held;
    if (st == OM_OK && budget && (cs->bytes > budget || files > budget - cs->bytes)) {
        st = OM_E_BUDGET;
        if (d) d->status = st, d->asked = cs->bytes + files, d->left = budget;
        if (d) {
            int n = snprintf(d->msg, sizeof d->msg, "--budget %zu is too small for the scene "
                             "alone: its arena needs %zu bytes", budget, cs->bytes);
            if (files && n > 0 && (size_t)n < sizeof d->msg)
                snprintf(d->msg + n, sizeof d->msg - (size_t)n, ", and its text and meshes %zu "
                         "more while it is read", files);
        }
    }
    if (st == OM_OK) {
        cs->mem = malloc(cs->bytes ? cs->bytes : 1);
        if (!cs->mem) st = cli_oom(d);
    }
    if (st == OM_OK) {
        om_arena_init(&cs->arena, cs->mem, cs->bytes, "scene");
        st = om_scene_parse(text, len, &ld, &cs->arena, &cs->scene, d);
    }
    /* The scene keeps nothing of its text or files; their paths stay, so that a
     * command can refuse to write over a file the scene read (cli_scene_free). */
    om_file_loader_drop_data(&cs->files);
    free(cs->text);
    cs->text = NULL;
    return st;
}

void cli_scene_free(cli_scene *cs)
{
    free(cs->text);
    free(cs->mem);
    om_file_loader_free(&cs->files);
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

char *cli_path(const char *dir, const char *file)
{
    size_t a = strlen(dir), b = strlen(file);
    char *p = malloc(a + b + 2);
    if (p) {
        memcpy(p, dir, a);
        p[a] = '/';
        memcpy(p + a + 1, file, b + 1);
    }
    return p;
}

const char *cli_base_name(const char *path)
{
    const char *b = strrchr(path, '/');
    return b ? b + 1 : path;
}

om_status cli_grab_mask(void *user, const om_strip *st, const om_framebuffer *fb)
{
    cli_masks *o = (cli_masks *)user;
    for (uint32_t i = 0; i < st->rows * st->width; i++)
        o->mask[(size_t)st->y0 * st->width + i] = om_mask_of(&st->samples[i], &st->terms[i]);
    if (o->rgb) memcpy(o->rgb + (size_t)st->y0 * st->width * 3, fb->pixels, (size_t)st->rows * fb->stride);
    return OM_OK;
}

om_status cli_scene_view(const cli_scene *cs, uint32_t w, uint32_t h, om_view *v, om_diag *d)
{
    om_camera cam;
    om_light light;
    om_scene_at(&cs->scene, 0, &cam, &light);
    if (w) { cam.width = w; cam.height = h; }
    return om_view_init(v, &cam, &light, &cs->scene, d);
}

om_status cli_oom(om_diag *d)
{
    if (d) {
        d->status = OM_E_BUDGET;
        snprintf(d->msg, sizeof d->msg, "the host could not allocate memory for the arenas");
    }
    return OM_E_BUDGET;
}

/* "NAME=VALUE" into name and value; prints what is wrong and returns false. */
static bool split(const char *setting, char *name, size_t n, double *v)
{
    const char *eq = strchr(setting, '=');
    if (!eq || eq == setting || (size_t)(eq - setting) >= n) {
        fprintf(stderr, "ombra: --set takes NAME=VALUE, not '%s' (see 'ombra methods')\n", setting);
        return false;
    }
    memcpy(name, setting, (size_t)(eq - setting));
    name[eq - setting] = '\0';
    char *end;
    errno = 0;
    *v = strtod(eq + 1, &end);
    if (errno || end == eq + 1 || *end) {
        fprintf(stderr, "ombra: %s takes a number, not '%s'\n", name, eq + 1);
        return false;
    }
    return true;
}

bool cli_set(om_method_cfg *c, const char *setting)
{
    char name[64];
    double v;
    if (!split(setting, name, sizeof name, &v)) return false;
    om_diag d;
    om_status st = om_method_cfg_set(c, name, v, &d);
    if (st != OM_OK) {
        fprintf(stderr, "ombra: setting '%s': %s (see 'ombra methods')\n", name, d.msg);
        return false;
    }
    return true;
}

bool cli_settings_add(cli_settings *s, const char *setting)
{
    char name[64];
    double v;
    if (!split(setting, name, sizeof name, &v)) return false;
    bool taken = false;
    for (size_t i = 0; i < om_method_count() && !taken; i++)
        taken = om_method_setting(om_method_at(i), name) != NULL;
    if (!taken) {
        fprintf(stderr, "ombra: unknown setting '%s': no method takes it (see 'ombra methods')\n", name);
        return false;
    }
    if (s->n == (int)(sizeof s->item / sizeof s->item[0]) || strlen(setting) >= sizeof s->item[0]) {
        fprintf(stderr, "ombra: too many settings, or '%s' is too long\n", setting);
        return false;
    }
    memcpy(s->item[s->n++], setting, strlen(setting) + 1);
    return true;
}

bool cli_cfg(const om_method *m, const cli_settings *s, om_method_cfg *c, const char *note)
{
    om_method_cfg_default(c, m);
    for (int i = 0; s && i < s->n; i++) {
        char name[64];
        double v;
        if (!split(s->item[i], name, sizeof name, &v)) return false;
        if (!om_method_setting(m, name)) {
            if (note) fprintf(stderr, "ombra %s: %s takes no setting '%s' (ignored)\n", note, om_method_name(m), name);
            continue;
        }
        if (!cli_set(c, s->item[i])) return false;
    }
    return true;
}

/* The pool every frame of this command runs on (NULL: inline). */
static om_jobs *pool;

bool cli_threads_start(const char *cmd, const char *arg)
{
    return cli_threads_start_in(cmd, arg, 0, NULL);
}

bool cli_threads_start_in(const char *cmd, const char *arg, size_t budget, size_t *workers)
{
    uint32_t n = om_cpus_online();
    if (arg && !cli_parse_u32(arg, 1, 1024, &n)) {
        cli_usage_error(cmd, "--threads takes a thread count 1..1024, not '%s'", arg);
        return false;
    }
    /* Under a budget the workers are counted in it, and take at most a sixteenth. */
    const size_t most = budget ? 1 + budget / 16 / OM_JOBS_WORKER_BYTES : 1024;
    if (n > most) n = (uint32_t)most;
    if (workers) *workers = budget ? (size_t)(n - 1) * OM_JOBS_WORKER_BYTES : 0;
    cli_threads_stop();
    om_diag d;
    om_status st = om_jobs_start(&pool, n, &d);
    if (st != OM_OK) {
        cli_error(cmd, &d, st);
        return false;
    }
    return true;
}

void cli_threads_stop(void)
{
    om_jobs_stop(pool);
    pool = NULL;
}

uint32_t cli_threads(void)
{
    return om_jobs_threads(pool);
}

void cli_frame_jobs(om_frame_desc *fd)
{
    fd->parallel_for = pool ? om_jobs_for : NULL;
    fd->parallel_user = pool;
    fd->threads = om_jobs_threads(pool);
    fd->worker = pool ? om_jobs_worker : NULL;
}

om_frame_need cli_frame_need(const om_method *m, const void *state, const om_scene *s, const om_view *v,
                             uint32_t rows, bool jobs)
{
    om_frame_desc fd;
    om_frame_need need;
    memset(&fd, 0, sizeof fd);
    memset(&need, 0, sizeof need);
    fd.scene = s;
    fd.view = v;
    fd.method = m;
    fd.method_state = (void *)(uintptr_t)state;   /* the query only reads it */
    fd.strip_rows = rows;
    if (jobs) cli_frame_jobs(&fd);
    om_frame_bytes(&fd, &need);
    return need;
}

size_t cli_frame_rows(const om_scene *s, uint32_t width, uint32_t rows, bool bins)
{
    om_view v;
    memset(&v, 0, sizeof v);
    v.cam.width = width;
    v.cam.height = rows;
    v.light.kind = OM_LIGHT_SPOT;
    const om_frame_need need = cli_frame_need(NULL, NULL, s, &v, rows, false);
    return bins ? need.with_bins : need.least;
}
