/* Built-in domain: a 2D polygon set with holes. The signed distance is exact: the distance to
 * the nearest edge, negative when a ray crosses the rings an odd number of times. Validation
 * finds crossing edges by a sweep over edges sorted by their lowest x. */
#include "mem.h"
#include "refuse.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define VPDSI_POLYGON_COOKIE 0x56505047u /* 'VPPG' */

struct vpds_polygon {
    uint32_t magic;
    size_t n_edges;
    double *ax; /* edge e runs from (ax, ay)[e] to (bx, by)[e] */
    double *ay;
    double *bx;
    double *by;
    vpdsi_mem mem;
};

vpds_polygon_desc vpds_default_polygon_desc(void)
{
    vpds_polygon_desc d;
    memset(&d, 0, sizeof d);
    d.cookie = VPDSI_POLYGON_COOKIE;
    d.struct_size = (uint32_t)sizeof d;
    return d;
}


typedef struct {
    double xmin, xmax, ymin, ymax;
    size_t ring, edge; /* edge index within its ring */
    size_t a, b;       /* vertex indices into xy */
} poly_edge;

/* A ring whose area is below this fraction of its width squared is flat to round-off. */
#define POLYGON_FLAT 1e-12

static int by_xmin(const void *p, const void *q)
{
    double a = ((const poly_edge *)p)->xmin, b = ((const poly_edge *)q)->xmin;
    return a < b ? -1 : a > b;
}

static double orient(const double *p, const double *q, const double *r)
{
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
}

/* r on segment pq, given that the three are collinear */
static int on_segment(const double *p, const double *q, const double *r)
{
    return fmin(p[0], q[0]) <= r[0] && r[0] <= fmax(p[0], q[0]) && fmin(p[1], q[1]) <= r[1] &&
           r[1] <= fmax(p[1], q[1]);
}

static int segments_meet(const double *p1, const double *p2, const double *q1, const double *q2)
{
    double o1 = orient(p1, p2, q1), o2 = orient(p1, p2, q2), o3 = orient(q1, q2, p1),
           o4 = orient(q1, q2, p2);
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
        return 1;
    return (o1 == 0 && on_segment(p1, p2, q1)) || (o2 == 0 && on_segment(p1, p2, q2)) ||
           (o3 == 0 && on_segment(q1, q2, p1)) || (o4 == 0 && on_segment(q1, q2, p2));
}

/* Edges e and f of one ring share a vertex when they are consecutive. */
static int adjacent(const poly_edge *e, const poly_edge *f, const size_t *ring_sizes)
{
    size_t m = ring_sizes[e->ring];
    if (e->ring != f->ring) return 0;
    return (e->edge + 1) % m == f->edge || (f->edge + 1) % m == e->edge;
}

