/* test_energy.c - energies, their gradients, the barrier and the objective.

   The optimizer trusts two things about every function it minimizes: the
   value is the energy of sec 3.2 / 3.3, and the gradient is its derivative.
   Nothing here reuses the library's formulas:

     (a) the closed-form singular values of bp__triangle_energy against the
         generalized eigenvalues of (E^T E, D^T D) computed here from the raw
         3D edges E and UV edges D (no rest shape, no Q/R split), for all five
         energies, and the symmetric Dirichlet value against eq 3.3's own
         expression (areas, edge lengths, dot products);
     (b) exact values at isometries, similarities and axis stretches;
     (c) bp__rest_shape reproduces the three 3D edge lengths;
     (d) every energy's gradient against finite differences on 2000 random
         valid configurations each;
     (e) bp__energy_sv's partials against finite differences in (s_max, s_min);
     (f) the barrier E_B's gradient on jittered polygons where many vertex /
         edge pairs are closer than eps (none at distance 0);
     (g) the full objective E_D + E_B on the bishop chart (start map and a
         partly optimized map, default and large eps), on a random subset of
         coordinates;
     (h) every energy (all BP_ENERGY_*) with the barrier, and the barrier
         alone, on camel_b's chart after 5 iterations.
   Every gradient check uses fd_check below: Richardson-extrapolated central
   differences whose own error is estimated (two-step consistency plus a
   rounding floor) and must be below 5e-7 of the component, so that a
   relative error of 1e-6 in the analytic gradient fails; each check shows
   that by also running on the gradient times (1 + 1e-6).
   With BP_TEST_QUICK set (make test), (h) checks half as many coordinates
   (an eighth of the boundary's, a 64th of the others'); make check all
   of them. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <float.h>
#include <math.h>
#include <string.h>
#include <stdlib.h>


static const double PI = 3.14159265358979323846;
static const char *const ENAME[] = { "symmetric Dirichlet", "conformal", "MIPS", "isometric", "max isometric" };

/* Energy as a function of the singular values, written out here from the
   dissertation's list (sec 3.2) rather than taken from the library. */
static double ref_energy(int kind, double smax, double smin)
{
    switch (kind) {
    case BP_ENERGY_CONFORMAL: return smax / smin;
    case BP_ENERGY_MIPS: return smax / smin + smin / smax;
    case BP_ENERGY_ISOMETRIC: return sqrt(smax * smax + 1 / (smin * smin));
    case BP_ENERGY_MAX_ISOMETRIC: return smax > 1 / smin ? smax : 1 / smin;
    default: return smax * smax + smin * smin + 1 / (smax * smax) + 1 / (smin * smin);
    }
}

/* Singular values of the map P-triangle -> U-triangle from the raw edges:
   s^2 are the eigenvalues of (E^T E)^-1 (D^T D), E = [P2-P1, P3-P1] (3x2),
   D = [U2-U1, U3-U1] (2x2).  Long double throughout. */
static void ref_singular(const double *p1, const double *p2, const double *p3, const double *u1,
                         const double *u2, const double *u3, double *smax, double *smin)
{
    long double e1[3], e2[3], d1[2], d2[2], G[3], H[3], gi[3], dg, M00, M11, tr, det, disc, l1, l2;
    int k;
    for (k = 0; k < 3; k++) { e1[k] = (long double)p2[k] - p1[k]; e2[k] = (long double)p3[k] - p1[k]; }
    for (k = 0; k < 2; k++) { d1[k] = (long double)u2[k] - u1[k]; d2[k] = (long double)u3[k] - u1[k]; }
    G[0] = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    G[1] = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
    G[2] = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    H[0] = d1[0] * d1[0] + d1[1] * d1[1];
    H[1] = d1[0] * d2[0] + d1[1] * d2[1];
    H[2] = d2[0] * d2[0] + d2[1] * d2[1];
    dg = G[0] * G[2] - G[1] * G[1];
    gi[0] = G[2] / dg; gi[1] = -G[1] / dg; gi[2] = G[0] / dg;
    M00 = gi[0] * H[0] + gi[1] * H[1];
    M11 = gi[1] * H[1] + gi[2] * H[2];
    tr = M00 + M11;
    det = (H[0] * H[2] - H[1] * H[1]) / dg;
    disc = tr * tr / 4 - det;
    if (disc < 0) disc = 0;
    l1 = tr / 2 + sqrtl(disc);
    l2 = det / l1;                    /* accurate when l2 << l1 */
    *smax = (double)sqrtl(l1);
    *smin = (double)sqrtl(l2);
}

static double tri_quality(const double *a, const double *b, const double *c, int dim)
{
    /* smallest angle (radians) of the triangle */
    const double *p[3];
    double best = 10;
    int i, k;
    p[0] = a; p[1] = b; p[2] = c;
    for (i = 0; i < 3; i++) {
        const double *o = p[i], *q = p[(i + 1) % 3], *r = p[(i + 2) % 3];
        double u[3] = { 0, 0, 0 }, v[3] = { 0, 0, 0 }, dot = 0, nu = 0, nv = 0, ang;
        for (k = 0; k < dim; k++) { u[k] = q[k] - o[k]; v[k] = r[k] - o[k]; dot += u[k] * v[k]; nu += u[k] * u[k]; nv += v[k] * v[k]; }
        ang = acos(dot / sqrt(nu * nv));
        if (ang < best) best = ang;
    }
    return best;
}

static void make_rest(const double *p1, const double *p2, const double *p3, double weight, bp__rest *r)
{
    double w, x, y;
    bp__rest_shape(p1, p2, p3, &w, &x, &y);
    bp__rest_inverse(w, x, y, 1, r);
    r->weight = weight;
}

