/* The background grid's candidate lists (bgrid.c) against brute force, in 1D to 5D: for every
 * base cell, vpdsi_bgrid_near_packed returns vpdsi_bgrid_near's samples in its order with their
 * points, every sample within reach of the cell among them (samples in the border too), and
 * vpdsi_bgrid_slide, carried along each row of base cells on axis 0 from its first, holds the
 * same set of samples with the same points at every step. VPDS_TEST_QUICK (valgrind): one grid
 * per dimension, smaller in 4D and 5D, the brute force every seventh base cell. */
#include "check.h"
#include "vpds.h"
#include "bgrid.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static unsigned long long rng_state = 4242;
static int quick;
static double unit(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)((rng_state ^ (rng_state >> 29)) >> 11) * (1.0 / 9007199254740992.0);
}

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* Squared distance from x to the box [lo, hi]. */
static double box_gap2(int d, const double *x, const double *lo, const double *hi)
{
    double s = 0;
    int k;
    for (k = 0; k < d; k++) {
        double e = x[k] < lo[k] ? lo[k] - x[k] : x[k] > hi[k] ? x[k] - hi[k] : 0;
        s += e * e;
    }
    return s;
}

/* The list at base cell c (padded index at), against near and brute force; its set, sorted,
 * into sorted. */
/* n_pts 0: the brute force skipped. */
static void check_cell(const vpdsi_bgrid *g, const double *x, size_t n_pts, const uint64_t *c,
                       uint64_t at, double reach, int32_t *out, double *px, uint16_t *tag,
                       int32_t *plain, int32_t *sorted, size_t *n_sorted)
{
    int d = g->dim, k;
    size_t n = vpdsi_bgrid_near_packed(g, x, at, out, px, tag), np = vpdsi_bgrid_near(g, at, plain), i;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    CHECK(n == np && memcmp(out, plain, n * sizeof *out) == 0);
    for (i = 0; i < n; i++) CHECK(memcmp(px + i * (size_t)d, x + (size_t)out[i] * (size_t)d, (size_t)d * sizeof *px) == 0);
    for (k = 0; k < d; k++) {
        lo[k] = g->lo[k] + (double)c[k] * g->side[k];
        hi[k] = lo[k] + g->side[k];
    }
    memcpy(sorted, out, n * sizeof *out);
    qsort(sorted, n, sizeof *sorted, cmp_i32);
    for (i = 0; i < n_pts; i++) { /* every sample the grid holds within reach is listed */
        int32_t key = (int32_t)i;
        if (box_gap2(d, x + i * (size_t)d, lo, hi) < reach * reach * (1 - 1e-9))
            CHECK_MSG(bsearch(&key, sorted, n, sizeof *sorted, cmp_i32) != NULL, "%dD: sample %zu missing", d, i);
    }
    *n_sorted = n;
}

static void check_grid(int d, int rep)
{
    vpdsi_mem mem;
    vpdsi_bgrid g;
    uint64_t n0[VPDS_MAX_DIM], c[VPDS_MAX_DIM], cells = 1;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], side[VPDS_MAX_DIM], reach = 1, *x, *px, *spx;
    size_t cap, n_pts = 0, i, n_slide = 0, n_ref;
    int32_t *out, *plain, *sorted, *slid, *ssorted;
    uint16_t *tag, *stag;
    int k;
    memset(&g, 0, sizeof g);
    vpdsi_mem_init(&mem, NULL);
    for (k = 0; k < d; k++) {
        n0[k] = 2 + (uint64_t)(unit() * (d <= 2 ? 12 : d == 3 ? 7 : quick ? 2 : 4));
        /* the run's cells: diagonal at most the reach (one sample each), some narrower */
        side[k] = reach / sqrt((double)d) * (rep % 2 ? 1 : 0.55 + 0.45 * unit());
        lo[k] = -0.3 + unit();
        hi[k] = lo[k] + (double)n0[k] * side[k];
        cells *= n0[k] + 8;
    }
    CHECK(vpdsi_bgrid_setup(&g, &mem, d, n0, lo, side, reach) == 0);
    cap = (size_t)cells;
    x = (double *)malloc(cap * (size_t)d * sizeof *x);
    px = (double *)malloc((g.n_stencil + 1) * (size_t)d * sizeof *px);
    spx = (double *)malloc((g.n_stencil + 1) * (size_t)d * sizeof *spx);
    out = (int32_t *)malloc((g.n_stencil + 1) * sizeof *out);
    plain = (int32_t *)malloc((g.n_stencil + 1) * sizeof *plain);
    sorted = (int32_t *)malloc((g.n_stencil + 1) * sizeof *sorted);
    slid = (int32_t *)malloc((g.n_stencil + 1) * sizeof *slid);
    ssorted = (int32_t *)malloc((g.n_stencil + 1) * sizeof *ssorted);
    tag = (uint16_t *)malloc((g.n_stencil + 1) * sizeof *tag);
    stag = (uint16_t *)malloc((g.n_stencil + 1) * sizeof *stag);
    /* random points in and around the box (the border holds fixed points outside it); a point
     * whose cell is taken is dropped, as a run never places two in one cell */
    for (i = 0; i < cap; i++) {
        double *p = x + n_pts * (size_t)d;
        for (k = 0; k < d; k++) p[k] = lo[k] - 2.5 * side[k] + unit() * (hi[k] - lo[k] + 5 * side[k]);
        if (vpdsi_bgrid_place(&g, p, lo, hi, (int32_t)n_pts) == 0) n_pts++;
    }
    /* every base cell in lattice order; along axis 0 the list slides from the row's first */
    memset(c, 0, sizeof c);
    for (;;) {
        uint64_t at = vpdsi_bgrid_index(&g, c);
        check_cell(&g, x, quick && at % 7 ? 0 : n_pts, c, at, reach, out, px, tag, plain, sorted, &n_ref);
        if (c[0] == 0) {
            n_slide = vpdsi_bgrid_near_packed(&g, x, at, slid, spx, stag);
        } else {
            n_slide = vpdsi_bgrid_slide(&g, x, at, slid, spx, stag, n_slide);
        }
        for (i = 0; i < n_slide; i++)
            CHECK(memcmp(spx + i * (size_t)d, x + (size_t)slid[i] * (size_t)d, (size_t)d * sizeof *spx) == 0);
        memcpy(ssorted, slid, n_slide * sizeof *slid);
        qsort(ssorted, n_slide, sizeof *ssorted, cmp_i32);
        CHECK_MSG(n_slide == n_ref && memcmp(ssorted, sorted, n_ref * sizeof *sorted) == 0,
                  "%dD: the slid list differs from the stencil's at cell %llu (%zu against %zu)", d,
                  (unsigned long long)c[0], n_slide, n_ref);
        for (k = 0; k < d; k++) {
            if (++c[k] < n0[k]) break;
            c[k] = 0;
        }
        if (k == d) break;
    }
    vpdsi_bgrid_release(&g, &mem);
    free(x); free(px); free(spx); free(out); free(plain); free(sorted); free(slid); free(ssorted);
    free(tag); free(stag);
}

int main(void)
{
    int d, rep;
    quick = getenv("VPDS_TEST_QUICK") != NULL;
    for (d = 1; d <= VPDSI_BGRID_MAX_DIM; d++)
        for (rep = 0; rep < (quick ? 1 : d <= 3 ? 6 : 2); rep++) check_grid(d, rep);
    CHECK_DONE();
}
