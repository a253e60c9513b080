/* ppm.c — PPM (P6) and PGM (P5) sinks that write each strip as it arrives, plus the
 * shadow mask. A framebuffer in RGB565 or L8 is widened to RGB888 for the PPM. */
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

static om_status io_fail(om_diag *d, const char *path, const char *what)
{
    if (d) {
        d->status = OM_E_IO;
        snprintf(d->msg, sizeof d->msg, "%s: %s: %s", path, what, strerror(errno));
    }
    return OM_E_IO;
}

om_status om_ppm_open(om_ppm_sink *k, const char *img_path, const char *mask_path,
                      uint32_t width, uint32_t height, om_diag *d)
{
    memset(k, 0, sizeof *k);
    k->width = width;
    k->height = height;
    k->img_path = img_path;
    k->mask_path = mask_path;
    k->hash_img = k->hash_mask = OM_HASH_INIT;
    k->row = malloc((size_t)width * 3);
    if (!k->row) return io_fail(d, img_path ? img_path : "-", "out of memory");
    if (img_path) {
        k->img = fopen(img_path, "wb");
        if (!k->img) return io_fail(d, img_path, "cannot create");
        fprintf(k->img, "P6\n%u %u\n255\n", width, height);
    }
    if (mask_path) {
        k->mask = fopen(mask_path, "wb");
        if (!k->mask) return io_fail(d, mask_path, "cannot create");
        fprintf(k->mask, "P5\n%u %u\n255\n", width, height);
    }
    return OM_OK;
}

om_status om_ppm_strip(void *user, const om_strip *st, const om_framebuffer *fb)
{
    om_ppm_sink *k = (om_ppm_sink *)user;
    for (uint32_t y = 0; y < st->rows; y++) {
        om_row_to_rgb(fb, y, k->row);
        k->hash_img = om_hash(k->hash_img, k->row, (size_t)st->width * 3);
        if (k->img && fwrite(k->row, 3, st->width, k->img) != st->width) return OM_E_IO;
        for (uint32_t x = 0; x < st->width; x++)
            k->row[x] = om_mask_of(&st->samples[(size_t)y * st->width + x],
                                   &st->terms[(size_t)y * st->width + x]);
        k->hash_mask = om_hash(k->hash_mask, k->row, st->width);
        if (k->mask && fwrite(k->row, 1, st->width, k->mask) != st->width) return OM_E_IO;
    }
    return OM_OK;
}

om_status om_ppm_close(om_ppm_sink *k, om_diag *d)
{
    om_status st = OM_OK;
    if (k->img && (fflush(k->img) != 0 || ferror(k->img))) st = io_fail(d, k->img_path, "write failed");
    if (k->img && fclose(k->img) != 0 && st == OM_OK) st = io_fail(d, k->img_path, "close failed");
    if (k->mask && (fflush(k->mask) != 0 || ferror(k->mask)) && st == OM_OK)
        st = io_fail(d, k->mask_path, "write failed");
    if (k->mask && fclose(k->mask) != 0 && st == OM_OK) st = io_fail(d, k->mask_path, "close failed");
    free(k->row);
    k->img = k->mask = NULL;
    k->row = NULL;
    return st;
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

om_status om_pgm_read(const char *path, uint32_t *w, uint32_t *h, uint8_t **pixels, om_diag *d)
{
    char *data;
    size_t len, at = 2;
    uint32_t maxval;
    *pixels = NULL;
    om_status st = om_file_read(path, &data, &len, d);
    if (st != OM_OK) return st;
    if (len < 2 || data[0] != 'P' || data[1] != '5' || !pnm_uint(data, len, &at, w) ||
        !pnm_uint(data, len, &at, h) || !pnm_uint(data, len, &at, &maxval) || maxval != 255 ||
        at >= len || *w == 0 || *h == 0 || *w > OM_MAX_DIM || *h > OM_MAX_DIM ||
        len - at - 1 < (size_t)*w * *h) {
        free(data);
        if (d) {
            d->status = OM_E_PARSE;
            snprintf(d->msg, sizeof d->msg, "%s: not a binary 8-bit PGM (P5, maxval 255) of its stated size", path);
        }
        return OM_E_PARSE;
    }
    *pixels = malloc((size_t)*w * *h);
    if (!*pixels) { free(data); return OM_E_IO; }
    memcpy(*pixels, data + at + 1, (size_t)*w * *h);
    free(data);
    return OM_OK;
}

om_status om_ppm_write(const char *path, const uint8_t *rgb, uint32_t w, uint32_t h, om_diag *d)
{
    FILE *f = fopen(path, "wb");
    if (!f) return io_fail(d, path, "cannot create");
    fprintf(f, "P6\n%u %u\n255\n", w, h);
    size_t n = (size_t)w * h * 3;
    bool ok = fwrite(rgb, 1, n, f) == n;
    ok = fclose(f) == 0 && ok;
    return ok ? OM_OK : io_fail(d, path, "write failed");
}
