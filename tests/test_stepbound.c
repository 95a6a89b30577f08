/* test_stepbound.c - the singularity-aware step bound of sec 3.4.2.

   The line search never looks past tmax, so tmax must be exactly the first
   moment along U + t V at which three points become collinear: the corners
   of a triangle (eq 3.4), or a boundary vertex and a boundary edge of its
   loop while the vertex lies within the edge (eq 3.5).  Checked against
   references written here:

     (a) bp__collinear_time (triangle case) on random triangles and random
         directions: the orientation, evaluated in long double from the
         relative motion, stays positive on 1000 samples of [0, tmax) and at
         tmax (1 - 1e-9); at tmax it is ~0; with no root it stays positive up
         to a huge t; and tmax equals the first sign change found by a grid
         + bisection brute force.  Also: exactly linear motion (alpha = 0),
         nearly common velocities (alpha ~ rho^2, beta ~ rho), and designed
         near-double roots (t0 +- delta, tiny discriminants) on both sides of
         tangency.
     (b) the edge/vertex case: the vertex reaches the segment at tmax and not
         before (distance sampled over time), collinear moments outside the
         segment are ignored, constructed contacts at known (t0, s0).
     (c) bp__step_bound on real charts (bishop start and optimized maps,
         face_holes with 7 loops, all 13 spot charts) for random, smooth and
         gradient directions equals the brute force over ALL triangles and ALL
         (edge, vertex) pairs of each loop computed with the same
         bp__collinear_time without the hash -- exactly (the swept hash must
         lose nothing); also with the triangles removed so the boundary pairs
         alone decide; and the same bits whether the small loops are
         scanned (the default), hashed, or every loop scanned.  And the bound is tight and safe: the map is exactly
         valid (bp_check) on [0, tmax) samples, and invalid just after tmax.
     (d) the barrier pair's whole Hessian for Newton (bp__barrier_pair_hessian,
         >>barrier) against second differences of the pair's energy in long
         double; its projection PSD and above the unprojected one; inside the
         segment it is not the Gauss-Newton part alone. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <float.h>
#include <math.h>
#include <string.h>
#include <stdlib.h>

static const double PI = 3.14159265358979323846;

/* ---- references ------------------------------------------------------------ */

/* det[B - A, C - A] at time t from the relative motion, long double. */
static long double det_at(const double *A, const double *VA, const double *B, const double *VB, const double *C,
                          const double *VC, long double t)
{
    long double e1x = ((long double)B[0] - A[0]) + t * ((long double)VB[0] - VA[0]);
    long double e1y = ((long double)B[1] - A[1]) + t * ((long double)VB[1] - VA[1]);
    long double e2x = ((long double)C[0] - A[0]) + t * ((long double)VC[0] - VA[0]);
    long double e2y = ((long double)C[1] - A[1]) + t * ((long double)VC[1] - VA[1]);
    return e1x * e2y - e1y * e2x;
}

/* |B - A| |C - A| at time t (the scale of det). */
static long double det_scale(const double *A, const double *VA, const double *B, const double *VB, const double *C,
                             const double *VC, long double t)
{
    long double e1x = ((long double)B[0] - A[0]) + t * ((long double)VB[0] - VA[0]);
    long double e1y = ((long double)B[1] - A[1]) + t * ((long double)VB[1] - VA[1]);
    long double e2x = ((long double)C[0] - A[0]) + t * ((long double)VC[0] - VA[0]);
    long double e2y = ((long double)C[1] - A[1]) + t * ((long double)VC[1] - VA[1]);
    return sqrtl(e1x * e1x + e1y * e1y) * sqrtl(e2x * e2x + e2y * e2y);
}

/* Segment parameter of P on [A, B] at time t. */
static long double seg_param(const double *A, const double *VA, const double *B, const double *VB, const double *P,
                             const double *VP, long double t)
{
    long double ex = ((long double)B[0] - A[0]) + t * ((long double)VB[0] - VA[0]);
    long double ey = ((long double)B[1] - A[1]) + t * ((long double)VB[1] - VA[1]);
    long double px = ((long double)P[0] - A[0]) + t * ((long double)VP[0] - VA[0]);
    long double py = ((long double)P[1] - A[1]) + t * ((long double)VP[1] - VA[1]);
    return (px * ex + py * ey) / (ex * ex + ey * ey);
}

/* Distance from P(t) to segment [A(t), B(t)], long double. */
static long double seg_dist_at(const double *A, const double *VA, const double *B, const double *VB, const double *P,
                               const double *VP, long double t)
{
    long double ex = ((long double)B[0] - A[0]) + t * ((long double)VB[0] - VA[0]);
    long double ey = ((long double)B[1] - A[1]) + t * ((long double)VB[1] - VA[1]);
    long double px = ((long double)P[0] - A[0]) + t * ((long double)VP[0] - VA[0]);
    long double py = ((long double)P[1] - A[1]) + t * ((long double)VP[1] - VA[1]);
    long double l2 = ex * ex + ey * ey, s = l2 > 0 ? (px * ex + py * ey) / l2 : 0;
    if (s < 0) s = 0;
    if (s > 1) s = 1;
    return sqrtl((px - s * ex) * (px - s * ex) + (py - s * ey) * (py - s * ey));
}

/* Brute force: first sign change of det on a uniform grid of [0, T] (n
   cells), refined by bisection; for the edge case a crossing counts only
   with the segment parameter in [0, 1] at the refined root.  Returns
   HUGE_VAL when there is none. */
static double brute_root(const double *A, const double *VA, const double *B, const double *VB, const double *C,
                         const double *VC, double T, int n, int edge_case)
{
    long double prev = det_at(A, VA, B, VB, C, VC, 0), t0 = 0;
    int i;
    for (i = 1; i <= n; i++) {
        long double t1 = (long double)T * i / n, cur = det_at(A, VA, B, VB, C, VC, t1);
        if ((prev > 0 && cur <= 0) || (prev < 0 && cur >= 0)) {
            long double lo = t0, hi = t1, s;
            int k;
            if (cur != 0)
                for (k = 0; k < 200; k++) {
                    long double mid = 0.5L * (lo + hi), dm = det_at(A, VA, B, VB, C, VC, mid);
                    if ((dm > 0) == (prev > 0) && dm != 0) lo = mid; else hi = mid;
                }
            if (!edge_case) return (double)hi;
            s = seg_param(A, VA, B, VB, C, VC, hi);
            if (s >= 0 && s <= 1) return (double)hi;
        }
        prev = cur;
        t0 = t1;
    }
    return HUGE_VAL;
}

/* Roots of the det polynomial computed in long double from the relative
   motion (the true polynomial of the double inputs to ~1e-19). */
