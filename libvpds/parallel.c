/* The tasks of a tiling run side by side: a batch of tiles that never interact (tiles.c), each a
 * run from its dependencies' samples, on POSIX threads or on the caller's executor. A tile's
 * points depend on its seed and its dependencies alone, so they are the same bytes for any number
 * of threads, any executor and any order in which tasks finish. */
#include "parallel.h"
#include "refuse.h"
#include <stdio.h>
#include <string.h>

#define VPDSI_TILING_RUN_COOKIE 0x56505452u /* 'VPTR': layout 1 of vpds_tiling_run_desc */
#define MAX_THREADS 256

#ifdef VPDSI_THREADS
static void *locked_alloc(size_t size, void *user)
{
    vpdsi_locked_allocator *l = (vpdsi_locked_allocator *)user;
    void *p;
    pthread_mutex_lock(&l->lock);
    p = l->inner.alloc(size, l->inner.user);
    pthread_mutex_unlock(&l->lock);
    return p;
}
static void *locked_realloc(void *ptr, size_t old_size, size_t new_size, void *user)
{
    vpdsi_locked_allocator *l = (vpdsi_locked_allocator *)user;
    void *p;
    pthread_mutex_lock(&l->lock);
    p = l->inner.realloc(ptr, old_size, new_size, l->inner.user);
    pthread_mutex_unlock(&l->lock);
    return p;
}
static void locked_free(void *ptr, size_t size, void *user)
{
    vpdsi_locked_allocator *l = (vpdsi_locked_allocator *)user;
    pthread_mutex_lock(&l->lock);
    l->inner.free(ptr, size, l->inner.user);
    pthread_mutex_unlock(&l->lock);
}
#endif

vpds_tiling_run_desc vpds_default_tiling_run_desc(void)
{
    vpds_tiling_run_desc d;
    memset(&d, 0, sizeof d);
    d.cookie = VPDSI_TILING_RUN_COOKIE;
    d.struct_size = (uint32_t)sizeof d;
    return d;
}

/* The dependencies' own samples, handed to the tile's run (res of earlier phases). */
static vpds_status tile_deps(const vpdsi_batch *b, uint64_t tile, vpdsi_mem *m, uint64_t **dep,
                             vpds_tile_points **pts, size_t *nd, size_t *cap)
{
    size_t i;
    *cap = vpdsi_tiling_codes(b->t->dim);
    *dep = (uint64_t *)vpdsi_mem_alloc(m, *cap * sizeof **dep);
    *pts = (vpds_tile_points *)vpdsi_mem_alloc(m, *cap * sizeof **pts);
    if (!*dep || !*pts) return VPDS_ERR_OUT_OF_MEMORY;
    *nd = vpdsi_tiling_deps_into(b->t, tile, *dep); /* allocates nothing: no unlocked call */
    for (i = 0; i < *nd; i++) {
        const vpdsi_tile_result *o = &b->res[(*dep)[i]];
        (*pts)[i].tile = (*dep)[i];
        (*pts)[i].x = o->x;
        (*pts)[i].r = o->r;
        (*pts)[i].n = o->n;
    }
    return VPDS_OK;
}

