/* Samples one named mesh configuration and writes it, for the golden outputs of meshes
 * (tests/determinism.sh): int64 n, then n*3 doubles x, n radii, n scales t, n uint32 faces and
 * n*3 doubles of barycentrics.
 * usage: mesh_tool OUT mesh rule sizing radius seed [KEY=VALUE...]
 *   mesh: terrain (a 6 x 6 height field, 72 triangles) or needle (a fan of four triangles, one
 *   of them a needle 2e-4 wide: the stream's hard case); rule: prior|current|bigger|smaller;
 *   sizing: const (radius), vertex (vertex radii 0.03 + 0.08 x) or steep (0.03 + 0.1 |x|, L 0.1)
 *   KEY=VALUE: run=0|1 (vpds_mesh_run first; default 1), stream=N (then N events of
 *   vpds_mesh_next, t_min 0), refine=T (vpds_mesh_refine to T after them), version=N */
#include "vpds.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GRID 6

static double steep(const double *x, void *u) { (void)u; return 0.03 + 0.1 * fabs(x[0]); }

/* A height field over the unit square: (GRID + 1)^2 vertices, 2 GRID^2 triangles. */
static void terrain(double *v, size_t *nv, uint32_t *tri, size_t *nt)
{
    int i, j;
    *nv = *nt = 0;
    for (j = 0; j <= GRID; j++)
        for (i = 0; i <= GRID; i++) {
            double x = (double)i / GRID, y = (double)j / GRID;
            v[3 * *nv] = x;
            v[3 * *nv + 1] = y;
            v[3 * *nv + 2] = 0.15 * sin(3 * x) * cos(2 * y);
            (*nv)++;
        }
    for (j = 0; j < GRID; j++)
        for (i = 0; i < GRID; i++) {
            uint32_t a = (uint32_t)(j * (GRID + 1) + i), b = a + 1, c = a + GRID + 1, d = c + 1;
            uint32_t t[6] = {a, b, d, a, d, c};
            memcpy(tri + 3 * *nt, t, sizeof t);
            *nt += 2;
        }
}

/* Four triangles about the origin, one a needle 1 long and 2e-4 wide. */
static void needle(double *v, size_t *nv, uint32_t *tri, size_t *nt)
{
    static const double pts[6][3] = {{0, 0, 0}, {1, 0, 0}, {1, 2e-4, 0}, {0, 0.6, 0.1},
                                     {-0.5, 0.1, 0.2}, {0.2, -0.5, 0}};
    static const uint32_t t[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 5, 1}};
    memcpy(v, pts, sizeof pts);
    memcpy(tri, t, sizeof t);
    *nv = 6;
    *nt = 4;
}

static int write_samples(const char *path, const vpds_mesh *m)
{
    size_t n = vpds_mesh_count(m);
    long long hdr = (long long)n;
    FILE *f = fopen(path, "wb");
    if (!f) return 1;
    fwrite(&hdr, sizeof hdr, 1, f);
    fwrite(vpds_mesh_points(m), sizeof(double), 3 * n, f);
    fwrite(vpds_mesh_radii(m), sizeof(double), n, f);
    fwrite(vpds_mesh_scales(m), sizeof(double), n, f);
    fwrite(vpds_mesh_faces(m), sizeof(uint32_t), n, f);
    fwrite(vpds_mesh_barycentrics(m), sizeof(double), 3 * n, f);
    return fclose(f) != 0;
}

int main(int argc, char **argv)
{
    static double v[3 * (GRID + 1) * (GRID + 1)], vr[(GRID + 1) * (GRID + 1)];
    static uint32_t tri[3 * 2 * GRID * GRID];
    vpds_mesh_desc d = vpds_default_mesh_desc();
    vpds_mesh *m;
    vpds_status st = VPDS_OK;
    int run = 1, a;
    long events = 0, e;
    double refine = 0;
    size_t k;
    if (argc < 7) {
        fprintf(stderr, "usage: %s OUT mesh rule sizing radius seed [KEY=VALUE...]\n", argv[0]);
        return 2;
    }
    if (!strcmp(argv[2], "terrain")) terrain(v, &d.n_vertices, tri, &d.n_triangles);
    else needle(v, &d.n_vertices, tri, &d.n_triangles);
    d.vertices = v;
    d.triangles = tri;
    d.rule = !strcmp(argv[3], "prior")     ? VPDS_RULE_PRIOR
             : !strcmp(argv[3], "current") ? VPDS_RULE_CURRENT
             : !strcmp(argv[3], "bigger")  ? VPDS_RULE_BIGGER
                                           : VPDS_RULE_SMALLER;
    d.radius = atof(argv[5]);
    if (!strcmp(argv[4], "vertex")) {
        for (k = 0; k < d.n_vertices; k++) vr[k] = 0.03 + 0.08 * fabs(v[3 * k]);
        d.vertex_radii = vr;
    } else if (!strcmp(argv[4], "steep")) {
        d.sizing = steep;
        d.lipschitz = 0.1;
    }
    d.seed = strtoull(argv[6], NULL, 10);
    for (a = 7; a < argc; a++) {
        const char *val = strchr(argv[a], '=') ? strchr(argv[a], '=') + 1 : "";
        if (!strncmp(argv[a], "run=", 4)) run = atoi(val);
        else if (!strncmp(argv[a], "stream=", 7)) events = atol(val);
        else if (!strncmp(argv[a], "refine=", 7)) refine = atof(val);
        else if (!strncmp(argv[a], "version=", 8)) d.algorithm_version = (uint32_t)atoi(val);
        else {
            fprintf(stderr, "mesh_tool: unknown option '%s'\n", argv[a]);
            return 2;
        }
    }
    if ((st = vpds_mesh_create(&d, &m)) != VPDS_OK) {
        char msg[512];
        vpds_mesh_validate(&d, msg, sizeof msg);
        fprintf(stderr, "vpds_mesh_create: %s: %s\n", vpds_status_string(st), msg);
        return 1;
    }
    if (run) st = vpds_mesh_run(m);
    for (e = 0; st == VPDS_OK && e < events; e++) {
        double x[3], t;
        st = vpds_mesh_next(m, 0.0, x, &t);
        if (st == VPDS_STREAM_END) st = VPDS_OK, e = events;
    }
    if (st == VPDS_OK && refine > 0) st = vpds_mesh_refine(m, refine);
    if (st != VPDS_OK) {
        fprintf(stderr, "mesh_tool: %s: %s\n", vpds_status_string(st), vpds_mesh_last_error(m));
        vpds_mesh_destroy(m);
        return 1;
    }
    if (write_samples(argv[1], m)) return 1;
    printf("n=%zu levels=%u\n", vpds_mesh_count(m), vpds_mesh_get_stats(m).levels);
    vpds_mesh_destroy(m);
    return 0;
}
