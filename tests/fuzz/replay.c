/* replay.c — runs a libFuzzer target's entry point over files, without libFuzzer, so
 * that `make test` (every compiler, and ASan + UBSan in test-sanitize) replays the
 * inputs in tests/fuzz/regress/ and the seeds: any that crashes, trips a sanitizer or
 * makes the target abort fails the run. Usage: fuzz-replay-TARGET FILE... */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        FILE *f = fopen(argv[i], "rb");
        if (!f) { fprintf(stderr, "replay: cannot open %s\n", argv[i]); return 1; }
        size_t cap = 4096, n = 0, got;
        uint8_t *buf = malloc(cap);
        while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0) {
            n += got;
            if (n == cap) {
                uint8_t *more = realloc(buf, cap * 2);
                if (!more) { free(buf); buf = NULL; break; }
                buf = more;
                cap *= 2;
            }
        }
        fclose(f);
        if (!buf) { fprintf(stderr, "replay: out of memory on %s\n", argv[i]); return 1; }
        /* exactly the input's bytes, as libFuzzer hands them: a read past them is seen */
        uint8_t *exact = malloc(n ? n : 1);
        if (!exact) { free(buf); return 1; }
        memcpy(exact, buf, n);
        free(buf);
        LLVMFuzzerTestOneInput(exact, n);
        free(exact);
    }
    printf("replay: %d input(s), no crash\n", argc - 1);
    return 0;
}