static int ref_roots(const double *A, const double *VA, const double *B, const double *VB, const double *C,
                     const double *VC, long double r[2])
{
    long double e1x = (long double)B[0] - A[0], e1y = (long double)B[1] - A[1];
    long double e2x = (long double)C[0] - A[0], e2y = (long double)C[1] - A[1];
    long double f1x = (long double)VB[0] - VA[0], f1y = (long double)VB[1] - VA[1];
    long double f2x = (long double)VC[0] - VA[0], f2y = (long double)VC[1] - VA[1];
    long double g = e1x * e2y - e1y * e2x, b = e1x * f2y - e1y * f2x + f1x * e2y - f1y * e2x, a = f1x * f2y - f1y * f2x;
    long double disc = b * b - 4 * a * g, q;
    if (disc < 0) return 0;
    q = -0.5L * (b + (b >= 0 ? sqrtl(disc) : -sqrtl(disc)));
    r[0] = a != 0 ? q / a : HUGE_VAL;
    r[1] = q != 0 ? g / q : HUGE_VAL;
    if (r[0] > r[1]) { long double tmp = r[0]; r[0] = r[1]; r[1] = tmp; }
    return 2;
}

/* ---- (a) triangles ---------------------------------------------------------- */

static double tri_min_angle(const double *a, const double *b, const double *c)
{
    const double *p[3];
    double best = 10;
    int i;
    p[0] = a; p[1] = b; p[2] = c;
    for (i = 0; i < 3; i++) {
        const double *o = p[i], *q = p[(i + 1) % 3], *r = p[(i + 2) % 3];
        double ux = q[0] - o[0], uy = q[1] - o[1], vx = r[0] - o[0], vy = r[1] - o[1];
        double ang = acos((ux * vx + uy * vy) / sqrt((ux * ux + uy * uy) * (vx * vx + vy * vy)));
        if (ang < best) best = ang;
    }
    return best;
}

static void random_triangle(double P[3][2], double scale)
{
    do {
        int i;
        for (i = 0; i < 3; i++) { P[i][0] = scale * bpt_rng_range(-1, 1) + 3 * scale; P[i][1] = scale * bpt_rng_range(-1, 1) - scale; }
        if ((P[1][0] - P[0][0]) * (P[2][1] - P[0][1]) - (P[1][1] - P[0][1]) * (P[2][0] - P[0][0]) < 0) {
            double t0 = P[1][0], t1 = P[1][1];
            P[1][0] = P[2][0]; P[1][1] = P[2][1]; P[2][0] = t0; P[2][1] = t1;
        }
    } while (tri_min_angle(P[0], P[1], P[2]) < 3 * PI / 180);
}

/* Safety of a triangle-case answer tm: positive before, ~0 at tm, and, with
   no root, positive far out.  Returns 0 on failure. */
static int check_triangle_answer(const double P[3][2], const double V[3][2], double tm, double horizon,
                                 double *worst_at_root)
{
    int k;
    if (tm < HUGE_VAL) {
        long double d, sc;
        for (k = 0; k < 1000; k++)
            if (!(det_at(P[0], V[0], P[1], V[1], P[2], V[2], (long double)tm * k / 1000) > 0)) return 0;
        if (!(det_at(P[0], V[0], P[1], V[1], P[2], V[2], (long double)tm * (1 - 1e-9)) > 0)) return 0;
        d = det_at(P[0], V[0], P[1], V[1], P[2], V[2], tm);
        sc = det_scale(P[0], V[0], P[1], V[1], P[2], V[2], tm);
        if ((double)(fabsl(d) / sc) > *worst_at_root) *worst_at_root = (double)(fabsl(d) / sc);
        if (!(fabsl(d) <= 1e-8L * sc)) return 0;
        return 1;
    }
    for (k = 0; k <= 2000; k++) {
        long double t = (long double)horizon * k / 2000;
        if (!(det_at(P[0], V[0], P[1], V[1], P[2], V[2], t) > 0)) return 0;
    }
    for (k = 0; k <= 60; k++) {
        long double t = (long double)horizon * powl(10.0L, (long double)k / 4);
        if (!(det_at(P[0], V[0], P[1], V[1], P[2], V[2], t) > 0)) return 0;
    }
    return 1;
}