vpds_status vpds_polygon_validate(const vpds_polygon_desc *d, char *msg, size_t cap)
{
    size_t total = 0, i, j, r, at;
    poly_edge *edges;
    vpdsi_mem m;
    if (msg && cap) msg[0] = 0;
    if (!d) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc is NULL");
    if (d->cookie != VPDSI_POLYGON_COOKIE)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "polygon desc: cookie 0x%08x is not from "
             "vpds_default_polygon_desc()", (unsigned)d->cookie);
    if (d->struct_size != sizeof *d)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "polygon desc: struct_size %u, this library reads %u",
             (unsigned)d->struct_size, (unsigned)sizeof *d);
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc: allocator.alloc and allocator.free must both "
             "be set or both NULL");
    if (d->n_rings == 0) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc: n_rings = 0, need a ring");
    if (!d->xy || !d->ring_sizes) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc: xy or ring_sizes is NULL");
    for (r = 0; r < d->n_rings; r++) {
        if (d->ring_sizes[r] < 3)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc: ring_sizes[%zu] = %zu, a ring needs at "
                 "least 3 vertices", r, d->ring_sizes[r]);
        if (total + d->ring_sizes[r] < total || total + d->ring_sizes[r] > ((size_t)-1) / (2 * sizeof(poly_edge)))
            VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "polygon desc: the vertex count overflows at ring %zu", r);
        total += d->ring_sizes[r];
    }
    for (i = 0; i < 2 * total; i++)
        if (!isfinite(d->xy[i]) || fabs(d->xy[i]) > 1e150)
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc: xy[%zu] = %g, vertices must be finite "
                 "(within 1e150)", i, d->xy[i]);
    vpdsi_mem_init(&m, &d->allocator);
    edges = (poly_edge *)vpdsi_mem_alloc(&m, total * sizeof *edges);
    if (!edges) VPDSI_REFUSE(VPDS_ERR_OUT_OF_MEMORY, "polygon desc: out of memory for %zu edges", total);
    for (r = 0, at = 0, i = 0; r < d->n_rings; at += d->ring_sizes[r], r++) {
        for (j = 0; j < d->ring_sizes[r]; j++, i++) {
            poly_edge *e = edges + i;
            const double *a = d->xy + 2 * (at + j), *b = d->xy + 2 * (at + (j + 1) % d->ring_sizes[r]);
            e->a = at + j;
            e->b = at + (j + 1) % d->ring_sizes[r];
            e->ring = r;
            e->edge = j;
            e->xmin = fmin(a[0], b[0]);
            e->xmax = fmax(a[0], b[0]);
            e->ymin = fmin(a[1], b[1]);
            e->ymax = fmax(a[1], b[1]);
            if (a[0] == b[0] && a[1] == b[1]) {
                vpdsi_mem_free(&m, edges, total * sizeof *edges);
                VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc: ring %zu repeats vertex %zu at (%g, %g)"
                     " (a zero-length edge)", r, j, a[0], a[1]);
            }
        }
    }
    qsort(edges, total, sizeof *edges, by_xmin);
    for (i = 0; i < total; i++) {
        for (j = i + 1; j < total && edges[j].xmin <= edges[i].xmax; j++) {
            const poly_edge *e = edges + i, *f = edges + j;
            if (f->ymin > e->ymax || f->ymax < e->ymin || adjacent(e, f, d->ring_sizes)) continue;
            if (segments_meet(d->xy + 2 * e->a, d->xy + 2 * e->b, d->xy + 2 * f->a, d->xy + 2 * f->b)) {
                size_t er = e->ring, ee = e->edge, fr = f->ring, fe = f->edge;
                double x = d->xy[2 * e->a], y = d->xy[2 * e->a + 1];
                vpdsi_mem_free(&m, edges, total * sizeof *edges);
                VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc: edge %zu of ring %zu (from (%g, %g)) "
                     "crosses or touches edge %zu of ring %zu: the polygon intersects itself",
                     ee, er, x, y, fe, fr);
            }
        }
    }
    /* consecutive edges folding back on each other (a spike of zero width) */
    for (r = 0, at = 0; r < d->n_rings; at += d->ring_sizes[r], r++) {
        size_t n = d->ring_sizes[r];
        for (j = 0; j < n; j++) {
            const double *p = d->xy + 2 * (at + j), *q = d->xy + 2 * (at + (j + 1) % n),
                         *s = d->xy + 2 * (at + (j + 2) % n);
            if (orient(p, q, s) == 0 && (q[0] - p[0]) * (s[0] - q[0]) + (q[1] - p[1]) * (s[1] - q[1]) < 0) {
                vpdsi_mem_free(&m, edges, total * sizeof *edges);
                VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc: ring %zu folds back on itself at vertex "
                     "%zu (%g, %g)", r, (j + 1) % n, q[0], q[1]);
            }
        }
    }
    vpdsi_mem_free(&m, edges, total * sizeof *edges);
    /* a ring flat to round-off (a triangle 1e-300 high) passes the tests above, and a run in it
     * splits cells without end waiting for a dart to land inside */
    for (r = 0, at = 0; r < d->n_rings; at += d->ring_sizes[r], r++) {
        size_t n = d->ring_sizes[r];
        const double *o = d->xy + 2 * at;
        double area = 0, wide = 0;
        for (j = 0; j < n; j++) {
            const double *p = d->xy + 2 * (at + j), *q = d->xy + 2 * (at + (j + 1) % n);
            area += (p[0] - o[0]) * (q[1] - o[1]) - (q[0] - o[0]) * (p[1] - o[1]);
            wide = fmax(wide, fmax(fabs(p[0] - o[0]), fabs(p[1] - o[1])));
        }
        if (!(fabs(area) > POLYGON_FLAT * wide * wide))
            VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "polygon desc: ring %zu encloses no area at the precision "
                 "of its coordinates (area %g in a ring %g wide)", r, 0.5 * fabs(area), wide);
    }
    return VPDS_OK;
}

