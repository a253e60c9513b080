/* unit/core.c — arena (exhaustion, alignment, rewind, fault injection), pools,
 * deterministic trigonometry and the diagnostic formatter. */
#include "../test.h"
#include "../../engine/testing.h"
#include "../../engine/core/core.h"

#include <math.h>

static void arena_alignment(void)
{
    unsigned char buf[256];
    om_arena a;
    void *p;
    om_arena_init(&a, buf + 1, sizeof buf - 1, "t");   /* deliberately misaligned base */
    CHECK_OK(om_arena_alloc(&a, 3, 1, &p, NULL));
    CHECK(p == buf + 1);
    for (size_t al = 1; al <= 64; al *= 2) {
        CHECK_OK(om_arena_alloc(&a, 1, al, &p, NULL));
        CHECK(((uintptr_t)p & (al - 1)) == 0);
    }
    CHECK(om_arena_alloc(&a, 1, 3, &p, NULL) == OM_E_INVALID);
}

static void arena_exhaustion(void)
{
    unsigned char buf[128 + 16];
    om_arena a;
    om_diag d;
    void *p;
    memset(buf, 0xAB, sizeof buf);
    om_arena_init(&a, buf + 8, 128, "scene");
    CHECK_OK(om_arena_alloc(&a, 100, 4, &p, NULL));
    size_t used = a.used;
    CHECK(om_arena_alloc(&a, 40, 4, &p, &d) == OM_E_BUDGET);
    CHECK(p == NULL);
    CHECK_EQ_U(a.used, used);
    CHECK_EQ_U(d.asked, 40);
    CHECK_EQ_U(d.left, 28);
    CHECK(strstr(d.msg, "scene arena") != NULL);
    CHECK(strstr(d.msg, "40 bytes") != NULL);
    /* a request near SIZE_MAX must not wrap around */
    CHECK(om_arena_alloc(&a, (size_t)-1, 16, &p, NULL) == OM_E_BUDGET);
    CHECK_OK(om_arena_alloc(&a, 28, 1, &p, NULL));
    for (int i = 0; i < 8; i++) CHECK(buf[i] == 0xAB && buf[136 + i] == 0xAB);
    /* a NULL buffer is an arena of zero bytes */
    om_arena_init(&a, NULL, 100, "empty");
    CHECK(om_arena_alloc(&a, 1, 1, &p, NULL) == OM_E_BUDGET);
    CHECK_OK(om_arena_alloc(&a, 0, 1, &p, NULL));
}

static void arena_rewind_peak(void)
{
    unsigned char buf[256];
    om_arena a;
    void *p;
    om_arena_init(&a, buf, sizeof buf, "t");
    CHECK_OK(om_arena_alloc(&a, 10, 1, &p, NULL));
    size_t m = om_arena_mark(&a);
    CHECK_OK(om_arena_alloc(&a, 100, 1, &p, NULL));
    memset(p, 0xFF, 100);
    om_arena_rewind(&a, m);
    CHECK_EQ_U(a.used, 10);
    CHECK_EQ_U(a.peak, 110);
    CHECK_OK(om_arena_alloc(&a, 50, 1, &p, NULL));
    CHECK(((unsigned char *)p)[0] == 0 && ((unsigned char *)p)[49] == 0);   /* zeroed */
    om_arena sub;
    CHECK_OK(om_arena_sub(&a, 64, "child", &sub, NULL));
    CHECK_EQ_U(sub.cap, 64);
    CHECK(om_arena_sub(&a, 4096, "big", &sub, NULL) == OM_E_BUDGET);
    CHECK_EQ_U(sub.cap, 0);
}

static void arena_fault_injection(void)
{
    unsigned char buf[256];
    om_arena a;
    void *p;
    om_arena_init(&a, buf, sizeof buf, "t");
    om__test_fail_carve(&a, 2);
    CHECK_OK(om_arena_alloc(&a, 8, 8, &p, NULL));
    CHECK(om_arena_alloc(&a, 8, 8, &p, NULL) == OM_E_BUDGET);
    CHECK_OK(om_arena_alloc(&a, 8, 8, &p, NULL));
    CHECK(om_arena_need(10, 8) >= 10 + 7);
}

