/* sparse_bench.c - the Newton system's factorization on a real chart
   (>>sparse, >>newton).

   Build: cc -std=c99 -O2 -I. bench/sparse_bench.c -o build/bench/sparse_bench -lm -pthread
   Usage: build/bench/sparse_bench MESH [repeats [laplacian | meanvalue | numeric]]
   Takes the mesh's largest chart at its start map, assembles projected
   Newton's matrix H (bp__newton_assemble) and reports, for the scalar
   up-looking LDL^T and the supernodal Cholesky: nnz(L), the flop count
   sum_j colcount_j^2, CPU seconds of the analysis, of one numeric
   factorization (median of `repeats`) and of one solve, and the relative
   residual |H x - b| / |b|; for the supernodal factor also its flops by
   dissection phase and a two-thread bound (every task timed alone, the
   tasks of each parallel loop dealt in order to the less loaded of two
   threads), and the same for the solve: one thread's time (median of
   `repeats`) and the dissection phases' two-thread bound.
   One thread, but for the ordering's line: bp__nd_order alone
   on one thread and on a pool of two, wall and CPU, medians of `repeats`.
   With `laplacian` as the third argument:
   the L-BFGS preconditioner's scalar Laplacian instead (bp__laplacian's K,
   from the Tutte start, which is faster to reach on big charts), factored
   by the scalar rows and by the supernodal Cholesky with blocks of 1
   (K.super1): nnz(L), flops, analysis+numeric, numeric alone, the
   conversion to the single-precision rows (bp__factor_single and the solve
   plan) and one bp__precondition (both coordinates), all CPU seconds.
   With `meanvalue`: the start map's mean-value system of the chart
   (>>tutte phases 1-5) solved both ways: the LU by the scalar rows
   (bp__factorize + bp__solve_refined per coordinate, the fallback) and
   phase 6a (the symmetrized Laplacian's supernodal Cholesky and
   BiCGSTAB, bp__tutte_krylov): CPU seconds, iterations, residuals.
   With `numeric`: Newton's matrix factored
   once by the supernodal Cholesky, then refactored `repeats` times on one
   thread (bp__fact_numeric): the median and the least CPU time of one
   refactorization, and a checksum of L (sum of x_i (1 + i mod 7) over the
   stored values), the same for every build that computes the same bits
   (build with -DBP_NO_SIMD for the plain C kernels: the same checksum). */
#define _POSIX_C_SOURCE 199309L     /* clock_gettime */
#define BP_IMPLEMENTATION
#define BP_USE_PTHREADS             /* the ordering on two threads (sec 6.15) */
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

/* A parallel loop run serially, each task timed: acc[0] += the loop's
   time, acc[1] += its time on two threads taking the tasks in order, each
   to the less loaded one. */
static void timed_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    double *acc = (double *)user, load[2] = {0, 0}, t0;
    uint32_t i;
    for (i = 0; i < count; i++) {
        t0 = cpu();
        fn(task, i);
        load[load[1] < load[0]] += cpu() - t0;
    }
    acc[0] += load[0] + load[1];
    acc[1] += load[0] > load[1] ? load[0] : load[1];
}

