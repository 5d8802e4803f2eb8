/* The continuous stream on a surface (Section 4.2 carried to meshes): each call inserts the
 * point of the surface farthest from the samples in the rule's scaled distance
 * g(y) = min_i |y - x_i| / f(r(x_i), r(y)), found by branch and bound over pieces: a max-heap of
 * pieces keyed by an upper bound of g over each (kept lazily: bounds only fall as samples come),
 * the top one refreshed, then accepted at its centroid when g there is within
 * VPDS_STREAM_TOLERANCE of the bound, else split: in four at its edges' midpoints (algorithm
 * versions 3-6), or in two at the midpoint of its longest edge (7 on), so that a needle's pieces
 * get shorter without getting thinner. From version 7 with a constant radius a piece small beside
 * its nearest sample takes its largest gap exactly from the few samples near it, and the stream
 * inserts exact farthest points (except where a piece that can split no more has more than
 * VPDSI_SURFACE_GAP_MAX_POINTS samples near: its centre at the tolerance, as for other radii).
 * The first sample is uniform by area. */
#ifndef VPDS_SURFACE_STREAM_H
#define VPDS_SURFACE_STREAM_H
#include "pieces.h"
#include "rng.h"

/* A piece of a triangle as its corners' parameters: the midpoints of dyadic parameters are
 * exact, so the four-way split gives the lattice pieces of pieces.h bit for bit. */
typedef struct vpdsi_surface_heap_entry {
    double uv[3][2];         /* the corners' parameters along the triangle's two edges */
    double ub;               /* an upper bound of g over the piece */
    uint32_t tri;            /* the live triangle */
    uint32_t level;          /* splits from the whole triangle */
} vpdsi_surface_heap_entry;

/* The best point seen since the last sample was placed: g there, r, and where. */
typedef struct vpdsi_surface_best {
    double g, r, uv[2], x[3];
    uint32_t tri;
} vpdsi_surface_best;

typedef struct vpdsi_surface_stream {
    int bisect;              /* split in two at the longest edge (version 7 on), else in four */
    int started;             /* the first sample is placed */
    vpdsi_surface_best best; /* kept across calls that fail or end: the samples are the same */
    vpdsi_surface_heap_entry *heap;
    size_t n_heap, cap_heap;
    int32_t *cand;           /* scratch: the samples near a piece */
    size_t n_cand, cap_cand;
} vpdsi_surface_stream;

/* An empty stream for the mesh's algorithm version. */
void vpdsi_surface_stream_init(vpdsi_surface_stream *ss, uint32_t algorithm_version);
void vpdsi_surface_stream_release(vpdsi_surface_stream *ss, vpdsi_mem *m);
/* The next sample into x_out (3 doubles), its scale into *t_out: VPDS_OK, or VPDS_STREAM_END when
 * its scale would be at or below t_min (nothing consumed), or an error (nothing consumed). The
 * store may hold the samples of a run maximal at t_max (+INFINITY: none), which caps the scales;
 * samples added between two calls (a refine) are taken as they are. */
vpds_status vpdsi_surface_next(vpdsi_surface_stream *ss, const vpdsi_surface_ctx *ctx,
                               double t_min, double t_max, double *x_out, double *t_out);
#endif
