/* png.h — RGB and grey images as PNG, still or animated (APNG), and as base64 data
 * URIs, so the report page carries its own pictures. No zlib: each row is filtered
 * against the one above and deflated with the fixed Huffman codes and runs only
 * (distance 1, or one pixel back), which is what masks and flat renders need. */
#ifndef OM_PNG_H
#define OM_PNG_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* Encodes w x h RGB888 pixels; returns a malloc'd buffer (NULL when out of memory). */
uint8_t *png_encode(const uint8_t *rgb, uint32_t w, uint32_t h, size_t *len);
/* The same for pixels of `ch` channels: 1 (grey) or 3 (RGB888). */
uint8_t *png_encode_px(const uint8_t *px, unsigned ch, uint32_t w, uint32_t h, size_t *len);
/* An APNG of `frames` images of w x h pixels of `ch` channels, one after the other in
 * px, each shown delay_ms, looping for ever; a viewer without APNG shows the first.
 * Returns a malloc'd buffer (NULL when out of memory). */
uint8_t *png_encode_anim(const uint8_t *px, unsigned ch, uint32_t w, uint32_t h, uint32_t frames,
                         uint32_t delay_ms, size_t *len);
/* Writes `data:image/png;base64,...` for the image to f. */
void png_data_uri(FILE *f, const uint8_t *rgb, uint32_t w, uint32_t h);
/* The same for an encoded PNG of n bytes. */
void png_data_uri_bytes(FILE *f, const uint8_t *png, size_t n);

#endif
