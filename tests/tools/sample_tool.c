/* Samples one named configuration and writes it for the independent checkers in tests/py:
 * int64 n, int64 dim, then n*dim doubles x, n radii, n scales t.
 * usage: sample_tool OUT dim rule sizing radius seed lo hi [budget [weighted]] [KEY=VALUE...]
 *   rule: prior|current|bigger|smaller; sizing: const|ramp|radial (the paper's Figures 1, 10),
 *   mild (0.04 + 0.04 x), steep (0.05 + 0.2 x, the fuzzers' ramp) or wide (1.2 + 0.4 x, for 9D
 *   and up); weighted: 1 for the
 *   weighted-bias-free process (Eq. 12)
 *   KEY=VALUE: inhibition=F (two radii), periodic=MASK (bit k: axis k), domain=ball (the ball
 *   of radius 0.4 about the box centre), version=N (desc.algorithm_version), run=0 (no
 *   vpds_run: a stream from empty), stream=N (then N events of vpds_next, t_min 0),
 *   hi0=F (axis 0 ends at F: a longer box, for a few samples in high dimension) */
#include "vpds.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double ramp(const double *x, void *u) { (void)u; return 0.001 + 0.3 * x[0]; }
static double mild(const double *x, void *u) { (void)u; return 0.04 + 0.04 * x[0]; }
static double wide(const double *x, void *u) { (void)u; return 1.2 + 0.4 * x[0]; }
static double steep(const double *x, void *u) { (void)u; return 0.05 + 0.2 * fabs(x[0]); }
static double ball(const double *x, void *u)
{
    int dim = *(int *)u, k;
    double d2 = 0;
    for (k = 0; k < dim; k++) d2 += (x[k] - 0.5) * (x[k] - 0.5);
    return sqrt(d2) - 0.4;
}
static double radial(const double *x, void *u)
{
    int dim = *(int *)u, k;
    double d2 = 0;
    for (k = 0; k < dim; k++) d2 += (x[k] - 0.5) * (x[k] - 0.5);
    return 0.015 + (0.00015 - 0.015) * fabs(sin(8 * 3.14159265358979323846 * sqrt(d2)));
}

int main(int argc, char **argv)
{
    vpds_desc d = vpds_default_desc();
    vpds_sampler *s;
    vpds_status st;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    int dim, k, periodic[VPDS_MAX_DIM] = {0}, positional = argc, a, run = 1;
    long events = 0, e;
    FILE *f;
    long long hdr[2];
    vpds_stats stats;
    if (argc < 9) {
        fprintf(stderr, "usage: %s OUT dim rule sizing radius seed lo hi [budget]\n", argv[0]);
        return 2;
    }
    for (a = 9; a < argc; a++)
        if (strchr(argv[a], '=') && positional == argc) positional = a;
    dim = atoi(argv[2]);
    d.dim = dim;
    for (k = 0; k < dim && k < VPDS_MAX_DIM; k++) {
        lo[k] = atof(argv[7]);
        hi[k] = atof(argv[8]);
    }
    d.lo = lo;
    d.hi = hi;
    d.rule = !strcmp(argv[3], "prior")     ? VPDS_RULE_PRIOR
             : !strcmp(argv[3], "current") ? VPDS_RULE_CURRENT
             : !strcmp(argv[3], "bigger")  ? VPDS_RULE_BIGGER
                                           : VPDS_RULE_SMALLER;
    d.radius = atof(argv[5]);
    if (!strcmp(argv[4], "ramp")) {
        d.sizing = ramp;
        d.lipschitz = 0.3;
    } else if (!strcmp(argv[4], "mild")) {
        d.sizing = mild;
        d.lipschitz = 0.04;
        d.radius_min = 0.04;
    } else if (!strcmp(argv[4], "wide")) {
        d.sizing = wide;
        d.lipschitz = 0.4;
        d.radius_min = 1.2;
    } else if (!strcmp(argv[4], "steep")) {
        d.sizing = steep;
        d.lipschitz = 0.2;
    } else if (!strcmp(argv[4], "radial")) {
        d.sizing = radial;
        d.sizing_user = &dim;
        d.lipschitz = 0.01485 * 8 * 3.14159265358979323846 * (1 + 1e-9);
    }
    d.seed = strtoull(argv[6], NULL, 10);
    if (positional > 9) d.budget = strtoull(argv[9], NULL, 10);
    if (positional > 10) d.weighted = atoi(argv[10]);
    for (a = positional; a < argc; a++) {
        const char *v = strchr(argv[a], '=') + 1;
        if (!strncmp(argv[a], "inhibition=", 11)) {
            d.inhibition = atof(v);
        } else if (!strncmp(argv[a], "periodic=", 9)) {
            for (k = 0; k < dim && k < VPDS_MAX_DIM; k++) periodic[k] = (atoi(v) >> k) & 1;
            d.periodic = periodic;
        } else if (!strcmp(argv[a], "domain=ball")) {
            d.domain = ball;
            d.domain_user = &dim;
        } else if (!strncmp(argv[a], "hi0=", 4)) {
            hi[0] = atof(v); /* a longer first axis: a few samples in high dimension */
        } else if (!strncmp(argv[a], "run=", 4)) {
            run = atoi(v);
        } else if (!strncmp(argv[a], "stream=", 7)) {
            events = atol(v);
        } else if (!strncmp(argv[a], "version=", 8)) {
            d.algorithm_version = (uint32_t)atoi(v);
        } else {
            fprintf(stderr, "sample_tool: unknown option '%s'\n", argv[a]);
            return 2;
        }
    }
    if ((st = vpds_create(&d, &s)) != VPDS_OK) {
        char msg[512];
        vpds_validate(&d, msg, sizeof msg);
        fprintf(stderr, "vpds_create: %s: %s\n", vpds_status_string(st), msg);
        return 1;
    }
    st = VPDS_OK;
    while (run && (st = vpds_run(s)) == VPDS_PAUSED) {}
    if (st != VPDS_OK) {
        fprintf(stderr, "vpds_run: %s: %s\n", vpds_status_string(st), vpds_last_error(s));
        return 1;
    }
    for (e = 0; e < events; e++) {
        double x[VPDS_MAX_DIM], t;
        st = vpds_next(s, 0.0, x, &t);
        if (st == VPDS_STREAM_END) break;
        if (st != VPDS_OK) {
            fprintf(stderr, "vpds_next (event %ld): %s: %s\n", e, vpds_status_string(st),
                    vpds_last_error(s));
            return 1;
        }
    }
    stats = vpds_get_stats(s);
    hdr[0] = (long long)vpds_count(s);
    hdr[1] = dim;
    f = fopen(argv[1], "wb");
    if (!f) return 1;
    fwrite(hdr, sizeof hdr[0], 2, f);
    fwrite(vpds_points(s), sizeof(double), vpds_count(s) * (size_t)dim, f);
    fwrite(vpds_radii(s), sizeof(double), vpds_count(s), f);
    fwrite(vpds_scales(s), sizeof(double), vpds_count(s), f);
    fclose(f);
    printf("n=%zu darts=%llu levels=%u delta=%g\n", vpds_count(s),
           (unsigned long long)stats.darts, stats.levels, stats.delta);
    vpds_destroy(s);
    return 0;
}
