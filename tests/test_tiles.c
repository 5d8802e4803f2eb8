/* Tiled sampling: conflict-free and maximal across every seam under each rule (brute force, in
 * the order phase, tile, insertion), periodic wraps, the same bytes for any order of tiles and
 * for a tile sampled on demand through its cone, grid windows equal to the whole grid, and every
 * refused argument. */
#include "check.h"
#include "sampler.h" /* which index a run used */
#include "vpds.h"
#include <math.h>
#include <stdint.h>
#include <string.h>

typedef struct {
    double *x, *r;
    size_t n;
} tile_out;

static int quick(void) { return getenv("VPDS_TEST_QUICK") != NULL; }

static const char *rule_names[] = {"default", "prior", "current", "bigger", "smaller"};

/* Run one tile from the outputs of its dependencies (which must be done). */
static vpds_status run_tile(const vpds_tiling *tg, uint64_t tile, tile_out *outs, int dim,
                            const vpds_grid *window)
{
    uint64_t dep[VPDS_TILING_MAX_DEPS];
    vpds_tile_points pts[VPDS_TILING_MAX_DEPS];
    size_t nd = 0, i, nf = 0, n;
    vpds_sampler *s = NULL;
    vpds_status st;
    char msg[512];
    CHECK(vpds_tiling_deps(tg, tile, dep, VPDS_TILING_MAX_DEPS, &nd) == VPDS_OK);
    /* handed over in reverse: the order of deps must not matter */
    for (i = 0; i < nd; i++) {
        const tile_out *o = &outs[dep[nd - 1 - i]];
        CHECK_MSG(o->x != NULL || o->n == 0, "tile %llu ran before its dependency %llu",
                  (unsigned long long)tile, (unsigned long long)dep[nd - 1 - i]);
        pts[i].tile = dep[nd - 1 - i];
        pts[i].x = o->x;
        pts[i].r = o->r;
        pts[i].n = o->n;
    }
    st = vpds_tile_create(tg, tile, pts, nd, window, &s, &nf, msg, sizeof msg);
    CHECK_MSG(st == VPDS_OK, "tile %llu: %s", (unsigned long long)tile, msg);
    if (st != VPDS_OK) return st;
    st = vpds_run(s);
    CHECK_MSG(st == VPDS_OK, "tile %llu run: %s", (unsigned long long)tile, vpds_last_error(s));
    n = vpds_count(s) - nf;
    outs[tile].n = n;
    outs[tile].x = (double *)malloc((n ? n : 1) * (size_t)dim * sizeof(double));
    outs[tile].r = (double *)malloc((n ? n : 1) * sizeof(double));
    memcpy(outs[tile].x, vpds_points(s) + nf * (size_t)dim, n * (size_t)dim * sizeof(double));
    memcpy(outs[tile].r, vpds_radii(s) + nf, n * sizeof(double));
    for (i = 0; i < n; i++) CHECK(!(vpds_flags(s)[nf + i] & VPDS_FLAG_FIXED));
    vpds_destroy(s);
    return st;
}

static void free_outs(tile_out *outs, uint64_t count)
{
    uint64_t i;
    for (i = 0; i < count; i++) {
        free(outs[i].x);
        free(outs[i].r);
    }
    free(outs);
}

/* All tiles, phase by phase; within a phase ascending (reverse = 0) or descending. */
static tile_out *run_all(const vpds_tiling *tg, int dim, int reverse, vpds_grid **windows)
{
    uint64_t count = vpds_tiling_count(tg), i;
    int ph, phases = 1 << dim;
    tile_out *outs = (tile_out *)calloc((size_t)count, sizeof *outs);
    for (ph = 0; ph < phases; ph++)
        for (i = 0; i < count; i++) {
            uint64_t tile = reverse ? count - 1 - i : i;
            if (vpds_tiling_phase(tg, tile) == ph) run_tile(tg, tile, outs, dim, windows ? windows[tile] : NULL);
        }
    return outs;
}

/* The union in the order (phase, tile, insertion). */
static size_t gather_union(const vpds_tiling *tg, int dim, const tile_out *outs, double **x, double **r)
{
    uint64_t count = vpds_tiling_count(tg), i;
    size_t n = 0, m = 0;
    int ph;
    for (i = 0; i < count; i++) n += outs[i].n;
    *x = (double *)malloc((n ? n : 1) * (size_t)dim * sizeof(double));
    *r = (double *)malloc((n ? n : 1) * sizeof(double));
    for (ph = 0; ph < (1 << dim); ph++)
        for (i = 0; i < count; i++)
            if (vpds_tiling_phase(tg, i) == ph) {
                memcpy(*x + m * (size_t)dim, outs[i].x, outs[i].n * (size_t)dim * sizeof(double));
                memcpy(*r + m, outs[i].r, outs[i].n * sizeof(double));
                m += outs[i].n;
            }
    return n;
}

