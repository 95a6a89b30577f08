/* test_sparse.c - the supernodal Cholesky factorization of >>sparse.

   Nothing here takes the factorization on trust:

     (a) random symmetric positive definite matrices in 2x2 blocks with
         mesh-like patterns (a triangulated grid of vertices, random 6x6
         positive semidefinite "triangle" blocks R R^T, plus random
         long-range vertex pairs like the barrier's, plus a small shift):
         the ordering is a permutation and its inverse; no entry of the
         matrix joins the two halves of a split of the dissection tree
         (what the parallel phases rely on); every entry of the dense
         Cholesky factor of the permuted matrix, computed here by brute
         force, that lies outside the supernodal pattern is exactly 0 (the
         symbolic analysis misses no fill), and every stored entry equals
         the dense one to rounding; the solve's relative residual
         |A x - b| / |b| is at rounding level; the scalar up-looking LDL^T
         of the same matrix gives the same solution to rounding;
     (b) the same bits (factor values and pivots) when the parallel tasks
         run in reverse and in odd-even order on a runner of two threads
         (so the top phase, one separator, takes the WIDE pass), also on
         a 48 x 48 grid whose separators are cut into several OUTSIDE
         pieces and a 100 x 100 grid whose top supernode is big enough for
         the dense panels' rows to be cut (BP__DENSE_WIDE), the next
         panel's triangle taken ahead by task 0 (computing it before that
         task's rows fails here) (no dense brute force there: 4,608
         unknowns; residual and scalar only);
     (c) a matrix that is not positive definite is reported
         (BP_ERR_NUMERICAL) and a matrix flagged blocks2 that is not made
         of whole 2x2 blocks falls back to the scalar factorization and is
         still solved;
     (d) projected Newton's matrix on camel_b (the Tutte start, with a
         wide barrier so that its vertex pairs are in the pattern): the
         supernodal solve's residual, the scalar solve's solution to the
         conditioning's rounding, and the same bits in reverse task order;
     (e) the same as (a), (b) and (c) for scalar SPD matrices (A->super1,
         blocks of 1) on mesh-like grids: against the dense Cholesky by
         brute force, residuals, the scalar rows' solution, the same bits
         in other task orders; converted to the preconditioner's single-
         precision rows, bp__precondition solves both coordinates as the
         double factor does; an indefinite matrix falls back to the scalar
         rows and is still solved;
     (f) the scatter map of the refactorizations (bp__super_start, blocks
         of 2): every entry of A maps to the row of its supernode's block
         found by a linear scan (BP__NONE above the supernode's first
         vertex); a
         refactorization through the map of new values on the same
         pattern solves the new matrix (residual) and gives the same bits
         as a fresh factorization of those values (rows found by a look-up
         in the whole nodes, by binary searches in the separators' pieces).
     (g) the supernodal solve in the dissection's parallel phases (the
         forward solve gathering from the update lists, separators in
         OUTSIDE pieces on the 48 x 48 and 64 x 64 grids, the backward
         solve top-down, each task permuting its own range in and out),
         for (a) and (e): the same bits with its tasks run backwards and
         odd-even, and the solution of Gaussian elimination on the dense
         matrix by brute force (a separator's range left out of either
         permutation fails it); for (e), two right-hand sides in one
         solve (bp__super_solve_n) give the bits of two solves, serially,
         backwards and odd-even;
     (h) the nested-dissection ordering on several threads
         (bp__nd_order with a runner): on the 48 x 48 grid's vertex graph
         and the 64 x 64 scalar grid, a graph of 9 mesh-like components
         (grids, a path, lone vertices) with its vertices shuffled, and
         camel_b's Newton matrix and vertex graph, in both modes: the
         order is a permutation, no edge of the graph joins the two
         halves of a recorded split (what makes the pieces independent),
         and with the tasks run backwards and odd-even (counted: the
         parallel path is taken, with several tasks a loop) the order and
         the tree are the serial loop's, bit for bit; the same with a
         loop of 37 counting tasks beside the root split
         (bp__nd_order_with, as the conformal start's columns run),
         serially, in those task orders and on real pools: each of its
         tasks runs once.
     (i) the separators' refinement (bp__nd_refine): on grids, shuffled
         components and the vertex graphs of camelhead, face_holes and
         fertility, nnz(L) under the refined order (mode 1), counted here
         by brute force, is at most 2% above the unrefined one's (mode 2)
         and on the three meshes at least 5% below it (measured 10-19%),
         and the top separator is no bigger; both modes also pass (a)'s
         and (h)'s checks of the order.
     (j) the symbolic analysis in the dissection's phases, on camelhead's
         and fertility's vertex graphs: the supernodes' rows against a
         brute-force symbolic factorization, the update lists against a
         brute-force scan, and every array of the analysis the serial
         one's with the tasks run backwards, odd-even and on a real pool.
     (k) the AVX kernels (bp__super_dots_avx, bp__super_trsm4_avx): every
         factor of (a), (b), (d) and (e) -- blocks of 2 and of 1, grids up
         to the 100 x 100 one's big separators, camel_b's Newton matrix --
         refactored with the AVX path switched off (the test's own
         BP__HAVE_AVX) has the same bits, L and pivots.  On a processor
         without AVX (or another compiler) there is one path, and the
         test says so in a line of its output.
     (l) the column counts of one thread (bp__sym_counts_gnp, Gilbert,
         Ng and Peyton's algorithm) equal the row subtrees' counts
         (bp__row_count, the parallel phases' way, walked here row by row)
         on the vertex graphs of camelhead and fertility and on the
         shuffled components graph, in the dissection's order, the
         identity, its reverse and a random order.
   With BP_TEST_QUICK set (make test) the 100 x 100 grid of (a) is checked
   by its residual alone, not against the scalar factorization too (3.6 s
   at -Og); make check compares it. */
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__) && !defined(BP_NO_SIMD)
#define TEST_AVX 1
static int avx_allowed = 1;
static unsigned long avx_asked;          /* kernel calls that asked, AVX allowed (from any thread) */
#define BP__HAVE_AVX() \
    (avx_allowed && (__atomic_fetch_add(&avx_asked, 1ul, __ATOMIC_RELAXED), __builtin_cpu_supports("avx")))
#else
#define TEST_AVX 0
#endif
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"
#include "bpt_triplets.h"

static int quick = 0;   /* BP_TEST_QUICK: the short form (make test) */

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef BP_USE_PTHREADS
/* A runner on a real pool of r threads (*P NULL if it could not start). */
static bp__par real_pool(bp_allocator *al, int r, bp__pool **P)
{
    bp__par par = bp__par_serial();
    *P = bp__pool_start(al, r);
    par.run = bp__pool_for;
    par.user = *P;
    par.threads = r;
    return par;
}
#endif

/* A random SPD matrix in 2x2 blocks on a g x g grid of vertices: two
   triangles per cell (the diagonal chosen at random), each adding R R^T
   (R 6x6 random) on its vertices' coordinates; `pairs` random vertex
   pairs each adding w w^T (w random on both vertices' 4 coordinates);
   1e-3 on the diagonal. */
static int random_matrix(uint32_t g, uint32_t pairs, bp__sparse *A)
{
    bp_allocator al;
    uint32_t nv = g * g, i, j, t, k, l, r, ntri = 2 * (g - 1) * (g - 1);
    size_t cap = 36 * (size_t)ntri + 16 * (size_t)pairs + 2 * (size_t)nv, nt = 0;
    bpt_trip *tr = (bpt_trip *)malloc(cap * sizeof *tr);
    int ok;
    memset(&al, 0, sizeof al);
    memset(A, 0, sizeof *A);
    for (i = 0; i + 1 < g; i++)
        for (j = 0; j + 1 < g; j++)
            for (t = 0; t < 2; t++) {
                uint32_t v[3], a = i * g + j, b = a + 1, c = a + g, d = c + 1;
                double R[36];
                if (bpt_rng_unit() < 0.5) { v[0] = a; v[1] = b; v[2] = t ? d : c; if (t) { v[0] = a; v[1] = d; v[2] = c; } }
                else { v[0] = a; v[1] = b; v[2] = d; if (t) { v[0] = b; v[1] = d; v[2] = c; } }
                for (k = 0; k < 36; k++) R[k] = bpt_rng_range(-1, 1);
                for (k = 0; k < 6; k++)
                    for (l = 0; l < 6; l++) {
                        double s = 0;
                        for (r = 0; r < 6; r++) s += R[6 * k + r] * R[6 * l + r];
                        tr[nt].i = 2 * v[k / 2] + k % 2; tr[nt].j = 2 * v[l / 2] + l % 2; tr[nt++].v = s;
                    }
            }
    for (k = 0; k < pairs; k++) {
        uint32_t u = (uint32_t)(bpt_rng_unit() * nv) % nv, w = (uint32_t)(bpt_rng_unit() * nv) % nv, vv[2];
        double x[4];
        if (u == w) continue;
        vv[0] = u; vv[1] = w;
        for (l = 0; l < 4; l++) x[l] = bpt_rng_range(-1, 1);
        for (l = 0; l < 4; l++)
            for (r = 0; r < 4; r++) { tr[nt].i = 2 * vv[l / 2] + l % 2; tr[nt].j = 2 * vv[r / 2] + r % 2; tr[nt++].v = x[l] * x[r]; }
    }
    for (k = 0; k < 2 * nv; k++) { tr[nt].i = tr[nt].j = k; tr[nt++].v = 1e-3; }
    A->symmetric = 1;
    A->blocks2 = 1;
    ok = bpt_from_triplets(&al, 2 * nv, tr, nt, A);
    free(tr);
    return ok;
}

