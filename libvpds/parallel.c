/* A whole tiling on several threads: phase after phase, the tiles of one phase side by side
 * (they never interact, tiles.c), each tile a run from its dependencies' samples. A tile's
 * points depend on its seed and its dependencies alone, so the result is the same bytes for
 * any number of threads, any executor and any order in which tasks finish. */
#include "tiles.h"
#include "refuse.h"
#include <stdio.h>
#include <string.h>
#if !defined(_WIN32)
#define VPDSI_THREADS 1
#include <pthread.h>
#endif

#define VPDSI_TILED_MAGIC 0x56505450u       /* 'VPTP' */
#define VPDSI_TILING_RUN_COOKIE 0x56505452u /* 'VPTR': layout 1 of vpds_tiling_run_desc */
#define MAX_THREADS 256

struct vpds_tiled {
    uint32_t magic;
    vpdsi_mem mem;
    int dim, threads;
    size_t count;
    double *x, *r;
    uint64_t *tile;
};

/* One tile's own samples. */
typedef struct {
    double *x, *r;
    size_t n;
} tile_result;

/* The library's lock around an allocator that is not declared thread-safe. */
typedef struct {
#ifdef VPDSI_THREADS
    pthread_mutex_t lock;
#endif
    vpds_allocator inner;
} locked_allocator;

/* A phase: its tiles as tasks, the results of every tile, the next task a thread takes. */
typedef struct {
    const vpds_tiling *t;
    const vpds_allocator *alloc; /* the tiles' allocator (NULL: the tiling's) */
    tile_result *res;
    const uint64_t *tasks;
    uint64_t n_tasks, next;
    uint64_t failed;      /* the first failing task of the phase (UINT64_MAX: none) */
    vpds_status failed_st;
    char failed_msg[512];
#ifdef VPDSI_THREADS
    pthread_mutex_t next_lock; /* guards next and the failure */
#endif
} phase_batch;

#ifdef VPDSI_THREADS
static void *locked_alloc(size_t size, void *user)
{
    locked_allocator *l = (locked_allocator *)user;
    void *p;
    pthread_mutex_lock(&l->lock);
    p = l->inner.alloc(size, l->inner.user);
    pthread_mutex_unlock(&l->lock);
    return p;
}
static void *locked_realloc(void *ptr, size_t old_size, size_t new_size, void *user)
{
    locked_allocator *l = (locked_allocator *)user;
    void *p;
    pthread_mutex_lock(&l->lock);
    p = l->inner.realloc(ptr, old_size, new_size, l->inner.user);
    pthread_mutex_unlock(&l->lock);
    return p;
}
static void locked_free(void *ptr, size_t size, void *user)
{
    locked_allocator *l = (locked_allocator *)user;
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
static vpds_status tile_deps(const phase_batch *b, uint64_t tile, vpdsi_mem *m, uint64_t **dep,
                             vpds_tile_points **pts, size_t *nd, size_t *cap)
{
    size_t i;
    *cap = vpdsi_tiling_codes(b->t->dim);
    *dep = (uint64_t *)vpdsi_mem_alloc(m, *cap * sizeof **dep);
    *pts = (vpds_tile_points *)vpdsi_mem_alloc(m, *cap * sizeof **pts);
    if (!*dep || !*pts) return VPDS_ERR_OUT_OF_MEMORY;
    *nd = vpdsi_tiling_deps_into(b->t, tile, *dep); /* allocates nothing: no unlocked call */
    for (i = 0; i < *nd; i++) {
        const tile_result *o = &b->res[(*dep)[i]];
        (*pts)[i].tile = (*dep)[i];
        (*pts)[i].x = o->x;
        (*pts)[i].r = o->r;
        (*pts)[i].n = o->n;
    }
    return VPDS_OK;
}

/* Keep the tile's own samples (those after its fixed points). */
static vpds_status keep_own(const vpds_sampler *s, size_t n_fixed, int dim, vpdsi_mem *m,
                            tile_result *out)
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
static void note_failure(phase_batch *b, uint64_t i, vpds_status st, const char *msg)
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
    phase_batch *b = (phase_batch *)batch;
    uint64_t tile = b->tasks[i], *dep = NULL;
    tile_result *out = &b->res[tile];
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
    if (st != VPDS_OK) note_failure(b, i, st, msg);
    if (s) vpds_destroy(s);
    if (dep) vpdsi_mem_free(&m, dep, cap * sizeof *dep);
    if (pts) vpdsi_mem_free(&m, pts, cap * sizeof *pts);
}

