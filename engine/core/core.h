/* core.h — engine-internal helpers shared by every module: diagnostics text built
 * without stdio, vector and matrix math, and deterministic trigonometry.
 * Private names carry the om__ prefix; nothing here is part of the public API. */
#ifndef OM_CORE_H
#define OM_CORE_H

#include "ombra.h"
#include "config.h"

#include <float.h>
#include <math.h>

/* ---- determinism (engine/DESIGN.md, Determinism): every engine file includes this header.
 * Float arithmetic must be evaluated in float (FLT_EVAL_METHOD 0): x87 (2) and s390x
 * gcc's standard mode (1) compute in a wider type, and the frames differ in their last
 * bits from every other CPU's. OM_ALLOW_EXCESS_PRECISION builds anyway, outside that
 * promise (every loop still ends). */
#if FLT_EVAL_METHOD != 0 && !defined(OM_ALLOW_EXCESS_PRECISION)
#error "ombra: FLT_EVAL_METHOD != 0 (x87 or s390x gcc): frames would differ from other CPUs; use -msse2 -mfpmath=sse on i386, -fexcess-precision=fast with s390x gcc, or define OM_ALLOW_EXCESS_PRECISION"
#endif
/* No a * b + c fused into one rounding (FMA) unless the source says so, even when the
 * build forgets -ffp-contract=off. clang honours the pragma (not under
 * -ffp-contract=fast); gcc ignores it with a warning, so gcc needs the flag. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

/* ---- size arithmetic that saturates at SIZE_MAX instead of wrapping: a byte count
 * that does not fit a size_t asks for more than any arena holds, so a carve of it
 * fails with OM_E_BUDGET (on 32-bit targets as on 64-bit ones). */
static inline size_t om__size_add(size_t a, size_t b) { return a > SIZE_MAX - b ? SIZE_MAX : a + b; }
static inline size_t om__size_mul(size_t a, size_t b) { return b && a > SIZE_MAX / b ? SIZE_MAX : a * b; }

/* An image of width x height the engine takes: each side 1..OM_MAX_DIM (every byte
 * count of a frame then fits a 32-bit size_t). */
static inline bool om__side_ok(uint32_t width, uint32_t height)
{
    return width >= 1 && width <= OM_MAX_DIM && height >= 1 && height <= OM_MAX_DIM;
}

/* ---- diagnostics: a bounded string builder (no stdio in the engine) */
typedef struct om__str { char *buf; size_t cap, len; } om__str;

void om__str_init(om__str *s, char *buf, size_t cap);
void om__str_s(om__str *s, const char *text);
void om__str_u(om__str *s, uint64_t v);
void om__str_i(om__str *s, int64_t v);
void om__str_f(om__str *s, double v, int decimals);

/* Sets d->status and d->msg (if d) and returns `st`, so callers write
 * `return om__fail(d, OM_E_INVALID, "width must be 1..8192");`. */
om_status om__fail(om_diag *d, om_status st, const char *msg);
/* Starts a message in d->msg and returns a builder over it (a dummy one if d is NULL). */
om__str om__diag_begin(om_diag *d, om_status st, char *scratch, size_t scratch_cap);

/* OM_OK when `a` has `need` bytes left; otherwise OM_E_BUDGET with a message naming
 * `who` and the minimum. Inits call it with their bytes query's figure. */
om_status om__need(om_arena *a, size_t need, const char *who, om_diag *d);

/* om_arena_alloc without the zeroing: the bytes are what the host's buffer held. Only
 * for memory its user writes whole before anything reads it (the frame's per-pixel
 * buffers and bins, megabytes that the eye pass and om__bins_make fill anyway), where
 * zeroing them would be a pass over them on one thread. */
om_status om__arena_alloc_raw(om_arena *a, size_t size, size_t align, void **out, om_diag *d);

/* ---- bits */
/* Index of the lowest set bit of x != 0: one instruction where the compiler offers it
 * (bit masks are scanned per texel), else a loop. */
static inline int om__ctz32(uint32_t x)
{
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_ctz(x);
#else
    int k = 0;
    while (!((x >> k) & 1u)) k++;
    return k;
#endif
}

/* For a per-sample helper that must sit in its loop: gcc's inliner gives up on some
 * once their caller is large, and the call then costs more than the work. */
#if defined(__GNUC__) || defined(__clang__)
#define OM_INLINE static inline __attribute__((always_inline))
#else
#define OM_INLINE static inline
#endif

/* sqrtf and fabsf as the compiler's own instructions where it has them: a firmware
 * built freestanding (-ffreestanding implies -fno-builtin) would otherwise call the
 * library for each. The same correctly rounded results either way. */
