/* unit/measure.c — the metrics on hand-made masks: counts, the edge band, the
 * difference image and flicker. */
#include "../test.h"
#include "ombra.h"
#include "ombra_measure.h"

static void counts_and_edge_band(void)
{
    /* 8 x 4: reference lit on the left half, shadowed on the right; row 0 background. */
    uint8_t ref[32], m[32];
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 8; x++) {
            ref[y * 8 + x] = y == 0 ? OM_MASK_BG : x < 4 ? OM_MASK_LIT : OM_MASK_SHADOW;
            m[y * 8 + x] = ref[y * 8 + x];
        }
    m[1 * 8 + 0] = OM_MASK_SHADOW;   /* false shadowed, far from the edge (x=0, edge at 3|4) */
    m[2 * 8 + 4] = OM_MASK_LIT;      /* false lit, at the edge */
    om_metrics r;
    om_compare_masks(ref, m, 8, 4, &r);
    CHECK_EQ_U(r.samples, 24);
    CHECK_EQ_U(r.false_lit, 1);
    CHECK_EQ_U(r.false_shadowed, 1);
    /* columns 2..5 lie within 2 px of a differing reference pixel */
    CHECK_EQ_U(r.edge_samples, 12);
    CHECK_EQ_U(r.edge_false_lit, 1);
    CHECK_EQ_U(r.edge_false_shadowed, 0);
    CHECK_EQ_U(r.mismatched_bg, 0);
    CHECK(om_metrics_match(&r) > 0.916 && om_metrics_match(&r) < 0.917);
    m[0] = OM_MASK_LIT;
    om_compare_masks(ref, m, 8, 4, &r);
    CHECK_EQ_U(r.mismatched_bg, 1);
    uint8_t rgb[96];
    om_diff_image(ref, m, 8, 4, rgb);
    CHECK(rgb[3 * 20] == 255 && rgb[3 * 20 + 2] == 40);   /* (4,2) false lit: red */
    CHECK(rgb[3 * 8 + 2] == 255 && rgb[3 * 8] == 40);     /* (0,1) false shadowed: blue */
    CHECK(rgb[3 * 9] == 190 && rgb[3 * 15] == 70);
}

static void flicker(void)
{
    uint8_t r0[4] = {255, 255, 0, 128}, r1[4] = {255, 0, 0, 128};
    uint8_t m0[4] = {255, 255, 255, 128}, m1[4] = {0, 0, 0, 128};
    om_flicker f = {0, 0, 0};
    om_flicker_add(&f, r0, m0, r1, m1, 4);
    /* sample 0: method changes, reference does not -> flicker; sample 1: both change;
     * sample 2: method changes, reference does not -> flicker; sample 3: background */
    CHECK_EQ_U(f.samples, 3);
    CHECK_EQ_U(f.flicker, 2);
    CHECK(om_flicker_share(&f) > 0.66 && om_flicker_share(&f) < 0.67);
}

void suite_measure(void)
{
    RUN(counts_and_edge_band);
    RUN(flicker);
}