/* y = A x */
static void mul(const bp__sparse *A, const double *x, double *y)
{
    uint32_t j, p;
    for (j = 0; j < A->n; j++) y[j] = 0;
    for (j = 0; j < A->n; j++)
        for (p = A->colp[j]; p < A->colp[j + 1]; p++) y[A->row[p]] += A->val[p] * x[j];
}

static double rel_residual(const bp__sparse *A, const double *x, const double *b)
{
    double *y = (double *)malloc(A->n * sizeof(double)), rr = 0, bb = 0;
    uint32_t i;
    mul(A, x, y);
    for (i = 0; i < A->n; i++) { rr += (y[i] - b[i]) * (y[i] - b[i]); bb += b[i] * b[i]; }
    free(y);
    return sqrt(rr / bb);
}

static double rel_diff(const double *x, const double *y, uint32_t n)
{
    double d = 0, s = 0;
    uint32_t i;
    for (i = 0; i < n; i++) { d += (x[i] - y[i]) * (x[i] - y[i]); s += y[i] * y[i]; }
    return sqrt(d / s);
}

/* (a): the factor against brute force. */
static void check_against_dense(const bp__sparse *A, const bp__factor *F, const char *what)
{
    const bp__super *S = F->sn;
    uint32_t bs = S->bs, n = A->n, nv = n / bs, i, j, k, p, s, bad = 0, outside = 0, isperm = 1;
    double *L = (double *)calloc((size_t)n * n, sizeof(double)), worst = 0, scale = 0;
    unsigned char *in = (unsigned char *)calloc((size_t)n * n, 1), *seen = (unsigned char *)calloc(nv, 1);
    /* the ordering */
    for (i = 0; i < nv; i++) {
        if (S->vperm[i] >= nv || seen[S->vperm[i]]) isperm = 0;
        else seen[S->vperm[i]] = 1;
        if (S->vperm[i] < nv && S->viperm[S->vperm[i]] != i) isperm = 0;
    }
    BPT_CHECK(isperm, "%s: the vertex order is a permutation of %u and viperm its inverse", what, nv);
    /* the dissection tree's splits: no entry joins [lo, a) and [a, b) */
    for (k = 0; k < BP__ND_NODES; k++) {
        const bp__ndnode *N = &F->tree[k];
        uint32_t cross = 0;
        if (!N->used || !N->split) continue;
        for (j = 0; j < n; j++)
            for (p = A->colp[j]; p < A->colp[j + 1]; p++) {
                uint32_t u = S->viperm[j / bs], w = S->viperm[A->row[p] / bs];
                if (u >= N->lo && u < N->a && w >= N->a && w < N->b) cross++;
            }
        if (cross) bad++;
    }
    BPT_CHECK(bad == 0, "%s: no matrix entry joins the two halves of a split of the dissection tree (%u bad nodes)", what, bad);
    /* dense P A P^T, then its Cholesky factor in place (lower) */
    for (j = 0; j < n; j++)
        for (p = A->colp[j]; p < A->colp[j + 1]; p++) {
            uint32_t r = bs * S->viperm[A->row[p] / bs] + A->row[p] % bs, c = bs * S->viperm[j / bs] + j % bs;
            L[(size_t)r * n + c] = A->val[p];
        }
    for (j = 0; j < n; j++) {
        double d = L[(size_t)j * n + j];
        for (k = 0; k < j; k++) d -= L[(size_t)j * n + k] * L[(size_t)j * n + k];
        d = sqrt(d);
        L[(size_t)j * n + j] = d;
        for (i = j + 1; i < n; i++) {
            double t = L[(size_t)i * n + j];
            for (k = 0; k < j; k++) t -= L[(size_t)i * n + k] * L[(size_t)j * n + k];
            L[(size_t)i * n + j] = t / d;
        }
    }
    for (i = 0; i < n; i++) for (j = 0; j <= i; j++) if (fabs(L[(size_t)i * n + j]) > scale) scale = fabs(L[(size_t)i * n + j]);
    /* every stored entry against the dense one */
    for (s = 0; s < S->ns; s++) {
        uint32_t c2 = bs * (S->first[s + 1] - S->first[s]), m2 = bs * (S->rp[s + 1] - S->rp[s]);
        const double *B = S->x + S->xp[s];
        for (i = 0; i < m2; i++)
            for (j = 0; j < c2; j++) {
                uint32_t r = bs * S->ri[S->rp[s] + i / bs] + i % bs, c = bs * S->first[s] + j;
                double e;
                if (r < c) continue;
                in[(size_t)r * n + c] = 1;
                e = fabs(B[(size_t)i * c2 + j] - L[(size_t)r * n + c]);
                if (e > worst) worst = e;
            }
    }
    for (i = 0; i < n; i++)
        for (j = 0; j <= i; j++)
            if (!in[(size_t)i * n + j] && L[(size_t)i * n + j] != 0) outside++;
    BPT_CHECK(outside == 0, "%s: the dense Cholesky factor has no nonzero outside the supernodal pattern (%u found)", what,
              outside);
    BPT_CHECK(worst <= 1e-10 * scale, "%s: every stored entry equals the dense factor's, max |diff| %.3g (max |L| %.3g)", what,
              worst, scale);
    free(L); free(in); free(seen);
}

/* (f) the scatter map against a linear scan of each supernode's rows, then
   new values on the same pattern (each entry scaled by 1 + 0.3 r, r in
   [-1, 1] symmetric, and the diagonal raised: still SPD) refactored
   through the map: the residual of the new matrix, and the same bits as a
   fresh analysis and factorization of the new values. */
static void check_scatter_map(bp__sparse *A, bp__factor *F, const double *b, const char *what)
{
    const bp__super *S = F->sn;
    uint32_t s, v, c, p, bad, wrong = 0, n = A->n;
    double *old = (double *)malloc(A->colp[n] * sizeof(double)), *x = (double *)malloc(n * sizeof(double)),
           *z = (double *)malloc(n * sizeof(double));
    bp__factor Ff;
    bp_allocator al;
    bp__par ser = bp__par_serial();
    memset(&al, 0, sizeof al);
    if (!BPT_CHECK(S->amap && S->amap_ok, "%s: the scatter map is built", what)) { free(old); free(x); free(z); return; }
    for (s = 0; s < S->ns; s++)
        for (v = S->first[s]; v < S->first[s + 1]; v++)
            for (c = 2 * S->vperm[v]; c < 2 * S->vperm[v] + 2; c++)
                for (p = A->colp[c]; p < A->colp[c + 1]; p++) {
                    uint32_t u = S->viperm[A->row[p] / 2], r, want = BP__NONE;
                    if (u >= S->first[s])
                        for (r = 0; r < S->rp[s + 1] - S->rp[s]; r++)
                            if (S->ri[S->rp[s] + r] == u) want = 2 * r + A->row[p] % 2;
                    if (S->amap[p] != want) wrong++;
                }
    BPT_CHECK(wrong == 0, "%s: every entry's scatter map row is the linear scan's (%u wrong)", what, wrong);
    memcpy(old, A->val, A->colp[n] * sizeof(double));
    for (c = 0; c < n; c++)
        for (p = A->colp[c]; p < A->colp[c + 1]; p++)
            if (A->row[p] < c) {
                double f = 1 + 0.3 * bpt_rng_range(-1, 1);
                A->val[p] *= f;
                A->val[bp__sparse_find(A, c, A->row[p])] *= f;
            } else if (A->row[p] == c) A->val[p] = 1.5 * A->val[p] + 1;
    if (BPT_CHECK(bp__fact_numeric(&al, A, F, NULL, &ser), "%s: refactored through the map", what)) {
        bp__factor_solve(F, b, x, z);
        BPT_CHECK(rel_residual(A, x, b) < 1e-10, "%s: new values through the map: |A x - b| / |b| = %.3g", what,
                  rel_residual(A, x, b));
        if (BPT_CHECK(bp__factorize(&al, A, &Ff, &bad, NULL) == BP_OK && Ff.sn, "%s: new values factored afresh", what)) {
            int same = Ff.sn->xp[Ff.sn->ns] == S->xp[S->ns] &&
                       memcmp(Ff.sn->x, S->x, S->xp[S->ns] * sizeof(double)) == 0 && memcmp(Ff.D, F->D, n * sizeof(double)) == 0;
            BPT_CHECK(same, "%s: through the map and afresh: the same bits", what);
            bp__factor_free(&al, &Ff);
        }
    }
    memcpy(A->val, old, A->colp[n] * sizeof(double));
    free(old); free(x); free(z);
}

/* A grid big enough for separators cut into several OUTSIDE pieces: some
   supernode spans 16 vertices or more. */
static void check_big_supernodes(const bp__factor *F, const char *what)
{
    uint32_t s, big = 0;
    for (s = 0; s < F->sn->ns; s++) if (F->sn->first[s + 1] - F->sn->first[s] >= 16) big++;
    BPT_CHECK(big > 0, "%s: %u supernodes of 16 vertices or more (cut into pieces)", what, big);
}

/* (k) F (factored with the AVX kernels where the processor has them)
   refactored with them switched off: the same bits. */
static uint32_t simd_compared;