static double rule_f(int rule, double rx, double ry)
{
    switch (rule) {
    case 1: return rx;
    case 2: return ry;
    case 3: return rx > ry ? rx : ry;
    default: return rx < ry ? rx : ry;
    }
}

/* Toroidal or plain distance. */
static double dist(int dim, const double *a, const double *b, const double *lo, const double *hi,
                   const int *per)
{
    double s = 0;
    int k;
    for (k = 0; k < dim; k++) {
        double d = fabs(a[k] - b[k]);
        if (per && per[k]) {
            double P = hi[k] - lo[k];
            d = fmod(d, P);
            if (P - d < d) d = P - d;
        }
        s += d * d;
    }
    return sqrt(s);
}

/* Brute force, independent of the library: pairs j < i with |x_i - x_j| < t R_f f(x_j, x_i). */
static size_t conflicts(int dim, const double *x, const double *r, size_t n, int rule, double reach,
                        const double *lo, const double *hi, const int *per)
{
    size_t i, j, bad = 0;
    for (i = 0; i < n; i++)
        for (j = 0; j < i; j++)
            if (dist(dim, x + i * dim, x + j * dim, lo, hi, per) <
                reach * rule_f(rule, r[j], r[i]) * (1 - 1e-12))
                bad++;
    return bad;
}

static uint64_t lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s >> 11;
}

/* Random probes of the box, each covered by some sample at t R_c f (r at the probe from rfn). */
static size_t uncovered_probes(int dim, const double *x, const double *r, size_t n, int rule,
                               double reach, const double *lo, const double *hi, const int *per,
                               double (*rfn)(const double *, void *), size_t probes)
{
    uint64_t seed = 12345;
    size_t p, i, bad = 0;
    for (p = 0; p < probes; p++) {
        double y[VPDS_MAX_DIM], ry;
        int k, ok = 0;
        for (k = 0; k < dim; k++)
            y[k] = lo[k] + (hi[k] - lo[k]) * ((double)lcg(&seed) / 9007199254740992.0);
        ry = rfn(y, NULL);
        for (i = 0; i < n && !ok; i++)
            if (dist(dim, y, x + i * dim, lo, hi, per) <= reach * rule_f(rule, r[i], ry) * (1 + 1e-12))
                ok = 1;
        if (!ok) bad++;
    }
    return bad;
}

static double wave(const double *x, void *u)
{
    (void)u;
    return 0.03 + 0.01 * sin(6.0 * x[0]) * cos(5.0 * x[1]);
}
static double const_r(const double *x, void *u) { (void)x; (void)u; return 0.04; }

static int same_outs(const tile_out *a, const tile_out *b, uint64_t count, int dim)
{
    uint64_t i;
    for (i = 0; i < count; i++) {
        if (a[i].n != b[i].n) return 0;
        if (memcmp(a[i].x, b[i].x, a[i].n * (size_t)dim * sizeof(double)) != 0) return 0;
        if (memcmp(a[i].r, b[i].r, a[i].n * sizeof(double)) != 0) return 0;
    }
    return 1;
}

/* A tiled run checked whole: conflicts in the order (phase, tile, insertion), coverage by
 * probes, any order of tiles gives the same bytes. */
