/* test_tutte.c - the start map and the sparse solver behind it.

   (a) The sparse direct solver (>>sparse) against dense Gaussian
       elimination written here: random symmetric positive definite
       matrices with a mesh-like pattern (graph Laplacian + positive
       diagonal) and random nonsymmetric, diagonally dominant M-matrices
       (the mean-value case), several sizes; the nested-dissection order is
       a permutation; the refined solution's residual is tiny.
   (b) The start map of every chart of every mesh in tests/data that can be
       flattened, with Tutte and with mean-value weights: exactly valid by
       the complete bp_check (positive triangles, disjoint boundary loops,
       one counter-clockwise loop, holes inside it), the outer loop on the
       circle of the chart's area in counter-clockwise order, spaced by 3D
       arc length, and every interior vertex at the weighted mean of its
       neighbours (the linear system really solved).  The larger meshes
       (hilbert, beetle, horse_cut) are included; a missing file is a
       counted failure.
   (c) The preconditioner of the optimizer (the rest-shape Laplacian of a
       real chart, factored and solved in phases along the dissection tree):
       the factor and the solve give the same bits under three task orders
       (serial, backwards, odd then even), the single-precision solve agrees
       with the double one, and the double one solves K r = q.  K itself,
       assembled in columns on the threads, against the triplet assembly
       (tests/bpt_triplets.h), pattern and bits, also with pins.
   (d) The mean-value system's Krylov solve (phase 6a): on the random
       M-matrices of (a) against dense elimination; on real charts its
       residual recomputed here, the LU's solution, the same bits when the
       tasks run backwards.
   (e) Phases 2, 3 and 5 (adjacency, weights, system), gathers per vertex
       chunk, against triangle-order scatters (written
       here), bit for bit, with the chunks run serially, backwards and odd
       then even.
   (f) BiCGSTAB on real charts: its products by A (a gather over A's
       rows) against a column scatter, the scaling D^-1 A and the
       symmetrized M (column chunks) against serial loops, and the whole
       iteration against a serial reference (all
       written here), bit for bit, with the tasks run backwards and odd
       then even.
   With BP_TEST_QUICK set (make test), (d), (e) and (f) leave out
   horse_cut (camel_b, camelhead and face_holes stay); make check runs
   them on it too. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"
#include "bpt_triplets.h"

static int quick = 0;   /* BP_TEST_QUICK: the short form (make test) */

#include <math.h>
#include <stdlib.h>
#include <string.h>

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double rng_unit(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

/* Dense solve of an n x n system (row-major a, overwritten) with partial
   pivoting, the independent reference. */
static void dense_solve(int n, double *a, double *b)
{
    int i, j, k;
    for (k = 0; k < n; k++) {
        int p = k;
        for (i = k + 1; i < n; i++) if (fabs(a[i * n + k]) > fabs(a[p * n + k])) p = i;
        if (p != k) {
            double t;
            for (j = 0; j < n; j++) { t = a[k * n + j]; a[k * n + j] = a[p * n + j]; a[p * n + j] = t; }
            t = b[k]; b[k] = b[p]; b[p] = t;
        }
        for (i = k + 1; i < n; i++) {
            double f = a[i * n + k] / a[k * n + k];
            for (j = k; j < n; j++) a[i * n + j] -= f * a[k * n + j];
            b[i] -= f * b[k];
        }
    }
    for (k = n - 1; k >= 0; k--) {
        double s = b[k];
        for (j = k + 1; j < n; j++) s -= a[k * n + j] * b[j];
        b[k] = s / a[k * n + k];
    }
}

/* A random planar-ish graph on a jittered grid (each vertex linked to its
   right, upper and one diagonal neighbour, some edges dropped), as a
   matrix: symmetric -> Laplacian with weights + diagonal shift;
   nonsymmetric -> row weights differ, diagonal = row sum + shift. */
static double krylov_worst = 0;     /* (a) the Krylov solve against dense elimination */

static void test_solver(int w, int h, int symmetric, double *worst_err, double *worst_res, int *perm_ok)
{
    int n = w * h, i, j;
    double *dense = (double *)calloc((size_t)n * n, sizeof(double)), *copy = (double *)malloc((size_t)n * n * sizeof(double));
    double *b = (double *)calloc(n, sizeof(double)), *xd = (double *)calloc(n, sizeof(double));
    double *x = (double *)malloc(n * sizeof(double)), *work = (double *)malloc(3 * n * sizeof(double));
    bpt_trip *t = (bpt_trip *)malloc((size_t)8 * n * sizeof(bpt_trip));
    size_t nt = 0;
    bp__sparse A;
    bp__factor F;
    bp_allocator a;
    uint32_t bad = 0, *seen;
    memset(&a, 0, sizeof a);
    memset(&A, 0, sizeof A);
    for (j = 0; j < h; j++)
        for (i = 0; i < w; i++) {
            int v = j * w + i, nb[3], k;
            nb[0] = i + 1 < w ? v + 1 : -1;
            nb[1] = j + 1 < h ? v + w : -1;
            nb[2] = (i + 1 < w && j + 1 < h) ? v + w + 1 : -1;
            for (k = 0; k < 3; k++) {
                double wij, wji;
                if (nb[k] < 0 || (k == 2 && rng_unit() < 0.5) || rng_unit() < 0.05) continue;
                wij = 0.1 + rng_unit();
                wji = symmetric ? wij : 0.1 + rng_unit();
                dense[v * n + nb[k]] -= wij; dense[v * n + v] += wij;
                dense[nb[k] * n + v] -= wji; dense[nb[k] * n + nb[k]] += wji;
            }
        }
    for (i = 0; i < n; i++) dense[i * n + i] += 0.01 + 0.1 * rng_unit();   /* Dirichlet-like shift */
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++)
            if (dense[i * n + j] != 0 || i == j) { t[nt].i = (uint32_t)i; t[nt].j = (uint32_t)j; t[nt++].v = dense[i * n + j]; }
    A.symmetric = symmetric;
    bpt_from_triplets(&a, (uint32_t)n, t, nt, &A);
    for (i = 0; i < n; i++) b[i] = xd[i] = rng_unit() - 0.5;
    memcpy(copy, dense, (size_t)n * n * sizeof(double));
    dense_solve(n, copy, xd);
    if (!symmetric) {                  /* the Krylov solve of phase 6a, both right-hand sides b */
        bp__tutte T;
        double kerr = 0, kscale = 0;
        memset(&T, 0, sizeof T);
        T.A = A;
        T.nfree = (uint32_t)n;
        T.rhs = (double *)malloc(2 * n * sizeof(double));
        T.sol = (double *)malloc(2 * n * sizeof(double));
        for (i = 0; i < n; i++) T.rhs[i] = T.rhs[n + i] = b[i];
        if (bp__tutte_krylov(&a, &T, NULL) == 1)
            for (i = 0; i < 2 * n; i++) {
                if (fabs(T.sol[i] - xd[i % n]) > kerr) kerr = fabs(T.sol[i] - xd[i % n]);
                if (fabs(xd[i % n]) > kscale) kscale = fabs(xd[i % n]);
            }
        else kerr = HUGE_VAL, kscale = 1;
        if (kerr / kscale > krylov_worst) krylov_worst = kerr / kscale;
        free(T.rhs); free(T.sol);
    }
    if (bp__factorize(&a, &A, &F, &bad, NULL) == BP_OK) {
        double err = 0, res = 0, scale = 0;
        seen = (uint32_t *)calloc(n, sizeof(uint32_t));
        for (i = 0; i < n; i++) if (F.perm[i] < (uint32_t)n) seen[F.perm[i]]++;
        for (i = 0; i < n; i++) if (seen[i] != 1) *perm_ok = 0;
        free(seen);
        bp__solve_refined(&A, &F, b, x, work);
        for (i = 0; i < n; i++) {
            double r = b[i];
            for (j = 0; j < n; j++) r -= dense[i * n + j] * x[j];
            if (fabs(r) > res) res = fabs(r);
            if (fabs(x[i] - xd[i]) > err) err = fabs(x[i] - xd[i]);
            if (fabs(xd[i]) > scale) scale = fabs(xd[i]);
        }
        if (err / scale > *worst_err) *worst_err = err / scale;
        if (res > *worst_res) *worst_res = res;
        bp__factor_free(&a, &F);
    } else {
        *worst_err = HUGE_VAL;
    }
    bp__sparse_free(&a, &A);
    free(dense); free(copy); free(b); free(xd); free(x); free(work); free(t);
}