#ifdef VPDSI_THREADS
/* A worker: take the next task until none is left. */
static void *work(void *batch)
{
    phase_batch *b = (phase_batch *)batch;
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

/* Run the phase's tasks on `threads` threads (the calling one among them), or the executor. */
static void dispatch(phase_batch *b, int threads, const vpds_tiling_run_desc *d)
{
    uint64_t i;
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

/* Threads to use: one when a callback (sizing, domain, progress) is not declared thread-safe. */
static int threads_for(const vpds_tiling *t, const vpds_tiling_run_desc *d)
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

static vpds_status check_run_desc(const vpds_tiling *t, const vpds_tiling_run_desc *d, char *msg,
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

static void free_results(const vpds_tiling *t, tile_result *res, const vpds_allocator *alloc)
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

/* The tiles' samples in (phase, tile, insertion) order, into one vpds_tiled. */
static vpds_status assemble(const vpds_tiling *t, const tile_result *res, const uint64_t *order,
                            int threads, vpds_tiled **out, char *msg, size_t cap)
{
    vpdsi_mem m = t->mem;
    vpds_tiled *r;
    size_t total = 0, at = 0, nx = 0, d = (size_t)t->dim;
    uint64_t i;
    for (i = 0; i < t->count; i++) total += res[i].n;
    if (!(r = (vpds_tiled *)vpdsi_mem_alloc(&m, sizeof *r)))
        VPDSI_REFUSE(VPDS_ERR_OUT_OF_MEMORY, "out of memory for the result");
    memset(r, 0, sizeof *r);
    if (vpdsi_mul_size(total ? total : 1, d * sizeof(double), &nx) ||
        !(r->x = (double *)vpdsi_mem_alloc(&m, nx)) ||
        !(r->r = (double *)vpdsi_mem_alloc(&m, (total ? total : 1) * sizeof(double))) ||
        !(r->tile = (uint64_t *)vpdsi_mem_alloc(&m, (total ? total : 1) * sizeof(uint64_t)))) {
        if (r->x) vpdsi_mem_free(&m, r->x, nx);
        if (r->r) vpdsi_mem_free(&m, r->r, (total ? total : 1) * sizeof(double));
        vpdsi_mem_free(&m, r, sizeof *r);
        VPDSI_REFUSE(VPDS_ERR_OUT_OF_MEMORY, "out of memory for the %zu samples of the result", total);
    }
    for (i = 0; i < t->count; i++) {
        const tile_result *o = &res[order[i]];
        size_t j;
        memcpy(r->x + at * d, o->x, o->n * d * sizeof(double));
        memcpy(r->r + at, o->r, o->n * sizeof(double));
        for (j = 0; j < o->n; j++) r->tile[at + j] = order[i];
        at += o->n;
    }
    r->mem = m;
    r->dim = t->dim;
    r->threads = threads;
    r->count = total;
    r->magic = VPDSI_TILED_MAGIC;
    *out = r;
    return VPDS_OK;
}

/* Every phase in turn; on the first failing tile (in phase, tile order) say which and why. */
static vpds_status run_phases(phase_batch *b, uint64_t *order, int threads,
                              const vpds_tiling_run_desc *d, char *msg, size_t cap)
{
    const vpds_tiling *t = b->t;
    uint64_t i, placed = 0;
    int phase, phases = 1 << t->dim;
    for (phase = 0; phase < phases; phase++) {
        uint64_t first = placed;
        for (i = 0; i < t->count; i++)
            if (vpds_tiling_phase(t, i) == phase) order[placed++] = i;
        b->tasks = order + first;
        b->n_tasks = placed - first;
        b->failed = UINT64_MAX;
        if (b->n_tasks == 0) continue;
        dispatch(b, threads, d);
        if (b->failed != UINT64_MAX)
            VPDSI_REFUSE(b->failed_st, "tile %llu (phase %d): %s",
                         (unsigned long long)b->tasks[b->failed], phase, b->failed_msg);
    }
    return VPDS_OK;
}

vpds_status vpds_tiling_run(const vpds_tiling *t, const vpds_tiling_run_desc *desc, vpds_tiled **out,
                            char *msg, size_t cap)
{
    vpds_tiling_run_desc d = desc ? *desc : vpds_default_tiling_run_desc();
    vpdsi_mem m;
    phase_batch b;
    locked_allocator lock;
    vpds_allocator wrapped;
    tile_result *res = NULL;
    uint64_t *order = NULL;
    size_t res_bytes = 0, order_bytes = 0;
    vpds_status st;
    int threads, locked = 0;
    if (msg && cap) msg[0] = 0;
    if (!out) VPDSI_REFUSE(VPDS_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if ((st = check_run_desc(t, &d, msg, cap)) != VPDS_OK) return st;
    threads = threads_for(t, &d);
    memset(&b, 0, sizeof b);
    memset(&wrapped, 0, sizeof wrapped);
    memset(&lock, 0, sizeof lock);
    b.t = t;
#ifdef VPDSI_THREADS
    if (threads != 1 && t->desc.allocator.alloc && !d.allocator_thread_safe) {
        lock.inner = t->mem.a;
        if (pthread_mutex_init(&lock.lock, NULL) != 0)
            VPDSI_REFUSE(VPDS_ERR_OUT_OF_MEMORY, "could not make the allocator's lock");
        locked = 1;
        wrapped.alloc = locked_alloc;
        wrapped.realloc = lock.inner.realloc ? locked_realloc : NULL;
        wrapped.free = locked_free;
        wrapped.user = &lock;
        b.alloc = &wrapped;
    }
    if (pthread_mutex_init(&b.next_lock, NULL) != 0) {
        if (locked) pthread_mutex_destroy(&lock.lock);
        VPDSI_REFUSE(VPDS_ERR_OUT_OF_MEMORY, "could not make the task queue's lock");
    }
#endif
    m = t->mem;
    if ((uint64_t)(size_t)t->count != t->count ||
        vpdsi_mul_size((size_t)t->count, sizeof *res, &res_bytes) ||
        vpdsi_mul_size((size_t)t->count, sizeof *order, &order_bytes)) {
        st = VPDS_ERR_OVERFLOW;
        if (msg && cap) snprintf(msg, cap, "%llu tiles: their records overflow the address space",
                                 (unsigned long long)t->count);
    } else if (!(res = (tile_result *)vpdsi_mem_alloc(&m, res_bytes)) ||
               !(order = (uint64_t *)vpdsi_mem_alloc(&m, order_bytes))) {
        st = VPDS_ERR_OUT_OF_MEMORY;
        if (msg && cap) snprintf(msg, cap, "out of memory for %llu tiles", (unsigned long long)t->count);
    } else {
        memset(res, 0, res_bytes);
        b.res = res;
        if ((st = run_phases(&b, order, threads, &d, msg, cap)) == VPDS_OK)
            st = assemble(t, res, order, threads, out, msg, cap);
    }
    if (b.res) free_results(t, b.res, b.alloc); /* set once res is zeroed */
    if (res) vpdsi_mem_free(&m, res, res_bytes);
    if (order) vpdsi_mem_free(&m, order, order_bytes);
#ifdef VPDSI_THREADS
    pthread_mutex_destroy(&b.next_lock);
    if (locked) pthread_mutex_destroy(&lock.lock);
#endif
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
