#define _POSIX_C_SOURCE 199309L
/* bp_atlas_build alone.

     build_bench MESH THREADS RUNS

   Reads MESH once, then builds its charts RUNS times with opt.threads =
   THREADS and prints one line: the median wall and process-CPU
   milliseconds of bp_atlas_build, the charts, and a checksum of the atlas
   (charts, vertex maps, corner maps, repairs), which must not depend on the
   thread count.  Compile it against any bijparam.h (-I DIR) to compare
   versions:
     cc -std=c99 -O2 -I. -DBP_USE_PTHREADS -pthread bench/build_bench.c -o build/build_bench -lm */
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

static uint64_t mix(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = (const unsigned char *)p;
    size_t i;
    for (i = 0; i < n; i++) h = (h ^ c[i]) * 1099511628211ull;
    return h;
}

static uint64_t atlas_hash(const bp_atlas *at)
{
    uint64_t h = 1469598103934665603ull;
    uint32_t c;
    h = mix(h, &at->num_charts, sizeof at->num_charts);
    h = mix(h, at->corner_chart, 4 * (size_t)at->num_corners);
    h = mix(h, at->corner_vertex, 4 * (size_t)at->num_corners);
    h = mix(h, &at->repairs, sizeof at->repairs);
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        h = mix(h, ch->vertex, 4 * (size_t)ch->num_vertices);
        h = mix(h, ch->vertex_uv, 4 * (size_t)ch->num_vertices);
        h = mix(h, ch->triangles, 12 * (size_t)ch->num_triangles);
        h = mix(h, ch->face, 4 * (size_t)ch->num_triangles);
        h = mix(h, ch->loop_start, 4 * ((size_t)ch->num_loops + 1));
        h = mix(h, ch->loop_vertices, 4 * (size_t)ch->loop_start[ch->num_loops]);
        h = mix(h, &ch->area3d, sizeof ch->area3d);
        h = mix(h, &ch->split_vertices, sizeof ch->split_vertices);
        h = mix(h, &ch->cut_edges, sizeof ch->cut_edges);
        h = mix(h, &ch->error.status, sizeof ch->error.status);
        if (ch->rest_side) h = mix(h, ch->rest_side, 8 * (size_t)ch->num_triangles);
    }
    return h;
}

int main(int argc, char **argv)
{
    bp_mesh m;
    bp_options opt;
    bp_atlas at;
    bp_error err;
    int runs = argc > 3 ? atoi(argv[3]) : 9, r;
    double *w, *c;
    uint64_t h = 0;
    bp_status st = BP_OK;
    if (argc < 3) { fprintf(stderr, "usage: build_bench MESH THREADS [RUNS]\n"); return 2; }
    memset(&opt, 0, sizeof opt);
    opt.threads = atoi(argv[2]);
    if (bp_read_mesh(argv[1], &m, NULL, &err) != BP_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
    w = (double *)malloc(sizeof(double) * runs);
    c = (double *)malloc(sizeof(double) * runs);
    for (r = 0; r < runs; r++) {
        double w0 = wall(), c0 = cpu();
        st = bp_atlas_build(&at, &m, &opt, &err);
        w[r] = 1e3 * (wall() - w0);
        c[r] = 1e3 * (cpu() - c0);
        if (st != BP_OK && st != BP_ERR_CHARTS_FAILED) { fprintf(stderr, "%s\n", err.message); return 1; }
        h = atlas_hash(&at);
        bp_atlas_free(&at);
    }
    qsort(w, runs, sizeof *w, cmp_d);
    qsort(c, runs, sizeof *c, cmp_d);
    printf("%s threads %d: build %.2f ms wall, %.2f ms cpu (median of %d; min %.2f) charts-hash %016llx\n",
           argv[1], opt.threads, w[runs / 2], c[runs / 2], runs, w[0], (unsigned long long)h);
    free(w); free(c);
    bp_mesh_free(&m, NULL);
    return 0;
}
