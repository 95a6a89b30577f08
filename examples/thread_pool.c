/* thread_pool.c - plugging your own job system into bijparam.

   The library splits its heavy loops (energy and gradient, barrier, step
   bound, the preconditioner solve) into tasks and hands them to
   opt.parallel_for, a function that must call fn(task, i) once for every i
   in [0, count) -- in any order, on any threads -- and return when all
   have returned.  The library combines the tasks' results in a fixed order,
   so the map is bit-identical whatever the number of threads.

   This file brings its own parallel_for: a small persistent pool of POSIX
   threads (workers wait on a condition variable; each call publishes a job
   and the workers and the caller take indices from a shared counter under
   a mutex).  It parameterizes a mesh serially and with the pool and checks
   that the two maps are equal bit for bit (memcmp), and prints both times
   (on a mesh of a few thousand triangles the synchronization per call
   costs about what the threads save; the gain grows with the mesh).
   (The header also has its own pool: define BP_USE_PTHREADS and set
   opt.threads, or keep one across calls with bp_pool_create and
   opt.parallel_for = bp_pool_for; this example shows the hook you would
   use for TBB, OpenMP, a game engine's job system...)  Build with -pthread.

       build/examples/thread_pool [mesh] [threads] */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#define BP_IMPLEMENTATION
#include "bijparam.h"

typedef struct pool {
    pthread_mutex_t lock;
    pthread_cond_t work, done;
    pthread_t *threads;
    int nthreads, quit;
    unsigned long generation;        /* bumped by every job              */
    bp_task_fn fn;                   /* the current job                  */
    void *task;
    uint32_t count, next, finished;
} pool;

/* Take indices until none are left; returns when the job is exhausted. */
static void pool_drain(pool *p)
{
    for (;;) {
        uint32_t i;
        pthread_mutex_lock(&p->lock);
        if (p->next >= p->count) { pthread_mutex_unlock(&p->lock); return; }
        i = p->next++;
        pthread_mutex_unlock(&p->lock);
        p->fn(p->task, i);
        pthread_mutex_lock(&p->lock);
        if (++p->finished == p->count) pthread_cond_broadcast(&p->done);
        pthread_mutex_unlock(&p->lock);
    }
}

static void *pool_worker(void *arg)
{
    pool *p = (pool *)arg;
    unsigned long seen = 0;
    for (;;) {
        pthread_mutex_lock(&p->lock);
        while (!p->quit && p->generation == seen) pthread_cond_wait(&p->work, &p->lock);
        if (p->quit) { pthread_mutex_unlock(&p->lock); return NULL; }
        seen = p->generation;
        pthread_mutex_unlock(&p->lock);
        pool_drain(p);
    }
}

/* The bp_parallel_for_fn: publish the job, help with it, wait for the end. */
static void pool_parallel_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    pool *p = (pool *)user;
    if (count == 0) return;
    pthread_mutex_lock(&p->lock);
    p->fn = fn; p->task = task; p->count = count; p->next = 0; p->finished = 0;
    p->generation++;
    pthread_cond_broadcast(&p->work);
    pthread_mutex_unlock(&p->lock);
    pool_drain(p);
    pthread_mutex_lock(&p->lock);
    while (p->finished < p->count) pthread_cond_wait(&p->done, &p->lock);
    pthread_mutex_unlock(&p->lock);
}

static int pool_start(pool *p, int n)
{
    int k;
    memset(p, 0, sizeof *p);
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->work, NULL);
    pthread_cond_init(&p->done, NULL);
    p->threads = (pthread_t *)malloc(sizeof(pthread_t) * (size_t)(n > 0 ? n : 1));
    if (!p->threads) return 0;
    for (k = 0; k < n; k++) {
        if (pthread_create(&p->threads[k], NULL, pool_worker, p) != 0) break;
        p->nthreads++;
    }
    return 1;
}

static void pool_stop(pool *p)
{
    int k;
    pthread_mutex_lock(&p->lock);
    p->quit = 1;
    pthread_cond_broadcast(&p->work);
    pthread_mutex_unlock(&p->lock);
    for (k = 0; k < p->nthreads; k++) pthread_join(p->threads[k], NULL);
    free(p->threads);
    pthread_mutex_destroy(&p->lock);
    pthread_cond_destroy(&p->work);
    pthread_cond_destroy(&p->done);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "tests/data/cow_param_withSUV.obj";
    int nthreads = argc > 2 ? atoi(argv[2]) : 4, same = 1;
    bp_mesh mesh;
    bp_atlas serial, parallel;
    bp_error err;
    bp_options opt;
    pool p;
    double t0, t_serial, t_pool;
    uint32_t c;

    if (bp_read_mesh(path, &mesh, NULL, &err) != BP_OK) { fprintf(stderr, "%s: %s\n", path, err.message); return 1; }
    memset(&opt, 0, sizeof opt);                /* no parallel_for: serial loops */
    t0 = now();
    if (bp_parameterize(&serial, &mesh, &opt, &err) != BP_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
    t_serial = now() - t0;

    if (!pool_start(&p, nthreads - 1)) return 1; /* the caller is the last worker */
    opt.parallel_for = pool_parallel_for;
    opt.parallel_user = &p;
    t0 = now();
    if (bp_parameterize(&parallel, &mesh, &opt, &err) != BP_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
    t_pool = now() - t0;
    pool_stop(&p);

    for (c = 0; c < serial.num_charts; c++) {
        const bp_chart *a = &serial.charts[c], *b = &parallel.charts[c];
        if (a->num_vertices != b->num_vertices || a->iterations != b->iterations ||
            memcmp(a->uv, b->uv, 2 * (size_t)a->num_vertices * sizeof(double)) != 0)
            same = 0;
    }
    printf("%s: %u chart(s), energy %.9f\n", path, (unsigned)serial.num_charts, serial.charts[0].energy_end);
    printf("serial %.3f s, %d threads %.3f s: the maps are %s\n", t_serial, p.nthreads + 1, t_pool,
           same ? "bit-identical" : "DIFFERENT");
    bp_atlas_free(&serial);
    bp_atlas_free(&parallel);
    bp_mesh_free(&mesh, NULL);
    return same ? 0 : 1;
}
