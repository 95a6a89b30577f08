/* test_newton.c - the projected Newton direction (>>hessian, >>newton).

   Nothing here takes the library's Hessian formulas on trust:

     (a) every energy's unprojected 6x6 triangle Hessian (bp__triangle_hessian,
         project = 0) against central finite differences of the library's
         gradient (bp__triangle_energy, which test_energy.c checks against
         finite differences of the energy), on random valid triangles with
         random rest shapes, away from the kinks of the non-smooth energies;
     (b) the projected Hessian is positive semidefinite: its smallest
         eigenvalue, by Jacobi rotations written here, is >= -1e-9 |H|;
     (c) where the energy is convex in J (the finite-difference Hessian in
         the 4 entries of J, from a triangle whose rest shape is the unit
         right triangle so that J = D, is positive definite) the projected
         Hessian equals the finite differences; where it is not, the
         projection changed something (so (c) cannot pass by never
         projecting).  Conformal, MIPS and max isometric are never strictly
         convex in J (a twist eigenvalue <= 0, or a linear piece), which the
         finite differences must confirm;
     (d) on a real chart (camel_b, Tutte start), the assembled matrix
         (gathered by vertex in parallel chunks, over values the pattern
         left as allocated, set to NaN here) is, without the barrier,
         the scatter of the triangles' Hessians in triangle order written
         here (searching H's columns) plus delta I, bit for bit, and has the
         same bits with its chunks run backwards; the shift delta the
         library took (its trace summed from the gather tasks' diagonals
         and, with the barrier's pairs, theirs) is 1e-8 trace / n of H
         before the shift, recovered from H's diagonal; it
         without the barrier dominates the true Hessian: w^T H w >=
         w^T (finite-difference Hessian) w for random w, since clamping
         adds a positive semidefinite term per triangle; with the barrier,
         w^T H w >= 0;
     (e) bp_chart_optimize with BP_DIRECTION_NEWTON on camel_b and the
         bishop chart: converged, exactly bijective, an energy no higher than
         the preconditioned L-BFGS's (+0.1%), in fewer iterations; and the
         same bits when the parallel loops run their tasks in reverse order;
     (f) pins: with every 7th vertex of camel_b held (bp__newton.hold), the
         Newton direction is exactly 0 (==) on the held coordinates, is a
         descent direction, and solves the unpinned system on the free
         rows: |(H v + g)_i| <= 1e-8 max |g| for every free row i, H the
         matrix assembled without pins (so the held rows were fixed, not
         dropped from the other rows' equations); and without the hold the
         same direction is not 0 there (so the check can fail).
         tests/test_pins.c runs whole pinned Newton solves;
     (g) longer steps (bp__opt_extend): a whole Newton solve of camel_b
         whose progress callback runs the exact bp_check on every accepted
         map: all bijective, and some accepted steps are longer than 1 (so
         the extension ran), every one of those maps checked too; the
         gate (BP__NEWTON_EXTEND_RATIO, set by this file): camel_b with
         the doubling tried after a full step only from 0.9 of the model's
         decrease is the same bits as with it always tried, in fewer of
         bp__opt_extend's loop tests (counted by this file's
         BP__NEWTON_EXTEND_MAX), and never doubling changes the map;
     (h) factor reuse: along 30 camel_b maps of a Newton iteration with its
         own backtracking line search (without the barrier, so that H's
         pattern is fixed), conjugate gradients preconditioned by the
         factor of the previous map's H (bp__newton_reuse_solve) give a
         descent direction with a negative quadratic model m(v) = g.v +
         v.H v / 2 (H multiplied here, not by the library), never below
         the exact Newton step's model (its minimum, from a fresh
         factorization); and at the maps where the library's gate allows
         reuse (the last step was the full step and decreased f by 1/2 to 2
         times the model's prediction and by at most a tenth) CG converges
         within 10% of that minimum.  The plain gradient direction scaled to its best length
         is shown far worse, so the bound can fail.  At every 7th map the
         same CG on a two-thread runner with its tasks run backwards (the
         products, the vector passes and the solves in chunks) gives the
         same bits;
     (i) the model's wider barrier after a boundary clip: the assembled
         matrix with it minus the one without equals, along random w, the
         brute-force sum of the wider barrier's Gauss-Newton terms (second
         derivatives by finite differences), so it is positive
         semidefinite, and it is not 0;
     (j) Newton's pattern (bp__newton_pattern) against a brute-force
         construction: H's columns, tpos and dpos on camelhead, serially,
         with extra pairs in reversed chunk order, and on a real pool;
     (k) a kept order (bp__nd_keeps, bp__newton_factorize): on camelhead's
         H, bp__nd_keeps agrees with a brute force over every split node
         on 3000 random vertex pairs (both verdicts occur); after valid
         pairs grow the pattern, the next factorization keeps the old
         vertex order and tree (counted), solves H x = b to a residual of
         1e-7, and has the same bits with its tasks run backwards on two
         threads; after an invalid pair it takes a new order, which
         separates every extra pair;
     (l) the isotropic block's closed form (bp__hessian_iso_j): for
         every energy, on 4000 random Jacobians with det > 0 (a tenth of
         them exact similarities, R = 0), C equals (B_00 + B_11) / 2 of
         the projected 4x4 bp__hessian_j builds from its eigenvectors
         (within 1e-11 of the 4x4's largest entry), and the triangles'
         six numbers (bp__triangle_hessian_iso) equal (xx + yy) / 2 of
         the projected 6x6's corner blocks; R = 0 and both cases of the
         scaling block (already semidefinite, clamped to one
         eigenvector) occur;
     (m) the isotropic phase: on camel_b without the barrier, with a
         barrier 4 mean edges wide and with every 7th vertex held, the
         library's K1 equals (H(2u, 2v) + H(2u+1, 2v+1)) / 2 of the H it
         assembles otherwise, entry by entry, and its shift is H's (within
         1e-12 max |H|, and 1e-9 of the shift; H shown
         anisotropic, so the average is a test); its direction is one of
         descent, solves (K1 (x) I) v = -g with K1 built here from H (max
         residual 1e-8 max |g|), is exactly 0 on held vertices and is not
         Newton's; K1 refactored through its scatter map has the bits of a
         fresh factorization on the same order, and so has K1 factored
         with the analysis copied from H's factor in that order
         (bp__super_clone: every array the same; bp__newton_iso_like
         takes that factor, and refuses it with one row of its pattern
         moved); the phase's end frees K1
         and its factor's values, and H's first factorization after it
         copies that analysis (bp__newton_h_like; where no barrier pair
         grew H's pattern since: without the barrier) with every array,
         value and pivot of a fresh factorization in that order.  A whole default solve of camelhead (Newton,
         isotropic first): every accepted map exactly bijective by
         bp_check, the energy never up, the same bits on one thread and on
         two with the tasks run backwards.
   With BP_TEST_QUICK set (make test) the default's choice leaves out lucy,
   beetle and camelhead 3 x 3, and the allocator fallback runs on camel_b
   instead of camelhead; make check runs it all. */
/* every loop through the job system, even on these small charts (as in
   test_threads.c), so that (e)'s reversed task order is a real test */
#define BP__PAR_MIN_TRIANGLES 1u
#define BP__PAR_MIN_ITEMS     1u
/* (g): bp__opt_extend's loop tests counted, its gate's share set here */
static long bpt_extend_loops;
static double bpt_extend_ratio = 0.9;
#define BP__NEWTON_EXTEND_MAX (bpt_extend_loops++, 40)
#define BP__NEWTON_EXTEND_RATIO bpt_extend_ratio
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <string.h>
#include <stdlib.h>

static int quick;   /* BP_TEST_QUICK: the short form (make test) */

static const char *const ENAME[] = { "symmetric Dirichlet", "conformal", "MIPS", "isometric", "max isometric" };

