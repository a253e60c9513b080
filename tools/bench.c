/* bench.c — `ombra bench`: sweeps every method over the settings listed for it below
 * (cli_sweep) on a set of scenes, and for each point prints and writes to
 * CSV the median frame time per stage, the method's peak arena bytes and its accuracy
 * against the reference on the same visible samples; then draws the charts: mismatch
 * share against time per frame and against bytes (each method a series, its Pareto
 * front dashed), against the first frame's time (the method's init, where ref builds
 * its BVH, plus a frame) and, for the exact methods, the first frame's time against
 * triangle count. A method joins every table and chart by its registry entry alone (at
 * its defaults until it has a line in `sweeps`). Then the scaling table: each method
 * at its defaults on each scene, its frames on 1, 2 and the machine's cores.
 * Names are checked before any work; a run that fails writes nothing, and the files
 * of one that succeeds replace the old ones together (om_out). */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "svg.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char bench_help[] =
    "usage: ombra bench [options]\n"
    "\n"
    "Sweeps every method's settings (see 'ombra methods') on a set of scenes and writes\n"
    "a CSV table and SVG charts of accuracy against speed and memory.\n"
    "\n"
    "  --scenes LIST     comma-separated: default, town, random-1K, random-10K,\n"
    "                    random-100K, random-1M, or scene files (default:\n"
    "                    default,random-10K,town@512x384); NAME@WxH measures that scene\n"
    "                    at its own size\n"
    "  --methods LIST    comma-separated method names (default: every swept method)\n"
    "  --size WxH        image size (default: each scene's own camera size)\n"
    "  --runs N          frames per point; times are their median (default 3)\n"
    "  --threads N       threads each frame runs on (default: the CPUs online); the\n"
    "                    CSV's threads column says how many jobs ran at once\n"
    "  --no-scaling      leave out the scaling table (each method at its defaults on\n"
    "                    1, 2 and the machine's cores: median frame, speed-up on 1,\n"
    "                    beside the machine's own on work of pure compute and memory)\n"
    "  --tri-sweep       also time the exact methods on 1K..1M random triangles\n"
    "  --out DIR         where bench.csv and the charts go (default out/bench)\n";


static const char *random_scene(const char *name, char *buf, size_t n)
{
    unsigned count = 0;
    if (!strcmp(name, "random-1K")) count = 1000;
    else if (!strcmp(name, "random-10K")) count = 10000;
    else if (!strcmp(name, "random-100K")) count = 100000;
    else if (!strcmp(name, "random-1M")) count = 1000000;
    if (!count) return NULL;
    /* Table 1 of the Alias-Free Shadow Maps paper: constant total area. */
    snprintf(buf, n,
             "camera eye 0 6 14 target 0 1 0 fov 50 near 0.1 far 100\n"
             "light spot pos 8 20 6 target 0 0 0 fov 60 near 5 far 60\n"
             "plane size 14 14 albedo 0.7 0.7 0.7\n"
             "triangles count %u seed 7 area 20 in -5 0.5 -5 5 3 5\n", count);
    return buf;
}

bool cli_scene_size(char *entry, uint32_t *w, uint32_t *h)
{
    char *at = strrchr(entry, '@');
    *w = *h = 0;
    if (!at) return true;
    if (!cli_parse_size(at + 1, w, h)) return false;
    *at = 0;
    return true;
}

bool cli_builtin_scene(const char *name)
{
    char text[512];
    return !strcmp(name, "default") || !strcmp(name, "town") ||
           random_scene(name, text, sizeof text) != NULL;
}

/* A built-in scene's text (no meshes) into cs's arena, sized by its bytes query. */
static om_status load_text(const char *text, size_t len, cli_scene *cs, om_diag *d)
{
    om_status st = om_scene_bytes(text, len, NULL, &cs->bytes, d);
    if (st) return st;
    cs->mem = malloc(cs->bytes ? cs->bytes : 1);
    if (!cs->mem) return cli_oom(d);
    om_arena_init(&cs->arena, cs->mem, cs->bytes, "scene");
    return om_scene_parse(text, len, NULL, &cs->arena, &cs->scene, d);
}

om_status cli_load_named(const char *name, cli_scene *cs, om_diag *d)
{
    char text[512];
    if (!strcmp(name, "default")) return cli_scene_load(cs, NULL, 0, d);
    if (!strcmp(name, "town")) {
        memset(cs, 0, sizeof *cs);
        const size_t len = om_scene_town_text(NULL, 0);
        char *town = malloc(len + 1);
        if (!town) return cli_oom(d);
        om_scene_town_text(town, len + 1);
        om_status st = load_text(town, len, cs, d);
        free(town);
        return st;
    }
    const char *r = random_scene(name, text, sizeof text);
    if (!r) return cli_scene_load(cs, name, 0, d);
    memset(cs, 0, sizeof *cs);
    return load_text(r, strlen(r), cs, d);
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_d);
    return v[n / 2];
}

om_status cli_measure(const om_method *m, const om_method_cfg *cfg, const cli_scene *cs,
                      const om_view *v, int runs, uint8_t *mask, uint8_t *rgb, cli_point *p, om_diag *d)
{
    return cli_measure_strips(m, cfg, cs, v, runs, 0, cli_frame_rows(NULL, v->cam.width, v->cam.height, false), mask,
                              rgb, p, d);
}

