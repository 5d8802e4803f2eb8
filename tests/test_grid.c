/* Grid sizing: multilinear interpolation, its exact Lipschitz constant (largest gradient norm,
 * not the steepest axis step), the Lipschitz envelope, and sampling with a grid. */
#include "check.h"
#include "vpds.h"
#include <math.h>
#include <string.h>

static uint64_t lcg = 12345;
static double unit(void)
{
    lcg = lcg * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(lcg >> 11) * (1.0 / 9007199254740992.0);
}

static vpds_grid *make(int dim, const size_t *shape, const double *values, const double *lo,
                       const double *hi)
{
    vpds_grid_desc gd = vpds_default_grid_desc();
    vpds_grid *g = NULL;
    gd.dim = dim;
    gd.shape = shape;
    gd.values = values;
    gd.lo = lo;
    gd.hi = hi;
    CHECK(vpds_grid_create(&gd, &g) == VPDS_OK);
    return g;
}

/* max |f(a) - f(b)| / |a - b| over random close pairs: a lower estimate of L */
static double observed_lipschitz(const vpds_grid *g, int dim, int pairs)
{
    double best = 0, a[3], b[3];
    int i, k;
    for (i = 0; i < pairs; i++) {
        double d2 = 0, dir[3], len = 0;
        for (k = 0; k < dim; k++) {
            a[k] = unit();
            dir[k] = unit() - 0.5;
            len += dir[k] * dir[k];
        }
        len = sqrt(len);
        for (k = 0; k < dim; k++) {
            b[k] = a[k] + 1e-7 * dir[k] / len;
            d2 += (b[k] - a[k]) * (b[k] - a[k]);
        }
        {
            double q = fabs(vpds_grid_eval(g, a) - vpds_grid_eval(g, b)) / sqrt(d2);
            if (q > best) best = q;
        }
    }
    return best;
}

