/* imgfile.h — the format an image file is written in, chosen by its name's
 * extension (.ppm, .pgm, .png), and writing a whole image in it. The commands refuse
 * a name whose extension they do not write, so a file is what its name says. */
#ifndef OM_IMGFILE_H
#define OM_IMGFILE_H

#include "cli.h"

typedef enum img_fmt {
    IMG_NETPBM = 0,   /* no extension, written directly ("-", /dev/..., a FIFO): as ever */
    IMG_PPM,          /* binary PPM (P6), RGB */
    IMG_PGM,          /* binary PGM (P5), grey */
    IMG_PNG           /* PNG, RGB or grey (stored deflate, tools/png.c) */
} img_fmt;

#define IMG_ACCEPT_PPM 1u
#define IMG_ACCEPT_PGM 2u
#define IMG_ACCEPT_PNG 4u

/* The format `path`, given to option `flag` of command `cmd`, names by its extension
 * (any case), among those `accept` allows (`accepted` says them in words, e.g. ".ppm or
 * .png"). A name without such an extension is refused, unless it is written directly
 * (om_out_is_direct: "-", /dev/..., /proc/..., a FIFO): that one is IMG_NETPBM. On a
 * refusal prints a usage error naming the option, the file and what is accepted, and
 * returns 2; else 0. */
int img_fmt_of(const char *cmd, const char *flag, const char *path, unsigned accept, const char *accepted,
               img_fmt *out);

/* Writes w x h pixels of `ch` channels (1 grey, 3 RGB888) into o as fmt: PPM (grey
 * widened to RGB), PGM (grey only) or PNG; IMG_NETPBM is PGM for grey, PPM for RGB.
 * OM_E_IO naming the file on a failed write, OM_E_BUDGET when memory runs out. */
om_status img_put(om_out *o, img_fmt fmt, const uint8_t *px, unsigned ch, uint32_t w, uint32_t h,
                  om_diag *d);
/* The same into the file at path, which replaces the old one only once whole. */
om_status img_write(const char *path, img_fmt fmt, const uint8_t *px, unsigned ch, uint32_t w, uint32_t h,
                    om_diag *d);

#endif
