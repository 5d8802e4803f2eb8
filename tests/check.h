/* Minimal test support: CHECK prints the failing expression and counts it; tests end with
 * CHECK_DONE(), which returns non-zero when anything failed. */
#ifndef VPDS_TEST_CHECK_H
#define VPDS_TEST_CHECK_H
#include <stdio.h>
#include <stdlib.h>

static int check_failures = 0;
static long check_count = 0;

#define CHECK(cond) do { check_count++; if (!(cond)) { check_failures++; \
    fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); } } while (0)
#define CHECK_MSG(cond, ...) do { check_count++; if (!(cond)) { check_failures++; \
    fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
    fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); } } while (0)
#define CHECK_DONE() do { if (check_failures) { fprintf(stderr, "%d check(s) failed\n", \
    check_failures); return 1; } printf("ok: %ld checks\n", check_count); return 0; } while (0)
#endif
