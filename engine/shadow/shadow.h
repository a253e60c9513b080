/* shadow.h — what shadow methods share inside the engine: reading a configuration,
 * declaring settings, and the settings several methods take. */
#ifndef OM_SHADOW_H
#define OM_SHADOW_H

#include "../frame/frame.h"

/* Copies c's values into method m's own configuration struct `out` (m->cfg_bytes
 * bytes); OM_E_INVALID, with a message, when c was made for another method. A copy,
 * not a cast: the struct is the method's, the store only bytes. */
om_status om__method_cfg_of(const om_method_cfg *c, const om_method *m, void *out, om_diag *d);

/* A method's configuration struct T must fit the host's store. */
#define OM__CFG_FITS(T) typedef char T##_fits[sizeof(T) <= OM_METHOD_CFG_BYTES ? 1 : -1]

/* One entry of a method's settings: field `field` of its configuration struct T. */
#define OM__SETTING(T, field, name, kind, lo, hi, def, doc) \
    {name, doc, kind, offsetof(T, field), lo, hi, def}

/* The settings of a shadow map's depth test, for methods whose struct T has the field
 * of the same name (sm and rtw take all of them, spsm the map, asm the bias). */
#define OM__SET_MAP(T) \
    OM__SETTING(T, map_size, "map", OM_SETTING_U32, 1, OM_MAX_DIM, 2048, "shadow-map side in texels")
#define OM__SET_BIAS(T) \
    OM__SETTING(T, bias_const, "bias", OM_SETTING_F32, 0, 1e6, 0.01, \
                "constant bias, world units along the light ray (0.01: 1 cm)")
#define OM__SET_SLOPE(T) \
    OM__SETTING(T, bias_slope, "slope", OM_SETTING_F32, 0, 1e3, 1.5, \
                "slope-scaled bias in texels: a plane's depth across that many texels")
#define OM__SET_OFFSET(T) \
    OM__SETTING(T, normal_offset, "offset", OM_SETTING_F32, 0, 1e3, 0, "normal offset in texels")
#define OM__SET_PCF(T) \
    OM__SETTING(T, pcf, "pcf", OM_SETTING_U32, 1, 9, 1, "k x k percentage-closer filtering, 1 = off")

/* The pool of an irregular z-buffer, for izb and hybrid, whose struct T holds it at `f`
 * (a field designator). */
#define OM__SET_IZB_POOL(T, f) \
    OM__SETTING(T, f, "izb.pool", OM_SETTING_U32, 0, 1e9, 0, \
                "samples the pool holds, 0 = izb: n^2/2^20 for n triangles, 32768 to the frame; hybrid: the frame, at most 2 a triangle (32768..262144)")

#endif