static double wall(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* The ordering alone (sec 6.15): bp__nd_order of the vertex graph (mode
   1, the supernodal factor's) and of H itself (mode 0, the scalar rows'),
   on one thread (par NULL: the serial loop) and on a pool of two;
   medians of `reps` of wall and CPU seconds, the ratio, the two-thread
   bound of its tasks timed alone, and whether order and tree are the
   same bits. */
static void ordering(const bp_allocator *a, const bp__sparse *H, int reps)
{
    bp__sparse G;
    bp__pool *P = bp__pool_start(a, 2);
    int mode, r;
    if (bp__super_graph(a, H, &G) != 1 || !P) { fprintf(stderr, "ordering: no graph or no pool\n"); return; }
    for (mode = 1; mode >= 0; mode--) {
        const bp__sparse *M = mode ? &G : H;
        uint32_t *o1 = (uint32_t *)malloc(M->n * sizeof(uint32_t)), *o2 = (uint32_t *)malloc(M->n * sizeof(uint32_t));
        bp__ndnode t1[BP__ND_NODES], t2[BP__ND_NODES];
        double w[2][64], c[2][64], acc[2] = {0, 0}, t0, c0;
        bp__par two = bp__par_serial(), tp = bp__par_serial();
        int same = 1, th;
        two.run = bp__pool_for; two.user = P; two.threads = 2;
        for (r = 0; r < reps; r++)
            for (th = 0; th < 2; th++) {
                t0 = wall(); c0 = cpu();
                bp__nd_order(a, M, th ? o2 : o1, th ? t2 : t1, mode, th ? &two : NULL);
                w[th][r] = wall() - t0; c[th][r] = cpu() - c0;
                if (th) same &= !memcmp(o1, o2, M->n * sizeof(uint32_t)) && !memcmp(t1, t2, sizeof t1);
            }
        tp.run = timed_for; tp.user = acc; tp.threads = 2;
        t0 = cpu();
        bp__nd_order(a, M, o2, t2, mode, &tp);
        t0 = cpu() - t0;
        for (th = 0; th < 2; th++) { qsort(w[th], reps, sizeof(double), cmpd); qsort(c[th], reps, sizeof(double), cmpd); }
        printf("ordering mode %d (n = %u): 1 thread wall %.4f s cpu %.4f s; 2 threads wall %.4f s cpu %.4f s; "
               "wall ratio %.2fx; by tasks %.4f s + serial %.4f s, on two threads at best %.2fx; same bits %s\n",
               mode, M->n, w[0][reps / 2], c[0][reps / 2], w[1][reps / 2], c[1][reps / 2], w[0][reps / 2] / w[1][reps / 2],
               acc[0], t0 - acc[0], t0 / (t0 - acc[0] + acc[1]), same ? "yes" : "NO");
        free(o1); free(o2);
    }
    bp__pool_stop(a, P);
    bp__sparse_free(a, &G);
}

static double residual(const bp__sparse *A, const double *x, const double *b)
{
    uint32_t j, p, n = A->n;
    double *r = (double *)malloc(n * sizeof(double)), rr = 0, bb = 0;
    for (j = 0; j < n; j++) r[j] = b[j];
    for (j = 0; j < n; j++)
        for (p = A->colp[j]; p < A->colp[j + 1]; p++) r[A->row[p]] -= A->val[p] * x[j];
    for (j = 0; j < n; j++) { rr += r[j] * r[j]; bb += b[j] * b[j]; }
    free(r);
    return sqrt(rr / bb);
}

/* The mean-value section (see the top). */
static int meanvalue(const bp_allocator *a, bp_chart *ch, const bp_mesh *mesh)
{
    bp__tutte T;
    bp__factor F;
    uint32_t n, bad, i;
    double t0, t_lu, t_kr, diff = 0, big = 0, *keep;
    memset(&T, 0, sizeof T);
    if (!bp__tutte_fill(a, &T, ch, mesh) || !bp__tutte_adjacency(a, &T) || !bp__tutte_weights(a, &T, 1) ||
        !bp__tutte_circle(a, &T, ch) || !bp__tutte_system(a, &T, ch, 1)) { fprintf(stderr, "system failed\n"); return 1; }
    n = T.nfree;
    keep = (double *)malloc(2 * sizeof(double) * n);
    printf("mean-value system: %u faces, n = %u, nnz(A) = %u\n", ch->num_triangles, n, T.A.colp[n]);
    t0 = cpu();
    if (bp__tutte_krylov(a, &T, NULL) != 1) { fprintf(stderr, "krylov failed\n"); return 1; }
    t_kr = cpu() - t0;
    memcpy(keep, T.sol, 2 * sizeof(double) * n);
    printf("krylov: %.3f s, %d iterations, relative residual %.2g\n", t_kr, T.krylov_iters, T.krylov_rel);
    t0 = cpu();
    if (bp__factorize(a, &T.A, &F, &bad, NULL) != BP_OK) { fprintf(stderr, "LU failed\n"); return 1; }
    printf("LU: factor %.3f s, nnz(L) %u\n", cpu() - t0, F.Rp[n]);
    bp__solve_refined(&T.A, &F, T.rhs, T.sol, T.work);
    bp__solve_refined(&T.A, &F, T.rhs + n, T.sol + n, T.work);
    t_lu = cpu() - t0;
    for (i = 0; i < 2 * n; i++) {
        if (fabs(T.sol[i] - keep[i]) > diff) diff = fabs(T.sol[i] - keep[i]);
        if (fabs(T.sol[i]) > big) big = fabs(T.sol[i]);
    }
    printf("LU + refined solves: %.3f s; max |x_LU - x_krylov| %.2g of %.2g; LU / krylov %.2fx\n", t_lu, diff, big, t_lu / t_kr);
    bp__factor_free(a, &F);
    bp__tutte_free(a, &T);
    free(keep);
    return 0;
}

/* The Laplacian section (see the top). */
static int laplacian(const bp_allocator *a, bp__solver *S, const bp_chart *ch, const bp_mesh *mesh, const bp_options *opt,
                     int reps)
{
    double *rw = (double *)malloc(3 * sizeof(double) * ch->num_triangles), *q, *r, *z, t0, t[64];
    uint32_t n, i, k, bad;
    int sup, rr;
    bp__sparse K;
    bp__factor F;
    bp_error err;
    bp__solver_free(S);
    if (bp__solver_chart(S, a, ch, mesh, opt, rw, &err) != BP_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
    memset(&K, 0, sizeof K);
    memset(&F, 0, sizeof F);
    if (bp__laplacian(a, S, rw, NULL, &K, &F, NULL, NULL) != BP_OK) { fprintf(stderr, "laplacian failed\n"); return 1; }
    bp__factor_free(a, &F);
    n = K.n;
    q = (double *)malloc(2 * sizeof(double) * n);
    r = (double *)malloc(2 * sizeof(double) * n);
    z = (double *)malloc(4 * sizeof(double) * n);
    for (i = 0; i < 2 * n; i++) q[i] = sin(1.0 + i);
    printf("Laplacian: %u faces, n = %u, nnz(K) = %u\n", ch->num_triangles, n, K.colp[n]);
    for (sup = 0; sup < 2; sup++) {
        bp__par ser = bp__par_serial();
        double flops = 0, nnzl = 0, t_an, t_single, res = 0, qq = 0;
        uint32_t *cc = (uint32_t *)calloc(n, sizeof(uint32_t)), j, p;
        K.super1 = sup;
        t0 = cpu();
        if (bp__factorize(a, &K, &F, &bad, NULL) != BP_OK || (sup && !F.sn)) { fprintf(stderr, "factorize failed\n"); return 1; }
        t_an = cpu() - t0;
        if (sup) {
            const bp__super *SS = F.sn;
            uint32_t s;
            for (s = 0; s < SS->ns; s++) {
                double c = SS->first[s + 1] - SS->first[s], m = SS->rp[s + 1] - SS->rp[s];
                for (j = 0; j < c; j++) { nnzl += m - j; flops += (m - j) * (m - j); }
            }
            printf("  supernodes %u (mean %.2f vertices), stored doubles %zu\n", SS->ns, (double)SS->nv / SS->ns, SS->xp[SS->ns]);
        } else {
            for (k = 0; k < F.Rp[n]; k++) cc[F.Ri[k]]++;
            for (j = 0; j < n; j++) flops += (double)(cc[j] + 1) * (cc[j] + 1);
            nnzl = F.Rp[n] + n;
        }
        for (rr = 0; rr < reps; rr++) {
            t0 = cpu();
            bp__fact_numeric(a, &K, &F, NULL, &ser);
            t[rr] = cpu() - t0;
        }
        qsort(t, reps, sizeof(double), cmpd);
        t0 = cpu();
        if (!bp__factor_single(a, &F, NULL) || !bp__solve_plan(a, &F)) { fprintf(stderr, "single failed\n"); return 1; }
        t_single = cpu() - t0;
        t0 = cpu();
        bp__precondition(&F, &ser, q, r, z);
        t0 = cpu() - t0;
        for (i = 0; i < 2 * n; i++) z[i] = -q[i];
        for (j = 0; j < n; j++)
            for (p = K.colp[j]; p < K.colp[j + 1]; p++) {
                z[2 * K.row[p]] += K.val[p] * r[2 * j];
                z[2 * K.row[p] + 1] += K.val[p] * r[2 * j + 1];
            }
        for (i = 0; i < 2 * n; i++) { res += z[i] * z[i]; qq += q[i] * q[i]; }
        printf("%s nnz(L) %10.0f  flops %.4g  analyse+factor %.3f s  numeric %.3f s  to single rows %.3f s  "
               "precondition %.4f s  residual %.2g\n", sup ? "supernodal:" : "scalar:    ", nnzl, flops, t_an, t[reps / 2],
               t_single, t0, sqrt(res / qq));
        bp__factor_free(a, &F);
        free(cc);
    }
    free(q); free(r); free(z); free(rw);
    bp__sparse_free(a, &K);
    return 0;
}

/* `numeric`: refactorizations of H on one thread, their median and least
   CPU time, and the checksum of L. */
static int numeric(const bp_allocator *a, bp__sparse *H, int reps)
{
    bp__factor F;
    bp__par ser = bp__par_serial();
    double t[64], sum = 0;
    uint32_t bad;
    size_t i;
    int r;
    H->blocks2 = 1;
    if (bp__factorize(a, H, &F, &bad, NULL) != BP_OK || !F.sn) { fprintf(stderr, "factorize failed\n"); return 1; }
    for (r = 0; r < reps; r++) {
        double t0 = cpu();
        bp__fact_numeric(a, H, &F, NULL, &ser);
        t[r] = cpu() - t0;
    }
    for (i = 0; i < F.sn->xp[F.sn->ns]; i++) sum += F.sn->x[i] * (double)(1 + i % 7);
    qsort(t, (size_t)reps, sizeof t[0], cmpd);
    printf("numeric factorization (n = %u): median %.4f s, least %.4f s (%d runs, CPU); checksum of L %.17g; "
           "AVX kernels %s\n", H->n, t[reps / 2], t[0], reps, sum, BP__AVX && BP__HAVE_AVX() ? "on" : "off");
    bp__factor_free(a, &F);
    return 0;
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
    uint32_t c, best = 0, n, j, bad, k;
    int reps = argc > 2 ? atoi(argv[2]) : 3, r;
    double t0, t_an, t[64], *b, *x, *z, flops = 0;
    if (argc < 2) { fprintf(stderr, "usage: %s MESH [repeats]\n", argv[0]); return 2; }
    if (reps > 64) reps = 64;
    memset(&opt, 0, sizeof opt);
    memset(&a, 0, sizeof a);
    if (bp_read_mesh(argv[1], &mesh, NULL, &err) != BP_OK || bp_atlas_build(&atlas, &mesh, &opt, &err) != BP_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    for (c = 1; c < atlas.num_charts; c++)
        if (atlas.charts[c].num_triangles > atlas.charts[best].num_triangles) best = c;
    if (argc > 3 && (!strcmp(argv[3], "laplacian") || !strcmp(argv[3], "meanvalue"))) opt.init = BP_INIT_TUTTE;
    if (bp_chart_init(&atlas.charts[best], &mesh, &opt, &err) != BP_OK ||
        bp__solver_chart(&S, &a, &atlas.charts[best], &mesh, &opt, NULL, &err) != BP_OK ||
        bp__newton_init(&N, &a, &S) != BP_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    if (argc > 3 && !strcmp(argv[3], "meanvalue")) return meanvalue(&a, &atlas.charts[best], &mesh);
    if (argc > 3 && !strcmp(argv[3], "laplacian")) return laplacian(&a, &S, &atlas.charts[best], &mesh, &opt, reps);
    bp__newton_assemble(&N, &S, atlas.charts[best].uv);
    if (argc > 3 && !strcmp(argv[3], "numeric")) return numeric(&a, &N.H, reps);
    n = N.H.n;
    b = (double *)malloc(n * sizeof(double));
    x = (double *)malloc(n * sizeof(double));
    z = (double *)malloc(n * sizeof(double));
    for (j = 0; j < n; j++) b[j] = sin(1.0 + j);
    printf("%s: chart of %u faces, %u vertices, n = %u, nnz(A) = %u\n", argv[1], atlas.charts[best].num_triangles, S.nv, n,
           N.H.colp[n]);
    ordering(&a, &N.H, reps);
    for (int sup = 0; sup < 2; sup++) {   /* scalar, supernodal */
        bp__factor F;
        uint32_t *cc = (uint32_t *)calloc(n, sizeof(uint32_t));
        bp__par ser = bp__par_serial();
        double nnzl = 0;
        N.H.blocks2 = sup;
        flops = 0;
        t0 = cpu();
        if (bp__factorize(&a, &N.H, &F, &bad, NULL) != BP_OK) { fprintf(stderr, "factorize failed\n"); return 1; }
        t_an = cpu() - t0;
        if (!sup) {
            for (k = 0; k < F.Rp[n]; k++) cc[F.Ri[k]]++;
            for (j = 0; j < n; j++) flops += (double)(cc[j] + 1) * (cc[j] + 1);
            nnzl = F.Rp[n] + n;
        } else {
            const bp__super *S = F.sn;
            uint32_t s;
            for (s = 0; s < S->ns; s++) {
                double c = 2.0 * (S->first[s + 1] - S->first[s]), m = 2.0 * (S->rp[s + 1] - S->rp[s]);
                for (j = 0; j < c; j++) { nnzl += m - j; flops += (m - j) * (m - j); }
            }
            {
                double fl[BP__ND_DEPTH + 2] = {0};
                int ph;
                for (ph = 0; ph <= BP__ND_DEPTH; ph++) {
                    uint32_t nodes[BP__ND_NODES], cn = bp__nd_phase(&F, ph, nodes), q, s2;
                    for (q = 0; q < cn; q++) {
                        const bp__ndnode *Nd = &F.tree[nodes[q]];
                        uint32_t v0 = ph ? Nd->b : Nd->lo;
                        if (v0 >= Nd->hi) continue;
                        if (ph) printf("  phase %d node %u: separator %u vertices of %u\n", ph, nodes[q], Nd->hi - Nd->b, Nd->hi - Nd->lo);
                        for (s2 = S->snode[v0]; s2 <= S->snode[Nd->hi - 1]; s2++) {
                            double c = 2.0 * (S->first[s2 + 1] - S->first[s2]), m = 2.0 * (S->rp[s2 + 1] - S->rp[s2]);
                            for (j = 0; j < c; j++) fl[ph] += (m - j) * (m - j);
                        }
                    }
                    printf("  phase %d: flops %.3g\n", ph, fl[ph]);
                }
            }
            {   /* every task timed alone: the two-thread bound */
                double acc[2] = {0, 0};
                bp__par tp = bp__par_serial();
                tp.run = timed_for;
                tp.user = acc;
                bp__fact_numeric(&a, &N.H, &F, NULL, &tp);
                printf("  numeric by tasks: %.4f s; on two threads at best %.4f s (%.2fx)\n", acc[0], acc[1], acc[0] / acc[1]);
            }
            {   /* the solve (sec 6.14): one thread's plain scatter, median of
                   reps, and the phases with every task timed alone */
                double acc[2] = {0, 0}, ts[64], tall, *y = (double *)malloc(n * sizeof(double));
                bp__par tp = bp__par_serial();
                for (r = 0; r < reps; r++) {
                    t0 = cpu();
                    bp__factor_solve(&F, b, x, z);
                    ts[r] = cpu() - t0;
                }
                qsort(ts, reps, sizeof(double), cmpd);
                tp.run = timed_for;
                tp.user = acc;
                tp.threads = 2;
                t0 = cpu();
                bp__factor_solve_par(&F, b, y, z, &tp);
                tall = cpu() - t0;
                printf("  solve: one thread %.4f s; phases by tasks %.4f s + serial %.4f s, on two threads at best "
                       "%.4f s (%.2fx); same bits %s\n", ts[reps / 2], acc[0], tall - acc[0], tall - acc[0] + acc[1],
                       ts[reps / 2] / (tall - acc[0] + acc[1]), memcmp(x, y, n * sizeof(double)) ? "NO" : "yes");
                free(y);
            }
            printf("supernodes %u (mean %.2f vertices), row indices %u, stored doubles %zu\n", S->ns, (double)S->nv / S->ns,
                   S->rp[S->ns], S->xp[S->ns]);
        }
        for (r = 0; r < reps; r++) {
            t0 = cpu();
            bp__fact_numeric(&a, &N.H, &F, NULL, &ser);
            t[r] = cpu() - t0;
        }
        qsort(t, reps, sizeof(double), cmpd);
        t0 = cpu();
        bp__factor_solve(&F, b, x, z);
        printf("%s nnz(L) %10.0f  flops %.4g  analyse+factor %.3f s  numeric %.3f s  solve %.4f s  residual %.2g\n",
               sup ? "supernodal:" : "scalar:    ", nnzl, flops, t_an, t[reps / 2], cpu() - t0, residual(&N.H, x, b));
        bp__factor_free(&a, &F);
        free(cc);
    }
    free(b); free(x); free(z);
    bp__newton_free(&a, &N);
    bp__solver_free(&S);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
    return 0;
}