static void test_triangle_case(void)
{
    int n, bad_safe = 0, bad_bf = 0, finite = 0, tangent_pairs = 0, nonfinite_ok = 0;
    double worst_root = 0, worst_rel = 0;
    for (n = 0; n < 3000; n++) {
        double P[3][2], V[3][2], scale = exp(bpt_rng_range(-5, 5)), vs = scale * exp(bpt_rng_range(-2, 2)), tm, bf, T;
        int i;
        random_triangle(P, scale);
        for (i = 0; i < 3; i++) { V[i][0] = vs * bpt_rng_range(-1, 1); V[i][1] = vs * bpt_rng_range(-1, 1); }
        tm = bp__collinear_time(P[0], V[0], P[1], V[1], P[2], V[2], HUGE_VAL, 0);
        T = tm < HUGE_VAL ? 1.5 * tm : 50 * scale / vs;
        if (!check_triangle_answer((const double(*)[2])P, (const double(*)[2])V, tm, 50 * scale / vs, &worst_root)) bad_safe++;
        bf = brute_root(P[0], V[0], P[1], V[1], P[2], V[2], T, 20000, 0);
        if (tm < HUGE_VAL) {
            finite++;
            if (bf < HUGE_VAL) {
                double rel = fabs(tm - bf) / bf;
                if (rel > worst_rel) worst_rel = rel;
                if (!(rel <= 1e-9)) bad_bf++;
            } else {
                /* no sign change on the grid: acceptable only for a double
                   root pair inside one grid cell (det touches 0 at tm) */
                long double r[2];
                if (ref_roots(P[0], V[0], P[1], V[1], P[2], V[2], r) == 2 && r[1] - r[0] < T / 20000 &&
                    fabsl(r[0] - tm) <= 1e-9L * tm)
                    tangent_pairs++;
                else
                    bad_bf++;
            }
        } else {
            if (bf < HUGE_VAL) bad_bf++; else nonfinite_ok++;
        }
    }
    BPT_CHECK(bad_safe == 0, "triangle case, 3000 random triangles/directions (scales 1e-5..1e5): det > 0 on [0, tmax) "
              "(1000 samples + tmax(1-1e-9)), |det(tmax)| <= 1e-8 |e1||e2| (worst %.3g), no root -> positive to 1e15 horizons",
              worst_root);
    BPT_CHECK(bad_bf == 0 && finite > 300 && nonfinite_ok > 300,
              "triangle case: tmax == first sign change of grid(20000)+bisection brute force within 1e-9 "
              "(%d with a root, worst rel %.3g; %d tangent pairs inside one cell; %d without a root, brute force agrees)",
              finite, worst_rel, tangent_pairs, nonfinite_ok);

    /* alpha == 0 exactly: B moves with A, C with A + w */
    {
        int bad = 0, roots = 0;
        double worst = 0;
        for (n = 0; n < 1000; n++) {
            double P[3][2], V[3][2], tm, r;
            long double g, b;
            int i;
            random_triangle(P, 1.0);
            V[0][0] = bpt_rng_range(-1, 1); V[0][1] = bpt_rng_range(-1, 1);
            V[1][0] = V[0][0]; V[1][1] = V[0][1];
            V[2][0] = V[0][0] + bpt_rng_range(-1, 1); V[2][1] = V[0][1] + bpt_rng_range(-1, 1);
            if (n % 2) for (i = 0; i < 2; i++) { double tmp = V[1][i]; V[1][i] = V[2][i] - V[0][i] + V[0][i]; V[2][i] = tmp; }
            tm = bp__collinear_time(P[0], V[0], P[1], V[1], P[2], V[2], HUGE_VAL, 0);
            g = det_at(P[0], V[0], P[1], V[1], P[2], V[2], 0);
            b = det_at(P[0], V[0], P[1], V[1], P[2], V[2], 1) - g;     /* linear: det = g + b t */
            r = b < 0 ? (double)(-g / b) : HUGE_VAL;
            if (r < HUGE_VAL) {
                roots++;
                if (!(fabs(tm - r) <= 1e-12 * r)) bad++;
                if (fabs(tm - r) / r > worst) worst = fabs(tm - r) / r;
            } else if (tm != HUGE_VAL) bad++;
        }
        BPT_CHECK(bad == 0 && roots > 100, "exactly linear motion (alpha == 0): tmax == -gamma/beta to 1e-12 "
                  "(%d roots, worst rel %.3g), HUGE_VAL when beta >= 0", roots, worst);
    }

    /* nearly common velocity: V_i = W + rho * noise, rho down to 1e-12 */
    {
        int bad = 0, cnt = 0, roots = 0;
        double worst = 0, worst_root2 = 0;
        for (n = 0; n < 2000; n++) {
            double P[3][2], V[3][2], W[2], rho = pow(10.0, -(double)(3 * (1 + n % 4))), tm;
            long double r[2];
            int i, nr;
            random_triangle(P, 1.0);
            W[0] = bpt_rng_range(-1, 1); W[1] = bpt_rng_range(-1, 1);
            for (i = 0; i < 3; i++) { V[i][0] = W[0] + rho * bpt_rng_range(-1, 1); V[i][1] = W[1] + rho * bpt_rng_range(-1, 1); }
            tm = bp__collinear_time(P[0], V[0], P[1], V[1], P[2], V[2], HUGE_VAL, 0);
            nr = ref_roots(P[0], V[0], P[1], V[1], P[2], V[2], r);
            {
                long double first = HUGE_VAL;
                int k;
                for (k = 0; k < nr; k++) if (r[k] > 0) { first = r[k]; break; }
                if (first < HUGE_VAL) {
                    roots++;
                    if (!(fabsl(tm - first) <= 1e-9L * first)) bad++;
                    if ((double)(fabsl(tm - first) / first) > worst) worst = (double)(fabsl(tm - first) / first);
                    if (!check_triangle_answer((const double(*)[2])P, (const double(*)[2])V, tm, 1, &worst_root2)) bad++;
                } else if (tm != HUGE_VAL) bad++;
            }
            cnt++;
        }
        BPT_CHECK(bad == 0 && roots > 200, "near-common velocity (rho 1e-3..1e-12, roots up to ~1e12): tmax == long double "
                  "reference root within 1e-9 and safe (%d of %d with a root, worst rel %.3g)", roots, cnt, worst);
    }

    /* designed near-double roots: det = a ((t - t0)^2 -+ delta^2) */
    {
        int bad_cross = 0, bad_miss = 0, cross = 0, miss = 0, spurious = 0, tiny_total = 0, tiny_missed = 0, tiny_bad = 0,
            tiny_real_miss = 0;
        double worst = 0;
        for (n = 0; n < 4000; n++) {
            double P[3][2], V[3][2], B0[2], VB[2], VC[2], C0[2], a, t0 = bpt_rng_range(0.5, 2), rel, delta, m00, m01, m10, m11,
                r0, r1, dt, tm, A[2], VA[2];
            int crossing = n % 2, i, tiny = (n % 8) >= 6;
            rel = tiny ? pow(10.0, -bpt_rng_range(8, 10)) : pow(10.0, -bpt_rng_range(2, 6));
            delta = rel * t0;
            do {
                B0[0] = bpt_rng_range(-1, 1); B0[1] = bpt_rng_range(-1, 1);
                VB[0] = bpt_rng_range(-1, 1); VB[1] = bpt_rng_range(-1, 1);
                VC[0] = bpt_rng_range(-1, 1); VC[1] = bpt_rng_range(-1, 1);
                a = VB[0] * VC[1] - VB[1] * VC[0];
            } while (fabs(a) < 0.1 || fabs(B0[0] * VB[1] - B0[1] * VB[0]) < 0.1);
            if (a < 0) { double t = VC[0]; VC[0] = VC[1]; VC[1] = t; a = -a; }
            /* solve det(B0, C0) = -+ a delta^2, det(VB, C0) = -det(B0, VC) */
            m00 = -B0[1]; m01 = B0[0]; m10 = -VB[1]; m11 = VB[0];
            r0 = (crossing ? -1 : 1) * a * delta * delta;
            r1 = -(B0[0] * VC[1] - B0[1] * VC[0]);
            dt = m00 * m11 - m01 * m10;
            C0[0] = (r0 * m11 - m01 * r1) / dt;
            C0[1] = (m00 * r1 - m10 * r0) / dt;
            A[0] = bpt_rng_range(-2, 2); A[1] = bpt_rng_range(-2, 2); VA[0] = bpt_rng_range(-1, 1); VA[1] = bpt_rng_range(-1, 1);
            P[0][0] = A[0]; P[0][1] = A[1];
            V[0][0] = VA[0]; V[0][1] = VA[1];
            for (i = 0; i < 2; i++) {
                P[1][i] = A[i] + B0[i] - t0 * VB[i]; V[1][i] = VA[i] + VB[i];
                P[2][i] = A[i] + C0[i] - t0 * VC[i]; V[2][i] = VA[i] + VC[i];
            }
            if (!(det_at(P[0], V[0], P[1], V[1], P[2], V[2], 0) > 0)) continue;
            tm = bp__collinear_time(P[0], V[0], P[1], V[1], P[2], V[2], HUGE_VAL, 0);
            if (tiny) {
                /* below double resolution (delta/t0 1e-8..1e-10): the data
                   themselves are rounded at ~1e-16 of det, so only require
                   an answer at t0 (within 1e-6) or none; count the misses */
                tiny_total++;
                if (tm == HUGE_VAL) {
                    if (crossing) {
                        /* a miss is allowed only below the resolution of the
                           data: the designed minimum a delta^2 of det must be
                           within a few roundings of the coordinates at t0
                           (|P| + t0 |V|)^2 eps; otherwise it is a real miss */
                        double big = 0, res;
                        int j;
                        for (i = 0; i < 3; i++)
                            for (j = 0; j < 2; j++) if (fabs(P[i][j]) + t0 * fabs(V[i][j]) > big) big = fabs(P[i][j]) + t0 * fabs(V[i][j]);
                        res = 64 * DBL_EPSILON * big * big;
                        tiny_missed++;
                        if (!(a * delta * delta <= res)) tiny_real_miss++;
                    }
                }
                else if (!(fabs(tm - t0) <= 1e-6 * t0)) tiny_bad++;
                continue;
            }
            {
                long double r[2];
                int nr = ref_roots(P[0], V[0], P[1], V[1], P[2], V[2], r);
                if (crossing) {
                    cross++;
                    if (nr != 2 || !(r[0] > 0)) { bad_cross++; continue; }
                    /* conditioning of a close pair: |dt| ~ 1e-16 t0^2 / delta */
                    if (!(fabsl(tm - r[0]) <= 1e-3L * delta)) bad_cross++;
                    if ((double)(fabsl(tm - r[0]) / delta) > worst) worst = (double)(fabsl(tm - r[0]) / delta);
                    {
                        int k, ok = 1;
                        for (k = 0; k < 1000; k++)
                            if (!(det_at(P[0], V[0], P[1], V[1], P[2], V[2], (long double)tm * (1 - 1e-6) * k / 999) > 0)) ok = 0;
                        if (!(det_at(P[0], V[0], P[1], V[1], P[2], V[2], t0) < 0)) ok = 0;   /* the designed flip exists */
                        if (!ok) bad_cross++;
                    }
                } else {
                    miss++;
                    if (tm != HUGE_VAL) {
                        /* a conservative answer at the near-touch is allowed */
                        if (fabs(tm - t0) <= 1e-3 * t0) spurious++; else bad_miss++;
                    }
                }
            }
        }
        BPT_CHECK(bad_cross == 0 && cross > 500, "near-double roots t0 +- delta (delta/t0 1e-2..1e-6): tmax == first root "
                  "within 1e-3 delta (worst %.3g delta), det > 0 before, det(t0) < 0 (%d cases)", worst, cross);
        BPT_CHECK(bad_miss == 0 && miss > 500, "near-touch without crossing (min det = +a delta^2): no root, or a conservative "
                  "one at t0 (%d cases, %d conservative)", miss, spurious);
        BPT_CHECK(tiny_bad == 0 && tiny_total > 500, "sub-resolution pairs (delta/t0 1e-8..1e-10, %d cases): tmax is t0 within "
                  "1e-6 or HUGE_VAL", tiny_total);
        BPT_CHECK(tiny_real_miss == 0, "sub-resolution pairs: each of the %d missed crossings is below the resolution of the "
                  "data (min det a delta^2 <= 64 eps (|P| + t0 |V|)^2; %d are not); their flips last < 2e-8 t0 and the exact "
                  "check after each step covers them", tiny_missed, tiny_real_miss);
    }
}