/* Byte counts saturate instead of wrapping: 8 items of SIZE_MAX / 8 + 1 bytes (2^61 on
 * a 64-bit host, 2^29 on a 32-bit one) ask for more than any arena holds, and the
 * pool's carve fails without a write. */
static void sizes_never_wrap(void)
{
    unsigned char buf[1024];
    om_arena a;
    om_pool p;
    om_arena_init(&a, buf, sizeof buf, "t");
    CHECK(om_arena_need(SIZE_MAX, 64) == SIZE_MAX);
    CHECK(om_arena_need(SIZE_MAX - 3, 8) == SIZE_MAX);
    const size_t huge = SIZE_MAX / 8 + 1;
    CHECK(om_pool_bytes(huge, 8) == SIZE_MAX);
    CHECK(om_pool_bytes(SIZE_MAX, 1) == SIZE_MAX);
    CHECK(om_pool_bytes(8, UINT32_MAX) >= (size_t)UINT32_MAX * 8 || om_pool_bytes(8, UINT32_MAX) == SIZE_MAX);
    CHECK(om_pool_init(&p, &a, huge, 8, NULL) == OM_E_BUDGET);
    CHECK(om_pool_init(&p, &a, SIZE_MAX, 2, NULL) == OM_E_BUDGET);
    CHECK(a.used == 0);
}

/* The library says which release it is, as the header does. */
static void version_matches_header(void)
{
    CHECK(strcmp(om_version(), OMBRA_VERSION_STRING) == 0);
}

static void pool_recycles(void)
{
    unsigned char buf[1024];
    om_arena a;
    om_pool pool;
    om_arena_init(&a, buf, sizeof buf, "t");
    CHECK_OK(om_pool_init(&pool, &a, 12, 4, NULL));
    CHECK(a.used <= om_pool_bytes(12, 4));
    void *it[5];
    for (int i = 0; i < 4; i++) CHECK((it[i] = om_pool_get(&pool)) != NULL);
    CHECK(om_pool_get(&pool) == NULL);
    om_pool_put(&pool, it[2]);
    it[4] = om_pool_get(&pool);
    CHECK(it[4] == it[2]);
    CHECK_EQ_U(pool.peak, 4);
    CHECK_EQ_U(om_pool_index(&pool, it[3]), 3);
}

static void trig_matches_libm(void)
{
    double worst = 0;
    for (int i = -2000; i <= 2000; i++) {
        double x = i * 0.01;
        double e1 = fabs(om__sin(x) - sin(x)), e2 = fabs(om__cos(x) - cos(x));
        double e3 = fabs(om__atan(x * 7) - atan(x * 7));
        if (e1 > worst) worst = e1;
        if (e2 > worst) worst = e2;
        if (e3 > worst) worst = e3;
    }
    CHECK_MSG(worst < 1e-14, "worst trig error %g", worst);
    CHECK(fabs(om__tan(OM_PI / 4) - 1.0) < 1e-15);
}

static void formatter(void)
{
    char buf[32];
    om__str s;
    om__str_init(&s, buf, sizeof buf);
    om__str_s(&s, "x=");
    om__str_i(&s, -42);
    om__str_s(&s, " f=");
    om__str_f(&s, 3.14159, 2);
    CHECK(strcmp(buf, "x=-42 f=3.14") == 0);
    om__str_init(&s, buf, 8);
    om__str_s(&s, "0123456789");
    CHECK(strcmp(buf, "0123456") == 0);   /* truncated, still terminated */
    CHECK(strcmp(om_status_str(OM_E_BUDGET), "budget exceeded") == 0);
}

void suite_core(void)
{
    RUN(arena_alignment);
    RUN(arena_exhaustion);
    RUN(arena_rewind_peak);
    RUN(arena_fault_injection);
    RUN(version_matches_header);
    RUN(sizes_never_wrap);
    RUN(pool_recycles);
    RUN(trig_matches_libm);
    RUN(formatter);
}
