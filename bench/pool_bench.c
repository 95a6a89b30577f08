#define _POSIX_C_SOURCE 199309L
/* A batch in one process: a pool per call against one kept bp_pool
   (make bench-pool; docs/performance.md, "Many small charts, and batches").

     pool_bench OUT_DIR RUNS MESH...

   Each round runs the tool's pipeline -- bp_read_mesh_opt, bp_parameterize,
   bp_write_obj_opt into OUT_DIR -- on every MESH, three ways in an order
   that turns with the round:
     serial  opt.threads = 1
     calls   opt.threads = 2: each call starts its own pool
     kept    one bp_pool of 2 threads, made before the first round,
             handed to every call as opt.parallel_for = bp_pool_for
   and prints per way the median over RUNS rounds of the batch's wall and
   process-CPU milliseconds, and whether every output file is the same
   bytes as the serial one (it must be).  Never asserts times.
     cc -std=c99 -O2 -I. -DBP_USE_PTHREADS -pthread bench/pool_bench.c -o build/pool_bench -lm */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double wall(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static double cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The whole file at path (NULL on failure); *n its length. */
static char *slurp(const char *path, long *n)
{
    FILE *f = fopen(path, "rb");
    char *s = NULL;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (*n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (s = (char *)malloc((size_t)*n + 1)) != NULL && fread(s, 1, (size_t)*n, f) != (size_t)*n) {
        free(s);
        s = NULL;
    }
    fclose(f);
    return s;
}

/* read, parameterize, write one mesh; 0 on any failure. */
static int pipeline(const char *in, const char *out, const bp_options *o)
{
    bp_mesh m;
    bp_atlas at;
    bp_error e;
    bp_status st;
    if (bp_read_mesh_opt(in, &m, o, &e) != BP_OK) { fprintf(stderr, "%s: %s\n", in, e.message); return 0; }
    st = bp_parameterize(&at, &m, o, &e);
    if (st == BP_OK) st = bp_write_obj_opt(out, NULL, &m, &at, o, &e);
    if (st != BP_OK) fprintf(stderr, "%s: %s\n", in, e.message);
    if (st == BP_OK || st == BP_ERR_CHARTS_FAILED || st == BP_ERR_CANCELLED) bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
    return st == BP_OK;
}

int main(int argc, char **argv)
{
    enum { WAYS = 3, MAXRUNS = 64 };
    static const char *name[WAYS] = { "serial", "calls", "kept" };
    double w[WAYS][MAXRUNS], c[WAYS][MAXRUNS];
    int runs, r, k, i, nmesh, same = 1;
    bp_pool *pool;
    bp_error e;
    char path[1024];
    if (argc < 4 || (runs = atoi(argv[2])) < 1 || runs > MAXRUNS) {
        fprintf(stderr, "usage: pool_bench OUT_DIR RUNS(1..%d) MESH...\n", MAXRUNS);
        return 2;
    }
    nmesh = argc - 3;
    if (bp_pool_create(&pool, 2, NULL, &e) != BP_OK) { fprintf(stderr, "%s\n", e.message); return 1; }
    for (r = 0; r < runs; r++)
        for (k = 0; k < WAYS; k++) {
            int way = (k + r) % WAYS;
            bp_options o;
            double w0, c0;
            bp_options_init(&o);
            o.threads = way == 0 ? 1 : 2;
            if (way == 2) { o.parallel_for = bp_pool_for; o.parallel_user = pool; }
            w0 = wall(); c0 = cpu();
            for (i = 0; i < nmesh; i++) {
                snprintf(path, sizeof path, "%s/%d_%s.obj", argv[1], i, name[way]);
                if (!pipeline(argv[3 + i], path, &o)) return 1;
            }
            w[way][r] = 1e3 * (wall() - w0);
            c[way][r] = 1e3 * (cpu() - c0);
        }
    bp_pool_destroy(pool);
    for (i = 0; i < nmesh; i++) {                /* each way's output against the serial one */
        long n0 = 0, n1 = 0;
        char *s0, *s1;
        snprintf(path, sizeof path, "%s/%d_%s.obj", argv[1], i, name[0]);
        s0 = slurp(path, &n0);
        for (k = 1; k < WAYS; k++) {
            snprintf(path, sizeof path, "%s/%d_%s.obj", argv[1], i, name[k]);
            s1 = slurp(path, &n1);
            same = same && s0 && s1 && n0 == n1 && !memcmp(s0, s1, (size_t)n0);
            free(s1);
        }
        free(s0);
    }
    printf("%d meshes, %d rounds (medians, ms per batch)\n", nmesh, runs);
    for (k = 0; k < WAYS; k++) {
        qsort(w[k], (size_t)runs, sizeof(double), cmp_d);
        qsort(c[k], (size_t)runs, sizeof(double), cmp_d);
        printf("%-7s wall %9.1f  cpu %9.1f\n", name[k], w[k][runs / 2], c[k][runs / 2]);
    }
    printf("kept / calls wall %.3f; outputs the same bytes as serial: %s\n", w[2][runs / 2] / w[1][runs / 2],
           same ? "yes" : "NO");
    return same ? 0 : 1;
}
