/* unit/platform.c — the PPM/PGM sinks (headers, streamed rows, mask values, format
 * conversion), output files that keep the old bytes until the new ones are whole,
 * the mesh loader (each file once, long directories kept), file reading errors
 * that name the file, and the pool of threads (platform/jobs.c). */
#define _XOPEN_SOURCE 700   /* mkdir, dirent */
#include "../test.h"
#include "../../platform/platform.h"

#include <dirent.h>
#include <stdlib.h>
#include <sys/stat.h>

static void ppm_round_trip(void)
{
    const char *img = "build/test-sink.ppm", *msk = "build/test-sink.pgm";
    om_ppm_sink k;
    om_diag d;
    CHECK_OK(om_ppm_open(&k, img, msk, 3, 2, false, &d));
    /* two strips of one row, RGB565 framebuffer */
    uint8_t px[6];
    om_framebuffer fb = {OM_RGB565, 3, 1, 6, px};
    om_sample smp[3];
    om_term term[3];
    memset(smp, 0, sizeof smp);
    memset(term, 0, sizeof term);
    smp[0].tri = 1; term[0].r = term[0].g = term[0].b = 255; term[0].flags = OM_TERM_EXPOSED;
    smp[1].tri = 2; term[1].r = 255; term[1].g = term[1].b = 128; term[1].flags = OM_TERM_EXPOSED;
    smp[2].tri = OM_NO_TRI;
    om_strip st = {3, 2, 0, 1, smp, term, {0, 0, 0}};
    uint16_t words[3] = {0xF800, 0x07E0, 0x001F};   /* red, green, blue */
    for (int i = 0; i < 3; i++) { px[2 * i] = (uint8_t)(words[i] & 0xFF); px[2 * i + 1] = (uint8_t)(words[i] >> 8); }
    CHECK_OK(om_ppm_strip(&k, &st, &fb));
    st.y0 = 1;
    smp[0].tri = OM_NO_TRI;
    CHECK_OK(om_ppm_strip(&k, &st, &fb));
    CHECK_OK(om_ppm_close(&k, &d));
    char *data;
    size_t len;
    CHECK_OK(om_file_read(img, &data, &len, &d));
    const char *hdr = "P6\n3 2\n255\n";
    CHECK(len == strlen(hdr) + 18 && !memcmp(data, hdr, strlen(hdr)));
    const unsigned char *p = (const unsigned char *)data + strlen(hdr);
    CHECK(p[0] == 255 && p[1] == 0 && p[2] == 0 && p[3] == 0 && p[4] == 255 && p[5] == 0 &&
          p[6] == 0 && p[7] == 0 && p[8] == 255);
    free(data);
    CHECK_OK(om_file_read(msk, &data, &len, &d));
    const char *mh = "P5\n3 2\n255\n";
    CHECK(len == strlen(mh) + 6 && !memcmp(data, mh, strlen(mh)));
    p = (const unsigned char *)data + strlen(mh);
    CHECK(p[0] == 255 && p[1] == 0 && p[2] == 128 && p[3] == 128 && p[4] == 0 && p[5] == 128);
    free(data);
}

static void file_errors_name_the_file(void)
{
    char *data;
    size_t len;
    om_diag d;
    CHECK(om_file_read("build/no/such/file.obj", &data, &len, &d) == OM_E_NOTFOUND);
    CHECK(strstr(d.msg, "build/no/such/file.obj") != NULL);
    om_ppm_sink k;
    CHECK(om_ppm_open(&k, "build/no/such/dir/x.ppm", NULL, 4, 4, false, &d) == OM_E_IO);
    CHECK(strstr(d.msg, "x.ppm") != NULL);
    CHECK(k.row == NULL && k.img.f == NULL);   /* nothing left open or allocated */
    om_ppm_discard(&k);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (f) { fputs(text, f); fclose(f); }
}

