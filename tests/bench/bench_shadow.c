/* bench_shadow.c — the reference and the conventional map at 1024x768, for the default
 * scene and 1K/10K/100K random triangles of constant total area: the reference's BVH
 * build and shadow-test time and samples per second; the map's build and lookup time
 * and its mismatch share against the reference at 1024, 2048 and 4096. */
#include "bench.h"

static void one_scene(const bscene *b)
{
    const uint32_t W = 1024, H = 768;
    uint8_t *ref = malloc((size_t)W * H), *sm = malloc((size_t)W * H);
    double bi[3], sh[3];
    mrun r;
    for (int k = 0; k < 3; k++) {
        if (bench_run(b, "ref", NULL, W, H, 0, ref, &r)) return;
        bi[k] = r.init_ms;
        sh[k] = r.resolve_ms;
    }
    double s = bench_median(sh, 3);
    printf("%-12s ref  %ux%u: BVH build %7.2f ms, shadow tests %8.2f ms, %.2f M samples/s (%u samples)\n",
           b->name, W, H, bench_median(bi, 3), s, (double)r.stats.counters[0] / (s * 1e3),
           r.stats.counters[0]);
    for (uint32_t size = 1024; size <= 4096; size *= 2) {
        double bu[3], lo[3];
        om_method_cfg c;
        om_method_cfg_default(&c, om_method_find("sm"));
        om_method_cfg_set(&c, "map", size, NULL);
        for (int k = 0; k < 3; k++) {
            if (bench_run(b, "sm", &c, W, H, 0, sm, &r)) return;
            bu[k] = r.build_ms;
            lo[k] = r.resolve_ms;
        }
        om_metrics mt;
        om_compare_masks(ref, sm, W, H, &mt);
        printf("%-12s sm %4u: build %7.2f ms, lookup %6.2f ms, mismatches %.4f%% (false lit %llu, false shadowed %llu)\n",
               b->name, size, bench_median(bu, 3), bench_median(lo, 3), 100.0 * (1.0 - om_metrics_match(&mt)),
               (unsigned long long)mt.false_lit, (unsigned long long)mt.false_shadowed);
    }
    free(ref);
    free(sm);
}

void bench_shadow(void)
{
    bscene b;
    if (bench_load(&b, "default", om_scene_default_text())) return;
    one_scene(&b);
    bench_free(&b);
    static const unsigned counts[] = {1000, 10000, 100000};
    for (int k = 0; k < 3; k++) {
        if (bench_load_random(&b, counts[k])) return;
        one_scene(&b);
        bench_free(&b);
    }
}