vpds_status vpds_polygon_create(const vpds_polygon_desc *d, vpds_polygon **out)
{
    vpdsi_mem m;
    vpds_polygon *p;
    size_t total = 0, r, j, at, i;
    vpds_status st;
    if (!out) return VPDS_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if ((st = vpds_polygon_validate(d, NULL, 0)) != VPDS_OK) return st;
    for (r = 0; r < d->n_rings; r++) total += d->ring_sizes[r];
    vpdsi_mem_init(&m, &d->allocator);
    p = (vpds_polygon *)vpdsi_mem_alloc(&m, sizeof *p);
    if (!p) return VPDS_ERR_OUT_OF_MEMORY;
    memset(p, 0, sizeof *p);
    p->ax = (double *)vpdsi_mem_alloc(&m, 4 * total * sizeof(double));
    if (!p->ax) {
        vpdsi_mem_free(&m, p, sizeof *p);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    p->ay = p->ax + total;
    p->bx = p->ay + total;
    p->by = p->bx + total;
    for (r = 0, at = 0, i = 0; r < d->n_rings; at += d->ring_sizes[r], r++)
        for (j = 0; j < d->ring_sizes[r]; j++, i++) {
            size_t b = at + (j + 1) % d->ring_sizes[r];
            p->ax[i] = d->xy[2 * (at + j)];
            p->ay[i] = d->xy[2 * (at + j) + 1];
            p->bx[i] = d->xy[2 * b];
            p->by[i] = d->xy[2 * b + 1];
        }
    p->n_edges = total;
    p->magic = VPDSI_POLYGON_COOKIE;
    p->mem = m;
    *out = p;
    return VPDS_OK;
}

void vpds_polygon_destroy(vpds_polygon *p)
{
    vpdsi_mem m;
    if (!p || p->magic != VPDSI_POLYGON_COOKIE) return;
    m = p->mem;
    vpdsi_mem_free(&m, p->ax, 4 * p->n_edges * sizeof(double));
    p->magic = 0;
    vpdsi_mem_free(&m, p, sizeof *p);
}

double vpds_polygon_sdf(const double *x, void *user)
{
    const vpds_polygon *p = (const vpds_polygon *)user;
    double best = INFINITY;
    size_t e;
    int inside = 0;
    if (!p || p->magic != VPDSI_POLYGON_COOKIE || !x) return NAN;
    for (e = 0; e < p->n_edges; e++) {
        double ax = p->ax[e], ay = p->ay[e], bx = p->bx[e], by = p->by[e];
        double ex = bx - ax, ey = by - ay, wx = x[0] - ax, wy = x[1] - ay;
        double u = (wx * ex + wy * ey) / (ex * ex + ey * ey), dx, dy, d2;
        u = u < 0 ? 0 : u > 1 ? 1 : u;
        dx = wx - u * ex;
        dy = wy - u * ey;
        d2 = dx * dx + dy * dy;
        if (d2 < best) best = d2;
        /* even-odd: the horizontal ray to +x crosses this edge (half-open in y) */
        if ((ay > x[1]) != (by > x[1]) && x[0] < ax + (x[1] - ay) / (by - ay) * ex) inside = !inside;
    }
    return inside ? -sqrt(best) : sqrt(best);
}
