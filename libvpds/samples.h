/* What a neighbour index reads of the samples: a view of the store's arrays, and the flags. */
#ifndef VPDS_SAMPLES_H
#define VPDS_SAMPLES_H
#include <stdint.h>

/* Per-sample flags. */
#define VPDSI_SAMPLE_FIXED 1u      /* added by vpds_add_points */
#define VPDSI_SAMPLE_OWN_RADIUS 2u /* its radius was given, not read from the sizing */

/* The samples an index holds (owned by the store, which may move them). */
typedef struct vpdsi_kd_samples {
    const double *x;   /* n * dim */
    const double *r;   /* n */
    const uint8_t *flags;
} vpdsi_kd_samples;
#endif
