/* A whole tiling, phase after phase, the tiles of a phase side by side (parallel.c runs them),
 * in steps of at most a given number of tiles: an engine spreads the run over frames. A tile's
 * points depend on its seed and its dependencies alone, so the steps, the threads and the order
 * in which tasks finish change nothing, and a tile that failed (out of memory, a callback's
 * error) is run again by the next step with the same result. vpds_tiling_run is one job run in
 * one step. */
#include "parallel.h"
#include "refuse.h"
#include <stdio.h>
#include <string.h>

#define VPDSI_TILED_MAGIC 0x56505450u /* 'VPTP' */
#define VPDSI_JOB_MAGIC 0x5650544au   /* 'VPTJ' */

struct vpds_tiled {
    uint32_t magic;
    vpdsi_mem mem;
    int dim, threads;
    size_t count;
    double *x, *r;
    uint64_t *tile;
};

struct vpds_tiling_job {
    uint32_t magic;
    const vpds_tiling *t;
    vpds_tiling_run_desc d;
    vpdsi_mem mem;                /* the tiling's allocator, for the job's own records */
    int threads;
    vpdsi_locked_allocator lock;  /* around the allocator when threads share one */
    vpdsi_batch b;
    int batch_live;
    vpdsi_tile_result *res;       /* per tile */
    uint8_t *done;                /* per tile */
    uint64_t *order;              /* every tile, by phase then index */
    uint64_t *tasks;              /* a step's batch */
    uint64_t *phase_start;        /* 2^dim + 1 offsets into order */
    uint64_t n_done, cursor;      /* tiles done; order[0 .. cursor) are all done */
    int phase;                    /* the phase of order[cursor] */
    size_t res_bytes, order_bytes;
};

static int job_live(const vpds_tiling_job *j) { return j && j->magic == VPDSI_JOB_MAGIC; }

/* The job's records: results, flags, the order by phase and its offsets. */
static vpds_status job_records(vpds_tiling_job *j, char *msg, size_t cap)
{
    const vpds_tiling *t = j->t;
    uint64_t i, placed = 0;
    int phase, phases = 1 << t->dim;
    if ((uint64_t)(size_t)t->count != t->count ||
        vpdsi_mul_size((size_t)t->count, sizeof *j->res, &j->res_bytes) ||
        vpdsi_mul_size((size_t)t->count, sizeof *j->order, &j->order_bytes))
        VPDSI_REFUSE(VPDS_ERR_OVERFLOW, "%llu tiles: their records overflow the address space",
                     (unsigned long long)t->count);
    if ((j->res = (vpdsi_tile_result *)vpdsi_mem_alloc(&j->mem, j->res_bytes)) != NULL)
        memset(j->res, 0, j->res_bytes); /* destroy frees what it holds */
    if (!j->res || !(j->done = (uint8_t *)vpdsi_mem_alloc(&j->mem, (size_t)t->count)) ||
        !(j->order = (uint64_t *)vpdsi_mem_alloc(&j->mem, j->order_bytes)) ||
        !(j->tasks = (uint64_t *)vpdsi_mem_alloc(&j->mem, j->order_bytes)) ||
        !(j->phase_start = (uint64_t *)vpdsi_mem_alloc(&j->mem, ((size_t)phases + 1) * sizeof(uint64_t))))
        VPDSI_REFUSE(VPDS_ERR_OUT_OF_MEMORY, "out of memory for %llu tiles", (unsigned long long)t->count);
    memset(j->done, 0, (size_t)t->count);
    for (phase = 0; phase < phases; phase++) {
        j->phase_start[phase] = placed;
        for (i = 0; i < t->count; i++)
            if (vpds_tiling_phase(t, i) == phase) j->order[placed++] = i;
    }
    j->phase_start[phases] = placed;
    return VPDS_OK;
}

void vpds_tiling_job_destroy(vpds_tiling_job *j)
{
    vpdsi_mem m;
    int phases;
    if (!job_live(j)) return;
    m = j->mem;
    phases = 1 << j->t->dim;
    if (j->res) {
        vpdsi_free_results(j->t, j->res, j->b.alloc);
        vpdsi_mem_free(&m, j->res, j->res_bytes);
    }
    if (j->done) vpdsi_mem_free(&m, j->done, (size_t)j->t->count);
    if (j->order) vpdsi_mem_free(&m, j->order, j->order_bytes);
    if (j->tasks) vpdsi_mem_free(&m, j->tasks, j->order_bytes);
    if (j->phase_start) vpdsi_mem_free(&m, j->phase_start, ((size_t)phases + 1) * sizeof(uint64_t));
    if (j->batch_live) vpdsi_batch_destroy(&j->b);
    vpdsi_locked_allocator_destroy(&j->lock);
    j->magic = 0;
    vpdsi_mem_free(&m, j, sizeof *j);
}