/* The mask grab, timed: the frame's wall time leaves the host's callbacks out. */
typedef struct timed_masks { cli_masks out; uint64_t ns; } timed_masks;

static om_status grab_timed(void *user, const om_strip *st, const om_framebuffer *fb)
{
    timed_masks *g = (timed_masks *)user;
    uint64_t t0 = om_clock_ns(NULL);
    om_status s = cli_grab_mask(&g->out, st, fb);
    g->ns += om_clock_ns(NULL) - t0;
    return s;
}

/* Init once, render `runs` frames (progressive methods refine meanwhile); times are
 * medians over the frames, the mask is the last frame's. */
om_status cli_measure_strips(const om_method *m, const om_method_cfg *cfg, const cli_scene *cs,
                             const om_view *v, int runs, uint32_t rows, size_t fbytes, uint8_t *mask,
                             uint8_t *rgb, cli_point *p, om_diag *d)
{
    uint32_t W = v->cam.width, H = v->cam.height;
    size_t mn, full;
    om_status st = om_method_bytes(m, cfg, &cs->scene, W, H, &mn, &full);
    if (st) return st;
    /* threads: each job's scratch, and the bins the bands of a whole frame use */
    if (cli_threads() > 1) {
        const om_frame_need need = cli_frame_need(m, NULL, &cs->scene, v, rows, true);
        fbytes += need.with_jobs - need.with_bins;
        if (!rows || rows >= H) fbytes += need.with_bins - need.least;
    }
    void *mem = malloc(full ? full : 1), *fmem = malloc(fbytes), *px = malloc((size_t)W * H * 3);
    if (!mem || !fmem || !px) {
        free(mem); free(fmem); free(px);
        return cli_oom(d);
    }
    om_arena ma, fa;
    om_arena_init(&ma, mem, full, "method");
    om_arena_init(&fa, fmem, fbytes, "frame");
    void *state;
    double t[5][16], wall[16];
    if (runs > 16) runs = 16;
    /* init is a stage of its own: a user pays it whenever the scene changes */
    uint64_t t0 = om_clock_ns(NULL);
    st = om_method_init(m, &state, &ma, cfg, &cs->scene, W, H, d);
    p->init = (double)(om_clock_ns(NULL) - t0) / 1e6;
    p->w = W;
    p->h = H;
    for (int r = 0; r < runs && st == OM_OK; r++) {
        om_shade_cfg shade;
        om_shade_cfg_default(&shade);
        om_framebuffer fb = {OM_RGB888, W, H, (size_t)W * 3, (uint8_t *)px};
        timed_masks mo = {{mask, rgb}, 0};
        om_frame_desc fd;
        memset(&fd, 0, sizeof fd);
        fd.scene = &cs->scene; fd.view = v; fd.method = m; fd.method_state = state;
        fd.shade = &shade; fd.fb = &fb; fd.on_strip = grab_timed; fd.user = &mo; fd.clock = om_clock_ns;
        fd.strip_rows = rows;
        cli_frame_jobs(&fd);
        om_frame_stats fs;
        const uint64_t w0 = om_clock_ns(NULL);
        st = om_render_frame(&fd, &fa, &fs, d);
        wall[r] = (double)(om_clock_ns(NULL) - w0 - mo.ns) / 1e6;
        p->threads = fs.jobs;
        t[0][r] = (double)fs.ns_eye / 1e6;
        t[1][r] = (double)fs.ns_observe / 1e6;
        t[2][r] = (double)fs.ns_build / 1e6;
        t[3][r] = (double)fs.ns_resolve / 1e6;
        t[4][r] = (double)fs.ns_shade / 1e6;
    }
    if (st == OM_OK) {
        double tot[16];
        for (int r = 0; r < runs; r++) tot[r] = t[0][r] + t[1][r] + t[2][r] + t[3][r] + t[4][r];
        p->total = median(tot, runs);   /* sorts tot */
        p->tmin = tot[0];
        p->tmax = tot[runs - 1];
        p->wall = median(wall, runs);
        p->eye = median(t[0], runs);
        p->observe = median(t[1], runs);
        p->build = median(t[2], runs);
        p->resolve = median(t[3], runs);
        p->shade = median(t[4], runs);
        p->bytes = ma.peak;
        om_method_stats ms;
        om_method_get_stats(m, state, &ms);
        size_t n = 0;
        p->stats[0] = '\0';
        for (uint32_t k = 0; k < ms.ncounters && n + 1 < sizeof p->stats; k++) {
            int w = snprintf(p->stats + n, sizeof p->stats - n, "%s%s=%u", k ? "; " : "", ms.counter_names[k],
                             ms.counters[k]);
            if (w < 0 || (size_t)w >= sizeof p->stats - n) { p->stats[n] = '\0'; break; }
            n += (size_t)w;
        }
        if (!p->stats[0]) strcpy(p->stats, "-");
    }
    free(mem);
    free(fmem);
    free(px);
    return st;
}

/* What each method sweeps, by name (see cli_sweep). */
static const struct { const char *method, *sweep; } sweeps[] = {
    {"none", ""},
    {"sm", "map=256,512,1024,2048,4096,8192"},
    {"csm", "csm.map=256,512,1024,2048 csm.fit=0,1"},
    {"izb", "izb.pool=0,65536,16384"},
    {"asm", "asm.cap=1048576,4194304,8388608,16777216"},
    {"rtw", "map=512,1024,2048 rtw.exact=1,0"},
    {"spsm", "map=512,1024,2048,4096"},
    {"hybrid", "hybrid.map=128,256,512"},
};