static void check_simd(const bp__sparse *A, bp__factor *F, const char *what)
{
#if TEST_AVX
    bp_allocator al;
    bp__par ser = bp__par_serial();
    size_t nx = F->sn->xp[F->sn->ns];
    double *x, *d;
    unsigned long asked = __atomic_load_n(&avx_asked, __ATOMIC_RELAXED);
    if (!__builtin_cpu_supports("avx")) return;
    memset(&al, 0, sizeof al);
    x = (double *)malloc(nx * sizeof(double));
    d = (double *)malloc(A->n * sizeof(double));
    bp__fact_numeric(&al, A, F, NULL, &ser);           /* AVX, the asks counted */
    asked = __atomic_load_n(&avx_asked, __ATOMIC_RELAXED) - asked;
    memcpy(x, F->sn->x, nx * sizeof(double));
    memcpy(d, F->D, A->n * sizeof(double));
    avx_allowed = 0;
    bp__fact_numeric(&al, A, F, NULL, &ser);           /* the plain loops */
    avx_allowed = 1;
    BPT_CHECK(memcmp(x, F->sn->x, nx * sizeof(double)) == 0 && memcmp(d, F->D, A->n * sizeof(double)) == 0,
              "%s: the plain loops give the AVX kernels' bits (%lu kernel calls asked for AVX)", what, asked);
    if (asked > 0) simd_compared++;             /* (the smallest grids have no block to ask for) */
    free(x);
    free(d);
#else
    (void)A; (void)F; (void)what;
#endif
}

/* (b) the same bits on other task orders: a new analysis of A with the
   numeric phase run backwards, then refactored odd-even, against F; the
   runners say two threads, so a phase of one separator goes WIDE, and so
   does a phase of two or more whose biggest separator holds most of the
   work (bp__super_unbalanced; counted in wide_unbalanced, which
   test_random requires to be reached). */
static uint32_t wide_unbalanced;

static void check_task_orders(const bp__sparse *A, const bp__factor *F, const char *what)
{
    bp_allocator al;
    bp__factor Fr;
    uint32_t bad, nodes[BP__ND_NODES], c;
    int phase;
    bp__par rev = bp__par_serial(), oe = bp__par_serial();
    memset(&al, 0, sizeof al);
    for (phase = 1; phase <= BP__ND_DEPTH; phase++)
        if ((c = bp__nd_phase(F, phase, nodes)) >= 2 && bp__super_unbalanced(F, nodes, c, 2)) wide_unbalanced++;
    rev.run = bpt_backwards_for;
    oe.run = bpt_odd_even_for;
    rev.threads = oe.threads = 2;
    if (BPT_CHECK(bp__factorize(&al, A, &Fr, &bad, &rev) == BP_OK && Fr.sn, "%s: factorization, tasks backwards", what)) {
        int same = memcmp(F->sn->x, Fr.sn->x, F->sn->xp[F->sn->ns] * sizeof(double)) == 0 &&
                   memcmp(F->D, Fr.D, A->n * sizeof(double)) == 0;
        BPT_CHECK(same, "%s: tasks run backwards give the same bits", what);
        memset(Fr.sn->x, 0, Fr.sn->xp[Fr.sn->ns] * sizeof(double));
        bp__fact_numeric(&al, A, &Fr, NULL, &oe);
        same = memcmp(F->sn->x, Fr.sn->x, F->sn->xp[F->sn->ns] * sizeof(double)) == 0;
        BPT_CHECK(same, "%s: refactored in odd-even task order: the same bits", what);
        bp__factor_free(&al, &Fr);
    }
#ifdef BP_USE_PTHREADS
    {   /* on real threads (built with the pool: ThreadSanitizer's make tsan) */
        int r;
        for (r = 2; r <= 3; r++) {
            bp__pool *P;
            bp__par par = real_pool(&al, r, &P);
            if (!BPT_CHECK(P != NULL, "%s: a pool of %d threads", what, r)) break;
            if (BPT_CHECK(bp__factorize(&al, A, &Fr, &bad, &par) == BP_OK && Fr.sn, "%s: factored on %d threads", what, r)) {
                BPT_CHECK(memcmp(F->sn->x, Fr.sn->x, F->sn->xp[F->sn->ns] * sizeof(double)) == 0 &&
                          memcmp(F->D, Fr.D, A->n * sizeof(double)) == 0, "%s: on %d threads: the same bits", what, r);
                bp__factor_free(&al, &Fr);
            }
            bp__pool_stop(&al, P);
        }
    }
#endif
}

/* (g) the supernodal solve in the dissection's parallel phases: its
   tasks run backwards and odd-even give the same bits as the serial
   order, and (n <= 400) its solution is the dense one, computed here by
   Gaussian elimination with partial pivoting on A itself.  Solves whose
   forward pass buffers phase 0's terms for the separators
   (bp__ssolve_buffers) are counted in solves_buffered, which test_random
   requires to be reached. */
static uint32_t solves_buffered;

static void check_solve(const bp__sparse *A, const bp__factor *F, const double *b, const double *x, const char *what)
{
    uint32_t n = A->n, i, j, k, p;
    double *y = (double *)malloc(n * sizeof(double)), *z = (double *)malloc(n * sizeof(double));
    bp__ssolve_task T;
    memset(&T, 0, sizeof T);
    T.F = F;
    bp__ssolve_buffers(&T, F, y);
    solves_buffered += T.buf != NULL;
    bp__par rev = bp__par_serial(), oe = bp__par_serial();
    rev.run = bpt_backwards_for;
    oe.run = bpt_odd_even_for;
    rev.threads = oe.threads = 2;                 /* the phases, not the serial scatter */
    bp__factor_solve_par(F, b, y, z, &rev);
    BPT_CHECK(memcmp(x, y, n * sizeof(double)) == 0, "%s: the solve's tasks run backwards give the same bits", what);
    bp__factor_solve_par(F, b, y, z, &oe);
    BPT_CHECK(memcmp(x, y, n * sizeof(double)) == 0, "%s: the solve's tasks run odd-even give the same bits", what);
    if (n <= 400) {
        double *M = (double *)calloc((size_t)n * (n + 1), sizeof(double));
        for (j = 0; j < n; j++)
            for (p = A->colp[j]; p < A->colp[j + 1]; p++) M[(size_t)A->row[p] * (n + 1) + j] = A->val[p];
        for (i = 0; i < n; i++) M[(size_t)i * (n + 1) + n] = b[i];
        for (k = 0; k < n; k++) {
            uint32_t best = k;
            for (i = k + 1; i < n; i++)
                if (fabs(M[(size_t)i * (n + 1) + k]) > fabs(M[(size_t)best * (n + 1) + k])) best = i;
            for (j = 0; j <= n; j++) {
                double t = M[(size_t)k * (n + 1) + j];
                M[(size_t)k * (n + 1) + j] = M[(size_t)best * (n + 1) + j];
                M[(size_t)best * (n + 1) + j] = t;
            }
            for (i = k + 1; i < n; i++) {
                double f = M[(size_t)i * (n + 1) + k] / M[(size_t)k * (n + 1) + k];
                for (j = k; j <= n; j++) M[(size_t)i * (n + 1) + j] -= f * M[(size_t)k * (n + 1) + j];
            }
        }
        for (i = n; i-- > 0;) {
            double t = M[(size_t)i * (n + 1) + n];
            for (j = i + 1; j < n; j++) t -= M[(size_t)i * (n + 1) + j] * y[j];
            y[i] = t / M[(size_t)i * (n + 1) + i];
        }
        BPT_CHECK(rel_diff(x, y, n) < 1e-8, "%s: the solve equals the dense solution by brute force, rel. diff %.3g", what,
                  rel_diff(x, y, n));
        free(M);
    }
    free(y); free(z);
}

static void test_random(void)
{
    static const uint32_t G[] = { 3, 6, 9, 12, 48, 100 };
    static const uint32_t PAIRS[] = { 0, 4, 20, 40, 30, 60 };
    bp_allocator al;
    int c;
    memset(&al, 0, sizeof al);
    for (c = 0; c < 6; c++) {
        bp__sparse A;
        bp__factor F, Fs;
        uint32_t n, i, bad;
        double *b, *x, *xs, *z;
        char what[64];
        sprintf(what, "grid %ux%u + %u pairs", G[c], G[c], PAIRS[c]);
        if (!BPT_CHECK(random_matrix(G[c], PAIRS[c], &A), "%s: built", what)) return;
        n = A.n;
        b = (double *)malloc(n * sizeof(double)); x = (double *)malloc(n * sizeof(double));
        xs = (double *)malloc(n * sizeof(double)); z = (double *)malloc(n * sizeof(double));
        for (i = 0; i < n; i++) b[i] = bpt_rng_range(-1, 1);
        if (!BPT_CHECK(bp__factorize(&al, &A, &F, &bad, NULL) == BP_OK && F.sn, "%s: supernodal factorization", what)) return;
        if (G[c] <= 12) check_against_dense(&A, &F, what);
        else check_big_supernodes(&F, what);
        if (G[c] == 100) {
            uint32_t s, wide = 0;
            for (s = 0; s < F.sn->ns; s++) {
                double c2 = 2.0 * (F.sn->first[s + 1] - F.sn->first[s]), m2 = 2.0 * (F.sn->rp[s + 1] - F.sn->rp[s]);
                if (m2 * c2 * c2 / 2 >= BP__DENSE_WIDE) wide++;
            }
            BPT_CHECK(wide > 0, "%s: %u supernodes big enough for the WIDE dense panels", what, wide);
        }
        bp__factor_solve(&F, b, x, z);
        BPT_CHECK(rel_residual(&A, x, b) < 1e-10, "%s: |A x - b| / |b| = %.3g", what, rel_residual(&A, x, b));
        check_solve(&A, &F, b, x, what);
        if (!quick || G[c] < 100) {   /* the 100 x 100 grid's scalar factorization: 3.6 s */
            A.blocks2 = 0;
            BPT_CHECK(bp__factorize(&al, &A, &Fs, &bad, NULL) == BP_OK && !Fs.sn, "%s: scalar factorization", what);
            bp__factor_solve(&Fs, b, xs, z);
            BPT_CHECK(rel_diff(x, xs, n) < 1e-9, "%s: supernodal and scalar solutions agree, rel. diff %.3g", what,
                      rel_diff(x, xs, n));
            A.blocks2 = 1;
            bp__factor_free(&al, &Fs);
        }
        /* (b) the same bits on other task orders: a new analysis with the
           numeric phase run backwards, then refactored odd-even */
        check_task_orders(&A, &F, what);
        check_simd(&A, &F, what);
        check_scatter_map(&A, &F, b, what);
        bp__factor_free(&al, &F);
        /* (c) not positive definite: one diagonal entry made very negative */
        A.val[bp__sparse_find(&A, n / 2, n / 2)] = -1e6;
        BPT_CHECK(bp__factorize(&al, &A, &F, &bad, NULL) == BP_ERR_NUMERICAL, "%s: an indefinite matrix is reported (row %u)",
                  what, bad);
        bp__sparse_free(&al, &A);
        free(b); free(x); free(xs); free(z);
    }
    BPT_CHECK(wide_unbalanced > 0, "grids: %u phases of two or more separators went WIDE (one holds most of the work), "
              "their bits checked above", wide_unbalanced);
    BPT_CHECK(solves_buffered > 0, "grids: %u factors solved with phase 0's separator terms buffered, checked above",
              solves_buffered);
}

