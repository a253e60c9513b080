/* parse.c — the scene text format (see om_scene_parse in ombra.h and the grammar in
 * FORMAT.md): the commands and the two passes over the text (parameters, their ranges
 * and the messages are params.c's).
 * The first pass validates every line and counts what it will produce (om_scene_bytes
 * stops there), so every error comes with a line and column before any memory is
 * carved; the second pass runs the very same code with a sink that writes into arrays
 * carved once, at their exact sizes. Lines, tokens and numbers are lex.c's; camera and
 * light paths are paths.c's. */
#include "parse.h"

#include <math.h>
#include <string.h>

enum {
    C_CAMERA, C_LIGHT, C_MATERIAL, C_PLANE, C_BOX, C_SPHERE, C_CYLINDER, C_MESH,
    C_TRIANGLES, C_KEY, C_COPY, C_N_
};
static const char *const cmd_names[C_N_] = {
    "camera", "light", "material", "plane", "box", "sphere", "cylinder", "mesh",
    "triangles", "key", "copy",
};

/* The parameters each command takes. */
#define COMMON_PARAMS P_SCALE, P_ROTATE, P_TRANSLATE, P_ALBEDO, P_OPACITY, P_MATERIAL, P_NAME
static const uint8_t cam_params[] = {P_EYE, P_TARGET, P_UP, P_FOV, P_SIZE, P_NEAR, P_FAR};
static const uint8_t spot_params[] = {P_POS, P_TARGET, P_FOV, P_NEAR, P_FAR};
static const uint8_t dir_params[] = {P_DIR};
static const uint8_t mat_params[] = {P_ALBEDO, P_OPACITY};
static const uint8_t plane_params[] = {P_SIZE2, P_DIVISIONS, COMMON_PARAMS};
static const uint8_t box_params[] = {P_SIZE3, COMMON_PARAMS};
static const uint8_t sphere_params[] = {P_RADIUS, P_SEGMENTS, P_RINGS, COMMON_PARAMS};
static const uint8_t cyl_params[] = {P_RADIUS, P_HEIGHT, P_SEGMENTS, COMMON_PARAMS};
static const uint8_t mesh_params[] = {COMMON_PARAMS};
static const uint8_t tris_params[] = {P_COUNT, P_SEED, P_AREA, P_IN, COMMON_PARAMS};
static const uint8_t keycam_params[] = {P_EYE, P_TARGET};
static const uint8_t keylight_params[] = {P_POS, P_TARGET, P_DIR};
static const uint8_t keyobj_params[] = {P_TRANSLATE, P_ROTATE, P_SCALE1};
static const uint8_t copy_params[] = {COMMON_PARAMS};
#define NP(a) (sizeof(a) / sizeof((a)[0]))

/* ---------------------------------------------------------------- camera and light */

static void default_camera(om_camera *c)
{
    memset(c, 0, sizeof *c);
    c->eye = om__v3(0, 5, 15);
    c->target = om__v3(0, 0, 0);
    c->up = om__v3(0, 1, 0);
    c->fovy_deg = 50.0f;
    c->width = 640;
    c->height = 480;
    c->znear = 0.1f;
    c->zfar = 1000.0f;
}

static void default_light(om_light *l)
{
    memset(l, 0, sizeof *l);
    l->kind = OM_LIGHT_SPOT;
    l->pos = om__v3(10, 20, 10);
    l->target = om__v3(0, 0, 0);
    l->dir = om__normalize(om__sub(l->target, l->pos));
    l->fov_deg = 60.0f;
    l->znear = 0.5f;
    l->zfar = 1000.0f;
}

static om_status do_camera(parser *p)
{
    pv pl[P_N_];
    om_status st;
    if (p->have_cam) return om__parse_second_line(p, "camera", p->cam_line);
    if ((st = om__parse_params(p, "camera", cam_params, NP(cam_params), pl)) != OM_OK) return st;
    if (!pl[P_EYE].has || !pl[P_TARGET].has) return om__parse_missing(p, "camera", "eye X Y Z and target X Y Z");
    om_camera c;
    default_camera(&c);
    c.eye = pv3(&pl[P_EYE], 0);
    c.target = pv3(&pl[P_TARGET], 0);
    if (pl[P_UP].has) c.up = pv3(&pl[P_UP], 0);
    c.fovy_deg = (float)val(pl, P_FOV, 0, 50.0);
    c.width = (uint32_t)val(pl, P_SIZE, 0, 640.0);
    c.height = (uint32_t)val(pl, P_SIZE, 1, 480.0);
    c.znear = (float)val(pl, P_NEAR, 0, 0.1);
    c.zfar = (float)val(pl, P_FAR, 0, 1000.0);
    if (v3_no_dir(om__sub(c.target, c.eye)))
        return om__parse_fail(p, OM_E_RANGE, pl[P_TARGET].vcol[0], "camera eye and target must differ: their difference gives no direction",
                    NULL, 0, NULL);
    if (v3_zero(c.up))
        return om__parse_fail(p, OM_E_RANGE, pl[P_UP].vcol[0], "'up' must not be zero", NULL, 0, NULL);
    if ((st = om__parse_near_far(p, pl, c.znear, c.zfar)) != OM_OK) return st;
    p->cam = c;
    p->have_cam = true;
    p->cam_line = p->l.no;
    return OM_OK;
}

static om_status do_light(parser *p)
{
    pv pl[P_N_];
    om_status st;
    om__tok t;
    if (p->have_light) return om__parse_second_line(p, "light", p->light_line);
    int r = om__tok_next(&p->l, &t);
    if (r < 0) return om__parse_bad_byte(p, &t);
    bool spot = r > 0 && om__tok_is(p->text, &t, "spot");
    if (!spot && !(r > 0 && om__tok_is(p->text, &t, "directional"))) {
        if (r == 0)
            return om__parse_fail(p, OM_E_PARSE, om__line_end_col(&p->l),
                        "expected 'spot' or 'directional' after 'light'", NULL, 0, NULL);
        return om__parse_fail_tok(p, OM_E_PARSE, &t, "expected 'spot' or 'directional' after 'light', found ",
                        NULL);
    }
    om_light l;
    default_light(&l);
    if (spot) {
        if ((st = om__parse_params(p, "light spot", spot_params, NP(spot_params), pl)) != OM_OK) return st;
        if (!pl[P_POS].has || !pl[P_TARGET].has)
            return om__parse_missing(p, "light spot", "pos X Y Z and target X Y Z");
        l.pos = pv3(&pl[P_POS], 0);
        l.target = pv3(&pl[P_TARGET], 0);
        l.fov_deg = (float)val(pl, P_FOV, 0, 60.0);
        l.znear = (float)val(pl, P_NEAR, 0, 0.5);
        l.zfar = (float)val(pl, P_FAR, 0, 1000.0);
        if (v3_no_dir(om__sub(l.target, l.pos)))
            return om__parse_fail(p, OM_E_RANGE, pl[P_TARGET].vcol[0], "light pos and target must differ: their difference gives no direction",
                        NULL, 0, NULL);
        if ((st = om__parse_near_far(p, pl, l.znear, l.zfar)) != OM_OK) return st;
        l.dir = om__normalize(om__sub(l.target, l.pos));
    } else {
        if ((st = om__parse_params(p, "light directional", dir_params, NP(dir_params), pl)) != OM_OK)
            return st;
        if (!pl[P_DIR].has) return om__parse_missing(p, "light directional", "dir X Y Z");
        l.kind = OM_LIGHT_DIRECTIONAL;
        l.pos = l.target = om__v3(0, 0, 0);
        l.dir = pv3(&pl[P_DIR], 0);
        if (v3_no_dir(l.dir))
            return om__parse_fail(p, OM_E_RANGE, pl[P_DIR].vcol[0], "'dir' must not be zero, nor too short to give a direction", NULL, 0, NULL);
    }
    p->light = l;
    p->have_light = true;
    p->light_line = p->l.no;
    return OM_OK;
}

/* ---------------------------------------------------------------- materials */

static uint32_t name_hash(const char *s, size_t n)
{
    uint32_t h = 2166136261u;
    for (size_t i = 0; i < n; i++) h = (h ^ (unsigned char)s[i]) * 16777619u;
    return h;
}

