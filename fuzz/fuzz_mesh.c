/* Mesh descriptors and runs from the input: up to 10 vertices (NaN, inf and huge values now and
 * then), up to 8 triangles with any indices (out of range, repeated: degenerate), a radius or
 * vertex radii, a rule, a budget; a run or the stream, and mixed: a stream after the run, a refine
 * after the stream. A refused descriptor has a documented status and a message,
 * and create refuses it too; an accepted one runs (through pauses) to a documented status, its
 * samples on their triangles and conflict-free, and a completed run covers probes on every
 * triangle of area. */
#include "fuzz_common.h"

#define MAX_V 10
#define MAX_T 8

static double tri_area(const double *v, const uint32_t *t, double *longest)
{
    const double *a = v + 3 * t[0], *b = v + 3 * t[1], *c = v + 3 * t[2];
    double e1[3], e2[3], e3[3], cr[3];
    int k;
    for (k = 0; k < 3; k++) e1[k] = b[k] - a[k], e2[k] = c[k] - a[k], e3[k] = c[k] - b[k];
    cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
    cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
    cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
    *longest = sqrt(fmax(fmax(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2], e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]),
                         e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2]));
    return 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
}

static double radius_at(const double *vr, double radius, const uint32_t *t, const double *b)
{
    return vr ? b[0] * vr[t[0]] + b[1] * vr[t[1]] + b[2] * vr[t[2]] : radius;
}

