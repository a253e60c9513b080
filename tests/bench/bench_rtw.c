/* bench_rtw.c — Rectilinear Texture Warping at 1024x768 for the default scene and the
 * 10K and 100K random-triangle scenes: for RTW maps of 512, 1024 and 2048, the exact map
 * (the default) and the paper's warped-vertex map with tessellation off, 5% and 2.5%,
 * the time of each stage (importance, warp, map, lookup; medians of 5 interleaved
 * runs), the method's time and the frame's against the conventional map of the same
 * size (overhead), the mismatch share against the reference, the maximum effective
 * resolution and the triangles drawn; plus the 512 map with hybrid analysis and the
 * shadow-edge function. */
#include "bench.h"
#include "../../engine/shadow/rtw/rtw.h"

#include <string.h>

/* rtw's stages after a frame: the warp tables and the map run again on the frame's
 * importance map, timed alone (each gives the same result again); the importance is
 * the rest of observe and build, the lookup is resolve. */
static void stages(void *state, mrun *out)
{
    om__rtw *m = (om__rtw *)state;
    uint64_t t0 = om_clock_ns(NULL);
    om__rtw_build_tables(m);
    uint64_t t1 = om_clock_ns(NULL);
    om__rtw_render_map(m);
    uint64_t t2 = om_clock_ns(NULL);
    out->stage_ms[1] = (double)(t1 - t0) / 1e6;
    out->stage_ms[2] = (double)(t2 - t1) / 1e6;
    out->stage_ms[0] = out->observe_ms + out->build_ms - out->stage_ms[1] - out->stage_ms[2];
    if (out->stage_ms[0] < 0.0) out->stage_ms[0] = 0.0;
    out->stage_ms[3] = out->resolve_ms;
}

static int run(const bscene *b, const char *name, const om_method_cfg *c, uint32_t W, uint32_t H,
               uint8_t *mask, mrun *out)
{
    return bench_run_hooked(b, name, c, W, H, 0, mask, out, strcmp(name, "rtw") ? NULL : stages);
}

static double share(const uint8_t *ref, const uint8_t *m, uint32_t W, uint32_t H)
{
    om_metrics mt;
    om_compare_masks(ref, m, W, H, &mt);
    return 100.0 * (1.0 - om_metrics_match(&mt));
}

/* Method time: what the method adds to a frame (observe + build + resolve); frame
 * time: the whole frame with the eye pass and shading, as the paper's tables count.
 * The runs of the conventional map and of every RTW setting are interleaved, so that a
 * busy machine slows them alike and the ratios stay meaningful. */
static void one_scene(const bscene *b)
{
    enum { N = 5, C = 5 };
    static const struct { uint32_t exact; float tess; uint32_t analysis, funcs; } cf[C] = {
        {1, 0.0f, 0, 11}, {0, 0.0f, 0, 11}, {0, 0.05f, 0, 11}, {0, 0.025f, 0, 11}, {1, 0.0f, 2, 15},
    };
    const uint32_t W = 1024, H = 768;
    uint8_t *ref = malloc((size_t)W * H), *mk = malloc((size_t)W * H);
    mrun r;
    om_method_cfg rc;
    om_method_cfg_default(&rc, om_method_find("ref"));
    if (run(b, "ref", &rc, W, H, ref, &r)) goto out;
    /* the accurate 512 setting (hybrid) against the conventional 2048 map: what a user
     * who wants sm 2048's accuracy pays for it in memory and time */
    double hy_frame = 0.0, hy_share = 0.0;
    for (uint32_t size = 512; size <= 2048; size *= 2) {
        double sm_m[N], sm_f[N], sm_b[N], sm_l[N], sm_share = 0.0;
        double m_ms[C][N], f_ms[C][N], st[C][4][N], shr[C];
        om_method_stats last[C];
        int nc = size == 512 ? C : C - 1;   /* hybrid at 512 only */
        for (int k = 0; k < N; k++) {
            om_method_cfg c;   /* rtw's: sm takes its map */
            om_method_cfg_default(&c, om_method_find("rtw"));
            om_method_cfg_set(&c, "map", size, NULL);
            if (run(b, "sm", &c, W, H, mk, &r)) goto out;
            sm_b[k] = r.build_ms;
            sm_l[k] = r.resolve_ms;
            sm_m[k] = r.build_ms + r.resolve_ms;
            sm_f[k] = r.eye_ms + sm_m[k] + r.shade_ms;
            sm_share = share(ref, mk, W, H);
            for (int t = 0; t < nc; t++) {
                om_method_cfg_set(&c, "rtw.exact", cf[t].exact, NULL);
                om_method_cfg_set(&c, "rtw.tess", cf[t].tess, NULL);
                om_method_cfg_set(&c, "rtw.analysis", cf[t].analysis, NULL);
                om_method_cfg_set(&c, "rtw.funcs", cf[t].funcs, NULL);
                if (run(b, "rtw", &c, W, H, mk, &r)) goto out;
                for (int s = 0; s < 4; s++) st[t][s][k] = r.stage_ms[s];
                m_ms[t][k] = r.observe_ms + r.build_ms + r.resolve_ms;
                f_ms[t][k] = r.eye_ms + m_ms[t][k] + r.shade_ms;
                shr[t] = share(ref, mk, W, H);
                last[t] = r.stats;
            }
        }
        double sm_ms = bench_median(sm_m, N), sm_frame = bench_median(sm_f, N);
        printf("%-10s sm  %4u %-12s: method %7.2f ms, frame %7.2f ms (map %6.2f, lookup %6.2f), mismatches %.4f%%\n",
               b->name, size, "", sm_ms, sm_frame, bench_median(sm_b, N), bench_median(sm_l, N), sm_share);
        for (int t = 0; t < nc; t++) {
            double rtw_ms = bench_median(m_ms[t], N), rtw_frame = bench_median(f_ms[t], N);
            char what[32];
            if (cf[t].exact) snprintf(what, sizeof what, "exact%s", cf[t].analysis ? " hybrid" : "");
            else snprintf(what, sizeof what, "tess %.1f%%", 100.0 * cf[t].tess);
            printf("%-10s rtw %4u %-12s: method %7.2f ms (%.2fx), frame %7.2f ms (%.2fx) [importance %5.2f, warp %4.2f, map %6.2f, lookup %6.2f], "
                   "mismatches %.4f%%, MER %ux%u, %u tris\n",
                   b->name, size, what, rtw_ms, rtw_ms / sm_ms,
                   rtw_frame, rtw_frame / sm_frame, bench_median(st[t][0], N), bench_median(st[t][1], N),
                   bench_median(st[t][2], N), bench_median(st[t][3], N), shr[t], last[t].counters[2],
                   last[t].counters[3], last[t].counters[1]);
        }
        if (size == 512) {
            hy_frame = bench_median(f_ms[C - 1], N);
            hy_share = shr[C - 1];
        } else if (size == 2048) {
            printf("%-10s rtw 512 exact hybrid against sm 2048: frame %.2fx, mismatches %.4f%% against %.4f%% (%s)\n",
                   b->name, hy_frame / sm_frame, hy_share, sm_share,
                   hy_share <= sm_share ? "as accurate or better" : "less accurate");
        }
    }
out:
    free(ref);
    free(mk);
}

void bench_rtw(void) { bench_default_and_clouds(one_scene); }
