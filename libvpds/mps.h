/* Algorithm 1 (Section 3.1): darts into active cells, a coverage sweep per level. Owns its
 * cells, its scratch and, with two radii, the uncovered-cell index. */
#ifndef VPDS_MPS_H
#define VPDS_MPS_H
#include "cells.h"
#include "context.h"
#include "uncovered.h"

typedef enum {
    VPDSI_IDLE,   /* nothing set up at the current scale */
    VPDSI_FILTER, /* dropping base cells covered by samples that existed before the run */
    VPDSI_DARTS,  /* throwing the darts of the current level */
    VPDSI_SWEEP,  /* coverage sweep: splitting active cells, keeping uncovered children */
    VPDSI_VFILTER, /* two radii: dropping the new cells whose R_c-neighbourhood is covered */
    VPDSI_DONE    /* maximal at the current scale */
} vpdsi_phase;

/* Algorithm 1's state between chunks of work; a pause or an error leaves it consistent. */
typedef struct vpdsi_run {
    vpdsi_phase phase;
    double t;                      /* scale */
    vpdsi_lattice geom;            /* base cells of the scale and their boxes */
    uint64_t base_count;           /* prod n0 */
    unsigned max_level;            /* precision limit */
    int implicit;                  /* the level-0 cells are all base cells, not stored */
    vpdsi_cells cur, next;
    uint64_t pos;                  /* cells of cur swept so far */
    uint64_t darts_left;           /* darts still to throw at this level */
    uint64_t vpos, wpos;           /* VFILTER: cells of next read, cells kept */
    int vsplit;                    /* VFILTER: bit 0 the sweep split, bit 1 it was FILTER */
} vpdsi_run;

/* Samples near a box of the lattice, kept while the cells in it are swept (mps.c). */
typedef struct vpdsi_near_list {
    int32_t *idx; size_t n, cap;
    uint64_t key;                           /* which box; 0: none */
    size_t store_n;                         /* the store's count when searched */
    double r_bound;                         /* it holds for cells of r <= r_bound */
} vpdsi_near_list;

typedef struct vpdsi_mps {
    vpdsi_run run;
    int32_t *cand; size_t n_cand, cap_cand; /* the samples near the cell being swept */
    int32_t holder;                         /* octave grid: the sample that held the last
                                               cell dropped, or -1 */
    double *cand_x; size_t cap_cand_x;      /* background grid: their coordinates, d apart */
    uint16_t *cand_tag; size_t cap_cand_tag; /* ... and their places (vpdsi_bgrid_slide) */
    double *buf_x; size_t cap_buf_x;        /* a chunk's darts or cell centres */
    double *buf_r; size_t cap_buf_r;        /* r there */
    double *buf_u; size_t cap_buf_u;        /* weighted mode: the acceptance draw of each dart */
    uint64_t *buf_at; size_t cap_buf_at;    /* background grid: each dart's cell, located once
                                               for its two prefetches and its test */
    vpdsi_uncovered unc;                    /* two radii */
    vpdsi_near_list strip, base;            /* the samples near the cells being swept (the
                                               background grid: base's key and store_n name
                                               the base cell cand holds) */
    vpdsi_near_list group;                  /* octave grid: the samples near the ancestor
                                               group_c at group_level - GROUP_UP of the cells
                                               being swept (mps.c group_list) */
    uint64_t group_c[3];
    unsigned group_level;
} vpdsi_mps;

/* What one call may spend and whom it tells. */
typedef struct vpdsi_work {
    uint64_t budget;              /* work units before VPDS_PAUSED; 0: no limit */
    vpds_progress_fn progress;
    void *user;
    int keep_tree;                /* a stream is under way: the kd-tree stays the index */
} vpdsi_work;

void vpdsi_mps_init(vpdsi_mps *m, int dim, const double *period);
/* Forget the run: the next vpdsi_mps_run starts at scale t. */
void vpdsi_mps_reset(vpdsi_mps *m, double t);
/* Done at this scale: free the cells and the background grid (rebuilt on the next run). */
void vpdsi_mps_release_cells(vpdsi_mps *m, vpdsi_store *st);
/* Free everything (the sampler's end). */
void vpdsi_mps_release(vpdsi_mps *m, vpdsi_store *st);
vpds_status vpdsi_mps_run(vpdsi_mps *m, const vpdsi_ctx *c, const vpdsi_work *w);
#endif