static bool file_is(const char *path, const char *text)
{
    char *data;
    size_t len;
    om_diag d;
    if (om_file_read(path, &data, &len, &d) != OM_OK) return false;
    bool same = len == strlen(text) && !memcmp(data, text, len);
    free(data);
    return same;
}

/* Entries in a directory other than . and .. (a temporary left behind shows here). */
static int entries(const char *dir)
{
    DIR *dp = opendir(dir);
    int n = 0;
    for (struct dirent *e; dp && (e = readdir(dp)) != NULL;)
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    if (dp) closedir(dp);
    return n;
}

static void outputs_replace_whole_or_not_at_all(void)
{
    const char *dir = "build/test-out", *a = "build/test-out/a.ppm", *b = "build/test-out/b.pgm";
    mkdir(dir, 0777);
    remove(a);
    remove(b);
    write_file(a, "old image");
    om_diag d;
    om_out o, p;
    /* discarded: the old file's bytes stay, and no temporary remains */
    CHECK_OK(om_out_open(&o, a, &d));
    CHECK(o.tmp != NULL && !o.direct);
    CHECK(om_out_write(&o, "new", 3));
    CHECK(file_is(a, "old image"));
    om_out_discard(&o);
    CHECK(file_is(a, "old image"));
    CHECK_EQ_U(entries(dir), 1);
    /* two committed together: both appear only at the commit */
    CHECK_OK(om_out_open(&o, a, &d));
    CHECK_OK(om_out_open(&p, b, &d));
    CHECK(om_out_write(&o, "new image", 9) && om_out_write(&p, "mask", 4));
    CHECK(file_is(a, "old image"));
    om_out *both[2] = {&o, &p};
    CHECK_OK(om_out_commit(both, 2, &d));
    CHECK(file_is(a, "new image") && file_is(b, "mask"));
    CHECK_EQ_U(entries(dir), 2);
    /* one of a set fails: neither is replaced, and the failure names its file */
    CHECK_OK(om_out_open(&o, a, &d));
    CHECK_OK(om_out_open(&p, "/dev/full", &d));
    CHECK(p.direct && p.tmp == NULL);
    om_out_write(&o, "newer", 5);
    om_out_write(&p, "x", 1);
    CHECK(om_out_commit(both, 2, &d) == OM_E_IO);
    CHECK_MSG(strstr(d.msg, "/dev/full") && strstr(d.msg, "No space left"), "%s", d.msg);
    CHECK(file_is(a, "new image"));
    CHECK_EQ_U(entries(dir), 2);
    /* a sink whose render failed leaves the old image */
    om_ppm_sink k;
    CHECK_OK(om_ppm_open(&k, a, NULL, 2, 2, false, &d));
    om_ppm_discard(&k);
    CHECK(file_is(a, "new image"));
    /* names */
    CHECK(om_out_same(a, "build/test-out/../test-out/a.ppm"));
    CHECK(om_out_same("build/test-out/c.ppm", "build/./test-out/c.ppm"));   /* not there yet */
    CHECK(!om_out_same(a, b));
    CHECK(om_out_same("-", "/dev/stdout"));
    CHECK(!om_out_same("/dev/null", "/dev/zero"));
    CHECK(!om_out_same("/dev/null", "/dev/null"));   /* discarding twice loses nothing */
    CHECK(om_out_is_direct("-") && om_out_is_direct("/dev/null") && !om_out_is_direct(a));
}

static void grey_sink_writes_pgm(void)
{
    const char *img = "build/test-grey.pgm";
    om_ppm_sink k;
    om_diag d;
    CHECK_OK(om_ppm_open(&k, img, NULL, 2, 1, true, &d));
    uint8_t px[2] = {7, 200};
    om_framebuffer fb = {OM_L8, 2, 1, 2, px};
    om_sample smp[2];
    om_term term[2];
    memset(smp, 0, sizeof smp);
    memset(term, 0, sizeof term);
    om_strip st = {2, 1, 0, 1, smp, term, {0, 0, 0}};
    CHECK_OK(om_ppm_strip(&k, &st, &fb));
    CHECK_OK(om_ppm_close(&k, &d));
    CHECK(file_is(img, "P5\n2 1\n255\n\x07\xc8"));
}

