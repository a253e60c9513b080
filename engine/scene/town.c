/* town.c — the built-in town: houses, towers, garden walls, street lamps and trees
 * (boxes and cylinders) along the streets of a ground a kilometre across, a camera at
 * eye height in the main street looking down it, and a low sun. The scene where a
 * directional light covers a large world seen from near the ground, the case that
 * cascaded shadow maps exist for: a pole's shadow at the camera's feet and a tower's
 * a kilometre away are both on screen.
 *
 * Its text is too long for one C99 string literal (4095 characters), so a small
 * generator writes it into the caller's buffer. Every figure is a whole number of
 * decimetres drawn from splitmix64 with a fixed seed and written with integer
 * arithmetic, so the text is the same bytes on every machine; the parser then makes
 * the same floats everywhere. */
#include "scene.h"

typedef struct town {
    char *buf;
    size_t cap;
    size_t len;            /* every byte of the text so far, written or not */
    uint64_t rng;
} town;

/* Appends s, writing only what fits with the final NUL. */
static void put(town *t, const char *s)
{
    for (; *s; s++, t->len++)
        if (t->len + 1 < t->cap) t->buf[t->len] = *s;
}

/* " 12.5": v decimetres written in metres, without a trailing ".0". */
static void dm(town *t, int32_t v)
{
    char tmp[24];
    om__str s;
    const uint32_t a = v < 0 ? (uint32_t)0 - (uint32_t)v : (uint32_t)v;
    om__str_init(&s, tmp, sizeof tmp);
    om__str_s(&s, v < 0 ? " -" : " ");
    om__str_u(&s, a / 10u);
    if (a % 10u) {
        om__str_s(&s, ".");
        om__str_u(&s, a % 10u);
    }
    put(t, tmp);
}

/* " 12": a whole number. */
static void whole(town *t, int32_t n) { dm(t, 10 * n); }

/* Uniform in lo..hi. C leaves the order of a call's arguments open, so no call takes
 * two draws among its arguments: each is drawn into a variable first. */
static int32_t pick(town *t, int32_t lo, int32_t hi)
{
    return lo + (int32_t)(om__mix_next(&t->rng) % (uint64_t)(hi - lo + 1));
}

/* A box of sx x sy x sz standing on y0, centred on (x, z); sy is even, so its centre
 * is whole decimetres too. */
static void box(town *t, int32_t x, int32_t z, int32_t sx, int32_t sy, int32_t sz, int32_t y0,
                const char *mat)
{
    put(t, "box size");
    dm(t, sx); dm(t, sy); dm(t, sz);
    put(t, " translate");
    dm(t, x); dm(t, y0 + sy / 2); dm(t, z);
    put(t, " material ");
    put(t, mat);
    put(t, "\n");
}

static void cylinder(town *t, int32_t x, int32_t y, int32_t z, int32_t r, int32_t h,
                     int32_t segments, const char *mat)
{
    put(t, "cylinder radius");
    dm(t, r);
    put(t, " height");
    dm(t, h);
    put(t, " segments");
    whole(t, segments);
    put(t, " translate");
    dm(t, x); dm(t, y); dm(t, z);
    put(t, " material ");
    put(t, mat);
    put(t, "\n");
}

/* ---- the plan, in decimetres: x east, z south; the main street runs along z */

enum {
    HALF = 5000,          /* the ground: 1 km square, centred on the origin */
    LAMP_X = 46,          /* the main street: a carriageway |x| < 4 m, lamps, trees, */
    TREE_X = 65,          /* then the houses' fronts at 9 m and more */
    FRONT_X = 90,
    SIDE_X = 1300,        /* two side streets, parallel to the main one */
    CROSS = 1000,         /* cross streets every 100 m ... */
    CROSS_HALF = 60,      /* ... 12 m wide */
    BLOCKS = 10,
    EDGE = 4900           /* the town stops 10 m short of the ground's edge */
};

/* Block b's extent along z, between two cross streets (or a street and the edge). */
static void block_z(int b, int32_t *zs, int32_t *ze)
{
    *zs = b == 0 ? -EDGE : -HALF + CROSS * b + CROSS_HALF;
    *ze = b == BLOCKS - 1 ? EDGE : -HALF + CROSS * (b + 1) - CROSS_HALF;
}

static const char *house_material(town *t)
{
    static const char *const mats[3] = {"plaster", "brick", "stone"};
    return mats[pick(t, 0, 2)];
}

/* A row of houses along z from zs to ze, their fronts `front` from the street's axis
 * at x = axis on side `side` (+1 east, -1 west), gaps up to gap_max between them. */
static void row(town *t, int32_t axis, int32_t side, int32_t front, int32_t zs, int32_t ze,
                int32_t gap_max, int32_t hmin, int32_t hmax)
{
    int32_t z = zs + 2 * pick(t, 0, 10);
    for (;;) {
        int32_t w = 2 * pick(t, 40, 90);                  /* 8 to 18 m along the street */
        if (z + w > ze) w = (ze - z) / 2 * 2;
        if (w < 60) break;
        const int32_t depth = 2 * pick(t, 50, 80), back = 2 * pick(t, 0, 15);
        const int32_t h = 2 * pick(t, hmin / 2, hmax / 2);
        const char *mat = house_material(t);
        box(t, axis + side * (front + back + depth / 2), z + w / 2, depth, h, w, 0, mat);
        z += w + 2 * pick(t, 0, gap_max / 2);
    }
}