static void check_tiled(int dim, const uint64_t *tiles, const int *per, int rule, int callback,
                        double inhibition, size_t probes, const char *what)
{
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], *x, *r;
    vpds_desc d = vpds_default_desc();
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling *tg = NULL;
    tile_out *a, *b;
    size_t n, bad;
    char msg[512];
    int k;
    for (k = 0; k < dim; k++) {
        lo[k] = 0;
        hi[k] = k == 0 ? 1.0 : 0.8;
    }
    d.dim = dim;
    d.lo = lo;
    d.hi = hi;
    d.periodic = per;
    d.rule = (vpds_rule)rule;
    d.seed = 77;
    d.radius = 0.04;
    d.inhibition = inhibition;
    if (callback) {
        d.sizing = wave;
        d.lipschitz = 0.08; /* |grad| <= 0.01 * hypot(6, 5) */
        d.radius_max = 0.04;
    }
    td.sampler = &d;
    td.tiles = tiles;
    CHECK_MSG(vpds_tiling_validate(&td, msg, sizeof msg) == VPDS_OK, "%s: %s", what, msg);
    if (vpds_tiling_create(&td, &tg) != VPDS_OK) return;
    a = run_all(tg, dim, 0, NULL);
    b = run_all(tg, dim, 1, NULL);
    CHECK_MSG(same_outs(a, b, vpds_tiling_count(tg), dim), "%s: the order of tiles changed the points", what);
    n = gather_union(tg, dim, a, &x, &r);
    CHECK_MSG(n > 10, "%s: only %zu samples", what, n);
    bad = conflicts(dim, x, r, n, rule, inhibition, lo, hi, per);
    CHECK_MSG(bad == 0, "%s (%s): %zu conflicts across the seams", what, rule_names[rule], bad);
    bad = uncovered_probes(dim, x, r, n, rule, 1.0, lo, hi, per, callback ? wave : const_r, probes);
    CHECK_MSG(bad == 0, "%s (%s): %zu of %zu probes uncovered", what, rule_names[rule], bad, probes);
    for (k = 0; k < dim; k++) /* every sample inside the box */
        for (bad = 0; bad < n; bad++)
            CHECK(x[bad * dim + k] >= lo[k] && x[bad * dim + k] <= hi[k]);
    free(x);
    free(r);
    free_outs(a, vpds_tiling_count(tg));
    free_outs(b, vpds_tiling_count(tg));
    vpds_tiling_destroy(tg);
}

/* A tile sampled on demand through its cone, in cone order, equals the batch's tile. */
static void check_on_demand(void)
{
    uint64_t tiles[2] = {6, 5}, cone[64], target, count, i;
    int64_t coords[2] = {3, 3};
    double lo[2] = {0, 0}, hi[2] = {1.2, 1.0};
    vpds_desc d = vpds_default_desc();
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling *tg = NULL;
    tile_out *batch, *lazy;
    size_t n = 0, j;
    d.lo = lo;
    d.hi = hi;
    d.radius = 0.05;
    d.seed = 5;
    td.sampler = &d;
    td.tiles = tiles;
    CHECK(vpds_tiling_create(&td, &tg) == VPDS_OK);
    if (!tg) return;
    count = vpds_tiling_count(tg);
    CHECK(count == 30);
    CHECK(vpds_tiling_index(tg, coords, &target) == VPDS_OK && target == 3 * 5 + 3);
    CHECK(vpds_tiling_phase(tg, target) == 3);
    CHECK(vpds_tiling_cone(tg, target, cone, 64, &n) == VPDS_OK);
    /* phase 3 at (3,3): phase 2 above and below, phase 1 left and right, phase 0 at the
     * corners, and the cone of those: a 7 x 5 lifted box clipped to the tiles */
    CHECK_MSG(n > 8 && n < 30, "cone of %zu tiles", n);
    for (j = 1; j < n; j++) CHECK(vpds_tiling_phase(tg, cone[j - 1]) <= vpds_tiling_phase(tg, cone[j]));
    batch = run_all(tg, 2, 0, NULL);
    lazy = (tile_out *)calloc((size_t)count, sizeof *lazy);
    for (j = 0; j < n; j++) run_tile(tg, cone[j], lazy, 2, NULL);
    run_tile(tg, target, lazy, 2, NULL);
    CHECK(lazy[target].n == batch[target].n && lazy[target].n > 0);
    CHECK(lazy[target].n == batch[target].n &&
          memcmp(lazy[target].x, batch[target].x, batch[target].n * 2 * sizeof(double)) == 0);
    for (i = 0, j = 0; i < count; i++) j += lazy[i].x != NULL;
    CHECK(j == n + 1); /* nothing outside the cone ran */
    free_outs(batch, count);
    free_outs(lazy, count);
    vpds_tiling_destroy(tg);
}