static void cache_put(parser *p, const om__tok *name, uint32_t ord)
{
    mslot *m = &p->cache[name_hash(p->text + name->at, name->len) % MCACHE];
    m->at = name->at;
    m->len = name->len;
    m->ord = ord;
    m->used = true;
}

/* The ordinal of the latest `material NAME` line before this one. The cache answers
 * most look-ups; a miss reads the earlier lines again (they are known to be valid),
 * which keeps the parser free of any name table it would have to allocate. */
static bool mat_find(parser *p, const om__tok *name, uint32_t *ord)
{
    const char *nm = p->text + name->at;
    const mslot *m = &p->cache[name_hash(nm, name->len) % MCACHE];
    if (m->used && m->len == name->len && memcmp(p->text + m->at, nm, m->len) == 0) {
        *ord = m->ord;
        return true;
    }
    om__line l;
    om__line_init(&l, p->text, p->l.start, false);
    uint32_t n = 0;
    bool found = false;
    while (om__line_next(&l)) {
        om__tok t, w;
        if (om__tok_next(&l, &t) != 1 || !om__tok_is(p->text, &t, "material")) continue;
        if (om__tok_next(&l, &w) == 1 && w.len == name->len && memcmp(p->text + w.at, nm, w.len) == 0) {
            *ord = n;
            found = true;
        }
        n++;
    }
    if (found) cache_put(p, name, *ord);
    return found;
}

static bool valid_name(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        bool alpha = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
        if (!alpha && (i == 0 || !(om__is_digit(c) || c == '.' || c == '-'))) return false;
    }
    return n > 0;
}

static om_status add_material(parser *p)
{
    if (1u + p->nnamed + p->ninline >= 65535u)
        return om__parse_fail(p, OM_E_RANGE, p->cmd.col, "too many materials (a scene has at most 65535)",
                    NULL, 0, NULL);
    return OM_OK;
}

static om_status do_material(parser *p)
{
    pv pl[P_N_];
    om_status st;
    om__tok name;
    int r = om__tok_next(&p->l, &name);
    if (r < 0) return om__parse_bad_byte(p, &name);
    if (r == 0)
        return om__parse_fail(p, OM_E_PARSE, om__line_end_col(&p->l), "expected a name after 'material'",
                    NULL, 0, NULL);
    if (!valid_name(p->text + name.at, name.len))
        return om__parse_fail_tok(p, OM_E_PARSE, &name, "bad material name ",
                        " (a letter or _, then letters, digits, _ . -)");
    if ((st = om__parse_params(p, "material", mat_params, NP(mat_params), pl)) != OM_OK) return st;
    if ((st = add_material(p)) != OM_OK) return st;
    if (p->fill) {
        om_material *m = &p->s->mats[1 + p->nnamed];
        m->r = (float)val(pl, P_ALBEDO, 0, 0.8);
        m->g = (float)val(pl, P_ALBEDO, 1, 0.8);
        m->b = (float)val(pl, P_ALBEDO, 2, 0.8);
        m->opacity = (float)val(pl, P_OPACITY, 0, 1.0);
    }
    cache_put(p, &name, p->nnamed);
    p->nnamed++;
    return OM_OK;
}

/* ---------------------------------------------------------------- objects */

static const struct { const uint8_t *ids; size_t n; } sets[C_N_] = {
    [C_PLANE] = {plane_params, NP(plane_params)},
    [C_BOX] = {box_params, NP(box_params)},
    [C_SPHERE] = {sphere_params, NP(sphere_params)},
    [C_CYLINDER] = {cyl_params, NP(cyl_params)},
    [C_MESH] = {mesh_params, NP(mesh_params)},
    [C_TRIANGLES] = {tris_params, NP(tris_params)},
    [C_COPY] = {copy_params, NP(copy_params)},
};

/* Transform and material of an object from its COMMON parameters. Materials are laid
 * out as [default, named in order of definition, inline in order of appearance]. */
static om_status object_common(parser *p, const pv *pl, om__xform *xf, uint16_t *mat)
{
    double one[3] = {1.0, 1.0, 1.0}, zero[3] = {0.0, 0.0, 0.0};
    om__xform_make(xf, pl[P_SCALE].has ? pl[P_SCALE].v : one,
                   pl[P_ROTATE].has ? pl[P_ROTATE].v : zero,
                   pl[P_TRANSLATE].has ? pl[P_TRANSLATE].v : zero);
    uint32_t m = 0;
    if (pl[P_MATERIAL].has) {
        uint32_t ord;
        const om__tok *w = &pl[P_MATERIAL].w;
        if (!mat_find(p, w, &ord))
            return om__parse_fail_tok(p, OM_E_PARSE, w, "unknown material ",
                            " (define it on a 'material' line above)");
        m = 1 + ord;
    }
    if (pl[P_ALBEDO].has || pl[P_OPACITY].has) {
        om_status st = add_material(p);
        if (st != OM_OK) return st;
        uint32_t own = 1 + p->nnamed_total + p->ninline;
        if (p->fill) {
            om_material *dst = &p->s->mats[own];
            *dst = p->s->mats[m];
            if (pl[P_ALBEDO].has) {
                dst->r = (float)pl[P_ALBEDO].v[0];
                dst->g = (float)pl[P_ALBEDO].v[1];
                dst->b = (float)pl[P_ALBEDO].v[2];
            }
            if (pl[P_OPACITY].has) dst->opacity = (float)pl[P_OPACITY].v[0];
        }
        p->ninline++;
        m = own;
    }
    *mat = (uint16_t)m;
    return OM_OK;
}

static om_status check_totals(parser *p, uint64_t nv, uint64_t nt)
{
    if (p->nv + nv > OM__MAX_ELEMS || p->nt + nt > OM__MAX_ELEMS)
        return om__parse_fail(p, OM_E_RANGE, p->cmd.col,
                    "the scene would have more than 2147483647 vertices or triangles", NULL, 0,
                    NULL);
    return OM_OK;
}

static void shape_counts(int cmd, const pv *pl, uint64_t *nv, uint64_t *nt)
{
    switch (cmd) {
    case C_PLANE: om__plane_counts((uint32_t)val(pl, P_DIVISIONS, 0, 1), nv, nt); break;
    case C_BOX: *nv = 8; *nt = 12; break;
    case C_SPHERE:
        om__sphere_counts((uint32_t)val(pl, P_SEGMENTS, 0, 32), (uint32_t)val(pl, P_RINGS, 0, 16),
                          nv, nt);
        break;
    case C_CYLINDER: om__cylinder_counts((uint32_t)val(pl, P_SEGMENTS, 0, 32), nv, nt); break;
    default: /* C_TRIANGLES */
        *nt = (uint64_t)val(pl, P_COUNT, 0, 0);
        *nv = 3 * *nt;
        break;
    }
}

static void shape_gen(om__sink *k, int cmd, const pv *pl)
{
    static const double in_default[6] = {-5, 0.5, -5, 5, 3, 5};
    switch (cmd) {
    case C_PLANE:
        om__gen_plane(k, val(pl, P_SIZE2, 0, 10), val(pl, P_SIZE2, 1, 10),
                      (uint32_t)val(pl, P_DIVISIONS, 0, 1));
        break;
    case C_BOX:
        om__gen_box(k, val(pl, P_SIZE3, 0, 1), val(pl, P_SIZE3, 1, 1), val(pl, P_SIZE3, 2, 1));
        break;
    case C_SPHERE:
        om__gen_sphere(k, val(pl, P_RADIUS, 0, 1), (uint32_t)val(pl, P_SEGMENTS, 0, 32),
                       (uint32_t)val(pl, P_RINGS, 0, 16));
        break;
    case C_CYLINDER:
        om__gen_cylinder(k, val(pl, P_RADIUS, 0, 0.5), val(pl, P_HEIGHT, 0, 1),
                         (uint32_t)val(pl, P_SEGMENTS, 0, 32));
        break;
    default: /* C_TRIANGLES */
        om__gen_triangles(k, (uint32_t)val(pl, P_COUNT, 0, 0), (uint32_t)val(pl, P_SEED, 0, 1),
                          val(pl, P_AREA, 0, 1), pl[P_IN].has ? pl[P_IN].v : in_default);
        break;
    }
}

