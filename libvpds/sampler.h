/* Private state of a vpds_sampler, shared by the public entry points and the MPS driver. */
#ifndef VPDS_SAMPLER_H
#define VPDS_SAMPLER_H
#include "bgrid.h"
#include "cells.h"
#include "domain.h"
#include "kdtree.h"
#include "rng.h"
#include "sizing.h"
#include "stream.h"

#define VPDSI_SAMPLER_MAGIC 0x56505353u /* 'VPSS' */
#define VPDSI_DESC_COOKIE 0x56504431u    /* 'VPD1': layout 1 of vpds_desc */

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
    uint64_t n0[VPDS_MAX_DIM];     /* base cells per axis */
    double side0[VPDS_MAX_DIM];    /* base cell side per axis */
    uint64_t base_count;           /* prod n0 */
    unsigned max_level;            /* precision limit */
    int implicit;                  /* the level-0 cells are all base cells, not stored */
    vpdsi_cells cur, next;
    uint64_t pos;                  /* cells of cur swept so far */
    uint64_t darts_left;           /* darts still to throw at this level */
    uint64_t vpos, wpos;           /* VFILTER: cells of next read, cells kept */
    int vsplit;                    /* VFILTER: bit 0 the sweep split, bit 1 it was FILTER */
} vpdsi_run;

struct vpds_sampler {
    uint32_t magic;
    vpdsi_mem mem;
    int dim;
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    vpds_rule rule;
    double inhibition, coverage;
    int two_radii;                 /* inhibition < coverage (Section 3) */
    unsigned algorithm;            /* desc.algorithm_version, 0 resolved to the current one */
    double period[VPDS_MAX_DIM];   /* box side on a periodic axis, 0 on an open one */
    int any_periodic;
    int weighted;
    vpdsi_sizing sizing;
    vpds_domain_fn domain;         /* NULL: the whole box */
    void *domain_user;
    uint64_t domain_calls;
    vpdsi_rng rng;
    uint64_t budget;
    vpds_progress_fn progress;
    void *progress_user;

    /* samples, insertion order */
    size_t n;
    double *x; size_t cap_x;
    double *r; size_t cap_r;
    double *t; size_t cap_t;
    uint8_t *flags; size_t cap_flags;
    size_t n_fixed;
    vpdsi_kdtree tree;   /* holds samples [0, tree_n); synced before kd-tree queries */
    size_t tree_n;
    vpdsi_bgrid grid;    /* the uniform-radius accelerator, in use when grid_mode */
    int grid_mode;

    vpdsi_run run;
    vpdsi_stream stream;
    vpds_stats stats;

    /* scratch reused between chunks */
    int32_t *cand; size_t n_cand, cap_cand;
    int32_t *cand2; size_t n_cand2, cap_cand2; /* uncovered.c, inside a sweep's cell */
    double *bb_stack; size_t cap_bb_stack;     /* uncovered.c: boxes still to examine */
    /* two radii: the cells of run.next not inside one coverage disk hold every uncovered
     * point; a kd-tree of their centres answers "is U near?" (uncovered.c) */
    uint8_t *next_u; size_t cap_next_u;
    vpdsi_kdtree utree;
    double *ux; size_t cap_ux;
    double *ur; size_t cap_ur;
    uint8_t *uf; size_t cap_uf;
    double u_half;   /* largest half-diagonal of those cells */
    int u_ready;     /* utree describes the current cells */
    double *buf_x; size_t cap_buf_x;
    double *buf_r; size_t cap_buf_r;
    double *buf_u; size_t cap_buf_u; /* weighted mode: the acceptance draw of each dart */
    char err[512];
};

void vpdsi_set_error(vpds_sampler *s, const char *fmt, ...);
/* Replace coordinates outside the box on periodic axes by their image inside. */
void vpdsi_wrap_point(const vpds_sampler *s, double *x);
/* r at a point, wrapped into the box on periodic axes (where the sizing is defined). */
vpds_status vpdsi_radius_at(vpds_sampler *s, const double *p, double *r);
/* Room for `more` samples in every per-sample array and the tree; nothing changes on failure. */
vpds_status vpdsi_reserve_samples(vpds_sampler *s, size_t more);
/* Insert samples [tree_n, n) into the kd-tree (for leaving grid mode). */
vpds_status vpdsi_sync_tree(vpds_sampler *s);
/* Append and index a sample (after vpdsi_reserve_samples). */
void vpdsi_append_sample(vpds_sampler *s, const double *x, double r, double t, uint8_t flags);
vpdsi_kd_samples vpdsi_samples_view(const vpds_sampler *s);

/* mps.c: Algorithm 1 */
/* Box of the cell at `level` with integer coordinates c (the last cell of an axis ends exactly
 * at the box's face); returns the squared diagonal. */
double vpdsi_cell_box(const vpds_sampler *s, unsigned level, const uint64_t *c, double *lo,
                      double *hi);
void vpdsi_mps_reset(vpds_sampler *s, double t);
vpds_status vpdsi_mps_run(vpds_sampler *s);
void vpdsi_mps_release(vpds_sampler *s);
#endif