/* ---- (b) edge / vertex ----------------------------------------------------- */

static void test_edge_case(void)
{
    int n, bad = 0, bad_dist = 0, roots = 0, outside_ignored = 0, contacts = 0, bad_contact = 0, bad_outside = 0;
    double worst_dist = 0;
    for (n = 0; n < 6000; n++) {
        double A[2], B[2], P[2], VA[2], VB[2], VP[2], tm, ref = HUGE_VAL, T;
        int mode = n % 3, i, k;
        long double r[2];
        int nr;
        /* mode 0: random; 1: constructed contact inside the segment at t0;
           2: constructed collinearity outside the segment at t0 */
        for (i = 0; i < 2; i++) {
            VA[i] = bpt_rng_range(-1, 1); VB[i] = bpt_rng_range(-1, 1); VP[i] = bpt_rng_range(-1, 1);
        }
        if (mode == 0) {
            for (i = 0; i < 2; i++) { A[i] = bpt_rng_range(-1, 1); B[i] = bpt_rng_range(-1, 1); P[i] = bpt_rng_range(-1, 1); }
        } else {
            double t0 = bpt_rng_range(0.1, 2), s0 = mode == 1 ? bpt_rng_range(0.02, 0.98) : (n % 2 ? bpt_rng_range(1.1, 2) : bpt_rng_range(-1, -0.1));
            double A0[2], B0[2], P0[2];
            for (i = 0; i < 2; i++) { A0[i] = bpt_rng_range(-1, 1); B0[i] = bpt_rng_range(-1, 1); }
            for (i = 0; i < 2; i++) {
                P0[i] = A0[i] + s0 * (B0[i] - A0[i]);
                A[i] = A0[i] - t0 * VA[i]; B[i] = B0[i] - t0 * VB[i]; P[i] = P0[i] - t0 * VP[i];
            }
            if (mode == 1) contacts++;
            tm = bp__collinear_time(A, VA, B, VB, P, VP, HUGE_VAL, 1);
            if (mode == 1 && !(tm <= t0 * (1 + 1e-9))) bad_contact++;    /* contact at t0 at the latest */
            if (mode == 2 && fabs(tm - t0) <= 1e-9 * t0) {
                /* returned the outside collinearity: only right if the vertex
                   really is on the segment there (it is not, by design) */
                long double s = seg_param(A, VA, B, VB, P, VP, t0);
                if (s < -1e-9L || s > 1 + 1e-9L) bad_outside++;
            }
            if (mode == 2 && !(fabs(tm - t0) <= 1e-9 * t0)) outside_ignored++;
        }
        tm = bp__collinear_time(A, VA, B, VB, P, VP, HUGE_VAL, 1);
        /* reference: first positive root of the long double polynomial with
           the vertex within the segment */
        nr = ref_roots(A, VA, B, VB, P, VP, r);
        for (k = 0; k < nr; k++) {
            long double s;
            if (!(r[k] > 0) || !(r[k] < HUGE_VAL)) continue;
            s = seg_param(A, VA, B, VB, P, VP, r[k]);
            if (s >= 0 && s <= 1) { ref = (double)r[k]; break; }
        }
        if (ref < HUGE_VAL) {
            long double s = seg_param(A, VA, B, VB, P, VP, ref);
            roots++;
            /* a root whose segment parameter is within rounding of 0 or 1 may
               go either way */
            if (!(fabs(tm - ref) <= 1e-9 * ref) && !(s < 1e-9L || s > 1 - 1e-9L)) bad++;
        } else if (tm != HUGE_VAL) {
            long double s = seg_param(A, VA, B, VB, P, VP, tm);
            if (!(s > -1e-9L && s < 1 + 1e-9L)) bad++;
        }
        /* distance along time: positive on [0, tmax), ~0 at tmax */
        T = tm < HUGE_VAL ? tm : 20;
        {
            long double len = 0;
            for (k = 0; k < 2000; k++) {
                long double t = (long double)T * k / 2000;
                if (tm < HUGE_VAL && !(seg_dist_at(A, VA, B, VB, P, VP, t) > 0)) bad_dist++;
                if (tm == HUGE_VAL && k > 0) {
                    /* no contact: the brute force finds no crossing either */
                }
            }
            if (tm < HUGE_VAL) {
                long double d = seg_dist_at(A, VA, B, VB, P, VP, tm);
                long double ex = ((long double)B[0] - A[0]) + tm * ((long double)VB[0] - VA[0]);
                long double ey = ((long double)B[1] - A[1]) + tm * ((long double)VB[1] - VA[1]);
                len = sqrtl(ex * ex + ey * ey);
                if ((double)(d / len) > worst_dist) worst_dist = (double)(d / len);
                if (!(d <= 1e-9L * len)) bad_dist++;
            } else if (brute_root(A, VA, B, VB, P, VP, 20, 20000, 1) < HUGE_VAL) {
                bad_dist++;
            }
        }
    }
    BPT_CHECK(bad == 0 && roots > 1000, "edge/vertex: tmax == first long double root with the vertex within the segment "
              "(6000 cases, %d with contact)", roots);
    BPT_CHECK(bad_dist == 0, "edge/vertex: distance vertex-segment > 0 on 2000 samples of [0, tmax), <= 1e-9 |AB| at tmax "
              "(worst %.3g); with no contact the grid brute force finds none on [0, 20]", worst_dist);
    BPT_CHECK(bad_contact == 0, "edge/vertex: a constructed contact at (t0, s0 in (0,1)) bounds tmax by t0 (%d cases)", contacts);
    BPT_CHECK(bad_outside == 0 && outside_ignored > 1500, "edge/vertex: a collinear moment outside the segment (s0 < 0 or > 1) "
              "is not returned (%d of 2000 ignored; the rest had an earlier real contact)", outside_ignored);
}

