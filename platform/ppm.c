/* ppm.c — PPM (P6) and PGM (P5) sinks that write each strip as it arrives, plus the
 * shadow mask, through om_out (out.c): the files appear whole or not at all. A
 * framebuffer in RGB565 is widened to RGB888 for the PPM; an L8 one may go to a PGM. */
#include "platform.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

void om_row_to_rgb(const om_framebuffer *fb, uint32_t y, unsigned char *rgb)
{
    const uint8_t *p = fb->pixels + (size_t)y * fb->stride;
    for (uint32_t x = 0; x < fb->width; x++) {
        unsigned char *o = rgb + 3 * (size_t)x;
        switch (fb->format) {
        case OM_RGB888: o[0] = p[3 * x]; o[1] = p[3 * x + 1]; o[2] = p[3 * x + 2]; break;
        case OM_RGB565: {
            unsigned w = (unsigned)p[2 * x] | ((unsigned)p[2 * x + 1] << 8);
            unsigned r = (w >> 11) & 31, g = (w >> 5) & 63, b = w & 31;
            o[0] = (unsigned char)((r << 3) | (r >> 2));
            o[1] = (unsigned char)((g << 2) | (g >> 4));
            o[2] = (unsigned char)((b << 3) | (b >> 2));
            break;
        }
        default: o[0] = o[1] = o[2] = p[x]; break;
        }
    }
}

static om_status oom(om_diag *d, const char *path)
{
    if (d) {
        d->status = OM_E_IO;
        snprintf(d->msg, sizeof d->msg, "%s: out of memory", path);
    }
    return OM_E_IO;
}

/* Opens one output and writes its header; NULL path: nothing to open. */
static om_status open_one(om_out *o, const char *path, char kind, uint32_t w, uint32_t h, om_diag *d)
{
    if (!path) return OM_OK;
    om_status st = om_out_open(o, path, d);
    if (st != OM_OK) return st;
    char hdr[64];
    int n = snprintf(hdr, sizeof hdr, "P%c\n%u %u\n255\n", kind, w, h);
    om_out_write(o, hdr, (size_t)n);
    return om_out_failed(o, d);
}

om_status om_ppm_open(om_ppm_sink *k, const char *img_path, const char *mask_path,
                      uint32_t width, uint32_t height, bool grey, om_diag *d)
{
    memset(k, 0, sizeof *k);
    k->width = width;
    k->height = height;
    k->grey = grey;
    k->hash_img = k->hash_mask = OM_HASH_INIT;
    k->row = malloc((size_t)width * 3);
    om_status st = k->row ? OM_OK : oom(d, img_path ? img_path : mask_path ? mask_path : "-");
    if (st == OM_OK) st = open_one(&k->img, img_path, grey ? '5' : '6', width, height, d);
    if (st == OM_OK) st = open_one(&k->mask, mask_path, '5', width, height, d);
    if (st != OM_OK) om_ppm_discard(k);
    return st;
}

om_status om_ppm_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    om_ppm_sink *k = (om_ppm_sink *)user;
    if (k->grey && fb->format != OM_L8) return OM_E_INVALID;
    for (uint32_t y = 0; y < st->rows; y++) {
        size_t n = (size_t)st->width * (k->grey ? 1 : 3);
        if (k->grey) memcpy(k->row, fb->pixels + (size_t)y * fb->stride, n);
        else om_row_to_rgb(fb, y, k->row);
        k->hash_img = om_hash(k->hash_img, k->row, n);
        if (k->img.f && !om_out_write(&k->img, k->row, n)) return OM_E_IO;
        for (uint32_t x = 0; x < st->width; x++)
            k->row[x] = om_mask_of(&st->samples[(size_t)y * st->width + x],
                                   &st->terms[(size_t)y * st->width + x]);
        k->hash_mask = om_hash(k->hash_mask, k->row, st->width);
        if (k->mask.f && !om_out_write(&k->mask, k->row, st->width)) return OM_E_IO;
    }
    return OM_OK;
}