int main(void)
{
    /* v = x + y on a 2x2 grid: gradient (1, 1), L = sqrt 2, while each axis step is 1 */
    {
        size_t shape[2] = {2, 2};
        double v[4] = {1, 2, 2, 3}, p[2] = {0.25, 0.75};
        vpds_grid *g = make(2, shape, v, NULL, NULL);
        CHECK(fabs(vpds_grid_lipschitz(g) - sqrt(2.0)) < 1e-15);
        CHECK(fabs(vpds_grid_eval(g, p) - 2.0) < 1e-15);
        p[0] = -5; p[1] = 7; /* clamped to the corner (0, 1) */
        CHECK(vpds_grid_eval(g, p) == 2.0);
        p[0] = NAN; /* no value at no point (it read the first node's) */
        CHECK(isnan(vpds_grid_eval(g, p)));
        vpds_grid_destroy(g);
    }
    /* random 3D grid: values at nodes, exact L bounds every observed slope and is approached */
    {
        size_t shape[3] = {5, 4, 6}, n = 120, i;
        double v[120], lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, node[3], L, seen;
        vpds_grid *g;
        for (i = 0; i < n; i++) v[i] = 0.05 + 0.1 * unit();
        g = make(3, shape, v, lo, hi);
        node[0] = 2.0 / 4; node[1] = 1.0 / 3; node[2] = 3.0 / 5;
        CHECK(fabs(vpds_grid_eval(g, node) - v[2 * 24 + 1 * 6 + 3]) < 1e-15);
        L = vpds_grid_lipschitz(g);
        seen = observed_lipschitz(g, 3, 200000);
        CHECK_MSG(seen <= L * (1 + 1e-6), "observed %g > exact %g", seen, L);
        {
            /* finite differences just inside every corner of every cell reach L */
            double best = 0, q[3], e = 1e-7;
            size_t c0, c1, c2;
            unsigned corner;
            int k;
            for (c0 = 0; c0 < 4; c0++) for (c1 = 0; c1 < 3; c1++) for (c2 = 0; c2 < 5; c2++)
                for (corner = 0; corner < 8; corner++) {
                    size_t cell[3] = {c0, c1, c2};
                    double sgn[3], g2 = 0, f0;
                    for (k = 0; k < 3; k++) {
                        int up = (corner >> k) & 1;
                        sgn[k] = up ? -1 : 1;
                        node[k] = (double)(cell[k] + (size_t)up) / (double)(shape[k] - 1) + sgn[k] * e;
                    }
                    f0 = vpds_grid_eval(g, node);
                    for (k = 0; k < 3; k++) {
                        double gk;
                        memcpy(q, node, sizeof q);
                        q[k] += sgn[k] * e;
                        gk = (vpds_grid_eval(g, q) - f0) / e;
                        g2 += gk * gk;
                    }
                    if (sqrt(g2) > best) best = sqrt(g2);
                }
            CHECK_MSG(fabs(best - L) < 1e-5 * L, "corner gradients reach %.9g, exact %.9g", best, L);
            CHECK(L > seen * 1.0000001 || fabs(L - seen) < 1e-6);
        }
        /* the envelope lowers only, as little as the edge-slope condition allows */
        {
            double target = L / 3, c[3];
            const double *w;
            size_t idx, k;
            CHECK(vpds_grid_enforce_lipschitz(g, target) == VPDS_OK);
            w = vpds_grid_values(g);
            CHECK(vpds_grid_lipschitz(g) <= target * (1 + 1e-12));
            CHECK(observed_lipschitz(g, 3, 100000) <= target * (1 + 1e-6));
            for (k = 0; k < 3; k++) c[k] = target * (1.0 / (double)(shape[k] - 1)) / sqrt(3.0);
            for (idx = 0; idx < n; idx++) {
                size_t ii[3] = {idx / 24, idx / 6 % 4, idx % 6}, st[3] = {24, 6, 1};
                int tight = w[idx] == v[idx];
                CHECK(w[idx] <= v[idx] && w[idx] > 0);
                /* a lowered node is held down by a neighbour through an edge of slope exactly c */
                for (k = 0; k < 3 && !tight; k++) {
                    if (ii[k] > 0 && fabs(w[idx] - (w[idx - st[k]] + c[k])) < 1e-15) tight = 1;
                    if (ii[k] + 1 < shape[k] && fabs(w[idx] - (w[idx + st[k]] + c[k])) < 1e-15) tight = 1;
                }
                CHECK_MSG(tight, "node %zu lowered more than needed", idx);
            }
            CHECK(vpds_grid_enforce_lipschitz(g, 0) == VPDS_ERR_INVALID_ARGUMENT);
            CHECK(vpds_grid_enforce_lipschitz(g, NAN) == VPDS_ERR_INVALID_ARGUMENT);
        }
        vpds_grid_destroy(g);
    }
    /* sampling with a grid: the paper's ramp as a 2-node grid along x */
    {
        size_t shape[2] = {2, 2}, i, j;
        double v[4] = {0.001, 0.001, 0.301, 0.301};
        vpds_grid *g = make(2, shape, v, NULL, NULL);
        vpds_desc d = vpds_default_desc();
        vpds_sampler *s;
        d.sizing_grid = g;
        d.rule = VPDS_RULE_PRIOR;
        CHECK(vpds_create(&d, &s) == VPDS_OK);
        vpds_grid_destroy(g); /* the sampler holds its own copy */
        CHECK(vpds_run(s) == VPDS_OK && vpds_count(s) > 1000);
        for (i = 0; i < vpds_count(s); i++) {
            const double *p = vpds_points(s) + 2 * i;
            CHECK(fabs(vpds_radii(s)[i] - (0.001 + 0.3 * p[0])) < 1e-15);
            for (j = 0; j < i && j < 200; j++) {
                const double *q = vpds_points(s) + 2 * j;
                CHECK(hypot(p[0] - q[0], p[1] - q[1]) >= vpds_radii(s)[j]);
            }
        }
        vpds_destroy(s);
    }
    /* grid errors */
    {
        vpds_grid_desc gd = vpds_default_grid_desc();
        vpds_grid *g = NULL;
        size_t shape[2] = {2, 1}, big[2] = {(size_t)1 << 40, (size_t)1 << 40};
        double v[4] = {1, 1, 1, 1}, lo[2] = {0, 1}, hi[2] = {1, 1};
        char msg[256];
        gd.shape = shape;
        gd.values = v;
        CHECK(vpds_grid_validate(&gd, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "shape[1] = 1"));
        CHECK(vpds_grid_create(&gd, &g) == VPDS_ERR_INVALID_ARGUMENT && g == NULL);
        shape[1] = 2;
        v[2] = 0;
        CHECK(vpds_grid_validate(&gd, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "values[2] = 0"));
        v[2] = NAN;
        CHECK(vpds_grid_validate(&gd, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "values[2] = nan"));
        v[2] = 1;
        gd.lo = lo;
        gd.hi = hi;
        CHECK(vpds_grid_validate(&gd, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "axis 1"));
        gd.lo = gd.hi = NULL;
        gd.shape = big;
        CHECK(vpds_grid_validate(&gd, msg, sizeof msg) == VPDS_ERR_OVERFLOW);
        gd.shape = shape;
        gd.cookie = 0;
        CHECK(vpds_grid_validate(&gd, msg, sizeof msg) == VPDS_ERR_BAD_DESCRIPTOR);
        gd = vpds_default_grid_desc();
        gd.shape = shape;
        gd.values = v;
        v[3] = 2; /* L = 1 along both axes at that corner: sqrt 2 */
        CHECK(vpds_grid_create(&gd, &g) == VPDS_OK);
        {
            vpds_desc d = vpds_default_desc();
            d.sizing_grid = g;
            d.dim = 3;
            CHECK(vpds_validate(&d, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "dim 2"));
            d.dim = 2;
            CHECK(vpds_validate(&d, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "limit 1"));
            CHECK(vpds_grid_enforce_lipschitz(g, 0.5) == VPDS_OK);
            CHECK(vpds_validate(&d, msg, sizeof msg) == VPDS_OK);
            d.lipschitz = 0.1;
            CHECK(vpds_validate(&d, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT && strstr(msg, "below the grid"));
            d.lipschitz = 0.9;
            CHECK(vpds_validate(&d, msg, sizeof msg) == VPDS_OK);
            d.sizing = (vpds_sizing_fn)NULL;
        }
        vpds_grid_destroy(g);
        CHECK(isnan(vpds_grid_lipschitz(NULL)) && vpds_grid_values(NULL) == NULL);
        vpds_grid_destroy(NULL);
    }
    CHECK_DONE();
}