/* Keep the tile's own samples (those after its fixed points). */
static vpds_status keep_own(const vpds_sampler *s, size_t n_fixed, int dim, vpdsi_mem *m,
                            vpdsi_tile_result *out)
{
    size_t n = vpds_count(s) - n_fixed, nx = 0;
    if (vpdsi_mul_size(n ? n : 1, (size_t)dim, &nx) ||
        !(out->x = (double *)vpdsi_mem_alloc(m, nx * sizeof(double))) ||
        !(out->r = (double *)vpdsi_mem_alloc(m, (n ? n : 1) * sizeof(double)))) {
        if (out->x) vpdsi_mem_free(m, out->x, nx * sizeof(double));
        out->x = NULL;
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    memcpy(out->x, vpds_points(s) + n_fixed * (size_t)dim, n * (size_t)dim * sizeof(double));
    memcpy(out->r, vpds_radii(s) + n_fixed, n * sizeof(double));
    out->n = n;
    return VPDS_OK;
}

/* A failing task: the phase keeps the message of the first in task order. */
static void note_failure(vpdsi_batch *b, uint64_t i, vpds_status st, const char *msg)
{
#ifdef VPDSI_THREADS
    pthread_mutex_lock(&b->next_lock);
#endif
    if (i < b->failed) {
        b->failed = i;
        b->failed_st = st;
        snprintf(b->failed_msg, sizeof b->failed_msg, "%s", msg);
    }
#ifdef VPDSI_THREADS
    pthread_mutex_unlock(&b->next_lock);
#endif
}

/* Task i of a phase: run its tile to completion (pauses of the tile's budget resumed). */
static void run_task(void *batch, uint64_t i)
{
    vpdsi_batch *b = (vpdsi_batch *)batch;
    uint64_t tile = b->tasks[i], *dep = NULL;
    vpdsi_tile_result *out = &b->res[tile];
    vpds_tile_points *pts = NULL;
    vpds_sampler *s = NULL;
    vpdsi_mem m;
    size_t nd = 0, cap = 0, n_fixed = 0;
    vpds_status st;
    char msg[512];
    vpdsi_mem_init(&m, b->alloc ? b->alloc : &b->t->mem.a);
    msg[0] = 0;
    if ((st = tile_deps(b, tile, &m, &dep, &pts, &nd, &cap)) != VPDS_OK) {
        snprintf(msg, sizeof msg, "out of memory for its dependencies");
    } else if ((st = vpdsi_tile_create(b->t, tile, pts, nd, NULL, b->alloc, &s, &n_fixed, msg,
                                       sizeof msg)) == VPDS_OK) {
        while ((st = vpds_run(s)) == VPDS_PAUSED) {}
        if (st != VPDS_OK)
            snprintf(msg, sizeof msg, "%s", vpds_last_error(s));
        else if ((st = keep_own(s, n_fixed, b->t->dim, &m, out)) != VPDS_OK)
            snprintf(msg, sizeof msg, "out of memory for its samples");
    }
    if (st != VPDS_OK)
        note_failure(b, i, st, msg);
    else
        b->done[tile] = 1; /* one byte per tile: tasks write apart */
    if (s) vpds_destroy(s);
    if (dep) vpdsi_mem_free(&m, dep, cap * sizeof *dep);
    if (pts) vpdsi_mem_free(&m, pts, cap * sizeof *pts);
}

#ifdef VPDSI_THREADS
/* A worker: take the next task until none is left. */
static void *work(void *batch)
{
    vpdsi_batch *b = (vpdsi_batch *)batch;
    for (;;) {
        uint64_t i;
        pthread_mutex_lock(&b->next_lock);
        i = b->next++;
        pthread_mutex_unlock(&b->next_lock);
        if (i >= b->n_tasks) return NULL;
        run_task(b, i);
    }
}
#endif

void vpdsi_batch_run(vpdsi_batch *b, int threads, const vpds_tiling_run_desc *d)
{
    uint64_t i;
    b->failed = UINT64_MAX;
    if (d->executor && threads == 0) { /* 1: kept serial (threads_for) */
        d->executor(run_task, b, b->n_tasks, d->executor_user);
        return;
    }
#ifdef VPDSI_THREADS
    if (threads > 1 && b->n_tasks > 1) {
        pthread_t id[MAX_THREADS];
        int k, started = 0;
        b->next = 0;
        for (k = 1; k < threads && (uint64_t)k < b->n_tasks; k++)
            if (pthread_create(&id[started], NULL, work, b) == 0) started++;
        work(b); /* a thread that could not start leaves its share to the others */
        for (k = 0; k < started; k++) pthread_join(id[k], NULL);
        return;
    }
#endif
    (void)threads;
    for (i = 0; i < b->n_tasks; i++) run_task(b, i);
}

int vpdsi_run_threads(const vpds_tiling *t, const vpds_tiling_run_desc *d)
{
    const vpds_desc *s = &t->desc;
    int callbacks = s->sizing || s->sizing_batch || s->domain || s->progress;
    if (callbacks && !d->callbacks_thread_safe) return 1;
#ifdef VPDSI_THREADS
    if (d->executor) return 0;
    return d->threads > 1 ? d->threads : 1;
#else
    return 1; /* no POSIX threads here: an executor is not called either */
#endif
}

vpds_status vpdsi_check_run_desc(const vpds_tiling *t, const vpds_tiling_run_desc *d, char *msg,
                                  size_t cap)
{
    if (!t || t->magic != VPDSI_TILING_MAGIC)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling is NULL or not a live vpds_tiling");
    if (d->cookie != VPDSI_TILING_RUN_COOKIE)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "tiling run desc.cookie = 0x%08x: the descriptor did not "
                     "come from vpds_default_tiling_run_desc()", (unsigned)d->cookie);
    if (d->struct_size != sizeof *d)
        VPDSI_REFUSE(VPDS_ERR_BAD_DESCRIPTOR, "tiling run desc.struct_size = %u: a layout this library "
                     "cannot read (it reads %u)", (unsigned)d->struct_size, (unsigned)sizeof *d);
    if (d->threads < 0 || d->threads > MAX_THREADS)
        VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "tiling run desc.threads = %d: must be in 0..%d",
                     d->threads, MAX_THREADS);
    if (t->per_tile)
        VPDSI_REFUSE(VPDS_ERR_UNSUPPORTED, "the tiling has sizing_per_tile: each tile's window of the grid "
                     "comes from the caller (run the tiles with vpds_tile_create)");
    return VPDS_OK;
}

