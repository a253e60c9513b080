/* png.h — RGB and grey images as PNG (stored, uncompressed deflate: no zlib needed) and as
 * base64 data URIs, so the report page carries its own pictures. */
#ifndef OM_PNG_H
#define OM_PNG_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* Encodes w x h RGB888 pixels; returns a malloc'd buffer (NULL when out of memory). */
uint8_t *png_encode(const uint8_t *rgb, uint32_t w, uint32_t h, size_t *len);
/* The same for pixels of `ch` channels: 1 (grey) or 3 (RGB888). */
uint8_t *png_encode_px(const uint8_t *px, unsigned ch, uint32_t w, uint32_t h, size_t *len);
/* Writes `data:image/png;base64,...` for the image to f. */
void png_data_uri(FILE *f, const uint8_t *rgb, uint32_t w, uint32_t h);

#endif
