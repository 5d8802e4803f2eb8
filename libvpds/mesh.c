/* Public entry points for surfaces: the mesh descriptor (defaults, validation naming the vertex
 * or triangle), the mesh object that owns copies of the arrays, runs, refinement and results.
 * The algorithm is surface.c's; the sizing and its checks are the box sampler's (vpds_validate
 * on a 3D descriptor made from the mesh's). */
#include "grid.h"
#include "refuse.h"
#include "rules.h"
#include "surface.h"
#include "surface_stream.h"
#include <math.h>
#include <string.h>

#define VPDSI_MESH_COOKIE 0x56504d31u /* 'VPM1': layout 1 of vpds_mesh_desc */
#define VPDSI_MESH_MAGIC 0x56504d53u  /* 'VPMS' */
#define MESH_ALGORITHM_FIRST 3        /* meshes came with algorithm version 3 */
/* a triangle below this area per longest edge squared is degenerate (height < 2^-39 length) */
#define DEGENERATE_AREA 9.094947017729282e-13 /* 2^-40 */
#define MESH_PRECISION_BITS 44                     /* as the box: no piece splits below 2^-44 of |x| */

struct vpds_mesh {
    uint32_t magic;
    vpdsi_mem mem;
    double *v, *vr, *area, *longest;
    uint32_t *tri, *live;
    size_t n_v, n_tri;
    vpdsi_trimesh view;
    vpdsi_store store;
    vpdsi_surface surface;
    vpdsi_surface_marks marks;
    vpdsi_surface_stream stream;   /* in use once vpds_mesh_next was called */
    double run_t;                  /* the scale of the last run completed (+INFINITY: none): the
                                      stream after it reports no scale above it */
    vpdsi_rng rng;
    vpds_stats stats;
    vpds_rule rule;
    double coverage;
    uint64_t budget;
    vpds_progress_fn progress;
    void *progress_user;
};

vpds_mesh_desc vpds_default_mesh_desc(void)
{
    vpds_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.cookie = VPDSI_MESH_COOKIE;
    d.struct_size = (uint32_t)sizeof d;
    d.radius = 0.05;
    d.lipschitz = VPDS_UNSET;
    d.rule = VPDS_RULE_DEFAULT;
    d.inhibition = 1.0;
    d.coverage = 1.0;
    return d;
}

/* The box sampler's descriptor for the mesh's sizing (3D), which vpds_validate checks and
 * vpdsi_sizing_from_desc reads. */
static vpds_desc sizing_desc(const vpds_mesh_desc *d)
{
    vpds_desc b = vpds_default_desc();
    b.dim = 3;
    if (!d->vertex_radii) b.radius = d->radius;
    b.sizing = d->sizing;
    b.sizing_batch = d->sizing_batch;
    b.sizing_user = d->sizing_user;
    b.sizing_grid = d->sizing_grid;
    b.lipschitz = d->lipschitz;
    b.rule = d->rule;
    b.inhibition = d->inhibition;
    b.coverage = d->coverage;
    b.allocator = d->allocator;
    return b;
}

/* The edges of triangle t divided by their largest coordinate difference *m (0: one point), so
 * that squares neither overflow nor underflow whatever the triangle's size. */
static void scaled_edges(const double *v, const uint32_t *t, double e[3][3], double *m)
{
    const double *a = v + 3 * (size_t)t[0], *b = v + 3 * (size_t)t[1], *c = v + 3 * (size_t)t[2];
    int k, q;
    *m = 0;
    for (k = 0; k < 3; k++) {
        e[0][k] = b[k] - a[k];
        e[1][k] = c[k] - a[k];
        e[2][k] = c[k] - b[k];
        for (q = 0; q < 3; q++) *m = fabs(e[q][k]) > *m ? fabs(e[q][k]) : *m;
    }
    for (q = 0; *m > 0 && q < 3; q++)
        for (k = 0; k < 3; k++) e[q][k] /= *m;
}

