/* test_platform.c — the PPM/PGM sinks (headers, streamed rows, mask values, format
 * conversion) and file reading errors that name the file. */
#include "test.h"
#include "../platform/platform.h"

#include <stdlib.h>

static void ppm_round_trip(void)
{
    const char *img = "build/test-sink.ppm", *msk = "build/test-sink.pgm";
    om_ppm_sink k;
    om_diag d;
    CHECK_OK(om_ppm_open(&k, img, msk, 3, 2, &d));
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
    om_strip st = {3, 2, 0, 1, smp, term};
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
    CHECK(om_ppm_open(&k, "build/no/such/dir/x.ppm", NULL, 4, 4, &d) == OM_E_IO);
    CHECK(strstr(d.msg, "x.ppm") != NULL);
    om_ppm_close(&k, NULL);
}

void suite_platform(void)
{
    RUN(ppm_round_trip);
    RUN(file_errors_name_the_file);
}