const char *cli_sweep(const om_method *m)
{
    for (size_t i = 0; m && i < sizeof sweeps / sizeof sweeps[0]; i++)
        if (!strcmp(sweeps[i].method, om_method_name(m))) return sweeps[i].sweep;
    return NULL;
}

/* The points of a sweep string: the product of its NAME=V1,V2 lists. */
static int expand(const char *sweep, char out[][96], int max)
{
    char names[4][32], vals[4][8][24];
    int nv[4] = {0}, nk = 0;
    const char *s = sweep ? sweep : "";
    while (*s && nk < 4) {
        while (*s == ' ') s++;
        const char *eq = strchr(s, '=');
        if (!eq) break;
        size_t l = (size_t)(eq - s) < 31 ? (size_t)(eq - s) : 31;
        memcpy(names[nk], s, l);
        names[nk][l] = 0;
        s = eq + 1;
        while (*s && *s != ' ' && nv[nk] < 8) {
            size_t j = 0;
            while (*s && *s != ',' && *s != ' ' && j < 23) vals[nk][nv[nk]][j++] = *s++;
            vals[nk][nv[nk]++][j] = 0;
            if (*s == ',') s++;
        }
        nk++;
    }
    int n = 1;
    for (int k = 0; k < nk; k++) n *= nv[k];
    if (n > max) n = max;
    for (int i = 0; i < n; i++) {
        out[i][0] = 0;
        int rem = i;
        for (int k = nk - 1; k >= 0; k--) {
            char part[64];
            snprintf(part, sizeof part, "%s=%s", names[k], vals[k][rem % nv[k]]);
            rem /= nv[k];
            char tmp[96];
            snprintf(tmp, sizeof tmp, "%s%s%s", part, out[i][0] ? " " : "", out[i]);
            memcpy(out[i], tmp, sizeof tmp);
        }
    }
    return n;
}

static bool apply(om_method_cfg *c, const char *setting)
{
    char buf[96];
    const char *p = setting;
    while (*p) {   /* space-separated NAME=VALUE (no strtok: the caller is inside one) */
        size_t n = strcspn(p, " ");
        if (n && n < sizeof buf) {
            memcpy(buf, p, n);
            buf[n] = 0;
            if (!cli_set(c, buf)) return false;
        }
        p += n;
        while (*p == ' ') p++;
    }
    return true;
}

static bool in_list(const char *list, const char *name)
{
    if (!list) return true;
    size_t n = strlen(name);
    for (const char *p = list; (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ',') && (p[n] == 0 || p[n] == ',')) return true;
    return false;
}

static void progress(int i, int n, const cli_point *p)
{
    if (isatty(2)) fprintf(stderr, "\r\033[K[%d/%d] %s %s %s", i, n, p->scene, p->method, p->setting);
    else fprintf(stderr, "[%d/%d] %s %s %s\n", i, n, p->scene, p->method, p->setting);
}

/* A point's label on a chart: its setting, short ("asm.cap=1048576" -> "cap 1M",
 * "map=512 rtw.exact=1" -> "map 512, exact 1"), the full one staying in the tooltip. */
void cli_short_setting(const char *setting, char *out, size_t n)
{
    size_t o = 0;
    out[0] = 0;
    if (!strcmp(setting, "defaults")) { snprintf(out, n, "defaults"); return; }
    for (const char *p = setting; *p && o + 1 < n;) {
        size_t len = strcspn(p, " ");
        char item[96], *eq;
        snprintf(item, sizeof item, "%.*s", (int)(len < 95 ? len : 95), p);
        p += len;
        while (*p == ' ') p++;
        if (!(eq = strchr(item, '='))) continue;
        *eq = 0;
        const char *name = strrchr(item, '.') ? strrchr(item, '.') + 1 : item;
        char *end;
        unsigned long long v = strtoull(eq + 1, &end, 10);
        char val[32];
        if (!*end && v >= 16384 && v % 1048576 == 0) snprintf(val, sizeof val, "%lluM", v / 1048576);
        else if (!*end && v >= 16384 && v % 1024 == 0) snprintf(val, sizeof val, "%lluK", v / 1024);
        else snprintf(val, sizeof val, "%s", eq + 1);
        int w = snprintf(out + o, n - o, "%s%s %s", o ? ", " : "", name, val);
        if (w < 0 || (size_t)w >= n - o) break;
        o += (size_t)w;
    }
}

/* One chart of a scene's points, mismatch share against x: 0 time per frame, 1 method
 * bytes, 2 the first frame (init + frame); each method a series, each point labelled
 * and, on the time charts, with the spread of its frames. */