/* Area, longest edge and shape (area / longest^2, scale-free) of triangle t. */
static void triangle_shape(const double *v, const uint32_t *t, double *area, double *longest, double *shape)
{
    double e[3][3], m, cr[3], l2 = 0;
    int q;
    scaled_edges(v, t, e, &m);
    for (q = 0; q < 3; q++) {
        double d = e[q][0] * e[q][0] + e[q][1] * e[q][1] + e[q][2] * e[q][2];
        if (d > l2) l2 = d;
    }
    cr[0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
    cr[1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
    cr[2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    *shape = l2 > 0 ? 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]) / l2 : 0;
    *longest = m * sqrt(l2);
    *area = *shape * *longest * *longest;
}

static int degenerate(double shape, double longest)
{
    return !(longest > 0) || !(shape > DEGENERATE_AREA);
}

/* |grad r| of the vertex radii over triangle t (not degenerate): r linear in the triangle's
 * plane, |g|^2 = dr^T G^-1 dr with G the Gram matrix of two edges (in units of m), det G the
 * squared cross product. */
static double radius_slope(const double *v, const double *vr, const uint32_t *t)
{
    double e[3][3], m, g11 = 0, g12 = 0, g22 = 0, d1 = vr[t[1]] - vr[t[0]], d2 = vr[t[2]] - vr[t[0]], q, det;
    int k;
    scaled_edges(v, t, e, &m);
    for (k = 0; k < 3; k++) {
        g11 += e[0][k] * e[0][k];
        g12 += e[0][k] * e[1][k];
        g22 += e[1][k] * e[1][k];
    }
    det = g11 * g22 - g12 * g12;
    q = det > 0 ? (d1 * d1 * g22 - 2 * d1 * d2 * g12 + d2 * d2 * g11) / det : INFINITY;
    return q > 0 ? sqrt(q) / m : 0;
}

static vpds_status validate_arrays(const vpds_mesh_desc *d, char *msg, size_t cap)
{
    size_t i, n_live = 0;
    int k;
    if (!d->vertices && d->n_vertices > 0)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.vertices is NULL (n_vertices = %zu)", d->n_vertices);
    if (!d->triangles && d->n_triangles > 0)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.triangles is NULL (n_triangles = %zu)", d->n_triangles);
    if (!d->vertices || d->n_vertices == 0)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.vertices: no vertices (n_vertices = %zu)", d->n_vertices);
    if (!d->triangles || d->n_triangles == 0)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.triangles: a mesh needs at least one triangle "
                     "(n_triangles = %zu)", d->n_triangles);
    if (d->n_vertices > SIZE_MAX / 24 || d->n_triangles > (size_t)UINT32_MAX)
        VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "desc: %zu vertices, %zu triangles: at most %u triangles, and "
                     "the arrays' sizes must not overflow", d->n_vertices, d->n_triangles, UINT32_MAX);
    for (i = 0; i < d->n_vertices; i++)
        for (k = 0; k < 3; k++) {
            double x = d->vertices[3 * i + (size_t)k];
            if (!isfinite(x) || fabs(x) > VPDSI_MAGNITUDE_MAX)
                VPDSI_REFUSE(isfinite(x) ? VPDS_ERR_OVERFLOW : VPDS_ERR_INVALID_ARGUMENT,
                             "desc.vertices: vertex %zu coordinate %d = %g: must be finite, within "
                             "1e150 in magnitude", i, k, x);
        }
    if (d->vertex_radii)
        for (i = 0; i < d->n_vertices; i++)
            if (!vpdsi_radius_ok(d->vertex_radii[i]))
                VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.vertex_radii[%zu] = %g: must be within "
                             "[1e-100, 1e100] (> 0)", i, d->vertex_radii[i]);
    for (i = 0; i < d->n_triangles; i++) {
        const uint32_t *t = d->triangles + 3 * i;
        double area, longest, shape;
        for (k = 0; k < 3; k++)
            if (t[k] >= d->n_vertices)
                VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.triangles: triangle %zu corner %d is vertex %u, "
                             "out of range (n_vertices = %zu)", i, k, (unsigned)t[k], d->n_vertices);
        triangle_shape(d->vertices, t, &area, &longest, &shape);
        if (!isfinite(area) || !isfinite(longest))
            VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "desc.triangles: triangle %zu: its area or edges overflow", i);
        if (degenerate(shape, longest)) continue;
        n_live++;
        if (d->vertex_radii) {
            double L = radius_slope(d->vertices, d->vertex_radii, t) * d->coverage;
            double limit = vpdsi_rule_max_lipschitz(vpdsi_rule_resolve(d->rule));
            if (!(L < limit))
                VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.vertex_radii: over triangle %zu r changes with "
                             "slope coverage * |grad r| = %g, at or above the %s rule's limit %g (Table 1)",
                             i, L, vpdsi_rule_name(vpdsi_rule_resolve(d->rule)), limit);
        }
    }
    if (n_live == 0)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.triangles: all %zu triangles are degenerate (area "
                     "below 2^-40 of the longest edge squared): nothing to sample", d->n_triangles);
    return VPDS_OK;
}

