/* shade.c — the geometric half of the lit rule, Lambert + ambient shading, and the
 * pixel formats of small devices. Shading is float arithmetic with no contraction and
 * one rounding to 8 bits, so it is bit-identical on every CPU. */
#include "frame.h"

om_vec3 om__to_light(const om_view *v, om_vec3 p)
{
    if (v->light.kind == OM_LIGHT_DIRECTIONAL) return om__scale(v->light_axis, -1.0f);
    return om__to_point(v->light.pos, p);
}

bool om__exposed(const om_scene *s, const om_view *v, om_sample *smp)
{
    const om_vec3 anchor = om__sub(s->verts[s->idx[(size_t)smp->tri * 3]], v->origin);
    return om__exposed_at(v, om__v3(smp->p[0], smp->p[1], smp->p[2]),
                          om__v3(smp->n[0], smp->n[1], smp->n[2]), anchor, &smp->nl);
}

void om_shade_cfg_default(om_shade_cfg *c)
{
    if (!c) return;
    c->ambient = 0.25f;
    c->bg_r = 36;
    c->bg_g = 44;
    c->bg_b = 60;
}

uint32_t om_format_bpp(om_format f)
{
    return f == OM_RGB888 ? 3u : f == OM_RGB565 ? 2u : 1u;
}

/* The clamps compare the float's bits as an integer, which orders non-negative
 * floats as their values (and puts every negative one, -0 too, at or below 0): the
 * same answers as float comparisons for the finite values shading makes, without a
 * transfer of the float unit's flags per comparison. The upper one is at 256.0f,
 * whose bits an ARM comparison takes as an immediate (255.0f's it must load): below
 * it the truncation of 255.x is 255 anyway. */
static uint8_t to8(float v)
{
    union { float f; int32_t i; } b;
    b.f = v * 255.0f + 0.5f;
    return b.i <= 0 ? 0 : b.i >= 0x43800000 /* 256.0f */ ? 255 : (uint8_t)b.f;
}

/* In line with a constant format (shade_row's callers): the switch then goes. */
static inline void put(om_format f, uint8_t *px, uint8_t r, uint8_t g, uint8_t b)
{
    switch (f) {
    case OM_RGB888: px[0] = r; px[1] = g; px[2] = b; break;
    case OM_RGB565: {   /* little-endian 16-bit word: r in the top 5 bits */
        uint16_t w = (uint16_t)(((r >> 3) << 11) | ((g >> 2) << 5) | (b >> 3));
        px[0] = (uint8_t)(w & 0xFF);
        px[1] = (uint8_t)(w >> 8);
        break;
    }
    default: px[0] = (uint8_t)((77u * r + 150u * g + 29u * b + 128u) >> 8); break;
    }
}

/* One row of the strip into the framebuffer row `px`, `bpp` bytes a pixel. The cosine
 * is the one the exposure marks kept in the sample (om__exposed), the same bits as
 * working it out here. A blocked term adds k * 0 = 0 to the ambient light (k is
 * finite), so it is skipped. What is the same for many pixels is worked out once:
 * the background's pixel, the light of a grey term (one channel's operations give
 * all three), and the pixel of the last material drawn with ambient light alone,
 * which depends on the material only. */
static inline void shade_row(const om_scene *s, const om_shade_cfg *c, const om_sample *smp,
                             const om_term *t, uint32_t width, om_format f, uint32_t bpp, uint8_t *px)
{
    uint8_t bg[3], dark[3] = {0, 0, 0};
    put(f, bg, c->bg_r, c->bg_g, c->bg_b);
    const float amb = c->ambient, direct = 1.0f - c->ambient;
    uint32_t dark_mat = UINT32_MAX;
    for (uint32_t x = 0; x < width; x++, smp++, t++, px += bpp) {
        if (smp->tri == OM_NO_TRI) {
            for (uint32_t k = 0; k < bpp; k++) px[k] = bg[k];
            continue;
        }
        const uint32_t mi = s->tri_mat[smp->tri];
        const om_material *m = &s->mats[mi];
        if ((t->flags & OM_TERM_EXPOSED) && (t->r | t->g | t->b)) {
            const float k = smp->nl * direct * (1.0f / 255.0f);
            const float lr = amb + k * (float)t->r;
            float lg = lr, lb = lr;
            if (t->g != t->r || t->b != t->r) {
                lg = amb + k * (float)t->g;
                lb = amb + k * (float)t->b;
            }
            put(f, px, to8(m->r * lr), to8(m->g * lg), to8(m->b * lb));
            continue;
        }
        if (mi != dark_mat) {
            dark_mat = mi;
            put(f, dark, to8(m->r * amb), to8(m->g * amb), to8(m->b * amb));
        }
        for (uint32_t k = 0; k < bpp; k++) px[k] = dark[k];
    }
}

void om__shade_strip(const om_scene *s, const om_view *v, const om_shade_cfg *c,
                     const om_strip *st, om_framebuffer *fb)
{
    (void)v;   /* the light's direction is in the samples (nl) */
    const uint32_t bpp = om_format_bpp(fb->format);
    for (uint32_t y = 0; y < st->rows; y++) {
        const size_t i = (size_t)y * st->width;
        uint8_t *row = fb->pixels + (size_t)y * fb->stride;
        switch (fb->format) {
        case OM_RGB888: shade_row(s, c, st->samples + i, st->terms + i, st->width, OM_RGB888, 3, row); break;
        case OM_RGB565: shade_row(s, c, st->samples + i, st->terms + i, st->width, OM_RGB565, 2, row); break;
        default: shade_row(s, c, st->samples + i, st->terms + i, st->width, fb->format, bpp, row); break;
        }
    }
}
