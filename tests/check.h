/* Minimal assertions for plain-C tests (after libuv's test helpers). Each failing check
 * prints file:line and the values, and the test exits 1 at the end (CHECK_DONE). */
#ifndef GR_TEST_CHECK_H
#define GR_TEST_CHECK_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int gr_check_failures = 0;

#define CHECK(cond) do { if (!(cond)) { \
    fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
    gr_check_failures++; } } while (0)
#define CHECK_MSG(cond, ...) do { if (!(cond)) { \
    fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
    fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); gr_check_failures++; } } while (0)
/* |a - b| <= tol */
#define CHECK_NEAR(a, b, tol) do { double ca_ = (double)(a), cb_ = (double)(b); \
    if (!(fabs(ca_ - cb_) <= (tol))) { fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.9g, %s = %.9g, tol %.3g\n", \
    __FILE__, __LINE__, #a, ca_, #b, cb_, (double)(tol)); gr_check_failures++; } } while (0)
/* |a - b| <= rel * |b| */
#define CHECK_REL(a, b, rel) do { double ca_ = (double)(a), cb_ = (double)(b); \
    if (!(fabs(ca_ - cb_) <= (rel) * fabs(cb_))) { fprintf(stderr, "%s:%d: CHECK_REL failed: %s = %.9g, %s = %.9g, rel %.3g (got %.3g)\n", \
    __FILE__, __LINE__, #a, ca_, #b, cb_, (double)(rel), fabs(ca_ - cb_) / fabs(cb_)); gr_check_failures++; } } while (0)
#define CHECK_OK(st, err) do { if ((st) != 0) { fprintf(stderr, "%s:%d: status %d: %s\n", \
    __FILE__, __LINE__, (int)(st), (err).msg); gr_check_failures++; } } while (0)
#define CHECK_DONE() do { if (gr_check_failures) { fprintf(stderr, "%d check(s) failed\n", gr_check_failures); return 1; } \
    printf("all checks passed\n"); return 0; } while (0)

#endif