static bool chart(om_out *o, const svg_chart *c, const cli_point *pts, int n, const char *scene,
                  int xkind)
{
    svg_series s[16];
    static double xs[16][64], ys[16][64], lo[16][64], hi[16][64];
    static char text[16][64][48];
    static const char *labels[16][64];
    size_t ns = 0;
    for (size_t k = 0; k < om_method_count() && ns < 16; k++) {
        const om_method *m = om_method_at(k);
        size_t np = 0;
        for (int i = 0; i < n && np < 64; i++) {
            const cli_point *p = &pts[i];
            if (!p->ok || strcmp(p->method, om_method_name(m)) || strcmp(p->scene, scene)) continue;
            double first = xkind == 2 ? p->init : 0;
            xs[ns][np] = xkind == 1 ? (double)p->bytes : first + p->total;
            lo[ns][np] = first + p->tmin;
            hi[ns][np] = first + p->tmax;
            ys[ns][np] = 1.0 - om_metrics_match(&p->m);
            cli_short_setting(p->setting, text[ns][np], sizeof text[ns][np]);
            labels[ns][np] = text[ns][np];
            np++;
        }
        if (!np) continue;
        s[ns].name = om_method_name(m);
        s[ns].x = xs[ns];
        s[ns].y = ys[ns];
        s[ns].n = np;
        s[ns].labels = labels[ns];
        s[ns].xlo = xkind == 1 ? NULL : lo[ns];
        s[ns].xhi = xkind == 1 ? NULL : hi[ns];
        ns++;
    }
    return svg_write(o->f, c, s, ns);
}

/* Splits a comma-separated list in place; returns the count (empty items kept). */
static size_t split(char *list, char **items, size_t max)
{
    size_t n = 0;
    for (char *p = list; n < max;) {
        items[n++] = p;
        char *c = strchr(p, ',');
        if (!c) break;
        *c = '\0';
        p = c + 1;
    }
    return n;
}

/* Every name on the command line means something before any work starts: a scene is
 * built in or a file that is there, a method is in the registry and swept. */
static int check_names(const char *cmd, char **names, size_t n, const char *methods)
{
    struct stat sb;
    for (size_t i = 0; i < n; i++) {
        if (!names[i][0]) return cli_usage_error(cmd, "--scenes has an empty name%s", "");
        if (!cli_builtin_scene(names[i]) && (stat(names[i], &sb) != 0 || S_ISDIR(sb.st_mode)))
            return cli_usage_error(cmd, "unknown scene '%s': not default, town, random-1K, "
                                   "random-10K, random-100K, random-1M or a scene file", names[i]);
        for (size_t j = 0; j < i; j++)
            if (!strcmp(cli_base_name(names[i]), cli_base_name(names[j])))
                return cli_usage_error(cmd, "two scenes named '%s' would write the same charts",
                                       cli_base_name(names[i]));
    }
    for (const char *p = methods; p && *p;) {
        char name[32];
        size_t l = strcspn(p, ",");
        snprintf(name, sizeof name, "%.*s", (int)(l < 31 ? l : 31), p);
        const om_method *m = om_method_find(name);
        if (!m) return cli_unknown_method(cmd, "--methods", name);
        if (cli_sweep(m) && !cli_sweep(m)[0])
            return cli_usage_error(cmd, "'%s' is left out of sweeps (nothing to compare)", name);
        p += l + (p[l] == ',');
    }
    return 0;
}

/* The share of the samples near a reference shadow edge that are wrong (0 for none). */
static double edge_share(const om_metrics *m)
{
    return m->edge_samples ? (double)(m->edge_false_lit + m->edge_false_shadowed) / (double)m->edge_samples : 0.0;
}

