/* png.c — see png.h. A PNG is a signature and chunks (length, type, data, CRC-32);
 * IDAT holds a zlib stream, here of stored deflate blocks of at most 65535 bytes, each
 * scanline prefixed by filter type 0. */
#include "png.h"

#include <stdlib.h>
#include <string.h>

static uint32_t crc_table[256];

static void crc_init(void)
{
    if (crc_table[1]) return;
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        crc_table[n] = c;
    }
}

static uint32_t crc(const uint8_t *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) c = crc_table[(c ^ p[i]) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

static uint8_t *put32(uint8_t *o, uint32_t v)
{
    o[0] = (uint8_t)(v >> 24); o[1] = (uint8_t)(v >> 16); o[2] = (uint8_t)(v >> 8); o[3] = (uint8_t)v;
    return o + 4;
}

static uint8_t *chunk(uint8_t *o, const char *type, const uint8_t *data, size_t n)
{
    o = put32(o, (uint32_t)n);
    uint8_t *start = o;
    memcpy(o, type, 4);
    o += 4;
    if (n) memcpy(o, data, n);
    o += n;
    return put32(o, crc(start, n + 4));
}

uint8_t *png_encode(const uint8_t *rgb, uint32_t w, uint32_t h, size_t *len)
{
    return png_encode_px(rgb, 3, w, h, len);
}

uint8_t *png_encode_px(const uint8_t *px, unsigned ch, uint32_t w, uint32_t h, size_t *len)
{
    crc_init();
    size_t raw = (size_t)h * (1 + (size_t)w * ch);
    size_t blocks = raw / 65535 + 1;
    size_t zlen = 2 + raw + blocks * 5 + 4;
    uint8_t *z = malloc(zlen), *out = malloc(8 + 25 + 12 + zlen + 12);
    uint8_t *line = malloc(1 + (size_t)w * ch);
    if (!z || !out || !line) { free(z); free(out); free(line); return NULL; }
    /* zlib stream: header, stored blocks, Adler-32 of the raw data */
    uint8_t *q = z;
    *q++ = 0x78;
    *q++ = 0x01;
    uint32_t a = 1, b = 0;
    size_t left = raw, row = 0, col = 0;
    while (left > 0 || q == z + 2) {
        size_t n = left < 65535 ? left : 65535;
        left -= n;
        *q++ = left == 0 ? 1 : 0;
        *q++ = (uint8_t)(n & 0xFF); *q++ = (uint8_t)(n >> 8);
        *q++ = (uint8_t)(~n & 0xFF); *q++ = (uint8_t)((~n >> 8) & 0xFF);
        for (size_t i = 0; i < n; i++) {
            uint8_t v = col == 0 ? 0 : px[row * w * ch + col - 1];
            if (++col == 1 + (size_t)w * ch) { col = 0; row++; }
            *q++ = v;
            a = (a + v) % 65521;
            b = (b + a) % 65521;
        }
        if (n == 0) break;
    }
    q = put32(q, (b << 16) | a);
    uint8_t ihdr[13];
    put32(ihdr, w);
    put32(ihdr + 4, h);
    /* 8 bits, colour type 0 (grey) or 2 (RGB), no interlace */
    ihdr[8] = 8; ihdr[9] = ch == 1 ? 0 : 2; ihdr[10] = 0; ihdr[11] = 0; ihdr[12] = 0;
    uint8_t *o = out;
    memcpy(o, "\x89PNG\r\n\x1a\n", 8);
    o += 8;
    o = chunk(o, "IHDR", ihdr, 13);
    o = chunk(o, "IDAT", z, (size_t)(q - z));
    o = chunk(o, "IEND", NULL, 0);
    *len = (size_t)(o - out);
    free(z);
    free(line);
    return out;
}

void png_data_uri(FILE *f, const uint8_t *rgb, uint32_t w, uint32_t h)
{
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t n;
    uint8_t *p = png_encode(rgb, w, h, &n);
    fputs("data:image/png;base64,", f);
    for (size_t i = 0; p && i < n; i += 3) {
        uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        fputc(b64[v >> 18 & 63], f);
        fputc(b64[v >> 12 & 63], f);
        fputc(i + 1 < n ? b64[v >> 6 & 63] : '=', f);
        fputc(i + 2 < n ? b64[v & 63] : '=', f);
    }
    free(p);
}
