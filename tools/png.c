/* png.c — see png.h. A PNG is a signature and chunks (length, type, data, CRC-32);
 * IDAT holds a zlib stream of the scanlines, each prefixed by its filter type: the
 * first row unfiltered, the others "up" (the difference to the row above), so a row
 * like the last is all zeros. The deflate stream is one block of the fixed Huffman
 * codes: literals, and runs copied from one byte or one pixel back. An APNG adds acTL
 * before the first frame, an fcTL before each, and carries the frames after the first
 * in fdAT chunks; fcTL and fdAT share one sequence count. */
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

/* Bits go out least significant first; Huffman codes are sent from their top bit. */
typedef struct bits { uint8_t *o; uint32_t acc; int n; } bits;

static void put_bits(bits *b, uint32_t v, int n)
{
    b->acc |= v << b->n;
    b->n += n;
    while (b->n >= 8) { *b->o++ = (uint8_t)b->acc; b->acc >>= 8; b->n -= 8; }
}

static void put_code(bits *b, uint32_t code, int len)
{
    uint32_t r = 0;
    for (int i = 0; i < len; i++) r |= ((code >> i) & 1u) << (len - 1 - i);
    put_bits(b, r, len);
}

/* The fixed literal/length code (RFC 1951, 3.2.6). */
static void put_sym(bits *b, unsigned s)
{
    if (s < 144) put_code(b, 0x30 + s, 8);
    else if (s < 256) put_code(b, 0x190 + s - 144, 9);
    else if (s < 280) put_code(b, s - 256, 7);
    else put_code(b, 0xC0 + s - 280, 8);
}

static const uint16_t len_base[29] = {3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31,
                                      35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
static const uint8_t len_extra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2,
                                      3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};

/* A copy of len (3..258) bytes from dist (1..4) back. */
static void put_match(bits *b, unsigned len, unsigned dist)
{
    int k = 28;
    while (len_base[k] > len) k--;
    put_sym(b, 257 + (unsigned)k);
    if (len_extra[k]) put_bits(b, len - len_base[k], len_extra[k]);
    put_code(b, dist - 1, 5);   /* distance codes 0..3 are distances 1..4, no extra bits */
}

/* The zlib stream of n bytes at z (room: n + n / 8 + 16): one fixed-code block of
 * literals and runs from `step` bytes back or one. Returns its length. */
static size_t zlib(const uint8_t *raw, size_t n, unsigned step, uint8_t *z)
{
    bits b = {z + 2, 0, 0};
    z[0] = 0x78;
    z[1] = 0x01;
    put_bits(&b, 1, 1);   /* the last block */
    put_bits(&b, 1, 2);   /* fixed codes */
    for (size_t i = 0; i < n;) {
        size_t best = 0;
        unsigned dist = 0;
        for (unsigned d = 1; d <= step; d += step > 1 ? step - 1 : 1) {
            if (i < d) break;
            size_t l = 0;
            while (l < 258 && i + l < n && raw[i + l] == raw[i + l - d]) l++;
            if (l > best) { best = l; dist = d; }
        }
        if (best >= 3) {
            put_match(&b, (unsigned)best, dist);
            i += best;
        } else {
            put_sym(&b, raw[i++]);
        }
    }
    put_sym(&b, 256);
    if (b.n) put_bits(&b, 0, 8 - b.n);
    uint32_t a = 1, s = 0;
    for (size_t i = 0; i < n; i++) { a = (a + raw[i]) % 65521; s = (s + a) % 65521; }
    return (size_t)(put32(b.o, (s << 16) | a) - z);
}

/* Scanlines of one image, filtered: the first row as it is, the rest "up". */
static void filter(const uint8_t *px, unsigned ch, uint32_t w, uint32_t h, uint8_t *raw)
{
    size_t stride = (size_t)w * ch;
    for (uint32_t y = 0; y < h; y++) {
        uint8_t *o = raw + y * (stride + 1);
        const uint8_t *p = px + y * stride, *up = y ? p - stride : NULL;
        o[0] = y ? 2 : 0;
        for (size_t i = 0; i < stride; i++) o[1 + i] = (uint8_t)(up ? p[i] - up[i] : p[i]);
    }
}

