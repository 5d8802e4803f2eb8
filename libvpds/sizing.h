/* Evaluation of r(x): constant, grid, per-point callback or batched callback, with every value
 * checked (finite, > 0) so that a bad callback becomes VPDS_ERR_SIZING, never a wrong sample. */
#ifndef VPDS_SIZING_H
#define VPDS_SIZING_H
#include "grid.h"
#include "mem.h"

/* Distances are compared squared; beyond these ranges the squares overflow or underflow and a
 * conflict could be missed: coordinates within 1e150, extents at least 1e-150, radii within
 * [1e-100, 1e100] and scale factors (t * coverage) within [1e-50, 1e50], so that every reach
 * lies in [1e-150, 1e150]. */
#define VPDSI_MAGNITUDE_MIN 1e-150
#define VPDSI_MAGNITUDE_MAX 1e150
#define VPDSI_RADIUS_MIN 1e-100
#define VPDSI_RADIUS_MAX 1e100
#define VPDSI_SCALE_MIN 1e-50
#define VPDSI_SCALE_MAX 1e50
static inline int vpdsi_radius_ok(double r) { return r >= VPDSI_RADIUS_MIN && r <= VPDSI_RADIUS_MAX; }
static inline int vpdsi_scale_ok(double t) { return t >= VPDSI_SCALE_MIN && t <= VPDSI_SCALE_MAX; }

typedef enum { VPDSI_SIZING_CONSTANT, VPDSI_SIZING_GRID, VPDSI_SIZING_CALLBACK } vpdsi_sizing_kind;

typedef struct vpdsi_sizing {
    vpdsi_sizing_kind kind;
    int dim;
    double radius;       /* constant case */
    vpds_grid *grid;     /* owned copy */
    vpds_sizing_fn fn;
    vpds_sizing_batch_fn batch;
    void *user;
    double lipschitz;    /* L in use (0 for a constant) */
    double rmin, rmax;   /* known bounds (rmin 0: unknown) */
    uint64_t calls;
} vpdsi_sizing;

/* L, r_min and r_max that a descriptor's sizing implies (r_min 0, r_max 0: unknown). */
void vpdsi_sizing_bounds(const vpds_desc *d, double *L, double *rmin, double *rmax);
/* The sizing of a descriptor (a grid is cloned through the allocator a). */
vpds_status vpdsi_sizing_from_desc(vpdsi_sizing *s, const vpds_desc *d);
/* Unknown r_max with a callback: estimate it over the box [lo, hi] (see sizing.c); capped:
 * at most 4096 probes in any dimension (algorithm version 7 on), else 3^d from 7 dimensions. */
vpds_status vpdsi_sizing_estimate_rmax(vpdsi_sizing *s, vpdsi_mem *m, const double *lo,
                                       const double *hi, int capped, char *err, size_t cap);
/* r at n points into out. On a bad value returns VPDS_ERR_SIZING and says where in err. */
vpds_status vpdsi_sizing_eval(vpdsi_sizing *s, const double *x, size_t n, double *out, char *err,
                              size_t cap);
/* "x0, x1, ..." with every digit, for error messages. */
void vpdsi_format_point(char *buf, size_t cap, const double *x, int dim);
#endif