/* (e) A random scalar SPD matrix (A->super1) on the same grids: each
   triangle adds R R^T (R 3x3 random) on its three vertices, `pairs`
   random vertex pairs w w^T, 1e-3 on the diagonal. */
static int random_scalar(uint32_t g, uint32_t pairs, bp__sparse *A)
{
    bp_allocator al;
    uint32_t nv = g * g, i, j, t, k, l, r, ntri = 2 * (g - 1) * (g - 1);
    size_t nt = 0;
    bpt_trip *tr = (bpt_trip *)malloc((9 * (size_t)ntri + 4 * (size_t)pairs + nv) * sizeof *tr);
    int ok;
    memset(&al, 0, sizeof al);
    memset(A, 0, sizeof *A);
    for (i = 0; i + 1 < g; i++)
        for (j = 0; j + 1 < g; j++)
            for (t = 0; t < 2; t++) {
                uint32_t v[3], a = i * g + j, b = a + 1, c = a + g, d = c + 1;
                double R[9];
                if (bpt_rng_unit() < 0.5) { v[0] = a; v[1] = t ? d : b; v[2] = t ? c : d; }
                else { v[0] = t ? b : a; v[1] = t ? d : b; v[2] = c; }
                for (k = 0; k < 9; k++) R[k] = bpt_rng_range(-1, 1);
                for (k = 0; k < 3; k++)
                    for (l = 0; l < 3; l++) {
                        double s = 0;
                        for (r = 0; r < 3; r++) s += R[3 * k + r] * R[3 * l + r];
                        tr[nt].i = v[k]; tr[nt].j = v[l]; tr[nt++].v = s;
                    }
            }
    for (k = 0; k < pairs; k++) {
        uint32_t u = (uint32_t)(bpt_rng_unit() * nv) % nv, w = (uint32_t)(bpt_rng_unit() * nv) % nv;
        double x0 = bpt_rng_range(-1, 1), x1 = bpt_rng_range(-1, 1);
        if (u == w) continue;
        tr[nt].i = u; tr[nt].j = u; tr[nt++].v = x0 * x0;
        tr[nt].i = w; tr[nt].j = w; tr[nt++].v = x1 * x1;
        tr[nt].i = u; tr[nt].j = w; tr[nt++].v = x0 * x1;
        tr[nt].i = w; tr[nt].j = u; tr[nt++].v = x0 * x1;
    }
    for (k = 0; k < nv; k++) { tr[nt].i = tr[nt].j = k; tr[nt++].v = 1e-3; }
    A->symmetric = 1;
    A->super1 = 1;
    ok = bpt_from_triplets(&al, nv, tr, nt, A);
    free(tr);
    return ok;
}

/* bp__super_to_rows on several threads (ranges of supernodes, each with
   its own cursors) against the rows written here from the supernodal
   blocks by brute force: every entry (i, j) of C below the diagonal as
   float(C(i, j) / C(j, j)), sorted by row, then column.  F is converted
   (and its blocks freed). */
typedef struct ref_rowent { uint32_t i, j; float v; } ref_rowent;

static int ref_rowent_cmp(const void *pa, const void *pb)
{
    const ref_rowent *a = (const ref_rowent *)pa, *b = (const ref_rowent *)pb;
    if (a->i != b->i) return a->i < b->i ? -1 : 1;
    return a->j < b->j ? -1 : a->j > b->j;
}

static void check_rows_parallel(bp__factor *F, bp__par *par, const char *order, const char *what)
{
    const bp__super *S = F->sn;
    uint32_t n = S->nv, s, jj, ii, k, ne = 0, *rp = (uint32_t *)calloc(n + 1, sizeof(uint32_t));
    bp_allocator al;
    ref_rowent *e = (ref_rowent *)malloc((S->xp[S->ns] + 1) * sizeof(ref_rowent));
    int same;
    memset(&al, 0, sizeof al);
    for (s = 0; s < S->ns; s++) {
        uint32_t f = S->first[s], nc = S->first[s + 1] - f, m = S->rp[s + 1] - S->rp[s];
        const uint32_t *rows = S->ri + S->rp[s];
        const double *B = S->x + S->xp[s];
        for (jj = 0; jj < nc; jj++)
            for (ii = jj + 1; ii < m; ii++) {
                e[ne].i = rows[ii]; e[ne].j = f + jj;
                e[ne++].v = (float)(B[(size_t)ii * nc + jj] / B[(size_t)jj * nc + jj]);
            }
    }
    qsort(e, ne, sizeof *e, ref_rowent_cmp);
    for (k = 0; k < ne; k++) rp[e[k].i + 1]++;
    for (k = 0; k < n; k++) rp[k + 1] += rp[k];
    if (BPT_CHECK(bp__factor_single(&al, F, par) && !F->sn, "%s: converted to single rows (tasks %s)", what, order)) {
        same = !memcmp(rp, F->Rp, (n + 1) * sizeof(uint32_t));
        for (k = 0; same && k < ne; k++) same = F->Ri[k] == e[k].j && !memcmp(&F->Rxf[k], &e[k].v, sizeof(float));
        BPT_CHECK(same && n >= 1024, "%s: the rows (tasks %s, %u entries) are the blocks' entries sorted "
                  "by row and column, bit for bit", what, order, ne);
    }
    free(rp);
    free(e);
}

/* (e): the scalar supernodal factor (blocks of 1) as (a), (b) and (c),
   and its single-precision rows for the preconditioner. */
