/* imgfile.c — see imgfile.h. */
#include "imgfile.h"
#include "png.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

/* Whether path ends in ext (".png"), in any case. */
static bool ends_in(const char *path, const char *ext)
{
    size_t n = strlen(path), k = strlen(ext);
    if (n <= k || path[n - k - 1] == '/') return false;   /* ".png" alone is no name */
    for (size_t i = 0; i < k; i++)
        if (tolower((unsigned char)path[n - k + i]) != ext[i]) return false;
    return true;
}

int img_fmt_of(const char *cmd, const char *flag, const char *path, unsigned accept, const char *accepted,
               img_fmt *out)
{
    static const struct { const char *ext; unsigned bit; img_fmt fmt; } kinds[] = {
        {".ppm", IMG_ACCEPT_PPM, IMG_PPM}, {".pgm", IMG_ACCEPT_PGM, IMG_PGM}, {".png", IMG_ACCEPT_PNG, IMG_PNG},
    };
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
        if (ends_in(path, kinds[i].ext)) {
            if (!(accept & kinds[i].bit)) {
                fprintf(stderr, "ombra %s: %s '%s': %s does not write %s files; name it %s\n(see 'ombra %s --help')\n",
                        cmd, flag, path, flag, kinds[i].ext, accepted, cmd);
                return 2;
            }
            *out = kinds[i].fmt;
            return 0;
        }
    if (path[0] && om_out_is_direct(path)) {
        *out = IMG_NETPBM;
        return 0;
    }
    const char *base = strrchr(path, '/'), *dot;
    base = base ? base + 1 : path;
    dot = strrchr(base, '.');
    if (dot && dot != base && dot[1])
        fprintf(stderr, "ombra %s: %s '%s': unknown extension '%s'; %s writes %s ('-' for standard output)\n",
                cmd, flag, path, dot, flag, accepted);
    else
        fprintf(stderr, "ombra %s: %s '%s': no extension to choose the format by; %s writes %s ('-' for "
                "standard output)\n", cmd, flag, path, flag, accepted);
    fprintf(stderr, "(see 'ombra %s --help')\n", cmd);
    return 2;
}

static om_status out_of_memory(const om_out *o, om_diag *d)
{
    if (d) {
        d->status = OM_E_BUDGET;
        snprintf(d->msg, sizeof d->msg, "%s: out of memory", o->path ? o->path : "-");
    }
    return OM_E_BUDGET;
}

om_status img_put(om_out *o, img_fmt fmt, const uint8_t *px, unsigned ch, uint32_t w, uint32_t h,
                  om_diag *d)
{
    const size_t n = (size_t)w * h;
    if (fmt == IMG_NETPBM) fmt = ch == 1 ? IMG_PGM : IMG_PPM;
    if (fmt == IMG_PNG) {
        size_t len;
        uint8_t *png = png_encode_px(px, ch, w, h, &len);
        if (!png) return out_of_memory(o, d);
        om_out_write(o, png, len);
        free(png);
    } else if (fmt == IMG_PGM || ch == 3) {
        if (fmt == IMG_PGM && ch != 1) return OM_E_INVALID;   /* no grey of a colour image here */
        char hdr[64];
        int k = snprintf(hdr, sizeof hdr, "P%c\n%u %u\n255\n", fmt == IMG_PGM ? '5' : '6', w, h);
        if (om_out_write(o, hdr, (size_t)k)) om_out_write(o, px, n * ch);
    } else {
        /* grey as a PPM: each value three times, a row at a time */
        uint8_t *row = malloc((size_t)w * 3);
        if (!row) return out_of_memory(o, d);
        char hdr[64];
        int k = snprintf(hdr, sizeof hdr, "P6\n%u %u\n255\n", w, h);
        bool ok = om_out_write(o, hdr, (size_t)k);
        for (uint32_t y = 0; ok && y < h; y++) {
            for (uint32_t x = 0; x < w; x++) row[3 * x] = row[3 * x + 1] = row[3 * x + 2] = px[(size_t)y * w + x];
            ok = om_out_write(o, row, (size_t)w * 3);
        }
        free(row);
    }
    return om_out_failed(o, d);
}

om_status img_write(const char *path, img_fmt fmt, const uint8_t *px, unsigned ch, uint32_t w, uint32_t h,
                    om_diag *d)
{
    om_out o;
    om_status st = om_out_open(&o, path, d);
    if (st != OM_OK) return st;
    if ((st = img_put(&o, fmt, px, ch, w, h, d)) != OM_OK) {
        om_out_discard(&o);
        return st;
    }
    om_out *outs[1] = {&o};
    return om_out_commit(outs, 1, d);
}