/* ---- (c) the whole chart ----------------------------------------------------- */


static void solver_free(bp__solver *S)
{
    bp__solver_free(S);       /* frees the rest shapes too */
}

/* The step bound with the loops of at most scan_max vertices scanned
   instead of hashed (0: every loop in the table); the solver's default
   (BP__SCAN_MAX) is restored. */
static double bound_scanned(bp__solver *S, const double *x, const double *v, uint32_t scan_max)
{
    double t;
    bp__hash_set_scan(&S->hash, S->nloops, scan_max);
    t = bp__step_bound(S, x, v, HUGE_VAL);
    bp__hash_set_scan(&S->hash, S->nloops, BP__SCAN_MAX);
    return t;
}

/* The solver bp_chart_optimize builds, set up the same way by hand. */
static void solver_for_chart(bp__solver *S, const bp_allocator *a, const bp_chart *ch, const bp_mesh *m)
{
    /* the library's own set-up (bp__solver_chart, as bp_chart_optimize) */
    bp_options o;
    memset(&o, 0, sizeof o);
    o.energy = BP_ENERGY_SYMMETRIC_DIRICHLET;
    bp__solver_chart(S, a, ch, m, &o, NULL, NULL);
}

/* The brute force: every triangle, then (same cap as the library when no
   triangle degenerates) every (edge, vertex) pair of every loop. */
static double brute_step_bound(const bp__solver *S, const double *x, const double *v, int use_triangles)
{
    double tmax = HUGE_VAL;
    uint32_t t, L;
    if (use_triangles)
        for (t = 0; t < S->nt; t++) {
            const uint32_t *tr = S->tri + 3 * (size_t)t;
            tmax = bp__collinear_time(x + 2 * (size_t)tr[0], v + 2 * (size_t)tr[0], x + 2 * (size_t)tr[1],
                                      v + 2 * (size_t)tr[1], x + 2 * (size_t)tr[2], v + 2 * (size_t)tr[2], tmax, 0);
        }
    if (tmax == HUGE_VAL) {
        double vmax = 0;
        uint32_t i;
        for (i = 0; i < 2 * S->nv; i++) if (fabs(v[i]) > vmax) vmax = fabs(v[i]);
        tmax = vmax > 0 ? 100 * S->mean_edge * S->nb / vmax : 1;
    }
    for (L = 0; L < S->nloops; L++) {
        uint32_t s0 = S->loop_start[L], n = S->loop_start[L + 1] - s0, e, k;
        for (e = 0; e < n; e++) {
            uint32_t va = S->loop_vertices[s0 + e], vb = S->loop_vertices[s0 + (e + 1) % n];
            for (k = 0; k < n; k++) {
                uint32_t vp;
                if (k == e || k == (e + 1) % n) continue;
                vp = S->loop_vertices[s0 + k];
                tmax = bp__collinear_time(x + 2 * (size_t)va, v + 2 * (size_t)va, x + 2 * (size_t)vb, v + 2 * (size_t)vb,
                                          x + 2 * (size_t)vp, v + 2 * (size_t)vp, tmax, 1);
            }
        }
    }
    return tmax;
}

static int map_valid(const bp_chart *ch, const double *uv)
{
    bp_check_report rep;
    bp_status st = bp_check(ch->triangles, ch->num_triangles, uv, ch->num_vertices, NULL, &rep, NULL);
    if (st != BP_OK && st != BP_ERR_NOT_BIJECTIVE && st != BP_ERR_NONFINITE) return -1;
    return st == BP_OK;
}

typedef struct chart_stats {
    int cases, equal, equal_bnd, boundary_binds, shrunk, safe_bad, tight, tight_total, bsafe_bad, btight, btight_total;
    int scan_cases, scan_same;
    double worst_rel;
} chart_stats;

/* Conflicting edge pairs within each loop (the library's own exact pair
   test, bp__edges_conflict, over ALL pairs: no grid). */