static void loader_reads_each_file_once(void)
{
    /* a directory path longer than any fixed buffer the loader once had (1 KB) */
    char dir[1400] = "build/test-long";
    mkdir(dir, 0777);
    while (strlen(dir) < 1200) {
        strcat(dir, "/dddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddd");
        mkdir(dir, 0777);
    }
    char scene[1500], obj[1500];
    snprintf(scene, sizeof scene, "%s/s.scene", dir);
    snprintf(obj, sizeof obj, "%s/m.obj", dir);
    write_file(obj, "v 0 0 0\n");
    write_file("build/m.obj", "not this one\n");
    om_file_loader fl;
    CHECK_OK(om_file_loader_init(&fl, scene));
    om_loader ld = om_file_loader_get(&fl);
    const char *data, *again;
    size_t len, len2;
    CHECK_OK(ld.load(ld.user, "m.obj", &data, &len));
    CHECK(len == 8 && !memcmp(data, "v 0 0 0\n", 8));
    write_file(obj, "v 1 1 1\nv 2 2 2\n");   /* changed between passes: not seen */
    CHECK_OK(ld.load(ld.user, "m.obj", &again, &len2));
    CHECK(again == data && len2 == len);
    /* many files, no fixed limit (the loader once held 64) */
    for (int i = 0; i < 100; i++) {
        char name[32], path[1600];
        snprintf(name, sizeof name, "f%d.obj", i);
        snprintf(path, sizeof path, "%s/%s", dir, name);
        write_file(path, "v 0 0 0\n");
        CHECK_OK(ld.load(ld.user, name, &data, &len));
    }
    CHECK_EQ_U(fl.nfiles, 101);
    om_file_loader_free(&fl);
}

/* The platform's pool runs every index of every call once, whatever the threads and n
 * (each thread's chunk first, then the others' next jobs): counted per index. */
typedef struct once_ctx {
    om_jobs *pool;
    uint32_t threads, count[100], bad_worker;
} once_ctx;

static void count_once(void *user, uint32_t i)
{
    once_ctx *o = (once_ctx *)user;
    __atomic_fetch_add(&o->count[i], 1u, __ATOMIC_RELAXED);
    if (om_jobs_worker(o->pool) >= o->threads) __atomic_store_n(&o->bad_worker, 1u, __ATOMIC_RELAXED);
}

static void pool_each_once(void)
{
    static const uint32_t threads[] = {1, 2, 3, 7, 16}, ns[] = {0, 1, 2, 3, 5, 7, 16, 17, 31, 64, 100};
    for (int k = 0; k < 5; k++) {
        once_ctx o;
        memset(&o, 0, sizeof o);
        o.threads = threads[k];
        CHECK_OK(om_jobs_start(&o.pool, threads[k], NULL));
        for (int round = 0; round < 3; round++)
            for (int c = 0; c < 11; c++) {
                memset(o.count, 0, sizeof o.count);
                om_jobs_for(o.pool, count_once, &o, ns[c]);
                for (uint32_t i = 0; i < 100; i++)
                    CHECK_MSG(o.count[i] == (i < ns[c]), "%u threads, n %u: job %u ran %u times", threads[k],
                              ns[c], i, o.count[i]);
            }
        CHECK(!o.bad_worker);
        om_jobs_stop(o.pool);
    }
}

void suite_platform(void)
{
    RUN(ppm_round_trip);
    RUN(file_errors_name_the_file);
    RUN(outputs_replace_whole_or_not_at_all);
    RUN(grey_sink_writes_pgm);
    RUN(loader_reads_each_file_once);
    RUN(pool_each_once);
}