/* Windows of a grid give the whole grid's points, tile for tile. */
static void check_windows(void)
{
    enum { NX = 41, NY = 33 };
    static double values[NX * NY];
    uint64_t tiles[2] = {4, 3}, count, i;
    size_t shape[2] = {NX, NY}, k;
    double lo[2] = {0, 0}, hi[2] = {1.0, 0.8};
    vpds_grid_desc gd = vpds_default_grid_desc();
    vpds_grid *whole = NULL, **windows;
    vpds_desc d = vpds_default_desc(), dw;
    vpds_tiling_desc td = vpds_default_tiling_desc(), tw;
    vpds_tiling *tg = NULL, *tgw = NULL;
    tile_out *a, *b;
    for (k = 0; k < NX * NY; k++) {
        double u = (double)(k / NY) / (NX - 1), v = (double)(k % NY) / (NY - 1);
        values[k] = 0.025 + 0.012 * u * u + 0.006 * sin(4 * v);
    }
    gd.shape = shape;
    gd.values = values;
    gd.lo = lo;
    gd.hi = hi;
    CHECK(vpds_grid_create(&gd, &whole) == VPDS_OK);
    if (!whole) return;
    d.lo = lo;
    d.hi = hi;
    d.sizing_grid = whole;
    d.seed = 9;
    td.sampler = &d;
    td.tiles = tiles;
    CHECK(vpds_tiling_create(&td, &tg) == VPDS_OK);
    /* the per-tile form: no sizing in the sampler, the whole grid's L and bounds declared */
    dw = d;
    dw.sizing_grid = NULL;
    dw.lipschitz = vpds_grid_lipschitz(whole);
    dw.radius_max = 0, dw.radius_min = 0;
    for (k = 0; k < NX * NY; k++) {
        if (values[k] > dw.radius_max) dw.radius_max = values[k];
        if (dw.radius_min == 0 || values[k] < dw.radius_min) dw.radius_min = values[k];
    }
    tw = td;
    tw.sampler = &dw;
    tw.sizing_per_tile = 1;
    CHECK(vpds_tiling_create(&tw, &tgw) == VPDS_OK);
    if (!tg || !tgw) return;
    count = vpds_tiling_count(tg);
    windows = (vpds_grid **)calloc((size_t)count, sizeof *windows);
    for (i = 0; i < count; i++) {
        /* the nodes of the cells the core touches, one more on each side */
        double tlo[2], thi[2];
        size_t off[2], wshape[2], a0, a1, j, m;
        double *wv;
        vpds_grid_desc wd = vpds_default_grid_desc();
        vpds_tiling_box(tgw, i, tlo, thi);
        for (k = 0; k < 2; k++) {
            double step = (hi[k] - lo[k]) / (double)(shape[k] - 1);
            a0 = (size_t)floor((tlo[k] - lo[k]) / step);
            a1 = (size_t)floor((thi[k] - lo[k]) / step) + 3;
            a0 = a0 > 0 ? a0 - 1 : 0;
            if (a1 > shape[k]) a1 = shape[k];
            off[k] = a0;
            wshape[k] = a1 - a0;
        }
        wv = (double *)malloc(wshape[0] * wshape[1] * sizeof(double));
        for (j = 0, m = 0; j < wshape[0]; j++)
            for (k = 0; k < wshape[1]; k++) wv[m++] = values[(off[0] + j) * NY + off[1] + k];
        wd.shape = wshape;
        wd.values = wv;
        wd.lo = lo;
        wd.hi = hi;
        CHECK(vpds_grid_create_window(&wd, shape, off, &windows[i]) == VPDS_OK);
        free(wv);
    }
    a = run_all(tg, 2, 0, NULL);
    b = run_all(tgw, 2, 1, windows);
    CHECK_MSG(same_outs(a, b, count, 2), "grid windows gave other points than the whole grid");
    CHECK(a[0].n > 10);
    {
        /* a window evaluates as the whole grid inside, and NaN outside the nodes it holds */
        double p[2] = {0.05, 0.05}, far[2] = {0.95, 0.75};
        CHECK(vpds_grid_eval(windows[0], p) == vpds_grid_eval(whole, p));
        CHECK(isnan(vpds_grid_eval(windows[0], far)));
        CHECK(vpds_grid_enforce_lipschitz(windows[0], 0.1) == VPDS_ERR_UNSUPPORTED);
    }
    {
        /* a window that does not cover its tile stops the run with a sizing error */
        vpds_sampler *s = NULL;
        char msg[512];
        size_t nf;
        if (vpds_tile_create(tgw, count - 1, NULL, 0, windows[0], &s, &nf, msg, sizeof msg) == VPDS_OK) {
            CHECK(0); /* tile count-1 has dependencies: refused before any run */
            vpds_destroy(s);
        }
        CHECK(strstr(msg, "needs tile") != NULL);
        if (vpds_tile_create(tgw, 0, NULL, 0, windows[count - 1], &s, &nf, msg, sizeof msg) == VPDS_OK) {
            CHECK(vpds_run(s) == VPDS_ERR_SIZING);
            CHECK_MSG(strstr(vpds_last_error(s), "outside the sizing grid window") != NULL, "%s",
                      vpds_last_error(s));
            vpds_destroy(s);
        }
    }
    for (i = 0; i < count; i++) vpds_grid_destroy(windows[i]);
    free(windows);
    free_outs(a, count);
    free_outs(b, count);
    vpds_tiling_destroy(tg);
    vpds_tiling_destroy(tgw);
    vpds_grid_destroy(whole);
}