om_status om_ppm_failed(const om_ppm_sink *k, om_diag *d)
{
    om_status st = om_out_failed(&k->img, d);
    return st != OM_OK ? st : om_out_failed(&k->mask, d);
}

om_status om_ppm_close(om_ppm_sink *k, om_diag *d)
{
    om_out *outs[2] = {&k->img, &k->mask};
    om_status st = om_out_commit(outs, 2, d);
    free(k->row);
    k->row = NULL;
    return st;
}

void om_ppm_discard(om_ppm_sink *k)
{
    om_out_discard(&k->img);
    om_out_discard(&k->mask);
    free(k->row);
    k->row = NULL;
}

/* A PGM header token: skips whitespace and '#' comments; false on anything else. */
static bool pnm_uint(const char *s, size_t len, size_t *at, uint32_t *out)
{
    while (*at < len) {
        char c = s[*at];
        if (c == '#') { while (*at < len && s[*at] != '\n') (*at)++; }
        else if (c == ' ' || c == '\t' || c == '\r' || c == '\n') (*at)++;
        else break;
    }
    uint64_t v = 0;
    size_t start = *at;
    while (*at < len && s[*at] >= '0' && s[*at] <= '9' && v < 100000000) v = v * 10 + (uint64_t)(s[(*at)++] - '0');
    if (*at == start) return false;
    *out = (uint32_t)v;
    return true;
}

/* Reads only the header and the pixels it states, so a huge or endless file (a mask
 * named /dev/zero) costs a header's worth of reading before it is refused. */
om_status om_pgm_read(const char *path, uint32_t *w, uint32_t *h, uint8_t **pixels, om_diag *d)
{
    char head[4096];
    size_t len, at = 2;
    uint32_t maxval;
    *pixels = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        om_status st = errno == ENOENT ? OM_E_NOTFOUND : OM_E_IO;
        if (d) {
            d->status = st;
            snprintf(d->msg, sizeof d->msg, "%s: %s", path, strerror(errno));
        }
        return st;
    }
    len = fread(head, 1, sizeof head, f);
    bool ok = len >= 2 && head[0] == 'P' && head[1] == '5' && pnm_uint(head, len, &at, w) &&
              pnm_uint(head, len, &at, h) && pnm_uint(head, len, &at, &maxval) && maxval == 255 &&
              at < len && *w > 0 && *h > 0 && *w <= OM_MAX_DIM && *h <= OM_MAX_DIM;
    size_t n = ok ? (size_t)*w * *h : 0, have = ok ? len - at - 1 : 0;
    if (ok && !(*pixels = malloc(n))) {
        fclose(f);
        if (d) {
            d->status = OM_E_IO;
            snprintf(d->msg, sizeof d->msg, "%s: out of memory", path);
        }
        return OM_E_IO;
    }
    if (ok) {
        if (have > n) have = n;
        memcpy(*pixels, head + at + 1, have);
        ok = have == n || fread(*pixels + have, 1, n - have, f) == n - have;
    }
    fclose(f);
    if (!ok) {
        free(*pixels);
        *pixels = NULL;
        if (d) {
            d->status = OM_E_PARSE;
            snprintf(d->msg, sizeof d->msg, "%s: not a binary 8-bit PGM (P5, maxval 255) of its stated size", path);
        }
        return OM_E_PARSE;
    }
    return OM_OK;
}

bool om_ppm_put(om_out *o, const uint8_t *rgb, uint32_t w, uint32_t h)
{
    char hdr[64];
    int n = snprintf(hdr, sizeof hdr, "P6\n%u %u\n255\n", w, h);
    return om_out_write(o, hdr, (size_t)n) && om_out_write(o, rgb, (size_t)w * h * 3);
}

om_status om_ppm_write(const char *path, const uint8_t *rgb, uint32_t w, uint32_t h, om_diag *d)
{
    om_out o;
    om_status st = om_out_open(&o, path, d);
    if (st != OM_OK) return st;
    om_out *outs[1] = {&o};
    if (!om_ppm_put(&o, rgb, w, h)) {
        st = om_out_failed(&o, d);
        om_out_discard(&o);
        return st;
    }
    return om_out_commit(outs, 1, d);
}