static void test_scalar(void)
{
    static const uint32_t G[] = { 3, 7, 10, 13, 64 };
    static const uint32_t PAIRS[] = { 0, 3, 10, 30, 40 };
    bp_allocator al;
    int c;
    memset(&al, 0, sizeof al);
    for (c = 0; c < 5; c++) {
        bp__sparse A;
        bp__factor F, Fs;
        uint32_t n, i, bad;
        double *b, *x, *xs, *z, *q2, *r2, err = 0, big = 0;
        char what[80];
        bp__par oe = bp__par_serial();
        oe.run = bpt_odd_even_for;
        sprintf(what, "scalar grid %ux%u + %u pairs", G[c], G[c], PAIRS[c]);
        if (!BPT_CHECK(random_scalar(G[c], PAIRS[c], &A), "%s: built", what)) return;
        n = A.n;
        b = (double *)malloc(n * sizeof(double)); x = (double *)malloc(n * sizeof(double));
        xs = (double *)malloc(n * sizeof(double)); z = (double *)malloc(4 * n * sizeof(double));
        q2 = (double *)malloc(2 * n * sizeof(double)); r2 = (double *)malloc(2 * n * sizeof(double));
        for (i = 0; i < n; i++) b[i] = bpt_rng_range(-1, 1);
        if (!BPT_CHECK(bp__factorize(&al, &A, &F, &bad, NULL) == BP_OK && F.sn && F.sn->bs == 1,
                       "%s: supernodal factorization with blocks of 1", what)) return;
        if (G[c] <= 13) check_against_dense(&A, &F, what);
        else check_big_supernodes(&F, what);
        bp__factor_solve(&F, b, x, z);
        BPT_CHECK(rel_residual(&A, x, b) < 1e-10, "%s: |A x - b| / |b| = %.3g", what, rel_residual(&A, x, b));
        check_solve(&A, &F, b, x, what);
        {   /* (g) two right-hand sides in one solve (bp__super_solve_n) */
            double *rb = (double *)malloc(n * sizeof(double));
            bp__par ps[3];
            int k, same = 1;
            for (i = 0; i < n; i++) { q2[2 * i] = b[i]; q2[2 * i + 1] = b[n - 1 - i]; xs[i] = b[n - 1 - i]; }
            bp__factor_solve(&F, xs, rb, z);
            ps[0] = bp__par_serial();
            ps[1] = ps[0]; ps[1].run = bpt_backwards_for; ps[1].threads = 2;
            ps[2] = ps[0]; ps[2].run = bpt_odd_even_for; ps[2].threads = 2;
            for (k = 0; k < 3; k++) {
                bp__super_solve_n(&F, q2, r2, z, &ps[k], 2);
                for (i = 0; i < n; i++)
                    if (memcmp(r2 + 2 * i, x + i, sizeof(double)) || memcmp(r2 + 2 * i + 1, rb + i, sizeof(double))) same = 0;
            }
            BPT_CHECK(same, "%s: two right-hand sides in one solve are the bits of two solves, serially, backwards and "
                      "odd-even", what);
            free(rb);
        }
        A.super1 = 0;
        BPT_CHECK(bp__factorize(&al, &A, &Fs, &bad, NULL) == BP_OK && !Fs.sn, "%s: scalar rows", what);
        bp__factor_solve(&Fs, b, xs, z);
        BPT_CHECK(rel_diff(x, xs, n) < 1e-9, "%s: supernodal and scalar-row solutions agree, rel. diff %.3g", what,
                  rel_diff(x, xs, n));
        bp__factor_free(&al, &Fs);
        A.super1 = 1;
        check_task_orders(&A, &F, what);
        check_simd(&A, &F, what);
        /* the preconditioner's form: single-precision rows, both
           coordinates (the second one b reversed) against the double solve */
        for (i = 0; i < n; i++) { q2[2 * i] = b[i]; q2[2 * i + 1] = b[n - 1 - i]; }
        for (i = 0; i < n; i++) xs[i] = b[n - 1 - i];
        bp__factor_solve(&F, xs, xs, z + n);
        if (BPT_CHECK(bp__factor_single(&al, &F, NULL) && !F.sn && bp__solve_plan(&al, &F), "%s: converted to single rows", what)) {
            bp__precondition(&F, &oe, q2, r2, z);
            for (i = 0; i < n; i++) {
                if (fabs(r2[2 * i] - x[i]) > err) err = fabs(r2[2 * i] - x[i]);
                if (fabs(r2[2 * i + 1] - xs[i]) > err) err = fabs(r2[2 * i + 1] - xs[i]);
                if (fabs(x[i]) > big) big = fabs(x[i]);
                if (fabs(xs[i]) > big) big = fabs(xs[i]);
            }
            BPT_CHECK(err < 1e-3 * big, "%s: the single-precision rows solve both coordinates as the double factor "
                      "(max diff %.2g of %.2g)", what, err, big);
        }
        bp__factor_free(&al, &F);
        if (n >= 1024) {                        /* (the runner serves 1024 rows and more) */
            bp__par rev = bp__par_serial();
            rev.run = bpt_backwards_for;
            rev.threads = oe.threads = 2;
            if (bp__factorize(&al, &A, &F, &bad, NULL) == BP_OK && F.sn) check_rows_parallel(&F, &rev, "backwards", what);
            bp__factor_free(&al, &F);
            if (bp__factorize(&al, &A, &F, &bad, NULL) == BP_OK && F.sn) check_rows_parallel(&F, &oe, "odd then even", what);
            bp__factor_free(&al, &F);
        }
        /* (c) not positive definite: the scalar rows (LDL^T) take over */
        A.val[bp__sparse_find(&A, n / 2, n / 2)] = -1e3;
        if (BPT_CHECK(bp__factorize(&al, &A, &F, &bad, NULL) == BP_OK && !F.sn,
                      "%s: an indefinite matrix falls back to the scalar rows", what)) {
            bp__factor_solve(&F, b, x, z);
            BPT_CHECK(rel_residual(&A, x, b) < 1e-8, "%s: ... and is solved, |A x - b| / |b| = %.3g", what,
                      rel_residual(&A, x, b));
            bp__factor_free(&al, &F);
        }
        bp__sparse_free(&al, &A);
        free(b); free(x); free(xs); free(z); free(q2); free(r2);
    }
}

/* (h) the ordering on several threads against the serial loop.  A
   runner that counts its loops and tasks and hands them to `run`. */
typedef struct counted_runner {
    bp_parallel_for_fn run;
    uint32_t loops, tasks;
} counted_runner;

static void counted_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    counted_runner *c = (counted_runner *)user;
    c->loops++;
    c->tasks += count;
    c->run(NULL, fn, task, count);
}

/* A loop beside the dissection (bp__nd_order_with): task i counts its
   runs in slot i. */
#define WITH_TASKS 37u
static void count_slot(void *task, uint32_t i) { ((uint32_t *)task)[i]++; }

/* The dissection with WITH_TASKS counting tasks beside it: the order and
   tree o, t (those without it), and every task run once. */
static void check_with(const bp_allocator *al, const bp__sparse *M, const bp__par *par, int mode, const uint32_t *o,
                       const bp__ndnode *t, const char *what, const char *how)
{
    uint32_t n = M->n, i, once = 0, slot[WITH_TASKS], *op = (uint32_t *)malloc(n * sizeof(uint32_t));
    bp__ndnode tp[BP__ND_NODES];
    bp__loop with;
    memset(slot, 0, sizeof slot);
    with.fn = count_slot; with.task = slot; with.count = WITH_TASKS;
    if (BPT_CHECK(bp__nd_order_with(al, M, op, tp, mode, par, &with), "%s, mode %d, %s: ordered with a loop beside", what,
                  mode, how)) {
        for (i = 0; i < WITH_TASKS; i++) once += slot[i] == 1;
        BPT_CHECK(once == WITH_TASKS && memcmp(o, op, n * sizeof(uint32_t)) == 0 && memcmp(t, tp, sizeof tp) == 0,
                  "%s, mode %d, %s: with a loop beside the root split, the same order and tree, and each of its %u tasks "
                  "run once (%u)", what, mode, how, WITH_TASKS, once);
    }
    free(op);
}

static void check_order(const bp__sparse *M, const char *what)
{
    bp_allocator al;
    uint32_t n = M->n, i, j, p, k, bad, cross;
    uint32_t *o = (uint32_t *)malloc(n * sizeof(uint32_t)), *op = (uint32_t *)malloc(n * sizeof(uint32_t)),
             *inv = (uint32_t *)malloc(n * sizeof(uint32_t));
    bp__ndnode t[BP__ND_NODES], tp[BP__ND_NODES];
    int mode, r;
    memset(&al, 0, sizeof al);
    for (mode = 0; mode < 3; mode++) {
        if (!BPT_CHECK(bp__nd_order(&al, M, o, t, mode, NULL), "%s, mode %d: ordered serially", what, mode)) break;
        for (i = 0; i < n; i++) inv[i] = BP__NONE;
        for (i = 0, bad = 0; i < n; i++) {
            if (o[i] >= n || inv[o[i]] != BP__NONE) bad++;
            else inv[o[i]] = i;
        }
        BPT_CHECK(bad == 0, "%s, mode %d: the order is a permutation of %u (%u bad)", what, mode, n, bad);
        if (bad) break;
        for (k = 0, bad = 0; k < BP__ND_NODES; k++) {
            const bp__ndnode *N = &t[k];
            if (!N->used || !N->split) continue;
            for (j = 0, cross = 0; j < n; j++)
                for (p = M->colp[j]; p < M->colp[j + 1]; p++) {
                    uint32_t u = inv[j], w = inv[M->row[p]];
                    if (u >= N->lo && u < N->a && w >= N->a && w < N->b) cross++;
                }
            if (cross) bad++;
        }
        BPT_CHECK(bad == 0 && t[0].split, "%s, mode %d: the root is split and no edge joins the two halves of a split "
                  "(%u bad nodes)", what, mode, bad);
        check_with(&al, M, NULL, mode, o, t, what, "serially");
        for (r = 0; r < 2; r++) {
            counted_runner c;
            bp__par par = bp__par_serial();
            c.run = r ? bpt_odd_even_for : bpt_backwards_for;
            c.loops = c.tasks = 0;
            par.run = counted_for;
            par.user = &c;
            par.threads = 2;
            memset(op, 0xff, n * sizeof(uint32_t));
            memset(tp, 0xff, sizeof tp);
            if (!BPT_CHECK(bp__nd_order(&al, M, op, tp, mode, &par), "%s, mode %d: ordered with a runner", what, mode)) break;
            BPT_CHECK(c.loops >= 2 && c.tasks >= c.loops + 2, "%s, mode %d: the parallel path (%u tasks in %u loops)", what,
                      mode, c.tasks, c.loops);
            BPT_CHECK(memcmp(o, op, n * sizeof(uint32_t)) == 0 && memcmp(t, tp, sizeof t) == 0,
                      "%s, mode %d: tasks run %s: the serial loop's order and tree, bit for bit", what, mode,
                      r ? "odd-even" : "backwards");
            check_with(&al, M, &par, mode, o, t, what, r ? "tasks odd-even" : "tasks backwards");
        }
#ifdef BP_USE_PTHREADS
        for (r = 2; r <= 3; r++) {      /* on real threads (built with the pool: ThreadSanitizer) */
            bp__pool *P;
            bp__par par = real_pool(&al, r, &P);
            if (!BPT_CHECK(P != NULL, "%s: a pool of %d threads", what, r)) break;
            BPT_CHECK(bp__nd_order(&al, M, op, tp, mode, &par) && memcmp(o, op, n * sizeof(uint32_t)) == 0 &&
                      memcmp(t, tp, sizeof t) == 0, "%s, mode %d: on %d threads: the serial loop's order and tree", what,
                      mode, r);
            check_with(&al, M, &par, mode, o, t, what, r == 2 ? "2 threads" : "3 threads");
            bp__pool_stop(&al, P);
        }
#endif
    }
    free(o); free(op); free(inv);
}