/* A box in the shape's own space that holds all its vertices: the transformed corners
 * of it bound the object, so most objects pass the range check without generating. */
static void shape_box(int cmd, const pv *pl, double lo[3], double hi[3])
{
    double r = val(pl, P_RADIUS, 0, cmd == C_SPHERE ? 1.0 : 0.5);
    switch (cmd) {
    case C_PLANE:
        hi[0] = 0.5 * val(pl, P_SIZE2, 0, 10); hi[1] = 0.0; hi[2] = 0.5 * val(pl, P_SIZE2, 1, 10);
        break;
    case C_BOX:
        for (int i = 0; i < 3; i++) hi[i] = 0.5 * val(pl, P_SIZE3, i, 1);
        break;
    case C_SPHERE: hi[0] = hi[1] = hi[2] = r; break;
    case C_CYLINDER: hi[0] = hi[2] = r; hi[1] = val(pl, P_HEIGHT, 0, 1); break;
    default: { /* C_TRIANGLES: the `in` box widened by a triangle's circumradius */
        static const double in_default[6] = {-5, 0.5, -5, 5, 3, 5};
        const double *in = pl[P_IN].has ? pl[P_IN].v : in_default;
        double R = sqrt(4.0 * val(pl, P_AREA, 0, 1) / val(pl, P_COUNT, 0, 1) / (3.0 * 1.7320508075688772));
        for (int i = 0; i < 3; i++) { lo[i] = in[i] - R; hi[i] = in[i + 3] + R; }
        return;
    }
    }
    for (int i = 0; i < 3; i++) lo[i] = cmd == C_CYLINDER && i == 1 ? 0.0 : -hi[i];
}