static double orient(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* ---- the finite-difference checker ----------------------------------------

   A gradient component g_i is compared with a derivative estimated to a
   known accuracy, not with a plain central difference under a loose fixed
   tolerance.  For steps h, h/2, h/4 (the steps actually represented,
   (x + h) - x) the central differences D(h) have error c2 h^2 + c4 h^4 +
   rounding; Richardson's R(h) = (4 D(h/2) - D(h)) / 3 cancels the h^2 term.
   Two extrapolations R1 = R(h) and R2 = R(h/2) estimate the error of R2 by
   |R1 - R2| (the h^4 term of R1 is 16 times that of R2), and rounding adds
   at most ~ k eps |f| / h per difference (f a sum of positive terms whose
   evaluation loses ~ k eps |f|, k = 4 + sqrt(terms)).  So
       err(R2) <= 2 |R1 - R2| + 6 k eps |f| / (h/4)
   is the tolerance of this coordinate.  The estimate is "conclusive" when
   that bound is below 1e-7 of the component (or of 1e-4 max |g| for tiny
   components); otherwise the step is divided by 4 (a kink or a steep
   barrier nearby, a non-finite value) up to 6 times, and a coordinate that
   never gets there is counted as inconclusive and reported (the checks
   below require almost none).  A wrong component then fails when its error
   exceeds the bound, so an injected relative error of 1e-6 fails every
   conclusive component with |g_i| >= 1e-4 max |g|: each check below also
   runs on the gradient times (1 + 1e-6) and requires exactly that. */

typedef double (*fd_fn)(void *ctx, const double *x);

typedef struct fd_stats {
    long checked, bad, inconclusive;   /* the true gradient               */
    long catchable, caught;            /* the gradient times (1 + 1e-6)   */
    double worst;                      /* max |R2 - g| / |bound|           */
    double worst_rel;                  /* max |R2 - g| / max(|g|, 1e-4 gmax) */
} fd_stats;

static int quick = 0;   /* BP_TEST_QUICK: the short form (make test) */

#define FD_TARGET 5e-7
#define FD_INJECT 1e-6

/* Checks component i of g (gmax = max |g|) at x (modified and restored);
   len the length scale of x (the first step is 1e-3 len), nterms the number
   of positive terms f sums (f / nterms / len is then the natural size of a
   component: a bound below 1e-7 of max(|g_i|, 1e-4 gmax, 1e-4 f / nterms /
   len) is conclusive).  The step shrinks when truncation dominates the
   bound and grows when rounding does. */
static void fd_check(fd_fn fn, void *ctx, double *x, size_t i, double gi, double gmax, double len, double nterms,
                     fd_stats *st)
{
    double h0 = 1e-3 * len, f0 = fabs(fn(ctx, x));
    double floor_g = fabs(gi), save = x[i];
    int tries;
    if (1e-4 * gmax > floor_g) floor_g = 1e-4 * gmax;
    if (1e-4 * f0 / nterms / len > floor_g) floor_g = 1e-4 * f0 / nterms / len;
    for (tries = 0; tries < 16; tries++) {
        double D[4], h = h0, fmax = 0, hmin = 0, R1, R2, R3, trunc, round;
        int j, finite = 1;
        for (j = 0; j < 4 && finite; j++, h /= 2) {
            double xp = save + h, xm = save - h, fp, fm;
            x[i] = xp; fp = fn(ctx, x);
            x[i] = xm; fm = fn(ctx, x);
            x[i] = save;
            if (!(fabs(fp) < HUGE_VAL) || !(fabs(fm) < HUGE_VAL)) finite = 0;
            D[j] = (fp - fm) / (xp - xm);
            if (fabs(fp) > fmax) fmax = fabs(fp);
            if (fabs(fm) > fmax) fmax = fabs(fm);
            hmin = 0.5 * (xp - xm);
        }
        if (!finite) { h0 /= 2; continue; }
        R1 = (4 * D[1] - D[0]) / 3;
        R2 = (4 * D[2] - D[1]) / 3;
        R3 = (4 * D[3] - D[2]) / 3;
        trunc = 2 * (fabs(R1 - R2) > fabs(R2 - R3) ? fabs(R1 - R2) : fabs(R2 - R3));
        round = 4 * DBL_EPSILON * fmax / hmin;
        R2 = R3;     /* the estimate compared below */
        if (!(trunc + round <= FD_TARGET * floor_g)) {
            if (trunc >= round || h0 >= 0.1 * len) h0 /= 2; else h0 *= 2;
            continue;
        }
        st->checked++;
        if (!(fabs(R2 - gi) <= trunc + round)) st->bad++;
        if (fabs(R2 - gi) / (trunc + round) > st->worst) st->worst = fabs(R2 - gi) / (trunc + round);
        if (fabs(R2 - gi) / floor_g > st->worst_rel) st->worst_rel = fabs(R2 - gi) / floor_g;
        if (fabs(gi) >= floor_g) {
            double wrong = gi * (1 + FD_INJECT);
            st->catchable++;
            if (!(fabs(R2 - wrong) <= trunc + round)) st->caught++;
        }
        return;
    }
    st->inconclusive++;
}

/* The checks every caller makes: no bad component, the injected error
   caught everywhere it can be, and few inconclusive coordinates. */
static void fd_report(const fd_stats *st, long max_inconclusive, const char *what)
{
    BPT_CHECK(st->bad == 0 && st->checked > 0 && st->inconclusive <= max_inconclusive,
              "%s: analytic gradient == Richardson central differences within their error bound on %ld components "
              "(worst error %.2g of the bound, %.2g of the component; bound <= %.0e of the component; %ld inconclusive, "
              "at most %ld allowed)", what, st->checked, st->worst, st->worst_rel, FD_TARGET, st->inconclusive,
              max_inconclusive);
    BPT_CHECK(st->catchable > 0 && st->caught == st->catchable,
              "%s: the same check fails the gradient times (1 + %.0e) on %ld of its %ld components >= 1e-4 max |g| "
              "(the tolerance is tight enough to see a 1e-6 relative error)", what, FD_INJECT, st->caught, st->catchable);
}

/* E_t of one triangle as a function of its six uv coordinates. */
typedef struct tri_ctx { bp_energy kind; const bp__rest *r; } tri_ctx;
static double tri_fn(void *ctx, const double *u)
{
    const tri_ctx *c = (const tri_ctx *)ctx;
    return c->r->weight * bp__triangle_energy(c->kind, c->r, u, u + 2, u + 4, NULL, NULL, NULL);
}

/* bp__energy_sv as a function of (s_max, s_min). */
static double sv_fn(void *ctx, const double *sv)
{
    double fa, fb;
    return bp__energy_sv((bp_energy)*(const int *)ctx, sv[0], sv[1], &fa, &fb);
}

/* E_B alone (bptest.h's bpt_barrier) as a function of the positions. */
static double barrier_fn(void *ctx, const double *x)
{
    return bpt_barrier((bp__solver *)ctx, x, NULL);
}

/* The objective E_D + E_B the optimizer minimizes. */
static double objective_fn(void *ctx, const double *x)
{
    double ed;
    return bp__objective((bp__solver *)ctx, x, NULL, &ed);
}

/* ---- a solver over bare polygons (barrier tests) ------------------------- */
typedef struct poly_solver {
    bp__solver S;
    bp_allocator a;
} poly_solver;



/* The solver bp_chart_optimize builds, set up the same way by hand. */
static bp__rest *solver_for_chart(bp__solver *S, const bp_allocator *a, const bp_chart *ch, const bp_mesh *m,
                                  bp_energy energy, int barrier, double eps)
{
    /* the library's own set-up (bp__solver_chart, as bp_chart_optimize);
       the test frees the returned rest shapes itself (bpt_solver_free) */
    bp_options o;
    memset(&o, 0, sizeof o);
    o.energy = energy;
    o.no_barrier = !barrier;
    o.epsilon = eps > 0 ? eps : 0;
    bp__solver_chart(S, a, ch, m, &o, NULL, NULL);
    return S->rest;
}

/* ---- (a)-(e) per-triangle energies --------------------------------------- */

static void random_config(double P[3][3], double U[3][2], double *uv_scale)
{
    for (;;) {
        double s3 = exp(bpt_rng_range(log(0.1), log(10.0))), s2 = s3 * exp(bpt_rng_range(-1.0, 1.0));
        int i, k;
        for (i = 0; i < 3; i++) for (k = 0; k < 3; k++) P[i][k] = s3 * bpt_rng_range(-1, 1) + 5 * s3;
        if (tri_quality(P[0], P[1], P[2], 3) < 15 * PI / 180) continue;
        for (i = 0; i < 3; i++) for (k = 0; k < 2; k++) U[i][k] = s2 * bpt_rng_range(-1, 1) - 3 * s2;
        if (orient(U[0], U[1], U[2]) < 0) {
            double tmp[2];
            memcpy(tmp, U[1], sizeof tmp); memcpy(U[1], U[2], sizeof tmp); memcpy(U[2], tmp, sizeof tmp);
        }
        if (tri_quality(U[0], U[1], U[2], 2) < 10 * PI / 180) continue;
        *uv_scale = s2;
        return;
    }
}

static void test_triangle_energies(void)
{
    int kind;
    /* (a) singular values / values against the independent computation */
    {
        double worst[BP_ENERGY_COUNT] = { 0 }, worst33 = 0;
        int n;
        for (n = 0; n < 3000; n++) {
            double P[3][3], U[3][2], s, smax, smin, g[3][2];
            bp__rest r;
            double area_p, area_u, d31[3], d21[3], u31[2], u21[2], dir, e33;
            int k;
            random_config(P, U, &s);
            make_rest(P[0], P[1], P[2], 1.0, &r);
            ref_singular(P[0], P[1], P[2], U[0], U[1], U[2], &smax, &smin);
            for (kind = 0; kind < BP_ENERGY_COUNT; kind++) {
                double e = bp__triangle_energy((bp_energy)kind, &r, U[0], U[1], U[2], NULL, NULL, NULL);
                double ref = ref_energy(kind, smax, smin), rel = fabs(e - ref) / ref;
                if (!(rel <= worst[kind])) worst[kind] = rel != rel ? 1e300 : rel;
            }
            /* eq 3.3, per unit area: (1 + A_P^2/A_U^2) * Dirichlet */
            for (k = 0; k < 3; k++) { d31[k] = P[2][k] - P[0][k]; d21[k] = P[1][k] - P[0][k]; }
            for (k = 0; k < 2; k++) { u31[k] = U[2][k] - U[0][k]; u21[k] = U[1][k] - U[0][k]; }
            {
                double c[3];
                c[0] = d21[1] * d31[2] - d21[2] * d31[1];
                c[1] = d21[2] * d31[0] - d21[0] * d31[2];
                c[2] = d21[0] * d31[1] - d21[1] * d31[0];
                area_p = 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
            }
            area_u = 0.5 * orient(U[0], U[1], U[2]);
            dir = ((u31[0] * u31[0] + u31[1] * u31[1]) * (d21[0] * d21[0] + d21[1] * d21[1] + d21[2] * d21[2]) +
                   (u21[0] * u21[0] + u21[1] * u21[1]) * (d31[0] * d31[0] + d31[1] * d31[1] + d31[2] * d31[2])) /
                      (4 * area_p * area_p) -
                  (u31[0] * u21[0] + u31[1] * u21[1]) * (d31[0] * d21[0] + d31[1] * d21[1] + d31[2] * d21[2]) /
                      (2 * area_p * area_p);
            e33 = (1 + area_p * area_p / (area_u * area_u)) * dir;
            {
                double e = bp__triangle_energy(BP_ENERGY_SYMMETRIC_DIRICHLET, &r, U[0], U[1], U[2], g[0], g[1], g[2]);
                double rel = fabs(e - e33) / e33;
                if (!(rel <= worst33)) worst33 = rel != rel ? 1e300 : rel;
            }
        }
        for (kind = 0; kind < BP_ENERGY_COUNT; kind++)
            BPT_CHECK(worst[kind] < 1e-10,
                      "%s value == f(s_max, s_min) with s from the eigenvalues of (E^T E)^-1 D^T D (3000 triangles, "
                      "max rel err %.3g)", ENAME[kind], worst[kind]);
        BPT_CHECK(worst33 < 1e-10, "symmetric Dirichlet == eq 3.3's area/edge form (max rel err %.3g)", worst33);
    }

    /* (c) rest shape keeps the 3D edge lengths */
    {
        double worst = 0;
        int n;
        for (n = 0; n < 1000; n++) {
            double P[3][3], U[3][2], s, w, x, y, l[3], f[3];
            int k;
            random_config(P, U, &s);
            bp__rest_shape(P[0], P[1], P[2], &w, &x, &y);
            for (k = 0; k < 3; k++) {
                const double *a = P[k], *b = P[(k + 1) % 3];
                l[k] = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
            }
            f[0] = w;
            f[1] = sqrt((x - w) * (x - w) + y * y);
            f[2] = sqrt(x * x + y * y);
            for (k = 0; k < 3; k++) if (fabs(f[k] - l[k]) / l[k] > worst) worst = fabs(f[k] - l[k]) / l[k];
            if (!(y > 0)) worst = 1;
        }
        BPT_CHECK(worst < 1e-13, "bp__rest_shape: (0,0),(w,0),(x,y) with y > 0 has the 3D edge lengths (max rel err %.3g)", worst);
    }

    /* (b) exact values */
    {
        double err_iso[BP_ENERGY_COUNT] = { 0 }, err_sim[BP_ENERGY_COUNT] = { 0 }, err_str[BP_ENERGY_COUNT] = { 0 };
        int n;
        for (n = 0; n < 500; n++) {
            double P[3][3], U[3][2], s, w, x, y, F[3][2], ang = bpt_rng_range(0, 2 * PI), c = cos(ang), sn = sin(ang);
            double tx = bpt_rng_range(-10, 10), ty = bpt_rng_range(-10, 10), sa = exp(bpt_rng_range(-1.5, 1.5)), sb = exp(bpt_rng_range(-1.5, 1.5));
            double V[3][2], W[3][2];
            bp__rest r;
            int i;
            random_config(P, U, &s);
            make_rest(P[0], P[1], P[2], 1.0, &r);
            bp__rest_shape(P[0], P[1], P[2], &w, &x, &y);
            F[0][0] = 0; F[0][1] = 0; F[1][0] = w; F[1][1] = 0; F[2][0] = x; F[2][1] = y;
            for (i = 0; i < 3; i++) {
                U[i][0] = c * F[i][0] - sn * F[i][1] + tx;          /* rotation */
                U[i][1] = sn * F[i][0] + c * F[i][1] + ty;
                V[i][0] = 2 * (c * F[i][0] - sn * F[i][1]) + tx;    /* similarity x2 */
                V[i][1] = 2 * (sn * F[i][0] + c * F[i][1]) + ty;
                /* stretch by sa along x, sb along y of the rest frame, then rotate */
                W[i][0] = c * sa * F[i][0] - sn * sb * F[i][1] + tx;
                W[i][1] = sn * sa * F[i][0] + c * sb * F[i][1] + ty;
            }
            for (i = 0; i < BP_ENERGY_COUNT; i++) {
                double want_iso[BP_ENERGY_COUNT], want_sim[BP_ENERGY_COUNT], e, big = sa > sb ? sa : sb, small = sa > sb ? sb : sa;
                want_iso[0] = 4; want_iso[1] = 1; want_iso[2] = 2; want_iso[3] = sqrt(2.0); want_iso[4] = 1;
                want_sim[0] = 2 * (4 + 0.25); want_sim[1] = 1; want_sim[2] = 2; want_sim[3] = sqrt(4 + 0.25); want_sim[4] = 2;
                e = bp__triangle_energy((bp_energy)i, &r, U[0], U[1], U[2], NULL, NULL, NULL);
                if (!(fabs(e - want_iso[i]) <= err_iso[i])) err_iso[i] = e == e ? fabs(e - want_iso[i]) : 1e300;
                e = bp__triangle_energy((bp_energy)i, &r, V[0], V[1], V[2], NULL, NULL, NULL);
                if (!(fabs(e - want_sim[i]) <= err_sim[i])) err_sim[i] = e == e ? fabs(e - want_sim[i]) : 1e300;
                e = bp__triangle_energy((bp_energy)i, &r, W[0], W[1], W[2], NULL, NULL, NULL);
                if (!(fabs(e - ref_energy(i, big, small)) / ref_energy(i, big, small) <= err_str[i]))
                    err_str[i] = e == e ? fabs(e - ref_energy(i, big, small)) / ref_energy(i, big, small) : 1e300;
            }
        }
        BPT_CHECK(err_iso[0] <= 1e-12, "isometry (rotated rest triangle): symmetric Dirichlet == 4 (max err %.3g)", err_iso[0]);
        BPT_CHECK(err_iso[1] <= 1e-12, "isometry: conformal == 1 (max err %.3g)", err_iso[1]);
        BPT_CHECK(err_iso[2] <= 1e-12, "isometry: MIPS == 2 (max err %.3g)", err_iso[2]);
        BPT_CHECK(err_iso[3] <= 1e-12, "isometry: isometric == sqrt 2 (max err %.3g)", err_iso[3]);
        BPT_CHECK(err_iso[4] <= 1e-12, "isometry: max isometric == 1 (max err %.3g)", err_iso[4]);
        BPT_CHECK(err_sim[0] <= 1e-12, "similarity x2: symmetric Dirichlet == 2 (4 + 1/4) (max err %.3g)", err_sim[0]);
        BPT_CHECK(err_sim[1] <= 1e-12 && err_sim[2] <= 1e-12, "similarity x2: conformal == 1, MIPS == 2 (max err %.3g, %.3g)",
                  err_sim[1], err_sim[2]);
        BPT_CHECK(err_sim[3] <= 1e-12 && err_sim[4] <= 1e-12,
                  "similarity x2: isometric == sqrt(4.25), max isometric == 2 (max err %.3g, %.3g)", err_sim[3], err_sim[4]);
        for (kind = 0; kind < BP_ENERGY_COUNT; kind++)
            BPT_CHECK(err_str[kind] <= 1e-12, "%s of a stretch (sa, sb) of the rest triangle == f(max, min) (max rel err %.3g)",
                      ENAME[kind], err_str[kind]);
    }

    /* (d) gradients against central differences (the checker above) */
    for (kind = 0; kind < BP_ENERGY_COUNT; kind++) {
        int n = 0, skipped = 0;
        fd_stats st;
        char what[160];
        memset(&st, 0, sizeof st);
        while (n < 2000) {
            double P[3][3], U[3][2], s, smax, smin, g[3][2], gmax = 0, weight = bpt_rng_range(0.5, 2);
            bp__rest r;
            tri_ctx c;
            int i, k;
            random_config(P, U, &s);
            make_rest(P[0], P[1], P[2], weight, &r);
            ref_singular(P[0], P[1], P[2], U[0], U[1], U[2], &smax, &smin);
            /* Kinks: conformal, isometric and max isometric are not
               differentiable where s_max == s_min (R = 0 in the closed form:
               their f_a - f_b does not vanish there), max isometric also
               where s_max == 1 / s_min.  Differences across a kink measure
               the mean of two one-sided slopes, so configurations within
               1e-3 (relative) of a kink are skipped and counted. */
            if ((kind == BP_ENERGY_CONFORMAL || kind == BP_ENERGY_ISOMETRIC || kind == BP_ENERGY_MAX_ISOMETRIC) &&
                (smax - smin) < 1e-3 * smax) { skipped++; continue; }
            if (kind == BP_ENERGY_MAX_ISOMETRIC && fabs(smax * smin - 1) < 1e-3) { skipped++; continue; }
            memset(g, 0, sizeof g);
            bp__triangle_energy((bp_energy)kind, &r, U[0], U[1], U[2], g[0], g[1], g[2]);
            for (i = 0; i < 3; i++) for (k = 0; k < 2; k++) if (fabs(g[i][k]) > gmax) gmax = fabs(g[i][k]);
            c.kind = (bp_energy)kind; c.r = &r;
            for (i = 0; i < 6; i++) fd_check(tri_fn, &c, &U[0][0], (size_t)i, (&g[0][0])[i], gmax, s, 1, &st);
            n++;
        }
        snprintf(what, sizeof what, "%s on %d random triangles (%d skipped within 1e-3 of a kink)", ENAME[kind], n, skipped);
        fd_report(&st, st.checked / 1000, what);
    }

    /* (d') near-conformal maps, where the closed form divides by R -> 0:
       symmetric Dirichlet and MIPS are smooth there (symmetric in s_max,
       s_min) and are checked at exact similarities (R ~ rounding) and at
       R/Q ~ 1e-2 .. 1e-6; the kinked energies only at R/Q >= 2e-3. */
    for (kind = 0; kind < BP_ENERGY_COUNT; kind++) {
        int n, tested = 0;
        int smooth = kind == BP_ENERGY_SYMMETRIC_DIRICHLET || kind == BP_ENERGY_MIPS;
        fd_stats st;
        char what[160];
        memset(&st, 0, sizeof st);
        for (n = 0; n < 1000; n++) {
            double P[3][3], U[3][2], s, w, x, y, F[3][2], ang = bpt_rng_range(0, 2 * PI), c = cos(ang), sn = sin(ang);
            double sc = exp(bpt_rng_range(-1, 1)), pert = (n % 5 == 0) ? 0 : pow(10.0, -bpt_rng_range(2, 6)), g[3][2], gnorm = 0;
            double smax, smin;
            bp__rest r;
            tri_ctx tc;
            int i, k;
            random_config(P, U, &s);
            make_rest(P[0], P[1], P[2], 1.0, &r);
            bp__rest_shape(P[0], P[1], P[2], &w, &x, &y);
            F[0][0] = 0; F[0][1] = 0; F[1][0] = w; F[1][1] = 0; F[2][0] = x; F[2][1] = y;
            for (i = 0; i < 3; i++) {
                U[i][0] = sc * (c * F[i][0] - sn * F[i][1]) + pert * w * bpt_rng_range(-1, 1) + 1;
                U[i][1] = sc * (sn * F[i][0] + c * F[i][1]) + pert * w * bpt_rng_range(-1, 1) - 2;
            }
            ref_singular(P[0], P[1], P[2], U[0], U[1], U[2], &smax, &smin);
            if (!smooth && smax - smin < 2e-3 * smax) continue;
            if (kind == BP_ENERGY_MAX_ISOMETRIC && fabs(smax * smin - 1) < 1e-3) continue;
            memset(g, 0, sizeof g);
            bp__triangle_energy((bp_energy)kind, &r, U[0], U[1], U[2], g[0], g[1], g[2]);
            for (i = 0; i < 3; i++) for (k = 0; k < 2; k++) if (fabs(g[i][k]) > gnorm) gnorm = fabs(g[i][k]);
            tc.kind = (bp_energy)kind; tc.r = &r;
            /* the first step stays well below the distance to the kink (R/Q >= 2e-3) */
            for (i = 0; i < 6; i++) fd_check(tri_fn, &tc, &U[0][0], (size_t)i, (&g[0][0])[i], gnorm, 1e-2 * sc * w, 1, &st);
            tested++;
        }
        snprintf(what, sizeof what, "%s near conformal maps (%d configurations, %s)", ENAME[kind], tested,
                 smooth ? "including exact similarities" : "R/Q >= 2e-3");
        BPT_CHECK(tested > 100, "%s: %d configurations tested", what, tested);
        fd_report(&st, st.checked / 1000, what);
    }

    /* (e) bp__energy_sv partials in (s_max, s_min) */
    for (kind = 0; kind < BP_ENERGY_COUNT; kind++) {
        int n, badv = 0;
        fd_stats st;
        char what[160];
        memset(&st, 0, sizeof st);
        for (n = 0; n < 2000; n++) {
            double sv[2], fab[2], f, gmax;
            int kk = kind;
            sv[0] = exp(bpt_rng_range(-2, 2));
            sv[1] = sv[0] * exp(bpt_rng_range(-3, -1e-3));
            if (kind == BP_ENERGY_MAX_ISOMETRIC && fabs(sv[0] * sv[1] - 1) < 1e-3) continue;
            f = bp__energy_sv((bp_energy)kind, sv[0], sv[1], &fab[0], &fab[1]);
            if (!(fabs(f - ref_energy(kind, sv[0], sv[1])) <= 1e-13 * f)) badv++;
            gmax = fabs(fab[0]) > fabs(fab[1]) ? fabs(fab[0]) : fabs(fab[1]);
            fd_check(sv_fn, &kk, sv, 0, fab[0], gmax, 0.1 * sv[1], 1, &st);
            fd_check(sv_fn, &kk, sv, 1, fab[1], gmax, 0.1 * sv[1], 1, &st);
        }
        BPT_CHECK(badv == 0, "%s: bp__energy_sv value == the reference f(s_max, s_min) to 1e-13", ENAME[kind]);
        snprintf(what, sizeof what, "%s: bp__energy_sv partials (f_a, f_b)", ENAME[kind]);
        fd_report(&st, st.checked / 1000, what);
    }
    /* degenerate / flipped triangles are infinite */
    {
        double P[3][3], U[3][2], s, tmp[2];
        bp__rest r;
        int bad = 0;
        random_config(P, U, &s);
        make_rest(P[0], P[1], P[2], 1.0, &r);
        memcpy(tmp, U[1], sizeof tmp); memcpy(U[1], U[2], sizeof tmp); memcpy(U[2], tmp, sizeof tmp);
        for (kind = 0; kind < BP_ENERGY_COUNT; kind++)
            if (bp__triangle_energy((bp_energy)kind, &r, U[0], U[1], U[2], NULL, NULL, NULL) != HUGE_VAL) bad++;
        U[2][0] = 0.5 * (U[0][0] + U[1][0]);
        U[2][1] = 0.5 * (U[0][1] + U[1][1]);
        U[0][0] = 0; U[0][1] = 0; U[1][0] = 2; U[1][1] = 2; U[2][0] = 1; U[2][1] = 1;
        for (kind = 0; kind < BP_ENERGY_COUNT; kind++)
            if (bp__triangle_energy((bp_energy)kind, &r, U[0], U[1], U[2], NULL, NULL, NULL) != HUGE_VAL) bad++;
        BPT_CHECK(bad == 0, "every energy is +inf on a flipped and on a degenerate triangle");
    }
}

/* ---- (f) the barrier on polygons ----------------------------------------- */

/* Distance from p to segment [a, b] (reference, long double). */
static double seg_dist(const double *a, const double *b, const double *p)
{
    long double ex = (long double)b[0] - a[0], ey = (long double)b[1] - a[1];
    long double px = (long double)p[0] - a[0], py = (long double)p[1] - a[1];
    long double l2 = ex * ex + ey * ey, s = l2 > 0 ? (px * ex + py * ey) / l2 : 0, dx, dy;
    if (s < 0) s = 0;
    if (s > 1) s = 1;
    dx = px - s * ex; dy = py - s * ey;
    return (double)sqrtl(dx * dx + dy * dy);
}

/* Polygons: kind 0 jittered circle, 1 flat ellipse (opposite sides within
   eps), 2 wavy star; plus an optional hole (second loop). */
static void make_polygon(int kind, uint32_t n, double *x)
{
    uint32_t i;
    for (i = 0; i < n; i++) {
        double th = 2 * PI * (i + bpt_rng_range(-0.3, 0.3)) / n, r = 1 + bpt_rng_range(-0.05, 0.05);
        if (kind == 0) { x[2 * i] = r * cos(th); x[2 * i + 1] = r * sin(th); }
        else if (kind == 1) { x[2 * i] = r * cos(th); x[2 * i + 1] = 0.12 * r * sin(th); }
        else { r *= 1 + 0.35 * cos(7 * th); x[2 * i] = r * cos(th); x[2 * i + 1] = r * sin(th); }
    }
}

static void test_barrier_gradient(void)
{
    int kind, bad = 0, trials = 0;
    double mind_rel = 1e300;
    long pairs_in = 0;
    fd_stats st;
    char what[160];
    memset(&st, 0, sizeof st);
    for (kind = 0; kind < 3; kind++) {
        int rep;
        for (rep = 0; rep < 30; rep++) {
            uint32_t n = 40, nh = (rep % 2) ? 12 : 0, N = n + nh, i, k;
            uint32_t loop_start[3], *lv = (uint32_t *)malloc(N * sizeof(uint32_t));
            double *x = (double *)malloc(2 * N * sizeof(double)), *g = (double *)calloc(2 * N, sizeof(double));
            double eps = kind == 0 ? 0.35 : kind == 1 ? 0.3 : 0.3, f0;
            bp__solver S;
            bp_allocator a;
            uint32_t L;
            memset(&a, 0, sizeof a);
            memset(&S, 0, sizeof S);
            make_polygon(kind, n, x);
            for (i = 0; i < nh; i++) {       /* a small clockwise hole near the middle */
                double th = -2 * PI * i / nh;
                x[2 * (n + i)] = 0.1 * cos(th) + 0.05;
                x[2 * (n + i) + 1] = (kind == 1 ? 0.01 : 0.1) * sin(th);
            }
            for (i = 0; i < N; i++) lv[i] = i;
            loop_start[0] = 0; loop_start[1] = n; loop_start[2] = N;
            S.a = &a;
            S.nv = N;
            S.nloops = nh ? 2 : 1;
            S.loop_start = loop_start;
            S.loop_vertices = lv;
            S.nb = N;
            S.barrier = 1;
            S.eps = eps;
            bpt_solver_workspace(&S, N);
            /* pairs within eps, and the closest (must not be 0) */
            for (L = 0; L < S.nloops; L++) {
                uint32_t s0 = loop_start[L], m = loop_start[L + 1] - s0, e;
                for (e = 0; e < m; e++)
                    for (k = 0; k < m; k++) {
                        double d;
                        if (k == e || k == (e + 1) % m) continue;
                        d = seg_dist(x + 2 * lv[s0 + e], x + 2 * lv[s0 + (e + 1) % m], x + 2 * lv[s0 + k]);
                        if (d < eps) pairs_in++;
                        if (d / eps < mind_rel) mind_rel = d / eps;
                    }
            }
            f0 = bpt_barrier(&S, x, g);
            {
                double gmax = 0;
                for (i = 0; i < 2 * N; i++) if (fabs(g[i]) > gmax) gmax = fabs(g[i]);
                for (i = 0; i < 2 * N; i++) fd_check(barrier_fn, &S, x, i, g[i], gmax, 0.1, N, &st);
            }
            if (!(f0 > 0) || !(f0 < HUGE_VAL)) bad++;
            trials++;
            bpt_solver_free(&S);
            free(lv); free(x); free(g);
        }
    }
    BPT_CHECK(mind_rel > 0.01, "barrier polygons: no boundary vertex closer than 0.01 eps to an edge of its loop (min %.3g eps)", mind_rel);
    BPT_CHECK(pairs_in > 20 * trials, "barrier polygons: %ld vertex/edge pairs inside eps over %d polygons", pairs_in, trials);
    BPT_CHECK(bad == 0, "barrier E_B: positive and finite on %d jittered polygons", trials);
    snprintf(what, sizeof what, "barrier E_B on %d jittered polygons (circle, flat ellipse, star; with and without a hole)",
             trials);
    fd_report(&st, st.checked / 1000, what);
}

/* ---- (g) the objective on a real chart ----------------------------------- */

static void test_objective_on_chart(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    bp_allocator a;
    int phase;
    memset(&opt, 0, sizeof opt);
    opt.init = BP_INIT_TUTTE;   /* the maps whose inconclusive counts the limits below were set on */
    opt.direction = BP_DIRECTION_PRECONDITIONED;   /* (phase 2's map: the default took it before sec 6.36) */
    memset(&a, 0, sizeof a);
    if (!BPT_CHECK(bp_read_obj("tests/data/bishop_part_f1000.obj", &mesh, NULL, &err) == BP_OK, "read bishop: %s", err.message))
        return;
    if (!BPT_CHECK(bp_atlas_build(&atlas, &mesh, &opt, &err) == BP_OK && atlas.num_charts == 1, "bishop: one chart")) {
        bp_mesh_free(&mesh, NULL);
        return;
    }
    BPT_CHECK(bp_chart_init(&atlas.charts[0], &mesh, &opt, &err) == BP_OK, "bishop start map: %s", err.message);
    for (phase = 0; phase < 4; phase++) {
        bp_chart *ch = &atlas.charts[0];
        bp__solver S;
        bp__rest *rest;
        double *x, *g, f, ed, ed2, f2, uvedge = 0, gmax = 0, eb;
        uint32_t i, nv2 = 2 * ch->num_vertices, nb = ch->loop_start[1], k;
        int energy = phase == 3 ? BP_ENERGY_MIPS : BP_ENERGY_SYMMETRIC_DIRICHLET;
        fd_stats st;
        char what[160];
        if (phase == 2) {       /* a partly optimized map: the boundary has moved */
            opt.max_iterations = 40;
            bp_chart_optimize(ch, 0, &mesh, &opt, &err);
        }
        for (k = 0; k < nb; k++) {
            const double *p = ch->uv + 2 * ch->loop_vertices[k], *q = ch->uv + 2 * ch->loop_vertices[(k + 1) % nb];
            uvedge += sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1])) / nb;
        }
        /* phase 0: default eps; 1-3: eps = 2 mean uv boundary edges, so E_B is active */
        rest = solver_for_chart(&S, &a, ch, &mesh, (bp_energy)energy, 1, phase == 0 ? 0 : 2 * uvedge);
        x = (double *)malloc(nv2 * sizeof(double));
        g = (double *)malloc(nv2 * sizeof(double));
        memcpy(x, ch->uv, nv2 * sizeof(double));
        f = bp__objective(&S, x, g, &ed);
        f2 = bp__objective(&S, x, NULL, &ed2);
        eb = bpt_barrier(&S, x, NULL);
        BPT_CHECK(f == f2 && ed == ed2 && fabs(f - (ed + eb)) <= 1e-12 * f,
                  "bishop phase %d: objective value is E_D + E_B with or without the gradient (E_D %.6g, E_B %.6g)", phase,
                  ed, eb);
        if (phase > 0) BPT_CHECK(eb > 0, "bishop phase %d: the barrier is active (E_B = %.6g)", phase, eb);
        for (i = 0; i < nv2; i++) if (fabs(g[i]) > gmax) gmax = fabs(g[i]);
        memset(&st, 0, sizeof st);
        for (i = 0; i < nv2; i++) {
            int is_boundary = 0;
            for (k = 0; k < nb; k++) if (ch->loop_vertices[k] == i / 2) is_boundary = 1;
            if (!is_boundary && bpt_rng_unit() > 0.25) continue;    /* all boundary coordinates, 1/4 of the rest */
            fd_check(objective_fn, &S, x, i, g[i], gmax, uvedge, S.nt + S.nb, &st);
        }
        snprintf(what, sizeof what, "bishop phase %d (%s, eps %s): objective E_D + E_B", phase, ENAME[energy],
                 phase == 0 ? "default" : "2 uv edges");
        fd_report(&st, st.checked / 20, what);
        bpt_solver_free(&S);
        free(rest); free(x); free(g);
    }
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* (h) every energy and the barrier on a real chart: camel_b after a few
   iterations (a map the optimizer really visits, not a toy triangle), with
   eps = 2 mean uv boundary edges so E_B is active along the whole
   boundary.  A random quarter of the boundary coordinates and 1/32 of the
   others (~400 per energy). */
