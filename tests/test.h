/* test.h — the project's own tiny test runner. A test is a function; CHECK records a
 * failure with file and line and lets the test go on; the runner counts tests, prints
 * each failure, and ends with "N passed, N failed". */
#ifndef OM_TEST_H
#define OM_TEST_H

#include <stdio.h>
#include <string.h>

extern int om_t_failed_checks;   /* checks failed in the current test */

void om_t_report(const char *file, int line, const char *what);
void om_t_run(const char *name, void (*fn)(void));

#define CHECK(c) do { if (!(c)) om_t_report(__FILE__, __LINE__, #c); } while (0)
#define CHECK_MSG(c, ...) do { if (!(c)) { char m_[512]; snprintf(m_, sizeof m_, __VA_ARGS__); \
    om_t_report(__FILE__, __LINE__, m_); } } while (0)
#define CHECK_EQ_U(a, b) do { unsigned long long a_ = (unsigned long long)(a), b_ = (unsigned long long)(b); \
    if (a_ != b_) { char m_[256]; snprintf(m_, sizeof m_, "%s == %s (%llu vs %llu)", #a, #b, a_, b_); \
    om_t_report(__FILE__, __LINE__, m_); } } while (0)
#define CHECK_OK(expr) do { om_status s_ = (expr); if (s_ != OM_OK) { char m_[256]; \
    snprintf(m_, sizeof m_, "%s returned %s", #expr, om_status_str(s_)); \
    om_t_report(__FILE__, __LINE__, m_); } } while (0)
#define RUN(fn) om_t_run(#fn, fn)

#endif