/* A graph of mesh-like components, its vertices shuffled: grids g x h
   (two triangles a cell), a path, lone vertices. */
static int components_graph(bp__sparse *A)
{
    static const uint32_t GW[] = { 30, 13, 3, 40, 1, 2, 17, 1, 5 }, GH[] = { 30, 20, 3, 6, 1, 1, 1, 200, 33 };
    bp_allocator al;
    uint32_t nv = 0, c, i, j, k, *perm, base = 0;
    size_t nt = 0;
    bpt_trip *tr;
    int ok;
    memset(&al, 0, sizeof al);
    memset(A, 0, sizeof *A);
    for (c = 0; c < 9; c++) nv += GW[c] * GH[c];
    perm = (uint32_t *)malloc(nv * sizeof(uint32_t));
    tr = (bpt_trip *)malloc((size_t)(nv * 9 + nv) * sizeof *tr);
    for (i = 0; i < nv; i++) perm[i] = i;
    for (i = nv; i > 1; i--) { k = (uint32_t)(bpt_rng_unit() * i) % i; j = perm[i - 1]; perm[i - 1] = perm[k]; perm[k] = j; }
    for (c = 0; c < 9; c++) {
        uint32_t g = GW[c], h = GH[c];
        for (i = 0; i < h; i++)
            for (j = 0; j < g; j++) {
                uint32_t v = perm[base + i * g + j], nb[3], q;
                nb[0] = j + 1 < g ? perm[base + i * g + j + 1] : BP__NONE;
                nb[1] = i + 1 < h ? perm[base + (i + 1) * g + j] : BP__NONE;
                nb[2] = j + 1 < g && i + 1 < h ? perm[base + (i + 1) * g + j + 1] : BP__NONE;
                for (q = 0; q < 3; q++)
                    if (nb[q] != BP__NONE) {
                        tr[nt].i = v; tr[nt].j = nb[q]; tr[nt++].v = -1;
                        tr[nt].i = nb[q]; tr[nt].j = v; tr[nt++].v = -1;
                    }
                tr[nt].i = tr[nt].j = v; tr[nt++].v = 8;
            }
        base += g * h;
    }
    A->symmetric = 1;
    ok = bpt_from_triplets(&al, nv, tr, nt, A);
    free(tr); free(perm);
    return ok;
}

/* (i) the separators' refinement (bp__nd_refine): nnz(L) of the vertex
   graph under an order, counted here by brute force (the elimination
   tree by Liu's algorithm, then each row's reach in it, one mark per
   column), for mode 1 (keys, refined) and mode 2 (keys alone): the
   refinement never costs more than 2% and, on the real meshes, saves
   at least `save` of it; the top separator is no bigger. */
static double fill_count(const bp__sparse *M, const uint32_t *order)
{
    uint32_t n = M->n, k, p, j, *inv = (uint32_t *)malloc(n * sizeof(uint32_t)), *par = (uint32_t *)malloc(n * sizeof(uint32_t)),
             *anc = (uint32_t *)malloc(n * sizeof(uint32_t)), *mark = (uint32_t *)malloc(n * sizeof(uint32_t));
    double nnz = 0;
    for (k = 0; k < n; k++) inv[order[k]] = k;
    for (k = 0; k < n; k++) {
        par[k] = anc[k] = BP__NONE;
        for (p = M->colp[order[k]]; p < M->colp[order[k] + 1]; p++)
            for (j = inv[M->row[p]]; j != BP__NONE && j < k;) {
                uint32_t next = anc[j];
                anc[j] = k;
                if (next == BP__NONE) { par[j] = k; break; }
                j = next;
            }
    }
    for (k = 0; k < n; k++) mark[k] = BP__NONE;
    for (k = 0; k < n; k++) {
        mark[k] = k;
        nnz++;
        for (p = M->colp[order[k]]; p < M->colp[order[k] + 1]; p++)
            for (j = inv[M->row[p]]; j < k && mark[j] != k; j = par[j]) { mark[j] = k; nnz++; }
    }
    free(inv); free(par); free(anc); free(mark);
    return nnz;
}

static void check_refined(const bp__sparse *M, const char *what, double save)
{
    bp_allocator al;
    uint32_t *o1 = (uint32_t *)malloc(M->n * sizeof(uint32_t)), *o2 = (uint32_t *)malloc(M->n * sizeof(uint32_t));
    bp__ndnode t1[BP__ND_NODES], t2[BP__ND_NODES];
    memset(&al, 0, sizeof al);
    if (BPT_CHECK(bp__nd_order(&al, M, o1, t1, 1, NULL) && bp__nd_order(&al, M, o2, t2, 2, NULL), "%s: ordered in modes 1 and 2",
                  what)) {
        double f1 = fill_count(M, o1), f2 = fill_count(M, o2);
        BPT_CHECK(f1 <= 1.02 * f2 && f1 <= (1 - save) * f2, "%s: nnz(L) refined %.0f against %.0f unrefined (%.1f%% less; "
                  "at least %.0f%% wanted)", what, f1, f2, 100 * (1 - f1 / f2), 100 * save);
        BPT_CHECK(t1[0].hi - t1[0].b <= t2[0].hi - t2[0].b, "%s: top separator refined %u, unrefined %u", what,
                  t1[0].hi - t1[0].b, t2[0].hi - t2[0].b);
    }
    free(o1); free(o2);
}

/* The vertex graph of a mesh file's triangles (diagonal included). */
static int mesh_graph(const char *path, bp__sparse *G)
{
    bp_mesh m;
    bp_error err;
    bp_allocator al;
    bpt_trip *tr;
    size_t nt = 0;
    uint32_t t, k, l;
    int ok;
    memset(&al, 0, sizeof al);
    memset(G, 0, sizeof *G);
    if (bp_read_mesh(path, &m, NULL, &err) != BP_OK) return 0;
    tr = (bpt_trip *)malloc((6 * (size_t)m.num_triangles + m.num_vertices) * sizeof(bpt_trip));
    for (t = 0; t < m.num_triangles; t++)
        for (k = 0; k < 3; k++)
            for (l = 0; l < 3; l++)
                if (k != l) { tr[nt].i = m.triangles[3 * t + k]; tr[nt].j = m.triangles[3 * t + l]; tr[nt++].v = 1; }
    for (t = 0; t < m.num_vertices; t++) { tr[nt].i = tr[nt].j = t; tr[nt++].v = 1; }
    G->symmetric = 1;
    ok = bpt_from_triplets(&al, m.num_vertices, tr, nt, G);
    free(tr);
    bp_mesh_free(&m, NULL);
    return ok;
}

static void test_order(void)
{
    bp_allocator al;
    bp__sparse A, G;
    memset(&al, 0, sizeof al);
    if (BPT_CHECK(random_matrix(48, 30, &A), "order: 48 x 48 grid built")) {
        if (BPT_CHECK(bp__super_graph(&al, &A, &G) == 1, "order: the 48 x 48 grid's vertex graph")) {
            check_order(&G, "vertex graph of the 48 x 48 grid");
            check_refined(&G, "vertex graph of the 48 x 48 grid", 0);
            bp__sparse_free(&al, &G);
        }
        bp__sparse_free(&al, &A);
    }
    if (BPT_CHECK(random_scalar(64, 40, &A), "order: scalar 64 x 64 grid built")) {
        check_order(&A, "scalar 64 x 64 grid");
        check_refined(&A, "scalar 64 x 64 grid", 0);
        bp__sparse_free(&al, &A);
    }
    if (BPT_CHECK(components_graph(&A), "order: the components graph built")) {
        check_order(&A, "9 shuffled components");
        check_refined(&A, "9 shuffled components", 0);
        bp__sparse_free(&al, &A);
    }
    {
        static const char *MESH[] = { "tests/data/camelhead.off", "tests/data/face_holes.off", "tests/data/fertility.off" };
        int k;
        for (k = 0; k < 3; k++)
            if (BPT_CHECK(mesh_graph(MESH[k], &G), "order: %s's vertex graph", MESH[k])) {
                check_order(&G, MESH[k]);
                check_refined(&G, MESH[k], 0.05);
                bp__sparse_free(&al, &G);
            }
    }
}

/* (j) The symbolic analysis on several threads (bp__super_analyse: the
   etree and column counts, then the supernodes' rows, in the dissection's
   phases).  On the vertex graphs of camelhead and fertility: with the
   serial runner, every supernode's rows are its own vertices followed by
   the pattern below its last column, every one of its columns' patterns
   lies inside these, and a supernode whose columns do not each have the
   pattern of the next plus that next column (a relaxed one) holds no more
   explicit zeros than the rule allows, all as a brute-force
   symbolic factorization written here computes them (column j's pattern
   = G's entries below j in column j and the patterns of j's children
   without j, the parent the smallest row); then with the phases' tasks
   run backwards, odd-even and on a real pool of two threads, every array
   of the analysis (order, supernodes, rows, updates, offsets) is the
   serial one's. */
static int analyse(const bp__sparse *G, bp__factor *F, const bp__par *par)
{
    bp_allocator al;
    memset(&al, 0, sizeof al);
    memset(F, 0, sizeof *F);
    F->n = 2 * G->n;
    F->sn = (bp__super *)calloc(1, sizeof(bp__super));
    F->sn->bs = 2;
    return bp__super_analyse(&al, G, F, par, NULL, NULL) == BP_OK;
}