/* Tutte/Floater checks on one chart; returns the number of failed checks. */
static int check_start(const bp_mesh *m, bp_chart *ch, int mvc, const char *name, uint32_t c)
{
    bp_options o;
    bp_error e;
    bp_check_report r;
    uint32_t i, j, k;
    double R, total = 0, acc = 0, worst_r = 0, worst_a = 0, worst_mean = 0;
    int bad = 0, ccw = 1;
    memset(&o, 0, sizeof o);
    o.init = mvc ? BP_INIT_MEAN_VALUE : BP_INIT_TUTTE;
    if (!BPT_CHECK(bp_chart_init(ch, m, &o, &e) == BP_OK, "%s chart %u (%s): start map: %s", name, c,
                   mvc ? "mean value" : "Tutte", e.message))
        return 1;
    if (bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &r, NULL) != BP_OK) bad++;
    if (r.flipped || r.degenerate || r.nonfinite || r.boundary_intersections || r.loop_orientation || r.nested) bad++;
    /* the outer loop: on the circle of the chart's area, by 3D arc length */
    R = sqrt(ch->area3d / 3.14159265358979323846);
    for (j = ch->loop_start[0]; j < ch->loop_start[1]; j++) {
        uint32_t va = ch->loop_vertices[j], vb = ch->loop_vertices[j + 1 < ch->loop_start[1] ? j + 1 : 0];
        total += bp__dist3(bp__pos(m, ch->vertex[va]), bp__pos(m, ch->vertex[vb]));
    }
    for (j = ch->loop_start[0]; j < ch->loop_start[1]; j++) {
        uint32_t va = ch->loop_vertices[j], vb = ch->loop_vertices[j + 1 < ch->loop_start[1] ? j + 1 : 0];
        double x = ch->uv[2 * va], y = ch->uv[2 * va + 1], ang = atan2(y, x), want = 2 * 3.14159265358979323846 * acc / total;
        double d = fabs(remainder(ang - want, 2 * 3.14159265358979323846));
        if (fabs(sqrt(x * x + y * y) - R) > worst_r) worst_r = fabs(sqrt(x * x + y * y) - R);
        if (d > worst_a) worst_a = d;
        acc += bp__dist3(bp__pos(m, ch->vertex[va]), bp__pos(m, ch->vertex[vb]));
        if (j > ch->loop_start[0] && j + 1 < ch->loop_start[1]) {
            const double *p = ch->uv + 2 * ch->loop_vertices[j - 1], *q = ch->uv + 2 * va, *s = ch->uv + 2 * vb;
            if (bp_orient2d(p, q, s) < 0) ccw = 0;
        }
    }
    /* Tutte only: an interior vertex is the mean of its neighbours (holes
       make fan-centre neighbours, so only vertices not on any loop whose
       neighbours are not on holes are tested, via the chart's triangles) */
    if (!mvc) {
        uint32_t *onb = (uint32_t *)calloc(ch->num_vertices, sizeof(uint32_t));
        double *sx = (double *)calloc(2 * (size_t)ch->num_vertices, sizeof(double));
        uint32_t *deg = (uint32_t *)calloc(ch->num_vertices, sizeof(uint32_t));
        bp__edge_rec *er = (bp__edge_rec *)malloc(3 * (size_t)ch->num_triangles * sizeof(bp__edge_rec));
        size_t ne = 0, q;
        for (j = 0; j < ch->loop_start[ch->num_loops]; j++) onb[ch->loop_vertices[j]] = 1;
        for (i = 0; i < ch->num_triangles; i++)
            for (k = 0; k < 3; k++) {
                uint32_t va = ch->triangles[3 * i + k], vb = ch->triangles[3 * i + (k + 1) % 3];
                er[ne].lo = va < vb ? va : vb; er[ne].hi = va < vb ? vb : va; er[ne].ce = 0; ne++;
            }
        qsort(er, ne, sizeof *er, bp__edge_cmp);
        for (q = 0; q < ne; q++) {
            if (q > 0 && er[q].lo == er[q - 1].lo && er[q].hi == er[q - 1].hi) continue;
            sx[2 * er[q].lo] += ch->uv[2 * er[q].hi]; sx[2 * er[q].lo + 1] += ch->uv[2 * er[q].hi + 1]; deg[er[q].lo]++;
            sx[2 * er[q].hi] += ch->uv[2 * er[q].lo]; sx[2 * er[q].hi + 1] += ch->uv[2 * er[q].lo + 1]; deg[er[q].hi]++;
        }
        for (i = 0; i < ch->num_vertices; i++) {
            double dx, dy;
            if (onb[i] || !deg[i]) continue;
            dx = sx[2 * i] / deg[i] - ch->uv[2 * i];
            dy = sx[2 * i + 1] / deg[i] - ch->uv[2 * i + 1];
            if (sqrt(dx * dx + dy * dy) > worst_mean) worst_mean = sqrt(dx * dx + dy * dy);
        }
        free(onb); free(sx); free(deg); free(er);
    }
    if (worst_r > 1e-12 * R || worst_a > 1e-12 || !ccw || worst_mean > 1e-9 * R) bad++;
    BPT_CHECK(!bad, "%s chart %u (%s, %u triangles, %u loops): exactly bijective (flip %u deg %u bnd %u loops %u nested %u), "
              "outer loop on the circle (radius error %.1e R, angle error %.1e), counter-clockwise, %s%.1e R",
              name, c, mvc ? "mean value" : "Tutte", ch->num_triangles, ch->num_loops, r.flipped, r.degenerate,
              r.boundary_intersections, r.loop_orientation, r.nested, worst_r / R, worst_a,
              mvc ? "" : "interior vertices at the mean of their neighbours within ", mvc ? 0.0 : worst_mean / R);
    return bad;
}