/* The CSV and the charts, all replaced together once every one is written whole. */
static int write_outputs(const char *dir, char **names, size_t nn, const cli_point *pts, int np,
                         const double *tri_x, const double (*tri_y)[4], const size_t *tri_n,
                         const char *const *tri_names, size_t ntri, bool tri_sweep)
{
    size_t nout = 1 + 3 * nn + (tri_sweep ? 1 : 0), k = 0;
    om_out *outs = calloc(nout, sizeof *outs);
    om_out **list = calloc(nout, sizeof *list);
    char **paths = calloc(nout, sizeof *paths);
    om_diag d;
    memset(&d, 0, sizeof d);
    om_status st = outs && list && paths ? OM_OK : cli_oom(&d);
    for (size_t i = 0; i < nout; i++) if (list) list[i] = outs ? &outs[i] : NULL;
    /* the table */
    if (st == OM_OK && !(paths[k] = cli_path(dir, "bench.csv"))) st = cli_oom(&d);
    if (st == OM_OK && (st = om_out_open(&outs[k], paths[k], &d)) == OM_OK) {
        FILE *f = outs[k].f;
        fprintf(f, "scene,method,setting,width,height,time_ms,init_ms,eye_ms,observe_ms,build_ms,"
                   "resolve_ms,shade_ms,bytes,samples,false_lit,false_shadowed,mismatch_share,"
                   "edge_samples,edge_mismatch_share,time_min_ms,time_max_ms,frame_wall_ms,threads,stats\n");
        for (int i = 0; i < np; i++) {
            const cli_point *p = &pts[i];
            double share = 1.0 - om_metrics_match(&p->m), edge = edge_share(&p->m);
            fprintf(f, "%s,%s,%s,%u,%u,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%zu,%llu,%llu,%llu,%.6f,%llu,%.6f,%.3f,%.3f,%.3f,%u,%s\n",
                    p->scene, p->method, p->setting, p->w, p->h, p->total, p->init, p->eye,
                    p->observe, p->build, p->resolve, p->shade, p->bytes,
                    (unsigned long long)p->m.samples, (unsigned long long)p->m.false_lit,
                    (unsigned long long)p->m.false_shadowed, share,
                    (unsigned long long)p->m.edge_samples, edge, p->tmin, p->tmax, p->wall, p->threads,
                    p->stats);
        }
        k++;
    }
    /* the charts, three per scene */
    static const char *const suffix[3] = {"time", "bytes", "first"};
    static const char *const xlabel[3] = {"time per frame (median; bar: fastest to slowest frame)",
                                          "method memory: the arena's peak bytes",
                                          "first frame: the method's init + one frame"};
    static const svg_unit xunit[3] = {SVG_MS, SVG_BYTES, SVG_MS};
    static const char *const what[3] = {"accuracy against speed", "accuracy against memory",
                                        "accuracy against the first frame's time"};
    for (size_t i = 0; i < nn && st == OM_OK; i++) {
        uint32_t W = 0, H = 0;
        for (int j = 0; j < np; j++)
            if (!strcmp(pts[j].scene, names[i])) { W = pts[j].w; H = pts[j].h; break; }
        for (int c = 0; c < 3 && st == OM_OK; c++) {
            char file[300], title[300];
            snprintf(file, sizeof file, "%s-%s.svg", cli_base_name(names[i]), suffix[c]);
            snprintf(title, sizeof title, "%s at %ux%u: %s", cli_base_name(names[i]), W, H, what[c]);
            svg_chart ch = {title, xlabel[c], "samples wrong against ref", true, true, true, false,
                            xunit[c], SVG_SHARE};
            if (!(paths[k] = cli_path(dir, file))) st = cli_oom(&d);
            else if ((st = om_out_open(&outs[k], paths[k], &d)) == OM_OK) chart(&outs[k++], &ch, pts, np, names[i], c);
        }
    }
    /* time against triangle count, exact methods, random scenes 1K..1M */
    if (tri_sweep && st == OM_OK) {
        svg_series s[16];
        for (size_t i = 0; i < ntri; i++) {
            s[i].name = tri_names[i];
            s[i].x = tri_x;
            s[i].y = tri_y[i];
            s[i].n = tri_n[i];
            s[i].labels = NULL;
            s[i].xlo = s[i].xhi = NULL;
        }
        svg_chart c = {"exact methods on the random scenes: time against triangles", "triangles",
                       "first frame: init + frame", true, true, false, true, SVG_PLAIN, SVG_MS};
        if (!(paths[k] = cli_path(dir, "triangles.svg"))) st = cli_oom(&d);
        else if ((st = om_out_open(&outs[k], paths[k], &d)) == OM_OK) svg_write(outs[k++].f, &c, s, ntri);
    }
    if (st == OM_OK) st = om_out_commit(list, nout, &d);
    for (size_t i = 0; outs && i < nout; i++) om_out_discard(&outs[i]);
    for (size_t i = 0; paths && i < nout; i++) free(paths[i]);
    free(outs);
    free(list);
    free(paths);
    return st == OM_OK ? 0 : cli_error(NULL, &d, st);
}

/* The machine's own scaling, the table's first two rows: the same work in CALIB_JOBS
 * jobs on each thread count, as a frame's is. `compute` needs no memory (a job runs
 * eight independent float chains); `memory` is nothing but memory (a job copies its
 * MiB of one CALIB_JOBS MiB buffer into another: more than most caches). Cores
 * that share a power budget or a memory bus, or a virtual machine among others, gain
 * less than their count even here; a frame, which both computes and streams, mostly
 * gains between the two. */
#define CALIB_JOBS 64
#define CALIB_BYTES ((size_t)1 << 20)

typedef struct calib {
    unsigned char *buf;        /* two of CALIB_JOBS * CALIB_BYTES: from, to */
    float out[CALIB_JOBS];     /* each job's result, so that no compiler drops its work */
} calib;

static void calib_compute(void *user, uint32_t i)
{
    float y[8];
    for (int k = 0; k < 8; k++) y[k] = (float)(i + (uint32_t)k);
    for (int n = 0; n < 100000; n++)
        for (int k = 0; k < 8; k++) y[k] = y[k] * 0.9999f + 0.5f;   /* tends to 5000 */
    ((calib *)user)->out[i] = y[0] + y[1] + y[2] + y[3] + y[4] + y[5] + y[6] + y[7];
}

static void calib_memory(void *user, uint32_t i)
{
    calib *c = (calib *)user;
    unsigned char *to = c->buf + (CALIB_JOBS + (size_t)i) * CALIB_BYTES;
    memcpy(to, c->buf + (size_t)i * CALIB_BYTES, CALIB_BYTES);
    c->out[i] = (float)to[i];
}

/* The median time of `runs` calls of fn's jobs on the current pool, in ms. */
static double calib_ms(om_job_fn fn, calib *c, int runs)
{
    om_frame_desc fd;
    memset(&fd, 0, sizeof fd);
    cli_frame_jobs(&fd);
    double t[16];
    if (runs > 16) runs = 16;
    for (int r = 0; r < runs; r++) {
        const uint64_t t0 = om_clock_ns(NULL);
        if (fd.parallel_for && fd.threads > 1) fd.parallel_for(fd.parallel_user, fn, c, CALIB_JOBS);
        else
            for (uint32_t i = 0; i < CALIB_JOBS; i++) fn(c, i);
        t[r] = (double)(om_clock_ns(NULL) - t0) / 1e6;
    }
    return median(t, runs);
}