static int same_analysis(const bp__super *A, const bp__super *B)
{
    uint32_t n = A->nv, ns = A->ns;
    return A->nv == B->nv && ns == B->ns && A->ntask == B->ntask && A->maxcols == B->maxcols && A->maxrows == B->maxrows &&
           !memcmp(A->vperm, B->vperm, n * sizeof(uint32_t)) && !memcmp(A->snode, B->snode, n * sizeof(uint32_t)) &&
           !memcmp(A->first, B->first, (ns + 1) * sizeof(uint32_t)) && !memcmp(A->rp, B->rp, (ns + 1) * sizeof(uint32_t)) &&
           !memcmp(A->ri, B->ri, A->rp[ns] * sizeof(uint32_t)) && !memcmp(A->xp, B->xp, (ns + 1) * sizeof(size_t)) &&
           !memcmp(A->up, B->up, (ns + 1) * sizeof(uint32_t)) && !memcmp(A->uk, B->uk, A->up[ns] * sizeof(uint32_t)) &&
           !memcmp(A->uo, B->uo, A->up[ns] * sizeof(uint32_t));
}

/* Brute force: col[j] (sorted, malloc'd) the pattern of L below j in
   column j, for the order vperm of G. */
static uint32_t **brute_columns(const bp__sparse *G, const uint32_t *vperm, uint32_t *len)
{
    uint32_t n = G->n, j, p, c, i, *iperm = (uint32_t *)malloc(n * sizeof(uint32_t)), *mark = (uint32_t *)malloc(n * sizeof(uint32_t));
    uint32_t *head = (uint32_t *)malloc(n * sizeof(uint32_t)), *next = (uint32_t *)malloc(n * sizeof(uint32_t));
    uint32_t **col = (uint32_t **)calloc(n, sizeof(uint32_t *)), *buf = (uint32_t *)malloc(n * sizeof(uint32_t));
    for (j = 0; j < n; j++) { iperm[vperm[j]] = j; mark[j] = head[j] = BP__NONE; }
    for (j = 0; j < n; j++) {
        uint32_t m = 0;
        for (p = G->colp[vperm[j]]; p < G->colp[vperm[j] + 1]; p++) {
            uint32_t r = iperm[G->row[p]];
            if (r > j && mark[r] != j) { mark[r] = j; buf[m++] = r; }
        }
        for (c = head[j]; c != BP__NONE; c = next[c])
            for (i = 0; i < len[c]; i++)
                if (col[c][i] > j && mark[col[c][i]] != j) { mark[col[c][i]] = j; buf[m++] = col[c][i]; }
        qsort(buf, m, sizeof(uint32_t), bp__u32_cmp);
        col[j] = (uint32_t *)malloc((m ? m : 1) * sizeof(uint32_t));
        memcpy(col[j], buf, m * sizeof(uint32_t));
        len[j] = m;
        if (m) { next[j] = head[buf[0]]; head[buf[0]] = j; }
    }
    free(iperm); free(mark); free(head); free(next); free(buf);
    return col;
}

/* The relaxed amalgamation's rule, restated (CHOLMOD's thresholds in
   vertices of two columns): nc <= 2, or nc <= 8 with at most 80% explicit
   zeros, nc <= 24 with 10%, else 5%. */
static int relax_rule(uint32_t nc, double nz, double size)
{
    double z = 1 - nz / size;
    return nc <= 2 || (nc <= 8 && z < 0.8) || (nc <= 24 && z < 0.1) || z < 0.05;
}

static void check_against_brute(const bp__sparse *G, const bp__super *S, const char *what)
{
    uint32_t n = G->n, *len = (uint32_t *)malloc(n * sizeof(uint32_t)), **col = brute_columns(G, S->vperm, len), s, j, i, bad = 0;
    uint32_t nrelax = 0;
    for (s = 0; s < S->ns; s++) {
        uint32_t f = S->first[s], l = S->first[s + 1], m = S->rp[s + 1] - S->rp[s];
        const uint32_t *ri = S->ri + S->rp[s];
        if (m != (l - f) + len[l - 1]) { bad++; continue; }
        for (i = 0; i < l - f; i++) bad += ri[i] != f + i;
        for (i = 0; i < len[l - 1]; i++) bad += ri[l - f + i] != col[l - 1][i];
        {   /* every column's own pattern inside the stored one: below the
               diagonal block, the last column's rows (relaxed supernodes,
               bp__super_relax: a chain of the elimination tree) */
            uint32_t fund = 1;
            double nz = 0, size = (double)(l - f) * m - (double)(l - f) * (l - f - 1) / 2;
            for (j = f; j < l; j++) {
                uint32_t a = 0;
                nz += len[j] + 1;
                for (i = 0; i < len[j]; i++) {
                    uint32_t r = col[j][i];
                    if (r < l) continue;               /* in the dense diagonal block */
                    while (a < len[l - 1] && col[l - 1][a] < r) a++;
                    bad += a == len[l - 1] || col[l - 1][a] != r;
                }
                if (j + 1 < l)                          /* fundamental: j+1 and the next column's pattern */
                    fund &= len[j] == len[j + 1] + 1 && col[j][0] == j + 1 &&
                            memcmp(col[j] + 1, col[j + 1], len[j + 1] * sizeof(uint32_t)) == 0;
            }
            if (!fund) {                                /* merged: the rule allowed these explicit zeros */
                nrelax++;
                bad += !relax_rule(l - f, nz, size);
            }
        }
    }
    BPT_CHECK(bad == 0 && S->ns > 0, "%s: the supernodes' rows hold the brute-force pattern of L, and each relaxed one "
              "(%u of %u) the explicit zeros bp__super_relax allows (%u wrong)", what, nrelax, S->ns, bad);
    BPT_CHECK(nrelax > 0, "%s: relaxed supernodes in the analysis (%u)", what, nrelax);
    {   /* the update lists: under each J, every K with rows in J once, by
           increasing K, at K's first row in J; as many as the (K, J) pairs */
        uint32_t J, e, pairs = 0, wrong = 0;
        for (s = 0; s < S->ns; s++) {
            uint32_t last = BP__NONE, q;
            for (q = S->rp[s] + S->first[s + 1] - S->first[s]; q < S->rp[s + 1]; q++) {
                uint32_t t;
                for (t = 0; S->first[t + 1] <= S->ri[q]; t++) {}     /* the supernode of the row, by a scan */
                if (t != last) { pairs++; last = t; }
            }
        }
        for (J = 0; J < S->ns; J++)
            for (e = S->up[J]; e < S->up[J + 1]; e++) {
                uint32_t K = S->uk[e], q = S->rp[K] + S->uo[e], c0 = S->rp[K] + S->first[K + 1] - S->first[K];
                uint32_t r = S->ri[q];
                wrong += (e > S->up[J] && S->uk[e - 1] >= K) || K >= J || q < c0 || q >= S->rp[K + 1] || r < S->first[J] ||
                         r >= S->first[J + 1] || (q > c0 && S->ri[q - 1] >= S->first[J]);
            }
        BPT_CHECK(wrong == 0 && S->up[S->ns] == pairs, "%s: the update lists are every (K, J) pair once, by K (%u wrong, %u of %u)",
                  what, wrong, S->up[S->ns], pairs);
    }
    for (j = 0; j < n; j++) free(col[j]);
    free(col); free(len);
}

static void check_same_analysis(const bp__sparse *G, const bp__super *S0, const bp__par *par, const char *mesh, const char *how)
{
    bp_allocator al;
    bp__factor F1;
    memset(&al, 0, sizeof al);
    if (BPT_CHECK(analyse(G, &F1, par), "%s: analysed, %s", mesh, how)) {
        BPT_CHECK(same_analysis(S0, F1.sn), "%s: %s: every array of the analysis is the serial one's", mesh, how);
        bp__factor_free(&al, &F1);
    }
}

/* (l) GNP's counts against the row subtrees', in four orders. */
static void check_counts(const bp__sparse *G, const char *what)
{
    bp_allocator al;
    uint32_t n = G->n, k, o, *cnt = (uint32_t *)malloc(n * sizeof(uint32_t)), *ref = (uint32_t *)calloc(n, sizeof(uint32_t));
    uint32_t *parent = (uint32_t *)malloc(n * sizeof(uint32_t)), *mark = (uint32_t *)malloc(n * sizeof(uint32_t));
    uint32_t *perm = (uint32_t *)malloc(n * sizeof(uint32_t)), *iperm = (uint32_t *)malloc(n * sizeof(uint32_t));
    bp__ndnode tree[BP__ND_NODES];
    uint64_t rng = 88172645463325252ull;
    memset(&al, 0, sizeof al);
    for (o = 0; o < 4; o++) {
        static const char *HOW[] = { "the dissection's order", "the identity", "the reverse", "a random order" };
        bp__factor F;
        uint32_t wrong = 0;
        double nnz = 0;
        int ok = 1;
        if (o == 0) ok = bp__nd_order(&al, G, perm, tree, 1, NULL);
        for (k = 0; k < n && o > 0; k++) perm[k] = o == 2 ? n - 1 - k : k;
        for (k = n; o == 3 && k > 1; k--) {
            uint32_t r, t;
            rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
            r = (uint32_t)(rng % k); t = perm[k - 1]; perm[k - 1] = perm[r]; perm[r] = t;
        }
        for (k = 0; k < n; k++) iperm[perm[k]] = k;
        memset(&F, 0, sizeof F);
        F.perm = perm; F.iperm = iperm;
        bp__fact_etree(G, &F, parent, mark);
        memset(ref, 0, n * sizeof(uint32_t));
        for (k = 0; k < n; k++) mark[k] = BP__NONE;
        for (k = 0; k < n; k++) bp__row_count(G, &F, parent, mark, k, ref);
        ok = ok && bp__sym_counts_gnp(&al, G, &F, parent, cnt);
        for (k = 0; k < n && ok; k++) { wrong += cnt[k] != ref[k]; nnz += ref[k]; }
        BPT_CHECK(ok && wrong == 0 && nnz > n, "%s, %s: the column counts by Gilbert, Ng and Peyton are the row subtrees' "
                  "(%.0f entries below the diagonal; %u columns differ)", what, HOW[o], nnz, wrong);
    }
    free(cnt); free(ref); free(parent); free(mark); free(perm); free(iperm);
}

