/* host_linux.c — the cross driver's host on a hosted C library: print with puts. */
#include <stdio.h>

int om_cross_main(void);

void om_host_puts(const char *line) { puts(line); }

int main(void) { return om_cross_main(); }