static bool box_inside(const om__xform *xf, const double lo[3], const double hi[3])
{
    /* A margin far above rounding keeps the shortcut on the safe side. */
    const double lim = OM__COORD_MAX * (1.0 - 1e-9);
    for (int c = 0; c < 8; c++) {
        double q[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        for (int r = 0; r < 3; r++) {
            const double *m = xf->m + 4 * r;
            double v = m[0] * q[0] + m[1] * q[1] + m[2] * q[2] + m[3];
            if (!(fabs(v) <= lim)) return false;
        }
    }
    return true;
}

static om_status out_of_range(parser *p, const char *what)
{
    char tmp[4];
    om__str s = om__parse_fail_begin(p, OM_E_RANGE, p->cmd.col, tmp, sizeof tmp);
    om__str_s(&s, what);
    om__str_s(&s, " reaches beyond 1e7 in some coordinate after its scale, rotate and translate");
    return OM_E_RANGE;
}

/* A mesh's file: loaded through the host's loader in both passes (the engine keeps no
 * pointer between calls), read by obj.c into a counting or the writing sink. */
static om_status do_mesh(parser *p, const om__tok *file, const char *name, const om__xform *xf,
                         uint16_t mat)
{
    om_diag *d = p->d;
    if (!p->ld || !p->ld->load)
        return om__parse_fail(p, OM_E_NOTFOUND, file->col, "mesh ", name, file->len,
                    ": no file loader was given to read it");
    const char *data = NULL;
    size_t dlen = 0;
    if (d) d->msg[0] = '\0';
    om_status st = p->ld->load(p->ld->user, name, &data, &dlen);
    if (st == OM_OK && !data && dlen) st = OM_E_INVALID;
    if (st != OM_OK) {
        /* Keep the loader's own words (it may name the path and the system's reason). */
        char why[sizeof d->msg];
        why[0] = '\0';
        if (d) memcpy(why, d->msg, sizeof why);
        why[sizeof why - 1] = '\0';
        char tmp[4];
        om__str s = om__parse_fail_begin(p, st, file->col, tmp, sizeof tmp);
        om__str_s(&s, "cannot load mesh ");
        om__str_tok(&s, name, file->len);
        om__str_s(&s, ": ");
        om__str_s(&s, why[0] ? why : om_status_str(st));
        return st;
    }
    if (p->fill) {
        uint64_t nv0 = p->out.nv, nt0 = p->out.nt;
        om__sink_begin(&p->out, xf, mat);
        if ((st = om__obj_run(data, dlen, name, p->l.no, &p->out, d)) != OM_OK) return st;
        if (p->out.out_of_range)   /* passed the first pass: the file has changed since */
            return om__parse_fail(p, OM_E_INVALID, file->col, "mesh ", name, file->len,
                        " changed between the counting and filling passes");
        p->nv += p->out.nv - nv0;
        p->nt += p->out.nt - nt0;
        return OM_OK;
    }
    om__sink k;
    om__sink_init(&k, false);
    om__sink_begin(&k, xf, mat);
    if ((st = om__obj_run(data, dlen, name, p->l.no, &k, d)) != OM_OK) return st;
    if (k.out_of_range) {
        char tmp[4];
        om__str s = om__parse_fail_begin(p, OM_E_RANGE, p->cmd.col, tmp, sizeof tmp);
        om__str_s(&s, "mesh ");
        om__str_tok(&s, name, file->len);
        om__str_s(&s, " reaches beyond 1e7 after its transform (vertex on OBJ line ");
        om__str_u(&s, k.where);
        om__str_s(&s, ")");
        return OM_E_RANGE;
    }
    if ((st = check_totals(p, k.nv, k.nt)) != OM_OK) return st;
    p->nv += k.nv;
    p->nt += k.nt;
    return OM_OK;
}

/* Second pass: records the closed shape just generated, triangles [first, first + nt),
 * with the box of its vertices (the shape's own, base .. nv of the sink). */
static void add_solid(parser *p, uint64_t first, uint64_t nt)
{
    const om__sink *k = &p->out;
    om_scene *s = p->s;
    if (p->nsolids >= s->nsolids || k->overflow || k->nv > k->vcap || k->base >= k->nv) return;
    om_solid *o = &s->solids[p->nsolids];
    o->first = (uint32_t)first;
    o->count = (uint32_t)nt;
    o->lo = o->hi = k->verts[k->base];
    for (uint64_t i = k->base + 1; i < k->nv; i++) {
        om_vec3 v = k->verts[i];
        o->lo = om__v3(fminf(o->lo.x, v.x), fminf(o->lo.y, v.y), fminf(o->lo.z, v.z));
        o->hi = om__v3(fmaxf(o->hi.x, v.x), fmaxf(o->hi.y, v.y), fmaxf(o->hi.z, v.z));
    }
}

/* ---------------------------------------------------------------- named objects */

static int cmd_of(const char *text, const om__tok *t)
{
    for (int i = 0; i < C_N_; i++)
        if (om__tok_is(text, t, cmd_names[i])) return i;
    return -1;
}

static bool tok_eq(const char *text, const om__tok *t, const char *nm, size_t n)
{
    return t->len == n && memcmp(text + t->at, nm, n) == 0;
}

static void common_xform(const pv *pl, om__xform *xf)
{
    double one[3] = {1.0, 1.0, 1.0}, zero[3] = {0.0, 0.0, 0.0};
    om__xform_make(xf, pl[P_SCALE].has ? pl[P_SCALE].v : one,
                   pl[P_ROTATE].has ? pl[P_ROTATE].v : zero,
                   pl[P_TRANSLATE].has ? pl[P_TRANSLATE].v : zero);
}

/* How far a copy's vertices can reach: its transform moves a point of the mesh at
 * distance r at most by the largest scale times r plus the translation. */
static double copy_radius(const pv *pl, double r)
{
    double sm = 1.0, t = 0.0;
    if (pl[P_SCALE].has)
        sm = fmax(fabs(pl[P_SCALE].v[0]), fmax(fabs(pl[P_SCALE].v[1]), fabs(pl[P_SCALE].v[2])));
    if (pl[P_TRANSLATE].has)
        for (int i = 0; i < 3; i++) t += pl[P_TRANSLATE].v[i] * pl[P_TRANSLATE].v[i];
    return sm * r + sqrt(t);
}

/* A named shape or mesh line's mesh: counts and reach, from a counting sink. */
static om_status measure(parser *p, int cmd, const pv *pl, const char *file, oinfo *o)
{
    om__xform xf;
    common_xform(pl, &xf);
    om__sink k;
    om__sink_init(&k, false);
    om__sink_begin(&k, &xf, 0);
    if (cmd == C_MESH) {
        const char *data = NULL;
        size_t dlen = 0;
        om_status st = p->ld && p->ld->load ? p->ld->load(p->ld->user, file, &data, &dlen) : OM_E_NOTFOUND;
        if (st != OM_OK) return st;
        if ((st = om__obj_run(data, dlen, file, p->l.no, &k, NULL)) != OM_OK) return st;
    } else {
        shape_gen(&k, cmd, pl);
    }
    o->nv = k.nv;
    o->nt = k.nt;
    o->radius = sqrt(k.r2);
    o->closed = cmd == C_BOX || cmd == C_SPHERE || cmd == C_CYLINDER;
    return OM_OK;
}

static oinfo *ocache_slot(parser *p, const char *nm, size_t n)
{
    return &p->ocache[name_hash(nm, n) % OCACHE];
}

static bool obj_find(parser *p, const char *nm, size_t n, oinfo *out);

/* A line above, read for its object without reading its numbers (the lines above are
 * known to be valid): whether it makes an object, and the names it gives. */
typedef struct oline {
    int cmd;
    bool object;           /* a named shape or mesh line, or a copy */
    om__tok name, src;     /* its name (len 0: none); a copy's source */
} oline;

static void oline_read(const char *text, om__line *l, int cmd, oline *o)
{
    om__tok t;
    memset(o, 0, sizeof *o);
    o->cmd = cmd;
    if ((cmd == C_MESH || cmd == C_COPY) && om__tok_next(l, &t) == 1) o->src = t;   /* file or source */
    /* words follow only 'material' and 'name' (their values); everything else is a
     * parameter's name or a number */
    while (om__tok_next(l, &t) == 1) {
        const bool mat = om__tok_is(text, &t, "material"), nm = om__tok_is(text, &t, "name");
        if (!mat && !nm) continue;
        om__tok v;
        if (om__tok_next(l, &v) != 1) break;
        if (nm) o->name = v;
    }
    o->object = cmd == C_COPY || o->name.len > 0;
}

/* Where the object named nm is named in the lines above the current one (the light
 * read: no numbers), its index and, unless a copy names it, its mesh's; and its keys.
 * false: no line names it. */
typedef struct odef {
    uint32_t ord, mesh, no;   /* mesh: for a copy, its source's (found by obj_scan) */
    size_t start;             /* the naming line */
    uint32_t nkeys, last_line;
    float last_t, last_scale;
} odef;

static bool obj_def(parser *p, const char *nm, size_t n, odef *out)
{
    om__line l;
    om__line_init(&l, p->text, p->l.start, false);
    uint32_t ord = 0, mesh = 0;
    bool found = false;
    memset(out, 0, sizeof *out);
    while (om__line_next(&l)) {
        om__tok t, a, w;
        if (om__tok_next(&l, &t) != 1) continue;
        const int cmd = cmd_of(p->text, &t);
        if (cmd == C_KEY) {
            if (!found || om__tok_next(&l, &a) != 1 || !om__tok_is(p->text, &a, "object") ||
                om__tok_next(&l, &w) != 1 || !tok_eq(p->text, &w, nm, n))
                continue;
            parser q;
            memset(&q, 0, sizeof q);
            q.text = p->text;
            q.len = p->len;
            q.l = l;
            pv pl[P_N_];
            double T;
            uint32_t col;
            if (om__parse_value(&q, "key object", K_NUM, R_COORD, 1, &T, &col) != OM_OK ||
                om__parse_params(&q, "key object", keyobj_params, NP(keyobj_params), pl) != OM_OK)
                continue;
            out->nkeys++;
            out->last_t = (float)T;
            out->last_line = l.no;
            out->last_scale = (float)val(pl, P_SCALE1, 0, 1.0);
            continue;
        }
        if (cmd < C_PLANE) continue;
        oline o;
        oline_read(p->text, &l, cmd, &o);
        if (!o.object) continue;
        if (!found && o.name.len && tok_eq(p->text, &o.name, nm, n)) {
            out->ord = ord;
            out->mesh = mesh;
            out->start = l.start;
            out->no = l.no;
            found = true;
        }
        ord++;
        if (cmd != C_COPY) mesh++;
    }
    return found;
}

/* What the parser needs of the object named nm (obj_def), and of its mesh: through
 * the chain of copies it may be a copy of, to the line that made the mesh. A copy's
 * reach is its largest scale times its source's plus its move's length, so along the
 * chain reach = A * (the mesh's) + B. Each source is named above its copy: the walk
 * ends. Only the lines of the chain are parsed whole. */
static bool obj_scan(parser *p, const char *nm, size_t n, oinfo *out)
{
    odef def;
    if (!obj_def(p, nm, n, &def)) return false;
    memset(out, 0, sizeof *out);
    out->len = n;
    out->used = true;
    out->ord = def.ord;
    out->line = def.no;
    out->nkeys = def.nkeys;
    out->last_t = def.last_t;
    out->last_line = def.last_line;
    out->last_scale = def.last_scale;
    double A = 1.0, B = 0.0;
    odef at = def;
    for (;;) {
        parser q;
        memset(&q, 0, sizeof q);
        q.text = p->text;
        q.len = p->len;
        q.ld = p->ld;
        om__line_init(&q.l, p->text, p->len, false);
        q.l.next = at.start;
        q.l.no = at.no - 1;
        om__tok t, src;
        if (!om__line_next(&q.l) || om__tok_next(&q.l, &t) != 1) return false;
        const int cmd = cmd_of(p->text, &t);
        if (cmd < C_PLANE || cmd == C_KEY) return false;
        char file[256];
        if (cmd == C_MESH || cmd == C_COPY) {
            if (om__tok_next(&q.l, &src) != 1 || src.len >= sizeof file) return false;
            memcpy(file, p->text + src.at, src.len);
            file[src.len] = '\0';
        }
        pv pl[P_N_];
        if (om__parse_params(&q, cmd_names[cmd], sets[cmd].ids, sets[cmd].n, pl) != OM_OK) return false;
        if (at.start == def.start) out->at = pl[P_NAME].w.at;
        if (cmd != C_COPY) {
            oinfo m;
            memset(&m, 0, sizeof m);
            if (measure(&q, cmd, pl, file, &m) != OM_OK) return false;
            out->mesh = at.mesh;
            out->nv = m.nv;
            out->nt = m.nt;
            out->closed = m.closed;
            out->radius = A * m.radius + B;
            return true;
        }
        const double b0 = copy_radius(pl, 0.0);
        B += A * b0;
        A *= copy_radius(pl, 1.0) - b0;
        const oinfo *c = ocache_slot(p, p->text + src.at, src.len);
        if (c->used && tok_eq(p->text, &src, p->text + c->at, c->len)) {   /* the source known */
            out->mesh = c->mesh;
            out->nv = c->nv;
            out->nt = c->nt;
            out->closed = c->closed;
            out->radius = A * c->radius + B;
            return true;
        }
        odef up;   /* the source, named above its copy */
        if (!obj_def(p, p->text + src.at, src.len, &up) || up.start >= at.start) return false;
        at = up;
    }
}

static bool obj_find(parser *p, const char *nm, size_t n, oinfo *out)
{
    oinfo *c = ocache_slot(p, nm, n);
    if (c->used && c->len == n && memcmp(p->text + c->at, nm, n) == 0) {
        *out = *c;
        return true;
    }
    if (!obj_scan(p, nm, n, out)) return false;
    *c = *out;
    return true;
}

/* A name given on this line must be new. */
static om_status name_check(parser *p, const pv *pl)
{
    /* the second pass reads the text the first one found unique */
    if (!pl[P_NAME].has || p->fill) return OM_OK;
    const om__tok *w = &pl[P_NAME].w;
    if (!valid_name(p->text + w->at, w->len))
        return om__parse_fail_tok(p, OM_E_PARSE, w, "bad object name ",
                                  " (a letter or _, then letters, digits, _ . -)");
    oinfo o;
    const uint32_t h = name_hash(p->text + w->at, w->len) % NAME_BITS;
    /* a name the filter has not seen is new; else the lines above say */
    if ((p->name_bits[h / 32] >> (h % 32) & 1u) && obj_find(p, p->text + w->at, w->len, &o)) {
        char tmp[4];
        om__str s = om__parse_fail_begin(p, OM_E_PARSE, w->col, tmp, sizeof tmp);
        om__str_s(&s, "object name ");
        om__str_tok(&s, p->text + w->at, w->len);
        om__str_s(&s, " is already used (on line ");
        om__str_u(&s, o.line);
        om__str_s(&s, ")");
        return OM_E_PARSE;
    }
    return OM_OK;
}

/* Second pass: the object's record and its name; its geometry lies at
 * [first_v, first_v + nv) and [first_t, first_t + nt). */
static om_object *object_add(parser *p, const pv *pl, uint32_t mesh, uint64_t first_v, uint64_t first_t,
                             bool closed)
{
    om_scene *s = p->s;
    om_object *o = &s->objects[p->nobjects];
    memset(o, 0, sizeof *o);
    o->mesh = mesh;
    o->first_vert = (uint32_t)first_v;
    o->first_tri = (uint32_t)first_t;
    o->solid = closed ? p->nsolids : OM_NO_TRI;
    o->first_key = OM_NO_TRI;
    o->last_key = OM_NO_TRI;
    o->base[0] = o->base[5] = o->base[10] = 1.0;
    o->name = "";
    if (pl[P_NAME].has) {
        char *nm = s->names + p->name_bytes;
        memcpy(nm, p->text + pl[P_NAME].w.at, pl[P_NAME].w.len);
        nm[pl[P_NAME].w.len] = '\0';
        o->name = nm;
    }
    return o;
}

/* Remembers a new object in the cache and counts it. */
static void object_count(parser *p, const pv *pl, oinfo *o)
{
    if (pl[P_NAME].has) {
        o->at = pl[P_NAME].w.at;
        o->len = pl[P_NAME].w.len;
        o->used = true;
        o->ord = p->nobjects;
        o->line = p->l.no;
        o->nkeys = 0;
        *ocache_slot(p, p->text + o->at, o->len) = *o;
        p->name_bytes += o->len + 1;
        const uint32_t h = name_hash(p->text + o->at, o->len) % NAME_BITS;
        p->name_bits[h / 32] |= 1u << (h % 32);
    }
    p->nobjects++;
}

/* A named shape or mesh line, after its geometry went to the scene as a static
 * line's would ([first_v, ..) and [first_t, ..)): it becomes its mesh too, and its
 * object is posed through om__object_write like every later move. */
static om_status named_done(parser *p, int cmd, const pv *pl, const char *file, uint64_t first_v,
                            uint64_t first_t)
{
    oinfo o;
    om_status st;
    memset(&o, 0, sizeof o);
    o.mesh = p->nmeshes;
    if ((st = measure(p, cmd, pl, file, &o)) != OM_OK) return st;
    if (p->fill) {
        om_scene *s = p->s;
        if (p->out.overflow || first_v + o.nv > s->nverts || first_t + o.nt > s->ntris)
            return OM_E_INVALID;
        om_mesh *me = &s->meshes[p->nmeshes];
        me->first_vert = (uint32_t)p->nmesh_v;
        me->nverts = (uint32_t)o.nv;
        me->first_idx = (uint32_t)(3 * p->nmesh_t);
        me->ntris = (uint32_t)o.nt;
        me->closed = o.closed;
        memcpy(s->mesh_verts + p->nmesh_v, s->verts + first_v, (size_t)o.nv * sizeof(om_vec3));
        for (uint64_t i = 0; i < 3 * o.nt; i++)
            s->mesh_idx[3 * p->nmesh_t + i] = s->idx[3 * first_t + i] - (uint32_t)first_v;
        om_object *ob = object_add(p, pl, p->nmeshes, first_v, first_t, o.closed);
        /* the solid (if closed) was recorded by the shape's own path, just before */
        if (o.closed) ob->solid = p->nsolids - 1;
        double id[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
        if ((st = om__object_write(s, p->nobjects, id, p->d)) != OM_OK) return st;
        ob->old_lo = ob->lo;
        ob->old_hi = ob->hi;
    }
    p->nmesh_v += o.nv;
    p->nmesh_t += o.nt;
    p->nmeshes++;
    object_count(p, pl, &o);
    return OM_OK;
}

/* copy SRC [name NAME] COMMON: an object sharing SRC's mesh, under its own transform. */
static om_status do_copy(parser *p)
{
    pv pl[P_N_];
    om_status st;
    om__tok src;
    int r = om__tok_next(&p->l, &src);
    if (r < 0) return om__parse_bad_byte(p, &src);
    if (r == 0)
        return om__parse_fail(p, OM_E_PARSE, om__line_end_col(&p->l), "expected an object's name after 'copy'",
                              NULL, 0, NULL);
    if ((st = om__parse_params(p, "copy", copy_params, NP(copy_params), pl)) != OM_OK) return st;
    oinfo si;
    if (!obj_find(p, p->text + src.at, src.len, &si))
        return om__parse_fail_tok(p, OM_E_PARSE, &src, "unknown object ",
                                  " (name it with 'name' on a shape or mesh line above)");
    if ((st = name_check(p, pl)) != OM_OK) return st;
    om__xform xf;
    uint16_t mat = 0;
    if ((st = object_common(p, pl, &xf, &mat)) != OM_OK) return st;
    oinfo o = si;
    o.radius = copy_radius(pl, si.radius);
    if (!(o.radius <= OM__COORD_MAX * (1.0 - 1e-9))) return out_of_range(p, "copy");
    if ((st = check_totals(p, si.nv, si.nt)) != OM_OK) return st;
    if (p->fill) {
        om_scene *s = p->s;
        if (p->nv + si.nv > s->nverts || p->nt + si.nt > s->ntris || si.mesh >= p->nmeshes)
            return OM_E_INVALID;
        om_object *ob = object_add(p, pl, si.mesh, p->nv, p->nt, si.closed);
        memcpy(ob->base, xf.m, sizeof ob->base);
        for (uint64_t t = 0; t < si.nt; t++) s->tri_mat[p->nt + t] = mat;
        if (si.closed) {
            om_solid *so = &s->solids[p->nsolids];
            so->first = (uint32_t)p->nt;
            so->count = (uint32_t)si.nt;
        }
        if ((st = om__object_write(s, p->nobjects, ob->base, p->d)) != OM_OK) return st;
        ob->old_lo = ob->lo;
        ob->old_hi = ob->hi;
        p->out.nv += si.nv;
        p->out.nt += si.nt;
    }
    p->nv += si.nv;
    p->nt += si.nt;
    p->nsolids += si.closed;
    object_count(p, pl, &o);
    return OM_OK;
}

static om_status do_object(parser *p, int cmd)
{
    pv pl[P_N_];
    om_status st;
    om__tok file;
    char name[256];
    if (cmd == C_MESH) {
        int r = om__tok_next(&p->l, &file);
        if (r < 0) return om__parse_bad_byte(p, &file);
        if (r == 0)
            return om__parse_fail(p, OM_E_PARSE, om__line_end_col(&p->l), "expected a file name after 'mesh'",
                        NULL, 0, NULL);
        if (file.len >= sizeof name)
            return om__parse_fail(p, OM_E_PARSE, file.col, "file name longer than 255 bytes", NULL, 0, NULL);
        memcpy(name, p->text + file.at, file.len);
        name[file.len] = '\0';
    }
    if ((st = om__parse_params(p, cmd_names[cmd], sets[cmd].ids, sets[cmd].n, pl)) != OM_OK) return st;
    if (cmd == C_TRIANGLES) {
        if (!pl[P_COUNT].has) return om__parse_missing(p, "triangles", "count N");
        for (int i = 0; i < 3 && pl[P_IN].has; i++)
            if (pl[P_IN].v[i] > pl[P_IN].v[i + 3])
                return om__parse_fail(p, OM_E_RANGE, pl[P_IN].vcol[i + 3],
                            "'in' needs X0 <= X1, Y0 <= Y1 and Z0 <= Z1", NULL, 0, NULL);
    }
    if ((st = name_check(p, pl)) != OM_OK) return st;
    om__xform xf;
    uint16_t mat = 0;
    if ((st = object_common(p, pl, &xf, &mat)) != OM_OK) return st;
    const uint64_t first_v = p->nv, first_t = p->nt;
    if (cmd == C_MESH) {
        if ((st = do_mesh(p, &file, name, &xf, mat)) != OM_OK) return st;
        return pl[P_NAME].has ? named_done(p, cmd, pl, name, first_v, first_t) : OM_OK;
    }

    uint64_t nv, nt;
    shape_counts(cmd, pl, &nv, &nt);
    if ((st = check_totals(p, nv, nt)) != OM_OK) return st;
    const bool closed = cmd == C_BOX || cmd == C_SPHERE || cmd == C_CYLINDER;
    if (p->fill) {
        om__sink_begin(&p->out, &xf, mat);
        uint64_t first = p->out.nt;
        shape_gen(&p->out, cmd, pl);
        if (closed) add_solid(p, first, nt);
    } else {
        double lo[3], hi[3];
        shape_box(cmd, pl, lo, hi);
        if (!box_inside(&xf, lo, hi)) {
            /* Near the limit: generate without storing, so the check is exact per vertex. */
            om__sink k;
            om__sink_init(&k, false);
            om__sink_begin(&k, &xf, mat);
            shape_gen(&k, cmd, pl);
            if (k.out_of_range) return out_of_range(p, cmd_names[cmd]);
        }
    }
    p->nv += nv;
    p->nt += nt;
    p->nsolids += closed;
    return pl[P_NAME].has ? named_done(p, cmd, pl, NULL, first_v, first_t) : OM_OK;
}

/* ---------------------------------------------------------------- keys */

/* "<what><a><line of the key before><b><its t><c>": a key that does not follow
 * from the one before it. */
static om_status key_fail(parser *p, om_status st, uint32_t col, const char *what, const char *a,
                          uint32_t line, const char *b, float last, const char *c)
{
    char tmp[4];
    om__str s = om__parse_fail_begin(p, st, col, tmp, sizeof tmp);
    om__str_s(&s, what);
    om__str_s(&s, a);
    om__str_u(&s, line);
    om__str_s(&s, b);
    om__str_f(&s, last, 3);
    om__str_s(&s, c);
    return st;
}

static om_status key_order(parser *p, const char *what, uint32_t col, float last, uint32_t line)
{
    return key_fail(p, OM_E_PARSE, col, what, " times must increase (the key before, on line ",
                    line, ", is at t = ", last, ")");
}

/* A segment of a path along which the view would lose its direction (eye on its
 * target, a spot light on its target, a directional light's dir through zero). */
static om_status key_meets(parser *p, const char *what, uint32_t col, float last, uint32_t line,
                           const char *how)
{
    return key_fail(p, OM_E_RANGE, col, what, ": between the key on line ", line, " (t = ", last, how);
}

/* key object NAME T [translate X Y Z] [rotate AX AY AZ] [scale S]: applied after the
 * object's own transform. A key's scale and translation bound how far its vertices
 * reach at any rotation (|translate| + |scale| * radius), and between two keys of one
 * sign the scale never passes through zero, so no pose along the path is refused. */
static om_status do_key_object(parser *p)
{
    pv pl[P_N_];
    om_status st;
    om__tok w;
    const char *what = "key object";
    int r = om__tok_next(&p->l, &w);
    if (r < 0) return om__parse_bad_byte(p, &w);
    if (r == 0)
        return om__parse_fail(p, OM_E_PARSE, om__line_end_col(&p->l), "expected an object's name after 'key object'",
                              NULL, 0, NULL);
    double T;
    uint32_t tcol;
    if ((st = om__parse_value(p, what, K_NUM, R_COORD, 1, &T, &tcol)) != OM_OK) return st;
    if ((st = om__parse_params(p, what, keyobj_params, NP(keyobj_params), pl)) != OM_OK) return st;
    oinfo o;
    if (!obj_find(p, p->text + w.at, w.len, &o))
        return om__parse_fail_tok(p, OM_E_PARSE, &w, "unknown object ",
                                  " (name it with 'name' on a shape, mesh or copy line above)");
    om_object_key k;
    memset(&k, 0, sizeof k);
    k.t = (float)T;
    k.scale = (float)val(pl, P_SCALE1, 0, 1.0);
    k.next = OM_NO_TRI;
    double reach = 0.0;
    for (int i = 0; i < 3; i++) {
        k.move[i] = (float)val(pl, P_TRANSLATE, i, 0.0);
        k.rot_deg[i] = (float)val(pl, P_ROTATE, i, 0.0);
        reach += (double)k.move[i] * k.move[i];
    }
    if (o.nkeys && !(k.t > o.last_t)) return key_order(p, what, tcol, o.last_t, o.last_line);
    if (o.nkeys && (k.scale < 0.0f) != (o.last_scale < 0.0f))
        return key_meets(p, what, pl[P_SCALE1].has ? pl[P_SCALE1].vcol[0] : p->cmd.col, o.last_t, o.last_line,
                         ") and this one the scale passes through zero");
    if (!(sqrt(reach) + fabs((double)k.scale) * o.radius <= OM__COORD_MAX * (1.0 - 1e-9)))
        return out_of_range(p, "key object");
    if (p->fill) {
        om_scene *s = p->s;
        if (p->nobj_keys >= s->nobj_keys || o.ord >= s->nobjects) return OM_E_INVALID;
        om_object *ob = &s->objects[o.ord];
        s->obj_keys[p->nobj_keys] = k;
        if (ob->nkeys) s->obj_keys[ob->last_key].next = p->nobj_keys;
        else ob->first_key = p->nobj_keys;
        ob->last_key = p->nobj_keys;
        ob->nkeys++;
    }
    o.nkeys++;
    o.last_t = k.t;
    o.last_line = p->l.no;
    o.last_scale = k.scale;
    *ocache_slot(p, p->text + o.at, o.len) = o;
    p->nobj_keys++;
    return OM_OK;
}

static om_status do_key(parser *p)
{
    pv pl[P_N_];
    om_status st;
    om__tok t;
    int r = om__tok_next(&p->l, &t);
    if (r < 0) return om__parse_bad_byte(p, &t);
    bool cam = r > 0 && om__tok_is(p->text, &t, "camera");
    if (r > 0 && om__tok_is(p->text, &t, "object")) return do_key_object(p);
    if (!cam && !(r > 0 && om__tok_is(p->text, &t, "light"))) {
        if (r == 0)
            return om__parse_fail(p, OM_E_PARSE, om__line_end_col(&p->l),
                        "expected 'camera', 'light' or 'object' after 'key'", NULL, 0, NULL);
        return om__parse_fail_tok(p, OM_E_PARSE, &t, "expected 'camera', 'light' or 'object' after 'key', found ", NULL);
    }
    const char *what = cam ? "key camera" : "key light";
    double T;
    uint32_t tcol;
    if ((st = om__parse_value(p, what, K_NUM, R_COORD, 1, &T, &tcol)) != OM_OK) return st;
    float tf = (float)T;
    if (cam) {
        if ((st = om__parse_params(p, what, keycam_params, NP(keycam_params), pl)) != OM_OK) return st;
        if (!pl[P_EYE].has || !pl[P_TARGET].has) return om__parse_missing(p, what, "eye X Y Z and target X Y Z");
        om_camera_key k;
        k.t = tf;
        k.eye = pv3(&pl[P_EYE], 0);
        k.target = pv3(&pl[P_TARGET], 0);
        if (v3_no_dir(om__sub(k.target, k.eye)))
            return om__parse_fail(p, OM_E_RANGE, pl[P_TARGET].vcol[0], "camera eye and target must differ: their difference gives no direction",
                        NULL, 0, NULL);
        if (p->ncam && !(tf > p->cam_t)) return key_order(p, what, tcol, p->cam_t, p->cam_t_line);
        if (p->ncam && om__path_meets(p->cam_k.eye, p->cam_k.target, k.eye, k.target))
            return key_meets(p, what, pl[P_EYE].vcol[0], p->cam_t, p->cam_t_line,
                             ") and this one the eye passes through its target");
        if (p->fill) p->s->cam_keys[p->ncam] = k;
        p->cam_k = k;
        p->ncam++;
        p->cam_t = tf;
        p->cam_t_line = p->l.no;
        return OM_OK;
    }
    if ((st = om__parse_params(p, what, keylight_params, NP(keylight_params), pl)) != OM_OK) return st;
    int form;
    om_light_key k;
    memset(&k, 0, sizeof k);
    k.t = tf;
    if (pl[P_DIR].has) {
        if (pl[P_POS].has || pl[P_TARGET].has)
            return om__parse_fail(p, OM_E_PARSE, pl[P_DIR].col,
                        "a light key has either pos and target (spot) or dir (directional)", NULL,
                        0, NULL);
        form = 2;
        k.dir = pv3(&pl[P_DIR], 0);
        if (v3_no_dir(k.dir))
            return om__parse_fail(p, OM_E_RANGE, pl[P_DIR].vcol[0], "'dir' must not be zero, nor too short to give a direction", NULL, 0, NULL);
    } else {
        if (!pl[P_POS].has || !pl[P_TARGET].has)
            return om__parse_missing(p, what, "pos X Y Z and target X Y Z, or dir X Y Z");
        form = 1;
        k.pos = pv3(&pl[P_POS], 0);
        k.target = pv3(&pl[P_TARGET], 0);
        if (v3_no_dir(om__sub(k.target, k.pos)))
            return om__parse_fail(p, OM_E_RANGE, pl[P_TARGET].vcol[0], "light pos and target must differ: their difference gives no direction",
                        NULL, 0, NULL);
        k.dir = om__normalize(om__sub(k.target, k.pos));
    }
    if (p->lkey_form && form != p->lkey_form) {
        char tmp[4];
        om__str s = om__parse_fail_begin(p, OM_E_PARSE, p->cmd.col, tmp, sizeof tmp);
        om__str_s(&s, "light keys mix pos/target and dir (the first key, on line ");
        om__str_u(&s, p->lkey_line);
        om__str_s(&s, form == 1 ? ", uses dir)" : ", uses pos/target)");
        return OM_E_PARSE;
    }
    if (p->nlight && !(tf > p->light_t)) return key_order(p, what, tcol, p->light_t, p->light_t_line);
    const om_vec3 zero = {0.0f, 0.0f, 0.0f};
    if (p->nlight && (form == 1 ? om__path_meets(p->light_k.pos, p->light_k.target, k.pos, k.target)
                                : om__path_meets(p->light_k.dir, zero, k.dir, zero)))
        return key_meets(p, what, pl[form == 1 ? P_POS : P_DIR].vcol[0], p->light_t, p->light_t_line,
                         form == 1 ? ") and this one the light passes through its target"
                                   : ") and this one 'dir' passes through zero");
    if (!p->lkey_form) {
        p->lkey_form = form;
        p->lkey_line = p->l.no;
        p->lkey_col = p->cmd.col;
    }
    if (p->fill) p->s->light_keys[p->nlight] = k;
    p->light_k = k;
    p->nlight++;
    p->light_t = tf;
    p->light_t_line = p->l.no;
    return OM_OK;
}

/* ---------------------------------------------------------------- one pass */

static om_status run(parser *p)
{
    om_status st = OM_OK;
    default_camera(&p->cam);
    default_light(&p->light);
    om__line_init(&p->l, p->text, p->len, true);
    while (om__line_next(&p->l)) {
        om__tok t;
        int r = om__tok_next(&p->l, &t);
        if (r < 0) return om__parse_bad_byte(p, &t);
        if (r == 0) continue;
        p->cmd = t;
        int cmd = -1;
        for (int i = 0; i < C_N_ && cmd < 0; i++)
            if (om__tok_is(p->text, &t, cmd_names[i])) cmd = i;
        switch (cmd) {
        case C_CAMERA: st = do_camera(p); break;
        case C_LIGHT: st = do_light(p); break;
        case C_MATERIAL: st = do_material(p); break;
        case C_KEY: st = do_key(p); break;
        case C_COPY: st = do_copy(p); break;
        case -1: {
            char tmp[4];
            om__str s = om__parse_fail_begin(p, OM_E_PARSE, t.col, tmp, sizeof tmp);
            om__str_s(&s, "unknown command ");
            om__str_tok(&s, p->text + t.at, t.len);
            om__str_s(&s, " (expected ");
            for (int i = 0; i < C_N_; i++) {
                if (i) om__str_s(&s, ", ");
                om__str_s(&s, cmd_names[i]);
            }
            om__str_s(&s, ")");
            return OM_E_PARSE;
        }
        default: st = do_object(p, cmd); break;
        }
        if (st != OM_OK) return st;
    }
    /* Light keys must match the light's kind, whichever line came first. */
    if (p->lkey_form && (p->lkey_form == 1) != (p->light.kind == OM_LIGHT_SPOT)) {
        char tmp[4];
        om__str s = om__perr(p->d, OM_E_PARSE, NULL, p->lkey_line, p->lkey_col, tmp, sizeof tmp);
        om__str_s(&s, p->lkey_form == 1 ? "light keys give pos/target but the light is directional"
                                        : "light keys give dir but the light is a spot light");
        return OM_E_PARSE;
    }
    return OM_OK;
}

/* ================================================================ public entry points */

/* The bounds of a scene with objects: of the vertices outside every object (objects
 * lie in increasing order of their first vertex), then with each object's. */
static void scene_bounds_objects(om_scene *s)
{
    uint32_t v = 0;
    s->has_static = false;
    for (uint32_t i = 0; i <= s->nobjects; i++) {
        const uint32_t end = i < s->nobjects ? s->objects[i].first_vert : s->nverts;
        for (; v < end; v++) {
            om_vec3 x = s->verts[v];
            if (!s->has_static) {
                s->static_lo = s->static_hi = x;
                s->has_static = true;
            }
            s->static_lo = om__v3(fminf(s->static_lo.x, x.x), fminf(s->static_lo.y, x.y), fminf(s->static_lo.z, x.z));
            s->static_hi = om__v3(fmaxf(s->static_hi.x, x.x), fmaxf(s->static_hi.y, x.y), fmaxf(s->static_hi.z, x.z));
        }
        if (i < s->nobjects) v += s->meshes[s->objects[i].mesh].nverts;
    }
    om__scene_bounds(s);
}

typedef struct al_vec3 { char c; om_vec3 x; } al_vec3;
typedef struct al_u32 { char c; uint32_t x; } al_u32;
typedef struct al_u16 { char c; uint16_t x; } al_u16;
typedef struct al_mat { char c; om_material x; } al_mat;
typedef struct al_ck { char c; om_camera_key x; } al_ck;
typedef struct al_lk { char c; om_light_key x; } al_lk;
typedef struct al_so { char c; om_solid x; } al_so;
typedef struct al_ob { char c; om_object x; } al_ob;
typedef struct al_me { char c; om_mesh x; } al_me;
typedef struct al_ok { char c; om_object_key x; } al_ok;

enum {
    A_VERTS, A_IDX, A_TRIMAT, A_MATS, A_CKEYS, A_LKEYS, A_SOLIDS, A_OBJS, A_MESHES, A_MVERTS,
    A_MIDX, A_OKEYS, A_NAMES, A_N_
};

/* Each array's size and alignment, from the first pass's counts. */
static void layout(const parser *p, uint64_t size[A_N_], size_t align[A_N_])
{
    size[A_VERTS] = p->nv * sizeof(om_vec3);          align[A_VERTS] = offsetof(al_vec3, x);
    size[A_IDX] = p->nt * 3 * sizeof(uint32_t);       align[A_IDX] = offsetof(al_u32, x);
    size[A_TRIMAT] = p->nt * sizeof(uint16_t);        align[A_TRIMAT] = offsetof(al_u16, x);
    size[A_MATS] = (1 + (uint64_t)p->nnamed + p->ninline) * sizeof(om_material);
    align[A_MATS] = offsetof(al_mat, x);
    size[A_CKEYS] = (uint64_t)p->ncam * sizeof(om_camera_key);   align[A_CKEYS] = offsetof(al_ck, x);
    size[A_LKEYS] = (uint64_t)p->nlight * sizeof(om_light_key);  align[A_LKEYS] = offsetof(al_lk, x);
    size[A_SOLIDS] = (uint64_t)p->nsolids * sizeof(om_solid);    align[A_SOLIDS] = offsetof(al_so, x);
    size[A_OBJS] = (uint64_t)p->nobjects * sizeof(om_object);    align[A_OBJS] = offsetof(al_ob, x);
    size[A_MESHES] = (uint64_t)p->nmeshes * sizeof(om_mesh);     align[A_MESHES] = offsetof(al_me, x);
    size[A_MVERTS] = p->nmesh_v * sizeof(om_vec3);               align[A_MVERTS] = offsetof(al_vec3, x);
    size[A_MIDX] = p->nmesh_t * 3 * sizeof(uint32_t);            align[A_MIDX] = offsetof(al_u32, x);
    size[A_OKEYS] = (uint64_t)p->nobj_keys * sizeof(om_object_key); align[A_OKEYS] = offsetof(al_ok, x);
    size[A_NAMES] = p->name_bytes;                               align[A_NAMES] = 1;
}

/* Bytes of one array: om_arena_need's worst case, or nothing for an empty array. */
static uint64_t array_need(uint64_t size, size_t align)
{
    return size ? size + (align > 1 ? align - 1 : 0) : 0;
}

static void diag_clear(om_diag *d)
{
    if (!d) return;
    d->status = OM_OK;
    d->asked = d->left = 0;
    d->line = d->col = 0;
    d->msg[0] = '\0';
}

static void parser_init(parser *p, const char *text, size_t len, const om_loader *ld, om_diag *d)
{
    memset(p, 0, sizeof *p);
    p->text = text;
    p->len = text ? len : 0;
    p->ld = ld;
    p->d = d;
}

static om_status total_bytes(const parser *p, uint64_t *total, om_diag *d)
{
    uint64_t size[A_N_];
    size_t align[A_N_];
    layout(p, size, align);
    *total = 0;
    for (int i = 0; i < A_N_; i++) *total += array_need(size[i], align[i]);
    if (*total > (uint64_t)SIZE_MAX) {
        if (d) {
            d->asked = SIZE_MAX;
            d->left = 0;
        }
        return om__fail(d, OM_E_BUDGET, "the scene needs more bytes than this machine can address");
    }
    return OM_OK;
}

om_status om_scene_bytes(const char *text, size_t len, const om_loader *ld, size_t *bytes,
                         om_diag *d)
{
    diag_clear(d);
    if (bytes) *bytes = 0;
    if (!bytes) return om__fail(d, OM_E_INVALID, "om_scene_bytes needs somewhere to put the bytes");
    if (!text && len) return om__fail(d, OM_E_INVALID, "scene text is NULL");
    parser p;
    parser_init(&p, text, len, ld, d);
    om_status st = run(&p);
    if (st != OM_OK) return st;
    uint64_t total;
    if ((st = total_bytes(&p, &total, d)) != OM_OK) return st;
    *bytes = (size_t)total;
    return OM_OK;
}

om_status om_scene_parse(const char *text, size_t len, const om_loader *ld, om_arena *a,
                         om_scene *out, om_diag *d)
{
    diag_clear(d);
    if (!a || !out) return om__fail(d, OM_E_INVALID, "om_scene_parse needs an arena and a scene");
    memset(out, 0, sizeof *out);
    if (!text && len) return om__fail(d, OM_E_INVALID, "scene text is NULL");
    parser p;
    parser_init(&p, text, len, ld, d);
    om_status st = run(&p);
    if (st != OM_OK) return st;
    uint64_t total, size[A_N_];
    size_t align[A_N_];
    if ((st = total_bytes(&p, &total, d)) != OM_OK) return st;
    layout(&p, size, align);

    /* Each array is one carve of exactly what om_scene_bytes counted for it (its size
     * plus the worst-case alignment padding), aligned inside the carve: the arena use
     * is then exactly the bytes query wherever the host's buffer starts, so a budget of
     * one byte less fails rather than depending on where the buffer happens to lie. */
    void *arr[A_N_] = {NULL};
    size_t mark = om_arena_mark(a);
    for (int i = 0; i < A_N_; i++) {
        if (!size[i]) continue;
        void *raw;
        if ((st = om_arena_alloc(a, (size_t)array_need(size[i], align[i]), 1, &raw, d)) != OM_OK) {
            om_arena_rewind(a, mark);
            return st;
        }
        uintptr_t at = (uintptr_t)raw;
        arr[i] = (unsigned char *)raw + ((align[i] - (at & (align[i] - 1))) & (align[i] - 1));
    }
    om_scene *s = out;
    s->nverts = (uint32_t)p.nv;
    s->ntris = (uint32_t)p.nt;
    s->nmats = 1 + p.nnamed + p.ninline;
    s->ncam_keys = p.ncam;
    s->nlight_keys = p.nlight;
    s->verts = (om_vec3 *)arr[A_VERTS];
    s->idx = (uint32_t *)arr[A_IDX];
    s->tri_mat = (uint16_t *)arr[A_TRIMAT];
    s->mats = (om_material *)arr[A_MATS];
    s->cam_keys = (om_camera_key *)arr[A_CKEYS];
    s->light_keys = (om_light_key *)arr[A_LKEYS];
    s->nsolids = p.nsolids;
    s->solids = (om_solid *)arr[A_SOLIDS];
    s->nobjects = p.nobjects;
    s->nmeshes = p.nmeshes;
    s->nobj_keys = p.nobj_keys;
    s->nmesh_verts = (uint32_t)p.nmesh_v;
    s->nmesh_tris = (uint32_t)p.nmesh_t;
    s->objects = (om_object *)arr[A_OBJS];
    s->meshes = (om_mesh *)arr[A_MESHES];
    s->mesh_verts = (om_vec3 *)arr[A_MVERTS];
    s->mesh_idx = (uint32_t *)arr[A_MIDX];
    s->obj_keys = (om_object_key *)arr[A_OKEYS];
    s->names = (char *)arr[A_NAMES];
    s->mats[0].r = s->mats[0].g = s->mats[0].b = 0.8f;
    s->mats[0].opacity = 1.0f;

    /* The second pass reuses the parser: one on the stack is enough for small targets. */
    uint32_t named = p.nnamed, inline_ = p.ninline, solids = p.nsolids;
    const uint64_t nmesh_v = p.nmesh_v, name_bytes = p.name_bytes;
    parser_init(&p, text, len, ld, d);
    p.fill = true;
    p.nnamed_total = named;
    p.s = s;
    om__sink_init(&p.out, true);
    p.out.verts = s->verts;
    p.out.idx = s->idx;
    p.out.tri_mat = s->tri_mat;
    p.out.vcap = s->nverts;
    p.out.tcap = s->ntris;
    st = run(&p);
    /* Only a mesh file that changed between the two loads can make the passes differ. */
    if (st == OM_OK && (p.out.overflow || p.out.nv != s->nverts || p.out.nt != s->ntris ||
                        p.nv != s->nverts || p.nt != s->ntris || p.nnamed != named ||
                        p.ninline != inline_ || p.ncam != s->ncam_keys || p.nlight != s->nlight_keys ||
                        p.nsolids != solids || p.nobjects != s->nobjects || p.nmeshes != s->nmeshes ||
                        p.nobj_keys != s->nobj_keys || p.nmesh_v != nmesh_v || p.name_bytes != name_bytes))
        st = om__fail(d, OM_E_INVALID, "a mesh file changed between the counting and filling passes");
    if (st != OM_OK) {
        om_arena_rewind(a, mark);
        memset(out, 0, sizeof *out);
        return st;
    }
    s->camera = p.cam;
    s->light = p.light;
    if (s->nobjects) {
        scene_bounds_objects(s);
    } else if (s->nverts) {
        s->lo = s->hi = s->verts[0];
        for (uint32_t i = 1; i < s->nverts; i++) {
            om_vec3 v = s->verts[i];
            s->lo = om__v3(fminf(s->lo.x, v.x), fminf(s->lo.y, v.y), fminf(s->lo.z, v.z));
            s->hi = om__v3(fmaxf(s->hi.x, v.x), fmaxf(s->hi.y, v.y), fmaxf(s->hi.z, v.z));
        }
    }
    return OM_OK;
}