/* The solve plan against a linear scan of every separator row: the first
   cut is the row's start, the last one its first entry at or above b, the
   cuts increase, the column ranges of one separator never overlap (so the
   backward tasks write disjoint sums), and each range holds at most its
   share of the entries plus one column's worth. */
static void check_plan(const char *path, const bp__factor *F)
{
    uint32_t k, i, r, p, seps = 0, ranges = 0, bad = 0, worst_node = 0;
    double worst = 0;
    for (k = 0; k < BP__ND_NODES; k++) {
        const bp__ndnode *N = &F->tree[k];
        uint32_t lo_col[BP__PLAN_RANGES], hi_col[BP__PLAN_RANGES], colmax = 0, c;
        size_t ent[BP__PLAN_RANGES], e = 0;
        if (!N->ncut) continue;
        seps++;
        ranges += N->ncut;
        bad += N->ncut > BP__PLAN_RANGES;
        if (N->ncut > BP__PLAN_RANGES) continue;
        for (r = 0; r < N->ncut; r++) { lo_col[r] = UINT32_MAX; hi_col[r] = 0; ent[r] = 0; }
        for (i = N->b; i < N->hi; i++) {
            const uint32_t *cut = bp__row_cuts(F, N, i);
            uint32_t first_b = F->Rp[i];
            while (first_b < F->Rp[i + 1] && F->Ri[first_b] < N->b) first_b++;
            bad += cut[0] != F->Rp[i] || cut[N->ncut] != first_b;
            for (r = 0; r < N->ncut; r++) {
                bad += cut[r] > cut[r + 1];
                for (p = cut[r]; p < cut[r + 1]; p++) {
                    if (F->Ri[p] < lo_col[r]) lo_col[r] = F->Ri[p];
                    if (F->Ri[p] > hi_col[r]) hi_col[r] = F->Ri[p];
                    ent[r]++;
                }
            }
        }
        for (c = N->lo; c < N->b; c++) {               /* the densest column */
            uint32_t m = 0;
            for (i = N->b; i < N->hi; i++)
                for (p = F->Rp[i]; p < F->Rp[i + 1]; p++) m += F->Ri[p] == c;
            if (m > colmax) colmax = m;
        }
        for (r = 0; r < N->ncut; r++) e += ent[r];
        for (r = 0; r < N->ncut; r++) {
            double share = (double)ent[r] / ((double)e / N->ncut);
            bad += r + 1 < N->ncut && ent[r] && ent[r + 1] && hi_col[r] >= lo_col[r + 1];
            bad += ent[r] > e / N->ncut + colmax + 1;
            if (share > worst) { worst = share; worst_node = k; }
        }
    }
    BPT_CHECK(seps > 0 && bad == 0, "%s: solve plan of %u separators, %u column ranges: the cuts are where a scan puts "
              "them, the ranges are disjoint and within one column of their share (largest %.2f of the mean, node %u)",
              path, seps, ranges, worst, worst_node);
}

/* (c) The preconditioner's K as the triplet assembly built it (each
   corner's 1/2 cot into four triplets, triangle by triangle, then the
   regularizer; pins keep only it), by the tests' own bpt_from_triplets:
   bp__laplacian assembles it straight into columns on the threads and must
   give the same pattern and the same bits. */
static int ref_laplacian(const bp__solver *S, const double *rw, const uint32_t *pidx, bp__sparse *R)
{
    bp_allocator a = bp__allocator_of(NULL);
    bpt_trip *t = (bpt_trip *)malloc((12 * (size_t)S->nt + S->nv) * sizeof *t);
    size_t n = 0;
    uint32_t f, i;
    double diag = 0;
    int ok;
    if (!t) return 0;
    for (f = 0; f < S->nt; f++) {
        const double *r = rw + 3 * (size_t)f;
        double P[3][2], area2 = r[0] * r[2];
        int c;
        P[0][0] = 0; P[0][1] = 0; P[1][0] = r[0]; P[1][1] = 0; P[2][0] = r[1]; P[2][1] = r[2];
        for (c = 0; c < 3; c++) {
            int j = (c + 1) % 3, k = (c + 2) % 3;
            double ux = P[j][0] - P[c][0], uy = P[j][1] - P[c][1], vx = P[k][0] - P[c][0], vy = P[k][1] - P[c][1];
            double w = 0.5 * (ux * vx + uy * vy) / area2;
            uint32_t vj = S->tri[3 * (size_t)f + j], vk = S->tri[3 * (size_t)f + k];
            int hj = pidx && pidx[vj] != BP__NONE, hk = pidx && pidx[vk] != BP__NONE;
            if (!hj && !hk) {
                t[n].i = vj; t[n].j = vk; t[n++].v = -w;
                t[n].i = vk; t[n].j = vj; t[n++].v = -w;
            }
            if (!hj) { t[n].i = vj; t[n].j = vj; t[n++].v = w; }
            if (!hk) { t[n].i = vk; t[n].j = vk; t[n++].v = w; }
            diag += 2 * w;
        }
    }
    for (i = 0; i < S->nv; i++)
        { t[n].i = i; t[n].j = i; t[n++].v = (pidx && pidx[i] != BP__NONE ? 1 : 1e-8) * diag / S->nv; }
    memset(R, 0, sizeof *R);
    ok = bpt_from_triplets(&a, S->nv, t, n, R);
    free(t);
    return ok;
}

static int same_matrix(const bp__sparse *A, const bp__sparse *B)
{
    return A->n == B->n && !memcmp(A->colp, B->colp, ((size_t)A->n + 1) * sizeof(uint32_t)) &&
           !memcmp(A->row, B->row, A->colp[A->n] * sizeof(uint32_t)) &&
           !memcmp(A->val, B->val, A->colp[A->n] * sizeof(double));
}

/* (c) The same with every fifth vertex pinned (and the first and the
   last): a pinned vertex's column holds only its diagonal and no free
   column a row of it, serially and with the tasks run backwards. */
static void pins_laplacian(const char *path, bp__solver *S, const double *rw)
{
    static const bp_parallel_for_fn orders[2] = { bp__serial_for, bpt_backwards_for };
    bp_allocator a = bp__allocator_of(NULL);
    bp_parallel_for_fn keep = S->par.run;
    uint32_t *pidx = (uint32_t *)malloc((size_t)S->nv * sizeof(uint32_t)), v, np = 0, p, only_diag = 1;
    bp__sparse K, R;
    bp__factor F;
    int k, same = 1, ok = pidx != NULL;
    memset(&R, 0, sizeof R);
    for (v = 0; ok && v < S->nv; v++) {
        pidx[v] = v % 5 == 0 || v + 1 == S->nv ? np : BP__NONE;
        np += pidx[v] != BP__NONE;
    }
    ok = ok && ref_laplacian(S, rw, pidx, &R);
    for (k = 0; ok && k < 2; k++) {
        S->par.run = orders[k];
        memset(&K, 0, sizeof K);
        memset(&F, 0, sizeof F);
        ok = bp__laplacian(&a, S, rw, pidx, &K, &F, NULL, NULL) == BP_OK;
        same &= ok && same_matrix(&K, &R);
        for (v = 0; ok && v < S->nv; v++)
            for (p = K.colp[v]; p < K.colp[v + 1]; p++)
                if (K.row[p] != v && (pidx[v] != BP__NONE || pidx[K.row[p]] != BP__NONE)) only_diag = 0;
        bp__sparse_free(&a, &K);
        bp__factor_free(&a, &F);
    }
    S->par.run = keep;
    BPT_CHECK(ok && same && only_diag, "%s with %u of %u vertices pinned: K in columns is the triplet assembly's, "
              "pattern and bits, serially and backwards; pinned vertices couple to nothing", path, np, S->nv);
    if (R.colp) bp__sparse_free(&a, &R);
    free(pidx);
}

