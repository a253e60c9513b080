/* stability.c — `make stability`: every method along the camera and light paths of the
 * cases in tests/stability/ (each where some method is known to fail: close-ups of a
 * far light's shadows, grazing light, a memory cap far below the view's needs with a
 * fast camera, the irregular z-buffer's hot spot with a small pool, curved edges
 * without tessellation, shadow fusion and thin geometry, the splits of cascaded maps
 * along a walk through the town) and where objects move (one passing under a lattice,
 * a spinning fan, a door opening into light: the states kept across frames must
 * follow them). Per method and case: mean and
 * worst mismatch share against the reference, the same near shadow edges, flicker, the
 * median frame time and the arena's peak bytes, to stdout and a CSV the report shows
 * (with each frame's mismatch share and the frame that flickers most, for its strips).
 * It asserts what must hold: exact methods have zero mismatches on every frame, every
 * frame renders, no method uses more than its arena, and a second run is bit-identical.
 * A case's "# ombra-set NAME=VALUE ..." comment lines set method settings. */
#include "../bench/bench.h"

#include <string.h>

#define W 160
#define H 120

static int failures;

typedef struct grab_ctx { uint8_t *mask; } grab_ctx;

static om_status grab(void *user, const om_strip *st, const om_framebuffer *fb)
{
    (void)fb;
    uint8_t *mask = ((grab_ctx *)user)->mask;
    for (uint32_t i = 0; i < st->rows * st->width; i++)
        mask[st->y0 * st->width + i] = om_mask_of(&st->samples[i], &st->terms[i]);
    return OM_OK;
}

static char *read_file(const char *path)
{
    char *data;
    size_t len;
    om_diag d;
    if (om_file_read(path, &data, &len, &d) != OM_OK) {
        fprintf(stderr, "stability: %s\n", d.msg);
        return NULL;
    }
    return data;
}

/* "# ombra-set a=1 b=2" lines -> the settings of them that m takes */
static void settings(const char *text, const om_method *m, om_method_cfg *c)
{
    om_method_cfg_default(c, m);
    for (const char *p = strstr(text, "# ombra-set "); p; p = strstr(p + 1, "# ombra-set ")) {
        const char *q = p + 12;
        while (*q && *q != '\n') {
            char name[64];
            double v;
            int used = 0;
            if (sscanf(q, " %63[^= \n]=%lf%n", name, &v, &used) == 2) {
                om_diag d;
                if (om_method_setting(m, name) && om_method_cfg_set(c, name, v, &d) != OM_OK)
                    fprintf(stderr, "stability: %s: %s\n", name, d.msg);
                q += used;
            } else {
                break;
            }
        }
    }
}

/* The last key's time, of the camera, the light or any object */
static float end_time(const om_scene *s)
{
    float t = 0;
    if (s->ncam_keys) t = s->cam_keys[s->ncam_keys - 1].t;
    if (s->nlight_keys && s->light_keys[s->nlight_keys - 1].t > t) t = s->light_keys[s->nlight_keys - 1].t;
    for (uint32_t k = 0; k < s->nobj_keys; k++)
        if (s->obj_keys[k].t > t) t = s->obj_keys[k].t;
    return t;
}

/* Renders `frames` frames of method m with one state (progressive methods refine),
 * the objects posed at each frame's time (at time 0 before the state is made, so
 * every run starts from the same scene); masks out; returns 0 when every frame
 * rendered within the arena. */
static int path(om_scene *s, const om_method *m, const om_method_cfg *cfg, int frames,
                uint8_t *masks, double *ms, size_t *peak)
{
    size_t mn, full;
    om_diag d;
    if (om_method_bytes(m, cfg, s, W, H, &mn, &full) != OM_OK) return 1;
    void *mem = malloc(full + 64), *fmem = malloc(bench_frame_bytes(NULL, NULL, W, H, 1));
    static uint8_t px[W * H * 2];
    memset(mem, 0x3C, full + 64);
    om_arena ma, fa;
    om_arena_init(&ma, mem, full, "method");
    om_arena_init(&fa, fmem, bench_frame_bytes(NULL, NULL, W, H, 1), "frame");
    void *state;
    int bad = om_scene_pose_at(s, 0, &d) != OM_OK || om_method_init(m, &state, &ma, cfg, s, W, H, &d) != OM_OK;
    float tend = end_time(s);
    for (int f = 0; f < frames && !bad; f++) {
        om_camera cam;
        om_light light;
        om_view v;
        float t = frames > 1 ? tend * (float)f / (float)(frames - 1) : 0;
        if (om_scene_pose_at(s, t, &d) != OM_OK) { bad = 1; break; }
        om_scene_at(s, t, &cam, &light);
        cam.width = W;
        cam.height = H;
        if (om_view_init(&v, &cam, &light, s, &d) != OM_OK) { bad = 1; break; }
        om_shade_cfg shade;
        om_shade_cfg_default(&shade);
        om_framebuffer fb = {OM_RGB565, W, H, W * 2, px};
        grab_ctx g = {masks + (size_t)f * W * H};
        om_frame_desc fd;
        memset(&fd, 0, sizeof fd);
        fd.scene = s; fd.view = &v; fd.method = m; fd.method_state = state; fd.shade = &shade;
        fd.strip_rows = 0; fd.fb = &fb; fd.on_strip = grab; fd.user = &g; fd.clock = om_clock_ns;
        om_frame_stats fs;
        if (om_render_frame(&fd, &fa, &fs, &d) != OM_OK) {
            fprintf(stderr, "stability: %s frame %d: %s\n", om_method_name(m), f, d.msg);
            bad = 1;
        }
        ms[f] = (double)(fs.ns_eye + fs.ns_observe + fs.ns_build + fs.ns_resolve + fs.ns_shade) / 1e6;
    }
    const unsigned char *guard = (const unsigned char *)mem + full;
    for (int i = 0; i < 64; i++) bad |= guard[i] != 0x3C;
    *peak = ma.peak;
    free(mem);
    free(fmem);
    return bad;
}