static int loop_conflicts(const bp_chart *ch, const double *uv)
{
    uint32_t L, i, j;
    int cnt = 0;
    for (L = 0; L < ch->num_loops; L++) {
        uint32_t s0 = ch->loop_start[L], n = ch->loop_start[L + 1] - s0;
        for (i = 0; i < n; i++)
            for (j = i + 1; j < n; j++) {
                bp__dedge e, f;
                e.a = ch->loop_vertices[s0 + i]; e.b = ch->loop_vertices[s0 + (i + 1) % n];
                f.a = ch->loop_vertices[s0 + j]; f.b = ch->loop_vertices[s0 + (j + 1) % n];
                if (bp__edges_conflict(uv, &e, &f)) cnt++;
            }
    }
    return cnt;
}

/* Directions: 0 random per-vertex, 1-2 smooth random fields (waves with
   wavelength ~ the chart), 3 minus the objective gradient. */
static void make_direction(int kind, const bp__solver *S, const double *x, double *v, double size)
{
    uint32_t i;
    if (kind == 3) {
        double ed, vmax = 0;
        bp__objective((bp__solver *)S, x, v, &ed);
        for (i = 0; i < 2 * S->nv; i++) { v[i] = -v[i]; if (fabs(v[i]) > vmax) vmax = fabs(v[i]); }
        for (i = 0; i < 2 * S->nv; i++) v[i] *= 0.3 * size / vmax;
        return;
    }
    if (kind == 0) {
        for (i = 0; i < 2 * S->nv; i++) v[i] = size * bpt_rng_range(-0.05, 0.05);
        return;
    }
    {
        double k[4][2], ph[4], amp[4][2];
        int w;
        for (w = 0; w < 4; w++) {
            double ang = bpt_rng_range(0, 2 * PI), kk = bpt_rng_range(0.5, 3) * 2 * PI / size;
            k[w][0] = kk * cos(ang); k[w][1] = kk * sin(ang); ph[w] = bpt_rng_range(0, 2 * PI);
            amp[w][0] = size * bpt_rng_range(-1, 1); amp[w][1] = size * bpt_rng_range(-1, 1);
        }
        for (i = 0; i < S->nv; i++) {
            double px = x[2 * i], py = x[2 * i + 1];
            v[2 * i] = v[2 * i + 1] = 0;
            for (w = 0; w < 4; w++) {
                double s = sin(k[w][0] * px + k[w][1] * py + ph[w]);
                v[2 * i] += amp[w][0] * s;
                v[2 * i + 1] += amp[w][1] * s;
            }
        }
    }
}

static void check_chart(const char *name, const bp_chart *ch, const bp_mesh *m, int ndirs, chart_stats *st)
{
    bp__solver S;
    bp_allocator a;
    double *v = (double *)malloc(2 * ch->num_vertices * sizeof(double));
    double *y = (double *)malloc(2 * ch->num_vertices * sizeof(double));
    double lo[2] = { HUGE_VAL, HUGE_VAL }, hi[2] = { -HUGE_VAL, -HUGE_VAL }, size;
    uint32_t i, interior;
    int d;
    (void)name;
    memset(&a, 0, sizeof a);
    solver_for_chart(&S, &a, ch, m);
    for (i = 0; i < ch->num_vertices; i++) {
        int k;
        for (k = 0; k < 2; k++) {
            if (ch->uv[2 * i + k] < lo[k]) lo[k] = ch->uv[2 * i + k];
            if (ch->uv[2 * i + k] > hi[k]) hi[k] = ch->uv[2 * i + k];
        }
    }
    size = hi[0] - lo[0] > hi[1] - lo[1] ? hi[0] - lo[0] : hi[1] - lo[1];
    {
        /* an interior vertex: on no loop */
        uint8_t *on = (uint8_t *)calloc(ch->num_vertices, 1);
        for (i = 0; i < ch->loop_start[ch->num_loops]; i++) on[ch->loop_vertices[i]] = 1;
        for (i = 0; i < ch->num_vertices && on[i]; i++) {}
        interior = i < ch->num_vertices ? i : BP__NONE;
        free(on);
    }
    for (d = 0; d < ndirs; d++) {
        double t_hash, t_brute, t_tri, t_hash_b, t_brute_b, cap, saved;
        uint32_t nt_save = S.nt;
        make_direction(d % 4, &S, ch->uv, v, size);
        t_hash = bp__step_bound(&S, ch->uv, v, HUGE_VAL);
        t_brute = brute_step_bound(&S, ch->uv, v, 1);
        /* a minimum: the same bits whichever loops are scanned */
        st->scan_cases++;
        if (bound_scanned(&S, ch->uv, v, 0) == t_hash && bound_scanned(&S, ch->uv, v, 0xffffffffu) == t_hash)
            st->scan_same++;
        st->cases++;
        if (t_hash == t_brute) st->equal++;
        else if (fabs(t_hash - t_brute) / t_brute > st->worst_rel) st->worst_rel = fabs(t_hash - t_brute) / t_brute;
        /* which constraint binds? */
        {
            uint32_t t;
            t_tri = HUGE_VAL;
            for (t = 0; t < S.nt; t++) {
                const uint32_t *tr = S.tri + 3 * (size_t)t;
                t_tri = bp__collinear_time(ch->uv + 2 * tr[0], v + 2 * tr[0], ch->uv + 2 * tr[1], v + 2 * tr[1],
                                           ch->uv + 2 * tr[2], v + 2 * tr[2], t_tri, 0);
            }
            if (t_hash < t_tri) st->boundary_binds++;
        }
        /* the boundary pairs alone (no triangles): the hash decides.  With
           no triangle the library starts from its cap, 100 mean edges * nb
           / max|v|, so far out that the swept boxes cover the whole chart
           and the hash degenerates to one cell.  To exercise it with small
           cells, an interior vertex (it belongs to no loop, so no pair
           changes) gets the speed that puts the cap at 1.5x .. 3x the first
           boundary contact: the vertices are swept only that far. */
        S.nt = 0;
        t_brute_b = brute_step_bound(&S, ch->uv, v, 0);
        saved = interior != BP__NONE ? v[2 * interior] : 0;
        if (d % 2 == 1 && interior != BP__NONE) {
            double vmax = 0, want;
            for (i = 0; i < 2 * S.nv; i++) if (fabs(v[i]) > vmax) vmax = fabs(v[i]);
            want = 100 * S.mean_edge * S.nb / (bpt_rng_range(1.5, 3) * t_brute_b);
            if (want > vmax) { v[2 * interior] = want; st->shrunk++; }
            t_brute_b = brute_step_bound(&S, ch->uv, v, 0);
        }
        t_hash_b = bp__step_bound(&S, ch->uv, v, HUGE_VAL);
        st->scan_cases++;
        if (bound_scanned(&S, ch->uv, v, 0) == t_hash_b && bound_scanned(&S, ch->uv, v, 0xffffffffu) == t_hash_b)
            st->scan_same++;
        S.nt = nt_save;
        {
            double vmax = 0;
            for (i = 0; i < 2 * S.nv; i++) if (fabs(v[i]) > vmax) vmax = fabs(v[i]);
            cap = 100 * S.mean_edge * S.nb / vmax;        /* the library's "large value" */
        }
        if (t_hash_b < cap) {
            /* boundary-only bound: no loop touches itself before, one does after */
            int k, ok = 1;
            double fr[5] = { 0.1, 0.5, 0.9, 0.99, 0.999999 };
            for (k = 0; k < 5; k++) {
                for (i = 0; i < 2 * ch->num_vertices; i++) y[i] = ch->uv[i] + fr[k] * t_hash_b * v[i];
                if (loop_conflicts(ch, y)) ok = 0;
            }
            if (!ok) st->bsafe_bad++;
            for (i = 0; i < 2 * ch->num_vertices; i++) y[i] = ch->uv[i] + (1 + 1e-6) * t_hash_b * v[i];
            st->btight_total++;
            if (loop_conflicts(ch, y)) st->btight++;
        }
        st->cases++;
        if (t_hash_b == t_brute_b) { st->equal++; st->equal_bnd++; }
        else if (fabs(t_hash_b - t_brute_b) / t_brute_b > st->worst_rel) st->worst_rel = fabs(t_hash_b - t_brute_b) / t_brute_b;
        if (interior != BP__NONE) v[2 * interior] = saved;     /* back to the direction t_hash was computed for */
        /* safe: valid at samples of [0, tmax); tight: invalid just after */
        if (t_hash < HUGE_VAL) {
            int k, ok = 1;
            double fr[6] = { 0.1, 0.5, 0.9, 0.99, 0.999999, 0 };
            for (k = 0; k < 5; k++) {
                for (i = 0; i < 2 * ch->num_vertices; i++) y[i] = ch->uv[i] + fr[k] * t_hash * v[i];
                if (map_valid(ch, y) != 1) ok = 0;
            }
            if (!ok) st->safe_bad++;
            for (i = 0; i < 2 * ch->num_vertices; i++) y[i] = ch->uv[i] + (1 + 1e-6) * t_hash * v[i];
            st->tight_total++;
            if (map_valid(ch, y) == 0) st->tight++;
        }
    }
    solver_free(&S);
    free(v);
    free(y);
}

