/* bench_spsm.c — Sub-Pixel Shadow Maps against the conventional map at 1024x768, for
 * the default scene and the 10K and 100K random-triangle scenes, at map sizes 512 to
 * 4096: time per stage (medians of 5 interleaved runs; SPSM's observe marks the
 * texels its lookup will read, and its build makes only their records), SPSM's
 * overhead over the map (observe, build and lookup, the stages the two differ in; the
 * paper's Table 2 measured 81, 56, 44 and 27%, on frames that include rendering the
 * scene: our "frame" figure adds the eye pass to both), each one's mismatch share
 * against the reference, SPSM's classification shares (lit, shadowed, uncertain; and
 * the uncertain share that recovery shadowed) and the share of texels whose records
 * it made. On the default scene a third series, spsm.fine = 1 (the plain-map fallback
 * at 2 x 2 points per texel), runs with them. */
#include "bench.h"

enum { N = 5 };   /* runs per method and size */

static void one_scene(const bscene *b, bool fine)
{
    const uint32_t W = 1024, H = 768;
    uint8_t *ref = malloc((size_t)W * H), *mask = malloc((size_t)W * H);
    mrun r;
    if (bench_run(b, "ref", NULL, W, H, 0, ref, &r)) goto out;
    printf("%-12s %ux%u, %u exposed samples; time = [observe +] build + lookup, median of %d interleaved runs\n", b->name, W, H,
           r.stats.counters[0], N);
    for (uint32_t size = 512; size <= 4096; size *= 2) {
        /* the two methods' runs alternate, so that a busy spell of the machine slows
         * both alike and the overhead stays meaningful */
        const char *names[3] = {"sm", "spsm", "spsm"};
        double ob[3], bu[3], lo[3], ey[3], miss[3], to[3][N], tb[3][N], tl[3][N], te[3][N];
        const int series = fine ? 3 : 2;
        mrun last, lastsp;
        memset(&lastsp, 0, sizeof lastsp);   /* read after the loop, which gcc -O1 cannot see runs */
        om_method_cfg c[3];
        for (int k = 0; k < 3; k++) {
            om_method_cfg_default(&c[k], om_method_find(names[k]));
            om_method_cfg_set(&c[k], "map", size, NULL);
        }
        om_method_cfg_set(&c[2], "spsm.fine", 1, NULL);
        for (int run = 0; run < N; run++)
            for (int k = 0; k < series; k++) {
                if (bench_run(b, names[k], &c[k], W, H, 0, mask, &last)) goto out;
                if (k == 1) lastsp = last;
                to[k][run] = last.observe_ms;
                tb[k][run] = last.build_ms;
                tl[k][run] = last.resolve_ms;
                te[k][run] = last.eye_ms;
                if (run == N - 1) {
                    om_metrics mt;
                    om_compare_masks(ref, mask, W, H, &mt);
                    miss[k] = 100.0 * (1.0 - om_metrics_match(&mt));
                }
            }
        for (int k = 0; k < series; k++) {
            ob[k] = bench_median(to[k], N);
            bu[k] = bench_median(tb[k], N);
            lo[k] = bench_median(tl[k], N);
            ey[k] = bench_median(te[k], N);
        }
        const uint32_t *cn = lastsp.stats.counters;   /* spsm's, from its last run */
        double n = cn[0] ? (double)cn[0] : 1.0;
        const double sm = ob[0] + bu[0] + lo[0], sp = ob[1] + bu[1] + lo[1];
        printf("%-12s %4u  sm %6.2f + %6.2f ms, %.4f%% wrong | spsm %5.2f + %6.2f + %6.2f ms, %.4f%% wrong, "
               "overhead %+5.0f%% (frame %+4.0f%%) | lit %.1f%% shadowed %.1f%% uncertain %.1f%% (recovered shadow %.1f%%)"
               " | records made %.1f%%\n",
               b->name, size, bu[0], lo[0], miss[0], ob[1], bu[1], lo[1], miss[1], 100.0 * (sp / sm - 1.0),
               100.0 * ((ey[1] + sp) / (ey[0] + sm) - 1.0), 100.0 * cn[1] / n, 100.0 * cn[2] / n,
               100.0 * cn[3] / n, 100.0 * cn[4] / n, 100.0 * cn[7] / ((double)size * size));
        if (fine) {
            const double sf = ob[2] + bu[2] + lo[2];
            printf("%-12s %4u  spsm.fine=1 %5.2f + %6.2f + %6.2f ms, %.4f%% wrong, overhead %+5.0f%% (frame %+4.0f%%)\n",
                   b->name, size, ob[2], bu[2], lo[2], miss[2], 100.0 * (sf / sm - 1.0),
                   100.0 * ((ey[2] + sf) / (ey[0] + sm) - 1.0));
        }
    }
out:
    free(ref);
    free(mask);
}

void bench_spsm(void)
{
    bscene b;
    if (bench_load(&b, "default", om_scene_default_text())) return;
    one_scene(&b, true);
    bench_free(&b);
    static const unsigned counts[] = {10000, 100000};
    for (int k = 0; k < 2; k++) {
        if (bench_load_random(&b, counts[k])) return;
        one_scene(&b, false);
        bench_free(&b);
    }
}