/* A tree: a trunk and a crown, both cylinders. */
static void tree(town *t, int32_t x, int32_t z)
{
    cylinder(t, x, 0, z, 2, 30, 8, "bark");
    const int32_t r = 2 * pick(t, 8, 12), h = 2 * pick(t, 18, 25);
    cylinder(t, x, 28, z, r, h, 12, "leaves");
}

static void write_town(town *t)
{
    put(t,
        "# ombra town: 514 boxes and cylinders, 10,100 triangles: houses, towers, garden\n"
        "# walls, street lamps and trees along the streets of a ground a kilometre across,\n"
        "# seen from eye height in the main street, under a low sun. A directional light\n"
        "# over a large world seen from near the ground: a lamp's shadow at the camera's\n"
        "# feet and a tower's hundreds of metres away are both on screen.\n"
        "\n"
        "camera eye -2.5 1.7 470 target -0.5 1.5 370 fov 60 size 1024 768 near 0.2 far 1000\n"
        "# 25 degrees up, behind the camera: shadows twice as long as what casts them fall\n"
        "# down the main street, the west side's across it\n"
        "light directional dir 0.25 -0.42 -0.87\n"
        "\n"
        "material ground albedo 0.62 0.60 0.56\n"
        "material plaster albedo 0.85 0.80 0.70\n"
        "material brick albedo 0.70 0.42 0.32\n"
        "material stone albedo 0.60 0.58 0.55\n"
        "material concrete albedo 0.72 0.73 0.75\n"
        "material metal albedo 0.60 0.62 0.66\n"
        "material bark albedo 0.42 0.32 0.22\n"
        "material leaves albedo 0.32 0.55 0.26\n"
        "\n"
        "plane size 1000 1000 divisions 10 material ground\n");
    for (int b = 0; b < BLOCKS; b++) {
        int32_t zs, ze;
        block_z(b, &zs, &ze);
        put(t, "\n# block ");
        whole(t, b + 1);
        put(t, " of 10, z from");
        dm(t, zs);
        put(t, " to");
        dm(t, ze);
        put(t, "\n");
        /* the main street: terraces of 6 to 24 m, a park on the west of block 9 */
        row(t, 0, 1, FRONT_X, zs, ze, 30, 60, 240);
        if (b == 8) {
            for (int32_t i = 0; i < 3; i++)
                for (int32_t j = 0; j < 5; j++) tree(t, -140 - 70 * i, zs + 140 + 150 * j);
            box(t, -450, (zs + ze) / 2, 4, 16, ze - zs - 100, 0, "stone");
        } else {
            row(t, 0, -1, FRONT_X, zs, ze, 30, 60, 240);
        }
        /* garden walls behind the houses, 1.2 to 2.4 m high */
        for (int32_t side = -1; side <= 1; side += 2) {
            const int32_t x = side * 2 * pick(t, 160, 190), h = 2 * pick(t, 6, 12);
            box(t, x, (zs + ze) / 2, 4, h, ze - zs - 2 * pick(t, 25, 75), 0, "stone");
        }
        /* the side streets: lower houses with gardens between them */
        for (int32_t side = -1; side <= 1; side += 2)
            for (int32_t s2 = -1; s2 <= 1; s2 += 2)
                row(t, side * SIDE_X, s2, 80, zs, ze, 100, 50, 140);
        /* a tower of 40 to 90 m in one block of three, a round one in every fourth */
        if (pick(t, 0, 2) == 0) {
            const int32_t side = pick(t, 0, 1) ? 1 : -1, x = side * 2 * pick(t, 270, 400);
            const int32_t sx = 2 * pick(t, 70, 120), h = 2 * pick(t, 200, 450);
            box(t, x, (zs + ze) / 2, sx, h, 2 * pick(t, 70, 120), 0, "concrete");
        }
        if (b % 4 == 1) {
            const int32_t x = (b % 8 == 1 ? -1 : 1) * 2 * pick(t, 250, 350), r = pick(t, 50, 100);
            cylinder(t, x, 0, (zs + ze) / 2, r, 2 * pick(t, 150, 300), 24, "concrete");
        }
        /* street lamps every 25 m on both pavements; trees between them in every
         * other block, the camera's among them */
        for (int32_t z = -HALF + 125; z < HALF; z += 250) {
            if (z < zs || z > ze) continue;
            cylinder(t, -LAMP_X, 0, z, 1, 70, 6, "metal");
            cylinder(t, LAMP_X, 0, z, 1, 70, 6, "metal");
            if (b % 2 == 1 && z + 125 < ze - 30) {
                tree(t, -TREE_X, z + 125);
                tree(t, TREE_X, z + 125);
            }
        }
    }
    put(t,
        "\n"
        "# a walk down the main street at 1.5 m/s (t in seconds)\n"
        "key camera 0 eye -2.5 1.7 470 target -0.5 1.5 370\n"
        "key camera 20 eye -2.5 1.7 440 target -0.5 1.5 340\n"
        "# the sun sinks a little and swings west\n"
        "key light 0 dir 0.25 -0.42 -0.87\n"
        "key light 20 dir 0.38 -0.36 -0.85\n");
}

size_t om_scene_town_text(char *buf, size_t cap)
{
    town t;
    t.buf = buf;
    t.cap = buf ? cap : 0;
    t.len = 0;
    t.rng = 0x746F776Eu;   /* "town" */
    write_town(&t);
    if (t.cap) t.buf[t.len < t.cap ? t.len : t.cap - 1] = '\0';
    return t.len;
}
