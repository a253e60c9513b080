/* main.c — runs every suite; a suite is a function that RUNs its tests. The optional
 * argument is a substring: only tests whose name contains it run. */
#include "test.h"
#include "suites.h"

#include <stdlib.h>
#include <time.h>

int om_t_failed_checks;
static int passed, failed;
static const char *filter;

/* Names are unique across suites (a filter names one test), and a test that takes
 * more than a second of CPU says so, so that the slow ones are known. */
#define MAX_TESTS 1024
static const char *names[MAX_TESTS];
static int nnames;
#define SLOW_SECONDS 1.0

void om_t_report(const char *file, int line, const char *what)
{
    om_t_failed_checks++;
    fprintf(stderr, "  FAIL %s:%d: %s\n", file, line, what);
}

void om_t_run(const char *name, void (*fn)(void))
{
    for (int i = 0; i < nnames; i++)
        if (!strcmp(names[i], name)) {
            failed++;
            fprintf(stderr, "FAILED %s: another suite has a test of this name\n", name);
            return;
        }
    if (nnames < MAX_TESTS) names[nnames++] = name;
    if (filter && !strstr(name, filter)) return;
    om_t_failed_checks = 0;
    const clock_t t0 = clock();
    fn();
    const double secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (secs > SLOW_SECONDS) fprintf(stderr, "  slow: %s %.1f s\n", name, secs);
    if (om_t_failed_checks) {
        failed++;
        fprintf(stderr, "FAILED %s (%d checks)\n", name, om_t_failed_checks);
    } else {
        passed++;
    }
}

int main(int argc, char **argv)
{
    filter = argc > 1 ? argv[1] : NULL;
#define X(suite) suite();
    OM_SUITES
#undef X
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