void vpdsi_free_results(const vpds_tiling *t, vpdsi_tile_result *res, const vpds_allocator *alloc)
{
    vpdsi_mem m;
    uint64_t i;
    vpdsi_mem_init(&m, alloc ? alloc : &t->mem.a);
    for (i = 0; i < t->count; i++) {
        size_t n = res[i].n ? res[i].n : 1;
        if (res[i].x) vpdsi_mem_free(&m, res[i].x, n * (size_t)t->dim * sizeof(double));
        if (res[i].r) vpdsi_mem_free(&m, res[i].r, n * sizeof(double));
    }
}

vpds_status vpdsi_locked_allocator_init(vpdsi_locked_allocator *l, const vpds_tiling *t,
                                        const vpds_tiling_run_desc *d, int threads,
                                        const vpds_allocator **use)
{
    memset(l, 0, sizeof *l);
    *use = NULL;
#ifdef VPDSI_THREADS
    if (threads != 1 && t->desc.allocator.alloc && !d->allocator_thread_safe) {
        l->inner = t->mem.a;
        if (pthread_mutex_init(&l->lock, NULL) != 0) return VPDS_ERR_OUT_OF_MEMORY;
        l->live = 1;
        l->wrapped.alloc = locked_alloc;
        l->wrapped.realloc = l->inner.realloc ? locked_realloc : NULL;
        l->wrapped.free = locked_free;
        l->wrapped.user = l;
        *use = &l->wrapped;
    }
#else
    (void)t;
    (void)d;
    (void)threads;
#endif
    return VPDS_OK;
}

void vpdsi_locked_allocator_destroy(vpdsi_locked_allocator *l)
{
#ifdef VPDSI_THREADS
    if (l->live) pthread_mutex_destroy(&l->lock);
#endif
    l->live = 0;
}

vpds_status vpdsi_batch_init(vpdsi_batch *b, const vpds_tiling *t)
{
    memset(b, 0, sizeof *b);
    b->t = t;
    b->failed = UINT64_MAX;
#ifdef VPDSI_THREADS
    if (pthread_mutex_init(&b->next_lock, NULL) != 0) return VPDS_ERR_OUT_OF_MEMORY;
#endif
    return VPDS_OK;
}

void vpdsi_batch_destroy(vpdsi_batch *b)
{
#ifdef VPDSI_THREADS
    pthread_mutex_destroy(&b->next_lock);
#endif
    (void)b;
}