vpds_status vpds_tiling_job_create(const vpds_tiling *t, const vpds_tiling_run_desc *desc,
                                   vpds_tiling_job **out, char *msg, size_t cap)
{
    vpds_tiling_run_desc d = desc ? *desc : vpds_default_tiling_run_desc();
    vpds_tiling_job *j;
    vpdsi_mem m;
    const vpds_allocator *use;
    vpds_status st;
    if (msg && cap) msg[0] = 0;
    if (!out) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if ((st = vpdsi_check_run_desc(t, &d, msg, cap)) != VPDS_OK) return st;
    m = t->mem;
    if (!(j = (vpds_tiling_job *)vpdsi_mem_alloc(&m, sizeof *j)))
        VPDSI_REFUSE(VPDS_ERR_OUT_OF_MEMORY, "out of memory for the job");
    memset(j, 0, sizeof *j);
    j->magic = VPDSI_JOB_MAGIC;
    j->t = t;
    j->d = d;
    j->mem = m;
    j->threads = vpdsi_run_threads(t, &d);
    if (vpdsi_locked_allocator_init(&j->lock, t, &d, j->threads, &use) != VPDS_OK) {
        st = VPDS_ERR_OUT_OF_MEMORY;
        if (msg && cap) snprintf(msg, cap, "could not make the allocator's lock");
    } else if (vpdsi_batch_init(&j->b, t) != VPDS_OK) {
        st = VPDS_ERR_OUT_OF_MEMORY;
        if (msg && cap) snprintf(msg, cap, "could not make the task queue's lock");
    } else {
        j->batch_live = 1;
        j->b.alloc = use;
        st = job_records(j, msg, cap);
    }
    if (st != VPDS_OK) {
        vpds_tiling_job_destroy(j);
        return st;
    }
    j->b.res = j->res;
    j->b.done = j->done;
    *out = j;
    return VPDS_OK;
}

vpds_status vpds_tiling_job_step(vpds_tiling_job *j, uint64_t max_tiles, char *msg, size_t cap)
{
    uint64_t left = max_tiles ? max_tiles : UINT64_MAX;
    if (msg && cap) msg[0] = 0;
    if (!job_live(j)) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "job is NULL or not a live vpds_tiling_job");
    while (left > 0 && j->n_done < j->t->count) {
        uint64_t i, n = 0, k, end;
        /* every tile before the cursor is done; a phase starts once the earlier ones are */
        while (j->done[j->order[j->cursor]]) j->cursor++;
        while (j->cursor >= j->phase_start[j->phase + 1]) j->phase++;
        end = j->phase_start[j->phase + 1];
        for (i = j->cursor; i < end && n < left; i++)
            if (!j->done[j->order[i]]) j->tasks[n++] = j->order[i];
        j->b.tasks = j->tasks;
        j->b.n_tasks = n;
        vpdsi_batch_run(&j->b, j->threads, &j->d);
        for (k = 0; k < n; k++) j->n_done += j->done[j->tasks[k]];
        left -= n;
        if (j->b.failed != UINT64_MAX) /* the tiles that succeeded stay done */
            VPDSI_REFUSE(j->b.failed_st, "tile %llu (phase %d): %s",
                         (unsigned long long)j->tasks[j->b.failed], j->phase, j->b.failed_msg);
        for (k = 0; k < n; k++) /* else the next step would hand it the same tasks forever */
            if (!j->done[j->tasks[k]])
                VPDSI_REFUSE(VPDS_ERR_STATE, "the executor returned without running task %llu of "
                             "%llu (tile %llu, phase %d): it must run run(batch, i) for every i < n",
                             (unsigned long long)k, (unsigned long long)n,
                             (unsigned long long)j->tasks[k], j->phase);
    }
    return j->n_done < j->t->count ? VPDS_PAUSED : VPDS_OK;
}

uint64_t vpds_tiling_job_tiles_done(const vpds_tiling_job *j) { return job_live(j) ? j->n_done : 0; }