/* The scaling table's rounds: each takes the thread counts in turn, so that a machine
 * whose speed drifts while it runs (another load, a power state) moves every count
 * alike. A row's time on a count is the median over the rounds, its speed-up the
 * median of each round's own (that round's one-thread time over its time). */
#define SCALING_ROUNDS 3

typedef struct scale_row {
    double ms[3][SCALING_ROUNDS];
    bool fewer[3];   /* fewer jobs ran than threads asked, in some round */
} scale_row;

/* Prints one row; true when a column of it is starred. */
static bool scale_print(const char *scene, const char *name, scale_row *r, int nc)
{
    bool starred = false;
    printf("%-12s %-6s", scene, name);
    for (int c = 0; c < nc; c++) {
        double ratio[SCALING_ROUNDS], ms[SCALING_ROUNDS];
        for (int k = 0; k < SCALING_ROUNDS; k++) {
            ratio[k] = r->ms[c][k] > 0.0 ? r->ms[0][k] / r->ms[c][k] : 0.0;
            ms[k] = r->ms[c][k];
        }
        printf(" %10.2f", median(ms, SCALING_ROUNDS));
        if (c) printf(" %6.2fx%c", median(ratio, SCALING_ROUNDS), r->fewer[c] ? '*' : ' ');
        starred |= c && r->fewer[c];
    }
    printf("\n");
    return starred;
}

/* Starts the pool of `n` threads; false when it would not start (said). */
static bool pool_of(const char *cmd, uint32_t n)
{
    char arg[16];
    snprintf(arg, sizeof arg, "%u", n);
    return cli_threads_start(cmd, arg);
}

/* The machine's two rows; false when a pool would not start (said). */
static bool calib_rows(const char *cmd, const uint32_t *counts, int nc, int runs)
{
    calib c;
    memset(&c, 0, sizeof c);
    if ((c.buf = malloc(2 * CALIB_JOBS * CALIB_BYTES)))
        memset(c.buf, 1, 2 * CALIB_JOBS * CALIB_BYTES);   /* its pages mapped before any timing */
    for (int row = 0; row < 2; row++) {
        if (row && !c.buf) {
            printf("%-12s %-6s (no room for its %u MiB)\n", "machine", "memory", 2 * CALIB_JOBS);
            break;
        }
        scale_row r;
        memset(&r, 0, sizeof r);
        for (int k = 0; k < SCALING_ROUNDS; k++)
            for (int i = 0; i < nc; i++) {
                if (!pool_of(cmd, counts[i])) {
                    free(c.buf);
                    return false;
                }
                r.ms[i][k] = calib_ms(row ? calib_memory : calib_compute, &c, runs);
            }
        scale_print("machine", row ? "memory" : "compute", &r, nc);
        fflush(stdout);
    }
    free(c.buf);
    return true;
}

/* The scaling table: first the machine's own rows (calib), then each method of the
 * sweep at its defaults on each scene, `runs` frames on each of 1, 2 and the
 * machine's cores threads in each round (a fresh state each): the median frame (init
 * apart) and its speed-up on one thread; then a row "eye" per scene, the eye pass
 * alone (its median within the first method's frames: the bins and the visible
 * samples of every strip). The pool is the user's again afterwards. */
static int scaling(const char *cmd, char **names, size_t nn, const uint32_t *sw, const uint32_t *sh,
                   uint32_t w, uint32_t h, const char *methods, int runs, const char *threads)
{
    uint32_t counts[3] = {1, 2, om_cpus_online()};
    const int nc = counts[2] > 2 ? 3 : 2;
    printf("\nscaling: median frame in ms on 1, 2%s threads, %d rounds of %d frames; speed-up on 1 thread\n",
           nc == 3 ? " and the machine's cores" : " (the machine's cores)", SCALING_ROUNDS, runs);
    printf("%-12s %-6s", "scene", "meth");
    for (int c = 0; c < nc; c++) {
        char head[16];
        snprintf(head, sizeof head, "%u thr", counts[c]);
        printf(c ? " %10s %7s" : " %10s", head, "speedup");
    }
    printf("\n");
    int rc = calib_rows(cmd, counts, nc, runs) ? 0 : 1;
    bool starred = false;   /* the footnote only under a starred row */
    for (size_t si = 0; si < nn && !rc; si++) {
        om_diag d;
        memset(&d, 0, sizeof d);
        cli_scene cs;
        om_view v;
        uint8_t *mask = NULL;
        om_status st = cli_load_named(names[si], &cs, &d);
        if (st == OM_OK && (st = cli_scene_view(&cs, sw[si] ? sw[si] : w, sw[si] ? sh[si] : h, &v, &d)) == OM_OK &&
            !(mask = malloc((size_t)v.cam.width * v.cam.height)))
            st = cli_oom(&d);
        scale_row eye;
        memset(&eye, 0, sizeof eye);
        bool have_eye = false;
        for (size_t k = 0; k < om_method_count() && st == OM_OK && !rc; k++) {
            const om_method *m = om_method_at(k);
            if ((cli_sweep(m) && !cli_sweep(m)[0]) || !in_list(methods, om_method_name(m))) continue;
            om_method_cfg cfg;
            om_method_cfg_default(&cfg, m);
            scale_row r;
            memset(&r, 0, sizeof r);
            for (int round = 0; round < SCALING_ROUNDS && st == OM_OK && !rc; round++)
                for (int c = 0; c < nc && st == OM_OK; c++) {
                    if (!pool_of(cmd, counts[c])) { rc = 1; break; }
                    cli_point p;
                    memset(&p, 0, sizeof p);
                    st = cli_measure(m, &cfg, &cs, &v, runs, mask, NULL, &p, &d);
                    r.ms[c][round] = p.total;
                    r.fewer[c] |= p.threads != counts[c];
                    if (!have_eye) {
                        eye.ms[c][round] = p.eye;
                        eye.fewer[c] = r.fewer[c];
                    }
                }
            if (st != OM_OK || rc) break;
            starred |= scale_print(cli_base_name(names[si]), om_method_name(m), &r, nc);
            fflush(stdout);
            have_eye = true;
        }
        if (have_eye && st == OM_OK && !rc) starred |= scale_print(cli_base_name(names[si]), "eye", &eye, nc);
        if (st != OM_OK && !rc) rc = cli_error(names[si], &d, st);
        free(mask);
        cli_scene_free(&cs);
    }
    if (!rc && starred) printf("(* fewer jobs ran than threads asked)\n");
    if (!rc && !cli_threads_start(cmd, threads)) rc = 1;
    return rc;
}