static inline float om__sqrtf(float x)
{
#if (defined(__GNUC__) || defined(__clang__)) && defined(__arm__) && defined(__ARM_FP) && (__ARM_FP & 4)
    /* 32-bit ARM with a single-precision unit: its instruction alone. The compiler's
     * own (errno kept, as C asks) tests for a negative argument first, to call the
     * library: a test and a branch per root, and a Cortex-M4F takes a root twice a
     * covered pixel (the exposure marks and the lookup's bias). A negative argument
     * gives a NaN either way; no test or rounding of the engine tells one NaN from
     * another. */
    float r;
    __asm__("vsqrt.f32 %0, %1" : "=t"(r) : "t"(x));
    return r;
#elif defined(__GNUC__) || defined(__clang__)
    return __builtin_sqrtf(x);
#else
    return sqrtf(x);
#endif
}

static inline float om__fabsf(float x)
{
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_fabsf(x);
#else
    return fabsf(x);
#endif
}

/* floor(f) for |f| < 2^31, through a 32-bit conversion (one instruction on a CPU
 * with a float unit; floorf and a conversion to 64 bits are library routines on a
 * Cortex-M4F, the latter through double). Exact: (float)i is f itself once |f| >=
 * 2^23, where every float is an integer, and exact below. */
static inline int32_t om__floorf_i32(float f)
{
    const int32_t i = (int32_t)f;   /* towards zero */
    return i - ((float)i > f);
}

/* ---- vectors */
static inline om_vec3 om__v3(float x, float y, float z) { om_vec3 v; v.x = x; v.y = y; v.z = z; return v; }
static inline om_vec3 om__add(om_vec3 a, om_vec3 b) { return om__v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline om_vec3 om__sub(om_vec3 a, om_vec3 b) { return om__v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline om_vec3 om__scale(om_vec3 a, float s) { return om__v3(a.x * s, a.y * s, a.z * s); }
static inline float om__dot(om_vec3 a, om_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline om_vec3 om__cross(om_vec3 a, om_vec3 b)
{
    return om__v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
om_vec3 om__normalize(om_vec3 a);          /* zero vector stays zero */
bool om__finite3(om_vec3 a);
static inline bool om__finite(float f) { return f == f && f - f == 0.0f; }

/* ---- matrices (row-major, v' = M v) */
om_mat4 om__mat_identity(void);
om_mat4 om__mat_mul(const om_mat4 *a, const om_mat4 *b);
/* w = 1; in line: every lookup of every sample runs it */
static inline om_vec4 om__mat_apply(const om_mat4 *m, om_vec3 p)
{
    const float *a = m->m;
    om_vec4 r;
    r.x = a[0] * p.x + a[1] * p.y + a[2] * p.z + a[3];
    r.y = a[4] * p.x + a[5] * p.y + a[6] * p.z + a[7];
    r.z = a[8] * p.x + a[9] * p.y + a[10] * p.z + a[11];
    r.w = a[12] * p.x + a[13] * p.y + a[14] * p.z + a[15];
    return r;
}
om_vec3 om__mat_apply_dir(const om_mat4 *m, om_vec3 d);    /* w = 0 */
/* View matrix looking from eye to target; fails (false) when degenerate. */
bool om__mat_look_at(om_mat4 *out, om_vec3 eye, om_vec3 target, om_vec3 up);
/* Perspective projection onto clip space with depth z/w in [0, 1] (0 at znear). */
om_mat4 om__mat_perspective(float fovy_deg, float aspect, float znear, float zfar);
/* Orthographic projection of the view-space box to x, y in [-1,1], z in [0,1]. */
om_mat4 om__mat_ortho(float l, float r, float b, float t, float znear, float zfar);

/* ---- deterministic trigonometry and logarithms: our own polynomials in IEEE double,
 * so that every C library and CPU gives the same bits (libm's need not). */
double om__sin(double x);
double om__cos(double x);
double om__tan(double x);
double om__atan(double x);
double om__log2(double x);     /* x > 0 */
double om__exp2(double x);
#define OM_PI 3.14159265358979323846

/* OM_FAST_FLOAT (config.h) picks the float-first paths of a CPU without double
 * hardware. */

/* A cold path kept out of its caller, so that the hot path stays small enough to be
 * inlined where it runs (a hint; GCC and Clang only). */
#if defined(__GNUC__) || defined(__clang__)
#define OM_NOINLINE __attribute__((noinline))
#else
#define OM_NOINLINE
#endif

/* A hint that the line holding *p is about to be written: fetched, and every other
 * core's copy of it dropped, ahead of the store. For an array that one thread writes
 * by parts and every thread then reads (the bins' vertices on a host's threads), each
 * store would otherwise wait for the other cores' copies to be dropped, and a second
 * thread would add more waiting than work. x86 needs
 * its own instruction: the compilers' write hint is a read prefetch there unless the
 * build targets PREFETCHW, which AMD's x86-64 CPUs and Intel's since Broadwell list
 * (CPUID's PRFCHW); older Intel ones are said to take it as a no-op, which this
 * project has not run. It changes no result. */
#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#define OM_PREFETCH_WRITE(p) __asm__("prefetchw %0" : : "m"(*(const char *)(p)))
#elif defined(__GNUC__) || defined(__clang__)
#define OM_PREFETCH_WRITE(p) __builtin_prefetch((p), 1)
#else
#define OM_PREFETCH_WRITE(p) ((void)(p))
#endif

#endif