vpds_status vpds_mesh_validate(const vpds_mesh_desc *d, char *msg, size_t cap)
{
    vpds_desc b;
    vpds_status e;
    if (msg && cap) msg[0] = 0;
    if (!d) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc is NULL");
    if (d->cookie != VPDSI_MESH_COOKIE)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "desc.cookie = 0x%08x: the descriptor did not come from "
                     "vpds_default_mesh_desc()", (unsigned)d->cookie);
    if (d->struct_size != sizeof *d)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "desc.struct_size = %u: a layout this library cannot read "
                     "(it reads %u; rebuild against this vpds.h)", (unsigned)d->struct_size,
                     (unsigned)sizeof *d);
    if (d->algorithm_version && (d->algorithm_version < MESH_ALGORITHM_FIRST ||
                                 d->algorithm_version > VPDS_ALGORITHM_VERSION))
        VPDSI_REFUSE(VPDS_ERR_UNSUPPORTED, "desc.algorithm_version = %u: meshes have versions %d..%d",
                     (unsigned)d->algorithm_version, MESH_ALGORITHM_FIRST, VPDS_ALGORITHM_VERSION);
    if (d->vertex_radii && (d->sizing || d->sizing_batch || d->sizing_grid))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.vertex_radii and a sizing (sizing, sizing_batch or "
                     "sizing_grid) are both set: give one");
    if (d->sizing_grid && d->sizing_grid->magic == VPDSI_GRID_COOKIE && d->sizing_grid->dim != 3)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "desc.sizing_grid has dim %d: a mesh needs a 3D grid",
                     d->sizing_grid->dim);
    b = sizing_desc(d);
    if ((e = vpds_validate(&b, msg, cap)) != VPDS_OK) return e;
    if (d->inhibition != d->coverage)
        VPDSI_REFUSE(VPDS_ERR_UNSUPPORTED, "desc.inhibition = %g, desc.coverage = %g: two radii on a mesh "
                     "are not in this version (set them equal)", d->inhibition, d->coverage);
    return validate_arrays(d, msg, cap);
}

static void *copy_array(vpdsi_mem *m, const void *src, size_t bytes)
{
    void *p = vpdsi_mem_alloc(m, bytes);
    if (p && src) memcpy(p, src, bytes);
    return p;
}

static void free_arrays(vpds_mesh *s)
{
    vpdsi_mem *m = &s->mem;
    vpdsi_mem_free(m, s->v, s->n_v * 3 * sizeof(double));
    vpdsi_mem_free(m, s->vr, s->n_v * sizeof(double));
    vpdsi_mem_free(m, s->tri, s->n_tri * 3 * sizeof(uint32_t));
    vpdsi_mem_free(m, s->live, s->n_tri * sizeof(uint32_t));
    vpdsi_mem_free(m, s->area, s->n_tri * sizeof(double));
    vpdsi_mem_free(m, s->longest, s->n_tri * sizeof(double));
}

