#define _POSIX_C_SOURCE 199309L
/* libvpds workloads for `make bench`. Prints "name n seconds peak_bytes" per line (with
 * VPDS_BENCH_COUNTS set, a run's and a mesh run's work counters too, on stderr).
 * usage: bench uniform DIM RADIUS | tworadii DIM RADIUS INHIBITION [VERSION] | ramp RULE | floor N DIM
 *        | tworamp3 VERSION [INHIBITION] (3D two radii R_f = INHIBITION R_c (0.5), r = 0.03 + 0.12 x0, periodic axes 1 and 2,
 *          rule bigger, at algorithm_version VERSION: a fuzz input's workload)
 *        | annulus RADIUS (a domain) | stream DIM RADIUS N STEPS [VERSION [INHIBITION]] (prints one line per N/STEPS samples: the cost along n)
 *        | afterrun DIM RADIUS N [VERSION] (N events of the stream after a maximal run)
 *        | streamramp RULE N STEPS [VERSION] (the same with the ramp r = 0.001 + 0.3 x0 on the unit square)
 *        | threads DIM RADIUS TILES THREADS (vpds_tiling_run of TILES per axis on THREADS threads)
 *        | rampthreads RULE TILES_X TILES_Y THREADS (the ramp's box tiled so, its sizing thread-safe)
 *        | tilestats DIM RADIUS TILES (the speed-up model's inputs: one run, each phase's tile work
 *          and largest tile, and the bounds it gives for 2, 16, 64, 1024 workers)
 *        | mesh square|sphere RADIUS (the unit square as two triangles, or the unit sphere as an
 *          icosahedron split into 40^2 triangles per face: vpds_mesh_run)
 *        | meshstream N [VERSION] (N calls of vpds_mesh_next on that sphere, at an algorithm version)
 *        | meshfile FILE RADIUS (vertices and triangles from a text file: "nv nt", then nv lines
 *          of x y z, then nt lines of i j k) */
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
static double ramp3(const double *x, void *u) { (void)u; return 0.03 + 0.12 * x[0]; }
/* the annulus 0.2 <= |x - (0.5, 0.5)| <= 0.45 as a signed distance */
static double annulus(const double *x, void *u)
{
    double r = sqrt((x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.5) * (x[1] - 0.5));
    (void)u;
    return r - 0.45 > 0.2 - r ? r - 0.45 : 0.2 - r;
}

/* With VPDS_BENCH_COUNTS set, the run's work counters on stderr (darts, levels, peak cells). */
static void print_counts(const vpds_stats *stats)
{
    if (!getenv("VPDS_BENCH_COUNTS")) return;
    fprintf(stderr, "darts %llu accepted %llu levels %u peak_active_cells %llu sizing_calls %llu\n",
            (unsigned long long)stats->darts, (unsigned long long)stats->accepted, (unsigned)stats->levels,
            (unsigned long long)stats->peak_active_cells, (unsigned long long)stats->sizing_calls);
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
    print_counts(&stats);
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
            /* name n seconds_total peak_bytes seconds_of_this_interval t stream_slack */
            printf("stream %zu %.6f %zu %.6f %.6g %.3g\n", i, now_s - t0, vpds_get_stats(s).peak_bytes,
                   now_s - t_step, t, vpds_get_stats(s).stream_slack);
            fflush(stdout);
            t_step = now_s;
        }
    }
    vpds_destroy(s);
    return 0;
}

/* N events of the stream after a maximal run (its time apart): what an engine does that
 * refines a world it has made. */
static int stream_after_run(vpds_desc *d, size_t n)
{
    vpds_sampler *s;
    double x[VPDS_MAX_DIM], t, t0 = now(), t1;
    size_t i;
    if (vpds_create(d, &s) != VPDS_OK || vpds_run(s) != VPDS_OK) return 1;
    t1 = now();
    for (i = 0; i < n; i++)
        if (vpds_next(s, 0.0, x, &t) != VPDS_OK) {
            fprintf(stderr, "afterrun: %s\n", vpds_last_error(s));
            return 1;
        }
    /* name samples_of_the_run run_seconds stream_seconds peak_bytes last_t */
    printf("afterrun %zu %.6f %.6f %zu %.6g\n", vpds_count(s) - n, t1 - t0, now() - t1,
           vpds_get_stats(s).peak_bytes, t);
    vpds_destroy(s);
    return 0;
}

