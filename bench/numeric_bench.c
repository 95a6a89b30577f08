/* numeric_bench.c - one numeric factorization of Newton's matrix, repeated
   (>>sparse; docs/performance.md 6.28).

   Build: cc -std=c99 -O2 -I. bench/numeric_bench.c -o build/bench/numeric_bench -lm -pthread
          (add -DBP_NO_SIMD for the plain C kernels)
   Usage: build/bench/numeric_bench MESH [repeats]

   Takes the mesh's largest chart at its start map, assembles projected
   Newton's matrix H (bp__newton_assemble), analyses and factors it once
   (bp__factorize, the supernodal Cholesky), then refactors the same
   values `repeats` times (default 9) on one thread (bp__fact_numeric) and
   prints the median and the least CPU time of one refactorization, and a
   checksum of L (sum of x_i (1 + i mod 7) over the stored values) that
   is the same for every build that computes the same bits: with and
   without BP_NO_SIMD, before and after a change that should not move a
   bit.  Never asserts a time. */
#define _POSIX_C_SOURCE 199309L     /* clock_gettime */
#define BP_IMPLEMENTATION
#include "bijparam.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    bp_allocator a;
    bp__solver S;
    bp__newton N;
    bp__factor F;
    bp__par ser = bp__par_serial();
    uint32_t c, best = 0, bad;
    int reps = argc > 2 ? atoi(argv[2]) : 9, r;
    double t[64], sum = 0;
    size_t i;
    if (argc < 2) { fprintf(stderr, "usage: %s MESH [repeats]\n", argv[0]); return 2; }
    if (reps < 1) reps = 1;
    if (reps > 64) reps = 64;
    memset(&opt, 0, sizeof opt);
    memset(&a, 0, sizeof a);
    if (bp_read_mesh(argv[1], &mesh, NULL, &err) != BP_OK || bp_atlas_build(&atlas, &mesh, &opt, &err) != BP_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    for (c = 1; c < atlas.num_charts; c++)
        if (atlas.charts[c].num_triangles > atlas.charts[best].num_triangles) best = c;
    if (bp_chart_init(&atlas.charts[best], &mesh, &opt, &err) != BP_OK ||
        bp__solver_chart(&S, &a, &atlas.charts[best], &mesh, &opt, NULL, &err) != BP_OK ||
        bp__newton_init(&N, &a, &S) != BP_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    bp__newton_assemble(&N, &S, atlas.charts[best].uv);
    N.H.blocks2 = 1;
    if (bp__factorize(&a, &N.H, &F, &bad, NULL) != BP_OK || !F.sn) {
        fprintf(stderr, "the supernodal factorization failed\n");
        return 1;
    }
    for (r = 0; r < reps; r++) {
        double t0 = cpu();
        bp__fact_numeric(&a, &N.H, &F, NULL, &ser);
        t[r] = cpu() - t0;
    }
    for (i = 0; i < F.sn->xp[F.sn->ns]; i++) sum += F.sn->x[i] * (double)(1 + i % 7);
    qsort(t, (size_t)reps, sizeof t[0], cmpd);
    printf("%s: chart of %u faces, n = %u: numeric factorization median %.4f s, least %.4f s (%d runs, CPU); "
           "checksum of L %.17g; AVX kernels %s\n", argv[1], atlas.charts[best].num_triangles, N.H.n, t[reps / 2], t[0],
           reps, sum, BP__AVX && BP__HAVE_AVX() ? "on" : "off");
    bp__factor_free(&a, &F);
    bp__newton_free(&a, &N);
    bp__solver_free(&S);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
    return 0;
}