uint8_t *png_encode(const uint8_t *rgb, uint32_t w, uint32_t h, size_t *len)
{
    return png_encode_px(rgb, 3, w, h, len);
}

uint8_t *png_encode_px(const uint8_t *px, unsigned ch, uint32_t w, uint32_t h, size_t *len)
{
    return png_encode_anim(px, ch, w, h, 1, 0, len);
}

uint8_t *png_encode_anim(const uint8_t *px, unsigned ch, uint32_t w, uint32_t h, uint32_t frames,
                         uint32_t delay_ms, size_t *len)
{
    crc_init();
    size_t raw_n = (size_t)h * (1 + (size_t)w * ch), zcap = raw_n + raw_n / 8 + 16;
    size_t cap = 8 + 25 + 20 + (size_t)frames * (38 + 16 + zcap) + 12;
    uint8_t *raw = malloc(raw_n), *z = malloc(zcap + 4), *out = malloc(cap);
    if (!raw || !z || !out || !frames) { free(raw); free(z); free(out); return NULL; }
    uint8_t ihdr[13];
    put32(ihdr, w);
    put32(ihdr + 4, h);
    /* 8 bits, colour type 0 (grey) or 2 (RGB), no interlace */
    ihdr[8] = 8; ihdr[9] = ch == 1 ? 0 : 2; ihdr[10] = 0; ihdr[11] = 0; ihdr[12] = 0;
    uint8_t *o = out;
    memcpy(o, "\x89PNG\r\n\x1a\n", 8);
    o += 8;
    o = chunk(o, "IHDR", ihdr, 13);
    if (frames > 1) {
        uint8_t actl[8];
        put32(actl, frames);
        put32(actl + 4, 0);   /* loop for ever */
        o = chunk(o, "acTL", actl, 8);
    }
    uint32_t seq = 0;
    for (uint32_t k = 0; k < frames; k++) {
        if (frames > 1) {
            uint8_t fctl[26];
            put32(fctl, seq++);
            put32(fctl + 4, w);
            put32(fctl + 8, h);
            put32(fctl + 12, 0);
            put32(fctl + 16, 0);
            fctl[20] = (uint8_t)(delay_ms >> 8); fctl[21] = (uint8_t)delay_ms;   /* delay_ms / 1000 s */
            fctl[22] = 1000 >> 8; fctl[23] = 1000 & 0xFF;
            fctl[24] = 0;   /* dispose: none */
            fctl[25] = 0;   /* blend: source, the frame replaces what was there */
            o = chunk(o, "fcTL", fctl, 26);
        }
        filter(px + (size_t)k * w * h * ch, ch, w, h, raw);
        size_t zn;
        if (k == 0) {
            zn = zlib(raw, raw_n, ch, z);
            o = chunk(o, "IDAT", z, zn);
        } else {
            put32(z, seq++);
            zn = zlib(raw, raw_n, ch, z + 4);
            o = chunk(o, "fdAT", z, zn + 4);
        }
    }
    o = chunk(o, "IEND", NULL, 0);
    *len = (size_t)(o - out);
    free(raw);
    free(z);
    return out;
}

void png_data_uri_bytes(FILE *f, const uint8_t *p, size_t n)
{
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    fputs("data:image/png;base64,", f);
    for (size_t i = 0; p && i < n; i += 3) {
        uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        fputc(b64[v >> 18 & 63], f);
        fputc(b64[v >> 12 & 63], f);
        fputc(i + 1 < n ? b64[v >> 6 & 63] : '=', f);
        fputc(i + 2 < n ? b64[v & 63] : '=', f);
    }
}

void png_data_uri(FILE *f, const uint8_t *rgb, uint32_t w, uint32_t h)
{
    size_t n = 0;
    uint8_t *p = png_encode(rgb, w, h, &n);
    png_data_uri_bytes(f, p, n);
    free(p);
}