/* A whole tiling (tiles per axis) on some threads: its wall time against one run's. */
static int tiled(vpds_desc *d, const uint64_t *tiles, int threads)
{
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    vpds_tiling *tg;
    vpds_tiled *out;
    char msg[512];
    double t0;
    td.sampler = d;
    td.tiles = tiles;
    rd.threads = threads;
    rd.callbacks_thread_safe = 1; /* the bench's sizing functions are pure */
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

/* tilestats: an executor that runs each batch (a phase) serially, timing every task. */
typedef struct {
    double sum[1 << VPDS_MAX_DIM], max[1 << VPDS_MAX_DIM];
    int phases;
} tile_times;

static void timing_executor(vpds_task_fn run, void *batch, uint64_t n, void *user)
{
    tile_times *tt = (tile_times *)user;
    uint64_t i;
    int p = tt->phases++;
    tt->sum[p] = tt->max[p] = 0;
    for (i = 0; i < n; i++) {
        double t0 = now(), dt;
        run(batch, i);
        dt = now() - t0;
        tt->sum[p] += dt;
        if (dt > tt->max[p]) tt->max[p] = dt;
    }
}

/* The inputs of the speed-up model (README, "Expected speed-up"): one run of the box (W1), the
 * tiles' work per phase (W_p) and its largest tile (m_p), and, for T workers, the greedy
 * schedule's bounds per phase, max(W_p / T, m_p) <= phase time <= W_p / T + m_p (Graham). */
static int tilestats(vpds_desc *d, uint64_t per_axis)
{
    static const int workers[4] = {2, 16, 64, 1024};
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    uint64_t tiles[VPDS_MAX_DIM];
    vpds_tiling *tg;
    vpds_tiled *out;
    vpds_sampler *s;
    tile_times tt;
    double t0, w1, wall, work = 0;
    char msg[512];
    int k, p, w;
    memset(&tt, 0, sizeof tt);
    if (vpds_create(d, &s) != VPDS_OK) return 1;
    t0 = now();
    while (vpds_run(s) == VPDS_PAUSED) {}
    w1 = now() - t0;
    printf("one run: %zu samples in %.3f s\n", vpds_count(s), w1);
    vpds_destroy(s);
    for (k = 0; k < d->dim; k++) tiles[k] = per_axis;
    td.sampler = d;
    td.tiles = tiles;
    rd.executor = timing_executor;
    rd.executor_user = &tt;
    if (vpds_tiling_create(&td, &tg) != VPDS_OK) return 1;
    t0 = now();
    if (vpds_tiling_run(tg, &rd, &out, msg, sizeof msg) != VPDS_OK) {
        fprintf(stderr, "tilestats: %s\n", msg);
        return 1;
    }
    wall = now() - t0;
    for (p = 0; p < tt.phases; p++) work += tt.sum[p];
    printf("tiled: %zu samples, %llu tiles, %d phases; tiles' work %.3f s (%.3fx one run), "
           "outside the tiles %.3f s\n", vpds_tiled_count(out), (unsigned long long)vpds_tiling_count(tg),
           tt.phases, work, work / w1, wall - work);
    for (p = 0; p < tt.phases; p++)
        printf("  phase %d: work %.4f s, largest tile %.4f s\n", p, tt.sum[p], tt.max[p]);
    for (w = 0; w < 4; w++) {
        double lo = 0, hi = 0;
        for (p = 0; p < tt.phases; p++) {
            double even = tt.sum[p] / workers[w];
            lo += even > tt.max[p] ? even : tt.max[p];
            hi += even + tt.max[p];
        }
        printf("  %4d workers: speed-up over one run between %.2f and %.2f\n", workers[w], w1 / hi, w1 / lo);
    }
    vpds_tiled_destroy(out);
    vpds_tiling_destroy(tg);
    return 0;
}

/* The unit sphere: each face of an icosahedron split into k*k triangles, pushed onto it. */
static void icosphere(int k, double **v_out, uint32_t **t_out, size_t *nv, size_t *nt)
{
    static const int f[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9},
                                 {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2},
                                 {3, 2, 6}, {3, 6, 8}, {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10},
                                 {8, 6, 7}, {9, 8, 1}};
    double p = (1 + sqrt(5.0)) / 2, ico[12][3] = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                                                  {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                                                  {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
    size_t per = (size_t)((k + 1) * (k + 2) / 2);
    double *v = (double *)malloc(20 * per * 3 * sizeof(double));
    uint32_t *t = (uint32_t *)malloc(20 * (size_t)k * (size_t)k * 3 * sizeof(uint32_t));
    int fi, a, b, c;
    *nv = *nt = 0;
    for (fi = 0; fi < 20; fi++) {
        size_t base = *nv;
        for (a = 0; a <= k; a++)
            for (b = 0; a + b <= k; b++) {
                double q[3], n = 0;
                for (c = 0; c < 3; c++) {
                    q[c] = ico[f[fi][0]][c] + (double)a / k * (ico[f[fi][1]][c] - ico[f[fi][0]][c]) +
                           (double)b / k * (ico[f[fi][2]][c] - ico[f[fi][0]][c]);
                    n += q[c] * q[c];
                }
                for (c = 0; c < 3; c++) v[3 * *nv + (size_t)c] = q[c] / sqrt(n);
                (*nv)++;
            }
#define IDX(a, b) (uint32_t)(base + (size_t)((a) * (2 * k + 3 - (a)) / 2 + (b)))
        for (a = 0; a < k; a++)
            for (b = 0; a + b < k; b++) {
                uint32_t *o = t + 3 * (*nt)++;
                o[0] = IDX(a, b), o[1] = IDX(a + 1, b), o[2] = IDX(a, b + 1);
                if (a + b + 1 < k) {
                    o = t + 3 * (*nt)++;
                    o[0] = IDX(a + 1, b), o[1] = IDX(a + 1, b + 1), o[2] = IDX(a, b + 1);
                }
            }
#undef IDX
    }
    *v_out = v;
    *t_out = t;
}

static int run_mesh(const char *name, const double *v, size_t nv, const uint32_t *t, size_t nt, double radius)
{
    vpds_mesh_desc md = vpds_default_mesh_desc();
    vpds_mesh *m;
    double t0;
    md.vertices = v;
    md.n_vertices = nv;
    md.triangles = t;
    md.n_triangles = nt;
    md.radius = radius;
    md.seed = 1;
    if (vpds_mesh_create(&md, &m) != VPDS_OK) return 1;
    t0 = now();
    if (vpds_mesh_run(m) != VPDS_OK) {
        fprintf(stderr, "%s: %s\n", name, vpds_mesh_last_error(m));
        return 1;
    }
    printf("%s %zu %.6f %zu\n", name, vpds_mesh_count(m), now() - t0, vpds_mesh_get_stats(m).peak_bytes);
    {
        vpds_stats stats = vpds_mesh_get_stats(m);
        print_counts(&stats);
    }
    vpds_mesh_destroy(m);
    return 0;
}

/* The stream on the unit sphere: n calls of vpds_mesh_next. */
static int mesh_stream(size_t n, unsigned version)
{
    vpds_mesh_desc md = vpds_default_mesh_desc();
    vpds_mesh *m;
    double *v, x[3], t, t0;
    uint32_t *tri;
    size_t nv, nt, i;
    icosphere(40, &v, &tri, &nv, &nt);
    md.vertices = v;
    md.n_vertices = nv;
    md.triangles = tri;
    md.n_triangles = nt;
    md.radius = 1;
    md.seed = 1;
    md.algorithm_version = version;
    if (vpds_mesh_create(&md, &m) != VPDS_OK) return 1;
    t0 = now();
    for (i = 0; i < n; i++)
        if (vpds_mesh_next(m, 0, x, &t) != VPDS_OK) {
            fprintf(stderr, "meshstream: %s\n", vpds_mesh_last_error(m));
            return 1;
        }
    printf("meshstream %zu %.6f %zu\n", n, now() - t0, vpds_mesh_get_stats(m).peak_bytes);
    vpds_mesh_destroy(m);
    free(v);
    free(tri);
    return 0;
}

static int mesh_file(const char *path, double radius)
{
    FILE *f = fopen(path, "r");
    size_t nv, nt, i;
    double *v;
    uint32_t *t;
    int ok, rc;
    if (!f || fscanf(f, "%zu %zu", &nv, &nt) != 2) return 1;
    v = (double *)malloc(3 * nv * sizeof(double));
    t = (uint32_t *)malloc(3 * nt * sizeof(uint32_t));
    for (i = 0, ok = 1; ok && i < 3 * nv; i++) ok = fscanf(f, "%lf", v + i) == 1;
    for (i = 0; ok && i < 3 * nt; i++) ok = fscanf(f, "%u", t + i) == 1;
    fclose(f);
    rc = ok ? run_mesh("meshfile", v, nv, t, nt, radius) : 1;
    free(v);
    free(t);
    return rc;
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
        if (argc >= 6) d.algorithm_version = (uint32_t)atoi(argv[5]);
        return run("tworadii", &d);
    }
    if (argc >= 3 && !strcmp(argv[1], "tworamp3")) {
        static const int periodic[3] = {0, 1, 1};
        d.dim = 3;
        d.sizing = ramp3;
        d.lipschitz = 0.12;
        d.inhibition = argc >= 4 ? atof(argv[3]) : 0.5;
        d.rule = VPDS_RULE_BIGGER;
        d.periodic = periodic;
        d.algorithm_version = (uint32_t)atoi(argv[2]);
        return run("tworamp3", &d);
    }
    if (argc >= 6 && !strcmp(argv[1], "threads")) {
        d.dim = atoi(argv[2]);
        d.radius = atof(argv[3]);
        uint64_t tiles[VPDS_MAX_DIM];
        int k;
        d.dim = d.dim < 1 ? 1 : d.dim > VPDS_MAX_DIM ? VPDS_MAX_DIM : d.dim;
        for (k = 0; k < d.dim; k++) tiles[k] = (uint64_t)atoi(argv[4]);
        return tiled(&d, tiles, atoi(argv[5]));
    }
    if (argc >= 5 && !strcmp(argv[1], "tilestats")) {
        d.dim = atoi(argv[2]);
        d.radius = atof(argv[3]);
        return tilestats(&d, (uint64_t)atoi(argv[4]));
    }
    if (argc >= 3 && !strcmp(argv[1], "annulus")) {
        d.radius = atof(argv[2]);
        d.domain = annulus;
        return run("annulus", &d);
    }
    if (argc >= 6 && !strcmp(argv[1], "stream")) {
        d.dim = atoi(argv[2]);
        d.radius = atof(argv[3]);
        if (argc >= 7) d.algorithm_version = (uint32_t)atoi(argv[6]);
        if (argc >= 8) d.inhibition = atof(argv[7]);
        return stream(&d, (size_t)atof(argv[4]), (size_t)atoi(argv[5]));
    }
    if (argc >= 5 && !strcmp(argv[1], "afterrun")) {
        d.dim = atoi(argv[2]);
        d.radius = atof(argv[3]);
        if (argc >= 6) d.algorithm_version = (uint32_t)atoi(argv[5]);
        return stream_after_run(&d, (size_t)atof(argv[4]));
    }
    if (argc >= 5 && !strcmp(argv[1], "streamramp")) {
        /* the stream with the ramp r = 0.001 + 0.3 x0 on the unit square, one rule */
        d.sizing = ramp;
        d.lipschitz = 0.3;
        d.rule = !strcmp(argv[2], "prior") ? VPDS_RULE_PRIOR : !strcmp(argv[2], "current") ? VPDS_RULE_CURRENT
                 : !strcmp(argv[2], "bigger") ? VPDS_RULE_BIGGER : VPDS_RULE_SMALLER;
        if (argc >= 6) d.algorithm_version = (uint32_t)atoi(argv[5]);
        return stream(&d, (size_t)atof(argv[3]), (size_t)atoi(argv[4]));
    }
    if (argc >= 3 && (!strcmp(argv[1], "ramp") || (argc >= 6 && !strcmp(argv[1], "rampthreads")))) {
        /* the paper's Figure 1 ramp on a box 400 times taller: about a million samples */
        double lo[2] = {0, 0}, hi[2] = {1, 400};
        d.lo = lo;
        d.hi = hi;
        d.sizing = ramp;
        d.lipschitz = 0.3;
        d.rule = !strcmp(argv[2], "prior") ? VPDS_RULE_PRIOR : !strcmp(argv[2], "current") ? VPDS_RULE_CURRENT
                 : !strcmp(argv[2], "bigger") ? VPDS_RULE_BIGGER : VPDS_RULE_SMALLER;
        if (!strcmp(argv[1], "rampthreads")) {
            uint64_t tiles[2];
            d.radius_max = 0.301;
            tiles[0] = (uint64_t)atoi(argv[3]);
            tiles[1] = (uint64_t)atoi(argv[4]);
            return tiled(&d, tiles, atoi(argv[5]));
        }
        return run(argv[2], &d);
    }
    if (argc >= 4 && !strcmp(argv[1], "mesh")) {
        static const double sq_v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
        static const uint32_t sq_t[6] = {0, 1, 2, 1, 3, 2};
        double *v;
        uint32_t *t;
        size_t nv, nt;
        int rc;
        if (!strcmp(argv[2], "square")) return run_mesh("mesh-square", sq_v, 4, sq_t, 2, atof(argv[3]));
        icosphere(40, &v, &t, &nv, &nt);
        rc = run_mesh("mesh-sphere", v, nv, t, nt, atof(argv[3]));
        free(v);
        free(t);
        return rc;
    }
    if (argc >= 3 && !strcmp(argv[1], "meshstream")) return mesh_stream((size_t)atof(argv[2]), argc >= 4 ? (unsigned)atoi(argv[3]) : 0);
    if (argc >= 4 && !strcmp(argv[1], "meshfile")) return mesh_file(argv[2], atof(argv[3]));
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
    fprintf(stderr, "usage: bench uniform DIM RADIUS | tworadii DIM RADIUS INHIBITION | ramp RULE | rampthreads RULE TX TY THREADS"
                    " | tworamp3 VERSION | floor N DIM | stream DIM RADIUS N STEPS [VERSION [INHIBITION]] | afterrun DIM RADIUS N [VERSION] | streamramp RULE N STEPS [VERSION] | mesh square|sphere RADIUS | meshstream N [VERSION] | meshfile FILE RADIUS\n");
    return 2;
}