static void check_run(const vpds_mesh *s, const double *v, const uint32_t *tri, size_t nt,
                      const double *vr, double radius, vpds_rule rule, int complete, double tol)
{
    size_t n = vpds_mesh_count(s), i, j, f;
    const double *x = vpds_mesh_points(s), *r = vpds_mesh_radii(s), *bc = vpds_mesh_barycentrics(s);
    const double *ts = vpds_mesh_scales(s);
    const uint32_t *face = vpds_mesh_faces(s);
    if (rule == VPDS_RULE_DEFAULT) rule = VPDS_RULE_SMALLER;
    for (i = 0; i < n; i++) {
        const uint32_t *t;
        int k;
        FUZZ_ASSERT(face[i] < nt, "sample %zu on face %u", i, (unsigned)face[i]);
        t = tri + 3 * face[i];
        FUZZ_ASSERT(fabs(bc[3 * i] + bc[3 * i + 1] + bc[3 * i + 2] - 1) < 1e-12, "barycentrics of %zu", i);
        for (k = 0; k < 3; k++) {
            double p = bc[3 * i] * v[3 * t[0] + k] + bc[3 * i + 1] * v[3 * t[1] + k] + bc[3 * i + 2] * v[3 * t[2] + k];
            FUZZ_ASSERT(fabs(p - x[3 * i + k]) <= 1e-9 * (1 + fabs(p)), "sample %zu off its triangle", i);
        }
        FUZZ_ASSERT(fabs(r[i] - radius_at(vr, radius, t, bc + 3 * i)) <= 1e-12 * r[i], "radius of %zu", i);
        for (j = 0; j < i; j++) {
            double d2 = 0, fr = ts[i] * rule_f(rule, r[j], r[i]) * (1 - tol);
            for (k = 0; k < 3; k++) d2 += (x[3 * i + k] - x[3 * j + k]) * (x[3 * i + k] - x[3 * j + k]);
            FUZZ_ASSERT(d2 >= fr * fr * (1 - 1e-12), "samples %zu and %zu conflict", j, i);
        }
    }
    if (!complete) return;
    for (f = 0; f < nt; f++) {
        const uint32_t *t = tri + 3 * f;
        double longest, area = tri_area(v, t, &longest);
        int a, b, steps = 12;
        if (!(area > 9.094947017729282e-13 * longest * longest)) continue;
        for (a = 0; a <= steps; a++)
            for (b = 0; a + b <= steps; b++) {
                double bb[3] = {1 - (double)(a + b) / steps, (double)a / steps, (double)b / steps}, y[3], ry;
                int k, hit = 0;
                for (k = 0; k < 3; k++) y[k] = bb[0] * v[3 * t[0] + k] + bb[1] * v[3 * t[1] + k] + bb[2] * v[3 * t[2] + k];
                ry = radius_at(vr, radius, t, bb);
                for (i = 0; i < n && !hit; i++) {
                    double d2 = 0, fr = rule_f(rule, r[i], ry);
                    for (k = 0; k < 3; k++) d2 += (y[k] - x[3 * i + k]) * (y[k] - x[3 * i + k]);
                    hit = d2 <= fr * fr * (1 + 1e-9);
                }
                FUZZ_ASSERT(hit, "probe (%d, %d) of triangle %zu uncovered", a, b, f);
            }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes_t in = {data, size};
    vpds_mesh_desc d = vpds_default_mesh_desc();
    double v[3 * MAX_V], vr[MAX_V];
    uint32_t tri[3 * MAX_T];
    size_t nv = 3 + take_u8(&in) % (MAX_V - 2), nt = take_u8(&in) % (MAX_T + 1), i;
    int mode = take_u8(&in), use_vr = mode & 1, calls;
    char msg[512];
    vpds_mesh *s = NULL;
    vpds_status st;
    for (i = 0; i < 3 * nv; i++) v[i] = take_double(&in, -1, 1, 1);
    for (i = 0; i < nv; i++) vr[i] = take_double(&in, 0.2, 0.4, 1);
    for (i = 0; i < 3 * nt; i++) tri[i] = take_u8(&in) % (uint32_t)(nv + 1); /* nv: out of range */
    d.vertices = v;
    d.n_vertices = nv;
    d.triangles = tri;
    d.n_triangles = nt;
    d.radius = take_double(&in, 0.1, 0.5, 1);
    if (use_vr) d.vertex_radii = vr;
    d.rule = (vpds_rule)(take_u8(&in) % 5);
    d.seed = take_u32(&in);
    d.budget = 1 + take_u8(&in) * 16u;
    st = vpds_mesh_validate(&d, msg, sizeof msg);
    check_status(st);
    if (st != VPDS_OK) {
        FUZZ_ASSERT(st < 0 && msg[0], "refused with status %d and no message", (int)st);
        FUZZ_ASSERT(vpds_mesh_create(&d, &s) == st && s == NULL, "create accepted a refused descriptor");
        return 0;
    }
    FUZZ_ASSERT(vpds_mesh_create(&d, &s) == VPDS_OK, "create refused a valid descriptor");
    if (mode & 2) {
        /* the stream: t never rises, each sample on its triangle and clear of the others */
        double x[3], t, last = INFINITY;
        if (mode & 8) {
            /* the 40 events in one call of vpds_mesh_next_n: written as stored, t never rising */
            double xs[40 * 3], ts[40];
            size_t got = 99, k;
            st = vpds_mesh_next_n(s, 40, 0, xs, ts, &got);
            FUZZ_ASSERT(got <= 40 && vpds_mesh_count(s) == got, "next_n: %zu events, %zu held", got,
                        vpds_mesh_count(s));
            for (k = 0; k < got; k++) {
                FUZZ_ASSERT(ts[k] <= last && !isnan(ts[k]) && ts[k] == vpds_mesh_scales(s)[k] &&
                            memcmp(xs + 3 * k, vpds_mesh_points(s) + 3 * k, sizeof x) == 0,
                            "next_n: event %zu (t %g after %g)", k, ts[k], last);
                last = t = ts[k];
            }
        } else {
            for (calls = 0; calls < 40 && (st = vpds_mesh_next(s, 0, x, &t)) == VPDS_OK; calls++) {
                FUZZ_ASSERT(t <= last && !isnan(t), "stream t %g after %g", t, last);
                last = t;
            }
        }
        check_status(st);
        FUZZ_ASSERT(st == VPDS_OK, "stream status %d: %s", (int)st, vpds_mesh_last_error(s));
        /* the samples are maximal at the last t: a run has nothing to add */
        i = vpds_mesh_count(s);
        FUZZ_ASSERT(vpds_mesh_run(s) == VPDS_OK && vpds_mesh_count(s) == i, "a run after the stream");
        st = VPDS_ERR_STATE;
        if ((mode & 4) && isfinite(last)) { /* a refine below it, through its pauses, and the stream again */
            double t_ref = 0.8 * last;
            for (calls = 0; calls < 2000 && (st = vpds_mesh_refine(s, t_ref)) == VPDS_PAUSED; calls++) {}
            check_status(st);
            FUZZ_ASSERT(st == VPDS_OK || st == VPDS_PAUSED || st == VPDS_ERR_OVERFLOW, "refine after the stream: "
                        "status %d: %s", (int)st, vpds_mesh_last_error(s));
            for (calls = 0, last = t_ref; st == VPDS_OK && calls < 5; calls++) {
                FUZZ_ASSERT(vpds_mesh_next(s, 0, x, &t) == VPDS_OK && t <= last, "stream after a refine: t %g after %g",
                            t, last);
                last = t;
            }
            /* probed at scale 1: covered there when covered at t_ref <= 1 (the disks only grow) */
            st = st == VPDS_OK && t_ref <= 1 && vpds_mesh_get_stats(s).delta == 0 ? VPDS_OK : VPDS_ERR_STATE;
        }
        check_run(s, v, tri, nt, d.vertex_radii, d.radius, d.rule, st == VPDS_OK, VPDS_STREAM_TOLERANCE);
        vpds_mesh_destroy(s);
        return 0;
    }
    for (calls = 0; calls < 2000 && (st = vpds_mesh_run(s)) == VPDS_PAUSED; calls++) {}
    check_status(st);
    FUZZ_ASSERT(st == VPDS_OK || st == VPDS_PAUSED || st == VPDS_ERR_OVERFLOW, "status %d: %s", (int)st,
                vpds_mesh_last_error(s));
    check_run(s, v, tri, nt, d.vertex_radii, d.radius, d.rule,
              st == VPDS_OK && vpds_mesh_get_stats(s).delta == 0, 0);
    if (st == VPDS_OK) FUZZ_ASSERT(vpds_mesh_get_stats(s).maximal, "completed but not maximal");
    if (st == VPDS_OK && (mode & 4)) { /* the stream continued after the run: t <= 1, never rising */
        double x[3], t, last = 1.0;
        for (calls = 0; calls < 20 && (st = vpds_mesh_next(s, 0, x, &t)) == VPDS_OK; calls++) {
            FUZZ_ASSERT(t <= last && !isnan(t), "stream after a run: t %g after %g", t, last);
            last = t;
        }
        check_status(st);
        FUZZ_ASSERT(st == VPDS_OK, "stream after a run: status %d: %s", (int)st, vpds_mesh_last_error(s));
        check_run(s, v, tri, nt, d.vertex_radii, d.radius, d.rule, 0, VPDS_STREAM_TOLERANCE);
    }
    vpds_mesh_destroy(s);
    return 0;
}