int main(int argc, char **argv)
{
    int frames = 30;
    const char *csv = NULL;
    int first = 1;
    for (; first < argc && argv[first][0] == '-'; first++) {
        if (!strcmp(argv[first], "--frames") && first + 1 < argc) frames = atoi(argv[++first]);
        else if (!strcmp(argv[first], "--csv") && first + 1 < argc) csv = argv[++first];
    }
    if (frames < 2 || frames > 240) frames = 30;
    FILE *out = csv ? fopen(csv, "w") : NULL;
    if (out) fprintf(out, "case,method,frames,mean_mismatch,worst_mismatch,mean_edge_mismatch,flicker,median_ms,bytes,"
                          "flicker_frame,frame_mismatch\n");
    printf("%-12s %-5s %8s %8s %8s %8s %8s %10s\n", "case", "meth", "mean", "worst", "edge",
           "flicker", "ms", "bytes");
    for (int a = first; a < argc; a++) {
        char *text = read_file(argv[a]);
        if (!text) { failures++; continue; }
        const char *base = strrchr(argv[a], '/') ? strrchr(argv[a], '/') + 1 : argv[a];
        char name[64];
        snprintf(name, sizeof name, "%.*s", (int)strcspn(base, "."), base);
        bscene b;
        if (bench_load(&b, name, text)) { failures++; free(text); continue; }
        om_method_cfg cfg;
        settings(text, om_method_find("ref"), &cfg);
        size_t n = (size_t)W * H;
        uint8_t *ref = malloc(n * (size_t)frames), *mk = malloc(n * (size_t)frames),
                *again = malloc(n * (size_t)frames);
        double ms[240];
        size_t peak;
        if (path(&b.s, om_method_find("ref"), &cfg, frames, ref, ms, &peak)) {
            printf("stability: FAIL %s: the reference does not render\n", name);
            failures++;
        }
        for (size_t k = 0; k < om_method_count(); k++) {
            const om_method *m = om_method_at(k);
            settings(text, m, &cfg);
            if (path(&b.s, m, &cfg, frames, mk, ms, &peak)) {
                printf("stability: FAIL %s / %s: a frame did not render, or the arena was overrun\n", name, om_method_name(m));
                failures++;
                continue;
            }
            double sum = 0, worst = 0, edge = 0, share[240];
            om_flicker fl = {0, 0, 0};
            uint64_t most = 0;
            int flicker_frame = 0;   /* the frame whose changes from the one before flicker most */
            int wrong_frames = 0;
            for (int f = 0; f < frames; f++) {
                om_metrics mt;
                om_compare_masks(ref + (size_t)f * n, mk + (size_t)f * n, W, H, &mt);
                double sh = 1.0 - om_metrics_match(&mt);
                share[f] = sh;
                sum += sh;
                if (sh > worst) worst = sh;
                edge += mt.edge_samples ? (double)(mt.edge_false_lit + mt.edge_false_shadowed) / (double)mt.edge_samples : 0;
                wrong_frames += mt.false_lit + mt.false_shadowed > 0;
                uint64_t before = fl.flicker;
                if (f > 0) om_flicker_add(&fl, ref + (size_t)(f - 1) * n, mk + (size_t)(f - 1) * n, ref + (size_t)f * n, mk + (size_t)f * n, n);
                if (fl.flicker - before > most) { most = fl.flicker - before; flicker_frame = f; }
            }
            if ((om_method_flags(m) & OM_METHOD_EXACT) && wrong_frames) {
                printf("stability: FAIL %s / %s: an exact method is wrong on %d frames\n", name, om_method_name(m), wrong_frames);
                failures++;
            }
            size_t peak2;
            double ms2[240];
            if (path(&b.s, m, &cfg, frames, again, ms2, &peak2) || memcmp(again, mk, n * (size_t)frames)) {
                printf("stability: FAIL %s / %s: a second run is not bit-identical\n", name, om_method_name(m));
                failures++;
            }
            double med = bench_median(ms, frames);
            printf("%-12s %-5s %7.3f%% %7.3f%% %7.3f%% %7.3f%% %8.2f %10zu\n", name, om_method_name(m),
                   100 * sum / frames, 100 * worst, 100 * edge / frames, 100 * om_flicker_share(&fl), med, peak);
            if (out) {
                fprintf(out, "%s,%s,%d,%.6f,%.6f,%.6f,%.6f,%.3f,%zu,%d,", name, om_method_name(m), frames, sum / frames,
                        worst, edge / frames, om_flicker_share(&fl), med, peak, flicker_frame);
                for (int f = 0; f < frames; f++) fprintf(out, "%s%.6f", f ? ";" : "", share[f]);
                fputc('\n', out);
            }
        }
        free(ref);
        free(mk);
        free(again);
        bench_free(&b);
        free(text);
    }
    if (out) fclose(out);
    printf("stability: %s (%d failures)\n", failures ? "FAIL" : "ok", failures);
    return failures != 0;
}
