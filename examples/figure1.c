/* The paper's Figure 1 / Figure 9: r(x, y) = 0.001 + 0.3 x on the unit square, sampled with each
 * of the four rules and the same seed. Writes OUT_DIR/figure1_<rule>.csv (x, y, r, t) and prints
 * a line per rule. usage: figure1 OUT_DIR */
#include "vpds.h"
#include <stdio.h>
#include <time.h>

static double ramp(const double *x, void *user)
{
    (void)user;
    return 0.001 + 0.3 * x[0];
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : ".";
    const vpds_rule rules[4] = {VPDS_RULE_PRIOR, VPDS_RULE_CURRENT, VPDS_RULE_BIGGER, VPDS_RULE_SMALLER};
    const char *names[4] = {"prior", "current", "bigger", "smaller"};
    int i;
    for (i = 0; i < 4; i++) {
        vpds_desc desc = vpds_default_desc();
        vpds_sampler *s;
        vpds_status st;
        vpds_stats stats;
        char path[1024];
        FILE *f;
        size_t k, n;
        clock_t t0;
        desc.sizing = ramp;
        desc.lipschitz = 0.3; /* |dr/dx| */
        desc.rule = rules[i];
        desc.seed = 2024;
        if ((st = vpds_create(&desc, &s)) != VPDS_OK) {
            char msg[256];
            vpds_validate(&desc, msg, sizeof msg);
            fprintf(stderr, "vpds_create: %s\n", msg);
            return 1;
        }
        t0 = clock();
        if ((st = vpds_run(s)) != VPDS_OK) {
            fprintf(stderr, "vpds_run: %s: %s\n", vpds_status_string(st), vpds_last_error(s));
            vpds_destroy(s);
            return 1;
        }
        stats = vpds_get_stats(s);
        n = vpds_count(s);
        snprintf(path, sizeof path, "%s/figure1_%s.csv", dir, names[i]);
        if (!(f = fopen(path, "w"))) {
            fprintf(stderr, "cannot write %s\n", path);
            vpds_destroy(s);
            return 1;
        }
        fprintf(f, "x,y,r,t\n");
        for (k = 0; k < n; k++)
            fprintf(f, "%.17g,%.17g,%.17g,%.17g\n", vpds_points(s)[2 * k], vpds_points(s)[2 * k + 1],
                    vpds_radii(s)[k], vpds_scales(s)[k]);
        fclose(f);
        printf("%-8s %6zu samples in %.3f s, %llu darts, %u levels, maximal (delta = %g) -> %s\n",
               names[i], n, (double)(clock() - t0) / CLOCKS_PER_SEC,
               (unsigned long long)stats.darts, stats.levels, stats.delta, path);
        vpds_destroy(s);
    }
    return 0;
}