static void test_real_charts(void)
{
    const char *files[3] = { "tests/data/bishop_part_f1000.obj", "tests/data/face_holes.off", "tests/data/spot.obj" };
    int f;
    for (f = 0; f < 3; f++) {
        bp_mesh mesh;
        bp_atlas atlas;
        bp_error err;
        bp_options opt;
        chart_stats st;
        uint32_t c;
        int init_ok = 1;
        memset(&opt, 0, sizeof opt);
        memset(&st, 0, sizeof st);
        if (!BPT_CHECK(bp_read_mesh(files[f], &mesh, NULL, &err) == BP_OK, "read %s: %s", files[f], err.message)) continue;
        if (!BPT_CHECK(bp_atlas_build(&atlas, &mesh, &opt, &err) == BP_OK, "%s: charts (%s)", files[f], err.message)) {
            bp_mesh_free(&mesh, NULL);
            continue;
        }
        for (c = 0; c < atlas.num_charts; c++) {
            if (bp_chart_init(&atlas.charts[c], &mesh, &opt, &err) != BP_OK) { init_ok = 0; continue; }
            check_chart(files[f], &atlas.charts[c], &mesh, atlas.num_charts > 1 ? 8 : 40, &st);
            if (f != 1) {
                /* an optimized map: the boundary has moved and bent */
                opt.max_iterations = f == 0 ? 60 : 25;
                bp_chart_optimize(&atlas.charts[c], c, &mesh, &opt, &err);
                check_chart(files[f], &atlas.charts[c], &mesh, atlas.num_charts > 1 ? 8 : 40, &st);
                opt.max_iterations = 0;
            }
        }
        BPT_CHECK(init_ok, "%s: start maps of all %u charts", files[f], atlas.num_charts);
        BPT_CHECK(st.equal == st.cases, "%s: bp__step_bound (swept hash) == brute force over all triangles and all "
                  "(edge, vertex) pairs of each loop, exactly, in %d of %d cases (%d boundary-only cases, %d of them with the cap near the contact; worst rel diff %.3g)",
                  files[f], st.equal, st.cases, st.cases / 2, st.shrunk, st.worst_rel);
        BPT_CHECK(st.scan_same == st.scan_cases && st.scan_cases > 0, "%s: the step bound is the same bits with the small "
                  "loops scanned (the default), every loop in the table and every loop scanned, in %d of %d cases",
                  files[f], st.scan_same, st.scan_cases);
        BPT_CHECK(st.safe_bad == 0, "%s: map exactly valid (bp_check) at 0.1 .. 0.999999 tmax in all %d directions "
                  "(boundary bound the step in %d)", files[f], st.tight_total, st.boundary_binds);
        BPT_CHECK(st.bsafe_bad == 0 && st.btight_total > 0, "%s: boundary-only bound: no loop meets itself (all edge pairs, "
                  "exact) at 0.1 .. 0.999999 tmax in all %d directions where a pair meets before the cap",
                  files[f], st.btight_total);
        BPT_CHECK(st.btight * 10 >= st.btight_total * 9, "%s: boundary-only bound is tight: a loop meets itself at "
                  "(1 + 1e-6) tmax in %d of %d directions", files[f], st.btight, st.btight_total);
        BPT_CHECK(st.tight * 10 >= st.tight_total * 9, "%s: the bound is tight: the map is invalid at (1 + 1e-6) tmax in "
                  "%d of %d directions", files[f], st.tight, st.tight_total);
        bp_atlas_free(&atlas);
        bp_mesh_free(&mesh, NULL);
    }
}

/* ---- (d) the barrier pair's curvature for Newton (>>barrier) ------------- */

/* The barrier of one pair, (eps / d - 1)^2 for d < eps, with d the
   distance from P to the segment AB: long double, written here. */
static long double pair_energy(const double *x, double eps)
{
    long double ex = (long double)x[4] - x[2], ey = (long double)x[5] - x[3];
    long double qx = (long double)x[0] - x[2], qy = (long double)x[1] - x[3];
    long double s = (qx * ex + qy * ey) / (ex * ex + ey * ey), dx, dy, d;
    if (s < 0) s = 0;
    if (s > 1) s = 1;
    dx = qx - s * ex; dy = qy - s * ey;
    d = sqrtl(dx * dx + dy * dy);
    return d < eps ? ((long double)eps / d - 1) * ((long double)eps / d - 1) : 0;
}