/* The tiles' samples in (phase, tile, insertion) order, into one vpds_tiled. */
static vpds_status assemble(const vpds_tiling_job *j, vpds_tiled **out, char *msg, size_t cap)
{
    const vpds_tiling *t = j->t;
    vpdsi_mem m = t->mem;
    vpds_tiled *r;
    size_t total = 0, at = 0, nx = 0, d = (size_t)t->dim, n1;
    uint64_t i;
    for (i = 0; i < t->count; i++) total += j->res[i].n;
    n1 = total ? total : 1;
    if (!(r = (vpds_tiled *)vpdsi_mem_alloc(&m, sizeof *r)))
        VPDSI_REFUSE(VPDS_ERR_OUT_OF_MEMORY, "out of memory for the result");
    memset(r, 0, sizeof *r);
    if (vpdsi_mul_size(n1, d * sizeof(double), &nx) || !(r->x = (double *)vpdsi_mem_alloc(&m, nx)) ||
        !(r->r = (double *)vpdsi_mem_alloc(&m, n1 * sizeof(double))) ||
        !(r->tile = (uint64_t *)vpdsi_mem_alloc(&m, n1 * sizeof(uint64_t)))) {
        if (r->x) vpdsi_mem_free(&m, r->x, nx);
        if (r->r) vpdsi_mem_free(&m, r->r, n1 * sizeof(double));
        vpdsi_mem_free(&m, r, sizeof *r);
        VPDSI_REFUSE(VPDS_ERR_OUT_OF_MEMORY, "out of memory for the %zu samples of the result", total);
    }
    for (i = 0; i < t->count; i++) {
        uint64_t tile = j->order[i];
        const vpdsi_tile_result *o = &j->res[tile];
        size_t k;
        memcpy(r->x + at * d, o->x, o->n * d * sizeof(double));
        memcpy(r->r + at, o->r, o->n * sizeof(double));
        for (k = 0; k < o->n; k++) r->tile[at + k] = tile;
        at += o->n;
    }
    r->mem = m;
    r->dim = t->dim;
    r->threads = j->threads;
    r->count = total;
    r->magic = VPDSI_TILED_MAGIC;
    *out = r;
    return VPDS_OK;
}

vpds_status vpds_tiling_job_result(const vpds_tiling_job *j, vpds_tiled **out, char *msg, size_t cap)
{
    if (msg && cap) msg[0] = 0;
    if (!out) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (!job_live(j)) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "job is NULL or not a live vpds_tiling_job");
    if (j->n_done < j->t->count)
        VPDSI_REFUSE(VPDS_ERR_STATE, "%llu of %llu tiles done: vpds_tiling_job_step until it returns VPDS_OK",
                     (unsigned long long)j->n_done, (unsigned long long)j->t->count);
    return assemble(j, out, msg, cap);
}

vpds_status vpds_tiling_run(const vpds_tiling *t, const vpds_tiling_run_desc *desc, vpds_tiled **out,
                            char *msg, size_t cap)
{
    vpds_tiling_job *j = NULL;
    vpds_status st;
    if (msg && cap) msg[0] = 0;
    if (!out) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if ((st = vpds_tiling_job_create(t, desc, &j, msg, cap)) != VPDS_OK) return st;
    if ((st = vpds_tiling_job_step(j, 0, msg, cap)) == VPDS_OK) st = vpds_tiling_job_result(j, out, msg, cap);
    vpds_tiling_job_destroy(j);
    return st;
}

static int tiled_live(const vpds_tiled *r) { return r && r->magic == VPDSI_TILED_MAGIC; }

void vpds_tiled_destroy(vpds_tiled *r)
{
    vpdsi_mem m;
    size_t n;
    if (!tiled_live(r)) return;
    m = r->mem;
    n = r->count ? r->count : 1;
    vpdsi_mem_free(&m, r->x, n * (size_t)r->dim * sizeof(double));
    vpdsi_mem_free(&m, r->r, n * sizeof(double));
    vpdsi_mem_free(&m, r->tile, n * sizeof(uint64_t));
    r->magic = 0;
    vpdsi_mem_free(&m, r, sizeof *r);
}

size_t vpds_tiled_count(const vpds_tiled *r) { return tiled_live(r) ? r->count : 0; }
int vpds_tiled_dim(const vpds_tiled *r) { return tiled_live(r) ? r->dim : 0; }
const double *vpds_tiled_points(const vpds_tiled *r) { return tiled_live(r) ? r->x : NULL; }
const double *vpds_tiled_radii(const vpds_tiled *r) { return tiled_live(r) ? r->r : NULL; }
const uint64_t *vpds_tiled_tiles(const vpds_tiled *r) { return tiled_live(r) ? r->tile : NULL; }
int vpds_tiled_threads(const vpds_tiled *r) { return tiled_live(r) ? r->threads : 0; }
