/* The tasks of a tiling run on threads or on the caller's executor: one batch of independent
 * tiles (one phase's, or part of one) run side by side, each from its dependencies' samples.
 * tiling_job.c decides which tiles form a batch; this file only runs them. */
#ifndef VPDS_PARALLEL_H
#define VPDS_PARALLEL_H
#include "tiles.h"
#if !defined(_WIN32)
#define VPDSI_THREADS 1
#include <pthread.h>
#endif

/* One tile's own samples (NULL until the tile is done). */
typedef struct {
    double *x, *r;
    size_t n;
} vpdsi_tile_result;

/* The library's lock around an allocator that is not declared thread-safe. */
typedef struct {
#ifdef VPDSI_THREADS
    pthread_mutex_t lock;
#endif
    vpds_allocator inner;
    vpds_allocator wrapped; /* inner, called under lock */
    int live;
} vpdsi_locked_allocator;

/* A batch: its tiles as tasks, the results of every tile, the next task a thread takes. */
typedef struct {
    const vpds_tiling *t;
    const vpds_allocator *alloc; /* the tiles' allocator (NULL: the tiling's) */
    vpdsi_tile_result *res;      /* per tile of the tiling */
    uint8_t *done;               /* per tile: its result is in res */
    const uint64_t *tasks;       /* the batch's tiles */
    uint64_t n_tasks, next;
    uint64_t failed;             /* the first failing task of the batch (UINT64_MAX: none) */
    vpds_status failed_st;
    char failed_msg[512];
#ifdef VPDSI_THREADS
    pthread_mutex_t next_lock; /* guards next and the failure */
#endif
} vpdsi_batch;

/* The descriptor's checks (cookie, layout, threads, a tiling the library can run alone). */
vpds_status vpdsi_check_run_desc(const vpds_tiling *t, const vpds_tiling_run_desc *d, char *msg,
                                 size_t cap);
/* Threads to use: 1 when a callback (sizing, domain, progress) is not declared thread-safe, 0
 * for the executor. */
int vpdsi_run_threads(const vpds_tiling *t, const vpds_tiling_run_desc *d);
/* Wrap the tiling's allocator in a lock when several threads would call one that is not
 * declared thread-safe (*use: the allocator the tiles get, NULL: the tiling's own). */
vpds_status vpdsi_locked_allocator_init(vpdsi_locked_allocator *l, const vpds_tiling *t,
                                        const vpds_tiling_run_desc *d, int threads,
                                        const vpds_allocator **use);
void vpdsi_locked_allocator_destroy(vpdsi_locked_allocator *l);
vpds_status vpdsi_batch_init(vpdsi_batch *b, const vpds_tiling *t);
void vpdsi_batch_destroy(vpdsi_batch *b);
/* Run the batch's tasks on `threads` threads (the calling one among them), or the executor;
 * each task that succeeds sets done[tile], the first that fails (in task order) is noted. */
void vpdsi_batch_run(vpdsi_batch *b, int threads, const vpds_tiling_run_desc *d);
/* Free the results of every tile (their allocator: alloc, NULL for the tiling's). */
void vpdsi_free_results(const vpds_tiling *t, vpdsi_tile_result *res, const vpds_allocator *alloc);
#endif
