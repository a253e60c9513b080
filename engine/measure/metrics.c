/* metrics.c — accuracy against the reference on the same visible samples: match
 * share, false lit and false shadowed, the same in a band around the reference's
 * shadow edges, difference images, and flicker along a path. Masks in, counts out:
 * any two masks of one frame compare, whichever method made them; and the frame hash. */
#include "../core/core.h"   /* the determinism checks every engine file has */
#include "ombra_measure.h"

#include <string.h>

static bool near_edge(const uint8_t *ref, uint32_t w, uint32_t h, uint32_t x, uint32_t y)
{
    uint8_t c = ref[(size_t)y * w + x];
    uint32_t x0 = x >= OM_EDGE_BAND ? x - OM_EDGE_BAND : 0, y0 = y >= OM_EDGE_BAND ? y - OM_EDGE_BAND : 0;
    uint32_t x1 = x + OM_EDGE_BAND < w ? x + OM_EDGE_BAND : w - 1;
    uint32_t y1 = y + OM_EDGE_BAND < h ? y + OM_EDGE_BAND : h - 1;
    for (uint32_t yy = y0; yy <= y1; yy++)
        for (uint32_t xx = x0; xx <= x1; xx++) {
            uint8_t o = ref[(size_t)yy * w + xx];
            if (o != OM_MASK_BG && o != c) return true;
        }
    return false;
}

void om_compare_masks(const uint8_t *ref, const uint8_t *m, uint32_t width, uint32_t height,
                      om_metrics *out)
{
    if (!out) return;
    memset(out, 0, sizeof *out);
    if (!ref || !m) return;
    for (uint32_t y = 0; y < height; y++)
        for (uint32_t x = 0; x < width; x++) {
            size_t i = (size_t)y * width + x;
            uint8_t r = ref[i], a = m[i];
            if (r == OM_MASK_BG || a == OM_MASK_BG) {
                out->mismatched_bg += (r == OM_MASK_BG) != (a == OM_MASK_BG);
                continue;
            }
            bool fl = r == OM_MASK_SHADOW && a == OM_MASK_LIT;
            bool fs = r == OM_MASK_LIT && a == OM_MASK_SHADOW;
            out->samples++;
            out->false_lit += fl;
            out->false_shadowed += fs;
            if (near_edge(ref, width, height, x, y)) {
                out->edge_samples++;
                out->edge_false_lit += fl;
                out->edge_false_shadowed += fs;
            }
        }
}

double om_metrics_match(const om_metrics *m)
{
    if (!m || m->samples == 0) return 1.0;
    return 1.0 - (double)(m->false_lit + m->false_shadowed) / (double)m->samples;
}

void om_diff_image(const uint8_t *ref, const uint8_t *m, uint32_t width, uint32_t height,
                   uint8_t *rgb)
{
    const size_t n = ref && m && rgb ? (size_t)width * height : 0;
    for (size_t i = 0; i < n; i++) {
        uint8_t r = ref[i], a = m[i], *o = rgb + 3 * i;
        if (r == OM_MASK_BG || a == OM_MASK_BG) { o[0] = o[1] = o[2] = 0; }
        else if (r == OM_MASK_SHADOW && a == OM_MASK_LIT) { o[0] = 255; o[1] = 40; o[2] = 40; }
        else if (r == OM_MASK_LIT && a == OM_MASK_SHADOW) { o[0] = 40; o[1] = 80; o[2] = 255; }
        else o[0] = o[1] = o[2] = r == OM_MASK_LIT ? 190 : 70;
    }
}

void om_flicker_add(om_flicker *f, const uint8_t *ref_prev, const uint8_t *m_prev,
                    const uint8_t *ref, const uint8_t *m, size_t n)
{
    if (!f || !ref_prev || !m_prev || !ref || !m) return;
    for (size_t i = 0; i < n; i++) {
        if (ref_prev[i] == OM_MASK_BG || ref[i] == OM_MASK_BG || m_prev[i] == OM_MASK_BG ||
            m[i] == OM_MASK_BG)
            continue;
        f->samples++;
        f->flicker += m_prev[i] != m[i] && ref_prev[i] == ref[i];
    }
    f->frames++;
}

double om_flicker_share(const om_flicker *f)
{
    return f && f->samples ? (double)f->flicker / (double)f->samples : 0.0;
}

uint64_t om_hash(uint64_t h, const void *data, size_t len)
{
    const unsigned char *p = (const unsigned char *)data;
    for (size_t i = 0; p && i < len; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}
