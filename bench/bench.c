#define _POSIX_C_SOURCE 199309L
/* libvpds workloads for `make bench`. Prints "name n seconds peak_bytes" per line.
 * usage: bench uniform DIM RADIUS | tworadii DIM RADIUS INHIBITION | ramp RULE | floor N DIM
 *        | annulus RADIUS (a domain) | stream DIM RADIUS N STEPS (prints one line per N/STEPS samples: the cost along n)
 *        | threads DIM RADIUS TILES THREADS (vpds_tiling_run of TILES per axis on THREADS threads) */
#include "rng.h"
#include "vpds.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double ramp(const double *x, void *u) { (void)u; return 0.001 + 0.3 * x[0]; }
/* the annulus 0.2 <= |x - (0.5, 0.5)| <= 0.45 as a signed distance */
static double annulus(const double *x, void *u)
{
    double r = sqrt((x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.5) * (x[1] - 0.5));
    (void)u;
    return r - 0.45 > 0.2 - r ? r - 0.45 : 0.2 - r;
}

static int run(const char *name, vpds_desc *d)
{
    vpds_sampler *s;
    vpds_status st;
    double t0;
    vpds_stats stats;
    if (vpds_create(d, &s) != VPDS_OK) return 1;
    t0 = now();
    st = vpds_run(s);
    if (st != VPDS_OK) {
        fprintf(stderr, "%s: %s\n", name, vpds_last_error(s));
        return 1;
    }
    stats = vpds_get_stats(s);
    printf("%s %zu %.6f %zu\n", name, vpds_count(s), now() - t0, stats.peak_bytes);
    vpds_destroy(s);
    return 0;
}

/* The continuous stream from an empty sampler: N calls of vpds_next, timed in STEPS intervals. */
static int stream(vpds_desc *d, size_t n, size_t steps)
{
    vpds_sampler *s;
    double x[VPDS_MAX_DIM], t, t0 = now(), t_step = t0;
    size_t i, every = n / steps ? n / steps : 1;
    if (vpds_create(d, &s) != VPDS_OK) return 1;
    for (i = 1; i <= n; i++) {
        vpds_status st = vpds_next(s, 0.0, x, &t);
        if (st != VPDS_OK) {
            fprintf(stderr, "stream: %s\n", vpds_last_error(s));
            return 1;
        }
        if (i % every == 0 || i == n) {
            double now_s = now();
            /* name n seconds_total peak_bytes seconds_of_this_interval t */
            printf("stream %zu %.6f %zu %.6f %.6g\n", i, now_s - t0, vpds_get_stats(s).peak_bytes,
                   now_s - t_step, t);
            fflush(stdout);
            t_step = now_s;
        }
    }
    vpds_destroy(s);
    return 0;
}

/* A whole tiling (tiles per axis) on some threads: its wall time against one run's. */
static int tiled(vpds_desc *d, uint64_t per_axis, int threads)
{
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    uint64_t tiles[VPDS_MAX_DIM];
    vpds_tiling *tg;
    vpds_tiled *out;
    char msg[512];
    double t0;
    int k;
    for (k = 0; k < d->dim; k++) tiles[k] = per_axis;
    td.sampler = d;
    td.tiles = tiles;
    rd.threads = threads;
    if (vpds_tiling_create(&td, &tg) != VPDS_OK) return 1;
    t0 = now();
    if (vpds_tiling_run(tg, &rd, &out, msg, sizeof msg) != VPDS_OK) {
        fprintf(stderr, "threads: %s\n", msg);
        return 1;
    }
    printf("threads %zu %.6f 0\n", vpds_tiled_count(out), now() - t0);
    vpds_tiled_destroy(out);
    vpds_tiling_destroy(tg);
    return 0;
}

int main(int argc, char **argv)
{
    vpds_desc d = vpds_default_desc();
    d.seed = 1;
    if (argc >= 4 && !strcmp(argv[1], "uniform")) {
        d.dim = atoi(argv[2]);
        d.radius = atof(argv[3]);
        return run("uniform", &d);
    }
    if (argc >= 5 && !strcmp(argv[1], "tworadii")) {
        d.dim = atoi(argv[2]);
        d.radius = atof(argv[3]);
        d.inhibition = atof(argv[4]);
        return run("tworadii", &d);
    }
    if (argc >= 6 && !strcmp(argv[1], "threads")) {
        d.dim = atoi(argv[2]);
        d.radius = atof(argv[3]);
        return tiled(&d, (uint64_t)atoi(argv[4]), atoi(argv[5]));
    }
    if (argc >= 3 && !strcmp(argv[1], "annulus")) {
        d.radius = atof(argv[2]);
        d.domain = annulus;
        return run("annulus", &d);
    }
    if (argc >= 6 && !strcmp(argv[1], "stream")) {
        d.dim = atoi(argv[2]);
        d.radius = atof(argv[3]);
        return stream(&d, (size_t)atof(argv[4]), (size_t)atoi(argv[5]));
    }
    if (argc >= 3 && !strcmp(argv[1], "ramp")) {
        /* the paper's Figure 1 ramp on a box 400 times taller: about a million samples */
        double lo[2] = {0, 0}, hi[2] = {1, 400};
        d.lo = lo;
        d.hi = hi;
        d.sizing = ramp;
        d.lipschitz = 0.3;
        d.rule = !strcmp(argv[2], "prior") ? VPDS_RULE_PRIOR : !strcmp(argv[2], "current") ? VPDS_RULE_CURRENT
                 : !strcmp(argv[2], "bigger") ? VPDS_RULE_BIGGER : VPDS_RULE_SMALLER;
        return run(argv[2], &d);
    }
    if (argc >= 4 && !strcmp(argv[1], "floor")) {
        /* the floor: as many uniform random points with the library's own generator */
        size_t n = (size_t)atof(argv[2]), i, dim = (size_t)atoi(argv[3]);
        double *x = (double *)malloc(n * dim * sizeof(double)), t0, sum = 0;
        vpdsi_rng r;
        vpdsi_rng_seed(&r, 1);
        t0 = now();
        for (i = 0; i < n * dim; i++) x[i] = vpdsi_rng_unit(&r);
        t0 = now() - t0;
        for (i = 0; i < n * dim; i += 4096) sum += x[i];
        printf("floor %zu %.6f %zu\n", n, t0 + 0 * sum, n * dim * sizeof(double));
        free(x);
        return 0;
    }
    fprintf(stderr, "usage: bench uniform DIM RADIUS | tworadii DIM RADIUS INHIBITION | ramp RULE"
                    " | floor N DIM | stream DIM RADIUS N STEPS\n");
    return 2;
}