static void test_counts(void)
{
    static const char *MESH[] = { "tests/data/camelhead.off", "tests/data/fertility.off" };
    bp_allocator al;
    bp__sparse G;
    int k;
    memset(&al, 0, sizeof al);
    for (k = 0; k < 2; k++)
        if (BPT_CHECK(mesh_graph(MESH[k], &G), "counts: %s's vertex graph", MESH[k])) {
            check_counts(&G, MESH[k]);
            bp__sparse_free(&al, &G);
        }
    if (BPT_CHECK(components_graph(&G), "counts: the components graph")) {
        check_counts(&G, "shuffled components");
        bp__sparse_free(&al, &G);
    }
}

static void test_analysis(void)
{
    static const char *MESH[] = { "tests/data/camelhead.off", "tests/data/fertility.off" };
    bp_allocator al;
    int k, r;
    memset(&al, 0, sizeof al);
    for (k = 0; k < 2; k++) {
        bp__sparse G;
        bp__factor F0;
        if (!BPT_CHECK(mesh_graph(MESH[k], &G), "analysis: %s's vertex graph", MESH[k])) continue;
        if (BPT_CHECK(analyse(&G, &F0, NULL), "%s: analysed serially", MESH[k])) {
            BPT_CHECK(F0.sn->ntask > 1, "%s: the analysis has parallel phases (%u tasks)", MESH[k], F0.sn->ntask);
            check_against_brute(&G, F0.sn, MESH[k]);
            for (r = 0; r < 3; r++) {
                static const char *HOW[] = { "tasks backwards", "tasks odd-even", "a pool of two threads" };
                bp__par par = bp__par_serial();
                par.threads = 2;
                par.run = r ? bpt_odd_even_for : bpt_backwards_for;
#ifdef BP_USE_PTHREADS
                {
                    bp__pool *P = NULL;
                    if (r == 2) {
                        par = real_pool(&al, 2, &P);
                        if (!BPT_CHECK(P != NULL, "a pool of two threads")) break;
                    }
                    check_same_analysis(&G, F0.sn, &par, MESH[k], HOW[r]);
                    if (P) bp__pool_stop(&al, P);
                }
#else
                if (r < 2) check_same_analysis(&G, F0.sn, &par, MESH[k], HOW[r]);
#endif
            }
            bp__factor_free(&al, &F0);
        }
        bp__sparse_free(&al, &G);
    }
}

/* (c) flagged blocks2 but not in whole blocks: a tridiagonal matrix of odd
   and even size. */
static void test_fallback(void)
{
    bp_allocator al;
    uint32_t sz, i, bad;
    memset(&al, 0, sizeof al);
    for (sz = 7; sz <= 8; sz++) {
        bpt_trip tr[32];
        size_t nt = 0;
        bp__sparse A;
        bp__factor F;
        double b[8], x[8], z[8];
        memset(&A, 0, sizeof A);
        for (i = 0; i < sz; i++) {
            tr[nt].i = tr[nt].j = i; tr[nt++].v = 4;
            if (i + 1 < sz) { tr[nt].i = i; tr[nt].j = i + 1; tr[nt++].v = -1; tr[nt].i = i + 1; tr[nt].j = i; tr[nt++].v = -1; }
            b[i] = i + 1.0;
        }
        A.symmetric = 1;
        A.blocks2 = 1;
        bpt_from_triplets(&al, sz, tr, nt, &A);
        if (BPT_CHECK(bp__factorize(&al, &A, &F, &bad, NULL) == BP_OK && !F.sn,
                      "tridiagonal %u x %u flagged blocks2: the scalar factorization serves", sz, sz)) {
            bp__factor_solve(&F, b, x, z);
            BPT_CHECK(rel_residual(&A, x, b) < 1e-14, "tridiagonal %u: solved, residual %.3g", sz, rel_residual(&A, x, b));
            bp__factor_free(&al, &F);
        }
        bp__sparse_free(&al, &A);
    }
}

/* (d) projected Newton's matrix on camel_b. */
static void test_newton_matrix(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    bp_allocator a;
    bp__solver S;
    bp__newton N;
    memset(&opt, 0, sizeof opt);
    memset(&a, 0, sizeof a);
    if (!bpt_one_chart("tests/data/camel_b.obj", &mesh, &atlas, &opt, 1)) return;
    if (!BPT_CHECK(bp__solver_chart(&S, &a, &atlas.charts[0], &mesh, &opt, NULL, &err) == BP_OK, "camel_b solver")) {
        bp_atlas_free(&atlas);
        bp_mesh_free(&mesh, NULL);
        return;
    }
    S.eps = 4 * S.mean_edge;     /* many barrier pairs: their couplings join the pattern */
    if (BPT_CHECK(bp__newton_init(&N, &a, &S) == BP_OK, "Newton set-up")) {
        uint32_t n, i, bad, extra;
        double *b, *x, *xs, *z;
        bp__factor F, Fs;
        bp__par rev = bp__par_serial();
        rev.run = bpt_backwards_for;
        bp__newton_assemble(&N, &S, atlas.charts[0].uv);
        N.factored = 1;
        N.since_grow = 8;
        bp__newton_assemble(&N, &S, atlas.charts[0].uv);          /* the pairs' couplings now in the pattern */
        extra = (uint32_t)N.extra.count;
        n = N.H.n;
        BPT_CHECK(extra > 0 && N.H.blocks2, "camel_b Newton matrix: %u barrier couplings in the pattern, blocks2 set", extra);
        {   /* (h) the ordering of the matrix and of its vertex graph */
            bp__sparse G;
            check_order(&N.H, "camel_b Newton matrix");
            if (BPT_CHECK(bp__super_graph(&a, &N.H, &G) == 1, "camel_b vertex graph")) {
                check_order(&G, "camel_b vertex graph");
                bp__sparse_free(&a, &G);
            }
        }
        b = (double *)malloc(n * sizeof(double)); x = (double *)malloc(n * sizeof(double));
        xs = (double *)malloc(n * sizeof(double)); z = (double *)malloc(n * sizeof(double));
        for (i = 0; i < n; i++) b[i] = sin(1.0 + i);
        if (BPT_CHECK(bp__factorize(&a, &N.H, &F, &bad, NULL) == BP_OK && F.sn, "camel_b Newton matrix: supernodal")) {
            double res;
            bp__factor_solve(&F, b, x, z);
            res = rel_residual(&N.H, x, b);
            BPT_CHECK(res < 1e-6, "camel_b Newton matrix: |H x - b| / |b| = %.3g", res);
            N.H.blocks2 = 0;
            if (BPT_CHECK(bp__factorize(&a, &N.H, &Fs, &bad, NULL) == BP_OK, "camel_b Newton matrix: scalar")) {
                bp__factor_solve(&Fs, b, xs, z);
                BPT_CHECK(rel_diff(x, xs, n) < 1e-5, "camel_b Newton matrix: supernodal and scalar solutions agree, rel. diff "
                          "%.3g (scalar residual %.3g)", rel_diff(x, xs, n), rel_residual(&N.H, xs, b));
                bp__factor_free(&a, &Fs);
            }
            N.H.blocks2 = 1;
            {
                double *keep = (double *)malloc(F.sn->xp[F.sn->ns] * sizeof(double));
                memcpy(keep, F.sn->x, F.sn->xp[F.sn->ns] * sizeof(double));
                bp__fact_numeric(&a, &N.H, &F, NULL, &rev);
                BPT_CHECK(memcmp(keep, F.sn->x, F.sn->xp[F.sn->ns] * sizeof(double)) == 0,
                          "camel_b Newton matrix: refactored with tasks backwards, the same bits");
                check_simd(&N.H, &F, "camel_b Newton matrix");
                free(keep);
            }
            bp__factor_free(&a, &F);
        }
        free(b); free(x); free(xs); free(z);
        bp__newton_free(&a, &N);
    }
    bp__solver_free(&S);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

int main(void)
{
    quick = getenv("BP_TEST_QUICK") != NULL;
    test_random();
    test_scalar();
    test_fallback();
    test_order();
    test_newton_matrix();
    test_analysis();
    test_counts();
#if TEST_AVX
    if (__builtin_cpu_supports("avx"))
        BPT_CHECK(simd_compared >= 11, "(k) %u factors that took the AVX kernels compared without them", simd_compared);
    else
#endif
        printf("note test_sparse: no AVX on this processor or compiler: (k), AVX against the plain loops, not run\n");
    return bpt_finish();
}
