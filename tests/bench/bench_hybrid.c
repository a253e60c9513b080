/* bench_hybrid.c — the hybrid exact method against what it must beat, at 1024x768 on
 * the default scene and the 10K and 100K random clouds: frame times (eye pass, build,
 * resolve and shading; init apart) of `sm` at map 1024, `izb` and `hybrid` at maps
 * 128, 256 (its default at 1024x768) and 512, in interleaved rounds (medians), the
 * ratios the method is judged by, where hybrid's time goes, the share of samples its
 * map decides, and its mismatches against izb (always 0: both are exact). */
#include "bench.h"

#define ROUNDS 5
#define NCFG 5

static double frame_ms(const mrun *r) { return r->eye_ms + r->observe_ms + r->build_ms + r->resolve_ms + r->shade_ms; }

static void one_scene(const bscene *b)
{
    const uint32_t W = 1024, H = 768;
    static const char *const names[NCFG] = {"sm", "izb", "hybrid", "hybrid", "hybrid"};
    static const uint32_t maps[NCFG] = {1024, 0, 128, 256, 512};
    double t[NCFG][ROUNDS], bu[NCFG][ROUNDS], re[NCFG][ROUNDS];
    mrun last[NCFG];
    uint8_t *exact = malloc((size_t)W * H), *mk = malloc((size_t)W * H);
    uint64_t wrong[NCFG] = {0};
    for (int r = 0; r < ROUNDS; r++)
        for (int k = 0; k < NCFG; k++) {
            om_method_cfg c;
            om_method_cfg_default(&c, om_method_find(names[k]));   /* each takes one of the two */
            om_method_cfg_set(&c, "map", maps[k], NULL);
            om_method_cfg_set(&c, "hybrid.map", maps[k], NULL);
            if (bench_run(b, names[k], &c, W, H, 0, k == 1 ? exact : mk, &last[k])) goto out;
            t[k][r] = frame_ms(&last[k]);
            bu[k][r] = last[k].build_ms;
            re[k][r] = last[k].resolve_ms;
            if (k >= 2) {
                om_metrics mt;
                om_compare_masks(exact, mk, W, H, &mt);
                wrong[k] += mt.false_lit + mt.false_shadowed;
            }
        }
    double sm = bench_median(t[0], ROUNDS), izb = bench_median(t[1], ROUNDS);
    printf("%-12s sm 1024 frame %7.2f ms, izb frame %7.2f ms\n", b->name, sm, izb);
    for (int k = 2; k < NCFG; k++) {
        const om_method_stats *s = &last[k].stats;
        double n = (double)s->counters[0] + s->counters[1] + s->counters[2];
        double f = bench_median(t[k], ROUNDS);
        printf("%-12s hybrid %4u: frame %7.2f ms = %.2fx sm, %.2fx izb; build %6.2f, resolve %6.2f; "
               "lit %.1f%%, shadowed %.1f%%, uncertain %.1f%%; %llu differ from izb\n",
               b->name, maps[k], f, f / sm, f / izb, bench_median(bu[k], ROUNDS), bench_median(re[k], ROUNDS),
               100.0 * s->counters[0] / n, 100.0 * s->counters[1] / n, 100.0 * s->counters[2] / n,
               (unsigned long long)wrong[k]);
    }
out:
    free(exact);
    free(mk);
}

void bench_hybrid(void) { bench_default_and_clouds(one_scene); }
