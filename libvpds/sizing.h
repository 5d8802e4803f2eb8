/* Evaluation of r(x): constant, grid, per-point callback or batched callback, with every value
 * checked (finite, > 0) so that a bad callback becomes VPDS_ERR_SIZING, never a wrong sample. */
#ifndef VPDS_SIZING_H
#define VPDS_SIZING_H
#include "grid.h"

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

/* r at n points into out. On a bad value returns VPDS_ERR_SIZING and says where in err. */
vpds_status vpdsi_sizing_eval(vpdsi_sizing *s, const double *x, size_t n, double *out, char *err,
                              size_t cap);
/* "x0, x1, ..." with every digit, for error messages. */
void vpdsi_format_point(char *buf, size_t cap, const double *x, int dim);
#endif