int cmd_bench(int argc, char **argv)
{
    const char *scenes = "default,random-10K,town@512x384", *methods = NULL, *dir = "out/bench";
    uint32_t w = 0, h = 0, runs = 3;
    bool tri_sweep = false, scale = true;
    const char *threads = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { fputs(bench_help, stdout); return 0; }
        if (!strcmp(a, "--tri-sweep")) { tri_sweep = true; continue; }
        if (!strcmp(a, "--no-scaling")) { scale = false; continue; }
        if (!v) return cli_usage_error(argv[0], "unknown option or missing value: '%s'", a);
        if (!strcmp(a, "--scenes")) scenes = v;
        else if (!strcmp(a, "--methods")) methods = v;
        else if (!strcmp(a, "--out")) dir = v;
        else if (!strcmp(a, "--threads")) threads = v;
        else if (!strcmp(a, "--size")) { if (!cli_parse_size(v, &w, &h)) return cli_usage_error(argv[0], "--size takes WxH, not '%s'", v); }
        else if (!strcmp(a, "--runs")) { if (!cli_parse_u32(v, 1, 16, &runs)) return cli_usage_error(argv[0], "--runs takes 1..16, not '%s'", v); }
        else return cli_usage_error(argv[0], "unknown option '%s'", a);
        i++;
    }
    if (!cli_threads_start(argv[0], threads)) return 2;
    size_t cap = 1;
    for (const char *p = scenes; *p; p++) cap += *p == ',';
    char *list = malloc(strlen(scenes) + 1), **names = calloc(cap, sizeof *names);
    enum { MAXP = 512 };
    cli_point *pts = calloc(MAXP, sizeof *pts);
    if (!list || !names || !pts) {
        free(list); free(names); free(pts);
        om_diag d;
        return cli_error(NULL, &d, cli_oom(&d));
    }
    memcpy(list, scenes, strlen(scenes) + 1);
    size_t nn = split(list, names, cap);
    uint32_t *sw = calloc(nn, sizeof *sw), *sh = calloc(nn, sizeof *sh);
    int rc = sw && sh ? 0 : 1;
    for (size_t i = 0; i < nn && !rc; i++)
        if (!cli_scene_size(names[i], &sw[i], &sh[i]))
            rc = cli_usage_error(argv[0], "a scene's @ takes WxH: '%s'", names[i]);
    if (!rc) rc = check_names(argv[0], names, nn, methods);
    /* the directory first, so that an unwritable one fails before the work */
    char *path = rc ? NULL : malloc(strlen(dir) + 1);
    if (!rc && path) {
        memcpy(path, dir, strlen(dir) + 1);
        for (char *p = path + 1; *p; p++)
            if (*p == '/') { *p = 0; mkdir(path, 0777); *p = '/'; }
        if (mkdir(path, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "ombra: %s: cannot create the output directory: %s\n", dir, strerror(errno));
            rc = 1;
        }
    }
    free(path);
    int np = 0, total = 0, done = 0;
    for (size_t k = 0; k < om_method_count() && !rc; k++) {
        const om_method *m = om_method_at(k);
        char tmp[64][96];
        if (cli_sweep(m) && !cli_sweep(m)[0]) continue;
        if (in_list(methods, om_method_name(m))) total += expand(cli_sweep(m), tmp, 64) * (int)nn;
    }
    /* Any scene that does not load, view or measure fails the run: nothing is written. */
    for (size_t si = 0; si < nn && !rc; si++) {
        const char *name = names[si];
        om_diag d;
        memset(&d, 0, sizeof d);
        cli_scene cs;
        om_view v;
        uint32_t W = 0, H = 0;
        uint8_t *ref = NULL, *mask = NULL;
        om_status st = cli_load_named(name, &cs, &d);
        if (st == OM_OK && (st = cli_scene_view(&cs, sw[si] ? sw[si] : w, sw[si] ? sh[si] : h, &v, &d)) == OM_OK) {
            W = v.cam.width;
            H = v.cam.height;
            ref = malloc((size_t)W * H);
            mask = malloc((size_t)W * H);
            if (!ref || !mask) st = cli_oom(&d);
        }
        cli_point rp;
        memset(&rp, 0, sizeof rp);
        om_method_cfg rc_cfg;
        om_method_cfg_default(&rc_cfg, om_method_find("ref"));
        if (st == OM_OK) st = cli_measure(om_method_find("ref"), &rc_cfg, &cs, &v, 1, ref, NULL, &rp, &d);
        if (st != OM_OK) rc = cli_error(name, &d, st);
        for (size_t k = 0; k < om_method_count() && np < MAXP && !rc; k++) {
            const om_method *m = om_method_at(k);
            if ((cli_sweep(m) && !cli_sweep(m)[0]) || !in_list(methods, om_method_name(m))) continue;
            char settings[64][96];
            int ns = expand(cli_sweep(m), settings, 64);
            if (ns == 0) { settings[0][0] = 0; ns = 1; }
            for (int j = 0; j < ns && np < MAXP; j++) {
                cli_point *p = &pts[np];
                p->scene = name;
                snprintf(p->method, sizeof p->method, "%s", om_method_name(m));
                const char *label = settings[j][0] ? settings[j] : "defaults";
                size_t ll = strlen(label) < sizeof p->setting ? strlen(label) : sizeof p->setting - 1;
                memcpy(p->setting, label, ll);
                p->setting[ll] = '\0';
                progress(++done, total, p);
                om_method_cfg cfg;
                om_method_cfg_default(&cfg, m);
                if (settings[j][0] && !apply(&cfg, settings[j])) continue;
                st = cli_measure(m, &cfg, &cs, &v, (int)runs, mask, NULL, p, &d);
                if (st) {
                    /* a point a method cannot run (its memory, say) is left out, said */
                    fprintf(stderr, "\nombra: %s %s on %s: %s\n", om_method_name(m), p->setting, name, d.msg);
                    continue;
                }
                om_compare_masks(ref, mask, W, H, &p->m);
                p->ok = 1;
                np++;
            }
        }
        free(ref);
        free(mask);
        cli_scene_free(&cs);
    }
    if (isatty(2) && done) fprintf(stderr, "\n");
    /* time against triangle count, exact methods, random scenes 1K..1M, each at its
     * first frame: init (the BVH) is paid whenever the triangles change */
    static const char *const counts[] = {"random-1K", "random-10K", "random-100K", "random-1M"};
    static const double tris[] = {1e3, 1e4, 1e5, 1e6};
    double ty[16][4];
    size_t tn[16] = {0}, ntri = 0;
    const char *tnames[16];
    for (size_t k = 0; tri_sweep && !rc && k < om_method_count() && ntri < 16; k++) {
        const om_method *m = om_method_at(k);
        if (!(om_method_flags(m) & OM_METHOD_EXACT)) continue;
        tnames[ntri] = om_method_name(m);
        for (int j = 0; j < 4 && !rc; j++) {
            om_diag d;
            memset(&d, 0, sizeof d);
            cli_scene cs;
            uint8_t *tmask = NULL;
            om_status st = cli_load_named(counts[j], &cs, &d);
            om_view v;
            if (st == OM_OK && (st = cli_scene_view(&cs, w, h, &v, &d)) == OM_OK) {
                om_method_cfg cfg;
                om_method_cfg_default(&cfg, m);
                cli_point p;
                memset(&p, 0, sizeof p);
                p.scene = counts[j];
                snprintf(p.method, sizeof p.method, "%s", om_method_name(m));
                snprintf(p.setting, sizeof p.setting, "triangle sweep");
                progress(j + 1, 4, &p);
                if (!(tmask = malloc((size_t)v.cam.width * v.cam.height))) st = cli_oom(&d);
                if (st == OM_OK) st = cli_measure(m, &cfg, &cs, &v, (int)runs, tmask, NULL, &p, &d);
                if (st == OM_OK) {
                    ty[ntri][tn[ntri]++] = p.init + p.total;
                    printf("%-12s %-5s triangle sweep: init %.2f ms, frame %.2f ms\n", counts[j],
                           om_method_name(m), p.init, p.total);
                }
            }
            if (st != OM_OK) rc = cli_error(counts[j], &d, st);
            free(tmask);
            cli_scene_free(&cs);
        }
        ntri++;
    }
    if (tri_sweep && isatty(2)) fprintf(stderr, "\n");
    if (!rc) {
        printf("%-12s %-5s %-28s %9s %9s %9s %11s %9s %9s %9s\n", "scene", "meth", "setting", "time ms",
               "init", "resolve", "bytes", "mismatch", "edge", "wall ms");
        for (int i = 0; i < np; i++) {
            const cli_point *p = &pts[i];
            double share = 1.0 - om_metrics_match(&p->m), edge = edge_share(&p->m);
            printf("%-12s %-5s %-28s %9.2f %9.2f %9.2f %11zu %8.4f%% %8.3f%% %9.2f\n", p->scene, p->method,
                   p->setting, p->total, p->init, p->resolve, p->bytes, 100 * share, 100 * edge, p->wall);
        }
        if (scale) rc = scaling(argv[0], names, nn, sw, sh, w, h, methods, (int)runs, threads);
        if (!rc)
            rc = write_outputs(dir, names, nn, pts, np, tris, (const double (*)[4])ty, tn, tnames, ntri,
                               tri_sweep);
    }
    if (!rc) printf("wrote %s/bench.csv and the charts beside it\n", dir);
    free(pts);
    free(names);
    free(sw);
    free(sh);
    free(list);
    return rc;
}