#define EXPECT_REFUSED(td, status, text) do { char m_[512]; vpds_tiling *t_ = NULL; \
    CHECK(vpds_tiling_validate(&(td), m_, sizeof m_) == (status)); \
    CHECK_MSG(strstr(m_, text) != NULL, "message: %s", m_); \
    CHECK(vpds_tiling_create(&(td), &t_) == (status) && t_ == NULL); } while (0)

static void check_errors(void)
{
    uint64_t tiles[2] = {4, 4}, odd[2] = {3, 4}, thin[2] = {40, 4}, zero[2] = {0, 4}, dep[16];
    int per[2] = {1, 0};
    vpds_desc d = vpds_default_desc(), bad = vpds_default_desc();
    vpds_tiling_desc td = vpds_default_tiling_desc(), t2;
    vpds_tiling *tg = NULL;
    vpds_sampler *s = NULL;
    vpds_tile_points pts[4];
    double x[2] = {0.24, 0.24}, r[1] = {0.05};
    size_t n = 0, nf;
    char msg[512];
    td.sampler = &d;
    td.tiles = tiles;
    CHECK(vpds_tiling_validate(NULL, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    t2 = td; t2.cookie = 0;
    EXPECT_REFUSED(t2, VPDS_ERR_BAD_DESCRIPTOR, "vpds_default_tiling_desc");
    t2 = td; t2.struct_size = 8;
    EXPECT_REFUSED(t2, VPDS_ERR_BAD_DESCRIPTOR, "struct_size = 8");
    t2 = td; t2.sampler = NULL;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "desc.sampler is NULL");
    bad.radius = -1;
    t2 = td; t2.sampler = &bad;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "desc.sampler: desc.radius = -1");
    {
        vpds_desc high = vpds_default_desc();
        uint64_t nine[9] = {2, 2, 2, 2, 2, 2, 2, 2, 2};
        high.dim = 9;
        high.radius = 1.5;
        t2 = td; t2.sampler = &high; t2.tiles = nine;
        EXPECT_REFUSED(t2, VPDS_ERR_UNSUPPORTED, "sampler->dim = 9: tilings go up to 8 dimensions");
    }
    t2 = td; t2.tiles = NULL;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "tiles is NULL");
    t2 = td; t2.tiles = zero;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "tiles[0] = 0");
    t2 = td; t2.tiles = thin;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "tiles[0] = 40: the tile side 0.025 is below the margin");
    t2 = td; t2.scale = NAN;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "scale = nan");
    t2 = td; t2.scale = 0;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "scale = 0");
    d.periodic = per;
    t2 = td; t2.tiles = odd;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "tiles[0] = 3: a periodic axis needs an even tile count");
    d.periodic = NULL;
    d.sizing = wave;
    d.lipschitz = 0.08;
    EXPECT_REFUSED(td, VPDS_ERR_INVALID_ARGUMENT, "radius_max = 0: a tiling with a sizing callback needs");
    d.radius_max = 0.04;
    d.rule = VPDS_RULE_PRIOR;
    t2 = td; t2.scale = 10; /* 10 * 0.08 >= 1/2 */
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "scale * coverage * L = 0.8 is at or above the prior");
    t2 = td; t2.sizing_per_tile = 1;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "not both");
    d.sizing = NULL;
    d.lipschitz = VPDS_UNSET;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "sizing_per_tile needs desc.sampler->lipschitz");
    d.lipschitz = 0.1;
    d.radius_max = 0;
    EXPECT_REFUSED(t2, VPDS_ERR_INVALID_ARGUMENT, "sizing_per_tile needs desc.sampler->radius_max");
    d.lipschitz = VPDS_UNSET;
    d.rule = VPDS_RULE_DEFAULT;

    /* the queries and the tile step */
    CHECK(vpds_tiling_create(&td, &tg) == VPDS_OK);
    if (!tg) return;
    CHECK(vpds_tiling_phase(tg, 16) == -1);
    CHECK(vpds_tiling_phase(NULL, 0) == -1);
    CHECK(vpds_tiling_count(NULL) == 0);
    CHECK(vpds_tiling_deps(tg, 16, dep, 16, &n) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(vpds_tiling_deps(tg, 5, dep, 2, &n) == VPDS_ERR_OVERFLOW && n == 8); /* (1,1): phase 3 */
    CHECK(vpds_tiling_deps(tg, 5, dep, 16, &n) == VPDS_OK && n == 8 && dep[0] == 0 && dep[7] == 10);
    CHECK(vpds_tiling_deps(tg, 0, dep, 16, &n) == VPDS_OK && n == 0);
    CHECK(vpds_tiling_cone(tg, 5, dep, 1, &n) == VPDS_ERR_OVERFLOW && n > 8);
    {
        size_t need = n;
        CHECK(vpds_tiling_cone(tg, 5, dep, 16, &n) == VPDS_OK && n == need);
    }
    CHECK(vpds_tile_create(tg, 99, NULL, 0, NULL, &s, &nf, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(msg, "tile = 99: the tiling has tiles 0..15") != NULL);
    CHECK(vpds_tile_create(tg, 1, NULL, 0, NULL, &s, &nf, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK_MSG(strstr(msg, "tile 1 (phase 2) needs tile 0 (phase 0) first") != NULL, "%s", msg);
    pts[0].tile = 0; pts[0].x = x; pts[0].r = r; pts[0].n = 1;
    pts[1] = pts[0];
    pts[2] = pts[0];
    pts[3] = pts[0];
    CHECK(vpds_tile_create(tg, 1, pts, 2, NULL, &s, &nf, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK_MSG(strstr(msg, "deps[1].tile = 0 repeats deps[0]") != NULL, "%s", msg);
    pts[1].tile = 3;
    CHECK(vpds_tile_create(tg, 1, pts, 2, NULL, &s, &nf, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK_MSG(strstr(msg, "deps[1].tile = 3 is not a dependency of tile 1") != NULL, "%s", msg);
    pts[0].x = NULL;
    CHECK(vpds_tile_create(tg, 1, pts, 1, NULL, &s, &nf, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    CHECK_MSG(strstr(msg, "x or r is NULL with n = 1") != NULL, "%s", msg);
    pts[0].x = x;
    {
        /* a dependency's bad sample is named by its place in deps (an infinite one was dropped
         * as out of reach, a NaN named by its place in the tile's own list) */
        double bad_x[4] = {0.24, 0.24, 0.1, INFINITY}, bad_r[2] = {r[0], r[0]};
        pts[1].tile = 6; pts[1].x = bad_x; pts[1].r = bad_r; pts[1].n = 2;
        pts[2].tile = 2; pts[2].n = 0;
        pts[3].tile = 4; pts[3].n = 0;
        CHECK(vpds_tile_create(tg, 1, pts, 4, NULL, &s, &nf, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
        CHECK_MSG(strstr(msg, "deps[1].x[1][1] = inf") != NULL, "%s", msg);
        bad_x[3] = 0.1;
        bad_r[1] = NAN;
        CHECK(vpds_tile_create(tg, 1, pts, 4, NULL, &s, &nf, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
        CHECK_MSG(strstr(msg, "deps[1].r[1] = nan") != NULL, "%s", msg);
        pts[1] = pts[0];
    }
    /* tile 1 = (0, 1), phase 2, needs 0, 2, 4 and 6; only tile 0 holds a point */
    pts[1].tile = 6; pts[1].n = 0;
    pts[2].tile = 2; pts[2].n = 0;
    pts[3].tile = 4; pts[3].n = 0;
    CHECK(vpds_tile_create(tg, 1, pts, 4, NULL, &s, &nf, msg, sizeof msg) == VPDS_OK);
    CHECK(nf == 1); /* (0.24, 0.24) lies within the margin 0.05 of tile 1's core [0, 0.25] x [0.25, 0.5] */
    CHECK(vpds_count(s) == 1 && (vpds_flags(s)[0] & VPDS_FLAG_FIXED));
    vpds_destroy(s);
    x[1] = 0.1; /* 0.15 below the core: beyond the margin */
    CHECK(vpds_tile_create(tg, 1, pts, 4, NULL, &s, &nf, msg, sizeof msg) == VPDS_OK && nf == 0);
    vpds_destroy(s);
    CHECK(vpds_tile_create(tg, 0, NULL, 0, NULL, NULL, &nf, msg, sizeof msg) == VPDS_ERR_INVALID_ARGUMENT);
    vpds_tiling_destroy(tg);
    vpds_tiling_destroy(NULL);
}

/* Seeds differ per tile and follow the global seed; phases alternate by parity. */
static void check_layout(void)
{
    uint64_t tiles[3] = {2, 4, 3}, c[3], t, seen = 0;
    int per[3] = {1, 1, 0};
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, blo[3], bhi[3], nlo[3], nhi[3];
    vpds_desc d = vpds_default_desc();
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling *tg = NULL;
    size_t n;
    uint64_t dep[64];
    d.dim = 3;
    d.lo = lo;
    d.hi = hi;
    d.periodic = per;
    d.radius = 0.1;
    td.sampler = &d;
    td.tiles = tiles;
    CHECK(vpds_tiling_create(&td, &tg) == VPDS_OK);
    if (!tg) return;
    CHECK(vpds_tiling_count(tg) == 24);
    CHECK(fabs(vpds_tiling_margin(tg) - 0.1) < 1e-8 && vpds_tiling_margin(tg) >= 0.1);
    for (t = 0; t < 24; t++) {
        int64_t ic[3];
        uint64_t back;
        CHECK(vpds_tiling_coords(tg, t, c) == VPDS_OK);
        CHECK(vpds_tiling_phase(tg, t) == (int)((c[0] & 1) | (c[1] & 1) << 1 | (c[2] & 1) << 2));
        ic[0] = (int64_t)c[0] - 2; /* periodic: wraps */
        ic[1] = (int64_t)c[1] + 4;
        ic[2] = (int64_t)c[2];
        CHECK(vpds_tiling_index(tg, ic, &back) == VPDS_OK && back == t);
        CHECK(vpds_tiling_seed(tg, t) != vpds_tiling_seed(tg, (t + 1) % 24));
        if (vpds_tiling_seed(tg, t) & 1) seen++;
        CHECK(vpds_tiling_deps(tg, t, dep, 64, &n) == VPDS_OK);
        /* 2 tiles on axis 0: both neighbours along it are the same tile, listed once */
        if (vpds_tiling_phase(tg, t) == 7) CHECK_MSG(n == 17 || n == 11, "deps %zu", n);
    }
    CHECK(seen > 4 && seen < 20);
    {
        int64_t ic[3] = {0, 0, 3};
        uint64_t back;
        CHECK(vpds_tiling_index(tg, ic, &back) == VPDS_ERR_INVALID_ARGUMENT); /* closed axis */
    }
    /* neighbouring cores share faces exactly, and the last face is the box's */
    CHECK(vpds_tiling_box(tg, 0, blo, bhi) == VPDS_OK);
    CHECK(vpds_tiling_box(tg, 1, nlo, nhi) == VPDS_OK); /* (0,0,1) */
    CHECK(bhi[2] == nlo[2] && blo[0] == 0.0);
    CHECK(vpds_tiling_box(tg, 23, nlo, nhi) == VPDS_OK && nhi[0] == 1.0 && nhi[1] == 1.0 && nhi[2] == 1.0);
    vpds_tiling_destroy(tg);
}

/* Run [0,1]^dim at radius r with fixed points fx (nf, at r): its own samples into *own. */
static size_t run_with_fixed(int dim, double r, uint64_t seed, const double *fx, size_t nf,
                             int on_grid, double **own)
{
    vpds_desc d = vpds_default_desc();
    vpds_sampler *s = NULL;
    vpds_status st;
    size_t n = 0;
    d.dim = dim;
    d.radius = r;
    d.seed = seed;
    *own = NULL;
    CHECK(vpds_create(&d, &s) == VPDS_OK);
    CHECK(vpds_add_points(s, fx, NULL, nf) == VPDS_OK);
    /* paused once, to see which index the run is on (the store leaves it at the end) */
    CHECK(vpds_set_budget(s, 50) == VPDS_OK && vpds_run(s) == VPDS_PAUSED);
    CHECK_MSG(s->store.grid_mode == on_grid, "%dD, %zu fixed points: the run was %s the background grid",
              dim, nf, on_grid ? "not on" : "on");
    CHECK(vpds_set_budget(s, 0) == VPDS_OK);
    while ((st = vpds_run(s)) == VPDS_PAUSED) {}
    CHECK(st == VPDS_OK && vpds_count(s) >= nf);
    if (st == VPDS_OK && vpds_count(s) >= nf) {
        n = vpds_count(s) - nf;
        *own = (double *)malloc((n ? n : 1) * (size_t)dim * sizeof(double));
        memcpy(*own, vpds_points(s) + nf * (size_t)dim, n * (size_t)dim * sizeof(double));
    }
    vpds_destroy(s);
    return n;
}

/* Fixed points at the sizing's radius around the box (a tile's neighbours) and inside it sit in
 * the background grid, those outside in its border cells. The same fixed points with one given
 * twice (two in one cell: the grid cannot hold them, the kd-tree answers) must give the same
 * own samples, bit for bit; and those are conflict-free with every fixed point and cover the
 * box (brute force). */
static void check_fixed_on_grid(int dim, double r, uint64_t seed, size_t probes)
{
    vpds_desc d = vpds_default_desc();
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], ulo[VPDS_MAX_DIM] = {0}, uhi[VPDS_MAX_DIM];
    double *fx, *all, *rr, *own_grid = NULL, *own_tree = NULL;
    size_t n, nf = 0, ng, nt, i, inside = SIZE_MAX;
    vpds_sampler *s = NULL;
    int k;
    for (k = 0; k < dim; k++) {
        lo[k] = -0.2;
        hi[k] = 1.2;
        uhi[k] = 1;
    }
    d.dim = dim;
    d.lo = lo;
    d.hi = hi;
    d.radius = r;
    d.seed = seed + 100;
    CHECK(vpds_create(&d, &s) == VPDS_OK && vpds_run(s) == VPDS_OK);
    n = vpds_count(s);
    fx = (double *)malloc((n + 1) * (size_t)dim * sizeof(double));
    for (i = 0; i < n; i++) { /* the frame around [0,1]^dim, and the strip x0 < 0.25 inside */
        const double *x = vpds_points(s) + i * (size_t)dim;
        int out = 0, in_strip = x[0] < 0.25 && x[0] >= 0;
        for (k = 0; k < dim; k++) out |= x[k] < 0 || x[k] > 1;
        if (!out && !in_strip) continue;
        if (!out && inside == SIZE_MAX) inside = nf;
        memcpy(fx + nf++ * (size_t)dim, x, (size_t)dim * sizeof(double));
    }
    vpds_destroy(s);
    CHECK_MSG(inside != SIZE_MAX && nf > 10, "%dD: %zu fixed points, none inside", dim, nf);
    if (inside == SIZE_MAX) {
        free(fx);
        return;
    }
    ng = run_with_fixed(dim, r, seed, fx, nf, 1, &own_grid);
    memcpy(fx + nf * (size_t)dim, fx + inside * (size_t)dim, (size_t)dim * sizeof(double));
    nt = run_with_fixed(dim, r, seed, fx, nf + 1, 0, &own_tree);
    CHECK_MSG(ng > 0 && ng == nt && own_grid && own_tree &&
                  memcmp(own_grid, own_tree, ng * (size_t)dim * sizeof(double)) == 0,
              "%dD fixed points: %zu own samples on the grid, %zu on the kd-tree, not the same",
              dim, ng, nt);
    all = (double *)malloc((nf + ng + 1) * (size_t)dim * sizeof(double));
    rr = (double *)malloc((nf + ng + 1) * sizeof(double));
    memcpy(all, fx, nf * (size_t)dim * sizeof(double));
    if (own_grid) memcpy(all + nf * (size_t)dim, own_grid, ng * (size_t)dim * sizeof(double));
    for (i = 0; i < nf + ng; i++) rr[i] = r;
    CHECK_MSG(conflicts(dim, all, rr, nf + ng, 1, 1.0, ulo, uhi, NULL) == 0,
              "%dD fixed points: a conflict", dim);
    CHECK_MSG(uncovered_probes(dim, all, rr, nf + ng, 1, 1.0, ulo, uhi, NULL, const_r, probes) == 0,
              "%dD fixed points: an uncovered probe", dim);
    free(fx);
    free(all);
    free(rr);
    free(own_grid);
    free(own_tree);
}

int main(void)
{
    uint64_t t2[2] = {4, 3}, t2p[2] = {4, 2}, t1[1] = {6}, t3[3] = {2, 2, 2};
    int per2[2] = {1, 1}, per1[1] = {1};
    int rule;
    size_t probes = quick() ? 2000 : 20000;
    check_errors();
    check_layout();
    for (rule = 1; rule <= 4; rule++) check_tiled(2, t2, NULL, rule, 1, 1.0, probes, "2D wave");
    check_tiled(2, t2, NULL, 4, 0, 1.0, probes, "2D uniform");
    check_tiled(2, t2p, per2, 4, 0, 1.0, probes, "2D periodic 4 x 2");
    check_tiled(2, t2p, per2, 3, 1, 1.0, probes, "2D periodic wave");
    check_tiled(2, t2, NULL, 4, 0, 0.5, probes, "2D two radii");
    check_tiled(1, t1, per1, 2, 0, 1.0, probes, "1D periodic");
    if (!quick()) check_tiled(3, t3, NULL, 4, 0, 1.0, probes / 4, "3D uniform");
    check_fixed_on_grid(1, 0.01, 1, probes);
    check_fixed_on_grid(2, 0.03, 2, probes);
    check_fixed_on_grid(3, 0.09, 3, probes / 4);
    check_on_demand();
    check_windows();
    CHECK_DONE();
}