static void check_precondition(const char *path)
{
    static const bp_parallel_for_fn orders[3] = { bp__serial_for, bpt_backwards_for, bpt_odd_even_for };
    bp_mesh m;
    bp_atlas at;
    bp_error e;
    bp_options o;
    bp_allocator a = bp__allocator_of(NULL);
    bp__solver S;
    bp__sparse K[3];
    bp__factor F[3], Fd;
    double *rw, *q, *r[3], *z, *rd, *col, *work, mean[2] = { 0, 0 }, err = 0, big = 0, res = 0, qmax = 0;
    uint32_t c, best = 0, n, i, j, p, bad;
    int k, same_factor = 1, same_solve = 1, nodes, same_k = 1, ok_ref;
    bp__sparse R;
    FILE *f = fopen(path, "rb");
    if (!BPT_CHECK(f != NULL, "%s: present (tests/data is part of the repository; a missing file is a failure, "
                   "not a skip)", path)) return;
    fclose(f);
    memset(&o, 0, sizeof o);
    if (!BPT_CHECK(bp_read_mesh(path, &m, NULL, &e) == BP_OK, "%s: read: %s", path, e.message)) return;
    if (!BPT_CHECK(bp_atlas_build(&at, &m, &o, &e) == BP_OK, "%s: charts: %s", path, e.message)) {
        bp_mesh_free(&m, NULL);
        return;
    }
    for (c = 0; c < at.num_charts; c++) if (at.charts[c].num_triangles > at.charts[best].num_triangles) best = c;
    rw = (double *)malloc(3 * sizeof(double) * at.charts[best].num_triangles);
    bp__solver_chart(&S, &a, &at.charts[best], &m, &o, rw, &e);
    n = S.nv;
    q = (double *)malloc(2 * sizeof(double) * n);
    z = (double *)malloc(4 * sizeof(double) * n);
    rd = (double *)malloc(2 * sizeof(double) * n);
    col = (double *)malloc(2 * sizeof(double) * n);
    work = (double *)malloc(3 * sizeof(double) * n);
    for (i = 0; i < 2 * n; i++) { q[i] = rng_unit() - 0.5; mean[i & 1] += q[i] / n; }
    for (i = 0; i < 2 * n; i++) { q[i] -= mean[i & 1]; if (fabs(q[i]) > qmax) qmax = fabs(q[i]); }  /* no translation part */
    ok_ref = ref_laplacian(&S, rw, NULL, &R);
    for (k = 0; k < 3; k++) {
        S.par.run = orders[k];
        S.par.user = NULL;
        memset(&K[k], 0, sizeof K[k]);
        BPT_CHECK(bp__laplacian(&a, &S, rw, NULL, &K[k], &F[k], NULL, NULL) == BP_OK, "%s: Laplacian factored (order %d)", path, k);
        same_k &= same_matrix(&K[k], &R);
        r[k] = (double *)malloc(2 * sizeof(double) * n);
        bp__precondition(&F[k], &S.par, q, r[k], z);
        if (k > 0) {
            same_factor &= F[k].Rp[n] == F[0].Rp[n] && !memcmp(F[k].Ri, F[0].Ri, F[0].Rp[n] * sizeof(uint32_t)) &&
                           !memcmp(F[k].Rxf, F[0].Rxf, F[0].Rp[n] * sizeof(float)) &&
                           !memcmp(F[k].D, F[0].D, n * sizeof(double));
            same_solve &= !memcmp(r[k], r[0], 2 * n * sizeof(double));
        }
    }
    BPT_CHECK(ok_ref && same_k, "%s: K assembled in columns on the threads is the triplet assembly's K, pattern and "
              "bits, under three task orders (nnz %u)", path, R.colp ? R.colp[n] : 0);
    pins_laplacian(path, &S, rw);
    for (nodes = 0, i = 0; i < BP__ND_NODES; i++) nodes += F[0].tree[i].used && F[0].tree[i].split;
    BPT_CHECK(same_factor, "%s (%u unknowns, %d separators in the phase tree, nnz(L) %u): the factor has the same bits "
              "under three task orders", path, n, nodes, F[0].Rp[n]);
    BPT_CHECK(same_solve, "%s: the preconditioner solve has the same bits under three task orders", path);
    check_plan(path, &F[0]);
    /* against the double factor and its serial solve, per coordinate */
    BPT_CHECK(bp__factorize(&a, &K[0], &Fd, &bad, NULL) == BP_OK, "%s: double factor", path);
    for (j = 0; j < 2; j++) {
        double *b = work, *x = work + n;
        for (i = 0; i < n; i++) b[i] = q[2 * i + j];
        bp__factor_solve(&Fd, b, x, z);
        for (i = 0; i < n; i++) rd[2 * i + j] = x[i];
    }
    for (i = 0; i < 2 * n; i++) {
        if (fabs(r[0][i] - rd[i]) > err) err = fabs(r[0][i] - rd[i]);
        if (fabs(rd[i]) > big) big = fabs(rd[i]);
    }
    for (i = 0; i < 2 * n; i++) col[i] = 0;                    /* K rd */
    for (j = 0; j < n; j++)
        for (p = K[0].colp[j]; p < K[0].colp[j + 1]; p++) {
            col[2 * K[0].row[p]] += K[0].val[p] * rd[2 * j];
            col[2 * K[0].row[p] + 1] += K[0].val[p] * rd[2 * j + 1];
        }
    for (i = 0; i < 2 * n; i++) if (fabs(col[i] - q[i]) > res) res = fabs(col[i] - q[i]);
    BPT_CHECK(err < 1e-3 * big, "%s: the single-precision solve matches the double one to 1e-3 (float L; max difference %.2g of max |r| %.2g)",
              path, err, big);
    BPT_CHECK(res < 1e-8 * qmax, "%s: the double factor solves K r = q (residual %.2g of max |q| %.2g)", path, res, qmax);
    for (k = 0; k < 3; k++) { bp__factor_free(&a, &F[k]); bp__sparse_free(&a, &K[k]); free(r[k]); }
    bp__factor_free(&a, &Fd);
    bp__sparse_free(&a, &R);
    bp__solver_free(&S);
    free(rw); free(q); free(z); free(rd); free(col); free(work);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

/* (d) Phase 6a on the largest chart of a real mesh: BiCGSTAB preconditioned
   by the Cholesky of the symmetrized matrix converges; its residual,
   recomputed here, is below BP__KRYLOV_TOL; the LU of phase 6 gives the
   same solution to the conditioning's rounding; the same bits when the
   tasks run backwards. */
/* (f) BiCGSTAB's products by A are gathers over A's rows in row chunks,
   its vector updates run in chunks, its dot products share passes: here
   a column scatter and a whole serial iteration, written out in plain
   loops, against the header's, bit for bit,
   with the tasks run backwards and odd then even. */
static void ref_spmv2(const bp__sparse *A, const double *x, double *y)
{
    uint32_t j, p;
    memset(y, 0, 2 * (size_t)A->n * sizeof(double));
    for (j = 0; j < A->n; j++)
        for (p = A->colp[j]; p < A->colp[j + 1]; p++) {
            y[2 * (size_t)A->row[p]] += A->val[p] * x[2 * (size_t)j];
            y[2 * (size_t)A->row[p] + 1] += A->val[p] * x[2 * (size_t)j + 1];
        }
}

static void ref_dot2(const double *u, const double *v, size_t n, double *d)
{
    size_t i;
    d[0] = d[1] = 0;
    for (i = 0; i < n; i++) { d[0] += u[2 * i] * v[2 * i]; d[1] += u[2 * i + 1] * v[2 * i + 1]; }
}

static int ref_done(const bp__sparse *A, const double *b, const double *x, double *r)
{
    double rr[2], bb[2];
    size_t i, n = A->n;
    ref_spmv2(A, x, r);
    for (i = 0; i < 2 * n; i++) r[i] = b[i] - r[i];
    ref_dot2(r, r, n, rr);
    ref_dot2(b, b, n, bb);
    return rr[0] <= BP__KRYLOV_TOL * BP__KRYLOV_TOL * bb[0] && rr[1] <= BP__KRYLOV_TOL * BP__KRYLOV_TOL * bb[1];
}

static int ref_bicgstab(const bp__sparse *A, const bp__factor *K, const double *b, double *x)
{
    size_t n = A->n, i, m = 2 * n;
    double *buf = (double *)malloc((12 * n + 1) * sizeof(double)), *z = (double *)malloc((4 * n + 1) * sizeof(double));
    double *r, *rh, *p, *v, *ph, *t, rho[2] = {1, 1}, al[2] = {1, 1}, om[2] = {1, 1};
    int it, c, ok = -1, live[2] = {1, 1};
    bp__par serial = bp__par_serial();
    r = buf; rh = r + m; p = rh + m; v = p + m; ph = v + m; t = ph + m;
    for (i = 0; i < m; i++) { x[i] = 0; r[i] = rh[i] = b[i]; p[i] = v[i] = 0; }
    for (it = 1; it <= BP__KRYLOV_ITERS; it++) {
        double rn[2], d[2], e[2];
        ref_dot2(rh, r, n, rn);
        for (c = 0; c < 2; c++) {
            double beta = live[c] ? (rn[c] / rho[c]) * (al[c] / om[c]) : 0;
            if (live[c] && !(beta - beta == 0)) goto done;
            rho[c] = rn[c];
            for (i = c; i < m; i += 2) p[i] = live[c] ? r[i] + beta * (p[i] - om[c] * v[i]) : 0;
        }
        bp__precondition(K, &serial, p, ph, z);
        ref_spmv2(A, ph, v);
        ref_dot2(rh, v, n, d);
        for (c = 0; c < 2; c++) {
            al[c] = live[c] ? rho[c] / d[c] : 0;
            if (!(al[c] - al[c] == 0)) goto done;
            for (i = c; i < m; i += 2) { x[i] += al[c] * ph[i]; r[i] -= al[c] * v[i]; }
        }
        bp__precondition(K, &serial, r, ph, z);
        ref_spmv2(A, ph, t);
        ref_dot2(t, r, n, d);
        ref_dot2(t, t, n, e);
        for (c = 0; c < 2; c++) {
            om[c] = live[c] && e[c] > 0 ? d[c] / e[c] : 0;
            if (live[c] && !(om[c] != 0 && om[c] - om[c] == 0)) live[c] = 0;
            for (i = c; i < m; i += 2) { x[i] += om[c] * ph[i]; r[i] -= om[c] * t[i]; }
        }
        ref_dot2(r, r, n, d);
        ref_dot2(b, b, n, e);
        for (c = 0; c < 2; c++)
            if (live[c] && d[c] <= 0.01 * BP__KRYLOV_TOL * BP__KRYLOV_TOL * e[c]) live[c] = 0;
        if ((!live[0] && !live[1]) || it % 10 == 0) {
            if (ref_done(A, b, x, t)) { ok = it; break; }
            if (!live[0] && !live[1]) break;
        }
    }
done:
    free(buf);
    free(z);
    return ok;
}

/* The symmetrized M of phase 6a computed serially: the row
   sums scattered column by column, the transposes by a cursor per row. */
static int ref_symmetric(const bp__sparse *A, bp__sparse *M)
{
    uint32_t n = A->n, j, p, *tpos = (uint32_t *)malloc((A->colp[n] + 1) * sizeof(uint32_t));
    uint32_t *cur = (uint32_t *)malloc(((size_t)n + 1) * sizeof(uint32_t));
    double *fix = (double *)calloc((size_t)n + 1, sizeof(double));
    memset(M, 0, sizeof *M);
    M->val = (double *)malloc((A->colp[n] + 1) * sizeof(double));
    if (!tpos || !cur || !fix || !M->val) { free(tpos); free(cur); free(fix); free(M->val); M->val = NULL; return 0; }
    for (j = 0; j < n; j++) cur[j] = A->colp[j];
    for (j = 0; j < n; j++)
        for (p = A->colp[j]; p < A->colp[j + 1]; p++) tpos[p] = cur[A->row[p]]++;
    for (j = 0; j < n; j++)
        for (p = A->colp[j]; p < A->colp[j + 1]; p++) fix[A->row[p]] += A->val[p];
    for (j = 0; j < n; j++) {
        uint32_t d = 0xffffffffu;
        double off = 0;
        for (p = A->colp[j]; p < A->colp[j + 1]; p++) {
            if (A->row[p] == j) { d = p; continue; }
            M->val[p] = 0.5 * (A->val[p] + A->val[tpos[p]]);
            off -= M->val[p];
        }
        if (d != 0xffffffffu) M->val[d] = fix[j] + off;
    }
    free(tpos); free(cur); free(fix);
    return 1;
}

/* Phase 6a's set-up on the threads (bp__tutte_scaled, bp__tutte_symmetric)
   against the serial loops written here, bit for bit, with the column
   chunks run backwards and odd then even. */
static void same_scaled(const char *path, const bp__tutte *T, const double *sval, const double *b)
{
    uint32_t n = T->nfree, nnz = T->A.colp[n], order;
    double *v = (double *)malloc((nnz + 1) * sizeof(double)), *bb = (double *)malloc((2 * (size_t)n + 1) * sizeof(double));
    double *dg = (double *)malloc(((size_t)n + 1) * sizeof(double));
    bp__par par = bp__par_serial();
    int same = v && bb && dg;
    par.threads = 2;
    for (order = 0; same && order < 2; order++) {
        par.run = order ? bpt_odd_even_for : bpt_backwards_for;
        memset(v, 0xff, nnz * sizeof(double));
        bp__tutte_scaled(&T->A, T->rhs, &par, v, bb, dg);
        same &= !memcmp(v, sval, nnz * sizeof(double)) && !memcmp(bb, b, 2 * (size_t)n * sizeof(double));
    }
    BPT_CHECK(same, "%s: D^-1 A and D^-1 b in column chunks (backwards, odd then even) are the serial loops' bits "
              "(%u unknowns, %u chunks)", path, n, bp__nchunks(n, BP__VERT_CHUNK));
    free(v); free(bb); free(dg);
}

static void same_symmetric(const char *path, const bp__sparse *As)
{
    bp_allocator a;
    bp__sparse M, R;
    bp__par par = bp__par_serial();
    uint32_t order;
    int same = ref_symmetric(As, &R);
    memset(&a, 0, sizeof a);
    par.threads = 2;
    for (order = 0; same && order < 3; order++) {
        par.run = order == 2 ? bp__serial_for : order ? bpt_odd_even_for : bpt_backwards_for;
        same &= bp__tutte_symmetric(&a, As, &M, order == 2 ? NULL : &par) &&
                !memcmp(M.colp, As->colp, ((size_t)As->n + 1) * sizeof(uint32_t)) &&
                !memcmp(M.row, As->row, As->colp[As->n] * sizeof(uint32_t)) &&
                !memcmp(M.val, R.val, As->colp[As->n] * sizeof(double));
        bp__sparse_free(&a, &M);
    }
    BPT_CHECK(same, "%s: the symmetrized M in column chunks (backwards, odd then even, serial) is the serial "
              "scatter's, pattern and bits", path);
    free(R.val);
}

/* T: a mean-value system (phases 1-5 done). */
static void check_bicgstab(const char *path, bp__tutte *T)
{
    bp_allocator a;
    bp__sparse M, As = T->A;
    bp__factor K;
    bp__krylov_task J;
    bp__par par = bp__par_serial();
    uint32_t n = T->nfree, i, j, p, bad, order;
    double *x = (double *)malloc(2 * (size_t)n * sizeof(double)), *y0 = (double *)malloc(2 * (size_t)n * sizeof(double));
    double *y1 = (double *)malloc(2 * (size_t)n * sizeof(double)), *b = (double *)malloc(2 * (size_t)n * sizeof(double));
    double *dg = (double *)malloc(n * sizeof(double)), rel;
    int it0, it1;
    memset(&a, 0, sizeof a);
    memset(&J, 0, sizeof J);
    memset(&K, 0, sizeof K);
    /* the scaled system exactly as bp__tutte_krylov makes it */
    As.val = (double *)malloc(T->A.colp[n] * sizeof(double));
    for (j = 0; j < n; j++) dg[j] = 1;
    for (j = 0; j < n; j++)
        for (p = T->A.colp[j]; p < T->A.colp[j + 1]; p++)
            if (T->A.row[p] == j && T->A.val[p] > 0) dg[j] = T->A.val[p];
    for (j = 0; j < n; j++)
        for (p = T->A.colp[j]; p < T->A.colp[j + 1]; p++) As.val[p] = T->A.val[p] / dg[T->A.row[p]];
    for (i = 0; i < n; i++) { b[2 * i] = T->rhs[i] / dg[i]; b[2 * i + 1] = T->rhs[n + i] / dg[i]; }
    for (i = 0; i < 2 * n; i++) x[i] = rng_unit() - 0.5;
    ref_spmv2(&As, x, y0);
    J.n = n;
    J.nc = bp__nchunks(n, BP__KRYLOV_CHUNK);
    par.threads = 2;
    if (!BPT_CHECK(bp__sparse_rows(&a, &As, (uint32_t **)&J.rp, (uint32_t **)&J.ci, (double **)&J.rv) && J.nc >= 4,
                   "%s: A by rows (%u row chunks)", path, J.nc)) goto out;
    for (order = 0; order < 2; order++) {
        par.run = order ? bpt_odd_even_for : bpt_backwards_for;
        memset(y1, 0xff, 2 * (size_t)n * sizeof(double));
        bp__krylov_spmv(&J, &par, x, y1, 0);
        BPT_CHECK(!memcmp(y0, y1, 2 * (size_t)n * sizeof(double)), "%s: A x by rows (tasks %s) has the column "
                  "scatter's bits", path, order ? "odd then even" : "backwards");
    }
    same_scaled(path, T, As.val, b);
    same_symmetric(path, &As);
    if (!BPT_CHECK(bp__tutte_symmetric(&a, &As, &M, NULL) && bp__factorize(&a, &M, &K, &bad, NULL) == BP_OK && K.sn &&
                   bp__factor_single(&a, &K, NULL) && bp__solve_plan(&a, &K), "%s: the preconditioner", path)) goto out2;
    it0 = ref_bicgstab(&As, &K, b, y0);
    for (order = 0; order < 2; order++) {
        par.run = order ? bpt_odd_even_for : bpt_backwards_for;
        it1 = bp__tutte_bicgstab(&a, &As, &K, &par, b, y1, &rel);
        BPT_CHECK(it0 > 0 && it1 == it0 && !memcmp(y0, y1, 2 * (size_t)n * sizeof(double)), "%s: BiCGSTAB (tasks %s, "
                  "%d iterations) has the serial reference's bits (%d iterations)", path,
                  order ? "odd then even" : "backwards", it1, it0);
    }
out2:
    bp__factor_free(&a, &K);
    bp__free(&a, M.colp); bp__free(&a, M.row); bp__free(&a, M.val);
out:
    bp__free(&a, (void *)J.rp); bp__free(&a, (void *)J.ci); bp__free(&a, (void *)J.rv);
    free(As.val); free(x); free(y0); free(y1); free(b); free(dg);
}

static void check_krylov(const char *path)
{
    bp_mesh m;
    bp_atlas at;
    bp_error e;
    bp_options o;
    bp_allocator a;
    bp__tutte T;
    bp__factor F;
    bp__par rev = bp__par_serial();
    uint32_t c, best = 0, i, j, p, n, bad;
    double *keep, *r, *work, rr = 0, bb = 0, diff = 0, big = 0;
    int ok;
    memset(&a, 0, sizeof a);
    memset(&o, 0, sizeof o);
    memset(&T, 0, sizeof T);
    rev.run = bpt_backwards_for;
    if (!BPT_CHECK(bp_read_mesh(path, &m, NULL, &e) == BP_OK, "%s: read: %s", path, e.message)) return;
    if (!BPT_CHECK(bp_atlas_build(&at, &m, &o, &e) == BP_OK, "%s: charts: %s", path, e.message)) { bp_mesh_free(&m, NULL); return; }
    for (c = 0; c < at.num_charts; c++) if (at.charts[c].num_triangles > at.charts[best].num_triangles) best = c;
    if (!BPT_CHECK(bp_chart_init(&at.charts[best], &m, &o, &e) == BP_OK, "%s: start map (allocates uv): %s", path, e.message))
        goto out;
    if (!BPT_CHECK(bp__tutte_fill(&a, &T, &at.charts[best], &m) && bp__tutte_adjacency(&a, &T) && bp__tutte_weights(&a, &T, 1) &&
                   bp__tutte_circle(&a, &T, &at.charts[best]) && bp__tutte_system(&a, &T, &at.charts[best], 1),
                   "%s: the mean-value system", path)) goto out;
    n = T.nfree;
    if (n > 2 * BP__KRYLOV_CHUNK) check_bicgstab(path, &T);   /* (several row chunks) */
    ok = bp__tutte_krylov(&a, &T, NULL) == 1;
    BPT_CHECK(ok, "%s (%u unknowns): BiCGSTAB converged in %d iterations, its residual %.2g", path, n, T.krylov_iters,
              T.krylov_rel);
    r = (double *)malloc(2 * n * sizeof(double));
    keep = (double *)malloc(2 * n * sizeof(double));
    work = (double *)malloc(3 * n * sizeof(double));
    for (i = 0; i < 2 * n; i++) r[i] = T.rhs[i];
    for (j = 0; j < n; j++)
        for (p = T.A.colp[j]; p < T.A.colp[j + 1]; p++) {
            r[T.A.row[p]] -= T.A.val[p] * T.sol[j];
            r[n + T.A.row[p]] -= T.A.val[p] * T.sol[n + j];
        }
    for (i = 0; i < 2 * n; i++) { rr += r[i] * r[i]; bb += T.rhs[i] * T.rhs[i]; }
    BPT_CHECK(sqrt(rr / bb) <= BP__KRYLOV_TOL, "%s: |b - A x| / |b| = %.2g recomputed", path, sqrt(rr / bb));
    memcpy(keep, T.sol, 2 * n * sizeof(double));
    if (BPT_CHECK(bp__factorize(&a, &T.A, &F, &bad, NULL) == BP_OK, "%s: LU", path)) {
        bp__solve_refined(&T.A, &F, T.rhs, r, work);
        bp__solve_refined(&T.A, &F, T.rhs + n, r + n, work);
        for (i = 0; i < 2 * n; i++) {
            if (fabs(r[i] - keep[i]) > diff) diff = fabs(r[i] - keep[i]);
            if (fabs(r[i]) > big) big = fabs(r[i]);
        }
        BPT_CHECK(diff <= 1e-9 * big, "%s: the LU's solution agrees, max diff %.2g of %.2g", path, diff, big);
        bp__factor_free(&a, &F);
    }
    BPT_CHECK(bp__tutte_krylov(&a, &T, &rev) == 1 && !memcmp(keep, T.sol, 2 * n * sizeof(double)),
              "%s: the same bits with the tasks run backwards", path);
    free(r); free(keep); free(work);
out:
    bp__tutte_free(&a, &T);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

/* (e) Phases 2, 3 and 5 of the start map (adjacency, weights, system) are
   gathers per vertex chunk; here against the triangle-order scatters they
   replaced (written out below, as the header had them), bit for bit, with
   the chunks run serially, backwards and odd then even. */
static int ref_u32_cmp(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

static uint32_t ref_find(const uint32_t *adjp, const uint32_t *adj, uint32_t i, uint32_t j)
{
    uint32_t e;
    for (e = adjp[i]; e < adjp[i + 1]; e++) if (adj[e] == j) return e;
    return BP__NONE;
}

/* a serial reference of phases 2, 3, 5 on T (after phase 1 and 4's circle: idx, uv) */
static void ref_phases(bp__tutte *T, const bp_chart *ch, int mvc, uint32_t **adjp_, uint32_t **adj_, double **w_,
                       uint32_t **colp_, uint32_t **row_, double **val_, double **rhs_)
{
    uint32_t t, k, i, e, N = T->N, ne = 0, *cnt = (uint32_t *)calloc(N + 1, sizeof(uint32_t));
    uint32_t *adjp = (uint32_t *)calloc(N + 1, sizeof(uint32_t)), *adj = (uint32_t *)malloc(6 * T->nt * sizeof(uint32_t));
    uint32_t nfree = T->nfree, j, p, nnz = 0, *colp, *row;
    double *w, *val, *rhs;
    for (t = 0; t < T->nt; t++)
        for (k = 0; k < 3; k++) { adjp[T->tri[3 * t + k] + 1]++; adjp[T->tri[3 * t + (k + 1) % 3] + 1]++; }
    for (i = 0; i < N; i++) adjp[i + 1] += adjp[i];
    memcpy(cnt, adjp, (N + 1) * sizeof(uint32_t));
    for (t = 0; t < T->nt; t++)
        for (k = 0; k < 3; k++) {
            uint32_t va = T->tri[3 * t + k], vb = T->tri[3 * t + (k + 1) % 3];
            adj[cnt[va]++] = vb;
            adj[cnt[vb]++] = va;
        }
    for (i = 0; i < N; i++) {
        uint32_t s0 = adjp[i], s1 = adjp[i + 1], last = BP__NONE;
        qsort(adj + s0, s1 - s0, sizeof(uint32_t), ref_u32_cmp);
        adjp[i] = ne;
        for (e = s0; e < s1; e++) if (adj[e] != last) adj[ne++] = last = adj[e];
    }
    adjp[N] = ne;
    w = (double *)calloc(ne + 1, sizeof(double));
    for (t = 0; t < T->nt; t++)
        for (k = 0; k < 3; k++) {
            uint32_t vi = T->tri[3 * t + k], vj = T->tri[3 * t + (k + 1) % 3], vk = T->tri[3 * t + (k + 2) % 3];
            uint32_t ej = ref_find(adjp, adj, vi, vj), ek = ref_find(adjp, adj, vi, vk);
            if (!mvc) w[ej] = w[ek] = 1;
            else {
                const double *pi = T->pos + 3 * (size_t)vi, *pj = T->pos + 3 * (size_t)vj, *pk = T->pos + 3 * (size_t)vk;
                double th = bp__tan(0.5 * bp__angle3(pi, pj, pk));   /* the library's own tan (>>math) */
                w[ej] += th / bp__dist3(pi, pj);
                w[ek] += th / bp__dist3(pi, pk);
            }
        }
    for (e = 0; e < ne; e++) if (!(w[e] > 0) || !(w[e] - w[e] == 0)) w[e] = 1;
    colp = (uint32_t *)malloc((nfree + 1) * sizeof(uint32_t));
    row = (uint32_t *)malloc((ne + nfree) * sizeof(uint32_t));
    val = (double *)malloc((ne + nfree) * sizeof(double));
    rhs = (double *)calloc(2 * nfree + 1, sizeof(double));
    for (j = 0; j < N; j++) {
        uint32_t cj = T->idx[j];
        double diag = 0;
        int diag_done = 0;
        if (cj == BP__NONE) continue;
        colp[cj] = nnz;
        for (e = adjp[j]; e < adjp[j + 1]; e++) {
            uint32_t vi = adj[e];
            diag += w[e];
            if (T->idx[vi] == BP__NONE) {
                rhs[cj] += w[e] * ch->uv[2 * (size_t)vi];
                rhs[nfree + cj] += w[e] * ch->uv[2 * (size_t)vi + 1];
            }
        }
        for (e = adjp[j]; e < adjp[j + 1]; e++) {
            uint32_t vi = adj[e];
            if (T->idx[vi] == BP__NONE) continue;
            if (!diag_done && vi > j) { row[nnz] = cj; val[nnz++] = 0; diag_done = 1; }
            row[nnz] = T->idx[vi];
            val[nnz++] = -w[ref_find(adjp, adj, vi, j)];
        }
        if (!diag_done) { row[nnz] = cj; val[nnz++] = 0; }
        for (p = colp[cj]; p < nnz; p++) if (row[p] == cj) val[p] = diag;
    }
    colp[nfree] = nnz;
    free(cnt);
    *adjp_ = adjp; *adj_ = adj; *w_ = w; *colp_ = colp; *row_ = row; *val_ = val; *rhs_ = rhs;
}

static void check_phases(const char *path)
{
    bp_mesh m;
    bp_atlas at;
    bp_error e;
    bp_options o;
    bp_allocator a;
    uint32_t c, best = 0;
    int mvc, order;
    memset(&a, 0, sizeof a);
    memset(&o, 0, sizeof o);
    if (!BPT_CHECK(bp_read_mesh(path, &m, NULL, &e) == BP_OK, "%s: read: %s", path, e.message)) return;
    if (!BPT_CHECK(bp_atlas_build(&at, &m, &o, &e) == BP_OK, "%s: charts: %s", path, e.message)) { bp_mesh_free(&m, NULL); return; }
    for (c = 0; c < at.num_charts; c++) if (at.charts[c].num_triangles > at.charts[best].num_triangles) best = c;
    if (!BPT_CHECK(bp_chart_init(&at.charts[best], &m, &o, &e) == BP_OK, "%s: start map (allocates uv): %s", path, e.message))
        goto out;
    for (mvc = 0; mvc < 2; mvc++)
        for (order = 0; order < 3; order++) {
            bp__tutte T;
            bp_chart *ch = &at.charts[best];
            uint32_t *adjp, *adj, *colp, *row, N, nf;
            double *w, *val, *rhs;
            int same;
            memset(&T, 0, sizeof T);
            if (order) {
                T.par = bp__par_serial();
                T.par.run = order == 1 ? bpt_backwards_for : bpt_odd_even_for;
                T.par.threads = 2;
            }
            if (!BPT_CHECK(bp__tutte_fill(&a, &T, ch, &m) && bp__tutte_adjacency(&a, &T) && bp__tutte_weights(&a, &T, mvc) &&
                           bp__tutte_circle(&a, &T, ch) && bp__tutte_system(&a, &T, ch, mvc), "%s: phases 1-5", path)) {
                bp__tutte_free(&a, &T);
                continue;
            }
            ref_phases(&T, ch, mvc, &adjp, &adj, &w, &colp, &row, &val, &rhs);
            N = T.N;
            nf = T.nfree;
            same = !memcmp(adjp, T.adjp, (N + 1) * sizeof(uint32_t)) && !memcmp(adj, T.adj, adjp[N] * sizeof(uint32_t)) &&
                   !memcmp(w, T.w, adjp[N] * sizeof(double)) && !memcmp(colp, T.A.colp, (nf + 1) * sizeof(uint32_t)) &&
                   !memcmp(row, T.A.row, colp[nf] * sizeof(uint32_t)) && !memcmp(val, T.A.val, colp[nf] * sizeof(double)) &&
                   !memcmp(rhs, T.rhs, 2 * nf * sizeof(double));
            BPT_CHECK(same && T.N > 2 * BP__TUTTE_CHUNK, "%s (%s, %u vertices, tasks %s): adjacency, weights and system "
                      "equal the triangle-order scatter's bits", path, mvc ? "mean value" : "Tutte", N,
                      order == 0 ? "serial" : order == 1 ? "backwards" : "odd then even");
            free(adjp); free(adj); free(w); free(colp); free(row); free(val); free(rhs);
            bp__tutte_free(&a, &T);
        }
out:
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

static void check_mesh(const char *path)
{
    bp_mesh m;
    bp_atlas at;
    bp_error e;
    bp_options o;
    FILE *f = fopen(path, "rb");
    uint32_t c;
    int mvc;
    if (!BPT_CHECK(f != NULL, "%s: present (tests/data is part of the repository; a missing file is a failure, "
                   "not a skip)", path)) return;
    fclose(f);
    if (!BPT_CHECK(bp_read_mesh(path, &m, NULL, &e) == BP_OK, "%s: read: %s", path, e.message)) return;
    memset(&o, 0, sizeof o);
    if (bp_atlas_build(&at, &m, &o, &e) != BP_OK) {
        BPT_CHECK(0, "%s: charts: %s", path, e.message);
        bp_mesh_free(&m, NULL);
        return;
    }
    for (mvc = 0; mvc < 2; mvc++)
        for (c = 0; c < at.num_charts; c++) check_start(&m, &at.charts[c], mvc, path, c);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

int main(void)
{
    static const int sizes[][2] = { { 3, 3 }, { 8, 5 }, { 12, 12 }, { 30, 7 }, { 25, 25 } };
    double err_s = 0, res_s = 0, err_n = 0, res_n = 0;
    int k, perm_ok = 1;
    for (k = 0; k < 5; k++) {
        int r;
        for (r = 0; r < 4; r++) {
            test_solver(sizes[k][0], sizes[k][1], 1, &err_s, &res_s, &perm_ok);
            test_solver(sizes[k][0], sizes[k][1], 0, &err_n, &res_n, &perm_ok);
        }
    }
    BPT_CHECK(perm_ok, "nested dissection orders are permutations");
    BPT_CHECK(err_s < 1e-10 && res_s < 1e-12, "sparse LDL^T (symmetric) matches dense elimination: relative error %.1e, "
              "residual %.1e (20 matrices up to 625 unknowns)", err_s, res_s);
    BPT_CHECK(err_n < 1e-10 && res_n < 1e-12, "sparse LU on a symmetric pattern (nonsymmetric M-matrix) matches dense "
              "elimination: relative error %.1e, residual %.1e", err_n, res_n);

    BPT_CHECK(krylov_worst < 1e-10, "the Krylov solve of the mean-value system (phase 6a) matches dense elimination: "
              "relative error %.1e (20 nonsymmetric M-matrices, both right-hand sides)", krylov_worst);
    quick = getenv("BP_TEST_QUICK") != NULL;
    check_krylov("tests/data/camel_b.obj");
    check_krylov("tests/data/camelhead.off");
    if (!quick) check_krylov("tests/data/horse_cut.obj");
    check_phases("tests/data/face_holes.off");
    check_phases("tests/data/camelhead.off");
    if (!quick) check_phases("tests/data/horse_cut.obj");
    check_precondition("tests/data/camel_b.obj");
    check_precondition("tests/data/camelhead.off");
    if (!quick) check_precondition("tests/data/horse_cut.obj");
    check_mesh("tests/data/bishop_part_f1000.obj");
    check_mesh("tests/data/camel_b.obj");
    check_mesh("tests/data/cow_param_withSUV.obj");
    check_mesh("tests/data/spot.obj");
    check_mesh("tests/data/face_holes.off");
    check_mesh("tests/data/mech-holes-shark.off");
    check_mesh("tests/data/camelhead.off");
    check_mesh("tests/data/hilbert.obj");
    check_mesh("tests/data/beetle.off");
    check_mesh("tests/data/horse_cut.obj");
    return bpt_finish();
}
