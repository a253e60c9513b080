/* shade.c — the geometric half of the lit rule, Lambert + ambient shading, and the
 * pixel formats of small devices. Shading is a light level in float with no
 * contraction, rounded to 256ths, times the material's 8-bit colour in integers, so it
 * is bit-identical on every CPU. */
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
 * whose bits an ARM comparison takes as an immediate. */
static uint32_t round_clamped(float v, uint32_t hi)   /* hi: 255 or 256 */
{
    union { float f; int32_t i; } b;
    b.f = v + 0.5f;
    return b.i <= 0 ? 0u : b.i >= 0x43800000 /* 256.0f */ ? hi : (uint32_t)b.f;
}

/* A material's channel in 8 bits (0..1 to 0..255). */
static uint32_t to8(float v)
{
    return round_clamped(v * 255.0f, 255u);
}

/* A light level in 256ths, 0..256 (at 256 a channel keeps its value). */
static uint32_t level(float v256)
{
    return round_clamped(v256, 256u);
}

/* An 8-bit channel c under light level l, rounded: at most 255. */
static uint8_t lit8(uint32_t c, uint32_t l)
{
    return (uint8_t)((c * l + 128u) >> 8);
}

/* In line with a constant format (shade_row's callers): the switch then goes. A
 * 16-bit pixel is stored as one little-endian word where the target is little-endian
 * and the compiler has the builtin (one store rather than two), else byte by byte:
 * the same bytes. */
static inline void put(om_format f, uint8_t *px, uint8_t r, uint8_t g, uint8_t b)
{
    switch (f) {
    case OM_RGB888: px[0] = r; px[1] = g; px[2] = b; break;
    case OM_RGB565: {   /* little-endian 16-bit word: r in the top 5 bits */
        const uint16_t w = (uint16_t)(((r >> 3) << 11) | ((g >> 2) << 5) | (b >> 3));
#if defined(__GNUC__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
        __builtin_memcpy(px, &w, 2);
#else
        px[0] = (uint8_t)(w & 0xFF);
        px[1] = (uint8_t)(w >> 8);
#endif
        break;
    }
    default: px[0] = (uint8_t)((77u * r + 150u * g + 29u * b + 128u) >> 8); break;
    }
}

/* One row of the strip into the framebuffer row `px`, `bpp` bytes a pixel. A pixel
 * is its material's colour in 8 bits times its light level in 256ths: the ambient
 * share plus the direct share times the cosine the exposure marks kept in the sample
 * (nl, om__exposed) times the term; one float rounding per level (a grey term's serves
 * all three channels) and integer products per channel. A blocked term adds k * 0 = 0
 * to the ambient light (k is finite), so it is skipped. What is the same for many
 * pixels is worked out once: the background's pixel, the material of the last
 * triangle in 8 bits, and the pixel of the last material drawn with ambient light
 * alone. The scene's values sit in locals: the pixels' byte stores may alias them,
 * and the compiler would load them again per pixel. */
OM_INLINE void shade_row(const om_scene *s, const om_shade_cfg *c, const om_sample *smp,
                          const om_term *t, uint32_t width, om_format f, uint32_t bpp, uint8_t *px)
{
    uint8_t bg[3], dark[3] = {0, 0, 0};
    put(f, bg, c->bg_r, c->bg_g, c->bg_b);
    const float amb256 = c->ambient * 256.0f, k256 = (1.0f - c->ambient) * (256.0f / 255.0f);
    const uint32_t amb = level(amb256);
    const uint16_t *tri_mat = s->tri_mat;
    const om_material *mats = s->mats;
    uint32_t dark_mat = UINT32_MAX, tri = OM_NO_TRI, mi = UINT32_MAX, mr = 0, mg = 0, mb = 0;
    for (uint32_t x = 0; x < width; x++, smp++, t++, px += bpp) {
        if (smp->tri != tri) {
            tri = smp->tri;
            if (tri != OM_NO_TRI && tri_mat[tri] != mi) {
                mi = tri_mat[tri];
                mr = to8(mats[mi].r);
                mg = to8(mats[mi].g);
                mb = to8(mats[mi].b);
            }
        }
        if (tri == OM_NO_TRI) {
            for (uint32_t k = 0; k < bpp; k++) px[k] = bg[k];
            continue;
        }
        if ((t->flags & OM_TERM_EXPOSED) && (t->r | t->g | t->b)) {
            const float k = smp->nl * k256;
            const uint32_t lr = level(amb256 + k * (float)t->r);
            uint32_t lg = lr, lb = lr;
            if (t->g != t->r || t->b != t->r) {
                lg = level(amb256 + k * (float)t->g);
                lb = level(amb256 + k * (float)t->b);
            }
            put(f, px, lit8(mr, lr), lit8(mg, lg), lit8(mb, lb));
            continue;
        }
        if (mi != dark_mat) {
            dark_mat = mi;
            put(f, dark, lit8(mr, amb), lit8(mg, amb), lit8(mb, amb));
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
