/* unit/scene_fuzz.c — random mutations of the default scene's text (flipped, deleted,
 * inserted and duplicated bytes, cut-short text) through both passes of the scene
 * reader: never a crash or an out-of-range status, both passes agree on errors, and
 * every scene that parses holds in-range indices, materials and finite vertices. */
#include "../test.h"
#include "../scene_util.h"

#include <math.h>
#include <stdlib.h>

static uint64_t rng_next(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s >> 33;
}

static unsigned char fuzz_mem[4 << 20];

static void fuzz_mutations(void)
{
    const char *base = om_scene_default_text();
    size_t blen = strlen(base), cap = blen + 4096;
    char *t = (char *)malloc(cap);
    static const char *snippets[] = {
        "1e999", "nan", "-", "\n", "#", "\r\n", " 0 ", "4096", "1e30", "\0", "box", "material",
        "key camera 0 eye 0 0 0 target 0 0 0\n", "mesh a.obj", "scale", "-1e7", "9999999999999999999999",
        "triangles count 20000 ", "sphere segments 4096 ", ".", "\t", "\xff",
    };
    uint64_t seed = 12345;
    uint32_t ok = 0, errs[OM_E_COUNT_] = {0};
    for (int it = 0; it < 2000; it++) {
        memcpy(t, base, blen);
        size_t len = blen;
        int edits = 1 + (int)(rng_next(&seed) % 6);
        for (int e = 0; e < edits; e++) {
            size_t at = len ? (size_t)(rng_next(&seed) % len) : 0;
            switch (rng_next(&seed) % 6) {
            case 0: /* flip a byte */
                if (len) t[at] = (char)rng_next(&seed);
                break;
            case 1: /* delete a run */
            {
                size_t n = rng_next(&seed) % 40;
                if (n > len - at) n = len - at;
                memmove(t + at, t + at + n, len - at - n);
                len -= n;
                break;
            }
            case 2: /* insert a snippet */
            {
                const char *sn = snippets[rng_next(&seed) % (sizeof snippets / sizeof snippets[0])];
                size_t n = sn[0] ? strlen(sn) : 1;
                if (len + n > cap) break;
                memmove(t + at + n, t + at, len - at);
                memcpy(t + at, sn, n);
                len += n;
                break;
            }
            case 3: /* cut the text short */
                len = at;
                break;
            case 4: /* replace a digit */
                if (len && t[at] >= '0' && t[at] <= '9') t[at] = (char)('0' + rng_next(&seed) % 10);
                else if (len) t[at] = ' ';
                break;
            default: /* duplicate a chunk */
            {
                size_t n = rng_next(&seed) % 80, from = len ? (size_t)(rng_next(&seed) % len) : 0;
                if (n > len - from) n = len - from;
                if (len + n > cap) break;
                memmove(t + at + n, t + at, len - at);
                memmove(t + at, t + (from < at ? from : from + n), n);
                len += n;
                break;
            }
            }
        }
        size_t bytes = 0;
        om_diag d1, d2;
        char *x = exact_copy(t, len);
        om_status s1 = om_scene_bytes(x, len, NULL, &bytes, &d1);
        om_arena a;
        om_scene s;
        om_arena_init(&a, fuzz_mem, sizeof fuzz_mem, "scene");
        om_status s2 = om_scene_parse(x, len, NULL, &a, &s, &d2);
        free(x);
        CHECK((unsigned)s1 < OM_E_COUNT_ && (unsigned)s2 < OM_E_COUNT_);
        CHECK(memchr(d1.msg, '\0', sizeof d1.msg) != NULL);
        if (s1 != OM_OK) {
            CHECK(s2 == s1 && d1.line == d2.line && d1.col == d2.col);
            CHECK(d1.msg[0] != '\0');
            if (s1 == OM_E_PARSE) CHECK(d1.line >= 1 && d1.col >= 1);
            errs[s1]++;
            continue;
        }
        if (s2 == OM_E_BUDGET) {
            CHECK(bytes > sizeof fuzz_mem);
            errs[OM_E_BUDGET]++;
            continue;
        }
        CHECK(s2 == OM_OK && a.used == bytes);
        if (s2 != OM_OK) continue;
        ok++;
        uint32_t badidx = 0, badmat = 0;
        for (uint32_t i = 0; i < 3 * s.ntris; i++) badidx += s.idx[i] >= s.nverts;
        for (uint32_t i = 0; i < s.ntris; i++) badmat += s.tri_mat[i] >= s.nmats;
        CHECK(badidx == 0 && badmat == 0);
        for (uint32_t i = 0; i < s.nverts; i++) {
            om_vec3 v = s.verts[i];
            CHECK(om__finite3(v) && fabsf(v.x) <= 1e7f && fabsf(v.y) <= 1e7f && fabsf(v.z) <= 1e7f);
        }
        om_camera c;
        om_light l;
        om_scene_at(&s, (float)(rng_next(&seed) % 50) * 0.1f - 0.5f, &c, &l);
        CHECK(om__finite3(c.eye) && om__finite3(l.pos));
    }
    CHECK_MSG(ok > 100 && errs[OM_E_PARSE] > 100, "fuzz: %u ok, %u parse errors", ok, errs[OM_E_PARSE]);
    free(t);
}

void suite_scene_fuzz(void)
{
    RUN(fuzz_mutations);
}
