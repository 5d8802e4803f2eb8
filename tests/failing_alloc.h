/* An allocator for the tests that fails its fail_at-th call (0: never) and counts the bytes it
 * holds: pass fa_alloc / fa_free with a failing_alloc as the allocator's user pointer. */
#ifndef VPDS_TEST_FAILING_ALLOC_H
#define VPDS_TEST_FAILING_ALLOC_H
#include <stdlib.h>

typedef struct {
    size_t calls, fail_at, live;
} failing_alloc;

static void *fa_alloc(size_t size, void *u)
{
    failing_alloc *a = (failing_alloc *)u;
    if (++a->calls == a->fail_at) return NULL;
    a->live += size;
    return malloc(size);
}

static void fa_free(void *p, size_t size, void *u)
{
    ((failing_alloc *)u)->live -= size;
    free(p);
}
#endif
