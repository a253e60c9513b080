/* main.c — runs every suite; a suite is a function that RUNs its tests. The optional
 * argument is a substring: only tests whose name contains it run. */
#include "test.h"
#include "suites.h"

#include <stdlib.h>

int om_t_failed_checks;
static int passed, failed;
static const char *filter;

void om_t_report(const char *file, int line, const char *what)
{
    om_t_failed_checks++;
    fprintf(stderr, "  FAIL %s:%d: %s\n", file, line, what);
}

void om_t_run(const char *name, void (*fn)(void))
{
    if (filter && !strstr(name, filter)) return;
    om_t_failed_checks = 0;
    fn();
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
