/* Algorithm 1 on a triangle mesh: active pieces are sub-triangles of the lattice that midpoint
 * subdivision makes (each split gives four similar children of equal area), darts land uniform
 * by area over the active pieces, and a piece is dropped once one sample covers its three
 * corners (a ball is convex). Samples go to the store (3D) with their triangle and barycentric
 * coordinates in the marks beside it. */
#ifndef VPDS_SURFACE_H
#define VPDS_SURFACE_H
#include "piece_array.h"
#include "rng.h"

typedef enum {
    VPDSI_SURF_IDLE, VPDSI_SURF_SEED, VPDSI_SURF_FILTER, VPDSI_SURF_DARTS, VPDSI_SURF_SWEEP,
    VPDSI_SURF_DONE
} vpdsi_surf_phase;

typedef struct vpdsi_surface {
    vpdsi_surf_phase phase;
    double t;                            /* scale being sampled */
    double prev_t;                       /* the scale and phase before vpdsi_surface_begin */
    vpdsi_surf_phase prev_phase;
    int floor_lifted;                    /* only pieces below the area floor were left */
    uint64_t *seed_m;                    /* per live triangle: m, its seed pieces per edge */
    double *tri_cum;                     /* running sums of the live triangles' areas */
    size_t cap_seed_m, cap_tri_cum;
    uint64_t seed_total;                 /* seed pieces in all: sum of m^2 */
    int implicit;                        /* the active pieces are all the seed pieces (level 0,
                                            never stored: darts land uniform on the surface) */
    size_t ctri; uint64_t crow, cpos;    /* implicit sweep: triangle, row, place in the row */
    int32_t *cache; size_t n_cache, cap_cache; /* samples near a box around recent pieces */
    double cache_lo[3], cache_hi[3], cache_r;
    int cache_ok;
    int32_t last_cover;                  /* the sample that held the last covered piece */
    vpdsi_piece_array cur, next;         /* active pieces, and those of the next level */
    uint64_t m_max;                      /* the largest seed_m */
    double *cum;  size_t cap_cum;        /* running sums of the active pieces' areas */
    int cum_ready;                       /* cum holds this level's sums */
    size_t pos;                          /* seed: next live triangle; sweeps: next piece */
    uint64_t ipos;                       /* implicit sweep: seed pieces done */
    uint64_t darts_left;
    int split_any;                       /* the sweep split a piece (else the run ends) */
    int32_t *near; size_t n_near, cap_near;
} vpdsi_surface;

void vpdsi_surface_init(vpdsi_surface *s);
void vpdsi_surface_release(vpdsi_surface *s, vpdsi_mem *m);
/* The samples are maximal at t (a stream's event): a later run at t is done, a refine goes
 * below it; the pieces are released. */
void vpdsi_surface_done_at(vpdsi_surface *s, vpdsi_mem *m, double t);
/* Start sampling at scale t (the store may hold samples of larger scales). */
void vpdsi_surface_begin(vpdsi_surface *s, double t);
/* Work until maximal at s->t (VPDS_OK), paused (VPDS_PAUSED) or failed (the state as a pause). */
vpds_status vpdsi_surface_run(vpdsi_surface *s, const vpdsi_surface_ctx *ctx);
#endif