/* The copies, the live triangles with their shapes, and the bounding box of the vertices. */
static vpds_status take_arrays(vpds_mesh *s, const vpds_mesh_desc *d, double *lo, double *hi)
{
    vpdsi_mem *m = &s->mem;
    size_t i, n = 0;
    double mag = 0;
    int k;
    s->n_v = d->n_vertices;
    s->n_tri = d->n_triangles;
    s->v = (double *)copy_array(m, d->vertices, s->n_v * 3 * sizeof(double));
    s->vr = d->vertex_radii ? (double *)copy_array(m, d->vertex_radii, s->n_v * sizeof(double)) : NULL;
    s->tri = (uint32_t *)copy_array(m, d->triangles, s->n_tri * 3 * sizeof(uint32_t));
    s->live = (uint32_t *)copy_array(m, NULL, s->n_tri * sizeof(uint32_t));
    s->area = (double *)copy_array(m, NULL, s->n_tri * sizeof(double));
    s->longest = (double *)copy_array(m, NULL, s->n_tri * sizeof(double));
    if (!s->v || (d->vertex_radii && !s->vr) || !s->tri || !s->live || !s->area || !s->longest) {
        free_arrays(s);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    for (i = 0; i < s->n_tri; i++) {
        double area, longest, shape;
        triangle_shape(s->v, s->tri + 3 * i, &area, &longest, &shape);
        if (degenerate(shape, longest)) continue;
        s->live[n] = (uint32_t)i;
        s->area[n] = area;
        s->longest[n++] = longest;
    }
    /* the box and the precision of the sampled set: the corners of the live triangles (a vertex
     * no live triangle uses would widen the index's box for nothing) */
    for (k = 0; k < 3; k++) lo[k] = hi[k] = s->v[3 * (size_t)s->tri[3 * (size_t)s->live[0]] + (size_t)k];
    for (i = 0; i < 3 * n; i++)
        for (k = 0; k < 3; k++) {
            double x = s->v[3 * (size_t)s->tri[3 * (size_t)s->live[i / 3] + i % 3] + (size_t)k];
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
            if (fabs(x) > mag) mag = fabs(x);
        }
    s->view.v = s->v;
    s->view.tri = s->tri;
    s->view.vr = s->vr;
    s->view.n_vertices = s->n_v;
    s->view.live = s->live;
    s->view.area = s->area;
    s->view.longest = s->longest;
    s->view.n_live = n;
    s->view.min_edge = ldexp(mag, -MESH_PRECISION_BITS);
    return VPDS_OK;
}

vpds_status vpds_mesh_create(const vpds_mesh_desc *d, vpds_mesh **out)
{
    vpdsi_mem m;
    vpds_mesh *s;
    vpds_desc b;
    vpds_status e;
    double lo[3], hi[3];
    if (!out) return VPDS_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if ((e = vpds_mesh_validate(d, NULL, 0)) != VPDS_OK) return e;
    vpdsi_mem_init(&m, &d->allocator);
    if (!(s = (vpds_mesh *)vpdsi_mem_alloc(&m, sizeof *s))) return VPDS_ERR_OUT_OF_MEMORY;
    memset(s, 0, sizeof *s);
    s->mem = m;
    if ((e = take_arrays(s, d, lo, hi)) != VPDS_OK) {
        m = s->mem;
        vpdsi_mem_free(&m, s, sizeof *s);
        return e;
    }
    vpdsi_store_init(&s->store, &s->mem, 3, lo, hi, NULL);
    b = sizing_desc(d);
    if ((e = vpdsi_sizing_from_desc(&s->store.sizing, &b)) != VPDS_OK) {
        free_arrays(s);
        m = s->mem;
        vpdsi_mem_free(&m, s, sizeof *s);
        return e;
    }
    s->rule = vpdsi_rule_resolve(d->rule);
    s->coverage = d->coverage;
    s->budget = d->budget;
    s->run_t = INFINITY;
    s->progress = d->progress;
    s->progress_user = d->progress_user;
    vpdsi_rng_seed(&s->rng, d->seed);
    vpdsi_surface_init(&s->surface);
    vpdsi_surface_stream_init(&s->stream, d->algorithm_version ? d->algorithm_version : VPDS_ALGORITHM_VERSION);
    s->magic = VPDSI_MESH_MAGIC;
    *out = s;
    return VPDS_OK;
}

static int live(const vpds_mesh *s) { return s && s->magic == VPDSI_MESH_MAGIC; }

void vpds_mesh_destroy(vpds_mesh *s)
{
    vpdsi_mem m;
    if (!live(s)) return;
    vpdsi_surface_release(&s->surface, &s->mem);
    vpdsi_marks_release(&s->marks, &s->mem);
    vpdsi_surface_stream_release(&s->stream, &s->mem);
    vpdsi_store_release(&s->store);
    free_arrays(s);
    m = s->mem;
    s->magic = 0;
    vpdsi_mem_free(&m, s, sizeof *s);
}

const char *vpds_mesh_last_error(const vpds_mesh *s)
{
    if (!s) return "mesh is NULL";
    if (!live(s)) return "not a live vpds_mesh (destroyed or never created)";
    return s->store.err;
}

/* The context of a call of the algorithms: the mesh, its subsystems and the problem. */
static vpdsi_surface_ctx mesh_context(vpds_mesh *s)
{
    vpdsi_surface_ctx c;
    c.mesh = &s->view;
    c.st = &s->store;
    c.marks = &s->marks;
    c.rng = &s->rng;
    c.stats = &s->stats;
    c.rule = s->rule;
    c.coverage = s->coverage;
    c.budget = s->budget;
    c.progress = s->progress;
    c.progress_user = s->progress_user;
    return c;
}

static vpds_status mesh_work(vpds_mesh *s)
{
    vpdsi_surface_ctx c = mesh_context(s);
    size_t before = s->store.n;
    int was_done = s->surface.phase == VPDSI_SURF_DONE;
    vpds_status e;
    s->store.err[0] = 0;
    e = vpdsi_surface_run(&s->surface, &c);
    /* a run after a stream: the stream's best point seen is stale once samples are added */
    if (s->store.n != before) s->stream.best.g = -1;
    if (e == VPDS_OK && !was_done) s->run_t = s->surface.t;
    return e;
}

vpds_status vpds_mesh_run(vpds_mesh *s)
{
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    if (s->surface.phase == VPDSI_SURF_IDLE) vpdsi_surface_begin(&s->surface, 1.0);
    return mesh_work(s);
}

vpds_status vpds_mesh_refine(vpds_mesh *s, double t)
{
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    if (!isfinite(t) || !vpdsi_scale_ok(t * s->coverage)) {
        vpdsi_store_error(&s->store, "t = %g: must be finite, > 0, with t * coverage within [1e-50, 1e50]", t);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if (s->surface.phase != VPDSI_SURF_IDLE && t == s->surface.t) return mesh_work(s);
    if (s->surface.phase != VPDSI_SURF_IDLE && s->surface.phase != VPDSI_SURF_DONE) {
        vpdsi_store_error(&s->store, "refine to t = %g: the run at t = %g is not complete (call it "
                          "again until VPDS_OK first)", t, s->surface.t);
        return VPDS_ERR_STATE;
    }
    if (s->surface.phase == VPDSI_SURF_DONE && !(t < s->surface.t)) {
        vpdsi_store_error(&s->store, "refine to t = %g: must be below the current scale %g", t, s->surface.t);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    vpdsi_surface_begin(&s->surface, t);
    return mesh_work(s);
}

/* The arguments every stream call shares (who calls says in `who`), and the state it starts
 * from: empty, or a completed run. */
static vpds_status mesh_stream_may_start(vpds_mesh *s, const char *who, double t_min)
{
    if (!(t_min >= 0) || t_min == INFINITY) {
        vpdsi_store_error(&s->store, "%s: t_min = %g: must be finite and >= 0", who, t_min);
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if (s->surface.phase != VPDSI_SURF_IDLE && s->surface.phase != VPDSI_SURF_DONE) {
        vpdsi_store_error(&s->store, "%s: the run at scale %g is not finished; a stream starts "
                          "from an empty mesh sampler or a maximal one (call vpds_mesh_run until "
                          "VPDS_OK)", who, s->surface.t);
        return VPDS_ERR_STATE;
    }
    return VPDS_OK;
}

/* One event of the surface stream (after mesh_stream_may_start). */
static vpds_status mesh_stream_event(vpds_mesh *s, double t_min, double *x_out, double *t_out)
{
    vpdsi_surface_ctx c = mesh_context(s);
    vpds_status e;
    s->store.err[0] = 0;
    e = vpdsi_surface_next(&s->stream, &c, t_min, s->run_t, x_out, t_out);
    /* the samples are maximal at t (Section 4.2): a later refine goes below it */
    if (e == VPDS_OK) vpdsi_surface_done_at(&s->surface, &s->mem, *t_out);
    return e;
}

vpds_status vpds_mesh_next(vpds_mesh *s, double t_min, double *x_out, double *t_out)
{
    vpds_status e;
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    if (!x_out || !t_out) {
        vpdsi_store_error(&s->store, "vpds_mesh_next: x_out and t_out must not be NULL");
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if ((e = mesh_stream_may_start(s, "vpds_mesh_next", t_min)) != VPDS_OK) return e;
    return mesh_stream_event(s, t_min, x_out, t_out);
}

vpds_status vpds_mesh_next_n(vpds_mesh *s, size_t n, double t_min, double *x_out, double *t_out,
                             size_t *count)
{
    vpds_status e;
    double x[3], t;
    if (count) *count = 0;
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    if (!count) {
        vpdsi_store_error(&s->store, "vpds_mesh_next_n: count must not be NULL (it says how many "
                          "events were written)");
        return VPDS_ERR_INVALID_ARGUMENT;
    }
    if ((e = mesh_stream_may_start(s, "vpds_mesh_next_n", t_min)) != VPDS_OK) return e;
    for (; *count < n; (*count)++) {
        if ((e = mesh_stream_event(s, t_min, x, &t)) != VPDS_OK) return e;
        if (x_out) memcpy(x_out + 3 * *count, x, sizeof x);
        if (t_out) t_out[*count] = t;
    }
    return VPDS_OK;
}

vpds_status vpds_mesh_set_budget(vpds_mesh *s, uint64_t budget)
{
    if (!live(s)) return VPDS_ERR_INVALID_ARGUMENT;
    s->budget = budget;
    return VPDS_OK;
}

size_t vpds_mesh_count(const vpds_mesh *s) { return live(s) ? s->store.n : 0; }
const double *vpds_mesh_points(const vpds_mesh *s) { return live(s) ? s->store.x : NULL; }
const double *vpds_mesh_radii(const vpds_mesh *s) { return live(s) ? s->store.r : NULL; }
const double *vpds_mesh_scales(const vpds_mesh *s) { return live(s) ? s->store.t : NULL; }
const uint32_t *vpds_mesh_faces(const vpds_mesh *s) { return live(s) ? s->marks.face : NULL; }
const double *vpds_mesh_barycentrics(const vpds_mesh *s) { return live(s) ? s->marks.bary : NULL; }

vpds_stats vpds_mesh_get_stats(const vpds_mesh *s)
{
    vpds_stats st;
    if (!live(s)) {
        memset(&st, 0, sizeof st);
        return st;
    }
    st = s->stats;
    st.bytes_held = s->mem.held;
    st.peak_bytes = s->mem.peak;
    st.sizing_calls = s->store.sizing.calls;
    st.t = s->surface.t; /* a stream's event leaves the surface maximal at its t */
    st.maximal = s->surface.phase == VPDSI_SURF_DONE;
    return st;
}