static void test_all_energies_on_camel(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    bp_allocator a;
    bp_chart *ch;
    int kind;
    uint32_t c, best = 0;
    memset(&opt, 0, sizeof opt);
    memset(&a, 0, sizeof a);
    if (!BPT_CHECK(bp_read_obj("tests/data/camel_b.obj", &mesh, NULL, &err) == BP_OK, "read camel_b: %s", err.message)) return;
    if (!BPT_CHECK(bp_atlas_build(&atlas, &mesh, &opt, &err) == BP_OK, "camel_b: charts: %s", err.message)) {
        bp_mesh_free(&mesh, NULL);
        return;
    }
    for (c = 0; c < atlas.num_charts; c++) if (atlas.charts[c].num_triangles > atlas.charts[best].num_triangles) best = c;
    ch = &atlas.charts[best];
    opt.max_iterations = 5;
    if (!BPT_CHECK(bp_chart_init(ch, &mesh, &opt, &err) == BP_OK && bp_chart_optimize(ch, 0, &mesh, &opt, &err) == BP_OK,
                   "camel_b: chart %u (%u triangles) started and optimized for 5 iterations: %s", best, ch->num_triangles,
                   err.message)) {
        bp_atlas_free(&atlas);
        bp_mesh_free(&mesh, NULL);
        return;
    }
    for (kind = 0; kind <= BP_ENERGY_COUNT; kind++) {      /* BP_ENERGY_COUNT: the barrier alone */
        bp__solver S;
        bp__rest *rest;
        double *x, *g, ed, uvedge = 0, gmax = 0, eb;
        uint32_t i, k, nv2 = 2 * ch->num_vertices, nb = ch->loop_start[ch->num_loops];
        unsigned char *on_boundary = (unsigned char *)calloc(ch->num_vertices, 1);
        int barrier_only = kind == BP_ENERGY_COUNT;
        fd_stats st;
        char what[200];
        for (k = 0; k < nb; k++) on_boundary[ch->loop_vertices[k]] = 1;
        for (k = 0; k < ch->loop_start[1]; k++) {
            const double *p = ch->uv + 2 * ch->loop_vertices[k], *q = ch->uv + 2 * ch->loop_vertices[(k + 1) % ch->loop_start[1]];
            uvedge += sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1])) / ch->loop_start[1];
        }
        rest = solver_for_chart(&S, &a, ch, &mesh, barrier_only ? BP_ENERGY_SYMMETRIC_DIRICHLET : (bp_energy)kind, 1,
                                2 * uvedge);
        x = (double *)malloc(nv2 * sizeof(double));
        g = (double *)calloc(nv2, sizeof(double));
        memcpy(x, ch->uv, nv2 * sizeof(double));
        if (barrier_only) eb = bpt_barrier(&S, x, g);
        else { bp__objective(&S, x, g, &ed); eb = bpt_barrier(&S, x, NULL); }
        BPT_CHECK(eb > 0 && eb < HUGE_VAL, "camel_b chart %u: the barrier is active (E_B = %.6g)", best, eb);
        for (i = 0; i < nv2; i++) if (fabs(g[i]) > gmax) gmax = fabs(g[i]);
        memset(&st, 0, sizeof st);
        for (i = 0; i < nv2; i++) {
            if (bpt_rng_unit() > (on_boundary[i / 2] ? 0.25 : 1.0 / 32) / (quick ? 2 : 1)) continue;
            if (barrier_only && !on_boundary[i / 2]) continue;    /* E_B depends on boundary vertices only */
            fd_check(barrier_only ? barrier_fn : objective_fn, &S, x, i, g[i], gmax, uvedge,
                     barrier_only ? S.nb : S.nt + S.nb, &st);
        }
        if (barrier_only)
            snprintf(what, sizeof what, "camel_b chart %u (%u triangles, 5 iterations): barrier E_B alone (eps 2 uv edges)",
                     best, ch->num_triangles);
        else
            snprintf(what, sizeof what, "camel_b chart %u (%u triangles, 5 iterations): %s + barrier (eps 2 uv edges)", best,
                     ch->num_triangles, ENAME[kind]);
        fd_report(&st, st.checked / 20, what);
        bpt_solver_free(&S);
        free(rest); free(x); free(g); free(on_boundary);
    }
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

int main(void)
{
    bpt_rng_state = 0x9E3779B97F4A7C15ull;
    quick = getenv("BP_TEST_QUICK") != NULL;
    test_triangle_energies();
    test_barrier_gradient();
    test_objective_on_chart();
    test_all_energies_on_camel();
    return bpt_finish();
}