/* Checks bp__barrier_pair_hessian against second differences of the
   energy above (the whole Hessian, unprojected), then its projection: PSD
   on random vectors and K_proj - K PSD too (only negative eigenvalues were
   raised), and where the closest point is inside the segment the whole
   Hessian differs from the Gauss-Newton part (the slide-rotate coupling
   that part misses: the Gauss-Newton part alone fails this test). */
static void test_barrier_pair_hessian(void)
{
    int trial, fd_bad = 0, psd_bad = 0, raise_bad = 0, inside = 0, inside_differs = 0, far_ok = 1, n = 0;
    double worst = 0;
    for (trial = 0; trial < 400; trial++) {
        double x[6], K0[36], K[36], G[36], eps = 0.5, h, scale = 0;
        long double f0;
        int i, j, k, interior;
        x[2] = bpt_rng_range(-1, 1); x[3] = bpt_rng_range(-1, 1);
        x[4] = x[2] + bpt_rng_range(0.5, 1.5); x[5] = x[3] + bpt_rng_range(-0.5, 0.5);
        {   /* P at a random distance in (eps/50, eps) from a random point of (or beyond) the segment */
            double s = bpt_rng_range(-0.3, 1.3), ex = x[4] - x[2], ey = x[5] - x[3], L = sqrt(ex * ex + ey * ey);
            double d = eps * pow(50, -bpt_rng_range(0, 1)), side = trial % 2 ? 1 : -1;
            double cx = x[2] + (s < 0 ? 0 : s > 1 ? 1 : s) * ex, cy = x[3] + (s < 0 ? 0 : s > 1 ? 1 : s) * ey;
            double nx = -ey / L * side, ny = ex / L * side;
            if (s < 0 || s > 1) { double a = bpt_rng_range(-1.2, 1.2); nx = cos(a) * (s < 0 ? -ex : ex) / L - sin(a) * (s < 0 ? -ey : ey) / L;
                                  ny = sin(a) * (s < 0 ? -ex : ex) / L + cos(a) * (s < 0 ? -ey : ey) / L; }
            x[0] = cx + d * nx; x[1] = cy + d * ny;
            interior = s > 0.02 && s < 0.98;
            if (s > -0.02 && s < 0.02) continue;                 /* near the switch: differences straddle it */
            if (s > 0.98 && s < 1.02) continue;
            h = 1e-4 * d;
        }
        if (!bp__barrier_pair_hessian(x, x + 2, x + 4, eps, 0, K0)) continue;
        memcpy(K, K0, sizeof K);
        bp__barrier_pair_hessian(x, x + 2, x + 4, eps, 1, K);
        n++;
        f0 = pair_energy(x, eps);
        (void)f0;
        for (i = 0; i < 36; i++) if (fabs(K0[i]) > scale) scale = fabs(K0[i]);
        for (i = 0; i < 6; i++)
            for (j = 0; j < 6; j++) {
                double y[6];
                long double fpp, fpm, fmp, fmm;
                memcpy(y, x, sizeof y); y[i] += h; y[j] += h; fpp = pair_energy(y, eps);
                memcpy(y, x, sizeof y); y[i] += h; y[j] -= h; fpm = pair_energy(y, eps);
                memcpy(y, x, sizeof y); y[i] -= h; y[j] += h; fmp = pair_energy(y, eps);
                memcpy(y, x, sizeof y); y[i] -= h; y[j] -= h; fmm = pair_energy(y, eps);
                G[6 * i + j] = (double)((fpp - fpm - fmp + fmm) / (4.0L * h * h));
            }
        for (i = 0; i < 36; i++) {
            double e = fabs(G[i] - K0[i]) / scale;
            if (e > worst) worst = e;
            if (e > 1e-4) fd_bad++;
        }
        for (k = 0; k < 20; k++) {
            double u[6], a = 0, b = 0, nu = 0;
            for (i = 0; i < 6; i++) { u[i] = bpt_rng_range(-1, 1); nu += u[i] * u[i]; }
            for (i = 0; i < 6; i++)
                for (j = 0; j < 6; j++) { a += u[i] * K[6 * i + j] * u[j]; b += u[i] * (K[6 * i + j] - K0[6 * i + j]) * u[j]; }
            if (a < -1e-10 * scale * nu) psd_bad++;
            if (b < -1e-10 * scale * nu) raise_bad++;
        }
        if (interior) {
            /* the Gauss-Newton part f'' g g^T, g = grad d = (n, -(1-s) n, -s n) */
            double ex = x[4] - x[2], ey = x[5] - x[3], s = ((x[0] - x[2]) * ex + (x[1] - x[3]) * ey) / (ex * ex + ey * ey);
            double dx = x[0] - x[2] - s * ex, dy = x[1] - x[3] - s * ey, d = sqrt(dx * dx + dy * dy), g[6], f2, diff = 0;
            f2 = 2 * eps * eps / (d * d * d * d) + 4 * (eps / d - 1) * eps / (d * d * d);
            g[0] = dx / d; g[1] = dy / d; g[2] = -(1 - s) * g[0]; g[3] = -(1 - s) * g[1]; g[4] = -s * g[0]; g[5] = -s * g[1];
            for (i = 0; i < 6; i++) for (j = 0; j < 6; j++) diff += fabs(K0[6 * i + j] - f2 * g[i] * g[j]);
            inside++;
            if (diff > 1e-3 * scale) inside_differs++;
        }
    }
    {   /* beyond eps: no term */
        double x[6] = {0, 0.6, -1, 0, 1, 0}, K[36];
        far_ok = !bp__barrier_pair_hessian(x, x + 2, x + 4, 0.5, 1, K);
    }
    BPT_CHECK(n >= 300 && fd_bad == 0, "(d) barrier pair Hessian = second differences of (eps/d - 1)^2 (long double) "
              "on %d pairs, all 36 entries (worst relative error %.2g)", n, worst);
    BPT_CHECK(psd_bad == 0 && raise_bad == 0, "(d) the projected pair Hessian is PSD and K_proj - K is PSD (20 random "
              "vectors x %d pairs)", n);
    BPT_CHECK(inside > 100 && inside_differs == inside, "(d) closest point inside the segment: the whole Hessian is not "
              "the Gauss-Newton part (%d of %d pairs differ)", inside_differs, inside);
    BPT_CHECK(far_ok, "(d) a pair beyond eps has no term");
}

int main(void)
{
    bpt_rng_state = 0xD1B54A32D192ED03ull;
    test_triangle_case();
    test_edge_case();
    test_real_charts();
    test_barrier_pair_hessian();
    return bpt_finish();
}