/* Smallest eigenvalue of a symmetric n x n matrix (n <= 6) by cyclic Jacobi. */
static double min_eig(const double *h, int n)
{
    double a[36], mn;
    int sweep, p, q, k;
    memcpy(a, h, (size_t)n * n * sizeof(double));
    for (sweep = 0; sweep < 60; sweep++) {
        double off = 0;
        for (p = 0; p < n; p++) for (q = p + 1; q < n; q++) off += a[p * n + q] * a[p * n + q];
        if (off < 1e-300) break;
        for (p = 0; p < n; p++)
            for (q = p + 1; q < n; q++) {
                double apq = a[p * n + q], th, t, c, s;
                if (apq == 0) continue;
                th = (a[q * n + q] - a[p * n + p]) / (2 * apq);
                t = (th >= 0 ? 1 : -1) / (fabs(th) + sqrt(th * th + 1));
                c = 1 / sqrt(t * t + 1);
                s = t * c;
                for (k = 0; k < n; k++) {          /* A = J^T A J on columns then rows */
                    double akp = a[k * n + p], akq = a[k * n + q];
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                for (k = 0; k < n; k++) {
                    double apk = a[p * n + k], aqk = a[q * n + k];
                    a[p * n + k] = c * apk - s * aqk;
                    a[q * n + k] = s * apk + c * aqk;
                }
            }
    }
    mn = a[0];
    for (p = 1; p < n; p++) if (a[p * n + p] < mn) mn = a[p * n + p];
    return mn;
}

/* Singular values of J = D M^-1 from J^T J (test's own formula). */
static void sv_of(const bp__rest *r, double U[3][2], double *sa, double *sb)
{
    double d00 = U[1][0] - U[0][0], d10 = U[1][1] - U[0][1], d01 = U[2][0] - U[0][0], d11 = U[2][1] - U[0][1];
    double a = d00 * r->m00, b = d00 * r->m01 + d01 * r->m11, c = d10 * r->m00, d = d10 * r->m01 + d11 * r->m11;
    double p = a * a + c * c, q = a * b + c * d, s = b * b + d * d, tr = p + s, det = p * s - q * q;
    double disc = sqrt(fmax(0, tr * tr / 4 - det));
    *sa = sqrt(tr / 2 + disc);
    *sb = sqrt(fmax(0, tr / 2 - disc));
}

/* Finite-difference Hessian of weight * E_t: columns from central
   differences of the library's gradient. */
static int fd_hessian(bp_energy kind, const bp__rest *r, double U[3][2], double h, double out[36])
{
    int j, i;
    for (j = 0; j < 6; j++) {
        double gp[6] = { 0 }, gm[6] = { 0 }, save = U[j / 2][j % 2];
        U[j / 2][j % 2] = save + h;
        if (bp__triangle_energy(kind, r, U[0], U[1], U[2], gp, gp + 2, gp + 4) == HUGE_VAL) { U[j / 2][j % 2] = save; return 0; }
        U[j / 2][j % 2] = save - h;
        if (bp__triangle_energy(kind, r, U[0], U[1], U[2], gm, gm + 2, gm + 4) == HUGE_VAL) { U[j / 2][j % 2] = save; return 0; }
        U[j / 2][j % 2] = save;
        for (i = 0; i < 6; i++) out[6 * i + j] = (gp[i] - gm[i]) / (2 * h);
    }
    return 1;
}

static double max_abs(const double *h, int n)
{
    double m = 0;
    int i;
    for (i = 0; i < n; i++) if (fabs(h[i]) > m) m = fabs(h[i]);
    return m;
}

/* A random valid triangle: rest M^-1 from a random 3D-like shape, UV a
   random positively oriented triangle. */
static void random_triangle(bp__rest *r, double U[3][2], int unit_rest)
{
    double w = exp(bpt_rng_range(-1, 1)), px = w * bpt_rng_range(-0.5, 1.5), py = w * exp(bpt_rng_range(-1, 0.5));
    int i, k;
    if (unit_rest) { w = 1; px = 0; py = 1; }
    bp__rest_inverse(w, px, py, 1, r);
    r->weight = unit_rest ? 1 : exp(bpt_rng_range(-1, 1));
    for (;;) {
        double s = exp(bpt_rng_range(-1.2, 1.2));
        for (i = 0; i < 3; i++) for (k = 0; k < 2; k++) U[i][k] = s * bpt_rng_range(-1, 1);
        if ((U[1][0] - U[0][0]) * (U[2][1] - U[0][1]) - (U[1][1] - U[0][1]) * (U[2][0] - U[0][0]) > 0.05 * s * s) break;
    }
}

static void test_triangle_hessians(void)
{
    int kind;
    for (kind = 0; kind < BP_ENERGY_COUNT; kind++) {
        int trial, checked = 0, bad = 0, notpsd = 0, convex = 0, convex_bad = 0, nonconvex = 0, projected = 0;
        double worst = 0, worst_psd = 0, worst_cvx = 0;
        for (trial = 0; trial < 3000; trial++) {
            bp__rest r;
            double U[3][2], sa, sb, H[36], P[36], FD[36], scale, e, h;
            int i, unit = trial % 2;
            random_triangle(&r, U, unit);
            sv_of(&r, U, &sa, &sb);
            /* away from the kinks: s_max = s_min (all but the smooth SD and MIPS)
               and s_max s_min = 1 (max isometric) */
            if (kind != BP_ENERGY_SYMMETRIC_DIRICHLET && kind != BP_ENERGY_MIPS && sa - sb < 0.05 * sa) continue;
            if (kind == BP_ENERGY_MAX_ISOMETRIC && fabs(sa * sb - 1) < 0.05) continue;
            if (!bp__triangle_hessian((bp_energy)kind, &r, U[0], U[1], U[2], 0, H)) continue;
            if (!bp__triangle_hessian((bp_energy)kind, &r, U[0], U[1], U[2], 1, P)) continue;
            h = 1e-5 * sb / (r.m00 > r.m11 ? r.m00 : r.m11);
            if (!fd_hessian((bp_energy)kind, &r, U, h, FD)) continue;
            scale = max_abs(FD, 36);
            if (scale < 1e-12) scale = 1e-12;
            e = 0;
            for (i = 0; i < 36; i++) if (fabs(H[i] - FD[i]) / scale > e) e = fabs(H[i] - FD[i]) / scale;
            if (!(e <= worst)) worst = e;
            if (!(e <= 1e-5)) bad++;
            checked++;
            /* (b) */
            e = min_eig(P, 6) / max_abs(P, 36);
            if (-e > worst_psd) worst_psd = -e;
            if (!(e >= -1e-9)) notpsd++;
            /* (c) convex in J: with the unit rest, rows/columns 2..5 of FD are d^2/dJ^2 */
            if (unit) {
                double F4[16];
                int a2, b2;
                for (a2 = 0; a2 < 4; a2++)
                    for (b2 = 0; b2 < 4; b2++) {
                        /* dof 2 + k: u2x, u2y, u3x, u3y = J00, J10, J01, J11 */
                        static const int jidx[4] = { 0, 2, 1, 3 };
                        F4[4 * jidx[a2] + jidx[b2]] = FD[6 * (2 + a2) + 2 + b2];
                    }
                if (min_eig(F4, 4) > 1e-6 * max_abs(F4, 16)) {
                    double d = 0;
                    convex++;
                    for (i = 0; i < 36; i++) if (fabs(P[i] - FD[i]) / scale > d) d = fabs(P[i] - FD[i]) / scale;
                    if (d > worst_cvx) worst_cvx = d;
                    if (!(d <= 1e-5)) convex_bad++;
                } else if (min_eig(F4, 4) < -1e-3 * max_abs(F4, 16)) {
                    double d = 0;
                    nonconvex++;
                    for (i = 0; i < 36; i++) if (fabs(P[i] - H[i]) > d) d = fabs(P[i] - H[i]);
                    if (d > 1e-6 * scale) projected++;
                }
            }
        }
        BPT_CHECK(checked >= 500 && bad == 0, "%s: Hessian == finite differences of the gradient on %d triangles "
                  "(max err / max|H| %.2g)", ENAME[kind], checked, worst);
        BPT_CHECK(notpsd == 0, "%s: projected Hessian positive semidefinite on %d triangles (min eig / max|H| >= %.2g)",
                  ENAME[kind], checked, -worst_psd);
        if (kind == BP_ENERGY_SYMMETRIC_DIRICHLET || kind == BP_ENERGY_ISOMETRIC)
            BPT_CHECK(convex > 0 && convex_bad == 0, "%s: projected == true Hessian on the %d triangles convex in J "
                      "(max err %.2g)", ENAME[kind], convex, worst_cvx);
        else    /* twist eigenvalue (f_a + f_b) / (s_max + s_min) <= 0 for conformal and MIPS, a zero scaling
                   curvature on max isometric's s_max piece: never strictly convex in J */
            BPT_CHECK(convex == 0, "%s: never strictly convex in J, as its eigenvalues say (finite differences agree: "
                      "%d of the unit-rest triangles convex)", ENAME[kind], convex);
        if (kind != BP_ENERGY_MAX_ISOMETRIC || nonconvex > 0)
            BPT_CHECK(nonconvex > 0 && projected == nonconvex, "%s: the projection changed all %d Hessians that are "
                      "not convex in J (%d changed)", ENAME[kind], nonconvex, projected);
    }
}

/* (d) H's gather by vertex (bp__newton_gather_task) against a scatter
   written here: every triangle in turn adds its whole 6x6 projected
   Hessian (bp__triangle_hessian at x, not the library's packed blocks
   N->ht) to the entries it finds by searching H's columns (not through
   tpos).  Without
   the barrier (delta given) H is that plus delta on the diagonal, bit for
   bit (the scatter's order per entry is the gather's); and assembled
   again with the vertex chunks run backwards on a two-thread runner, H
   has the same bits. */
static void check_gather(bp__newton *N, bp__solver *S, const double *x, const double *delta)
{
    uint32_t n = N->H.n, t, r, c, a, b, p, bad = 0, miss = 0;
    double *Hs = (double *)calloc(N->H.colp[n] + 1, sizeof(double)), *H1 = (double *)malloc((N->H.colp[n] + 1) * sizeof(double));
    bp__par keep = S->par;
    for (t = 0; t < S->nt; t++) {
        const uint32_t *tr = S->tri + 3 * (size_t)t;
        double h6[36];
        if (!bp__triangle_hessian(S->energy, &S->rest[t], x + 2 * (size_t)tr[0], x + 2 * (size_t)tr[1],
                                  x + 2 * (size_t)tr[2], 1, h6))
            memset(h6, 0, sizeof h6);
        for (r = 0; r < 3; r++)
            for (c = 0; c < 3; c++)
                for (a = 0; a < 2; a++)
                    for (b = 0; b < 2; b++) {
                        uint32_t row = 2 * tr[r] + a, col = 2 * tr[c] + b;
                        for (p = N->H.colp[col]; p < N->H.colp[col + 1] && N->H.row[p] != row; p++) {}
                        if (p == N->H.colp[col + 1]) { miss++; continue; }
                        Hs[p] += h6[6 * (2 * r + a) + 2 * c + b];
                    }
    }
    BPT_CHECK(miss == 0, "camel_b: every triangle block is in H's pattern (%u missing)", miss);
    if (delta) {       /* the library's shift from this H's trace: 1e-8 trace / n */
        double tr = 0, d;
        for (c = 0; c < S->nv; c++) tr += Hs[N->dpos[4 * c]] + Hs[N->dpos[4 * c + 3]];
        d = 1e-8 * tr / n;
        BPT_CHECK(fabs(d - *delta) <= 1e-6 * *delta, "camel_b without barrier: the shift %.6g as recovered from H's trace (%.6g)", d,
                  *delta);
        for (c = 0; c < n; c++)
            for (p = N->H.colp[c]; p < N->H.colp[c + 1]; p++)
                if (N->H.val[p] != (N->H.row[p] == c ? Hs[p] + d : Hs[p])) bad++;
        BPT_CHECK(bad == 0, "camel_b without barrier: H is the triangle-order scatter + delta I, bit for bit (%u differ)", bad);
    }
    memcpy(H1, N->H.val, N->H.colp[n] * sizeof(double));
    S->par.run = bpt_backwards_for;
    S->par.user = NULL;
    S->par.threads = 2;
    bp__newton_assemble(N, S, x);
    BPT_CHECK(memcmp(H1, N->H.val, N->H.colp[n] * sizeof(double)) == 0,
              "camel_b %s: H assembled with the vertex chunks backwards: the same bits", delta ? "without barrier" : "with the barrier");
    S->par = keep;
    free(Hs); free(H1);
}

/* (d) the assembled system on a real chart. */
static void test_assembled(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    bp_allocator a;
    int withb;
    memset(&opt, 0, sizeof opt);
    memset(&a, 0, sizeof a);
    if (!bpt_one_chart("tests/data/camel_b.obj", &mesh, &atlas, &opt, 1)) return;
    for (withb = 0; withb < 2; withb++) {
        bp_chart *ch = &atlas.charts[0];
        bp__solver S;
        bp__newton N;
        bp_options o;
        uint32_t nv2 = 2 * ch->num_vertices, i, j, p;
        double *x = (double *)malloc(nv2 * sizeof(double)), *w = (double *)malloc(nv2 * sizeof(double));
        double *gp = (double *)malloc(nv2 * sizeof(double)), *gm = (double *)malloc(nv2 * sizeof(double));
        double ed, worst = 0, wmin = HUGE_VAL, delta;
        int k, below = 0, neg = 0;
        memset(&o, 0, sizeof o);
        o.no_barrier = !withb;
        if (!BPT_CHECK(bp__solver_chart(&S, &a, ch, &mesh, &o, NULL, &err) == BP_OK, "solver for camel_b")) break;
        if (withb) S.eps = 4 * S.mean_edge;   /* far wider than the default: many pairs within eps */
        BPT_CHECK(bp__newton_init(&N, &a, &S) == BP_OK, "Newton set-up on camel_b");
        for (i = 0; i < N.H.colp[N.H.n]; i++) N.H.val[i] = NAN;   /* the pattern leaves them as allocated: the
                                                                      assembly must not read them */
        memcpy(x, ch->uv, nv2 * sizeof(double));
        bp__objective(&S, x, gp, &ed);
        bp__newton_assemble(&N, &S, x);
        {
            double tr = 0, bsum = 0;
            for (i = 0; i < S.nv; i++) tr += N.H.val[N.dpos[4 * i]] + N.H.val[N.dpos[4 * i + 3]];
            for (i = 0; i < N.pairs.count; i++)
                for (j = 0; j < 36; j++) bsum += fabs(((const bp__bpair *)N.pairs.data)[i].K[j]);
            delta = 1e-8 * (tr / (1 + 1e-8)) / nv2;
            if (withb) BPT_CHECK(bsum > 0 && N.pairs.count > 0, "camel_b, eps = 4 mean edges: the barrier adds to H (sum "
                                 "|pair Hessians| %.3g, %u pairs)", bsum, (unsigned)N.pairs.count);
            /* the shift the library took (summed from its gather tasks' and
               the pairs' diagonals) against the one recovered from H's own
               diagonal: a diagonal left out of the trace, or taken before
               the pairs added to it, fails this */
            BPT_CHECK(fabs(N.delta - delta) <= 1e-9 * delta, "camel_b %s: the shift delta %.9g is 1e-8 trace / n of H before "
                      "it (%.9g recovered from H's diagonal)", withb ? "with the barrier" : "without barrier", N.delta, delta);
        }
        check_gather(&N, &S, x, withb ? NULL : &delta);
        for (k = 0; k < 20; k++) {
            double wHw = 0, wFw = 0, ww = 0, h, wmax = 0;
            for (i = 0; i < nv2; i++) { w[i] = bpt_rng_range(-1, 1); ww += w[i] * w[i]; if (fabs(w[i]) > wmax) wmax = fabs(w[i]); }
            for (j = 0; j < nv2; j++)
                for (p = N.H.colp[j]; p < N.H.colp[j + 1]; p++) wHw += w[N.H.row[p]] * N.H.val[p] * w[j];
            wHw -= delta * ww;
            if (wHw < wmin) wmin = wHw;
            if (wHw < 0) neg++;
            if (!withb) {
                /* w^T H_true w by central differences of the gradient along w, step
                   small against the smallest triangle's scale */
                h = 1e-7 / wmax;
                for (i = 0; i < nv2; i++) x[i] = ch->uv[i] + h * w[i];
                bp__objective(&S, x, gp, &ed);
                for (i = 0; i < nv2; i++) x[i] = ch->uv[i] - h * w[i];
                bp__objective(&S, x, gm, &ed);
                for (i = 0; i < nv2; i++) wFw += w[i] * (gp[i] - gm[i]) / (2 * h);
                if (wHw < wFw - 1e-6 * fabs(wFw)) below++;
                if (fabs(wHw - wFw) / fabs(wFw) > worst) worst = fabs(wHw - wFw) / fabs(wFw);
                memcpy(x, ch->uv, nv2 * sizeof(double));
            }
        }
        BPT_CHECK(neg == 0, "camel_b %s: w^T H w >= 0 for 20 random w (min %.3g)", withb ? "with the barrier" : "without barrier",
                  wmin);
        if (!withb)
            BPT_CHECK(below == 0 && worst > 1e-6, "camel_b start map: w^T H_projected w >= w^T H_true w (finite differences) "
                      "for 20 random w, and differs (max relative gap %.3g)", worst);
        bp__newton_free(&a, &N);
        bp__solver_free(&S);
        free(x); free(w); free(gp); free(gm);
    }
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

static void test_optimize(const char *path)
{
    bp_mesh mesh;
    bp_error err;
    bp_atlas at[3];
    bp_options opt;
    int r;
    if (!BPT_CHECK(bp_read_mesh(path, &mesh, NULL, &err) == BP_OK, "read %s: %s", path, err.message)) return;
    for (r = 0; r < 3; r++) {
        memset(&opt, 0, sizeof opt);
        opt.threads = 1;
        opt.direction = r == 0 ? BP_DIRECTION_PRECONDITIONED : BP_DIRECTION_NEWTON;
        if (r == 2) opt.parallel_for = bpt_backwards_for;
        BPT_CHECK(bp_parameterize(&at[r], &mesh, &opt, &err) == BP_OK, "%s direction %d: %s", path, (int)opt.direction,
                  err.message);
    }
    {
        bp_chart *cp = &at[0].charts[0], *cn = &at[1].charts[0];
        bp_check_report rep;
        bp_status st = bp_check(cn->triangles, cn->num_triangles, cn->uv, cn->num_vertices, NULL, &rep, NULL);
        BPT_CHECK(st == BP_OK && rep.flipped == 0 && rep.degenerate == 0 && rep.boundary_intersections == 0 &&
                  rep.loop_orientation == 0 && rep.nested == 0 && rep.nonfinite == 0,
                  "%s Newton: the map is exactly bijective", path);
        BPT_CHECK(cn->stop == BP_STOP_CONVERGED, "%s Newton: converged (%s after %d iterations)", path,
                  bp_stop_string(cn->stop), cn->iterations);
        BPT_CHECK(cn->energy_end <= cp->energy_end * 1.001, "%s Newton: energy %.6f <= L-BFGS's %.6f + 0.1%%", path,
                  cn->energy_end, cp->energy_end);
        BPT_CHECK(cn->iterations < cp->iterations, "%s Newton: %d iterations < L-BFGS's %d", path, cn->iterations,
                  cp->iterations);
        BPT_CHECK(memcmp(cn->uv, at[2].charts[0].uv, 2 * (size_t)cn->num_vertices * sizeof(double)) == 0 &&
                  cn->iterations == at[2].charts[0].iterations,
                  "%s Newton: the same bits with the parallel tasks run in reverse order", path);
    }
    for (r = 0; r < 3; r++) bp_atlas_free(&at[r]);
    bp_mesh_free(&mesh, NULL);
}

static void test_pinned_direction(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options o;
    bp_allocator a;
    bp__solver S;
    bp__newton N, N0;
    bp_chart *ch;
    uint32_t nv2, i, j, p, *hold, nheld = 0, zero = 0, moved_free = 0;
    double *x, *g, *v, *v0, *r, gv = 0, gv0 = 0, ed, gmax = 0, worst = 0;
    int nd, nd0;
    memset(&o, 0, sizeof o);
    memset(&a, 0, sizeof a);
    if (!bpt_one_chart("tests/data/camel_b.obj", &mesh, &atlas, &o, 1)) return;
    ch = &atlas.charts[0];
    nv2 = 2 * ch->num_vertices;
    x = (double *)malloc(nv2 * sizeof(double)); g = (double *)malloc(nv2 * sizeof(double));
    v = (double *)malloc(nv2 * sizeof(double)); v0 = (double *)malloc(nv2 * sizeof(double));
    r = (double *)malloc(nv2 * sizeof(double));
    hold = (uint32_t *)malloc(ch->num_vertices * sizeof(uint32_t));
    for (i = 0; i < ch->num_vertices; i++) hold[i] = i % 7 == 3 ? nheld++ : BP__NONE;
    if (BPT_CHECK(bp__solver_chart(&S, &a, ch, &mesh, &o, NULL, &err) == BP_OK, "solver for camel_b")) {
        memcpy(x, ch->uv, nv2 * sizeof(double));
        bp__objective(&S, x, g, &ed);
        for (i = 0; i < ch->num_vertices; i++)
            if (hold[i] != BP__NONE) g[2 * i] = g[2 * i + 1] = 0;         /* as bp__opt_hold does */
        for (i = 0; i < nv2; i++) if (fabs(g[i]) > gmax) gmax = fabs(g[i]);
        BPT_CHECK(bp__newton_init(&N, &a, &S) == BP_OK && bp__newton_init(&N0, &a, &S) == BP_OK, "Newton set-ups");
        N.hold = hold;
        nd = bp__newton_direction(&N, &S, x, g, v, &gv);
        nd0 = bp__newton_direction(&N0, &S, x, g, v0, &gv0);       /* no hold: N0.H is the unpinned matrix */
        BPT_CHECK(nd == 1 && nd0 == 1 && gv < 0, "camel_b, %u of %u vertices held: Newton directions factored (%d %d), "
                  "g.v = %.3g < 0", nheld, ch->num_vertices, nd, nd0, gv);
        for (i = 0; i < ch->num_vertices; i++) {
            if (hold[i] != BP__NONE) {
                zero += v[2 * i] == 0 && v[2 * i + 1] == 0;
                moved_free += v0[2 * i] != 0 || v0[2 * i + 1] != 0;
            }
        }
        BPT_CHECK(zero == nheld, "held: v exactly 0 on %u of %u held vertices", zero, nheld);
        BPT_CHECK(moved_free > nheld / 2, "without the hold v is nonzero on %u of those %u vertices", moved_free, nheld);
        for (i = 0; i < nv2; i++) r[i] = g[i];
        for (j = 0; j < nv2; j++)
            for (p = N0.H.colp[j]; p < N0.H.colp[j + 1]; p++) r[N0.H.row[p]] += N0.H.val[p] * v[j];
        for (i = 0; i < nv2; i++)
            if (hold[i / 2] == BP__NONE && fabs(r[i]) > worst) worst = fabs(r[i]);
        BPT_CHECK(worst <= 1e-8 * gmax, "held: the free rows solve the unpinned system, max |(H v + g)_i| = %.3g "
                  "(max |g| %.3g)", worst, gmax);
        bp__newton_free(&a, &N);
        bp__newton_free(&a, &N0);
        bp__solver_free(&S);
    }
    free(x); free(g); free(v); free(v0); free(r); free(hold);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* (g) */
typedef struct ext_watch { bp_chart *ch; int iters, longer, bad, longer_checked; double tmax; } ext_watch;

static int ext_progress(void *user, uint32_t chart, int it, double e, double step)
{
    ext_watch *W = (ext_watch *)user;
    bp_check_report rep;
    bp_status st = bp_check(W->ch->triangles, W->ch->num_triangles, W->ch->uv, W->ch->num_vertices, NULL, &rep, NULL);
    (void)chart; (void)e;
    W->iters = it;
    if (st != BP_OK || rep.flipped || rep.degenerate || rep.boundary_intersections || rep.nonfinite) W->bad++;
    if (step > 1) { W->longer++; if (st == BP_OK) W->longer_checked++; }
    if (step > W->tmax) W->tmax = step;
    return 0;
}

static void test_longer_steps(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options o;
    ext_watch W;
    memset(&o, 0, sizeof o);
    memset(&W, 0, sizeof W);
    if (bpt_one_chart("tests/data/camel_b.obj", &mesh, &atlas, &o, 1)) {
        W.ch = &atlas.charts[0];
        o.direction = BP_DIRECTION_NEWTON;
        o.threads = 1;
        o.progress = ext_progress;
        o.progress_user = &W;
        BPT_CHECK(bp_chart_optimize(W.ch, 0, &mesh, &o, &err) == BP_OK && W.ch->stop == BP_STOP_CONVERGED,
                  "camel_b Newton with the progress check: converged (%s, %d iterations)", bp_stop_string(W.ch->stop),
                  W.ch->iterations);
        BPT_CHECK(W.iters > 0 && W.bad == 0, "camel_b Newton: all %d accepted maps exactly bijective by bp_check (%d not)",
                  W.iters, W.bad);
        BPT_CHECK(W.longer > 0 && W.longer_checked == W.longer,
                  "camel_b Newton: %d accepted steps longer than 1 (longest %.3g), each map checked bijective",
                  W.longer, W.tmax);
        bp_atlas_free(&atlas);
        bp_mesh_free(&mesh, NULL);
    }
}

/* (g) the gate: camel_b by Newton, one thread, with the doubling tried
   after a full step only from a share `ratio` of the model's decrease;
   the map, and the count of bp__opt_extend's loop tests. */
static int solve_gated(double ratio, double **uv, long *loops)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options o;
    int ok = 0;
    memset(&o, 0, sizeof o);
    *uv = NULL;
    if (!bpt_one_chart("tests/data/camel_b.obj", &mesh, &atlas, &o, 1)) return 0;
    o.direction = BP_DIRECTION_NEWTON;
    o.threads = 1;
    bpt_extend_ratio = ratio;
    bpt_extend_loops = 0;
    if (bp_chart_optimize(&atlas.charts[0], 0, &mesh, &o, &err) == BP_OK) {
        size_t bytes = 2 * (size_t)atlas.charts[0].num_vertices * sizeof(double);
        *uv = (double *)malloc(bytes);
        memcpy(*uv, atlas.charts[0].uv, bytes);
        ok = (int)(bytes / sizeof(double));
    }
    *loops = bpt_extend_loops;
    bpt_extend_ratio = 0.9;
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
    return ok;
}

static void test_extend_gate(void)
{
    double *gated, *always, *never;
    long lg, la, ln;
    int n = solve_gated(0.9, &gated, &lg), na = solve_gated(-HUGE_VAL, &always, &la), nn = solve_gated(HUGE_VAL, &never, &ln);
    if (BPT_CHECK(n > 0 && na == n && nn == n, "camel_b Newton, gated, always and never extended: solved"))  {
        BPT_CHECK(memcmp(gated, always, n * sizeof(double)) == 0 && lg < la,
                  "camel_b Newton: the gate (a share of 0.9 of the model's decrease) declines doublings (%ld loop "
                  "tests against %ld) that would have gained nothing: the same bits as always trying", lg, la);
        BPT_CHECK(ln == 0 && memcmp(never, always, n * sizeof(double)) != 0,
                  "camel_b Newton: never doubling (%ld loop tests) gives another map, so the comparison can fail", ln);
    }
    free(gated); free(always); free(never);
}

/* (h): m(v) = g.v + v.H v / 2 with H's stored values (full pattern). */
static double model(const bp__sparse *H, const double *g, const double *v)
{
    uint32_t j, p;
    double vhv = 0, gv = 0;
    for (j = 0; j < H->n; j++) {
        gv += g[j] * v[j];
        for (p = H->colp[j]; p < H->colp[j + 1]; p++) vhv += v[H->row[p]] * H->val[p] * v[j];
    }
    return gv + 0.5 * vhv;
}

static void test_reuse(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options o;
    bp_allocator a;
    bp__solver S;
    bp__newton N, N2;
    uint32_t nv2, i, j, p;
    double *x, *xn, *g, *v, *vs, *rhs, ed, f, fn;
    int k, descent = 0, above = 0, gated = 0, gconv = 0, close = 0, tries = 0, prev_full = 0;
    double worst_gap = 0, gd_gap = 1, prev_pred = 0, prev_dec = 0, prev_f = 0;
    memset(&o, 0, sizeof o);
    memset(&a, 0, sizeof a);
    o.no_barrier = 1;
    if (!bpt_one_chart("tests/data/camel_b.obj", &mesh, &atlas, &o, 1)) return;
    nv2 = 2 * atlas.charts[0].num_vertices;
    x = (double *)malloc(nv2 * sizeof(double)); g = (double *)malloc(nv2 * sizeof(double));
    v = (double *)malloc(nv2 * sizeof(double)); vs = (double *)malloc(nv2 * sizeof(double));
    rhs = (double *)malloc(nv2 * sizeof(double)); xn = (double *)malloc(nv2 * sizeof(double));
    if (BPT_CHECK(bp__solver_chart(&S, &a, &atlas.charts[0], &mesh, &o, NULL, &err) == BP_OK, "solver for camel_b") &&
        BPT_CHECK(bp__newton_init(&N, &a, &S) == BP_OK, "Newton set-up")) {
        memcpy(x, atlas.charts[0].uv, nv2 * sizeof(double));
        f = bp__objective(&S, x, g, &ed);
        for (k = 0; k < 30; k++) {
            double gv = 0, ms, mr, tmax, t;
            int ok;
            if (k > 0) {                                   /* N.F: the factor at the previous map */
                /* the library's gate: the last step was the full one and
                   decreased f by [1/2, 2] x the model's prediction */
                int gate = prev_full && prev_dec >= 0.5 * prev_pred && prev_dec <= 2 * prev_pred && prev_dec <= 0.1 * prev_f;
                bp__newton_assemble(&N, &S, x);
                for (i = 0; i < nv2; i++) rhs[i] = -g[i];
                ok = bp__newton_reuse_solve(&N, rhs, v);
                tries++;
                if (k % 7 == 1) {      /* the same CG on a two-thread runner, tasks backwards */
                    double *v2 = (double *)malloc(nv2 * sizeof(double));
                    bp__par back = S.par;
                    int ok2;
                    back.run = bpt_backwards_for;
                    back.user = NULL;
                    back.threads = 2;
                    N.par = &back;
                    ok2 = bp__newton_reuse_solve(&N, rhs, v2);
                    N.par = NULL;
                    BPT_CHECK(ok2 == ok && memcmp(v, v2, nv2 * sizeof(double)) == 0,
                              "camel_b map %d: the reused factor's CG on two threads, tasks backwards: the same bits", k);
                    free(v2);
                }
                if (bp__newton_init(&N2, &a, &S) == BP_OK) {  /* the exact step at x: a fresh factorization */
                    bp__newton_direction(&N2, &S, x, g, vs, &gv);
                    gv = 0;
                    for (i = 0; i < nv2; i++) gv += g[i] * v[i];
                    ms = model(&N2.H, g, vs);
                    mr = model(&N2.H, g, v);
                    descent += gv < 0 && mr < 0;
                    above += mr >= ms - 1e-9 * fabs(ms);
                    if (gate) {
                        gated++;
                        if (ok) { gconv++; close += mr <= 0.9 * ms; if (1 - mr / ms > worst_gap) worst_gap = 1 - mr / ms; }
                    }
                    {   /* the gradient at its best length: m(-a g) = -a |g|^2 + a^2 g.H g / 2 */
                        double gg = 0, gHg = 0;
                        for (j = 0; j < nv2; j++) {
                            gg += g[j] * g[j];
                            for (p = N2.H.colp[j]; p < N2.H.colp[j + 1]; p++) gHg += g[N2.H.row[p]] * N2.H.val[p] * g[j];
                        }
                        if (gHg > 0 && (-0.5 * gg * gg / gHg) / ms < gd_gap) gd_gap = (-0.5 * gg * gg / gHg) / ms;
                    }
                    bp__newton_free(&a, &N2);
                }
            }
            N.cut = 1;                                     /* factor at x: the next map's preconditioner */
            if (bp__newton_direction(&N, &S, x, g, v, &gv) != 1) break;
            /* a plain backtracking line search within the bound */
            tmax = bp__step_bound(&S, x, v, 1 / 0.9);
            t = tmax < 1 / 0.9 ? 0.9 * tmax : 1;
            for (;; t *= 0.5) {
                for (i = 0; i < nv2; i++) xn[i] = x[i] + t * v[i];
                fn = bp__objective(&S, xn, rhs, &ed);
                if (fn <= f + 1e-4 * t * gv || t < 1e-12) break;
            }
            prev_full = t == 1;
            prev_pred = -0.5 * gv;
            prev_dec = f - fn;
            prev_f = f;
            memcpy(x, xn, nv2 * sizeof(double));
            f = bp__objective(&S, x, g, &ed);
        }
        BPT_CHECK(tries == 29 && descent == tries && above == tries,
                  "camel_b, 29 maps: CG preconditioned by the previous map's factor gives descent directions with "
                  "m(v) < 0 (%d), never below the exact step's model (%d)", descent, above);
        BPT_CHECK(gated >= 5 && gconv == gated && close == gconv,
                  "camel_b: at the %d maps the gate lets reuse, CG converged (%d) within 10%% of the exact step's model "
                  "decrease (%d; largest shortfall %.3g; the best gradient step reaches only %.3g of it)",
                  gated, gconv, close, worst_gap, gd_gap);
        BPT_CHECK(gd_gap < 0.9, "the gradient step falls short of 90%% of the model decrease (%.3g), so the bound can fail",
                  gd_gap);
        bp__newton_free(&a, &N);
        bp__solver_free(&S);
    }
    free(x); free(xn); free(g); free(v); free(vs); free(rhs);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* The default direction (bp__opt_choose_newton, docs/performance.md, "The
   default direction"): for each chart the default's map after a few
   iterations must be, bit for bit, the one of the direction that the
   documented rule names for the chart's energy, size and reported start
   energy -- Newton for the symmetric Dirichlet energy on 1,000 triangles
   or more with a finite energy_start of at least 8, at any size; else the
   preconditioned L-BFGS -- and differ from the other direction's (so that
   the comparison can fail).  camel_b (E0 870) and bishop (71) are small
   charts far from an isometry, face_holes (4.08) a small one near it,
   camel_b and camelhead under MIPS charts of another energy, camelhead
   (65) and lucy (its mean-value start at 1.2e15) mid-sized charts far
   from an isometry, beetle (38,656 triangles, 4.19) a mid-sized one near
   it, and camelhead subdivided 3 x 3 (204,336 triangles, its conformal
   start at 65, its mean-value one at 121: far from an isometry either
   way) a large one.  A rule by size alone (Newton for every chart of
   20,000-99,999 triangles, L-BFGS above) fails the last three. */
static void test_default_choice_mesh(const char *name, const bp_mesh *mesh, bp_energy energy, int iterations)
{
    bp_error err;
    bp_atlas at[3];
    bp_options opt;
    int r, ok = 1;
    for (r = 0; r < 3; r++) {
        static const bp_direction D[3] = { BP_DIRECTION_DEFAULT, BP_DIRECTION_PRECONDITIONED, BP_DIRECTION_NEWTON };
        memset(&opt, 0, sizeof opt);
        opt.threads = 1;
        opt.max_iterations = iterations;
        opt.energy = energy;
        opt.direction = D[r];
        ok &= BPT_CHECK(bp_parameterize(&at[r], mesh, &opt, &err) == BP_OK, "%s direction %d: %s", name, (int)D[r],
                        err.message);
    }
    if (ok) {
        const bp_chart *cd = &at[0].charts[0];
        size_t n = 2 * (size_t)cd->num_vertices * sizeof(double);
        int newton = energy == BP_ENERGY_SYMMETRIC_DIRICHLET && cd->num_triangles >= 1000 &&
                     cd->energy_start >= 8 && cd->energy_start < HUGE_VAL;
        const bp_chart *want = &at[newton ? 2 : 1].charts[0], *other = &at[newton ? 1 : 2].charts[0];
        BPT_CHECK(at[0].num_charts == 1 && memcmp(cd->uv, want->uv, n) == 0 && cd->iterations == want->iterations,
                  "%s (%u triangles, energy %d, start energy %.3g): the default is %s, bit for bit", name,
                  cd->num_triangles, (int)energy, cd->energy_start, newton ? "Newton" : "the preconditioned L-BFGS");
        BPT_CHECK(memcmp(cd->uv, other->uv, n) != 0, "%s: and not %s", name,
                  newton ? "the preconditioned L-BFGS" : "Newton");
    }
    for (r = 0; r < 3; r++) if (ok) bp_atlas_free(&at[r]);
}

static void test_default_choice(const char *path, bp_energy energy)
{
    bp_mesh mesh;
    bp_error err;
    if (!BPT_CHECK(bp_read_mesh(path, &mesh, NULL, &err) == BP_OK, "read %s: %s", path, err.message)) return;
    test_default_choice_mesh(path, &mesh, energy, 3);
    bp_mesh_free(&mesh, NULL);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Every triangle of `in` split into 3 x 3 similar ones in its own plane
   (bench/subdivide.py's grid P(i, j) = a + i/3 (b - a) + j/3 (c - a), no
   bump): the two points on an edge are shared by its triangles, so a disk
   stays a disk with the same loops.  Returns 0 out of memory. */
static int subdivide3(const bp_mesh *in, bp_mesh *out)
{
    uint32_t nv = in->num_vertices, nt = in->num_triangles, t, k, ne = 0, i, j;
    uint64_t *key = (uint64_t *)malloc(3 * (size_t)nt * sizeof(uint64_t));
    memset(out, 0, sizeof *out);
    if (!key) return 0;
    for (t = 0; t < nt; t++)
        for (k = 0; k < 3; k++) {
            uint64_t u = in->triangles[3 * t + k], v = in->triangles[3 * t + (k + 1) % 3];
            key[3 * (size_t)t + k] = u < v ? u * nv + v : v * nv + u;
        }
    qsort(key, 3 * (size_t)nt, sizeof(uint64_t), cmp_u64);
    for (k = 0; k < 3 * nt; k++) if (k == 0 || key[k] != key[k - 1]) key[ne++] = key[k];
    out->num_vertices = nv + 2 * ne + nt;
    out->num_triangles = out->num_faces = 9 * nt;
    out->positions = (double *)malloc(3 * (size_t)out->num_vertices * sizeof(double));
    out->triangles = (uint32_t *)malloc(3 * (size_t)out->num_triangles * sizeof(uint32_t));
    if (!out->positions || !out->triangles) { free(key); free(out->positions); free(out->triangles); return 0; }
    memcpy(out->positions, in->positions, 3 * (size_t)nv * sizeof(double));
    for (k = 0; k < ne; k++) {                       /* the edge's points at 1/3 and 2/3 from its lower end */
        const double *lo = in->positions + 3 * (key[k] / nv), *hi = in->positions + 3 * (key[k] % nv);
        for (i = 0; i < 3; i++) {
            out->positions[3 * ((size_t)nv + 2 * k) + i] = lo[i] + (hi[i] - lo[i]) / 3;
            out->positions[3 * ((size_t)nv + 2 * k + 1) + i] = lo[i] + 2 * (hi[i] - lo[i]) / 3;
        }
    }
    for (t = 0; t < nt; t++) {
        const uint32_t *c = in->triangles + 3 * (size_t)t;
        uint32_t P[4][4], *o = out->triangles + 27 * (size_t)t, q = 0;
        uint32_t ends[3][2] = { { c[0], c[1] }, { c[0], c[2] }, { c[1], c[2] } }, pt[3][2];
        for (k = 0; k < 3; k++) {                    /* pt[k][s]: the point (s+1)/3 from ends[k][0] */
            uint32_t u = ends[k][0], v = ends[k][1];
            uint64_t want = u < v ? (uint64_t)u * nv + v : (uint64_t)v * nv + u;
            const uint64_t *f = (const uint64_t *)bsearch(&want, key, ne, sizeof(uint64_t), cmp_u64);
            uint32_t e = nv + 2 * (uint32_t)(f - key);
            pt[k][0] = u < v ? e : e + 1;
            pt[k][1] = u < v ? e + 1 : e;
        }
        P[0][0] = c[0]; P[3][0] = c[1]; P[0][3] = c[2];
        P[1][0] = pt[0][0]; P[2][0] = pt[0][1];      /* a -> b */
        P[0][1] = pt[1][0]; P[0][2] = pt[1][1];      /* a -> c */
        P[2][1] = pt[2][0]; P[1][2] = pt[2][1];      /* b -> c: (i, j) = (3 - s, s) */
        P[1][1] = nv + 2 * ne + t;
        for (k = 0; k < 3; k++)
            out->positions[3 * (size_t)P[1][1] + k] = (in->positions[3 * (size_t)c[0] + k] +
                                                       in->positions[3 * (size_t)c[1] + k] +
                                                       in->positions[3 * (size_t)c[2] + k]) / 3;
        for (i = 0; i < 3; i++)
            for (j = 0; i + j < 3; j++) {
                o[q++] = P[i][j]; o[q++] = P[i + 1][j]; o[q++] = P[i][j + 1];
                if (i + j < 2) { o[q++] = P[i + 1][j]; o[q++] = P[i + 1][j + 1]; o[q++] = P[i][j + 1]; }
            }
    }
    free(key);
    return 1;
}

/* The large chart of test_default_choice: camelhead 3 x 3 (204,336
   triangles, above the 100,000 where the earlier rule stopped). */
static void test_default_choice_large(void)
{
    bp_mesh mesh, big;
    bp_error err;
    if (!BPT_CHECK(bp_read_mesh("tests/data/camelhead.off", &mesh, NULL, &err) == BP_OK, "read camelhead: %s",
                   err.message))
        return;
    if (BPT_CHECK(subdivide3(&mesh, &big), "camelhead 3 x 3 made (else out of memory)")) {
        BPT_CHECK(big.num_triangles == 204336 && big.num_vertices == 102253, "camelhead 3 x 3: %u triangles, %u vertices",
                  big.num_triangles, big.num_vertices);
        test_default_choice_mesh("camelhead 3 x 3", &big, BP_ENERGY_SYMMETRIC_DIRICHLET, 2);
        free(big.positions);
        free(big.triangles);
    }
    bp_mesh_free(&mesh, NULL);
}

/* (i) the model's wider barrier (>>newton):
   after a step clipped by the boundary's step bound, the matrix takes the
   Gauss-Newton terms of a barrier of width em = BP__NEWTON_WIDE eps.  On
   camel_b (eps = one mean edge, so that many pairs lie within 3 eps), the
   matrix assembled with it minus the one without, along random w, must be
       sum over the pairs (f''(d; em) - f''(d; eps)) (sum_j c_j n.w_j)^2
   plus the change of the shift delta I, f''(d; e) of f = (e/d - 1)^2 taken
   by central differences here (0 beyond e), every boundary vertex / edge
   pair of a loop enumerated by brute force (no hash), c = 1, -(1 - s), -s
   on the vertex and the edge's ends, n the unit direction from the
   edge's closest point.  Hence also: the difference is positive
   semidefinite (the direction stays a descent direction), and it is not 0.
   (A pair whose closest point is inside its edge gets its whole Hessian,
   projected, in the matrix (>>barrier, bp__barrier_pair_hessian, checked
   against second differences by tests/test_stepbound.c (d)); the pairs
   this test finds within 3 eps of one mean edge all meet their edge at an
   end, where the whole Hessian's projection is the Gauss-Newton term, so
   the brute-force sum above is the whole expected difference.) */
static double fd_f2(double d, double e)
{
    double h = 1e-4 * d, f0, fp, fm;
    if (!(d < e)) return 0;
    f0 = (e / d - 1) * (e / d - 1);
    fp = d + h < e ? (e / (d + h) - 1) * (e / (d + h) - 1) : 0;
    fm = (e / (d - h) - 1) * (e / (d - h) - 1);
    return (fp - 2 * f0 + fm) / (h * h);
}

static void test_wide_barrier(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options o;
    bp_allocator a;
    bp__solver S;
    bp__newton N;
    uint32_t nv2, i, e, k, p, j;
    double *x, *g, *hn, ed, worst = 0, tn = 0, tw = 0;
    int trial, npairs = 0, nbeyond = 0, neg = 0, nonzero = 0;
    memset(&o, 0, sizeof o);
    memset(&a, 0, sizeof a);
    if (!bpt_one_chart("tests/data/camel_b.obj", &mesh, &atlas, &o, 1)) return;
    nv2 = 2 * atlas.charts[0].num_vertices;
    x = (double *)malloc(nv2 * sizeof(double)); g = (double *)malloc(nv2 * sizeof(double));
    if (BPT_CHECK(bp__solver_chart(&S, &a, &atlas.charts[0], &mesh, &o, NULL, &err) == BP_OK, "solver for camel_b") &&
        BPT_CHECK(bp__newton_init(&N, &a, &S) == BP_OK, "Newton set-up")) {
        double em;
        S.eps = S.mean_edge;
        em = BP__NEWTON_WIDE * S.eps;
        memcpy(x, atlas.charts[0].uv, nv2 * sizeof(double));
        bp__objective(&S, x, g, &ed);
        N.wide = 0;
        bp__newton_assemble(&N, &S, x);               /* grows the pattern by every pair within 3 eps */
        hn = (double *)malloc((size_t)N.H.colp[N.H.n] * sizeof(double));
        memcpy(hn, N.H.val, (size_t)N.H.colp[N.H.n] * sizeof(double));
        for (i = 0; i < S.nv; i++) tn += hn[N.dpos[4 * i]] + hn[N.dpos[4 * i + 3]];
        N.wide = 1;
        bp__newton_assemble(&N, &S, x);
        for (i = 0; i < S.nv; i++) tw += N.H.val[N.dpos[4 * i]] + N.H.val[N.dpos[4 * i + 3]];
        BPT_CHECK(N.H.colp[N.H.n] > 0 && N.H.n == nv2, "camel_b: the same pattern with and without the wider barrier");
        for (trial = 0; trial < 20; trial++) {
            double *wv = (double *)malloc(nv2 * sizeof(double)), got = 0, want = 0, ww = 0, dn, dw;
            for (i = 0; i < nv2; i++) { wv[i] = bpt_rng_range(-1, 1); ww += wv[i] * wv[i]; }
            for (j = 0; j < nv2; j++)
                for (p = N.H.colp[j]; p < N.H.colp[j + 1]; p++) got += wv[N.H.row[p]] * (N.H.val[p] - hn[p]) * wv[j];
            /* the shifts: delta = 1e-8 trace / n of the matrix before the shift */
            dn = 1e-8 * (tn / (1 + 1e-8)) / nv2;
            dw = 1e-8 * (tw / (1 + 1e-8)) / nv2;
            want = (dw - dn) * ww;
            for (e = 0; e < S.nb; e++) {
                uint32_t L = S.bl_loop[e], s0 = S.loop_start[L], n = S.loop_start[L + 1] - s0, ii = e - s0, i1 = (ii + 1) % n;
                const double *A = x + 2 * (size_t)S.loop_vertices[e], *B = x + 2 * (size_t)S.loop_vertices[s0 + i1];
                for (k = 0; k < n; k++) {
                    const double *P;
                    double ex, ey, len2, sp, dx, dy, d, c[3], t;
                    uint32_t vv[3];
                    if (k == ii || k == i1) continue;
                    vv[0] = S.loop_vertices[s0 + k]; vv[1] = S.loop_vertices[e]; vv[2] = S.loop_vertices[s0 + i1];
                    P = x + 2 * (size_t)vv[0];
                    ex = B[0] - A[0]; ey = B[1] - A[1];
                    len2 = ex * ex + ey * ey;
                    sp = len2 > 0 ? ((P[0] - A[0]) * ex + (P[1] - A[1]) * ey) / len2 : 0;
                    if (sp < 0) sp = 0;
                    if (sp > 1) sp = 1;
                    dx = P[0] - (A[0] + sp * ex); dy = P[1] - (A[1] + sp * ey);
                    d = sqrt(dx * dx + dy * dy);
                    if (!(d < em) || !(d > 0)) continue;
                    if (trial == 0) { npairs++; nbeyond += d >= S.eps; }
                    c[0] = 1; c[1] = -(1 - sp); c[2] = -sp;
                    t = 0;
                    for (j = 0; j < 3; j++) t += c[j] * (dx / d * wv[2 * vv[j]] + dy / d * wv[2 * vv[j] + 1]);
                    want += (fd_f2(d, em) - fd_f2(d, S.eps)) * t * t;
                }
            }
            if (fabs(got - want) / fabs(want) > worst) worst = fabs(got - want) / fabs(want);
            neg += got < 0;
            nonzero += got > 0;
            free(wv);
        }
        BPT_CHECK(nbeyond > 0 && npairs > nbeyond, "camel_b, eps = 1 mean edge: %d pairs within %g eps, %d of them "
                  "beyond eps", npairs, (double)BP__NEWTON_WIDE, nbeyond);
        BPT_CHECK(worst < 1e-5, "camel_b: w.(H_wide - H) w == the brute-force sum of the wider barrier's terms by "
                  "finite differences, 20 random w (max relative error %.3g)", worst);
        BPT_CHECK(neg == 0 && nonzero == 20, "camel_b: the wider barrier adds a positive semidefinite, nonzero term "
                  "(%d of 20 w negative, %d positive)", neg, nonzero);
        free(hn);
        bp__newton_free(&a, &N);
        bp__solver_free(&S);
    }
    free(x); free(g);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* (j) Newton's pattern (bp__newton_pattern, built column by column in
   parallel chunks) against a brute-force construction written here: every
   (row, column) vertex pair of every triangle (the diagonal included),
   every vertex's diagonal and both orders of every extra pair, sorted by
   column then row by qsort and made distinct.  H's columns 2v and 2v+1
   must hold exactly the rows 2w, 2w+1 of those w in order, tpos must point
   at each triangle block's entry (2 tri[k], 2 tri[l]) and dpos at each
   vertex's diagonal entries, and H's values must be 0.  On camelhead
   (six vertex chunks), serially, then with extra pairs (random, some
   repeated, some already edges) with the chunks run backwards on a
   two-thread runner, and on a real pool of two threads. */
static int pair_cmp(const void *a, const void *b)
{
    const uint32_t *x = (const uint32_t *)a, *y = (const uint32_t *)b;
    return x[1] != y[1] ? (x[1] < y[1] ? -1 : 1) : (x[0] < y[0] ? -1 : x[0] > y[0]);
}

static void check_pattern(const bp__newton *N, const bp__solver *S, const char *what)
{
    const uint32_t *ex = (const uint32_t *)N->extra.data;
    size_t np = 9 * (size_t)S->nt + S->nv + 2 * N->extra.count, k, q = 0;
    uint32_t *pr = (uint32_t *)malloc(2 * np * sizeof(uint32_t)), v, t, a, b, bad = 0, badt = 0, badd = 0, badv = 0;
    const bp__sparse *H = &N->H;
    for (t = 0; t < S->nt; t++)
        for (a = 0; a < 3; a++)
            for (b = 0; b < 3; b++) { pr[2 * q] = S->tri[3 * t + a]; pr[2 * q + 1] = S->tri[3 * t + b]; q++; }
    for (v = 0; v < S->nv; v++) { pr[2 * q] = pr[2 * q + 1] = v; q++; }
    for (k = 0; k < N->extra.count; k++) {
        pr[2 * q] = ex[2 * k]; pr[2 * q + 1] = ex[2 * k + 1]; q++;
        pr[2 * q] = ex[2 * k + 1]; pr[2 * q + 1] = ex[2 * k]; q++;
    }
    qsort(pr, q, 2 * sizeof(uint32_t), pair_cmp);
    BPT_CHECK(H->n == 2 * S->nv, "%s: H is 2nv x 2nv (%u)", what, H->n);
    for (k = 0, v = 0; v < S->nv && !bad; v++) {   /* column v's distinct rows */
        uint32_t m = 0, c, i, *rows = pr + 2 * k;      /* (the pairs' rows, read in place) */
        size_t k0 = k;
        for (; k < q && pr[2 * k + 1] == v; k++)
            if (k == k0 || pr[2 * k] != pr[2 * k - 2]) rows[2 * m++] = pr[2 * k];
        if (H->colp[2 * v + 1] - H->colp[2 * v] != 2 * m || H->colp[2 * v + 2] - H->colp[2 * v + 1] != 2 * m) { bad++; break; }
        for (c = 0; c < 2; c++)
            for (i = 0; i < m; i++) {
                uint32_t p = H->colp[2 * v + c] + 2 * i;
                if (H->row[p] != 2 * rows[2 * i] || H->row[p + 1] != 2 * rows[2 * i] + 1) bad++;
            }
    }
    BPT_CHECK(bad == 0, "%s: H's columns are the brute-force vertex pairs, sorted (%u wrong, at vertex %u)", what, bad, v);
    for (t = 0; t < S->nt; t++)
        for (a = 0; a < 3; a++)
            for (b = 0; b < 3; b++) {
                uint32_t P = N->tpos[9 * t + 3 * a + b], col = 2 * S->tri[3 * t + b];
                if (P < H->colp[col] || P >= H->colp[col + 1] || H->row[P] != 2 * S->tri[3 * t + a]) badt++;
            }
    BPT_CHECK(badt == 0, "%s: tpos points at every triangle block's entry (%u wrong)", what, badt);
    for (v = 0; v < S->nv; v++)
        for (a = 0; a < 4; a++) {
            uint32_t P = N->dpos[4 * v + a], col = 2 * v + a / 2;
            if (P < H->colp[col] || P >= H->colp[col + 1] || H->row[P] != 2 * v + a % 2) badd++;
        }
    BPT_CHECK(badd == 0, "%s: dpos points at every vertex's diagonal entries (%u wrong)", what, badd);
    badv = H->val[H->colp[H->n]] != 0;
    BPT_CHECK(badv == 0, "%s: H's values end in a 0 past the last entry (its values are left as allocated: (d) "
              "assembles over NaNs)", what);
    free(pr);
}

/* (j), (k): camelhead (an OFF file, so not through bpt_one_chart's OBJ
   reader) as one chart with its start map and a solver of default
   options; on failure what was made is freed and 0 returned. */
static int camelhead_solver(bp_mesh *mesh, bp_atlas *atlas, bp__solver *S, bp_allocator *a)
{
    bp_options opt;
    bp_error err;
    int built;
    memset(&opt, 0, sizeof opt);
    memset(a, 0, sizeof *a);
    if (!BPT_CHECK(bp_read_mesh("tests/data/camelhead.off", mesh, NULL, &err) == BP_OK, "read camelhead: %s", err.message))
        return 0;
    built = bp_atlas_build(atlas, mesh, &opt, &err) == BP_OK;
    if (BPT_CHECK(built && atlas->num_charts == 1 && bp_chart_init(&atlas->charts[0], mesh, &opt, &err) == BP_OK,
                  "camelhead: one chart, start map") &&
        BPT_CHECK(bp__solver_chart(S, a, &atlas->charts[0], mesh, &opt, NULL, &err) == BP_OK, "solver for camelhead"))
        return 1;
    if (built) bp_atlas_free(atlas);
    bp_mesh_free(mesh, NULL);
    return 0;
}

static void test_pattern(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_allocator a;
    bp__solver S;
    bp__newton N;
    uint32_t k;
    if (camelhead_solver(&mesh, &atlas, &S, &a)) {
        BPT_CHECK(S.nchunk_v > 2, "camelhead: several vertex chunks (%u)", S.nchunk_v);
        if (BPT_CHECK(bp__newton_init(&N, &a, &S) == BP_OK, "Newton set-up on camelhead")) {
            check_pattern(&N, &S, "camelhead, serial");
            for (k = 0; k < 300; k++) {      /* pairs anywhere, some twice, some edges */
                uint32_t uw[2];
                uw[0] = (uint32_t)(bpt_rng_unit() * S.nv) % S.nv;
                uw[1] = k % 5 ? (uint32_t)(bpt_rng_unit() * S.nv) % S.nv : S.tri[3 * k + 1];
                if (k % 5 == 0) uw[0] = S.tri[3 * k];
                if (uw[0] == uw[1]) continue;
                bp__vec_push(&a, &N.extra, uw);
                if (k % 7 == 0) bp__vec_push(&a, &N.extra, uw);
            }
            S.par.run = bpt_backwards_for;
            S.par.threads = 2;
            BPT_CHECK(bp__newton_pattern(&N, &a, &S) == BP_OK, "camelhead: the pattern with extra pairs");
            check_pattern(&N, &S, "camelhead, extra pairs, chunks backwards");
#ifdef BP_USE_PTHREADS
            {
                bp__pool *P = bp__pool_start(&a, 2);
                if (BPT_CHECK(P != NULL, "a pool of 2 threads")) {
                    S.par.run = bp__pool_for;
                    S.par.user = P;
                    BPT_CHECK(bp__newton_pattern(&N, &a, &S) == BP_OK, "camelhead: the pattern on 2 threads");
                    check_pattern(&N, &S, "camelhead, extra pairs, a pool of 2 threads");
                    bp__pool_stop(&a, P);
                }
            }
#endif
            bp__newton_free(&a, &N);
        }
        bp__solver_free(&S);
        bp_atlas_free(&atlas);
        bp_mesh_free(&mesh, NULL);
    }
}

/* (k) whether a pair of vertices keeps the tree a dissection, by brute
   force: no split node has one of them in each half. */
static int keeps_brute(const bp__ndnode *t, const uint32_t *iperm, uint32_t u, uint32_t w)
{
    uint32_t k, pu = iperm[u], pw = iperm[w];
    for (k = 0; k < BP__ND_NODES; k++) {
        const bp__ndnode *N = &t[k];
        if (!N->used || !N->split) continue;
        if ((pu >= N->lo && pu < N->a && pw >= N->a && pw < N->b) || (pw >= N->lo && pw < N->a && pu >= N->a && pu < N->b))
            return 0;
    }
    return 1;
}

static double residual_H(const bp__sparse *H, const double *x, const double *b)
{
    uint32_t j, p;
    double *r = (double *)calloc(H->n, sizeof(double)), rr = 0, bb = 0;
    for (j = 0; j < H->n; j++)
        for (p = H->colp[j]; p < H->colp[j + 1]; p++) r[H->row[p]] += H->val[p] * x[j];
    for (j = 0; j < H->n; j++) { rr += (r[j] - b[j]) * (r[j] - b[j]); bb += b[j] * b[j]; }
    free(r);
    return sqrt(rr / bb);
}

static void test_kept_order(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_allocator a;
    bp__solver S;
    bp__newton N;
    uint32_t k, bad, nv, n, mism = 0, valid = 0, invalid = 0, pushed = 0, sep = 0, badpair[2] = { 0, 0 };
    uint32_t *perm = NULL;
    bp_status st;
    bp__ndnode tree[BP__ND_NODES];
    if (!camelhead_solver(&mesh, &atlas, &S, &a)) return;
    if (BPT_CHECK(bp__newton_init(&N, &a, &S) == BP_OK, "Newton set-up on camelhead")) {
        double *b, *x, *z;
        bp__factor F2;
        nv = S.nv;
        n = 2 * nv;
        b = (double *)malloc(n * sizeof(double)); x = (double *)malloc(n * sizeof(double));
        z = (double *)malloc(n * sizeof(double));
        perm = (uint32_t *)malloc(nv * sizeof(uint32_t));
        bp__newton_assemble(&N, &S, atlas.charts[0].uv);
        BPT_CHECK(bp__newton_factorize(&N, &S, &bad) == BP_OK && N.F.sn && N.nkept == 0, "camelhead: H factored, a new order");
        memcpy(perm, N.F.sn->vperm, nv * sizeof(uint32_t));
        memcpy(tree, N.F.tree, sizeof tree);
        for (k = 0; k < 3000; k++) {
            uint32_t uw[2];
            int kb, kl;
            uw[0] = (uint32_t)(bpt_rng_unit() * nv) % nv;
            uw[1] = (uint32_t)(bpt_rng_unit() * nv) % nv;
            if (uw[0] == uw[1]) continue;
            kb = keeps_brute(tree, N.F.sn->viperm, uw[0], uw[1]);
            kl = bp__nd_keeps(tree, N.F.sn->viperm, uw, 1);
            mism += kb != kl;
            if (kb) valid++; else { invalid++; badpair[0] = uw[0]; badpair[1] = uw[1]; }
            if (kb && pushed < 20) { bp__vec_push(&a, &N.extra, uw); pushed++; }
        }
        BPT_CHECK(mism == 0 && valid > 0 && invalid > 0, "camelhead: bp__nd_keeps agrees with the brute force on %u valid "
                  "and %u invalid pairs (%u differ)", valid, invalid, mism);
        BPT_CHECK(bp__newton_pattern(&N, &a, &S) == BP_OK && N.kperm != NULL, "camelhead: %u valid pairs grow the pattern, "
                  "the old order kept", pushed);
        bp__newton_assemble(&N, &S, atlas.charts[0].uv);
        st = bp__newton_factorize(&N, &S, &bad);
        if (BPT_CHECK(st == BP_OK && N.nkept == 1 && N.kperm == NULL, "camelhead: factored with the kept order (counted %ld)",
                      N.nkept)) {
            int fb = 0;
            bp__par back = bp__par_serial();
            BPT_CHECK(memcmp(perm, N.F.sn->vperm, nv * sizeof(uint32_t)) == 0 && memcmp(tree, N.F.tree, sizeof tree) == 0,
                      "camelhead: the new factor's order and tree are the old ones");
            for (k = 0; k < n; k++) b[k] = bpt_rng_range(-1, 1);
            bp__factor_solve(&N.F, b, x, z);
            BPT_CHECK(residual_H(&N.H, x, b) < 1e-7, "camelhead, kept order: |H x - b| / |b| = %.2g", residual_H(&N.H, x, b));
            back.run = bpt_backwards_for;
            back.threads = 2;
            if (BPT_CHECK(bp__super_factorize(&a, &N.H, &F2, &bad, &back, 2, &fb, perm, tree) == BP_OK && F2.sn,
                          "camelhead: the kept order factored with tasks backwards on two threads")) {
                BPT_CHECK(memcmp(F2.sn->x, N.F.sn->x, N.F.sn->xp[N.F.sn->ns] * sizeof(double)) == 0,
                          "camelhead, kept order: the same bits with the tasks backwards");
                bp__factor_free(&a, &F2);
            }
        }
        bp__vec_push(&a, &N.extra, badpair);           /* an invalid pair: a new order */
        BPT_CHECK(bp__newton_pattern(&N, &a, &S) == BP_OK, "camelhead: an invalid pair grows the pattern");
        bp__newton_assemble(&N, &S, atlas.charts[0].uv);
        st = bp__newton_factorize(&N, &S, &bad);
        if (BPT_CHECK(st == BP_OK && N.nkept == 1, "camelhead: after an invalid pair, factored with a new order (kept %ld "
                      "times in all)", N.nkept)) {
            const uint32_t *ex = (const uint32_t *)N.extra.data;
            for (k = 0; k < N.extra.count; k++) sep += !keeps_brute(N.F.tree, N.F.sn->viperm, ex[2 * k], ex[2 * k + 1]);
            BPT_CHECK(sep == 0, "camelhead: the new order separates all %u extra pairs (%u cross a split)",
                      (uint32_t)N.extra.count, sep);
        }
        free(b); free(x); free(z); free(perm);
        bp__newton_free(&a, &N);
    }
    bp__solver_free(&S);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* (l) One ordering for the start map and Newton (>>tutte, phase 5b).
   bp__nd_restrict on camelhead's vertex graph and a random subset of its
   vertices: the kept vertices in a permutation, and every edge between
   two of them on one side of each split (keeps_brute), each kept vertex
   in the same part of every node as in the full order.  Then face_holes (six holes:
   the filled chart's hole centres are dropped) and bishop: bp_chart_init
   leaves an order of the chart's vertices that separates every chart
   edge; bp_chart_optimize takes it (NULL after).  On bishop, where the
   start map's barrier pairs respect it (face_holes' do not, and Newton
   orders anew there), it is the order Newton finds itself (the same
   graph: the same bits as a run without it), another valid order put
   there (the identity, an unsplit root) is used (the bits differ), one
   and two threads give the same bits, and a spoiled order (out of range,
   two vertices swapped across the root's split, or a tree not nested) is
   dropped: the same bits as with none; all of it for Newton and for the
   preconditioned L-BFGS (its Laplacian).  And before the first
   factorization a growing pattern keeps the start map's order
   (bp__newton_keep_order). */
static int part_of(const bp__ndnode *N, uint32_t p)
{
    return p < N->lo || p >= N->hi ? -1 : p < N->a ? 0 : p < N->b ? 1 : 2;
}

static void test_restrict(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_allocator a;
    bp__solver S;
    bp__newton N;
    bp__sparse G;
    bp__ndnode tree[BP__ND_NODES], rtree[BP__ND_NODES];
    uint32_t nv, m = 0, v, p, k, bad = 0, edges = 0, moved = 0, *order, *keep, *out, *pre, *iv, *riv;
    if (!camelhead_solver(&mesh, &atlas, &S, &a)) return;
    nv = S.nv;
    if (BPT_CHECK(bp__newton_init(&N, &a, &S) == BP_OK && bp__super_graph(&a, &N.H, &G) == 1, "camelhead: H's vertex graph")) {
        order = (uint32_t *)malloc(nv * sizeof(uint32_t)); keep = (uint32_t *)calloc(nv + 1, sizeof(uint32_t));
        out = (uint32_t *)malloc(nv * sizeof(uint32_t)); pre = (uint32_t *)malloc((nv + 1) * sizeof(uint32_t));
        iv = (uint32_t *)malloc(nv * sizeof(uint32_t)); riv = (uint32_t *)malloc(nv * sizeof(uint32_t));
        BPT_CHECK(bp__nd_order(&a, &G, order, tree, BP__SUPER_ORDER, NULL), "camelhead: ordered");
        for (v = 0; v < nv; v++) keep[v] = bpt_rng_unit() < 0.7 ? m++ : BP__NONE;
        bp__nd_restrict(order, tree, nv, keep, out, rtree, pre);
        for (v = 0; v < m; v++) riv[v] = BP__NONE;
        for (k = 0; k < m; k++) { bad += out[k] >= m || riv[out[k]] != BP__NONE; if (out[k] < m) riv[out[k]] = k; }
        BPT_CHECK(bad == 0 && rtree[0].lo == 0 && rtree[0].hi == m, "camelhead: %u of %u vertices kept, a permutation of "
                  "them (%u wrong), the root over all", m, nv, bad);
        for (k = 0; k < nv; k++) iv[order[k]] = k;
        for (v = 0; v < nv; v++) {
            if (keep[v] == BP__NONE) continue;
            for (k = 0; k < BP__ND_NODES; k++)
                if (tree[k].used) moved += part_of(&tree[k], iv[v]) != part_of(&rtree[k], riv[keep[v]]);
            for (p = G.colp[v]; p < G.colp[v + 1]; p++) {
                uint32_t w = G.row[p];
                if (w <= v || keep[w] == BP__NONE) continue;
                edges++;
                bad += !keeps_brute(rtree, riv, keep[v], keep[w]);
            }
        }
        BPT_CHECK(bad == 0 && moved == 0 && edges > 0, "camelhead, restricted: every node's parts hold the same kept "
                  "vertices (%u moved), %u edges between kept vertices all separated (%u cross a split)", moved, edges, bad);
        {   /* a pattern grown before any factor keeps the start map's order */
            uint32_t *kp = (uint32_t *)bp__alloc_array(&a, nv, sizeof(uint32_t)), uw[2];
            uint32_t *ki = (uint32_t *)bp__alloc_array(&a, nv, sizeof(uint32_t));
            memcpy(kp, order, nv * sizeof(uint32_t));
            for (k = 0; k < nv; k++) ki[order[k]] = k;
            N.kperm = kp; N.kiperm = ki;
            memcpy(N.ktree, tree, sizeof tree);
            uw[0] = S.tri[0]; uw[1] = S.tri[3 * (S.nt / 2)];
            bp__vec_push(&a, &N.extra, uw);
            BPT_CHECK(bp__newton_pattern(&N, &a, &S) == BP_OK && N.kperm == kp && N.kiperm == ki,
                      "camelhead: the pattern grown before the first factorization, the given order kept");
        }
        free(order); free(keep); free(out); free(pre); free(iv); free(riv);
        bp__free(&a, G.colp); bp__free(&a, G.row);
    }
    bp__newton_free(&a, &N);
    bp__solver_free(&S);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* The one chart of path solved by Newton (or direction dir) from its
   start map with threads t; spoil: 0 keep the start map's order, 1 drop
   it, 2 spoil it (out of range), 3 put the identity there (an unsplit
   root), 4 swap two vertices across the root's split.  Returns the uvs
   (malloc'd), *nv their vertices. */
static double *solve_start_order_dir(const char *path, int threads, int spoil, const char *what, uint32_t *nvp,
                                     bp_direction dir)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    double *uv = NULL;
    memset(&opt, 0, sizeof opt);
    opt.threads = threads;
    opt.direction = dir;                         /* (the default takes L-BFGS below 20K faces) */
    if (!BPT_CHECK(bp_read_mesh(path, &mesh, NULL, &err) == BP_OK, "read %s: %s", path, err.message))
        return NULL;
    if (BPT_CHECK(bp_atlas_build(&atlas, &mesh, &opt, &err) == BP_OK && atlas.num_charts == 1 &&
                  bp_chart_init(&atlas.charts[0], &mesh, &opt, &err) == BP_OK, "%s: one chart, start map", what)) {
        bp_chart *ch = &atlas.charts[0];
        uint32_t nv = ch->num_vertices, k, t, bad = 0, *iv = (uint32_t *)malloc(nv * sizeof(uint32_t));
        bp__ndnode tr[BP__ND_NODES];
        if (BPT_CHECK(ch->start_order != NULL, "%s: the start map left its order", what)) {
            for (k = 0; k < nv; k++) iv[k] = BP__NONE;
            for (k = 0; k < nv; k++) { bad += ch->start_order[k] >= nv || iv[ch->start_order[k]] != BP__NONE; if (ch->start_order[k] < nv) iv[ch->start_order[k]] = k; }
            for (k = 0; k < BP__ND_NODES; k++) {
                const uint32_t *w = ch->start_order + nv + 6 * k;
                tr[k].lo = w[0]; tr[k].a = w[1]; tr[k].b = w[2]; tr[k].hi = w[3]; tr[k].used = (int)w[4]; tr[k].split = (int)w[5];
            }
            for (t = 0; bad == 0 && t < 3 * ch->num_triangles; t++)
                bad += !keeps_brute(tr, iv, ch->triangles[t], ch->triangles[t % 3 == 2 ? t - 2 : t + 1]);
            BPT_CHECK(bad == 0 && tr[0].used && tr[0].lo == 0 && tr[0].hi == nv && tr[0].split,
                      "%s: a permutation of the %u chart vertices that separates every chart edge (%u wrong)", what, nv, bad);
            if (spoil == 1) { free(ch->start_order); ch->start_order = NULL; }
            if (spoil == 2) ch->start_order[0] = nv;
            if (spoil == 4) {                      /* a permutation that puts edges across the root's split */
                uint32_t *o = ch->start_order, x = o[tr[0].lo];
                o[tr[0].lo] = o[tr[0].a];
                o[tr[0].a] = x;
            }
            if (spoil == 5) ch->start_order[nv + 6 + 3] = nv;   /* node 1 over its sibling too: not nested */
            if (spoil == 3) {                      /* another valid order: identity, the root unsplit */
                memset(ch->start_order + nv, 0, 6 * BP__ND_NODES * sizeof(uint32_t));
                for (k = 0; k < nv; k++) ch->start_order[k] = k;
                ch->start_order[nv + 1] = ch->start_order[nv + 2] = ch->start_order[nv + 3] = nv;
                ch->start_order[nv + 4] = 1;
            }
        }
        free(iv);
        if (BPT_CHECK(bp_chart_optimize(ch, 0, &mesh, &opt, &err) == BP_OK && ch->start_order == NULL,
                      "%s: optimized, the order taken", what)) {
            uv = (double *)malloc(2 * nv * sizeof(double));
            memcpy(uv, ch->uv, 2 * nv * sizeof(double));
            *nvp = nv;
        }
        bp_atlas_free(&atlas);
    }
    bp_mesh_free(&mesh, NULL);
    return uv;
}

/* On bishop, for Newton and the preconditioned L-BFGS: each case against
   a run whose start order was dropped (spoil 1).  The start map's own
   order is the one the factorization finds itself (one loop, no barrier
   pair at the start: the same graph), so the same bits, on 1 and on 2
   threads; an identity order put there is used (the bits differ); an
   order out of range, crossed at the root or not nested is dropped (the
   same bits). */
static void test_start_order(void)
{
    static const struct { int threads, spoil, differs; const char *what; } C[] = {
        { 1, 0, 0, "the start map's order, 1 thread: the order the factorization finds itself (the same bits)" },
        { 2, 0, 0, "the start map's order, 2 threads: the same bits" },
        { 1, 3, 1, "another valid order (the identity) is used (the bits differ)" },
        { 1, 2, 0, "an order out of range is dropped (the same bits as none)" },
        { 1, 4, 0, "an order whose split the chart's edges cross is dropped (the same bits as none)" },
        { 1, 5, 0, "a tree whose node 1 covers its sibling is dropped (the same bits as none)" },
    };
    static const bp_direction D[] = { BP_DIRECTION_NEWTON, BP_DIRECTION_PRECONDITIONED };
    static const char *const DN[] = { "bishop, Newton", "bishop, L-BFGS" };
    const char *B = "tests/data/bishop_part_f1000.obj";
    uint32_t nv = 0;
    size_t d, c;
    free(solve_start_order_dir("tests/data/face_holes.off", 2, 0, "face_holes (6 holes)", &nv, BP_DIRECTION_NEWTON));
    for (d = 0; d < 2; d++) {
        double *un = solve_start_order_dir(B, 1, 1, DN[d], &nv, D[d]);
        for (c = 0; un && c < sizeof C / sizeof *C; c++) {
            double *u = solve_start_order_dir(B, C[c].threads, C[c].spoil, DN[d], &nv, D[d]);
            if (u) BPT_CHECK((memcmp(u, un, 2 * (size_t)nv * sizeof(double)) != 0) == C[c].differs, "%s: %s", DN[d], C[c].what);
            free(u);
        }
        free(un);
    }
}


/* (m) K1's analysis copied from a factor of H's size (bp__super_clone):
   H factored in blocks of 2 in K1's order, handed over as the conformal
   start hands its factor; bp__newton_iso_like takes it (and refuses it
   when one row of its pattern differs), and K1 factored with it has
   every array of the fresh factorization F, values and pivots bit for
   bit. */
static void check_iso_like(const bp_allocator *a, bp__newton *N, const bp__newton *N0, const bp__factor *F, const char *what)
{
    bp__handoff h;
    bp__factor F2, Fl;
    const bp__super *A = F->sn, *B;
    uint32_t bad, ns = A->ns, nv = A->nv, keep;
    int fb, same;
    memset(&h, 0, sizeof h);
    if (!BPT_CHECK(bp__super_factorize(a, &N0->H, &F2, &bad, NULL, 2, &fb, A->vperm, F->tree) == BP_OK && F2.sn,
                   "camel_b, %s: H factored in K1's order", what)) return;
    h.F = F2; h.n = N0->H.n; h.colp = N0->H.colp; h.row = N0->H.row;
    N->given = &h;
    BPT_CHECK(bp__newton_iso_like(N, A->vperm, F->tree) == &h.F, "camel_b, %s: H's factor is K1's analysis", what);
    keep = h.row[h.colp[2 * (nv / 2)] + 2];
    h.row[h.colp[2 * (nv / 2)] + 2] = keep + 2;         /* one row of the pattern moved */
    BPT_CHECK(bp__newton_iso_like(N, A->vperm, F->tree) == NULL, "camel_b, %s: ... not with one row of the pattern moved",
              what);
    h.row[h.colp[2 * (nv / 2)] + 2] = keep;
    N->given = NULL;
    if (BPT_CHECK(bp__super_factorize_like(a, &N->K1, &Fl, &bad, NULL, 1, &fb, A->vperm, F->tree, &F2) == BP_OK && Fl.sn,
                  "camel_b, %s: K1 factored with the copied analysis", what)) {
        B = Fl.sn;
        same = B->ns == ns && B->nv == nv && B->bs == 1 && B->maxcols == A->maxcols && B->maxrows == A->maxrows &&
               B->ntask == A->ntask && !memcmp(B->vperm, A->vperm, nv * sizeof(uint32_t)) &&
               !memcmp(B->viperm, A->viperm, nv * sizeof(uint32_t)) && !memcmp(B->snode, A->snode, nv * sizeof(uint32_t)) &&
               !memcmp(B->first, A->first, (ns + 1) * sizeof(uint32_t)) && !memcmp(B->rp, A->rp, (ns + 1) * sizeof(uint32_t)) &&
               !memcmp(B->ri, A->ri, A->rp[ns] * sizeof(uint32_t)) && !memcmp(B->xp, A->xp, (ns + 1) * sizeof(size_t)) &&
               !memcmp(B->up, A->up, (ns + 1) * sizeof(uint32_t)) && !memcmp(B->uk, A->uk, A->up[ns] * sizeof(uint32_t)) &&
               !memcmp(B->uo, A->uo, A->up[ns] * sizeof(uint32_t)) && !memcmp(Fl.tree, F->tree, sizeof Fl.tree) &&
               !memcmp(B->x, A->x, A->xp[ns] * sizeof(double)) && !memcmp(Fl.D, F->D, nv * sizeof(double));
        BPT_CHECK(same, "camel_b, %s: ... every array of the analysis, the values and the pivots those of the fresh "
                  "factorization (%u supernodes)", what, ns);
        bp__factor_free(a, &Fl);
    }
    bp__factor_free(a, &F2);
}

/* (m) the isotropic phase (>>newton). */
static double iso_entry(const bp__sparse *H, uint32_t u, uint32_t v)   /* (H(2u,2v) + H(2u+1,2v+1)) / 2 */
{
    uint32_t p, xx = BP__NONE, yy = BP__NONE;
    for (p = H->colp[2 * v]; p < H->colp[2 * v + 1]; p++) if (H->row[p] == 2 * u) xx = p;
    for (p = H->colp[2 * v + 1]; p < H->colp[2 * v + 2]; p++) if (H->row[p] == 2 * u + 1) yy = p;
    return xx == BP__NONE || yy == BP__NONE ? HUGE_VAL : 0.5 * (H->val[xx] + H->val[yy]);
}

static void test_isotropic(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_allocator a;
    bp_status st;
    int mode, copied = 0;
    memset(&a, 0, sizeof a);
    {
        bp_options o;
        memset(&o, 0, sizeof o);
        if (!bpt_one_chart("tests/data/camel_b.obj", &mesh, &atlas, &o, 1)) return;
    }
    for (mode = 0; mode < 3; mode++) {          /* plain; the barrier 4 mean edges wide; every 7th vertex held */
        static const char *const MN[] = { "no barrier", "a wide barrier", "pins held" };
        bp_chart *ch = &atlas.charts[0];
        bp__solver S;
        bp__newton N, N0;
        bp_options o;
        uint32_t nv = ch->num_vertices, nv2 = 2 * nv, i, v, p, k, *hold = NULL, bad = 0, aniso = 0, xy = 0, samep = 1;
        double *x = (double *)malloc(nv2 * sizeof(double)), *g = (double *)malloc(nv2 * sizeof(double));
        double *dv = (double *)malloc(nv2 * sizeof(double)), *d0 = (double *)malloc(nv2 * sizeof(double));
        double ed, hmax = 0, worst = 0, res = 0, gmax = 0, gv = 0, gv0 = 0, diff = 0, dn = 0;
        int r, r0;
        memset(&o, 0, sizeof o);
        o.no_barrier = mode == 0;
        if (!BPT_CHECK(bp__solver_chart(&S, &a, ch, &mesh, &o, NULL, &err) == BP_OK, "solver for camel_b")) break;
        if (mode == 1) S.eps = 4 * S.mean_edge;
        if (mode == 2) {
            hold = (uint32_t *)malloc(nv * sizeof(uint32_t));
            for (i = 0, k = 0; i < nv; i++) hold[i] = i % 7 == 3 ? k++ : BP__NONE;
        }
        BPT_CHECK(bp__newton_init(&N, &a, &S) == BP_OK && bp__newton_init(&N0, &a, &S) == BP_OK, "Newton set-ups");
        N.hold = N0.hold = hold;
        memcpy(x, ch->uv, nv2 * sizeof(double));
        bp__objective(&S, x, g, &ed);
        if (hold) for (i = 0; i < nv; i++) if (hold[i] != BP__NONE) g[2 * i] = g[2 * i + 1] = 0;
        for (i = 0; i < nv2; i++) if (fabs(g[i]) > gmax) gmax = fabs(g[i]);
        /* K1 assembled by the library against the average of H's entries */
        bp__newton_assemble(&N0, &S, x);              /* H itself (N0.iso = 0) */
        N.iso = 1;
        bp__newton_assemble(&N, &S, x);               /* K1 alone */
        BPT_CHECK(fabs(N.delta - N0.delta) <= 1e-9 * N0.delta, "camel_b, %s: K1's shift %.9g is H's (%.9g): its trace, "
                  "summed from its own diagonal and the pairs', is half of H's", MN[mode], N.delta, N0.delta);
        for (i = 0; i < N0.H.colp[N0.H.n]; i++) if (fabs(N0.H.val[i]) > hmax) hmax = fabs(N0.H.val[i]);
        BPT_CHECK(N.K1.n == nv && N.K1.colp[nv] == N0.H.colp[N0.H.n] / 4, "camel_b, %s: K1 is %u x %u with a quarter of "
                  "H's entries (%u of %u)", MN[mode], N.K1.n, nv, N.K1.colp[nv], N0.H.colp[N0.H.n]);
        for (v = 0; v < nv && N.K1.n == nv; v++)
            for (p = N.K1.colp[v]; p < N.K1.colp[v + 1]; p++) {
                double want = iso_entry(&N0.H, N.K1.row[p], v), e = fabs(N.K1.val[p] - want);
                if (!(e <= 1e-12 * hmax)) bad++;
                if (e > worst || want == HUGE_VAL) worst = want == HUGE_VAL ? HUGE_VAL : e;
                if (p > N.K1.colp[v] && N.K1.row[p] <= N.K1.row[p - 1]) samep = 0;
            }
        for (v = 0; v < nv2; v++)                      /* H's anisotropy: xx != yy, xy != 0 somewhere */
            for (p = N0.H.colp[v]; p < N0.H.colp[v + 1]; p++) {
                uint32_t u = N0.H.row[p];
                if ((u & 1) != (v & 1) && fabs(N0.H.val[p]) > 1e-6 * hmax) xy++;
                if ((u & 1) == 0 && (v & 1) == 0 && p + 1 < N0.H.colp[v + 1] &&
                    fabs(N0.H.val[p] - N0.H.val[N0.H.colp[v + 1] + (p - N0.H.colp[v]) + 1]) > 1e-6 * hmax) aniso++;
            }
        BPT_CHECK(bad == 0 && samep, "camel_b, %s: K1(u, v) = (H(2u, 2v) + H(2u+1, 2v+1)) / 2 within 1e-12 max |H| "
                  "everywhere (%u off, worst %.3g of max |H|), rows sorted", MN[mode], bad, worst / hmax);
        BPT_CHECK(aniso > 0 && xy > 0, "camel_b, %s: H is not isotropic (%u entries with xx != yy, %u xy entries), so "
                  "the average is a test", MN[mode], aniso, xy);
        /* the direction: descent, and it solves (K1 (x) I) v = -g with K1 built here from H */
        r = bp__newton_direction(&N, &S, x, g, dv, &gv);
        r0 = bp__newton_direction(&N0, &S, x, g, d0, &gv0);
        BPT_CHECK(r == 1 && N.niso == 1 && N.k1ok && gv < 0 && r0 == 1, "camel_b, %s: an isotropic direction (%d, %ld "
                  "of them), g.v = %.3g < 0", MN[mode], r, N.niso, gv);
        for (i = 0; i < nv && r == 1; i++) {
            double s0 = g[2 * i], s1 = g[2 * i + 1];
            for (p = N.K1.colp[i]; p < N.K1.colp[i + 1]; p++) {   /* row i of the symmetric K1: column i */
                double kk = iso_entry(&N0.H, N.K1.row[p], i);
                s0 += kk * dv[2 * N.K1.row[p]];
                s1 += kk * dv[2 * N.K1.row[p] + 1];
            }
            if (fabs(s0) > res) res = fabs(s0);
            if (fabs(s1) > res) res = fabs(s1);
        }
        for (i = 0; i < nv2; i++) { diff += (dv[i] - d0[i]) * (dv[i] - d0[i]); dn += d0[i] * d0[i]; }
        BPT_CHECK(res <= 1e-8 * gmax, "camel_b, %s: max |(K1 (x) I) v + g| = %.3g (max |g| %.3g)", MN[mode], res, gmax);
        BPT_CHECK(diff > 1e-6 * dn, "camel_b, %s: not Newton's direction (|v - v_newton|^2 / |v_newton|^2 = %.3g)",
                  MN[mode], diff / dn);
        if (hold) {
            uint32_t zero = 0, nheld = 0;
            for (i = 0; i < nv; i++) if (hold[i] != BP__NONE) { nheld++; zero += dv[2 * i] == 0 && dv[2 * i + 1] == 0; }
            BPT_CHECK(zero == nheld, "camel_b, pins held: the isotropic v is exactly 0 on %u of %u held vertices", zero, nheld);
        }
        /* a refactorization through the scatter map (K1.super1 == 2) has the bits of a fresh one */
        if (r == 1 && N.F1.sn) {
            bp__factor F;
            uint32_t badrow;
            int fb;
            for (i = 0; i < nv2; i++) x[i] += 1e-3 * S.mean_edge * (double)((i * 7) % 5 - 2);
            bp__objective(&S, x, g, &ed);
            bp__newton_assemble(&N, &S, x);
            BPT_CHECK(N.F1.sn->amap && N.F1.sn->amap_ok && bp__newton_iso_factor(&N, &S) == 1,
                      "camel_b, %s: K1 refactored through its scatter map", MN[mode]);
            BPT_CHECK(bp__super_factorize(&a, &N.K1, &F, &badrow, NULL, 1, &fb, N.F1.sn->vperm, N.F1.tree) == BP_OK && F.sn &&
                      F.sn->xp[F.sn->ns] == N.F1.sn->xp[N.F1.sn->ns] &&
                      !memcmp(F.sn->x, N.F1.sn->x, F.sn->xp[F.sn->ns] * sizeof(double)),
                      "camel_b, %s: ... the same bits as a fresh factorization on the same order", MN[mode]);
            check_iso_like(&a, &N, &N0, &F, MN[mode]);
            bp__factor_free(&a, &F);
        }
        bp__newton_iso_end(&N, &a);
        BPT_CHECK(!N.iso && !N.k1ok && !N.K1.colp && N.cut && (!N.F1.sn || (!N.F1.sn->x && N.F1.sn->ri)),
                  "camel_b, %s: the phase's end frees K1 and F1's values, and keeps F1's analysis", MN[mode]);
        if (r == 1 && N.F1.sn) bp__newton_assemble(&N, &S, x);   /* H (a barrier pair may grow its pattern) */
        if (r == 1 && N.F1.sn) {                       /* H's first factorization copies the analysis */
            bp__factor F;
            uint32_t badrow;
            int fb;
            st = bp__newton_factorize(&N, &S, &badrow);
            BPT_CHECK(st == BP_OK && N.F.sn && N.ncloned == 1 && !N.F1.sn,
                      "camel_b, %s: H's first factorization copies K1's analysis and frees it", MN[mode]);
            copied++;
            if (N.F.sn && BPT_CHECK(bp__super_factorize(&a, &N.H, &F, &badrow, NULL, 2, &fb, N.F.sn->vperm, N.F.tree) ==
                                    BP_OK && F.sn, "camel_b, %s: H factored afresh in that order", MN[mode])) {
                const bp__super *A = F.sn, *B = N.F.sn;
                uint32_t ns = A->ns, nvv = A->nv;
                BPT_CHECK(B->ns == ns && B->nv == nvv && B->bs == 2 && B->maxcols == A->maxcols &&
                          B->maxrows == A->maxrows && B->ntask == A->ntask &&
                          !memcmp(B->snode, A->snode, nvv * sizeof(uint32_t)) &&
                          !memcmp(B->first, A->first, (ns + 1) * sizeof(uint32_t)) &&
                          !memcmp(B->rp, A->rp, (ns + 1) * sizeof(uint32_t)) &&
                          !memcmp(B->ri, A->ri, A->rp[ns] * sizeof(uint32_t)) &&
                          !memcmp(B->xp, A->xp, (ns + 1) * sizeof(size_t)) &&
                          !memcmp(B->up, A->up, (ns + 1) * sizeof(uint32_t)) &&
                          !memcmp(B->uk, A->uk, A->up[ns] * sizeof(uint32_t)) &&
                          !memcmp(B->uo, A->uo, A->up[ns] * sizeof(uint32_t)) &&
                          !memcmp(B->x, A->x, A->xp[ns] * sizeof(double)) && !memcmp(N.F.D, F.D, N.H.n * sizeof(double)),
                          "camel_b, %s: ... every array of its analysis, its values and pivots those of a fresh "
                          "factorization (%u supernodes)", MN[mode], ns);
                bp__factor_free(&a, &F);
            }
        }
        bp__newton_free(&a, &N);
        bp__newton_free(&a, &N0);
        bp__solver_free(&S);
        free(x); free(g); free(dv); free(d0); free(hold);
    }
    BPT_CHECK(copied >= 1, "camel_b: H's first factorization copied K1's analysis in %d of the modes (where no barrier "
              "pair grew H's pattern after the phase)", copied);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* (m) a whole default solve of camelhead (Newton, 22,704 triangles): every
   accepted map exactly bijective (bp_check in the progress callback), the
   energy going down, and the final map the same bits on one thread and on
   two with the tasks run backwards. */
typedef struct iso_watch { const bp_chart *ch; int maps, bad; double last; } iso_watch;

static int iso_progress(void *user, uint32_t chart, int it, double e, double t)
{
    iso_watch *W = (iso_watch *)user;
    bp_check_report rep;
    (void)chart; (void)it; (void)t;
    W->maps++;
    if (bp_check(W->ch->triangles, W->ch->num_triangles, W->ch->uv, W->ch->num_vertices, NULL, &rep, NULL) != BP_OK ||
        rep.flipped || rep.degenerate || rep.boundary_intersections || !(e <= W->last))
        W->bad++;
    W->last = e;
    return 0;
}


static void test_isotropic_solve(void)
{
    bp_mesh mesh;
    bp_atlas atlas[2];
    bp_error err;
    int r, built = 0;
    bp_status st;
    iso_watch W;
    if (!BPT_CHECK(bp_read_mesh("tests/data/camelhead.off", &mesh, NULL, &err) == BP_OK, "read camelhead: %s", err.message))
        return;
    for (r = 0; r < 2; r++) {
        bp_options opt;
        memset(&opt, 0, sizeof opt);
        opt.threads = r ? 2 : 1;
        if (r) opt.parallel_for = bpt_backwards_for;
        if (!BPT_CHECK(bp_atlas_build(&atlas[r], &mesh, &opt, &err) == BP_OK && atlas[r].num_charts == 1 &&
                       bp_chart_init(&atlas[r].charts[0], &mesh, &opt, &err) == BP_OK, "camelhead: one chart, start map"))
            break;
        built++;
        memset(&W, 0, sizeof W);
        W.ch = &atlas[r].charts[0];
        W.last = HUGE_VAL;
        if (!r) { opt.progress = iso_progress; opt.progress_user = &W; }
        st = bp_chart_optimize(&atlas[r].charts[0], 0, &mesh, &opt, &err);
        BPT_CHECK(st == BP_OK && atlas[r].charts[0].stop == BP_STOP_CONVERGED, "camelhead, default direction (Newton, "
                  "isotropic first), %d thread(s): converged (%s after %d iterations)", opt.threads,
                  bp_stop_string(atlas[r].charts[0].stop), atlas[r].charts[0].iterations);
        if (!r) BPT_CHECK(W.maps == atlas[0].charts[0].iterations && W.maps > 5 && W.bad == 0, "camelhead: each of the %d "
                          "accepted maps exactly bijective (bp_check), the energy never up (%d bad)", W.maps, W.bad);
    }
    if (built == 2)
        BPT_CHECK(atlas[0].charts[0].iterations == atlas[1].charts[0].iterations &&
                  !memcmp(atlas[0].charts[0].uv, atlas[1].charts[0].uv, 2 * (size_t)atlas[0].charts[0].num_vertices * sizeof(double)),
                  "camelhead: the same bits on one thread and on two with the tasks run backwards");
    for (r = 0; r < built; r++) bp_atlas_free(&atlas[r]);
    bp_mesh_free(&mesh, NULL);
}

/* (l) */
static void test_iso_block(void)
{
    int kind;
    for (kind = 0; kind < BP_ENERGY_COUNT; kind++) {
        int trial, bad = 0, bad6 = 0, n = 0, n6 = 0, refused = 0, psd = 0, one = 0, sim = 0;
        double worst = 0, worst6 = 0;
        for (trial = 0; trial < 4000; trial++) {
            /* h4 a zero-initialized local read right after the call: the pattern GCC 12 folded to zeros
               before bp__hessian_j built its result in a local array (see there) */
            double J[4], h4[16] = { 0 }, C[8] = { 0 }, M[3], sa, sb, fa, fb, hs[3], tw, fl, t, l2, big = 0, e;
            int i;
            if (trial % 10 == 0) {                 /* s R(th): F = G = 0 exactly */
                double s = exp(bpt_rng_range(-1.5, 1.5)), th = bpt_rng_range(-3, 3);
                J[0] = J[3] = s * cos(th); J[2] = s * sin(th); J[1] = -J[2];
            } else
                do { for (i = 0; i < 4; i++) J[i] = bpt_rng_range(-2, 2); } while (J[0] * J[3] - J[1] * J[2] < 0.05);
            if (!bp__hessian_j((bp_energy)kind, J, 1, h4) || !bp__hessian_iso_j((bp_energy)kind, J, C)) { refused++; continue; }
            for (i = 0; i < 16; i++) if (fabs(h4[i]) > big) big = fabs(h4[i]);
            M[0] = 0.5 * (h4[0] + h4[10]); M[1] = 0.5 * (h4[1] + h4[11]); M[2] = 0.5 * (h4[5] + h4[15]);
            e = fabs(C[0] - M[0]);
            if (fabs(C[1] - M[1]) > e) e = fabs(C[1] - M[1]);
            if (fabs(C[5] - M[2]) > e) e = fabs(C[5] - M[2]);
            if (C[4] != C[1]) e = HUGE_VAL;
            if (!(e <= 1e-11 * big)) bad++;
            if (big > 0 && e / big > worst) worst = e / big;
            n++;
            /* which case of the scaling block this was (its eigenvalues, as the library's) */
            sa = sqrt(0.25 * (J[0] + J[3]) * (J[0] + J[3]) + 0.25 * (J[2] - J[1]) * (J[2] - J[1]));
            t = sqrt(0.25 * (J[0] - J[3]) * (J[0] - J[3]) + 0.25 * (J[2] + J[1]) * (J[2] + J[1]));
            if (t == 0) sim++;
            sa += t;
            sb = (J[0] * J[3] - J[1] * J[2]) / sa;
            bp__energy_sv((bp_energy)kind, sa, sb, &fa, &fb);
            bp__energy_sv2((bp_energy)kind, sa, sb, fa, fb, hs, &tw, &fl);
            t = sqrt(0.25 * (hs[0] - hs[2]) * (hs[0] - hs[2]) + hs[1] * hs[1]);
            l2 = 0.5 * (hs[0] + hs[2]) - t;
            if (l2 >= 0) psd++;
            else if (l2 + 2 * t > 0) one++;
        }
        for (trial = 0; trial < 500; trial++) {    /* the triangles' six numbers */
            bp__rest r;
            double U[3][2], P[36], k6[6], big = 0, e = 0;
            int i, k, l;
            random_triangle(&r, U, trial % 2);
            if (!bp__triangle_hessian((bp_energy)kind, &r, U[0], U[1], U[2], 1, P)) continue;
            if (!bp__triangle_hessian_iso((bp_energy)kind, &r, U[0], U[1], U[2], k6)) { refused++; continue; }
            n6++;
            for (i = 0; i < 36; i++) if (fabs(P[i]) > big) big = fabs(P[i]);
            for (k = 0; k < 3; k++)
                for (l = k; l < 3; l++) {
                    double want = 0.5 * (P[6 * (2 * k) + 2 * l] + P[6 * (2 * k + 1) + 2 * l + 1]);
                    double d = fabs(k6[bp__ht_block[k][l] / 4] - want);
                    if (d > e) e = d;
                }
            if (!(e <= 1e-11 * big)) bad6++;
            if (big > 0 && e / big > worst6) worst6 = e / big;
        }
        BPT_CHECK(refused == 0 && n == 4000 && bad == 0, "%s: C = (B_00 + B_11) / 2 of the projected 4x4 on %d "
                  "Jacobians (worst %.2g of its largest entry; %d refused)", ENAME[kind], n, worst, refused);
        BPT_CHECK(n6 >= 400 && bad6 == 0, "%s: the six isotropic numbers = (xx + yy) / 2 of the projected 6x6 on %d "
                  "triangles (worst %.2g)", ENAME[kind], n6, worst6);
        BPT_CHECK(sim >= 300, "%s: %d exact similarities (R = 0)", ENAME[kind], sim);
        /* the scaling block [f_aa f_ab; f_ab f_bb]: conformal's has f_aa = 0 and f_ab != 0, so one negative
           eigenvalue always; MIPS's both cases; the others' are diagonal and >= 0 */
        if (kind == BP_ENERGY_CONFORMAL)
            BPT_CHECK(one == n, "%s: one eigenvector of the scaling block kept on all %d (%d)", ENAME[kind], n, one);
        else if (kind == BP_ENERGY_MIPS)
            BPT_CHECK(psd > 0 && one > 0 && psd + one == n, "%s: the scaling block semidefinite (%d) and clamped to "
                      "one eigenvector (%d), both occur", ENAME[kind], psd, one);
        else
            BPT_CHECK(psd == n, "%s: the scaling block is semidefinite on all %d (%d)", ENAME[kind], n, psd);
    }
}

/* (j) The fallback (bp__chart_optimize_pen, >>optimize): where the default chose Newton and the allocator refuses its
   memory, L-BFGS finishes the chart.  An allocator that refuses every
   block larger than the largest one a whole preconditioned L-BFGS run of
   camelhead asks for (start map included): the default, which takes
   Newton there (E0 65), must return BP_OK with chart.direction
   PRECONDITIONED, a map bp_check passes, a final energy within 1e-4 of the
   L-BFGS run's, the uncapped run's energy_start, and iterations that the
   progress callback saw as 1, 2, ..., n with n = chart.iterations (the
   count goes on across the fallback); the cap must have refused at least
   once, and every block must be freed.  Newton asked for by name under
   the same cap fails with BP_ERR_OUT_OF_MEMORY (no fallback), and the
   uncapped default reports NEWTON. */
typedef struct cap_alloc {
    size_t cap, largest;
    long refused, live;
} cap_alloc;

static void *cap_alloc_fn(void *user, size_t size)
{
    cap_alloc *c = (cap_alloc *)user;
    void *p;
    if (c->cap && size > c->cap) { c->refused++; return NULL; }
    if (size > c->largest) c->largest = size;
    p = malloc(size);
    if (p) c->live++;
    return p;
}

static void cap_free_fn(void *user, void *ptr)
{
    cap_alloc *c = (cap_alloc *)user;
    if (ptr) c->live--;
    free(ptr);
}

typedef struct iter_seq {
    int n, gaps;
} iter_seq;

static int iter_seq_fn(void *user, uint32_t chart, int iteration, double energy, double step)
{
    iter_seq *q = (iter_seq *)user;
    (void)chart; (void)energy; (void)step;
    if (iteration != q->n + 1) q->gaps++;
    q->n = iteration;
    return 0;
}

static int run_capped(const bp_mesh *mesh, bp_direction d, size_t cap, cap_alloc *ca, iter_seq *q, bp_atlas *at,
                      bp_error *err)
{
    bp_options opt;
    memset(&opt, 0, sizeof opt);
    memset(ca, 0, sizeof *ca);
    ca->cap = cap;
    opt.threads = 1;
    opt.direction = d;
    opt.allocator.alloc = cap_alloc_fn;
    opt.allocator.free = cap_free_fn;
    opt.allocator.user = ca;
    if (q) { memset(q, 0, sizeof *q); opt.progress = iter_seq_fn; opt.progress_user = q; }
    return (int)bp_parameterize(at, mesh, &opt, err);
}

static void test_fallback(const char *path, const char *name)
{
    bp_mesh mesh;
    bp_error err;
    bp_atlas lb, dn, fb, nw;
    cap_alloc ca;
    iter_seq q;
    int st;
    if (!BPT_CHECK(bp_read_mesh(path, &mesh, NULL, &err) == BP_OK, "read %s: %s", name, err.message))
        return;
    st = run_capped(&mesh, BP_DIRECTION_PRECONDITIONED, 0, &ca, NULL, &lb, &err);
    if (BPT_CHECK(st == BP_OK, "%s, L-BFGS: %s", name, err.message)) {
        size_t cap = ca.largest;
        const bp_chart *cl = &lb.charts[0];
        BPT_CHECK(cl->direction == BP_DIRECTION_PRECONDITIONED, "%s, L-BFGS asked: chart.direction %d", name,
                  (int)cl->direction);
        st = run_capped(&mesh, BP_DIRECTION_DEFAULT, 0, &ca, NULL, &dn, &err);
        if (BPT_CHECK(st == BP_OK, "%s, default: %s", name, err.message)) {
            BPT_CHECK(dn.charts[0].direction == BP_DIRECTION_NEWTON, "%s, default, uncapped: Newton (%d)", name,
                      (int)dn.charts[0].direction);
            st = run_capped(&mesh, BP_DIRECTION_DEFAULT, cap, &ca, &q, &fb, &err);
            if (BPT_CHECK(st == BP_OK, "%s, default, blocks above %zu bytes refused: BP_OK (%s)", name, cap,
                          err.message)) {
                const bp_chart *c = &fb.charts[0];
                bp_check_report r;
                memset(&r, 0, sizeof r);
                BPT_CHECK(ca.refused > 0, "the cap refused %ld blocks", ca.refused);
                BPT_CHECK(c->direction == BP_DIRECTION_PRECONDITIONED, "the chart fell back to L-BFGS (direction %d)",
                          (int)c->direction);
                BPT_CHECK(bp_check(c->triangles, c->num_triangles, c->uv, c->num_vertices, NULL, &r, NULL) == BP_OK &&
                              !r.flipped && !r.degenerate && !r.boundary_intersections,
                          "its map is bijective (flipped %u, boundary %u)", r.flipped, r.boundary_intersections);
                BPT_CHECK(fabs(c->energy_end - cl->energy_end) <= 1e-4 * cl->energy_end,
                          "its final energy %.7f, L-BFGS's %.7f", c->energy_end, cl->energy_end);
                BPT_CHECK(c->energy_start == dn.charts[0].energy_start, "energy_start %.17g, the uncapped run's %.17g",
                          c->energy_start, dn.charts[0].energy_start);
                BPT_CHECK(q.gaps == 0 && q.n == c->iterations && q.n > 0,
                          "the progress callback saw iterations 1..%d without a gap (%d gaps), chart.iterations %d", q.n,
                          q.gaps, c->iterations);
                bp_atlas_free(&fb);
            }
            BPT_CHECK(ca.live == 0, "every block freed (%ld live)", ca.live);
            /* the same below the uncapped default's largest block: refused
               after Newton's first iterations (its isotropic phase runs on
               a smaller scalar factor), so L-BFGS takes over mid-solve */
            run_capped(&mesh, BP_DIRECTION_DEFAULT, 0, &ca, NULL, &fb, &err);
            bp_atlas_free(&fb);
            st = run_capped(&mesh, BP_DIRECTION_DEFAULT, ca.largest - 1, &ca, &q, &fb, &err);
            if (BPT_CHECK(st == BP_OK, "%s, default, below Newton's largest block: BP_OK (%s)", name, err.message)) {
                const bp_chart *c = &fb.charts[0];
                BPT_CHECK(ca.refused > 0 && c->direction == BP_DIRECTION_PRECONDITIONED,
                          "refused %ld, fell back (direction %d)", ca.refused, (int)c->direction);
                BPT_CHECK(q.gaps == 0 && q.n == c->iterations && c->iterations != cl->iterations,
                          "iterations 1..%d without a gap (%d gaps; Newton's first, then L-BFGS's: not L-BFGS's %d)",
                          q.n, q.gaps, cl->iterations);
                BPT_CHECK(c->energy_start == dn.charts[0].energy_start &&
                              fabs(c->energy_end - cl->energy_end) <= 1e-4 * cl->energy_end,
                          "energy_start kept, final energy %.7f (L-BFGS's %.7f)", c->energy_end, cl->energy_end);
                bp_atlas_free(&fb);
            }
            BPT_CHECK(ca.live == 0, "every block freed (%ld live)", ca.live);
            st = run_capped(&mesh, BP_DIRECTION_NEWTON, cap, &ca, NULL, &nw, &err);
            BPT_CHECK(st == BP_ERR_OUT_OF_MEMORY && ca.live == 0,
                      "Newton asked for by name under the cap: BP_ERR_OUT_OF_MEMORY, not a fallback (%s: %s)",
                      bp_status_string((bp_status)st), err.message);
            if (st == BP_OK || st == BP_ERR_CHARTS_FAILED) bp_atlas_free(&nw);
            bp_atlas_free(&dn);
        }
        bp_atlas_free(&lb);
    }
    bp_mesh_free(&mesh, NULL);
}

int main(void)
{
    quick = getenv("BP_TEST_QUICK") != NULL;
    bpt_rng_state = 0x9E3779B97F4A7C15ull;
    test_triangle_hessians();
    test_iso_block();
    test_assembled();
    test_pattern();
    test_kept_order();
    test_restrict();
    test_start_order();
    test_optimize("tests/data/bishop_part_f1000.obj");
    test_optimize("tests/data/camel_b.obj");
    test_pinned_direction();
    test_longer_steps();
    test_extend_gate();
    test_reuse();
    test_wide_barrier();
    test_isotropic();
    test_isotropic_solve();
    test_default_choice("tests/data/camel_b.obj", BP_ENERGY_SYMMETRIC_DIRICHLET);
    test_default_choice("tests/data/camel_b.obj", BP_ENERGY_MIPS);
    test_default_choice("tests/data/bishop_part_f1000.obj", BP_ENERGY_SYMMETRIC_DIRICHLET);
    test_default_choice("tests/data/face_holes.off", BP_ENERGY_SYMMETRIC_DIRICHLET);
    test_default_choice("tests/data/camelhead.off", BP_ENERGY_SYMMETRIC_DIRICHLET);
    if (!quick) test_default_choice("tests/data/lucy_o_f48275.obj", BP_ENERGY_SYMMETRIC_DIRICHLET);
    test_default_choice("tests/data/camelhead.off", BP_ENERGY_MIPS);
    if (!quick) test_default_choice("tests/data/beetle.off", BP_ENERGY_SYMMETRIC_DIRICHLET);
    if (!quick) test_default_choice_large();
    if (quick) test_fallback("tests/data/camel_b.obj", "camel_b");
    else test_fallback("tests/data/camelhead.off", "camelhead");
    return bpt_finish();
}
