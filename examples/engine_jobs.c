/* An engine's own job system running a parallel tiled scatter, spread over frames: each frame
 * calls vpds_tiling_job_step for a few tiles, which hands them to the executor as a batch of
 * independent tasks; the engine's workers (here a small pool of POSIX threads that pull task
 * numbers from a shared counter) run them and the executor returns when the batch is done. The
 * points are the same bytes as one vpds_tiling_run on one thread: the program checks it and
 * prints the count and the frames it took.
 *
 *   cc -std=c99 examples/engine_jobs.c -Iinclude build/libvpds.a -lm -pthread -o engine_jobs */
#include <vpds.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#define WORKERS 3

/* The engine's job system: one batch at a time, WORKERS threads pulling task numbers. */
typedef struct {
    pthread_mutex_t lock;
    vpds_task_fn run;
    void *batch;
    uint64_t n, next;
} job_batch;

static void *worker(void *arg)
{
    job_batch *jb = (job_batch *)arg;
    for (;;) {
        uint64_t i;
        pthread_mutex_lock(&jb->lock);
        i = jb->next++;
        pthread_mutex_unlock(&jb->lock);
        if (i >= jb->n) return NULL;
        jb->run(jb->batch, i);
    }
}

static void engine_executor(vpds_task_fn run, void *batch, uint64_t n, void *user)
{
    job_batch jb;
    pthread_t id[WORKERS];
    int k, started = 0;
    (void)user;
    pthread_mutex_init(&jb.lock, NULL);
    jb.run = run;
    jb.batch = batch;
    jb.n = n;
    jb.next = 0;
    for (k = 0; k < WORKERS; k++)
        if (pthread_create(&id[started], NULL, worker, &jb) == 0) started++;
    if (started == 0) worker(&jb); /* no thread could start: run the batch here */
    for (k = 0; k < started; k++) pthread_join(id[k], NULL);
    pthread_mutex_destroy(&jb.lock);
}

static vpds_tiled *scatter(const vpds_tiling *tiling, vpds_executor_fn executor, int threads)
{
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    vpds_tiled *out = NULL;
    char msg[256];
    rd.executor = executor;
    rd.threads = threads;
    if (vpds_tiling_run(tiling, &rd, &out, msg, sizeof msg) != VPDS_OK) {
        fprintf(stderr, "vpds_tiling_run: %s\n", msg);
        return NULL;
    }
    return out;
}

/* The engine's frame loop: TILES_PER_FRAME tiles a frame on its workers, the job kept between
 * frames (a real engine would render in between). */
#define TILES_PER_FRAME 6
static vpds_tiled *scatter_over_frames(const vpds_tiling *tiling, int *frames)
{
    vpds_tiling_run_desc rd = vpds_default_tiling_run_desc();
    vpds_tiling_job *job = NULL;
    vpds_tiled *out = NULL;
    vpds_status st;
    char msg[256];
    rd.executor = engine_executor;
    if (vpds_tiling_job_create(tiling, &rd, &job, msg, sizeof msg) != VPDS_OK) {
        fprintf(stderr, "vpds_tiling_job_create: %s\n", msg);
        return NULL;
    }
    *frames = 0;
    do {
        st = vpds_tiling_job_step(job, TILES_PER_FRAME, msg, sizeof msg);
        ++*frames;
    } while (st == VPDS_PAUSED);
    if (st != VPDS_OK || vpds_tiling_job_result(job, &out, msg, sizeof msg) != VPDS_OK)
        fprintf(stderr, "vpds_tiling_job: %s\n", msg);
    vpds_tiling_job_destroy(job);
    return out;
}

int main(void)
{
    double lo[2] = {0, 0}, hi[2] = {100, 100};
    uint64_t tiles[2] = {8, 8};
    vpds_desc d = vpds_default_desc();
    vpds_tiling_desc td = vpds_default_tiling_desc();
    vpds_tiling *tiling = NULL;
    vpds_tiled *mine, *one, *framed;
    int same, frames = 0;
    d.lo = lo; /* a 100 x 100 terrain, rocks 0.5 apart */
    d.hi = hi;
    d.radius = 0.5;
    d.seed = 2026;
    td.sampler = &d;
    td.tiles = tiles;
    if (vpds_tiling_create(&td, &tiling) != VPDS_OK) return 1;
    mine = scatter(tiling, engine_executor, 0);
    one = scatter(tiling, NULL, 1);
    framed = scatter_over_frames(tiling, &frames);
    same = mine && one && framed && vpds_tiled_count(mine) == vpds_tiled_count(one) &&
           memcmp(vpds_tiled_points(mine), vpds_tiled_points(one),
                  vpds_tiled_count(one) * 2 * sizeof(double)) == 0 &&
           vpds_tiled_count(framed) == vpds_tiled_count(one) &&
           memcmp(vpds_tiled_points(framed), vpds_tiled_points(one),
                  vpds_tiled_count(one) * 2 * sizeof(double)) == 0;
    printf("%zu rocks on %d engine workers, in one call and over %d frames of %d tiles, %s the one-thread bytes\n",
           vpds_tiled_count(mine), WORKERS, frames, TILES_PER_FRAME, same ? "the same as" : "NOT the same as");
    vpds_tiled_destroy(mine);
    vpds_tiled_destroy(framed);
    vpds_tiled_destroy(one);
    vpds_tiling_destroy(tiling);
    return same ? 0 : 1;
}
